//! The linear manifolds (layers) of SBMF step B, the fast sweep-blur (Bauszat thesis §4.3.2):
//! `n_L = 2·n_F + 1` layers at equidistant signed circles of confusion `j·τ/n_F`,
//! `j = −n_F..n_F`, front (most negative, nearest the camera) first; the layer at `j` uses
//! filter scale `|j|`, a box whose support matches the CoC `|j|·τ/n_F` (front and back layers
//! of equal `|CoC|` share a scale — the thesis leaves this open; seed-000 digest §1.4).
//!
//! Deviations and choices: the box's half-width is the one whose `(2b+1)²` area equals the CoC
//! disc's `π·r²`, rounded (`b = round((√π·r − 1)/2)`, at least 0), since a box of half-width
//! `r` would spread 4/π times the disc's area; samples beyond `±τ` go to the outermost layer;
//! with `τ = 0` (everything in focus, or a pinhole) every sample is on the focal layer.

/// Most filter scales supported (`n_F ≤ 3`, i.e. 7 layers), including scale 0 (no blur).
pub(crate) const MAX_SCALES: usize = 4;

/// Layer layout for one image.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Layers {
    /// Layers in front of (and behind) the focal plane.
    pub n_f: usize,
    /// CoC of the outermost layers, in pixels.
    pub tau: f32,
}

impl Layers {
    /// Number of layers.
    pub fn count(&self) -> usize {
        2 * self.n_f + 1
    }

    /// The filter scale of layer `k`.
    pub fn scale(&self, k: usize) -> usize {
        k.abs_diff(self.n_f)
    }

    /// Box half-width in pixels of scale `f`.
    pub fn half_width(&self, f: usize) -> usize {
        if self.n_f == 0 {
            return 0;
        }
        let r = f as f32 * self.tau / self.n_f as f32;
        ((std::f32::consts::PI.sqrt() * r - 1.0) * 0.5)
            .round()
            .max(0.0) as usize
    }

    /// The two nearest layers of a sample with signed CoC `coc` and the linear weight of the
    /// second (`(k, k + 1, t)`, or `(k, k, 0)` on a layer or beyond the outermost).
    #[inline]
    pub fn classify(&self, coc: f32) -> (usize, usize, f32) {
        let last = 2 * self.n_f;
        if self.tau.is_nan() || self.tau <= 0.0 || !coc.is_finite() {
            return (self.n_f, self.n_f, 0.0);
        }
        let u = (coc / self.tau * self.n_f as f32 + self.n_f as f32).clamp(0.0, last as f32);
        let k = (u.floor() as usize).min(last);
        if k == last {
            return (last, last, 0.0);
        }
        (k, k + 1, u - k as f32)
    }
}

/// The weights of Eqs. 4.5–4.6 for a layer of own scale `own`, from the coverage `cov[f]` of
/// each of the `scales` scales by the layers in front: scale `f ≠ own` weighs `cov[f]`, the own
/// scale `cw = 1 − Σ_{f≠own} cov[f]`. Clamping `cw` at 0 alone would let the weights sum past 1
/// where the front layers' coverage adds up to more than 1 (blurred coverage can); there the
/// other scales' weights are scaled to sum to 1 instead, so the weights are always a partition
/// of unity (deviation: the thesis only says the weights normalise).
#[inline]
pub(crate) fn layer_weights(
    cov: &[f32; MAX_SCALES],
    scales: usize,
    own: usize,
) -> [f32; MAX_SCALES] {
    let mut w = [0.0; MAX_SCALES];
    let others: f32 = (0..scales).filter(|&f| f != own).map(|f| cov[f]).sum();
    let norm = if others > 1.0 { 1.0 / others } else { 1.0 };
    for f in 0..scales {
        w[f] = if f == own { 0.0 } else { cov[f] * norm };
    }
    w[own] = (1.0 - others).max(0.0);
    w
}
