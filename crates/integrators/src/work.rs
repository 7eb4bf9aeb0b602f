//! Work items of the techniques that render a pass in chunks of paths and merge each chunk's
//! results into the film in item order (so images do not depend on the thread count).

use std::ops::Range;

/// Paths `first..first + count` of sample index `index` (light paths, or pixels in
/// row-major order).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) struct Item {
    pub index: u32,
    pub first: u32,
    pub count: u32,
}

/// The items covering `paths` paths per sample index in chunks of `chunk`, index by index.
pub(crate) fn items(indices: Range<u32>, paths: u32, chunk: u32) -> Vec<Item> {
    indices
        .flat_map(|index| {
            (0..paths.div_ceil(chunk)).map(move |c| Item {
                index,
                first: c * chunk,
                count: chunk.min(paths - c * chunk),
            })
        })
        .collect()
}

/// Rows of an image of `rows` rows to report as done after `done` of `total` items.
pub(crate) fn rows_done(done: usize, total: usize, rows: u32) -> u32 {
    (done as u64 * u64::from(rows) / total.max(1) as u64) as u32
}
