//! A rendering as denoisers see it: the pixel means plus whatever else the film kept, each
//! channel an image of its own type, and its EXR round trip.
//!
//! Saving a [`NoisyFrame`] and reading it back gives the same bits (every channel is written
//! as 32-bit float), so a denoising experiment can be re-run on saved frames without
//! re-rendering. The EXR layout, one channel group per [`Channel`]:
//!
//! | channel | EXR channels |
//! |---|---|
//! | colour | `R`, `G`, `B` |
//! | variance (of the mean) | `variance.{R,G,B}` |
//! | halves (even/odd samples' means) | `even.{R,G,B}`, `odd.{R,G,B}` |
//! | albedo, its variance | `albedo.{R,G,B}`, `albedo_variance.{R,G,B}` |
//! | normal, its variance | `normal.{X,Y,Z}`, `normal_variance.{X,Y,Z}` |
//! | position, its variance | `position.{X,Y,Z}`, `position_variance.{X,Y,Z}` |
//! | depth, its variance | `depth.Z`, `depth_variance.Z` |
//! | lighting split | `emission.`, `direct.`, `indirect.`, `diffuse.`, `glossy.`, `irradiance.{R,G,B}` |

use crate::output::{read_exr, ExrImage};
use crate::{AovSet, Film, FilmError, LightSplit, SampleRecords};
use rt_core::glam::Vec3;
use rt_core::{Image, Rgb};
use std::fmt;
use std::path::Path;

/// One channel of a [`NoisyFrame`].
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
#[non_exhaustive]
pub enum Channel {
    /// The pixel means (always present).
    Colour,
    /// Variance of each pixel mean.
    Variance,
    /// Means of the even- and odd-numbered samples.
    Halves,
    /// First-hit albedo.
    Albedo,
    /// Variance of the mean albedo.
    AlbedoVariance,
    /// First-hit shading normal.
    Normal,
    /// Variance of the mean normal.
    NormalVariance,
    /// First-hit world position.
    Position,
    /// Variance of the mean position.
    PositionVariance,
    /// First-hit distance from the camera.
    Depth,
    /// Variance of the mean depth.
    DepthVariance,
    /// Light seen directly.
    Emission,
    /// Light reflected once at the first hit.
    Direct,
    /// Light reflected at the first hit after further bounces.
    Indirect,
    /// Light reflected by the first hit's diffuse layers.
    Diffuse,
    /// Light reflected by the first hit's specular layers.
    Glossy,
    /// Reflected light over albedo.
    Irradiance,
    /// Every camera sample's record (for SBMF); held in memory, never in a file.
    Samples,
}

/// Components of a three-component channel group, by kind.
const RGB: [&str; 3] = ["R", "G", "B"];
const XYZ: [&str; 3] = ["X", "Y", "Z"];

impl Channel {
    /// Every channel, in file order.
    pub const ALL: [Channel; 18] = [
        Channel::Colour,
        Channel::Variance,
        Channel::Halves,
        Channel::Albedo,
        Channel::AlbedoVariance,
        Channel::Normal,
        Channel::NormalVariance,
        Channel::Position,
        Channel::PositionVariance,
        Channel::Depth,
        Channel::DepthVariance,
        Channel::Emission,
        Channel::Direct,
        Channel::Indirect,
        Channel::Diffuse,
        Channel::Glossy,
        Channel::Irradiance,
        Channel::Samples,
    ];

    /// The channel's name in messages and the prefix of its EXR channels.
    pub fn name(self) -> &'static str {
        match self {
            Channel::Colour => "colour",
            Channel::Variance => "variance",
            Channel::Halves => "halves",
            Channel::Albedo => "albedo",
            Channel::AlbedoVariance => "albedo_variance",
            Channel::Normal => "normal",
            Channel::NormalVariance => "normal_variance",
            Channel::Position => "position",
            Channel::PositionVariance => "position_variance",
            Channel::Depth => "depth",
            Channel::DepthVariance => "depth_variance",
            Channel::Emission => "emission",
            Channel::Direct => "direct",
            Channel::Indirect => "indirect",
            Channel::Diffuse => "diffuse",
            Channel::Glossy => "glossy",
            Channel::Irradiance => "irradiance",
            Channel::Samples => "samples",
        }
    }

    /// How to get this channel into a frame, for error messages: the hint of the last flag
    /// of [`crate::AOV_FLAGS`] that the channel needs (a feature's variance needs the feature
    /// and `feature-variance`, whose hint names both).
    pub fn hint(self) -> &'static str {
        crate::AOV_FLAGS
            .iter()
            .rev()
            .find(|f| f.channels.contains(&self))
            .map_or("every frame has it", |f| f.hint)
    }
}

