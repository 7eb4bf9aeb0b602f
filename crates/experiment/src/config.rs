//! The experiment file (TOML; every key in docs/experiments.md) and its validation. Everything
//! that can be wrong is found here, before the first sample of a long grid: scenes load,
//! cameras exist, names are unique, budgets are sane, reference files match the image size.

use crate::{ExperimentError, Result as CrateResult};
use rt_accel::AccelSpec;
use rt_core::Camera;
use rt_denoise::DenoiserSpec;
use rt_film::{read_rgb, AovSet};
use rt_integrators::spec::{check_ao_distance, check_max_depth};
use rt_integrators::IntegratorSpec;
use rt_metrics::RgbImage;
use rt_scene::LoadedScene;
use rt_session::{pick_camera, Budgets, ImageSize, Overrides, StopRule, MAX_SPP};
use rt_temporal::TemporalSpec;
use serde::de::{self, MapAccess, Visitor};
use serde::{Deserialize, Deserializer};
use std::collections::HashSet;
use std::fmt;
use std::path::{Path, PathBuf};

/// Longest time budget accepted, in seconds (a day): anything longer is a typo.
const MAX_SECONDS: f64 = rt_session::adaptive::MAX_TIME_LIMIT;

/// Validation inside [`build`] speaks in messages about one entry; [`load`] makes them a
/// [`ExperimentError::Config`] naming the file.
type Result<T, E = String> = std::result::Result<T, E>;

/// Returns a validation message.
macro_rules! bail {
    ($($arg:tt)*) => {
        return Err(format!($($arg)*))
    };
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct ConfigDesc {
    name: Option<String>,
    epsilon: Option<f64>,
    crop: Option<u32>,
    #[serde(default)]
    scene: Vec<SceneDesc>,
    #[serde(default)]
    method: Vec<MethodDesc>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct SceneDesc {
    path: String,
    name: Option<String>,
    camera: Option<String>,
    resolution: Option<[u32; 2]>,
    scale: Option<f64>,
    reference: Option<ReferenceDesc>,
    frames: Option<[u32; 2]>,
    fps: Option<f64>,
    event: Option<u32>,
}

/// `reference = "file.exr"` or `reference = { spp = 4096, ... }`.
enum ReferenceDesc {
    File(String),
    Render(RenderReferenceDesc),
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RenderReferenceDesc {
    spp: u32,
    integrator: Option<String>,
    max_depth: Option<u32>,
    ao_distance: Option<f32>,
    seed: Option<u64>,
    accel: Option<String>,
}

impl<'de> Deserialize<'de> for ReferenceDesc {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        struct V;
        impl<'de> Visitor<'de> for V {
            type Value = ReferenceDesc;
            fn expecting(&self, f: &mut fmt::Formatter) -> fmt::Result {
                f.write_str("an image file name or a table such as { spp = 4096 }")
            }
            fn visit_str<E: de::Error>(self, s: &str) -> Result<ReferenceDesc, E> {
                Ok(ReferenceDesc::File(s.to_string()))
            }
            fn visit_map<A: MapAccess<'de>>(self, map: A) -> Result<ReferenceDesc, A::Error> {
                RenderReferenceDesc::deserialize(de::value::MapAccessDeserializer::new(map))
                    .map(ReferenceDesc::Render)
            }
        }
        d.deserialize_any(V)
    }
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct MethodDesc {
    name: String,
    integrator: Option<String>,
    accel: Option<String>,
    max_depth: Option<u32>,
    ao_distance: Option<f32>,
    seed: Option<u64>,
    spp: Option<OneOrMany<u32>>,
    seconds: Option<Vec<f64>>,
    error: Option<OneOrMany<f32>>,
    time_limit: Option<OneOrMany<f64>>,
    scenes: Option<Vec<String>>,
    denoiser: Option<String>,
    gree: Option<String>,
    bank: Option<Vec<String>>,
}

/// `key = V` or `key = [V, ...]` of numbers.
enum OneOrMany<T> {
    One(T),
    Many(Vec<T>),
}

impl<'de, T: Deserialize<'de>> Deserialize<'de> for OneOrMany<T> {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        use serde::de::IntoDeserializer;
        struct V<T>(std::marker::PhantomData<T>);
        impl<'de, T: Deserialize<'de>> Visitor<'de> for V<T> {
            type Value = OneOrMany<T>;
            fn expecting(&self, f: &mut fmt::Formatter) -> fmt::Result {
                f.write_str("a number or a list of numbers")
            }
            fn visit_i64<E: de::Error>(self, v: i64) -> Result<Self::Value, E> {
                T::deserialize(v.into_deserializer()).map(OneOrMany::One)
            }
            fn visit_u64<E: de::Error>(self, v: u64) -> Result<Self::Value, E> {
                T::deserialize(v.into_deserializer()).map(OneOrMany::One)
            }
            fn visit_f64<E: de::Error>(self, v: f64) -> Result<Self::Value, E> {
                T::deserialize(v.into_deserializer()).map(OneOrMany::One)
            }
            fn visit_seq<A: de::SeqAccess<'de>>(self, seq: A) -> Result<Self::Value, A::Error> {
                Vec::<T>::deserialize(de::value::SeqAccessDeserializer::new(seq))
                    .map(OneOrMany::Many)
            }
        }
        d.deserialize_any(V(std::marker::PhantomData))
    }
}

impl<T> OneOrMany<T> {
    fn into_vec(self) -> Vec<T> {
        match self {
            OneOrMany::One(v) => vec![v],
            OneOrMany::Many(v) => v,
        }
    }
}

/// A validated experiment.
pub struct Plan {
    /// Experiment name (output folder, report title).
    pub name: String,
    /// The experiment file.
    pub path: PathBuf,
    /// relMSE's epsilon.
    pub epsilon: f64,
    /// Side of the report's crops in pixels.
    pub crop: u32,
    /// Scenes in file order.
    pub scenes: Vec<ScenePlan>,
    /// Methods in file order.
    pub methods: Vec<MethodPlan>,
    /// Every (scene, method) pair to run, scene-major.
    pub pairs: Vec<Pair>,
    /// Things worth saying that do not stop the experiment.
    pub warnings: Vec<String>,
}

impl Plan {
    /// True for a sequence experiment (every scene has `frames`; methods render frames).
    pub fn is_sequence(&self) -> bool {
        self.scenes.iter().any(|s| s.sequence.is_some())
    }
}

