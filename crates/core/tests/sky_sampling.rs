//! Importance sampling of the Preetham sky (`rt_core::environment::sky`): the tabulated map
//! plus its sun disc, sampled as a mixture. χ² goodness of fit (`rt_testkit::chi2`) of
//! `Environment::sample` against `Environment::pdf` over the whole sphere, and a second χ²
//! zoomed onto the sun (the disc is 0.27° across, inside one bin of the first test), each with
//! a control that a wrong pdf or sampler fails; then `sample`/`pdf`/`radiance` agreement and
//! finiteness over extreme skies. Samples are independent (`rt_testkit::Rng`), as in
//! `light_sampling.rs`.

use rt_core::environment::sky::{Sky, DEFAULT_RESOLUTION};
use rt_core::environment::{Environment, SunDisc};
use rt_core::frame::Frame;
use rt_core::glam::{Vec2, Vec3};
use rt_testkit::chi2;
use rt_testkit::Rng;

/// Family-wise false-alarm rate of this file's χ² tests (Šidák-corrected over them).
const FAMILY_ALPHA: f64 = 0.01;
/// χ² tests in this file that must pass (the controls are judged at the same level).
const TESTS: usize = 2;
/// Samples per test.
const N: usize = 400_000;

fn alpha() -> f64 {
    chi2::sidak(FAMILY_ALPHA, TESTS)
}

/// Direction in the χ² helper's frame (θ from +z, φ from +x towards +y) at the centre of bin
/// (`t`, `p`), so the sun disc lies far inside one bin.
fn bin_centre(t: usize, p: usize) -> Vec3 {
    let theta = (t as f32 + 0.5) * std::f32::consts::PI / chi2::THETA_BINS as f32;
    let phi = (p as f32 + 0.5) * 2.0 * std::f32::consts::PI / chi2::PHI_BINS as f32;
    Vec3::new(
        theta.sin() * phi.cos(),
        theta.sin() * phi.sin(),
        theta.cos(),
    )
}

/// The sky of the tests: turbidity 3, the sun at 56° elevation in the middle of χ² bin
/// (12, 20), tabulated at the default resolution.
fn sky() -> (Environment, Vec3) {
    let sun = bin_centre(12, 20);
    assert!(sun.y > 0.8, "{sun}");
    let (w, h) = DEFAULT_RESOLUTION;
    let map = Sky::new(sun, 3.0).unwrap().to_env_map(1.0, w, h).unwrap();
    (Environment::Map(map), sun)
}

fn sun_of(env: &Environment) -> &SunDisc {
    env.map().unwrap().sun().unwrap()
}

fn sun_prob(env: &Environment) -> f64 {
    env.map().unwrap().importance().sun_probability() as f64
}

/// Observed counts per χ² bin of `N` draws of `sample` (after `map`; `None` is skipped).
fn observe(
    mut sample: impl FnMut(&mut Rng) -> Option<Vec3>,
    map: impl Fn(Vec3) -> Option<Vec3>,
) -> (Vec<f64>, usize) {
    let mut rng = Rng::new(0x5c1e5);
    let mut observed = vec![0.0; chi2::THETA_BINS * chi2::PHI_BINS];
    let mut kept = 0;
    for _ in 0..N {
        if let Some(d) = sample(&mut rng).and_then(&map) {
            observed[chi2::bin_of(d)] += 1.0;
            kept += 1;
        }
    }
    (observed, kept)
}

/// Expected fractions over the sphere for `pdf`, with the sun disc's part (`sun_mass`, the
/// probability of landing in the disc, which a midpoint grid cannot integrate) added to the
/// bin that holds `sun`; `pdf` must leave the disc's part out.
fn expected_with_sun(pdf: impl Fn(Vec3) -> f64, sun: Vec3, sun_mass: f64) -> Vec<f64> {
    // 16 × 16 points per bin: a bin (4.5°) spans 6.4 texel columns of the 512-wide map.
    let mut e = chi2::expected(pdf, 16);
    e[chi2::bin_of(sun)] += sun_mass;
    e
}

