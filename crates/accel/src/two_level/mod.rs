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
//! **Rigid-body entry-point clustering** (Dammertz 2011, §4.5; `clusters:t=T`): the top level
//! does not stop at whole objects. Each object BVH is cut into *entry points*, the nodes (or
//! leaves) whose world-space size is below `size(scene) / t` while their parents' are not
//! ([`Bvh8::entry_points`]), cut once when the structure is built (the thesis' preprocess;
//! the scene's size is taken then); the top level is a binary SAH tree over the entry points'
//! world boxes, rebuilt every frame down to one entry per leaf, and a ray reaching a leaf continues
//! inside the object at that node with the inverse-transformed ray
//! ([`Bvh8::closest_hit_prepared`]: the ray's slab and triangle setup is made once per
//! placement and kept across the consecutive entries of that placement a ray often enters).
//! Overlapping parts (seats inside a hull) then separate in the top level instead of forcing
//! every ray into both. Deviation: sizes are the boxes' longest
//! sides, and an object's threshold is divided by its instance's largest scale factor (the
//! BVH is shared by instances of different sizes).
//!
//! **Motion blur**: when the scene's shutter is open ([`Scene::shutter`]) an instance that
//! moves meanwhile is placed per ray, at the ray's [`Ray::time`] (its keyed transform and the
//! inverse computed for the ray), and its top-level box (or its entry points' boxes) bounds
//! its whole sweep: the object box's world boxes at the shutter's ends, at every key inside
//! it and at 16 steps between, padded by twice the largest distance a box corner moves
//! between two neighbouring steps. A corner's path between steps is an arc of the slerped
//! rotation with linear translation and scale; at 1/16 of the shutter or less it is at most a
//! few per cent longer than its chord unless the instance spins through several turns while
//! the shutter is open, so the padding covers it with margin. Rays at time 0 take the
//! precomputed placement, bit for bit what a render without blur traces.
//!
//! Deviations: the static geometry is one object (not one per `[[geometry]]`): seed 002 found
//! per-object BVHs of overlapping static parts slower than one, and nothing moves there. The
//! world box of an instance is its object box's eight corners transformed, padded by a
//! rounding bound: loose under rotation, as in Embree.
//! The top level's binary SAH tree is collapsed eight wide and walked with one AVX2 test of
//! eight boxes per node (two SSE halves without AVX2), where the thesis walks its top level
//! binary: a ray then visits about a third as many top-level nodes (see `top.rs`).

mod top;

pub use top::TopLevel;

use crate::wide::PreparedRay;
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
    /// Index into `TwoLevel::moving` if the instance moves while the shutter is open.
    moving: Option<u32>,
    object: u32,
    /// World to object space and back; `None` for the identity.
    to_object: Option<Mat4>,
    to_world: Option<Mat4>,
    /// Scene index of the instance's first triangle (its world copy).
    first: u32,
    /// The world copy's winding is reversed (a mirroring transform).
    flip: bool,
    world: Aabb,
}

/// An instance that moves while the shutter is open: placed per ray.
struct Moving {
    /// Its motion (keys after the base placement).
    instance: Instance,
    /// Object-to-world matrices at the sample times across the shutter, in time order.
    samples: Vec<Mat4>,
}

