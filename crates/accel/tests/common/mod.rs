//! Shared test helpers of the acceleration-structure tests (the seeded RNG and the OBJ reader
//! come from `rt-testkit`): triangle soups, ray sets, closed meshes and the hit
//! comparison against the brute-force oracle.
#![allow(dead_code)] // each test binary uses a different subset

use glam::{Quat, Vec3};
use rt_accel::wide::QChild;
use rt_accel::{BruteForce, BuildParams, Bvh2, WideBvh, WideNode};
use rt_core::triangle::{intersect_triangle, RayPrecomp};
use rt_core::{Accel, Hit, Ray, TraversalCounters};

/// The workspace's one seeded test RNG.
pub use rt_testkit::Rng;

/// Planes that axis-aligned soup triangles lie in; rays start on them too.
pub const PLANES: [f32; 4] = [-0.5, 0.0, 0.25, 0.5];

/// A point of the 1/8 grid in [-1, 1] on which axis-aligned soup triangles have their vertices,
/// so that they share edges and overlap exactly.
fn grid(rng: &mut Rng) -> f32 {
    (rng.below(17) as f32 - 8.0) / 8.0
}

/// A triangle soup in roughly [-1, 1]^3 mixing ordinary triangles of many sizes, long thin ones,
/// degenerate ones (collinear, two equal vertices, a point), exact and vertex-rotated duplicates
/// and axis-aligned coplanar ones sharing edges.
pub fn soup(rng: &mut Rng, n: usize) -> Vec<[Vec3; 3]> {
    let mut tris: Vec<[Vec3; 3]> = Vec::with_capacity(n);
    while tris.len() < n {
        let t = match rng.below(10) {
            0..=2 => {
                let c = rng.vec_in(-1.0, 1.0);
                let size = 10f32.powf(rng.range(-3.0, 0.0));
                [0; 3].map(|_| c + rng.vec_in(-size, size))
            }
            3 => {
                let a = rng.vec_in(-1.0, 1.0);
                let b = a + rng.unit_vec() * rng.range(0.5, 2.0);
                let thin = rng.unit_vec() * 10f32.powf(rng.range(-6.0, -3.0));
                [a, b, (a + b) * 0.5 + thin]
            }
            4 => {
                let a = rng.vec_in(-1.0, 1.0);
                let b = a + rng.vec_in(-0.3, 0.3);
                match rng.below(3) {
                    0 => [a, b, a + (b - a) * rng.f32()],
                    1 => [a, b, b],
                    _ => [a, a, a],
                }
            }
            5 if !tris.is_empty() => {
                let t = tris[rng.below(tris.len())];
                match rng.below(3) {
                    0 => t,
                    1 => [t[1], t[2], t[0]],
                    _ => [t[0], t[2], t[1]],
                }
            }
            6 | 7 => {
                let axis = rng.below(3);
                let plane = PLANES[rng.below(PLANES.len())];
                [0; 3].map(|_| {
                    let mut v = Vec3::new(grid(rng), grid(rng), grid(rng));
                    v[axis] = plane;
                    v
                })
            }
            _ => {
                let c = rng.vec_in(-0.5, 0.5);
                [0; 3].map(|_| c + rng.vec_in(-2.0, 2.0))
            }
        };
        tris.push(t);
    }
    tris
}

/// A direction with some components replaced by `0.0` or `-0.0`, never all.
fn direction_with_zeros(rng: &mut Rng) -> Vec3 {
    loop {
        let mut d = rng.unit_vec();
        for axis in 0..3 {
            match rng.below(3) {
                0 => d[axis] = 0.0,
                1 => d[axis] = -0.0,
                _ => {}
            }
        }
        if d != Vec3::ZERO {
            return d;
        }
    }
}

