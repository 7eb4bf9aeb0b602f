//! The filter-bank denoisers (gaussian, bilateral, nlm, guided) against the properties every
//! bank member must have (constant images, borders, determinism, channel and parameter
//! errors) and the one each is for (edges kept by the guide, variance-driven NL-means).

use rt_core::glam::Vec3;
use rt_core::sampler::hash_u32;
use rt_core::{Image, Rgb, RgbImage};
use rt_denoise::{DenoiseError, Denoiser, DenoiserSpec, NoisyFrame};

/// Uniform in [0, 1) from a seed and an index.
fn uniform(seed: u32, i: u32) -> f32 {
    (hash_u32(hash_u32(seed) ^ i) >> 8) as f32 / (1u32 << 24) as f32
}

/// A standard normal variate (Box–Muller on two hashed uniforms).
fn normal01(seed: u32, i: u32) -> f32 {
    let u1 = uniform(seed, 2 * i).max(1e-7);
    let u2 = uniform(seed, 2 * i + 1);
    (-2.0 * u1.ln()).sqrt() * (std::f32::consts::TAU * u2).cos()
}

fn noise3(seed: u32, i: usize) -> Vec3 {
    let i = 3 * i as u32;
    Vec3::new(
        normal01(seed, i),
        normal01(seed, i + 1),
        normal01(seed, i + 2),
    )
}

fn build(spec: &str) -> Box<dyn Denoiser> {
    spec.parse::<DenoiserSpec>()
        .unwrap_or_else(|e| panic!("{spec}: {e}"))
        .build()
        .unwrap_or_else(|e| panic!("{spec}: {e}"))
}

/// Every bank member, with its option variants that take different code paths.
const SPECS: [&str; 10] = [
    "gaussian",
    "gaussian:sigma=0.7",
    "bilateral",
    "bilateral:variances=off:colour=0.5",
    "bilateral:variances=on",
    "nlm",
    "nlm:radius=2:patch=0",
    "guided",
    "guided:guide=normal:radius=2",
    "guided:guide=colour",
];

/// A frame with every channel the bank reads: the given colour, varied (hashed) features and
/// variances.
fn full_frame(colour: RgbImage, seed: u32) -> NoisyFrame {
    let (w, h) = colour.size();
    let img = |f: &dyn Fn(usize) -> Vec3| Image::from_fn(w, h, |x, y| f(y * w + x));
    let r = |k: u32, i: usize| {
        Vec3::new(
            uniform(seed ^ k, 3 * i as u32),
            uniform(seed ^ k, 3 * i as u32 + 1),
            uniform(seed ^ k, 3 * i as u32 + 2),
        )
    };
    let mut f = NoisyFrame::new(colour);
    f.variance = Some(img(&|i| r(1, i) * 0.01));
    f.albedo = Some(img(&|i| r(2, i)));
    f.albedo_variance = Some(img(&|i| r(3, i) * 0.001));
    f.normal = Some(img(&|i| (r(4, i) - 0.5).normalize_or_zero()));
    f.normal_variance = Some(img(&|i| r(5, i) * 0.001));
    f.position = Some(img(&|i| r(6, i) * 10.0));
    f.position_variance = Some(img(&|i| r(7, i) * 0.01));
    f
}

fn noisy_image(w: usize, h: usize, seed: u32) -> RgbImage {
    Image::from_fn(w, h, |x, y| {
        Rgb::splat(0.5) + noise3(seed, y * w + x) * 0.2 + Rgb::new(x as f32 * 0.01, 0.0, 0.0)
    })
}

#[test]
fn constant_colour_stays_constant_at_every_size_including_borders() {
    let c = Rgb::new(0.3, 2.0, 7.5);
    for (w, h) in [
        (0, 0),
        (0, 3),
        (1, 1),
        (1, 7),
        (7, 1),
        (3, 2),
        (13, 9),
        (40, 33),
    ] {
        let frame = full_frame(Image::filled(w, h, c), 11);
        for spec in SPECS {
            let out = build(spec).denoise(&frame).unwrap();
            assert_eq!(out.size(), (w, h), "{spec}");
            for (i, p) in out.pixels().iter().enumerate() {
                let err = ((*p - c) / c).abs().max_element();
                assert!(err < 1e-5, "{spec} {w}x{h} pixel {i}: {p} vs {c}");
            }
        }
    }
}

