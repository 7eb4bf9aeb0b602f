//! A job rendered into a film the caller keeps, for callers that hold their own scene,
//! structure and camera (an experiment's methods and references): [`RenderJob::render_stops`]
//! hands the film to the caller at each stop ([`FilmStop`]): at every budget of a progressive
//! render, or once at the end of a fixed or adaptive one. No file is written.

use super::parts::Cut;
use super::report::{AdaptiveSummary, JobSink};
use super::{JobError, RenderJob};
use crate::{render_adaptive, Budgets, Checkpoint, Session};
use rt_film::{Film, Rect};
use rt_integrators::{Ctx, RenderStats, Technique};

/// Where a job rendered into a film stands at one of its stops: what the caller records
/// (an experiment's row), with the film as it is then.
pub struct FilmStop<'a> {
    /// The film so far.
    pub film: &'a Film,
    /// The index of the budget reached (0 for a fixed or adaptive job), the samples per pixel
    /// (for an adaptive job: of the pixels that sampled longest) and the time, samples and
    /// rays so far.
    pub at: Checkpoint,
    /// How an adaptive job stopped (`None` for a fixed or progressive one).
    pub adaptive: Option<AdaptiveSummary>,
}

/// The stop of one pass or adaptive render: budget 0, `spp` samples per pixel, `stats`.
fn checkpoint(spp: u32, stats: &RenderStats) -> Checkpoint {
    Checkpoint {
        budget: 0,
        spp,
        seconds: stats.elapsed.as_secs_f64(),
        samples: stats.samples,
        rays: stats.rays.rays + stats.rays.shadow_rays,
        discarded: stats.discarded,
    }
}