fn axis_direction(rng: &mut Rng) -> Vec3 {
    let mut d = Vec3::ZERO;
    d[rng.below(3)] = if rng.chance(0.5) { 1.0 } else { -1.0 };
    // Keep signed zeros in the other components half the time.
    if rng.chance(0.5) {
        d = d.map(|c| if c == 0.0 { -0.0 } else { c });
    }
    d
}

/// A point on a random triangle of `tris`, from barycentrics, as a renderer computes hit points.
fn point_on(rng: &mut Rng, tris: &[[Vec3; 3]]) -> Vec3 {
    let t = tris[rng.below(tris.len())];
    let (b1, b2) = rng.barycentric();
    rt_core::triangle::point_at(&t, b1, b2)
}

/// Rays for `tris`, each with its `t_max`: random rays, rays aimed at points on triangles and at
/// their vertices, rays along the axes and with zero and negative-zero direction components,
/// rays starting on a triangle, and rays lying in the planes of the axis-aligned triangles.
pub fn rays(rng: &mut Rng, tris: &[[Vec3; 3]], n: usize) -> Vec<(Ray, f32)> {
    (0..n)
        .map(|_| {
            let ray = match rng.below(9) {
                0 => Ray::new(rng.vec_in(-2.0, 2.0), rng.unit_vec()),
                1 => {
                    let o = rng.vec_in(-2.0, 2.0);
                    Ray::new(o, point_on(rng, tris) - o)
                }
                2 => {
                    let o = rng.vec_in(-2.0, 2.0);
                    Ray::new(o, tris[rng.below(tris.len())][rng.below(3)] - o)
                }
                3 => {
                    // Aim along an axis at a point of a triangle, so axis rays do hit things.
                    let d = axis_direction(rng);
                    let p = point_on(rng, tris);
                    Ray::new(p - d * rng.range(0.5, 2.0), d)
                }
                4 => Ray::new(rng.vec_in(-2.0, 2.0), direction_with_zeros(rng)),
                5 => {
                    // Through a point of a triangle with zero components: the origin shares
                    // that point's coordinates on those axes exactly.
                    let p = point_on(rng, tris);
                    let d = direction_with_zeros(rng);
                    Ray::new(p - d * rng.range(0.5, 2.0), d)
                }
                6 | 7 => {
                    let o = point_on(rng, tris);
                    let d = if rng.chance(0.5) {
                        rng.unit_vec()
                    } else {
                        direction_with_zeros(rng)
                    };
                    Ray::new(o, d)
                }
                _ => {
                    // In the plane of the axis-aligned triangles, moving parallel to it, often
                    // from a grid point: slab distances become 0 * inf there.
                    let axis = rng.below(3);
                    let mut o = if rng.chance(0.5) {
                        Vec3::new(grid(rng), grid(rng), grid(rng)) * 1.5
                    } else {
                        rng.vec_in(-1.5, 1.5)
                    };
                    o[axis] = PLANES[rng.below(PLANES.len())];
                    let mut d = if rng.chance(0.5) {
                        axis_direction(rng)
                    } else {
                        rng.unit_vec()
                    };
                    d[axis] = if rng.chance(0.5) { 0.0 } else { -0.0 };
                    if d == Vec3::ZERO {
                        d[(axis + 1) % 3] = 1.0;
                    }
                    Ray::new(o, d)
                }
            };
            let t_max = match rng.below(4) {
                0 => rng.range(0.1, 3.0),
                _ => f32::INFINITY,
            };
            (ray, t_max)
        })
        .collect()
}

/// The watertight test against one triangle, as the structures run it.
pub fn hit_one(ray: &Ray, tri: &[Vec3; 3], t_max: f32) -> Option<(f32, f32, f32)> {
    intersect_triangle(&RayPrecomp::new(ray), tri, t_max).map(|h| (h.t, h.b1, h.b2))
}

/// How a structure's answer related to the oracle's.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Agreement {
    /// Same triangle, bit-identical values (or both missed).
    Exact,
    /// A different triangle at the same distance up to rounding.
    Tie,
    /// The oracle's closest hit was one that lies outside its own triangle's bounding box, which
    /// box culling may legitimately skip; see [`check_ray`].
    OracleOutsideBox,
}

