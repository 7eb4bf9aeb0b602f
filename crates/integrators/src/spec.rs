//! Naming an integrator and its options in one string, and building it: the one dispatch point
//! for integrators, as `rt_accel::AccelSpec` is for acceleration structures.
//!
//! `--integrator`, the scene's `[render] integrator` and an experiment's `methods` all take the
//! same text, in the one option grammar of every spec ([`rt_core::options`]): a kind followed
//! by options separated by `:` or `,`, e.g. `path`, `path:max-depth=4`,
//! `path-bsdf`, `direct`, `ao:distance=0.5`. [`IntegratorSpec`] parses it
//! ([`std::str::FromStr`]), prints it back in a canonical form ([`std::fmt::Display`]: the
//! options it sets), builds the integrator ([`IntegratorSpec::build`]) and says
//! what it converges to ([`IntegratorSpec::target`]).
//!
//! | option | kinds | meaning |
//! |---|---|---|
//! | `max-depth=N` | path, wavefront, path-bsdf, light, bdpt, partitioned |
//! | `vpls=N`, `photons=N`, `clamp=F`, `cull=off\|unbiased\|biased`, `maps=on\|off`, `indirect-caustics=N` | partitioned | VPL paths and caustic photons per pass (16, 100000), G-clamp distance as a fraction of the scene diagonal (0.001), VPL culling (unbiased), projection maps (on), caustic photons also from the VPLs of the first N diffuse bounces (0): [`PartitionOptions`] | bounce limit (default [`DEFAULT_MAX_DEPTH`], at most [`MAX_DEPTH`]) |
//! | `distance=F` | ao | occluder distance (default unlimited) |
//! | `lanes=N` | wavefront | paths per thread's batch (default [`crate::DEFAULT_LANES`], 1 to [`MAX_LANES`]); speed only, the image is the same |

use crate::{
    AoIntegrator, Bdpt, CameraRays, Culling, LightTracer, PartitionOptions, Partitioned,
    PathIntegrator, Technique,
};
use rt_core::options::Options;
use std::fmt;
use std::str::FromStr;

/// Bounce limit when nothing sets one.
pub const DEFAULT_MAX_DEPTH: u32 = 16;

/// Largest bounce limit a spec accepts; beyond it a path is numerically meaningless and a typo
/// is the likelier explanation.
pub const MAX_DEPTH: u32 = 10_000;

/// The integrators this crate builds.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
#[non_exhaustive]
pub enum IntegratorKind {
    /// Path tracing with next-event estimation and MIS ([`PathIntegrator::new`]).
    Path,
    /// The same estimator advanced in batches, stage by stage ([`crate::Wavefront`]): the
    /// same image as `path`, bit for bit.
    Wavefront,
    /// Path tracing with BSDF sampling only ([`PathIntegrator::bsdf_only`]).
    PathBsdf,
    /// Direct lighting: one bounce, NEE + MIS ([`PathIntegrator::direct`]).
    Direct,
    /// Ambient occlusion ([`AoIntegrator`]).
    Ao,
    /// Light tracing: particles from the lights splatted through the camera
    /// ([`LightTracer`]).
    Light,
    /// Bidirectional path tracing with MIS over all strategies ([`Bdpt`]).
    Bdpt,
    /// The path-space-partitioned progressive renderer: VPLs, caustic histogram, specular
    /// gathering ([`Partitioned`]).
    Partitioned,
}

impl IntegratorKind {
    /// Every kind, in the order help texts list them.
    pub const ALL: [IntegratorKind; 8] = [
        IntegratorKind::Path,
        IntegratorKind::Wavefront,
        IntegratorKind::PathBsdf,
        IntegratorKind::Direct,
        IntegratorKind::Ao,
        IntegratorKind::Light,
        IntegratorKind::Bdpt,
        IntegratorKind::Partitioned,
    ];