#[test]
fn every_denoiser_gives_the_same_bits_twice_and_on_one_thread() {
    // 37×29: strips of 16 rows do not divide it, and the windows reach every border.
    let frame = full_frame(noisy_image(37, 29, 5), 3);
    let one = rayon::ThreadPoolBuilder::new()
        .num_threads(1)
        .build()
        .unwrap();
    let three = rayon::ThreadPoolBuilder::new()
        .num_threads(3)
        .build()
        .unwrap();
    for spec in SPECS {
        let d = build(spec);
        let a = d.denoise(&frame).unwrap();
        assert_ne!(a, frame.colour, "{spec} changed nothing");
        assert_eq!(a, d.denoise(&frame).unwrap(), "{spec}");
        assert_eq!(
            a,
            one.install(|| d.denoise(&frame).unwrap()),
            "{spec}: 1 thread"
        );
        assert_eq!(
            a,
            three.install(|| d.denoise(&frame).unwrap()),
            "{spec}: 3 threads"
        );
    }
}

#[test]
fn a_nan_or_inf_pixel_stays_local_and_never_reaches_the_output() {
    let (w, h) = (40, 33);
    let clean = full_frame(noisy_image(w, h, 8), 9);
    let mut bad = clean.clone();
    bad.colour.pixels_mut()[2 * w + 2] = Rgb::new(f32::NAN, 1.0, 1.0);
    bad.colour.pixels_mut()[3 * w + 5] = Rgb::splat(f32::INFINITY);
    for spec in SPECS {
        let d = build(spec);
        let (a, b) = (d.denoise(&clean).unwrap(), d.denoise(&bad).unwrap());
        assert!(b.pixels().iter().all(|p| p.is_finite()), "{spec}");
        // Far from the bad pixels (beyond every filter's reach) nothing changed.
        for (x, y) in [(39, 32), (39, 0), (0, 32)] {
            let (p, q) = (a.pixel(x, y), b.pixel(x, y));
            assert!(
                (p - q).abs().max_element() < 1e-4,
                "{spec} ({x}, {y}): {p} vs {q}"
            );
        }
    }
}

/// Mean squared error over the pixels with `keep(x, y)`.
fn mse(a: &RgbImage, b: &RgbImage, keep: impl Fn(usize, usize) -> bool) -> f32 {
    let (w, h) = a.size();
    let (mut s, mut n) = (0.0, 0);
    for y in 0..h {
        for x in 0..w {
            if keep(x, y) {
                s += (a.pixel(x, y) - b.pixel(x, y)).length_squared() / 3.0;
                n += 1;
            }
        }
    }
    s / n as f32
}

/// A vertical step at x = 16 in a 32×32 frame (colour 0.2 left, 1.0 right, light noise), with
/// flat features; `edge_in` puts the same step into one feature.
fn step_frame(edge_in: &str) -> (NoisyFrame, RgbImage) {
    let (w, h) = (32, 32);
    let left = |x: usize| x < 16;
    let truth = Image::from_fn(w, h, |x, _| Rgb::splat(if left(x) { 0.2 } else { 1.0 }));
    let noisy = Image::from_fn(w, h, |x, y| truth.pixel(x, y) + noise3(9, y * w + x) * 0.02);
    let mut f = NoisyFrame::new(noisy);
    let step = |a: Vec3, b: Vec3| Image::from_fn(w, h, |x, _| if left(x) { a } else { b });
    let flat = |v: Vec3| Image::filled(w, h, v);
    f.normal = Some(match edge_in {
        "normal" => step(Vec3::Z, Vec3::X),
        _ => flat(Vec3::Z),
    });
    f.albedo = Some(match edge_in {
        "albedo" => step(Vec3::splat(0.2), Vec3::splat(0.9)),
        _ => flat(Vec3::splat(0.5)),
    });
    f.position = Some(Image::from_fn(w, h, |x, y| {
        Vec3::new(x as f32, y as f32, 0.0)
    }));
    (f, truth)
}

