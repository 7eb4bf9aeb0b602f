//! The edge-avoiding À-Trous filter through the public API: invariants (constants, thread
//! counts, the portable and AVX2 code), the weightless transform against a naive B3
//! convolution, what each edge-stopping weight and the demodulation keep, the lighting
//! splits' recombination, scale invariance, and the errors.

use rt_core::glam::Vec3;
use rt_core::sampler::hash_u32;
use rt_core::{Image, Rgb, RgbImage};
use rt_denoise::{Channel, DenoiseError, Denoiser, DenoiserSpec, FrameError, NoisyFrame};

/// A uniform number in [0, 1) for pixel `(x, y)` and stream `k`.
fn u(x: usize, y: usize, k: u32) -> f32 {
    let h = hash_u32(hash_u32(x as u32 ^ (k << 20)) ^ (y as u32).wrapping_mul(0x9e37_79b9));
    (h >> 8) as f32 / (1 << 24) as f32
}

fn build(spec: &str) -> Box<dyn Denoiser> {
    spec.parse::<DenoiserSpec>()
        .and_then(|s| s.build())
        .unwrap_or_else(|e| panic!("{spec}: {e}"))
}

fn run(spec: &str, f: &NoisyFrame) -> RgbImage {
    build(spec)
        .denoise(f)
        .unwrap_or_else(|e| panic!("{spec}: {e}"))
}

/// Random colours, normals and positions.
fn noisy(w: usize, h: usize) -> NoisyFrame {
    let mut f = NoisyFrame::new(Image::from_fn(w, h, |x, y| {
        Rgb::new(u(x, y, 1), u(x, y, 2), u(x, y, 3)) * 3.0
    }));
    f.normal = Some(Image::from_fn(w, h, |x, y| {
        Vec3::new(u(x, y, 4) - 0.5, u(x, y, 5) - 0.5, 1.0).normalize()
    }));
    f.position = Some(Image::from_fn(w, h, |x, y| {
        Vec3::new(x as f32, y as f32, 4.0 * u(x, y, 6)) / 64.0
    }));
    f
}

fn max_diff(a: &RgbImage, b: &RgbImage) -> f32 {
    assert_eq!(a.size(), b.size());
    a.pixels()
        .iter()
        .zip(b.pixels())
        .map(|(p, q)| (*p - *q).abs().max_element())
        .fold(0.0, f32::max)
}

#[test]
fn a_constant_image_stays_constant_with_every_weight_up_to_the_borders() {
    let c = Rgb::new(0.3, 0.5, 2.0);
    let mut f = noisy(37, 23);
    f.colour = Image::filled(37, 23, c);
    for it in [1, 5, 10] {
        for halve in ["phi", "sigma", "none"] {
            let out = run(&format!("atrous:iterations={it}:halve={halve}"), &f);
            let worst = max_diff(&out, &f.colour);
            assert!(
                worst < 2e-6,
                "{it} iterations, halve={halve}: off by {worst}"
            );
        }
    }
}

#[test]
fn same_bits_on_any_thread_count_and_in_the_portable_code() {
    let f = noisy(301, 67);
    let at = |threads: usize, spec: &str| {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap();
        pool.install(|| run(spec, &f))
    };
    for weights in ["", ":colour=off:normal=off:position=off", ":position=off"] {
        let spec = format!("atrous{weights}");
        let one = at(1, &spec);
        assert_eq!(at(2, &spec), one, "{spec}");
        assert_eq!(at(3, &spec), one, "{spec}");
        assert_eq!(at(2, &format!("{spec}:simd=off")), one, "{spec}, portable");
    }
}

/// Level `level` of the unweighted transform, computed tap by tap with clamped borders.
fn naive_b3(img: &RgbImage, level: usize) -> RgbImage {
    let b3 = [1.0 / 16.0, 0.25, 0.375, 0.25, 1.0 / 16.0];
    let s = 1isize << level;
    let (w, h) = img.size();
    Image::from_fn(w, h, |x, y| {
        let mut sum = Rgb::ZERO;
        for j in 0..5 {
            for i in 0..5 {
                let qx = x as isize + (i as isize - 2) * s;
                let qy = y as isize + (j as isize - 2) * s;
                sum += img.clamped(qx, qy) * (b3[i] * b3[j]);
            }
        }
        sum
    })
}

