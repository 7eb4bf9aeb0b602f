//! A filter bank: several denoisers run on the same frame, the input of GREE's per-pixel
//! selection (Bauszat, thesis ch. 5: every member must take the same noisy image, and may be
//! any black box).

use crate::{Channel, DenoiseError, Denoiser, DenoiserSpec, NoisyFrame};
use rt_core::RgbImage;
use std::time::{Duration, Instant};

/// The default bank: the thesis' eight filters (Gaussians of σ 2, 4, 8, 16 pixels and joint
/// bilateral filters of σ 1, 2, 4, 8 on normal, position and albedo, §5.1), plus the identity
/// (for pixels no filter improves: fine texture the caches see), the edge-avoiding À-Trous
/// filter and non-local means.
pub const DEFAULT_BANK: [&str; 11] = [
    "box:radius=0",
    "gaussian:sigma=2",
    "gaussian:sigma=4",
    "gaussian:sigma=8",
    "gaussian:sigma=16",
    "bilateral:sigma=1",
    "bilateral:sigma=2",
    "bilateral:sigma=4",
    "bilateral:sigma=8",
    "atrous:demodulate=on",
    "nlm",
];

/// Denoisers applied to one frame.
pub struct Bank {
    members: Vec<Box<dyn Denoiser>>,
}

/// What running a bank produced: one image per member, in order, and each member's time.
pub struct BankOutput {
    /// Filtered images.
    pub images: Vec<RgbImage>,
    /// Wall time of each member.
    pub times: Vec<Duration>,
}

impl Bank {
    /// A bank of the denoisers named by `specs` (at least one, each a [`DenoiserSpec`]).
    pub fn from_specs<S: AsRef<str>>(specs: &[S]) -> Result<Self, DenoiseError> {
        if specs.is_empty() {
            return Err(DenoiseError::Spec(
                "a filter bank needs at least one denoiser".into(),
            ));
        }
        let members = specs
            .iter()
            .map(|s| s.as_ref().parse::<DenoiserSpec>()?.build())
            .collect::<Result<Vec<_>, _>>()?;
        Ok(Self { members })
    }

    /// A bank file: TOML with one key, `denoisers = ["gaussian:sigma=2", ...]`. Every error
    /// names the file.
    pub fn from_file(path: &std::path::Path) -> Result<Self, DenoiseError> {
        #[derive(serde::Deserialize)]
        #[serde(deny_unknown_fields)]
        struct BankFile {
            denoisers: Vec<String>,
        }
        let at = |m: String| DenoiseError::Spec(format!("{}: {m}", path.display()));
        let text = std::fs::read_to_string(path).map_err(|e| at(e.to_string()))?;
        let file: BankFile = toml::from_str(&text).map_err(|e| at(e.message().to_string()))?;
        Self::from_specs(&file.denoisers).map_err(|e| at(e.to_string()))
    }

    /// [`DEFAULT_BANK`].
    pub fn default_gree() -> Result<Self, DenoiseError> {
        Self::from_specs(&DEFAULT_BANK)
    }

    /// The members, in order.
    pub fn members(&self) -> &[Box<dyn Denoiser>] {
        &self.members
    }

    /// Every channel some member reads.
    pub fn needs(&self) -> Vec<Channel> {
        let mut all: Vec<Channel> = Vec::new();
        for c in self.members.iter().flat_map(|m| m.needs()) {
            if !all.contains(c) {
                all.push(*c);
            }
        }
        all
    }

    /// Runs every member on `frame` (each member parallelises inside; members run one after
    /// another so their times are their own).
    pub fn apply(&self, frame: &NoisyFrame) -> Result<BankOutput, DenoiseError> {
        let mut images = Vec::with_capacity(self.members.len());
        let mut times = Vec::with_capacity(self.members.len());
        for m in &self.members {
            let t = Instant::now();
            images.push(m.denoise(frame)?);
            times.push(t.elapsed());
        }
        Ok(BankOutput { images, times })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use rt_core::{Image, Rgb};

    #[test]
    fn banks_run_every_member_and_refuse_bad_or_empty_lists() {
        let bank = Bank::from_specs(&["box:radius=0", "box:radius=1"]).unwrap();
        let frame = NoisyFrame::new(Image::from_fn(4, 3, |x, y| Rgb::splat((x * y) as f32)));
        let out = bank.apply(&frame).unwrap();
        assert_eq!(out.images.len(), 2);
        assert_eq!(out.images[0], frame.colour);
        assert_ne!(out.images[1], frame.colour);
        assert!(Bank::from_specs::<&str>(&[]).is_err());
        assert!(Bank::from_specs(&["box", "nope"]).is_err());
        assert!(bank.needs().is_empty());

        let dir = tempfile::tempdir().unwrap();
        let p = dir.path().join("bank.toml");
        std::fs::write(&p, "denoisers = [\"box:radius=0\", \"box:radius=2\"]\n").unwrap();
        assert_eq!(
            Bank::from_file(&p).unwrap().members()[1].name(),
            "box:radius=2"
        );
        std::fs::write(&p, "denoisers = [\"box:radius=99\"]\n").unwrap();
        let e = Bank::from_file(&p).err().unwrap().to_string();
        assert!(e.contains("bank.toml") && e.contains("at most 64"), "{e}");
        std::fs::write(&p, "filters = []\n").unwrap();
        assert!(Bank::from_file(&p)
            .err()
            .unwrap()
            .to_string()
            .contains("bank.toml"));
    }
}
