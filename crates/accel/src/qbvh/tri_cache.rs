//! The per-thread triangle cache of Dammertz §5.1, kept for measurement: leaves read their
//! triangles from a flat copy (36 bytes per triangle, as a renderer's own mesh arrays would
//! hold them) through a direct-mapped cache of swizzled four-wide packets, instead of from the
//! packets swizzled once at build time.

use super::node::leaf_parts;
use super::tri4::Tri4;
use super::Qbvh;
use std::cell::RefCell;

/// Lines of the cache; each holds one leaf (up to 16 triangles), as in the thesis' Table 3.3.
const LINES: usize = 128;

struct Line {
    /// Leaf code cached in the line; 0 (never a leaf code) when empty.
    tag: u32,
    packets: [Tri4; 4],
}

struct Cache {
    owner: u64,
    lines: Vec<Line>,
}

thread_local! {
    static CACHE: RefCell<Cache> = const { RefCell::new(Cache { owner: 0, lines: Vec::new() }) };
}

impl Qbvh {
    /// Calls `test` with the swizzled packets of leaf `code`, filling the calling thread's cache
    /// line from the flat triangle copy on a miss.
    #[inline(always)]
    pub(crate) fn with_cached_packets<R>(&self, code: u32, test: impl FnOnce(&[Tri4]) -> R) -> R {
        CACHE.with(|cache| {
            let mut cache = cache.borrow_mut();
            if cache.owner != self.id || cache.lines.is_empty() {
                cache.owner = self.id;
                cache.lines = (0..LINES)
                    .map(|_| Line {
                        tag: 0,
                        packets: [Tri4 { v: [[0.0; 4]; 9] }; 4],
                    })
                    .collect();
            }
            let (first, count) = leaf_parts(code);
            let n = count.div_ceil(4);
            let line = &mut cache.lines[first % LINES];
            if line.tag != code {
                for (k, packet) in line.packets[..n].iter_mut().enumerate() {
                    let slot = 4 * (first + k);
                    *packet = Tri4::pack(&self.flat[slot..slot + 4]);
                }
                line.tag = code;
            }
            test(&line.packets[..n])
        })
    }
}
