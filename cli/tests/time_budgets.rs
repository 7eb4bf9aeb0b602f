//! Time-budgeted rendering (`seconds = [...]` in an experiment), on which every equal-time
//! result depends (`configs/accel.toml`): driven through `render experiment`, read back from
//! `results.csv` (`spp` and `seconds` used, `budget` asked for).
//!
//! What must hold (`docs/experiments.md`, "Budgets"): the budgets are snapshots of one
//! progressive render, so samples grow with the budget; a budget is reached by passes sized
//! from the time per sample, and the loop stops when less than half a sample's time remains,
//! so the time used is at least the budget less one sample's time (`seconds / spp`); and a
//! pass at most doubles the samples so far, so the last pass took at most half the time used,
//! and the time is at most the budget plus that pass: `seconds ≤ budget + seconds / 2`, i.e.
//! `seconds ≤ 2 · budget`. (Timing on a loaded machine can stretch one pass; the bound has no
//! slack beyond that doubling, so a run on a machine slower than the pass sizing assumed can
//! fail it, which is then a real finding about the budgets.)

use std::process::Command;

mod common;

const CONFIG: &str = r#"
name = "budgets"

[[scene]]
name = "room"
path = "scene.toml"
resolution = [32, 32]
reference = { spp = 16 }

[[method]]
name = "nee"
integrator = "path"
seconds = [0.05, 0.1, 0.2, 0.4]
"#;

#[test]
fn time_budgets_grow_samples_and_use_the_time_asked_for() {
    let dir = tempfile::tempdir().unwrap();
    let scene = format!(
        "[[camera]]\nname = \"main\"\nposition = [0.0, 1.0, 3.0]\nlook_at = [0.0, 1.0, 0.0]\n\
         fov = 40.0\nresolution = [64, 64]\n{}\n[render]\nmax_depth = 3\n",
        common::FLOOR_AND_LAMP
    );
    std::fs::write(dir.path().join("scene.toml"), scene).unwrap();
    std::fs::write(dir.path().join("x.toml"), CONFIG).unwrap();
    let o = Command::new(env!("CARGO_BIN_EXE_render"))
        .current_dir(dir.path())
        .args([
            "experiment",
            "x.toml",
            "--out",
            "out",
            "--threads",
            "2",
            "-q",
        ])
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let csv = std::fs::read_to_string(dir.path().join("out/results.csv")).unwrap();
    let mut lines = csv.lines();
    let header: Vec<&str> = lines.next().unwrap().split(',').collect();
    let col = |name: &str| header.iter().position(|h| *h == name).unwrap();
    let (spp_col, seconds_col, budget_col) = (col("spp"), col("seconds"), col("budget"));
    let runs: Vec<(u32, f64, f64)> = lines
        .map(|l| {
            let f: Vec<&str> = l.split(',').collect();
            (
                f[spp_col].parse().unwrap(),
                f[seconds_col].parse().unwrap(),
                f[budget_col].parse().unwrap(),
            )
        })
        .collect();
    eprintln!("(spp, seconds, budget): {runs:?}");
    assert_eq!(runs.len(), 4, "{csv}");
    for w in runs.windows(2) {
        assert!(w[0].2 < w[1].2, "budgets in order: {runs:?}");
        assert!(
            w[1].0 > w[0].0,
            "samples must grow with the budget: {runs:?}"
        );
        assert!(w[1].1 >= w[0].1, "time must grow with the budget: {runs:?}");
    }
    for &(spp, seconds, budget) in &runs {
        let per_sample = seconds / f64::from(spp);
        assert!(
            seconds >= budget - per_sample,
            "budget {budget} s: stopped at {seconds} s, more than one sample's time \
             ({per_sample} s) early"
        );
        assert!(
            seconds <= 2.0 * budget,
            "budget {budget} s: used {seconds} s, more than one (at most doubling) pass over"
        );
    }
}
