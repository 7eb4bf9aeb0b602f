//! Command-line arguments.

use clap::{Parser, Subcommand};
use rt_integrators::IntegratorSpec;
use std::path::PathBuf;

/// Render a TOML scene (see docs/scene-format.md) to an EXR or PNG image.
///
/// Settings come from the command line; any left out fall back to the scene's optional
/// `[render]` table, then to the defaults shown here. `render bench-accel` measures the
/// acceleration structures instead (see `render bench-accel --help`); `render compare A B`
/// measures the error of image A against the reference B; `render stress` runs the numerical
/// stress suite.
#[derive(Parser, Debug)]
#[command(
    name = "render",
    version,
    about,
    long_about = None,
    args_conflicts_with_subcommands = true,
    subcommand_negates_reqs = true
)]
pub struct Args {
    /// Another task instead of rendering.
    #[command(subcommand)]
    pub command: Option<Command>,

    /// Scene file (TOML, or Mitsuba XML: `.xml`), or gen:NAME for a procedural scene
    /// (worst-case, rotated, mixed, million).
    #[arg(required_unless_present = "resume")]
    pub scene: Option<PathBuf>,

    /// A Mitsuba scene's parameter: replaces `$NAME`, winning over its `<default>`. Repeatable.
    #[arg(short = 'D', value_name = "NAME=VALUE", value_parser = rt_scene::mitsuba::parse_define)]
    pub define: Vec<(String, String)>,

    /// Output image; the extension picks the format: .exr (linear float, AOVs as extra
    /// channels) or .png (sRGB, exposure then clamp). [default: `[render] output`, else
    /// the scene's file name with .exr]
    #[arg(short, long)]
    pub output: Option<PathBuf>,

    /// Samples per pixel. [default: `[render] spp`, else 64] With --error or --time-limit:
    /// the most samples any pixel takes [default: no cap below 2^20].
    #[arg(long)]
    pub spp: Option<u32>,

    /// Render until the hierarchical stopping criterion (Dammertz 2009) finds every block of
    /// the image below error V (the thesis uses 2e-4, for radiance in about [0, 1]); finished
    /// blocks stop sampling. Works with every integrator.
    #[arg(long, value_name = "V", allow_hyphen_values = true)]
    pub error: Option<f32>,

    /// Stop rendering after this many seconds of passes (with or without --error).
    #[arg(long, value_name = "SECONDS", allow_hyphen_values = true)]
    pub time_limit: Option<f64>,

    /// Light transport algorithm and its options, KIND[:OPTION...]: path (path tracing,
    /// next-event estimation + MIS), path-bsdf (path tracing with BSDF sampling only), direct
    /// (direct lighting: one bounce, NEE + MIS), ao (ambient occlusion), light (light tracing:
    /// particles from the lights and the sky splatted through the camera; one light path per
    /// pixel per spp; no AOVs), bdpt (bidirectional path tracing, MIS over all strategies;
    /// one camera and one light subpath per pixel per spp; no AOVs), partitioned (the
    /// path-space-partitioned renderer: VPLs, caustic histogram, specular gathering; options
    /// vpls=N, photons=N, clamp=F, cull=off|unbiased|biased, maps=on|off, indirect-caustics=N); options
    /// max-depth=N (wavefront, path, path-bsdf, light, bdpt, partitioned), lanes=N
    /// (wavefront) and distance=F (ao), separated by `:` or `,`, e.g. path:max-depth=4
    /// (crates/integrators/src/spec.rs). [default: `[render] integrator`, else wavefront]
    #[arg(long, value_name = "SPEC", value_parser = parse_integrator)]
    pub integrator: Option<IntegratorSpec>,

    #[arg(long, value_name = "SPEC", help = accel_help())]
    pub accel: Option<String>,

    /// Maximum number of bounces (scattering events). Light arriving after the last bounce
    /// counts, whether found by a light-sampled connection from the last vertex or by a BSDF
    /// ray hitting an emitter; 0 shows only emitters seen directly, 1 is direct lighting.
    /// (Mitsuba's max_depth = this + 1.) [default: `[render] max_depth`, else 16]
    #[arg(long)]
    pub max_depth: Option<u32>,

    /// Worker threads. The image does not depend on it. [default: `[render] threads`, else
    /// all cores]
    #[arg(long)]
    pub threads: Option<usize>,

