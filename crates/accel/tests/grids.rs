//! The uniform and irregular grids against brute force (random soups of many sizes, long thin
//! triangles spanning the grid, degenerate triangles, one plane, closed meshes, the bunny), and
//! the irregular grid's invariants after merging and expansion.

mod common;

use common::{
    check_rays, icosphere, rays, rays_at_edges_and_vertices, shared_mesh, soup, thin_diagonal_soup,
    Rng,
};
use rt_accel::grid::{Binning, GridError};
use rt_accel::{IrregularGrid, IrregularGridParams, UniformGrid, UniformGridParams};
use rt_core::glam::Vec3;
use rt_core::{Accel, Ray, TraversalCounters};

/// Every grid variant the tests exercise, by label.
fn grids(tris: &[[Vec3; 3]]) -> Vec<(String, Box<dyn Accel>)> {
    let mut out: Vec<(String, Box<dyn Accel>)> = Vec::new();
    for binning in [Binning::Exact, Binning::Boxes] {
        let p = UniformGridParams {
            binning,
            ..Default::default()
        };
        out.push((
            format!("uniform {binning:?}"),
            Box::new(UniformGrid::build(tris, &p).unwrap()),
        ));
        let p = IrregularGridParams {
            binning,
            ..Default::default()
        };
        let g = IrregularGrid::build(tris, &p).unwrap();
        g.validate().unwrap();
        out.push((format!("irregular {binning:?}"), Box::new(g)));
    }
    // The plain two-level grid, and merging without expansion.
    for (merge, expansion_passes) in [(false, 0), (true, 0)] {
        let p = IrregularGridParams {
            merge,
            expansion_passes,
            ..Default::default()
        };
        let g = IrregularGrid::build(tris, &p).unwrap();
        g.validate().unwrap();
        out.push((format!("irregular merge={merge} passes=0"), Box::new(g)));
    }
    out
}

/// Checks every grid variant over `tris` on `n` rays against brute force (closest hit,
/// occlusion agreeing with it, counters filled); returns the hits of the first variant.
fn check_all(tris: &[[Vec3; 3]], n: usize, seed: u64, label: &str) -> usize {
    let mut rng = Rng::new(seed);
    let rays = rays(&mut rng, tris, n);
    let mut first = None;
    for (name, g) in grids(tris) {
        let hits = check_rays(g.as_ref(), tris, &rays, &format!("{label} {name}"));
        for (ray, t_max) in &rays {
            let got = g.intersect(ray, *t_max);
            let target = ray.origin + ray.dir * t_max.min(1.0);
            assert_eq!(
                g.occluded_toward(ray, *t_max, target),
                got.is_some(),
                "{label} {name}"
            );
            let mut c = TraversalCounters::default();
            assert_eq!(g.closest_hit(ray, *t_max, Some(&mut c)), got);
            if got.is_some() {
                assert!(c.prims_tested >= 1 && c.nodes_visited >= 2, "{c:?}");
            }
        }
        assert!(g.counts_traversal());
        first.get_or_insert(hits);
    }
    first.unwrap()
}

#[test]
fn soups_of_many_sizes_agree_with_brute_force() {
    for (n, n_rays, seed) in [(1, 400, 1), (2, 400, 2), (100, 3000, 3), (10_000, 1500, 4)] {
        let mut rng = Rng::new(seed);
        let tris = soup(&mut rng, n);
        let hits = check_all(&tris, n_rays, seed + 100, &format!("soup {n}"));
        assert!(hits > n_rays / 10, "soup {n}: {hits} hits");
    }
}

#[test]
fn more_seeds_of_medium_soups() {
    for seed in 10..16 {
        let mut rng = Rng::new(seed);
        let n = [30, 300, 1000][seed as usize % 3];
        let tris = soup(&mut rng, n);
        check_all(&tris, 1500, seed + 100, &format!("soup {n} seed {seed}"));
    }
}

#[test]
fn long_thin_triangles_spanning_the_grid() {
    let mut rng = Rng::new(21);
    let mut tris = soup(&mut rng, 300);
    // Corner to corner of the soup's box, in several directions, and slivers along them.
    for k in 0..8 {
        let a = Vec3::new(
            if k & 1 == 0 { -1.0 } else { 1.0 },
            if k & 2 == 0 { -1.0 } else { 1.0 },
            if k & 4 == 0 { -1.0 } else { 1.0 },
        );
        let across = a.cross(Vec3::new(0.3, 0.5, 0.7)).normalize();
        tris.push([a, -a, across * 0.01]);
        tris.push([a, -a, across * 1e-5]);
    }
    tris.extend(thin_diagonal_soup(&mut rng, 200));
    check_all(&tris, 3000, 22, "thin");
}