/// Checks `accel`'s closest hit and occlusion for one ray against the brute-force `oracle` over
/// the same `tris`.
///
/// The same triangle must come with bit-identical values. A different triangle is accepted only
/// if its hit is genuine (exactly what the triangle test reports for it) and
///
/// - it is a tie: no closer than the oracle's (the minimum over all triangles) and farther by
///   less than the triangle test's own rounding. Coplanar overlapping triangles are hit at the
///   same exact distance, but each computes it from different vertices, so the computed
///   distances differ in the last bits and culling may settle on either; the hit points then
///   agree to within [`TIE_ULPS`] ulps of the coordinates involved. Or
/// - the oracle's hit is not inside its triangle's bounding box. `rt-core`'s triangle test
///   computes the distance of a nearly degenerate triangle (three almost collinear vertices,
///   e.g. a collinear triple after rounding) from a determinant that is mostly rounding noise,
///   and can report a point far from the triangle. A bounding volume hierarchy rightly skips
///   such a hit when its box lies beyond a real one, so there the answer must instead be no
///   closer than the oracle's and no farther than the closest hit that does lie in its box.
pub fn check_ray(
    accel: &dyn Accel,
    oracle: &dyn Accel,
    ray: &Ray,
    t_max: f32,
    tris: &[[Vec3; 3]],
) -> Result<Agreement, String> {
    let got = accel.intersect(ray, t_max);
    let want = oracle.intersect(ray, t_max);
    let occluded = accel.occluded(ray, t_max);
    let agreement = compare_hits(got, want, ray, t_max, tris)?;
    let must_occlude = match agreement {
        Agreement::OracleOutsideBox => closest_inside_box(ray, t_max, tris).is_some(),
        _ => want.is_some(),
    };
    if occluded != must_occlude && !(occluded && want.is_some()) {
        return Err(format!("occluded {occluded}, oracle {want:?}"));
    }
    Ok(agreement)
}

fn compare_hits(
    got: Option<Hit>,
    want: Option<Hit>,
    ray: &Ray,
    t_max: f32,
    tris: &[[Vec3; 3]],
) -> Result<Agreement, String> {
    let genuine = |h: Hit| hit_one(ray, &tris[h.prim as usize], t_max) == Some((h.t, h.b1, h.b2));
    match (got, want) {
        (None, None) => return Ok(Agreement::Exact),
        (Some(g), Some(w)) if g.prim == w.prim => {
            let bits = |h: Hit| (h.t.to_bits(), h.b1.to_bits(), h.b2.to_bits());
            return if bits(g) == bits(w) {
                Ok(Agreement::Exact)
            } else {
                Err(format!("same prim, different values: {got:?} vs {want:?}"))
            };
        }
        (Some(g), Some(w)) if genuine(g) && is_tie(g, w, ray, tris) => return Ok(Agreement::Tie),
        _ => {}
    }
    // Not exact and not a tie: acceptable only if the oracle's hit is one culling may skip.
    let Some(w) = want else {
        return Err(format!("{got:?} vs no hit"));
    };
    if inside_box(ray, w.t, &tris[w.prim as usize]) {
        return Err(format!("{got:?} vs {want:?}"));
    }
    let got_ok = got.is_none_or(|g| genuine(g) && g.t >= w.t);
    let far_enough = match (got, closest_inside_box(ray, t_max, tris)) {
        (_, None) => true,
        (None, Some(_)) => false,
        (Some(g), Some(c)) => g.t <= c.t || is_tie(g, c, ray, tris),
    };
    if got_ok && far_enough {
        Ok(Agreement::OracleOutsideBox)
    } else {
        Err(format!(
            "{got:?} vs {want:?} (whose hit lies outside its triangle's box)"
        ))
    }
}

