//! The BSDF stage for the most common vertex, a plain Lambertian surface (one layer, one
//! colour at all angles, [`rt_core::Material::plain_lambert`]), eight lanes at a time: the
//! shading frame, the light sample's BSDF value and MIS weight, the cosine-weighted sample and
//! its weight. Every other vertex is shaded by [`super::shade`] one lane at a time.
//!
//! The kernel is [`rt_core::material::Bsdf`]'s arithmetic for such a layer (`Frame::from_normal`,
//! `sides`, `eval_pdf`'s Lambertian branch, `sample`, `cosine_hemisphere`, the power heuristic)
//! written once on eight lanes ([`L8`]), in the same order, so the AVX and the portable forms and
//! the scalar tracer give the same bits (the tests here compare every lane with `Bsdf`; the
//! wavefront tests compare whole images). The one step not
//! vectorised is the concentric map's sine and cosine, evaluated lane by lane with `f32::sin`
//! and `f32::cos` as the scalar tracer does.

use super::simd::{L8, LANES, M8};
use rt_core::glam::Vec3;
use rt_core::lights::LightSample;
use rt_core::scene::SurfaceHit;
use rt_core::Rgb;
use std::f32::consts::{FRAC_1_PI, FRAC_PI_2, FRAC_PI_4};

/// A column of three-component values.
#[derive(Default)]
struct Column3 {
    x: Vec<f32>,
    y: Vec<f32>,
    z: Vec<f32>,
}

impl Column3 {
    fn with_capacity(n: usize) -> Self {
        Self {
            x: vec![0.0; n],
            y: vec![0.0; n],
            z: vec![0.0; n],
        }
    }

    #[inline]
    fn set(&mut self, k: usize, v: Vec3) {
        self.x[k] = v.x;
        self.y[k] = v.y;
        self.z[k] = v.z;
    }

    #[inline]
    fn get(&self, k: usize) -> Vec3 {
        Vec3::new(self.x[k], self.y[k], self.z[k])
    }

    #[inline(always)]
    fn load(&self, k: usize) -> V3 {
        V3 {
            x: L8::load(&self.x[k..]),
            y: L8::load(&self.y[k..]),
            z: L8::load(&self.z[k..]),
        }
    }

    #[inline(always)]
    fn store(&mut self, k: usize, v: V3) {
        v.x.store(&mut self.x[k..]);
        v.y.store(&mut self.y[k..]);
        v.z.store(&mut self.z[k..]);
    }
}

/// Three lanes-wide components (a vector per lane).
#[derive(Clone, Copy)]
struct V3 {
    x: L8,
    y: L8,
    z: L8,
}

impl V3 {
    /// `Vec3::dot`: `(x·x') + (y·y') + (z·z')`.
    #[inline(always)]
    fn dot(self, o: Self) -> L8 {
        self.x * o.x + self.y * o.y + self.z * o.z
    }

    #[inline(always)]
    fn mul(self, o: Self) -> Self {
        V3 {
            x: self.x * o.x,
            y: self.y * o.y,
            z: self.z * o.z,
        }
    }

    #[inline(always)]
    fn scale(self, s: L8) -> Self {
        V3 {
            x: self.x * s,
            y: self.y * s,
            z: self.z * s,
        }
    }

    #[inline(always)]
    fn select(m: M8, a: Self, b: Self) -> Self {
        V3 {
            x: L8::select(m, a.x, b.x),
            y: L8::select(m, a.y, b.y),
            z: L8::select(m, a.z, b.z),
        }
    }

    /// True where some component is positive: `Vec3::max_element() > 0` (NaN components
    /// count as not positive in both).
    #[inline(always)]
    fn any_positive(self) -> M8 {
        let zero = L8::splat(0.0);
        self.x.gt(zero) | self.y.gt(zero) | self.z.gt(zero)
    }
}

/// `rt_core::Frame` (Duff et al. 2017) around unit normal `n`.
#[derive(Clone, Copy)]
struct Frame {
    s: V3,
    t: V3,
    n: V3,
}

impl Frame {
    #[inline(always)]
    fn from_normal(n: V3) -> Self {
        let one = L8::splat(1.0);
        let sign = n.z.sign_one();
        let a = L8::splat(-1.0) / (sign + n.z);
        let b = n.x * n.y * a;
        let s = V3 {
            x: one + sign * n.x * n.x * a,
            y: sign * b,
            z: -sign * n.x,
        };
        let t = V3 {
            x: b,
            y: sign + n.y * n.y * a,
            z: -n.y,
        };
        Self { s, t, n }
    }

