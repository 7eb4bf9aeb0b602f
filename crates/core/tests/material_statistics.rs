//! Statistical checks of the layered material: sampling matches evaluation (χ² goodness of fit,
//! `rt_testkit::chi2`, at a Šidák-corrected 1 % over all cases) and no material reflects more
//! energy than it receives, at any incident angle. The samples are independent
//! (`rt_testkit::Rng`): the renderer's stratified sampler would make the χ² statistic too small
//! and the test too lenient.

use rt_core::glam::Vec3;
use rt_core::material::{Bsdf, Layer};
use rt_core::{Material, Rgb};
use rt_testkit::{chi2, Rng};

fn materials() -> Vec<Material> {
    let mut two = Material::diffuse("two-layer", Rgb::ONE);
    two.layers = vec![
        Layer::new(0.5, Rgb::new(0.9, 0.6, 0.3), 0.0),
        Layer::new(0.5, Rgb::ONE, 0.7),
    ];
    vec![
        Material::diffuse("diffuse", Rgb::ONE),
        Material::glossy("glossy-0.3", Rgb::ONE, 0.3),
        Material::glossy("glossy-0.8", Rgb::ONE, 0.8),
        Material::metal("metal", Rgb::splat(0.9), 0.6),
        Material::plastic("plastic", Rgb::ONE, 0.5, 1.5),
        Material::glass("frosted", Rgb::ONE, 1.5, 0.5),
        Material::glass("frosted-rough", Rgb::ONE, 1.33, 0.1),
        two,
    ]
}

fn wo_at(cos: f32, side: f32) -> Vec3 {
    Vec3::new((1.0 - cos * cos).sqrt(), 0.0, cos * side)
}

/// The control's sampler: `m` with every glossy exponent `k = 1024κ + 1` made 10 % larger and
/// every Lambertian layer made a Blinn–Phong lobe of exponent 2 (κ = 0.001). Its samples,
/// histogrammed against `m`'s pdf, must fail: the χ² test sees a sampler that disagrees with
/// its pdf by that much.
fn perturbed(m: &Material) -> Material {
    let mut m = m.clone();
    for l in &mut m.layers {
        if l.hardness <= 0.0 {
            l.hardness = 0.001;
        } else if l.hardness < 1.0 {
            l.hardness = ((1024.0 * l.hardness + 1.0) * 1.1 - 1.0) / 1024.0;
        }
    }
    m
}

/// χ² of `n` directions sampled from `sampler` for `wo` against `model`'s pdf.
fn chi_square(
    model: &Material,
    sampler: &Material,
    wo: Vec3,
    n: usize,
    rng: &mut Rng,
) -> chi2::ChiSquare {
    let bsdf = Bsdf::new(model, Rgb::ONE, Vec3::Z, Vec3::Z, wo);
    let exp = chi2::expected(|d| bsdf.pdf(d) as f64, 16);
    let source = Bsdf::new(sampler, Rgb::ONE, Vec3::Z, Vec3::Z, wo);
    let mut obs = vec![0.0f64; exp.len()];
    for _ in 0..n {
        if let Some(s) = source.sample(rng.f32(), rng.vec2()) {
            if !s.delta {
                obs[chi2::bin_of(s.wi)] += 1.0;
            }
        }
    }
    chi2::test(&obs, &exp, n)
}

#[test]
fn sampling_matches_the_pdf_chi_square() {
    let n = 200_000usize;
    let mut rng = Rng::new(0x853c_49e6_748f_ea9b);
    let cases: Vec<(Material, f32, f32)> = materials()
        .into_iter()
        .flat_map(|m| {
            [
                (m.clone(), 0.9, 1.0),
                (m.clone(), 0.35, 1.0),
                (m, 0.6, -1.0),
            ]
        })
        .collect();
    // Šidák: each case at the level that gives all of them together a 1 % false-alarm rate.
    let alpha = chi2::sidak(0.01, cases.len());
    let mut failures = Vec::new();
    for (m, cos, side) in &cases {
        let wo = wo_at(*cos, *side);
        let r = chi_square(m, m, wo, n, &mut rng);
        if !r.passes(alpha) {
            failures.push(format!("{} cos={cos} side={side}: {r:?}", m.name));
        }
        // Control: the perturbed sampler against the same pdf must fail at the same level.
        let c = chi_square(m, &perturbed(m), wo, n, &mut rng);
        if c.passes(alpha) {
            failures.push(format!(
                "control: {} cos={cos} side={side} with exponents x1.1 passes: {c:?}",
                m.name
            ));
        }
    }
    assert!(
        failures.is_empty(),
        "χ² failures at the per-case level α = {alpha:.2e} (1 % over {} cases):\n{}",
        cases.len(),
        failures.join("\n")
    );
}

