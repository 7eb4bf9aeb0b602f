//! Ray streams ([`Accel::intersect_stream`](rt_core::Accel::intersect_stream) and
//! [`Accel::occluded_stream`](rt_core::Accel::occluded_stream)) through a wide BVH: one
//! dispatch on the instruction set and the traversal options per stream instead of per ray, the
//! traversal loop inlined into a loop over the rays (so its stack frame is set up once), and
//! the next rays fetched ahead. A [`Bvh8`](super::Bvh8) on a CPU with AVX2 traces each run of
//! eight consecutive rays that point into one octant as a packet (`packet.rs`); every other ray
//! runs exactly the single-ray traversal. Either way a stream's answers are the single-ray
//! queries' bit for bit (`tests/streams.rs`).

#[cfg(target_arch = "x86_64")]
use super::bvh::Avx2;
use super::bvh::{Baseline, Isa, WideNode};
#[cfg(target_arch = "x86_64")]
use super::bvh8_node::Node8;
#[cfg(target_arch = "x86_64")]
use super::packet::{same_octant, Entry, PACKET};
#[cfg(target_arch = "x86_64")]
use super::traverse::STACK_SIZE;
use super::traverse::{PreparedRay, DISTANCE, SPLIT_PLANE, UNSORTED};
use super::{Order, WideBvh};
use crate::traversal::NoCount;
use glam::Vec3;
use rt_core::{Hit, Ray};
#[cfg(target_arch = "x86_64")]
use std::any::Any;

/// How many rays ahead of the one being traced the stream prefetches.
const PREFETCH_RAYS: usize = 8;

/// Starts fetching `rays[i]` (if it exists) into the cache.
#[inline(always)]
fn prefetch_ray(rays: &[Ray], i: usize) {
    #[cfg(target_arch = "x86_64")]
    if let Some(r) = rays.get(i) {
        use std::arch::x86_64::{_mm_prefetch, _MM_HINT_T0};
        // SAFETY: prefetching has no architectural effect and never faults; SSE is part of
        // the x86_64 baseline.
        #[allow(unsafe_code)]
        unsafe {
            _mm_prefetch::<_MM_HINT_T0>((r as *const Ray).cast::<i8>())
        };
    }
    #[cfg(not(target_arch = "x86_64"))]
    let _ = (rays, i);
}

impl<N: WideNode> WideBvh<N> {
    /// Closest hits of `rays` (each within its `t_max`) into `hits`, as many as the shortest of
    /// the three slices.
    pub(crate) fn closest_stream(&self, rays: &[Ray], t_max: &[f32], hits: &mut [Option<Hit>]) {
        #[cfg(target_arch = "x86_64")]
        if let Some(avx2) = self.avx2 {
            if let Some(bvh8) = (self as &dyn Any).downcast_ref::<WideBvh<Node8>>() {
                // SAFETY: `Avx2::detect` made `avx2`, so the CPU has AVX2.
                #[allow(unsafe_code)]
                return unsafe {
                    bvh8.packets_avx2::<false>(
                        rays,
                        &t_max[..t_max.len().min(hits.len())],
                        |i, h| hits[i] = h,
                        avx2,
                    )
                };
            }
            // SAFETY: `Avx2::detect` made `avx2`, so the CPU has AVX2.
            #[allow(unsafe_code)]
            return unsafe { self.closest_stream_avx2(rays, t_max, hits, avx2) };
        }
        self.closest_stream_isa(rays, t_max, hits, Baseline);
    }

    /// [`WideBvh::closest_stream`] compiled with AVX2 enabled.
    ///
    /// # Safety
    ///
    /// The CPU must support AVX2.
    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx2")]
    #[allow(unsafe_code)]
    unsafe fn closest_stream_avx2(
        &self,
        rays: &[Ray],
        t_max: &[f32],
        hits: &mut [Option<Hit>],
        avx2: Avx2,
    ) {
        self.closest_stream_isa(rays, t_max, hits, avx2);
    }

    #[inline(always)]
    fn closest_stream_isa<I: Isa>(
        &self,
        rays: &[Ray],
        t_max: &[f32],
        hits: &mut [Option<Hit>],
        isa: I,
    ) {
        match (self.options.order, self.options.t_stack) {
            (Order::SplitPlane, false) => {
                self.closest_loop::<SPLIT_PLANE, false, I>(rays, t_max, hits, isa)
            }
            (Order::SplitPlane, true) => {
                self.closest_loop::<SPLIT_PLANE, true, I>(rays, t_max, hits, isa)
            }
            (Order::Distance, false) => {
                self.closest_loop::<DISTANCE, false, I>(rays, t_max, hits, isa)
            }
            (Order::Distance, true) => {
                self.closest_loop::<DISTANCE, true, I>(rays, t_max, hits, isa)
            }
            (Order::Unsorted, false) => {
                self.closest_loop::<UNSORTED, false, I>(rays, t_max, hits, isa)
            }
            (Order::Unsorted, true) => {
                self.closest_loop::<UNSORTED, true, I>(rays, t_max, hits, isa)
            }
        }
    }