    #[inline(always)]
    fn to_local(self, v: V3) -> V3 {
        V3 {
            x: v.dot(self.s),
            y: v.dot(self.t),
            z: v.dot(self.n),
        }
    }

    /// `s·v.x + t·v.y + n·v.z`, summed left to right as `Vec3` does.
    #[inline(always)]
    fn to_world(self, v: V3) -> V3 {
        V3 {
            x: self.s.x * v.x + self.t.x * v.y + self.n.x * v.z,
            y: self.s.y * v.x + self.t.y * v.y + self.n.y * v.z,
            z: self.s.z * v.x + self.t.z * v.y + self.n.z * v.z,
        }
    }
}

/// The Lambertian vertices of one shading round: their inputs, the kernel's outputs, and what
/// the scalar finish needs (the lane, the surface point, the light sample). Allocated once per
/// batch; `clear` keeps the storage.
pub(crate) struct LambertQueue {
    len: usize,
    pub lane: Vec<u32>,
    pub surface: Vec<SurfaceHit>,
    pub light: Vec<Option<LightSample>>,
    ns: Column3,
    ng: Column3,
    wo: Column3,
    f: Column3,
    beta: Column3,
    light_wi: Column3,
    light_le: Column3,
    light_pdf: Vec<f32>,
    /// 0 where the light is a delta light, whose MIS weight takes a BSDF pdf of 0
    /// ([`LightSample::mis_weight`]), else 1.
    light_bsdf_mis: Vec<f32>,
    has_light: Vec<f32>,
    u0: Vec<f32>,
    u1: Vec<f32>,
    contribution: Column3,
    contributes: Vec<f32>,
    wi: Column3,
    weight: Column3,
    pdf: Vec<f32>,
    sampled: Vec<f32>,
}

/// What the kernel found for one queued vertex.
pub(crate) struct LambertResult {
    /// The light sample's contribution if unoccluded (`None`: it adds nothing).
    pub contribution: Option<Rgb>,
    /// The sampled direction, its weight `f·|cos|/pdf` and pdf (`None`: the path ends).
    pub sample: Option<(Vec3, Rgb, f32)>,
}

impl LambertQueue {
    /// Room for `capacity` vertices (rounded up to whole vectors).
    pub fn new(capacity: usize) -> Self {
        let n = capacity.div_ceil(LANES) * LANES;
        let column = || vec![0.0; n];
        Self {
            len: 0,
            lane: Vec::with_capacity(capacity),
            surface: Vec::with_capacity(capacity),
            light: Vec::with_capacity(capacity),
            ns: Column3::with_capacity(n),
            ng: Column3::with_capacity(n),
            wo: Column3::with_capacity(n),
            f: Column3::with_capacity(n),
            beta: Column3::with_capacity(n),
            light_wi: Column3::with_capacity(n),
            light_le: Column3::with_capacity(n),
            light_pdf: column(),
            light_bsdf_mis: column(),
            has_light: column(),
            u0: column(),
            u1: column(),
            contribution: Column3::with_capacity(n),
            contributes: column(),
            wi: Column3::with_capacity(n),
            weight: Column3::with_capacity(n),
            pdf: column(),
            sampled: column(),
        }
    }

    pub fn clear(&mut self) {
        self.len = 0;
        self.lane.clear();
        self.surface.clear();
        self.light.clear();
    }

    pub fn len(&self) -> usize {
        self.len
    }

    /// Queues the vertex of `lane` at surface point `si` seen along `wo`, with Lambertian
    /// value `f` (`colour · tint · weight / π`), path throughput `beta`, light sample `light`
    /// (`None` without light sampling or when it found nothing) and BSDF draw `u`.
    #[allow(clippy::too_many_arguments)]
    pub fn push(
        &mut self,
        lane: u32,
        si: &SurfaceHit,
        wo: Vec3,
        f: Rgb,
        beta: Rgb,
        light: Option<LightSample>,
        u: rt_core::glam::Vec2,
    ) {
        let k = self.len;
        self.lane.push(lane);
        self.surface.push(*si);
        self.light.push(light);
        self.ns.set(k, si.ns);
        self.ng.set(k, si.ng);
        self.wo.set(k, wo);
        self.f.set(k, f);
        self.beta.set(k, beta);
        match light {
            Some(ls) => {
                self.light_wi.set(k, ls.wi);
                self.light_le.set(k, ls.le);
                self.light_pdf[k] = ls.pdf;
                self.light_bsdf_mis[k] = if ls.delta { 0.0 } else { 1.0 };
                self.has_light[k] = 1.0;
            }
            None => {
                // Harmless values: the lane's light result is discarded.
                self.light_wi.set(k, si.ns);
                self.light_le.set(k, Vec3::ZERO);
                self.light_pdf[k] = 1.0;
                self.light_bsdf_mis[k] = 1.0;
                self.has_light[k] = 0.0;
            }
        }
        self.u0[k] = u.x;
        self.u1[k] = u.y;
        self.len += 1;
    }

