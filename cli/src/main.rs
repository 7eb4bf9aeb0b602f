//! `render`: the command-line front end. It parses arguments (clap), calls the libraries and
//! prints. `render SCENE` runs an `rt_session::RenderJob` (`render.rs`); `plan`, `part`, `merge`
//! (`parts.rs`) cut, run and merge jobs; `reference`, `experiment`, `compare`, `bench-accel`,
//! `bench-anim` call `rt-experiment`; `denoise` (`denoise.rs`) filters a saved frame, `convert`
//! a Mitsuba scene, `gen-scene` writes a procedural scene as OBJ, `stress` calls `rt-validate`,
//! `view` (`view/`) drives an `rt_session::viewer::LiveView`. Libraries return typed errors;
//! this prints one line on stderr and exits non-zero (2 for usage errors, 1 otherwise).

mod args;
mod bench_accel;
mod bench_anim;
mod compare;
mod convert;
mod denoise;
mod experiment;
mod parts;
mod progress;
mod reference;
mod render;
mod stress;
mod view;

use clap::Parser;
use std::process::ExitCode;

fn main() -> ExitCode {
    let args = match args::Args::try_parse() {
        Ok(a) => a,
        Err(e) => {
            // --help and --version are "errors" that print to stdout and succeed.
            let code = if e.use_stderr() { 2 } else { 0 };
            let _ = e.print();
            return ExitCode::from(code);
        }
    };
    let result = run(&args);
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("error: {}", one_line(&e));
            ExitCode::from(1)
        }
    }
}

/// Runs what the arguments ask for (also for `render part`, which runs a render of a plan).
pub(crate) fn run(args: &args::Args) -> anyhow::Result<()> {
    match &args.command {
        Some(args::Command::BenchAccel(bench)) => bench_accel::run(bench),
        Some(args::Command::BenchAnim(bench)) => bench_anim::run(bench),
        Some(args::Command::Compare(c)) => compare::run(c),
        Some(args::Command::Denoise(d)) => denoise::run(d),
        Some(args::Command::Reference(r)) => reference::run(r),
        Some(args::Command::Experiment(x)) => experiment::run(x),
        Some(args::Command::Stress(stress)) => stress::run(stress),
        Some(args::Command::View(v)) => view::run(v),
        Some(args::Command::Merge(m)) => parts::merge(m),
        Some(args::Command::Plan(p)) => parts::plan(p),
        Some(args::Command::Part(p)) => parts::part(p),
        Some(args::Command::Convert(c)) => convert::run(c),
        Some(args::Command::GenScene { name, output }) => {
            Ok(rt_experiment::bench::input::write_obj(name, output)?)
        }
        None => render::run(args),
    }
}

/// The error and its causes on one line. Library errors already print their cause (so that
/// they read well alone), so a cause whose text is already there is not repeated.
fn one_line(e: &anyhow::Error) -> String {
    let mut line = e.to_string();
    for cause in e.chain().skip(1) {
        let text = cause.to_string();
        if !line.contains(&text) {
            line.push_str(": ");
            line.push_str(&text);
        }
    }
    line
}