/// One scene of the grid.
pub struct ScenePlan {
    /// Short name (file names, report).
    pub name: String,
    /// The scene file, relative to the working directory.
    pub path: PathBuf,
    /// The loaded scene.
    pub loaded: LoadedScene,
    /// The camera, resized.
    pub camera: Camera,
    /// Where the reference comes from.
    pub reference: ReferencePlan,
    /// For a sequence scene (`frames = [A, B]`): which frames, at what rate, and how the
    /// camera is found again after the scene moves.
    pub sequence: Option<SequencePlan>,
}

impl ScenePlan {
    /// The request for a reference of this scene rendered by `estimator` at `spp` samples
    /// per pixel from stream `seed` (a [`ReferencePlan::Render`]'s fields).
    pub fn reference_request(
        &self,
        estimator: IntegratorSpec,
        spp: u32,
        seed: u32,
    ) -> crate::ReferenceRequest<'_> {
        crate::ReferenceRequest {
            scene_path: &self.path,
            scene: &self.loaded.scene,
            camera: &self.camera,
            estimator,
            spp,
            seed,
        }
    }
}

/// The frames of a sequence scene.
#[derive(Clone, Debug, PartialEq)]
pub struct SequencePlan {
    /// Frames `A..B` (half-open, at least two).
    pub frames: std::ops::Range<u32>,
    /// Frames per second: frame `f` is at time `f / fps`.
    pub fps: f64,
    /// A frame where something changes (a light toggles); the lag is measured from it. Inside
    /// `frames`, after the first.
    pub event: Option<u32>,
    /// The camera's name (`None`: the scene's first), looked up again at every frame's time
    /// because cameras may move.
    pub camera: Option<String>,
    /// The image size applied to the camera at every frame.
    pub size: ImageSize,
}

impl SequencePlan {
    /// How many frames.
    pub fn len(&self) -> usize {
        self.frames.len()
    }

    /// True when there are none (never, for a validated plan).
    pub fn is_empty(&self) -> bool {
        self.frames.is_empty()
    }
}

/// A scene's reference.
pub enum ReferencePlan {
    /// A user's image, already loaded (and checked to be the right size).
    File {
        /// The file.
        path: PathBuf,
        /// Its pixels.
        image: RgbImage,
    },
    /// Rendered by us (or taken from the cache).
    Render {
        /// Samples per pixel.
        spp: u32,
        /// Integrator and parameters.
        estimator: IntegratorSpec,
        /// Seed of the reference stream.
        seed: u32,
        /// Structure to render it with.
        accel: AccelSpec,
    },
}

/// One method of the grid.
pub struct MethodPlan {
    /// Short name (file names, legends).
    pub name: String,
    /// What it renders on each scene.
    pub runs: Runs,
    /// The denoiser applied to each of its images (`denoiser = "kind:key=value"`), already
    /// checked to build; its output is the method's image and error.
    pub denoiser: Option<DenoiserSpec>,
    /// GREE (`gree = "OPTIONS"`, `bank = [...]`): each `spp` budget is GREE's budget b, spent
    /// on its noisy image and its filter caches ([`rt_session::render_gree`]).
    pub gree: Option<GreePlan>,
    /// A sequence method's denoiser (`denoiser = "svgf[:options]"` or any single-frame spec,
    /// run per frame), already checked to build. Image experiments use [`MethodPlan::denoiser`].
    pub temporal: Option<TemporalSpec>,
}

/// A GREE method's settings, checked at load.
#[derive(Clone, Debug, PartialEq)]
pub struct GreePlan {
    /// GREE's options (`key=value:...`).
    pub options: rt_session::GreeSpec,
    /// The filter bank's denoiser specs.
    pub bank: Vec<String>,
}

/// How a method renders on a scene.
#[derive(Clone, Debug, PartialEq)]
pub enum Runs {
    /// One progressive render with a snapshot at each budget (`spp = [...]` or
    /// `seconds = [...]`): uniform sampling.
    Progressive(Budgets),
    /// One render per rule, each from the first sample, stopped as `render --error V
    /// --time-limit S --spp N` stops ([`rt_session::render_adaptive`]): `error` and
    /// `time_limit`, with `spp` as the cap (default [`MAX_SPP`]). In the order written
    /// (sorted: the largest error first, then the shortest time).
    Adaptive(Vec<StopRule>),
    /// A sequence experiment's method: every frame rendered at `spp` samples per pixel
    /// ([`Pair::sequence_job`]).
    Sequence {
        /// Samples per pixel per frame.
        spp: u32,
    },
}

impl Runs {
    /// How many images the method makes per scene.
    pub fn len(&self) -> usize {
        match self {
            Runs::Progressive(b) => b.len(),
            Runs::Adaptive(v) => v.len(),
            Runs::Sequence { .. } => 1,
        }
    }

    /// True when it makes none (never, for a validated plan).
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// The progressive budgets, if the method has them.
    pub fn budgets(&self) -> Option<&Budgets> {
        match self {
            Runs::Progressive(b) => Some(b),
            Runs::Adaptive(_) | Runs::Sequence { .. } => None,
        }
    }
}

/// A method on a scene, with its settings resolved against that scene's `[render]` table.
pub struct Pair {
    /// Index into [`Plan::scenes`].
    pub scene: usize,
    /// Index into [`Plan::methods`].
    pub method: usize,
    /// Integrator and parameters.
    pub estimator: IntegratorSpec,
    /// Acceleration structure.
    pub accel: AccelSpec,
    /// Seed.
    pub seed: u32,
}

/// Names become file names: keep them portable.
fn check_name(what: &str, name: &str) -> Result<(), String> {
    let ok = !name.is_empty()
        && name.len() <= 64
        && name
            .chars()
            .next()
            .is_some_and(|c| c.is_ascii_alphanumeric())
        && name
            .chars()
            .all(|c| c.is_ascii_alphanumeric() || matches!(c, '-' | '_' | '.'));
    if ok {
        Ok(())
    } else {
        Err(format!(
            "{what} name \"{name}\" must be 1-64 letters, digits, '-', '_' or '.', starting with a letter or digit"
        ))
    }
}

fn parse_accel(s: &str) -> Result<AccelSpec, String> {
    s.parse::<AccelSpec>()
        .map_err(|e| format!("accel = \"{s}\": {e}"))
}

