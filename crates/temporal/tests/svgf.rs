//! SVGF's derived unit tests (seed 001 §5) and reprojection against real guide buffers.

use rt_core::glam::{Vec2, Vec3};
use rt_core::{Camera, Image, Rgb, RgbImage};
use rt_film::{GuideBuffers, NoisyFrame, NO_ID};
use rt_integrators::{render_guides, Ctx, GuideOptions, PreviousView};
use rt_temporal::{Svgf, SvgfInput, SvgfParams, TemporalFrame, TemporalSpec};

/// A still camera looking at a flat diffuse wall of albedo 0.5.
fn flat_guides(w: usize, h: usize) -> GuideBuffers {
    GuideBuffers {
        depth: Image::filled(w, h, 2.0),
        position: Image::from_fn(w, h, |x, y| {
            Vec3::new(x as f32 * 0.01, y as f32 * 0.01, 2.0)
        }),
        normal: Image::filled(w, h, Vec3::Z),
        albedo: Image::filled(w, h, Rgb::splat(0.5)),
        emission: Image::filled(w, h, Rgb::ZERO),
        motion: Image::filled(w, h, Vec2::ZERO),
        previous_depth: Image::filled(w, h, 2.0),
        object: Image::filled(w, h, 0),
        instance: Image::filled(w, h, NO_ID),
        roughness: Image::filled(w, h, 1.0),
        reflected: None,
    }
}

/// Deterministic "noise" in [0, 1).
fn hash(x: usize, y: usize, k: usize) -> f32 {
    let mut v = ((x as u64) * 0x9E37_79B9) ^ ((y as u64) << 20) ^ ((k as u64) << 40);
    v ^= v >> 33;
    v = v.wrapping_mul(0xff51_afd7_ed55_8ccd);
    v ^= v >> 33;
    (v >> 40) as f32 / (1u64 << 24) as f32
}

fn push(svgf: &mut Svgf, g: &GuideBuffers, direct: &RgbImage) -> RgbImage {
    let (w, h) = g.size();
    let zero = Image::filled(w, h, Rgb::ZERO);
    svgf.push(&SvgfInput {
        guides: g,
        direct,
        indirect: &zero,
        emission: &zero,
    })
}

/// Only temporal accumulation: no À-Trous, no median, the smallest α.
fn accumulate_only() -> SvgfParams {
    SvgfParams {
        alpha: 1e-6,
        alpha_specular: 1e-6,
        alpha_moments: 1e-6,
        max_history: 1000.0,
        iterations: 0,
        feedback: 0,
        median: false,
        ..SvgfParams::default()
    }
}

#[test]
fn accumulation_with_alpha_one_over_h_is_the_mean_of_h_frames() {
    let (w, h) = (12, 9);
    let g = flat_guides(w, h);
    let mut svgf = Svgf::new(accumulate_only());
    let mut sum = vec![Rgb::ZERO; w * h];
    for k in 0..10 {
        let direct = Image::from_fn(w, h, |x, y| Rgb::new(hash(x, y, k), 0.3, hash(y, x, k)));
        for (s, d) in sum.iter_mut().zip(direct.pixels()) {
            *s += *d;
        }
        let out = push(&mut svgf, &g, &direct);
        for (o, s) in out.pixels().iter().zip(&sum) {
            let mean = *s / (k + 1) as f32;
            assert!(
                (*o - mean).abs().max_element() < 1e-5,
                "frame {k}: {o} vs mean {mean}"
            );
        }
    }
    assert!(svgf.history_lengths().iter().all(|&l| l == 10.0));
}

#[test]
fn a_constant_sequence_stays_constant() {
    let (w, h) = (24, 18);
    let g = flat_guides(w, h);
    let mut svgf = Svgf::new(SvgfParams::default());
    let direct = Image::filled(w, h, Rgb::new(0.2, 0.4, 0.8));
    for k in 0..6 {
        let out = push(&mut svgf, &g, &direct);
        for o in out.pixels() {
            assert!(
                (*o - Rgb::new(0.2, 0.4, 0.8)).abs().max_element() < 1e-5,
                "frame {k}: {o}"
            );
        }
    }
}

