//! The same scene at other scales and far from the origin must render the same image.
//!
//! Ray offsets have no scene-scale epsilon (`rt_core::ray::offset_ray_origin` scales with the
//! triangles), so the Cornell box scaled by 10⁻⁴ or 10⁴, or scaled by 100 and moved 10⁵ units
//! away, renders the original image within noise: no acne (self-shadowing darkens), no light
//! leaking through the corners (brightens), no missing contact shadows. Each transformed
//! render (one seed) is compared with an untransformed one (another seed) by
//! [`super::compare::compare`]. The control case injects acne on purpose and must be caught.

use super::{compare, render_film, Budget, Case, Check, Outcome};
use crate::LoadError;
use rt_core::{glam::Vec3, Aabb, Accel, Camera, Hit, Ray, Scene, TraversalCounters};
use rt_integrators::PathIntegrator;

/// The Cornell box of `scenes/cornell-box.toml` with a `resolution²` camera.
pub fn cornell_box(resolution: u32) -> Result<Scene, LoadError> {
    let toml = include_str!("../../../../scenes/cornell-box.toml");
    let loaded = rt_scene::load_str(
        toml,
        std::path::Path::new("."),
        std::path::Path::new("cornell-box.toml"),
    )
    .map_err(|e| LoadError::new("scenes/cornell-box.toml", e))?;
    Ok(transformed(&loaded.scene, 1.0, Vec3::ZERO, resolution))
}

/// `scene` scaled by `s` about the origin, then moved by `t`, camera included, with a
/// `resolution²` camera. Shading normals are unchanged by a uniform scale and a translation.
pub fn transformed(scene: &Scene, s: f32, t: Vec3, resolution: u32) -> Scene {
    let mut out = scene.clone();
    for tri in &mut out.triangles {
        *tri = tri.map(|v| v * s + t);
    }
    let c = &scene.cameras[0];
    out.cameras = vec![Camera::look_at(
        c.name.clone(),
        c.position * s + t,
        (c.position + c.forward) * s + t,
        c.up,
        c.fov_y_deg,
        resolution,
        resolution,
        c.aperture * s,
        c.focus_distance * s,
    )];
    out.build_lights();
    out
}

/// Blocks of this many pixels on a side are compared.
const BLOCK: u32 = 4;
/// Bounces of the path tracer (enough for the box's interreflection to matter).
const DEPTH: u32 = 8;

fn compare_case(b: &Budget, seed: u64, s: f32, t: Vec3) -> Result<Outcome, LoadError> {
    let base = cornell_box(b.resolution)?;
    let integrator = PathIntegrator::new(DEPTH);
    let reference_accel = crate::default_accel(&base);
    let (reference, _) = render_film(
        &base,
        reference_accel.as_ref(),
        &integrator,
        b.spp,
        seed as u32,
    );
    let scene = transformed(&base, s, t, b.resolution);
    let accel = crate::default_accel(&scene);
    // Another seed: the comparison is statistical, not bitwise.
    let (film, stats) = render_film(&scene, accel.as_ref(), &integrator, b.spp, seed as u32 + 1);
    Ok(comparison_outcome(&reference, &film, stats.discarded))
}

fn comparison_outcome(reference: &rt_film::Film, film: &rt_film::Film, discarded: u64) -> Outcome {
    let c = compare::compare(reference, film, BLOCK, compare::ALPHA);
    Outcome {
        checks: vec![
            Check::at_most(
                format!("max|z| of {} blocks", c.block_tests),
                c.max_block_z,
                c.block_crit,
            ),
            Check::at_most("|image z|", c.image_z.abs(), c.image_crit),
            Check::at_most("invalid values", super::invalid_values(film) as f64, 0.0),
        ],
        discarded: Some(discarded),
        skipped: None,
    }
}

/// An `Accel` that sabotages a fraction of the rays: their origin is pulled back along the
/// ray by `depth`, so a ray leaving a surface starts behind it and hits it again, as with an
/// offset that is too small. Camera rays are pulled back too, which changes nothing visible.
struct Acne<'a> {
    inner: &'a dyn Accel,
    fraction: f64,
    depth: f32,
}

impl Acne<'_> {
    /// The pulled-back ray and how much longer its parameter range must be, or `None` if this
    /// ray is left alone. Chosen by a hash of the ray, so renders stay deterministic.
    fn sabotage(&self, ray: &Ray) -> Option<(Ray, f32)> {
        if ray_uniform(ray) >= self.fraction {
            return None;
        }
        let len = ray.dir.length();
        let dt = self.depth / len;
        Some((Ray::new(ray.origin - ray.dir * dt, ray.dir), dt))
    }
}

