//! Command-line arguments.

use clap::{Parser, ValueEnum};
use std::path::PathBuf;

/// Render a TOML scene (see docs/scene-format.md) to an EXR or PNG image.
///
/// Settings come from the command line; any left out fall back to the scene's optional
/// `[render]` table, then to the defaults shown here.
#[derive(Parser, Debug)]
#[command(name = "render", version, about, long_about = None)]
pub struct Args {
    /// Scene file (TOML).
    pub scene: PathBuf,

    /// Output image; the extension picks the format: .exr (linear float, AOVs as extra
    /// channels) or .png (sRGB, exposure then clamp). [default: `[render] output`, else
    /// the scene's file name with .exr]
    #[arg(short, long)]
    pub output: Option<PathBuf>,

    /// Samples per pixel. [default: `[render] spp`, else 64]
    #[arg(long)]
    pub spp: Option<u32>,

    /// Light transport algorithm: path (path tracing, next-event estimation + MIS),
    /// path-bsdf (path tracing with BSDF sampling only), direct (direct lighting: one bounce,
    /// NEE + MIS), ao (ambient occlusion). [default: `[render] integrator`, else path]
    #[arg(long, value_enum)]
    pub integrator: Option<IntegratorKind>,

    /// Acceleration structure: bvh (binned-SAH binary BVH) or brute-force (tests every
    /// triangle; for checking only). [default: `[render] accel`, else bvh]
    #[arg(long, value_enum)]
    pub accel: Option<AccelKind>,

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
    /// visible surface, averaged over the pixel's samples) and variance (of the pixel mean).
    /// Only computed when asked for. [default: `[render] aov`, else none]
    #[arg(long, value_delimiter = ',')]
    pub aov: Option<Vec<String>>,

    /// Exposure in stops applied before PNG tone mapping (EXR is always written unscaled).
    #[arg(long, default_value_t = 0.0, allow_negative_numbers = true)]
    pub exposure: f32,

    /// Maximum occluder distance for the ao integrator. [default: unlimited]
    #[arg(long)]
    pub ao_distance: Option<f32>,

    /// No progress bar and no summary line.
    #[arg(short, long)]
    pub quiet: bool,
}

/// `--integrator` values.
#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub enum IntegratorKind {
    /// Path tracing with next-event estimation and MIS.
    Path,
    /// Path tracing with BSDF sampling only.
    PathBsdf,
    /// Direct lighting.
    Direct,
    /// Ambient occlusion.
    Ao,
}

/// `--accel` values.
#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub enum AccelKind {
    /// Binned-SAH binary BVH.
    Bvh,
    /// Every triangle for every ray.
    BruteForce,
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
        assert_eq!(a.integrator, Some(IntegratorKind::PathBsdf));
        assert_eq!(a.accel, Some(AccelKind::BruteForce));
        assert_eq!(a.aov.unwrap(), vec!["albedo", "normal"]);
        assert_eq!(a.exposure, -1.0);
        assert!(Args::try_parse_from(["render", "s.toml", "--integrator", "bdpt"]).is_err());
    }
}