#[test]
fn joint_bilateral_keeps_a_guide_edge_that_the_gaussian_blurs() {
    let gauss = build("gaussian:sigma=2");
    let jbf = build("bilateral:sigma=2");
    for edge in ["normal", "albedo"] {
        let (frame, truth) = step_frame(edge);
        let g = gauss.denoise(&frame).unwrap();
        let b = jbf.denoise(&frame).unwrap();
        for (side, band) in [("left", 12..16), ("right", 16..20)] {
            let near = |x: usize, _| band.contains(&x);
            let (eg, eb) = (mse(&g, &truth, near), mse(&b, &truth, near));
            assert!(eg > 1e-3, "{edge} {side}: the gaussian should blur ({eg})");
            // Orthogonal normals still get weight exp(-2 / (2 * 0.8²)) = 0.21 each, hence not 0.01.
            assert!(
                eb < 0.2 * eg,
                "{edge} {side}: bilateral {eb} vs gaussian {eg}"
            );
        }
        // Away from the edge it still smooths the noise like the Gaussian.
        let far = |x: usize, y: usize| (4..10).contains(&x) && (4..28).contains(&y);
        let noisy = mse(&frame.colour, &truth, far);
        assert!(
            mse(&b, &truth, far) < 0.2 * noisy,
            "{edge}: bilateral does not denoise"
        );
    }
    // With the guide's edge removed (flat features) it blurs like the Gaussian.
    let (frame, truth) = step_frame("none");
    let near = |x: usize, _| (12..20).contains(&x);
    let eb = mse(&jbf.denoise(&frame).unwrap(), &truth, near);
    assert!(eb > 0.5 * mse(&gauss.denoise(&frame).unwrap(), &truth, near));
}

#[test]
fn bilateral_positions_are_scale_invariant() {
    // A depth step: positions jump at x = 16, normals and albedo are flat.
    let (mut frame, _) = step_frame("none");
    let pos = |s: f32| {
        Image::from_fn(32, 32, |x, y| {
            Vec3::new(
                x as f32 * 0.01,
                y as f32 * 0.01,
                if x < 16 { 1.0 } else { 3.0 },
            ) * s
        })
    };
    let d = build("bilateral:sigma=3");
    frame.position = Some(pos(1.0));
    let a = d.denoise(&frame).unwrap();
    frame.position = Some(pos(1000.0));
    let b = d.denoise(&frame).unwrap();
    for (p, q) in a.pixels().iter().zip(b.pixels()) {
        assert!(
            (*p - *q).abs().max_element() < 1e-4 * p.abs().max_element().max(1.0),
            "{p} {q}"
        );
    }
    // And the depth step does act as an edge.
    let left = a.pixel(15, 10).x;
    assert!(left < 0.25, "{left}");
}

#[test]
fn bilateral_feature_variances_let_noisy_guides_average() {
    // Flat grey colour with noise, normals noisy by far more than σ_normal = 0.8 would allow,
    // with their variance supplied: Li et al.'s distance ignores differences within the noise.
    let (w, h) = (24, 24);
    let truth = Image::filled(w, h, Rgb::splat(0.5));
    let mut f = NoisyFrame::new(Image::from_fn(w, h, |x, y| {
        truth.pixel(x, y) + noise3(21, y * w + x) * 0.1
    }));
    f.normal = Some(Image::from_fn(w, h, |x, y| {
        Vec3::Z + noise3(22, y * w + x) * 1.0
    }));
    f.normal_variance = Some(Image::filled(w, h, Vec3::splat(1.0)));
    f.albedo = Some(Image::filled(w, h, Vec3::splat(0.5)));
    f.position = Some(Image::from_fn(w, h, |x, y| {
        Vec3::new(x as f32, y as f32, 0.0)
    }));
    let all = |_, _| true;
    let with = mse(&build("bilateral").denoise(&f).unwrap(), &truth, all);
    let without = mse(
        &build("bilateral:variances=off").denoise(&f).unwrap(),
        &truth,
        all,
    );
    assert!(
        with < 0.5 * without,
        "with variances {with}, without {without}"
    );
}

/// A piecewise-constant 64×64 image (four blocks and a bar) and its noisy version with noise
/// of standard deviation `sigma`, the variance channel holding `sigma² · var_scale`.
fn blocks_frame(sigma: f32, var_scale: f32) -> (NoisyFrame, RgbImage) {
    let (w, h) = (64, 64);
    let truth = Image::from_fn(w, h, |x, y| match (x < 32, y < 32, (28..36).contains(&x)) {
        (_, _, true) if y > 8 && y < 56 => Rgb::new(0.9, 0.9, 0.1),
        (true, true, _) => Rgb::new(0.2, 0.3, 0.4),
        (false, true, _) => Rgb::new(0.8, 0.2, 0.2),
        (true, false, _) => Rgb::new(0.1, 0.7, 0.3),
        (false, false, _) => Rgb::new(0.5, 0.5, 0.9),
    });
    let noisy = Image::from_fn(w, h, |x, y| {
        truth.pixel(x, y) + noise3(7, y * w + x) * sigma
    });
    let mut f = NoisyFrame::new(noisy);
    f.variance = Some(Image::filled(w, h, Rgb::splat(sigma * sigma * var_scale)));
    (f, truth)
}

