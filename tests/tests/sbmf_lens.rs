//! SBMF end to end through a thin lens: the depth-of-field step (step B) runs on the circles of
//! confusion the renderer records, and the image has the spread SBMF's known bias predicts.
//!
//! The scene is a square emitter (11.9 pixels across) facing a thin-lens camera at a third of
//! the focus distance, on black: its image is the square convolved with the lens's disc of
//! confusion, radius `r = 5` pixels (`Camera::signed_coc_px`), so the per-axis variance of the
//! image's intensity about its centroid is `w²/12 + 1/12 + r²/4` (square, pixel, disc). The
//! high-spp path-traced reference must have it (within 2 %: the lens through the renderer).
//!
//! SBMF filters samples that were already rendered through the lens and then blurs each by its
//! CoC in step B: the double blur the thesis lists as its limitation (docs/experiments.md,
//! "SBMF"). Every square sample lies on the outermost layer (`τ` is the largest |CoC|), blurred
//! by the box of half-width `b = round((√π r − 1)/2)` (the disc's area; `layers.rs`), so SBMF
//! adds the box's variance `((2b+1)² − 1)/12` to the spread of its own 4-spp input. The test
//! accepts the CoC the added spread implies within half a layer spacing (`τ/6`): an added
//! variance between that of the disc of radius `r − τ/6` and the box for `r + τ/6`. Controls
//! in the test, the records' CoCs zeroed (what a pinhole records), halved (radius read as
//! diameter) and doubled, must fail.

use rt_core::glam::Vec3;
use rt_core::{Rgb, RgbImage};
use rt_denoise::{Sbmf, SbmfParams};
use rt_film::{AovSet, FilmBuffers, Sample, SampleRecords};
use rt_integrators::PathIntegrator;
use rt_testkit::{scene_from_toml, Renderer};

const W: u32 = 48;
const H: u32 = 48;

fn scene() -> rt_core::Scene {
    scene_from_toml(&format!(
        r#"
[environment]
color = [0.0, 0.0, 0.0]

[[camera]]
name = "c"
position = [0.0, 0.0, 0.0]
look_at = [0.0, 0.0, -1.0]
fov = 30.0
resolution = [{W}, {H}]
aperture = 0.1256
focus_distance = 4.5

[[material]]
name = "lamp"
color = [0.0, 0.0, 0.0]
emission = [1.0, 1.0, 1.0]
two_sided = true

[[geometry]]
name = "square"
shape = "quad"
vertices = [[-0.1, -0.1, -1.5], [0.1, -0.1, -1.5], [0.1, 0.1, -1.5], [-0.1, 0.1, -1.5]]
material = "lamp"
"#
    ))
}

/// Total, and the per-axis variances of the image's intensity (red channel) about its centroid.
fn moments(img: &[Rgb]) -> (f64, f64, f64) {
    let (mut m0, mut mx, mut my) = (0.0f64, 0.0f64, 0.0f64);
    for (i, c) in img.iter().enumerate() {
        let (x, y) = ((i as u32 % W) as f64 + 0.5, (i as u32 / W) as f64 + 0.5);
        let v = c.x as f64;
        m0 += v;
        mx += v * x;
        my += v * y;
    }
    let (cx, cy) = (mx / m0, my / m0);
    let (mut vx, mut vy) = (0.0f64, 0.0f64);
    for (i, c) in img.iter().enumerate() {
        let (x, y) = ((i as u32 % W) as f64 + 0.5, (i as u32 / W) as f64 + 0.5);
        let v = c.x as f64;
        vx += v * (x - cx).powi(2);
        vy += v * (y - cy).powi(2);
    }
    (m0, vx / m0, vy / m0)
}

/// `r` with every sample's CoC mapped by `f`.
fn with_coc(r: &SampleRecords, f: impl Fn(f32) -> f32) -> SampleRecords {
    let samples: Vec<Sample> = (0..r.len())
        .map(|j| {
            let mut s = r.sample(j);
            s.coc = f(s.coc);
            s
        })
        .collect();
    SampleRecords::from_samples(r.width(), r.height(), &samples).unwrap()
}

/// The per-axis variance the step-B box of a CoC of `r` pixels adds, and that of its disc.
fn box_and_disc(r: f64) -> (f64, f64) {
    let b = ((std::f64::consts::PI.sqrt() * r - 1.0) / 2.0)
        .round()
        .max(0.0);
    (((2.0 * b + 1.0).powi(2) - 1.0) / 12.0, r * r / 4.0)
}

#[test]
fn sbmf_through_a_thin_lens_adds_its_box_to_the_lens_blur() {
    let t = std::time::Instant::now();
    let scene = scene();
    let camera = &scene.cameras[0];
    let r = Renderer::new(&scene).threads(2);
    let integrator = PathIntegrator::new(2);
    let buffers = FilmBuffers::for_outputs(AovSet::default()).with_samples();
    let (mut film, _) = r.render(&integrator, buffers, 4, 1);
    let noisy = moments(&film.mean_image());
    let records = film.take_sample_records().unwrap();
    let (reference, _) = r.render(&integrator, AovSet::default(), 1024, 2);
    let reference = moments(&reference.mean_image());

    let coc = -camera.signed_coc_px(Vec3::new(0.0, 0.0, -1.5)) as f64;
    let pixels_per_unit = H as f64 / (2.0 * (15.0f64).to_radians().tan() * 1.5);
    let width = 0.2 * pixels_per_unit;
    let lens = width * width / 12.0 + 1.0 / 12.0 + coc * coc / 4.0;
    for v in [reference.1, reference.2] {
        assert!(
            (v / lens - 1.0).abs() < 0.02,
            "the reference's spread {v:.3} is not the lens blur's {lens:.3}"
        );
    }

    let sbmf = Sbmf::new(SbmfParams::default()).unwrap();
    let added = |rec: &SampleRecords| -> f64 {
        let img: RgbImage = sbmf.filter_samples(rec, W as usize, H as usize).unwrap();
        let m = moments(img.pixels());
        ((m.1 - noisy.1) + (m.2 - noisy.2)) / 2.0
    };
    // τ = coc: every square sample is on the outermost layer; half a layer spacing is τ/6.
    let (lo, hi) = (
        box_and_disc(coc * 5.0 / 6.0).1,
        box_and_disc(coc * 7.0 / 6.0).0,
    );
    let honest = added(&records);
    let zeroed = added(&with_coc(&records, |_| 0.0));
    let halved = added(&with_coc(&records, |c| 0.5 * c));
    let doubled = added(&with_coc(&records, |c| 2.0 * c));
    eprintln!(
        "CoC {coc:.3} px; reference variance {:.3} {:.3} (lens {lens:.3}); SBMF adds {honest:.3} (accepted {lo:.3}..{hi:.3}, box {:.3}); CoC zeroed {zeroed:.3}, halved {halved:.3}, doubled {doubled:.3}; {:.2?}",
        reference.1,
        reference.2,
        box_and_disc(coc).0,
        t.elapsed()
    );
    let ok = |v: f64| (lo..=hi).contains(&v);
    assert!(ok(honest), "SBMF adds {honest:.3}, not {lo:.3}..{hi:.3}");
    for (what, v) in [("zeroed", zeroed), ("halved", halved), ("doubled", doubled)] {
        assert!(!ok(v), "records with the CoC {what} pass: {v:.3}");
    }
}
