//! The `.bin` ray file format: six little-endian `f32` per ray (origin xyz, direction xyz), no
//! header. Closest-hit sets are queried over (0, ∞); occlusion sets (`shadow.bin`) over (0, 1),
//! their direction reaching the light point.

use super::sets::{Generated, Query, RaySet};
use rt_core::{glam::Vec3, Ray};
use std::path::{Path, PathBuf};

/// Bytes per ray in ray files: six little-endian f32.
pub const RAY_BYTES: usize = 24;

/// What is wrong with the bytes of a ray file.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum FormatError {
    /// No rays at all.
    #[error("the ray file is empty")]
    Empty,
    /// The length is not a whole number of rays (a truncated or foreign file).
    #[error(
        "file size {len} bytes is not a multiple of {RAY_BYTES} (six little-endian f32 per ray: \
         origin xyz, direction xyz)"
    )]
    Size {
        /// The length in bytes.
        len: usize,
    },
    /// A NaN or infinite coordinate.
    #[error("ray {index} has a non-finite value: {values:?}")]
    NonFinite {
        /// Ray index in the file.
        index: usize,
        /// Its six values.
        values: [f32; 6],
    },
    /// A zero direction, which no query accepts.
    #[error("ray {index} has a zero direction")]
    ZeroDirection {
        /// Ray index in the file.
        index: usize,
    },
}

/// A ray file that cannot be read or written.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum RayFileError {
    /// The file system refused.
    #[error("{}: {source}", path.display())]
    Io {
        /// The file or directory.
        path: PathBuf,
        /// Why.
        #[source]
        source: std::io::Error,
    },
    /// The file's bytes are not a ray file.
    #[error("{}: {source}", path.display())]
    Format {
        /// The file.
        path: PathBuf,
        /// What is wrong.
        #[source]
        source: FormatError,
    },
}

/// The bytes of a ray file holding `rays`.
pub fn encode(rays: &[Ray]) -> Vec<u8> {
    let mut bytes = Vec::with_capacity(rays.len() * RAY_BYTES);
    for r in rays {
        for x in r.origin.to_array().into_iter().chain(r.dir.to_array()) {
            bytes.extend_from_slice(&x.to_le_bytes());
        }
    }
    bytes
}

/// The rays of a ray file's bytes: a whole, non-zero number of rays, every value finite, no
/// zero direction.
pub fn decode(bytes: &[u8]) -> Result<Vec<Ray>, FormatError> {
    if bytes.is_empty() {
        return Err(FormatError::Empty);
    }
    if !bytes.len().is_multiple_of(RAY_BYTES) {
        return Err(FormatError::Size { len: bytes.len() });
    }
    bytes
        .chunks_exact(RAY_BYTES)
        .enumerate()
        .map(|(index, rec)| {
            let mut values = [0f32; 6];
            for (v, b) in values.iter_mut().zip(rec.chunks_exact(4)) {
                *v = f32::from_le_bytes([b[0], b[1], b[2], b[3]]);
            }
            if values.iter().any(|x| !x.is_finite()) {
                return Err(FormatError::NonFinite { index, values });
            }
            let dir = Vec3::new(values[3], values[4], values[5]);
            if dir == Vec3::ZERO {
                return Err(FormatError::ZeroDirection { index });
            }
            Ok(Ray::new(Vec3::new(values[0], values[1], values[2]), dir))
        })
        .collect()
}

/// Reads a ray file.
pub fn read_rays(path: &Path) -> Result<Vec<Ray>, RayFileError> {
    let bytes = std::fs::read(path).map_err(|source| RayFileError::Io {
        path: path.to_owned(),
        source,
    })?;
    decode(&bytes).map_err(|source| RayFileError::Format {
        path: path.to_owned(),
        source,
    })
}

/// Reads a ray file as a set called `name`, traced with `query`.
pub fn read_set(path: &Path, name: &'static str, query: Query) -> Result<RaySet, RayFileError> {
    Ok(RaySet {
        name,
        rays: read_rays(path)?,
        query,
    })
}

/// Writes a ray file.
pub fn write_rays(path: &Path, rays: &[Ray]) -> Result<(), RayFileError> {
    std::fs::write(path, encode(rays)).map_err(|source| RayFileError::Io {
        path: path.to_owned(),
        source,
    })
}

/// Writes `DIR/NAME.bin` for each of the four sets (creating `DIR`).
pub fn dump(dir: &Path, sets: &Generated) -> Result<(), RayFileError> {
    std::fs::create_dir_all(dir).map_err(|source| RayFileError::Io {
        path: dir.to_owned(),
        source,
    })?;
    for set in sets.sets() {
        write_rays(&dir.join(format!("{}.bin", set.name)), &set.rays)?;
    }
    Ok(())
}