#[test]
fn nlm_removes_most_of_the_noise_and_its_weights_follow_the_variance() {
    let nlm = build("nlm");
    let all = |_, _| true;
    let (frame, truth) = blocks_frame(0.1, 1.0);
    let noisy = mse(&frame.colour, &truth, all);
    let out = nlm.denoise(&frame).unwrap();
    let filtered = mse(&out, &truth, all);
    assert!(filtered < 0.1 * noisy, "nlm {filtered} vs noisy {noisy}");
    // Overstating the variance 100× makes every patch look alike: it blurs the edges.
    let (over, _) = blocks_frame(0.1, 100.0);
    let blurred = nlm.denoise(&over).unwrap();
    let edges = |x: usize, y: usize| {
        [27, 28, 31, 32, 35, 36].contains(&x) || [8, 9, 31, 32, 56, 57].contains(&y)
    };
    let (e1, e100) = (mse(&out, &truth, edges), mse(&blurred, &truth, edges));
    assert!(
        e100 > 4.0 * e1,
        "edge error: variance x100 {e100}, true variance {e1}"
    );
    // Understating it 100× keeps the noise.
    let (under, _) = blocks_frame(0.1, 0.01);
    let kept = mse(&nlm.denoise(&under).unwrap(), &truth, all);
    assert!(kept > 4.0 * filtered, "variance /100 {kept} vs {filtered}");
}

#[test]
fn nlm_is_invariant_to_the_radiance_scale() {
    // Colour × 10 with variance × 100 gives the same distances, so the output is × 10.
    let (frame, _) = blocks_frame(0.1, 1.0);
    let mut bright = frame.clone();
    bright.colour = frame.colour.map(|c| *c * 10.0);
    bright.variance = frame.variance.as_ref().map(|v| v.map(|v| *v * 100.0));
    let nlm = build("nlm");
    let (a, b) = (nlm.denoise(&frame).unwrap(), nlm.denoise(&bright).unwrap());
    for (p, q) in a.pixels().iter().zip(b.pixels()) {
        assert!((*p * 10.0 - *q).abs().max_element() < 1e-4, "{p} {q}");
    }
}

#[test]
fn guided_filter_keeps_a_step_in_its_guide() {
    let (frame, truth) = step_frame("albedo");
    let near = |x: usize, _| (12..20).contains(&x);
    let far = |x: usize, y: usize| (2..10).contains(&x) && (4..28).contains(&y);
    let guided = build("guided:radius=4").denoise(&frame).unwrap();
    let edge = mse(&guided, &truth, near);
    let (flat, _) = step_frame("none");
    let blurred = build("guided:radius=4").denoise(&flat).unwrap();
    let edge_flat = mse(&blurred, &truth, near);
    assert!(
        edge_flat > 1e-3,
        "a flat guide should blur the step ({edge_flat})"
    );
    assert!(
        edge < 0.05 * edge_flat,
        "guided {edge} vs flat guide {edge_flat}"
    );
    assert!(mse(&guided, &truth, far) < 0.2 * mse(&frame.colour, &truth, far));
    // The normal guide keeps a normal step the same way, and eps is relative: scaling the
    // guide by 100 changes nothing.
    let (mut nf, _) = step_frame("normal");
    let g = build("guided:guide=normal:radius=4");
    let a = g.denoise(&nf).unwrap();
    assert!(mse(&a, &truth, near) < 0.05 * edge_flat);
    nf.normal = nf.normal.map(|n| n.map(|v| *v * 100.0 + Vec3::ONE));
    let b = g.denoise(&nf).unwrap();
    for (p, q) in a.pixels().iter().zip(b.pixels()) {
        assert!((*p - *q).abs().max_element() < 1e-4, "{p} {q}");
    }
}

