//! A job's part files and checkpoints (`rt-parts` holds the format and the exact merge): the
//! header of a slice, writing and restoring, and merging parts into the image the whole job
//! would have written.

use super::{extension, refuse, JobError, RenderJob};
use rt_film::{AovSet, Film, OutputOptions, Rect};
use rt_parts::{Part, PartHeader, PartKind};
use std::ops::Range;
use std::path::{Path, PathBuf};

/// The samples and pixels a render computes.
#[derive(Clone, Debug)]
pub(crate) struct Cut {
    /// Sample indices.
    pub samples: Range<u32>,
    /// Pixels.
    pub region: Rect,
}

impl Cut {
    /// The pixels to render, `None` for all of them.
    pub fn mask(&self, width: u32, height: u32) -> Option<std::sync::Arc<[bool]>> {
        if self.region == Rect::full(width, height) {
            return None;
        }
        Some(
            (0..height)
                .flat_map(|y| (0..width).map(move |x| self.region.contains(x, y)))
                .collect(),
        )
    }
}

impl RenderJob {
    /// The slice a part renders (`None` for a job that writes an image), refusing what a part
    /// cannot hold or what would not merge exactly, with one line each.
    pub(crate) fn cut(
        &self,
        width: u32,
        height: u32,
        film: &Film,
    ) -> Result<Option<Cut>, JobError> {
        if !self.writes_part() {
            return Ok(None);
        }
        let out = self.output.display();
        let cannot =
            |what: &str, why: &str| refuse(format!("{out}: a part file cannot hold {what}: {why}"));
        if self.stop.is_some() {
            return cannot(
                "an adaptive render (--error, --time-limit)",
                "the stopping criterion decides on the whole image; render parts with a fixed --spp and merge",
            );
        }
        if self.gree.is_some() {
            return cannot("GREE", "its filter caches need the whole noisy image");
        }
        if self.cache.is_some() {
            return cannot(
                "a world-space cache",
                "the cache carries light from one sample to the next",
            );
        }
        if film.buffers().samples {
            return cannot(
                "per-sample records (--denoiser sbmf)",
                "denoise after merging with a pixel-space denoiser",
            );
        }
        if self.settings.aovs.blocks {
            return cannot("--aov blocks", "it needs --error");
        }
        let spp = self.settings.spp;
        let samples = self.slice.samples.clone().unwrap_or(0..spp);
        if samples.end > spp || samples.start >= samples.end {
            return refuse(format!(
                "--sample-range {}..{}: the render takes samples 0..{spp} (--spp)",
                samples.start, samples.end
            ));
        }
        let region = self.slice.rect().unwrap_or(Rect::full(width, height));
        if !region.is_inside(width, height) {
            return refuse(format!(
                "--region {region}: outside the {width}x{height} image"
            ));
        }
        Ok(Some(Cut { samples, region }))
    }

    /// The header of a part or checkpoint of this job holding `cut` of `film`.
    pub(crate) fn header(
        &self,
        film: &Film,
        cut: &Cut,
        camera: &str,
        scene_hash: &str,
        frame: Option<u32>,
        kind: PartKind,
    ) -> PartHeader {
        let b = film.buffers();
        PartHeader {
            format: rt_parts::FORMAT,
            kind,
            binary: rt_parts::binary_id(env!("CARGO_PKG_VERSION")),
            scene: self.scene.display().to_string(),
            scene_hash: scene_hash.to_string(),
            settings: self.identity(camera),
            frame,
            width: film.width(),
            height: film.height(),
            spp: self.settings.spp,
            region: [cut.region.x0, cut.region.y0, cut.region.x1, cut.region.y1],
            samples: [cut.samples.start, cut.samples.end],
            aovs: b.aovs.names().into_iter().map(str::to_string).collect(),
            variance: b.variance,
            halves: b.halves,
            job: self.to_json(),
            seconds: 0.0,
        }
    }
}

/// Where a checkpointed render writes, and what it resumes from.
pub(crate) struct Checkpointer<'a> {
    pub job: &'a RenderJob,
    pub camera: &'a str,
    pub scene_hash: &'a str,
    pub frame: Option<u32>,
}

