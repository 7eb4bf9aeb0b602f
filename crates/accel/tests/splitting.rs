//! Triangle splitting (EVH, BBAH) and leaf compaction in the binary BVH: answers stay exactly
//! those of brute force, closed meshes stay watertight, shared edges split at the same points,
//! EVH leaves axis-aligned geometry alone, and compaction removes references without changing
//! any hit.

mod common;

use common::{
    check_rays, grid_cube, icosphere, rays, rays_at_edges_and_vertices, rotation, soup,
    thin_diagonal_soup, Mesh, Rng,
};
use glam::{Quat, Vec3};
use rt_accel::bvh2::{split_pieces, split_references};
use rt_accel::{BuildParams, Bvh2, Bvh8, Qbvh, Split};
use rt_core::{Aabb, Accel, Ray};
use std::collections::{HashMap, HashSet};

const SPLITS: [Split; 3] = [
    Split::Evh { t: 14 },
    Split::Evh { t: 20 },
    Split::Bbah { t: 12 },
];

fn params(split: Split, compact_leaves: bool) -> BuildParams {
    BuildParams {
        split,
        compact_leaves,
        max_leaf_size: 8,
        ..BuildParams::default()
    }
}

fn build(tris: &[[Vec3; 3]], params: &BuildParams) -> Bvh2 {
    let bvh = Bvh2::build(tris, params);
    bvh.validate()
        .unwrap_or_else(|e| panic!("{:?}: {e}", params.split));
    bvh
}

#[test]
fn random_soups_match_brute_force() {
    for split in SPLITS {
        for compact in [false, true] {
            let p = params(split, compact);
            // The soup's largest triangles span half the scene; EVH t = 20 and BBAH t = 12
            // cut them into thousands of pieces (about 400 references per triangle).
            let n = if split == (Split::Evh { t: 14 }) {
                600
            } else {
                150
            };
            let hits = common::check_soup::<Bvh2>(40 + u64::from(compact), n, 2000, &p);
            assert!(hits > 400, "{split:?}: only {hits} hits");
        }
    }
}

#[test]
fn thin_diagonal_soups_match_brute_force() {
    for split in SPLITS {
        for compact in [false, true] {
            let mut rng = Rng::new(7);
            let tris = thin_diagonal_soup(&mut rng, 300);
            let bvh = build(&tris, &params(split, compact));
            let s = bvh.stats();
            assert!(s.references > 2 * s.triangles, "{split:?}: {s}");
            let rays = rays(&mut rng, &tris, 3000);
            let hits = check_rays(&bvh, &tris, &rays, &format!("{split:?} {compact}"));
            assert!(hits > 500, "{split:?}: only {hits} hits");
        }
    }
}

/// An icosphere and a long thin box, both turned away from the axes, as one scene.
fn rotated_meshes() -> Vec<Mesh> {
    let mut rng = Rng::new(3);
    let q = rotation(&mut rng);
    let sphere = icosphere(3).transformed(|p| q * p + Vec3::new(0.3, -2.0, 1.1));
    let q = Quat::from_rotation_x(0.7) * Quat::from_rotation_z(0.5);
    let thin_box = grid_cube(4)
        .transformed(|p| q * (p * Vec3::new(4.0, 0.1, 0.15)) + Vec3::new(0.0, 1.0, 0.0));
    vec![sphere, thin_box]
}

#[test]
fn evh_keeps_closed_meshes_watertight() {
    let meshes = rotated_meshes();
    let tris: Vec<_> = meshes.iter().flat_map(Mesh::triangles).collect();
    for compact in [false, true] {
        let bvh = build(&tris, &params(Split::Evh { t: 20 }, compact));
        let s = bvh.stats();
        assert!(s.references > 2 * s.triangles, "{s}");
        // The QBVH collapsed from the split tree keeps the pieces' boxes.
        let qbvh = Qbvh::from_bvh2(&bvh);
        qbvh.validate().unwrap();
        let bvh8 = Bvh8::from_bvh2(&bvh);
        bvh8.validate().unwrap();
        let mut rng = Rng::new(11);
        for mesh in &meshes {
            mesh.assert_closed();
            for (i, ray) in rays_at_edges_and_vertices(mesh, &mut rng, 20_000)
                .iter()
                .enumerate()
            {
                for accel in [&bvh as &dyn Accel, &qbvh, &bvh8] {
                    let hit = accel.intersect(ray, f32::INFINITY);
                    assert!(
                        hit.is_some_and(|h| h.t <= 1.0 + 1e-3),
                        "{}: ray {i} {ray:?} found {hit:?}",
                        accel.name()
                    );
                    assert!(accel.occluded(ray, 1.0 + 1e-3), "ray {i} {ray:?}");
                }
            }
        }
    }
}

/// The points `e.0`–`e.1` is split at among `vertices`, found by descending the midpoint tree of
/// the edge wherever a midpoint is a vertex: a sub-edge is split only if it is a piece's edge.
fn split_points(e: (Vec3, Vec3), vertices: &HashSet<[u32; 3]>, out: &mut Vec<[u32; 3]>) {
    let key = |v: Vec3| v.to_array().map(f32::to_bits);
    let m = e.0 * 0.5 + e.1 * 0.5;
    if vertices.contains(&key(m)) {
        out.push(key(m));
        split_points((e.0, m), vertices, out);
        split_points((m, e.1), vertices, out);
    }
}

