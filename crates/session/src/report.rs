//! The render report behind `render --stats`: what a render built, what it skipped and why,
//! and what each stage cost in time and in bytes held. The libraries report the figures
//! (`Scene::memory`, `Accel::memory_bytes`, `LightSampler::memory_bytes`,
//! `EnvMap::importance_map_bytes`, `Film::memory`, ...); this module arranges them, and its
//! `Display` prints the table. Bytes are lengths times
//! element sizes of the buffers held after the render, not the process's resident memory.

use rt_core::{environment::Environment, Accel, Camera, Scene};
use rt_film::Film;
use rt_integrators::{RenderStats, TechniqueStage};
use std::fmt;
use std::path::Path;
use std::time::Duration;

/// Why the light sampler or the importance map was not built: nothing in the render asked.
const NOT_SAMPLED: &str = "the integrator samples no lights";

/// Whether a stage ran, and if not, why not.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum Status {
    /// It ran; the word says how ("built", "allocated", "used", "done").
    Ran(&'static str),
    /// It was not needed, for the given reason.
    Skipped(String),
}

/// One stage of a render.
#[derive(Clone, Debug, PartialEq)]
pub struct Stage {
    /// What the stage is.
    pub name: String,
    /// Ran or skipped.
    pub status: Status,
    /// Wall-clock time, where measured.
    pub time: Option<Duration>,
    /// Bytes held after the render (the file's size for the output write).
    pub bytes: Option<u64>,
    /// Counts, names and other particulars.
    pub details: String,
}

impl Stage {
    fn ran(name: &str, word: &'static str, time: Option<Duration>, bytes: Option<usize>) -> Self {
        Self {
            name: name.to_string(),
            status: Status::Ran(word),
            time,
            bytes: bytes.map(|b| b as u64),
            details: String::new(),
        }
    }

    fn skipped(name: &str, why: impl Into<String>) -> Self {
        Self {
            name: name.to_string(),
            status: Status::Skipped(why.into()),
            time: None,
            bytes: None,
            details: String::new(),
        }
    }

    fn details(mut self, d: impl Into<String>) -> Self {
        self.details = d.into();
        self
    }
}

/// The stages of one render, in order, and the bytes held at its end.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct RenderReport {
    /// Stages in the order they ran.
    pub stages: Vec<Stage>,
    /// Bytes of the scene, acceleration structure, sampling structures and film held together.
    pub held_bytes: u64,
}

/// Everything [`RenderReport::collect`] reads.
pub struct ReportInputs<'a> {
    /// The scene rendered.
    pub scene: &'a Scene,
    /// The camera (after any resize).
    pub camera: &'a Camera,
    /// The structure built.
    pub accel: &'a dyn Accel,
    /// The spec it was built from, as text.
    pub accel_spec: String,
    /// The film after the render.
    pub film: &'a Film,
    /// What the render passes reported.
    pub render: &'a RenderStats,
    /// The technique's own stages ([`rt_integrators::Technique::stages`]).
    pub technique: &'a [TechniqueStage],
    /// Scene load time.
    pub load_time: Duration,
    /// Acceleration structure build time.
    pub accel_time: Duration,
    /// Output write time.
    pub write_time: Duration,
    /// The output written (its size is read from disk).
    pub output: &'a Path,
}