#[test]
fn without_weights_each_level_is_a_b3_convolution_with_taps_two_to_the_level_apart() {
    let f = noisy(29, 19);
    let plain = ":colour=off:normal=off:position=off:demodulate=off";
    let level0 = naive_b3(&f.colour, 0);
    let out = run(&format!("atrous:iterations=1{plain}"), &f);
    assert!(max_diff(&out, &level0) < 1e-5);
    let level2 = naive_b3(&naive_b3(&level0, 1), 2);
    let out = run(&format!("atrous:iterations=3{plain}"), &f);
    assert!(max_diff(&out, &level2) < 1e-5);
    // Without guides the frame needs no channel besides the colour.
    assert!(build(&format!("atrous{plain}")).needs().is_empty());
}

/// Colour and normals with a vertical step edge at x = w/2 (no noise).
fn step_edge(w: usize, h: usize) -> NoisyFrame {
    let left = |x: usize| x < w / 2;
    let mut f = NoisyFrame::new(Image::from_fn(w, h, |x, _| {
        Rgb::splat(if left(x) { 0.2 } else { 1.0 })
    }));
    f.normal = Some(Image::from_fn(w, h, |x, _| {
        if left(x) {
            Vec3::Z
        } else {
            Vec3::X
        }
    }));
    f
}

#[test]
fn the_normal_weight_keeps_an_edge_that_plain_a_trous_blurs() {
    let f = step_edge(96, 8);
    let only_n = ":colour=off:position=off";
    let none = ":colour=off:normal=off:position=off";
    let blurred = max_diff(&run(&format!("atrous{none}"), &f), &f.colour);
    assert!(
        blurred > 0.3,
        "plain À-Trous moved the edge by only {blurred}"
    );
    // Levels 0 and 1: a 90° crease weighs exp(−2/4/0.1) ≈ 0.007 at stepwidth 2, so the edge
    // stays sharp.
    let kept = max_diff(&run(&format!("atrous:iterations=2{only_n}"), &f), &f.colour);
    assert!(kept < 0.02, "normal weight, 2 levels: {kept}");
    // From level 2 on the shader relaxes the normal weight (|Δn|²/stepwidth²): the edge
    // softens, but less than without the weight.
    let five = max_diff(&run(&format!("atrous{only_n}"), &f), &f.colour);
    assert!(
        five < 0.5 * blurred,
        "normal weight, 5 levels: {five} vs {blurred}"
    );
    // ... but it does soften: |Δn|² is divided by stepwidth², so the crease's weight grows from
    // exp(−200) at level 0 to 0.46 at level 4.
    assert!(five > 0.05, "normal weight, 5 levels: {five}");
}

#[test]
fn the_colour_weight_keeps_an_edge_too() {
    let mut f = step_edge(96, 8);
    f.normal = None;
    let only_c = ":normal=off:position=off";
    let none = ":colour=off:normal=off:position=off";
    let blurred = max_diff(&run(&format!("atrous{none}"), &f), &f.colour);
    // By default level 0 barely sees the colour (σ at twice the bright pixels' intensity, the
    // thesis' choice), the halved phis of later levels do, a little.
    let default = max_diff(&run(&format!("atrous{only_c}"), &f), &f.colour);
    assert!(
        default < blurred - 0.02,
        "colour weight: {default} vs {blurred}"
    );
    let tight = max_diff(&run(&format!("atrous:c_phi=0.1{only_c}"), &f), &f.colour);
    assert!(tight < 0.02, "colour weight, c_phi=0.1: {tight}");
}

#[test]
fn the_position_weight_keeps_a_depth_step() {
    let (w, h) = (96, 8);
    let mut f = step_edge(w, h);
    f.normal = None;
    // Two parallel planes 3 units apart, both facing the camera.
    f.position = Some(Image::from_fn(w, h, |x, y| {
        Vec3::new(
            x as f32 * 0.05,
            y as f32 * 0.05,
            if x < w / 2 { 0.0 } else { 3.0 },
        )
    }));
    let blurred = max_diff(
        &run("atrous:colour=off:normal=off:position=off", &f),
        &f.colour,
    );
    let kept = max_diff(&run("atrous:colour=off:normal=off", &f), &f.colour);
    assert!(
        kept < 0.05 * blurred,
        "position weight: {kept} vs {blurred}"
    );
}

