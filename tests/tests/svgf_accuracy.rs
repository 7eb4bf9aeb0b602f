//! SVGF end to end is accurate, not only steady: a sequence rendered at 1 spp per frame and
//! filtered by the shipped SVGF, measured against a path-traced reference of its last frame.
//!
//! The scene is a floor under one lamp that switches to twice its brightness at frame `STEP`
//! (a step key); nothing moves. SVGF's known bias here is its temporal lag: every frame blends
//! the new (demodulated) light into the reprojected history with `α = max(0.2, 1/h)`, so `m`
//! frames after the switch the pre-switch light keeps the weight `(1 − α)^m` in the history
//! (the history is the first À-Trous iteration's output, which a uniform scale of the light
//! passes through unchanged). The lamp being the only light, the pre-switch light is half the
//! new one, and the filtered last frame converges to `(1 − ½ (1 − α)^m)` times the reference.
//! The spatial filter averages within a footprint where the floor's light varies slowly: its
//! bias is bounded per block by how far the reference's block mean moves under the
//! un-weighted À-Trous kernel of the same iterations (edge-stopping weights only narrow it).
//!
//! Judged per 8 × 8 block and for the whole image by the block z-test
//! (`rt_testkit::stats::compare_estimates`): the SVGF frames' spread over independent seeds
//! against the reference's film variance, after moving the reference by the lag and each
//! block by its spatial bound towards the SVGF mean. Controls, through the same
//! `SequenceRenderer`: a history that never updates (the denoiser keeps its first output) and
//! a black frame must both fail.

use rt_core::{Rgb, RgbImage, Scene};
use rt_film::Channel;
use rt_integrators::{CameraRays, PathIntegrator};
use rt_session::SequenceRenderer;
use rt_temporal::{SvgfParams, TemporalDenoiser, TemporalError, TemporalFrame, TemporalSpec};
use rt_testkit::scene_from_toml;
use rt_testkit::stats::{compare_estimates, Comparison, Estimate, ALPHA};

const W: u32 = 32;
const H: u32 = 24;
/// Frame (and time, at one frame per second) at which the lamp doubles.
const STEP: u32 = 6;
/// The last frame, the one measured: `LAST − STEP + 1` frames after the switch.
const LAST: u32 = 13;
const DEPTH: u32 = 4;
/// Independent sequences (seeds) whose spread gives the SVGF frame's variance.
const RUNS: u32 = 8;
const BLOCK: u32 = 8;

fn scene() -> Scene {
    scene_from_toml(&format!(
        r#"
[[camera]]
name = "c"
position = [0.0, 1.5, 1.0]
look_at = [0.0, 0.0, -0.2]
fov = 35.0
resolution = [{W}, {H}]

[[material]]
name = "white"
color = [0.7, 0.7, 0.7]

[[material]]
name = "lamp"
color = [0.0, 0.0, 0.0]
emission = [1.0, 1.0, 1.0]

[[animation]]
target = "lamp"
interpolate = "step"
keys = [ {{ time = 0.0, emission = [1.0, 1.0, 1.0] }}, {{ time = {STEP}.0, emission = [2.0, 2.0, 2.0] }} ]

[[geometry]]
name = "floor"
shape = "quad"
vertices = [[-4, 0, 4], [4, 0, 4], [4, 0, -4], [-4, 0, -4]]
material = "white"

[[geometry]]
name = "light"
shape = "quad"
vertices = [[-3, 3, -3], [3, 3, -3], [3, 3, 3], [-3, 3, 3]]
material = "lamp"
"#
    ))
}

/// How a control spoils the real denoiser's output.
#[derive(Clone, Copy)]
enum Spoil {
    /// It keeps returning its first output: a history that never updates.
    Frozen,
    /// Its frames are replaced by black.
    Black,
}

/// The real denoiser with its output spoiled.
struct Spoiled {
    inner: Box<dyn TemporalDenoiser>,
    spoil: Spoil,
    first: Option<RgbImage>,
}

impl TemporalDenoiser for Spoiled {
    fn name(&self) -> &str {
        match self.spoil {
            Spoil::Frozen => "frozen svgf",
            Spoil::Black => "black svgf",
        }
    }
    fn needs(&self) -> &[Channel] {
        self.inner.needs()
    }
    fn needs_guides(&self) -> bool {
        self.inner.needs_guides()
    }
    fn filter(&mut self, frame: &TemporalFrame<'_>) -> Result<RgbImage, TemporalError> {
        let out = self.inner.filter(frame)?;
        Ok(match self.spoil {
            Spoil::Frozen => self.first.get_or_insert(out).clone(),
            Spoil::Black => RgbImage::filled(out.width(), out.height(), Rgb::ZERO),
        })
    }
    fn reset(&mut self) {
        self.inner.reset();
        self.first = None;
    }
}

fn spoiled(spoil: Spoil) -> Box<dyn TemporalDenoiser> {
    Box::new(Spoiled {
        inner: svgf(),
        spoil,
        first: None,
    })
}

fn svgf() -> Box<dyn TemporalDenoiser> {
    "svgf".parse::<TemporalSpec>().unwrap().build().unwrap()
}