impl fmt::Display for Channel {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

/// A frame that cannot serve: a channel is missing or has the wrong size.
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
#[non_exhaustive]
pub enum FrameError {
    /// A consumer needs a channel the frame lacks.
    #[error("{consumer} needs the {channel} channel, which the frame does not have ({hint})", hint = channel.hint())]
    Missing {
        /// Who needs it (a denoiser's name).
        consumer: String,
        /// The channel.
        channel: Channel,
    },
    /// A channel's size differs from the colour image's.
    #[error("the {channel} channel is {got:?} pixels but the colour image is {expected:?}")]
    Size {
        /// The channel.
        channel: Channel,
        /// The colour image's (width, height).
        expected: (usize, usize),
        /// The channel's.
        got: (usize, usize),
    },
}

/// A noisy rendering with its optional channels (see the module doc). Channels are plain
/// public data; [`NoisyFrame::check`] confirms they all have the colour image's size, and
/// [`NoisyFrame::require`] that a consumer's channels are there.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct NoisyFrame {
    /// Pixel means.
    pub colour: Image<Rgb>,
    /// Variance of each pixel mean.
    pub variance: Option<Image<Rgb>>,
    /// Means of the even- and odd-numbered samples.
    pub halves: Option<[Image<Rgb>; 2]>,
    /// First-hit albedo (mean over the pixel's samples that hit a surface).
    pub albedo: Option<Image<Rgb>>,
    /// Variance of the mean albedo.
    pub albedo_variance: Option<Image<Rgb>>,
    /// First-hit shading normal (mean, not renormalised).
    pub normal: Option<Image<Vec3>>,
    /// Variance of the mean normal, per component.
    pub normal_variance: Option<Image<Vec3>>,
    /// First-hit world position.
    pub position: Option<Image<Vec3>>,
    /// Variance of the mean position, per component.
    pub position_variance: Option<Image<Vec3>>,
    /// First-hit distance from the camera.
    pub depth: Option<Image<f32>>,
    /// Variance of the mean depth.
    pub depth_variance: Option<Image<f32>>,
    /// Light seen directly.
    pub emission: Option<Image<Rgb>>,
    /// Light reflected once at the first hit.
    pub direct: Option<Image<Rgb>>,
    /// Light reflected at the first hit after further bounces.
    pub indirect: Option<Image<Rgb>>,
    /// Light reflected by the first hit's diffuse layers.
    pub diffuse: Option<Image<Rgb>>,
    /// Light reflected by the first hit's specular layers.
    pub glossy: Option<Image<Rgb>>,
    /// Reflected light over albedo.
    pub irradiance: Option<Image<Rgb>>,
    /// Every camera sample's record, when the film kept them (never read from or written to a
    /// file).
    pub samples: Option<SampleRecords>,
}

