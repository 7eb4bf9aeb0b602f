//! The results: an aligned table on stdout and a CSV file.

use anyhow::Result;
use rt_core::TraversalCounters;
use std::path::Path;

/// The CSV header. The first ten columns are the interface of issue 3; the rest are extras.
pub const CSV_HEADER: &str = "accel,rays,threads,build_ms,bytes,mrays_per_s,hits,boxes_per_ray,\
leaves_per_ray,tris_per_ray,scene,triangles,bytes_per_tri,ray_count,seconds,check_mismatches,\
check_ties,structure_bytes,structure_bytes_per_tri";

/// One measurement: a structure, a ray set, a thread count.
pub struct Row {
    /// Canonical spec of the structure.
    pub accel: String,
    /// Name of the ray set.
    pub rays: String,
    pub threads: usize,
    /// Build time of the structure (one build, on the parallel pool).
    pub build_ms: f64,
    /// `Accel::memory_bytes` after the runs.
    pub bytes: usize,
    /// `Accel::structure_bytes` after the runs: the part of `bytes` beyond one copy of the
    /// triangles' vertices.
    pub structure_bytes: Option<usize>,
    /// Rays in the set.
    pub ray_count: usize,
    /// Best time over the repetitions.
    pub seconds: f64,
    /// Rays that hit (closest-hit sets) or were occluded (occlusion sets).
    pub hits: u64,
    /// Traversal work of one counted pass, if the structure counts.
    pub counters: Option<TraversalCounters>,
    pub triangles: usize,
    pub scene: String,
    /// Check against the binary BVH (per structure).
    pub mismatches: usize,
    pub ties: usize,
}

impl Row {
    fn mrays(&self) -> f64 {
        self.ray_count as f64 / self.seconds / 1e6
    }

    fn per_ray(&self, f: impl Fn(&TraversalCounters) -> u64) -> Option<f64> {
        self.counters
            .as_ref()
            .map(|c| f(c) as f64 / self.ray_count.max(1) as f64)
    }

    fn bytes_per_tri(&self) -> f64 {
        self.bytes as f64 / self.triangles.max(1) as f64
    }

    fn structure_per_tri(&self) -> Option<f64> {
        self.structure_bytes
            .map(|b| b as f64 / self.triangles.max(1) as f64)
    }

    /// Mrays/s relative to the first structure's on the same set and thread count.
    fn speedup(&self, rows: &[Row]) -> Option<f64> {
        let first = &rows.first()?.accel;
        let base = rows
            .iter()
            .find(|r| &r.accel == first && r.rays == self.rays && r.threads == self.threads)?;
        Some(self.mrays() / base.mrays())
    }
}

fn opt(v: Option<f64>, decimals: usize) -> String {
    v.map_or_else(|| "-".to_string(), |v| format!("{v:.decimals$}"))
}

/// Prints the table: build time and memory on each structure's first row, then per set and
/// thread count the speed, the hits and the traversal work per ray.
pub fn print_table(rows: &[Row], threads: usize) {
    let Some(first) = rows.first() else {
        return;
    };
    println!(
        "{}: {} triangles; Mrays/s best of the repetitions, on 1 and {threads} threads",
        first.scene, first.triangles
    );
    let header = [
        "accel",
        "build ms",
        "MiB",
        "B/tri",
        "struct B/tri",
        "rays",
        "count",
        "threads",
        "Mrays/s",
        "speedup",
        "hits %",
        "boxes/ray",
        "leaves/ray",
        "tris/ray",
    ];
    let mut cells: Vec<Vec<String>> = vec![header.iter().map(|s| s.to_string()).collect()];
    let mut last_accel = "";
    for r in rows {
        let new_accel = r.accel != last_accel;
        last_accel = &r.accel;
        let once = |s: String| if new_accel { s } else { String::new() };
        cells.push(vec![
            once(r.accel.clone()),
            once(format!("{:.1}", r.build_ms)),
            once(format!("{:.1}", r.bytes as f64 / (1u64 << 20) as f64)),
            once(format!("{:.1}", r.bytes_per_tri())),
            once(opt(r.structure_per_tri(), 2)),
            r.rays.clone(),
            r.ray_count.to_string(),
            r.threads.to_string(),
            format!("{:.2}", r.mrays()),
            opt(r.speedup(rows), 2),
            format!("{:.1}", 100.0 * r.hits as f64 / r.ray_count.max(1) as f64),
            opt(r.per_ray(|c| c.nodes_visited), 1),
            opt(r.per_ray(|c| c.leaves_visited), 2),
            opt(r.per_ray(|c| c.prims_tested), 2),
        ]);
    }
    let widths: Vec<usize> = (0..header.len())
        .map(|i| {
            cells
                .iter()
                .map(|row| row[i].chars().count())
                .max()
                .unwrap_or(0)
        })
        .collect();
    for row in &cells {
        let line: Vec<String> = row
            .iter()
            .enumerate()
            .map(|(i, c)| {
                // Names left-aligned, numbers right-aligned.
                if i == 0 || i == 5 {
                    format!("{c:<w$}", w = widths[i])
                } else {
                    format!("{c:>w$}", w = widths[i])
                }
            })
            .collect();
        println!("{}", line.join("  ").trim_end());
    }
    println!(
        "speedup: Mrays/s over {}'s on the same rays and threads; MiB and B/tri: all the \
         structure's memory; struct B/tri: beyond one copy of the triangles (36 B each)",
        first.accel
    );
}

/// A CSV field, quoted when it needs to be.
fn field(s: &str) -> String {
    if s.contains([',', '"', '\n', '\r']) {
        format!("\"{}\"", s.replace('"', "\"\""))
    } else {
        s.to_string()
    }
}

/// Writes [`CSV_HEADER`] and one line per row; empty traversal columns when a structure does
/// not count.
pub fn write_csv(path: &Path, rows: &[Row]) -> Result<()> {
    let mut out = String::from(CSV_HEADER);
    out.push('\n');
    let num = |v: Option<f64>| v.map_or(String::new(), |v| format!("{v:.4}"));
    for r in rows {
        let line = [
            field(&r.accel),
            field(&r.rays),
            r.threads.to_string(),
            format!("{:.3}", r.build_ms),
            r.bytes.to_string(),
            format!("{:.4}", r.mrays()),
            r.hits.to_string(),
            num(r.per_ray(|c| c.nodes_visited)),
            num(r.per_ray(|c| c.leaves_visited)),
            num(r.per_ray(|c| c.prims_tested)),
            field(&r.scene),
            r.triangles.to_string(),
            format!("{:.2}", r.bytes_per_tri()),
            r.ray_count.to_string(),
            format!("{:.6}", r.seconds),
            r.mismatches.to_string(),
            r.ties.to_string(),
            r.structure_bytes.map_or(String::new(), |b| b.to_string()),
            num(r.structure_per_tri()),
        ];
        out.push_str(&line.join(","));
        out.push('\n');
    }
    rt_film::write_bytes_atomic(path, out.as_bytes()).map_err(|e| anyhow::anyhow!("{e}"))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn csv_quotes_fields_that_need_it() {
        assert_eq!(field("bvh"), "bvh");
        assert_eq!(field("a,b.obj"), "\"a,b.obj\"");
        assert_eq!(field("say \"x\""), "\"say \"\"x\"\"\"");
        assert!(CSV_HEADER.starts_with(
            "accel,rays,threads,build_ms,bytes,mrays_per_s,hits,boxes_per_ray,leaves_per_ray,tris_per_ray"
        ));
    }
}
