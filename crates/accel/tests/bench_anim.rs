//! `rt_accel::bench::anim` on a tiny animated scene: every contender (flat rebuild, two-level
//! rebuilt and refitted, clusters) passes the per-frame check and gets a time for every
//! frame, and a structure that claims to follow the animation but does not is caught by the
//! check instead of being timed.

mod common;

use glam::Vec3;
use rt_accel::bench::anim::{self, AnimError, AnimOptions, Contender, Follow, Workload};
use rt_accel::AccelSpec;
use rt_core::animation::{Key, Motion};
use rt_core::instance::Prototype;
use rt_core::transform::Transform;
use rt_core::{Aabb, Accel, Camera, Hit, Ray, Scene, TraversalCounters};

/// A floor and four spheres that cross the camera's view in one second.
fn scene() -> Scene {
    let mut s = Scene::empty();
    s.materials
        .push(rt_core::Material::diffuse("m", rt_core::Rgb::ONE));
    let (a, b, c, d) = (
        Vec3::new(-4.0, 0.0, -4.0),
        Vec3::new(4.0, 0.0, -4.0),
        Vec3::new(4.0, 0.0, 4.0),
        Vec3::new(-4.0, 0.0, 4.0),
    );
    s.push_triangle([a, c, b], 0);
    s.push_triangle([a, d, c], 0);
    let sphere = common::icosphere(2).triangles();
    let p = s.add_prototype(Prototype {
        name: "sphere".into(),
        material_ids: vec![0; sphere.len()],
        triangles: sphere,
        ..Prototype::default()
    });
    for k in 0..4 {
        let start = Vec3::new(-2.5 + 1.6 * k as f32, 1.0, 0.0);
        let motion = Motion::new(vec![
            Key::from_trs(0.0, Vec3::ZERO, Vec3::ZERO, Vec3::ONE),
            Key::from_trs(
                1.0,
                Vec3::new(0.0, 0.0, 2.5),
                Vec3::new(0.0, 90.0, 0.0),
                Vec3::ONE,
            ),
        ])
        .unwrap();
        s.add_instance(
            format!("s{k}"),
            p,
            Transform::from_mat4(glam::Mat4::from_scale_rotation_translation(
                Vec3::splat(0.7),
                glam::Quat::IDENTITY,
                start,
            )),
            Some(motion),
        );
    }
    s.cameras.push(Camera::look_at(
        "main",
        Vec3::new(0.0, 3.0, 8.0),
        Vec3::new(0.0, 0.5, 0.0),
        Vec3::Y,
        45.0,
        32,
        20,
        0.0,
        1.0,
    ));
    s
}

fn options() -> AnimOptions {
    AnimOptions {
        frames: 0..4,
        fps: 4.0,
        camera: 0,
        width: 24,
        height: 16,
        seed: 3,
        check: 10_000,
        repeat: 2,
        count: true,
        workload: Workload::Full,
    }
}

fn pool() -> rayon::ThreadPool {
    rayon::ThreadPoolBuilder::new()
        .num_threads(1)
        .build()
        .unwrap()
}

fn contenders(scene: &Scene, specs: &[&str]) -> Vec<Contender> {
    specs
        .iter()
        .map(|s| Contender::build(&s.parse::<AccelSpec>().unwrap(), scene).unwrap())
        .collect()
}

