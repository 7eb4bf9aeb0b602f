//! The part file: what one slice of a render (or a checkpoint) computed, with everything needed
//! to tell whether slices belong together.
//!
//! Layout: the magic `RTPART\r\n` (the CR LF pair catches text-mode mangling); the header's
//! length (`u32`, little-endian) and the header as JSON ([`PartHeader`]); the sums' length
//! (`u64`) and the film's exact sums ([`rt_film::Film::encode_sums`]); the SHA-256 of
//! everything before it. Lengths are checked against the bytes actually present before
//! anything is allocated, and the checksum before anything is parsed.

use rt_film::{AovSet, FilmBuffers, Rect};
use serde::{Deserialize, Serialize};
use sha2::{Digest, Sha256};
use std::collections::BTreeMap;
use std::ops::Range;
use std::path::Path;

/// First bytes of every part file.
pub const MAGIC: &[u8; 8] = b"RTPART\r\n";
/// Version of the layout and of the header's meaning (2: the header holds the render's typed
/// job, not its command line).
pub const FORMAT: u32 = 2;
/// Largest image side a part may describe ([`rt_core::limits::MAX_IMAGE_SIDE`]).
pub const MAX_SIDE: u32 = rt_core::limits::MAX_IMAGE_SIDE;
/// Largest header accepted, in bytes.
const MAX_HEADER: u32 = 1 << 20;

/// What a part file holds: a slice of a render, or a render's state to resume from.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum PartKind {
    /// Samples `samples` of the pixels in `region` (`render --sample-range/--region`).
    Part,
    /// The samples `0..samples.end` of every pixel a render took before it stopped
    /// (`render --checkpoint`).
    Checkpoint,
}

/// Everything about a part except its sums. Parts merge only if every field but `kind`,
/// `region`, `samples`, `job` and `seconds` is equal.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PartHeader {
    /// [`FORMAT`].
    pub format: u32,
    /// Part or checkpoint.
    pub kind: PartKind,
    /// The renderer that wrote it ([`crate::binary_id`]): other builds may round differently.
    pub binary: String,
    /// The scene as the command line named it (for messages only).
    pub scene: String,
    /// SHA-256 of the content of every file the scene read ([`crate::content_hash`]).
    pub scene_hash: String,
    /// Every setting that changes the image's bits, by name (the caller's vocabulary).
    pub settings: BTreeMap<String, String>,
    /// Frame of a sequence, if any.
    pub frame: Option<u32>,
    /// Image width.
    pub width: u32,
    /// Image height.
    pub height: u32,
    /// Samples per pixel of the whole render.
    pub spp: u32,
    /// The pixels this part rendered: `[x0, y0, x1, y1]`.
    pub region: [u32; 4],
    /// The sample indices it rendered: `[start, end]`.
    pub samples: [u32; 2],
    /// Film outputs kept (AOV names, [`AovSet::names`]).
    pub aovs: Vec<String>,
    /// Whether the film keeps sums of squares.
    pub variance: bool,
    /// Whether the film keeps the even samples' sums.
    pub halves: bool,
    /// The render job that wrote it, as JSON with its own format version (`rt_session`'s
    /// `RenderJob::to_json`): what a checkpoint resumes and a merge denoises and exposes by.
    pub job: serde_json::Value,
    /// Seconds its samples took to render (a checkpoint: all of them so far).
    #[serde(default)]
    pub seconds: f64,
}

impl PartHeader {
    /// The region as a rectangle.
    pub fn rect(&self) -> Rect {
        let [x0, y0, x1, y1] = self.region;
        Rect { x0, y0, x1, y1 }
    }

    /// The sample range.
    pub fn sample_range(&self) -> Range<u32> {
        self.samples[0]..self.samples[1]
    }

    /// The film buffers the sums were taken with.
    pub fn buffers(&self) -> Result<FilmBuffers, PartError> {
        let aovs = AovSet::parse_list(self.aovs.iter().map(String::as_str))
            .map_err(|e| PartError::Header(e.to_string()))?;
        let mut b = FilmBuffers::for_outputs(aovs);
        b.variance |= self.variance;
        b.halves |= self.halves;
        Ok(b)
    }

    /// Checks the fields against each other (a header from a file is not trusted).
    pub fn validate(&self) -> Result<(), PartError> {
        let bad = |m: String| Err(PartError::Header(m));
        if self.format != FORMAT {
            return bad(format!(
                "format {} (this renderer reads {FORMAT})",
                self.format
            ));
        }
        if !(1..=MAX_SIDE).contains(&self.width) || !(1..=MAX_SIDE).contains(&self.height) {
            return bad(format!("image size {}x{}", self.width, self.height));
        }
        if !self.rect().is_inside(self.width, self.height) {
            return bad(format!(
                "region {} is empty or outside the {}x{} image",
                self.rect(),
                self.width,
                self.height
            ));
        }
        let [a, b] = self.samples;
        if a >= b || b > self.spp {
            return bad(format!("sample range {a}..{b} of {} spp", self.spp));
        }
        if self.kind == PartKind::Checkpoint
            && (a != 0 || self.rect() != Rect::full(self.width, self.height))
        {
            return bad("a checkpoint must hold samples from 0 of every pixel".into());
        }
        self.buffers().map(|_| ())
    }
}