/// A uniform number in [0, 1) that is a hash of the ray's bits: lets a sabotaged structure pick
/// a fraction of the rays deterministically (the same rays for any thread count).
pub fn ray_uniform(ray: &Ray) -> f64 {
    let mut h = 0xcbf2_9ce4_8422_2325u64;
    for x in ray.origin.to_array().into_iter().chain(ray.dir.to_array()) {
        h = (h ^ x.to_bits() as u64).wrapping_mul(0x0100_0000_01b3);
    }
    let h = (h ^ (h >> 29)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
    (h >> 11) as f64 / (1u64 << 53) as f64
}

impl Accel for Acne<'_> {
    fn name(&self) -> &str {
        "acne"
    }

    fn closest_hit(
        &self,
        ray: &Ray,
        t_max: f32,
        counters: Option<&mut TraversalCounters>,
    ) -> Option<Hit> {
        match self.sabotage(ray) {
            Some((r, dt)) => self
                .inner
                .closest_hit(&r, t_max + dt, counters)
                .map(|mut h| {
                    h.t = (h.t - dt).max(f32::MIN_POSITIVE);
                    h
                }),
            None => self.inner.closest_hit(ray, t_max, counters),
        }
    }

    fn any_hit(
        &self,
        ray: &Ray,
        t_max: f32,
        _toward: Option<Vec3>,
        counters: Option<&mut TraversalCounters>,
    ) -> bool {
        match self.sabotage(ray) {
            Some((r, dt)) => self.inner.any_hit(&r, t_max + dt, None, counters),
            None => self.inner.any_hit(ray, t_max, None, counters),
        }
    }

    fn bounds(&self) -> Aabb {
        self.inner.bounds()
    }

    fn memory_bytes(&self) -> usize {
        self.inner.memory_bytes()
    }
}

/// Fraction of rays the control case sabotages: the order of the false hits the QBVH reported
/// on `gen:mixed` before the offset fix (9.7 % of bounce rays), halved.
pub const CONTROL_FRACTION: f64 = 0.05;

fn control_case(b: &Budget, seed: u64) -> Result<Outcome, LoadError> {
    let base = cornell_box(b.resolution)?;
    let integrator = PathIntegrator::new(DEPTH);
    let accel = crate::default_accel(&base);
    let (reference, _) = render_film(&base, accel.as_ref(), &integrator, b.spp, seed as u32);
    let extent = Aabb::from_points(base.triangles.iter().flatten()).extent();
    let acne = Acne {
        inner: accel.as_ref(),
        fraction: CONTROL_FRACTION,
        depth: 1e-3 * extent.max_element(),
    };
    let (film, stats) = render_film(&base, &acne, &integrator, b.spp, seed as u32 + 1);
    let c = compare::compare(&reference, &film, BLOCK, compare::ALPHA);
    Ok(Outcome {
        checks: vec![Check::at_least(
            format!(
                "acne on {:.0} % of rays: max|z|/tol (blocks {:.2}/{:.2}, image {:.2}/{:.2})",
                CONTROL_FRACTION * 100.0,
                c.max_block_z,
                c.block_crit,
                c.image_z,
                c.image_crit
            ),
            c.detection(),
            1.0,
        )],
        discarded: Some(stats.discarded),
        skipped: None,
    })
}

/// The transformation cases: scale, scale and move, and the control.
pub fn cases() -> Vec<Case> {
    // The direction of the move is arbitrary but not along an axis, so every coordinate is
    // large; its length is the distance from the origin the issue asks for.
    fn far(d: f32) -> Vec3 {
        Vec3::new(0.6, 0.48, -0.64) * d
    }
    vec![
        Case {
            name: "transform/scale-1e-4",
            run: |b, seed| compare_case(b, seed, 1e-4, Vec3::ZERO),
        },
        Case {
            name: "transform/scale-1e4",
            run: |b, seed| compare_case(b, seed, 1e4, Vec3::ZERO),
        },
        Case {
            name: "transform/scale-100-moved-1e5",
            run: |b, seed| compare_case(b, seed, 100.0, far(1e5)),
        },
        Case {
            name: "transform/scale-1e-6",
            run: |b, seed| extreme(b, seed, 1e-6, Vec3::ZERO),
        },
        Case {
            name: "transform/scale-1e6",
            run: |b, seed| extreme(b, seed, 1e6, Vec3::ZERO),
        },
        Case {
            name: "transform/scale-1e3-moved-1e7",
            run: |b, seed| extreme(b, seed, 1e3, far(1e7)),
        },
        Case {
            name: "transform/control-acne",
            run: control_case,
        },
    ]
}

/// The extreme transformations run only with [`Budget::extreme`].
fn extreme(b: &Budget, seed: u64, s: f32, t: Vec3) -> Result<Outcome, LoadError> {
    if !b.extreme {
        return Ok(Outcome {
            skipped: Some("long run only".into()),
            ..Outcome::default()
        });
    }
    compare_case(b, seed, s, t)
}