#[test]
fn guided_filter_guided_by_its_input_with_tiny_eps_is_the_identity() {
    // With I = p and ε → 0, a = Σ⁻¹ cov(I, p) = identity and b = 0 in every window: a check on
    // the covariance assembly and the 3×3 solve.
    let img = noisy_image(23, 17, 4).map(|c| *c + Vec3::new(0.0, c.x * 0.5, c.y * 0.25));
    let out = build("guided:guide=colour:radius=2:eps=1e-7")
        .denoise(&NoisyFrame::new(img.clone()))
        .unwrap();
    for (p, q) in img.pixels().iter().zip(out.pixels()) {
        assert!((*p - *q).abs().max_element() < 1e-3, "{p} {q}");
    }
}

/// He et al.'s colour-guided filter by direct window sums in f64 (the definition, with windows
/// cut at the border and ε relative to the guide's frame variance, as documented).
fn guided_reference(guide: &Image<Vec3>, p: &RgbImage, r: usize, eps: f64) -> RgbImage {
    use rt_core::glam::{DMat3, DVec3};
    let (w, h) = p.size();
    let n = (w * h) as f64;
    let gm = guide
        .pixels()
        .iter()
        .fold(DVec3::ZERO, |s, v| s + v.as_dvec3())
        / n;
    let gvar = guide
        .pixels()
        .iter()
        .map(|v| (v.as_dvec3() - gm).length_squared())
        .sum::<f64>()
        / (3.0 * n);
    let eps = eps * gvar.max(1e-8);
    let win = |c: usize, len: usize| (c.saturating_sub(r), (c + r).min(len - 1));
    // Per-window coefficients a (rows per colour channel) and b.
    let mut coef = vec![(DMat3::ZERO, DVec3::ZERO); w * h];
    for y in 0..h {
        for x in 0..w {
            let ((x0, x1), (y0, y1)) = (win(x, w), win(y, h));
            let (mut mi, mut mp, mut mii, mut mip) =
                (DVec3::ZERO, DVec3::ZERO, DMat3::ZERO, DMat3::ZERO);
            let mut cnt = 0.0;
            for yy in y0..=y1 {
                for xx in x0..=x1 {
                    let (i, q) = (guide.pixel(xx, yy).as_dvec3(), p.pixel(xx, yy).as_dvec3());
                    mi += i;
                    mp += q;
                    mii += DMat3::from_cols(i * i.x, i * i.y, i * i.z);
                    // Column c holds I·p_c.
                    mip += DMat3::from_cols(i * q.x, i * q.y, i * q.z);
                    cnt += 1.0;
                }
            }
            let (mi, mp, mii, mip) = (mi / cnt, mp / cnt, mii * (1.0 / cnt), mip * (1.0 / cnt));
            let sigma = mii - DMat3::from_cols(mi * mi.x, mi * mi.y, mi * mi.z)
                + DMat3::from_diagonal(DVec3::splat(eps));
            let cov = mip - DMat3::from_cols(mi * mp.x, mi * mp.y, mi * mp.z);
            let a = sigma.inverse() * cov; // column c: a for channel c
            let b = mp - a.transpose() * mi;
            coef[y * w + x] = (a, b);
        }
    }
    Image::from_fn(w, h, |x, y| {
        let ((x0, x1), (y0, y1)) = (win(x, w), win(y, h));
        let (mut a, mut b, mut cnt) = (DMat3::ZERO, DVec3::ZERO, 0.0);
        for yy in y0..=y1 {
            for xx in x0..=x1 {
                let (ca, cb) = coef[yy * w + xx];
                a += ca;
                b += cb;
                cnt += 1.0;
            }
        }
        let q = (a * (1.0 / cnt)).transpose() * guide.pixel(x, y).as_dvec3() + b / cnt;
        q.as_vec3()
    })
}

#[test]
fn guided_filter_matches_the_definition_by_direct_sums() {
    let (w, h) = (19, 14);
    let p = noisy_image(w, h, 31);
    let guide = Image::from_fn(w, h, |x, y| {
        let i = y * w + x;
        Vec3::new(
            uniform(40, i as u32),
            if x < 9 { 0.2 } else { 0.9 },
            uniform(41, i as u32),
        )
    });
    let mut f = NoisyFrame::new(p.clone());
    f.albedo = Some(guide.clone());
    for (r, eps) in [(1, 0.01), (3, 0.1), (30, 0.01)] {
        let out = build(&format!("guided:radius={r}:eps={eps}"))
            .denoise(&f)
            .unwrap();
        let want = guided_reference(&guide, &p, r, eps);
        for (a, b) in out.pixels().iter().zip(want.pixels()) {
            assert!(
                (*a - *b).abs().max_element() < 1e-4,
                "r={r} eps={eps}: {a} vs {b}"
            );
        }
    }
}

