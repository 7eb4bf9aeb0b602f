//! Finding each pixel's history: where its surface (or, for specular pixels with Voorhuis'
//! extensions, its reflection) was in the previous frame, and the history there, fetched
//! bilinearly from the taps that pass the consistency tests (Schied et al. 2017 §4.1; Falcor's
//! renormalised taps and 3×3 fallback, seed 001 §1.3).
//!
//! The tests: a diffuse pixel's tap must see the same object at the depth its surface had in
//! the previous frame (within 5 % plus two neighbour steps) with a normal within ~25°; a mirror's
//! tap must be a mirror pixel with a reflection, a specular pixel's tap must be specular (the
//! thesis disables the geometric tests for glossy pixels; clipping catches what slips through).

use super::diamond;
use super::features::{Class, Features};
use super::history::History;
use super::params::{Reflections, SvgfParams};
use rt_core::glam::Vec3;
use rt_core::Rgb;
use rt_film::GuideBuffers;

/// Smallest summed weight of accepted bilinear taps (Falcor: 0.01).
const MIN_TAP_WEIGHT: f32 = 0.01;
/// Normal test of diffuse taps: cos of the largest angle between normals.
const MIN_NORMAL_DOT: f32 = 0.9;
/// Depth test of diffuse taps: relative tolerance, plus this many neighbour depth steps.
const DEPTH_TOLERANCE: f32 = 0.05;
const DEPTH_STEPS: f32 = 2.0;

/// A pixel's history as fetched.
#[derive(Clone, Copy, Debug, Default)]
pub struct Fetched {
    /// True if any history was accepted.
    pub valid: bool,
    /// Demodulated colour history of the direct and the indirect signal.
    pub colour: [Rgb; 2],
    /// Luminance moments (E[l], E[l²]) of both signals.
    pub moments: [[f32; 2]; 2],
    /// History length.
    pub length: f32,
}

/// How a pixel's taps are tested.
#[derive(Clone, Copy, PartialEq, Eq)]
enum Test {
    Geometric,
    Mirror,
    Specular,
}

/// Where pixel `i` was in the previous frame (continuous pixel coordinates) and how its taps are
/// tested; `None` if it has no history to look for.
fn previous_position(
    f: &Features,
    g: &GuideBuffers,
    h: &History,
    p: &SvgfParams,
    i: usize,
) -> Option<((f32, f32), Test)> {
    let (x, y) = (i % f.w, i / f.w);
    let mv = g.motion.pixels()[i];
    let primary = (x as f32 + 0.5 - mv.x, y as f32 + 0.5 - mv.y);
    let class = f.class[i];
    match p.reflections {
        _ if class == Class::Sky => None,
        Reflections::Drop if class.specular() => None,
        Reflections::Primary | Reflections::Drop => Some((primary, Test::Geometric)),
        Reflections::Reproject => {
            let refl = g.reflected.as_ref();
            let guess = (primary.0.floor() as i32, primary.1.floor() as i32);
            let start = (x as i32, y as i32);
            match class {
                Class::Mirror => {
                    let r = refl?;
                    if r.distance.pixels()[i] <= 0.0 {
                        return None;
                    }
                    let target = r.position.pixels()[i];
                    let m = diamond::search(
                        f.w,
                        f.h,
                        start,
                        guess,
                        p.diamond_step,
                        p.subpixel,
                        |qx, qy| {
                            let j = qy as usize * h.w + qx as usize;
                            if h.class[j] == Class::Mirror && h.reflected_distance[j] > 0.0 {
                                (h.reflected_position[j] - target).length()
                            } else {
                                f32::INFINITY
                            }
                        },
                    );
                    m.distance.is_finite().then_some(((m.x, m.y), Test::Mirror))
                }
                Class::SharpGlossy => {
                    let r = refl?;
                    let t = r.distance.pixels()[i];
                    if t <= 0.0 {
                        return Some((primary, Test::Specular));
                    }
                    let ray = (g.position.pixels()[i], r.direction.pixels()[i], t);
                    let m = diamond::search(
                        f.w,
                        f.h,
                        start,
                        guess,
                        p.diamond_step,
                        p.subpixel,
                        |qx, qy| {
                            let j = qy as usize * h.w + qx as usize;
                            if h.class[j].specular() && h.reflected_distance[j] > 0.0 {
                                let other = (
                                    h.position[j],
                                    h.reflected_direction[j],
                                    h.reflected_distance[j],
                                );
                                ray_distance(ray, other)
                            } else {
                                f32::INFINITY
                            }
                        },
                    );
                    m.distance
                        .is_finite()
                        .then_some(((m.x, m.y), Test::Specular))
                }
                Class::Glossy => Some((primary, Test::Specular)),
                _ => Some((primary, Test::Geometric)),
            }
        }
    }
}

