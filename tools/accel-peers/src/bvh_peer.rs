//! The `bvh` crate (crates.io): a binary SAH BVH with one triangle per leaf, built with
//! `Bvh::build_par`. The crate has no closest-hit triangle query of its own (its
//! `Ray::intersects_triangle` culls back faces, so it cannot answer two-sided queries), so
//! both variants intersect with a two-sided Möller–Trumbore test here; what differs is the
//! crate traversal that feeds it:
//!
//! - `bvh-crate`: `Bvh::traverse_iterator` with a query (the crate's `IntersectsAabb` trait)
//!   whose slab test is clipped to the closest hit so far, so nodes behind it are culled;
//! - `bvh-crate-flat`: `FlatBvh::traverse` with the crate's `Ray`, which collects every leaf
//!   whose box the ray crosses, then the nearest of them is found (no culling by distance).

use crate::peer::{Peer, Work};
use bvh::aabb::{Aabb, Bounded, IntersectsAabb};
use bvh::bounding_hierarchy::{BHShape, BoundingHierarchy};
use bvh::bvh::{Bvh, BvhNode};
use bvh::flat_bvh::{FlatBvh, FlatNode};
use nalgebra::{Point3, Vector3};
use rt_core::glam::Vec3;
use rt_core::Ray;
use std::cell::Cell;

/// One triangle as the crate sees it: its box, plus what the triangle test needs.
pub struct Shape {
    aabb: Aabb<f32, 3>,
    node: usize,
    v0: Vec3,
    e1: Vec3,
    e2: Vec3,
    index: u32,
}

impl Bounded<f32, 3> for Shape {
    fn aabb(&self) -> Aabb<f32, 3> {
        self.aabb
    }
}

impl BHShape<f32, 3> for Shape {
    fn set_bh_node_index(&mut self, index: usize) {
        self.node = index;
    }
    fn bh_node_index(&self) -> usize {
        self.node
    }
}

impl Shape {
    /// Two-sided Möller–Trumbore: `t ∈ (0, t_max]` or `None`.
    #[inline(always)]
    fn hit(&self, o: Vec3, d: Vec3, t_max: f32) -> Option<f32> {
        let p = d.cross(self.e2);
        let det = self.e1.dot(p);
        if det == 0.0 {
            return None;
        }
        let inv = 1.0 / det;
        let s = o - self.v0;
        let u = s.dot(p) * inv;
        if !(0.0..=1.0).contains(&u) {
            return None;
        }
        let q = s.cross(self.e1);
        let v = d.dot(q) * inv;
        if v < 0.0 || u + v > 1.0 {
            return None;
        }
        let t = self.e2.dot(q) * inv;
        (t > 0.0 && t <= t_max).then_some(t)
    }
}

enum Tree {
    Nodes(Bvh<f32, 3>),
    Flat(FlatBvh<f32, 3>),
}

/// The crate's BVH (or its flattened form) and the shapes it indexes.
pub struct BvhCrate {
    name: String,
    tree: Tree,
    shapes: Vec<Shape>,
}

/// Builds `bvh-crate` or `bvh-crate-flat`.
pub fn build(name: &str, tris: &[[Vec3; 3]]) -> anyhow::Result<Box<dyn Peer>> {
    let mut shapes: Vec<Shape> = tris
        .iter()
        .enumerate()
        .map(|(i, t)| {
            let (lo, hi) = (t[0].min(t[1]).min(t[2]), t[0].max(t[1]).max(t[2]));
            Shape {
                aabb: Aabb::with_bounds(
                    Point3::new(lo.x, lo.y, lo.z),
                    Point3::new(hi.x, hi.y, hi.z),
                ),
                node: 0,
                v0: t[0],
                e1: t[1] - t[0],
                e2: t[2] - t[0],
                index: i as u32,
            }
        })
        .collect();
    let bvh = Bvh::build_par(&mut shapes);
    let tree = if name == "bvh-crate-flat" {
        Tree::Flat(bvh.flatten())
    } else {
        Tree::Nodes(bvh)
    };
    Ok(Box::new(BvhCrate {
        name: name.to_string(),
        tree,
        shapes,
    }))
}

