//! The path-space-partitioned progressive renderer (Dammertz, Keller & Lensch 2010,
//! "Progressive Point-Light-Based Global Illumination"; Dammertz 2011, §6.3).
//!
//! Light paths `E(S|D)*L` are split, by the first vertex from the eye whose sampled layer is
//! diffuse (hardness below 0.2), into four disjoint parts that sum to the whole image:
//!
//! | part | paths | technique |
//! |---|---|---|
//! | A | `EDL`, `EDD(S\|D)*L` | virtual point lights (`vpl.rs`) |
//! | B | `EDS(S\|D)*L` | caustic histogram (`caustic.rs`) |
//! | C | `ES+D(S\|D)*L` | specular gathering: the eye path continues through `S`, and A and B are evaluated at its first `D` vertex |
//! | D | `ES*L` | emission found by the eye path (`eye.rs`) |
//!
//! The split is exact, not weighted: a vertex's BSDF is the sum of its diffuse and specular
//! layers ([`Bsdf::restricted`](rt_core::material::Bsdf::restricted)); the eye path picks one
//! part by its share, VPLs carry the diffuse part of the vertex they sit on and photons the
//! specular part of the vertices they pass. So no MIS is needed and even non-reciprocal
//! materials converge to one image.
//!
//! Point, spot and directional lights take part as the emitters do: each is a VPL of its own
//! (its light at an eye vertex is exact, `I·falloff/r²` or `E`, so it is not clamped) and a
//! source of caustic photons sent as [`rt_core::delta_light::DeltaLight::emit`] sends
//! particles (a point's projection map covers the whole sphere).
//!
//! Each pass (one sample index) regenerates everything: one eye path per pixel, `vpl_paths`
//! particle walks (a VPL at every vertex with a diffuse part, culled against 256 eye vertices
//! chosen by a Halton sequence), the caustic photons (`photons` per pass, from the walks'
//! light points, only in the directions their projection maps allow), and the gather. Only the
//! film persists: memory does not grow with the number of passes.
//!
//! Bias, all documented choices: the VPLs' geometric term is clamped at `1 / (clamp ·
//! diagonal)²` (`clamp = 0` disables it; the energy lost is light from VPLs closer than that
//! distance, in corners); the histogram's density estimate blurs caustics over half a pixel
//! footprint; biased culling (`cull=biased`) drops VPLs no chosen eye vertex sees. Deviations:
//! the bin radius is half the pixel's angle times the eye path's length, which is what ray
//! differentials give through planar mirrors (curved glass would widen or narrow it); photons
//! from the environment start by plane sampling and have no projection map; indirect caustics
//! (photons from VPLs beyond the lights, `EDS+D+L`) are traced only when asked for
//! (`indirect_caustics`), as in the thesis; by default those paths are missing. Dispersion:
//! eye paths, VPL walks and photons each keep the wavelength of their first dispersive event;
//! as in [`crate::Bdpt`], an eye path and a light walk that both dispersed join two
//! independent wavelengths.

mod caustic;
mod eye;
mod projection;
mod vpl;

use crate::driver::{RenderStats, SamplePass};
use crate::technique::{Technique, TechniqueStage};
use crate::{Ctx, RayCounters};
use rayon::prelude::*;
use rt_core::Rgb;
use rt_film::Film;
use std::sync::Mutex;
use std::time::{Duration, Instant};

/// How VPLs that none of the pass's chosen eye vertices sees are treated.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Culling {
    /// Every VPL is kept.
    Off,
    /// Unseen VPLs are kept with probability 1/8 and weighted by 8: unbiased.
    Unbiased,
    /// Unseen VPLs are dropped (slightly dark where only they light).
    Biased,
}

impl Culling {
    /// The name in specs.
    pub fn name(self) -> &'static str {
        match self {
            Culling::Off => "off",
            Culling::Unbiased => "unbiased",
            Culling::Biased => "biased",
        }
    }
}

/// The partitioned renderer's parameters; they change its speed and its noise, and (through
/// the clamp, the histogram radius and biased culling) its small bias, not what it converges
/// to otherwise.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PartitionOptions {
    /// Particle walks (VPL paths) per pass (thesis: 16).
    pub vpl_paths: u32,
    /// Caustic photons drawn per pass, shared by the walks' light points (thesis: 100,000).
    pub photons: u32,
    /// Distance below which the VPLs' geometric term is clamped, as a fraction of the scene's
    /// diagonal; 0: no clamp.
    pub clamp: f32,
    /// VPL culling.
    pub cull: Culling,
    /// Projection maps for caustic photons.
    pub projection_maps: bool,
    /// Indirect caustics: caustic photons also leave the VPLs of the first this many diffuse
    /// bounces (`per pass photons / VPL paths` each, so the cost grows with it); 0, the
    /// thesis' default, leaves out the paths `EDS+D+L` (light reaching a mirror from a
    /// diffuse surface).
    pub indirect_caustics: u32,
}

