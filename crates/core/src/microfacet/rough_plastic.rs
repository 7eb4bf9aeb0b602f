//! Mitsuba's `roughplastic`: a diffuse base under a rough dielectric coating. The coating
//! reflects as a microfacet dielectric interface (`F·D·G / 4 cos θo cos θi`); the base's
//! diffuse light is scaled by the coating's transmittance on the way in and out, and by the
//! series of internal reflections between base and coating, as in Mitsuba 3's plugin
//! (Weidlich and Wilkie 2007's layered model with a rough interface). One-sided, isotropic.
//!
//! The transmittance `T(cos θ)` of the rough interface and its internal diffuse reflectance are
//! tabulated at construction, as Mitsuba does ([`TRANSMITTANCE_RES`] cosines `max(1e-6, i/63)`,
//! looked up linearly; the internal reflectance is Mitsuba's `2·mean(R(μ)·μ)` over the same
//! cosines). Deviation: Mitsuba integrates with Gauss–Legendre quadrature over visible normals,
//! we over our own sampling of normals ([`QUADRATURE`]² points): both converge to the same
//! integrals (they agree to about 1e-4).
//!
//! A textured `alpha` (which Mitsuba 3 refuses) uses tables computed at [`ALPHA_NODES`]
//! roughnesses spanning the texture's range ([`AlphaTables`]); between two of them the tables
//! are interpolated linearly in α, so a texel's value that is a node (a checkerboard's two,
//! the range's ends) gets exactly the tables of the constant α.

use super::{reflect, Distribution, LocalBsdf, LocalSample};
use crate::material::{fresnel_dielectric, refract};
use crate::sampling::cosine_hemisphere;
use crate::Rgb;
use glam::{Vec2, Vec3};
use std::f32::consts::FRAC_1_PI;

/// Cosines at which the coating's transmittance is tabulated (Mitsuba's
/// `MI_ROUGH_TRANSMITTANCE_RES`).
pub const TRANSMITTANCE_RES: usize = 64;
/// Quadrature points per dimension of the tables' integrals.
pub const QUADRATURE: usize = 48;

/// Rough plastic.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RoughPlastic {
    /// The coating's normals (isotropic).
    pub distribution: Distribution,
    /// The base's albedo (Mitsuba's `diffuse_reflectance`, default 0.5).
    pub diffuse: Rgb,
    /// A factor on the coating's reflection (Mitsuba's `specular_reflectance`, default 1).
    pub specular: Rgb,
    /// Interior over exterior index of refraction of the coating.
    pub eta: f32,
    /// Account for the colour shift of repeated internal scattering (Mitsuba's `nonlinear`).
    pub nonlinear: bool,
    /// Reflect alike from below, mirrored (Mitsuba's `twosided`; false from
    /// [`RoughPlastic::new`]); applied by [`super::Microfacet`], which mirrors both directions to
    /// the front.
    pub two_sided: bool,
    /// The coating's transmittance at cosine `max(1e-6, i / (RES − 1))`.
    transmittance: [f32; TRANSMITTANCE_RES],
    /// The coating's diffuse reflectance from inside.
    internal_reflectance: f32,
}

impl RoughPlastic {
    /// Rough plastic with its tables computed.
    pub fn new(
        distribution: Distribution,
        diffuse: Rgb,
        specular: Rgb,
        eta: f32,
        nonlinear: bool,
    ) -> Self {
        let mut transmittance = [0.0; TRANSMITTANCE_RES];
        let mut internal = 0.0f64;
        for (i, t) in transmittance.iter_mut().enumerate() {
            let mu = (i as f32 / (TRANSMITTANCE_RES - 1) as f32).max(1e-6);
            let wi = Vec3::new((1.0 - mu * mu).sqrt(), 0.0, mu);
            *t = interface(&distribution, wi, eta).1;
            internal += (interface(&distribution, wi, 1.0 / eta).0 * mu) as f64;
        }
        Self {
            distribution,
            diffuse,
            specular,
            eta,
            nonlinear,
            two_sided: false,
            transmittance,
            internal_reflectance: (internal * 2.0 / TRANSMITTANCE_RES as f64) as f32,
        }
    }