/// Mean sample weight = directional albedo. Refracted weights carry the radiance factor 1/η²;
/// energy (flux) is conserved without it, so multiply it back.
fn albedo(m: &Material, wo: Vec3, n: usize, rng: &mut Rng) -> (f64, f64) {
    let bsdf = Bsdf::new(m, Rgb::ONE, Vec3::Z, Vec3::Z, wo);
    let (mut sum, mut sum2) = (0.0f64, 0.0f64);
    for _ in 0..n {
        let w = match bsdf.sample(rng.f32(), rng.vec2()) {
            Some(s) => {
                let mut w = s.weight.max_element() as f64;
                if s.transmitted {
                    let eta = if wo.z > 0.0 {
                        m.layers[0].ior
                    } else {
                        1.0 / m.layers[0].ior
                    };
                    w *= (eta * eta) as f64;
                }
                w
            }
            None => 0.0,
        };
        sum += w;
        sum2 += w * w;
    }
    let mean = sum / n as f64;
    let var = (sum2 / n as f64 - mean * mean).max(0.0);
    (mean, (var / n as f64).sqrt())
}

#[test]
fn every_material_conserves_energy_at_every_angle() {
    let mut rng = Rng::new(42);
    let mut all = materials();
    all.push(Material::mirror("mirror", Rgb::ONE));
    all.push(Material::glass("glass", Rgb::ONE, 1.5, 1.0));
    for m in &all {
        for cos in [1.0, 0.8, 0.5, 0.2, 0.05, 0.01] {
            for side in [1.0, -1.0] {
                let (a, se) = albedo(m, wo_at(cos, side), 20_000, &mut rng);
                assert!(
                    a <= 1.0 + 4.0 * se + 1e-4,
                    "{} cos={cos} side={side}: albedo {a} ± {se}",
                    m.name
                );
            }
        }
    }
}

#[test]
fn energy_conserving_presets_lose_nothing() {
    let mut rng = Rng::new(7);
    for m in [
        Material::diffuse("diffuse", Rgb::ONE),
        Material::mirror("mirror", Rgb::ONE),
        Material::glass("glass", Rgb::ONE, 1.5, 1.0),
    ] {
        for cos in [1.0, 0.6, 0.2, 0.03] {
            for side in [1.0, -1.0] {
                let (a, se) = albedo(&m, wo_at(cos, side), 5_000, &mut rng);
                assert!(
                    (a - 1.0).abs() <= 4.0 * se + 1e-4,
                    "{} cos={cos}: albedo {a} ± {se}",
                    m.name
                );
            }
        }
    }
}

#[test]
fn bsdf_eval_matches_sample_weight() {
    // For non-delta samples the returned weight must be f·|cos|/pdf of the same direction.
    let mut rng = Rng::new(99);
    for m in materials() {
        let wo = wo_at(0.7, 1.0);
        let bsdf = Bsdf::new(&m, Rgb::ONE, Vec3::Z, Vec3::Z, wo);
        for _ in 0..200 {
            if let Some(s) = bsdf.sample(rng.f32(), rng.vec2()) {
                if s.delta {
                    continue;
                }
                let (f, pdf) = bsdf.eval_pdf(s.wi);
                let w = f * (s.wi.z.abs() / pdf);
                assert!(
                    (w - s.weight).length() <= 1e-3 * (1.0 + w.length()),
                    "{}",
                    m.name
                );
                assert!((pdf - s.pdf).abs() <= 1e-4 * pdf.max(1.0));
            }
        }
    }
}
