//! The hierarchical stopping criterion driving real renders (`rt_session::render_adaptive`):
//! the image and the sample count are the same for any thread count, finished blocks take
//! fewer samples than the cap, a light-path technique stops by it too, and no block of a
//! camera-ray render stops above its threshold (recomputed here from the final film, which a
//! finished block no longer changes).

use rt_film::{AovSet, Film, FilmBuffers};
use rt_integrators::{CameraRays, LightTracer, PathIntegrator, Technique};
use rt_session::{render_adaptive, StopReason, StopRule};
use rt_testkit::{shipped_scene, Renderer, SceneExt};

fn adaptive(
    technique: &dyn Technique,
    threads: usize,
    v: f32,
    cap: u32,
) -> (Film, rt_session::Adaptive) {
    let scene = shipped_scene("cornell-box.toml").with_resolution(48, 48);
    let r = Renderer::new(&scene);
    let mut film = r.film(FilmBuffers::from(AovSet::default()).with_halves());
    let rule = StopRule {
        error: Some(v),
        time_limit: None,
        max_spp: cap,
    };
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .unwrap();
    let a = pool
        .install(|| render_adaptive(&r.ctx(), technique, &mut film, 9, &rule, &|_| {}))
        .unwrap();
    (film, a)
}

#[test]
fn adaptive_path_tracing_is_deterministic_and_saves_samples() {
    let pt = CameraRays(Box::new(PathIntegrator::new(8)));
    let (one, a1) = adaptive(&pt, 1, 5e-3, 1024);
    let (two, a2) = adaptive(&pt, 2, 5e-3, 1024);
    assert_eq!(one.mean_image(), two.mean_image());
    assert_eq!(a1.stats.samples, a2.stats.samples);
    let uniform = 48 * 48 * 1024;
    eprintln!(
        "{:?} after {} spp: {} of {uniform} samples",
        a1.reason, a1.spp, a1.stats.samples
    );
    // Blocks finished early: under half the samples the cap gives every pixel (measured 28 %).
    assert!(
        a1.stats.samples < uniform / 2,
        "{} samples",
        a1.stats.samples
    );
    // And the per-pixel counts differ: finished pixels kept the count they stopped at.
    let counts: Vec<u32> = one.pixels().map(|p| p.count()).collect();
    assert!(
        counts.iter().min() < counts.iter().max(),
        "no block stopped early"
    );
    assert!(
        counts.iter().all(|c| c % 2 == 0),
        "decisions follow even sample counts"
    );
}

#[test]
fn light_tracing_stops_by_the_criterion() {
    let (film, a) = adaptive(&LightTracer::new(8), 2, 5e-3, 4096);
    eprintln!("{:?} after {} spp", a.reason, a.spp);
    assert_eq!(a.reason, StopReason::Converged);
    assert!(a.spp < 4096);
    assert!(film.light_paths() > 0);
}

/// The block error of the thesis (`rt_film::stopping`'s module doc), computed independently
/// from the film's mean and even-half images.
fn block_error(film: &Film, b: &rt_film::stopping::Block) -> f64 {
    let (all, even) = (film.mean_image(), film.half_image(0).unwrap());
    let w = film.width() as usize;
    let mut sum = 0.0f64;
    for y in b.y0 as usize..b.y1 as usize {
        for x in b.x0 as usize..b.x1 as usize {
            let (i, a) = (all[y * w + x], even[y * w + x]);
            let num: f64 = (0..3).map(|c| f64::from((i[c] - a[c]).abs())).sum();
            let den: f64 = (0..3).map(|c| f64::from(i[c])).sum::<f64>().max(1e-8);
            sum += num / den.sqrt();
        }
    }
    let area = f64::from((b.x1 - b.x0) * (b.y1 - b.y0));
    let image = f64::from(film.width() * film.height());
    (area / image).sqrt() * sum / area
}

#[test]
fn no_block_stops_above_its_threshold() {
    let pt = CameraRays(Box::new(PathIntegrator::new(8)));
    let v = 5e-3;
    let (film, a) = adaptive(&pt, 2, v, 1024);
    assert!(a.finished_blocks.len() > 4, "{:?}", a.finished_blocks);
    let worst = a
        .finished_blocks
        .iter()
        .map(|b| block_error(&film, b))
        .fold(0.0, f64::max);
    eprintln!(
        "{} finished blocks, worst error {worst:.3e} against {v:.0e}",
        a.finished_blocks.len()
    );
    // f32 sums in the criterion against f64 here: a relative margin of 10⁻⁴.
    assert!(worst < f64::from(v) * (1.0 + 1e-4), "{worst}");
}
