//! Part files merged into what the whole render would have written: an image
//! (`rt_session::job::merge`) or, for the parts of a reference, the reference cache's entry
//! ([`Cache::store_parts`]); [`merge_plan`] merges every output of a plan.

use crate::cache::{Cache, Sidecar};
use crate::error::Result;
use std::fmt;
use std::path::{Path, PathBuf};
use std::time::Instant;

/// What a merge wrote.
pub enum Merged {
    /// An image.
    Image {
        /// What was merged.
        report: rt_session::job::MergeReport,
        /// The image written.
        output: PathBuf,
        /// Time taken by the merge.
        seconds: f64,
    },
    /// A reference, stored in the cache.
    Reference {
        /// Parts merged.
        parts: usize,
        /// The cache entry.
        path: PathBuf,
        /// Its sidecar.
        sidecar: Sidecar,
    },
}

impl fmt::Display for Merged {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Merged::Image {
                report,
                output,
                seconds,
            } => write!(f, "{report} in {seconds:.2} s -> {}", output.display()),
            Merged::Reference {
                parts,
                path,
                sidecar: s,
            } => write!(
                f,
                "merged {parts} parts of the reference of {} ({}x{}, {} spp, {:.1} s of rendering) -> {}",
                s.scene,
                s.width,
                s.height,
                s.spp,
                s.seconds,
                path.display()
            ),
        }
    }
}

/// Merges `files` into `output` (or, `into_cache`, into the reference cache directory
/// `output`, where `render reference` and experiments find it), refusing a film larger than
/// `limit` bytes.
pub fn merge_files(
    files: &[PathBuf],
    output: &Path,
    into_cache: bool,
    limit: Option<u64>,
) -> Result<Merged> {
    let parts = rt_session::job::read_parts(files)?;
    let t = Instant::now();
    if into_cache {
        let (path, sidecar) = Cache::new(output).store_parts(&parts, limit)?;
        return Ok(Merged::Reference {
            parts: parts.len(),
            path,
            sidecar,
        });
    }
    let report = rt_session::job::merge(&parts, output, limit)?;
    Ok(Merged::Image {
        report,
        output: output.to_path_buf(),
        seconds: t.elapsed().as_secs_f64(),
    })
}

/// Merges every output of `plan` from the parts in `dir`, handing each result to `each`.
pub fn merge_plan(
    plan: &rt_parts::Plan,
    dir: &Path,
    limit: Option<u64>,
    each: &mut dyn FnMut(&Merged),
) -> Result<()> {
    for out in &plan.outputs {
        let files: Vec<PathBuf> = out
            .parts
            .iter()
            .map(|&i| dir.join(&plan.parts[i].file))
            .collect();
        each(&merge_files(
            &files,
            Path::new(&out.output),
            out.into_cache,
            limit,
        )?);
    }
    Ok(())
}