#[test]
fn sky_sampling_matches_its_pdf_chi_square() {
    let (env, sun_dir) = sky();
    let sun = *sun_of(&env);
    let p = sun_prob(&env);
    // The pdf without the disc's term, p / Ω inside it: that term is added per bin.
    let without_disc = |d: Vec3| {
        let disc = if sun.contains(d) {
            p / sun.solid_angle() as f64
        } else {
            0.0
        };
        env.pdf(d) as f64 - disc
    };
    let expected = expected_with_sun(without_disc, sun_dir, p);
    let total: f64 = expected.iter().sum();
    assert!((total - 1.0).abs() < 2e-3, "the pdf integrates to {total}");
    let (observed, kept) = observe(|rng| Some(env.sample(rng.vec2())?.dir), Some);
    assert_eq!(kept, N, "every sample is a direction");
    let r = chi2::test(&observed, &expected, N);
    eprintln!("sky: p_sun {p:.4}, {r:?}, α {:.2e}", alpha());
    assert!(
        r.passes(alpha()),
        "sky samples do not follow the pdf: {r:?}"
    );

    // Controls, on the same samples: the sun's share misstated by 2 % (as from a power
    // computed without the sinθ of the texels), and the texels' pdf without its sinθ
    // Jacobian (the classic lat-long bug), must both fail.
    let wrong_share = expected_with_sun(
        |d| without_disc(d) * (1.0 - 1.02 * p) / (1.0 - p),
        sun_dir,
        1.02 * p,
    );
    let r = chi2::test(&observed, &wrong_share, N);
    eprintln!("control, sun share +2 %: {r:?}");
    assert!(!r.passes(alpha()), "control (sun share +2 %) passed: {r:?}");
    let no_jacobian = {
        let raw = chi2::expected(|d| without_disc(d) * d.x.hypot(d.z) as f64, 16);
        let scale = (1.0 - p) / raw.iter().sum::<f64>();
        let mut e: Vec<f64> = raw.iter().map(|v| v * scale).collect();
        e[chi2::bin_of(sun_dir)] += p;
        e
    };
    let r = chi2::test(&observed, &no_jacobian, N);
    eprintln!("control, no sinθ: {r:?}");
    assert!(!r.passes(alpha()), "control (no sinθ) passed: {r:?}");
}

/// Maps a direction inside the disc onto the whole sphere of the χ² helper: `1 − cos θ'`
/// (θ' from the disc's centre) linearly onto `z ∈ [−1, 1]`, the azimuth around the centre
/// kept. Uniform in the disc becomes uniform on the sphere; directions outside give `None`.
fn zoom(sun: &SunDisc, d: Vec3) -> Option<Vec3> {
    if !sun.contains(d) {
        return None;
    }
    let l = Frame::from_normal(sun.dir()).to_local(d.normalize());
    let sin2 = l.x * l.x + l.y * l.y;
    let one_minus_cos = sin2 / (1.0 + l.z.max(0.0));
    let rim = sun.solid_angle() / (2.0 * std::f32::consts::PI);
    let z = (1.0 - 2.0 * one_minus_cos / rim).clamp(-1.0, 1.0);
    let r = (1.0 - z * z).max(0.0).sqrt();
    let phi = l.y.atan2(l.x);
    Some(Vec3::new(r * phi.cos(), r * phi.sin(), z))
}

/// The inverse of [`zoom`]: the direction inside the disc that maps to `w`.
fn unzoom(sun: &SunDisc, w: Vec3) -> Vec3 {
    let rim = sun.solid_angle() / (2.0 * std::f32::consts::PI);
    let one_minus_cos = (1.0 - w.z) * 0.5 * rim;
    let sin_t = (one_minus_cos * (2.0 - one_minus_cos)).sqrt();
    let phi = w.y.atan2(w.x);
    let local = Vec3::new(sin_t * phi.cos(), sin_t * phi.sin(), 1.0 - one_minus_cos);
    Frame::from_normal(sun.dir()).to_world(local)
}

