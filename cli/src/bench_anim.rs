//! `render bench-anim`: seconds per frame of an animated scene, split into the structure's
//! update and the trace of a fixed per-frame workload. The arguments are here; the benchmark
//! (`rt_experiment::bench::anim`, over `rt_accel::bench::anim`) and its table and CSV are in
//! the library.

use crate::bench_accel::{flagged, parse_specs};
use anyhow::{anyhow, bail, Result};
use rt_accel::bench::anim::{AnimOptions, Workload};
use rt_experiment::bench::anim::{self, AnimBench, DEFAULT_SWEEP};
use rt_experiment::bench::input::{MAX_PIXELS, MAX_SIDE};
use std::path::PathBuf;

/// Arguments of `render bench-anim`.
#[derive(clap::Args, Debug)]
pub struct BenchAnimArgs {
    /// The animated scene: a .toml scene or gen:NAME (car, furniture).
    #[arg(value_name = "SCENE.toml|gen:NAME")]
    pub input: String,

    /// Frames A..B (half-open), frame f at time f / fps.
    #[arg(long, value_name = "A..B", value_parser = crate::args::parse_frames, default_value = "0..8")]
    pub frames: std::ops::Range<u32>,

    /// Frames per second.
    #[arg(long, default_value_t = 24.0)]
    pub fps: f64,

    /// Structures, comma separated, each KIND[:OPTION...] as for `render --accel`. Two-level
    /// kinds follow the animation by updating their top level; the others are rebuilt every
    /// frame. [default: bvh8, two-level, two-level:top=refit, clusters:t=1,2,4,...,512]
    #[arg(long, value_delimiter = ',')]
    pub accel: Option<Vec<String>>,

    /// Primary ray grid WxH (one jittered primary ray per pixel).
    #[arg(long, value_name = "WxH", value_parser = parse_size, default_value = "480x300")]
    pub size: (u32, u32),

    /// Rays per frame: full (each primary ray, a diffuse bounce and a shadow segment from each
    /// primary hit) or primary (primary rays only, as the thesis timed its figures).
    #[arg(long, value_enum, default_value = "full")]
    pub rays: Rays,

    /// Camera of the scene by name. [default: the first]
    #[arg(long)]
    pub camera: Option<String>,

    /// Seed of the jitter, bounce and light samples.
    #[arg(long, default_value_t = 0)]
    pub seed: u64,

    /// Rays of every set checked against a flat bvh8 per frame before timing; more than 0.1 %
    /// disagreeing stops the benchmark. 0 skips the check.
    #[arg(long, default_value_t = 2000)]
    pub check: usize,

    /// Timed rounds per frame (the contenders interleaved); the fastest counts.
    #[arg(long, default_value_t = 3)]
    pub repeat: u32,

    /// Threads of the untimed work (building, generating and checking rays). Timings always
    /// run on one thread.
    #[arg(long, default_value_t = 1)]
    pub threads: usize,

    /// Also count traversal work (boxes, leaves and triangles tested per ray) in an untimed
    /// pass per frame.
    #[arg(long)]
    pub count: bool,

    /// Write one row per structure and frame as CSV.
    #[arg(long, value_name = "OUT.csv")]
    pub csv: Option<PathBuf>,

    /// No progress lines on stderr.
    #[arg(short, long)]
    pub quiet: bool,
}

/// `--rays`.
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum Rays {
    /// Primary rays, a diffuse bounce and a shadow segment per primary hit.
    Full,
    /// Primary rays only.
    Primary,
}

/// `WxH`, each side in [1, 16384], at most 2^26 pixels (as `bench-accel`).
fn parse_size(s: &str) -> Result<(u32, u32), String> {
    let bad = || {
        format!(
            "size must be WxH with sides 1 to {MAX_SIDE} and at most {MAX_PIXELS} pixels, e.g. 480x300, got `{s}`"
        )
    };
    let (w, h) = rt_session::split_size(s).ok_or_else(bad)?;
    let side = 1..=MAX_SIDE;
    if !side.contains(&w) || !side.contains(&h) || u64::from(w) * u64::from(h) > MAX_PIXELS {
        return Err(bad());
    }
    Ok((w, h))
}

/// Runs the benchmark.
pub fn run(args: &BenchAnimArgs) -> Result<()> {
    let list: Vec<String> = match &args.accel {
        Some(l) => l.clone(),
        None => DEFAULT_SWEEP.split(',').map(str::to_owned).collect(),
    };
    let specs = parse_specs(&list, true)?;
    rt_session::job::check_fps(args.fps)?;
    if args.repeat == 0 {
        bail!("--repeat must be at least 1");
    }
    let info = |msg: &str| {
        if !args.quiet {
            eprintln!("{msg}");
        }
    };
    let bench = AnimBench {
        input: args.input.clone(),
        specs,
        camera: args.camera.clone(),
        threads: args.threads,
        options: AnimOptions {
            frames: args.frames.clone(),
            fps: args.fps,
            camera: 0,
            width: args.size.0,
            height: args.size.1,
            seed: args.seed,
            check: args.check,
            repeat: args.repeat,
            count: args.count,
            workload: match args.rays {
                Rays::Full => Workload::Full,
                Rays::Primary => Workload::Primary,
            },
        },
    };
    let report = anim::run(&bench, &info).map_err(|e| flagged(e, args.camera.as_deref()))?;
    print!("{}", anim::table(&args.input, &bench.options, &report));
    if let Some(path) = &args.csv {
        let csv = anim::csv(&args.input, &report);
        rt_film::write_bytes_atomic(path, csv.as_bytes()).map_err(|e| anyhow!("{e}"))?;
        info(&format!("wrote {}", path.display()));
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sizes_parse_and_bad_ones_say_why() {
        assert_eq!(parse_size("480x300"), Ok((480, 300)));
        assert_eq!(parse_size("8X6"), Ok((8, 6)));
        for bad in ["480", "0x3", "x3", "4x", "99999x2", "-1x2"] {
            assert!(parse_size(bad).unwrap_err().contains("WxH"), "{bad}");
        }
    }

    #[test]
    fn the_default_sweep_parses() {
        let list: Vec<String> = DEFAULT_SWEEP.split(',').map(str::to_owned).collect();
        let specs = parse_specs(&list, true).unwrap();
        assert_eq!(specs.len(), 13);
        assert!(parse_specs(&["iosp0".into()], true).is_err());
        assert!(parse_specs(&["bvh8".into(), "bvh8".into()], true).is_err());
    }
}
