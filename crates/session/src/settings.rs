//! The one place where a render's settings are resolved: each value comes from what the caller
//! gives (command-line flags, an experiment method, `render reference` flags), else from the
//! scene's `[render]` table, else from the default. Limits are checked here, for both sources,
//! and errors name where the bad value came from (the flag, or the scene file and key).

use rt_accel::AccelSpec;
use rt_film::AovSet;
use rt_integrators::spec::check_max_depth;
use rt_integrators::{IntegratorSpec, IntegratorSpecError};
use rt_scene::RenderDesc;
use std::fmt;
use std::path::{Path, PathBuf};

/// Largest sample count of one render.
pub const MAX_SPP: u32 = 1 << 20;

/// Most worker threads a render may ask for.
pub const MAX_THREADS: usize = 1024;

/// Samples per pixel when nothing sets them.
pub const DEFAULT_SPP: u32 = 64;

/// Settings a caller gives; each one left `None` falls back to the scene's `[render]` table,
/// then to the default.
#[derive(Clone, Debug, Default)]
pub struct Overrides {
    /// Integrator and its options. A `max-depth=` in it wins over [`Self::max_depth`] and the
    /// table's `max_depth`.
    pub integrator: Option<IntegratorSpec>,
    /// Bounce limit (`--max-depth`).
    pub max_depth: Option<u32>,
    /// `ao` occluder distance (never in `[render]`; unlimited by default).
    pub ao_distance: Option<f32>,
    /// Samples per pixel.
    pub spp: Option<u32>,
    /// Worker threads.
    pub threads: Option<usize>,
    /// Seed of the sample streams.
    pub seed: Option<u64>,
    /// Acceleration structure.
    pub accel: Option<AccelSpec>,
    /// AOV names.
    pub aovs: Option<Vec<String>>,
    /// Output path.
    pub output: Option<PathBuf>,
    /// Denoiser (`--denoiser`), as text: the caller checks it (it may be a temporal one);
    /// `none` turns the table's off.
    pub denoiser: Option<String>,
}

/// Fully resolved settings of one render.
#[derive(Clone, Debug, PartialEq)]
pub struct Settings {
    /// Integrator and its parameters.
    pub integrator: IntegratorSpec,
    /// Acceleration structure.
    pub accel: AccelSpec,
    /// Samples per pixel.
    pub spp: u32,
    /// Worker threads (`None`: all cores).
    pub threads: Option<usize>,
    /// The 32-bit stream key ([`fold_seed`] of the 64-bit seed).
    pub seed: u32,
    /// AOVs to write.
    pub aovs: AovSet,
    /// Output path, if the caller or the table named one.
    pub output: Option<PathBuf>,
    /// The denoiser the image is filtered with, as text (`None`: no denoising). From the
    /// table it is a single-frame [`rt_denoise::DenoiserSpec`], checked here.
    pub denoiser: Option<String>,
}

/// Where a value came from, for error messages.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum Origin {
    /// The caller (printed as the flag, e.g. `--spp`).
    Given(&'static str),
    /// The scene file's `[render]` table.
    Table {
        /// The scene file.
        file: PathBuf,
        /// The key.
        key: &'static str,
    },
}

impl fmt::Display for Origin {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Origin::Given(flag) => write!(f, "--{flag}"),
            Origin::Table { file, key } => write!(f, "{}: [render] {key}", file.display()),
        }
    }
}

