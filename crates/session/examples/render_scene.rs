//! Load a scene and render it as `render SCENE -o OUT --spp 16` does (the scene's `[render]`
//! table, the structure it picks, its denoiser), without the CLI:
//! `cargo run --release -p rt-session --example render_scene -- SCENE OUT` (defaults: the
//! Cornell box, `cornell.exr`).
use rt_session::{load_scene, Overrides, RenderJob};
use std::path::PathBuf;
use std::sync::atomic::AtomicBool;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let mut args = std::env::args().skip(1);
    let scene = PathBuf::from(args.next().unwrap_or("scenes/cornell-box.toml".into()));
    let out = PathBuf::from(args.next().unwrap_or("cornell.exr".into()));
    let loaded = load_scene(&scene, None, &[])?;
    let settings = Overrides {
        spp: Some(16),
        output: Some(out.clone()),
        ..Overrides::default()
    }
    .resolve(&loaded.loaded, &scene)?;
    let job = RenderJob::new(&scene, settings);
    job.run_loaded(loaded, Default::default(), &(), &AtomicBool::new(false))?;
    println!("{} -> {}", scene.display(), out.display());
    Ok(())
}
