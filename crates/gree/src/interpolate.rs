//! Dense error maps from the sparse cache errors (thesis §5.1.3): one Delaunay triangulation
//! of the cache pixels, piecewise-linear interpolation inside each triangle, reused for every
//! filter.
//!
//! [`Interpolator::new`] triangulates once and stores, for every pixel, three cache indices
//! and barycentric weights; [`Interpolator::apply`] then turns one filter's sparse errors into
//! a dense map in a single pass, so m filters cost one triangulation and m cheap passes.
//!
//! Hull padding (not in the thesis; the thesis does not say how it covers pixels outside the
//! caches' convex hull): the image corners and border pixels every `≈ sqrt(pixels/caches)`
//! that lie strictly outside the hull become pseudo-caches carrying the value of their
//! nearest cache. They are triangulated together with the caches in a *constrained*
//! triangulation whose constraints are the caches' hull edges, so inside the hull the
//! triangles are exactly the Delaunay triangles of the caches alone: the interpolant is exact
//! at the caches and reproduces linear functions inside the hull. Pixel centres are the integer
//! points (x, y), so the inside test and barycentric numerators are exact integer arithmetic.
//! When the caches are all collinear there is no hull; the padding is then triangulated
//! without constraints, and any pixel still uncovered (a one-pixel-high image) takes its
//! nearest cache's value.

use rayon::prelude::*;
use spade::{
    ConstrainedDelaunayTriangulation, DelaunayTriangulation, HasPosition, Point2,
    PositionInTriangulation, Triangulation,
};

/// A triangulation vertex: a pixel and the cache whose value it carries.
#[derive(Clone, Copy, Debug)]
struct Site {
    x: i64,
    y: i64,
    cache: u32,
}

impl HasPosition for Site {
    type Scalar = f64;
    fn position(&self) -> Point2<f64> {
        Point2::new(self.x as f64, self.y as f64)
    }
}

/// Per-pixel barycentric weights over the caches, built once per cache set.
#[derive(Clone, Debug)]
pub struct Interpolator {
    width: usize,
    height: usize,
    caches: usize,
    index: Vec<[u32; 3]>,
    weight: Vec<[f32; 3]>,
    pseudo_caches: usize,
}

/// Why the triangulation could not be built.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum InterpolateError {
    /// No cache pixels.
    #[error("no caches to interpolate")]
    NoCaches,
    /// A cache outside the image.
    #[error("cache ({x}, {y}) is outside the {width}x{height} image")]
    OutOfBounds {
        /// Column.
        x: u32,
        /// Row.
        y: u32,
        /// Image width.
        width: usize,
        /// Image height.
        height: usize,
    },
    /// The same pixel twice.
    #[error("cache ({x}, {y}) is given twice")]
    Duplicate {
        /// Column.
        x: u32,
        /// Row.
        y: u32,
    },
    /// spade rejected a vertex (cannot happen for pixel coordinates; kept typed).
    #[error("triangulation failed: {0}")]
    Triangulation(String),
}

