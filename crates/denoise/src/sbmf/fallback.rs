//! The under-represented-sample fallback of SBMF step A (Bauszat thesis §4.2.2): a sample far
//! from every manifold (slice denominator below a threshold) would come out unstable (black
//! halos) if sliced, too noisy if kept, and biased if dropped; it takes the noisy pixel image
//! box-blurred at a small radius instead (the thesis uses 4–8 pixels).
//!
//! The box is normalised by the samples it holds (sums of radiance over sums of counts), so
//! pixels without samples and the image border do not darken it.

use rt_core::Rgb;
use rt_film::SampleRecords;

/// Per pixel, the mean radiance of all samples within the `(2r+1)²` box around it (zero if
/// none).
pub(crate) fn box_blurred_pixels(
    records: &SampleRecords,
    w: usize,
    h: usize,
    r: usize,
) -> Vec<Rgb> {
    let mut sums: Vec<[f32; 4]> = (0..w * h)
        .map(|i| {
            let mut s = [0.0f32; 4];
            for j in records.pixel_range(i) {
                let c = records.radiance()[j];
                s[0] += c.x;
                s[1] += c.y;
                s[2] += c.z;
                s[3] += 1.0;
            }
            s
        })
        .collect();
    box_pass(&mut sums, w, h, r, true);
    box_pass(&mut sums, w, h, r, false);
    sums.iter()
        .map(|s| {
            if s[3] > 0.0 {
                Rgb::new(s[0], s[1], s[2]) / s[3]
            } else {
                Rgb::ZERO
            }
        })
        .collect()
}

/// Box sums of radius `r` along rows (`horizontal`) or columns, clamped at the border.
fn box_pass(v: &mut [[f32; 4]], w: usize, h: usize, r: usize, horizontal: bool) {
    let (n, lines) = if horizontal { (w, h) } else { (h, w) };
    let idx = |line: usize, k: usize| {
        if horizontal {
            line * w + k
        } else {
            k * w + line
        }
    };
    let mut line_buf = vec![[0.0f32; 4]; n];
    for line in 0..lines {
        for (k, b) in line_buf.iter_mut().enumerate() {
            *b = v[idx(line, k)];
        }
        for k in 0..n {
            let (lo, hi) = (k.saturating_sub(r), (k + r).min(n - 1));
            let mut s = [0.0f32; 4];
            for b in &line_buf[lo..=hi] {
                for c in 0..4 {
                    s[c] += b[c];
                }
            }
            v[idx(line, k)] = s;
        }
    }
}
