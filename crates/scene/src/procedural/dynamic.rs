//! The animated procedural scenes of the rigid-body benchmarks (Dammertz §4.5, Figs. 4.16 and
//! 4.17; seed 002's small dynamic scenes): every part a prototype placed by an instance with
//! keyframed motion, so `two-level` and `clusters` follow them frame by frame.
//!
//! - `car`: 61 rigid parts, like the thesis' car: a hull (an ellipsoid shell) with the engine,
//!   four seats, a dashboard and a steering wheel inside it (overlapping boxes, the case
//!   per-object instancing handles badly), four spinning wheels, two opening doors, bumpers,
//!   lights, mirrors, axles and exhausts. The car drives 4 units along x in 2 s.
//! - `furniture`: 123 pieces in a room (like the thesis' interior): 20 tables, 80 chairs, 10
//!   shelves, 8 lamps and 5 sofas, instances of five prototypes; the chairs slide and turn, the
//!   lamps swing, the room is static.

use super::{camera, Builder};
use glam::Vec3;
use rt_core::animation::{Key, Motion};
use rt_core::instance::Prototype;
use rt_core::shapes::icosphere;
use rt_core::transform::Transform;
use rt_core::{Material, Rgb, Scene};

/// Triangles of a box, each face an `n × n` grid (front faces outward).
fn tessellated_box(min: Vec3, max: Vec3, n: u32) -> Vec<[Vec3; 3]> {
    let mut out = Vec::new();
    let e = max - min;
    let mut face = |o: Vec3, e1: Vec3, e2: Vec3| {
        let p = |i: u32, j: u32| o + e1 * (i as f32 / n as f32) + e2 * (j as f32 / n as f32);
        for j in 0..n {
            for i in 0..n {
                let (a, b, c, d) = (p(i, j), p(i + 1, j), p(i + 1, j + 1), p(i, j + 1));
                out.push([a, b, c]);
                out.push([a, c, d]);
            }
        }
    };
    let (x, y, z) = (Vec3::X * e.x, Vec3::Y * e.y, Vec3::Z * e.z);
    face(min, y, x); // -z
    face(min + z, x, y); // +z
    face(min, z, y); // -x
    face(min + x, y, z); // +x
    face(min, x, z); // -y
    face(min + y, z, x); // +y
    out
}

/// An icosphere of `subdivisions` scaled per axis about the origin.
fn ellipsoid(scale: Vec3, subdivisions: u32) -> Vec<[Vec3; 3]> {
    let m = icosphere(subdivisions);
    m.faces
        .iter()
        .map(|f| f.map(|i| m.positions[i as usize] * scale))
        .collect()
}

/// Adds a prototype of one material.
fn prototype(s: &mut Scene, name: &str, triangles: Vec<[Vec3; 3]>, material: u32) -> u32 {
    s.add_prototype(Prototype {
        name: name.into(),
        material_ids: vec![material; triangles.len()],
        triangles,
        ..Prototype::default()
    })
}

/// Keys of a rigid motion: `place(t)` gives (translation, rotation in degrees) at the key
/// times `0, step, 2·step, ..., end`.
fn keyed(end: f32, step: f32, place: impl Fn(f32) -> (Vec3, Vec3)) -> Motion {
    let n = (end / step).round() as u32;
    Motion::new(
        (0..=n)
            .map(|k| {
                let t = k as f32 * step;
                let (tr, rot) = place(t);
                Key::from_trs(t, tr, rot, Vec3::ONE)
            })
            .collect(),
    )
    .expect("generated keys increase")
}

fn finish_dynamic(b: Builder, cam: rt_core::Camera) -> Scene {
    let mut s = b.finish(cam);
    s.set_time(0.0);
    s
}

