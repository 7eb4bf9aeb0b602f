//! High-sample references to measure other renders against.
//!
//! A reference draws its samples from the reference family of streams
//! (`rt_core::SampleStream::Reference`), which no normal render uses whatever its seed, so its
//! noise is independent of the noise of any image it is compared with. [`obtain`] takes it from
//! the [`Cache`] or renders it (and stores it there); experiments go through the same cache.

use crate::cache::{Cache, Key, ReferenceRequest, Sidecar};
use crate::error::{ExperimentError, Result};
use rt_accel::AccelSpec;
use rt_core::Accel;
use rt_film::{AovSet, Film};
use rt_integrators::{Ctx, RenderStats};
use rt_session::{RenderJob, Settings, Stream};
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

/// The render job of the reference `req` with `key` (its cache key, which part headers
/// carry so that the merged parts are stored under it), over `accel`, written to `output`:
/// the reference stream, the camera at the request's size, the variance AOV kept where the
/// film knows it. A technique that splats (bdpt, light; the reference for caustics that
/// camera paths rarely find) has no per-pixel variance, so its reference has no noise floor.
pub fn job(req: &ReferenceRequest<'_>, accel: AccelSpec, key: &Key, output: &Path) -> RenderJob {
    let settings = Settings {
        integrator: req.estimator,
        accel,
        spp: req.spp,
        threads: None,
        seed: req.seed,
        aovs: AovSet {
            variance: !req.estimator.build().splats(),
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
    let (film, stats) = render(&job, req, accel, progress)?;
    let seconds = stats.elapsed.as_secs_f64();
    let sidecar = Sidecar {
        key: key.hex.clone(),
        description: key.description.clone(),
        scene: req.scene_path.display().to_string(),
        width: req.camera.width,
        height: req.camera.height,
        spp: req.spp,
        seconds,
        samples_per_second: stats.samples as f64 / seconds.max(1e-9),
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

/// Reports a job's progress to a closure.
struct Progress<'a>(&'a (dyn Fn(f64) + Sync));

impl rt_session::JobSink for Progress<'_> {
    fn progress(&self, done: f64) {
        (self.0)(done)
    }
}

/// Renders the reference job over the request's scene and camera.
fn render(
    job: &RenderJob,
    req: &ReferenceRequest<'_>,
    accel: &dyn Accel,
    progress: &(dyn Fn(f64) + Sync),
) -> Result<(Film, RenderStats)> {
    let ctx = Ctx {
        scene: req.scene,
        accel,
        camera: req.camera,
    };
    let technique = job.settings.integrator.build();
    job.render_film(&ctx, technique.as_ref(), &Progress(progress))
        .map_err(|e| ExperimentError::Run(e.to_string()))
}
