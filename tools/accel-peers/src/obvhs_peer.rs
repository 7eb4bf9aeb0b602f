//! obvhs (crates.io): a PLOC-built BVH2 and the 8-wide compressed CWBVH, each traversed with the
//! crate's own `ray_traverse` (closest hit) and `ray_traverse_miss` (occlusion), intersecting
//! the crate's precomputed `RtTriangle`s reordered to the BVH's primitive order, as its
//! `cornell_box_cwbvh` example does (no index indirection in the leaf loop).
//!
//! Names: `obvhs-bvh2` and `obvhs-cwbvh`, optionally with a build preset `:fastest`, `:fast`,
//! `:medium` (the default: "around Embree's build time with faster traversal"), `:slow`.

use crate::peer::{Peer, Work};
use glam_obvhs::Vec3A;
use obvhs::bvh2::Bvh2;
use obvhs::cwbvh::CwBvh;
use obvhs::ray::{Ray as ORay, RayHit};
use obvhs::rt_triangle::RtTriangle;
use obvhs::triangle::Triangle;
use obvhs::BvhBuildParams;
use rt_core::glam::Vec3;
use rt_core::Ray;
use std::time::Duration;

/// Either tree, with the triangles in its leaf order and the map back to file order.
pub struct Obvhs<T> {
    name: String,
    tree: T,
    tris: Vec<RtTriangle>,
    original: Vec<u32>,
    tree_bytes: usize,
}

/// Builds `obvhs-<rest>`.
pub fn build(name: &str, rest: &str, tris: &[[Vec3; 3]]) -> anyhow::Result<Box<dyn Peer>> {
    let (kind, preset) = rest.split_once(':').unwrap_or((rest, "medium"));
    let params = match preset {
        "fastest" => BvhBuildParams::fastest_build(),
        "fast" => BvhBuildParams::fast_build(),
        "medium" => BvhBuildParams::medium_build(),
        "slow" => BvhBuildParams::slow_build(),
        _ => anyhow::bail!("{name}: unknown obvhs preset `{preset}`"),
    };
    let v = |p: Vec3| Vec3A::new(p.x, p.y, p.z);
    let input: Vec<Triangle> = tris
        .iter()
        .map(|t| Triangle {
            v0: v(t[0]),
            v1: v(t[1]),
            v2: v(t[2]),
        })
        .collect();
    let mut core_time = Duration::ZERO;
    let reorder = |indices: &[u32]| -> Vec<RtTriangle> {
        indices
            .iter()
            .map(|&i| RtTriangle::from(&input[i as usize]))
            .collect()
    };
    Ok(match kind {
        "bvh2" => {
            let tree = obvhs::bvh2::builder::build_bvh2_from_tris(&input, params, &mut core_time);
            let tree_bytes = tree.nodes.len() * size_of::<obvhs::bvh2::node::Bvh2Node>();
            Box::new(Obvhs {
                name: name.to_string(),
                tris: reorder(&tree.primitive_indices),
                original: tree.primitive_indices.clone(),
                tree,
                tree_bytes,
            })
        }
        "cwbvh" => {
            let tree = obvhs::cwbvh::builder::build_cwbvh_from_tris(&input, params, &mut core_time);
            let tree_bytes = tree.nodes.len() * size_of::<obvhs::cwbvh::node::CwBvhNode>();
            Box::new(Obvhs {
                name: name.to_string(),
                tris: reorder(&tree.primitive_indices),
                original: tree.primitive_indices.clone(),
                tree,
                tree_bytes,
            })
        }
        _ => anyhow::bail!("{name}: expected obvhs-bvh2 or obvhs-cwbvh"),
    })
}

fn oray(ray: &Ray, t_max: f32) -> ORay {
    let v = |p: Vec3| Vec3A::new(p.x, p.y, p.z);
    // t_min: the smallest positive float, so that t = 0 is excluded as in our (0, t_max].
    ORay::new(v(ray.origin), v(ray.dir), f32::MIN_POSITIVE, t_max)
}

/// The crate's two traversals, behind one name so both trees share the adapter.
pub trait Traverse: Send + Sync {
    /// `ray_traverse` of the crate.
    fn closest(&self, ray: ORay, hit: &mut RayHit, f: impl FnMut(&ORay, usize) -> f32) -> bool;
    /// `ray_traverse_miss` of the crate.
    fn miss(&self, ray: ORay, f: impl FnMut(&ORay, usize) -> f32) -> bool;
}

impl Traverse for Bvh2 {
    fn closest(&self, ray: ORay, hit: &mut RayHit, f: impl FnMut(&ORay, usize) -> f32) -> bool {
        self.ray_traverse(ray, hit, f)
    }
    fn miss(&self, ray: ORay, f: impl FnMut(&ORay, usize) -> f32) -> bool {
        self.ray_traverse_miss(ray, f)
    }
}

impl Traverse for CwBvh {
    fn closest(&self, ray: ORay, hit: &mut RayHit, f: impl FnMut(&ORay, usize) -> f32) -> bool {
        self.ray_traverse(ray, hit, f)
    }
    fn miss(&self, ray: ORay, f: impl FnMut(&ORay, usize) -> f32) -> bool {
        self.ray_traverse_miss(ray, f)
    }
}

impl<T: Traverse> Peer for Obvhs<T> {
    fn name(&self) -> &str {
        &self.name
    }

    fn bytes(&self) -> Option<usize> {
        Some(
            self.tree_bytes
                + self.original.len() * size_of::<u32>()
                + self.tris.len() * size_of::<RtTriangle>(),
        )
    }

    fn closest(&self, ray: &Ray, t_max: f32) -> Option<(f32, u32)> {
        let mut hit = RayHit::none();
        self.tree
            .closest(oray(ray, t_max), &mut hit, |r, i| self.tris[i].intersect(r))
            .then(|| (hit.t, self.original[hit.primitive_id as usize]))
    }

    fn occluded(&self, ray: &Ray, t_max: f32) -> bool {
        // The crate's test accepts t == tmax; stop one ulp short for our open (0, t_max).
        let r = oray(ray, f32::from_bits(t_max.to_bits().saturating_sub(1)));
        !self.tree.miss(r, |r, i| self.tris[i].intersect(r))
    }

    fn work(&self, ray: &Ray, t_max: f32, shadow: bool) -> Work {
        let mut tests = 0u64;
        let count = |r: &ORay, i: usize| {
            tests += 1;
            self.tris[i].intersect(r)
        };
        if shadow {
            self.tree.miss(oray(ray, t_max), count);
        } else {
            self.tree
                .closest(oray(ray, t_max), &mut RayHit::none(), count);
        }
        Work {
            tris: Some(tests),
            ..Work::default()
        }
    }
}