/// A channel's data, by kind.
enum Data<'a> {
    Three(&'a Image<Vec3>),
    One(&'a Image<f32>),
}

impl NoisyFrame {
    /// A frame holding only the colour image.
    pub fn new(colour: Image<Rgb>) -> Self {
        Self {
            colour,
            ..Default::default()
        }
    }

    /// Width in pixels.
    pub fn width(&self) -> usize {
        self.colour.width()
    }

    /// Height in pixels.
    pub fn height(&self) -> usize {
        self.colour.height()
    }

    /// The channels of `aovs` that `film` kept, plus the colour image. A buffer the film keeps
    /// for another consumer (the stopping criterion's halves, a z-test's variance) is left
    /// out unless `aovs` names it.
    pub fn from_film(film: &Film, aovs: AovSet) -> Self {
        let (w, h) = (film.width() as usize, film.height() as usize);
        let img = |v: Vec<Vec3>| Image::new(w, h, v).ok();
        let scalar = |v: Vec<f32>| Image::new(w, h, v).ok();
        let colour = Image::new(w, h, film.mean_image()).unwrap_or_default();
        let features = film
            .feature_variance_images()
            .filter(|_| aovs.feature_variance);
        let features = features.unwrap_or_default();
        let split = film.split_images();
        let part = |keep: bool, f: fn(&LightSplit) -> Rgb| {
            let s = split.as_ref().filter(|_| keep)?;
            img(s.iter().map(f).collect())
        };
        Self {
            colour,
            variance: film
                .variance_image()
                .filter(|_| aovs.variance)
                .and_then(img),
            halves: match (aovs.halves, film.half_image(0), film.half_image(1)) {
                (true, Some(e), Some(o)) => img(e).zip(img(o)).map(|(e, o)| [e, o]),
                _ => None,
            },
            albedo: film.albedo_image().and_then(img),
            albedo_variance: features.albedo.and_then(img),
            normal: film.normal_image().and_then(img),
            normal_variance: features.normal.and_then(img),
            position: film.position_image().and_then(img),
            position_variance: features.position.and_then(img),
            depth: film.depth_image().and_then(scalar),
            depth_variance: features.depth.and_then(scalar),
            emission: part(aovs.emission, |s| s.emission),
            direct: part(aovs.direct, |s| s.direct),
            indirect: part(aovs.indirect, |s| s.indirect),
            diffuse: part(aovs.diffuse, |s| s.diffuse),
            glossy: part(aovs.glossy, |s| s.glossy),
            irradiance: part(aovs.irradiance, |s| s.irradiance),
            samples: film.sample_records().filter(|_| aovs.samples).cloned(),
        }
    }

    /// [`NoisyFrame::from_film`] that moves the film's sample records into the frame instead
    /// of copying them (56 bytes per sample), for a caller done with the film.
    pub fn from_film_taking_samples(film: &mut Film, aovs: AovSet) -> Self {
        let mut frame = Self::from_film(
            film,
            AovSet {
                samples: false,
                ..aovs
            },
        );
        if aovs.samples {
            frame.samples = film.take_sample_records();
        }
        frame
    }

    /// The three-component channel `c` (every channel but depth and its variance), if present.
    pub fn image(&self, c: Channel) -> Option<&Image<Vec3>> {
        match self.data(c)? {
            Data::Three(i) => Some(i),
            Data::One(_) => None,
        }
    }

    fn data(&self, c: Channel) -> Option<Data<'_>> {
        fn three(i: &Option<Image<Vec3>>) -> Option<Data<'_>> {
            i.as_ref().map(Data::Three)
        }
        match c {
            Channel::Colour => Some(Data::Three(&self.colour)),
            Channel::Variance => three(&self.variance),
            Channel::Halves => self.halves.as_ref().map(|h| Data::Three(&h[0])),
            Channel::Albedo => three(&self.albedo),
            Channel::AlbedoVariance => three(&self.albedo_variance),
            Channel::Normal => three(&self.normal),
            Channel::NormalVariance => three(&self.normal_variance),
            Channel::Position => three(&self.position),
            Channel::PositionVariance => three(&self.position_variance),
            Channel::Depth => self.depth.as_ref().map(Data::One),
            Channel::DepthVariance => self.depth_variance.as_ref().map(Data::One),
            Channel::Emission => three(&self.emission),
            Channel::Direct => three(&self.direct),
            Channel::Indirect => three(&self.indirect),
            Channel::Diffuse => three(&self.diffuse),
            Channel::Glossy => three(&self.glossy),
            Channel::Irradiance => three(&self.irradiance),
            Channel::Samples => None,
        }
    }

    fn slot(&mut self, c: Channel) -> Option<&mut Option<Image<Vec3>>> {
        Some(match c {
            Channel::Variance => &mut self.variance,
            Channel::Albedo => &mut self.albedo,
            Channel::AlbedoVariance => &mut self.albedo_variance,
            Channel::Normal => &mut self.normal,
            Channel::NormalVariance => &mut self.normal_variance,
            Channel::Position => &mut self.position,
            Channel::PositionVariance => &mut self.position_variance,
            Channel::Emission => &mut self.emission,
            Channel::Direct => &mut self.direct,
            Channel::Indirect => &mut self.indirect,
            Channel::Diffuse => &mut self.diffuse,
            Channel::Glossy => &mut self.glossy,
            Channel::Irradiance => &mut self.irradiance,
            Channel::Colour
            | Channel::Halves
            | Channel::Depth
            | Channel::DepthVariance
            | Channel::Samples => return None,
        })
    }

    /// True if the frame has channel `c`.
    pub fn has(&self, c: Channel) -> bool {
        match c {
            Channel::Samples => self.samples.is_some(),
            _ => self.data(c).is_some(),
        }
    }

    /// The channels present, in file order.
    pub fn channels(&self) -> Vec<Channel> {
        Channel::ALL.into_iter().filter(|&c| self.has(c)).collect()
    }

    /// Checks that every channel has the colour image's size.
    pub fn check(&self) -> Result<(), FrameError> {
        let expected = self.colour.size();
        let mut sizes: Vec<(Channel, (usize, usize))> = Channel::ALL
            .into_iter()
            .filter_map(|c| {
                let size = match self.data(c)? {
                    Data::Three(i) => i.size(),
                    Data::One(i) => i.size(),
                };
                Some((c, size))
            })
            .collect();
        if let Some(h) = &self.halves {
            sizes.push((Channel::Halves, h[1].size()));
        }
        if let Some(r) = &self.samples {
            sizes.push((Channel::Samples, (r.width() as usize, r.height() as usize)));
        }
        match sizes.into_iter().find(|(_, s)| *s != expected) {
            Some((channel, got)) => Err(FrameError::Size {
                channel,
                expected,
                got,
            }),
            None => Ok(()),
        }
    }

    /// Checks that the frame is consistent and has every channel of `needs`; `consumer` names
    /// who asks, for the error.
    pub fn require(&self, consumer: &str, needs: &[Channel]) -> Result<(), FrameError> {
        self.check()?;
        match needs.iter().find(|&&c| !self.has(c)) {
            Some(&channel) => Err(FrameError::Missing {
                consumer: consumer.to_string(),
                channel,
            }),
            None => Ok(()),
        }
    }

    /// The named EXR channels of the frame, in file order (see the module doc).
    pub fn exr_channels(&self) -> Vec<(String, Vec<f32>)> {
        let mut out = Vec::new();
        let mut three = |prefix: &str, names: [&str; 3], img: &Image<Vec3>| {
            for (k, n) in names.iter().enumerate() {
                let sep = if prefix.is_empty() { "" } else { "." };
                out.push((
                    format!("{prefix}{sep}{n}"),
                    img.pixels().iter().map(|p| p[k]).collect(),
                ));
            }
        };
        for c in Channel::ALL {
            match (c, self.data(c)) {
                (Channel::Colour, _) => three("", RGB, &self.colour),
                (Channel::Halves, Some(_)) => {
                    if let Some([e, o]) = &self.halves {
                        three("even", RGB, e);
                        three("odd", RGB, o);
                    }
                }
                (_, Some(Data::Three(img))) => three(c.name(), components(c), img),
                _ => {}
            }
        }
        for (c, img) in [
            (Channel::Depth, &self.depth),
            (Channel::DepthVariance, &self.depth_variance),
        ] {
            if let Some(img) = img {
                out.push((format!("{}.Z", c.name()), img.pixels().to_vec()));
            }
        }
        out
    }

    /// Writes the frame to `path` (EXR, atomically), with further per-pixel channels `extra`
    /// (such as the stopping criterion's block map).
    pub fn write_exr(&self, path: &Path, extra: &[(&str, Vec<f32>)]) -> Result<(), FilmError> {
        self.exr_image(extra)
            .map_err(|message| FilmError::Codec {
                path: path.to_path_buf(),
                message,
            })?
            .write(path)
    }

    /// What [`NoisyFrame::write_exr`] writes, in memory.
    pub fn exr_image(&self, extra: &[(&str, Vec<f32>)]) -> Result<ExrImage, String> {
        let mut chans = self.exr_channels();
        chans.extend(extra.iter().map(|(n, v)| (n.to_string(), v.clone())));
        ExrImage::from_channels(self.colour.size(), chans)
    }

    /// Reads a frame written by [`NoisyFrame::write_exr`] (or `render --aov ... -o F.exr`):
    /// every channel group it finds, bit for bit. Other channels are ignored; a group with
    /// some but not all of its components is an error naming the file.
    pub fn from_exr(path: &Path) -> Result<Self, FilmError> {
        let exr = read_exr(path)?;
        Self::from_exr_image(&exr).map_err(|message| FilmError::Codec {
            path: path.to_path_buf(),
            message,
        })
    }

    /// [`NoisyFrame::from_exr`] of channels already in memory (an EXR's, or arrays named as
    /// in a file, as the Python module hands them over); the error names the problem, not a
    /// file.
    pub fn from_exr_image(exr: &ExrImage) -> Result<Self, String> {
        let (w, h) = (exr.width, exr.height);
        let group = |prefix: &str, names: [&str; 3]| -> Result<Option<Image<Vec3>>, String> {
            let full = |n: &str| {
                if prefix.is_empty() {
                    n.to_string()
                } else {
                    format!("{prefix}.{n}")
                }
            };
            let found: Vec<Option<&[f32]>> = names.iter().map(|n| exr.channel(&full(n))).collect();
            match found.iter().filter(|f| f.is_some()).count() {
                0 => Ok(None),
                3 => {
                    let [a, b, c] = [found[0], found[1], found[2]].map(Option::unwrap_or_default);
                    let px = (0..a.len()).map(|i| Vec3::new(a[i], b[i], c[i])).collect();
                    Image::new(w, h, px).map(Some).map_err(|e| e.to_string())
                }
                _ => Err(format!(
                    "channel group '{}' is incomplete: it needs {}",
                    if prefix.is_empty() { "colour" } else { prefix },
                    names.map(full).join(", ")
                )),
            }
        };
        let colour = group("", RGB)?.ok_or("no R, G, B channels: not a rendered frame")?;
        let mut frame = NoisyFrame::new(colour);
        for c in Channel::ALL {
            if let Some(slot) = frame.slot(c) {
                *slot = group(c.name(), components(c))?;
            }
        }
        frame.halves = match (group("even", RGB)?, group("odd", RGB)?) {
            (Some(e), Some(o)) => Some([e, o]),
            (None, None) => None,
            _ => return Err("only one of the half-buffers (even.*, odd.*) is present".into()),
        };
        let scalar = |name: &str| {
            exr.channel(name)
                .map(|v| Image::new(w, h, v.to_vec()).map_err(|e| e.to_string()))
                .transpose()
        };
        frame.depth = scalar("depth.Z")?;
        frame.depth_variance = scalar("depth_variance.Z")?;
        frame.check().map_err(|e| e.to_string())?;
        Ok(frame)
    }
}