    #[inline(always)]
    fn closest_loop<const ORDER: u8, const TSTACK: bool, I: Isa>(
        &self,
        rays: &[Ray],
        t_max: &[f32],
        hits: &mut [Option<Hit>],
        isa: I,
    ) {
        for (i, ((ray, &t), hit)) in rays.iter().zip(t_max).zip(hits.iter_mut()).enumerate() {
            prefetch_ray(rays, i + PREFETCH_RAYS);
            let mut pre = PreparedRay::new(ray);
            *hit = self.traverse::<false, ORDER, TSTACK, I, _>(0, &mut pre, t, isa, &mut NoCount);
        }
    }

    /// Occlusion of `rays` (each within its `t_max`) into `occluded`. Through the shadow cache
    /// when the options enable it (rays with a finite `toward`), else the plain any-hit
    /// traversal, whose answer never depends on `toward`.
    pub(crate) fn occluded_stream_impl(
        &self,
        rays: &[Ray],
        t_max: &[f32],
        toward: &[Vec3],
        occluded: &mut [bool],
    ) {
        if self.options.shadow_cache {
            for (((ray, &t), &p), o) in rays.iter().zip(t_max).zip(toward).zip(occluded.iter_mut())
            {
                *o = if p.is_finite() {
                    self.occluded_cached(ray, t, p, &mut NoCount)
                } else {
                    self.any_stream_one(ray, t)
                };
            }
            return;
        }
        let n = toward.len().min(occluded.len());
        let (rays, t_max, occluded) = (&rays[..n.min(rays.len())], t_max, &mut occluded[..n]);
        #[cfg(target_arch = "x86_64")]
        if let Some(avx2) = self.avx2 {
            if let Some(bvh8) = (self as &dyn Any).downcast_ref::<WideBvh<Node8>>() {
                let n = t_max.len().min(occluded.len());
                // SAFETY: `Avx2::detect` made `avx2`, so the CPU has AVX2.
                #[allow(unsafe_code)]
                unsafe {
                    bvh8.packets_avx2::<true>(
                        rays,
                        &t_max[..n],
                        |i, h| occluded[i] = h.is_some(),
                        avx2,
                    )
                };
                return;
            }
            // SAFETY: `Avx2::detect` made `avx2`, so the CPU has AVX2.
            #[allow(unsafe_code)]
            return unsafe { self.any_stream_avx2(rays, t_max, occluded, avx2) };
        }
        self.any_stream_isa(rays, t_max, occluded, Baseline);
    }

    /// One any-hit query, as [`Accel::occluded`](rt_core::Accel::occluded) runs it.
    #[inline]
    fn any_stream_one(&self, ray: &Ray, t_max: f32) -> bool {
        self.query::<true, _>(0, ray, t_max, &mut NoCount).is_some()
    }

    /// [`WideBvh::any_stream_isa`] compiled with AVX2 enabled.
    ///
    /// # Safety
    ///
    /// The CPU must support AVX2.
    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx2")]
    #[allow(unsafe_code)]
    unsafe fn any_stream_avx2(
        &self,
        rays: &[Ray],
        t_max: &[f32],
        occluded: &mut [bool],
        avx2: Avx2,
    ) {
        self.any_stream_isa(rays, t_max, occluded, avx2);
    }

    #[inline(always)]
    fn any_stream_isa<I: Isa>(&self, rays: &[Ray], t_max: &[f32], occluded: &mut [bool], isa: I) {
        // Any-hit queries never keep entry distances (see `WideBvh::query_any`).
        match self.options.order {
            Order::SplitPlane => self.any_loop::<SPLIT_PLANE, I>(rays, t_max, occluded, isa),
            Order::Distance => self.any_loop::<DISTANCE, I>(rays, t_max, occluded, isa),
            Order::Unsorted => self.any_loop::<UNSORTED, I>(rays, t_max, occluded, isa),
        }
    }

    #[inline(always)]
    fn any_loop<const ORDER: u8, I: Isa>(
        &self,
        rays: &[Ray],
        t_max: &[f32],
        occluded: &mut [bool],
        isa: I,
    ) {
        for (i, ((ray, &t), o)) in rays.iter().zip(t_max).zip(occluded.iter_mut()).enumerate() {
            prefetch_ray(rays, i + PREFETCH_RAYS);
            let mut pre = PreparedRay::new(ray);
            *o = self
                .traverse::<true, ORDER, false, I, _>(0, &mut pre, t, isa, &mut NoCount)
                .is_some();
        }
    }
}

