//! Warping functions from the unit square to the shapes a renderer samples, with their pdfs.

use glam::{Vec2, Vec3};
use std::f32::consts::{FRAC_1_PI, FRAC_PI_2, FRAC_PI_4, PI};

/// Concentric map of the unit square onto the unit disk (Shirley–Chiu): low distortion, so
/// stratification survives.
#[inline]
pub fn concentric_disk(u: Vec2) -> Vec2 {
    let o = 2.0 * u - Vec2::ONE;
    if o.x == 0.0 && o.y == 0.0 {
        return Vec2::ZERO;
    }
    let (r, theta) = if o.x.abs() > o.y.abs() {
        (o.x, FRAC_PI_4 * (o.y / o.x))
    } else {
        (o.y, FRAC_PI_2 - FRAC_PI_4 * (o.x / o.y))
    };
    r * Vec2::new(theta.cos(), theta.sin())
}

/// Cosine-weighted direction on the +z hemisphere (Malley's method).
#[inline]
pub fn cosine_hemisphere(u: Vec2) -> Vec3 {
    let d = concentric_disk(u);
    let z = (1.0 - d.length_squared()).max(0.0).sqrt();
    Vec3::new(d.x, d.y, z)
}

/// Pdf (solid angle) of [`cosine_hemisphere`].
#[inline]
pub fn cosine_hemisphere_pdf(cos_theta: f32) -> f32 {
    cos_theta.max(0.0) * FRAC_1_PI
}

/// Uniform direction on the sphere.
#[inline]
pub fn uniform_sphere(u: Vec2) -> Vec3 {
    let z = 1.0 - 2.0 * u.x;
    let r = (1.0 - z * z).max(0.0).sqrt();
    let phi = 2.0 * PI * u.y;
    Vec3::new(r * phi.cos(), r * phi.sin(), z)
}

/// Pdf of [`uniform_sphere`].
pub const UNIFORM_SPHERE_PDF: f32 = 1.0 / (4.0 * PI);

/// Uniform barycentrics `(b1, b2)` on a triangle. Uses Heitz's low-distortion square-to-triangle
/// map ("A Low-Distortion Map Between Triangle and Square", 2019) so stratification survives.
#[inline]
pub fn uniform_triangle(u: Vec2) -> (f32, f32) {
    let (b0, b1);
    if u.x < u.y {
        b0 = u.x / 2.0;
        b1 = u.y - b0;
    } else {
        b1 = u.y / 2.0;
        b0 = u.x - b1;
    }
    // (b0, b1) are the weights of vertices 0 and 1; return those of vertices 1 and 2.
    (b1, 1.0 - b0 - b1)
}

/// Power heuristic (β = 2) weight of a technique with pdf `f` (one sample) against one with pdf `g`.
#[inline]
pub fn power_heuristic(f: f32, g: f32) -> f32 {
    let (f2, g2) = (f * f, g * g);
    if f2.is_infinite() {
        return 1.0;
    }
    if f2 + g2 == 0.0 {
        return 0.0;
    }
    f2 / (f2 + g2)
}

/// Direction of a microfacet normal with pdf ∝ cos^k θ around +z (normalised Blinn–Phong).
#[inline]
pub fn blinn_phong_half(u: Vec2, k: f32) -> Vec3 {
    let cos_t = u.x.powf(1.0 / (k + 1.0));
    let sin_t = (1.0 - cos_t * cos_t).max(0.0).sqrt();
    let phi = 2.0 * PI * u.y;
    Vec3::new(sin_t * phi.cos(), sin_t * phi.sin(), cos_t)
}

/// Solid-angle pdf of [`blinn_phong_half`] for a half vector with `cos θh`.
#[inline]
pub fn blinn_phong_half_pdf(cos_h: f32, k: f32) -> f32 {
    if cos_h <= 0.0 {
        return 0.0;
    }
    (k + 1.0) * 0.5 * FRAC_1_PI * cos_h.powf(k)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn warps_land_on_their_domains() {
        for i in 0..32 {
            for j in 0..32 {
                let u = Vec2::new((i as f32 + 0.5) / 32.0, (j as f32 + 0.5) / 32.0);
                assert!(concentric_disk(u).length() <= 1.0 + 1e-6);
                let d = cosine_hemisphere(u);
                assert!((d.length() - 1.0).abs() < 1e-5 && d.z >= 0.0);
                assert!((uniform_sphere(u).length() - 1.0).abs() < 1e-5);
                let (b1, b2) = uniform_triangle(u);
                assert!(b1 >= 0.0 && b2 >= 0.0 && b1 + b2 <= 1.0 + 1e-6);
                let h = blinn_phong_half(u, 50.0);
                assert!((h.length() - 1.0).abs() < 1e-5 && h.z >= 0.0);
            }
        }
    }

    #[test]
    fn blinn_phong_pdf_integrates_to_one() {
        for k in [1.0f32, 10.0, 500.0] {
            // ∫ pdf dω over the hemisphere, midpoint rule in θ.
            let n = 20000;
            let mut sum = 0.0f64;
            for i in 0..n {
                let t = (i as f64 + 0.5) / n as f64 * std::f64::consts::FRAC_PI_2;
                let p = blinn_phong_half_pdf(t.cos() as f32, k) as f64;
                sum += p * t.sin() * 2.0 * std::f64::consts::PI * std::f64::consts::FRAC_PI_2
                    / n as f64;
            }
            assert!((sum - 1.0).abs() < 1e-3, "k={k}: {sum}");
        }
    }
}