/// A high-frequency albedo (2-pixel checkerboard) times a smooth irradiance with strong noise,
/// on a flat plane facing the camera; returns the frame and the noise-free image.
fn textured(w: usize, h: usize) -> (NoisyFrame, RgbImage, RgbImage) {
    let albedo = Image::from_fn(w, h, |x, y| {
        if (x / 2 + y / 2) % 2 == 0 {
            Rgb::new(0.8, 0.7, 0.6)
        } else {
            Rgb::new(0.15, 0.2, 0.25)
        }
    });
    let smooth = |x: usize, y: usize| {
        let t = (x as f32 / w as f32) * 3.0 + (y as f32 / h as f32) * 2.0;
        Rgb::splat(0.7 + 0.3 * t.sin())
    };
    let irr_noisy = Image::from_fn(w, h, |x, y| {
        smooth(x, y) * Rgb::new(u(x, y, 7), u(x, y, 8), u(x, y, 9)) * 2.0
    });
    let colour = Image::from_fn(w, h, |x, y| albedo.pixel(x, y) * irr_noisy.pixel(x, y));
    let reference = Image::from_fn(w, h, |x, y| albedo.pixel(x, y) * smooth(x, y));
    let mut f = NoisyFrame::new(colour);
    f.albedo = Some(albedo);
    f.normal = Some(Image::filled(w, h, Vec3::Z));
    f.position = Some(Image::from_fn(w, h, |x, y| {
        Vec3::new(x as f32, y as f32, 0.0)
    }));
    (f, reference, irr_noisy)
}

fn crop(img: &RgbImage, x0: usize, y0: usize, n: usize) -> RgbImage {
    Image::from_fn(n, n, |x, y| img.pixel(x0 + x, y0 + y))
}

#[test]
fn demodulation_keeps_a_texture_that_filtering_the_radiance_blurs() {
    let (f, reference, irr) = textured(96, 96);
    let ssim = |img: &RgbImage| {
        rt_metrics::ssim(&crop(img, 16, 16, 64), &crop(&reference, 16, 16, 64)).unwrap()
    };
    let radiance = ssim(&run("atrous:demodulate=off", &f));
    let divided = ssim(&run("atrous", &f));
    let mut with_irr = f.clone();
    with_irr.irradiance = Some(irr);
    with_irr.emission = Some(Image::filled(96, 96, Rgb::ZERO));
    let multiplied = ssim(&run("atrous:demodulate=on", &with_irr));
    let input = ssim(&f.colour);
    // Filtering the radiance averages the texture away (SSIM's structure term sees a flat
    // image); the demodulated filters keep it and remove noise.
    assert!(radiance < input, "radiance {radiance} vs input {input}");
    assert!(
        divided > input + 0.05,
        "albedo division {divided} vs input {input}"
    );
    assert!(
        divided > radiance + 0.1,
        "albedo division {divided} vs radiance {radiance}"
    );
    assert!(
        multiplied > radiance + 0.1,
        "irradiance channel {multiplied} vs radiance {radiance}"
    );
    // The irradiance here is exactly colour / albedo, so both paths filter the same signal.
    assert!(
        (multiplied - divided).abs() < 1e-3,
        "{multiplied} vs {divided}"
    );
}

/// A frame with consistent lighting splits: colour = emission + direct + indirect
/// = emission + diffuse + glossy, all noisy.
fn split_frame(w: usize, h: usize) -> NoisyFrame {
    let mut f = noisy(w, h);
    let part = |k: u32| {
        Image::from_fn(w, h, |x, y| {
            Rgb::new(u(x, y, k), u(x, y, k + 1), u(x, y, k + 2))
        })
    };
    let emission = Image::from_fn(w, h, |x, y| {
        Rgb::splat(if (x + y) % 7 == 0 { 5.0 } else { 0.0 })
    });
    let direct = part(10);
    let indirect = part(20);
    let diffuse = part(30);
    f.colour = Image::from_fn(w, h, |x, y| {
        emission.pixel(x, y) + direct.pixel(x, y) + indirect.pixel(x, y)
    });
    f.glossy = Some(Image::from_fn(w, h, |x, y| {
        f.colour.pixel(x, y) - emission.pixel(x, y) - diffuse.pixel(x, y)
    }));
    f.albedo = Some(Image::from_fn(w, h, |x, y| {
        Rgb::new(u(x, y, 40), u(x, y, 41), 0.0005 + 0.5 * u(x, y, 42))
    }));
    f.emission = Some(emission);
    f.direct = Some(direct);
    f.indirect = Some(indirect);
    f.diffuse = Some(diffuse);
    f
}