/// `g` is no closer than `w` and farther by less than the rounding of the triangle test.
fn is_tie(g: Hit, w: Hit, ray: &Ray, tris: &[[Vec3; 3]]) -> bool {
    let scale = tris[g.prim as usize]
        .iter()
        .chain(&tris[w.prim as usize])
        .chain([&ray.origin])
        .fold(0.0f32, |m, v| m.max(v.abs().max_element()));
    let gap = (g.t - w.t) * ray.dir.length();
    g.t >= w.t && gap <= TIE_ULPS * f32::EPSILON * scale
}

/// Whether the point at distance `t` along `ray` lies in the bounding box of `tri`, evaluated
/// in double precision so that the check itself does not round.
pub fn inside_box(ray: &Ray, t: f32, tri: &[Vec3; 3]) -> bool {
    let p = ray.origin.as_dvec3() + ray.dir.as_dvec3() * t as f64;
    let lo = tri[0].min(tri[1]).min(tri[2]).as_dvec3();
    let hi = tri[0].max(tri[1]).max(tri[2]).as_dvec3();
    p.cmpge(lo).all() && p.cmple(hi).all()
}

/// The closest hit among those inside their triangle's bounding box.
fn closest_inside_box(ray: &Ray, t_max: f32, tris: &[[Vec3; 3]]) -> Option<Hit> {
    let mut best: Option<Hit> = None;
    for (i, tri) in tris.iter().enumerate() {
        if let Some((t, b1, b2)) = hit_one(ray, tri, t_max) {
            if inside_box(ray, t, tri) && best.is_none_or(|b| t < b.t) {
                best = Some(Hit {
                    t,
                    prim: i as u32,
                    b1,
                    b2,
                });
            }
        }
    }
    best
}

/// How far apart, in ulps of the largest coordinate involved, two tied hit points may be.
pub const TIE_ULPS: f32 = 4.0;

/// An indexed triangle mesh whose triangles share vertices exactly.
pub struct Mesh {
    pub positions: Vec<Vec3>,
    pub faces: Vec<[u32; 3]>,
}

/// Faces around each vertex, and the faces of each undirected edge `(low, high)`, sorted by
/// edge.
pub type Adjacency = (Vec<Vec<usize>>, Vec<((u32, u32), Vec<usize>)>);

impl Mesh {
    /// See [`Adjacency`].
    pub fn adjacency(&self) -> Adjacency {
        let mut vertex_faces: Vec<Vec<usize>> = vec![Vec::new(); self.positions.len()];
        let mut edge_faces: std::collections::HashMap<(u32, u32), Vec<usize>> =
            std::collections::HashMap::new();
        for (fi, f) in self.faces.iter().enumerate() {
            for k in 0..3 {
                vertex_faces[f[k] as usize].push(fi);
                let (a, b) = (f[k], f[(k + 1) % 3]);
                edge_faces.entry((a.min(b), a.max(b))).or_default().push(fi);
            }
        }
        let mut edges: Vec<_> = edge_faces.into_iter().collect();
        edges.sort_unstable_by_key(|e| e.0);
        (vertex_faces, edges)
    }

    pub fn triangles(&self) -> Vec<[Vec3; 3]> {
        self.faces
            .iter()
            .map(|f| f.map(|i| self.positions[i as usize]))
            .collect()
    }

    /// Panics unless every directed edge appears once and its reverse once: closed, manifold and
    /// consistently oriented.
    pub fn assert_closed(&self) {
        let mut edges = std::collections::HashMap::new();
        for f in &self.faces {
            for k in 0..3 {
                *edges.entry((f[k], f[(k + 1) % 3])).or_insert(0u32) += 1;
            }
        }
        for (&(a, b), &n) in &edges {
            assert_eq!(n, 1, "edge {a}-{b} used {n} times");
            assert_eq!(edges.get(&(b, a)), Some(&1), "edge {a}-{b} has no twin");
        }
    }