fn parse_integrator(s: &str) -> Result<IntegratorSpec, String> {
    s.parse::<IntegratorSpec>()
        .map_err(|e| format!("integrator = {e}"))
}

/// Parses a denoiser spec and builds it once, so bad options are found at load.
fn parse_denoiser(s: &str) -> Result<DenoiserSpec, String> {
    let at = |e: rt_denoise::DenoiseError| format!("denoiser = \"{s}\": {e}");
    let spec = s.parse::<DenoiserSpec>().map_err(at)?;
    spec.build().map_err(at)?;
    Ok(spec)
}

fn check_depth(d: Option<u32>) -> Result<Option<u32>, String> {
    d.map(check_max_depth)
        .transpose()
        .map_err(|e| format!("max_depth: {e}"))
}

fn check_ao(d: Option<f32>) -> Result<Option<f32>, String> {
    d.map(check_ao_distance)
        .transpose()
        .map_err(|e| format!("ao_distance: {e}"))
}

/// Reads and validates the experiment file at `path`. Every error is one line that starts with
/// the file's name.
pub fn load(path: &Path) -> CrateResult<Plan> {
    load_with(path, &rt_scene::FileAccess::open())
}

/// [`load_with`] confined to the directory `confine` (`--confine`), or reading anything.
pub fn load_confined(path: &Path, confine: Option<&Path>) -> CrateResult<Plan> {
    let access = match confine {
        Some(dir) => rt_scene::FileAccess::confined_to(dir)?,
        None => rt_scene::FileAccess::open(),
    };
    load_with(path, &access)
}

/// [`load`], reading only the files `access` allows (`--confine`): the experiment file, its
/// scenes and everything they refer to, and reference images.
pub fn load_with(path: &Path, access: &rt_scene::FileAccess) -> CrateResult<Plan> {
    let config = |message: String| ExperimentError::Config {
        file: path.to_path_buf(),
        message,
    };
    access.check(path).map_err(|e| config(e.to_string()))?;
    let text = std::fs::read_to_string(path).map_err(|e| config(format!("cannot open: {e}")))?;
    let desc: ConfigDesc = toml::from_str(&text).map_err(|e| {
        let at = e
            .span()
            .map(|s| format!(":{}", rt_scene::LineCol::of_offset(&text, s.start)))
            .unwrap_or_default();
        let message: Vec<&str> = e.message().lines().map(str::trim).collect();
        ExperimentError::Config {
            file: PathBuf::from(format!("{}{at}", path.display())),
            message: message.join("; "),
        }
    })?;
    build(desc, path, access).map_err(config)
}

