//! A whole experiment without the CLI: two methods on a procedural scene against a rendered
//! reference, into a temporary folder; prints each run's relMSE and the report's path.
//! `cargo run --release -p rt-experiment --example tiny_experiment`
use rt_experiment::{config, prepare_out, run, Cache, Silent};

const CONFIG: &str = r#"
[[scene]]
path = "gen:rotated"
resolution = [48, 32]
reference = { spp = 64 }

[[method]]
name = "path"
spp = [1, 4, 16]

[[method]]
name = "path-bsdf"
integrator = "path-bsdf"
spp = [1, 4, 16]
"#;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let dir = tempfile::tempdir()?;
    let file = dir.path().join("tiny.toml");
    std::fs::write(&file, CONFIG)?;
    let plan = config::load(&file)?;
    let out = dir.path().join("out");
    prepare_out(&out)?;
    let outcome = run(&plan, &out, &Cache::new(&dir.path().join("cache")), &Silent)?;
    for row in &outcome.results.rows {
        let method = &plan.methods[plan.pairs[row.pair].method].name;
        println!(
            "{method} at {} spp: relMSE {:.3e}",
            row.spp, row.metrics.relmse
        );
    }
    println!("{}", outcome.report.display());
    Ok(())
}
