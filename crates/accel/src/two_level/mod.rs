//! Two-level acceleration: one BVH per object in its own space, under a top-level BVH over the
//! placements' world boxes (Embree's instancing scheme; the per-object BVHs seed 002 proposes
//! as its next step, §1.5).
//!
//! The object BVHs are built once: a prototype's in object space (shared by all its
//! instances), the static geometry's in world space as one more object. Per frame
//! ([`Accel::update`]) only the top level changes: its boxes come from the object BVHs' bounds
//! under the new transforms, and it is rebuilt by the binned SAH or refitted in place
//! ([`TopLevel`]). A ray reaching an instance leaf is taken into object space (origin and
//! direction by the inverse transform, the direction not renormalised, so `t` means the same
//! on both sides), traced through the object BVH and its hit renumbered into the scene's
//! flat triangle order; for a mirroring transform the barycentrics swap with the world copy's
//! winding ([`rt_core::instance::place_triangle`]).
//!
//! Deviations: the static geometry is one object (not one per `[[geometry]]`): seed 002 found
//! per-object BVHs of overlapping static parts slower than one, and nothing moves there. The
//! world box of an instance is its object box's eight corners transformed, padded by a
//! rounding bound: loose under rotation, as in Embree.

mod top;

pub use top::TopLevel;

use crate::{BuildParams, Bvh8, WideOptions};
use glam::{Mat4, Vec3};
use rt_core::instance::{Instance, Prototype};
use rt_core::ray::gamma;
use rt_core::{Aabb, Accel, Hit, Ray, Scene, TraversalCounters};

/// One object's structure and how its hits map to scene triangles.
struct Object {
    bvh: Bvh8,
    /// Scene index of each local triangle, when they are not one contiguous range.
    map: Option<Vec<u32>>,
    /// Scene index of local triangle 0 otherwise.
    first: u32,
    bounds: Aabb,
}

/// One placement of an object: the static geometry (identity) or an instance.
#[derive(Clone, Copy)]
struct Placement {
    object: u32,
    /// World to object space; `None` for the identity.
    to_object: Option<Mat4>,
    /// Scene index of the instance's first triangle (its world copy).
    first: u32,
    /// The world copy's winding is reversed (a mirroring transform).
    flip: bool,
    world: Aabb,
}

/// Per-object BVHs under a top-level BVH over their placements.
pub struct TwoLevel {
    objects: Vec<Object>,
    placements: Vec<Placement>,
    /// Each instance's object, and its prototype (to check an update matches the build).
    instance_objects: Vec<u32>,
    instance_prototypes: Vec<u32>,
    top: top::Top,
    mode: TopLevel,
    bounds: Aabb,
}

impl TwoLevel {
    /// Builds the object BVHs of `scene` (static geometry and prototypes) with `params` and
    /// `options`, and the top level over the placements at the scene's current time.
    pub fn build(
        scene: &Scene,
        params: &BuildParams,
        options: &WideOptions,
        mode: TopLevel,
    ) -> Self {
        Self::build_parts(
            &scene.triangles,
            &scene.instances,
            &scene.prototypes,
            params,
            options,
            mode,
        )
    }

    /// Over plain triangles: one static object (a BVH8 under a one-leaf top level).
    pub fn build_flat(
        triangles: &[[Vec3; 3]],
        params: &BuildParams,
        options: &WideOptions,
        mode: TopLevel,
    ) -> Self {
        Self::build_parts(triangles, &[], &[], params, options, mode)
    }

    fn build_parts(
        triangles: &[[Vec3; 3]],
        instances: &[Instance],
        prototypes: &[Prototype],
        params: &BuildParams,
        options: &WideOptions,
        mode: TopLevel,
    ) -> Self {
        let mut objects = Vec::new();
        let mut placements = Vec::new();
        // Static geometry: every triangle outside the instances' ranges.
        let mut in_instance = vec![false; triangles.len()];
        for i in instances {
            in_instance[i.first as usize..(i.first + i.count) as usize].fill(true);
        }
        let statics: Vec<u32> = (0..triangles.len() as u32)
            .filter(|&i| !in_instance[i as usize])
            .collect();
        if !statics.is_empty() {
            let tris: Vec<[Vec3; 3]> = statics.iter().map(|&i| triangles[i as usize]).collect();
            let contiguous =
                statics.last().map(|&l| l - statics[0] + 1) == Some(statics.len() as u32);
            let bvh = Bvh8::build_with(&tris, params, options);
            let bounds = bvh.bounds();
            objects.push(Object {
                bvh,
                first: statics[0],
                map: (!contiguous).then_some(statics),
                bounds,
            });
            placements.push(Placement {
                object: 0,
                to_object: None,
                first: 0,
                flip: false,
                world: bounds,
            });
        }
        // Prototypes used by instances, each built once.
        let mut object_of_prototype = vec![u32::MAX; prototypes.len()];
        let mut instance_objects = Vec::with_capacity(instances.len());
        for inst in instances {
            let p = inst.prototype as usize;
            if object_of_prototype[p] == u32::MAX {
                let bvh = Bvh8::build_with(&prototypes[p].triangles, params, options);
                let bounds = bvh.bounds();
                object_of_prototype[p] = objects.len() as u32;
                objects.push(Object {
                    bvh,
                    map: None,
                    first: 0,
                    bounds,
                });
            }
            instance_objects.push(object_of_prototype[p]);
        }
        let mut s = Self {
            objects,
            placements,
            instance_prototypes: instances.iter().map(|i| i.prototype).collect(),
            instance_objects,
            top: top::Top::default(),
            mode,
            bounds: Aabb::EMPTY,
        };
        s.place_instances(instances);
        s.top = top::Top::build(&s.boxes());
        s.bounds = s.boxes().into_iter().fold(Aabb::EMPTY, Aabb::union);
        s
    }