/// A ray segment `(0, t_max]` as a traversal query; `t_max` shrinks as hits are found.
struct Segment<const COUNT: bool> {
    o: Vec3,
    inv: Vec3,
    t_max: Cell<f32>,
    boxes: Cell<u64>,
}

impl<const COUNT: bool> Segment<COUNT> {
    fn new(ray: &Ray, t_max: f32) -> Self {
        Self {
            o: ray.origin,
            inv: ray.dir.recip(),
            t_max: Cell::new(t_max),
            boxes: Cell::new(0),
        }
    }
}

impl<const COUNT: bool> IntersectsAabb<f32, 3> for Segment<COUNT> {
    #[inline(always)]
    fn intersects_aabb(&self, b: &Aabb<f32, 3>) -> bool {
        if COUNT {
            self.boxes.set(self.boxes.get() + 1);
        }
        let lo = (Vec3::new(b.min.x, b.min.y, b.min.z) - self.o) * self.inv;
        let hi = (Vec3::new(b.max.x, b.max.y, b.max.z) - self.o) * self.inv;
        // Widened by 2 ulps (Ize, "Robust BVH ray traversal").
        let near = lo.min(hi).max_element().max(0.0);
        let far = lo.max(hi).min_element().min(self.t_max.get()) * (1.0 + 2.0 * f32::EPSILON);
        near <= far
    }
}

impl BvhCrate {
    /// Closest hit (or, with `any`, the first hit found) and the work done.
    fn query<const COUNT: bool>(
        &self,
        ray: &Ray,
        t_max: f32,
        any: bool,
    ) -> (Option<(f32, u32)>, Work) {
        let (o, d) = (ray.origin, ray.dir);
        let mut best: Option<(f32, u32)> = None;
        let mut tris = 0u64;
        let seg = Segment::<COUNT>::new(ray, t_max);
        match &self.tree {
            Tree::Nodes(bvh) => {
                for s in bvh.traverse_iterator(&seg, &self.shapes) {
                    tris += 1;
                    if let Some(t) = s.hit(o, d, seg.t_max.get()) {
                        best = Some((t, s.index));
                        seg.t_max.set(t);
                        if any {
                            break;
                        }
                    }
                }
            }
            Tree::Flat(flat) => {
                let r = bvh::ray::Ray::new(Point3::new(o.x, o.y, o.z), Vector3::new(d.x, d.y, d.z));
                for s in flat.traverse(&r, &self.shapes) {
                    tris += 1;
                    if let Some(t) = s.hit(o, d, best.map_or(t_max, |b| b.0)) {
                        best = Some((t, s.index));
                        if any {
                            break;
                        }
                    }
                }
            }
        }
        let work = Work {
            boxes: matches!(self.tree, Tree::Nodes(_)).then(|| seg.boxes.get()),
            leaves: None,
            tris: Some(tris),
        };
        (best, work)
    }
}

impl Peer for BvhCrate {
    fn name(&self) -> &str {
        &self.name
    }

    fn bytes(&self) -> Option<usize> {
        let tree = match &self.tree {
            Tree::Nodes(b) => b.nodes.len() * size_of::<BvhNode<f32, 3>>(),
            Tree::Flat(f) => f.len() * size_of::<FlatNode<f32, 3>>(),
        };
        Some(tree + self.shapes.len() * size_of::<Shape>())
    }

    fn closest(&self, ray: &Ray, t_max: f32) -> Option<(f32, u32)> {
        self.query::<false>(ray, t_max, false).0
    }

    fn occluded(&self, ray: &Ray, t_max: f32) -> bool {
        let t_open = f32::from_bits(t_max.to_bits().saturating_sub(1));
        self.query::<false>(ray, t_open, true).0.is_some()
    }

    fn work(&self, ray: &Ray, t_max: f32, shadow: bool) -> Work {
        self.query::<true>(ray, t_max, shadow).1
    }
}