    /// The name used in specs and reports.
    pub fn name(self) -> &'static str {
        match self {
            IntegratorKind::Path => "path",
            IntegratorKind::Wavefront => "wavefront",
            IntegratorKind::PathBsdf => "path-bsdf",
            IntegratorKind::Direct => "direct",
            IntegratorKind::Ao => "ao",
            IntegratorKind::Light => "light",
            IntegratorKind::Bdpt => "bdpt",
            IntegratorKind::Partitioned => "partitioned",
        }
    }

    /// True for the kinds whose bounce limit is an option.
    pub fn has_depth(self) -> bool {
        matches!(
            self,
            IntegratorKind::Path
                | IntegratorKind::Wavefront
                | IntegratorKind::PathBsdf
                | IntegratorKind::Light
                | IntegratorKind::Bdpt
                | IntegratorKind::Partitioned
        )
    }

    fn names() -> String {
        Self::ALL.map(Self::name).join(", ")
    }
}

impl FromStr for IntegratorKind {
    type Err = IntegratorSpecError;

    fn from_str(s: &str) -> Result<Self, Self::Err> {
        Self::ALL
            .into_iter()
            .find(|k| k.name().eq_ignore_ascii_case(s))
            .ok_or_else(|| IntegratorSpecError::UnknownKind(s.to_string()))
    }
}

impl fmt::Display for IntegratorKind {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

/// An integrator and the parameters that change what it converges to.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct IntegratorSpec {
    /// Which integrator.
    pub kind: IntegratorKind,
    /// Bounce limit (path tracers; `direct` is always one bounce, `ao` ignores it), if the spec
    /// sets one; `None` leaves it to the caller's settings, else [`DEFAULT_MAX_DEPTH`]
    /// ([`IntegratorSpec::depth`]).
    pub max_depth: Option<u32>,
    /// Occluder distance of `ao` (infinite: unlimited).
    pub ao_distance: f32,
    /// Parameters of `partitioned`.
    pub partition: PartitionOptions,
    /// Paths per thread's batch of `wavefront` ([`crate::DEFAULT_LANES`] unless set). Changes
    /// the speed, never the image.
    pub lanes: u32,
}

/// What an estimator converges to. Two estimators with the same target can be measured against
/// one reference; otherwise the error levels off at the difference of the two images.
#[derive(Clone, Copy, Debug, PartialEq)]
#[non_exhaustive]
pub enum Target {
    /// Light transport with at most this many bounces (`path`, `path-bsdf`, and `direct` = 1).
    Radiance {
        /// Bounce limit.
        bounces: u32,
    },
    /// Ambient occlusion with this occluder distance.
    Occlusion {
        /// Occluder distance.
        distance: f32,
    },
}

impl fmt::Display for Target {
    /// `8 bounces`, `distance 0.5`: for messages about estimators that do not compare.
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Target::Radiance { bounces } => write!(f, "{bounces} bounces"),
            Target::Occlusion { distance } => write!(f, "distance {distance}"),
        }
    }
}

/// Why an integrator spec was rejected.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum IntegratorSpecError {
    /// The text before the first `:` is not an integrator.
    #[error("\"{0}\" is not one of {names}", names = IntegratorKind::names())]
    UnknownKind(String),
    /// An option this crate does not know, or one that does not apply to the kind.
    #[error("option `{option}` does not apply to `{kind}` (options: max-depth=N for path, wavefront, path-bsdf, light, bdpt and partitioned, lanes=N for wavefront, distance=F for ao, vpls=N, photons=N, clamp=F, cull=off|unbiased|biased, maps=on|off and indirect-caustics=N for partitioned)")]
    UnknownOption {
        /// The integrator.
        kind: IntegratorKind,
        /// The option as written.
        option: String,
    },
    /// A bounce limit above [`MAX_DEPTH`] or one that does not parse.
    #[error("max depth must be an integer between 0 and {MAX_DEPTH}, got {0}")]
    BadDepth(String),
    /// A `wavefront` batch size out of range or not parsing.
    #[error("wavefront lanes must be an integer from 1 to {MAX_LANES}, got {0}")]
    BadLanes(String),
    /// An occluder distance that is not positive or does not parse.
    #[error("ao distance must be positive, got {0}")]
    BadDistance(String),
    /// The text breaks the option grammar (a key given twice, a key without its value).
    #[error(transparent)]
    Options(#[from] rt_core::options::OptionsError),
    /// A `partitioned` option out of range or not parsing.
    #[error("partitioned option `{option}`: {what}")]
    BadPartitionOption {
        /// The option as written.
        option: String,
        /// What it must be.
        what: &'static str,
    },
}