    /// Seed of the sample streams; the same scene, seed and settings give the same image.
    /// [default: `[render] seed`, else 0]
    #[arg(long)]
    pub seed: Option<u64>,

    /// Camera by name. [default: the first `[[camera]]` in the scene]
    #[arg(long)]
    pub camera: Option<String>,

    /// Extra EXR channels, comma separated: albedo, normal, depth, position (at the first
    /// visible surface, averaged over the pixel's samples), feature-variance (of each of those
    /// means), variance (of the pixel mean), halves (the even and odd samples' means), the
    /// lighting split emission, direct, indirect, diffuse, glossy and irradiance (reflected light
    /// over albedo; path tracers only), denoise (all of the above) and blocks (with --error: the
    /// stopping criterion's final block index, samples per pixel and converged flag per pixel).
    /// Only computed when asked for; `render denoise` reads them back. [default: `[render] aov`,
    /// else none]
    #[arg(long, value_delimiter = ',')]
    pub aov: Option<Vec<String>>,

    /// After the render, print a table of its stages to stdout: what was built and what was
    /// skipped (the light sampling structure without emitters, the environment importance map
    /// without an environment map, film buffers no output reads, lens samples for a pinhole
    /// camera), with the time and the bytes held by each. Printed even with -q.
    #[arg(long)]
    pub stats: bool,

    /// Exposure in stops applied before PNG tone mapping (EXR is always written unscaled).
    #[arg(long, default_value_t = 0.0, allow_negative_numbers = true)]
    pub exposure: f32,

    /// Maximum occluder distance for the ao integrator. [default: unlimited]
    #[arg(long)]
    pub ao_distance: Option<f32>,

    /// No progress bar and no summary line.
    #[arg(short, long)]
    pub quiet: bool,

    /// Render frames A..B (half-open) of the scene's animation, frame f at time f / fps, each
    /// with its own sample streams (from the seed and the frame); the output must name the
    /// frame, e.g. -o 'out/frame_{frame:04}.exr'. Without --accel, a scene whose instances
    /// move is rendered with clusters (any frame), which only rebuild their top level per
    /// frame.
    #[arg(long, value_name = "A..B", value_parser = parse_frames, conflicts_with = "frame")]
    pub frames: Option<std::ops::Range<u32>>,

    /// Render one frame of the scene's animation (time F / fps).
    #[arg(long, value_name = "F")]
    pub frame: Option<u32>,

    /// Frames per second of --frames and --frame.
    #[arg(long, default_value_t = 24.0)]
    pub fps: f64,

    /// Motion blur: the shutter stays open for this fraction of a frame (1 / fps seconds)
    /// from the frame's time; every camera sample draws a time in it, its rays carry it, and
    /// moving instances and cameras are placed at it. Needs a structure that places instances
    /// per ray (two-level or clusters; clusters when --accel is not given) and a camera-ray
    /// integrator (wavefront, path, path-bsdf, direct, ao).
    #[arg(long, value_name = "S", default_value_t = 0.0)]
    pub shutter: f64,

    /// Denoise the image before writing it, e.g. `atrous`, `sbmf` (filters the samples, which
    /// only a render has), `nlm:radius=5` (docs/denoising.md). The film keeps what the denoiser
    /// reads; the output is the denoised image. `none` turns off the scene's denoiser.
    /// [default: `[render] denoiser`, else none]
    #[arg(long, value_name = "NAME[:options]", conflicts_with = "gree")]
    pub denoiser: Option<String>,

    /// A world-space shading cache (Delaere 2021; docs/worldcache.md), kept across the passes
    /// of a frame and the frames of a sequence: `worldspace[:options]` (implicit points) or
    /// `grid[:options]` (fixed grid), options `key=value` separated by `,` or `:`: lod, s0,
    /// kappa, connectivity, select, jitter, radius, normals, min-samples, capacity,
    /// pass-capacity. The path tracers end secondary paths at cached diffuse vertices; ao shows
    /// the cache's reconstruction. Renders one sample index per pass, merging after each.
    #[arg(long, value_name = "NAME[:options]", conflicts_with = "gree")]
    pub cache: Option<String>,

    /// Refuse any file the scene refers to (meshes, material libraries, textures, glTF buffers
    /// and images, environment maps, and the scene file itself) whose real path, symbolic
    /// links resolved, lies outside DIR: for farms that render scenes they did not write.
    #[arg(long, value_name = "DIR")]
    pub confine: Option<PathBuf>,

