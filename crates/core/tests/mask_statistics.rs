//! Statistical checks of Mitsuba's `mask` (`Material::opacity`, `rt_core::material::Bsdf`):
//! the non-delta directions sampled match the pdf, which a mask scales by its opacity (χ²,
//! `rt_testkit::chi2`, Šidák-corrected 1 % over all cases; the pass-through is a delta lobe,
//! the missing mass), and the pass-through is chosen with probability `1 − opacity`, weight
//! one, along `−wo` (binomial, 4 standard deviations). Control: samples of opacity 0.5 judged
//! against the pdf of opacity 0.6 are rejected.

use rt_core::glam::Vec3;
use rt_core::material::Bsdf;
use rt_core::microfacet::{Distribution, DistributionKind, Microfacet, RoughConductor};
use rt_core::{Material, Rgb};
use rt_testkit::{chi2, Rng};

fn masked(mut m: Material, opacity: f32) -> Material {
    m.opacity = Some(opacity);
    m
}

fn gold(alpha: f32) -> Material {
    Material::microfacet(
        "gold",
        Microfacet::Conductor(RoughConductor {
            distribution: Some(Distribution::new(DistributionKind::Ggx, alpha, alpha)),
            eta: Rgb::new(0.143, 0.374, 1.442),
            k: Rgb::new(3.983, 2.385, 1.603),
            specular_reflectance: Rgb::ONE,
            two_sided: false,
        }),
    )
}

fn cases() -> Vec<Material> {
    vec![
        masked(Material::diffuse("diffuse", Rgb::ONE), 0.4),
        masked(Material::glossy("glossy", Rgb::ONE, 0.8), 0.7),
        masked(Material::plastic("plastic", Rgb::ONE, 0.5, 1.5), 0.5),
        masked(gold(0.3), 0.5),
    ]
}

fn wo() -> Vec3 {
    Vec3::new(0.6, 0.0, 0.8)
}

fn chi_square(model: &Material, sampler: &Material, n: usize, rng: &mut Rng) -> chi2::ChiSquare {
    let bsdf = Bsdf::new(model, Rgb::ONE, Vec3::Z, Vec3::Z, wo());
    let exp = chi2::expected(|d| bsdf.pdf(d) as f64, 16);
    let source = Bsdf::new(sampler, Rgb::ONE, Vec3::Z, Vec3::Z, wo());
    let mut obs = vec![0.0f64; exp.len()];
    for _ in 0..n {
        if let Some(s) = source.sample(rng.f32(), rng.vec2()).filter(|s| !s.delta) {
            obs[chi2::bin_of(s.wi)] += 1.0;
        }
    }
    chi2::test(&obs, &exp, n)
}

#[test]
fn masked_sampling_matches_the_pdf_chi_square() {
    let n = 200_000;
    let mut rng = Rng::new(0x2545_f491_4f6c_dd1d);
    let cases = cases();
    let alpha = chi2::sidak(0.01, cases.len());
    for m in &cases {
        let r = chi_square(m, m, n, &mut rng);
        assert!(r.passes(alpha), "{}: {r:?}", m.name);
    }
    // Control: opacity 0.5 sampled, 0.6 expected.
    let r = chi_square(
        &masked(gold(0.3), 0.6),
        &masked(gold(0.3), 0.5),
        n,
        &mut rng,
    );
    assert!(
        !r.passes(alpha),
        "the χ² test missed a wrong opacity: {r:?}"
    );
}

#[test]
fn the_pass_through_is_chosen_with_probability_one_minus_opacity() {
    let n = 100_000;
    let mut rng = Rng::new(0x9e37_79b9);
    for m in cases() {
        let op = m.opacity.unwrap() as f64;
        let bsdf = Bsdf::new(&m, Rgb::ONE, Vec3::Z, Vec3::Z, wo());
        let mut through = 0usize;
        for _ in 0..n {
            let Some(s) = bsdf.sample(rng.f32(), rng.vec2()) else {
                continue;
            };
            if s.transmitted && s.wi == -wo() {
                assert!(s.delta && s.weight == Rgb::ONE, "{}: {s:?}", m.name);
                assert!((s.pdf as f64 - (1.0 - op)).abs() < 1e-6);
                through += 1;
            }
        }
        let p = 1.0 - op;
        let sd = (n as f64 * p * (1.0 - p)).sqrt();
        assert!(
            (through as f64 - n as f64 * p).abs() < 4.0 * sd,
            "{}: {through} of {n} through, expected {}",
            m.name,
            n as f64 * p
        );
        // The lobes a mask lets light meet are scaled by the opacity.
        let opaque = Material {
            opacity: None,
            ..m.clone()
        };
        let wi = Vec3::new(-0.3, 0.2, 0.9).normalize();
        let (f, pdf) = bsdf.eval_pdf(wi);
        let (f1, pdf1) = Bsdf::new(&opaque, Rgb::ONE, Vec3::Z, Vec3::Z, wo()).eval_pdf(wi);
        assert!((f - f1 * op as f32).abs().max_element() <= 1e-6 * f1.max_element());
        assert!((pdf - pdf1 * op as f32).abs() <= 1e-6 * pdf1);
    }
}