/// Component names of a three-component channel in files.
fn components(c: Channel) -> [&'static str; 3] {
    match c {
        Channel::Normal
        | Channel::NormalVariance
        | Channel::Position
        | Channel::PositionVariance => XYZ,
        _ => RGB,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::{FilmBuffers, FirstHit};

    /// A film with every channel, filled with distinct, awkward values.
    fn full_film() -> Film {
        film_with(AovSet::denoise())
    }

    /// A film keeping the buffers of `aovs`, filled like [`full_film`].
    fn film_with(aovs: AovSet) -> Film {
        let mut film = Film::new(5, 3, FilmBuffers::for_outputs(aovs));
        let mut state = 7u32;
        let mut next = || {
            state = rt_core::sampler::hash_u32(state);
            (state >> 8) as f32 / (1 << 24) as f32
        };
        for y in 0..3 {
            for x in 0..5 {
                for i in 0..4 {
                    let v = next();
                    let hit = FirstHit {
                        albedo: Rgb::new(v, 0.5, 1.0 - v),
                        normal: Vec3::new(v, 1.0, -v).normalize(),
                        depth: 1.0 + 10.0 * v,
                        position: Vec3::new(x as f32, y as f32, v * 3.3),
                    };
                    let split = LightSplit {
                        emission: Rgb::splat(0.1 * v),
                        direct: Rgb::new(v, 2.0 * v, 0.3),
                        indirect: Rgb::splat(v * v),
                        diffuse: Rgb::splat(0.7 * v),
                        glossy: Rgb::splat(0.2),
                        irradiance: Rgb::splat(v / 0.7),
                    };
                    let mut bands = film.stripes_mut(3);
                    let l = Rgb::new(v * 1e3, v, 1e-7 / (v + 1e-3));
                    bands[0].add_sample_split(x, y, i, l, Some(&hit), Some(&split));
                }
            }
        }
        film
    }

    #[test]
    fn exr_round_trip_is_bit_exact_for_every_channel() {
        let frame = NoisyFrame::from_film(&full_film(), AovSet::denoise());
        // Every channel a file can hold (sample records stay in memory).
        let saved: Vec<Channel> = Channel::ALL
            .into_iter()
            .filter(|&c| c != Channel::Samples)
            .collect();
        assert_eq!(frame.channels(), saved, "every channel");
        let dir = tempfile::tempdir().unwrap();
        let p = dir.path().join("f.exr");
        frame.write_exr(&p, &[]).unwrap();
        let back = NoisyFrame::from_exr(&p).unwrap();
        let bits = |f: &NoisyFrame| -> Vec<(String, Vec<u32>)> {
            f.exr_channels()
                .into_iter()
                .map(|(n, v)| (n, v.into_iter().map(f32::to_bits).collect()))
                .collect()
        };
        assert_eq!(bits(&back), bits(&frame));
        assert_eq!(back, frame);
        // Variances are real statistics, not zeros.
        assert!(back
            .depth_variance
            .unwrap()
            .pixels()
            .iter()
            .all(|&v| v > 0.0));
    }

    #[test]
    fn frames_keep_only_what_was_asked_and_report_what_is_missing() {
        let film = full_film();
        let aovs = AovSet::parse_list(["albedo", "direct"]).unwrap();
        let frame = NoisyFrame::from_film(&film, aovs);
        // The film kept more (it was built for `denoise`), but variance, halves and the other
        // split parts were not asked for.
        assert!(frame.has(Channel::Direct) && !frame.has(Channel::Indirect));
        assert!(!frame.has(Channel::Variance) && !frame.has(Channel::Halves));
        let e = frame
            .require("atrous", &[Channel::Colour, Channel::Indirect])
            .unwrap_err();
        assert_eq!(
            e.to_string(),
            "atrous needs the indirect channel, which the frame does not have (render it with --aov indirect, or --aov denoise for every channel)"
        );
        let mut bad = frame.clone();
        bad.depth = Some(Image::filled(4, 3, 1.0));
        assert!(bad
            .require("x", &[])
            .unwrap_err()
            .to_string()
            .contains("depth channel is (4, 3)"));
    }

    /// Each channel alone gets a film that keeps it, and nothing beyond it (and, for a
    /// feature's variance, the feature).
    #[test]
    fn aovs_for_channels_give_exactly_those_channels() {
        assert_eq!(AovSet::for_channels(&[Channel::Colour]), AovSet::default());
        let all = AovSet::for_channels(&Channel::ALL);
        // Everything `--aov denoise` writes, and the in-memory sample records.
        assert_eq!(
            all,
            AovSet {
                samples: true,
                ..AovSet::denoise()
            }
        );
        for c in Channel::ALL {
            let aovs = AovSet::for_channels(&[c]);
            let got = NoisyFrame::from_film(&film_with(aovs), aovs).channels();
            let base = match c {
                Channel::AlbedoVariance => Channel::Albedo,
                Channel::NormalVariance => Channel::Normal,
                Channel::PositionVariance => Channel::Position,
                Channel::DepthVariance => Channel::Depth,
                other => other,
            };
            let mut want = vec![Channel::Colour, base, c];
            want.dedup();
            want.sort_by_key(|w| Channel::ALL.iter().position(|a| a == w));
            assert_eq!(got, want, "{c}");
        }
    }

    #[test]
    fn taking_the_samples_moves_them_and_changes_nothing_else() {
        let aovs = AovSet {
            samples: true,
            ..AovSet::parse_list(["albedo"]).unwrap()
        };
        let mut film = film_with(aovs);
        let mut records = SampleRecords::pass(5, 3, 1);
        for mut band in records.bands_mut(3) {
            band.record(1, 2, 0, Rgb::splat(0.5), None, 1.5);
        }
        film.add_sample_records(records);
        let copied = NoisyFrame::from_film(&film, aovs);
        assert_eq!(copied.samples.as_ref().map(SampleRecords::len), Some(1));
        let taken = NoisyFrame::from_film_taking_samples(&mut film, aovs);
        assert_eq!(taken, copied);
        assert_eq!(film.sample_records().map(SampleRecords::len), Some(0));
    }

    #[test]
    fn an_incomplete_group_is_an_error_naming_the_file() {
        let dir = tempfile::tempdir().unwrap();
        let p = dir.path().join("partial.exr");
        let mut chans = NoisyFrame::new(Image::filled(2, 2, Rgb::ONE)).exr_channels();
        chans.push(("albedo.R".into(), vec![0.5; 4]));
        ExrImage::from_channels((2, 2), chans)
            .unwrap()
            .write(&p)
            .unwrap();
        let e = NoisyFrame::from_exr(&p).unwrap_err().to_string();
        assert!(e.contains("partial.exr") && e.contains("albedo"), "{e}");
    }
}
