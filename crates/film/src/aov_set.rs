//! Which AOVs a render keeps ([`AovSet`]), and the one table every list of them derives from
//! ([`AOV_FLAGS`]): each flag's `--aov` name, how to get it into a frame, and the frame
//! channels that need it. The names `--aov` takes, their parsing, the union of two sets,
//! the set a list of channels needs and each channel's hint all read the table.

use crate::noisy_frame::Channel;

/// Which AOVs to keep: first-hit features, statistics of the pixel estimate, and the lighting
/// split. The integrator computes the first-hit features only if one of them is wanted, and the
/// split only if some part of it is.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct AovSet {
    /// Albedo of the first visible surface.
    pub albedo: bool,
    /// Shading normal.
    pub normal: bool,
    /// Distance from the camera.
    pub depth: bool,
    /// World position.
    pub position: bool,
    /// Per-pixel variance of the mean (needs the film's variance buffer, 12 bytes per pixel).
    pub variance: bool,
    /// The means of the even- and odd-numbered samples (two independent half estimates).
    pub halves: bool,
    /// For each first-hit feature kept, the variance of its per-pixel mean.
    pub feature_variance: bool,
    /// Light seen directly: emitters and the environment at the first hit.
    pub emission: bool,
    /// Light reflected once at the first hit (`emission + direct + indirect` is the pixel).
    pub direct: bool,
    /// Light reflected at the first hit after more than one bounce.
    pub indirect: bool,
    /// Light reflected by the first hit's diffuse layers (`emission + diffuse + glossy` is
    /// the pixel).
    pub diffuse: bool,
    /// Light reflected by the first hit's specular layers (glossy, mirror, glass).
    pub glossy: bool,
    /// Light reflected at the first hit divided by its albedo, per sample: the untextured
    /// lighting that demodulating filters smooth (zero where the albedo is).
    pub irradiance: bool,
    /// The stopping criterion's final blocks: per pixel its block's index, its sample count and
    /// whether the block met the threshold (an adaptive render's output, not a film buffer).
    pub blocks: bool,
    /// Every camera sample's record (radiance, first-hit features, signed circle of
    /// confusion), for SBMF. Kept in memory for a denoiser, never written to a file (so not a
    /// `--aov` name).
    pub samples: bool,
}

/// One flag of [`AovSet`]: a row of [`AOV_FLAGS`].
#[derive(Clone, Copy, Debug)]
pub struct AovFlag {
    /// The name `--aov` takes and [`AovSet::names`] gives; `None` for a flag that is no file
    /// output (the per-sample records).
    pub name: Option<&'static str>,
    /// How to get the flag's channels into a frame, for messages ([`Channel::hint`]).
    pub hint: &'static str,
    /// The frame channels ([`crate::NoisyFrame`] buffers) that need the flag: its own, and
    /// for a first-hit feature the feature's variance, which needs the feature too.
    pub channels: &'static [Channel],
    /// The flag's field.
    field: fn(&mut AovSet) -> &mut bool,
}

impl AovFlag {
    /// True if `set` has the flag.
    pub fn is_in(&self, mut set: AovSet) -> bool {
        *(self.field)(&mut set)
    }

    /// Sets the flag in `set`.
    pub fn add_to(&self, set: &mut AovSet) {
        *(self.field)(set) = true;
    }
}

/// The hint of a flag `--aov denoise` also gives.
macro_rules! with_denoise {
    ($name:literal) => {
        concat!(
            "render it with --aov ",
            $name,
            ", or --aov denoise for every channel"
        )
    };
}