fn build(desc: ConfigDesc, path: &Path, access: &rt_scene::FileAccess) -> Result<Plan> {
    let base = path.parent().unwrap_or(Path::new(""));
    let name = match desc.name {
        Some(n) => n,
        None => path
            .file_stem()
            .map(|s| s.to_string_lossy().into_owned())
            .unwrap_or_else(|| "experiment".into()),
    };
    check_name("experiment", &name)?;
    let epsilon = desc.epsilon.unwrap_or(rt_metrics::DEFAULT_EPSILON);
    if !(epsilon.is_finite() && epsilon > 0.0) {
        bail!("epsilon must be a positive number, got {epsilon}");
    }
    let crop = desc.crop.unwrap_or(64);
    if !(8..=1024).contains(&crop) {
        bail!("crop must be between 8 and 1024 pixels, got {crop}");
    }
    if desc.scene.is_empty() {
        bail!("no [[scene]]: an experiment needs at least one");
    }
    if desc.method.is_empty() {
        bail!("no [[method]]: an experiment needs at least one");
    }
    let mut warnings = Vec::new();

    let mut scenes = Vec::new();
    let mut seen = HashSet::new();
    for s in desc.scene {
        // Procedural scenes (`gen:NAME`) are names, not files.
        let scene_path = if s.path.starts_with("gen:") {
            PathBuf::from(&s.path)
        } else {
            base.join(&s.path)
        };
        let name = s
            .name
            .clone()
            .unwrap_or_else(|| match s.path.strip_prefix("gen:") {
                Some(generated) => generated.to_string(),
                None => scene_path
                    .file_stem()
                    .map(|n| n.to_string_lossy().into_owned())
                    .unwrap_or_default(),
            });
        let here = format!("[[scene]] \"{name}\"");
        check_name("scene", &name).map_err(|e| format!("{here}: {e}"))?;
        if !seen.insert(name.clone()) {
            bail!("{here}: two scenes are named \"{name}\" (set name = \"...\")");
        }
        let size = match (s.resolution, s.scale) {
            (Some(_), Some(_)) => bail!("{here}: give resolution or scale, not both"),
            (Some([w, h]), None) => ImageSize::Pixels(w, h),
            (None, Some(f)) => ImageSize::Scale(f),
            (None, None) => ImageSize::Native,
        };
        size.validate(&here).map_err(|e| e.to_string())?;
        let loaded =
            rt_scene::load_any_with(&scene_path, access).map_err(|e| format!("{here}: {e}"))?;
        let camera = size.apply(
            pick_camera(&loaded.scene, &scene_path, s.camera.as_deref())
                .map_err(|e| format!("{here}: {e}"))?,
        );
        let sequence = sequence_plan(&s, size, &here)?;
        let reference = match s.reference {
            Some(ReferenceDesc::File(_)) if sequence.is_some() => bail!(
                "{here}: a sequence's reference is rendered frame by frame: give reference = {{ spp = N }}, not an image file"
            ),
            None => bail!(
                "{here}: no reference (reference = {{ spp = N }} or reference = \"image.exr\")"
            ),
            Some(ReferenceDesc::File(f)) => {
                let file = base.join(&f);
                access
                    .check(&file)
                    .map_err(|e| format!("{here}: reference: {e}"))?;
                let image = read_rgb(&file).map_err(|e| format!("{here}: reference: {e}"))?;
                let (w, h) = (image.width(), image.height());
                if (w, h) != (camera.width as usize, camera.height as usize) {
                    bail!(
                        "{here}: reference {} is {w}x{h} but the scene renders at {}x{}",
                        file.display(),
                        camera.width,
                        camera.height
                    );
                }
                ReferencePlan::File { path: file, image }
            }
            Some(ReferenceDesc::Render(r)) => {
                if r.spp == 0 || r.spp > MAX_SPP {
                    bail!(
                        "{here}: reference spp must be between 1 and {MAX_SPP}, got {}",
                        r.spp
                    );
                }
                let at = |e: String| format!("{here}: reference: {e}");
                let overrides = Overrides {
                    integrator: r
                        .integrator
                        .as_deref()
                        .map(parse_integrator)
                        .transpose()
                        .map_err(at)?,
                    max_depth: check_depth(r.max_depth).map_err(at)?,
                    ao_distance: check_ao(r.ao_distance).map_err(at)?,
                    seed: r.seed,
                    accel: r
                        .accel
                        .as_deref()
                        .map(parse_accel)
                        .transpose()
                        .map_err(at)?,
                    ..Overrides::default()
                };
                let estimator = overrides
                    .integrator_spec(&loaded.render, &scene_path)
                    .map_err(|e| e.to_string())?;
                ReferencePlan::Render {
                    spp: r.spp,
                    estimator,
                    seed: overrides.seed(&loaded.render),
                    accel: overrides
                        .accel_spec(&loaded, &scene_path)
                        .map_err(|e| e.to_string())?,
                }
            }
        };
        scenes.push(ScenePlan {
            name,
            path: scene_path,
            loaded,
            camera,
            reference,
            sequence,
        });
    }
    if let (Some(seq), Some(still)) = (
        scenes.iter().find(|s| s.sequence.is_some()),
        scenes.iter().find(|s| s.sequence.is_none()),
    ) {
        bail!(
            "[[scene]] \"{}\" has no frames but [[scene]] \"{}\" is a sequence: an experiment's scenes are all sequences (frames = [A, B]) or all single images",
            still.name,
            seq.name
        );
    }
    let sequences = scenes.iter().any(|s| s.sequence.is_some());

    let mut methods = Vec::new();
    let mut method_overrides = Vec::new();
    let mut method_scenes = Vec::new();
    let mut seen = HashSet::new();
    for m in desc.method {
        let here = format!("[[method]] \"{}\"", m.name);
        check_name("method", &m.name).map_err(|e| format!("{here}: {e}"))?;
        if m.name == "reference" {
            bail!("{here}: \"reference\" is the name of the references' files; choose another");
        }
        if !seen.insert(m.name.clone()) {
            bail!("{here}: two methods are named \"{}\"", m.name);
        }
        let at = |e: String| format!("{here}: {e}");
        let runs = if sequences {
            sequence_runs(&m).map_err(at)?
        } else if m.error.is_some() || m.time_limit.is_some() {
            Runs::Adaptive(
                stop_rules(m.error, m.time_limit, m.spp, m.seconds.is_some()).map_err(at)?,
            )
        } else {
            Runs::Progressive(budgets(m.spp, m.seconds).map_err(at)?)
        };
        let overrides = Overrides {
            integrator: m
                .integrator
                .as_deref()
                .map(parse_integrator)
                .transpose()
                .map_err(at)?,
            max_depth: check_depth(m.max_depth).map_err(at)?,
            ao_distance: check_ao(m.ao_distance).map_err(at)?,
            seed: m.seed,
            accel: m
                .accel
                .as_deref()
                .map(parse_accel)
                .transpose()
                .map_err(at)?,
            ..Overrides::default()
        };
        if let Some(list) = &m.scenes {
            if list.is_empty() {
                bail!("{here}: scenes is an empty list (leave it out to run on every scene)");
            }
            for s in list {
                if !scenes.iter().any(|p: &ScenePlan| &p.name == s) {
                    let names: Vec<&str> = scenes.iter().map(|p| p.name.as_str()).collect();
                    bail!(
                        "{here}: no scene named \"{s}\" (scenes: {})",
                        names.join(", ")
                    );
                }
            }
        }
        let (denoiser, temporal) = if sequences {
            let t = m.denoiser.as_deref().map(parse_temporal).transpose();
            (None, t.map_err(at)?)
        } else {
            let d = m.denoiser.as_deref().map(parse_denoiser).transpose();
            (d.map_err(at)?, None)
        };
        let gree = match (m.gree, m.bank) {
            (None, None) => None,
            (None, Some(_)) => bail!("{here}: bank is GREE's filter bank: it needs gree = \"...\""),
            (Some(options), bank) => {
                if denoiser.is_some() {
                    bail!("{here}: gree chooses among its bank's denoisers; drop denoiser");
                }
                let Runs::Progressive(Budgets::Spp(budgets)) = &runs else {
                    bail!("{here}: gree spends sample budgets: give spp = [...], not seconds or error");
                };
                let options: rt_session::GreeSpec = options
                    .parse()
                    .map_err(|e: rt_core::options::OptionsError| at(e.to_string()))?;
                for &b in budgets {
                    options.params(b, 0).map_err(|e| at(format!("gree: {e}")))?;
                }
                let bank = bank.unwrap_or_else(|| {
                    rt_denoise::DEFAULT_BANK
                        .iter()
                        .map(|s| s.to_string())
                        .collect()
                });
                rt_denoise::Bank::from_specs(&bank).map_err(|e| at(format!("bank: {e}")))?;
                Some(GreePlan { options, bank })
            }
        };
        methods.push(MethodPlan {
            name: m.name,
            runs,
            denoiser,
            gree,
            temporal,
        });
        method_overrides.push(overrides);
        method_scenes.push(m.scenes);
    }

    let mut pairs = Vec::new();
    for (si, scene) in scenes.iter().enumerate() {
        for (mi, method) in methods.iter().enumerate() {
            if method_scenes[mi]
                .as_ref()
                .is_some_and(|list| !list.contains(&scene.name))
            {
                continue;
            }
            let o = &method_overrides[mi];
            let desc = &scene.loaded.render;
            let here =
                |e: rt_session::SettingsError| format!("[[method]] \"{}\": {e}", method.name);
            let estimator = o.integrator_spec(desc, &scene.path).map_err(here)?;
            if let Some(t) = &method.temporal {
                let reads_split = t
                    .build()
                    .is_ok_and(|d| AovSet::for_channels(d.needs()).any_split());
                let technique = estimator.build();
                if reads_split && !technique.writes_split() {
                    bail!(
                        "[[method]] \"{}\": denoiser = \"{t}\" reads the lighting split (direct, indirect, emission), which the {} technique does not write",
                        method.name,
                        technique.name()
                    );
                }
            }
            if let ReferencePlan::Render { estimator: r, .. } = &scene.reference {
                if r.target() != estimator.target() {
                    warnings.push(format!(
                        "method \"{}\" ({}) does not converge to scene \"{}\"'s reference ({}): \
                         its error will level off",
                        method.name,
                        describe(&estimator),
                        scene.name,
                        describe(r)
                    ));
                }
            }
            pairs.push(Pair {
                scene: si,
                method: mi,
                estimator,
                accel: o.accel_spec(&scene.loaded, &scene.path).map_err(here)?,
                seed: o.seed(desc),
            });
        }
    }
    if pairs.is_empty() {
        bail!("no method runs on any scene");
    }
    Ok(Plan {
        name,
        path: path.to_path_buf(),
        epsilon,
        crop,
        scenes,
        methods,
        pairs,
        warnings,
    })
}