#[cfg(target_arch = "x86_64")]
impl WideBvh<Node8> {
    /// Traces `rays` in runs of eight: as one packet when the eight point into one octant,
    /// else one by one. Calls `emit(i, hit)` with the closest hit of ray `i` (with `ANY_HIT`:
    /// `Some` if it is occluded).
    ///
    /// # Safety
    ///
    /// The CPU must support AVX2.
    #[allow(unsafe_code)]
    unsafe fn packets_avx2<const ANY_HIT: bool>(
        &self,
        rays: &[Ray],
        t_max: &[f32],
        emit: impl FnMut(usize, Option<Hit>),
        avx2: Avx2,
    ) {
        // SAFETY: the caller guarantees AVX2; `evex_for` is true only where the CPU also has
        // AVX-512F and AVX-512VL.
        unsafe {
            if avx2.evex_for(ANY_HIT) {
                self.packets_evex::<ANY_HIT>(rays, t_max, emit, avx2)
            } else {
                self.packets_vex::<ANY_HIT>(rays, t_max, emit, avx2)
            }
        }
    }

    /// [`WideBvh::packets_avx2`] compiled for AVX2 alone.
    ///
    /// # Safety
    ///
    /// The CPU must support AVX2.
    #[target_feature(enable = "avx2")]
    #[allow(unsafe_code)]
    unsafe fn packets_vex<const ANY_HIT: bool>(
        &self,
        rays: &[Ray],
        t_max: &[f32],
        emit: impl FnMut(usize, Option<Hit>),
        avx2: Avx2,
    ) {
        // SAFETY: as this function's.
        unsafe { self.packets_body::<ANY_HIT>(rays, t_max, emit, avx2) }
    }

    /// [`WideBvh::packets_avx2`] compiled with AVX-512F and AVX-512VL too: the same
    /// operations with 32 vector registers ([`Avx2::avx512vl`]).
    ///
    /// # Safety
    ///
    /// The CPU must support AVX2, AVX-512F and AVX-512VL.
    #[target_feature(enable = "avx2,avx512f,avx512vl")]
    #[allow(unsafe_code)]
    unsafe fn packets_evex<const ANY_HIT: bool>(
        &self,
        rays: &[Ray],
        t_max: &[f32],
        emit: impl FnMut(usize, Option<Hit>),
        avx2: Avx2,
    ) {
        // SAFETY: as this function's.
        unsafe { self.packets_body::<ANY_HIT>(rays, t_max, emit, avx2) }
    }

    /// The loop of [`WideBvh::packets_avx2`], inlined into each compilation.
    ///
    /// # Safety
    ///
    /// The CPU must support AVX2.
    #[inline(always)]
    #[allow(unsafe_code)]
    unsafe fn packets_body<const ANY_HIT: bool>(
        &self,
        rays: &[Ray],
        t_max: &[f32],
        mut emit: impl FnMut(usize, Option<Hit>),
        avx2: Avx2,
    ) {
        let n = rays.len().min(t_max.len());
        // Made once per stream: 7 KB, which cost more than a packet's traversal when it was
        // made for each packet.
        let mut stack = [Entry::default(); STACK_SIZE];
        let mut single = [None; PACKET];
        let mut i = 0;
        while i < n {
            let end = (i + PACKET).min(n);
            let (r, t) = (&rays[i..end], &t_max[i..end]);
            if end - i > 1 && same_octant(r) {
                // SAFETY: the caller guarantees AVX2.
                let h = unsafe { self.packet8::<ANY_HIT>(r, t, &mut stack, avx2) };
                for (j, h) in h[..end - i].iter().enumerate() {
                    emit(i + j, *h);
                }
            } else if ANY_HIT {
                for j in i..end {
                    let mut pre = PreparedRay::new(&rays[j]);
                    emit(j, self.any_one(&mut pre, t_max[j], avx2));
                }
            } else {
                let single = &mut single[..end - i];
                self.closest_stream_isa(r, t, single, avx2);
                for (j, h) in single.iter().enumerate() {
                    emit(i + j, *h);
                }
            }
            i = end;
        }
    }

    /// One any-hit query as `any_loop` runs it.
    #[inline(always)]
    fn any_one(&self, pre: &mut PreparedRay, t_max: f32, avx2: Avx2) -> Option<Hit> {
        match self.options.order {
            Order::SplitPlane => {
                self.traverse::<true, SPLIT_PLANE, false, _, _>(0, pre, t_max, avx2, &mut NoCount)
            }
            Order::Distance => {
                self.traverse::<true, DISTANCE, false, _, _>(0, pre, t_max, avx2, &mut NoCount)
            }
            Order::Unsorted => {
                self.traverse::<true, UNSORTED, false, _, _>(0, pre, t_max, avx2, &mut NoCount)
            }
        }
    }
}
