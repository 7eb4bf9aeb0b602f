//! What a film allocates: the optional buffers a caller asks for ([`FilmBuffers`]) and the
//! bytes each holds ([`FilmMemory`]), estimated before a render so that one that cannot fit
//! is refused before it starts.

use crate::film::EvenSums;
use crate::filtered::Weighted;
use crate::fixed::{Squares3, Sum1, Sum3};
use crate::pixel::{FeatureSquares, SplitSums};
use crate::AovSet;

/// Which per-pixel buffers a film allocates besides the mean and sample count, which it always
/// keeps. The caller fills this from what its outputs and consumers read, so that a render pays
/// only for those: the `variance` output or a z-test needs `variance`, the stopping criterion
/// and the GREE error estimates need `halves`, each first-hit AOV needs its own buffer.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct FilmBuffers {
    /// First-hit AOVs to accumulate, and which outputs will be written. Its `variance` flag
    /// implies [`FilmBuffers::variance`].
    pub aovs: AovSet,
    /// Sums of squares per pixel, for the variance of the mean (96 bytes per pixel).
    pub variance: bool,
    /// Sums and counts of the even-numbered samples, from which the odd ones follow (64 bytes
    /// per pixel).
    pub halves: bool,
    /// Every camera sample kept apart ([`SampleRecords`](crate::SampleRecords), 56 bytes per sample): radiance,
    /// first-hit guides and circle of confusion, for sample-space filters (SBMF). The render
    /// driver (`rt_integrators::render_samples`) fills them from camera samples; light-path
    /// splats belong to no pixel's samples and are not recorded.
    pub samples: bool,
}

impl FilmBuffers {
    /// The buffers needed to write `aovs` and nothing else.
    pub fn for_outputs(aovs: AovSet) -> Self {
        Self {
            aovs,
            variance: aovs.variance,
            halves: aovs.halves,
            samples: aovs.samples,
        }
    }

    /// Also keep the variance buffer (for a consumer that is not an output, e.g. a z-test).
    pub fn with_variance(mut self) -> Self {
        self.variance = true;
        self
    }

    /// Also keep the even/odd half-buffers.
    pub fn with_halves(mut self) -> Self {
        self.halves = true;
        self
    }

    /// Also keep every sample's record ([`Film::sample_records`](crate::Film::sample_records)).
    pub fn with_samples(mut self) -> Self {
        self.samples = true;
        self
    }
}

impl From<AovSet> for FilmBuffers {
    fn from(aovs: AovSet) -> Self {
        Self::for_outputs(aovs)
    }
}

/// The sums a film allocates with the first sample that needs them rather than up front: what
/// the technique and the camera will send it, known before a render starts.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct LateSums {
    /// Light-path splats (a technique whose paths start at the lights: `light`, `bdpt`).
    pub light_splats: bool,
    /// Filter-weighted sums (a camera whose pixel filter splats, `rt_core::pixel_filter`).
    pub filtered: bool,
}

impl std::ops::BitOr for LateSums {
    type Output = LateSums;

    /// The sums either makes (a merge of parts that made either).
    fn bitor(self, o: LateSums) -> LateSums {
        LateSums {
            light_splats: self.light_splats | o.light_splats,
            filtered: self.filtered | o.filtered,
        }
    }
}

/// Bytes held by each of a film's buffers (length × element size); `None` for a buffer the
/// film did not allocate.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct FilmMemory {
    /// Mean and sample count (always kept).
    pub mean: usize,
    /// Sums of squares.
    pub variance: Option<usize>,
    /// Even samples' sums and counts.
    pub halves: Option<usize>,
    /// Per-pixel count of samples with a first hit, shared by the first-hit AOVs.
    pub first_hits: Option<usize>,
    /// Albedo sums.
    pub albedo: Option<usize>,
    /// Shading-normal sums.
    pub normal: Option<usize>,
    /// Depth sums.
    pub depth: Option<usize>,
    /// Position sums.
    pub position: Option<usize>,
    /// Sums of squares of the first-hit features.
    pub feature_variance: Option<usize>,
    /// Sums of the lighting split (one buffer for all its parts).
    pub split: Option<usize>,
    /// Light-path splat sums (allocated by the first splat).
    pub splats: Option<usize>,
    /// Filter-weighted sums of a splatted pixel filter (allocated by the first band that
    /// splats; 64 bytes per pixel, twice that with half-buffers).
    pub filtered: Option<usize>,
    /// Per-sample records and their per-pixel offsets.
    pub samples: Option<usize>,
}

impl FilmMemory {
    /// What `Film::new(width, height, buffers)` holds once every pixel has
    /// `samples_per_pixel` samples (per-sample records grow with them) and the `late` sums
    /// have been made: the sizes [`Film::memory`](crate::Film::memory) reports, computed
    /// without allocating, so that a render that cannot fit is refused before it starts.
    pub fn estimate(
        width: u32,
        height: u32,
        buffers: impl Into<FilmBuffers>,
        samples_per_pixel: u64,
        late: LateSums,
    ) -> FilmMemory {
        let mut buffers = buffers.into();
        buffers.variance |= buffers.aovs.variance;
        let n = width as usize * height as usize;
        let a = buffers.aovs;
        let of = |keep: bool, element: usize| keep.then_some(n.saturating_mul(element));
        use std::mem::size_of;
        FilmMemory {
            mean: n * (size_of::<u32>() + size_of::<Sum3>()),
            variance: of(buffers.variance, size_of::<Squares3>()),
            halves: of(buffers.halves, size_of::<EvenSums>()),
            first_hits: of(a.any_first_hit(), size_of::<u32>()),
            albedo: of(a.albedo, size_of::<Sum3>()),
            normal: of(a.normal, size_of::<Sum3>()),
            depth: of(a.depth, size_of::<Sum1>()),
            position: of(a.position, size_of::<Sum3>()),
            feature_variance: of(
                a.feature_variance && a.any_first_hit(),
                size_of::<FeatureSquares>(),
            ),
            split: of(a.any_split(), size_of::<SplitSums>()),
            // The even samples' splats only with half-buffers (`SplatSums::add`).
            splats: of(
                late.light_splats,
                (1 + usize::from(buffers.halves)) * size_of::<Sum3>(),
            ),
            // The even samples' filtered sums only with half-buffers (`FilterSums::parts_mut`).
            filtered: of(
                late.filtered,
                (1 + usize::from(buffers.halves)) * size_of::<Weighted>(),
            ),
            samples: buffers.samples.then(|| {
                (n as u64)
                    .saturating_mul(samples_per_pixel)
                    .saturating_mul(crate::samples::SAMPLE_RECORD_BYTES as u64)
                    .min(usize::MAX as u64) as usize
                    + (n + 1) * size_of::<usize>()
            }),
        }
    }

    /// Bytes of all buffers together.
    pub fn total(&self) -> usize {
        self.mean
            + [
                self.variance,
                self.halves,
                self.first_hits,
                self.albedo,
                self.normal,
                self.depth,
                self.position,
                self.feature_variance,
                self.split,
                self.splats,
                self.filtered,
                self.samples,
            ]
            .iter()
            .flatten()
            .sum::<usize>()
    }
}
