//! The memory check of a job ([`crate::RenderJob::max_memory`], `render --max-memory`):
//! before the structure and the film are allocated, the render's memory is estimated (film
//! buffers and per-sample records exactly, `rt_film::FilmMemory::estimate`; the structure by
//! `rt_accel::AccelKind::memory_bound`), and a render that would not fit is refused with one
//! line instead of being killed half-way. The limit is the job's, else the memory the system
//! reports available now (Linux `MemAvailable`); the scene is already loaded, so it is not
//! counted again.

use rt_accel::AccelSpec;
use rt_film::{FilmBuffers, FilmMemory, LateSums};

/// A size that does not parse, or a render that would not fit.
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
#[error("{0}")]
pub struct MemoryError(pub String);

type Result<T> = std::result::Result<T, MemoryError>;

macro_rules! bail {
    ($($t:tt)*) => { return Err(MemoryError(format!($($t)*))) };
}

/// `text` as bytes: a number with an optional binary suffix `K`, `M`, `G` or `T` (powers of
/// 1024; `KiB`, `MB` and the like read the same), e.g. `512M`, `1.5G`, `1000000`.
pub fn parse_size(text: &str) -> Result<u64> {
    let t = text.trim();
    let digits = t
        .find(|c: char| !(c.is_ascii_digit() || c == '.'))
        .unwrap_or(t.len());
    let (number, unit) = t.split_at(digits);
    let value: f64 = number
        .parse()
        .map_err(|_| MemoryError(format!("--max-memory {text}: not a size (e.g. 512M, 8G)")))?;
    let shift = match unit
        .trim()
        .to_ascii_uppercase()
        .trim_end_matches('B')
        .trim_end_matches('I')
    {
        "" => 0,
        "K" => 10,
        "M" => 20,
        "G" => 30,
        "T" => 40,
        _ => bail!("--max-memory {text}: unknown unit {unit:?} (K, M, G or T)"),
    };
    let bytes = value * (1u64 << shift) as f64;
    if !(bytes.is_finite() && bytes >= 1.0) {
        bail!("--max-memory {text}: must be at least 1 byte");
    }
    Ok(bytes.min(u64::MAX as f64) as u64)
}

/// Bytes the system reports available (`MemAvailable` of /proc/meminfo), if it says.
pub fn available() -> Option<u64> {
    let info = std::fs::read_to_string("/proc/meminfo").ok()?;
    let line = info.lines().find(|l| l.starts_with("MemAvailable:"))?;
    let kib: u64 = line.split_whitespace().nth(1)?.parse().ok()?;
    Some(kib.saturating_mul(1024))
}

/// `bytes` for people: `1.5 GiB`.
pub fn human(bytes: u64) -> String {
    let units = ["B", "KiB", "MiB", "GiB", "TiB", "PiB", "EiB"];
    let mut v = bytes as f64;
    let mut u = 0;
    while v >= 1024.0 && u + 1 < units.len() {
        v /= 1024.0;
        u += 1;
    }
    if u == 0 {
        format!("{bytes} B")
    } else {
        format!("{v:.1} {}", units[u])
    }
}

/// What a render will need, in parts.
#[derive(Clone, Copy, Debug)]
pub struct Estimate {
    /// The film's buffers (records included).
    pub film: FilmMemory,
    /// The acceleration structure, built.
    pub structure: u64,
}

impl Estimate {
    /// Film of `width × height` keeping `buffers` after `spp` samples per pixel, with the
    /// `late` sums its technique and camera will make, and `accel` over `triangles`.
    pub fn new(
        width: u32,
        height: u32,
        buffers: FilmBuffers,
        spp: u32,
        late: LateSums,
        accel: &AccelSpec,
        triangles: usize,
    ) -> Self {
        Self {
            film: FilmMemory::estimate(width, height, buffers, u64::from(spp), late),
            structure: accel.kind.memory_bound(triangles),
        }
    }

    /// All parts together.
    pub fn total(&self) -> u64 {
        (self.film.total() as u64).saturating_add(self.structure)
    }

    /// Refuses the render if it needs more than `limit` (`--max-memory` if given, else what is
    /// available now); `what` names the scene in the error.
    pub fn check(&self, what: &str, limit: Option<u64>) -> Result<()> {
        let (limit, source) = match limit {
            Some(l) => (l, "--max-memory"),
            None => match available() {
                Some(a) => (a, "the memory available now"),
                None => return Ok(()),
            },
        };
        if self.total() <= limit {
            return Ok(());
        }
        let records = self.film.samples.unwrap_or(0) as u64;
        let film = self.film.total() as u64 - records;
        let records = if records > 0 {
            format!(", per-sample records {}", human(records))
        } else {
            String::new()
        };
        bail!(
            "{what}: this render needs an estimated {} (film {}{records}, acceleration structure up to {}), more than {} ({source}); lower the resolution, the samples per pixel or the outputs, or raise --max-memory",
            human(self.total()),
            human(film),
            human(self.structure),
            human(limit),
        )
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sizes_parse_with_binary_units() {
        assert_eq!(parse_size("1000").unwrap(), 1000);
        assert_eq!(parse_size("4K").unwrap(), 4096);
        assert_eq!(parse_size("512M").unwrap(), 512 << 20);
        assert_eq!(parse_size("1.5G").unwrap(), 3 << 29);
        assert_eq!(parse_size("2GiB").unwrap(), 2 << 30);
        assert_eq!(parse_size("1 t").unwrap(), 1 << 40);
        for bad in ["", "G", "-1G", "1X", "0", "1e9"] {
            assert!(parse_size(bad).is_err(), "{bad}");
        }
        assert_eq!(human(1536 << 20), "1.5 GiB");
        assert_eq!(human(12), "12 B");
    }
}