    /// Runs the kernel over every queued vertex: eight at a time with AVX when the CPU has it,
    /// the rest one at a time; the same bits either way.
    pub fn run(&mut self) {
        self.run_with(true);
    }

    /// `run`, with the AVX form allowed or not (tests compare the two).
    fn run_with(&mut self, allow_avx: bool) {
        // Pad the last vector with copies of a queued vertex so every lane computes
        // something finite; the copies' results are never read.
        let padded = self.len.div_ceil(LANES) * LANES;
        for j in self.len..padded {
            self.copy_inputs(0, j);
        }
        #[cfg(target_arch = "x86_64")]
        if allow_avx && std::arch::is_x86_feature_detected!("avx") {
            self.run_avx(padded);
            return;
        }
        let _ = allow_avx;
        for k in (0..padded).step_by(LANES) {
            vertex(self, k);
        }
    }

    #[cfg(target_arch = "x86_64")]
    #[allow(unsafe_code)] // the call into the AVX form, behind the check in `run_with`
    fn run_avx(&mut self, padded: usize) {
        #[target_feature(enable = "avx")]
        fn kernel(q: &mut LambertQueue, padded: usize) {
            for k in (0..padded).step_by(LANES) {
                vertex(q, k);
            }
        }
        // SAFETY: `run_with` checked that the CPU supports AVX, `kernel`'s only requirement.
        unsafe { kernel(self, padded) }
    }

    fn copy_inputs(&mut self, from: usize, to: usize) {
        for c in [
            &mut self.ns,
            &mut self.ng,
            &mut self.wo,
            &mut self.f,
            &mut self.beta,
            &mut self.light_wi,
            &mut self.light_le,
        ] {
            let v = c.get(from);
            c.set(to, v);
        }
        for c in [
            &mut self.light_pdf,
            &mut self.light_bsdf_mis,
            &mut self.has_light,
            &mut self.u0,
            &mut self.u1,
        ] {
            c[to] = c[from];
        }
    }

    /// The kernel's result for queued vertex `k`.
    pub fn result(&self, k: usize) -> LambertResult {
        LambertResult {
            contribution: (self.contributes[k] != 0.0).then(|| self.contribution.get(k)),
            sample: (self.sampled[k] != 0.0)
                .then(|| (self.wi.get(k), self.weight.get(k), self.pdf[k])),
        }
    }
}

/// What `Bsdf::sides` needs of the vertex: its frame, geometric normal, and on which side of
/// each normal `wo` lies.
#[derive(Clone, Copy)]
struct Side {
    frame: Frame,
    ng: V3,
    wo_ng_front: M8,
    wo_local_front: M8,
}

impl Side {
    /// `Bsdf::sides` for a world direction `wi` and its local form `wi_local`: whether the pair
    /// is consistent (`valid`) and, if so, a reflection (`reflect`).
    #[inline(always)]
    fn sides(self, wi: V3, wi_local: V3) -> (M8, M8) {
        let zero = L8::splat(0.0);
        let geo_same = wi.dot(self.ng).gt(zero).same(self.wo_ng_front);
        let sh_same = wi_local.z.gt(zero).same(self.wo_local_front);
        let valid = !wi_local.z.eq(zero) & geo_same.same(sh_same);
        (valid, geo_same)
    }

    /// `(f, pdf)` of `Bsdf::eval_pdf` for a Lambertian layer of value `f`: zero unless `wi` is
    /// a reflection.
    #[inline(always)]
    fn eval(self, f: V3, wi: V3) -> (V3, L8) {
        let zero = L8::splat(0.0);
        let wi_local = self.frame.to_local(wi);
        let (valid, reflect) = self.sides(wi, wi_local);
        let ok = valid & reflect;
        let none = V3 {
            x: zero,
            y: zero,
            z: zero,
        };
        let pdf = wi_local.z.abs() * L8::splat(FRAC_1_PI);
        (V3::select(ok, f, none), L8::select(ok, pdf, zero))
    }
}