    pub fn transformed(mut self, mut f: impl FnMut(Vec3) -> Vec3) -> Self {
        for p in &mut self.positions {
            *p = f(*p);
        }
        self
    }
}

/// Subdivided icosahedron on the unit sphere, outward-facing.
pub fn icosphere(subdivisions: u32) -> Mesh {
    let m = rt_core::shapes::icosphere(subdivisions);
    Mesh {
        positions: m.positions,
        faces: m.faces,
    }
}

/// The cube [-1, 1]^3 with every face split into an `n` x `n` grid of quads, two triangles each,
/// vertices shared along face borders; outward-facing.
pub fn grid_cube(n: u32) -> Mesh {
    let mut index = std::collections::HashMap::new();
    let mut positions = Vec::new();
    let mut vertex = |p: [i32; 3]| -> u32 {
        *index.entry(p).or_insert_with(|| {
            positions
                .push(Vec3::new(p[0] as f32, p[1] as f32, p[2] as f32) * (2.0 / n as f32) - 1.0);
            positions.len() as u32 - 1
        })
    };
    let n = n as i32;
    let mut faces = Vec::new();
    for axis in 0..3 {
        for side in [0, n] {
            let (u, v) = ((axis + 1) % 3, (axis + 2) % 3);
            for i in 0..n {
                for j in 0..n {
                    let corner = |di: i32, dj: i32| {
                        let mut p = [0; 3];
                        p[axis] = side;
                        p[u] = i + di;
                        p[v] = j + dj;
                        p
                    };
                    let q =
                        [corner(0, 0), corner(1, 0), corner(1, 1), corner(0, 1)].map(&mut vertex);
                    // (u, v, axis) is right-handed, so counter-clockwise in (u, v) faces +axis.
                    let tris = [[q[0], q[1], q[2]], [q[0], q[2], q[3]]];
                    for t in tris {
                        faces.push(if side == n { t } else { [t[0], t[2], t[1]] });
                    }
                }
            }
        }
    }
    Mesh { positions, faces }
}

/// A torus around the z axis, `n` x `m` quads, outward-facing, seam vertices shared.
pub fn torus(n: u32, m: u32, big_r: f32, small_r: f32) -> Mesh {
    let mut positions = Vec::new();
    for i in 0..n {
        let phi = i as f32 / n as f32 * std::f32::consts::TAU;
        for j in 0..m {
            let theta = j as f32 / m as f32 * std::f32::consts::TAU;
            let r = big_r + small_r * theta.cos();
            positions.push(Vec3::new(
                r * phi.cos(),
                r * phi.sin(),
                small_r * theta.sin(),
            ));
        }
    }
    let id = |i: u32, j: u32| (i % n) * m + (j % m);
    let mut faces = Vec::new();
    for i in 0..n {
        for j in 0..m {
            let q = [id(i, j), id(i + 1, j), id(i + 1, j + 1), id(i, j + 1)];
            faces.push([q[0], q[1], q[2]]);
            faces.push([q[0], q[2], q[3]]);
        }
    }
    Mesh { positions, faces }
}

/// A random rotation.
pub fn rotation(rng: &mut Rng) -> Quat {
    Quat::from_axis_angle(rng.unit_vec(), rng.range(0.0, std::f32::consts::TAU))
}

/// What the soup checks need of a built structure besides `Accel`.
pub trait Built: Accel {
    fn build(tris: &[[Vec3; 3]], params: &BuildParams) -> Self;
    fn validate(&self) -> Result<(), rt_accel::ValidationError>;
    /// Every (triangle, caller index) reference in the leaves.
    fn references(&self) -> Vec<([Vec3; 3], u32)>;
}