#[test]
fn degenerate_triangles() {
    let mut rng = Rng::new(31);
    let mut tris = Vec::new();
    for _ in 0..300 {
        let a = rng.vec_in(-1.0, 1.0);
        let b = rng.vec_in(-1.0, 1.0);
        tris.push(match rng.below(4) {
            0 => [a, a, a],
            1 => [a, b, b],
            2 => [a, b, a.lerp(b, rng.f32())],
            _ => [a, b, rng.vec_in(-1.0, 1.0)],
        });
    }
    check_all(&tris, 2000, 32, "degenerate");
    // Only degenerate ones: nothing is ever hit.
    let flat: Vec<_> = (0..50).map(|_| [rng.vec_in(-1.0, 1.0); 3]).collect();
    for (name, g) in grids(&flat) {
        for (ray, t_max) in rays(&mut rng, &flat, 200) {
            assert!(g.intersect(&ray, t_max).is_none(), "{name}");
        }
    }
}

#[test]
fn all_triangles_in_one_plane() {
    let mut rng = Rng::new(41);
    let tris: Vec<[Vec3; 3]> = (0..2000)
        .map(|_| {
            let c = Vec3::new(rng.range(-1.0, 1.0), rng.range(-1.0, 1.0), 0.25);
            [0; 3].map(|_| {
                let mut v = c + rng.vec_in(-0.05, 0.05);
                v.z = 0.25;
                v
            })
        })
        .collect();
    let hits = check_all(&tris, 3000, 42, "plane");
    assert!(hits > 300, "{hits}");
    let g = UniformGrid::build(&tris, &UniformGridParams::default()).unwrap();
    assert_eq!(g.resolution()[2], 1);
}

#[test]
fn closed_meshes_have_no_cracks() {
    let mut rng = Rng::new(51);
    let mesh = icosphere(4);
    let tris = mesh.triangles();
    let rays = rays_at_edges_and_vertices(&mesh, &mut rng, 3000);
    for (name, g) in grids(&tris) {
        for (i, r) in rays.iter().enumerate() {
            let h = g.intersect(r, f32::INFINITY);
            assert!(
                h.is_some_and(|h| h.t <= 1.0 + 1e-4),
                "{name}: ray {i} {r:?}: {h:?}"
            );
        }
    }
}

#[test]
fn nan_infinite_and_zero_rays_hit_nothing() {
    let mut rng = Rng::new(61);
    let tris = soup(&mut rng, 200);
    let bad = [
        Ray::new(Vec3::ZERO, Vec3::splat(f32::NAN)),
        Ray::new(Vec3::splat(f32::NAN), Vec3::Z),
        Ray::new(Vec3::new(0.1, f32::NAN, 0.2), Vec3::Z),
        Ray::new(Vec3::ZERO, Vec3::new(0.0, f32::INFINITY, -1.0)),
        Ray::new(Vec3::new(f32::INFINITY, 0.0, 0.0), -Vec3::X),
        Ray::new(Vec3::ZERO, Vec3::ZERO),
    ];
    for (name, g) in grids(&tris) {
        for r in &bad {
            for t_max in [f32::INFINITY, 1.0, f32::NAN] {
                assert!(g.intersect(r, t_max).is_none(), "{name} {r:?}");
                assert!(!g.occluded(r, t_max), "{name} {r:?}");
            }
        }
    }
}

#[test]
fn empty_scenes_and_bad_parameters() {
    for tris in [vec![], vec![[Vec3::splat(f32::NAN); 3]]] {
        for (name, g) in grids(&tris) {
            assert!(g.bounds().is_empty(), "{name}");
            assert!(g
                .intersect(&Ray::new(Vec3::ZERO, Vec3::X), f32::INFINITY)
                .is_none());
        }
    }
    let tri = [[Vec3::ZERO, Vec3::X, Vec3::Y]];
    for lambda in [0.0, -1.0, f32::NAN, f32::INFINITY] {
        let p = UniformGridParams {
            lambda,
            ..Default::default()
        };
        assert!(matches!(
            UniformGrid::build(&tri, &p),
            Err(GridError::BadParameter { name: "lambda", .. })
        ));
        let p = IrregularGridParams {
            lambda_sub: lambda,
            ..Default::default()
        };
        assert!(matches!(
            IrregularGrid::build(&tri, &p),
            Err(GridError::BadParameter { .. })
        ));
    }
}