impl RenderJob {
    /// Renders this job's image of `ctx` with `technique` into one film, calls `each` at
    /// every stop and returns the film: with `budgets`, progressively to each of them (one
    /// film, pass after pass: a list of budgets costs only its largest, and the image at N spp
    /// is bit for bit a single N-spp render's; [`Session::render`]) instead of to
    /// `settings.spp`; else once, when the job's samples (or its slice's) or its adaptive
    /// render ([`RenderJob::stop`]) are done. Call it inside the thread pool that should do the
    /// work; the film keeps the job's AOVs and what its denoiser reads, and is not denoised.
    pub fn render_stops<E: From<JobError>>(
        &self,
        ctx: &Ctx<'_>,
        technique: &dyn Technique,
        budgets: Option<&Budgets>,
        sink: &dyn JobSink,
        each: &mut dyn FnMut(&FilmStop<'_>) -> Result<(), E>,
    ) -> Result<Film, E> {
        let (w, h) = (ctx.camera.width, ctx.camera.height);
        let denoiser = self.frame_denoiser()?;
        let buffers = self.film_buffers(denoiser.as_deref());
        let seed = self.settings.seed;
        match (budgets, &self.stop) {
            (Some(_), Some(_)) => Err(JobError::Refused(
                "a progressive render stops at its budgets: it cannot be adaptive (--error, --time-limit)".into(),
            )
            .into()),
            (Some(budgets), None) => {
                if !self.slice.is_whole() {
                    return Err(JobError::Refused(
                        "a progressive render renders the whole image: it cannot be a slice".into(),
                    )
                    .into());
                }
                let session = Session {
                    ctx: *ctx,
                    integrator: technique,
                    seed,
                    stream: self.stream.sample_stream(),
                    buffers,
                };
                session.render(budgets, &|f| sink.progress(f), &mut |film, at| {
                    each(&FilmStop {
                        film,
                        at: *at,
                        adaptive: None,
                    })
                })
            }
            (None, Some(rule)) => {
                let mut film = Film::new(w, h, buffers);
                let a = render_adaptive(ctx, technique, &mut film, seed, rule, &|f| {
                    sink.progress(f)
                })
                .map_err(|e| JobError::Refused(format!("--error {}", e.0)))?;
                each(&FilmStop {
                    film: &film,
                    at: checkpoint(a.spp, &a.stats),
                    adaptive: Some(AdaptiveSummary::from(&a)),
                })?;
                Ok(film)
            }
            (None, None) => {
                let mut film = Film::new(w, h, buffers);
                let cut = Cut {
                    samples: self.slice.samples.clone().unwrap_or(0..self.settings.spp),
                    region: self.slice.rect().unwrap_or(Rect::full(w, h)),
                };
                let stats = self.fixed_pass(ctx, technique, &mut film, seed, &cut, sink);
                each(&FilmStop {
                    film: &film,
                    at: checkpoint(cut.samples.len() as u32, &stats),
                    adaptive: None,
                })?;
                Ok(film)
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::{pick_camera, ImageSize, Overrides, Settings, StopReason, StopRule};
    use rt_core::Rgb;
    use std::path::Path;

    /// What a test keeps of a [`FilmStop`].
    #[derive(Debug)]
    struct Seen {
        image: Vec<Rgb>,
        budget: usize,
        spp: u32,
        adaptive: Option<AdaptiveSummary>,
    }

    #[test]
    fn a_progressive_job_stops_at_each_budget_with_the_bits_of_a_fixed_job() {
        let path = Path::new("gen:worst-case");
        let loaded = rt_scene::load_any(path).unwrap();
        let overrides = Overrides {
            spp: Some(3),
            aovs: Some(vec!["variance".into()]),
            ..Overrides::default()
        };
        let settings = overrides.resolve(&loaded, path).unwrap();
        let scene = &loaded.scene;
        let camera = ImageSize::Pixels(16, 12).apply(pick_camera(scene, path, None).unwrap());
        let accel = settings.accel.build(scene).unwrap();
        let ctx = Ctx {
            scene,
            accel: accel.as_ref(),
            camera: &camera,
        };
        let technique = settings.integrator.build();
        let job = RenderJob::new(path, settings);
        // Every stop of `job` over a 16x12 image of the worst-case scene.
        let render = |job: &RenderJob, budgets: Option<&Budgets>| -> Result<Vec<Seen>, JobError> {
            let mut seen = Vec::new();
            job.render_stops(&ctx, technique.as_ref(), budgets, &(), &mut |s| {
                seen.push(Seen {
                    image: s.film.mean_image(),
                    budget: s.at.budget,
                    spp: s.at.spp,
                    adaptive: s.adaptive.clone(),
                });
                Ok::<_, JobError>(())
            })?;
            Ok(seen)
        };
        let fixed = |spp| {
            let job = RenderJob {
                settings: Settings {
                    spp,
                    ..job.settings.clone()
                },
                ..job.clone()
            };
            let mut seen = render(&job, None).unwrap();
            assert_eq!(seen.len(), 1);
            seen.remove(0)
        };

        let progressive = render(&job, Some(&Budgets::Spp(vec![1, 3]))).unwrap();
        let at: Vec<(usize, u32)> = progressive.iter().map(|s| (s.budget, s.spp)).collect();
        assert_eq!(at, [(0, 1), (1, 3)]);
        for (stop, spp) in progressive.iter().zip([1, 3]) {
            let whole = fixed(spp);
            assert!(whole.spp == spp && whole.adaptive.is_none());
            assert!(whole.image == stop.image, "{spp} spp");
        }
        assert!(progressive[0].image != progressive[1].image);

        let adaptive = RenderJob {
            stop: Some(StopRule::new(None, None, 2).unwrap()),
            ..job.clone()
        };
        let seen = render(&adaptive, None).unwrap();
        let summary = seen[0].adaptive.as_ref().expect("it says how it stopped");
        assert_eq!((seen.len(), seen[0].spp), (1, 2));
        assert_eq!((summary.reason, summary.spp), (StopReason::SampleCap, 2));
        assert!(seen[0].image == fixed(2).image);
        let e = render(&adaptive, Some(&Budgets::Spp(vec![1]))).unwrap_err();
        assert!(e.to_string().contains("cannot be adaptive"), "{e}");
    }
}
