//! Voorhuis' reflection reprojection against real guide buffers: a camera sliding past a mirror
//! floor that reflects a patterned wall. What a mirror pixel shows is a function of what it
//! reflects, so a history found where the reflection was matches the current frame, and one
//! found where the floor point was (primary motion) does not: the reflection moves across the
//! floor with parallax.

use rt_core::glam::{Vec2, Vec3};
use rt_core::{Camera, Image, Material, Rgb, RgbImage, SampleStream, Scene};
use rt_film::{AovSet, Channel, Film, FilmBuffers, GuideBuffers, NoisyFrame};
use rt_integrators::{render_guides, Ctx, GuideOptions, PreviousView, SamplePass};
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
    let accel = rt_accel::AccelSpec::default()
        .build(s)
        .expect("the structure builds over the scene");
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

/// A lamp seen only in mirrors: in the floor (one bounce) and in the back wall by way of the
/// floor (two), next to a diffuse ceiling the mirrors also show, under a dim sky that the
/// mirror chains leaving the scene see. Frame 0 through the path tracer at 1 spp, filtered,
/// and a 256-spp reference.
fn mirrored_lamp() -> (RgbImage, RgbImage, usize, usize) {
    let toml = r#"
        [environment]
        color = [0.2, 0.2, 0.2]
        [[camera]]
        name = "c"
        position = [0, 1.5, 6]
        look_at = [0, 0.8, 0]
        fov = 60
        resolution = [64, 48]
        [[material]]
        name = "mirror"
        type = "mirror"
        color = [0.9, 0.9, 0.9]
        [[material]]
        name = "lamp"
        color = [0, 0, 0]
        emission = [10, 10, 10]
        [[geometry]]
        name = "floor"
        shape = "quad"
        vertices = [[-8, 0, 8], [8, 0, 8], [8, 0, -4], [-8, 0, -4]]
        material = "mirror"
        [[geometry]]
        name = "back"
        shape = "quad"
        vertices = [[-8, 0, -4], [8, 0, -4], [8, 6, -4], [-8, 6, -4]]
        material = "mirror"
        [[material]]
        name = "white"
        color = [0.8, 0.8, 0.8]
        [[geometry]]
        name = "ceiling"
        shape = "quad"
        vertices = [[-8, 5.05, 6], [-8, 5.05, -4], [8, 5.05, -4], [8, 5.05, 6]]
        material = "white"
        [[geometry]]
        name = "lamp"
        shape = "quad"
        vertices = [[-2.5, 5, 0], [2.5, 5, 0], [2.5, 5, 3], [-2.5, 5, 3]]
        material = "lamp"
    "#;
    let scene = rt_scene::load_str(
        toml,
        std::path::Path::new("."),
        std::path::Path::new("t.toml"),
    )
    .unwrap()
    .scene;
    let camera = scene.cameras[0].clone();
    let accel = rt_accel::AccelSpec::default()
        .build(&scene)
        .expect("the structure builds over the scene");
    let ctx = Ctx {
        scene: &scene,
        accel: accel.as_ref(),
        camera: &camera,
    };
    let technique = "path"
        .parse::<rt_integrators::IntegratorSpec>()
        .unwrap()
        .build();
    let aovs = AovSet::for_channels(&[Channel::Direct, Channel::Indirect, Channel::Emission]);
    let render = |spp: u32, centre_first: bool| {
        let mut film = Film::new(camera.width, camera.height, FilmBuffers::for_outputs(aovs));
        let pass = SamplePass {
            indices: 0..spp,
            stream: SampleStream::Render,
            pixels: None,
            centre_first,
        };
        technique.render_pass(&ctx, &mut film, 3, &pass, &|_| {});
        NoisyFrame::from_film(&film, aovs)
    };
    let frame = render(1, true);
    let g = render_guides(&ctx, None, &GuideOptions::default());
    let r = g.reflected.as_ref().unwrap();
    let direct = frame.image(Channel::Direct).unwrap();
    let indirect = frame.image(Channel::Indirect).unwrap();
    let lamp_in = |pick: &dyn Fn(usize) -> bool| {
        (0..direct.pixels().len())
            .filter(|&i| r.emission.pixels()[i].x > 0.0 && pick(i))
            .count()
    };
    let one_bounce = lamp_in(&|i| direct.pixels()[i].x > 0.0);
    let two_bounces = lamp_in(&|i| direct.pixels()[i].x == 0.0 && indirect.pixels()[i].x > 0.0);
    let out = Svgf::new(SvgfParams::default()).push(&SvgfInput {
        guides: &g,
        direct,
        indirect,
        emission: frame.image(Channel::Emission).unwrap(),
    });
    (out, render(256, false).colour, one_bounce, two_bounces)
}

#[test]
fn a_lamp_seen_in_mirrors_is_not_divided_by_its_black_albedo() {
    // The lamp has no albedo to demodulate by: filtered as light over albedo 10⁻³, its
    // reflections became a thousand times too bright and bled into every mirror pixel near
    // them. Its light is carried past the filter like primary emission instead.
    let (out, reference, one, two) = mirrored_lamp();
    assert!(
        one > 20 && two > 20,
        "lamp pixels: {one} by one mirror, {two} by two"
    );
    let max = |img: &RgbImage| {
        img.pixels()
            .iter()
            .map(|c| c.max_element())
            .fold(0.0, f32::max)
    };
    let mean = |img: &RgbImage| {
        img.pixels().iter().map(|c| f64::from(c.x)).sum::<f64>() / img.pixels().len() as f64
    };
    assert!(
        max(&out) <= 1.01 * max(&reference),
        "max {} vs reference {}",
        max(&out),
        max(&reference)
    );
    let (m, m_ref) = (mean(&out), mean(&reference));
    assert!(
        (m - m_ref).abs() < 0.1 * m_ref,
        "mean {m} vs reference {m_ref}"
    );
}