impl Default for PartitionOptions {
    fn default() -> Self {
        Self {
            vpl_paths: 16,
            photons: 100_000,
            clamp: 1e-3,
            cull: Culling::Unbiased,
            projection_maps: true,
            indirect_caustics: 0,
        }
    }
}

/// Chosen eye vertices the culling test looks at, per pass.
const SENTINELS: u32 = 256;

/// Counts over the passes rendered so far, for measuring the parts' costs.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct PartitionStats {
    /// Passes (sample indices) rendered.
    pub passes: u64,
    /// VPLs stored.
    pub vpls: u64,
    /// VPLs culled.
    pub culled: u64,
    /// Caustic photon draws (the normalisation, rejected draws included).
    pub photons_emitted: u64,
    /// Photons traced (draws the projection maps let through).
    pub photons_traced: u64,
    /// Photon landings in bins.
    pub photons_landed: u64,
    /// Sum of the built projection maps' coverages ([`PartitionStats::mean_coverage`]).
    pub coverage_sum: f64,
    /// Projection maps built.
    pub maps: u64,
    /// Time building projection maps.
    pub map_time: Duration,
    /// Time in the caustic histogram (maps, bins and photons).
    pub caustic_time: Duration,
    /// Time in eye paths, VPL walks and gathering.
    pub other_time: Duration,
}

impl PartitionStats {
    /// Mean fraction of cells set in the projection maps built (the photon rays saved are
    /// about one minus the cosine-weighted coverage, which this approximates).
    pub fn mean_coverage(&self) -> f64 {
        if self.maps > 0 {
            self.coverage_sum / self.maps as f64
        } else {
            0.0
        }
    }
}

impl std::ops::AddAssign for PartitionStats {
    fn add_assign(&mut self, o: Self) {
        self.passes += o.passes;
        self.vpls += o.vpls;
        self.culled += o.culled;
        self.photons_emitted += o.photons_emitted;
        self.photons_traced += o.photons_traced;
        self.photons_landed += o.photons_landed;
        self.coverage_sum += o.coverage_sum;
        self.maps += o.maps;
        self.map_time += o.map_time;
        self.caustic_time += o.caustic_time;
        self.other_time += o.other_time;
    }
}

/// The path-space-partitioned progressive renderer.
#[derive(Debug)]
pub struct Partitioned {
    /// Maximum number of scattering vertices of a path, as for the path tracer.
    pub max_depth: u32,
    /// Bounce after which Russian roulette may end eye paths, walks and photons.
    pub rr_depth: u32,
    /// Parameters.
    pub options: PartitionOptions,
    stats: Mutex<PartitionStats>,
}

impl Partitioned {
    /// The renderer allowing `max_depth` bounces, with `options`.
    pub fn new(max_depth: u32, options: PartitionOptions) -> Self {
        Self {
            max_depth,
            rr_depth: 3,
            options,
            stats: Mutex::default(),
        }
    }

    /// What the passes so far did.
    pub fn stats(&self) -> PartitionStats {
        *self.stats.lock().unwrap_or_else(|e| e.into_inner())
    }
}

impl Technique for Partitioned {
    fn name(&self) -> &str {
        "partitioned"
    }

    fn stages(&self) -> Vec<TechniqueStage> {
        let s = self.stats();
        let share = |a: u64, b: u64| 100.0 * a as f64 / b.max(1) as f64;
        let maps = if !self.options.projection_maps {
            TechniqueStage {
                name: "projection maps",
                time: None,
                details: "off (maps=off)".into(),
            }
        } else if s.photons_emitted == 0 {
            TechniqueStage {
                name: "projection maps",
                time: Some(s.map_time),
                details: format!("{} maps, no caustic photons drawn", s.maps),
            }
        } else {
            TechniqueStage {
                name: "projection maps",
                time: Some(s.map_time),
                details: format!(
                    "{} maps, mean coverage {:.1} %, photons traced {:.1} % of drawn \
                     (saved {:.1} %), {:.1} % of caustic time",
                    s.maps,
                    100.0 * s.mean_coverage(),
                    share(s.photons_traced, s.photons_emitted),
                    100.0 - share(s.photons_traced, s.photons_emitted),
                    100.0 * s.map_time.as_secs_f64() / s.caustic_time.as_secs_f64().max(1e-12)
                ),
            }
        };
        vec![
            TechniqueStage {
                name: "eye paths and VPLs",
                time: Some(s.other_time),
                details: format!(
                    "{} passes, {} VPLs stored, {} culled ({})",
                    s.passes,
                    s.vpls,
                    s.culled,
                    self.options.cull.name()
                ),
            },
            TechniqueStage {
                name: "caustic histogram",
                time: Some(s.caustic_time),
                details: format!(
                    "{} photons drawn, {} traced, {} landed in bins",
                    s.photons_emitted, s.photons_traced, s.photons_landed
                ),
            },
            maps,
        ]
    }

