//! Statistical checks of the layered material: sampling matches evaluation (χ² goodness of fit)
//! and no material reflects more energy than it receives, at any incident angle.

use rt_core::glam::{Vec2, Vec3};
use rt_core::material::{Bsdf, Layer};
use rt_core::{Material, Rgb};
use std::f64::consts::PI;

/// PCG32: independent samples for the statistics (the renderer's stratified sampler would make
/// the χ² statistic too small and the test too lenient).
struct Pcg(u64);
impl Pcg {
    fn next(&mut self) -> f32 {
        self.0 = self
            .0
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        let x = (((self.0 >> 18) ^ self.0) >> 27) as u32;
        let r = (self.0 >> 59) as u32;
        (x.rotate_right(r) >> 8) as f32 / (1u32 << 24) as f32
    }
    fn next2(&mut self) -> Vec2 {
        Vec2::new(self.next(), self.next())
    }
}

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

/// Regularised lower incomplete gamma P(a, x) by series / continued fraction (Numerical
/// Recipes), for the χ² survival function.
fn gamma_p(a: f64, x: f64) -> f64 {
    fn ln_gamma(x: f64) -> f64 {
        let c = [
            76.18009172947146,
            -86.50532032941677,
            24.01409824083091,
            -1.231739572450155,
            0.1208650973866179e-2,
            -0.5395239384953e-5,
        ];
        let mut y = x;
        let t = x + 5.5 - (x + 0.5) * (x + 5.5).ln();
        let mut s = 1.000000000190015;
        for ci in c {
            y += 1.0;
            s += ci / y;
        }
        -t + (2.5066282746310005 * s / x).ln()
    }
    if x < a + 1.0 {
        let (mut sum, mut del, mut ap) = (1.0 / a, 1.0 / a, a);
        for _ in 0..10_000 {
            ap += 1.0;
            del *= x / ap;
            sum += del;
            if del.abs() < sum.abs() * 1e-15 {
                break;
            }
        }
        sum * (-x + a * x.ln() - ln_gamma(a)).exp()
    } else {
        let (mut b, mut c, mut d) = (x + 1.0 - a, 1.0 / 1e-300, 1.0 / (x + 1.0 - a));
        let mut h = d;
        for i in 1..10_000 {
            let an = -(i as f64) * (i as f64 - a);
            b += 2.0;
            d = an * d + b;
            if d.abs() < 1e-300 {
                d = 1e-300;
            }
            c = b + an / c;
            if c.abs() < 1e-300 {
                c = 1e-300;
            }
            d = 1.0 / d;
            let del = d * c;
            h *= del;
            if (del - 1.0).abs() < 1e-15 {
                break;
            }
        }
        1.0 - (-x + a * x.ln() - ln_gamma(a)).exp() * h
    }
}

const THETA_BINS: usize = 40;
const PHI_BINS: usize = 80;

fn bin_of(d: Vec3) -> usize {
    let theta = (d.z.clamp(-1.0, 1.0) as f64).acos();
    let phi = (d.y as f64).atan2(d.x as f64).rem_euclid(2.0 * PI);
    let t = ((theta / PI * THETA_BINS as f64) as usize).min(THETA_BINS - 1);
    let p = ((phi / (2.0 * PI) * PHI_BINS as f64) as usize).min(PHI_BINS - 1);
    t * PHI_BINS + p
}