/// Triangles around `offset`, and rays from nearby aimed at points on their edges.
fn edge_rays_far_from_the_origin(seed: u64, offset: Vec3) -> (Vec<[Vec3; 3]>, Vec<(Ray, f32)>) {
    let mut rng = Rng::new(seed);
    let tris: Vec<[Vec3; 3]> = (0..100)
        .map(|_| [0; 3].map(|_| offset + rng.vec_in(-1.0, 1.0)))
        .collect();
    let rays = (0..4000)
        .map(|_| {
            let t = tris[rng.below(tris.len())];
            let k = rng.below(3);
            let target = t[k] + (t[(k + 1) % 3] - t[k]) * rng.f32();
            let origin = target + rng.unit_vec() * rng.range(0.2, 1.0);
            (Ray::new(origin, target - origin), f32::INFINITY)
        })
        .collect();
    (tris, rays)
}

#[test]
fn reference_boxes_cover_their_triangles_far_from_the_origin() {
    // Midpoints round by up to half an ulp of the coordinates, which far from the origin is much
    // more than the traversal's margin for a ray from nearby, and puts points of the original
    // edges outside the boxes of the pieces' rounded vertices: the reference boxes must make up
    // for it.
    let offset = Vec3::new(1000.3, -777.7, 333.1);
    let (tris, rays) = edge_rays_far_from_the_origin(21, offset);
    for split in SPLITS {
        let refs = split_references(&tris, split);
        assert!(refs.len() > 10 * tris.len(), "{split:?}: {}", refs.len());
        // Exact points of every edge, in double precision.
        for (i, tri) in tris.iter().enumerate() {
            let boxes: Vec<_> = refs.iter().filter(|r| r.1 as usize == i).collect();
            for k in 0..3 {
                let (a, b) = (tri[k].as_dvec3(), tri[(k + 1) % 3].as_dvec3());
                for j in 0..=32 {
                    let p = a + (b - a) * (j as f64 / 32.0);
                    let inside = |r: &&(Aabb, u32)| {
                        p.cmpge(r.0.min.as_dvec3()).all() && p.cmple(r.0.max.as_dvec3()).all()
                    };
                    assert!(boxes.iter().any(inside), "{split:?}: {p} of triangle {i}");
                }
            }
        }
        let bvh = build(&tris, &params(split, true));
        let hits = check_rays(&bvh, &tris, &rays, &format!("{split:?}"));
        assert!(hits > 1000, "{hits}");
    }
}

#[test]
fn evh_splits_shared_edges_identically() {
    let meshes = rotated_meshes();
    let tris: Vec<_> = meshes.iter().flat_map(Mesh::triangles).collect();
    let mut vertices = vec![HashSet::new(); tris.len()];
    for (piece, i) in split_pieces(&tris, Split::Evh { t: 20 }) {
        vertices[i as usize].extend(piece.map(|v| v.to_array().map(f32::to_bits)));
    }
    let mut first_face = 0;
    let (mut edges, mut split_edges) = (0, 0);
    for mesh in &meshes {
        let mut faces_of_edge: HashMap<(u32, u32), Vec<usize>> = HashMap::new();
        for (f, face) in mesh.faces.iter().enumerate() {
            for k in 0..3 {
                let (a, b) = (face[k], face[(k + 1) % 3]);
                faces_of_edge
                    .entry((a.min(b), a.max(b)))
                    .or_default()
                    .push(first_face + f);
            }
        }
        for ((a, b), faces) in faces_of_edge {
            let e = (mesh.positions[a as usize], mesh.positions[b as usize]);
            // Walk the edge in opposite directions from the two sides, as the triangles do.
            let (mut p, mut q) = (Vec::new(), Vec::new());
            split_points(e, &vertices[faces[0]], &mut p);
            split_points((e.1, e.0), &vertices[faces[1]], &mut q);
            p.sort_unstable();
            q.sort_unstable();
            assert_eq!(p, q, "edge {a}-{b}");
            edges += 1;
            split_edges += usize::from(!p.is_empty());
        }
        first_face += mesh.faces.len();
    }
    assert!(
        split_edges * 4 > edges,
        "{split_edges} of {edges} edges split"
    );
}

