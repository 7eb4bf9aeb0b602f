//! Eye paths of the partitioned renderer: through specular vertices to the first diffuse one,
//! collecting emission on the way (part D, `ES*L`).

use super::Partitioned;
use crate::transport::survives_roulette;
use crate::Ctx;
use rayon::prelude::*;
use rt_core::{
    glam::{Vec2, Vec3},
    material::{Bsdf, LayerClass},
    ray::spawn_ray,
    Rgb, SampleStream, Sampler,
};
use rt_film::FirstHit;

/// Pixels per parallel work item.
const CHUNK: usize = 1024;

/// Where an eye path stopped: the first vertex whose sampled layer is diffuse. Holds what
/// rebuilding its BSDF needs rather than the BSDF, which is twice the size.
#[derive(Clone, Copy, Debug)]
pub(super) struct EyeVertex<'a> {
    pub p: Vec3,
    pub p_error: Vec3,
    pub ng: Vec3,
    pub ns: Vec3,
    /// Unit direction back along the eye path.
    pub wo: Vec3,
    /// Throughput from the camera, the choice of the diffuse part included (`1 / p_D`).
    pub beta: Rgb,
    pub material: u32,
    pub tint: rt_core::tint::Tint<'a>,
    /// Radius of its caustic-histogram bin: half the pixel footprint at this distance.
    pub radius: f32,
    /// Scattering vertices of the eye path, this one included.
    pub depth: u32,
    /// Row-major pixel index.
    pub pixel: u32,
}

impl<'a> EyeVertex<'a> {
    /// The diffuse part of the BSDF, through which VPLs and photons reach the eye.
    pub fn diffuse_bsdf(&self, ctx: &Ctx<'a>) -> Bsdf<'a> {
        let m = &ctx.scene.materials[self.material as usize];
        Bsdf::new(m, self.tint, self.ns, self.ng, self.wo).restricted(LayerClass::Diffuse)
    }
}

/// One pixel's eye path.
#[derive(Clone, Copy, Debug, Default)]
pub(super) struct EyeSample<'a> {
    /// Emission found along the path (`ES*L`).
    pub emitted: Rgb,
    pub vertex: Option<EyeVertex<'a>>,
    pub first_hit: Option<FirstHit>,
}

impl Partitioned {
    /// Every pixel's eye path of sample index `index`, in pixel order.
    pub(super) fn eye_paths<'a>(
        &self,
        ctx: &Ctx<'a>,
        seed: u32,
        stream: SampleStream,
        index: u32,
        want_first_hit: bool,
    ) -> Vec<EyeSample<'a>> {
        let cam = ctx.camera;
        let pixels = (cam.width * cam.height) as usize;
        // Angle subtended by a pixel at the centre of the image.
        let pixel_angle = cam.pixel_size();
        let chunks: Vec<Vec<EyeSample>> = (0..pixels.div_ceil(CHUNK))
            .into_par_iter()
            .map(|c| {
                let mut sampler = Sampler::with_stream(seed, stream);
                (c * CHUNK..pixels.min((c + 1) * CHUNK))
                    .map(|k| {
                        let (x, y) = (k as u32 % cam.width, k as u32 / cam.width);
                        sampler.start(x, y, index);
                        self.eye_path(ctx, &mut sampler, x, y, pixel_angle, want_first_hit)
                    })
                    .collect()
            })
            .collect();
        chunks.into_iter().flatten().collect()
    }

    fn eye_path<'a>(
        &self,
        ctx: &Ctx<'a>,
        sampler: &mut Sampler,
        x: u32,
        y: u32,
        pixel_angle: f32,
        want_first_hit: bool,
    ) -> EyeSample<'a> {
        let (scene, cam) = (ctx.scene, ctx.camera);
        let film_pos = cam.filter.film_position(x, y, sampler.next_2d());
        let lens = if cam.is_pinhole() {
            Vec2::ZERO
        } else {
            sampler.next_2d()
        };
        let mut ray = cam.generate_ray(film_pos, lens);
        let mut out = EyeSample::default();
        let mut beta = Rgb::ONE;
        let mut length = 0.0f32;
        let mut depth = 0u32;
        // The eye path's wavelength once a dispersive event has drawn one (§6.6).
        let mut lambda: Option<f32> = None;
        loop {
            let Some(hit) = ctx.accel.intersect(&ray, f32::INFINITY) else {
                out.emitted += beta * scene.environment.radiance(ray.dir);
                break;
            };
            length += hit.t * ray.dir.length();
            let si = scene.surface(&hit, 0.0);
            let material = &scene.materials[si.material as usize];
            let wo = -ray.dir;
            out.emitted += beta * material.emitted(si.ng, wo);
            let tint = scene.tint(material, si.uv);
            let bsdf = Bsdf::new(material, tint, si.ns, si.ng, wo).with_wavelength(lambda);
            if depth == 0 && want_first_hit {
                out.first_hit = Some(crate::first_hit(&bsdf, &si, wo, hit.t * ray.dir.length()));
            }
            if depth >= self.max_depth {
                break;
            }
            depth += 1;
            let u_layer = sampler.next_1d();
            let u_bsdf = sampler.next_2d();
            let u_rr = sampler.next_1d();
            let p_d = bsdf.share(LayerClass::Diffuse);
            if u_layer < p_d {
                out.vertex = Some(EyeVertex {
                    p: si.p,
                    p_error: si.p_error,
                    ng: si.ng,
                    ns: si.ns,
                    wo,
                    beta: beta / p_d,
                    material: si.material,
                    tint,
                    radius: 0.5 * pixel_angle * length,
                    depth,
                    pixel: y * cam.width + x,
                });
                break;
            }
            // The specular part, chosen with probability 1 - p_D.
            let u = ((u_layer - p_d) / (1.0 - p_d)).clamp(0.0, 0.999_999_94);
            let Some(s) = bsdf.restricted(LayerClass::Specular).sample(u, u_bsdf) else {
                break;
            };
            beta *= s.weight / (1.0 - p_d);
            lambda = s.wavelength;
            if beta.max_element() <= 0.0 || !beta.is_finite() {
                break;
            }
            if depth > self.rr_depth && !survives_roulette(&mut beta, 1.0, u_rr) {
                break;
            }
            ray = spawn_ray(si.p, si.p_error, si.ng, s.wi);
        }
        out
    }
}