impl Interpolator {
    /// Triangulates `caches` (distinct pixels of a `width × height` image) and builds the
    /// weights of every pixel.
    pub fn new(
        width: usize,
        height: usize,
        caches: &[(u32, u32)],
    ) -> Result<Self, InterpolateError> {
        if caches.is_empty() {
            return Err(InterpolateError::NoCaches);
        }
        let mut cache_at = vec![u32::MAX; width * height];
        for (k, &(x, y)) in caches.iter().enumerate() {
            if x as usize >= width || y as usize >= height {
                return Err(InterpolateError::OutOfBounds {
                    x,
                    y,
                    width,
                    height,
                });
            }
            let slot = &mut cache_at[y as usize * width + x as usize];
            if *slot != u32::MAX {
                return Err(InterpolateError::Duplicate { x, y });
            }
            *slot = k as u32;
        }
        let sites: Vec<Site> = caches
            .iter()
            .enumerate()
            .map(|(k, &(x, y))| Site {
                x: x as i64,
                y: y as i64,
                cache: k as u32,
            })
            .collect();
        let terr = |e: spade::InsertionError| InterpolateError::Triangulation(e.to_string());
        let dt = DelaunayTriangulation::<Site>::bulk_load(sites.clone()).map_err(terr)?;

        // Pseudo-caches on the border, strictly outside the caches' hull.
        let step = ((width * height) as f64 / caches.len() as f64)
            .sqrt()
            .round()
            .max(1.0) as usize;
        let mut border = Vec::new();
        let push_line =
            |border: &mut Vec<(usize, usize)>, len: usize, f: &dyn Fn(usize) -> (usize, usize)| {
                let mut i = 0;
                while i < len {
                    border.push(f(i));
                    i += step;
                }
                if len > 0 {
                    border.push(f(len - 1));
                }
            };
        let (w1, h1) = (width - 1, height - 1);
        push_line(&mut border, width, &|i| (i, 0));
        push_line(&mut border, width, &|i| (i, h1));
        push_line(&mut border, height, &|i| (0, i));
        push_line(&mut border, height, &|i| (w1, i));
        border.sort_unstable();
        border.dedup();
        let hull = dt.num_inner_faces() > 0;
        let mut padded = sites;
        for &(x, y) in &border {
            if cache_at[y * width + x] != u32::MAX {
                continue;
            }
            let pos = Point2::new(x as f64, y as f64);
            if hull
                && !matches!(
                    dt.locate(pos),
                    PositionInTriangulation::OutsideOfConvexHull(_)
                )
            {
                continue;
            }
            if let Some(v) = dt.nearest_neighbor(pos) {
                padded.push(Site {
                    x: x as i64,
                    y: y as i64,
                    cache: v.data().cache,
                });
            }
        }
        let pseudo_caches = padded.len() - caches.len();

        let mut this = Self {
            width,
            height,
            caches: caches.len(),
            index: vec![[0; 3]; width * height],
            weight: vec![[0.0; 3]; width * height],
            pseudo_caches,
        };
        let mut covered = vec![false; width * height];
        if hull {
            // The hull edges, by cache index (the bulk load keeps the vertex order).
            let edges: Vec<[usize; 2]> = dt
                .convex_hull()
                .map(|e| {
                    let [a, b] = e.vertices();
                    [a.data().cache as usize, b.data().cache as usize]
                })
                .collect();
            let cdt = ConstrainedDelaunayTriangulation::<Site>::bulk_load_cdt(padded, edges)
                .map_err(terr)?;
            this.rasterise(&cdt, &mut covered);
        } else {
            let t = DelaunayTriangulation::<Site>::bulk_load(padded).map_err(terr)?;
            this.rasterise(&t, &mut covered);
        }
        // Fallbacks: pixels no triangle covers (collinear sites) take the nearest cache.
        for (p, c) in covered.iter().enumerate() {
            if !*c {
                let pos = Point2::new((p % width) as f64, (p / width) as f64);
                let k = dt.nearest_neighbor(pos).map_or(0, |v| v.data().cache);
                this.index[p] = [k; 3];
                this.weight[p] = [1.0, 0.0, 0.0];
            }
        }
        // Exactly the cache's own value at a cache.
        for (p, &k) in cache_at.iter().enumerate() {
            if k != u32::MAX {
                this.index[p] = [k; 3];
                this.weight[p] = [1.0, 0.0, 0.0];
            }
        }
        Ok(this)
    }

    /// Writes the weights of every pixel inside a face of `t` that no earlier face covered.
    fn rasterise<T>(&mut self, t: &T, covered: &mut [bool])
    where
        T: Triangulation<Vertex = Site>,
    {
        let (w, h) = (self.width as i64, self.height as i64);
        for face in t.inner_faces() {
            let [a, b, c] = face.vertices().map(|v| *v.data());
            let det = (b.x - a.x) * (c.y - a.y) - (c.x - a.x) * (b.y - a.y);
            if det == 0 {
                continue;
            }
            let s = det.signum();
            let inv = 1.0 / det as f64;
            let (x0, x1) = (
                a.x.min(b.x).min(c.x).max(0),
                a.x.max(b.x).max(c.x).min(w - 1),
            );
            let (y0, y1) = (
                a.y.min(b.y).min(c.y).max(0),
                a.y.max(b.y).max(c.y).min(h - 1),
            );
            for py in y0..=y1 {
                for px in x0..=x1 {
                    let p = (py * w + px) as usize;
                    if covered[p] {
                        continue;
                    }
                    let nb = (px - a.x) * (c.y - a.y) - (c.x - a.x) * (py - a.y);
                    let nc = (b.x - a.x) * (py - a.y) - (px - a.x) * (b.y - a.y);
                    let na = det - nb - nc;
                    if na * s < 0 || nb * s < 0 || nc * s < 0 {
                        continue;
                    }
                    covered[p] = true;
                    self.index[p] = [a.cache, b.cache, c.cache];
                    self.weight[p] = [
                        (na as f64 * inv) as f32,
                        (nb as f64 * inv) as f32,
                        (nc as f64 * inv) as f32,
                    ];
                }
            }
        }
    }

    /// Width of the image.
    pub fn width(&self) -> usize {
        self.width
    }

    /// Height of the image.
    pub fn height(&self) -> usize {
        self.height
    }

    /// How many border pseudo-caches the hull padding added.
    pub fn pseudo_caches(&self) -> usize {
        self.pseudo_caches
    }