/// Longest sequence accepted, in frames: a typo beyond it.
const MAX_FRAMES: u32 = 100_000;

/// The frames of a scene with `frames = [A, B]` (`fps` and `event` only with them).
fn sequence_plan(s: &SceneDesc, size: ImageSize, here: &str) -> Result<Option<SequencePlan>> {
    let Some([a, b]) = s.frames else {
        for (key, given) in [("fps", s.fps.is_some()), ("event", s.event.is_some())] {
            if given {
                bail!("{here}: {key} belongs to a sequence: give frames = [A, B] too");
            }
        }
        return Ok(None);
    };
    if a >= b {
        bail!("{here}: frames = [{a}, {b}]: the first frame must come before the end (frames = [A, B] renders A, A + 1, ..., B - 1)");
    }
    if b - a < 2 {
        bail!("{here}: frames = [{a}, {b}]: a sequence needs at least two frames for its temporal metrics");
    }
    if b - a > MAX_FRAMES {
        bail!("{here}: frames = [{a}, {b}]: at most {MAX_FRAMES} frames");
    }
    let fps = s.fps.unwrap_or(24.0);
    if !(fps.is_finite() && fps > 0.0 && fps <= 1000.0) {
        bail!("{here}: fps must be in (0, 1000], got {fps}");
    }
    if let Some(e) = s.event {
        if !(a < e && e < b) {
            bail!("{here}: event = {e} must be a frame after the first and before the end of frames = [{a}, {b}] (the lag's steady state is measured before it)");
        }
    }
    Ok(Some(SequencePlan {
        frames: a..b,
        fps,
        event: s.event,
        camera: s.camera.clone(),
        size,
    }))
}

/// A sequence method's samples per frame; the budget keys of image experiments are refused.
fn sequence_runs(m: &MethodDesc) -> Result<Runs> {
    for (key, given) in [
        ("seconds", m.seconds.is_some()),
        ("error", m.error.is_some()),
        ("time_limit", m.time_limit.is_some()),
        ("gree", m.gree.is_some()),
        ("bank", m.bank.is_some()),
    ] {
        if given {
            bail!("{key} is not for sequences: a sequence method renders spp = N samples per pixel in every frame");
        }
    }
    let spp = match m.spp.as_ref().map(|s| match s {
        OneOrMany::One(n) => vec![*n],
        OneOrMany::Many(v) => v.clone(),
    }) {
        None => bail!("no spp: a sequence method needs spp = N (samples per pixel per frame)"),
        Some(v) => match v.as_slice() {
            &[n] if (1..=MAX_SPP).contains(&n) => n,
            &[n] => bail!("spp must be between 1 and {MAX_SPP}, got {n}"),
            v => bail!(
                "spp is the samples per pixel of every frame of a sequence: give one value, not a list of {}",
                v.len()
            ),
        },
    };
    Ok(Runs::Sequence { spp })
}

/// Parses a sequence denoiser (`svgf[:options]` or a single-frame spec run per frame) and
/// builds it once, so bad options are found at load.
fn parse_temporal(s: &str) -> Result<TemporalSpec, String> {
    let at = |e: &dyn fmt::Display| format!("denoiser = \"{s}\": {e}");
    let spec = s.parse::<TemporalSpec>().map_err(|e| at(&e))?;
    spec.build().map_err(|e| at(&e))?;
    Ok(spec)
}

/// The budgets of a progressive method: `spp = [...]` or `seconds = [...]`.
fn budgets(spp: Option<OneOrMany<u32>>, seconds: Option<Vec<f64>>) -> Result<Budgets> {
    match (spp.map(OneOrMany::into_vec), seconds) {
        (Some(_), Some(_)) => bail!("give spp or seconds, not both"),
        (None, None) => bail!(
            "no budgets (spp = [...] or seconds = [...], or error = V or time_limit = S for an adaptive render)"
        ),
        (Some(mut v), None) => {
            if v.is_empty() {
                bail!("spp is an empty list");
            }
            if let Some(bad) = v.iter().find(|&&n| n == 0 || n > MAX_SPP) {
                bail!("spp values must be between 1 and {MAX_SPP}, got {bad}");
            }
            v.sort_unstable();
            v.dedup();
            Ok(Budgets::Spp(v))
        }
        (None, Some(mut v)) => {
            if v.is_empty() {
                bail!("seconds is an empty list");
            }
            check_seconds("seconds", &v)?;
            v.sort_by(f64::total_cmp);
            v.dedup();
            Ok(Budgets::Seconds(v))
        }
    }
}

fn check_seconds(key: &str, v: &[f64]) -> Result<()> {
    if let Some(bad) = v
        .iter()
        .find(|&&t| !(t.is_finite() && t > 0.0 && t <= MAX_SECONDS))
    {
        bail!("{key} values must be in (0, {MAX_SECONDS}], got {bad}");
    }
    Ok(())
}

