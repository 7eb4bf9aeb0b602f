//! Procedural benchmark scenes, generated in memory: nothing is read from or written to disk,
//! and the same name always gives bit-identical triangles.
//!
//! They exist to stress acceleration structures in the ways the thesis' chapters 3 and 4 discuss
//! (`render bench-accel gen:NAME`), and each has a camera, a diffuse material, an emissive quad
//! and a dim constant sky, so it also renders (`render gen:NAME -o image.exr`).
//!
//! | name | triangles | what it stresses |
//! |---|---|---|
//! | `worst-case` | 4,100 | the thesis' worst case for axis-aligned boxes: a 64×64 grid of long, thin slivers, all parallel to the scene diagonal, each one's box covering a quarter of the scene |
//! | `rotated` | 97,794 | a tessellated city of boxes on a tessellated ground (axis-aligned triangles, the ideal case for boxes) rotated by 45° about x and then about y, the "rotated Sponza" idea: the same geometry, now with diagonal triangles |
//! | `mixed` | 36,934 | two ground and two backdrop triangles 2·10⁵ wide, grass blades of 10⁻¹, dust clouds of triangles from 10⁻² down to 10⁻⁶ across, far mountains of 10³: sizes over 11 orders of magnitude, coordinates from 10⁻⁴ to 10⁵ |
//! | `million` | 1,002,256 | a closed, displaced cube-sphere of 12·289² triangles on a ground quad |
//! | `car` | 70,114 | animated: 61 rigid parts of a car driving for 2 s (spinning wheels, opening doors, the engine and seats inside the hull), instances of 61 prototypes ([`dynamic`]) |
//! | `furniture` | 223,074 | animated: 123 pieces of furniture (five prototypes) in a static room, chairs sliding and turning, lamps swinging |
//!
//! ```
//! let scene = rt_scene::procedural::generate("worst-case").unwrap();
//! assert_eq!(scene.triangle_count(), 4_100);
//! assert!(!scene.lights().is_empty() && !scene.cameras.is_empty());
//! assert!(rt_scene::procedural::generate("teapot").is_err());
//! ```

use glam::{Vec2, Vec3};
use rt_core::{
    environment::Environment, scene::Object, transform::Transform, Camera, Material, Rgb, Scene,
};

/// Names accepted by [`generate`], in the order of the table above.
pub const NAMES: [&str; 6] = [
    "worst-case",
    "rotated",
    "mixed",
    "million",
    "car",
    "furniture",
];

/// A name that is not one of [`NAMES`].
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
#[error("unknown procedural scene `{0}` (expected one of worst-case, rotated, mixed, million, car, furniture)")]
pub struct UnknownScene(pub String);

/// Generates the scene called `name` (one of [`NAMES`]), ready to render: the light sampler is
/// built and the first camera is 512×512 (or 512×384).
pub fn generate(name: &str) -> Result<Scene, UnknownScene> {
    match name {
        "worst-case" => Ok(worst_case()),
        "rotated" => Ok(rotated()),
        "mixed" => Ok(mixed()),
        "million" => Ok(million()),
        "car" => Ok(dynamic::car()),
        "furniture" => Ok(dynamic::furniture()),
        _ => Err(UnknownScene(name.to_string())),
    }
}

/// The generators' random numbers: rt-core's SplitMix64 started at the seed itself (so the
/// scenes stay what they were when their sizes were specified).
type Rng = rt_core::rng::SplitMix64;

pub mod dynamic;

fn rng(seed: u64) -> Rng {
    Rng::from_state(seed)
}

/// Collects triangles into named objects.
struct Builder {
    scene: Scene,
    object_start: u32,
}

impl Builder {
    fn new() -> Self {
        let mut scene = Scene::empty();
        scene.environment = Environment::Constant(Rgb::splat(0.05));
        Self {
            scene,
            object_start: 0,
        }
    }

    fn material(&mut self, m: Material) -> u32 {
        self.scene.materials.push(m);
        self.scene.materials.len() as u32 - 1
    }

    fn emitter(&mut self, name: &str, radiance: f32) -> u32 {
        let mut m = Material::diffuse(name, Rgb::ZERO);
        m.emission = Rgb::splat(radiance);
        self.material(m)
    }

    fn tri(&mut self, v: [Vec3; 3], m: u32) {
        self.scene.push_triangle(v, m);
    }