#[test]
fn svgf_is_much_steadier_than_its_input_on_a_still_noisy_wall() {
    // The point of the filter: frame-to-frame change of the output is far below the input's.
    let (w, h) = (32, 24);
    let g = flat_guides(w, h);
    let mut svgf = Svgf::new(SvgfParams::default());
    let mut last: Option<(RgbImage, RgbImage)> = None;
    let (mut din, mut dout) = (0.0f64, 0.0f64);
    for k in 0..20 {
        let direct = Image::from_fn(w, h, |x, y| Rgb::splat(0.5 * (hash(x, y, k) * 2.0)));
        let out = push(&mut svgf, &g, &direct);
        if let Some((pd, po)) = &last {
            if k >= 10 {
                for i in 0..w * h {
                    din += (direct.pixels()[i] - pd.pixels()[i]).abs().x as f64;
                    dout += (out.pixels()[i] - po.pixels()[i]).abs().x as f64;
                }
            }
        }
        last = Some((direct, out));
    }
    assert!(
        dout * 10.0 < din,
        "output change {dout} vs input change {din}"
    );
}

/// Loads the Cornell box at a small size with its camera moved by `shift`.
fn cornell(shift: Vec3) -> (rt_core::Scene, Camera) {
    let path =
        std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../scenes/cornell-box.toml");
    let loaded = rt_scene::load_any(&path).expect("cornell box loads");
    let c = &loaded.scene.cameras[0];
    let camera = Camera::look_at(
        "moved",
        c.position + shift,
        c.position + shift + c.forward,
        c.up,
        39.3,
        64,
        64,
        0.0,
        1.0,
    );
    (loaded.scene, camera)
}

/// A smooth pattern fixed to the world: what a static scene's light would be.
fn world_light(p: Vec3) -> Rgb {
    Rgb::new(
        1.0 + 0.5 * (p.x * 0.02).sin(),
        1.0 + 0.5 * (p.y * 0.015).cos(),
        1.0 + 0.3 * (p.z * 0.01).sin(),
    )
}

fn guides_for(scene: &rt_core::Scene, camera: &Camera, prev: Option<&Camera>) -> GuideBuffers {
    let accel = rt_accel::AccelSpec::default()
        .build(scene)
        .expect("the structure builds over the scene");
    let ctx = Ctx {
        scene,
        accel: accel.as_ref(),
        camera,
    };
    let previous = prev.map(|c| PreviousView {
        camera: c,
        time: scene.time,
    });
    render_guides(&ctx, previous.as_ref(), &GuideOptions::default())
}

/// Mean relative difference of frame 2's output from its own input, where it has history.
fn reprojection_error(g1: &GuideBuffers, g2: &GuideBuffers) -> (f64, usize) {
    let light = |g: &GuideBuffers| {
        let (w, h) = g.size();
        Image::from_fn(w, h, |x, y| {
            let i = y * w + x;
            if g.has_surface(i) {
                g.albedo.pixels()[i] * world_light(g.position.pixels()[i])
            } else {
                Rgb::ZERO
            }
        })
    };
    let mut svgf = Svgf::new(accumulate_only());
    push(&mut svgf, g1, &light(g1));
    let l2 = light(g2);
    let out = push(&mut svgf, g2, &l2);
    let (mut err, mut n) = (0.0f64, 0usize);
    for (i, len) in svgf.history_lengths().iter().enumerate() {
        if *len == 2.0 && l2.pixels()[i].max_element() > 0.05 {
            let (o, r) = (out.pixels()[i], l2.pixels()[i]);
            err += ((o - r).abs() / r.max(Rgb::splat(1e-3))).max_element() as f64;
            n += 1;
        }
    }
    (err / n.max(1) as f64, n)
}

#[test]
fn exact_motion_vectors_reproduce_a_static_scene_under_a_moving_camera() {
    let (scene, cam1) = cornell(Vec3::ZERO);
    let (_, cam2) = cornell(Vec3::new(14.0, -9.0, 30.0));
    let g1 = guides_for(&scene, &cam1, None);
    let g2 = guides_for(&scene, &cam2, Some(&cam1));
    let (err, n) = reprojection_error(&g1, &g2);
    // Most of the image keeps its history, and what it fetches is what the pixel sees now.
    assert!(n > 64 * 64 / 2, "only {n} pixels reprojected");
    assert!(err < 0.01, "mean relative error {err}");
    // Control: with the motion vectors zeroed the history belongs to other points.
    let mut broken = g2.clone();
    broken.motion = Image::filled(64, 64, Vec2::ZERO);
    let (err_broken, _) = reprojection_error(&g1, &broken);
    assert!(
        err_broken > 5.0 * err,
        "zero motion {err_broken} vs exact {err}"
    );
}

