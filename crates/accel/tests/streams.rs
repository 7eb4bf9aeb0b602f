//! `Accel::intersect_stream` and `Accel::occluded_stream` answer exactly what the single-ray
//! queries answer, ray by ray (closest hit's t, triangle and barycentrics; occlusion), on
//! random rays and on coherent ones (a camera's rays of neighbouring pixels, bounce rays from
//! their hits, shadow rays toward one light and toward a few), for the structures that override
//! them and through `AccelSpec`.

mod common;

use common::{icosphere, rays, soup, torus, Rng};
use glam::Vec3;
use rt_accel::AccelSpec;
use rt_core::{Accel, Hit, Ray};

/// The stream answers of `accel` against its single-ray answers; panics on the first mismatch.
/// Returns the numbers of hits and of occluded rays.
fn same_as_single(accel: &dyn Accel, rays: &[Ray], t_max: &[f32], what: &str) -> [usize; 2] {
    let mut hits = vec![None; rays.len()];
    accel.intersect_stream(rays, t_max, &mut hits);
    let mut n_hits = 0;
    for (i, (ray, &t)) in rays.iter().zip(t_max).enumerate() {
        let want: Option<Hit> = accel.intersect(ray, t);
        let got = hits[i];
        // Bit for bit, NaN-free: compare the bits of every field.
        let bits =
            |h: Option<Hit>| h.map(|h| (h.t.to_bits(), h.prim, h.b1.to_bits(), h.b2.to_bits()));
        assert_eq!(
            bits(got),
            bits(want),
            "{what}: {} ray {i} {ray:?} t_max {t}",
            accel.name()
        );
        n_hits += usize::from(want.is_some());
    }
    // Shadow rays: toward the far end of the segment (finite), and without a target.
    let toward: Vec<Vec3> = rays
        .iter()
        .zip(t_max)
        .enumerate()
        .map(|(i, (r, &t))| {
            if i % 5 == 4 || !t.is_finite() {
                Vec3::splat(f32::INFINITY)
            } else {
                r.origin + r.dir * t
            }
        })
        .collect();
    let mut occluded = vec![false; rays.len()];
    accel.occluded_stream(rays, t_max, &toward, &mut occluded);
    let mut n_occ = 0;
    for (i, ((ray, &t), &p)) in rays.iter().zip(t_max).zip(&toward).enumerate() {
        let want = if p.is_finite() {
            accel.occluded_toward(ray, t, p)
        } else {
            accel.occluded(ray, t)
        };
        assert_eq!(
            occluded[i],
            want,
            "{what}: {} shadow ray {i} {ray:?} t_max {t}",
            accel.name()
        );
        n_occ += usize::from(want);
    }
    [n_hits, n_occ]
}

/// Both answers must occur among `n` rays with `counts` hits and occluded rays.
fn both_answers(counts: [usize; 2], n: usize, what: &str) {
    for (c, name) in counts.into_iter().zip(["hits", "occluded"]) {
        assert!(c > 0 && c < n, "{what}: {c} {name} of {n}");
    }
}