/// The runs of an adaptive method: every `error` threshold (checked as `render --error`
/// checks it, by the stopping criterion itself) or every `time_limit`, at most one of them a
/// list, with `spp` as the cap.
fn stop_rules(
    error: Option<OneOrMany<f32>>,
    time_limit: Option<OneOrMany<f64>>,
    spp: Option<OneOrMany<u32>>,
    has_seconds: bool,
) -> Result<Vec<StopRule>> {
    if has_seconds {
        bail!(
            "seconds are the budgets of a progressive render; an adaptive one (error, time_limit) stops at time_limit = S"
        );
    }
    let max_spp = match spp.map(OneOrMany::into_vec).as_deref() {
        None => MAX_SPP,
        Some(&[n]) if (1..=MAX_SPP).contains(&n) => n,
        Some(&[n]) => bail!("spp (the cap of an adaptive render) must be between 1 and {MAX_SPP}, got {n}"),
        Some(v) => bail!(
            "with error or time_limit, spp is the cap on samples per pixel: give one value, not {} (for several budgets, list error or time_limit)",
            v.len()
        ),
    };
    let mut errors: Vec<Option<f32>> = match error.map(OneOrMany::into_vec) {
        None => vec![None],
        Some(v) if v.is_empty() => bail!("error is an empty list"),
        Some(v) => v.into_iter().map(Some).collect(),
    };
    let mut limits: Vec<Option<f64>> = match time_limit.map(OneOrMany::into_vec) {
        None => vec![None],
        Some(v) if v.is_empty() => bail!("time_limit is an empty list"),
        Some(v) => v.into_iter().map(Some).collect(),
    };
    // Every value checked once, by the rule itself.
    for &e in errors.iter().flatten() {
        StopRule::new(Some(e), None, max_spp).map_err(|b| b.named("error", "time_limit"))?;
    }
    for &t in limits.iter().flatten() {
        StopRule::new(None, Some(t), max_spp).map_err(|b| b.named("error", "time_limit"))?;
    }
    if errors.len() > 1 && limits.len() > 1 {
        bail!("error and time_limit are both lists: give a list for one of them, a single value for the other");
    }
    // Largest threshold first (the cheapest run), shortest time first.
    errors.sort_by(|a, b| b.unwrap_or(0.0).total_cmp(&a.unwrap_or(0.0)));
    errors.dedup();
    limits.sort_by(|a, b| a.unwrap_or(0.0).total_cmp(&b.unwrap_or(0.0)));
    limits.dedup();
    Ok(errors
        .iter()
        .flat_map(|&error| {
            limits
                .iter()
                .map(move |&t| StopRule::new(error, t, max_spp).expect("checked above"))
        })
        .collect())
}