/// A part file read back: its header and the film's encoded sums.
#[derive(Clone, Debug)]
pub struct Part {
    /// The header.
    pub header: PartHeader,
    /// [`rt_film::Film::encode_sums`] of the region.
    pub sums: Vec<u8>,
}

/// Why a part file could not be written or read.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum PartError {
    /// Reading or writing failed.
    #[error("{0}")]
    Io(String),
    /// Not a part file, or cut short.
    #[error("not a part file ({0})")]
    Format(String),
    /// The checksum does not match: the file was damaged.
    #[error("damaged: its checksum does not match its content")]
    Checksum,
    /// The header is malformed or inconsistent.
    #[error("bad header: {0}")]
    Header(String),
}

impl Part {
    /// The file's bytes.
    pub fn to_bytes(&self) -> Vec<u8> {
        let header = serde_json::to_vec_pretty(&self.header).expect("a header serializes");
        let mut out = Vec::with_capacity(8 + 4 + header.len() + 8 + self.sums.len() + 32);
        out.extend_from_slice(MAGIC);
        out.extend_from_slice(&(header.len() as u32).to_le_bytes());
        out.extend_from_slice(&header);
        out.extend_from_slice(&(self.sums.len() as u64).to_le_bytes());
        out.extend_from_slice(&self.sums);
        let digest = Sha256::digest(&out);
        out.extend_from_slice(&digest);
        out
    }

    /// Parses a part file's bytes: magic, lengths, checksum, then the header, validated.
    pub fn from_bytes(bytes: &[u8]) -> Result<Part, PartError> {
        let short = || PartError::Format("cut short".into());
        if bytes.len() < MAGIC.len() || &bytes[..MAGIC.len()] != MAGIC {
            return Err(PartError::Format("no RTPART magic".into()));
        }
        if bytes.len() < 8 + 4 + 8 + 32 {
            return Err(short());
        }
        let (body, digest) = bytes.split_at(bytes.len() - 32);
        let header_len = u32::from_le_bytes(body[8..12].try_into().expect("4 bytes"));
        if header_len > MAX_HEADER || 12 + header_len as usize + 8 > body.len() {
            return Err(short());
        }
        let h_end = 12 + header_len as usize;
        let sums_len = u64::from_le_bytes(body[h_end..h_end + 8].try_into().expect("8 bytes"));
        if sums_len != (body.len() - h_end - 8) as u64 {
            return Err(short());
        }
        if Sha256::digest(body).as_slice() != digest {
            return Err(PartError::Checksum);
        }
        let header: PartHeader = serde_json::from_slice(&body[12..h_end])
            .map_err(|e| PartError::Header(e.to_string()))?;
        header.validate()?;
        Ok(Part {
            header,
            sums: body[h_end + 8..].to_vec(),
        })
    }

    /// Reads and checks a part file.
    pub fn read(path: &Path) -> Result<Part, PartError> {
        let bytes = std::fs::read(path).map_err(|e| PartError::Io(format!("cannot read: {e}")))?;
        Part::from_bytes(&bytes)
    }

    /// Writes the part atomically (a temporary file renamed into place), so that a part a
    /// scheduler runs again replaces the old file whole, and a reader never sees half of one.
    pub fn write(&self, path: &Path) -> Result<(), PartError> {
        rt_film::write_bytes_atomic(path, &self.to_bytes())
            .map_err(|e| PartError::Io(e.to_string()))
    }
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;

    pub(crate) fn header() -> PartHeader {
        PartHeader {
            format: FORMAT,
            kind: PartKind::Part,
            binary: "b".into(),
            scene: "s.toml".into(),
            scene_hash: "h".into(),
            settings: [("integrator".to_string(), "path".to_string())].into(),
            frame: None,
            width: 4,
            height: 3,
            spp: 8,
            region: [0, 0, 4, 3],
            samples: [0, 8],
            aovs: vec!["albedo".into()],
            variance: true,
            halves: false,
            job: serde_json::json!({"format": 1, "job": {}}),
            seconds: 1.5,
        }
    }

    #[test]
    fn round_trip_and_damage() {
        let part = Part {
            header: header(),
            sums: vec![1, 2, 3],
        };
        let bytes = part.to_bytes();
        let back = Part::from_bytes(&bytes).unwrap();
        assert_eq!(
            (back.header, back.sums),
            (part.header.clone(), part.sums.clone())
        );
        for cut in [0, 7, 8, 20, bytes.len() - 1] {
            assert!(Part::from_bytes(&bytes[..cut]).is_err(), "{cut}");
        }
        let mut flipped = bytes.clone();
        let k = 30; // inside the header
        flipped[k] ^= 1;
        assert!(matches!(
            Part::from_bytes(&flipped),
            Err(PartError::Checksum)
        ));
        let mut h = header();
        h.samples = [3, 9];
        assert!(h.validate().is_err());
        h = header();
        h.region = [2, 0, 5, 3];
        assert!(h.validate().is_err());
        h = header();
        h.aovs = vec!["bogus".into()];
        assert!(h.validate().is_err());
        h = header();
        h.width = 0;
        assert!(h.validate().is_err());
    }
}
