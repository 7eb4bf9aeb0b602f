//! High-sample references to measure other renders against.
//!
//! A reference draws its samples from the reference family of streams
//! (`rt_core::SampleStream::Reference`), which no normal render uses whatever its seed, so its
//! noise is independent of the noise of any image it is compared with. [`obtain`] takes it from
//! the [`Cache`] or renders it (and stores it there); experiments go through the same cache.

use crate::cache::{Cache, Key, ReferenceRequest, Sidecar};
use crate::error::{ExperimentError, Result};
use rt_core::{Accel, SampleStream};
use rt_film::{AovSet, Film};
use rt_integrators::Ctx;
use rt_session::{Budgets, Checkpoint, Session};
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

/// Finds `req` in `cache` or renders it (with `accel`) and stores it there. With no cache, the
/// reference is rendered and written to `write_to`. Call inside the thread pool to use.
pub fn obtain(
    req: &ReferenceRequest<'_>,
    accel: &dyn Accel,
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
    let (film, at) = render(req, accel, progress)?;
    let sidecar = Sidecar {
        key: key.hex.clone(),
        description: key.description.clone(),
        scene: req.scene_path.display().to_string(),
        width: req.camera.width,
        height: req.camera.height,
        spp: req.spp,
        seconds: at.seconds,
        samples_per_second: at.samples as f64 / at.seconds.max(1e-9),
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
        seconds: at.seconds,
    })
}

/// Renders the reference: the reference stream, the variance AOV kept where the film knows
/// it. A technique that splats (bdpt, light; the reference for caustics that camera paths
/// rarely find) has no per-pixel variance, so its reference has no noise floor.
fn render(
    req: &ReferenceRequest<'_>,
    accel: &dyn Accel,
    progress: &(dyn Fn(f64) + Sync),
) -> Result<(Film, Checkpoint)> {
    let integrator = req.estimator.build();
    let session = Session {
        ctx: Ctx {
            scene: req.scene,
            accel,
            camera: req.camera,
        },
        integrator: integrator.as_ref(),
        seed: req.seed,
        stream: SampleStream::Reference,
        aovs: AovSet {
            variance: !req.estimator.kind.splats(),
            ..AovSet::default()
        },
    };
    let mut last = Checkpoint::default();
    let film = session.render(&Budgets::Spp(vec![req.spp]), progress, &mut |_, at| {
        last = *at;
        Ok::<(), std::convert::Infallible>(())
    });
    let Ok(film) = film;
    Ok((film, last))
}
