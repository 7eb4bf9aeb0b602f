//! `render convert scene.xml -o scene.toml`: `rt_scene::mitsuba::convert_file`, the same
//! translation `render scene.xml` renders.

use anyhow::Result;
use std::path::PathBuf;

/// `render convert` arguments.
#[derive(clap::Args, Debug)]
pub struct ConvertArgs {
    /// The Mitsuba scene file (.xml).
    #[arg(value_name = "SCENE.xml")]
    pub input: PathBuf,

    /// The TOML file to write; file names in it are relative to its directory.
    #[arg(short, long, value_name = "OUT.toml")]
    pub output: PathBuf,

    /// A parameter of the scene: replaces `$NAME`, winning over its `<default>`. Repeatable.
    #[arg(short = 'D', value_name = "NAME=VALUE", value_parser = rt_scene::mitsuba::parse_define)]
    pub define: Vec<(String, String)>,
}

/// Runs `render convert`.
pub fn run(args: &ConvertArgs) -> Result<()> {
    for w in rt_scene::mitsuba::convert_file(&args.input, &args.output, &args.define)? {
        eprintln!("warning: {w}");
    }
    Ok(())
}