impl RenderReport {
    /// Gathers the stages of a finished render.
    pub fn collect(i: &ReportInputs<'_>) -> RenderReport {
        let scene = i.scene;
        let mut stages = Vec::new();

        let mem = scene.memory();
        stages.push(
            Stage::ran("scene load", "done", Some(i.load_time), Some(mem.total())).details(
                format!(
                    "triangles: {} ({} B), materials: {} ({} B), textures: {} ({} B), environment \
             map texels: {} B",
                    scene.triangle_count(),
                    mem.geometry,
                    scene.materials.len(),
                    mem.materials,
                    scene.textures.len(),
                    mem.textures,
                    mem.environment
                ),
            ),
        );

        let accel_bytes = i.accel.memory_bytes();
        stages.push(
            Stage::ran(
                "acceleration structure",
                "built",
                Some(i.accel_time),
                Some(accel_bytes),
            )
            .details({
                let name = if i.accel.name() == i.accel_spec {
                    i.accel_spec.clone()
                } else {
                    format!("{} ({})", i.accel.name(), i.accel_spec)
                };
                // The structure's own bytes apart from its copy of the triangles (issue 12).
                match i.accel.structure_bytes() {
                    Some(own) => format!(
                        "{name}; structure {own} B ({:.2} B/triangle) beyond {} B of triangles",
                        own as f64 / scene.triangle_count().max(1) as f64,
                        accel_bytes.saturating_sub(own)
                    ),
                    None => name,
                }
            }),
        );

        let env_sampled = !scene.environment.is_black();
        let light_stage = "light sampling structure";
        stages.push(match scene.lights_if_built() {
            Some(lights) if lights.emitter_count() + lights.delta_count() > 0 => Stage::ran(
                light_stage,
                "built",
                Some(lights.build_time()),
                Some(lights.memory_bytes()),
            )
            .details(match lights.delta_count() {
                0 => format!("{} emissive triangles", lights.emitter_count()),
                n => format!(
                    "{} emissive triangles, {n} point, spot or directional lights",
                    lights.emitter_count()
                ),
            }),
            Some(_) if env_sampled => Stage::skipped(
                light_stage,
                "no emitters (light samples go to the environment)",
            ),
            Some(_) => Stage::skipped(light_stage, "no emitters"),
            None => Stage::skipped(light_stage, NOT_SAMPLED),
        });

        let env_stage = "environment importance map";
        stages.push(match &scene.environment {
            Environment::Map(m) => match m.importance_if_built() {
                Some(imp) => {
                    let (w, h) = m.size();
                    Stage::ran(
                        env_stage,
                        "built",
                        Some(imp.build_time()),
                        Some(imp.memory_bytes()),
                    )
                    .details(format!("{w}x{h} map"))
                }
                None => Stage::skipped(env_stage, NOT_SAMPLED),
            },
            Environment::Constant(_) if env_sampled => {
                Stage::skipped(env_stage, "constant environment")
            }
            Environment::Constant(_) => Stage::skipped(env_stage, "no environment"),
        });

        let film = i.film;
        let fm = film.memory();
        let pixels = film.width() as usize * film.height() as usize;
        let per_pixel = |b: usize| format!("{} B/pixel", b / pixels.max(1));
        stages.push(
            Stage::ran("film mean + count", "allocated", None, Some(fm.mean))
                .details(per_pixel(fm.mean)),
        );
        let buffer = |name: &str, bytes: Option<usize>, why_not: &str| match bytes {
            Some(b) => Stage::ran(name, "allocated", None, Some(b)).details(per_pixel(b)),
            None => Stage::skipped(name, why_not),
        };
        stages.push(buffer(
            "film squares (variance)",
            fm.variance,
            "no consumer",
        ));
        stages.push(buffer("film half-buffers", fm.halves, "no consumer"));
        stages.push(buffer(
            "film AOV hit count",
            fm.first_hits,
            "no first-hit AOV requested",
        ));
        for (name, bytes) in [
            ("film AOV albedo", fm.albedo),
            ("film AOV normal", fm.normal),
            ("film AOV depth", fm.depth),
            ("film AOV position", fm.position),
        ] {
            stages.push(buffer(name, bytes, "not requested"));
        }

        stages.push(if i.camera.is_pinhole() {
            Stage::skipped("lens sampling", "pinhole camera")
        } else {
            Stage::ran("lens sampling", "used", None, None)
                .details(format!("aperture {}", i.camera.aperture))
        });

        let r = i.render;
        stages.push(
            Stage::ran("render", "done", Some(r.elapsed), None).details(format!(
                "{} samples, {} rays, {} shadow rays, {} discarded samples",
                r.samples, r.rays.rays, r.rays.shadow_rays, r.discarded
            )),
        );
        for t in i.technique {
            stages.push(Stage::ran(t.name, "done", t.time, None).details(t.details.clone()));
        }

        let file_bytes = std::fs::metadata(i.output).map(|m| m.len()).ok();
        let mut write = Stage::ran("output write", "done", Some(i.write_time), None)
            .details(i.output.display().to_string());
        write.bytes = file_bytes;
        stages.push(write);

        let held = mem.total()
            + accel_bytes
            + scene.lights_if_built().map_or(0, |l| l.memory_bytes())
            + scene
                .environment
                .map()
                .and_then(|m| m.importance_if_built())
                .map_or(0, |imp| imp.memory_bytes())
            + fm.total();
        RenderReport {
            stages,
            held_bytes: held as u64,
        }
    }

    /// The stage named `name`.
    pub fn stage(&self, name: &str) -> Option<&Stage> {
        self.stages.iter().find(|s| s.name == name)
    }
}

