//! Time of one SVGF frame (all stages, both signals) at a given size, on a real frame of a
//! shipped scene: `cargo run --release -p rt-temporal --example svgf_speed -- [SCENE] [SIZE]
//! [FRAMES]` (defaults scenes/animated.toml, 256, 20). Prints the median time per frame.

use rt_core::SampleStream;
use rt_film::{AovSet, Channel, Film, FilmBuffers, NoisyFrame};
use rt_integrators::{render_guides, Ctx, GuideOptions, IntegratorSpec, SamplePass};
use rt_temporal::{TemporalFrame, TemporalSpec};
use std::time::Instant;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args: Vec<String> = std::env::args().collect();
    let scene_path = args.get(1).map_or("scenes/animated.toml", |s| s.as_str());
    let size: u32 = args.get(2).map_or(Ok(256), |s| s.parse())?;
    let frames: usize = args.get(3).map_or(Ok(20), |s| s.parse())?;
    let spec = args.get(4).map_or("svgf", |s| s.as_str());
    let loaded = rt_scene::load_any(std::path::Path::new(scene_path))?;
    let scene = loaded.scene;
    let camera = scene.cameras[0].resized(size, size);
    let accel = rt_accel::AccelSpec::default_for_scene(&scene)
        .build(&scene)
        .expect("the structure builds over the scene");
    let ctx = Ctx {
        scene: &scene,
        accel: accel.as_ref(),
        camera: &camera,
    };
    let technique = "path".parse::<IntegratorSpec>()?.build();
    let aovs = AovSet::for_channels(&[Channel::Direct, Channel::Indirect, Channel::Emission]);
    let mut film = Film::new(size, size, FilmBuffers::for_outputs(aovs));
    let pass = SamplePass {
        indices: 0..1,
        stream: SampleStream::Render,
        pixels: None,
        centre_first: true,
    };
    technique.render_pass(&ctx, &mut film, 1, &pass, &|_| {});
    let frame = NoisyFrame::from_film(&film, aovs);
    let t = Instant::now();
    let guides = render_guides(&ctx, None, &GuideOptions::default());
    let guide_time = t.elapsed();
    let mut d = spec.parse::<TemporalSpec>()?.build()?;
    let mut times = Vec::new();
    for _ in 0..frames {
        let t = Instant::now();
        d.push(&TemporalFrame {
            frame: &frame,
            guides: Some(&guides),
            extra: &[],
        })?;
        times.push(t.elapsed().as_secs_f64());
    }
    times.sort_by(f64::total_cmp);
    println!(
        "{scene_path}: {size}x{size}, {}: median {:.2} ms per frame over {frames} frames ({} threads); guide pass {:.2} ms",
        d.name(),
        times[times.len() / 2] * 1e3,
        rayon::current_num_threads(),
        guide_time.as_secs_f64() * 1e3
    );
    Ok(())
}
