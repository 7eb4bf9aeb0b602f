//! How a complete, left-balanced binary tree splits its nodes between the two subtrees of its
//! root: the counts the IOSP-0 builder needs to cut a node's remaining triangles (thesis
//! Eq. 7.1 and its correction).
//!
//! Counts here are of *nodes*; in IOSP-0 a node holds two triangles, so the thesis' Eq. 7.1,
//! written over a split of `num` triangles (the node's own pair included), is
//! [`eq_7_1_corrected`]`(num) = 2 · hR` with `(hL, hR) = `[`complete_split`]`(num / 2)`.

/// Nodes `(left, right)` in the two subtrees of the root of a complete, left-balanced binary
/// tree of `h` nodes (levels filled left to right); `(0, 0)` for `h <= 1`.
///
/// With `H = floor(log2 h)` the levels `0..H` are full and the last holds
/// `last = h - (2^H - 1)` nodes, of which the left subtree takes up to `2^(H-1)`.
pub fn complete_split(h: u64) -> (u64, u64) {
    if h <= 1 {
        return (0, 0);
    }
    let levels = 63 - u64::from(h.leading_zeros()); // H = floor(log2 h) >= 1
    let half = 1u64 << (levels - 1);
    let last = h - ((1u64 << levels) - 1);
    (
        half - 1 + last.min(half),
        half - 1 + last.saturating_sub(half),
    )
}

/// The thesis' Eq. 7.1 **as printed**: triangles going to the right child of a split of `num`
/// triangles, `2((2^(H-1) - 1) + max(0, half - 3·2^(H-1) - 3))` with `half = num / 2` and
/// `H = floor(log2 half)`. Wrong for many sizes: for the thesis' own 12-triangle example
/// (Fig. 7.4) it sends 2 triangles right instead of 4. Kept only to document the erratum.
pub fn eq_7_1_printed(num: u64) -> u64 {
    eq_7_1(num, |half, p| {
        (half as i64 - 3 * p as i64 - 3).max(0) as u64
    })
}

/// Eq. 7.1 corrected: `2((2^(H-1) - 1) + max(0, half - 3·2^(H-1) + 1))`, which is
/// `2 · complete_split(half).1` for every `half >= 2` (0 below).
pub fn eq_7_1_corrected(num: u64) -> u64 {
    eq_7_1(num, |half, p| {
        (half as i64 - 3 * p as i64 + 1).max(0) as u64
    })
}

fn eq_7_1(num: u64, extra: impl Fn(u64, u64) -> u64) -> u64 {
    let half = num / 2;
    if half < 2 {
        return 0;
    }
    let levels = 63 - u64::from(half.leading_zeros());
    let p = 1u64 << (levels - 1);
    2 * ((p - 1) + extra(half, p))
}

/// Nodes in the subtree of heap node `j` in a heap of `n` nodes, by walking its levels: the
/// brute-force reference for [`complete_split`]. `O(log n)`.
pub fn heap_subtree_nodes(j: u64, n: u64) -> u64 {
    let (mut lo, mut hi, mut count) = (j, j, 0);
    while lo < n {
        count += hi.min(n - 1) - lo + 1;
        lo = 2 * lo + 1;
        hi = 2 * hi + 2;
    }
    count
}

/// True if the subtree of heap node `j` contains node `k`.
pub(crate) fn heap_contains(j: u64, k: u64) -> bool {
    let (mut lo, mut hi) = (j, j);
    while lo <= k {
        if k <= hi {
            return true;
        }
        lo = 2 * lo + 1;
        hi = 2 * hi + 2;
    }
    false
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn small_trees() {
        assert_eq!(complete_split(1), (0, 0));
        assert_eq!(complete_split(2), (1, 0));
        assert_eq!(complete_split(3), (1, 1));
        assert_eq!(complete_split(4), (2, 1));
        assert_eq!(complete_split(6), (3, 2));
        assert_eq!(complete_split(7), (3, 3));
        assert_eq!(complete_split(8), (4, 3));
        assert!(heap_contains(1, 3) && heap_contains(1, 8) && !heap_contains(1, 5));
    }

    #[test]
    fn figure_7_4_example() {
        // 12 triangles, 6 nodes: after the root's pair, 6 go left and 4 right (Fig. 7.4:
        // splits (2, 6) and (8, 4)); the printed formula sends 2 right.
        assert_eq!(eq_7_1_corrected(12), 4);
        assert_eq!(12 - 2 - eq_7_1_corrected(12), 6);
        assert_eq!(eq_7_1_printed(12), 2);
    }
}
