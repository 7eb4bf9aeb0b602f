//! Voorhuis' reflection reprojection against real guide buffers: a camera sliding past a mirror
//! floor that reflects a patterned wall. What a mirror pixel shows is a function of what it
//! reflects, so a history found where the reflection was matches the current frame, and one
//! found where the floor point was (primary motion) does not: the reflection moves across the
//! floor with parallax.

use rt_core::glam::{Vec2, Vec3};
use rt_core::{Camera, Image, Material, Rgb, RgbImage, Scene};
use rt_film::GuideBuffers;
use rt_integrators::{render_guides, Ctx, GuideOptions, PreviousView};
use rt_temporal::{Reflections, Svgf, SvgfInput, SvgfParams};

fn quad(s: &mut Scene, a: Vec3, b: Vec3, c: Vec3, d: Vec3, m: u32) {
    s.push_triangle([a, b, c], m);
    s.push_triangle([a, c, d], m);
}

/// A mirror (or glossy, by `floor`) floor in front of a diffuse wall.
fn scene(floor: Material) -> Scene {
    let mut s = Scene::empty();
    s.materials.push(floor);
    s.materials.push(Material::diffuse("wall", Rgb::splat(0.7)));
    quad(
        &mut s,
        Vec3::new(-10.0, 0.0, 10.0),
        Vec3::new(10.0, 0.0, 10.0),
        Vec3::new(10.0, 0.0, -4.0),
        Vec3::new(-10.0, 0.0, -4.0),
        0,
    );
    quad(
        &mut s,
        Vec3::new(-10.0, 0.0, -4.0),
        Vec3::new(10.0, 0.0, -4.0),
        Vec3::new(10.0, 8.0, -4.0),
        Vec3::new(-10.0, 8.0, -4.0),
        1,
    );
    s.objects.push(rt_core::scene::Object {
        name: "floor".into(),
        first: 0,
        count: 2,
    });
    s.objects.push(rt_core::scene::Object {
        name: "wall".into(),
        first: 2,
        count: 2,
    });
    s
}

fn camera(x: f32) -> Camera {
    Camera::look_at(
        "cam",
        Vec3::new(x, 1.5, 6.0),
        Vec3::new(x, 0.5, 0.0),
        Vec3::Y,
        50.0,
        96,
        72,
        0.0,
        1.0,
    )
}

/// A pattern fixed to the wall.
fn pattern(p: Vec3) -> Rgb {
    Rgb::splat(1.0 + 0.8 * (p.x * 2.3).sin() * (p.y * 1.9).cos())
}

/// The light of every pixel: the wall's pattern where the wall is seen, directly or in the
/// floor (reflected position).
fn light(g: &GuideBuffers) -> RgbImage {
    let (w, h) = g.size();
    let r = g.reflected.as_ref().expect("reflected guides");
    Image::from_fn(w, h, |x, y| {
        let i = y * w + x;
        if r.distance.pixels()[i] > 0.0 {
            pattern(r.position.pixels()[i])
        } else if g.object.pixels()[i] == 1 {
            pattern(g.position.pixels()[i])
        } else {
            Rgb::ZERO
        }
    })
}

fn guides(s: &Scene, cam: &Camera, prev: Option<&Camera>) -> GuideBuffers {
    let accel = rt_accel::AccelSpec::default().build_scene(s);
    let ctx = Ctx {
        scene: s,
        accel: accel.as_ref(),
        camera: cam,
    };
    let previous = prev.map(|c| PreviousView {
        camera: c,
        time: 0.0,
    });
    render_guides(&ctx, previous.as_ref(), &GuideOptions::default())
}

/// Mean absolute difference, over floor pixels that kept a history, between frame 2's
/// accumulated light and its own input (exact history gives 0: the light is noise-free).
fn floor_error(s: &Scene, reflections: Reflections) -> (f64, usize) {
    let params = SvgfParams {
        alpha: 1e-6,
        alpha_specular: 1e-6,
        alpha_moments: 1e-6,
        iterations: 0,
        feedback: 0,
        median: false,
        clip: false,
        reflections,
        ..SvgfParams::default()
    };
    let mut svgf = Svgf::new(params);
    let (c1, c2) = (camera(0.0), camera(0.35));
    let (g1, g2) = (guides(s, &c1, None), guides(s, &c2, Some(&c1)));
    let zero = Image::filled(96, 72, Rgb::ZERO);
    for g in [&g1, &g2] {
        let l = light(g);
        let out = svgf.push(&SvgfInput {
            guides: g,
            direct: &l,
            indirect: &zero,
            emission: &zero,
        });
        if std::ptr::eq(g, &g2) {
            let (mut e, mut n) = (0.0f64, 0usize);
            for (i, len) in svgf.history_lengths().iter().enumerate() {
                if g.object.pixels()[i] == 0 && *len == 2.0 {
                    // Output is albedo × filtered; compare demodulated values.
                    let a = g.reflected.as_ref().unwrap().albedo.pixels()[i].max(Rgb::splat(1e-3));
                    let got = out.pixels()[i] / a;
                    let want = l.pixels()[i] / a;
                    e += (got - want).abs().x as f64;
                    n += 1;
                }
            }
            return (e / n.max(1) as f64, n);
        }
    }
    unreachable!()
}

#[test]
fn mirror_pixels_reprojected_through_their_reflection_keep_a_matching_history() {
    let s = scene(Material::mirror("floor", Rgb::splat(0.9)));
    let (reproject, n) = floor_error(&s, Reflections::Reproject);
    let (primary, _) = floor_error(&s, Reflections::Primary);
    assert!(n > 500, "only {n} floor pixels kept a history");
    assert!(
        reproject * 4.0 < primary,
        "reflection reprojection {reproject} vs primary motion {primary}"
    );
}

#[test]
fn sharp_glossy_pixels_follow_their_representative_rays() {
    let s = scene(Material::glossy("floor", Rgb::splat(0.9), 0.9));
    let (reproject, n) = floor_error(&s, Reflections::Reproject);
    let (primary, _) = floor_error(&s, Reflections::Primary);
    assert!(n > 500, "only {n} floor pixels kept a history");
    assert!(
        reproject * 3.0 < primary,
        "representative-ray search {reproject} vs primary motion {primary}"
    );
}

#[test]
fn guide_motion_of_a_static_point_matches_its_projection() {
    // The motion vector carries a pixel to where its point projects in the previous frame.
    let s = scene(Material::diffuse("floor", Rgb::splat(0.5)));
    let (c1, c2) = (camera(0.0), camera(0.35));
    let g = guides(&s, &c2, Some(&c1));
    let (w, _) = g.size();
    for (x, y) in [(10usize, 60usize), (48, 40), (80, 20)] {
        let i = y * w + x;
        let p = g.position.pixels()[i];
        let before = c1.project(p).unwrap();
        let centre = Vec2::new(x as f32 + 0.5, y as f32 + 0.5);
        assert!((centre - g.motion.pixels()[i] - before).length() < 1e-3);
    }
}