    /// Corners counter-clockwise from the front.
    fn quad(&mut self, a: Vec3, b: Vec3, c: Vec3, d: Vec3, m: u32) {
        self.tri([a, b, c], m);
        self.tri([a, c, d], m);
    }

    /// The parallelogram `origin + s·e1 + t·e2`, s, t ∈ [0, 1], as `n1 × n2` quads; the front
    /// is towards `e1 × e2`.
    fn grid(&mut self, origin: Vec3, e1: Vec3, e2: Vec3, n1: u32, n2: u32, m: u32) {
        let p = |i: u32, j: u32| origin + e1 * (i as f32 / n1 as f32) + e2 * (j as f32 / n2 as f32);
        for j in 0..n2 {
            for i in 0..n1 {
                self.quad(p(i, j), p(i + 1, j), p(i + 1, j + 1), p(i, j + 1), m);
            }
        }
    }

    /// Ends the current object: the triangles added since the previous call.
    fn end_object(&mut self, name: &str) {
        let end = self.scene.triangles.len() as u32;
        self.scene.objects.push(Object {
            name: name.to_string(),
            first: self.object_start,
            count: end - self.object_start,
        });
        self.object_start = end;
    }

    fn finish(mut self, camera: Camera) -> Scene {
        self.scene.cameras.push(camera);
        self.scene.compact_attributes();
        self.scene
    }
}

fn camera(position: Vec3, look_at: Vec3, up: Vec3, fov: f32, width: u32, height: u32) -> Camera {
    let focus = (look_at - position).length();
    Camera::look_at(
        "main", position, look_at, up, fov, width, height, 0.0, focus,
    )
}

/// `worst-case`: 64×64 long, thin triangles parallel to the diagonal (1, 1, 1) over a floor.
fn worst_case() -> Scene {
    const G: u32 = 64;
    const S: f32 = 10.0;
    let mut b = Builder::new();
    let grey = b.material(Material::diffuse("grey", Rgb::splat(0.7)));
    let lamp = b.emitter("lamp", 20.0);
    let spacing = S / G as f32;
    // Perpendicular to the diagonal, in the x-z plane: the slivers' width direction.
    let across = Vec3::new(1.0, 0.0, -1.0).normalize();
    for j in 0..G {
        for i in 0..G {
            let v0 = Vec3::new((i as f32 + 0.5) * spacing, 0.0, (j as f32 + 0.5) * spacing);
            let v1 = v0 + Vec3::splat(S);
            // Slightly varying widths, so that no two slivers are exactly alike.
            let w = spacing * (0.3 + 0.2 * ((i * 7 + j * 13) % 11) as f32 / 10.0);
            b.tri([v0, v1, v1 + across * w], grey);
        }
    }
    b.end_object("slivers");
    b.quad(
        Vec3::new(-S, -0.01, 3.0 * S),
        Vec3::new(3.0 * S, -0.01, 3.0 * S),
        Vec3::new(3.0 * S, -0.01, -S),
        Vec3::new(-S, -0.01, -S),
        grey,
    );
    b.end_object("floor");
    let (l0, l1, h) = (0.6 * S, 1.4 * S, 1.6 * S);
    b.quad(
        Vec3::new(l0, h, l0),
        Vec3::new(l1, h, l0),
        Vec3::new(l1, h, l1),
        Vec3::new(l0, h, l1),
        lamp,
    );
    b.end_object("lamp");
    let centre = Vec3::new(S, 0.5 * S, S);
    b.finish(camera(
        centre + Vec3::new(-1.6, 1.0, 2.2) * S,
        centre,
        Vec3::Y,
        45.0,
        512,
        512,
    ))
}

