//! What a running job tells its caller ([`JobSink`]) and what it returns ([`JobReport`]):
//! one [`FrameReport`] per image written, whose `Display` is the summary line `render` prints.

use crate::{Adaptive, FrameTimes, GreeRun, RenderReport, StopReason};
use rt_film::Rect;
use rt_integrators::RenderStats;
use std::fmt;
use std::ops::Range;
use std::path::PathBuf;
use std::time::Duration;

/// Where a running job reports. Every method has a default that ignores the report.
pub trait JobSink: Sync {
    /// The fraction of the current image rendered, 0 to 1 (called from worker threads).
    fn progress(&self, _done: f64) {}
    /// A remark of the scene loader (a zero-area triangle, an unused material, ...).
    fn warning(&self, _text: &str) {}
    /// The image of `frame` (`None`: a still) of a job whose images go to the sink
    /// ([`super::Delivery::Sink`]): the channels its EXR output would hold. Called before
    /// the frame's [`JobSink::frame`].
    fn image(&self, _frame: Option<u32>, _image: rt_film::ExrImage) {}
    /// What the denoiser of `frame` read, in a job with a denoiser (not GREE): the noisy
    /// frame (with its sample records for SBMF) and, for a temporal one, its guide buffers and
    /// further samples. Called before the frame's [`JobSink::image`]; a sink that keeps a copy
    /// can denoise it again elsewhere (the Python module's `inputs=True`), and only such a
    /// sink pays for the copy.
    fn denoiser_input(&self, _frame: Option<u32>, _input: &rt_temporal::TemporalFrame<'_>) {}
    /// An image (or a part, or a frame of a sequence) was written, or handed to
    /// [`JobSink::image`].
    fn frame(&self, _report: &FrameReport) {}
}

/// A sink that ignores everything.
impl JobSink for () {}

/// What an adaptive render did, in short.
#[derive(Clone, Debug, PartialEq)]
pub struct AdaptiveSummary {
    /// Why it stopped.
    pub reason: StopReason,
    /// Samples per pixel of the pixels that sampled longest.
    pub spp: u32,
    /// Blocks still sampling.
    pub blocks_left: usize,
    /// Time spent deciding.
    pub decisions: Duration,
}

impl From<&Adaptive> for AdaptiveSummary {
    fn from(a: &Adaptive) -> Self {
        Self {
            reason: a.reason,
            spp: a.spp,
            blocks_left: a.active_blocks.len(),
            decisions: a.decisions,
        }
    }
}

/// GREE's account of one image: the budget's split, the stages' times and each filter's
/// share of the pixels.
#[derive(Clone, Debug, PartialEq)]
pub struct GreeSummary {
    /// Samples of N per pixel.
    pub n: u32,
    /// Caches placed.
    pub caches: usize,
    /// Samples per cache pixel.
    pub c: u32,
    /// Cache sparsity.
    pub sparsity: f32,
    /// Samples traced in all (N and caches).
    pub samples: u64,
    /// Rendering N.
    pub render: Duration,
    /// Rendering the caches.
    pub cache_render: Duration,
    /// GREE's own stages: placement, errors, interpolation, graph cut, fusion.
    pub stages: [Duration; 5],
    /// The bank's filters: name, share of the pixels, time.
    pub filters: Vec<(String, f64, Duration)>,
    /// Print the filters' colours (the label image was written).
    pub legend: bool,
}

impl GreeSummary {
    /// The summary of `run` with the bank's member `names`.
    pub fn of(run: &GreeRun, names: &[&str], legend: bool) -> Self {
        let (w, h) = run.frame.colour.size();
        let pixels = (w * h).max(1) as f64;
        let mut share = vec![0usize; names.len()];
        for &l in &run.composite.labels {
            share[l as usize] += 1;
        }
        let t = &run.composite.timings;
        Self {
            n: run.budget.n,
            caches: run.composite.caches.len(),
            c: run.budget.c,
            sparsity: run.budget.sparsity,
            samples: run.samples_traced(),
            render: run.render.elapsed,
            cache_render: run.caches.elapsed,
            stages: [
                t.placement,
                t.errors,
                t.interpolation,
                t.graph_cut,
                t.fusion,
            ],
            filters: names
                .iter()
                .enumerate()
                .map(|(i, n)| (n.to_string(), share[i] as f64 / pixels, run.bank.times[i]))
                .collect(),
            legend,
        }
    }
}

/// What kind of image a frame report is about.
#[derive(Clone, Debug, PartialEq)]
#[non_exhaustive]
pub enum Rendered {
    /// An image of `spp` samples per pixel, or an adaptive render's.
    Image {
        /// How an adaptive render stopped (`None`: a fixed sample count).
        adaptive: Option<AdaptiveSummary>,
    },
    /// An image denoised before it was written.
    Denoised {
        /// The denoiser's name.
        denoiser: String,
        /// Its time.
        time: Duration,
    },
    /// A part file.
    Part {
        /// Its sample indices.
        samples: Range<u32>,
        /// Its pixels.
        region: Rect,
    },
    /// An image denoised by GREE.
    Gree(Box<GreeSummary>),
    /// A frame of a temporally denoised sequence.
    Sequence {
        /// The denoiser's name.
        denoiser: String,
        /// The stages' times.
        times: FrameTimes,
    },
}

/// One image written by a job.
#[derive(Clone, Debug)]
pub struct FrameReport {
    /// The scene file, as the job names it.
    pub scene: PathBuf,
    /// The frame, for a sequence or a frame of one.
    pub frame: Option<u32>,
    /// The file written.
    pub output: PathBuf,
    /// Image width.
    pub width: u32,
    /// Image height.
    pub height: u32,
    /// Samples per pixel of the render (the cap of an adaptive one).
    pub spp: u32,
    /// The technique's name.
    pub technique: String,
    /// The structure's spec.
    pub accel: String,
    /// The structure's name.
    pub accel_name: String,
    /// Triangles of the scene.
    pub triangles: usize,
    /// Worker threads.
    pub threads: usize,
    /// Loading the scene (the first frame's report only).
    pub load: Duration,
    /// Building or updating the structure.
    pub build: Duration,
    /// Samples, rays and time of the render.
    pub stats: RenderStats,
    /// What was written.
    pub rendered: Rendered,
    /// The stages of the render, what was built and skipped (`render --stats`), for images.
    pub stages: Option<RenderReport>,
}

/// What a finished job did.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct JobReport {
    /// Images written.
    pub frames: usize,
    /// Wall-clock time of the frames (without loading the scene).
    pub elapsed: Duration,
    /// True for a temporally denoised sequence.
    pub temporal: bool,
}

