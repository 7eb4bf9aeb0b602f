//! Light sampling: emissive triangles and delta lights ([`crate::delta_light`]) chosen in
//! proportion to their power (thesis §2.3.5), and the environment.

use crate::delta_light::DeltaLight;
use crate::stage_time::StageTime;
use crate::{
    color::luminance, distribution::Distribution1D, sampling::power_heuristic,
    sampling::uniform_triangle, triangle, Aabb, Rgb, Scene,
};
use glam::{Vec2, Vec3};
use std::time::{Duration, Instant};

/// Chooses lights for next-event estimation. Without emissive triangles or delta lights it
/// holds no emitter table and no power distribution (nothing is allocated); it may still
/// sample the environment.
#[derive(Clone, Debug, Default)]
pub struct LightSampler {
    /// What sampling needs of each emissive triangle, so that a sample reads one record instead
    /// of the triangle, its material and a normal recomputed every time.
    pub(crate) records: Vec<Emitter>,
    /// The triangle index of each record, ascending: how a triangle found by a ray finds its
    /// record's probability in `dist`.
    prims: Vec<u32>,
    /// The scene's delta lights; in the power distribution they follow the triangles.
    pub(crate) deltas: Vec<DeltaLight>,
    pub(crate) dist: Option<Distribution1D>,
    total_power: f32,
    pub(crate) env_prob: f32,
    /// How long [`LightSampler::build`] took, for `render --stats` (it runs while a scene
    /// loads, where the caller cannot time it on its own).
    build_time: StageTime,
}

/// A point (or direction) on a light, as seen from a shading point.
#[derive(Clone, Copy, Debug)]
pub struct LightSample {
    /// Unit direction from the shading point to the light.
    pub wi: Vec3,
    /// Point on the light (for triangles) — the shadow ray's target.
    pub point: Vec3,
    /// Error bound of `point` ([`triangle::point_with_error`]; zero for the environment): the
    /// shadow ray's target is offset off the light by it.
    pub point_error: Vec3,
    /// Unit front normal of the light triangle (zero for the environment).
    pub normal: Vec3,
    /// Distance to the light point (`f32::INFINITY` for the environment).
    pub dist: f32,
    /// Radiance arriving from the light along `-wi`.
    pub le: Rgb,
    /// Solid-angle pdf of `wi`, including the probability of choosing this light.
    pub pdf: f32,
    /// The triangle emits from both faces (false for the environment).
    pub two_sided: bool,
    /// The light is a delta light: `pdf` is only the probability of choosing it, `le` what
    /// multiplies `f·|cos|` (`I/r²`, `E`), and BSDF sampling cannot find it.
    pub delta: bool,
}

impl LightSample {
    /// The MIS weight of this light-sampled contribution against BSDF sampling of the same
    /// direction with pdf `bsdf_pdf`: the power heuristic, or 1 for a delta light (BSDF
    /// sampling never finds one; `power_heuristic(p, 0)` is 1, so the arithmetic is shared).
    #[inline]
    pub fn mis_weight(&self, bsdf_pdf: f32) -> f32 {
        power_heuristic(self.pdf, if self.delta { 0.0 } else { bsdf_pdf })
    }
}