/// `rotated`: a 20×20 city of tessellated boxes on a tessellated ground, rotated 45° about x and
/// then 45° about y, with the camera and the lamp rotated along.
fn rotated() -> Scene {
    const CELLS: u32 = 20;
    const W: f32 = 50.0;
    let mut b = Builder::new();
    let ground = b.material(Material::diffuse("ground", Rgb::new(0.5, 0.5, 0.45)));
    let wall = b.material(Material::diffuse("wall", Rgb::new(0.75, 0.7, 0.65)));
    let lamp = b.emitter("lamp", 30.0);
    b.grid(
        Vec3::new(-W, 0.0, W),
        Vec3::new(2.0 * W, 0.0, 0.0),
        Vec3::new(0.0, 0.0, -2.0 * W),
        64,
        64,
        ground,
    );
    b.end_object("ground");
    let mut rng = rng(0x5eed_0002);
    let cell = 2.0 * W / CELLS as f32;
    for j in 0..CELLS {
        for i in 0..CELLS {
            let size = Vec2::new(rng.range(0.5, 0.8), rng.range(0.5, 0.8)) * cell;
            let c = Vec2::new(-W + (i as f32 + 0.5) * cell, -W + (j as f32 + 0.5) * cell);
            let h = rng.range(0.5, 4.0) * cell;
            let lo = Vec3::new(c.x - 0.5 * size.x, 0.0, c.y - 0.5 * size.y);
            let (x, y, z) = (Vec3::X * size.x, Vec3::Y * h, Vec3::Z * size.y);
            // Four walls of 4×6 quads and a roof of 4×4, all facing out.
            b.grid(lo + z, x, y, 4, 6, wall); // +z
            b.grid(lo + x, -x, y, 4, 6, wall); // -z
            b.grid(lo, z, y, 4, 6, wall); // -x
            b.grid(lo + x + z, -z, y, 4, 6, wall); // +x
            b.grid(lo + y + z, x, -z, 4, 4, wall); // roof
        }
    }
    b.end_object("city");
    let lh = 6.0 * cell;
    b.quad(
        Vec3::new(-10.0, lh, -10.0),
        Vec3::new(10.0, lh, -10.0),
        Vec3::new(10.0, lh, 10.0),
        Vec3::new(-10.0, lh, 10.0),
        lamp,
    );
    b.end_object("lamp");
    let r = Transform::from_trs(Vec3::ZERO, Vec3::new(45.0, 45.0, 0.0), Vec3::ONE);
    for t in &mut b.scene.triangles {
        *t = t.map(|p| r.point(p));
    }
    b.finish(camera(
        r.point(Vec3::new(-60.0, 45.0, 75.0)),
        r.point(Vec3::new(0.0, 5.0, 0.0)),
        r.normal(Vec3::Y),
        50.0,
        512,
        384,
    ))
}

/// `mixed`: huge ground and backdrop triangles, grass, dust clouds at five scales and far
/// mountains.
fn mixed() -> Scene {
    const HUGE: f32 = 1e5;
    let mut b = Builder::new();
    let grey = b.material(Material::diffuse("grey", Rgb::splat(0.6)));
    let green = b.material(Material::diffuse("green", Rgb::new(0.2, 0.5, 0.15)));
    let dust = b.material(Material::diffuse("dust", Rgb::new(0.8, 0.6, 0.4)));
    let lamp = b.emitter("lamp", 6.0);
    let mut rng = rng(0x5eed_0003);
    // Two ground triangles and two backdrop triangles, 2·10⁵ wide.
    b.quad(
        Vec3::new(-HUGE, 0.0, HUGE),
        Vec3::new(HUGE, 0.0, HUGE),
        Vec3::new(HUGE, 0.0, -HUGE),
        Vec3::new(-HUGE, 0.0, -HUGE),
        grey,
    );
    b.quad(
        Vec3::new(-HUGE, 0.0, -1e4),
        Vec3::new(HUGE, 0.0, -1e4),
        Vec3::new(HUGE, HUGE, -1e4),
        Vec3::new(-HUGE, HUGE, -1e4),
        grey,
    );
    b.end_object("huge");
    // Grass: 128×128 blades 0.1 tall and 0.012 wide on [-4, 4]².
    for j in 0..128 {
        for i in 0..128 {
            let x = -4.0 + (i as f32 + rng.f32()) / 16.0;
            let z = -4.0 + (j as f32 + rng.f32()) / 16.0;
            let a = rng.range(0.0, std::f32::consts::TAU);
            let side = Vec3::new(a.cos(), 0.0, a.sin()) * 0.006;
            let tip = Vec3::new(x + rng.range(-0.02, 0.02), rng.range(0.06, 0.1), z);
            let base = Vec3::new(x, 0.0, z);
            b.tri([base - side, base + side, tip], green);
        }
    }
    b.end_object("grass");
    // Dust: five clouds of 4,096 triangles, cloud k of radius 10^-k with triangles of 1/50 of
    // that; cloud 4 sits near the origin, so its coordinates are about 10^-4.
    for k in 0..5 {
        let radius = 10f32.powi(-k);
        let centre = if k == 4 {
            Vec3::new(2e-4, 3e-4, -1e-4)
        } else {
            Vec3::new(
                -1.5 + 0.9 * k as f32,
                0.6 + 0.2 * k as f32,
                0.5 - 0.3 * k as f32,
            )
        };
        let size = radius / 50.0;
        for _ in 0..4096 {
            let p = centre + rng.cube() * radius;
            let (u, v) = (rng.unit_vec() * size, rng.unit_vec() * size);
            b.tri([p, p + u, p + v], dust);
        }
    }
    b.end_object("dust");
    // Mountains: 64 triangles of about 10³, between 2·10³ and 8·10³ away.
    for i in 0..64 {
        let a = -1.2 + 2.4 * i as f32 / 64.0;
        let d = rng.range(2e3, 8e3);
        let dir = Vec3::new(a.sin(), 0.0, -a.cos());
        let side = Vec3::new(dir.z, 0.0, -dir.x) * rng.range(5e2, 1.5e3);
        let base = dir * d;
        let peak = base + Vec3::Y * rng.range(3e2, 1.5e3);
        b.tri([base + side, base - side, peak], grey);
    }
    b.end_object("mountains");
    b.quad(
        Vec3::new(-2.0, 8.0, -2.0),
        Vec3::new(2.0, 8.0, -2.0),
        Vec3::new(2.0, 8.0, 2.0),
        Vec3::new(-2.0, 8.0, 2.0),
        lamp,
    );
    b.end_object("lamp");
    b.finish(camera(
        Vec3::new(0.3, 1.2, 4.5),
        Vec3::new(-0.2, 0.4, 0.0),
        Vec3::Y,
        50.0,
        512,
        384,
    ))
}

