//! The reference the tree is checked against: the definitions, item by item.

use super::{check_items, distance_squared, radius_bound, Neighbour, PointError, PointItem};
use glam::Vec3;

/// Answers every query of [`PointKdTree`](super::PointKdTree) by looking at every item. It
/// allocates its results and is only meant as the oracle of tests and benchmarks.
#[derive(Clone, Debug, Default)]
pub struct BruteForcePoints {
    items: Vec<PointItem>,
}

impl BruteForcePoints {
    /// Copies `items`.
    ///
    /// # Errors
    ///
    /// The same bad items as [`PointKdTree::build`](super::PointKdTree::build).
    pub fn new(items: &[PointItem]) -> Result<Self, PointError> {
        check_items(items)?;
        Ok(Self {
            items: items.to_vec(),
        })
    }

    /// Every item within `max_radius` (all for `None`), sorted, truncated to `k`.
    pub fn nearest_k(&self, q: Vec3, k: usize, max_radius: Option<f32>) -> Vec<Neighbour> {
        let Ok(bound) = radius_bound(max_radius) else {
            return Vec::new();
        };
        let mut all = self.within_squared(q, bound);
        all.sort_unstable();
        all.truncate(k);
        all
    }

    /// Every item with `|p - q| <= radius`, sorted.
    pub fn within(&self, q: Vec3, radius: f32) -> Vec<Neighbour> {
        let Ok(bound) = radius_bound(Some(radius)) else {
            return Vec::new();
        };
        let mut all = self.within_squared(q, bound);
        all.sort_unstable();
        all
    }

    /// The smallest (distance, payload) among items whose own radius covers `q`.
    pub fn nearest_covering(&self, q: Vec3) -> Option<Neighbour> {
        if !q.is_finite() {
            return None;
        }
        self.items
            .iter()
            .filter_map(|it| {
                let dist2 = distance_squared(it.point, q);
                (dist2 <= it.radius * it.radius).then_some(Neighbour {
                    dist2,
                    payload: it.payload,
                })
            })
            .min()
    }

    fn within_squared(&self, q: Vec3, bound: f32) -> Vec<Neighbour> {
        if !q.is_finite() {
            return Vec::new();
        }
        self.items
            .iter()
            .map(|it| Neighbour {
                dist2: distance_squared(it.point, q),
                payload: it.payload,
            })
            .filter(|n| n.dist2 <= bound)
            .collect()
    }
}