/// `power_heuristic(f, g)`.
#[inline(always)]
fn power_heuristic(f: L8, g: L8) -> L8 {
    let (f2, g2) = (f * f, g * g);
    let zero = L8::splat(0.0);
    let w = f2 / (f2 + g2);
    let w = L8::select((f2 + g2).eq(zero), zero, w);
    L8::select(f2.abs().eq(L8::splat(f32::INFINITY)), L8::splat(1.0), w)
}

/// `concentric_disk(u)`'s cosine and sine, lane by lane with the standard library.
#[inline(always)]
fn cos_sin(theta: L8) -> (L8, L8) {
    (L8(theta.0.map(f32::cos)), L8(theta.0.map(f32::sin)))
}

/// One vector of queued vertices from index `k`.
#[inline(always)]
fn vertex(q: &mut LambertQueue, k: usize) {
    let zero = L8::splat(0.0);
    let one = L8::splat(1.0);
    let ns = q.ns.load(k);
    let ng = q.ng.load(k);
    let wo = q.wo.load(k);
    let f = q.f.load(k);
    let beta = q.beta.load(k);
    let frame = Frame::from_normal(ns);
    let wo_local = frame.to_local(wo);
    let wo_ng_front = wo.dot(ng).gt(zero);
    let wo_local_front = wo_local.z.gt(zero);
    let shading = Side {
        frame,
        ng,
        wo_ng_front,
        wo_local_front,
    };

    // The light sample: f, MIS weight and contribution.
    let light_wi = q.light_wi.load(k);
    let light_pdf = L8::load(&q.light_pdf[k..]);
    let (fl, bsdf_pdf) = shading.eval(f, light_wi);
    let cos = light_wi.dot(ns).abs();
    let contributes = L8::load(&q.has_light[k..]).gt(zero) & fl.any_positive() & cos.gt(zero);
    let w = power_heuristic(light_pdf, bsdf_pdf * L8::load(&q.light_bsdf_mis[k..]));
    let le = q.light_le.load(k);
    let c = beta.mul(fl).mul(le).scale(cos * w / light_pdf);
    q.contribution.store(k, c);
    L8::select(contributes, one, zero).store(&mut q.contributes[k..]);

    // The cosine-weighted sample (`sample_lobe`, `cosine_hemisphere`, `concentric_disk`).
    let ox = L8::splat(2.0) * L8::load(&q.u0[k..]) - one;
    let oy = L8::splat(2.0) * L8::load(&q.u1[k..]) - one;
    let centre = ox.eq(zero) & oy.eq(zero);
    let x_major = ox.abs().gt(oy.abs());
    let r = L8::select(x_major, ox, oy);
    // `oy / ox` where x is the major axis, else `ox / oy`: one division for both branches.
    let ratio = L8::select(x_major, oy, ox) / r;
    let quarter = L8::splat(FRAC_PI_4) * ratio;
    let theta = L8::select(x_major, quarter, L8::splat(FRAC_PI_2) - quarter);
    let (cos_t, sin_t) = cos_sin(theta);
    let dx = L8::select(centre, zero, r * cos_t);
    let dy = L8::select(centre, zero, r * sin_t);
    let dz = (one - (dx * dx + dy * dy)).max_zero().sqrt();
    let side = L8::select(wo_local.z.ge(zero), one, L8::splat(-1.0));
    let wi_local = V3 {
        x: dx,
        y: dy,
        z: dz * side,
    };
    let wi = frame.to_world(wi_local);
    let wi = wi.scale(one / wi.dot(wi).sqrt());
    let (valid, _) = shading.sides(wi, wi_local);
    let (fs, pdf) = shading.eval(f, wi);
    let sampled = valid & pdf.gt(zero) & pdf.abs().lt(L8::splat(f32::INFINITY));
    q.wi.store(k, wi);
    q.weight.store(k, fs.scale(wi_local.z.abs() / pdf));
    pdf.store(&mut q.pdf[k..]);
    L8::select(sampled, one, zero).store(&mut q.sampled[k..]);
}