    /// Refuse, before allocating, a render whose estimated memory (film buffers and per-sample
    /// records exactly, the acceleration structure by an upper bound) exceeds SIZE, e.g. 512M
    /// or 8G. [default: the memory the system reports available]
    #[arg(long, value_name = "SIZE")]
    pub max_memory: Option<String>,

    /// Render in passes of one sample per pixel and write the render's state to FILE
    /// (atomically) every --checkpoint-every seconds, and when SIGINT or SIGTERM stops the
    /// render at the next pass (the image so far is written too; a second signal ends it at
    /// once). `render --resume FILE` continues it to the same bytes as a render never stopped.
    /// Removed when the render completes.
    #[arg(long, value_name = "FILE.rpart")]
    pub checkpoint: Option<PathBuf>,

    /// Seconds between checkpoints (0: after every pass).
    #[arg(
        long,
        value_name = "SECONDS",
        default_value_t = rt_session::job::DEFAULT_CHECKPOINT_EVERY,
        requires = "checkpoint"
    )]
    pub checkpoint_every: f64,

    /// Continue the render a checkpoint was written for, with the settings it was started
    /// with (only --threads and -q may be given again).
    #[arg(long, value_name = "FILE.rpart", conflicts_with = "scene")]
    pub resume: Option<PathBuf>,

    /// Render only sample indices A..B (half-open) of every pixel, and light paths A..B of a
    /// light-path technique, into a part file (-o NAME.rpart) for `render merge`. Parts of
    /// any split merge to the very bits of the whole render (docs/distributed.md).
    #[arg(long, value_name = "A..B", value_parser = parse_sample_range)]
    pub sample_range: Option<std::ops::Range<u32>>,

    /// Render only the pixels x0..x1 × y0..y1 into a part file (-o NAME.rpart). Light-path
    /// techniques trace all their light paths and keep the splats that land inside.
    #[arg(long, value_name = "x0,y0,x1,y1", value_parser = parse_region)]
    pub region: Option<rt_film::Rect>,

    /// Denoise by GREE (Bauszat, thesis ch. 5): --spp is the budget b; render the noisy image
    /// at n = fraction x b spp, run the filter bank (--bank), render filter caches at a share
    /// 1 - sparsity of the pixels with independent samples, pick a filter per pixel by the
    /// caches' errors (graph cut) and fuse. Options `key=value` separated by `:` or `,`:
    /// fraction (0.875), sparsity (0.95), kappa (0.6), sigma-r (0.15), lambda (0.5), jacobi
    /// (2), metric (squared|relative). Camera-ray integrators only (docs/denoising.md).
    #[arg(long, value_name = "OPTIONS", num_args = 0..=1, default_missing_value = "")]
    pub gree: Option<String>,

    /// GREE's filter bank: a TOML file with `denoisers = ["gaussian:sigma=2", ...]`
    /// [default: the thesis' Gaussians and joint bilateral filters plus identity, À-Trous and
    /// non-local means]
    #[arg(long, value_name = "FILE", requires = "gree")]
    pub bank: Option<PathBuf>,

    /// With --gree: write the chosen filter per pixel as a colour-coded PNG (the legend is
    /// printed).
    #[arg(long, value_name = "FILE.png", requires = "gree")]
    pub labels: Option<PathBuf>,

    /// With --gree: write each filter's interpolated error map (EXR, and PNG in false colour
    /// on one log scale for all filters) into this directory.
    #[arg(long, value_name = "DIR", requires = "gree")]
    pub error_maps: Option<PathBuf>,
}

/// `A..B` with `A < B`.
pub fn parse_frames(s: &str) -> Result<std::ops::Range<u32>, String> {
    let bad = || format!("frames must be A..B with integers 0 <= A < B (half-open), got `{s}`");
    let (a, b) = s.split_once("..").ok_or_else(bad)?;
    let (a, b): (u32, u32) = (
        a.trim().parse().map_err(|_| bad())?,
        b.trim().parse().map_err(|_| bad())?,
    );
    if a >= b {
        return Err(bad());
    }
    Ok(a..b)
}

/// `--sample-range A..B`: sample indices, half-open, A < B.
pub fn parse_sample_range(s: &str) -> Result<std::ops::Range<u32>, String> {
    parse_frames(s).map_err(|_| {
        format!("--sample-range must be A..B with integers 0 <= A < B (half-open), got `{s}`")
    })
}

