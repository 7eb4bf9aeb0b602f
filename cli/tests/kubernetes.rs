//! The Kubernetes manifests in tools/kubernetes stay in step with their plan: the committed
//! plan is what its documented `render plan` command writes today, and the Indexed Job runs
//! exactly one pod per part of it, selecting the part by its completion index.

use std::path::Path;

fn field(yaml: &str, key: &str) -> u64 {
    let line = yaml
        .lines()
        .find(|l| l.trim_start().starts_with(&format!("{key}:")))
        .unwrap_or_else(|| panic!("no {key} in the manifest"));
    line.split(':').nth(1).unwrap().trim().parse().unwrap()
}

#[test]
fn the_indexed_job_has_one_completion_per_part_of_the_plan() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("..");
    let dir = root.join("tools/kubernetes");
    let committed = std::fs::read_to_string(dir.join("plan.json")).unwrap();
    // The command README.md gives, into a temporary file.
    let tmp = tempfile::tempdir().unwrap();
    let fresh = tmp.path().join("plan.json");
    let out = std::process::Command::new(env!("CARGO_BIN_EXE_render"))
        .current_dir(&root)
        .args([
            "plan",
            "scenes/cornell-box.toml",
            "--tiles",
            "256x256",
            "--sample-splits",
            "2",
        ])
        .arg("-o")
        .arg(&fresh)
        .args(["--", "--spp", "64", "-o", "/work/out/cornell.exr"])
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    assert_eq!(
        std::fs::read_to_string(&fresh).unwrap(),
        committed,
        "tools/kubernetes/plan.json is stale: regenerate it (tools/kubernetes/README.md)"
    );
    let plan: serde_json::Value = serde_json::from_str(&committed).unwrap();
    let parts = plan["parts"].as_array().unwrap().len() as u64;

    let job = std::fs::read_to_string(dir.join("parts-job.yaml")).unwrap();
    assert!(job.contains("completionMode: Indexed"));
    assert_eq!(field(&job, "completions"), parts, "one pod per part");
    assert!(field(&job, "parallelism") <= parts);
    assert!(
        job.contains("render part tools/kubernetes/plan.json --index \"$JOB_COMPLETION_INDEX\"")
    );
    let merge = std::fs::read_to_string(dir.join("merge-job.yaml")).unwrap();
    assert!(
        merge.contains(r#"["render", "merge", "--plan", "tools/kubernetes/plan.json", "parts"]"#)
    );
}