impl Checkpointer<'_> {
    /// The checkpoint of a film holding samples `0..samples` of every pixel.
    pub fn part(&self, film: &Film, samples: u32) -> Part {
        let full = Rect::full(film.width(), film.height());
        let cut = Cut {
            samples: 0..samples,
            region: full,
        };
        Part {
            header: self.job.header(
                film,
                &cut,
                self.camera,
                self.scene_hash,
                self.frame,
                PartKind::Checkpoint,
            ),
            sums: film.encode_sums(full),
        }
    }

    /// Writes the checkpoint of samples `0..samples`, `seconds` of rendering.
    pub fn write(&self, film: &Film, samples: u32, seconds: f64) -> Result<(), JobError> {
        let path = &self.job.checkpoint.as_ref().expect("checkpointing").path;
        let mut part = self.part(film, samples);
        part.header.seconds = seconds;
        part.write(path)
            .map_err(|e| JobError::Failed(format!("--checkpoint {}: {e}", path.display())))
    }

    /// Starts `film` from the checkpoint at `path` after checking that it belongs to this
    /// render; returns the next sample index and the seconds rendered so far.
    pub fn restore(&self, path: &Path, film: &mut Film) -> Result<(u32, f64), JobError> {
        let name = path.display().to_string();
        let part = Part::read(path).map_err(|e| JobError::Refused(format!("{name}: {e}")))?;
        let fresh = self.part(film, 1);
        rt_parts::check_belongs((&name, &part.header), ("this render", &fresh.header))
            .map_err(|e| JobError::Refused(format!("--resume: {e}")))?;
        let full = Rect::full(film.width(), film.height());
        film.add_encoded(full, &part.sums, true)
            .map_err(|e| JobError::Refused(format!("--resume {name}: {e}")))?;
        Ok((part.header.samples[1], part.header.seconds))
    }
}

/// Reads part files (checkpoints are refused: they are resumed, not merged), each named by
/// its path for messages.
pub fn read_parts(files: &[PathBuf]) -> Result<Vec<(String, Part)>, JobError> {
    let mut parts = Vec::with_capacity(files.len());
    for f in files {
        let p = Part::read(f).map_err(|e| JobError::Refused(format!("{}: {e}", f.display())))?;
        if p.header.kind != PartKind::Part {
            return refuse(format!(
                "{}: a checkpoint, not a part: continue it with render --resume",
                f.display()
            ));
        }
        parts.push((f.display().to_string(), p));
    }
    Ok(parts)
}

/// What a merge wrote.
#[derive(Clone, Debug, PartialEq)]
pub struct MergeReport {
    /// Parts merged.
    pub parts: usize,
    /// Sample ranges among them.
    pub ranges: usize,
    /// The scene, as the parts name it.
    pub scene: String,
    /// Image width.
    pub width: u32,
    /// Image height.
    pub height: u32,
    /// Samples per pixel.
    pub spp: u32,
}

impl std::fmt::Display for MergeReport {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(
            f,
            "merged {} parts ({} sample ranges) of {} ({}x{}, {} spp)",
            self.parts, self.ranges, self.scene, self.width, self.height, self.spp
        )
    }
}