#[test]
fn splits_recombine_exactly() {
    let f = split_frame(41, 27);
    for split in [
        "split=direct-indirect:direct_iterations=0:indirect_iterations=0",
        "split=diffuse-glossy:diffuse_iterations=0:glossy_iterations=0",
    ] {
        for demod in ["on", "off"] {
            let out = run(&format!("atrous:{split}:demodulate={demod}"), &f);
            assert_eq!(out, f.colour, "{split}, demodulate={demod}");
        }
    }
    // One part filtered, the other kept: emission + direct + À-Trous(indirect).
    let out = run(
        "atrous:split=direct-indirect:direct_iterations=0:demodulate=off",
        &f,
    );
    let mut indirect = f.clone();
    indirect.colour = f.indirect.clone().unwrap();
    let filtered = run("atrous:demodulate=off", &indirect);
    let expected = Image::from_fn(41, 27, |x, y| {
        f.emission.as_ref().unwrap().pixel(x, y)
            + f.direct.as_ref().unwrap().pixel(x, y)
            + filtered.pixel(x, y)
    });
    assert!(max_diff(&out, &expected) < 1e-5);
}

#[test]
fn zero_albedo_passes_through_when_demodulating() {
    let mut f = noisy(33, 17);
    f.albedo = Some(Image::from_fn(33, 17, |x, _| {
        if x < 10 {
            Rgb::ZERO
        } else {
            Rgb::splat(0.5)
        }
    }));
    f.emission = Some(Image::filled(33, 17, Rgb::ZERO));
    let out = run("atrous:demodulate=on", &f);
    for y in 0..17 {
        for x in 0..10 {
            assert_eq!(out.pixel(x, y), f.colour.pixel(x, y), "({x}, {y})");
        }
    }
    assert!(max_diff(&out, &f.colour) > 0.1);
}

#[test]
fn relative_phis_make_the_result_independent_of_scene_scale_and_exposure() {
    let f = noisy(45, 31);
    let base = run("atrous:demodulate=off", &f);
    // Powers of two scale every squared distance and its phi exactly.
    let mut bigger = f.clone();
    bigger.position = Some(f.position.as_ref().unwrap().map(|p| *p * 1024.0));
    assert_eq!(run("atrous:demodulate=off", &bigger), base);
    let mut brighter = f.clone();
    brighter.colour = f.colour.map(|c| *c * 64.0);
    assert_eq!(
        run("atrous:demodulate=off", &brighter),
        base.map(|c| *c * 64.0)
    );
    // With absolute phis the same scaling changes the result.
    let abs = "atrous:demodulate=off:scale=absolute:p_phi=10:c_phi=3";
    assert!(max_diff(&run(abs, &bigger), &run(abs, &f)) > 0.01);
}

#[test]
fn halving_modes_differ_only_when_the_colour_weight_is_on() {
    let f = noisy(40, 24);
    let phi = run("atrous:demodulate=off", &f);
    let sigma = run("atrous:demodulate=off:halve=sigma", &f);
    let none = run("atrous:demodulate=off:halve=none", &f);
    assert!(max_diff(&phi, &sigma) > 1e-3 && max_diff(&phi, &none) > 1e-3);
    // halve=sigma from c_phi = 4 equals halve=phi from c_phi = 2 at level 1 (both 1/2 of the
    // scale... of 4 and 2: 4/4 = 1, 2/2 = 1), so two levels give the same result only if the
    // first level matches too; check the one-level case instead: no halving happens before level 1.
    let one = |h: &str| run(&format!("atrous:demodulate=off:iterations=1:halve={h}"), &f);
    assert_eq!(one("phi"), one("sigma"));
    assert_eq!(one("phi"), one("none"));
    // Without the colour weight the mode is irrelevant.
    let nc = |h: &str| run(&format!("atrous:demodulate=off:colour=off:halve={h}"), &f);
    assert_eq!(nc("phi"), nc("sigma"));
}

