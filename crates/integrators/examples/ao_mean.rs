//! Ambient occlusion of a procedural scene at 4 spp through `IntegratorSpec` and its technique's passes,
//! printing the image mean: the integrators crate used on its own.
//! `cargo run --release -p rt-integrators --example ao_mean [SPEC]` (default `ao:distance=2`).
use rt_film::{Film, FilmBuffers};
use rt_integrators::{Ctx, IntegratorSpec, SamplePass};

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let spec: IntegratorSpec = std::env::args()
        .nth(1)
        .unwrap_or("ao:distance=2".into())
        .parse()?;
    let scene = rt_scene::procedural::generate("rotated")?;
    let mut camera = scene.cameras[0].clone();
    (camera.width, camera.height) = (64, 48);
    let accel = rt_accel::AccelSpec::default()
        .build(&scene.triangles)
        .expect("the default structure builds");
    let ctx = Ctx {
        scene: &scene,
        accel: accel.as_ref(),
        camera: &camera,
    };
    let mut film = Film::new(camera.width, camera.height, FilmBuffers::default());
    let pass = SamplePass {
        indices: 0..4,
        stream: rt_core::SampleStream::Render,
        pixels: None,
        centre_first: false,
    };
    let stats = spec.build().render_pass(&ctx, &mut film, 0, &pass, &|_| {});
    let mean = film.mean_image().iter().sum::<rt_core::Rgb>() / (64.0 * 48.0);
    println!("{spec}: mean {mean:?}, {} rays", stats.rays.rays);
    Ok(())
}
