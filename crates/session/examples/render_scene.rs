//! Load a scene, build the default structure (bvh8), render 16 spp, write an EXR: what `render`
//! does, without the CLI. `cargo run --release -p rt-session --example render_scene -- SCENE OUT`
//! (defaults: the Cornell box, `cornell.exr`).
use rt_session::{pick_camera, Budgets, Overrides, Session};
use std::path::PathBuf;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let mut args = std::env::args().skip(1);
    let scene = PathBuf::from(args.next().unwrap_or("scenes/cornell-box.toml".into()));
    let out = PathBuf::from(args.next().unwrap_or("cornell.exr".into()));
    let loaded = rt_scene::load_any(&scene)?;
    let settings = Overrides::default().resolve(&loaded.render, &scene)?;
    let camera = pick_camera(&loaded.scene, &scene, None)?;
    let accel = settings.accel.build_scene(&loaded.scene);
    let integrator = settings.integrator.build();
    let ctx = rt_integrators::Ctx {
        scene: &loaded.scene,
        accel: accel.as_ref(),
        camera,
    };
    let session = Session {
        ctx,
        integrator: integrator.as_ref(),
        seed: settings.seed,
        stream: Default::default(),
        aovs: settings.aovs,
    };
    let film = session.render(&Budgets::Spp(vec![16]), &|_| {}, &mut |_, _| {
        Ok::<_, std::io::Error>(())
    })?;
    rt_film::write_image(&out, &film, &Default::default())?;
    println!("{} -> {}", scene.display(), out.display());
    Ok(())
}