/// A bounce limit, checked against [`MAX_DEPTH`]: the one check, wherever the value comes from.
pub fn check_max_depth(depth: u32) -> Result<u32, IntegratorSpecError> {
    if depth > MAX_DEPTH {
        return Err(IntegratorSpecError::BadDepth(depth.to_string()));
    }
    Ok(depth)
}

/// An `ao` occluder distance: positive (infinite is unlimited).
pub fn check_ao_distance(distance: f32) -> Result<f32, IntegratorSpecError> {
    if distance.is_nan() || distance <= 0.0 {
        return Err(IntegratorSpecError::BadDistance(distance.to_string()));
    }
    Ok(distance)
}

impl IntegratorSpec {
    /// The default spec of `kind`.
    pub fn new(kind: IntegratorKind) -> Self {
        Self {
            kind,
            max_depth: None,
            ao_distance: f32::INFINITY,
            partition: PartitionOptions::default(),
            lanes: crate::DEFAULT_LANES,
        }
    }

    /// This spec with bounce limit `depth` ([`check_max_depth`]).
    pub fn with_max_depth(mut self, depth: u32) -> Result<Self, IntegratorSpecError> {
        self.max_depth = Some(check_max_depth(depth)?);
        Ok(self)
    }

    /// This spec with `ao` occluder distance `distance` ([`check_ao_distance`]).
    pub fn with_ao_distance(mut self, distance: f32) -> Result<Self, IntegratorSpecError> {
        self.ao_distance = check_ao_distance(distance)?;
        Ok(self)
    }

    /// The bounce limit in effect.
    pub fn depth(&self) -> u32 {
        self.max_depth.unwrap_or(DEFAULT_MAX_DEPTH)
    }

    /// Builds the technique.
    pub fn build(&self) -> Box<dyn Technique> {
        let camera =
            |i: Box<dyn crate::Integrator>| -> Box<dyn Technique> { Box::new(CameraRays(i)) };
        match self.kind {
            IntegratorKind::Path => camera(Box::new(PathIntegrator::new(self.depth()))),
            IntegratorKind::Wavefront => Box::new(crate::Wavefront::new(
                PathIntegrator::new(self.depth()),
                self.lanes,
            )),
            IntegratorKind::PathBsdf => camera(Box::new(PathIntegrator::bsdf_only(self.depth()))),
            IntegratorKind::Direct => camera(Box::new(PathIntegrator::direct())),
            IntegratorKind::Ao => camera(Box::new(AoIntegrator {
                max_distance: self.ao_distance,
            })),
            IntegratorKind::Light => Box::new(LightTracer::new(self.depth())),
            IntegratorKind::Bdpt => Box::new(Bdpt::new(self.depth())),
            IntegratorKind::Partitioned => Box::new(Partitioned::new(self.depth(), self.partition)),
        }
    }

    /// The technique reading and writing the world-space `cache` ([`crate::radiance_cache`]):
    /// path tracers end secondary paths at cached diffuse vertices, ambient occlusion shows the
    /// cache's reconstruction. `None` for techniques that cannot use a cache (direct lighting
    /// has no secondary vertices; light-path techniques are not camera-ray estimators).
    pub fn build_cached(
        &self,
        cache: std::sync::Arc<dyn crate::RadianceCache>,
    ) -> Option<Box<dyn Technique>> {
        let integrator: Box<dyn crate::Integrator> = match self.kind {
            // A cached render runs on the scalar tracer (the wavefront one leaves caches to it).
            IntegratorKind::Path | IntegratorKind::Wavefront => {
                Box::new(PathIntegrator::new(self.depth()).with_cache(cache.clone()))
            }
            IntegratorKind::PathBsdf => {
                Box::new(PathIntegrator::bsdf_only(self.depth()).with_cache(cache.clone()))
            }
            IntegratorKind::Ao => Box::new(crate::CachedAo {
                ao: AoIntegrator {
                    max_distance: self.ao_distance,
                },
                cache: crate::CacheRef(cache.clone()),
            }),
            _ => return None,
        };
        Some(Box::new(crate::CachedPasses::new(
            Box::new(CameraRays(integrator)),
            cache,
        )))
    }

