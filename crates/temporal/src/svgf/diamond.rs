//! Motion of reflections by search (Voorhuis 2018 §4.2, Appendix A): the previous-frame pixel
//! whose stored reflected hit is closest to this pixel's, found by a diamond search (Zhu & Ma
//! 2000) with Cheng et al.'s 5-tap large pattern scaled by a step that starts at 4 and halves
//! whenever the centre stays best, then a small-pattern step, then sub-pixel refinement
//! (Eq. 2–3) so reflections do not shake by whole pixels.
//!
//! Deviations and readings (\[ours\], the thesis' Fig. 3 did not survive extraction): the large
//! pattern is {(±2, 0), (0, ±2)}·step and the small one {(±1, 0), (0, ±1)}; taps are clamped
//! to the image; the search stops after [`MAX_STEPS`] moves; a candidate the caller scores as
//! infinitely far (not specular in the previous frame) is never chosen; when two distances are
//! zero the refinement's product weights all vanish and the best pixel is returned as it is;
//! the small pattern is repeated until its centre stays best (the thesis does it once, which
//! stops one diagonal pixel short of the minimum wherever the field is not separable).

/// Most moves of the large pattern before the search stops where it is.
pub const MAX_STEPS: u32 = 64;

const LARGE: [(i32, i32); 4] = [(2, 0), (-2, 0), (0, 2), (0, -2)];
const SMALL: [(i32, i32); 4] = [(1, 0), (-1, 0), (0, 1), (0, -1)];

/// Result of a search: the previous frame's matching position (continuous pixel coordinates,
/// pixel centres at +0.5) and its distance.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Match {
    /// Where the match is, x.
    pub x: f32,
    /// Where the match is, y.
    pub y: f32,
    /// Distance of the best integer pixel (infinite if nothing matched).
    pub distance: f32,
}

/// Searches a `w × h` image for the pixel minimising `dist`, starting from the better of
/// `start` and `guess` (integer pixels), with first step `step`. `dist` returns
/// `f32::INFINITY` for pixels that cannot match.
pub fn search(
    w: usize,
    h: usize,
    start: (i32, i32),
    guess: (i32, i32),
    step: u32,
    subpixel: bool,
    dist: impl Fn(i32, i32) -> f32,
) -> Match {
    let clamp = |(x, y): (i32, i32)| (x.clamp(0, w as i32 - 1), y.clamp(0, h as i32 - 1));
    let mut centre = clamp(start);
    let mut best_d = dist(centre.0, centre.1);
    let g = clamp(guess);
    let dg = dist(g.0, g.1);
    if dg < best_d {
        centre = g;
        best_d = dg;
    }
    let mut step = step.max(1) as i32;
    let mut best = centre;
    for _ in 0..MAX_STEPS {
        for (ox, oy) in LARGE {
            let q = clamp((centre.0 + ox * step, centre.1 + oy * step));
            let d = dist(q.0, q.1);
            if d < best_d {
                best = q;
                best_d = d;
            }
        }
        if best == centre {
            if step == 1 {
                break;
            }
            step /= 2;
        }
        centre = best;
    }
    // The small pattern, repeated until the centre stays best: a single step stops one
    // diagonal pixel short wherever the field is not separable.
    for _ in 0..MAX_STEPS {
        for (ox, oy) in SMALL {
            let q = clamp((centre.0 + ox, centre.1 + oy));
            let d = dist(q.0, q.1);
            if d < best_d {
                best = q;
                best_d = d;
            }
        }
        if best == centre {
            break;
        }
        centre = best;
    }
    let whole = Match {
        x: best.0 as f32 + 0.5,
        y: best.1 as f32 + 0.5,
        distance: best_d,
    };
    if !subpixel || !best_d.is_finite() {
        return whole;
    }
    refine(w, h, best, best_d, &dist).unwrap_or(whole)
}