#[test]
fn sun_disc_sampling_matches_the_pdf_chi_square_zoomed() {
    let (env, _) = sky();
    let sun = *sun_of(&env);
    // Density on the zoomed sphere ∝ pdf at the disc point (the map has a constant Jacobian
    // Ω / 4π); normalised to the samples that land in the disc.
    let zoomed_expected = || {
        let raw = chi2::expected(|w| env.pdf(unzoom(&sun, w)) as f64, 4);
        let total: f64 = raw.iter().sum();
        raw.into_iter().map(|v| v / total).collect::<Vec<_>>()
    };
    let expected = zoomed_expected();
    let (observed, kept) = observe(|rng| Some(env.sample(rng.vec2())?.dir), |d| zoom(&sun, d));
    // About p_sun of the samples land in the disc (plus the map's tiny share there).
    let p = sun_prob(&env);
    assert!(
        (kept as f64 / N as f64 - p).abs() < 5.0 * (p * (1.0 - p) / N as f64).sqrt() + 1e-4,
        "{kept} of {N} in the disc, p_sun {p}"
    );
    let r = chi2::test(&observed, &expected, kept);
    eprintln!("sun disc: {kept} samples, {r:?}, α {:.2e}", alpha());
    assert!(
        r.passes(alpha()),
        "samples in the sun disc do not follow the pdf: {r:?}"
    );

    // Control: directions uniform in the angle θ' instead of in solid angle (a cone sampled
    // with θ' = r·u) against the same pdf must fail.
    let radius = sun.radius();
    let frame = Frame::from_normal(sun.dir());
    let (observed, kept) = observe(
        |rng| {
            let u = rng.vec2();
            let t = radius * u.x;
            let phi = 2.0 * std::f32::consts::PI * u.y;
            Some(frame.to_world(Vec3::new(t.sin() * phi.cos(), t.sin() * phi.sin(), t.cos())))
        },
        |d| zoom(&sun, d),
    );
    let r = chi2::test(&observed, &expected, kept);
    eprintln!("control, uniform in angle: {r:?}");
    assert!(
        !r.passes(alpha()),
        "control (uniform in angle) passed: {r:?}"
    );
}

#[test]
fn sample_pdf_and_radiance_agree_and_are_finite_for_extreme_skies() {
    let mut rng = Rng::new(0xd15c);
    for (t, elevation) in [(1.7f32, 90.0f32), (10.0, 0.0), (3.0, 0.1), (2.0, 12.0)] {
        let e = elevation.to_radians();
        let sun = Vec3::new(0.3 * e.cos(), e.sin(), -(1.0f32 - 0.09).sqrt() * e.cos());
        let map = Sky::new(sun, t).unwrap().to_env_map(1.0, 128, 64).unwrap();
        let env = Environment::Map(map);
        let disc = *sun_of(&env);
        let (mut in_disc, mut outside_rim) = (0, 0);
        let n = 20_000;
        for i in 0..n {
            // Random points, and the corners and edges of the square.
            let u = match i {
                0 => Vec2::ZERO,
                1 => Vec2::splat(rt_core::distribution::ONE_MINUS_EPS),
                2 => Vec2::new(0.0, rt_core::distribution::ONE_MINUS_EPS),
                3 => Vec2::new(rt_core::distribution::ONE_MINUS_EPS, 0.0),
                _ => rng.vec2(),
            };
            let Some(s) = env.sample(u) else { continue };
            assert!(
                s.pdf.is_finite() && s.pdf > 0.0,
                "T {t} el {elevation}: {s:?}"
            );
            assert!(s.radiance.is_finite() && s.radiance.min_element() >= 0.0);
            let ratio = s.radiance / s.pdf;
            assert!(ratio.is_finite(), "radiance / pdf = {ratio}");
            // Exactly: `sample` evaluates both at its direction the way `pdf` and `radiance` do.
            assert_eq!(env.pdf(s.dir), s.pdf, "T {t} el {elevation} at {}", s.dir);
            assert_eq!(
                env.radiance(s.dir),
                s.radiance,
                "T {t} el {elevation} at {}",
                s.dir
            );
            if u.x < sun_prob(&env) as f32 {
                in_disc += 1;
                if !disc.contains(s.dir) {
                    outside_rim += 1;
                }
            }
        }
        assert!(
            in_disc > 0,
            "T {t} el {elevation}: the sun is never sampled"
        );
        eprintln!("T {t} el {elevation}: {outside_rim} of {in_disc} disc samples outside the rim");
        // Rounding puts at most a sliver of disc samples just outside the rim (radiance and
        // pdf are then both the map's, so they stay consistent).
        assert!(
            outside_rim * 1000 <= in_disc,
            "{outside_rim} of {in_disc} outside the rim"
        );
    }
}
