//! High-sample references to measure other renders against.
//!
//! A reference draws its samples from the reference family of streams
//! (`rt_core::SampleStream::Reference`), which no normal render uses whatever its seed, so its
//! noise is independent of the noise of any image it is compared with. [`obtain`] takes it from
//! the [`Cache`] or renders it (and stores it there); experiments go through the same cache.

use crate::cache::{Cache, Key, ReferenceRequest, Sidecar};
use crate::error::{ExperimentError, Result};
use crate::ProgressSink;
use rt_accel::AccelSpec;
use rt_core::Accel;
use rt_film::{AovSet, Film};
use rt_integrators::Ctx;
use rt_session::{Checkpoint, RenderJob, Settings, Stream};
use std::path::{Path, PathBuf};

/// A reference ready to use.
pub struct Obtained {
    /// The EXR (in the cache, or wherever it was written).
    pub path: PathBuf,
    /// True if it came from the cache.
    pub cached: bool,
    /// Render time (of the original render when cached).
    pub seconds: f64,
}

/// What a reference of one loaded scene renders, resolved from the scene's `[render]` table
/// and the caller's overrides (what `render reference` asks for).
pub struct Order {
    /// The camera, resized.
    pub camera: rt_core::Camera,
    /// The integrator: one that keeps per-pixel variance (camera rays only).
    pub estimator: rt_integrators::IntegratorSpec,
    /// The structure (the scene's default unless overridden).
    pub accel: AccelSpec,
    /// Samples per pixel.
    pub spp: u32,
    /// Seed of the reference stream.
    pub seed: u32,
}

impl Order {
    /// The reference of `loaded` (read from `scene_path`) through `camera` (the first by
    /// default) at `size`, with `spp` samples. A technique that splats is refused: it keeps no
    /// per-pixel variance.
    pub fn new(
        scene_path: &Path,
        loaded: &rt_scene::LoadedScene,
        overrides: &rt_session::Overrides,
        camera: Option<&str>,
        size: rt_session::ImageSize,
        spp: u32,
    ) -> Result<Self> {
        let estimator = overrides.integrator_spec(&loaded.render, scene_path)?;
        if estimator.build().splats() {
            return Err(ExperimentError::Run(format!(
                "{}: integrator `{}` splats light paths and keeps no per-pixel variance; render references with a camera-ray integrator (wavefront, path, path-bsdf, direct, ao)",
                scene_path.display(),
                estimator.kind
            )));
        }
        let accel = overrides.accel_spec(loaded, scene_path)?;
        let camera = size.apply(rt_session::pick_camera(&loaded.scene, scene_path, camera)?);
        Ok(Self {
            camera,
            estimator,
            accel,
            spp,
            seed: overrides.seed(&loaded.render),
        })
    }

    /// The cache's request for this reference of `scene` (loaded from `scene_path`).
    pub fn request<'a>(
        &'a self,
        scene_path: &'a Path,
        scene: &'a rt_core::Scene,
    ) -> ReferenceRequest<'a> {
        ReferenceRequest {
            scene_path,
            scene,
            camera: &self.camera,
            estimator: self.estimator,
            spp: self.spp,
            seed: self.seed,
        }
    }

    /// The job of a slice of this reference, written as the part file `output` whose header
    /// carries the cache key (for `render merge --plan` to store the merged parts under).
    pub fn part_job(
        &self,
        scene_path: &Path,
        scene: &rt_core::Scene,
        output: &Path,
    ) -> Result<RenderJob> {
        let req = self.request(scene_path, scene);
        Ok(job(&req, self.accel, &req.key()?, output))
    }

    /// The reference from `cache` or rendered ([`obtain`]); call inside the thread pool to
    /// use.
    pub fn obtain(
        &self,
        scene_path: &Path,
        scene: &rt_core::Scene,
        cache: Option<&Cache>,
        write_to: Option<&Path>,
        progress: &(dyn Fn(f64) + Sync),
    ) -> Result<Obtained> {
        let accel = self.accel.build(scene).map_err(|e| {
            ExperimentError::Run(format!("{}: {}: {e}", scene_path.display(), self.accel))
        })?;
        let req = self.request(scene_path, scene);
        obtain(
            &req,
            (&self.accel, accel.as_ref()),
            cache,
            write_to,
            progress,
        )
    }

    /// One line on where `obtained` came from.
    pub fn describe(&self, obtained: &Obtained) -> String {
        let (path, seconds) = (obtained.path.display(), obtained.seconds);
        if obtained.cached {
            format!("reference: cached {path} ({seconds:.1} s when rendered)")
        } else {
            let (w, h) = (self.camera.width, self.camera.height);
            let spp = self.spp;
            format!("reference: rendered {w}x{h} at {spp} spp in {seconds:.1} s -> {path}")
        }
    }
}