/// Sub-pixel refinement (Voorhuis Eq. 2–3): of the four 2×2 blocks holding `best`, the one
/// with the smallest summed distance; each of its pixels weighted by the product of the other
/// three's distances. `None` if no block lies wholly on the image with finite distances or
/// the weights vanish.
fn refine(
    w: usize,
    h: usize,
    best: (i32, i32),
    best_d: f32,
    dist: &impl Fn(i32, i32) -> f32,
) -> Option<Match> {
    if best_d == 0.0 {
        return None;
    }
    let inside = |x: i32, y: i32| x >= 0 && y >= 0 && x < w as i32 && y < h as i32;
    // The best block so far: its pixels, their distances, their sum.
    type Block = ([(i32, i32); 4], [f32; 4], f32);
    let mut chosen: Option<Block> = None;
    for (bx, by) in [(-1, -1), (0, -1), (-1, 0), (0, 0)] {
        let (x0, y0) = (best.0 + bx, best.1 + by);
        let block = [(x0, y0), (x0 + 1, y0), (x0, y0 + 1), (x0 + 1, y0 + 1)];
        if !block.iter().all(|&(x, y)| inside(x, y)) {
            continue;
        }
        let d = block.map(|(x, y)| dist(x, y));
        if !d.iter().all(|v| v.is_finite()) {
            continue;
        }
        let sum: f32 = d.iter().sum();
        if chosen.as_ref().is_none_or(|c| sum < c.2) {
            chosen = Some((block, d, sum));
        }
    }
    let (block, d, _) = chosen?;
    let (mut sx, mut sy, mut sw) = (0.0f64, 0.0f64, 0.0f64);
    for (i, (bx, by)) in block.iter().enumerate() {
        let wgt: f64 = (0..4).filter(|&j| j != i).map(|j| d[j] as f64).product();
        sx += wgt * (*bx as f64 + 0.5);
        sy += wgt * (*by as f64 + 0.5);
        sw += wgt;
    }
    (sw > 0.0 && sw.is_finite()).then(|| Match {
        x: (sx / sw) as f32,
        y: (sy / sw) as f32,
        distance: best_d,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A smooth "reflected position" field, shifted by `s` pixels: the previous frame saw at
    /// pixel q what the current frame sees at q + s.
    fn field(x: f32, y: f32) -> [f32; 3] {
        [x * 0.7 + (y * 0.05).sin(), y * 0.9 + (x * 0.04).cos(), 0.0]
    }

    fn distance_to(target: [f32; 3], s: (f32, f32)) -> impl Fn(i32, i32) -> f32 {
        move |x, y| {
            let p = field(x as f32 + 0.5 + s.0, y as f32 + 0.5 + s.1);
            ((p[0] - target[0]).powi(2) + (p[1] - target[1]).powi(2)).sqrt()
        }
    }

    #[test]
    fn finds_a_known_whole_pixel_shift_from_far_away() {
        let (w, h) = (128, 96);
        // Current pixel (70, 40) sees field(70.5, 40.5); previously at pixel (70 - 13, 40 + 9).
        let target = field(70.5, 40.5);
        let m = search(
            w,
            h,
            (70, 40),
            (70, 40),
            4,
            false,
            distance_to(target, (13.0, -9.0)),
        );
        assert_eq!((m.x, m.y), (57.5, 49.5));
        assert!(m.distance < 1e-4);
    }

    #[test]
    fn finds_a_known_sub_pixel_shift() {
        let (w, h) = (64, 64);
        let shift = (5.3f32, -2.6f32);
        let target = field(30.5, 30.5);
        // True previous position: centre minus shift.
        let (tx, ty) = (30.5 - shift.0, 30.5 - shift.1);
        let whole = search(
            w,
            h,
            (30, 30),
            (30, 30),
            4,
            false,
            distance_to(target, shift),
        );
        let refined = search(
            w,
            h,
            (30, 30),
            (30, 30),
            4,
            true,
            distance_to(target, shift),
        );
        let err = |m: Match| ((m.x - tx).powi(2) + (m.y - ty).powi(2)).sqrt();
        assert!(
            err(whole) <= 0.71,
            "whole-pixel match {whole:?} vs ({tx}, {ty})"
        );
        assert!(
            err(refined) < 0.35 && err(refined) < err(whole),
            "refined {refined:?} ({}) vs whole {whole:?} ({}), truth ({tx}, {ty})",
            err(refined),
            err(whole)
        );
    }

    #[test]
    fn never_picks_a_pixel_that_cannot_match() {
        // Only a block far from the start is specular; everything else is infinitely far.
        let m = search(32, 32, (5, 5), (5, 5), 4, true, |x, y| {
            if x >= 20 && y >= 20 {
                ((x - 25).pow(2) + (y - 24).pow(2)) as f32
            } else {
                f32::INFINITY
            }
        });
        // Nothing finite is reachable from the start: the search reports no match.
        assert!(!m.distance.is_finite());
        let m = search(32, 32, (5, 5), (22, 22), 4, false, |x, y| {
            if x >= 20 && y >= 20 {
                ((x - 25).pow(2) + (y - 24).pow(2)) as f32
            } else {
                f32::INFINITY
            }
        });
        assert_eq!((m.x, m.y, m.distance), (25.5, 24.5, 0.0));
    }

    #[test]
    fn refinement_weights_make_a_convex_combination() {
        // Equal distances: the refined point is the block's centre.
        let m = refine(8, 8, (3, 3), 1.0, &|_, _| 1.0).unwrap();
        assert!((2.0..=4.0).contains(&m.x) && (2.0..=4.0).contains(&m.y));
        assert_eq!((m.x.fract(), m.y.fract()), (0.0, 0.0));
    }
}