/// Every flag of [`AovSet`], in the order help texts list them; the per-sample records,
/// which have no name, last.
pub const AOV_FLAGS: [AovFlag; 15] = [
    AovFlag {
        name: Some("albedo"),
        hint: with_denoise!("albedo"),
        channels: &[Channel::Albedo, Channel::AlbedoVariance],
        field: |s| &mut s.albedo,
    },
    AovFlag {
        name: Some("normal"),
        hint: with_denoise!("normal"),
        channels: &[Channel::Normal, Channel::NormalVariance],
        field: |s| &mut s.normal,
    },
    AovFlag {
        name: Some("depth"),
        hint: with_denoise!("depth"),
        channels: &[Channel::Depth, Channel::DepthVariance],
        field: |s| &mut s.depth,
    },
    AovFlag {
        name: Some("position"),
        hint: with_denoise!("position"),
        channels: &[Channel::Position, Channel::PositionVariance],
        field: |s| &mut s.position,
    },
    AovFlag {
        name: Some("variance"),
        hint: with_denoise!("variance"),
        channels: &[Channel::Variance],
        field: |s| &mut s.variance,
    },
    AovFlag {
        name: Some("halves"),
        hint: with_denoise!("halves"),
        channels: &[Channel::Halves],
        field: |s| &mut s.halves,
    },
    AovFlag {
        name: Some("feature-variance"),
        hint: with_denoise!("feature-variance and the feature"),
        channels: &[
            Channel::AlbedoVariance,
            Channel::NormalVariance,
            Channel::PositionVariance,
            Channel::DepthVariance,
        ],
        field: |s| &mut s.feature_variance,
    },
    AovFlag {
        name: Some("emission"),
        hint: with_denoise!("emission"),
        channels: &[Channel::Emission],
        field: |s| &mut s.emission,
    },
    AovFlag {
        name: Some("direct"),
        hint: with_denoise!("direct"),
        channels: &[Channel::Direct],
        field: |s| &mut s.direct,
    },
    AovFlag {
        name: Some("indirect"),
        hint: with_denoise!("indirect"),
        channels: &[Channel::Indirect],
        field: |s| &mut s.indirect,
    },
    AovFlag {
        name: Some("diffuse"),
        hint: with_denoise!("diffuse"),
        channels: &[Channel::Diffuse],
        field: |s| &mut s.diffuse,
    },
    AovFlag {
        name: Some("glossy"),
        hint: with_denoise!("glossy"),
        channels: &[Channel::Glossy],
        field: |s| &mut s.glossy,
    },
    AovFlag {
        name: Some("irradiance"),
        hint: with_denoise!("irradiance"),
        channels: &[Channel::Irradiance],
        field: |s| &mut s.irradiance,
    },
    AovFlag {
        name: Some("blocks"),
        hint: "render it with --error and --aov blocks",
        channels: &[],
        field: |s| &mut s.blocks,
    },
    AovFlag {
        name: None,
        hint: "sample records are never saved to a file: denoise while rendering, render SCENE --denoiser ...",
        channels: &[Channel::Samples],
        field: |s| &mut s.samples,
    },
];

/// The names [`AovSet::parse_list`] knows, in the order help texts list them: every named
/// flag of [`AOV_FLAGS`], then `denoise` ([`AovSet::denoise`]).
pub const AOV_NAMES: [&str; 15] = {
    let mut names = [""; 15];
    let (mut i, mut n) = (0, 0);
    while i < AOV_FLAGS.len() {
        if let Some(name) = AOV_FLAGS[i].name {
            names[n] = name;
            n += 1;
        }
        i += 1;
    }
    assert!(n == names.len() - 1, "one name is left for `denoise`");
    names[n] = "denoise";
    names
};

impl AovSet {
    /// Everything a denoiser of `rt-denoise` reads: every named flag that fills frame
    /// channels (the features with their variances, the variance and half-buffers of the
    /// pixel estimate, and the whole lighting split), so not `blocks` (no frame channel) nor
    /// the per-sample records (no name). `--aov denoise` stands for it.
    pub fn denoise() -> AovSet {
        let mut s = AovSet::default();
        for f in AOV_FLAGS
            .iter()
            .filter(|f| f.name.is_some() && !f.channels.is_empty())
        {
            f.add_to(&mut s);
        }
        s
    }