    /// The coating's transmittance for a direction at cosine `cos` (Mitsuba's `lerp_gather`).
    pub fn transmittance(&self, cos: f32) -> f32 {
        let x = cos.clamp(0.0, 1.0) * (TRANSMITTANCE_RES - 1) as f32;
        let i = (x as usize).min(TRANSMITTANCE_RES - 2);
        let f = x - i as f32;
        self.transmittance[i] * (1.0 - f) + self.transmittance[i + 1] * f
    }

    /// The coating's diffuse reflectance from inside.
    pub fn internal_reflectance(&self) -> f32 {
        self.internal_reflectance
    }

    fn mean(c: Rgb) -> f32 {
        (c.x + c.y + c.z) / 3.0
    }

    /// The probability of sampling the coating's reflection for `wo` (Mitsuba's split by
    /// transmittance and the lobes' mean albedos).
    fn specular_probability(&self, t_o: f32) -> f32 {
        let (s, d) = (Self::mean(self.specular), Self::mean(self.diffuse));
        let w = s / (s + d);
        let ps = (1.0 - t_o) * w;
        let pd = t_o * (1.0 - w);
        if ps + pd > 0.0 {
            ps / (ps + pd)
        } else {
            1.0
        }
    }
}

/// Roughnesses at which [`AlphaTables`] tabulates the coating: interpolating between them is
/// within 2e-3 of the tables computed at the roughness itself over α ∈ [0.01, 1] (1.1e-3 for
/// GGX and 6e-4 for Beckmann, worst at grazing cosines; 16 nodes gave 4.9e-3), as
/// `interpolated_tables_are_close_to_exact_ones` checks. Computing them costs about 0.3 s per
/// material when the scene loads.
pub const ALPHA_NODES: usize = 32;

/// Rough plastic's tables at roughnesses spanning the range of a textured `alpha`.
#[derive(Clone, Debug, PartialEq)]
pub struct AlphaTables {
    /// Ascending roughnesses, at least one.
    alphas: Vec<f32>,
    /// The coating's tables at each of them.
    tables: Vec<RoughPlastic>,
}

impl AlphaTables {
    /// The tables of `p` (its other parameters) at [`ALPHA_NODES`] roughnesses evenly spread
    /// over `[lo, hi]`, evenly in `√α` (one when they are equal).
    pub fn new(p: &RoughPlastic, lo: f32, hi: f32) -> Self {
        let (lo, hi) = (lo.max(super::MIN_ALPHA), hi.max(super::MIN_ALPHA));
        let (lo, hi) = (lo.min(hi), lo.max(hi));
        let n = if lo == hi { 1 } else { ALPHA_NODES };
        // Even in √α: the tables change fastest at low roughness.
        let (s0, s1) = (lo.sqrt(), hi.sqrt());
        let alphas: Vec<f32> = (0..n)
            .map(|i| match i {
                0 => lo,
                _ if i + 1 == n => hi,
                _ => (s0 + (s1 - s0) * i as f32 / (n - 1) as f32).powi(2),
            })
            .collect();
        let tables = alphas
            .iter()
            .map(|&a| {
                let d = Distribution::new(p.distribution.kind, a, a);
                RoughPlastic::new(d, p.diffuse, p.specular, p.eta, p.nonlinear)
            })
            .collect();
        Self { alphas, tables }
    }

    /// The roughnesses tabulated.
    pub fn alphas(&self) -> &[f32] {
        &self.alphas
    }
}