#[test]
fn uniform_grid_follows_cleary_and_lists_every_overlapping_triangle() {
    let mut rng = Rng::new(71);
    // Triangles filling a 4 x 2 x 1 box.
    let tris: Vec<[Vec3; 3]> = (0..3000)
        .map(|_| {
            let c = rng.vec_in(0.0, 1.0) * Vec3::new(4.0, 2.0, 1.0);
            [0; 3].map(|_| c + rng.vec_in(-0.02, 0.02))
        })
        .collect();
    let g = UniformGrid::build(&tris, &UniformGridParams::default()).unwrap();
    let r = g.resolution();
    let cells = r.iter().product::<u32>() as f32;
    assert!((cells / 9000.0 - 1.0).abs() < 0.25, "{r:?}");
    assert!((r[0] as f32 / r[2] as f32 - 4.0).abs() < 0.5, "{r:?}");
    assert!((r[1] as f32 / r[2] as f32 - 2.0).abs() < 0.5, "{r:?}");
    assert!(g.memory_bytes() > g.structure_bytes() && g.structure_bytes() > 0);
    // Points on each triangle: the cell around each lists it.
    for (t, tri) in tris.iter().enumerate() {
        for _ in 0..4 {
            let (b1, b2) = rng.barycentric();
            let p = rt_core::triangle::point_at(tri, b1, b2);
            for z in 0..r[2] {
                for y in 0..r[1] {
                    for x in 0..r[0] {
                        let b = g.cell_bounds([x, y, z]).unwrap();
                        if b.contains(p) {
                            let list = g.cell_triangles([x, y, z]).unwrap();
                            assert!(list.contains(&(t as u32)), "cell {x},{y},{z} misses {t}");
                        }
                    }
                }
            }
        }
    }
}

/// Points on the triangles: the cell owning the virtual cell around each lists the triangle,
/// and so does every cell whose expanded box holds it.
fn check_irregular_invariants(tris: &[[Vec3; 3]], g: &IrregularGrid, rng: &mut Rng, label: &str) {
    g.validate().unwrap_or_else(|e| panic!("{label}: {e}"));
    g.validate_coverage()
        .unwrap_or_else(|e| panic!("{label}: {e}"));
    let cells: Vec<_> = g.cells().collect();
    assert_eq!(cells.len(), g.cell_count());
    for (t, tri) in tris.iter().enumerate() {
        if rt_core::triangle::area(tri) == 0.0 {
            continue;
        }
        for _ in 0..3 {
            let (b1, b2) = rng.barycentric();
            let p = rt_core::triangle::point_at(tri, b1, b2);
            let Some(v) = g.virtual_cell_strictly_at(p) else {
                continue;
            };
            let owner = g.owner(v).unwrap();
            assert!(
                cells[owner].triangles.contains(&(t as u32)),
                "{label}: owner {owner} of {v:?} misses {t}"
            );
            for (i, c) in cells.iter().enumerate() {
                let inside = (0..3).all(|a| v[a] >= c.expanded_lo[a] && v[a] < c.expanded_hi[a]);
                if inside {
                    assert!(
                        c.triangles.contains(&(t as u32)),
                        "{label}: cell {i} expanded over {v:?} misses {t}"
                    );
                }
            }
        }
    }
}

#[test]
fn irregular_grid_invariants() {
    for (seed, n) in [(81u64, 50usize), (82, 400), (83, 1500)] {
        let mut rng = Rng::new(seed);
        let tris = soup(&mut rng, n);
        let plain = IrregularGrid::build(
            &tris,
            &IrregularGridParams {
                merge: false,
                expansion_passes: 0,
                ..Default::default()
            },
        )
        .unwrap();
        let g = IrregularGrid::build(&tris, &IrregularGridParams::default()).unwrap();
        check_irregular_invariants(&tris, &plain, &mut rng, &format!("plain {n}"));
        check_irregular_invariants(&tris, &g, &mut rng, &format!("irregular {n}"));
        // Merging removes cells and expansion grows some.
        assert!(g.cell_count() < plain.cell_count(), "{n}");
        assert!(
            g.cells()
                .any(|c| c.expanded_lo != c.lo || c.expanded_hi != c.hi),
            "{n}: nothing expanded"
        );
        assert!(g.memory_bytes() > g.structure_bytes() && g.structure_bytes() > 0);
    }
}

#[test]
fn bunny_agrees_with_brute_force() {
    let Some(tris) = shared_mesh("models/stanford-bunny.obj") else {
        return;
    };
    let hits = check_all(&tris, 800, 2026, "bunny");
    assert!(hits > 200, "{hits}");
    let g = IrregularGrid::build(&tris, &IrregularGridParams::default()).unwrap();
    g.validate().unwrap();
}