/// `car`: 61 parts driving along x.
pub(super) fn car() -> Scene {
    let mut b = Builder::new();
    let paint = b.material(Material::diffuse("paint", Rgb::new(0.6, 0.1, 0.1)));
    let dark = b.material(Material::diffuse("dark", Rgb::splat(0.08)));
    let grey = b.material(Material::diffuse("grey", Rgb::splat(0.5)));
    let lamp = b.emitter("lamp", 12.0);
    // Static ground and a lamp above.
    b.grid(
        Vec3::new(-6.0, 0.0, 4.0),
        Vec3::new(14.0, 0.0, 0.0),
        Vec3::new(0.0, 0.0, -8.0),
        16,
        16,
        grey,
    );
    b.end_object("ground");
    b.quad(
        Vec3::new(0.0, 5.0, -1.0),
        Vec3::new(2.0, 5.0, -1.0),
        Vec3::new(2.0, 5.0, 1.0),
        Vec3::new(0.0, 5.0, 1.0),
        lamp,
    );
    b.end_object("lamp");
    let s = &mut b.scene;
    // Parts in the car's frame (x forward, y up), each placed by its own offset after the
    // car's motion. (name, triangles, material, offset, spin axis for wheels / door hinge).
    let mut parts: Vec<(String, u32, Vec3, u8)> = Vec::new();
    let mut part =
        |s: &mut Scene, name: String, tris: Vec<[Vec3; 3]>, m: u32, at: Vec3, kind: u8| {
            let p = prototype(s, &name, tris, m);
            parts.push((name, p, at, kind));
        };
    part(
        s,
        "hull".into(),
        ellipsoid(Vec3::new(2.2, 0.75, 1.0), 5),
        paint,
        Vec3::new(0.0, 0.9, 0.0),
        0,
    );
    for (k, (x, z)) in [(1.3, 0.9), (1.3, -0.9), (-1.3, 0.9), (-1.3, -0.9)]
        .iter()
        .enumerate()
    {
        part(
            s,
            format!("wheel{k}"),
            ellipsoid(Vec3::new(0.38, 0.38, 0.13), 4),
            dark,
            Vec3::new(*x, 0.38, *z),
            1,
        );
    }
    for (k, z) in [1.0f32, -1.0].iter().enumerate() {
        // Hinged at the front edge: the prototype's origin is the hinge.
        let door = tessellated_box(Vec3::new(-1.0, -0.3, -0.03), Vec3::new(0.0, 0.35, 0.03), 8);
        part(
            s,
            format!("door{k}"),
            door,
            paint,
            Vec3::new(0.5, 0.9, *z),
            2,
        );
    }
    for k in 0..16 {
        let (i, j) = (k % 4, k / 4);
        let min = Vec3::new(0.9 + 0.2 * i as f32, 0.45 + 0.12 * j as f32, -0.35);
        part(
            s,
            format!("engine{k}"),
            tessellated_box(min, min + Vec3::new(0.18, 0.1, 0.7), 6),
            grey,
            Vec3::ZERO,
            0,
        );
    }
    for seat in 0..4 {
        let (x, z) = (
            if seat < 2 { 0.1 } else { -0.7 },
            if seat % 2 == 0 { 0.4 } else { -0.4 },
        );
        let pieces = [
            (Vec3::new(-0.2, 0.45, -0.2), Vec3::new(0.2, 0.55, 0.2)),
            (Vec3::new(-0.25, 0.55, -0.2), Vec3::new(-0.15, 1.0, 0.2)),
            (Vec3::new(-0.2, 0.3, -0.05), Vec3::new(0.2, 0.45, 0.05)),
            (Vec3::new(-0.27, 1.0, -0.1), Vec3::new(-0.17, 1.15, 0.1)),
        ];
        for (k, (lo, hi)) in pieces.iter().enumerate() {
            let off = Vec3::new(x, 0.0, z);
            part(
                s,
                format!("seat{seat}-{k}"),
                tessellated_box(*lo + off, *hi + off, 6),
                dark,
                Vec3::ZERO,
                0,
            );
        }
    }
    for k in 0..4 {
        let min = Vec3::new(0.45, 0.8 + 0.06 * k as f32, -0.8);
        part(
            s,
            format!("dash{k}"),
            tessellated_box(min, min + Vec3::new(0.15, 0.05, 1.6), 6),
            grey,
            Vec3::ZERO,
            0,
        );
    }
    part(
        s,
        "steering".into(),
        ellipsoid(Vec3::new(0.03, 0.18, 0.18), 3),
        dark,
        Vec3::new(0.35, 1.0, 0.4),
        0,
    );
    for (k, z) in [0.9f32, -0.9].iter().enumerate() {
        part(
            s,
            format!("axle{k}"),
            tessellated_box(
                Vec3::new(-0.05, 0.33, -z.abs()),
                Vec3::new(0.05, 0.43, z.abs()),
                4,
            ),
            dark,
            Vec3::new(1.3 - 2.6 * k as f32, 0.0, 0.0),
            0,
        );
    }
    for k in 0..4 {
        let (x, z) = (
            if k < 2 { 2.1 } else { -2.1 },
            if k % 2 == 0 { 0.6 } else { -0.6 },
        );
        part(
            s,
            format!("light{k}"),
            ellipsoid(Vec3::splat(0.1), 3),
            grey,
            Vec3::new(x, 0.9, z),
            0,
        );
    }
    for (k, x) in [2.2f32, -2.2].iter().enumerate() {
        part(
            s,
            format!("bumper{k}"),
            tessellated_box(Vec3::new(-0.1, 0.4, -1.0), Vec3::new(0.1, 0.6, 1.0), 6),
            dark,
            Vec3::new(*x, 0.0, 0.0),
            0,
        );
    }
    for (k, z) in [1.05f32, -1.05].iter().enumerate() {
        part(
            s,
            format!("mirror{k}"),
            ellipsoid(Vec3::new(0.05, 0.06, 0.1), 3),
            paint,
            Vec3::new(0.6, 1.25, *z),
            0,
        );
    }
    for (k, z) in [0.3f32, -0.3].iter().enumerate() {
        part(
            s,
            format!("exhaust{k}"),
            tessellated_box(Vec3::new(-0.4, 0.3, -0.04), Vec3::new(0.0, 0.38, 0.04), 4),
            grey,
            Vec3::new(-2.1, 0.0, *z),
            0,
        );
    }
    for k in 0..5 {
        let min = Vec3::new(-0.9 + 0.4 * k as f32, 1.68, -0.6);
        part(
            s,
            format!("rack{k}"),
            tessellated_box(min, min + Vec3::new(0.05, 0.05, 1.2), 4),
            grey,
            Vec3::ZERO,
            0,
        );
    }
    debug_assert_eq!(parts.len(), 61);
    // The car drives 4 units along +x in 2 s; wheels turn (keys every 90°, so slerp takes
    // the intended way round); doors open to 60°.
    let drive = |t: f32| Vec3::new(-2.0 + 2.0 * t, 0.0, 0.0);
    for (name, proto, at, kind) in parts {
        let motion = match kind {
            1 => keyed(2.0, 0.125, |t| {
                (drive(t) + at, Vec3::new(0.0, 0.0, -360.0 * t))
            }),
            2 => keyed(2.0, 0.25, |t| {
                (drive(t) + at, Vec3::new(0.0, 30.0 * t, 0.0))
            }),
            _ => keyed(2.0, 1.0, |t| (drive(t) + at, Vec3::ZERO)),
        };
        s.add_instance(name, proto, Transform::default(), Some(motion));
    }
    let cam = camera(
        Vec3::new(3.0, 3.0, 6.0),
        Vec3::new(0.0, 0.8, 0.0),
        Vec3::Y,
        40.0,
        512,
        384,
    );
    finish_dynamic(b, cam)
}