    /// True if any first-hit quantity is wanted (variance is not a first-hit quantity).
    pub fn any_first_hit(&self) -> bool {
        self.albedo || self.normal || self.depth || self.position
    }

    /// True if any part of the lighting split is wanted.
    pub fn any_split(&self) -> bool {
        self.emission
            || self.direct
            || self.indirect
            || self.diffuse
            || self.glossy
            || self.irradiance
    }

    /// The union of two sets.
    pub fn union(self, o: AovSet) -> AovSet {
        let mut s = self;
        for f in AOV_FLAGS.iter().filter(|f| f.is_in(o)) {
            f.add_to(&mut s);
        }
        s
    }

    /// The names of the outputs in the set, in [`AOV_NAMES`] order, for [`AovSet::parse_list`]
    /// to read back (`samples`, which has no name, is left out).
    pub fn names(&self) -> Vec<&'static str> {
        AOV_FLAGS
            .iter()
            .filter(|f| f.is_in(*self))
            .filter_map(|f| f.name)
            .collect()
    }

    /// Parses a comma-separated list such as `albedo,normal,variance`; `denoise` stands for
    /// [`AovSet::denoise`].
    pub fn parse_list<'a>(names: impl IntoIterator<Item = &'a str>) -> Result<Self, UnknownAov> {
        let mut s = Self::default();
        for n in names {
            match n.trim() {
                "" => {}
                "denoise" => s = s.union(Self::denoise()),
                name => AOV_FLAGS
                    .iter()
                    .find(|f| f.name == Some(name))
                    .ok_or_else(|| UnknownAov(name.to_string()))?
                    .add_to(&mut s),
            }
        }
        Ok(s)
    }

    /// The smallest set whose film gives a [`crate::NoisyFrame`] with every channel of
    /// `channels` (through [`crate::NoisyFrame::from_film`] with the same set): what a
    /// consumer that reads those channels, e.g. a denoiser's `needs()`, must ask the film
    /// for. A feature's variance needs the feature too; the colour image is always there.
    pub fn for_channels(channels: &[Channel]) -> AovSet {
        let mut s = AovSet::default();
        for f in AOV_FLAGS
            .iter()
            .filter(|f| channels.iter().any(|c| f.channels.contains(c)))
        {
            f.add_to(&mut s);
        }
        s
    }
}

/// An AOV name [`AovSet::parse_list`] does not know.
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
#[error("unknown AOV '{0}' (expected one of: {names})", names = AOV_NAMES.join(", "))]
pub struct UnknownAov(pub String);

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn denoise_is_every_frame_output_and_no_more() {
        // Written out so that a new flag has to be placed in or out of `--aov denoise` here.
        let every_frame_output = AovSet {
            albedo: true,
            normal: true,
            depth: true,
            position: true,
            variance: true,
            halves: true,
            feature_variance: true,
            emission: true,
            direct: true,
            indirect: true,
            diffuse: true,
            glossy: true,
            irradiance: true,
            blocks: false,
            samples: false,
        };
        assert_eq!(AovSet::denoise(), every_frame_output);
        assert_eq!(AovSet::parse_list(["denoise"]), Ok(every_frame_output));
    }

    #[test]
    fn each_flag_sets_its_own_field_and_names_round_trip() {
        for (i, f) in AOV_FLAGS.iter().enumerate() {
            let mut s = AovSet::default();
            f.add_to(&mut s);
            let set: Vec<bool> = AOV_FLAGS.iter().map(|g| g.is_in(s)).collect();
            assert_eq!(set.iter().filter(|b| **b).count(), 1, "{f:?}");
            assert!(set[i], "{f:?}");
            if let Some(name) = f.name {
                assert_eq!(AovSet::parse_list([name]), Ok(s));
                assert_eq!(s.names(), [name]);
            }
        }
        assert!(AovSet::parse_list(["albedo", "bogus"]).is_err());
    }
}