    /// What the integrator converges to.
    pub fn target(&self) -> Target {
        match self.kind {
            // Light tracing misses paths ending in a delta bounce and the environment seen
            // directly; where a scene has neither, it converges to the path tracer's image.
            IntegratorKind::Path
            | IntegratorKind::Wavefront
            | IntegratorKind::PathBsdf
            | IntegratorKind::Light
            | IntegratorKind::Bdpt
            | IntegratorKind::Partitioned => Target::Radiance {
                bounces: self.depth(),
            },
            IntegratorKind::Direct => Target::Radiance { bounces: 1 },
            IntegratorKind::Ao => Target::Occlusion {
                distance: self.ao_distance,
            },
        }
    }
}

impl Default for IntegratorSpec {
    /// `wavefront` (the path tracer's estimator, in batches) with the default bounce limit.
    fn default() -> Self {
        Self::new(IntegratorKind::Wavefront)
    }
}

impl FromStr for IntegratorSpec {
    type Err = IntegratorSpecError;

    fn from_str(s: &str) -> Result<Self, Self::Err> {
        let mut o = Options::parse(s)?;
        let kind: IntegratorKind = o.kind().parse()?;
        let mut spec = IntegratorSpec::new(kind);
        if kind.has_depth() {
            if let Some(v) = o.text("max-depth")? {
                let depth = v
                    .parse()
                    .map_err(|_| IntegratorSpecError::BadDepth(v.clone()))?;
                spec = spec.with_max_depth(depth)?;
            }
        }
        if kind == IntegratorKind::Wavefront {
            if let Some(v) = o.text("lanes")? {
                spec.lanes = v
                    .parse()
                    .ok()
                    .filter(|n| (1..=MAX_LANES).contains(n))
                    .ok_or(IntegratorSpecError::BadLanes(v))?;
            }
        }
        if kind == IntegratorKind::Ao {
            if let Some(v) = o.text("distance")? {
                let d: f32 = v
                    .parse()
                    .map_err(|_| IntegratorSpecError::BadDistance(v.clone()))?;
                spec = spec.with_ao_distance(d)?;
            }
        }
        if kind == IntegratorKind::Partitioned {
            for key in PARTITION_KEYS {
                if let Some(v) = o.text(key)? {
                    spec.partition =
                        parse_partition_option(spec.partition, key, &v).map_err(|what| {
                            IntegratorSpecError::BadPartitionOption {
                                option: format!("{key}={v}"),
                                what,
                            }
                        })?;
                }
            }
        }
        if let Some(key) = o.unread() {
            let option = o
                .entries()
                .find(|(k, _)| *k == key)
                .map(|(k, v)| v.map_or(k.to_string(), |v| format!("{k}={v}")))
                .unwrap_or_default();
            return Err(IntegratorSpecError::UnknownOption { kind, option });
        }
        Ok(spec)
    }
}

/// The options of `partitioned`.
const PARTITION_KEYS: [&str; 6] = [
    "vpls",
    "photons",
    "clamp",
    "cull",
    "maps",
    "indirect-caustics",
];

/// Largest `wavefront` batch a spec may ask for (paths per thread; about 200 bytes each).
pub const MAX_LANES: u32 = 1 << 20;

/// Most VPL paths per pass a spec may ask for.
pub const MAX_VPL_PATHS: u32 = 65_536;
/// Most caustic photons per pass.
pub const MAX_PHOTONS: u32 = 100_000_000;

/// Deepest diffuse bounce indirect caustics may start from.
pub const MAX_INDIRECT_CAUSTICS: u32 = 64;