impl fmt::Display for RenderReport {
    /// One line per stage: name, status, time, bytes, then details or the reason for a skip.
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        writeln!(
            f,
            "{:<28} {:<9} {:>12} {:>12}  details",
            "stage", "status", "time", "bytes"
        )?;
        for s in &self.stages {
            let (status, details) = match &s.status {
                Status::Ran(word) => (*word, s.details.as_str()),
                Status::Skipped(why) => ("skipped", why.as_str()),
            };
            let time = s.time.map_or("-".to_string(), |t| {
                format!("{:.3} ms", t.as_secs_f64() * 1e3)
            });
            let bytes = s.bytes.map_or("-".to_string(), |b| b.to_string());
            writeln!(
                f,
                "{:<28} {:<9} {:>12} {:>12}  {details}",
                s.name, status, time, bytes
            )?;
        }
        writeln!(
            f,
            "{:<28} {:<9} {:>12} {:>12}  scene, acceleration structure, sampling structures, film",
            "held after render", "", "", self.held_bytes
        )
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use rt_core::{glam::Vec3, Material, Rgb};
    use rt_film::{AovSet, FilmBuffers};

    fn scene(emitting: bool) -> Scene {
        let mut s = Scene::empty();
        let mut m = Material::diffuse("m", Rgb::splat(0.5));
        if emitting {
            m.emission = Rgb::ONE;
        }
        s.materials.push(m);
        s.push_triangle([Vec3::ZERO, Vec3::X, Vec3::Y], 0);
        s.build_lights();
        s
    }

    fn stats_for(scene: &Scene, film: &Film, aperture: f32) -> RenderReport {
        let camera = Camera::look_at("c", Vec3::Z, Vec3::ZERO, Vec3::Y, 40.0, 4, 2, aperture, 1.0);
        let accel = rt_accel::BruteForce::new(&scene.triangles);
        RenderReport::collect(&ReportInputs {
            scene,
            camera: &camera,
            accel: &accel,
            accel_spec: "brute-force".into(),
            film,
            render: &RenderStats::default(),
            technique: &[],
            load_time: Duration::from_millis(2),
            accel_time: Duration::from_millis(1),
            write_time: Duration::from_millis(3),
            output: Path::new("/nonexistent/out.exr"),
        })
    }

    fn skipped(s: &RenderReport, name: &str) -> String {
        match &s
            .stage(name)
            .unwrap_or_else(|| panic!("no stage {name}"))
            .status
        {
            Status::Skipped(why) => why.clone(),
            other => panic!("{name}: {other:?}"),
        }
    }

    #[test]
    fn a_bare_scene_skips_every_optional_stage() {
        let scene = scene(false);
        let film = Film::new(4, 2, AovSet::default());
        let s = stats_for(&scene, &film, 0.0);
        assert_eq!(skipped(&s, "light sampling structure"), "no emitters");
        assert_eq!(skipped(&s, "environment importance map"), "no environment");
        assert_eq!(skipped(&s, "film squares (variance)"), "no consumer");
        assert_eq!(skipped(&s, "film half-buffers"), "no consumer");
        assert_eq!(skipped(&s, "film AOV albedo"), "not requested");
        assert_eq!(skipped(&s, "lens sampling"), "pinhole camera");
        assert_eq!(s.stage("film mean + count").unwrap().bytes, Some(8 * 52));
        assert_eq!(s.stage("output write").unwrap().bytes, None);
        let sum: u64 = ["scene load", "acceleration structure", "film mean + count"]
            .iter()
            .map(|n| s.stage(n).unwrap().bytes.unwrap())
            .sum();
        assert_eq!(s.held_bytes, sum);
        let table = s.to_string();
        assert_eq!(table.lines().count(), 2 + s.stages.len(), "{table}");
        assert!(
            table.contains("pinhole camera") && table.contains("2.000 ms"),
            "{table}"
        );
    }

    #[test]
    fn requested_and_present_things_are_reported_as_built() {
        let mut scene = scene(true);
        scene.environment = Environment::Constant(Rgb::ONE);
        scene.build_lights();
        let aovs = AovSet::parse_list(["variance", "albedo"]).unwrap();
        let film = Film::new(4, 2, FilmBuffers::for_outputs(aovs).with_halves());
        let s = stats_for(&scene, &film, 0.1);
        let lights = s.stage("light sampling structure").unwrap();
        assert_eq!(lights.status, Status::Ran("built"));
        assert!(lights.bytes.unwrap() > 0);
        assert_eq!(
            skipped(&s, "environment importance map"),
            "constant environment"
        );
        for (name, per_pixel) in [
            ("film squares (variance)", 96),
            ("film half-buffers", 64),
            ("film AOV hit count", 4),
            ("film AOV albedo", 48),
        ] {
            assert_eq!(s.stage(name).unwrap().bytes, Some(8 * per_pixel), "{name}");
        }
        assert_eq!(skipped(&s, "film AOV depth"), "not requested");
        assert_eq!(
            s.stage("lens sampling").unwrap().status,
            Status::Ran("used")
        );
    }
}