/// `path, 8 bounces` and the like, for messages.
fn describe(e: &IntegratorSpec) -> String {
    format!("{}, {}", e.kind, e.target())
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::time::Duration;

    const SCENE: &str = r#"
[[camera]]
name = "main"
position = [0.0, 1.0, 3.0]
look_at = [0.0, 1.0, 0.0]
resolution = [64, 48]

[[material]]
name = "lamp"
emission = [5.0, 5.0, 5.0]

[[geometry]]
name = "light"
shape = "quad"
vertices = [[-0.3, 2, -0.3], [0.3, 2, -0.3], [0.3, 2, 0.3], [-0.3, 2, 0.3]]
material = "lamp"

[render]
max_depth = 5
"#;

    const GOOD: &str = r#"
name = "t"
[[scene]]
path = "scenes/s.toml"
scale = 0.5
reference = { spp = 16 }

[[method]]
name = "a"
spp = [4, 1, 2, 2]

[[method]]
name = "b"
integrator = "path-bsdf"
accel = "bvh"
seconds = [0.5, 0.1]
"#;

    fn plan(config: &str) -> CrateResult<Plan> {
        let dir = tempfile::tempdir().unwrap();
        std::fs::create_dir(dir.path().join("scenes")).unwrap();
        std::fs::write(dir.path().join("scenes/s.toml"), SCENE).unwrap();
        let path = dir.path().join("x.toml");
        std::fs::write(&path, config).unwrap();
        load(&path)
    }

    fn error(config: &str) -> String {
        match plan(config) {
            Ok(_) => panic!("accepted:\n{config}"),
            Err(e) => {
                let s = format!("{e}");
                assert!(!s.contains('\n'), "{s}");
                assert!(s.contains("x.toml"), "{s}");
                s
            }
        }
    }

    #[test]
    fn a_good_config_resolves_against_the_scene() {
        let p = plan(GOOD).unwrap();
        assert_eq!(p.name, "t");
        assert_eq!(p.scenes[0].name, "s");
        assert_eq!(
            (p.scenes[0].camera.width, p.scenes[0].camera.height),
            (32, 24)
        );
        assert_eq!(
            p.methods[0].runs,
            Runs::Progressive(Budgets::Spp(vec![1, 2, 4]))
        );
        assert_eq!(
            p.methods[1].runs,
            Runs::Progressive(Budgets::Seconds(vec![0.1, 0.5]))
        );
        assert_eq!(p.pairs.len(), 2);
        // max_depth comes from the scene's [render] table for both method and reference.
        assert_eq!(p.pairs[0].estimator.depth(), 5);
        assert_eq!(
            p.pairs[1].estimator.kind,
            rt_integrators::IntegratorKind::PathBsdf
        );
        assert_eq!(p.pairs[1].accel.to_string(), "bvh");
        let ReferencePlan::Render { estimator, spp, .. } = &p.scenes[0].reference else {
            panic!()
        };
        assert_eq!((estimator.depth(), *spp), (5, 16));
        assert!(p.warnings.is_empty(), "{:?}", p.warnings);
        assert!(p.methods.iter().all(|m| m.denoiser.is_none()));
        let p = plan(&GOOD.replace("name = \"b\"", "name = \"b\"\ndenoiser = \"box:radius=2\""))
            .unwrap();
        assert_eq!(
            p.methods[1].denoiser.as_ref().map(|d| d.to_string()),
            Some("box:radius=2".into())
        );
        assert!(p.methods[0].denoiser.is_none());
    }

    #[test]
    fn bad_configs_name_the_file_and_the_problem() {
        let cases = [
            (
                GOOD.replace("name = \"a\"", "name = \"a\"\nsamples = 3"),
                "unknown field `samples`",
            ),
            (
                GOOD.replace("scenes/s.toml", "scenes/none.toml"),
                "none.toml: cannot open",
            ),
            (
                GOOD.replace("spp = [4, 1, 2, 2]", "spp = [4]\nseconds = [1.0]"),
                "not both",
            ),
            (
                GOOD.replace("spp = [4, 1, 2, 2]", "spp = []"),
                "spp is an empty list",
            ),
            (
                GOOD.replace("spp = [4, 1, 2, 2]", "spp = [0]"),
                "between 1 and",
            ),
            (
                GOOD.replace("seconds = [0.5, 0.1]", "seconds = [-1.0]"),
                "seconds values",
            ),
            (
                GOOD.replace("name = \"b\"", "name = \"a\""),
                "two methods are named \"a\"",
            ),
            (
                GOOD.replace("\"path-bsdf\"", "\"vcm\""),
                "\"vcm\" is not one of",
            ),
            (GOOD.replace("\"bvh\"", "\"kd-tree\""), "kd-tree"),
            (
                GOOD.replace("scale = 0.5", "scale = 0.5\nresolution = [8, 8]"),
                "not both",
            ),
            (GOOD.replace("reference = { spp = 16 }", ""), "no reference"),
            (
                GOOD.replace("{ spp = 16 }", "{ spp = 16, color = 1 }"),
                "unknown field `color`",
            ),
            (
                GOOD.replace("{ spp = 16 }", "\"missing.exr\""),
                "missing.exr",
            ),
            (
                GOOD.replace("name = \"b\"", "name = \"b/c\""),
                "must be 1-64 letters",
            ),
            (
                format!("{GOOD}\n[[method]]\nname = \"c\"\nspp = [1]\nscenes = [\"q\"]"),
                "no scene named \"q\"",
            ),
            ("name = \"t\"\n".to_string(), "no [[scene]]"),
            (
                GOOD.replace("spp = [4, 1, 2, 2]", "spp = \"many\""),
                "x.toml:",
            ),
            (
                GOOD.replace("name = \"b\"", "name = \"b\"\ndenoiser = \"fancy:x=1\""),
                "[[method]] \"b\": denoiser = \"fancy:x=1\": unknown denoiser 'fancy'",
            ),
            (
                GOOD.replace(
                    "name = \"b\"",
                    "name = \"b\"\ndenoiser = \"box:radius=100\"",
                ),
                "[[method]] \"b\": denoiser = \"box:radius=100\": box: radius: must be at most 64",
            ),
            (
                GOOD.replace("name = \"b\"", "name = \"b\"\ndenoiser = \"box:size=2\""),
                "unknown option `size`",
            ),
            (
                GOOD.replace("name = \"b\"", "name = \"b\"\ndenoiser = 3"),
                "x.toml:",
            ),
        ];
        for (config, needle) in cases {
            let e = error(&config);
            assert!(e.contains(needle), "{needle:?} not in {e:?}");
        }
    }

    /// GOOD with method "a" made adaptive by `keys` instead of its spp list.
    fn adaptive(keys: &str) -> String {
        GOOD.replace("spp = [4, 1, 2, 2]", keys)
    }

    #[test]
    fn adaptive_methods_stop_like_render_error_and_time_limit() {
        let rules = |keys: &str| match plan(&adaptive(keys)).unwrap().methods.remove(0).runs {
            Runs::Adaptive(r) => r,
            other => panic!("{keys}: {other:?}"),
        };
        let secs = |t: f64| Some(Duration::from_secs_f64(t));
        // One threshold, no cap: as `render --error 2e-4`.
        assert_eq!(
            rules("error = 2e-4"),
            [StopRule {
                error: Some(2e-4),
                time_limit: None,
                max_spp: MAX_SPP
            }]
        );
        // A list of thresholds (largest first), each capped by spp and the time limit.
        let r = rules("error = [1e-4, 1e-3, 1e-4]\nspp = 256\ntime_limit = 30");
        assert_eq!(r.len(), 2);
        assert_eq!((r[0].error, r[1].error), (Some(1e-3), Some(1e-4)));
        assert!(r
            .iter()
            .all(|r| r.max_spp == 256 && r.time_limit == secs(30.0)));
        // Time limits alone (uniform sampling in the adaptive render's passes), spp as a list
        // of one.
        let r = rules("time_limit = [2, 0.5]\nspp = [64]");
        assert_eq!(
            r.iter().map(|r| r.time_limit).collect::<Vec<_>>(),
            [secs(0.5), secs(2.0)]
        );
        assert!(r.iter().all(|r| r.error.is_none() && r.max_spp == 64));
        // A threshold with several time limits.
        let r = rules("error = 2e-4\ntime_limit = [1, 2]");
        assert_eq!(r.len(), 2);
        assert!(r.iter().all(|r| r.error == Some(2e-4)));
        // spp may be a single number for a progressive method too.
        let p = plan(&GOOD.replace("spp = [4, 1, 2, 2]", "spp = 8")).unwrap();
        assert_eq!(p.methods[0].runs, Runs::Progressive(Budgets::Spp(vec![8])));
    }

    #[test]
    fn bad_adaptive_methods_are_one_clear_line() {
        let cases = [
            (
                "error = -2e-4",
                "error must be a positive finite number, got -0.0002",
            ),
            (
                "error = 0.0",
                "error must be a positive finite number, got 0",
            ),
            ("error = [2e-4, 0.0]", "positive finite number, got 0"),
            ("error = nan", "positive finite number, got NaN"),
            ("error = inf", "positive finite number, got inf"),
            ("error = []", "error is an empty list"),
            (
                "error = \"small\"",
                "expected a number or a list of numbers",
            ),
            (
                "time_limit = 0",
                "time_limit must be a positive number of seconds, at most 86400, got 0",
            ),
            ("time_limit = -1.5", "time_limit must be a positive number"),
            ("time_limit = []", "time_limit is an empty list"),
            (
                "error = 2e-4\nspp = [16, 64]",
                "spp is the cap on samples per pixel: give one value",
            ),
            ("error = 2e-4\nspp = 0", "must be between 1 and"),
            (
                "error = 2e-4\nseconds = [1.0]",
                "seconds are the budgets of a progressive render",
            ),
            (
                "error = [1e-3, 2e-4]\ntime_limit = [1, 2]",
                "error and time_limit are both lists",
            ),
        ];
        for (keys, needle) in cases {
            let config = adaptive(keys);
            let e = error(&config);
            assert!(e.contains(needle), "{keys:?}: {needle:?} not in {e:?}");
            if !needle.starts_with("expected") {
                assert!(e.contains("[[method]] \"a\""), "{e}");
            }
        }
        // Method "b" has seconds; a time limit does not combine with them.
        let e = error(&GOOD.replace("seconds = [0.5, 0.1]", "seconds = [0.5]\ntime_limit = 1"));
        assert!(
            e.contains("[[method]] \"b\": seconds are the budgets"),
            "{e}"
        );
    }

    const SEQUENCE: &str = r#"
[[scene]]
path = "scenes/s.toml"
resolution = [16, 12]
frames = [0, 60]
event = 30
reference = { spp = 16 }

[[method]]
name = "a"
spp = 1
denoiser = "svgf:reflections=drop"

[[method]]
name = "b"
spp = [2]
denoiser = "atrous"

[[method]]
name = "c"
spp = 1
"#;

    #[test]
    fn sequence_configs_resolve() {
        let p = plan(SEQUENCE).unwrap();
        assert!(p.is_sequence());
        let seq = p.scenes[0].sequence.as_ref().unwrap();
        assert_eq!(
            (seq.frames.clone(), seq.fps, seq.event),
            (0..60, 24.0, Some(30))
        );
        assert_eq!(p.methods[0].runs, Runs::Sequence { spp: 1 });
        assert_eq!(p.methods[1].runs, Runs::Sequence { spp: 2 });
        let temporal: Vec<Option<bool>> = p
            .methods
            .iter()
            .map(|m| m.temporal.as_ref().map(TemporalSpec::is_temporal))
            .collect();
        assert_eq!(temporal, [Some(true), Some(false), None]);
        assert!(p.methods.iter().all(|m| m.denoiser.is_none()));
        assert_eq!(seq.size, ImageSize::Pixels(16, 12));
        assert!(!plan(GOOD).unwrap().is_sequence());
    }

    #[test]
    fn bad_sequence_configs_are_one_clear_line() {
        let mixed = format!(
            "{SEQUENCE}\n[[scene]]\nname = \"plain\"\npath = \"scenes/s.toml\"\nreference = {{ spp = 4 }}\n"
        );
        let cases = [
            (
                mixed,
                "[[scene]] \"plain\" has no frames but [[scene]] \"s\" is a sequence",
            ),
            (
                SEQUENCE.replace("spp = [2]", "spp = [2, 4]"),
                "[[method]] \"b\": spp is the samples per pixel of every frame of a sequence: give one value, not a list of 2",
            ),
            (
                SEQUENCE.replace("spp = [2]", "seconds = [1.0]"),
                "[[method]] \"b\": seconds is not for sequences",
            ),
            (
                SEQUENCE.replace("spp = [2]", "spp = 2\nerror = 0.01"),
                "error is not for sequences",
            ),
            (
                SEQUENCE.replace("spp = [2]", "spp = 2\ntime_limit = 1"),
                "time_limit is not for sequences",
            ),
            (
                SEQUENCE.replace("spp = [2]\ndenoiser = \"atrous\"", "spp = 2\ngree = \"sparsity=0.9\""),
                "gree is not for sequences",
            ),
            (SEQUENCE.replace("spp = [2]", ""), "[[method]] \"b\": no spp"),
            (SEQUENCE.replace("spp = [2]", "spp = 0"), "spp must be between 1 and"),
            (
                SEQUENCE.replace("frames = [0, 60]", "frames = [60, 0]"),
                "[[scene]] \"s\": frames = [60, 0]: the first frame must come before the end",
            ),
            (
                SEQUENCE.replace("frames = [0, 60]", "frames = [3, 4]"),
                "at least two frames",
            ),
            (
                SEQUENCE.replace("event = 30", "event = 0"),
                "event = 0 must be a frame after the first",
            ),
            (
                SEQUENCE.replace("event = 30", "event = 60"),
                "event = 60 must be a frame after the first and before the end",
            ),
            (
                SEQUENCE.replace("event = 30", "fps = 0"),
                "fps must be in (0, 1000], got 0",
            ),
            (
                GOOD.replace("scale = 0.5", "scale = 0.5\nevent = 3"),
                "event belongs to a sequence: give frames = [A, B] too",
            ),
            (
                SEQUENCE.replace("{ spp = 16 }", "\"r.exr\""),
                "a sequence's reference is rendered frame by frame",
            ),
            (
                SEQUENCE.replace("svgf:reflections=drop", "svgf:alpha=2"),
                "[[method]] \"a\": denoiser = \"svgf:alpha=2\": ",
            ),
            (
                SEQUENCE.replace("svgf:reflections=drop", "svgf:colour=1"),
                "colour",
            ),
            (
                SEQUENCE.replace("denoiser = \"svgf:reflections=drop\"", "denoiser = \"svgf\"\nintegrator = \"ao\""),
                "reads the lighting split (direct, indirect, emission), which the",
            ),
        ];
        for (config, needle) in cases {
            let e = error(&config);
            assert!(e.contains(needle), "{needle:?} not in {e:?}");
        }
        // OIDN per frame is refused in a build without it, as for images.
        if "oidn".parse::<DenoiserSpec>().is_err() {
            let e = error(&SEQUENCE.replace("\"atrous\"", "\"oidn\""));
            assert!(e.contains("'oidn' is not in this build"), "{e}");
        }
    }

    #[test]
    fn a_reference_file_must_match_the_image_size() {
        let dir = tempfile::tempdir().unwrap();
        std::fs::create_dir(dir.path().join("scenes")).unwrap();
        std::fs::write(dir.path().join("scenes/s.toml"), SCENE).unwrap();
        let img = RgbImage::from_fn(8, 8, |_, _| rt_core::Rgb::splat(0.5));
        rt_film::write_rgb(&dir.path().join("r.exr"), &img, &Default::default()).unwrap();
        let path = dir.path().join("x.toml");
        let config = GOOD.replace("{ spp = 16 }", "\"r.exr\"");
        std::fs::write(&path, &config).unwrap();
        let e = format!("{:#}", load(&path).err().unwrap());
        assert!(e.contains("is 8x8 but the scene renders at 32x24"), "{e}");
        std::fs::write(&path, config.replace("scale = 0.5", "resolution = [8, 8]")).unwrap();
        let p = load(&path).unwrap();
        assert!(matches!(p.scenes[0].reference, ReferencePlan::File { .. }));
    }

    #[test]
    fn procedural_scenes_are_names_not_files() {
        let config = GOOD
            .replace("scenes/s.toml", "gen:rotated")
            .replace("scale = 0.5", "resolution = [8, 8]");
        let p = plan(&config).unwrap();
        assert_eq!(p.scenes[0].name, "rotated");
        assert_eq!(p.scenes[0].path, PathBuf::from("gen:rotated"));
    }

    #[test]
    fn mismatched_estimators_are_a_warning() {
        let p = plan(&GOOD.replace("accel = \"bvh\"", "accel = \"bvh\"\nmax_depth = 2")).unwrap();
        assert_eq!(p.warnings.len(), 1);
        assert!(
            p.warnings[0].contains("will level off"),
            "{}",
            p.warnings[0]
        );
    }
}
