//! `.ci/run` itself: a step that fails fails the run. The script is run from a copy of `.ci/`
//! beside stub `cargo`, `.ci/setup`, `tools/oidn/setup.sh`, `.ci/python`, `.ci/slurm` and
//! `.ci/kubernetes` that record their calls; so the test checks the script's control flow, not
//! the tools.
//!
//! The failure it guards against: `bash .ci/setup && cargo test ...` under `set -e` skips the
//! tests when setup fails and carries on (bash ignores a failure on the left of `&&`), and the
//! run passes.

use std::path::Path;
use std::process::Command;

/// Runs a copy of `.ci/run` in a scratch tree whose `.ci/setup` exits with `setup_status`,
/// with a `cargo` that exits with `cargo_status` when its arguments contain `fail_on`.
/// Returns the run's success and the recorded calls, one a line.
fn run_ci(setup_status: i32, fail_on: &str) -> (bool, String) {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("..");
    let d = tempfile::tempdir().unwrap();
    let t = d.path();
    for dir in [".ci", "bin", "tools/oidn"] {
        std::fs::create_dir_all(t.join(dir)).unwrap();
    }
    std::fs::copy(root.join(".ci/run"), t.join(".ci/run")).unwrap();
    let calls = t.join("calls");
    let stub = |path: &str, body: &str| {
        let p = t.join(path);
        std::fs::write(&p, format!("#!/usr/bin/env bash\n{body}\n")).unwrap();
        Command::new("chmod").arg("+x").arg(&p).status().unwrap();
    };
    let log = calls.display();
    stub(
        ".ci/setup",
        &format!("echo setup >> {log}; exit {setup_status}"),
    );
    stub(".ci/python", &format!("echo python >> {log}"));
    stub(".ci/slurm", &format!("echo slurm >> {log}"));
    stub(".ci/kubernetes", &format!("echo kubernetes >> {log}"));
    stub(
        "tools/oidn/setup.sh",
        &format!("echo oidn-setup >> {log}; echo /nonexistent/libOpenImageDenoise.so.2"),
    );
    stub(
        "bin/cargo",
        &format!("echo \"cargo $*\" >> {log}\ncase \"$*\" in *'{fail_on}'*) exit 1;; esac; exit 0"),
    );
    let path = format!(
        "{}:{}",
        t.join("bin").display(),
        std::env::var("PATH").unwrap()
    );
    let status = Command::new("bash")
        .arg(t.join(".ci/run"))
        .env("PATH", path)
        .output()
        .unwrap()
        .status;
    (
        status.success(),
        std::fs::read_to_string(&calls).unwrap_or_default(),
    )
}

#[test]
fn a_failing_setup_fails_the_run_before_any_test() {
    let (ok, calls) = run_ci(1, "never");
    assert!(!ok, "the run passed although setup failed:\n{calls}");
    assert!(
        calls.contains("setup") && !calls.contains("cargo test"),
        "tests ran after a failed setup:\n{calls}"
    );
}

#[test]
fn every_step_runs_and_a_failing_one_fails_the_run() {
    // Control: with every stub passing, the run passes and runs each step.
    let (ok, calls) = run_ci(0, "never");
    assert!(ok, "{calls}");
    for step in [
        "cargo fmt",
        "cargo clippy",
        "cargo doc",
        "setup",
        "cargo test --workspace --release",
        "cargo check --manifest-path fuzz/Cargo.toml",
        "oidn-setup",
        "cargo test --release -p rt-denoise --features oidn",
        "cargo test --profile ci",
        "python",
        "slurm",
        "kubernetes",
    ] {
        assert!(calls.contains(step), "{step} did not run:\n{calls}");
    }
    for failing in [
        "--workspace --release",
        "fuzz/Cargo.toml",
        "--features oidn",
        "--profile ci",
    ] {
        let (ok, calls) = run_ci(0, failing);
        assert!(!ok, "a failing `{failing}` passed the run:\n{calls}");
        assert!(
            !calls.contains("slurm"),
            "the run went on after `{failing}`:\n{calls}"
        );
    }
}
