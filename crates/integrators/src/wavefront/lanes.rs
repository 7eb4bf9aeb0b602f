//! The path state of one batch, the per-bounce random numbers of all its lanes, and the kernel
//! that draws them eight lanes at a time.
//!
//! The draws are the scalar sampler's ([`rt_core::sampler::draw_1d`], [`draw_2d`]): integer
//! hashing only, so the AVX2 kernel gives the same bits as the scalar functions, and a
//! wavefront sample sees exactly the numbers the scalar path tracer's sample sees.
#![allow(unsafe_code)] // the call into the AVX2 kernel, behind runtime detection

use crate::transport::ShadowQuery;
use rt_core::glam::{Vec2, Vec3};
use rt_core::sampler::{draw_1d, draw_2d};
use rt_core::{Hit, Ray, Rgb, SampleKey};
use rt_film::FirstHit;

/// Random numbers one path vertex draws, in the scalar path tracer's order: light choice,
/// light point, layer choice, BSDF direction, roulette (five dimensions).
#[derive(Clone, Copy, Debug, Default)]
pub(crate) struct VertexDraws {
    pub light_sel: f32,
    pub light: Vec2,
    pub layer: f32,
    pub bsdf: Vec2,
    pub rr: f32,
}

/// Dimensions a vertex consumes.
pub(crate) const DIMS_PER_VERTEX: u32 = 5;

/// One path in flight.
#[derive(Clone, Copy, Debug)]
pub(crate) struct PathState {
    /// Pixel and sample index.
    pub x: u32,
    pub y: u32,
    pub index: u32,
    /// The sample's stream and the first dimension after the camera's draws.
    pub key: SampleKey,
    pub dim0: u32,
    pub ray: Ray,
    pub beta: Rgb,
    pub l: Rgb,
    /// MIS state of the previous vertex (as in the scalar path tracer).
    pub prev_delta: bool,
    pub prev_pdf: f32,
    pub prev_p: Vec3,
    pub depth: u32,
    pub lambda: Option<f32>,
    pub first_hit: Option<FirstHit>,
    /// The path ends once its pending shadow ray (if any) is resolved.
    pub done: bool,
}

/// A shadow ray waiting for the stream: the lane it belongs to and the radiance it adds if
/// unoccluded.
#[derive(Clone, Copy, Debug)]
pub(crate) struct PendingShadow {
    pub lane: u32,
    pub contribution: Rgb,
}

/// The shadow rays of one round, as the stream query takes them, and the lanes they serve.
pub(crate) struct ShadowQueue {
    pub rays: Vec<Ray>,
    pub t_max: Vec<f32>,
    /// The light point, or infinity for the environment.
    pub toward: Vec<Vec3>,
    pub occluded: Vec<bool>,
    pub pending: Vec<PendingShadow>,
}

impl ShadowQueue {
    fn new(capacity: usize) -> Self {
        Self {
            rays: Vec::with_capacity(capacity),
            t_max: Vec::with_capacity(capacity),
            toward: Vec::with_capacity(capacity),
            occluded: vec![false; capacity],
            pending: Vec::with_capacity(capacity),
        }
    }

    pub fn clear(&mut self) {
        self.rays.clear();
        self.t_max.clear();
        self.toward.clear();
        self.pending.clear();
    }

    #[inline]
    pub fn push(&mut self, shadow: Option<(ShadowQuery, PendingShadow)>) {
        if let Some((q, pending)) = shadow {
            self.rays.push(q.ray);
            self.t_max.push(q.t_max);
            self.toward.push(q.toward.unwrap_or(Vec3::INFINITY));
            self.pending.push(pending);
        }
    }
}

/// Every buffer of one thread's batch, allocated once.
pub(crate) struct Batch {
    pub capacity: usize,
    pub paths: Vec<PathState>,
    pub rays: Vec<Ray>,
    pub t_max: Vec<f32>,
    pub hits: Vec<Option<Hit>>,
    pub keys: Vec<SampleKey>,
    pub dims: Vec<u32>,
    pub draws: Vec<VertexDraws>,
    pub shadows: ShadowQueue,
    /// This round's plain Lambertian vertices, for the vectorised BSDF stage.
    pub lambert: super::lambert::LambertQueue,
}

impl Batch {
    pub fn new(capacity: usize) -> Self {
        Self {
            capacity,
            paths: Vec::with_capacity(capacity),
            rays: Vec::with_capacity(capacity),
            t_max: vec![f32::INFINITY; capacity],
            hits: vec![None; capacity],
            keys: Vec::with_capacity(capacity),
            dims: Vec::with_capacity(capacity),
            draws: vec![VertexDraws::default(); capacity],
            shadows: ShadowQueue::new(capacity),
            lambert: super::lambert::LambertQueue::new(capacity),
        }
    }
}

/// Fills `out[k]` with the draws of the vertex whose first dimension is `dims[k]` in the
/// stream `keys[k]`, for every `k`: eight lanes per step with AVX2 when the CPU has it
/// ([`super::draws_avx2`]), else one by one; the same bits either way.
pub(crate) fn draw_vertices(keys: &[SampleKey], dims: &[u32], out: &mut [VertexDraws]) {
    let n = keys.len().min(dims.len()).min(out.len());
    let mut k = 0;
    #[cfg(target_arch = "x86_64")]
    if std::arch::is_x86_feature_detected!("avx2") {
        while k + 8 <= n {
            let key: &[SampleKey; 8] = keys[k..k + 8].try_into().expect("eight keys");
            let dim: &[u32; 8] = dims[k..k + 8].try_into().expect("eight dimensions");
            let o: &mut [VertexDraws; 8] = (&mut out[k..k + 8]).try_into().expect("eight slots");
            // SAFETY: the CPU supports AVX2 (checked just above), the only requirement of
            // `draw_vertices8`.
            unsafe { super::draws_avx2::draw_vertices8(key, dim, o) };
            k += 8;
        }
    }
    for j in k..n {
        out[j] = one_vertex(keys[j], dims[j]);
    }
}

/// The draws of one vertex, one lane (the tail of a batch).
#[inline]
fn one_vertex(key: SampleKey, dim: u32) -> VertexDraws {
    VertexDraws {
        light_sel: draw_1d(key, dim),
        light: draw_2d(key, dim + 1),
        layer: draw_1d(key, dim + 2),
        bsdf: draw_2d(key, dim + 3),
        rr: draw_1d(key, dim + 4),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use rt_core::Sampler;

    #[test]
    fn batched_draws_are_the_samplers_draws() {
        let mut keys = Vec::new();
        let mut dims = Vec::new();
        let mut want = Vec::new();
        for n in 0..37u32 {
            let mut s = Sampler::new(11);
            s.start(n * 7, n / 3, n * 13 + 1);
            for _ in 0..(n % 4) {
                s.next_2d();
            }
            keys.push(s.key());
            dims.push(s.dimension());
            want.push((
                s.next_1d(),
                s.next_2d(),
                s.next_1d(),
                s.next_2d(),
                s.next_1d(),
            ));
        }
        let mut out = vec![VertexDraws::default(); keys.len()];
        draw_vertices(&keys, &dims, &mut out);
        let portable: Vec<_> = keys
            .iter()
            .zip(&dims)
            .map(|(&k, &d)| one_vertex(k, d))
            .collect();
        for ((o, p), w) in out.iter().zip(&portable).zip(&want) {
            assert_eq!((o.light_sel, o.light, o.layer, o.bsdf, o.rr), *w);
            assert_eq!((p.light_sel, p.light, p.layer, p.bsdf, p.rr), *w);
        }
    }
}