    /// Sets every instance's placement from the scene's current transforms.
    fn place_instances(&mut self, instances: &[Instance]) {
        let statics = usize::from(
            self.placements
                .first()
                .is_some_and(|p| p.to_object.is_none()),
        );
        self.placements.truncate(statics);
        for (inst, &object) in instances.iter().zip(&self.instance_objects) {
            let m = inst.transform.m;
            let world = world_box(&m, &self.objects[object as usize].bounds);
            self.placements.push(Placement {
                object,
                to_object: Some(m.inverse()),
                first: inst.first,
                flip: inst.transform.flips_handedness(),
                world,
            });
        }
    }

    fn boxes(&self) -> Vec<Aabb> {
        self.placements.iter().map(|p| p.world).collect()
    }

    /// Bytes of the top level alone (what a frame rebuilds).
    pub fn top_bytes(&self) -> usize {
        self.top.memory_bytes() + std::mem::size_of_val(self.placements.as_slice())
    }

    /// Closest hit (or any hit) over all placements.
    fn trace<const ANY: bool>(
        &self,
        ray: &Ray,
        t_max: f32,
        counters: Option<&mut TraversalCounters>,
    ) -> Option<Hit> {
        if ray.origin.is_nan() || ray.dir.is_nan() || !ray.dir.is_finite() {
            return None;
        }
        let mut best: Option<Hit> = None;
        let mut local = TraversalCounters::default();
        let counting = counters.is_some();
        self.top.walk(ray, t_max, &mut local, ANY, |k, t_cull, c| {
            let p = &self.placements[k as usize];
            let obj = &self.objects[p.object as usize];
            let r = match &p.to_object {
                None => *ray,
                Some(m) => Ray::new(m.transform_point3(ray.origin), m.transform_vector3(ray.dir)),
            };
            let hit = if ANY {
                obj.bvh
                    .any_hit(&r, t_cull, None, counting.then_some(&mut *c))
                    .then_some(Hit {
                        t: t_cull,
                        prim: 0,
                        b1: 0.0,
                        b2: 0.0,
                    })
            } else {
                obj.bvh.closest_hit(&r, t_cull, counting.then_some(&mut *c))
            };
            let mut h = hit?;
            if !ANY {
                h.prim = match (&obj.map, p.to_object) {
                    (Some(map), _) => map[h.prim as usize],
                    (None, None) => obj.first + h.prim,
                    (None, Some(_)) => p.first + h.prim,
                };
                if p.flip {
                    std::mem::swap(&mut h.b1, &mut h.b2);
                }
            }
            best = Some(h);
            Some(h.t)
        });
        if let Some(c) = counters {
            *c += local;
        }
        best
    }
}

/// The world box of an object box under `m`: its corners, padded by the rounding of the
/// transform so that a ray the object-space test would hit is not culled by the box.
fn world_box(m: &Mat4, b: &Aabb) -> Aabb {
    if b.is_empty() {
        return Aabb::EMPTY;
    }
    let mut out = Aabb::EMPTY;
    for i in 0..8 {
        let c = Vec3::new(
            if i & 1 == 0 { b.min.x } else { b.max.x },
            if i & 2 == 0 { b.min.y } else { b.max.y },
            if i & 4 == 0 { b.min.z } else { b.max.z },
        );
        out = out.grown(m.transform_point3(c));
    }
    let pad = gamma(8) * out.min.abs().max(out.max.abs());
    Aabb::new(out.min - pad, out.max + pad)
}

impl Accel for TwoLevel {
    fn name(&self) -> &str {
        "two-level"
    }

    fn closest_hit(
        &self,
        ray: &Ray,
        t_max: f32,
        counters: Option<&mut TraversalCounters>,
    ) -> Option<Hit> {
        self.trace::<false>(ray, t_max, counters)
    }

    fn any_hit(
        &self,
        ray: &Ray,
        t_max: f32,
        _toward: Option<Vec3>,
        counters: Option<&mut TraversalCounters>,
    ) -> bool {
        self.trace::<true>(ray, t_max, counters).is_some()
    }

    fn bounds(&self) -> Aabb {
        self.bounds
    }

    fn memory_bytes(&self) -> usize {
        self.objects
            .iter()
            .map(|o| o.bvh.memory_bytes() + o.map.as_ref().map_or(0, |m| 4 * m.len()))
            .sum::<usize>()
            + self.top_bytes()
    }

    fn counts_traversal(&self) -> bool {
        true
    }

    fn update(&mut self, scene: &Scene) -> bool {
        let same = scene.instances.len() == self.instance_prototypes.len()
            && scene
                .instances
                .iter()
                .zip(&self.instance_prototypes)
                .all(|(i, &p)| i.prototype == p);
        if !same {
            return false;
        }
        self.place_instances(&scene.instances);
        let boxes = self.boxes();
        match self.mode {
            TopLevel::Rebuild => self.top = top::Top::build(&boxes),
            TopLevel::Refit => self.top.refit(&boxes),
        }
        self.bounds = boxes.into_iter().fold(Aabb::EMPTY, Aabb::union);
        true
    }
}