/// `furniture`: 123 pieces in a static room.
pub(super) fn furniture() -> Scene {
    let mut b = Builder::new();
    let wood = b.material(Material::diffuse("wood", Rgb::new(0.5, 0.35, 0.2)));
    let cloth = b.material(Material::diffuse("cloth", Rgb::new(0.2, 0.3, 0.6)));
    let wall = b.material(Material::diffuse("wall", Rgb::splat(0.7)));
    let lamp = b.emitter("lamp", 8.0);
    let (w, h, d) = (20.0f32, 3.0f32, 12.0f32);
    b.grid(
        Vec3::new(0.0, 0.0, d),
        Vec3::new(w, 0.0, 0.0),
        Vec3::new(0.0, 0.0, -d),
        20,
        12,
        wall,
    );
    b.grid(
        Vec3::new(0.0, h, 0.0),
        Vec3::new(w, 0.0, 0.0),
        Vec3::new(0.0, 0.0, d),
        20,
        12,
        wall,
    );
    b.grid(
        Vec3::ZERO,
        Vec3::new(w, 0.0, 0.0),
        Vec3::new(0.0, h, 0.0),
        20,
        3,
        wall,
    );
    b.grid(
        Vec3::new(0.0, 0.0, d),
        Vec3::new(0.0, 0.0, -d),
        Vec3::new(0.0, h, 0.0),
        12,
        3,
        wall,
    );
    b.end_object("room");
    b.quad(
        Vec3::new(8.0, h - 0.01, 4.0),
        Vec3::new(12.0, h - 0.01, 4.0),
        Vec3::new(12.0, h - 0.01, 8.0),
        Vec3::new(8.0, h - 0.01, 8.0),
        lamp,
    );
    b.end_object("ceiling-lamp");
    let s = &mut b.scene;
    let boxes = |list: &[(Vec3, Vec3)], n: u32| -> Vec<[Vec3; 3]> {
        list.iter()
            .flat_map(|(lo, hi)| tessellated_box(*lo, *hi, n))
            .collect()
    };
    let leg = |x: f32, z: f32, top: f32| {
        (
            Vec3::new(x - 0.04, 0.0, z - 0.04),
            Vec3::new(x + 0.04, top, z + 0.04),
        )
    };
    let table = prototype(
        s,
        "table",
        boxes(
            &[
                (Vec3::new(-0.6, 0.72, -0.4), Vec3::new(0.6, 0.76, 0.4)),
                leg(-0.55, -0.35, 0.72),
                leg(0.55, -0.35, 0.72),
                leg(-0.55, 0.35, 0.72),
                leg(0.55, 0.35, 0.72),
            ],
            6,
        ),
        wood,
    );
    let chair = prototype(
        s,
        "chair",
        boxes(
            &[
                (Vec3::new(-0.22, 0.44, -0.22), Vec3::new(0.22, 0.48, 0.22)),
                (Vec3::new(-0.22, 0.48, 0.18), Vec3::new(0.22, 0.95, 0.22)),
                leg(-0.19, -0.19, 0.44),
                leg(0.19, -0.19, 0.44),
                leg(-0.19, 0.19, 0.44),
                leg(0.19, 0.19, 0.44),
            ],
            4,
        ),
        wood,
    );
    let shelf = prototype(
        s,
        "shelf",
        boxes(
            &[
                (Vec3::new(-0.5, 0.0, -0.2), Vec3::new(-0.47, 2.0, 0.2)),
                (Vec3::new(0.47, 0.0, -0.2), Vec3::new(0.5, 2.0, 0.2)),
                (Vec3::new(-0.47, 0.3, -0.2), Vec3::new(0.47, 0.33, 0.2)),
                (Vec3::new(-0.47, 0.9, -0.2), Vec3::new(0.47, 0.93, 0.2)),
                (Vec3::new(-0.47, 1.5, -0.2), Vec3::new(0.47, 1.53, 0.2)),
            ],
            6,
        ),
        wood,
    );
    let lamp_shade = prototype(s, "lamp", ellipsoid(Vec3::new(0.25, 0.2, 0.25), 4), cloth);
    let sofa = prototype(
        s,
        "sofa",
        boxes(
            &[
                (Vec3::new(-1.0, 0.0, -0.45), Vec3::new(1.0, 0.45, 0.45)),
                (Vec3::new(-1.0, 0.45, 0.3), Vec3::new(1.0, 0.9, 0.45)),
                (Vec3::new(-1.0, 0.45, -0.45), Vec3::new(-0.85, 0.65, 0.3)),
                (Vec3::new(0.85, 0.45, -0.45), Vec3::new(1.0, 0.65, 0.3)),
            ],
            10,
        ),
        cloth,
    );
    let fixed = |at: Vec3, yaw: f32| keyed(2.0, 2.0, move |_| (at, Vec3::new(0.0, yaw, 0.0)));
    let mut n = 0;
    // 20 tables in a 5 × 4 grid, four chairs each (80), sliding out and turning.
    for j in 0..4 {
        for i in 0..5 {
            let c = Vec3::new(2.5 + 3.2 * i as f32, 0.0, 2.0 + 2.4 * j as f32);
            s.add_instance(
                format!("table{n}"),
                table,
                Transform::default(),
                Some(fixed(c, 0.0)),
            );
            for (k, (dx, dz, yaw)) in [
                (0.0, 0.7, 180.0f32),
                (0.0, -0.7, 0.0),
                (0.9, 0.0, 90.0),
                (-0.9, 0.0, -90.0),
            ]
            .iter()
            .enumerate()
            {
                let (dx, dz, yaw) = (*dx, *dz, *yaw);
                let phase = (n * 4 + k) as f32 * 0.37;
                let motion = keyed(2.0, 0.25, move |t| {
                    let out = 0.25 * (1.0 - (std::f32::consts::PI * t + phase).cos());
                    let dir = Vec3::new(dx, 0.0, dz).normalize_or_zero();
                    (
                        c + Vec3::new(dx, 0.0, dz) + dir * out,
                        Vec3::new(0.0, yaw + 20.0 * t, 0.0),
                    )
                });
                s.add_instance(
                    format!("chair{n}-{k}"),
                    chair,
                    Transform::default(),
                    Some(motion),
                );
            }
            n += 1;
        }
    }
    for k in 0..10 {
        let at = Vec3::new(1.0 + 2.0 * k as f32, 0.0, 0.3);
        s.add_instance(
            format!("shelf{k}"),
            shelf,
            Transform::default(),
            Some(fixed(at, 0.0)),
        );
    }
    for k in 0..8 {
        let at = Vec3::new(2.0 + 2.3 * k as f32, 2.3, 10.5);
        let phase = k as f32;
        let motion = keyed(2.0, 0.25, move |t| {
            (at, Vec3::new(15.0 * (3.0 * t + phase).sin(), 0.0, 0.0))
        });
        s.add_instance(
            format!("lamp{k}"),
            lamp_shade,
            Transform::default(),
            Some(motion),
        );
    }
    for k in 0..5 {
        let at = Vec3::new(3.0 + 3.5 * k as f32, 0.0, 11.3);
        s.add_instance(
            format!("sofa{k}"),
            sofa,
            Transform::default(),
            Some(fixed(at, 180.0)),
        );
    }
    debug_assert_eq!(s.instances.len(), 123);
    let cam = camera(
        Vec3::new(1.0, 2.2, 11.0),
        Vec3::new(10.0, 0.6, 4.0),
        Vec3::Y,
        60.0,
        512,
        384,
    );
    finish_dynamic(b, cam)
}