/// Voorhuis Eq. 5: the distance from the nearer representative ray's approximate hit
/// (`o + d·t`, Eq. 4) to the farther ray's line.
pub fn ray_distance(a: (Vec3, Vec3, f32), b: (Vec3, Vec3, f32)) -> f32 {
    let (near, far) = if a.2 <= b.2 { (a, b) } else { (b, a) };
    let hit = near.0 + near.1 * near.2;
    far.1.cross(hit - far.0).length()
}

/// Whether history pixel `j` may stand in for pixel `i`.
fn accept(f: &Features, g: &GuideBuffers, h: &History, i: usize, j: usize, test: Test) -> bool {
    match test {
        Test::Geometric => {
            if h.class[j] == Class::Sky || h.object[j] != f.object[i] {
                return false;
            }
            let expected = g.previous_depth.pixels()[i];
            let tolerance = DEPTH_TOLERANCE * expected + DEPTH_STEPS * f.primary_step[i];
            (h.depth[j] - expected).abs() <= tolerance
                && h.normal[j].dot(g.normal.pixels()[i]) >= MIN_NORMAL_DOT
        }
        Test::Mirror => h.class[j] == Class::Mirror && h.reflected_distance[j] > 0.0,
        Test::Specular => h.class[j].specular(),
    }
}

/// The history of pixel `i`.
pub fn fetch(f: &Features, g: &GuideBuffers, h: &History, p: &SvgfParams, i: usize) -> Fetched {
    let Some(((qx, qy), test)) = previous_position(f, g, h, p, i) else {
        return Fetched::default();
    };
    let (tx, ty) = (qx - 0.5, qy - 0.5);
    if !(tx > -1.0 && ty > -1.0 && tx < h.w as f32 && ty < h.h as f32) {
        return Fetched::default();
    }
    let (x0, y0) = (tx.floor() as i64, ty.floor() as i64);
    let (fx, fy) = (tx - x0 as f32, ty - y0 as f32);
    let taps = [
        (x0, y0, (1.0 - fx) * (1.0 - fy)),
        (x0 + 1, y0, fx * (1.0 - fy)),
        (x0, y0 + 1, (1.0 - fx) * fy),
        (x0 + 1, y0 + 1, fx * fy),
    ];
    let mut out = Fetched::default();
    let mut total = 0.0f32;
    let add = |j: usize, wgt: f32, out: &mut Fetched| {
        for s in 0..2 {
            out.colour[s] += h.colour[s][j] * wgt;
            out.moments[s][0] += h.moments[s][j][0] * wgt;
            out.moments[s][1] += h.moments[s][j][1] * wgt;
        }
        out.length += h.length[j] * wgt;
    };
    let inside = |x: i64, y: i64| x >= 0 && y >= 0 && x < h.w as i64 && y < h.h as i64;
    for (x, y, wgt) in taps {
        if wgt <= 0.0 || !inside(x, y) {
            continue;
        }
        let j = y as usize * h.w + x as usize;
        if accept(f, g, h, i, j, test) {
            add(j, wgt, &mut out);
            total += wgt;
        }
    }
    if total < MIN_TAP_WEIGHT {
        // Falcor's fallback: the accepted pixels of the 3×3 window around the nearest one.
        out = Fetched::default();
        total = 0.0;
        let (cx, cy) = (qx.floor() as i64, qy.floor() as i64);
        for y in cy - 1..=cy + 1 {
            for x in cx - 1..=cx + 1 {
                if !inside(x, y) {
                    continue;
                }
                let j = y as usize * h.w + x as usize;
                if accept(f, g, h, i, j, test) {
                    add(j, 1.0, &mut out);
                    total += 1.0;
                }
            }
        }
    }
    if total <= 0.0 {
        return Fetched::default();
    }
    let inv = 1.0 / total;
    for s in 0..2 {
        out.colour[s] *= inv;
        out.moments[s][0] *= inv;
        out.moments[s][1] *= inv;
    }
    out.length *= inv;
    out.valid = true;
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ray_distance_is_symmetric_and_zero_for_identical_rays() {
        let a = (Vec3::ZERO, Vec3::X, 2.0);
        let b = (Vec3::new(0.0, 0.5, 0.0), Vec3::new(0.6, 0.8, 0.0), 5.0);
        assert_eq!(ray_distance(a, a), 0.0);
        assert_eq!(ray_distance(a, b), ray_distance(b, a));
        // a is nearer: its hit (2, 0, 0) measured to b's line.
        let hit = Vec3::new(2.0, 0.0, 0.0);
        let expected = b.1.cross(hit - b.0).length();
        assert!((ray_distance(a, b) - expected).abs() < 1e-6);
    }
}