#[test]
fn evh_leaves_axis_aligned_geometry_alone() {
    let cube = grid_cube(6)
        .transformed(|p| p * Vec3::new(3.0, 1.0, 0.5))
        .triangles();
    for t in [14, 20, 30] {
        assert_eq!(split_references(&cube, Split::Evh { t }).len(), cube.len());
    }
    assert!(split_references(&cube, Split::Bbah { t: 14 }).len() > cube.len());

    // Thin triangles along x, turned 45 degrees about z and then about x: off every axis plane.
    let q = Quat::from_rotation_x(std::f32::consts::FRAC_PI_4)
        * Quat::from_rotation_z(std::f32::consts::FRAC_PI_4);
    let thin: Vec<[Vec3; 3]> = (0..50)
        .map(|i| {
            let o = Vec3::new(0.0, i as f32 * 0.1, 0.0);
            [o, o + Vec3::X * 5.0, o + Vec3::new(2.5, 0.02, 0.0)].map(|v| q * v)
        })
        .collect();
    let evh = split_references(&thin, Split::Evh { t: 14 }).len();
    let bbah = split_references(&thin, Split::Bbah { t: 14 }).len();
    assert!(evh > thin.len(), "{evh}");
    assert!(bbah > evh, "BBAH {bbah}, EVH {evh}");
}

#[test]
fn reference_boxes_are_tighter_and_index_every_triangle() {
    let mut rng = Rng::new(5);
    let tris = thin_diagonal_soup(&mut rng, 200);
    let refs = split_references(&tris, Split::Evh { t: 14 });
    let mut seen = vec![false; tris.len()];
    let mut area = vec![0.0f64; tris.len()];
    for (b, i) in &refs {
        seen[*i as usize] = true;
        area[*i as usize] += b.surface_area() as f64;
    }
    assert!(seen.iter().all(|&s| s));
    let before: f64 = tris
        .iter()
        .map(|t| rt_core::Aabb::from_points(t).surface_area() as f64)
        .sum();
    let after: f64 = area.iter().sum();
    assert!(after < 0.7 * before, "box area {before} -> {after}");
}

#[test]
fn compaction_removes_duplicates_and_keeps_every_hit() {
    let mut rng = Rng::new(9);
    let mut tris = thin_diagonal_soup(&mut rng, 300);
    tris.extend(soup(&mut rng, 100));
    for split in SPLITS {
        let loose = build(&tris, &params(split, false));
        let tight = build(&tris, &params(split, true));
        let (l, t) = (loose.stats(), tight.stats());
        assert!(t.references < l.references, "{split:?}: {l} vs {t}");
        assert!(t.references >= t.triangles);
        assert_eq!(loose.nodes().len(), tight.nodes().len());
        for (ray, t_max) in rays(&mut rng, &tris, 3000) {
            assert_eq!(
                loose.intersect(&ray, t_max),
                tight.intersect(&ray, t_max),
                "{split:?} {ray:?}"
            );
            assert_eq!(loose.occluded(&ray, t_max), tight.occluded(&ray, t_max));
        }
    }
}

#[test]
fn parallel_and_sequential_split_builds_are_identical() {
    let mut rng = Rng::new(13);
    let tris = thin_diagonal_soup(&mut rng, 6000);
    for compact in [false, true] {
        let p = params(Split::Evh { t: 14 }, compact);
        let par = Bvh2::build(&tris, &p);
        let seq = Bvh2::build(
            &tris,
            &BuildParams {
                parallel: false,
                ..p
            },
        );
        assert_eq!(par.nodes(), seq.nodes());
        assert_eq!(par.prim_ids(), seq.prim_ids());
    }
}

#[test]
fn no_split_params_build_the_same_tree() {
    let tris = soup(&mut Rng::new(17), 2000);
    let plain = Bvh2::build(&tris, &BuildParams::default());
    let compacted = Bvh2::build(
        &tris,
        &BuildParams {
            compact_leaves: true,
            ..BuildParams::default()
        },
    );
    assert_eq!(plain.nodes(), compacted.nodes());
    assert_eq!(plain.prim_ids(), compacted.prim_ids());
    assert_eq!(plain.stats().references, tris.len());
}

/// Reference counts on real meshes, for the report: `cargo test --release -p rt-accel --test
/// splitting -- --ignored --nocapture`. Reads the OBJ files named in `RT_SPLIT_OBJS`
/// (colon-separated), or the shared Stanford bunny and Sibenik if present.
#[test]
#[ignore]
fn reference_counts_of_real_meshes() {
    let paths = std::env::var("RT_SPLIT_OBJS").unwrap_or_else(|_| {
        let dir = rt_testkit::data::default_dir();
        ["models/stanford-bunny.obj", "scenes/sibenik/sibenik.obj"]
            .map(|m| dir.join(m).display().to_string())
            .join(":")
    });
    for path in paths.split(':') {
        let Ok(text) = std::fs::read_to_string(path) else {
            println!("{path}: not found");
            continue;
        };
        let tris = rt_testkit::obj::parse(&text);
        let splits = [
            Split::None,
            Split::Evh { t: 14 },
            Split::Evh { t: 20 },
            Split::Bbah { t: 14 },
        ];
        for split in splits {
            let start = std::time::Instant::now();
            let n = split_references(&tris, split).len();
            println!(
                "{path}: {split:?}: {n} references / {} triangles = {:.3} ({:.0} ms)",
                tris.len(),
                n as f64 / tris.len() as f64,
                start.elapsed().as_secs_f64() * 1e3
            );
            for compact in [false, true] {
                let bvh = Bvh2::build(&tris, &params(split, compact));
                bvh.validate().unwrap();
                println!("  compact {compact}: {}", bvh.stats());
            }
        }
    }
}