#[test]
fn a_missing_channel_is_one_error_naming_it() {
    let frame = NoisyFrame::new(noisy_image(4, 3, 1));
    for (spec, channel) in [
        ("nlm", "variance"),
        ("bilateral", "normal"),
        ("bilateral:normal=0", "position"),
        ("bilateral:normal=0:position=0", "albedo"),
        ("guided", "albedo"),
        ("guided:guide=normal", "normal"),
    ] {
        match build(spec).denoise(&frame) {
            Err(e @ DenoiseError::Frame(_)) => {
                let m = e.to_string();
                assert!(m.contains(&format!("the {channel} channel")), "{spec}: {m}");
            }
            other => panic!("{spec}: {other:?}"),
        }
    }
    let mut f = full_frame(noisy_image(4, 3, 1), 2);
    f.normal_variance = None;
    let e = build("bilateral:variances=on").denoise(&f).unwrap_err();
    assert!(e.to_string().contains("normal_variance"), "{e}");
    // `auto` runs without it, and the colour-guided filter needs nothing.
    assert!(build("bilateral").denoise(&f).is_ok());
    assert!(build("guided:guide=colour").denoise(&frame).is_ok());
    assert_eq!(build("guided:guide=colour").needs(), &[]);
    assert_eq!(build("gaussian").needs(), &[]);
}

#[test]
fn bad_parameters_are_param_errors_naming_the_key() {
    for (spec, key) in [
        ("gaussian:sigma=-1", "sigma"),
        ("gaussian:sigma=nan", "sigma"),
        ("gaussian:sigma=100", "sigma"),
        ("bilateral:sigma=0", "sigma"),
        ("bilateral:sigma=-2", "sigma"),
        ("bilateral:normal=-0.1", "normal"),
        ("bilateral:position=inf", "position"),
        ("bilateral:albedo=nan", "albedo"),
        ("bilateral:colour=-1", "colour"),
        ("bilateral:variances=maybe", "variances"),
        ("nlm:radius=0", "radius"),
        ("nlm:radius=33", "radius"),
        ("nlm:patch=17", "patch"),
        ("nlm:k=-0.1", "k"),
        ("nlm:eps=0", "eps"),
        ("nlm:eps=nan", "eps"),
        ("guided:radius=0", "radius"),
        ("guided:eps=0", "eps"),
        ("guided:eps=-1", "eps"),
        ("guided:guide=depth", "guide"),
    ] {
        let s: DenoiserSpec = spec.parse().unwrap();
        match s.build() {
            Err(DenoiseError::Param { name, .. }) => assert_eq!(name, key, "{spec}"),
            Err(e) => panic!("{spec}: {e}"),
            Ok(d) => panic!("{spec}: built {}", d.name()),
        }
    }
    // Constructors check too (NaN cannot reach them through a spec).
    assert!(rt_denoise::Gaussian::new(f32::NAN).is_err());
    assert!(rt_denoise::Nlm::new(7, 3, f32::NAN, 1e-10).is_err());
    assert!(rt_denoise::GuidedFilter::new(8, f32::NAN, rt_denoise::Guide::Albedo).is_err());
    let v = rt_denoise::VarianceUse::Auto;
    assert!(rt_denoise::JointBilateral::new(2.0, [f32::NAN, 0.6, 0.25, 0.0], v).is_err());
}

#[test]
fn specs_name_every_bank_member_with_its_defaults() {
    for (spec, name) in [
        ("gaussian", "gaussian:sigma=2"),
        (
            "bilateral",
            "bilateral:sigma=2:normal=0.8:position=0.6:albedo=0.25:colour=0:variances=auto",
        ),
        ("nlm", "nlm:radius=7:patch=3:k=0.45:eps=1e-10"),
        ("guided", "guided:radius=8:eps=0.01:guide=albedo"),
    ] {
        let d = build(spec);
        assert_eq!(d.name(), name);
        // The name is itself a spec that builds the same filter.
        assert_eq!(build(name).name(), name);
    }
}