/// Why settings could not be resolved.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum SettingsError {
    /// A bad integrator name, option or parameter.
    #[error("{origin}: {source}")]
    Integrator {
        /// Where it came from.
        origin: Origin,
        /// What is wrong.
        source: IntegratorSpecError,
    },
    /// A bad acceleration structure spec.
    #[error("{origin} = \"{text}\": {source}")]
    Accel {
        /// Where it came from.
        origin: Origin,
        /// The spec as written.
        text: String,
        /// What is wrong.
        source: rt_accel::SpecError,
    },
    /// A number outside its range.
    #[error("{origin}: {what} must be between {min} and {max}, got {value}")]
    OutOfRange {
        /// Where it came from.
        origin: Origin,
        /// What the number is.
        what: &'static str,
        /// Smallest allowed.
        min: u64,
        /// Largest allowed.
        max: u64,
        /// As given.
        value: u64,
    },
    /// AOVs asked of a technique that cannot write them: a light tracer's splats have no
    /// per-pixel variance and its light paths no first camera hit.
    #[error("{origin}: the {technique} technique writes no AOVs (its light paths land on any pixel, so there is no first hit or per-pixel variance); drop the AOV list or use a camera-ray integrator")]
    AovUnsupported {
        /// Where the AOVs were asked for.
        origin: Origin,
        /// The technique's name.
        technique: &'static str,
    },
    /// Lighting-split AOVs asked of a technique that does not write them.
    #[error("{origin}: the {technique} technique does not write the lighting split (emission, direct, indirect, diffuse, glossy, irradiance); use path, path-bsdf or direct, or drop those AOVs")]
    SplitUnsupported {
        /// Where the AOVs were asked for.
        origin: Origin,
        /// The technique's name.
        technique: &'static str,
    },
    /// A bad denoiser name or option.
    #[error("{origin} = \"{text}\": {message}")]
    Denoiser {
        /// Where it came from.
        origin: Origin,
        /// The spec as written.
        text: String,
        /// What is wrong.
        message: String,
    },
    /// An unknown AOV name.
    #[error("{origin}: {source}")]
    Aov {
        /// Where it came from.
        origin: Origin,
        /// The name.
        source: rt_film::UnknownAov,
    },
}

/// The stream key of frame `frame` of an animation rendered with stream key `seed`: every
/// frame gets its own streams (frame 0 those of a plain render), so noise does not stand still
/// on the screen while the scene moves, and any frame renders alone to the same bits.
pub fn frame_seed(seed: u32, frame: u32) -> u32 {
    // The golden-ratio increment: consecutive frames land far apart in key space, and the
    // sampler hashes the key with every sample coordinate anyway.
    seed.wrapping_add(frame.wrapping_mul(0x9E37_79B9))
}

/// Folds a 64-bit seed into the 32-bit stream key without discarding the high half.
pub fn fold_seed(seed: u64) -> u32 {
    (seed ^ (seed >> 32)) as u32
}

/// Checks that `value` is in `min..=max`.
fn in_range(
    origin: impl FnOnce() -> Origin,
    what: &'static str,
    value: u64,
    min: u64,
    max: u64,
) -> Result<(), SettingsError> {
    if (min..=max).contains(&value) {
        return Ok(());
    }
    Err(SettingsError::OutOfRange {
        origin: origin(),
        what,
        min,
        max,
        value,
    })
}