#[test]
fn non_finite_input_gives_finite_output() {
    let mut f = noisy(20, 20);
    f.colour.pixels_mut()[45] = Rgb::new(f32::NAN, f32::INFINITY, 1.0);
    f.normal.as_mut().unwrap().pixels_mut()[3] = Vec3::splat(f32::NAN);
    let out = run("atrous", &f);
    assert!(out.pixels().iter().all(|p| p.is_finite()));
    // The bad components count as zero and spread no further than a zero would: the result
    // is exactly that of the frame with zeros in their place. (A NaN that reached the filter
    // would spread over the footprint, whose pixels `denoise` then zeroes: finite, but not
    // this image.)
    let mut zeroed = noisy(20, 20);
    zeroed.colour.pixels_mut()[45] = Rgb::new(0.0, 0.0, 1.0);
    zeroed.normal.as_mut().unwrap().pixels_mut()[3] = Vec3::ZERO;
    assert_eq!(out, run("atrous", &zeroed));
    assert!(max_diff(&out, &run("atrous", &noisy(20, 20))) > 0.0);
}

#[test]
fn tiny_and_empty_frames_keep_their_size() {
    for (w, h) in [(0, 0), (0, 3), (3, 0), (1, 1), (1, 7), (2, 2)] {
        let f = noisy(w, h);
        for spec in [
            "atrous",
            "atrous:iterations=10:halve=none",
            "atrous:split=none:demodulate=off",
        ] {
            let out = run(spec, &f);
            assert_eq!(out.size(), (w, h), "{spec}");
            if w * h == 1 {
                // 25 taps of the one pixel, normalised: equal up to rounding.
                assert!(max_diff(&out, &f.colour) < 1e-5, "{spec}");
            }
        }
    }
}

#[test]
fn missing_channels_are_one_frame_error_naming_the_channel() {
    let missing = |spec: &str, f: &NoisyFrame| match build(spec).denoise(f) {
        Err(DenoiseError::Frame(FrameError::Missing { channel, .. })) => channel,
        other => panic!("{spec}: {other:?}"),
    };
    let f = noisy(8, 8);
    assert_eq!(missing("atrous:split=direct-indirect", &f), Channel::Direct);
    assert_eq!(missing("atrous:split=diffuse-glossy", &f), Channel::Diffuse);
    assert_eq!(missing("atrous:demodulate=on", &f), Channel::Albedo);
    let bare = NoisyFrame::new(f.colour.clone());
    assert_eq!(missing("atrous", &bare), Channel::Normal);
    assert_eq!(missing("atrous:normal=off", &bare), Channel::Position);
    let mut d = f.clone();
    d.direct = Some(f.colour.clone());
    assert_eq!(
        missing("atrous:split=direct-indirect", &d),
        Channel::Indirect
    );
    let msg = build("atrous:split=direct-indirect")
        .denoise(&f)
        .unwrap_err()
        .to_string();
    assert!(msg.contains("direct") && msg.contains("--aov"), "{msg}");
}

#[test]
fn bad_options_are_parameter_errors() {
    for spec in [
        "atrous:iterations=0",
        "atrous:iterations=11",
        "atrous:c_phi=-1",
        "atrous:n_phi=0",
        "atrous:p_phi=-0.5",
        "atrous:halve=both",
        "atrous:demodulate=maybe",
        "atrous:split=left-right",
        "atrous:split=direct-indirect:direct_iterations=11",
        "atrous:scale=huge",
        "atrous:colour=sometimes",
    ] {
        match spec.parse::<DenoiserSpec>().unwrap().build() {
            Err(DenoiseError::Param { denoiser, .. }) => assert_eq!(denoiser, "atrous", "{spec}"),
            Err(e) => panic!("{spec}: {e:?}"),
            Ok(_) => panic!("{spec}: accepted"),
        }
    }
    // A part's iterations only exist for its split.
    let err = "atrous:glossy_iterations=2"
        .parse::<DenoiserSpec>()
        .unwrap()
        .build();
    assert!(matches!(err, Err(DenoiseError::Spec(_))));
    // The name lists every option, so it rebuilds the same filter.
    let d = build("atrous:split=diffuse-glossy:halve=sigma");
    assert_eq!(build(d.name()).name(), d.name());
    assert!(d.name().contains("glossy_iterations=2") && d.name().contains("halve=sigma"));
}
