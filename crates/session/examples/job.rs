//! A render job without the CLI: two frames of an animation, each rendered as two sample
//! ranges into part files and merged into the image of the whole frame (bit for bit); then a
//! checkpointed render, stopped after its first pass and resumed to the end.
//! `cargo run --release -p rt-session --example job` (from the workspace root).
use rt_session::job::{merge, read_parts};
use rt_session::{Checkpointing, Frames, JobError, Overrides, RenderJob, Slice};
use std::sync::atomic::AtomicBool;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let (dir, scene) = (std::env::temp_dir(), "scenes/animated.toml".as_ref());
    let loaded = rt_session::load_scene(scene, None, &[])?.loaded;
    let mut job = RenderJob::new(scene, Overrides::default().resolve(&loaded, scene)?);
    job.frames = Frames::Range(0..2);
    let (go, stop) = (AtomicBool::new(false), AtomicBool::new(true));
    for (k, samples) in [0..6, 6..16].into_iter().enumerate() {
        job.output = dir.join(format!("job-f{{frame}}-{k}.rpart"));
        job.slice = Slice::samples(samples);
        job.run(&(), &go)?;
    }
    for f in 0..2 {
        let parts = read_parts(&[0, 1].map(|k| dir.join(format!("job-f{f}-{k}.rpart"))))?;
        let merged = merge(&parts, &dir.join(format!("job-f{f}.exr")), None)?;
        println!("{merged}");
    }
    (job.frames, job.slice) = (Frames::One(1), Slice::default());
    job.output = dir.join("job-resumed.exr");
    job.checkpoint = Some(Checkpointing::new(dir.join("job.rpart")));
    let stopped = job.run(&(), &stop); // the stop flag is set: one pass, then the checkpoint
    assert!(matches!(stopped, Err(JobError::Interrupted { .. })));
    RenderJob::resume(&dir.join("job.rpart"))?.run(&(), &go)?;
    println!("resumed from the checkpoint -> {}", job.output.display());
    Ok(())
}