/// Coherent rays over `tris`: a 64 x 48 camera looking at the scene from `eye`, then a
/// diffuse-like bounce from every hit, then shadow segments from every hit to one light and to
/// four lights in turn. Returns (rays, t_max) per stage.
fn coherent_stages(accel: &dyn Accel, eye: Vec3, rng: &mut Rng) -> Vec<(Vec<Ray>, Vec<f32>)> {
    let b = accel.bounds();
    let centre = (b.min + b.max) * 0.5;
    let fwd = (centre - eye).normalize();
    let right = fwd.cross(Vec3::Y).normalize();
    let up = right.cross(fwd);
    let (w, h) = (64, 48);
    let mut camera = Vec::new();
    for y in 0..h {
        for x in 0..w {
            let sx = (x as f32 + 0.5) / w as f32 * 2.0 - 1.0;
            let sy = (y as f32 + 0.5) / h as f32 * 2.0 - 1.0;
            camera.push(Ray::new(eye, fwd + right * sx * 0.6 + up * sy * 0.45));
        }
    }
    let inf = vec![f32::INFINITY; camera.len()];
    let mut hits = vec![None; camera.len()];
    accel.intersect_stream(&camera, &inf, &mut hits);
    let points: Vec<Vec3> = camera
        .iter()
        .zip(&hits)
        .filter_map(|(r, h)| h.map(|h| r.at(h.t * 0.999)))
        .collect();
    let bounce: Vec<Ray> = points
        .iter()
        .map(|&p| Ray::new(p, rng.unit_vec()))
        .collect();
    let lights = [
        centre + Vec3::new(0.1, 2.0, 0.2) * (b.max - b.min).length(),
        centre + Vec3::new(-0.5, 0.3, 0.1),
        centre + Vec3::new(0.2, -0.1, 0.6),
        eye,
    ];
    let one_light: Vec<Ray> = points.iter().map(|&p| Ray::new(p, lights[0] - p)).collect();
    let four_lights: Vec<Ray> = points
        .iter()
        .enumerate()
        .map(|(i, &p)| Ray::new(p, lights[i % 4] - p))
        .collect();
    let n = points.len();
    vec![
        (camera, inf.clone()),
        (bounce, vec![f32::INFINITY; n]),
        (one_light, vec![1.0; n]),
        (four_lights, vec![1.0; n]),
    ]
}

fn specs() -> Vec<AccelSpec> {
    [
        "bvh8",
        "qbvh",
        "bvh8:order=split",
        "bvh8:no-tstack",
        "bvh8:shadow-cache",
        "bvh",
        "two-level",
    ]
    .iter()
    .map(|s| s.parse().unwrap_or_else(|e| panic!("{s}: {e}")))
    .collect()
}

#[test]
fn streams_of_random_rays_match_single_rays() {
    let mut rng = Rng::new(2028);
    let tris = soup(&mut rng, 3000);
    let set = rays(&mut rng, &tris, 6000);
    let (rays, t_max): (Vec<Ray>, Vec<f32>) = set.into_iter().unzip();
    for spec in specs() {
        let accel = spec.build(&tris).expect("the structure builds");
        let counts = same_as_single(&*accel, &rays, &t_max, "soup");
        both_answers(counts, rays.len(), "soup");
        // Streams of every length, including ones shorter than any packet.
        for len in [0, 1, 3, 7, 8, 9, 17] {
            same_as_single_quiet(&*accel, &rays[..len], &t_max[..len]);
        }
    }
}

/// [`same_as_single`] without requiring both answers to occur.
fn same_as_single_quiet(accel: &dyn Accel, rays: &[Ray], t_max: &[f32]) {
    let mut hits = vec![None; rays.len()];
    accel.intersect_stream(rays, t_max, &mut hits);
    let toward = vec![Vec3::splat(f32::INFINITY); rays.len()];
    let mut occ = vec![false; rays.len()];
    accel.occluded_stream(rays, t_max, &toward, &mut occ);
    for (i, (r, &t)) in rays.iter().zip(t_max).enumerate() {
        assert_eq!(hits[i], accel.intersect(r, t));
        assert_eq!(occ[i], accel.occluded(r, t));
    }
}

#[test]
fn streams_of_coherent_rays_match_single_rays() {
    let mut rng = Rng::new(7);
    let mut tris = torus(96, 48, 1.0, 0.35).triangles();
    tris.extend(
        icosphere(4)
            .transformed(|p| p * 0.3 + Vec3::new(0.2, 0.1, 0.3))
            .triangles(),
    );
    tris.extend(soup(&mut rng, 500));
    for spec in specs() {
        let accel = spec.build(&tris).expect("the structure builds");
        let (mut counts, mut n) = ([0, 0], 0);
        for eye in [
            Vec3::new(0.3, 2.5, 3.5),
            Vec3::new(-3.0, -0.4, 0.2),
            Vec3::new(0.05, 0.02, 0.0),
        ] {
            for (stage, (rays, t_max)) in coherent_stages(&*accel, eye, &mut rng).iter().enumerate()
            {
                let c = same_as_single(&*accel, rays, t_max, &format!("stage {stage} from {eye}"));
                counts = [counts[0] + c[0], counts[1] + c[1]];
                n += rays.len();
            }
        }
        both_answers(counts, n, &format!("{spec}: coherent stages"));
    }
}