/// Per-object BVHs under a top-level BVH over their placements.
pub struct TwoLevel {
    objects: Vec<Object>,
    placements: Vec<Placement>,
    /// Clustering's `t`; `None`: one entry per placement (its root).
    cut: Option<f32>,
    /// The top level's leaves: (placement, child code to start at; 0 for the object's root),
    /// their boxes in object space and in the world.
    entries: Vec<(u32, u32)>,
    entry_local: Vec<Aabb>,
    entry_boxes: Vec<Aabb>,
    /// Each instance's object, and its prototype (to check an update matches the build).
    instance_objects: Vec<u32>,
    instance_prototypes: Vec<u32>,
    top: top::Top,
    mode: TopLevel,
    bounds: Aabb,
    /// Top levels built or refitted (the build's included): what a frame costs.
    top_updates: usize,
    /// The shutter: the scene's time when it opens and how long it stays open (seconds).
    shutter: (f32, f32),
    /// The instances placed per ray.
    moving: Vec<Moving>,
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
            (&scene.instances, &scene.prototypes),
            (scene.time, scene.shutter),
            params,
            options,
            mode,
            None,
        )
    }

    /// [`TwoLevel::build`] with rigid-body entry-point clustering at threshold `t` (> 0).
    pub fn build_clustered(
        scene: &Scene,
        params: &BuildParams,
        options: &WideOptions,
        t: f32,
    ) -> Self {
        Self::build_parts(
            &scene.triangles,
            (&scene.instances, &scene.prototypes),
            (scene.time, scene.shutter),
            params,
            options,
            TopLevel::Rebuild,
            Some(t),
        )
    }

    /// Over plain triangles: one static object (a BVH8 under a one-leaf top level).
    pub fn build_flat(
        triangles: &[[Vec3; 3]],
        params: &BuildParams,
        options: &WideOptions,
        mode: TopLevel,
        cut: Option<f32>,
    ) -> Self {
        Self::build_parts(
            triangles,
            (&[], &[]),
            (0.0, 0.0),
            params,
            options,
            mode,
            cut,
        )
    }

    fn build_parts(
        triangles: &[[Vec3; 3]],
        (instances, prototypes): (&[Instance], &[Prototype]),
        shutter: (f32, f32),
        params: &BuildParams,
        options: &WideOptions,
        mode: TopLevel,
        cut: Option<f32>,
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
                moving: None,
                to_object: None,
                to_world: None,
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
            cut,
            entries: Vec::new(),
            entry_local: Vec::new(),
            entry_boxes: Vec::new(),
            top: top::Top::default(),
            mode,
            bounds: Aabb::EMPTY,
            top_updates: 1,
            shutter,
            moving: Vec::new(),
        };
        s.place_instances(instances);
        s.make_entries();
        s.place_entries();
        s.top = top::Top::build(&s.entry_boxes);
        s
    }

    /// Cuts the placements into the top level's leaves, once at the build (the thesis'
    /// preprocess): each placement's root, or with clustering its entry points, sized against
    /// the scene as it is at the build. The cut is kept from frame to frame, so an update only
    /// moves boxes and a refit always finds the same leaves.
    fn make_entries(&mut self) {
        self.entries.clear();
        self.entry_local.clear();
        let scene_size = (self.bounds.max - self.bounds.min).max_element();
        for (k, p) in self.placements.iter().enumerate() {
            let object = &self.objects[p.object as usize];
            let Some(t) = self.cut else {
                self.entries.push((k as u32, 0));
                self.entry_local.push(object.bounds);
                continue;
            };
            // The largest factor by which the placement stretches a length.
            let stretch = p.to_world.map_or(1.0, |m| {
                let len = |v: glam::Vec4| v.truncate().length();
                len(m.x_axis).max(len(m.y_axis)).max(len(m.z_axis))
            });
            let threshold = scene_size / t / stretch;
            for (code, local) in object.bvh.entry_points(threshold) {
                self.entries.push((k as u32, code));
                self.entry_local.push(local);
            }
        }
    }

    /// The entries' world boxes under the current placements (Dammertz's Listing 4.1: the
    /// local box's eight corners transformed).
    fn place_entries(&mut self) {
        self.entry_boxes.clear();
        for (&(k, code), local) in self.entries.iter().zip(&self.entry_local) {
            let p = &self.placements[k as usize];
            self.entry_boxes.push(match (&p.to_world, code, p.moving) {
                // An object's root: its world box (swept over the shutter) is already known.
                (_, 0, _) => p.world,
                (None, _, _) => *local,
                (Some(_), _, Some(i)) => swept_box(&self.moving[i as usize].samples, local),
                (Some(m), _, None) => world_box(m, local),
            });
        }
    }

    /// Sets every instance's placement from the scene's current transforms, and the bounds
    /// of all placements.
    fn place_instances(&mut self, instances: &[Instance]) {
        let statics = usize::from(
            self.placements
                .first()
                .is_some_and(|p| p.to_object.is_none()),
        );
        self.placements.truncate(statics);
        self.moving.clear();
        let (open, duration) = self.shutter;
        for (inst, &object) in instances.iter().zip(&self.instance_objects) {
            let m = inst.transform.m;
            let bounds = &self.objects[object as usize].bounds;
            let mut world = world_box(&m, bounds);
            let mut moving = None;
            if duration > 0.0 && inst.moves_during(open, open + duration) {
                let samples = shutter_samples(inst, open, duration);
                world = swept_box(&samples, bounds);
                moving = Some(self.moving.len() as u32);
                self.moving.push(Moving {
                    instance: inst.clone(),
                    samples,
                });
            }
            self.placements.push(Placement {
                moving,
                object,
                to_object: Some(m.inverse()),
                to_world: Some(m),
                first: inst.first,
                flip: inst.transform.flips_handedness(),
                world,
            });
        }
        self.bounds = self
            .placements
            .iter()
            .map(|p| p.world)
            .fold(Aabb::EMPTY, Aabb::union);
    }

    /// Bytes of the top level alone (what a frame rebuilds).
    pub fn top_bytes(&self) -> usize {
        self.top.memory_bytes()
            + std::mem::size_of_val(self.placements.as_slice())
            + std::mem::size_of_val(self.entries.as_slice())
            + std::mem::size_of_val(self.entry_local.as_slice())
            + std::mem::size_of_val(self.entry_boxes.as_slice())
    }

    /// Leaves of the top level (placements, or entry points when clustered).
    pub fn entry_count(&self) -> usize {
        self.entries.len()
    }

    /// Object BVHs this structure holds: built once, whatever the frames since.
    pub fn object_count(&self) -> usize {
        self.objects.len()
    }

    /// Times the top level was built or refitted, the first build included.
    pub fn top_updates(&self) -> usize {
        self.top_updates
    }

    /// The object BVHs' node arrays, by address: they stay put across [`Accel::update`]
    /// (nothing below the top level is rebuilt), which a test can check.
    pub fn object_addresses(&self) -> Vec<usize> {
        self.objects
            .iter()
            .map(|o| o.bvh.nodes().as_ptr() as usize)
            .collect()
    }

    /// Closest hit (or any hit) over all placements.
    fn trace<const ANY: bool>(
        &self,
        ray: &Ray,
        t_max: f32,
        counters: Option<&mut TraversalCounters>,
    ) -> Option<Hit> {
        if ray.origin.is_nan() || !ray.dir.is_finite() {
            return None;
        }
        let mut best: Option<Hit> = None;
        let mut local = TraversalCounters::default();
        let counting = counters.is_some();
        // The ray in the space of the placement entered last, set up for its traversal: a
        // clustered top level often enters several entry points of one object in a row.
        let mut last: Option<(u32, PreparedRay)> = None;
        let leaf = |e: u32, t_cull: f32, c: &mut TraversalCounters| {
            let (k, code) = self.entries[e as usize];
            let p = &self.placements[k as usize];
            let obj = &self.objects[p.object as usize];
            if last.as_ref().map(|l| l.0) != Some(k) {
                let r = match (&p.to_object, p.moving) {
                    (Some(_), Some(i)) if ray.time != 0.0 => {
                        let (open, duration) = self.shutter;
                        let to_world = self.moving[i as usize]
                            .instance
                            .matrix_at(open + ray.time * duration);
                        let m = to_world.inverse();
                        Ray::new(m.transform_point3(ray.origin), m.transform_vector3(ray.dir))
                    }
                    (None, _) => *ray,
                    (Some(m), _) => {
                        Ray::new(m.transform_point3(ray.origin), m.transform_vector3(ray.dir))
                    }
                };
                last = Some((k, Bvh8::prepare(&r)));
            }
            let Some((_, r)) = &mut last else {
                unreachable!("set above")
            };
            let hit = if ANY {
                obj.bvh
                    .any_hit_prepared(code, r, t_cull, counting.then_some(&mut *c))
                    .then_some(Hit {
                        t: t_cull,
                        prim: 0,
                        b1: 0.0,
                        b2: 0.0,
                    })
            } else {
                obj.bvh
                    .closest_hit_prepared(code, r, t_cull, counting.then_some(&mut *c))
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
        };
        if counting {
            self.top.walk::<true>(ray, t_max, &mut local, ANY, leaf);
        } else {
            self.top.walk::<false>(ray, t_max, &mut local, ANY, leaf);
        }
        if let Some(c) = counters {
            *c += local;
        }
        best
    }
}