/// Expected fraction of samples per bin: the pdf integrated over each bin (midpoint rule on a
/// fine sub-grid in (θ, φ), with the sinθ Jacobian).
fn expected(bsdf: &Bsdf) -> Vec<f64> {
    const SUB: usize = 16;
    let mut out = vec![0.0; THETA_BINS * PHI_BINS];
    for t in 0..THETA_BINS * SUB {
        let theta = (t as f64 + 0.5) / (THETA_BINS * SUB) as f64 * PI;
        let dtheta = PI / (THETA_BINS * SUB) as f64;
        for p in 0..PHI_BINS * SUB {
            let phi = (p as f64 + 0.5) / (PHI_BINS * SUB) as f64 * 2.0 * PI;
            let dphi = 2.0 * PI / (PHI_BINS * SUB) as f64;
            let d = Vec3::new(
                (theta.sin() * phi.cos()) as f32,
                (theta.sin() * phi.sin()) as f32,
                theta.cos() as f32,
            );
            let pdf = bsdf.pdf(d) as f64;
            out[(t / SUB) * PHI_BINS + p / SUB] += pdf * theta.sin() * dtheta * dphi;
        }
    }
    out
}

#[test]
fn sampling_matches_the_pdf_chi_square() {
    let n = 200_000usize;
    let mut rng = Pcg(0x853c49e6748fea9b);
    let mut tests = 0;
    let mut failures = Vec::new();
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
    for (m, cos, side) in &cases {
        let wo = wo_at(*cos, *side);
        let bsdf = Bsdf::new(m, Rgb::ONE, Vec3::Z, Vec3::Z, wo);
        let exp = expected(&bsdf);
        let mut obs = vec![0.0f64; exp.len()];
        for _ in 0..n {
            if let Some(s) = bsdf.sample(rng.next(), rng.next2()) {
                if !s.delta {
                    obs[bin_of(s.wi)] += 1.0;
                }
            }
        }
        // Pool bins with small expected counts (the χ² approximation needs ≥ 5 per cell).
        let (mut chi2, mut dof, mut pool_e, mut pool_o) = (0.0, 0usize, 0.0, 0.0);
        for (e, o) in exp.iter().map(|e| e * n as f64).zip(&obs) {
            if e < 5.0 {
                pool_e += e;
                pool_o += o;
                continue;
            }
            chi2 += (o - e) * (o - e) / e;
            dof += 1;
        }
        if pool_e >= 5.0 {
            chi2 += (pool_o - pool_e) * (pool_o - pool_e) / pool_e;
            dof += 1;
        } else {
            // Samples where the pdf says (almost) none may fall are a failure in themselves.
            assert!(
                pool_o < 20.0 + 10.0 * pool_e,
                "{}: {pool_o} samples in bins with expected {pool_e}",
                m.name
            );
        }
        let p_value = 1.0 - gamma_p((dof - 1) as f64 / 2.0, chi2 / 2.0);
        tests += 1;
        if p_value < 1e-3 {
            failures.push(format!(
                "{} cos={cos} side={side}: chi2={chi2:.1} dof={dof} p={p_value:.2e}",
                m.name
            ));
        }
    }
    // Šidák-corrected overall significance of 1% across all cases.
    let alpha = 1.0 - 0.99f64.powf(1.0 / tests as f64);
    assert!(alpha > 1e-4);
    assert!(
        failures.is_empty(),
        "χ² failures (per-test α≈{alpha:.1e}, threshold 1e-3):\n{}",
        failures.join("\n")
    );
}

/// Mean sample weight = directional albedo. Refracted weights carry the radiance factor 1/η²;
/// energy (flux) is conserved without it, so multiply it back.
fn albedo(m: &Material, wo: Vec3, n: usize, rng: &mut Pcg) -> (f64, f64) {
    let bsdf = Bsdf::new(m, Rgb::ONE, Vec3::Z, Vec3::Z, wo);
    let (mut sum, mut sum2) = (0.0f64, 0.0f64);
    for _ in 0..n {
        let w = match bsdf.sample(rng.next(), rng.next2()) {
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
    let mut rng = Pcg(42);
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
    let mut rng = Pcg(7);
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
    let mut rng = Pcg(99);
    for m in materials() {
        let wo = wo_at(0.7, 1.0);
        let bsdf = Bsdf::new(&m, Rgb::ONE, Vec3::Z, Vec3::Z, wo);
        for _ in 0..200 {
            if let Some(s) = bsdf.sample(rng.next(), rng.next2()) {
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