/// What [`LightSampler::choose`] picked besides the environment.
pub(crate) enum Chosen<'a> {
    Triangle(&'a Emitter),
    Delta(&'a DeltaLight),
}

/// An emissive triangle as light sampling uses it: a copy of what sampling reads, next to each
/// other in memory.
#[derive(Clone, Copy, Debug)]
pub struct Emitter {
    /// The triangle's corners.
    pub vertices: [Vec3; 3],
    /// Unit front normal.
    pub normal: Vec3,
    /// Area.
    pub area: f32,
    /// Emitted radiance.
    pub emission: Rgb,
    /// Emits from both faces.
    pub two_sided: bool,
}

impl Emitter {
    fn new(scene: &Scene, prim: u32) -> Self {
        let v = scene.triangles[prim as usize];
        let n_raw = triangle::geometric_normal(&v);
        let area = 0.5 * n_raw.length();
        let m = scene.material_of(prim);
        Self {
            vertices: v,
            normal: n_raw / (2.0 * area),
            area,
            emission: m.emission,
            two_sided: m.two_sided,
        }
    }
}

fn triangle_power(scene: &Scene, prim: u32) -> f32 {
    let m = scene.material_of(prim);
    triangle::area(&scene.triangles[prim as usize]) * luminance(m.emission) * m.emitting_faces()
}

/// The scene's delta lights that emit something (a black one is never chosen).
fn delta_lights(scene: &Scene) -> Vec<DeltaLight> {
    scene
        .delta_lights
        .iter()
        .filter(|l| l.emits())
        .copied()
        .collect()
}

/// The box of the scene's triangles (what a directional light's power is measured over).
fn scene_bounds(scene: &Scene) -> Aabb {
    Aabb::from_points(scene.triangles.iter().flatten())
}

/// True if triangle `prim` is one the sampler samples: emissive with positive power.
pub(crate) fn is_emitter(scene: &Scene, prim: u32) -> bool {
    scene.material_of(prim).is_emissive() && triangle_power(scene, prim) > 0.0
}

impl LightSampler {
    /// A sampler with nothing to sample, for integrators that do not sample lights.
    pub const NONE: LightSampler = LightSampler {
        records: Vec::new(),
        prims: Vec::new(),
        deltas: Vec::new(),
        dist: None,
        total_power: 0.0,
        env_prob: 0.0,
        build_time: StageTime(Duration::ZERO),
    };

    /// Collects the emissive triangles and delta lights of `scene` and weighs them by power.
    pub fn build(scene: &Scene) -> Self {
        let start = Instant::now();
        let emitters: Vec<u32> = (0..scene.triangles.len() as u32)
            .filter(|&i| is_emitter(scene, i))
            .collect();
        let mut powers: Vec<f32> = emitters.iter().map(|&i| triangle_power(scene, i)).collect();
        let deltas = delta_lights(scene);
        let bounds = if deltas
            .iter()
            .any(|l| matches!(l, DeltaLight::Directional { .. }))
        {
            scene_bounds(scene)
        } else {
            Aabb::default()
        };
        powers.extend(deltas.iter().map(|l| l.power_over_pi(&bounds)));
        let total_power: f32 = powers.iter().map(|&p| p as f64).sum::<f64>() as f32;
        let has_tris = total_power > 0.0;
        let has_env = !scene.environment.is_black();
        // Without a cheap estimate of how much of the environment a point sees, split evenly.
        let env_prob = match (has_tris, has_env) {
            (true, true) => 0.5,
            (false, true) => 1.0,
            _ => 0.0,
        };
        Self {
            dist: has_tris.then(|| Distribution1D::new(&powers)),
            records: emitters.iter().map(|&i| Emitter::new(scene, i)).collect(),
            prims: emitters,
            deltas,
            total_power,
            env_prob,
            build_time: StageTime(start.elapsed()),
        }
    }

    /// Bytes of the emitter table and power distribution (zero without emissive triangles).
    pub fn memory_bytes(&self) -> usize {
        std::mem::size_of_val(self.records.as_slice())
            + std::mem::size_of_val(self.deltas.as_slice())
            + self.dist.as_ref().map_or(0, Distribution1D::memory_bytes)
    }

    /// How long building took (the scan for emitters included).
    pub fn build_time(&self) -> Duration {
        self.build_time.0
    }

    /// True if there is anything to sample.
    pub fn is_empty(&self) -> bool {
        self.dist.is_none() && self.env_prob == 0.0
    }

    /// Number of emissive triangles.
    pub fn emitter_count(&self) -> usize {
        self.records.len()
    }

    /// Number of delta lights that emit (and so may be chosen).
    pub fn delta_count(&self) -> usize {
        self.deltas.len()
    }

    /// Picks a triangle or delta light by power for `u_sel` in `[env_prob, 1)`, with the
    /// probability of the pick (the choice over the environment included). `None` without
    /// any.
    #[inline]
    pub(crate) fn choose(&self, u_sel: f32) -> Option<(Chosen<'_>, f32)> {
        let dist = self.dist.as_ref()?;
        let u_tri = ((u_sel - self.env_prob) / (1.0 - self.env_prob)).clamp(0.0, 0.999_999_94);
        let (k, pmf, _) = dist.sample_discrete(u_tri);
        let chosen = match self.records.get(k) {
            Some(e) => Chosen::Triangle(e),
            None => Chosen::Delta(&self.deltas[k - self.records.len()]),
        };
        Some((chosen, pmf * (1.0 - self.env_prob)))
    }

    /// The delta light [`LightSampler::sample`] picks for `u_sel`, if it picks one.
    pub fn chosen_delta(&self, u_sel: f32) -> Option<&DeltaLight> {
        if u_sel < self.env_prob {
            return None;
        }
        match self.choose(u_sel)? {
            (Chosen::Delta(light), _) => Some(light),
            _ => None,
        }
    }

    /// Samples a light as seen from `x`. `None` if the chosen point cannot contribute (back face
    /// of a one-sided emitter, grazing angle, zero pdf).
    pub fn sample(&self, scene: &Scene, x: Vec3, u_sel: f32, u: Vec2) -> Option<LightSample> {
        if u_sel < self.env_prob {
            let s = scene.environment.sample(u)?;
            return Some(LightSample {
                wi: s.dir,
                point: Vec3::ZERO,
                point_error: Vec3::ZERO,
                normal: Vec3::ZERO,
                dist: f32::INFINITY,
                le: s.radiance,
                pdf: s.pdf * self.env_prob,
                two_sided: false,
                delta: false,
            });
        }
        let (e, p_choice) = match self.choose(u_sel)? {
            (Chosen::Triangle(e), p_choice) => (e, p_choice),
            (Chosen::Delta(light), p_choice) => {
                let inc = light.incident(x)?;
                return Some(LightSample {
                    wi: inc.wi,
                    point: inc.point,
                    point_error: Vec3::ZERO,
                    normal: Vec3::ZERO,
                    dist: inc.dist,
                    le: inc.le,
                    pdf: p_choice,
                    two_sided: false,
                    delta: true,
                });
            }
        };
        let (b1, b2) = uniform_triangle(u);
        let (p, point_error) = triangle::point_with_error(&e.vertices, b1, b2);
        let (n, area) = (e.normal, e.area);
        let d = p - x;
        let dist2 = d.length_squared();
        if dist2 <= 0.0 || !dist2.is_finite() {
            return None;
        }
        let r = dist2.sqrt();
        let wi = d / r;
        // `Material::emitted` for the front normal `n` and the outgoing direction `-wi`.
        let front = n.dot(-wi) > 0.0;
        let le = if e.two_sided || front {
            e.emission
        } else {
            Rgb::ZERO
        };
        let cos_l = n.dot(wi).abs();
        if cos_l <= 0.0 || le.max_element() <= 0.0 {
            return None;
        }
        let pdf = p_choice * dist2 / (area * cos_l);
        Some(LightSample {
            wi,
            point: p,
            point_error,
            normal: n,
            dist: r,
            le,
            pdf,
            two_sided: e.two_sided,
            delta: false,
        })
    }

    /// Solid-angle pdf with which [`LightSampler::sample`] picks point `p` on emissive triangle
    /// `prim` from `x`; `ng` is the triangle's unit normal.
    pub fn pdf_triangle(&self, scene: &Scene, prim: u32, x: Vec3, p: Vec3, ng: Vec3) -> f32 {
        if self.total_power <= 0.0 {
            return 0.0;
        }
        let d = p - x;
        let dist2 = d.length_squared();
        let cos_l = ng.dot(d).abs() / dist2.sqrt();
        // NaN (x = p, hence 0/0) gives 0 too: a NaN pdf would make the MIS
        // weight, and so the sample, NaN.
        let area = triangle::area(&scene.triangles[prim as usize]);
        if area <= 0.0 || cos_l.is_nan() || cos_l <= 0.0 {
            return 0.0;
        }
        self.choice_probability(prim) * dist2 / (area * cos_l)
    }

    /// The probability with which [`LightSampler::choose`] picks triangle `prim` (the choice
    /// over the environment included); zero for a triangle it never picks.
    ///
    /// Read from the power table's cumulative sums, the very numbers `choose` compares `u`
    /// with, not recomputed as `power / total`: the two differ where a triangle's share is
    /// below the cumulative sums' f32 resolution (2⁻²⁴ near 1). A 10⁻⁴-wide lamp of
    /// [`crate::material::MAX_RADIANCE`] next to big ones has a share of 9·10⁻⁹; its two
    /// triangles got 0 and 6·10⁻⁸ in the table, so MIS weighed the one never sampled as if it
    /// were and the path tracer lost a fifth of the image (`bad/emitters-zero-and-max`).
    #[inline]
    fn choice_probability(&self, prim: u32) -> f32 {
        let (Some(dist), Ok(k)) = (self.dist.as_ref(), self.prims.binary_search(&prim)) else {
            return 0.0;
        };
        dist.discrete_pmf(k) * (1.0 - self.env_prob)
    }

    /// Area pdf of a point on emissive triangle `prim` as [`LightSampler::sample`] and
    /// [`LightSampler::sample_emitter_point`] choose it (triangle by power, point uniform, the
    /// choice of the triangles over the environment included); zero for a triangle that does
    /// not emit.
    pub fn pdf_emitter_area(&self, scene: &Scene, prim: u32) -> f32 {
        if self.total_power <= 0.0 {
            return 0.0;
        }
        let area = triangle::area(&scene.triangles[prim as usize]);
        if area.is_nan() || area <= 0.0 {
            return 0.0;
        }
        self.choice_probability(prim) / area
    }

    /// Solid-angle pdf of sampling environment direction `d`.
    pub fn pdf_env(&self, scene: &Scene, d: Vec3) -> f32 {
        if self.env_prob == 0.0 {
            return 0.0;
        }
        self.env_prob * scene.environment.pdf(d)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::Material;

    #[test]
    fn pdf_of_a_light_point_seen_from_itself_is_zero_not_nan() {
        let mut scene = Scene::empty();
        let mut lamp = Material::diffuse("lamp", Rgb::ZERO);
        lamp.emission = Rgb::ONE;
        scene.materials.push(lamp);
        scene.push_triangle([Vec3::ZERO, Vec3::X, Vec3::Z], 0);
        scene.build_lights();
        let p = Vec3::new(0.25, 0.0, 0.25);
        let pdf = scene.lights().pdf_triangle(&scene, 0, p, p, Vec3::Y);
        assert_eq!(pdf, 0.0);
        let pdf = scene
            .lights()
            .pdf_triangle(&scene, 0, p + Vec3::Y, p, Vec3::Y);
        assert!(pdf > 0.0 && pdf.is_finite());
    }

    /// The emitters of `bad/emitters-zero-and-max`: two big lamps of the largest radiance and
    /// a 10⁻⁴-wide one, whose triangles' shares (9·10⁻⁹) are below the f32 resolution of the
    /// power table's cumulative sums. Every triangle's reported choice probability must be
    /// the fraction of all f32 `u` on the 2⁻²⁴ lattice (every `u` a sampler gives in
    /// [0.5, 1), a superset elsewhere) with which `choose` picks it; with the probability
    /// recomputed as `power / total`, the tiny lamp's triangles reported 9·10⁻⁹ and were
    /// picked with 0 and 6·10⁻⁸.
    #[test]
    fn reported_choice_probabilities_are_the_sampled_ones_for_a_tiny_bright_lamp() {
        let mut scene = Scene::empty();
        let mut lamp = Material::diffuse("lamp", Rgb::ZERO);
        lamp.emission = Rgb::splat(crate::material::MAX_RADIANCE);
        scene.materials.push(lamp.clone());
        lamp.two_sided = true;
        scene.materials.push(lamp);
        let quad = |s: &mut Scene, o: Vec3, a: Vec3, b: Vec3, m: u32| {
            s.push_triangle([o, o + a, o + a + b], m);
            s.push_triangle([o, o + a + b, o + b], m);
        };
        quad(&mut scene, Vec3::new(-0.5, 2.0, -0.5), Vec3::Z, Vec3::X, 0);
        quad(
            &mut scene,
            Vec3::splat(0.5),
            Vec3::X * 1e-4,
            Vec3::Y * 1e-4,
            1,
        );
        quad(&mut scene, Vec3::ZERO, Vec3::Y * 0.3, Vec3::X * 0.3, 0);
        scene.build_lights();
        let lights = scene.lights();
        assert_eq!(lights.emitter_count(), 6);
        let mut picks = [0u64; 6];
        const N: u32 = 1 << 24;
        for i in 0..N {
            let u = i as f32 / N as f32;
            let Some((Chosen::Triangle(e), _)) = lights.choose(u) else {
                panic!("u = {u} chose no triangle");
            };
            let k = lights
                .records
                .iter()
                .position(|r| std::ptr::eq(r, e))
                .expect("a record");
            picks[k] += 1;
        }
        for (k, &n) in picks.iter().enumerate() {
            let prim = k as u32;
            let reported =
                lights.pdf_emitter_area(&scene, prim) * triangle::area(&scene.triangles[k]);
            let sampled = n as f32 / N as f32;
            assert!(
                (reported - sampled).abs() <= 1e-6 * sampled.max(1e-9),
                "triangle {k}: reported {reported:e}, picked with {sampled:e}"
            );
        }
    }
}
