//! `render convert scene.xml -o scene.toml`: a Mitsuba scene file translated into our TOML
//! format by `rt_scene::mitsuba::to_toml`, the same translation `render scene.xml` renders.

use anyhow::{bail, Result};
use std::path::{Path, PathBuf};

/// `render convert` arguments.
#[derive(clap::Args, Debug)]
pub struct ConvertArgs {
    /// The Mitsuba scene file (.xml).
    #[arg(value_name = "SCENE.xml")]
    pub input: PathBuf,

    /// The TOML file to write; file names in it are relative to its directory when it sits
    /// beside the scene, else absolute.
    #[arg(short, long, value_name = "OUT.toml")]
    pub output: PathBuf,

    /// A parameter of the scene: replaces `$NAME`, winning over its `<default>`. Repeatable.
    #[arg(short = 'D', value_name = "NAME=VALUE", value_parser = crate::args::parse_define)]
    pub define: Vec<(String, String)>,
}

/// Runs `render convert`.
pub fn run(args: &ConvertArgs) -> Result<()> {
    if !rt_scene::is_mitsuba(&args.input) {
        bail!("{}: not a Mitsuba scene file (.xml)", args.input.display());
    }
    let out_dir = args.output.parent().unwrap_or(Path::new(""));
    let converted = rt_scene::mitsuba::to_toml(
        &args.input,
        Some(out_dir),
        &rt_scene::FileAccess::open(),
        &args.define,
    )?;
    for w in &converted.warnings {
        eprintln!("warning: {w}");
    }
    rt_film::write_bytes_atomic(&args.output, converted.toml.as_bytes())?;
    Ok(())
}
