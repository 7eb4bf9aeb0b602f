//! Parts, merges and plans on the command line (`rt-parts` does the work):
//! `render SCENE --sample-range A..B --region x0,y0,x1,y1 -o P.rpart` writes a part;
//! `render merge P... -o OUT` (or `--plan plan.json DIR`) writes what the whole render would
//! have; `render plan` cuts a render for a scheduler and `render part` runs one piece of it.

use crate::args::Args;
use crate::job::Job;
use anyhow::{bail, Context, Result};
use clap::Parser;
use rt_film::{Film, Rect};
use rt_parts::{Part, PartHeader, PartKind, Plan, PlanRequest, PlannedRender};
use std::collections::BTreeMap;
use std::ops::Range;
use std::path::{Path, PathBuf};

/// The slice of a render a part holds.
#[derive(Clone, Debug)]
pub struct Slice {
    /// Sample indices.
    pub samples: Range<u32>,
    /// Pixels.
    pub region: Rect,
}

impl Slice {
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

/// True if the render writes a part file (its output ends in `.rpart`).
pub fn writes_part(args: &Args) -> bool {
    args.output
        .as_ref()
        .and_then(|o| o.extension())
        .is_some_and(|e| e.eq_ignore_ascii_case("rpart"))
}

/// The slice a render computes: `None` for a whole render written as an image. Refuses what a
/// part cannot hold or what would not merge exactly, with one line each.
pub fn slice_of(
    args: &Args,
    job: &Job,
    camera: &rt_core::Camera,
    film: &Film,
) -> Result<Option<Slice>> {
    let part = writes_part(args);
    if !part {
        if args.sample_range.is_some() || args.region.is_some() {
            bail!(
                "{}: --sample-range and --region write a part file: -o must end in .rpart",
                job.output.display()
            );
        }
        return Ok(None);
    }
    let refuse = |what: &str, why: &str| -> Result<Option<Slice>> {
        bail!(
            "{}: a part file cannot hold {what}: {why}",
            job.output.display()
        )
    };
    if job.stop.is_some() {
        return refuse(
            "an adaptive render (--error, --time-limit)",
            "the stopping criterion decides on the whole image; render parts with a fixed --spp and merge",
        );
    }
    if args.gree.is_some() {
        return refuse("GREE", "its filter caches need the whole noisy image");
    }
    if args.cache.is_some() {
        return refuse(
            "a world-space cache",
            "the cache carries light from one sample to the next",
        );
    }
    if film.buffers().samples {
        return refuse(
            "per-sample records (--denoiser sbmf)",
            "denoise after merging with a pixel-space denoiser",
        );
    }
    if job.settings.aovs.blocks {
        return refuse("--aov blocks", "it needs --error");
    }
    let spp = job.settings.spp;
    let samples = args.sample_range.clone().unwrap_or(0..spp);
    if samples.end > spp {
        bail!(
            "--sample-range {}..{}: the render takes samples 0..{spp} (--spp)",
            samples.start,
            samples.end
        );
    }
    let region = args
        .region
        .unwrap_or(Rect::full(camera.width, camera.height));
    if !region.is_inside(camera.width, camera.height) {
        bail!(
            "--region {region}: outside the {}x{} image",
            camera.width,
            camera.height
        );
    }
    Ok(Some(Slice { samples, region }))
}

/// Every setting that changes the image's bits (`--threads`, `-o` and `-q` do not).
fn settings(args: &Args, job: &Job, camera: &rt_core::Camera) -> BTreeMap<String, String> {
    let s = &job.settings;
    [
        ("integrator", s.integrator.to_string()),
        ("accel", s.accel.to_string()),
        ("seed", s.seed.to_string()),
        ("camera", camera.name.clone()),
        ("exposure", args.exposure.to_string()),
        ("denoiser", s.denoiser.clone().unwrap_or_default()),
        ("shutter", args.shutter.to_string()),
        ("fps", args.fps.to_string()),
    ]
    .into_iter()
    .map(|(k, v)| (k.to_string(), v))
    .collect()
}

/// The header of a part or checkpoint of this render.
pub fn header(
    args: &Args,
    job: &Job,
    camera: &rt_core::Camera,
    film: &Film,
    slice: &Slice,
    scene_hash: &str,
    kind: PartKind,
) -> PartHeader {
    PartHeader {
        scene: job.scene_path.display().to_string(),
        scene_hash: scene_hash.to_string(),
        settings: settings(args, job, camera),
        frame: job.frame,
        spp: job.settings.spp,
        args: job.command.clone(),
        ..film_header(film, slice, kind)
    }
}

/// A header with what the film and the slice say (format, build, size, region, samples,
/// buffers); the caller fills in the scene, settings, spp, frame and command line.
pub fn film_header(film: &Film, slice: &Slice, kind: PartKind) -> PartHeader {
    let b = film.buffers();
    PartHeader {
        format: rt_parts::FORMAT,
        kind,
        binary: rt_parts::binary_id(env!("CARGO_PKG_VERSION")),
        scene: String::new(),
        scene_hash: String::new(),
        settings: BTreeMap::new(),
        frame: None,
        width: film.width(),
        height: film.height(),
        spp: slice.samples.end,
        region: [
            slice.region.x0,
            slice.region.y0,
            slice.region.x1,
            slice.region.y1,
        ],
        samples: [slice.samples.start, slice.samples.end],
        aovs: b.aovs.names().into_iter().map(str::to_string).collect(),
        variance: b.variance,
        halves: b.halves,
        args: Vec::new(),
        seconds: 0.0,
    }
}

/// Writes the film's sums of `slice` as a part file at the job's output, atomically.
pub fn write(
    args: &Args,
    job: &Job,
    camera: &rt_core::Camera,
    film: &Film,
    slice: &Slice,
    (scene_hash, seconds): (&str, f64),
) -> Result<()> {
    let part = Part {
        header: PartHeader {
            seconds,
            ..header(args, job, camera, film, slice, scene_hash, PartKind::Part)
        },
        sums: film.encode_sums(slice.region),
    };
    part.write(&job.output)
        .map_err(|e| anyhow::anyhow!("{}: {e}", job.output.display()))
}

/// `render merge`.
#[derive(clap::Args, Debug)]
pub struct MergeArgs {
    /// Part files (`.rpart`); with --plan, the directory holding the plan's parts.
    #[arg(required = true)]
    pub parts: Vec<PathBuf>,
    /// The image to write (.exr or .png), as the whole render would have written it.
    #[arg(short, long, required_unless_present = "plan")]
    pub output: Option<PathBuf>,
    /// Merge every output of this plan from the parts in the directory given.
    #[arg(long, value_name = "plan.json")]
    pub plan: Option<PathBuf>,
    /// Refuse a merge whose film would exceed SIZE (e.g. 8G). [default: the memory available]
    #[arg(long, value_name = "SIZE")]
    pub max_memory: Option<String>,
    /// No summary line.
    #[arg(short, long)]
    pub quiet: bool,
}

/// `render merge`.
pub fn merge(m: &MergeArgs) -> Result<()> {
    let limit = match &m.max_memory {
        Some(s) => Some(crate::memory::parse_size(s)?),
        None => crate::memory::available(),
    };
    let Some(plan_path) = &m.plan else {
        let output = m.output.as_ref().expect("clap requires -o without --plan");
        return merge_files(&m.parts, output, false, limit, m.quiet);
    };
    let plan = read_plan(plan_path)?;
    let [dir] = &m.parts[..] else {
        bail!(
            "merge --plan takes one directory of parts, got {}",
            m.parts.len()
        );
    };
    for out in &plan.outputs {
        let files: Vec<PathBuf> = out
            .parts
            .iter()
            .map(|&i| dir.join(&plan.parts[i].file))
            .collect();
        merge_files(
            &files,
            Path::new(&out.output),
            out.into_cache,
            limit,
            m.quiet,
        )?;
    }
    Ok(())
}

/// Merges `files` into `output` (or, `into_cache`, into the reference cache directory
/// `output`).
fn merge_files(
    files: &[PathBuf],
    output: &Path,
    into_cache: bool,
    limit: Option<u64>,
    quiet: bool,
) -> Result<()> {
    if into_cache {
        return merge_reference(files, output, limit, quiet);
    }
    match output
        .extension()
        .and_then(|e| e.to_str())
        .map(str::to_ascii_lowercase)
        .as_deref()
    {
        Some("exr") | Some("png") => {}
        _ => bail!(
            "{}: the merged image must end in .exr or .png",
            output.display()
        ),
    }
    let parts = read_parts(files)?;
    let t = std::time::Instant::now();
    let mut merged = rt_parts::merge(&parts, limit).map_err(|e| anyhow::anyhow!("{e}"))?;
    let h = &merged.header;
    let exposure: f32 = h
        .settings
        .get("exposure")
        .and_then(|v| v.parse().ok())
        .unwrap_or(0.0);
    let scene = PathBuf::from(&h.scene);
    match h.settings.get("denoiser").filter(|d| !d.is_empty()) {
        Some(text) => {
            let d = text
                .parse::<rt_denoise::DenoiserSpec>()
                .and_then(|s| s.build())
                .map_err(|e| anyhow::anyhow!("--denoiser {text}: {e}"))?;
            crate::job::write_denoised(&mut merged.film, d.as_ref(), output, exposure, &scene)?;
        }
        None => {
            if output
                .extension()
                .is_some_and(|e| e.eq_ignore_ascii_case("png"))
                && !h.aovs.is_empty()
            {
                bail!(
                    "{}: the parts hold AOVs, which need an .exr output",
                    output.display()
                );
            }
            rt_film::write_image_with(
                output,
                &merged.film,
                &rt_film::OutputOptions { exposure },
                &[],
            )
            .map_err(|e| anyhow::anyhow!("{e}"))?;
        }
    }
    if !quiet {
        println!(
            "merged {} parts ({} sample ranges) of {} ({}x{}, {} spp) in {:.2} s -> {}",
            parts.len(),
            merged.ranges.len(),
            h.scene,
            h.width,
            h.height,
            h.spp,
            t.elapsed().as_secs_f64(),
            output.display()
        );
    }
    Ok(())
}

/// Reads part files (checkpoints are refused: they are resumed, not merged).
fn read_parts(files: &[PathBuf]) -> Result<Vec<(String, Part)>> {
    let mut parts = Vec::with_capacity(files.len());
    for f in files {
        let p = Part::read(f).map_err(|e| anyhow::anyhow!("{}: {e}", f.display()))?;
        if p.header.kind != PartKind::Part {
            bail!(
                "{}: a checkpoint, not a part: continue it with render --resume",
                f.display()
            );
        }
        parts.push((f.display().to_string(), p));
    }
    Ok(parts)
}

/// Merges the parts of a reference (`render reference --sample-range/--region`) and stores
/// it in the reference cache `dir`, where `render reference` and experiments find it.
fn merge_reference(files: &[PathBuf], dir: &Path, limit: Option<u64>, quiet: bool) -> Result<()> {
    let parts = read_parts(files)?;
    let merged = rt_parts::merge(&parts, limit).map_err(|e| anyhow::anyhow!("{e}"))?;
    let h = &merged.header;
    let setting = |k: &str| {
        h.settings
            .get(k)
            .cloned()
            .ok_or_else(|| anyhow::anyhow!("{}: not a reference's part (no {k})", parts[0].0))
    };
    if setting("stream")? != "reference" {
        bail!("{}: not a reference's part", parts[0].0);
    }
    let key = rt_experiment::cache::Key {
        hex: setting("cache key")?,
        description: setting("cache description")?,
    };
    let seconds: f64 = parts.iter().map(|(_, p)| p.header.seconds).sum();
    let samples = u64::from(h.width) * u64::from(h.height) * u64::from(h.spp);
    let sidecar = rt_experiment::cache::Sidecar {
        key: key.hex.clone(),
        description: key.description.clone(),
        scene: h.scene.clone(),
        width: h.width,
        height: h.height,
        spp: h.spp,
        seconds,
        samples_per_second: samples as f64 / seconds.max(1e-9),
    };
    let path =
        rt_experiment::Cache::new(dir).store(Path::new(&h.scene), &key, &merged.film, &sidecar)?;
    if !quiet {
        println!(
            "merged {} parts of the reference of {} ({}x{}, {} spp, {:.1} s of rendering) -> {}",
            parts.len(),
            h.scene,
            h.width,
            h.height,
            h.spp,
            seconds,
            path.display()
        );
    }
    Ok(())
}

/// `render plan`.
#[derive(clap::Args, Debug)]
pub struct PlanArgs {
    /// Scene file (TOML), or gen:NAME; with --experiment, an experiment file.
    pub scene: PathBuf,
    /// Tiles of W×H pixels (the last column and row take what is left). [default: the whole
    /// image]
    #[arg(long, value_name = "WxH", value_parser = parse_tile)]
    pub tiles: Option<(u32, u32)>,
    /// Cut the samples of every pixel into K ranges.
    #[arg(long, value_name = "K", default_value_t = 1)]
    pub sample_splits: u32,
    /// Frames A..B of a sequence (the render's output must name the frame).
    #[arg(long, value_name = "A..B", value_parser = crate::args::parse_frames)]
    pub frames: Option<Range<u32>>,
    /// SCENE is an experiment file: plan the references it renders (into the reference cache,
    /// where `render experiment` then finds them); its timed runs stay on one machine.
    #[arg(long, conflicts_with = "frames")]
    pub experiment: bool,
    /// With --experiment: the reference cache the merge stores into.
    #[arg(long, value_name = "DIR", default_value = rt_experiment::DEFAULT_CACHE_DIR)]
    pub cache: PathBuf,
    /// Refuse any file the scene (or experiment) refers to outside DIR; give it after `--`
    /// too for the parts' renders.
    #[arg(long, value_name = "DIR")]
    pub confine: Option<PathBuf>,
    /// The plan to write (JSON).
    #[arg(short, long)]
    pub output: PathBuf,
    /// Everything else is passed to each part's render, e.g. `-- --spp 256 --integrator bdpt
    /// -o out.exr` (its -o is the merged image's path).
    #[arg(last = true)]
    pub render_args: Vec<String>,
}

fn parse_tile(s: &str) -> Result<(u32, u32), String> {
    let bad = || format!("--tiles must be WxH with positive integers, got `{s}`");
    let (w, h) = s.split_once(['x', 'X']).ok_or_else(bad)?;
    let (w, h): (u32, u32) = (w.parse().map_err(|_| bad())?, h.parse().map_err(|_| bad())?);
    if w == 0 || h == 0 {
        return Err(bad());
    }
    Ok((w, h))
}

/// `args` as `render` parses them (the program name added).
fn parse_args(args: &[String]) -> Result<Args> {
    let argv = std::iter::once("render".to_string()).chain(args.iter().cloned());
    Args::try_parse_from(argv)
        .map_err(|e| anyhow::anyhow!("{}", e.to_string().lines().next().unwrap_or_default()))
}

/// `render plan`.
pub fn plan(p: &PlanArgs) -> Result<()> {
    let requests = if p.experiment {
        if !p.render_args.is_empty() {
            bail!("render plan --experiment: the experiment file holds the settings; nothing goes after --");
        }
        experiment_requests(p)?
    } else {
        vec![render_request(p)?]
    };
    let plan = Plan::new(&requests).map_err(|e| anyhow::anyhow!("render plan: {e}"))?;
    rt_film::write_bytes_atomic(&p.output, plan.to_json().as_bytes())
        .map_err(|e| anyhow::anyhow!("{e}"))?;
    println!(
        "{} parts, {} outputs -> {}",
        plan.parts.len(),
        plan.outputs.len(),
        p.output.display()
    );
    Ok(())
}

/// One render, its frames and outputs, cut as `p` asks.
fn render_request(p: &PlanArgs) -> Result<PlanRequest> {
    let rest = p.render_args.clone();
    for flag in ["--frames", "--frame", "--sample-range", "--region"] {
        if rest
            .iter()
            .any(|a| a == flag || a.starts_with(&format!("{flag}=")))
        {
            bail!(
                "render plan: {flag} is the plan's to set; give --frames to the plan, not after --"
            );
        }
    }
    let mut all = vec![p.scene.display().to_string()];
    all.extend(rest.iter().cloned());
    let args = parse_args(&all)?;
    let access = crate::job::file_access(p.confine.as_deref())?;
    let loaded = crate::job::load_scene_with(&p.scene, &access)?;
    let job = Job::resolve(&args, &loaded.render)?;
    let camera = rt_session::pick_camera(&loaded.scene, &job.scene_path, job.camera.as_deref())?;
    let output = job.output.display().to_string();
    let frames: Vec<(Option<u32>, String)> = match &p.frames {
        None => vec![(None, output.clone())],
        Some(r) => {
            if !output.contains("{frame") {
                bail!("{output}: --frames needs an output that names the frame, e.g. -o 'out/frame_{{frame:04}}.exr'");
            }
            r.clone()
                .map(|f| {
                    let path = crate::frame_pattern::frame_path(&job.output, f);
                    (Some(f), path.display().to_string())
                })
                .collect()
        }
    };
    // The parts' command line: the scene, the render's arguments without its -o.
    let mut part_args = vec![p.scene.display().to_string()];
    let mut it = rest.into_iter();
    while let Some(a) = it.next() {
        if a == "-o" || a == "--output" {
            it.next();
        } else if !(a.starts_with("--output=") || a.starts_with("-o=")) {
            part_args.push(a);
        }
    }
    Ok(PlanRequest {
        render: PlannedRender {
            args: part_args,
            width: camera.width,
            height: camera.height,
            spp: job.settings.spp,
        },
        into_cache: false,
        frames,
        tile: p.tiles,
        sample_splits: p.sample_splits,
    })
}

/// The references an experiment renders, each a `render reference` cut as `p` asks and
/// merged into the cache. Sequence scenes (one reference per frame) are refused for now.
fn experiment_requests(p: &PlanArgs) -> Result<Vec<PlanRequest>> {
    let access = crate::job::file_access(p.confine.as_deref())?;
    let exp = rt_experiment::config::load_with(&p.scene, &access)?;
    let mut requests = Vec::new();
    for scene in &exp.scenes {
        let rt_experiment::config::ReferencePlan::Render {
            spp,
            estimator,
            seed,
            accel,
        } = &scene.reference
        else {
            continue;
        };
        if scene.sequence.is_some() {
            bail!(
                "{}: scene {}: the per-frame references of a sequence are not plannable yet",
                p.scene.display(),
                scene.name
            );
        }
        let c = &scene.camera;
        let args = [
            "reference".to_string(),
            scene.path.display().to_string(),
            format!("--spp={spp}"),
            format!("--seed={seed}"),
            format!("--integrator={estimator}"),
            format!("--camera={}", c.name),
            format!("--resolution={}x{}", c.width, c.height),
            format!("--accel={accel}"),
        ];
        requests.push(PlanRequest {
            render: PlannedRender {
                args: args.to_vec(),
                width: c.width,
                height: c.height,
                spp: *spp,
            },
            into_cache: true,
            frames: vec![(None, p.cache.display().to_string())],
            tile: p.tiles,
            sample_splits: p.sample_splits,
        });
    }
    if requests.is_empty() {
        bail!("{}: the experiment renders no reference", p.scene.display());
    }
    Ok(requests)
}

fn read_plan(path: &Path) -> Result<Plan> {
    let text = std::fs::read_to_string(path)
        .with_context(|| format!("{}: cannot read", path.display()))?;
    Plan::from_json(&text).map_err(|e| anyhow::anyhow!("{}: {e}", path.display()))
}

/// `render part`.
#[derive(clap::Args, Debug)]
pub struct PartArgs {
    /// The plan (`render plan`).
    pub plan: PathBuf,
    /// Which part: 0 .. the plan's part count (a scheduler's array index).
    #[arg(long)]
    pub index: usize,
    /// Directory to write the part file into (created if missing).
    #[arg(short, long)]
    pub output: PathBuf,
    /// No progress bar and no summary line.
    #[arg(short, long)]
    pub quiet: bool,
}

/// `render part`.
pub fn part(p: &PartArgs) -> Result<()> {
    let plan = read_plan(&p.plan)?;
    let Some(part) = plan.parts.get(p.index) else {
        bail!(
            "{}: --index {} but the plan has parts 0..{}",
            p.plan.display(),
            p.index,
            plan.parts.len()
        );
    };
    std::fs::create_dir_all(&p.output)
        .with_context(|| format!("{}: cannot create the parts directory", p.output.display()))?;
    let [x0, y0, x1, y1] = part.region;
    let [a, b] = part.samples;
    let mut argv: Vec<String> = plan.renders[part.render].args.clone();
    argv.extend([
        "--sample-range".into(),
        format!("{a}..{b}"),
        "--region".into(),
        format!("{x0},{y0},{x1},{y1}"),
        "-o".into(),
        p.output.join(&part.file).display().to_string(),
    ]);
    if let Some(f) = part.frame {
        argv.extend(["--frame".into(), f.to_string()]);
    }
    if p.quiet {
        argv.push("-q".into());
    }
    crate::run(&parse_args(&argv)?)
}
