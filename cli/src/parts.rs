//! Parts, merges and plans on the command line (`rt-parts` holds the format, `rt_session`'s
//! jobs render and merge them): `render SCENE --sample-range A..B --region x0,y0,x1,y1 -o
//! P.rpart` writes a part; `render merge P... -o OUT` (or `--plan plan.json DIR`) writes what
//! the whole render would have; `render plan` cuts a render's job for a scheduler and `render
//! part` runs one piece of it.

use crate::args::Args;
use anyhow::{anyhow, bail, Context, Result};
use clap::Parser;
use rt_experiment::merge::{merge_files, merge_plan, Merged};
use rt_parts::{Plan, PlanRequest};
use rt_session::RenderJob;
use std::ops::Range;
use std::path::{Path, PathBuf};

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
        Some(s) => Some(rt_session::memory::parse_size(s)?),
        None => rt_session::memory::available(),
    };
    let mut print = |merged: &Merged| {
        if !m.quiet {
            println!("{merged}");
        }
    };
    let Some(plan_path) = &m.plan else {
        let output = m.output.as_ref().expect("clap requires -o without --plan");
        print(&merge_files(&m.parts, output, false, limit)?);
        return Ok(());
    };
    let plan = read_plan(plan_path)?;
    let [dir] = &m.parts[..] else {
        bail!(
            "merge --plan takes one directory of parts, got {}",
            m.parts.len()
        );
    };
    Ok(merge_plan(&plan, dir, limit, &mut print)?)
}

/// `render plan`.
#[derive(clap::Args, Debug)]
pub struct PlanArgs {
    /// Scene file (TOML), or gen:NAME; with --experiment, an experiment file.
    pub scene: PathBuf,
    /// Tiles of W×H pixels (the last column and row take what is left). [default: the whole
    /// image]
    #[arg(long, value_name = "WxH", value_parser = rt_session::camera::parse_tiles)]
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
    /// Refuse any file the scene (or experiment) refers to outside DIR, here and in the
    /// parts' renders.
    #[arg(long, value_name = "DIR")]
    pub confine: Option<PathBuf>,
    /// The plan to write (JSON).
    #[arg(short, long)]
    pub output: PathBuf,
    /// The render's flags, as `render SCENE` takes them, e.g. `-- --spp 256 --integrator bdpt
    /// -o out.exr` (its -o is the merged image's path); the plan stores the job they make.
    #[arg(last = true)]
    pub render_args: Vec<String>,
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
    let plan = Plan::new(&requests).map_err(|e| anyhow!("render plan: {e}"))?;
    rt_film::write_bytes_atomic(&p.output, plan.to_json().as_bytes())?;
    println!(
        "{} parts, {} outputs -> {}",
        plan.parts.len(),
        plan.outputs.len(),
        p.output.display()
    );
    Ok(())
}

/// One render's job, its frames and outputs, cut as `p` asks.
fn render_request(p: &PlanArgs) -> Result<PlanRequest> {
    let mut all = vec![p.scene.display().to_string()];
    all.extend(p.render_args.iter().cloned());
    let args = parse_args(&all)?;
    for (given, flag) in [
        (args.frames.is_some(), "--frames"),
        (args.frame.is_some(), "--frame"),
        (args.sample_range.is_some(), "--sample-range"),
        (args.region.is_some(), "--region"),
    ] {
        if given {
            bail!(
                "render plan: {flag} is the plan's to set; give --frames to the plan, not after --"
            );
        }
    }
    let confine = p.confine.as_deref().or(args.confine.as_deref());
    let scene = rt_session::load_scene(&p.scene, confine, &args.define)?;
    let mut job = crate::render::job(&args, &scene.loaded)?;
    job.confine = confine.map(Path::to_path_buf);
    let frames = p.frames.clone();
    Ok(job.plan_request(&scene.loaded.scene, frames, p.tiles, p.sample_splits)?)
}

/// The references an experiment renders, merged into the cache (`rt_experiment::reference`).
fn experiment_requests(p: &PlanArgs) -> Result<Vec<PlanRequest>> {
    let exp = rt_experiment::config::load_confined(&p.scene, p.confine.as_deref())?;
    let (confine, tiles, splits) = (p.confine.as_deref(), p.tiles, p.sample_splits);
    Ok(rt_experiment::reference::plan_requests(
        &exp, &p.cache, confine, tiles, splits,
    )?)
}

fn read_plan(path: &Path) -> Result<Plan> {
    let text = std::fs::read_to_string(path)
        .with_context(|| format!("{}: cannot read", path.display()))?;
    Plan::from_json(&text).map_err(|e| anyhow!("{}: {e}", path.display()))
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

/// `render part`: the plan's job with the part's frame, slice and file.
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
    let job = RenderJob::for_part(&plan, part, &p.output)
        .map_err(|e| anyhow!("{}: {e}", p.plan.display()))?;
    crate::render::run_job(&job, None, p.quiet, false)
}