/// `million`: a cube-sphere of 6·289² quads, its vertices pushed onto a bumpy sphere.
fn million() -> Scene {
    const N: u32 = 289;
    let mut b = Builder::new();
    let clay = b.material(Material::diffuse("clay", Rgb::new(0.7, 0.6, 0.5)));
    let lamp = b.emitter("lamp", 20.0);
    let bump = |d: Vec3| -> Vec3 {
        let r = 1.0
            + 0.04 * (9.0 * d.x).sin() * (11.0 * d.y).sin() * (13.0 * d.z).sin()
            + 0.01 * (41.0 * d.x + 3.0 * d.z).sin() * (37.0 * d.y).sin();
        d * r + Vec3::Y * 1.1
    };
    // Each face of the cube [-1, 1]³ as origin + s·e1 + t·e2 with e1 × e2 pointing out.
    let faces = [
        (Vec3::new(1.0, -1.0, 1.0), -Vec3::Z, Vec3::Y),
        (Vec3::new(-1.0, -1.0, -1.0), Vec3::Z, Vec3::Y),
        (Vec3::new(-1.0, 1.0, 1.0), Vec3::X, -Vec3::Z),
        (Vec3::new(-1.0, -1.0, -1.0), Vec3::X, Vec3::Z),
        (Vec3::new(-1.0, -1.0, 1.0), Vec3::X, Vec3::Y),
        (Vec3::new(1.0, -1.0, -1.0), -Vec3::X, Vec3::Y),
    ];
    for (origin, e1, e2) in faces {
        let p = |i: u32, j: u32| {
            let c = origin + e1 * (2.0 * i as f32 / N as f32) + e2 * (2.0 * j as f32 / N as f32);
            bump(c.normalize())
        };
        for j in 0..N {
            for i in 0..N {
                b.quad(p(i, j), p(i + 1, j), p(i + 1, j + 1), p(i, j + 1), clay);
            }
        }
    }
    b.end_object("sphere");
    b.quad(
        Vec3::new(-6.0, 0.0, 6.0),
        Vec3::new(6.0, 0.0, 6.0),
        Vec3::new(6.0, 0.0, -6.0),
        Vec3::new(-6.0, 0.0, -6.0),
        clay,
    );
    b.end_object("floor");
    b.quad(
        Vec3::new(-1.0, 5.0, -1.0),
        Vec3::new(1.0, 5.0, -1.0),
        Vec3::new(1.0, 5.0, 1.0),
        Vec3::new(-1.0, 5.0, 1.0),
        lamp,
    );
    b.end_object("lamp");
    b.finish(camera(
        Vec3::new(2.2, 2.6, 3.4),
        Vec3::new(0.0, 1.1, 0.0),
        Vec3::Y,
        40.0,
        512,
        512,
    ))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Generates `name` and checks its arrays. `triangles` is the count the module's table
    /// documents: a specification, not a measurement, because the `gen:` scenes are benchmark
    /// inputs whose sizes `docs/benchmarks.md` reports results for, so a generator that changes
    /// them must change the table (and invalidate those results) deliberately.
    fn check(name: &str, triangles: usize) -> Scene {
        let scene = generate(name).unwrap();
        assert_eq!(scene.triangle_count(), triangles, "{name}");
        assert_eq!(scene.material_ids.len(), triangles);
        // Per-triangle normals, or none at all after compaction.
        assert!(scene.normals.is_empty() || scene.normals.len() == triangles);
        assert!(scene
            .material_ids
            .iter()
            .all(|&m| (m as usize) < scene.materials.len()));
        for (i, t) in scene.triangles.iter().enumerate() {
            assert!(
                t.iter().all(|v| v.is_finite()),
                "{name}: triangle {i}: {t:?}"
            );
            let area = rt_core::triangle::area(t);
            assert!(area > 0.0, "{name}: triangle {i} has zero area: {t:?}");
        }
        let covered: u32 = scene.objects.iter().map(|o| o.count).sum();
        assert_eq!(covered as usize, triangles);
        assert!(scene.lights().emitter_count() > 0, "{name}: no lights");
        assert_eq!(scene.cameras.len(), 1);
        for m in &scene.materials {
            m.validate().unwrap();
        }
        // Deterministic: a second call gives the same bits.
        let again = generate(name).unwrap();
        assert!(
            scene.triangles == again.triangles,
            "{name} is not deterministic"
        );
        assert_eq!(scene.material_ids, again.material_ids);
        // The camera sees the geometry's centre region.
        let cam = &scene.cameras[0];
        assert!(cam.position.is_finite() && cam.forward.is_finite());
        scene
    }

    #[test]
    fn worst_case() {
        let s = check("worst-case", 64 * 64 + 4);
        // Every sliver's box spans the whole height of the scene.
        for t in &s.triangles[..64 * 64] {
            let (lo, hi) = (t[0].min(t[1]).min(t[2]), t[0].max(t[1]).max(t[2]));
            assert!((hi - lo).min_element() >= 10.0 - 1e-3, "{t:?}");
        }
    }

    #[test]
    fn rotated() {
        let s = check("rotated", 97_794);
        // Rotated: no triangle of the city is axis-aligned any more.
        let aligned = s.triangles[..97_792]
            .iter()
            .filter(|t| {
                let n = rt_core::triangle::geometric_normal(t).normalize().abs();
                n.max_element() > 0.999
            })
            .count();
        assert_eq!(aligned, 0);
    }

    #[test]
    fn mixed() {
        let s = check("mixed", 36_934);
        let sizes: Vec<f32> = s
            .triangles
            .iter()
            .map(|t| (t[1] - t[0]).length().max((t[2] - t[0]).length()))
            .collect();
        let (lo, hi) = sizes
            .iter()
            .fold((f32::MAX, 0.0f32), |(lo, hi), &x| (lo.min(x), hi.max(x)));
        assert!(hi / lo > 1e10, "sizes {lo} to {hi}");
        let coords = s.triangles.iter().flatten().map(|v| v.abs().max_element());
        let (clo, chi) = coords.fold((f32::MAX, 0.0f32), |(lo, hi), x| (lo.min(x), hi.max(x)));
        assert!(chi / clo > 1e6, "coordinates {clo} to {chi}");
    }

    #[test]
    fn million() {
        let s = check("million", 12 * 289 * 289 + 4);
        assert!(s.triangle_count() >= 1_000_000);
    }

    #[test]
    fn dynamic_scenes_move_and_stay_finite() {
        for (name, parts, triangles) in [("car", 61, 70_114), ("furniture", 123, 223_074)] {
            let mut s = check(name, triangles);
            assert_eq!(s.instances.len(), parts, "{name}");
            assert!(s.instances.iter().any(|i| i.is_animated()), "{name}");
            let before = s.triangles.clone();
            let moved = s.set_time(1.0);
            assert!(!moved.is_empty(), "{name}: nothing moved");
            assert!(s.triangles.iter().flatten().all(|v| v.is_finite()));
            assert_ne!(s.triangles, before);
        }
    }

    #[test]
    fn unknown_name() {
        let e = generate("sponza").unwrap_err();
        assert!(e.to_string().contains("sponza") && e.to_string().contains("worst-case"));
        assert_eq!(NAMES.len(), 6);
        for n in NAMES {
            assert!(e.to_string().contains(n));
        }
    }
}