/// Object-to-world matrices of `inst` across the shutter `[open, open + duration]`: at both
/// ends, at every key inside and at 16 even steps, in time order.
fn shutter_samples(inst: &Instance, open: f32, duration: f32) -> Vec<Mat4> {
    const STEPS: u32 = 16;
    let close = open + duration;
    let mut times: Vec<f32> = (0..=STEPS)
        .map(|i| open + duration * i as f32 / STEPS as f32)
        .collect();
    if let Some(m) = &inst.motion {
        times.extend(
            m.keys()
                .iter()
                .map(|k| k.time)
                .filter(|&t| t > open && t < close),
        );
    }
    times.sort_by(f32::total_cmp);
    times.into_iter().map(|t| inst.matrix_at(t)).collect()
}

/// A world box holding an object box wherever the transforms `samples` (in time order, and
/// everything between neighbours) put it: the union of its boxes at the samples, padded by
/// twice the largest distance a corner moves between neighbouring samples (see the module
/// doc).
fn swept_box(samples: &[Mat4], b: &Aabb) -> Aabb {
    if b.is_empty() {
        return Aabb::EMPTY;
    }
    let corners = b.corners();
    let mut out = Aabb::EMPTY;
    let mut step = 0.0f32;
    for pair in samples.windows(2) {
        for c in corners {
            let moved = pair[1].transform_point3(c) - pair[0].transform_point3(c);
            step = step.max(moved.length());
        }
    }
    for m in samples {
        out = out.union(world_box(m, b));
    }
    let pad = Vec3::splat(2.0 * step);
    Aabb::new(out.min - pad, out.max + pad)
}