    /// The dense map, row-major, from one value per cache (in the caches' order).
    ///
    /// # Panics
    /// If `values` has not one value per cache.
    pub fn apply(&self, values: &[f32]) -> Vec<f32> {
        assert_eq!(values.len(), self.caches, "one value per cache");
        let mut out = vec![0.0; self.index.len()];
        out.par_chunks_mut(self.width.max(1))
            .enumerate()
            .for_each(|(y, row)| {
                let base = y * self.width;
                for (x, o) in row.iter_mut().enumerate() {
                    let (i, w) = (self.index[base + x], self.weight[base + x]);
                    *o = w[0] * values[i[0] as usize]
                        + w[1] * values[i[1] as usize]
                        + w[2] * values[i[2] as usize];
                }
            });
        out
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::placement::blue_noise;

    fn check_exact_and_linear(w: usize, h: usize, caches: &[(u32, u32)]) {
        let interp = Interpolator::new(w, h, caches).unwrap();
        // Exact at the caches, for arbitrary values.
        let values: Vec<f32> = (0..caches.len())
            .map(|k| ((k * 7919) % 101) as f32 * 0.37)
            .collect();
        let dense = interp.apply(&values);
        for (k, &(x, y)) in caches.iter().enumerate() {
            assert_eq!(dense[y as usize * w + x as usize], values[k], "cache {k}");
        }
        // Linear functions reproduced inside the caches' hull.
        let f = |x: f64, y: f64| 0.5 + 0.25 * x - 0.125 * y;
        let values: Vec<f32> = caches
            .iter()
            .map(|&(x, y)| f(x as f64, y as f64) as f32)
            .collect();
        let dense = interp.apply(&values);
        let dt = DelaunayTriangulation::<Point2<f64>>::bulk_load(
            caches
                .iter()
                .map(|&(x, y)| Point2::new(x as f64, y as f64))
                .collect(),
        )
        .unwrap();
        let mut inside = 0;
        for y in 0..h {
            for x in 0..w {
                let pos = Point2::new(x as f64, y as f64);
                if matches!(
                    dt.locate(pos),
                    PositionInTriangulation::OutsideOfConvexHull(_)
                ) {
                    continue;
                }
                inside += 1;
                let want = f(x as f64, y as f64);
                let got = dense[y * w + x] as f64;
                assert!(
                    (got - want).abs() <= 1e-5 * (1.0 + want.abs()),
                    "({x},{y}) {got} {want}"
                );
            }
        }
        assert!(inside > w * h / 2);
        // Every pixel is covered (finite, between min and max of the values).
        let (lo, hi) = values
            .iter()
            .fold((f32::MAX, f32::MIN), |(a, b), &v| (a.min(v), b.max(v)));
        for &d in &dense {
            assert!(d >= lo - 1e-4 && d <= hi + 1e-4);
        }
    }

    #[test]
    fn exact_at_caches_and_linear_inside_the_hull() {
        check_exact_and_linear(64, 40, &blue_noise(64, 40, 120, 1));
        check_exact_and_linear(50, 50, &blue_noise(50, 50, 30, 2));
        // Caches on a regular grid: many co-circular quadruples.
        let grid: Vec<_> = (0..8)
            .flat_map(|y| (0..8).map(move |x| (3 + 5 * x, 2 + 5 * y)))
            .collect();
        check_exact_and_linear(45, 45, &grid);
    }

    #[test]
    fn hull_padding_takes_the_nearest_cache() {
        let interp = Interpolator::new(21, 21, &[(10, 10), (11, 10), (10, 11)]).unwrap();
        assert!(interp.pseudo_caches() >= 4);
        let dense = interp.apply(&[1.0, 2.0, 3.0]);
        assert_eq!(dense[0], 1.0); // corner (0, 0): nearest is (10, 10)
        assert_eq!(dense[20 * 21], 3.0); // (0, 20): nearest is (10, 11)
        assert_eq!(dense[20], 2.0); // (20, 0): nearest is (11, 10)
        assert!(dense.iter().all(|v| v.is_finite()));
    }

    #[test]
    fn degenerate_cases() {
        // One cache: constant.
        let i = Interpolator::new(5, 4, &[(2, 2)]).unwrap();
        assert!(i.apply(&[3.0]).iter().all(|&v| v == 3.0));
        // A one-pixel-high image: collinear caches, nearest fallback where uncovered.
        let i = Interpolator::new(9, 1, &[(1, 0), (7, 0)]).unwrap();
        let d = i.apply(&[0.0, 6.0]);
        assert_eq!((d[1], d[7]), (0.0, 6.0));
        assert!(d.iter().all(|v| v.is_finite()));
        assert!(matches!(
            Interpolator::new(3, 3, &[(1, 1), (1, 1)]),
            Err(InterpolateError::Duplicate { .. })
        ));
        assert!(matches!(
            Interpolator::new(3, 3, &[]),
            Err(InterpolateError::NoCaches)
        ));
    }
}