    fn render_pass(
        &self,
        ctx: &Ctx<'_>,
        film: &mut Film,
        seed: u32,
        pass: &SamplePass,
        progress: &(dyn Fn(u32) + Sync),
    ) -> RenderStats {
        let start = Instant::now();
        let discarded_before = film.discarded();
        let (w, h) = (film.width(), film.height());
        let bounds = ctx.accel.bounds();
        let diagonal = bounds.extent().length();
        let g_max = if self.options.clamp > 0.0 {
            1.0 / (self.options.clamp * diagonal).powi(2)
        } else {
            f32::INFINITY
        };
        let occupants = caustic::occupants(ctx.scene);
        let want_first_hit = film.aovs().any_first_hit();
        let mut rays = RayCounters::default();
        let mut samples = 0u64;
        let mut stats = PartitionStats::default();
        let n_passes = pass.indices.len().max(1) as u64;
        for (p, index) in pass.indices.clone().enumerate() {
            let t0 = Instant::now();
            let eyes = self.eye_paths(ctx, seed, pass.stream, index, want_first_hit);
            rays.rays += eyes.len() as u64;
            let vertices: Vec<eye::EyeVertex> = eyes.iter().filter_map(|e| e.vertex).collect();
            // The culling test's eye vertices: Halton points over the image, new every pass.
            let sentinels: Vec<eye::EyeVertex> = (0..SENTINELS)
                .filter_map(|i| {
                    let u = vpl::halton2(index.wrapping_mul(SENTINELS).wrapping_add(i));
                    let x = ((u.x * w as f32) as u32).min(w - 1);
                    let y = ((u.y * h as f32) as u32).min(h - 1);
                    eyes[(y * w + x) as usize].vertex
                })
                .collect();
            let mut culled = 0;
            let (vpls, primaries) = self.vpls(
                ctx,
                &bounds,
                seed,
                pass.stream,
                index,
                &sentinels,
                &mut rays,
                &mut culled,
            );
            let t1 = Instant::now();
            let caustics = self.caustics(
                ctx,
                &bounds,
                seed,
                pass.stream,
                index,
                &vertices,
                &primaries,
                &vpls,
                &occupants,
                &mut rays,
            );
            let t2 = Instant::now();
            // Gather at the active pixels, in parallel by chunks, merged in pixel order.
            let active = |k: usize| pass.pixels.as_ref().is_none_or(|m| m[k]);
            let gathered: Vec<(Rgb, RayCounters)> = eyes
                .par_iter()
                .enumerate()
                .map(|(k, e)| {
                    let mut c = RayCounters::default();
                    let l = match (&e.vertex, active(k)) {
                        (Some(v), true) => self.gather(ctx, v, &vpls, g_max, &mut c),
                        _ => Rgb::ZERO,
                    };
                    (l, c)
                })
                .collect();
            for (k, (e, (l, c))) in eyes.iter().zip(gathered).enumerate() {
                rays += c;
                if !active(k) {
                    continue;
                }
                let value = e.emitted + l + caustics.radiance[k];
                film.add_sample(
                    k as u32 % w,
                    k as u32 / w,
                    index,
                    value,
                    e.first_hit.as_ref(),
                );
                samples += 1;
            }
            let t3 = Instant::now();
            stats.passes += 1;
            stats.vpls += vpls.len() as u64;
            stats.culled += culled;
            stats.photons_emitted += caustics.emitted;
            stats.photons_traced += caustics.traced;
            stats.photons_landed += caustics.landed;
            stats.maps += caustics.maps;
            stats.coverage_sum += caustics.coverage_sum;
            stats.map_time += caustics.map_time;
            stats.caustic_time += t2 - t1;
            stats.other_time += (t1 - t0) + (t3 - t2);
            progress(((p as u64 + 1) * u64::from(h) / n_passes) as u32);
        }
        *self.stats.lock().unwrap_or_else(|e| e.into_inner()) += stats;
        RenderStats {
            elapsed: start.elapsed(),
            samples,
            rays,
            discarded: film.discarded() - discarded_before,
        }
    }
}