#[test]
fn every_contender_is_checked_and_timed_on_every_frame() {
    let mut s = scene();
    let specs = [
        "bvh8",
        "two-level",
        "two-level:top=refit",
        "clusters:t=1",
        "clusters",
        "clusters:t=64",
    ];
    let mut cs = contenders(&s, &specs);
    assert_eq!(cs[0].follow, Follow::Rebuild(AccelSpec::default()));
    assert_eq!(cs[4].name, "clusters:t=8", "t is always written out");
    // Four instances and the static floor; clustering cuts them into more entries.
    assert_eq!(cs[1].entries, Some(5));
    assert!(cs[5].entries.unwrap() > cs[3].entries.unwrap());
    let mut lines = Vec::new();
    let report = anim::run(&mut s, &mut cs, &options(), &pool(), &mut |l| {
        lines.push(l.to_string())
    })
    .unwrap();
    assert_eq!(lines.len(), 4, "one progress line per frame: {lines:?}");
    assert_eq!(report.rays.len(), 4);
    assert!(report
        .rays
        .iter()
        .all(|r| r.primary == 24 * 16 && r.shadow > 0));
    assert_eq!(report.contenders.len(), specs.len());
    for c in &report.contenders {
        let frames: Vec<u32> = c.frames.iter().map(|f| f.frame).collect();
        assert_eq!(frames, [0, 1, 2, 3], "{}", c.name);
        assert!(
            c.frames.iter().all(|f| f.update > 0.0 && f.trace > 0.0),
            "{}",
            c.name
        );
        assert!(c.total() > c.trace(), "{}", c.name);
        if c.name != "bvh8" {
            assert_eq!(c.check.mismatches, 0, "{}: {:?}", c.name, c.check.examples);
            assert!(c.check.checked >= 4 * 24 * 16, "{}", c.name);
        }
    }
    // Every contender counts its work (two-level kinds through their object BVHs).
    let counted: Vec<_> = report
        .contenders
        .iter()
        .map(|c| c.counters().unwrap())
        .collect();
    assert!(counted.iter().all(|c| c.prims_tested > 0));
    // Every contender traced the same rays and found the same hits.
    let hits: Vec<u64> = report.contenders.iter().map(|c| c.frames[2].hits).collect();
    assert!(hits.iter().all(|&h| h == hits[0]), "{hits:?}");
}

/// Says it follows the animation, keeps the frame it was built at.
struct Stale(Box<dyn Accel>);

impl Accel for Stale {
    fn name(&self) -> &str {
        "stale"
    }
    fn closest_hit(&self, r: &Ray, t: f32, c: Option<&mut TraversalCounters>) -> Option<Hit> {
        self.0.closest_hit(r, t, c)
    }
    fn any_hit(
        &self,
        r: &Ray,
        t: f32,
        to: Option<Vec3>,
        c: Option<&mut TraversalCounters>,
    ) -> bool {
        self.0.any_hit(r, t, to, c)
    }
    fn bounds(&self) -> Aabb {
        self.0.bounds()
    }
    fn memory_bytes(&self) -> usize {
        0
    }
    fn update(&mut self, _: &Scene) -> bool {
        true
    }
}

#[test]
fn a_structure_that_does_not_follow_the_animation_fails_the_check() {
    let mut s = scene();
    let mut cs = contenders(&s, &["two-level"]);
    cs.push(Contender {
        name: "stale".into(),
        accel: Box::new(Stale(
            AccelSpec::default()
                .build(&s.triangles)
                .expect("the structure builds"),
        )),
        follow: Follow::Update,
        entries: None,
        build_seconds: 0.0,
    });
    let err = anim::run(&mut s, &mut cs, &options(), &pool(), &mut |_| {}).unwrap_err();
    match &err {
        AnimError::Mismatch { name, frame, .. } => {
            assert_eq!(name, "stale");
            assert!(*frame >= 1, "frame 0 is where it was built");
        }
        e => panic!("{e}"),
    }
    assert!(err.to_string().contains("disagree with the flat bvh8"));
    assert!(!err.to_string().contains('\n'));
}

#[test]
fn the_primary_workload_traces_primary_rays_only() {
    let mut s = scene();
    let mut cs = contenders(&s, &["bvh8", "clusters:t=4"]);
    let mut o = options();
    o.workload = Workload::Primary;
    let report = anim::run(&mut s, &mut cs, &o, &pool(), &mut |_| {}).unwrap();
    assert!(report
        .rays
        .iter()
        .all(|r| r.total() == 24 * 16 && r.incoherent == 0 && r.shadow == 0));
    assert_eq!(report.contenders[1].check.checked, 4 * 24 * 16);
}

#[test]
fn bad_options_are_errors() {
    let mut s = scene();
    let mut cs = contenders(&s, &["two-level"]);
    let mut o = options();
    o.frames = 3..3;
    assert!(matches!(
        anim::run(&mut s, &mut cs, &o, &pool(), &mut |_| {}),
        Err(AnimError::NoFrames { .. })
    ));
    let mut o = options();
    o.camera = 5;
    assert!(matches!(
        anim::run(&mut s, &mut cs, &o, &pool(), &mut |_| {}),
        Err(AnimError::Camera(5))
    ));
}