/// The render job of the reference `req` with `key` (its cache key, which part headers
/// carry so that the merged parts are stored under it), over `accel`, written to `output`:
/// the reference stream, the camera at the request's size, the variance AOV kept where the
/// film knows it. A technique that splats (bdpt, light; the reference for caustics that
/// camera paths rarely find) has no per-pixel variance, so its reference has no noise floor;
/// nor has a camera that splats its pixel filter (Mitsuba scene files' Gaussian).
pub fn job(req: &ReferenceRequest<'_>, accel: AccelSpec, key: &Key, output: &Path) -> RenderJob {
    let settings = Settings {
        integrator: req.estimator,
        accel,
        spp: req.spp,
        threads: None,
        seed: req.seed,
        aovs: AovSet {
            // Neither light-path nor filter splats leave a pixel its own samples.
            variance: !req.estimator.build().splats() && !req.camera.filter.splats(),
            ..AovSet::default()
        },
        output: Some(output.to_path_buf()),
        denoiser: None,
    };
    let mut job = RenderJob::new(req.scene_path, settings);
    job.camera = Some(req.camera.name.clone());
    job.size = rt_session::ImageSize::Pixels(req.camera.width, req.camera.height);
    job.stream = Stream::Reference;
    job.labels.insert("cache key".into(), key.hex.clone());
    job.labels
        .insert("cache description".into(), key.description.clone());
    job
}

/// The references `plan` renders, each a reference job (confined to `confine`) cut into
/// `tile`s and `sample_splits` sample ranges and merged into the cache `cache`, where the
/// experiment then finds them; what `render plan --experiment` writes. Sequence scenes (one
/// reference per frame) are refused for now.
pub fn plan_requests(
    plan: &crate::Plan,
    cache: &Path,
    confine: Option<&Path>,
    tile: Option<(u32, u32)>,
    sample_splits: u32,
) -> Result<Vec<rt_parts::PlanRequest>> {
    let mut requests = Vec::new();
    for scene in &plan.scenes {
        let crate::config::ReferencePlan::Render {
            spp,
            estimator,
            seed,
            accel,
        } = &scene.reference
        else {
            continue;
        };
        let req = scene.reference_request(*estimator, *spp, *seed);
        if scene.sequence.is_some() {
            return Err(ExperimentError::Config {
                file: plan.path.clone(),
                message: format!(
                    "scene {}: the per-frame references of a sequence are not plannable yet",
                    scene.name
                ),
            });
        }
        let mut job = job(&req, *accel, &req.key()?, cache);
        job.confine = confine.map(Path::to_path_buf);
        requests.push(rt_parts::PlanRequest {
            render: rt_parts::PlannedRender {
                job: job.to_json(),
                width: scene.camera.width,
                height: scene.camera.height,
                spp: req.spp,
            },
            into_cache: true,
            frames: vec![(None, cache.display().to_string())],
            tile,
            sample_splits,
        });
    }
    if requests.is_empty() {
        return Err(ExperimentError::Config {
            file: plan.path.clone(),
            message: "the experiment renders no reference".into(),
        });
    }
    Ok(requests)
}

/// Finds `req` in `cache` or renders it (with `accel`, built from `accel_spec`) and stores it
/// there. With no cache, the reference is rendered and written to `write_to`. Call inside the
/// thread pool to use.
pub fn obtain(
    req: &ReferenceRequest<'_>,
    (accel_spec, accel): (&AccelSpec, &dyn Accel),
    cache: Option<&Cache>,
    write_to: Option<&Path>,
    progress: &(dyn Fn(f64) + Sync),
) -> Result<Obtained> {
    let key: Key = req.key()?;
    if let Some(cache) = cache {
        if let Some((path, sidecar)) = cache.lookup(req.scene_path, &key) {
            return Ok(Obtained {
                path,
                cached: true,
                seconds: sidecar.seconds,
            });
        }
    }
    let out = write_to.unwrap_or(Path::new("reference.exr"));
    let job = job(req, *accel_spec, &key, out);
    let (film, done) = render(&job, req, accel, progress)?;
    let seconds = done.seconds;
    let sidecar = Sidecar {
        key: key.hex.clone(),
        description: key.description.clone(),
        scene: req.scene_path.display().to_string(),
        width: req.camera.width,
        height: req.camera.height,
        spp: req.spp,
        seconds,
        samples_per_second: done.samples as f64 / seconds.max(1e-9),
    };
    let path = match (cache, write_to) {
        (Some(cache), _) => cache.store(req.scene_path, &key, &film, &sidecar)?,
        (None, Some(out)) => {
            rt_film::write_image(out, &film, &rt_film::OutputOptions::default())?;
            out.to_path_buf()
        }
        (None, None) => {
            return Err(ExperimentError::Run(
                "a reference needs a cache or an output file".into(),
            ))
        }
    };
    Ok(Obtained {
        path,
        cached: false,
        seconds,
    })
}

/// Renders the reference job over the request's scene and camera: the film and what it took.
fn render(
    job: &RenderJob,
    req: &ReferenceRequest<'_>,
    accel: &dyn Accel,
    progress: &(dyn Fn(f64) + Sync),
) -> Result<(Film, Checkpoint)> {
    let ctx = Ctx {
        scene: req.scene,
        accel,
        camera: req.camera,
    };
    let technique = job.settings.integrator.build();
    let mut done = Checkpoint::default();
    let film = job.render_stops(
        &ctx,
        technique.as_ref(),
        None,
        &ProgressSink(progress),
        &mut |stop| -> Result<()> {
            done = stop.at;
            Ok(())
        },
    )?;
    Ok((film, done))
}