/// One `partitioned` option applied to `o`, or what its value must be.
fn parse_partition_option(
    mut o: PartitionOptions,
    key: &str,
    value: &str,
) -> Result<PartitionOptions, &'static str> {
    match key {
        "vpls" => {
            o.vpl_paths = value
                .parse()
                .ok()
                .filter(|n| (1..=MAX_VPL_PATHS).contains(n))
                .ok_or("VPL paths per pass must be an integer from 1 to 65536")?;
        }
        "photons" => {
            o.photons = value
                .parse()
                .ok()
                .filter(|n| (1..=MAX_PHOTONS).contains(n))
                .ok_or("caustic photons per pass must be an integer from 1 to 100000000")?;
        }
        "clamp" => {
            o.clamp = value
                .parse()
                .ok()
                .filter(|c: &f32| c.is_finite() && *c >= 0.0)
                .ok_or("the clamp distance (a fraction of the scene's diagonal) must be a number at least 0")?;
        }
        "indirect-caustics" => {
            o.indirect_caustics = value
                .parse()
                .ok()
                .filter(|n| *n <= MAX_INDIRECT_CAUSTICS)
                .ok_or("the depth of indirect caustics must be an integer from 0 to 64")?;
        }
        "cull" => {
            o.cull = [Culling::Off, Culling::Unbiased, Culling::Biased]
                .into_iter()
                .find(|c| c.name() == value)
                .ok_or("culling must be off, unbiased or biased")?;
        }
        _ => {
            o.projection_maps = match value {
                "on" => true,
                "off" => false,
                _ => return Err("projection maps must be on or off"),
            };
        }
    }
    Ok(o)
}