/// Slivers (a vertex 10⁻⁶ to 10⁻⁵ off the opposite edge) in a cloud of small triangles, with
/// rays aimed at points on the slivers: the watertight test's distance for a sliver is mostly
/// rounding noise, and the grids must still find whatever brute force finds inside the
/// sliver's box (they bin slivers by box, see `rt_accel::grid`).
#[test]
fn slivers_hit_by_aimed_rays() {
    let mut rng = Rng::new(91);
    let mut tris = Vec::new();
    for _ in 0..3000 {
        let c = rng.vec_in(-1.0, 1.0);
        tris.push([0; 3].map(|_| c + rng.vec_in(-0.04, 0.04)));
    }
    let first_sliver = tris.len();
    for _ in 0..300 {
        let a = rng.vec_in(-1.0, 1.0);
        let b = a + rng.unit_vec() * rng.range(0.5, 2.0);
        let across = (b - a).cross(rng.unit_vec()).normalize();
        tris.push([
            a,
            b,
            a.lerp(b, 0.5) + across * 10f32.powf(rng.range(-6.0, -5.0)),
        ]);
    }
    let rays: Vec<(Ray, f32)> = (0..4000)
        .map(|_| {
            let t = tris[first_sliver + rng.below(300)];
            let (b1, b2) = rng.barycentric();
            let p = rt_core::triangle::point_at(&t, b1, b2);
            let o = rng.vec_in(-2.0, 2.0);
            (Ray::new(o, p - o), f32::INFINITY)
        })
        .collect();
    for (name, g) in grids(&tris) {
        check_rays(g.as_ref(), &tris, &rays, &format!("slivers {name}"));
    }
}

/// Rays starting exactly on cell faces (of the uniform grid's cells, the irregular grid's own
/// and expanded boxes, and the grid's outer box), moving within the face plane (with `0.0` or
/// `-0.0` on its axis), across it along the axis, or obliquely.
#[test]
fn rays_from_cell_faces() {
    let mut rng = Rng::new(101);
    let tris = soup(&mut rng, 400);
    let uniform = UniformGrid::build(&tris, &UniformGridParams::default()).unwrap();
    let irregular = IrregularGrid::build(&tris, &IrregularGridParams::default()).unwrap();
    let r = uniform.resolution();
    let mut boxes = vec![uniform.bounds(), irregular.bounds()];
    for _ in 0..100 {
        let c = [0, 1, 2].map(|a| rng.below(r[a] as usize) as u32);
        boxes.push(uniform.cell_bounds(c).unwrap());
        let cell = irregular.cell(rng.below(irregular.cell_count())).unwrap();
        boxes.push(cell.bounds);
        boxes.push(cell.expanded_bounds);
    }
    let mut rays = Vec::new();
    for b in &boxes {
        for _ in 0..20 {
            let axis = rng.below(3);
            let mut o = b.min + (b.max - b.min) * rng.vec_in(0.0, 1.0);
            o[axis] = if rng.chance(0.5) {
                b.min[axis]
            } else {
                b.max[axis]
            };
            let mut d = match rng.below(3) {
                0 => rng.unit_vec(),
                1 => {
                    let mut d = Vec3::ZERO;
                    d[(axis + 1 + rng.below(2)) % 3] = if rng.chance(0.5) { 1.0 } else { -1.0 };
                    d
                }
                _ => {
                    let mut d = Vec3::splat(-0.0);
                    d[axis] = if rng.chance(0.5) { 1.0 } else { -1.0 };
                    d
                }
            };
            if d[axis].abs() != 1.0 {
                // In the face plane: a signed zero on its axis.
                d[axis] = if rng.chance(0.5) { 0.0 } else { -0.0 };
                if d == Vec3::ZERO {
                    d[(axis + 1) % 3] = 1.0;
                }
            }
            let t_max = if rng.chance(0.25) {
                rng.range(0.05, 2.0)
            } else {
                f32::INFINITY
            };
            rays.push((Ray::new(o, d), t_max));
        }
    }
    let mut hits = 0;
    for (name, g) in grids(&tris) {
        hits += check_rays(g.as_ref(), &tris, &rays, &format!("faces {name}"));
    }
    assert!(hits > rays.len(), "{hits}");
}

/// Rays from outside the grid's box (most of `rays`' origins lie inside it): aimed at points on
/// triangles from every side, so they enter through faces, edges and corners of the grid.
#[test]
fn rays_from_outside_the_grid() {
    let mut rng = Rng::new(111);
    let tris = soup(&mut rng, 1000);
    let rays: Vec<(Ray, f32)> = (0..3000)
        .map(|_| {
            let t = tris[rng.below(tris.len())];
            let (b1, b2) = rng.barycentric();
            let p = rt_core::triangle::point_at(&t, b1, b2);
            let o = rng.unit_vec() * rng.range(4.0, 20.0);
            (Ray::new(o, p - o), f32::INFINITY)
        })
        .collect();
    let mut hits = 0;
    for (name, g) in grids(&tris) {
        hits += check_rays(g.as_ref(), &tris, &rays, &format!("outside {name}"));
    }
    assert!(hits > rays.len(), "{hits}");
}