impl Built for Bvh2 {
    fn build(tris: &[[Vec3; 3]], params: &BuildParams) -> Self {
        Bvh2::build(tris, params)
    }
    fn validate(&self) -> Result<(), rt_accel::ValidationError> {
        Bvh2::validate(self)
    }
    fn references(&self) -> Vec<([Vec3; 3], u32)> {
        self.triangles()
            .iter()
            .copied()
            .zip(self.prim_ids().iter().copied())
            .collect()
    }
}

impl<N: WideNode> Built for WideBvh<N> {
    fn build(tris: &[[Vec3; 3]], params: &BuildParams) -> Self {
        WideBvh::build(tris, params)
    }
    fn validate(&self) -> Result<(), rt_accel::ValidationError> {
        WideBvh::validate(self)
    }
    fn references(&self) -> Vec<([Vec3; 3], u32)> {
        self.nodes()
            .iter()
            .flat_map(|n| (0..N::WIDTH).map(move |s| n.child(s)))
            .filter_map(|c| match c {
                QChild::Leaf(slots) => Some(slots),
                _ => None,
            })
            .flatten()
            .map(|s| self.reference(s))
            .collect()
    }
}

/// Builds structure `A` over a random soup and checks `n_rays` rays against brute force;
/// returns the number of hits so callers can make sure the rays were not all misses.
pub fn check_soup<A: Built>(
    seed: u64,
    n_tris: usize,
    n_rays: usize,
    params: &BuildParams,
) -> usize {
    let mut rng = Rng::new(seed);
    let tris = soup(&mut rng, n_tris);
    let accel = A::build(&tris, params);
    accel
        .validate()
        .unwrap_or_else(|e| panic!("{} seed {seed}, {n_tris} tris: {e}", accel.name()));
    let refs = accel.references();
    let mut seen = vec![false; tris.len()];
    for (tri, id) in refs {
        assert_eq!(tri, tris[id as usize]);
        seen[id as usize] = true;
    }
    assert!(seen.iter().all(|&s| s), "a triangle is in no leaf");
    let oracle = BruteForce::new(&tris);
    let mut hits = 0;
    let mut outside_box = 0;
    for (i, (ray, t_max)) in rays(&mut rng, &tris, n_rays).into_iter().enumerate() {
        match check_ray(&accel, &oracle, &ray, t_max, &tris) {
            Ok(Agreement::OracleOutsideBox) => outside_box += 1,
            Ok(_) => {}
            Err(e) => panic!(
                "{} seed {seed}, {n_tris} tris, ray {i} {ray:?} t_max {t_max}: {e}",
                accel.name()
            ),
        }
        let got = accel.intersect(&ray, t_max);
        let mut counters = TraversalCounters::default();
        assert_eq!(accel.closest_hit(&ray, t_max, Some(&mut counters)), got);
        assert!(counters.nodes_visited >= 1);
        if got.is_some() {
            assert!(counters.prims_tested >= 1);
        }
        hits += usize::from(got.is_some());
    }
    // The oracle's nearly-degenerate-triangle artefacts are rare; many would mean the soup or
    // the comparison is broken.
    assert!(
        outside_box * 1000 <= n_rays,
        "{outside_box} of {n_rays} rays"
    );
    hits
}

// The on-demand QBVH (`tests/on_demand.rs`): its references are its groups' triangles, and
// `validate` checks the top tree and the groups built so far.
impl Built for rt_accel::OnDemandQbvh {
    fn build(tris: &[[Vec3; 3]], params: &BuildParams) -> Self {
        rt_accel::OnDemandQbvh::new(tris, params, &rt_accel::WideOptions::default())
    }
    fn validate(&self) -> Result<(), rt_accel::ValidationError> {
        rt_accel::OnDemandQbvh::validate(self)
    }
    fn references(&self) -> Vec<([Vec3; 3], u32)> {
        self.group_order()
            .iter()
            .map(|&i| (self.triangles()[i as usize], i))
            .collect()
    }
}