/// The last frame of the sequence `0..=LAST` at 1 spp, seed `seed`, through `denoiser`.
fn last_frame(denoiser: Box<dyn TemporalDenoiser>, seed: u32) -> Vec<Rgb> {
    let mut scene = scene();
    let technique = Box::new(CameraRays(Box::new(PathIntegrator::new(DEPTH))));
    let mut r = SequenceRenderer::new(
        technique,
        Default::default(),
        Some(denoiser),
        None,
        1,
        seed,
        1.0,
    )
    .unwrap();
    let mut last = None;
    for f in 0..=LAST {
        last = Some(r.render(&mut scene, f).unwrap().image);
    }
    last.unwrap().pixels().to_vec()
}

fn runs(make: &dyn Fn() -> Box<dyn TemporalDenoiser>) -> Estimate {
    let images: Vec<Vec<Rgb>> = (0..RUNS)
        .map(|k| last_frame(make(), 1000 + 7919 * k))
        .collect();
    Estimate::from_runs(&images)
}

/// The B3-spline À-Trous kernel of `iterations` steps without edge-stopping weights (clamped
/// at the border) applied to `img`.
fn unweighted_atrous(img: &[Rgb], iterations: u32) -> Vec<Rgb> {
    const K: [f32; 5] = [1.0 / 16.0, 1.0 / 4.0, 3.0 / 8.0, 1.0 / 4.0, 1.0 / 16.0];
    let (w, h) = (W as i32, H as i32);
    let mut cur = img.to_vec();
    for i in 0..iterations {
        let step = 1i32 << i;
        let mut next = vec![Rgb::ZERO; cur.len()];
        for y in 0..h {
            for x in 0..w {
                let mut sum = Rgb::ZERO;
                let mut wsum = 0.0;
                for (dy, ky) in (-2..=2).zip(K) {
                    for (dx, kx) in (-2..=2).zip(K) {
                        let (xx, yy) = (x + dx * step, y + dy * step);
                        if (0..w).contains(&xx) && (0..h).contains(&yy) {
                            sum += cur[(yy * w + xx) as usize] * (kx * ky);
                            wsum += kx * ky;
                        }
                    }
                }
                next[(y * w + x) as usize] = sum / wsum;
            }
        }
        cur = next;
    }
    cur
}

struct Reference {
    mean: Vec<Rgb>,
    variance: Vec<Rgb>,
    /// Per pixel, the spatial bias bound of its block (the block-mean shift under the kernel,
    /// spread evenly over the block's pixels).
    spatial: Vec<Rgb>,
}

fn reference() -> Reference {
    let mut scene = scene();
    scene.set_time(LAST as f32);
    let film = rt_testkit::render(&scene, &PathIntegrator::new(DEPTH), 2048, 99);
    let mean = film.mean_image();
    let variance = film.variance_image().unwrap();
    let blurred = unweighted_atrous(&mean, SvgfParams::default().iterations);
    let mut spatial = vec![Rgb::ZERO; mean.len()];
    for by in (0..H).step_by(BLOCK as usize) {
        for bx in (0..W).step_by(BLOCK as usize) {
            let idx: Vec<usize> = (by..(by + BLOCK).min(H))
                .flat_map(|y| (bx..(bx + BLOCK).min(W)).map(move |x| (y * W + x) as usize))
                .collect();
            let n = idx.len() as f32;
            let shift: Rgb = idx.iter().map(|&i| blurred[i] - mean[i]).sum::<Rgb>() / n;
            for &i in &idx {
                spatial[i] = shift.abs();
            }
        }
    }
    Reference {
        mean,
        variance,
        spatial,
    }
}

/// The lag's factor `1 − ½ (1 − α)^m` at the last frame.
fn lag_factor() -> f32 {
    let alpha = SvgfParams::default().alpha;
    let m = (LAST - STEP + 1) as i32;
    1.0 - 0.5 * (1.0 - alpha).powi(m)
}

/// `svgf` against the reference times the lag, each pixel of the reference moved by its
/// block's spatial bound towards `svgf` (no further than `svgf`).
fn judge(svgf: &Estimate, r: &Reference) -> Comparison {
    let lag = lag_factor();
    let mean = r
        .mean
        .iter()
        .zip(&r.spatial)
        .zip(&svgf.mean)
        .map(|((m, s), a)| {
            let m = *m * lag;
            let lo = m - *s;
            let hi = m + *s;
            a.max(lo).min(hi)
        })
        .collect();
    let variance = r.variance.iter().map(|v| *v * (lag * lag)).collect();
    let b = Estimate {
        mean,
        variance,
        runs: None,
    };
    compare_estimates(svgf, &b, W, BLOCK, ALPHA)
}

#[test]
fn svgf_frames_match_a_path_traced_reference_within_the_filters_lag() {
    let t = std::time::Instant::now();
    let r = reference();
    let honest = judge(&runs(&svgf), &r);
    let frozen = judge(&runs(&|| spoiled(Spoil::Frozen)), &r);
    let black = judge(&runs(&|| spoiled(Spoil::Black)), &r);
    let mean = |v: &[Rgb]| v.iter().map(|c| c.x as f64).sum::<f64>() / v.len() as f64;
    eprintln!(
        "reference mean {:.4}, lag factor {:.4}, spatial bound mean {:.5}; svgf {honest:?}; frozen {frozen:?}; black {black:?}; {:.2?}",
        mean(&r.mean),
        lag_factor(),
        mean(&r.spatial),
        t.elapsed()
    );
    assert!(
        honest.same_within_noise(),
        "SVGF's last frame is off the reference by more than its lag and blur: {honest:?}"
    );
    assert!(
        !frozen.same_within_noise(),
        "a history that never updates passes: {frozen:?}"
    );
    assert!(!black.same_within_noise(), "black frames pass: {black:?}");
}