/// `--region x0,y0,x1,y1`: a non-empty pixel rectangle (checked against the image later).
pub fn parse_region(s: &str) -> Result<rt_film::Rect, String> {
    let bad = || format!("--region must be x0,y0,x1,y1 with x0 < x1 and y0 < y1, got `{s}`");
    let v: Vec<u32> = s
        .split(',')
        .map(|t| t.trim().parse().map_err(|_| bad()))
        .collect::<Result<_, _>>()?;
    let [x0, y0, x1, y1] = v[..] else {
        return Err(bad());
    };
    if x0 >= x1 || y0 >= y1 {
        return Err(bad());
    }
    Ok(rt_film::Rect { x0, y0, x1, y1 })
}

/// `--accel`'s help, naming the default from the accel crate.
fn accel_help() -> String {
    format!(
        "Acceleration structure and its options, KIND[:OPTION...]: bvh (binned-SAH binary BVH), \
         qbvh (four-wide BVH), bvh8 (eight-wide BVH), two-level (per-object BVHs under a top \
         level that follows animated instances), clusters (rigid-body entry-point clustering, \
         clusters:t=8), grid (uniform grid), irregular-grid, iosp0, iosp4, iosp2 (implicit BVHs in the \
         triangle order; the scene is reordered) or brute-force (tests every triangle; \
         for checking only), e.g. qbvh:evh=14:compact or qbvh:order=distance; the options are listed \
         in crates/accel/src/spec.rs. [default: `[render] accel`, else {}]",
        rt_accel::DEFAULT_ACCEL
    )
}

/// Parses `--integrator` (a usage error, exit code 2, when it does not parse).
pub fn parse_integrator(s: &str) -> Result<IntegratorSpec, String> {
    s.parse()
        .map_err(|e: rt_integrators::IntegratorSpecError| e.to_string())
}

/// Subcommands.
#[derive(Subcommand, Debug)]
pub enum Command {
    /// Measure acceleration structures: build time, memory, Mrays/s and traversal work for
    /// primary, incoherent (diffuse bounce) and shadow rays, after checking their answers
    /// against the binary BVH (docs/benchmarks.md, "Accel benchmark").
    BenchAccel(crate::bench_accel::BenchArgs),
    /// Measure seconds per frame on an animated scene: each structure's update (top-level
    /// rebuild or refit, or a flat structure's full rebuild) and the trace of primary, bounce
    /// and shadow rays, after checking its answers against a flat bvh8 (docs/benchmarks.md,
    /// "Rigid-body clustering").
    BenchAnim(crate::bench_anim::BenchAnimArgs),
    /// Compare image A with the reference B: MSE, relMSE, RMSE, PSNR and SSIM, one `name value`
    /// per line (or JSON), optionally a false-colour error image (docs/experiments.md).
    Compare(crate::compare::CompareArgs),
    /// Apply one denoiser to a saved frame (an EXR written with `--aov`): `render denoise
    /// IN.exr --denoiser NAME[:options] -o OUT` (docs/denoising.md).
    Denoise(crate::denoise::DenoiseArgs),
    /// Render a high-sample reference image (its own random streams, independent of any normal
    /// render) or take it from the reference cache; prints the EXR's path (docs/experiments.md).
    Reference(crate::reference::ReferenceArgs),
    /// Run an experiment: scenes x methods x budgets against references; writes images,
    /// results.csv, slopes.csv, log-log plots and report.md (docs/experiments.md).
    Experiment(crate::experiment::ExperimentArgs),
    /// Run the numerical stress suite: scaled and moved scenes compared within noise,
    /// self-intersection counts, bad geometry and bad values (docs/experiments.md, "Numerical
    /// stress tests"). One line per case; exit code 1 if any fails.
    Stress(crate::stress::StressArgs),
    /// Real-time mode: a window that path traces the animated scene at 1 spp per frame,
    /// denoises with SVGF, plays the animation and orbits the camera with the mouse (drag,
    /// wheel); or --headless, a sequence within a per-frame --frame-budget that reports frames
    /// per second (docs/real-time.md).
    View(crate::view::ViewArgs),
    /// Merge part files (`render SCENE --sample-range/--region -o P.rpart`, or `render part`)
    /// into the image the whole render would have written, bit for bit; refuses parts that do
    /// not belong together, overlap or leave a gap (docs/distributed.md).
    Merge(crate::parts::MergeArgs),
    /// Cut a render into parts for a scheduler: tiles x sample ranges x frames, written as a
    /// JSON plan that `render part` and `render merge --plan` read (docs/distributed.md).
    Plan(crate::parts::PlanArgs),
    /// Render part I of a plan into a directory: what a scheduler's task runs.
    Part(crate::parts::PartArgs),
    /// Translate a Mitsuba scene file (.xml) into our TOML format: the TOML renders the same
    /// image as the XML (docs/scene-format.md, "Mitsuba scene files").
    Convert(crate::convert::ConvertArgs),
    /// Write a procedural scene's triangles to a Wavefront OBJ file (one `o` per part), e.g.
    /// to benchmark other ray tracers on the same geometry.
    GenScene {
        /// worst-case, rotated, mixed or million.
        name: String,
        /// Output file (.obj).
        #[arg(short, long)]
        output: PathBuf,
    },
}

