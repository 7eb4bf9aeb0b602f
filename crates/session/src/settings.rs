//! The one place where a render's settings are resolved: each value comes from what the caller
//! gives (command-line flags, an experiment method, `render reference` flags), else from the
//! scene's `[render]` table, else from the default. Limits ([`rt_core::limits`]) are checked
//! here, for both sources, and errors name where the bad value came from (the flag, or the
//! scene file and key). What the settings cannot honour together (AOVs a technique does not
//! write, a denoiser beside saved AOVs, a denoiser reading channels the technique leaves
//! empty) is refused here too, so every caller refuses it alike.

use crate::text;
use rt_accel::AccelSpec;
use rt_film::AovSet;
use rt_integrators::spec::check_max_depth;
use rt_integrators::{IntegratorSpec, IntegratorSpecError};
use rt_scene::{LoadedScene, RenderDesc};
use rt_temporal::TemporalSpec;
use serde::{Deserialize, Serialize};
use std::fmt;
use std::path::{Path, PathBuf};

pub use rt_core::limits::{MAX_SPP, MAX_THREADS};

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
    /// Denoiser (`--denoiser`), as text: a single-frame spec or a temporal one (`svgf`);
    /// `none` turns the table's off.
    pub denoiser: Option<String>,
}

/// Fully resolved settings of one render.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Settings {
    /// Integrator and its parameters.
    #[serde(with = "text")]
    pub integrator: IntegratorSpec,
    /// Acceleration structure (the scene's default, [`AccelSpec::default_for_scene`], when
    /// nothing names one).
    #[serde(with = "text")]
    pub accel: AccelSpec,
    /// Samples per pixel.
    pub spp: u32,
    /// Worker threads (`None`: all cores).
    pub threads: Option<usize>,
    /// The 32-bit stream key ([`fold_seed`] of the 64-bit seed).
    pub seed: u32,
    /// AOVs to write.
    #[serde(with = "text::aovs")]
    pub aovs: AovSet,
    /// Output path, if the caller or the table named one.
    pub output: Option<PathBuf>,
    /// The denoiser the image is filtered with (`None`: no denoising): a single-frame spec
    /// ([`TemporalSpec::PerFrame`]; the table's is always one) or a temporal one
    /// ([`TemporalSpec::Svgf`], for sequences).
    #[serde(with = "text::option")]
    pub denoiser: Option<TemporalSpec>,
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
    /// A bad `--denoiser` name or option.
    #[error("--denoiser {text}: {message}")]
    GivenDenoiser {
        /// The spec as written.
        text: String,
        /// What is wrong.
        message: String,
    },
    /// A denoiser the other settings cannot honour: beside saved AOVs, or reading the
    /// lighting split of a technique that does not write it.
    #[error("{scene}{denoiser} {why}", scene = scene_prefix(scene, denoiser))]
    DenoiserConflict {
        /// The scene file.
        scene: PathBuf,
        /// The denoiser as the user gave it (`--denoiser X`, `[render] denoiser = "X"`).
        denoiser: String,
        /// What it cannot do.
        why: String,
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

/// `file: ` before a denoiser named on the command line (the table's names its file).
fn scene_prefix(scene: &Path, denoiser: &str) -> String {
    if denoiser.starts_with("--") {
        format!("{}: ", scene.display())
    } else {
        String::new()
    }
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
    /// Resolves every setting for the scene `loaded`, read from `scene_path`.
    pub fn resolve(
        &self,
        loaded: &LoadedScene,
        scene_path: &Path,
    ) -> Result<Settings, SettingsError> {
        let desc = &loaded.render;
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
        let aov_origin = || origin(self.aovs.is_some(), "aov", "aov");
        let aovs = match names {
            None => AovSet::default(),
            Some(list) => {
                AovSet::parse_list(list.iter().map(String::as_str)).map_err(|source| {
                    SettingsError::Aov {
                        origin: aov_origin(),
                        source,
                    }
                })?
            }
        };
        let integrator = self.integrator_spec(desc, scene_path)?;
        let technique = integrator.build();
        // The block map is the stopping criterion's, which serves every technique.
        let per_pixel = AovSet {
            blocks: false,
            ..aovs
        };
        if technique.splats() && per_pixel != AovSet::default() {
            return Err(SettingsError::AovUnsupported {
                origin: aov_origin(),
                technique: integrator.kind.name(),
            });
        }
        if aovs.any_split() && !technique.writes_split() {
            return Err(SettingsError::SplitUnsupported {
                origin: aov_origin(),
                technique: integrator.kind.name(),
            });
        }
        let denoiser = self.denoiser(desc, scene_path)?;
        if let Some(d) = &denoiser {
            let conflict = |why: String| {
                let denoiser = if self.denoiser.is_some() {
                    format!("--denoiser {d}")
                } else {
                    format!("{}: [render] denoiser = \"{d}\"", scene_path.display())
                };
                Err(SettingsError::DenoiserConflict {
                    scene: scene_path.to_path_buf(),
                    denoiser,
                    why,
                })
            };
            if aovs != AovSet::default() {
                return conflict(if self.denoiser.is_some() {
                    "writes the denoised image only; save a noisy frame's AOVs with a render without it".into()
                } else {
                    "writes the denoised image only; add --denoiser none to save a noisy frame's AOVs".into()
                });
            }
            let reads = match d.build() {
                Ok(built) => AovSet::for_channels(built.needs()),
                Err(_) => AovSet::default(),
            };
            if reads.any_split() && !technique.writes_split() {
                return conflict(format!(
                    "reads the lighting split (emission, direct, indirect), which the {} technique does not write",
                    integrator.kind.name()
                ));
            }
        }
        Ok(Settings {
            integrator,
            accel: self.accel_spec(loaded, scene_path)?,
            spp,
            threads,
            seed: self.seed(desc),
            aovs,
            output: self
                .output
                .clone()
                .or_else(|| desc.output.as_ref().map(PathBuf::from)),
            denoiser,
        })
    }

    /// The denoiser alone: the given text (`none`: no denoiser; a single-frame or a temporal
    /// spec), else the table's, which must be a single-frame denoiser. Both are built once
    /// here, so a bad option is found before anything renders.
    pub fn denoiser(
        &self,
        desc: &RenderDesc,
        scene_path: &Path,
    ) -> Result<Option<TemporalSpec>, SettingsError> {
        if let Some(text) = &self.denoiser {
            if text.trim().eq_ignore_ascii_case("none") {
                return Ok(None);
            }
            let given = |message: String| SettingsError::GivenDenoiser {
                text: text.clone(),
                message,
            };
            let spec: TemporalSpec = text.parse().map_err(|e| given(format!("{e}")))?;
            spec.build().map_err(|e| given(e.to_string()))?;
            return Ok(Some(spec));
        }
        let Some(text) = &desc.denoiser else {
            return Ok(None);
        };
        let spec = text
            .parse::<rt_denoise::DenoiserSpec>()
            .and_then(|spec| spec.build().map(|_| spec))
            .map_err(|e| SettingsError::Denoiser {
                origin: Origin::Table {
                    file: scene_path.to_path_buf(),
                    key: "denoiser",
                },
                text: text.clone(),
                message: e.to_string(),
            })?;
        Ok(Some(TemporalSpec::PerFrame(spec)))
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

    /// The acceleration structure alone: the given one, else the table's, else the scene's
    /// default ([`AccelSpec::default_for_scene`]: `clusters` when instances move).
    pub fn accel_spec(
        &self,
        loaded: &LoadedScene,
        scene_path: &Path,
    ) -> Result<AccelSpec, SettingsError> {
        if let Some(a) = self.accel {
            return Ok(a);
        }
        match &loaded.render.accel {
            Some(text) => text.parse().map_err(|source| SettingsError::Accel {
                origin: Origin::Table {
                    file: scene_path.to_path_buf(),
                    key: "accel",
                },
                text: text.clone(),
                source,
            }),
            None => Ok(AccelSpec::default_for_scene(&loaded.scene)),
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

    fn table(toml_like: impl FnOnce(&mut RenderDesc)) -> LoadedScene {
        let mut render = RenderDesc::default();
        toml_like(&mut render);
        LoadedScene {
            scene: rt_core::Scene::empty(),
            render,
            warnings: Vec::new(),
        }
    }

    #[test]
    fn given_wins_over_table_over_default() {
        let path = Path::new("s.toml");
        let none = Overrides::default().resolve(&table(|_| {}), path).unwrap();
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
        assert_eq!(t.denoiser.unwrap().to_string(), "nlm:k=0.3");
        let given = |d: &str| Overrides {
            denoiser: Some(d.into()),
            ..Overrides::default()
        };
        let g = given("atrous").resolve(&desc, path).unwrap();
        assert_eq!(g.denoiser.unwrap().to_string(), "atrous");
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
        .resolve(&table(|_| {}), path)
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
        .resolve(&table(|_| {}), path)
        .unwrap_err();
        assert!(e.to_string().contains("--aov") && e.to_string().contains("gloss"));
    }

    #[test]
    fn denoisers_the_settings_cannot_honour_are_refused_naming_their_origin() {
        let path = Path::new("s.toml");
        let desc = table(|d| d.denoiser = Some("box:radius=2".into()));
        let with =
            |o: Overrides, desc: &LoadedScene| o.resolve(desc, path).unwrap_err().to_string();
        let aovs = |d: Option<&str>| Overrides {
            aovs: Some(vec!["albedo".into()]),
            denoiser: d.map(str::to_string),
            ..Overrides::default()
        };
        let e = with(aovs(None), &desc);
        assert!(
            e.starts_with(
                "s.toml: [render] denoiser = \"box:radius=2\" writes the denoised image only"
            ) && e.contains("--denoiser none"),
            "{e}"
        );
        let e = with(aovs(Some("svgf")), &desc);
        assert!(
            e.starts_with("s.toml: --denoiser svgf writes the denoised image only"),
            "{e}"
        );
        assert!(aovs(Some("none")).resolve(&desc, path).is_ok());
        let split = Overrides {
            integrator: Some("ao".parse().unwrap()),
            denoiser: Some("svgf".into()),
            ..Overrides::default()
        };
        let e = with(split, &desc);
        assert!(
            e.starts_with("s.toml: --denoiser svgf reads the lighting split"),
            "{e}"
        );
        let bad = Overrides {
            denoiser: Some("nlm:k=-1".into()),
            ..Overrides::default()
        };
        assert!(with(bad, &desc).starts_with("--denoiser nlm:k=-1: "));
    }

    #[test]
    fn the_default_structure_follows_the_scene_and_settings_round_trip_as_json() {
        let path = Path::new("s.toml");
        let mut moving = table(|_| {});
        moving.scene = rt_scene::load_any(Path::new("gen:car")).unwrap().scene;
        let s = Overrides::default().resolve(&moving, path).unwrap();
        assert_eq!(s.accel, AccelSpec::default_for_scene(&moving.scene));
        assert_eq!(s.accel.kind, rt_accel::AccelKind::Clusters);
        let still = Overrides::default().resolve(&table(|_| {}), path).unwrap();
        assert_eq!(still.accel, AccelSpec::default());
        let given = Overrides {
            integrator: Some("path:max-depth=3".parse().unwrap()),
            aovs: Some(vec!["albedo".into(), "variance".into()]),
            denoiser: Some("svgf:alpha=0.1".into()),
            ..Overrides::default()
        };
        let given = Overrides {
            aovs: None,
            ..given
        }
        .resolve(&moving, path)
        .unwrap();
        for s in [s, still, given] {
            let json = serde_json::to_string(&s).unwrap();
            let back: Settings = serde_json::from_str(&json).unwrap();
            assert_eq!(back, s, "{json}");
        }
    }
}