impl Overrides {
    /// Resolves every setting for the scene at `scene_path` with `[render]` table `desc`.
    pub fn resolve(&self, desc: &RenderDesc, scene_path: &Path) -> Result<Settings, SettingsError> {
        let table = |key: &'static str| Origin::Table {
            file: scene_path.to_path_buf(),
            key,
        };
        let origin = |given: bool, flag: &'static str, key: &'static str| {
            if given {
                Origin::Given(flag)
            } else {
                table(key)
            }
        };
        let spp = self.spp.or(desc.spp).unwrap_or(DEFAULT_SPP);
        in_range(
            || origin(self.spp.is_some(), "spp", "spp"),
            "samples per pixel",
            spp.into(),
            1,
            MAX_SPP.into(),
        )?;
        let threads = self.threads.or(desc.threads);
        if let Some(t) = threads {
            in_range(
                || origin(self.threads.is_some(), "threads", "threads"),
                "thread count",
                t as u64,
                1,
                MAX_THREADS as u64,
            )?;
        }
        let names = self.aovs.as_ref().or(desc.aov.as_ref());
        let aovs = match names {
            None => AovSet::default(),
            Some(list) => {
                AovSet::parse_list(list.iter().map(String::as_str)).map_err(|source| {
                    SettingsError::Aov {
                        origin: origin(self.aovs.is_some(), "aov", "aov"),
                        source,
                    }
                })?
            }
        };
        let integrator = self.integrator_spec(desc, scene_path)?;
        // The block map is the stopping criterion's, which serves every technique.
        let per_pixel = AovSet {
            blocks: false,
            ..aovs
        };
        if integrator.kind.splats() && per_pixel != AovSet::default() {
            return Err(SettingsError::AovUnsupported {
                origin: origin(self.aovs.is_some(), "aov", "aov"),
                technique: integrator.kind.name(),
            });
        }
        if aovs.any_split() && !integrator.build().writes_split() {
            return Err(SettingsError::SplitUnsupported {
                origin: origin(self.aovs.is_some(), "aov", "aov"),
                technique: integrator.kind.name(),
            });
        }
        Ok(Settings {
            integrator,
            accel: self.accel_spec(desc, scene_path)?,
            spp,
            threads,
            seed: self.seed(desc),
            aovs,
            output: self
                .output
                .clone()
                .or_else(|| desc.output.as_ref().map(PathBuf::from)),
            denoiser: self.denoiser(desc, scene_path)?,
        })
    }

    /// The denoiser alone: the given text (`none`: no denoiser), else the table's, which must
    /// build as a single-frame denoiser.
    pub fn denoiser(
        &self,
        desc: &RenderDesc,
        scene_path: &Path,
    ) -> Result<Option<String>, SettingsError> {
        if let Some(text) = &self.denoiser {
            return Ok((!text.trim().eq_ignore_ascii_case("none")).then(|| text.clone()));
        }
        let Some(text) = &desc.denoiser else {
            return Ok(None);
        };
        text.parse::<rt_denoise::DenoiserSpec>()
            .and_then(|spec| spec.build())
            .map_err(|e| SettingsError::Denoiser {
                origin: Origin::Table {
                    file: scene_path.to_path_buf(),
                    key: "denoiser",
                },
                text: text.clone(),
                message: e.to_string(),
            })?;
        Ok(Some(text.clone()))
    }

    /// The integrator alone (experiments and references need no more).
    pub fn integrator_spec(
        &self,
        desc: &RenderDesc,
        scene_path: &Path,
    ) -> Result<IntegratorSpec, SettingsError> {
        let table = |key: &'static str| Origin::Table {
            file: scene_path.to_path_buf(),
            key,
        };
        let mut spec = match (&self.integrator, &desc.integrator) {
            (Some(spec), _) => *spec,
            (None, Some(text)) => text.parse().map_err(|source| SettingsError::Integrator {
                origin: table("integrator"),
                source,
            })?,
            (None, None) => IntegratorSpec::default(),
        };
        if spec.max_depth.is_none() {
            let depth = self.max_depth.or(desc.max_depth);
            if let Some(d) = depth {
                let at = if self.max_depth.is_some() {
                    Origin::Given("max-depth")
                } else {
                    table("max_depth")
                };
                spec.max_depth = Some(
                    check_max_depth(d)
                        .map_err(|source| SettingsError::Integrator { origin: at, source })?,
                );
            }
        }
        spec.max_depth = Some(spec.depth());
        if let Some(d) = self.ao_distance {
            spec = spec
                .with_ao_distance(d)
                .map_err(|source| SettingsError::Integrator {
                    origin: Origin::Given("ao-distance"),
                    source,
                })?;
        }
        Ok(spec)
    }

    /// The acceleration structure alone.
    pub fn accel_spec(
        &self,
        desc: &RenderDesc,
        scene_path: &Path,
    ) -> Result<AccelSpec, SettingsError> {
        if let Some(a) = self.accel {
            return Ok(a);
        }
        match &desc.accel {
            Some(text) => text.parse().map_err(|source| SettingsError::Accel {
                origin: Origin::Table {
                    file: scene_path.to_path_buf(),
                    key: "accel",
                },
                text: text.clone(),
                source,
            }),
            None => Ok(AccelSpec::default()),
        }
    }

    /// The 32-bit stream seed alone.
    pub fn seed(&self, desc: &RenderDesc) -> u32 {
        fold_seed(self.seed.or(desc.seed).unwrap_or(0))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use rt_integrators::IntegratorKind;

    fn table(toml_like: impl FnOnce(&mut RenderDesc)) -> RenderDesc {
        let mut d = RenderDesc::default();
        toml_like(&mut d);
        d
    }

    #[test]
    fn given_wins_over_table_over_default() {
        let path = Path::new("s.toml");
        let none = Overrides::default()
            .resolve(&RenderDesc::default(), path)
            .unwrap();
        assert_eq!(none.spp, DEFAULT_SPP);
        // The resolved spec states its bounce limit: the default one.
        assert_eq!(
            none.integrator,
            IntegratorSpec::default()
                .with_max_depth(rt_integrators::DEFAULT_MAX_DEPTH)
                .unwrap()
        );
        assert_eq!(none.accel, AccelSpec::default());
        let desc = table(|d| {
            d.spp = Some(8);
            d.max_depth = Some(3);
            d.integrator = Some("path-bsdf".into());
            d.seed = Some(1 << 32);
        });
        let t = Overrides::default().resolve(&desc, path).unwrap();
        assert_eq!((t.spp, t.integrator.depth()), (8, 3));
        assert_eq!(t.integrator.kind, IntegratorKind::PathBsdf);
        assert_eq!(t.seed, 1);
        let o = Overrides {
            spp: Some(2),
            max_depth: Some(5),
            ..Overrides::default()
        };
        let g = o.resolve(&desc, path).unwrap();
        assert_eq!((g.spp, g.integrator.depth()), (2, 5));
        // The denoiser: none by default, the table's, the given one, or `none` given.
        assert_eq!(none.denoiser, None);
        let desc = table(|d| d.denoiser = Some("nlm:k=0.3".into()));
        let t = Overrides::default().resolve(&desc, path).unwrap();
        assert_eq!(t.denoiser.as_deref(), Some("nlm:k=0.3"));
        let given = |d: &str| Overrides {
            denoiser: Some(d.into()),
            ..Overrides::default()
        };
        let g = given("atrous").resolve(&desc, path).unwrap();
        assert_eq!(g.denoiser.as_deref(), Some("atrous"));
        assert_eq!(given("none").resolve(&desc, path).unwrap().denoiser, None);
        // An explicit option in the spec text is the most specific setting.
        let o = Overrides {
            integrator: Some("path:max-depth=2".parse().unwrap()),
            max_depth: Some(5),
            ..Overrides::default()
        };
        assert_eq!(o.resolve(&desc, path).unwrap().integrator.depth(), 2);
        // Even when the spec names the default.
        let o = Overrides {
            integrator: Some("path:max-depth=16".parse().unwrap()),
            max_depth: Some(5),
            ..Overrides::default()
        };
        assert_eq!(o.resolve(&desc, path).unwrap().integrator.depth(), 16);
    }

    #[test]
    fn errors_name_their_origin() {
        let path = Path::new("s.toml");
        let e = Overrides::default()
            .resolve(&table(|d| d.spp = Some(0)), path)
            .unwrap_err();
        assert!(e.to_string().starts_with("s.toml: [render] spp:"), "{e}");
        let e = Overrides {
            threads: Some(0),
            ..Overrides::default()
        }
        .resolve(&RenderDesc::default(), path)
        .unwrap_err();
        assert!(e.to_string().starts_with("--threads: thread count"), "{e}");
        let e = Overrides::default()
            .resolve(&table(|d| d.integrator = Some("vcm".into())), path)
            .unwrap_err();
        assert!(
            e.to_string().contains("[render] integrator: \"vcm\""),
            "{e}"
        );
        let e = Overrides::default()
            .resolve(&table(|d| d.accel = Some("kd".into())), path)
            .unwrap_err();
        assert!(e.to_string().contains("[render] accel = \"kd\""), "{e}");
        for (bad, why) in [
            ("optix", "unknown denoiser 'optix'"),
            ("nlm:k=-1", "k"),
            ("nlm:size=3", "size"),
            ("svgf", "unknown denoiser 'svgf'"),
        ] {
            let e = Overrides::default()
                .resolve(&table(|d| d.denoiser = Some(bad.into())), path)
                .unwrap_err()
                .to_string();
            assert!(
                e.starts_with(&format!("s.toml: [render] denoiser = \"{bad}\": "))
                    && e.contains(why)
                    && !e.contains('\n'),
                "{e}"
            );
        }
        let e = Overrides::default()
            .resolve(
                &table(|d| d.max_depth = Some(rt_integrators::MAX_DEPTH + 1)),
                path,
            )
            .unwrap_err();
        assert!(e.to_string().contains("max_depth"), "{e}");
        let e = Overrides {
            aovs: Some(vec!["gloss".into()]),
            ..Overrides::default()
        }
        .resolve(&RenderDesc::default(), path)
        .unwrap_err();
        assert!(e.to_string().contains("--aov") && e.to_string().contains("gloss"));
    }
}
