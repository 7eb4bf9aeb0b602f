//! Traversal options of the QBVH (Dammertz §3.3 and §5).

/// Default largest leaf of a QBVH: the thesis' 16, four SIMD groups of four triangles.
pub const DEFAULT_LEAF_SIZE: usize = 16;

/// SAH cost of one triangle test relative to one node visit for QBVH builds: four triangles
/// are tested at once, so a leaf costs much less per triangle than a binary BVH's. 0.2 was the
/// fastest and smallest on the dragon and within noise of the best on the conference room
/// (`docs/benchmarks.md`, section G).
pub const DEFAULT_INTERSECTION_COST: f32 = 0.2;

/// The order in which a node's hit children are visited (Dammertz §3.3.3, Table 3.1).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Order {
    /// Slot order, whatever the ray: the cheapest per node, the most boxes per ray.
    Unsorted,
    /// Nearest entry distance first (a sorting network over the four hit slots). The
    /// eight-wide node sorts for closest-hit queries only: any-hit queries take its hit slots
    /// in slot order.
    Distance,
    /// The order of the binary splits the node was collapsed from, near side first according to
    /// the sign of the ray direction along each split axis. Needs no distances at all; the
    /// thesis found it the fastest.
    #[default]
    SplitPlane,
}

/// The ray–triangle test used in the leaves (Dammertz §4.4).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum TriangleTest {
    /// Woop–Benthin–Wald's watertight test, four triangles at a time.
    #[default]
    Watertight,
    /// The thesis' crack-free test: recursive midpoint subdivision of the triangle and its
    /// barycentric domain down to the float limit.
    Subdivision,
    /// Möller–Trumbore first, the subdivision test only where it reports a miss.
    Hybrid,
}

/// How a [`Qbvh`](super::Qbvh) or [`Bvh8`](super::Bvh8) is traversed. The defaults
/// ([`WideOptions::defaults_for`]; `Default` gives the QBVH's) are the fastest measured on this
/// project's benchmarks (see `docs/benchmarks.md`).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct WideOptions {
    /// Child visiting order.
    pub order: Order,
    /// Keep each pending child's entry distance on the stack and skip it when popped if a
    /// closer hit has been found since it was pushed (Dammertz §3.3.4).
    pub t_stack: bool,
    /// Start occlusion queries from the node of the last occluder found for the same light
    /// region, with backtracking through parent indices (Dammertz §5.3). Per thread.
    pub shadow_cache: bool,
    /// The leaf triangle test.
    pub intersection: TriangleTest,
}

impl WideOptions {
    /// The default options of a wide BVH with nodes `N`: they differ only in the child order
    /// and the t-stack.
    pub fn defaults_for<N: super::WideNode>() -> Self {
        Self {
            order: N::DEFAULT_ORDER,
            t_stack: N::DEFAULT_TSTACK,
            ..Self::default()
        }
    }
}