#[cfg(test)]
mod tests {
    use super::*;
    use clap::CommandFactory;

    #[test]
    fn cli_definition_is_consistent() {
        Args::command().debug_assert();
    }

    #[test]
    fn stats_is_an_opt_in_flag() {
        assert!(!Args::try_parse_from(["render", "s.toml"]).unwrap().stats);
        assert!(
            Args::try_parse_from(["render", "s.toml", "--stats"])
                .unwrap()
                .stats
        );
        assert!(Args::try_parse_from(["render", "s.toml", "--stats=yes"]).is_err());
    }

    #[test]
    fn flags_parse() {
        let a = Args::try_parse_from([
            "render",
            "s.toml",
            "-o",
            "x.png",
            "--spp",
            "8",
            "--integrator",
            "path-bsdf",
            "--accel",
            "brute-force",
            "--max-depth",
            "3",
            "--threads",
            "2",
            "--seed",
            "9",
            "--camera",
            "c",
            "--aov",
            "albedo,normal",
            "--exposure",
            "-1",
        ])
        .unwrap();
        assert_eq!(a.spp, Some(8));
        assert_eq!(a.integrator, "path-bsdf".parse().ok());
        assert_eq!(a.accel.as_deref(), Some("brute-force"));
        assert!(a.command.is_none());
        assert_eq!(a.aov.unwrap(), vec!["albedo", "normal"]);
        assert_eq!(a.exposure, -1.0);
        assert!(Args::try_parse_from(["render", "s.toml", "--integrator", "vcm"]).is_err());
    }

    #[test]
    fn subcommands_leave_rendering_alone() {
        let a =
            Args::try_parse_from(["render", "bench-accel", "gen:mixed", "--threads", "2"]).unwrap();
        let Some(Command::BenchAccel(b)) = &a.command else {
            panic!("{a:?}")
        };
        assert_eq!(b.input, "gen:mixed");
        assert_eq!(b.threads, Some(2));
        let a = Args::try_parse_from(["render", "stress", "--long", "--spp", "8", "--seed", "3"])
            .unwrap();
        let Some(Command::Stress(s)) = &a.command else {
            panic!("{a:?}")
        };
        assert!(s.long && s.spp == Some(8) && s.seed == 3 && s.only.is_empty());
        let a = Args::try_parse_from(["render", "gen-scene", "rotated", "-o", "r.obj"]).unwrap();
        assert!(matches!(a.command, Some(Command::GenScene { .. })));
        let a = Args::try_parse_from(["render", "compare", "a.exr", "b.png", "--json"]).unwrap();
        let Some(Command::Compare(c)) = &a.command else {
            panic!("{a:?}")
        };
        assert_eq!(
            (c.test.to_str(), c.reference.to_str()),
            (Some("a.exr"), Some("b.png"))
        );
        assert!(c.json && c.error_image.is_none());
        assert_eq!((c.epsilon, c.peak), (0.01, 1.0));
        assert!(Args::try_parse_from(["render", "compare", "a.exr"]).is_err());
        assert!(Args::try_parse_from(["render", "compare", "a", "b", "--epsilon", "0"]).is_err());
        // The scene is still required without a subcommand.
        assert!(Args::try_parse_from(["render", "--spp", "4"]).is_err());
        let a = Args::try_parse_from(["render", "scene.toml", "-o", "out.exr"]).unwrap();
        assert_eq!(a.scene, Some(PathBuf::from("scene.toml")));
        assert!(a.command.is_none());
    }
}