impl fmt::Display for JobReport {
    /// For a temporal sequence of several frames, `N frames in S s (F frames per second)`;
    /// nothing otherwise.
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        if self.temporal && self.frames > 1 {
            let secs = self.elapsed.as_secs_f64();
            write!(
                f,
                "{} frames in {secs:.2} s ({:.2} frames per second)",
                self.frames,
                self.frames as f64 / secs.max(1e-9)
            )?;
        }
        Ok(())
    }
}

impl fmt::Display for FrameReport {
    /// The summary line (GREE: and a line per filter).
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let scene = self.scene.display();
        let out = self.output.display();
        let (w, h) = (self.width, self.height);
        let s = &self.stats;
        let secs = s.elapsed.as_secs_f64();
        match &self.rendered {
            Rendered::Part { samples, region } => write!(
                f,
                "{scene}: samples {}..{} of pixels {region} ({} {}, {secs:.2} s render, {} invalid samples discarded) -> {out}",
                samples.start, samples.end, self.technique, self.accel, s.discarded
            ),
            Rendered::Denoised { denoiser, time } => write!(
                f,
                "{scene}: {w}x{h} {} spp {} ({secs:.2} s render), denoised by {denoiser} in {:.3} s -> {out}",
                s.samples / (u64::from(w) * u64::from(h)).max(1),
                self.technique,
                time.as_secs_f64()
            ),
            Rendered::Sequence { denoiser, times } => write!(
                f,
                "{scene}: frame {}: {w}x{h} {} spp {}, {:.3} s render, {:.3} s guides, {:.3} s {denoiser}, {:.3} s update -> {out}",
                self.frame.unwrap_or(0),
                self.spp,
                self.technique,
                times.render.as_secs_f64(),
                times.guides.as_secs_f64(),
                times.denoise.as_secs_f64(),
                times.update.as_secs_f64(),
            ),
            Rendered::Gree(g) => {
                let bank: f64 = g.filters.iter().map(|(_, _, t)| t.as_secs_f64()).sum();
                let st = g.stages.map(|d| d.as_secs_f64());
                let own: f64 = st.iter().sum();
                write!(
                    f,
                    "{scene}: {w}x{h} GREE b={} (n={} spp, {} caches x {} spp, s={}): {} samples traced ({:.2} spp), {secs:.2} s render, {:.2} s caches, {bank:.2} s bank ({} filters), {own:.3} s GREE (placement {:.3}, errors {:.3}, interpolation {:.3}, graph cut {:.3}, fusion {:.3}; {:.1} % of denoising) -> {out}",
                    self.spp,
                    g.n,
                    g.caches,
                    g.c,
                    g.sparsity,
                    g.samples,
                    g.samples as f64 / f64::from(w * h).max(1.0),
                    g.cache_render.as_secs_f64(),
                    g.filters.len(),
                    st[0],
                    st[1],
                    st[2],
                    st[3],
                    st[4],
                    100.0 * own / (own + bank).max(1e-12),
                )?;
                for (i, (name, share, time)) in g.filters.iter().enumerate() {
                    let hex = if g.legend {
                        let c = crate::gree::label_colour(i as u16)
                            .to_array()
                            .map(rt_core::color::linear_to_srgb);
                        format!(
                            " #{:02x}{:02x}{:02x}",
                            (c[0] * 255.0) as u8,
                            (c[1] * 255.0) as u8,
                            (c[2] * 255.0) as u8
                        )
                    } else {
                        String::new()
                    };
                    write!(
                        f,
                        "\n  label {i:2}{hex} {name}: {:.1} % of pixels, {:.3} s",
                        100.0 * share,
                        time.as_secs_f64()
                    )?;
                }
                Ok(())
            }
            Rendered::Image { adaptive } => {
                let sampling = match adaptive {
                    None => format!("{} spp", self.spp),
                    Some(a) => format!(
                        "adaptive: {} after {} spp, {} samples, {} blocks left, {:.3} s deciding;",
                        a.reason,
                        a.spp,
                        s.samples,
                        a.blocks_left,
                        a.decisions.as_secs_f64()
                    ),
                };
                // Discarded samples are always printed, zero included: a valid scene must
                // discard nothing, and a reader should not have to know that silence means
                // zero.
                write!(
                    f,
                    "{scene}: {w}x{h} {sampling} {} {} ({} tris, {} threads): {secs:.2} s render ({:.2} s load, {:.2} s {} build), \
                     {:.2} Msamples/s, {:.2} Mrays/s, {} invalid samples discarded -> {out}",
                    self.technique,
                    self.accel,
                    self.triangles,
                    self.threads,
                    self.load.as_secs_f64(),
                    self.build.as_secs_f64(),
                    self.accel_name,
                    s.samples_per_second() / 1e6,
                    s.rays_per_second() / 1e6,
                    s.discarded,
                )
            }
        }
    }
}