#[cfg(test)]
mod tests {
    use super::*;
    use rt_core::glam::Vec2;
    use rt_core::material::Bsdf;
    use rt_core::rng::SplitMix64;
    use rt_core::sampling::uniform_sphere;
    use rt_core::Material;

    fn unit(rng: &mut SplitMix64) -> Vec3 {
        uniform_sphere(rng.vec2())
    }

    /// The kernel, in both forms, against `Bsdf` for random frames, directions and draws,
    /// including the draws that hit the concentric map's centre and axes, and grazing and
    /// back-facing directions.
    #[test]
    fn the_lambert_stage_is_the_bsdfs_arithmetic_bit_for_bit() {
        let mut rng = SplitMix64::new(5);
        let material = Material::diffuse("d", Vec3::new(0.7, 0.5, 0.3));
        let special = [0.5, 0.0, 0.25, 0.75, 0.999_999_94];
        let mut queue = LambertQueue::new(300);
        let mut want = Vec::new();
        for n in 0..299usize {
            let ns = unit(&mut rng);
            // A geometric normal near the shading one (same side), sometimes the same.
            let ng = if n % 5 == 0 {
                ns
            } else {
                let g = (ns + 0.4 * unit(&mut rng)).normalize();
                if g.dot(ns) > 0.0 {
                    g
                } else {
                    ns
                }
            };
            let wo = if n % 7 == 0 {
                tangent(ns)
            } else {
                unit(&mut rng)
            };
            let tint = Vec3::new(rng.f32(), rng.f32(), 1.0);
            let beta = Vec3::new(rng.f32(), rng.f32(), rng.f32()) * 3.0;
            let u = match n % 4 {
                0 => Vec2::new(special[n / 4 % 5], special[n / 20 % 5]),
                _ => rng.vec2(),
            };
            let light = (n % 3 != 0).then(|| LightSample {
                wi: if n % 11 == 0 { ns } else { unit(&mut rng) },
                point: Vec3::ZERO,
                point_error: Vec3::ZERO,
                normal: Vec3::Z,
                dist: 1.0,
                le: Vec3::new(rng.f32(), 2.0, rng.f32()) * 10.0,
                pdf: if n % 13 == 0 {
                    f32::INFINITY
                } else {
                    rng.range(0.01, 5.0)
                },
                two_sided: false,
                delta: n % 17 == 0,
            });
            let si = SurfaceHit {
                p: Vec3::ZERO,
                p_error: Vec3::ZERO,
                ng,
                ns,
                uv: Vec2::ZERO,
                material: 0,
                prim: 0,
                instance: None,
                time: 0.0,
            };
            let f = material
                .plain_lambert(tint)
                .expect("a plain Lambertian material");
            queue.push(n as u32, &si, wo, f, beta, light, u);

            let bsdf = Bsdf::new(&material, tint, ns, ng, wo);
            let contribution = light.and_then(|ls| {
                let (f, bsdf_pdf) = bsdf.eval_pdf(ls.wi);
                let cos = ls.wi.dot(ns).abs();
                (f.max_element() > 0.0 && cos > 0.0)
                    .then(|| beta * f * ls.le * (cos * ls.mis_weight(bsdf_pdf) / ls.pdf))
            });
            let sample = bsdf.sample(0.3, u).map(|s| (s.wi, s.weight, s.pdf));
            want.push((contribution, sample));
        }
        let bits = |v: Vec3| v.to_array().map(f32::to_bits);
        for allow_avx in [true, false] {
            queue.run_with(allow_avx);
            for (k, (contribution, sample)) in want.iter().enumerate() {
                let r = queue.result(k);
                assert_eq!(
                    r.contribution.map(bits),
                    contribution.map(bits),
                    "vertex {k}, avx {allow_avx}"
                );
                assert_eq!(
                    r.sample
                        .map(|(wi, w, pdf)| (bits(wi), bits(w), pdf.to_bits())),
                    sample.map(|(wi, w, pdf)| (bits(wi), bits(w), pdf.to_bits())),
                    "vertex {k}, avx {allow_avx}"
                );
            }
        }
        assert!(want.iter().any(|w| w.0.is_some()) && want.iter().any(|w| w.0.is_none()));
        assert!(want.iter().any(|w| w.1.is_some()) && want.iter().any(|w| w.1.is_none()));
    }

    /// A direction in the tangent plane of `n` (exactly grazing in the local frame up to rounding).
    fn tangent(n: Vec3) -> Vec3 {
        rt_core::frame::Frame::from_normal(n).s
    }
}