impl RoughPlastic {
    /// This rough plastic at roughness `alpha` (clamped to the range of `tables`), its
    /// coating's tables interpolated from `tables`.
    pub fn with_alpha(&self, alpha: f32, tables: &AlphaTables) -> RoughPlastic {
        let a = &tables.alphas;
        let alpha = alpha.clamp(a[0], a[a.len() - 1]);
        let i = a
            .partition_point(|&x| x <= alpha)
            .clamp(1, a.len().max(2) - 1)
            - 1;
        let mut out = *self;
        out.distribution = Distribution::new(self.distribution.kind, alpha, alpha);
        let (t0, t1) = match tables.tables.get(i + 1) {
            Some(t1) => (&tables.tables[i], t1),
            None => (&tables.tables[i], &tables.tables[i]),
        };
        let f = if a.len() > 1 {
            ((alpha - a[i]) / (a[i + 1] - a[i])).clamp(0.0, 1.0)
        } else {
            0.0
        };
        if f == 0.0 || f == 1.0 {
            // A node: its own tables, bit for bit.
            let t = if f == 0.0 { t0 } else { t1 };
            out.transmittance = t.transmittance;
            out.internal_reflectance = t.internal_reflectance;
            return out;
        }
        for (o, (x, y)) in out
            .transmittance
            .iter_mut()
            .zip(t0.transmittance.iter().zip(&t1.transmittance))
        {
            *o = x * (1.0 - f) + y * f;
        }
        out.internal_reflectance =
            t0.internal_reflectance * (1.0 - f) + t1.internal_reflectance * f;
        out
    }
}

/// `(R, T)`: the fraction of light arriving along `wi` (upper side, unit) that a rough
/// interface of relative index `eta` reflects, and the fraction it transmits, masking
/// included (Mitsuba's `eval_reflectance` and `eval_transmittance`).
fn interface(d: &Distribution, wi: Vec3, eta: f32) -> (f32, f32) {
    let n = QUADRATURE;
    let (mut r, mut t) = (0.0f64, 0.0f64);
    for a in 0..n {
        for b in 0..n {
            let u = Vec2::new((a as f32 + 0.5) / n as f32, (b as f32 + 0.5) / n as f32);
            let m = d.sample(wi, u);
            let pdf = d.pdf(wi, m);
            let cos_im = wi.dot(m);
            if !(pdf > 0.0 && pdf.is_finite() && cos_im > 0.0) {
                continue;
            }
            // Weight of normal m in the interface's scattering: D·(wi·m)/cos θi over its pdf.
            let w = d.d(m) * cos_im / (wi.z * pdf);
            let f = fresnel_dielectric(cos_im, eta);
            let wr = reflect(wi, m);
            if wr.z > 0.0 {
                r += (f * d.g(wi, wr, m) * w) as f64;
            }
            if f < 1.0 {
                if let Some(wt) = refract(wi, m, eta) {
                    if wt.z < 0.0 {
                        t += ((1.0 - f) * d.g(wi, wt, m) * w) as f64;
                    }
                }
            }
        }
    }
    let cells = (n * n) as f64;
    ((r / cells) as f32, (t / cells) as f32)
}

impl LocalBsdf for RoughPlastic {
    fn eval_pdf(&self, wo: Vec3, wi: Vec3) -> (Rgb, f32) {
        if wo.z <= 0.0 || wi.z <= 0.0 {
            return (Rgb::ZERO, 0.0);
        }
        let d = &self.distribution;
        let (t_o, t_i) = (self.transmittance(wo.z), self.transmittance(wi.z));
        let ps = self.specular_probability(t_o);
        let mut f = Rgb::ZERO;
        let mut pdf = (1.0 - ps) * wi.z * FRAC_1_PI;
        let m = (wo + wi).normalize();
        if m.is_finite() && wo.dot(m) > 0.0 {
            let cos_om = wo.dot(m);
            let fresnel = fresnel_dielectric(cos_om, self.eta);
            f += self.specular * (fresnel * d.d(m) * d.g(wo, wi, m) / (4.0 * wo.z * wi.z));
            pdf += ps * d.pdf(wo, m) / (4.0 * cos_om);
        }
        let denom = if self.nonlinear {
            Rgb::ONE - self.diffuse * self.internal_reflectance
        } else {
            Rgb::splat(1.0 - self.internal_reflectance)
        };
        f += self.diffuse / denom * (FRAC_1_PI * t_o * t_i / (self.eta * self.eta));
        (f, pdf)
    }