/// The world box of an object box under `m`: its corners, padded by the rounding of the
/// transform so that a ray the object-space test would hit is not culled by the box.
fn world_box(m: &Mat4, b: &Aabb) -> Aabb {
    if b.is_empty() {
        return Aabb::EMPTY;
    }
    let mut out = Aabb::EMPTY;
    for c in b.corners() {
        out = out.grown(m.transform_point3(c));
    }
    let pad = gamma(8) * out.min.abs().max(out.max.abs());
    Aabb::new(out.min - pad, out.max + pad)
}

impl Accel for TwoLevel {
    fn name(&self) -> &str {
        if self.cut.is_some() {
            "clusters"
        } else {
            "two-level"
        }
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

    /// The object BVHs' own bytes (each prototype's once, whatever its instances), their
    /// index maps and the top level.
    fn structure_bytes(&self) -> Option<usize> {
        let objects = self
            .objects
            .iter()
            .map(|o| {
                let own = o
                    .bvh
                    .structure_bytes()
                    .unwrap_or_else(|| o.bvh.memory_bytes());
                own + o.map.as_ref().map_or(0, |m| 4 * m.len())
            })
            .sum::<usize>();
        Some(objects + self.top_bytes())
    }

    fn counts_traversal(&self) -> bool {
        true
    }

    fn interpolates_motion(&self) -> bool {
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
        self.shutter = (scene.time, scene.shutter);
        self.place_instances(&scene.instances);
        self.place_entries();
        self.top_updates += 1;
        if self.mode == TopLevel::Refit {
            self.top.refit(&self.entry_boxes);
        } else {
            self.top = top::Top::build(&self.entry_boxes);
        }
        true
    }
}