impl fmt::Display for IntegratorSpec {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.kind.name())?;
        if let (true, Some(depth)) = (self.kind.has_depth(), self.max_depth) {
            write!(f, ":max-depth={depth}")?;
        }
        if self.kind == IntegratorKind::Wavefront && self.lanes != crate::DEFAULT_LANES {
            write!(f, ":lanes={}", self.lanes)?;
        }
        if self.kind == IntegratorKind::Ao && self.ao_distance.is_finite() {
            write!(f, ":distance={}", self.ao_distance)?;
        }
        if self.kind == IntegratorKind::Partitioned {
            let (o, d) = (self.partition, PartitionOptions::default());
            if o.vpl_paths != d.vpl_paths {
                write!(f, ":vpls={}", o.vpl_paths)?;
            }
            if o.photons != d.photons {
                write!(f, ":photons={}", o.photons)?;
            }
            if o.clamp != d.clamp {
                write!(f, ":clamp={}", o.clamp)?;
            }
            if o.cull != d.cull {
                write!(f, ":cull={}", o.cull.name())?;
            }
            if o.projection_maps != d.projection_maps {
                write!(f, ":maps=off")?;
            }
            if o.indirect_caustics != d.indirect_caustics {
                write!(f, ":indirect-caustics={}", o.indirect_caustics)?;
            }
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn names_round_trip() {
        for k in IntegratorKind::ALL {
            assert_eq!(k.name().parse::<IntegratorKind>(), Ok(k));
            assert_eq!(
                k.name().parse::<IntegratorSpec>(),
                Ok(IntegratorSpec::new(k))
            );
        }
        let e = "vcm".parse::<IntegratorSpec>().unwrap_err();
        assert_eq!(
            e.to_string(),
            "\"vcm\" is not one of path, wavefront, path-bsdf, direct, ao, light, bdpt, partitioned"
        );
    }

    #[test]
    fn options_parse_print_and_validate() {
        let s: IntegratorSpec = "path:max-depth=4".parse().unwrap();
        assert_eq!((s.kind, s.max_depth), (IntegratorKind::Path, Some(4)));
        assert_eq!(s.to_string(), "path:max-depth=4");
        let w: IntegratorSpec = "wavefront:lanes=256:max-depth=3".parse().unwrap();
        assert_eq!((w.lanes, w.max_depth), (256, Some(3)));
        assert_eq!(w.to_string().parse::<IntegratorSpec>(), Ok(w));
        assert_eq!(
            "wavefront".parse::<IntegratorSpec>().unwrap().to_string(),
            "wavefront"
        );
        for bad in [
            "wavefront:lanes=0",
            "wavefront:lanes=x",
            "wavefront:lanes=2000000",
        ] {
            assert!(matches!(
                bad.parse::<IntegratorSpec>(),
                Err(IntegratorSpecError::BadLanes(_))
            ));
        }
        assert!("path:lanes=8".parse::<IntegratorSpec>().is_err());
        let a: IntegratorSpec = "ao:distance=0.5".parse().unwrap();
        assert_eq!(a.ao_distance, 0.5);
        assert_eq!(a.to_string().parse::<IntegratorSpec>(), Ok(a));
        // What the text says is kept, even the default: it wins over the caller's settings.
        let d: IntegratorSpec = "path:max-depth=16".parse().unwrap();
        assert_eq!(
            (d.to_string().as_str(), d.depth()),
            ("path:max-depth=16", 16)
        );
        assert_eq!(
            IntegratorSpec::new(IntegratorKind::Path).depth(),
            DEFAULT_MAX_DEPTH
        );
        for bad in [
            "direct:max-depth=3",
            "ao:max-depth=3",
            "path:distance=1",
            "path:max-depth=-1",
            "path:max-depth=10001",
            "ao:distance=0",
            "ao:distance=nan",
            "path:fast",
        ] {
            assert!(bad.parse::<IntegratorSpec>().is_err(), "{bad}");
        }
    }

    #[test]
    fn every_kind_displays_a_spec_that_parses_back_and_refusals_name_the_spec() {
        for text in [
            "path:max-depth=4",
            "wavefront:max-depth=3:lanes=64",
            "path-bsdf:max-depth=2",
            "direct",
            "ao:distance=0.25",
            "light:max-depth=5",
            "bdpt:max-depth=6",
            "partitioned:max-depth=4:vpls=8:cull=off",
        ] {
            let s: IntegratorSpec = text.parse().unwrap();
            assert_eq!(s.to_string(), text);
            assert_eq!(s.to_string().parse::<IntegratorSpec>(), Ok(s));
        }
        let s: IntegratorSpec = "wavefront,lanes=64,max-depth=3".parse().unwrap();
        assert_eq!(s.to_string(), "wavefront:max-depth=3:lanes=64");
        let e = |t: &str| t.parse::<IntegratorSpec>().unwrap_err().to_string();
        assert_eq!(
            e("path:max-depth=3:max-depth=4"),
            "path: option `max-depth` given twice"
        );
        assert!(
            e("wavefront:lanes=8:fast").starts_with("option `fast` does not apply to `wavefront`"),
            "{}",
            e("wavefront:lanes=8:fast")
        );
        assert!(e("path:max-depth").contains("option `max-depth` needs a value"));
    }

    #[test]
    fn targets_tell_comparable_estimators() {
        let e = |kind, depth| IntegratorSpec::new(kind).with_max_depth(depth).unwrap();
        let path = e(IntegratorKind::Path, 8);
        assert_eq!(path.target(), e(IntegratorKind::PathBsdf, 8).target());
        assert_ne!(path.target(), e(IntegratorKind::Path, 4).target());
        assert_eq!(
            e(IntegratorKind::Direct, 8).target(),
            e(IntegratorKind::Path, 1).target()
        );
        assert_ne!(path.target(), e(IntegratorKind::Ao, 8).target());
    }

    #[test]
    fn built_integrators_are_named_as_specs() {
        for k in IntegratorKind::ALL {
            assert_eq!(IntegratorSpec::new(k).build().name(), k.name());
        }
    }

    #[test]
    fn partition_options_round_trip_and_refuse_bad_values() {
        let text =
            "partitioned:vpls=4:photons=2000:clamp=0.01:cull=biased:maps=off:indirect-caustics=2";
        let spec: IntegratorSpec = text.parse().unwrap();
        assert_eq!(spec.partition.indirect_caustics, 2);
        assert_eq!(spec.to_string(), text);
        for bad in [
            "partitioned:indirect-caustics=-1",
            "partitioned:indirect-caustics=65",
            "path:indirect-caustics=1",
        ] {
            assert!(bad.parse::<IntegratorSpec>().is_err(), "{bad}");
        }
    }
}