    fn sample(&self, wo: Vec3, u_lobe: f32, u: Vec2) -> Option<LocalSample> {
        if wo.z <= 0.0 {
            return None;
        }
        let ps = self.specular_probability(self.transmittance(wo.z));
        let wi = if u_lobe < ps {
            reflect(wo, self.distribution.sample(wo, u))
        } else {
            cosine_hemisphere(u)
        };
        if wi.z <= 0.0 {
            return None;
        }
        self.sample_toward(wo, wi)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::microfacet::DistributionKind;

    #[test]
    fn a_smooth_limit_transmits_what_fresnel_lets_through() {
        // Nearly smooth: T(μ) is 1 − F(μ), and the internal reflectance is the hemispherical
        // Fresnel average from inside (d'Eon and Irving's fit, within its accuracy).
        let d = Distribution::new(DistributionKind::Ggx, 1e-3, 1e-3);
        let p = RoughPlastic::new(d, Rgb::splat(0.5), Rgb::ONE, 1.5, false);
        for cos in [0.2f32, 0.5, 0.9, 1.0] {
            let want = 1.0 - fresnel_dielectric(cos, 1.5);
            assert!(
                (p.transmittance(cos) - want).abs() < 5e-3,
                "{cos}: {} vs {want}",
                p.transmittance(cos)
            );
        }
        let fdr = crate::microfacet::fresnel_diffuse_reflectance(1.0 / 1.5);
        assert!(
            (p.internal_reflectance() - fdr).abs() < 0.02,
            "{} vs {fdr}",
            p.internal_reflectance()
        );
    }

    /// A textured roughness between two nodes gets tables within 2e-3 of the exact ones; at a
    /// node, exactly the constant's. Control: the tables of the range's lower end are
    /// farther than that from the exact ones in the middle.
    #[test]
    fn interpolated_tables_are_close_to_exact_ones() {
        for kind in [DistributionKind::Ggx, DistributionKind::Beckmann] {
            let at = |a: f32| {
                RoughPlastic::new(
                    Distribution::new(kind, a, a),
                    Rgb::splat(0.5),
                    Rgb::ONE,
                    1.5,
                    false,
                )
            };
            let (lo, hi) = (0.01, 1.0);
            let tables = AlphaTables::new(&at(0.3), lo, hi);
            assert_eq!(at(0.3).with_alpha(hi, &tables), at(hi));
            assert_eq!(at(0.3).with_alpha(lo, &tables), at(lo));
            let (mut far, mut worst) = (0.0f32, 0.0f32);
            for k in 0..40 {
                let a = lo + (hi - lo) * (k as f32 + 0.37) / 40.0;
                let (got, want) = (at(0.3).with_alpha(a, &tables), at(a));
                assert_eq!(got.distribution, want.distribution);
                for c in [0.05f32, 0.3, 0.7, 1.0] {
                    let e = (got.transmittance(c) - want.transmittance(c)).abs();
                    worst = worst.max(e);
                    let off = tables.tables[0].transmittance(c) - want.transmittance(c);
                    far = far.max(off.abs());
                }
                let e = (got.internal_reflectance - want.internal_reflectance).abs();
                worst = worst.max(e);
            }
            assert!(worst < 2e-3, "{kind:?}: interpolated tables {worst} off");
            assert!(far > 1e-2, "{kind:?}: the control is too close ({far})");
        }
    }
}