/// Merges `parts` into `output` (`.exr` or `.png`): the image the whole job would have
/// written, bit for bit, denoised first if the job has a denoiser. `limit`: the most bytes the
/// merged film may hold.
pub fn merge(
    parts: &[(String, Part)],
    output: &Path,
    limit: Option<u64>,
) -> Result<MergeReport, JobError> {
    match extension(output).as_deref() {
        Some("exr" | "png") => {}
        _ => {
            return refuse(format!(
                "{}: the merged image must end in .exr or .png",
                output.display()
            ))
        }
    }
    let mut merged = rt_parts::merge(parts, limit).map_err(|e| JobError::Refused(e.to_string()))?;
    let h = &merged.header;
    let job = RenderJob::from_json(&h.job)
        .map_err(|e| JobError::Format(format!("{}: {e}", parts[0].0)))?;
    match &job.settings.denoiser {
        Some(d) if !d.is_temporal() => {
            let rt_temporal::TemporalSpec::PerFrame(spec) = d else {
                unreachable!("not temporal")
            };
            let built = spec
                .build()
                .map_err(|e| JobError::Refused(format!("--denoiser {spec}: {e}")))?;
            let image = denoise_film(&mut merged.film, built.as_ref(), &job.scene, &(), None)?;
            let opts = OutputOptions {
                exposure: job.exposure,
            };
            rt_film::write_rgb(output, &image, &opts)
                .map_err(|e| JobError::Failed(e.to_string()))?;
        }
        _ => {
            if extension(output).as_deref() == Some("png") && !h.aovs.is_empty() {
                return refuse(format!(
                    "{}: the parts hold AOVs, which need an .exr output",
                    output.display()
                ));
            }
            rt_film::write_image_with(
                output,
                &merged.film,
                &OutputOptions {
                    exposure: job.exposure,
                },
                &[],
            )
            .map_err(|e| JobError::Failed(e.to_string()))?;
        }
    }
    Ok(MergeReport {
        parts: parts.len(),
        ranges: merged.ranges.len(),
        scene: h.scene.clone(),
        width: h.width,
        height: h.height,
        spp: h.spp,
    })
}

/// The film denoised by `d` (taking its sample records): the end of a job with a denoiser,
/// and of a merge of one. `sink` sees the denoiser's input first, as that of `frame`.
pub(crate) fn denoise_film(
    film: &mut Film,
    d: &dyn rt_denoise::Denoiser,
    scene: &Path,
    sink: &dyn super::JobSink,
    frame: Option<u32>,
) -> Result<rt_core::RgbImage, JobError> {
    let noisy =
        rt_film::NoisyFrame::from_film_taking_samples(film, AovSet::for_channels(d.needs()));
    let input = rt_temporal::TemporalFrame {
        frame: &noisy,
        guides: None,
        extra: &[],
    };
    sink.denoiser_input(frame, &input);
    d.denoise(&noisy)
        .map_err(|e| JobError::Failed(format!("{}: {e}", scene.display())))
}

impl RenderJob {
    /// What a plan needs of this job over `scene` (loaded from the job's scene): the job, its
    /// image size and samples, and one output per frame of `frames` (the job's output must
    /// then name the frame), cut into `tile`s and `sample_splits` sample ranges.
    pub fn plan_request(
        &self,
        scene: &rt_core::Scene,
        frames: Option<Range<u32>>,
        tile: Option<(u32, u32)>,
        sample_splits: u32,
    ) -> Result<rt_parts::PlanRequest, JobError> {
        let camera = crate::pick_camera(scene, &self.scene, self.camera.as_deref())?;
        let camera = self.size.apply(camera);
        let output = self.output.display().to_string();
        let frames: Vec<(Option<u32>, String)> = match frames {
            None => vec![(None, output)],
            Some(r) => {
                super::check_frame_pattern(&self.output)?;
                r.map(|f| {
                    let path = crate::frames::frame_path(&self.output, f);
                    (Some(f), path.display().to_string())
                })
                .collect()
            }
        };
        Ok(rt_parts::PlanRequest {
            render: rt_parts::PlannedRender {
                job: self.to_json(),
                width: camera.width,
                height: camera.height,
                spp: self.settings.spp,
            },
            into_cache: false,
            frames,
            tile,
            sample_splits,
        })
    }

    /// The job that renders `part` of `plan` into the directory `dir`: the plan's job with the
    /// part's frame, samples, pixels and file.
    pub fn for_part(
        plan: &rt_parts::Plan,
        part: &rt_parts::PlannedPart,
        dir: &Path,
    ) -> Result<RenderJob, JobError> {
        let mut job = RenderJob::from_json(&plan.renders[part.render].job)?;
        let [a, b] = part.samples;
        job.slice = super::Slice {
            samples: Some(a..b),
            region: Some(part.region),
        };
        job.frames = part.frame.map_or(super::Frames::Still, super::Frames::One);
        job.output = dir.join(&part.file);
        Ok(job)
    }
}