#[test]
fn bad_options_and_missing_guides_give_one_clear_line() {
    let err = |t: &str| match t.parse::<TemporalSpec>() {
        Err(e) => e.to_string(),
        Ok(s) => s.build().err().map(|e| e.to_string()).unwrap_or_default(),
    };
    assert_eq!(err("svgf:alpha=2"), "svgf: alpha: must be in (0, 1], got 2");
    assert_eq!(err("svgf:colour=on"), "svgf: unknown option `colour`");
    assert_eq!(
        err("svgf:reflections=maybe"),
        "svgf: reflections: `maybe` is not one of reproject, primary, drop"
    );
    assert!(err("svgf:feedback=7:iterations=3").contains("feedback: must be at most iterations"));
    assert!(err("svgf:alpha").contains("option `alpha` needs a value"));
    // A frame without guides, or without the lighting split.
    let mut d = "svgf".parse::<TemporalSpec>().unwrap().build().unwrap();
    let mut frame = NoisyFrame::new(Image::filled(4, 3, Rgb::ONE));
    let e = d
        .push(&TemporalFrame {
            frame: &frame,
            guides: None,
            extra: &[],
        })
        .unwrap_err()
        .to_string();
    assert!(e.contains("direct"), "{e}");
    frame.direct = Some(Image::filled(4, 3, Rgb::ONE));
    frame.indirect = Some(Image::filled(4, 3, Rgb::ZERO));
    frame.emission = Some(Image::filled(4, 3, Rgb::ZERO));
    let e = d
        .push(&TemporalFrame {
            frame: &frame,
            guides: None,
            extra: &[],
        })
        .unwrap_err()
        .to_string();
    assert!(e.contains("needs the frame's guide buffers"), "{e}");
    let g = flat_guides(5, 3);
    let e = d
        .push(&TemporalFrame {
            frame: &frame,
            guides: Some(&g),
            extra: &[],
        })
        .unwrap_err()
        .to_string();
    assert!(e.contains("guide buffers are 5x3, the frame is 4x3"), "{e}");
    assert!(!e.contains('\n'));
}

#[test]
fn guide_ray_supersampling_gives_a_partly_covered_pixel_both_sides() {
    // Left half: albedo 0.2, lit 1; right half: albedo 0.8, lit 2, facing another way. The
    // extra sample of boundary pixel (7, y) sees the right surface (lit 3 in its sample), so it
    // belongs to guide (8, y), whose input becomes the mean (2 + 2 + 3) / 3 of its own, its
    // pixel's extra sample and this one; pixel 7 is then (0.2 · 1 + 0.8 · 7/3) / 2. Kept apart
    // (no guide found) it would be (0.2 + 2.4) / 2; given to its own guide (0.2 + 0.8) · 2 / 2.
    let (w, h) = (16, 4);
    let right = |x: usize| x >= 8;
    let mut g = flat_guides(w, h);
    for y in 0..h {
        for x in 8..w {
            g.normal.pixels_mut()[y * w + x] = Vec3::X;
            g.albedo.pixels_mut()[y * w + x] = Rgb::splat(0.8);
            g.object.pixels_mut()[y * w + x] = 1;
        }
    }
    let lit = |x: usize| if right(x) { 1.6 } else { 0.2 };
    let direct = Image::from_fn(w, h, |x, _| Rgb::splat(lit(x)));
    // The extra sample: as its own guide everywhere except on the boundary column.
    let seen = |x: usize| if x == 7 { 8 } else { x };
    let e_direct = Image::from_fn(w, h, |x, _| Rgb::splat(if x == 7 { 2.4 } else { lit(x) }));
    let e_albedo = Image::from_fn(w, h, |x, y| g.albedo.pixel(seen(x), y));
    let e_normal = Image::from_fn(w, h, |x, y| g.normal.pixel(seen(x), y));
    let e_position = Image::from_fn(w, h, |x, y| g.position.pixel(seen(x), y));
    let zero = Image::filled(w, h, Rgb::ZERO);
    let extra = rt_temporal::svgf::supersample::ExtraSample {
        direct: &e_direct,
        indirect: &zero,
        emission: &zero,
        albedo: &e_albedo,
        normal: &e_normal,
        position: &e_position,
    };
    let mut svgf = Svgf::new(SvgfParams {
        iterations: 0,
        feedback: 0,
        median: false,
        ..SvgfParams::default()
    });
    let input = SvgfInput {
        guides: &g,
        direct: &direct,
        indirect: &zero,
        emission: &zero,
    };
    let out = svgf.push_supersampled(&input, &[extra]);
    for y in 0..h {
        let expected = (0.2 + 0.8 * 7.0 / 3.0) / 2.0;
        assert!(
            (out.pixel(7, y).x - expected).abs() < 1e-5,
            "{}",
            out.pixel(7, y)
        );
        assert!((out.pixel(3, y).x - 0.2).abs() < 1e-5);
        assert!((out.pixel(8, y).x - 0.8 * 7.0 / 3.0).abs() < 1e-5);
        assert!((out.pixel(12, y).x - 1.6).abs() < 1e-5);
    }
}