/// Long thin triangles in random directions, none in an axis plane: the boxes of such
/// triangles are mostly empty, which is what triangle splitting is for. A fifth of them lie
/// along the main diagonal, rotated 45 degrees from every axis plane, and some share edges.
pub fn thin_diagonal_soup(rng: &mut Rng, n: usize) -> Vec<[Vec3; 3]> {
    let diagonal = Vec3::ONE.normalize();
    let mut tris: Vec<[Vec3; 3]> = Vec::with_capacity(n);
    while tris.len() < n {
        let dir = if rng.chance(0.2) {
            diagonal
        } else {
            rng.unit_vec()
        };
        let a = rng.vec_in(-1.0, 1.0);
        let b = a + dir * rng.range(0.3, 2.5);
        let across = dir.cross(rng.unit_vec()).normalize_or(Vec3::X);
        let c = a.lerp(b, rng.f32()) + across * 10f32.powf(rng.range(-3.0, -1.0));
        tris.push([a, b, c]);
        if rng.chance(0.2) && tris.len() < n {
            // A neighbour across the long edge.
            tris.push([b, a, a.lerp(b, rng.f32()) - across * rng.range(0.001, 0.1)]);
        }
    }
    tris
}

/// Checks `accel` against brute force over `tris` for every ray with [`check_ray`], panicking
/// with `label` on a disagreement; returns the number of hits.
pub fn check_rays(
    accel: &dyn Accel,
    tris: &[[Vec3; 3]],
    rays: &[(Ray, f32)],
    label: &str,
) -> usize {
    let oracle = BruteForce::new(tris);
    let mut hits = 0;
    for (i, (ray, t_max)) in rays.iter().enumerate() {
        if let Err(e) = check_ray(accel, &oracle, ray, *t_max, tris) {
            panic!("{label}: ray {i} {ray:?} t_max {t_max}: {e}");
        }
        hits += usize::from(accel.intersect(ray, *t_max).is_some());
    }
    hits
}

/// `n` rays from outside a closed `mesh` aimed exactly at its vertices, edge midpoints and
/// random points on edges, from within 30 degrees of the mean normal there and crossing every
/// triangle around the target at more than 5 degrees (see `watertight.rs`); each must hit at
/// `t <= 1`, up to rounding.
pub fn rays_at_edges_and_vertices(mesh: &Mesh, rng: &mut Rng, n: usize) -> Vec<Ray> {
    let unit_normal: Vec<Vec3> = mesh
        .triangles()
        .iter()
        .map(|t| rt_core::triangle::geometric_normal(t).normalize())
        .collect();
    let (vertex_faces, edges) = mesh.adjacency();
    let radius = rt_core::Aabb::from_points(&mesh.positions).bounding_radius();
    let min_sin = 5f32.to_radians().sin();
    let mut out = Vec::with_capacity(n);
    while out.len() < n {
        let (point, faces) = match rng.below(3) {
            0 => {
                let v = rng.below(mesh.positions.len());
                (mesh.positions[v], &vertex_faces[v])
            }
            k => {
                let ((a, b), faces) = &edges[rng.below(edges.len())];
                let (a, b) = (mesh.positions[*a as usize], mesh.positions[*b as usize]);
                let s = if k == 1 { 0.5 } else { rng.f32() };
                (a + (b - a) * s, faces)
            }
        };
        let normal = faces
            .iter()
            .map(|&f| unit_normal[f])
            .sum::<Vec3>()
            .normalize();
        let d = (normal + rng.unit_vec() * 0.5).normalize();
        if faces.iter().all(|&f| unit_normal[f].dot(d) > min_sin) {
            let origin = point + d * radius * rng.range(2.0, 6.0);
            out.push(Ray::new(origin, point - origin));
        }
    }
    out
}

/// A mesh of `../shared/data` (a visible skip when absent, a
/// failure under `RT_REQUIRE_DATA=1`).
#[allow(unused_imports)] // only real_meshes.rs reads shared meshes
pub use rt_testkit::obj::shared_mesh;
