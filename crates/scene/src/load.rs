//! Turns a parsed scene description into an `rt_core::Scene`, section by section:
//! environment, cameras, materials, geometry, material assignments, instances and animation,
//! lights.

use crate::desc::{
    self, AssignDesc, CameraDesc, EnvironmentDesc, RenderTableDesc, SceneDesc, SkyDesc, V3,
};
use crate::error::{Result, Source};
use crate::files::FileAccess;
use crate::geometry;
use crate::image_io::{self, Textures};
use crate::instances;
use crate::material::{self, MaterialTable};
use crate::{LoadedScene, RenderDesc};
use glam::Vec3;
use rt_core::environment::sky::{Sky, SkyError, DEFAULT_RESOLUTION};
use rt_core::environment::sun::{SolarTime, TimeOfDay};
use rt_core::environment::{EnvMap, Environment};
use rt_core::pixel_filter::PixelFilter;
use rt_core::{material::MAX_RADIANCE, Camera, Rgb, Scene};
use std::collections::HashSet;
use std::path::{Path, PathBuf};
use toml::Spanned;

/// Largest image side in pixels.
pub(crate) const MAX_RESOLUTION: u32 = rt_core::limits::MAX_IMAGE_SIDE;
/// Largest pixel count (2^26, e.g. 8192×8192).
pub(crate) const MAX_PIXELS: u64 = rt_core::limits::MAX_IMAGE_PIXELS;

/// State shared by the sections while a scene loads.
pub(crate) struct Ctx<'a> {
    /// The TOML text and its name, for errors.
    pub src: Source<'a>,
    /// Directory that relative paths in the file are resolved against.
    pub base: &'a Path,
    /// Textures loaded so far.
    pub textures: Textures,
    /// Non-fatal remarks.
    pub warnings: Vec<String>,
}

impl Ctx<'_> {
    /// A path from the scene file, resolved against the file's directory.
    pub fn resolve(&self, rel: &str) -> PathBuf {
        self.base.join(rel)
    }
}

/// Loads a scene from TOML text (see [`crate::load_str`]).
pub(crate) fn load(
    text: &str,
    base: &Path,
    name: &Path,
    access: &FileAccess,
) -> Result<LoadedScene> {
    let src = Source { name, text };
    let d: SceneDesc = desc::parse(text).map_err(|e| src.toml_error(&e))?;
    let mut ctx = Ctx {
        src,
        base,
        textures: Textures::new(access.clone()),
        warnings: Vec::new(),
    };
    let mut scene = Scene::empty();
    if let Some(env) = &d.environment {
        scene.environment = environment(&ctx, env)?;
    }
    scene.delta_lights = crate::lights::build_all(&ctx, &d.light)?;
    scene.cameras = cameras(&ctx, &d.camera)?;
    let mut mats = MaterialTable::default();
    for m in &d.material {
        let built = material::build(&mut ctx, m, &mut mats)?;
        if mats.insert(built).is_none() {
            return Err(ctx.src.error_at(
                m.get_ref().name.span(),
                format!(
                    "material \"{}\" is defined twice",
                    m.get_ref().name.get_ref()
                ),
            ));
        }
    }
    geometry::build_all(&mut ctx, &d.geometry, &mut mats, &mut scene)?;
    for a in &d.assign {
        assign(&ctx, a.get_ref(), &mut mats, &mut scene)?;
    }
    let material_motions = instances::apply(
        &ctx,
        &d.instance,
        &d.animation,
        &d.camera,
        &mats,
        &mut scene,
    )?;
    far_clips(&ctx, &d.camera, &scene)?;
    let render = render(&ctx, d.render)?;

    for name in mats.unused() {
        ctx.warnings
            .push(format!("material \"{name}\" is defined but never used"));
    }
    scene.materials = mats.into_vec();
    if !material_motions.is_empty() {
        scene.material_motions = material_motions;
        scene.set_time(scene.time);
    }
    scene.textures = std::mem::take(&mut ctx.textures).into_vec();
    scene.compact_attributes();
    if !scene.has_light_sources() {
        ctx.warnings.push(
            "the scene has no light: no emissive material is used, no [[light]] emits and the \
             environment is black, so the image will be black"
                .into(),
        );
    }
    Ok(LoadedScene {
        scene,
        render,
        warnings: ctx.warnings,
    })
}

/// Checks that every component of `v` is finite; `what` names the key.
pub(crate) fn finite3(ctx: &Ctx, v: &Spanned<V3>, what: &str) -> Result<Vec3> {
    let a = v.get_ref().0;
    if a.iter().all(|x| x.is_finite()) {
        Ok(Vec3::from(a))
    } else {
        Err(ctx
            .src
            .error_at(v.span(), format!("{what} must be finite, got {a:?}")))
    }
}

/// `[environment]`.
fn environment(ctx: &Ctx, env: &Spanned<EnvironmentDesc>) -> Result<Environment> {
    let e = env.get_ref();
    let strength = match &e.strength {
        Some(s) => {
            let v = *s.get_ref();
            if !(v.is_finite() && v >= 0.0) {
                return Err(ctx.src.error_at(
                    s.span(),
                    format!("environment strength must be finite and >= 0, got {v}"),
                ));
            }
            v
        }
        None => 1.0,
    };
    let color = match &e.color {
        Some(c) => {
            let v = finite3(ctx, c, "environment color")?;
            if v.min_element() < 0.0 {
                return Err(ctx.src.error_at(
                    c.span(),
                    format!("environment color must be >= 0, got {:?}", c.get_ref().0),
                ));
            }
            v
        }
        None => Rgb::ZERO,
    };
    let too_bright = |radiance: Rgb, span: std::ops::Range<usize>| {
        ctx.src.error_at(
            span,
            format!(
                "environment radiance {:?} (color x strength) exceeds the maximum {MAX_RADIANCE:e}",
                radiance.to_array()
            ),
        )
    };
    if let Some(sky_desc) = &e.sky {
        if let Some(r) = &e.rotation {
            return Err(ctx
                .src
                .error_at(r.span(), "environment rotation turns a `map`, not a `sky`"));
        }
        if color != Rgb::ZERO {
            return Err(ctx.src.error_at(
                e.color.as_ref().map_or(sky_desc.span(), |c| c.span()),
                "environment has both a non-black `color` and a `sky`; give one of them",
            ));
        }
        if let Some(map) = &e.map {
            return Err(ctx.src.error_at(
                map.span(),
                "environment has both a `map` and a `sky`; give one of them",
            ));
        }
        let map = sky(
            ctx,
            sky_desc,
            strength,
            e.strength.as_ref().map(|s| s.span()),
        )?;
        let brightest = map
            .texels()
            .iter()
            .copied()
            .chain(map.sun().map(|s| s.radiance()))
            .fold(Rgb::ZERO, Rgb::max);
        if brightest.max_element() > MAX_RADIANCE {
            let span = e.strength.as_ref().map_or(sky_desc.span(), |s| s.span());
            return Err(ctx.src.error_at(
                span,
                format!(
                    "environment radiance {:?} (sky x strength) exceeds the maximum {MAX_RADIANCE:e}",
                    brightest.to_array()
                ),
            ));
        }
        return Ok(Environment::Map(map));
    }
    if let (Some(r), None) = (&e.rotation, &e.map) {
        return Err(ctx.src.error_at(
            r.span(),
            "environment rotation turns a `map`; there is none",
        ));
    }
    let Some(map) = &e.map else {
        let radiance = color * strength;
        if radiance.max_element() > MAX_RADIANCE {
            let span = e
                .strength
                .as_ref()
                .map_or_else(|| e.color.as_ref().map_or(0..0, |c| c.span()), |s| s.span());
            return Err(too_bright(radiance, span));
        }
        return Ok(Environment::Constant(radiance));
    };
    if color != Rgb::ZERO {
        return Err(ctx.src.error_at(
            e.color.as_ref().map_or(map.span(), |c| c.span()),
            "environment has both a non-black `color` and a `map`; give one of them",
        ));
    }
    let path = ctx.resolve(map.get_ref());
    let (w, h, mut texels) = image_io::read_env_map(ctx.textures.access(), &path)?;
    for t in &mut texels {
        *t *= strength;
        if t.max_element() > MAX_RADIANCE {
            let span = e.strength.as_ref().map_or(map.span(), |s| s.span());
            return Err(too_bright(*t, span));
        }
    }
    let mut env_map = EnvMap::new(w, h, texels);
    if let Some(r) = &e.rotation {
        env_map = env_map.rotated(rotation(ctx, r)?);
    }
    Ok(Environment::Map(env_map))
}

/// `[environment] rotation`: three rows of a proper rotation (orthonormal within 1e-4,
/// determinant +1).
fn rotation(ctx: &Ctx, r: &Spanned<[[f32; 3]; 3]>) -> Result<glam::Mat3> {
    let m = glam::Mat3::from_cols_array_2d(r.get_ref()).transpose();
    let ortho = (m * m.transpose() - glam::Mat3::IDENTITY)
        .to_cols_array()
        .iter()
        .all(|v| v.abs() < 1e-4);
    if !ortho || m.determinant() < 0.0 {
        return Err(ctx.src.error_at(
            r.span(),
            "environment rotation must be a rotation (orthonormal rows, no mirror)",
        ));
    }
    Ok(m)
}

/// `[environment] sky`: the sun from `sun_direction` or from a date, time and place; every
/// value is checked by `rt_core`'s sky, whose errors are placed at the key they concern.
fn sky(
    ctx: &Ctx,
    desc: &Spanned<SkyDesc>,
    strength: f32,
    strength_span: Option<std::ops::Range<usize>>,
) -> Result<EnvMap> {
    let d = desc.get_ref();
    let table = desc.span();
    let span_of = |v: Option<std::ops::Range<usize>>| v.unwrap_or_else(|| table.clone());
    let time_keys = [
        ("latitude", d.latitude.as_ref().map(|v| v.span())),
        ("longitude", d.longitude.as_ref().map(|v| v.span())),
        (
            "standard_meridian",
            d.standard_meridian.as_ref().map(|v| v.span()),
        ),
        ("day", d.day.as_ref().map(|v| v.span())),
        ("hour", d.hour.as_ref().map(|v| v.span())),
        ("solar_time", d.solar_time.as_ref().map(|v| v.span())),
    ];
    let turbidity = d.turbidity.as_ref().map_or(3.0, |t| *t.get_ref());
    // Where an error of the sky model belongs.
    let place = |e: SkyError, sun_span: std::ops::Range<usize>| {
        let span = match &e {
            SkyError::Turbidity(_) => span_of(d.turbidity.as_ref().map(|v| v.span())),
            SkyError::SunDirection(_) | SkyError::SunBelowHorizon(_) => sun_span,
            SkyError::Latitude(_) => span_of(d.latitude.as_ref().map(|v| v.span())),
            SkyError::Longitude(_) => span_of(d.longitude.as_ref().map(|v| v.span())),
            SkyError::StandardMeridian(_) => {
                span_of(d.standard_meridian.as_ref().map(|v| v.span()))
            }
            SkyError::Day(_) => span_of(d.day.as_ref().map(|v| v.span())),
            SkyError::Hour(_) => {
                span_of(d.hour.as_ref().or(d.solar_time.as_ref()).map(|v| v.span()))
            }
            SkyError::Scale(_) => span_of(strength_span.clone()),
            SkyError::Resolution(..) => span_of(d.resolution.as_ref().map(|v| v.span())),
            _ => table.clone(),
        };
        let message = e.to_string();
        let message = if message.starts_with("sky") {
            message
        } else {
            format!("sky: {message}")
        };
        ctx.src.error_at(span, message)
    };
    let model = match &d.sun_direction {
        Some(dir) => {
            if let Some((key, Some(span))) = time_keys.iter().find(|(_, s)| s.is_some()) {
                return Err(ctx.src.error_at(
                    span.clone(),
                    format!(
                        "sky has both `sun_direction` and `{key}`; give the sun's direction or a \
                         date, time and place, not both"
                    ),
                ));
            }
            Sky::new(Vec3::from(*dir.get_ref()), turbidity).map_err(|e| place(e, dir.span()))?
        }
        None => {
            let missing = |what: &str| {
                ctx.src.error_at(
                    table.clone(),
                    format!(
                        "sky needs `sun_direction`, or `latitude`, `day` and `hour` (with \
                         `longitude` and `standard_meridian`) or `solar_time`; {what}"
                    ),
                )
            };
            let (Some(latitude), Some(day)) = (&d.latitude, &d.day) else {
                return Err(missing("`latitude` or `day` is missing"));
            };
            let (time, time_span) = match (&d.hour, &d.solar_time) {
                (Some(_), Some(s)) => {
                    return Err(ctx.src.error_at(
                        s.span(),
                        "sky has both `hour` (clock time) and `solar_time`; give one of them",
                    ))
                }
                (None, None) => return Err(missing("`hour` or `solar_time` is missing")),
                (None, Some(solar)) => {
                    for (key, v) in [
                        ("longitude", &d.longitude),
                        ("standard_meridian", &d.standard_meridian),
                    ] {
                        if let Some(v) = v {
                            return Err(ctx.src.error_at(
                                v.span(),
                                format!(
                                    "sky `{key}` applies to `hour` (clock time), not to `solar_time`"
                                ),
                            ));
                        }
                    }
                    (TimeOfDay::Solar(*solar.get_ref()), solar.span())
                }
                (Some(hour), None) => {
                    let (Some(longitude), Some(meridian)) = (&d.longitude, &d.standard_meridian)
                    else {
                        return Err(ctx.src.error_at(
                            hour.span(),
                            "sky `hour` is clock time and needs `longitude` and \
                             `standard_meridian` (degrees east); use `solar_time` for local solar time",
                        ));
                    };
                    let time = TimeOfDay::Standard {
                        hour: *hour.get_ref(),
                        longitude: *longitude.get_ref(),
                        standard_meridian: *meridian.get_ref(),
                    };
                    (time, hour.span())
                }
            };
            let when = SolarTime {
                latitude: *latitude.get_ref(),
                day: *day.get_ref(),
                time,
            };
            Sky::at(&when, turbidity).map_err(|e| match e {
                SkyError::SunBelowHorizon(below) => {
                    let at = match when.time {
                        TimeOfDay::Solar(h) => format!("at {h} h solar time"),
                        TimeOfDay::Standard {
                            hour, longitude, ..
                        } => format!("at {hour} h clock time at longitude {longitude}"),
                    };
                    ctx.src.error_at(
                        time_span.clone(),
                        format!(
                            "sky: {at} on day {} at latitude {}, the sun is {below:.2} degrees \
                             below the horizon; the Preetham sky needs it at or above the horizon",
                            when.day, when.latitude
                        ),
                    )
                }
                e => place(e, time_span.clone()),
            })?
        }
    };
    let (w, h) = d
        .resolution
        .as_ref()
        .map_or(DEFAULT_RESOLUTION, |r| (r.get_ref().0[0], r.get_ref().0[1]));
    model
        .to_env_map(strength, w, h)
        .map_err(|e| place(e, table.clone()))
}

/// `[[camera]]`: at least one, unique names, every value in range.
fn cameras(ctx: &Ctx, descs: &[Spanned<CameraDesc>]) -> Result<Vec<Camera>> {
    if descs.is_empty() {
        return Err(ctx
            .src
            .error("the scene has no [[camera]]; at least one is required"));
    }
    let mut names = HashSet::new();
    descs
        .iter()
        .map(|d| {
            let d = d.get_ref();
            if !names.insert(d.name.get_ref().as_str()) {
                return Err(ctx.src.error_at(
                    d.name.span(),
                    format!("camera \"{}\" is defined twice", d.name.get_ref()),
                ));
            }
            camera(ctx, d)
        })
        .collect()
}

fn camera(ctx: &Ctx, d: &CameraDesc) -> Result<Camera> {
    let name = d.name.get_ref();
    let at = |span: std::ops::Range<usize>, msg: String| {
        Err(ctx.src.error_at(span, format!("camera \"{name}\": {msg}")))
    };
    let position = finite3(ctx, &d.position, "position")?;
    let look_at = finite3(ctx, &d.look_at, "look_at")?;
    let up = match &d.up {
        Some(u) => finite3(ctx, u, "up")?,
        None => Vec3::Y,
    };
    let view = look_at - position;
    if view.length_squared() == 0.0 || !view.length_squared().is_finite() {
        return at(
            d.look_at.span(),
            "look_at must differ from position (and be a finite distance away)".into(),
        );
    }
    let sin = view.normalize().cross(up.normalize_or_zero()).length();
    if sin.is_nan() || sin <= 1e-6 {
        let s = d.up.as_ref().unwrap_or(&d.look_at);
        return at(
            s.span(),
            format!("up {up} is zero or parallel to the view direction {view}"),
        );
    }
    let mut fov = 40.0;
    if let Some(f) = &d.fov {
        fov = *f.get_ref();
        if !(fov > 0.0 && fov < 180.0) {
            return at(
                f.span(),
                format!("fov must be in (0, 180) degrees (vertical), got {fov}"),
            );
        }
    }
    let (mut w, mut h) = (512, 512);
    if let Some(r) = &d.resolution {
        [w, h] = r.get_ref().0;
        if w == 0
            || h == 0
            || w > MAX_RESOLUTION
            || h > MAX_RESOLUTION
            || w as u64 * h as u64 > MAX_PIXELS
        {
            return at(
                r.span(),
                format!(
                    "absurd resolution {w}x{h}: width and height must be in [1, {MAX_RESOLUTION}] \
                     and width*height at most {MAX_PIXELS}"
                ),
            );
        }
    }
    let mut aperture = 0.0;
    if let Some(a) = &d.aperture {
        aperture = *a.get_ref();
        if !(aperture.is_finite() && aperture >= 0.0) {
            return at(
                a.span(),
                format!("aperture must be finite and >= 0, got {aperture}"),
            );
        }
    }
    let mut focus = view.length();
    if let Some(f) = &d.focus_distance {
        focus = *f.get_ref();
        if !(focus.is_finite() && focus > 0.0) {
            return at(
                f.span(),
                format!("focus_distance must be finite and > 0, got {focus}"),
            );
        }
    }
    // A crop window renders part of the `w × h` image, at its own size.
    let mut crop = None;
    if let Some(c) = &d.crop {
        let [x, y, cw, ch] = c.get_ref().0;
        crop = rt_core::camera::Crop::from_pixels(x, y, cw, ch, w, h);
        if crop.is_none() {
            return at(
                c.span(),
                format!(
                    "crop [{x}, {y}, {cw}, {ch}] must be a non-empty part of the {w}x{h} image"
                ),
            );
        }
        (w, h) = (cw, ch);
    }
    let mut camera = Camera::look_at(
        name.clone(),
        position,
        look_at,
        up,
        fov,
        w,
        h,
        aperture,
        focus,
    );
    camera.crop = crop;
    if let Some(n) = &d.near_clip {
        camera.near_clip = *n.get_ref();
        if !(camera.near_clip.is_finite() && camera.near_clip >= 0.0) {
            return at(
                n.span(),
                format!(
                    "near_clip must be finite and >= 0, got {}",
                    camera.near_clip
                ),
            );
        }
    }
    if let Some(f) = &d.far_clip {
        let far = *f.get_ref();
        if far.is_nan() || far <= camera.near_clip {
            return at(
                f.span(),
                format!(
                    "far_clip must be greater than near_clip ({}), got {far}",
                    camera.near_clip
                ),
            );
        }
    }
    if let Some(f) = &d.pixel_filter {
        camera.filter = PixelFilter::parse(f.get_ref()).map_err(|e| {
            ctx.src
                .error_at(f.span(), format!("camera \"{name}\": pixel_filter: {e}"))
        })?;
    }
    Ok(camera)
}

/// A camera's `far_clip` is accepted only where it cuts nothing: every triangle lies nearer
/// along the view axis. Applying it would mean a bounded primary ray in every integrator; a
/// clip that would hide geometry is refused rather than ignored, so no image silently
/// differs from what the scene asks for. A moving scene is not checked frame by frame, so
/// there a far clip is refused.
fn far_clips(ctx: &Ctx, descs: &[Spanned<CameraDesc>], scene: &Scene) -> Result<()> {
    for (d, camera) in descs.iter().zip(&scene.cameras) {
        let Some(f) = &d.get_ref().far_clip else {
            continue;
        };
        let (far, name) = (*f.get_ref(), &camera.name);
        if scene.instances.iter().any(|i| i.is_animated()) || !scene.camera_motions.is_empty() {
            return Err(ctx.src.error_at(
                f.span(),
                format!("camera \"{name}\": far_clip is not supported in an animated scene"),
            ));
        }
        let depth = scene
            .triangles
            .iter()
            .flatten()
            .map(|v| (*v - camera.position).dot(camera.forward))
            .fold(f32::NEG_INFINITY, f32::max);
        if depth >= far {
            return Err(ctx.src.error_at(
                f.span(),
                format!(
                    "camera \"{name}\": far_clip {far} would hide geometry (it reaches {depth} \
                     along the view axis); far clipping is not supported: remove far_clip or \
                     make it larger"
                ),
            ));
        }
    }
    Ok(())
}

/// `[[assign]]`: sets the material of a half-open triangle range of one geometry.
fn assign(ctx: &Ctx, a: &AssignDesc, mats: &mut MaterialTable, scene: &mut Scene) -> Result<()> {
    let g = a.geometry.get_ref();
    let Some(obj) = scene.objects.iter().find(|o| &o.name == g) else {
        return Err(ctx.src.error_at(
            a.geometry.span(),
            format!("geometry \"{g}\" used by [[assign]] is not defined"),
        ));
    };
    let [start, end] = a.triangles.get_ref().0;
    if start >= end || end > obj.count {
        return Err(ctx.src.error_at(
            a.triangles.span(),
            format!(
                "triangle range [{start}, {end}) is out of bounds: it must be non-empty and \
                 within geometry \"{g}\"'s {} triangles ([0, {}))",
                obj.count, obj.count
            ),
        ));
    }
    let m = a.material.get_ref();
    let Some(id) = mats.lookup(m) else {
        return Err(ctx.src.error_at(
            a.material.span(),
            format!("material \"{m}\" used by [[assign]] of geometry \"{g}\" is not defined"),
        ));
    };
    let first = obj.first as usize;
    scene.material_ids[first + start as usize..first + end as usize].fill(id);
    Ok(())
}

/// `[render]`.
fn render(ctx: &Ctx, r: Option<RenderTableDesc>) -> Result<RenderDesc> {
    let Some(r) = r else {
        return Ok(RenderDesc::default());
    };
    if let Some(s) = &r.spp {
        if *s.get_ref() == 0 {
            return Err(ctx.src.error_at(s.span(), "spp must be at least 1"));
        }
    }
    if let Some(t) = &r.threads {
        if *t.get_ref() == 0 {
            return Err(ctx.src.error_at(t.span(), "threads must be at least 1"));
        }
    }
    if let Some(d) = &r.denoiser {
        if d.get_ref().trim().is_empty() {
            return Err(ctx.src.error_at(
                d.span(),
                "denoiser must name a denoiser, e.g. \"nlm\" (leave the key out for none)",
            ));
        }
    }
    Ok(RenderDesc {
        spp: r.spp.map(Spanned::into_inner),
        integrator: r.integrator,
        accel: r.accel,
        max_depth: r.max_depth,
        seed: r.seed,
        threads: r.threads.map(Spanned::into_inner),
        aov: r.aov,
        output: r.output,
        denoiser: r.denoiser.map(Spanned::into_inner),
    })
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;
    use crate::LoadedScene;

    /// A camera and an emitting quad: the smallest valid scene.
    pub(crate) const BASE: &str = r#"
[[camera]]
name = "main"
position = [0, 1, 4]
look_at = [0, 1, 0]

[[material]]
name = "light"
emission = [1, 1, 1]

[[geometry]]
name = "lamp"
shape = "quad"
vertices = [[-1, 2, -1], [1, 2, -1], [1, 2, 1], [-1, 2, 1]]
material = "light"
"#;

    /// Loads `BASE` followed by `extra`, resolving paths against `dir`.
    pub(crate) fn load_in(dir: &Path, extra: &str) -> std::result::Result<LoadedScene, String> {
        crate::load_str(&format!("{BASE}{extra}"), dir, Path::new("t.toml"))
            .map_err(|e| e.to_string())
    }

    pub(crate) fn ok(extra: &str) -> LoadedScene {
        load_in(Path::new("."), extra).unwrap()
    }

    pub(crate) fn err(extra: &str) -> String {
        let e = load_in(Path::new("."), extra).unwrap_err();
        assert!(e.starts_with("t.toml:"), "{e}");
        assert!(!e.contains('\n'), "{e}");
        e
    }

    /// Line of `needle` in `BASE + extra`, 1-based, for position assertions.
    pub(crate) fn line_of(extra: &str, needle: &str) -> usize {
        let text = format!("{BASE}{extra}");
        text[..text.find(needle).unwrap()].matches('\n').count() + 1
    }

    fn env(s: &LoadedScene) -> Rgb {
        match &s.scene.environment {
            Environment::Constant(c) => *c,
            Environment::Map(_) => panic!("map"),
        }
    }

    #[test]
    fn environment_color_and_strength() {
        assert_eq!(env(&ok("")), Rgb::ZERO);
        assert_eq!(env(&ok("[environment]\n")), Rgb::ZERO);
        assert_eq!(
            env(&ok("[environment]\ncolor = [0.5, 1, 2]")),
            Rgb::new(0.5, 1.0, 2.0)
        );
        assert_eq!(
            env(&ok("[environment]\ncolor = [0.5, 1, 2]\nstrength = 2")),
            Rgb::new(1.0, 2.0, 4.0)
        );
        for bad in ["-1", "nan", "inf"] {
            let e = err(&format!("[environment]\nstrength = {bad}"));
            assert!(e.contains("strength must be finite and >= 0"), "{e}");
        }
        let e = err("[environment]\ncolor = [0, -1, 0]");
        assert!(e.contains("environment color must be >= 0"), "{e}");
        let e = err("[environment]\ncolor = [0, nan, 0]");
        assert!(e.contains("environment color must be finite"), "{e}");
        // Finite but beyond what the film can accumulate without overflow.
        let e = err("[environment]\ncolor = [1e30, 0, 0]");
        assert!(e.contains("exceeds the maximum 1e15"), "{e}");
        let e = err("[environment]\ncolor = [1e10, 1, 1]\nstrength = 1e10");
        assert!(e.contains("exceeds the maximum"), "{e}");
    }

    #[test]
    fn environment_map_is_read_relative_to_the_scene_and_scaled() {
        let dir = tempfile::tempdir().unwrap();
        std::fs::create_dir(dir.path().join("env")).unwrap();
        exr::prelude::write_rgb_file(dir.path().join("env/sky.exr"), 8, 4, |x, _| {
            (x as f32, 1.0f32, 0.0f32)
        })
        .unwrap();
        let s = load_in(
            dir.path(),
            "[environment]\nmap = \"env/sky.exr\"\nstrength = 0.5",
        )
        .unwrap();
        let Environment::Map(_) = &s.scene.environment else {
            panic!("expected a map")
        };
        // Column x = 7 is the last; u = 0.5 + atan2(dx, -dz)/2π: +x is u = 0.75, between the
        // centres of columns 5 and 6, where the map is interpolated.
        let r = s.scene.environment.radiance(Vec3::X);
        assert_eq!(r, Rgb::new(2.75, 0.5, 0.0));
        // A black colour next to a map is fine; a non-black one is not.
        load_in(
            dir.path(),
            "[environment]\nmap = \"env/sky.exr\"\ncolor = [0, 0, 0]",
        )
        .unwrap();
        let e = load_in(
            dir.path(),
            "[environment]\nmap = \"env/sky.exr\"\ncolor = [1, 0, 0]",
        )
        .unwrap_err();
        assert!(e.contains("both a non-black `color` and a `map`"), "{e}");
        let e = load_in(dir.path(), "[environment]\nmap = \"env/none.exr\"").unwrap_err();
        assert!(e.contains("none.exr: cannot open"), "{e}");
    }

    fn sky_map(s: &LoadedScene) -> &EnvMap {
        s.scene.environment.map().expect("a sky is a map")
    }

    #[test]
    fn sky_from_a_direction_or_a_time_and_place_scaled_by_strength() {
        let s = ok("[environment]\nsky = { sun_direction = [1, 1, 0], turbidity = 2.5 }");
        let map = sky_map(&s);
        assert_eq!(map.size(), DEFAULT_RESOLUTION);
        let sun = map.sun().expect("a sun");
        assert!((sun.dir() - Vec3::new(1.0, 1.0, 0.0).normalize()).length() < 1e-6);
        let model = Sky::new(Vec3::new(1.0, 1.0, 0.0), 2.5).unwrap();
        assert_eq!(sun.radiance(), model.sun_radiance());
        // The zenith texel's centre is 0.35° from the zenith: within a per cent of it.
        let (zenith, expected) = (
            s.scene.environment.radiance(Vec3::Y),
            model.radiance(Vec3::Y),
        );
        assert!((zenith - expected).abs().max_element() < 0.01 * expected.max_element());

        // Strength scales sky and sun; turbidity defaults to 3; resolution is the table's.
        let s = ok("[environment]\nstrength = 0.5\nsky = { sun_direction = [0, 1, 1], resolution = [64, 32] }");
        let map = sky_map(&s);
        assert_eq!(map.size(), (64, 32));
        let model = Sky::new(Vec3::new(0.0, 1.0, 1.0), 3.0).unwrap();
        assert_eq!(map.sun().unwrap().radiance(), model.sun_radiance() * 0.5);

        // A date, time and place: 14:30 CEST-less clock time (standard time, meridian 15° E)
        // in Zurich on 21 June, as `SolarTime` computes it.
        let s = ok("[environment]\nsky = { latitude = 47.4, longitude = 8.5, standard_meridian = 15, day = 172, hour = 14.5, turbidity = 4 }");
        let when = SolarTime {
            latitude: 47.4,
            day: 172,
            time: TimeOfDay::Standard {
                hour: 14.5,
                longitude: 8.5,
                standard_meridian: 15.0,
            },
        };
        let sun = sky_map(&s).sun().unwrap();
        assert!((sun.dir() - when.sun_direction()).length() < 1e-6);
        assert!(
            sun.dir().x < 0.0 && sun.dir().y > 0.5,
            "afternoon: west and high"
        );
        let s = ok("[environment]\nsky = { latitude = -33.9, day = 355, solar_time = 12 }");
        let sun = sky_map(&s).sun().unwrap();
        // Cape Town at its midsummer noon: sun 79.5° high in the north (−z).
        assert!(
            (sun.dir().y.asin().to_degrees() - 79.5).abs() < 0.2,
            "{}",
            sun.dir()
        );
        assert!(sun.dir().z < 0.0 && sun.dir().x.abs() < 1e-5);
        assert!(s.warnings.is_empty(), "{:?}", s.warnings);
    }

    #[test]
    fn every_sky_parameter_reaches_the_content_hash() {
        use rt_core::ContentHash;
        let content = |sky: &str| {
            let s = ok(&format!("[environment]\n{sky}\n"));
            let mut bytes = Vec::new();
            s.scene
                .content_hash(&mut |b: &[u8]| bytes.extend_from_slice(b));
            bytes
        };
        let base = "sky = { latitude = 47.4, longitude = 8.5, standard_meridian = 15, day = 172, hour = 14.5 }";
        let reference = content(base);
        assert_eq!(content(base), reference, "deterministic");
        for changed in [
            base.replace("47.4", "47.5"),
            base.replace("8.5", "8.6"),
            base.replace("= 15", "= 0"),
            base.replace("172", "173"),
            base.replace("14.5", "14.6"),
            base.replace(" }", ", turbidity = 3.1 }"),
            base.replace(" }", ", resolution = [256, 128] }"),
            format!("strength = 0.5\n{base}"),
        ] {
            assert_ne!(content(&changed), reference, "{changed}");
        }
        // Stated defaults are the defaults.
        assert_eq!(content(&base.replace(" }", ", turbidity = 3 }")), reference);
        assert_eq!(
            content(&base.replace(" }", ", resolution = [512, 256] }")),
            reference
        );
    }

    #[test]
    fn sky_errors_name_the_file_the_key_and_the_problem() {
        let sky = |keys: &str| format!("[environment]\nsky = {{ {keys} }}\n");
        let cases: [(&str, &str, &str); 21] = [
            (
                "sun_direction = [0, 1, 0], turbidity = 1.2",
                "turbidity = 1.2",
                "turbidity must be in [1.7, 10]",
            ),
            (
                "sun_direction = [0, 1, 0], turbidity = 11",
                "turbidity = 11",
                "turbidity must be in [1.7, 10]",
            ),
            (
                "sun_direction = [0, 0, 0]",
                "sun_direction = ",
                "must be finite and non-zero",
            ),
            (
                "sun_direction = [0, nan, 1]",
                "sun_direction = ",
                "must be finite and non-zero",
            ),
            (
                "sun_direction = [0, -1, 1]",
                "sun_direction = ",
                "sun is 45.00 degrees below the horizon",
            ),
            (
                "sun_direction = [0, 1, 0], day = 3",
                "day = 3",
                "both `sun_direction` and `day`",
            ),
            ("turbidity = 3", "sky = ", "needs `sun_direction`"),
            (
                "latitude = 40, solar_time = 12",
                "sky = ",
                "`latitude` or `day` is missing",
            ),
            (
                "latitude = 40, day = 80",
                "sky = ",
                "`hour` or `solar_time` is missing",
            ),
            (
                "latitude = 40, day = 80, hour = 12, solar_time = 12",
                "solar_time = 12",
                "give one of them",
            ),
            (
                "latitude = 40, day = 80, hour = 12",
                "hour = 12",
                "needs `longitude` and `standard_meridian`",
            ),
            (
                "latitude = 40, day = 80, solar_time = 12, longitude = 8",
                "longitude = 8",
                "not to `solar_time`",
            ),
            (
                "latitude = 91, day = 80, solar_time = 12",
                "latitude = 91",
                "latitude must be in [-90, 90]",
            ),
            (
                "latitude = 40, day = 0, solar_time = 12",
                "day = 0",
                "day of the year in [1, 366]",
            ),
            (
                "latitude = 40, day = 400, solar_time = 12",
                "day = 400",
                "day of the year in [1, 366]",
            ),
            (
                "latitude = 40, day = 80, solar_time = 25",
                "solar_time = 25",
                "in [0, 24] hours",
            ),
            (
                "latitude = 40, day = 80, hour = 12, longitude = 190, standard_meridian = 0",
                "longitude = 190",
                "longitude must be in [-180, 180]",
            ),
            (
                "latitude = 40, day = 80, hour = 12, longitude = 0, standard_meridian = -181",
                "standard_meridian = ",
                "standard_meridian must be in [-180, 180]",
            ),
            (
                "latitude = 40, day = 172, solar_time = 0.5",
                "solar_time = ",
                "at 0.5 h solar time on day 172 at latitude 40, the sun is 26.17 degrees below",
            ),
            (
                "sun_direction = [0, 1, 0], resolution = [1, 4]",
                "resolution = ",
                "resolution 1x4",
            ),
            (
                "sun_direction = [0, 1, 0], resolution = [9000, 4]",
                "resolution = ",
                "must be in [2, 8192]",
            ),
        ];
        for (keys, at, message) in cases {
            let extra = sky(keys);
            let e = err(&extra);
            assert!(e.contains(message), "{keys}: {e}");
            let line = line_of(&extra, at);
            assert!(e.starts_with(&format!("t.toml:{line}:")), "{keys}: {e}");
            // The column of the value after `at`'s "= ".
            let text = format!("{BASE}{extra}");
            let in_line = text.lines().nth(line - 1).unwrap().find(at).unwrap();
            let col = in_line + at.find("= ").unwrap() + 3;
            assert!(
                e.starts_with(&format!("t.toml:{line}:{col}:")),
                "{keys} (col {col}): {e}"
            );
        }
        // Types and unknown keys come from the TOML layer, also one line.
        for (keys, message) in [
            ("latitude = 40, day = -1, solar_time = 12", "-1"),
            ("latitude = 40, day = 80.5, solar_time = 12", "80.5"),
            ("sun_direction = [0, 1]", "invalid length 2"),
            ("sun = [0, 1, 0]", "unknown field `sun`"),
        ] {
            let e = err(&sky(keys));
            assert!(e.contains(message), "{keys}: {e}");
        }
        // The sky excludes a colour and a map, and the scaled sun must stay in range.
        let e = err("[environment]\ncolor = [1, 1, 1]\nsky = { sun_direction = [0, 1, 0] }");
        assert!(e.contains("both a non-black `color` and a `sky`"), "{e}");
        let e = err("[environment]\nmap = \"x.exr\"\nsky = { sun_direction = [0, 1, 0] }");
        assert!(e.contains("both a `map` and a `sky`"), "{e}");
        let e = err("[environment]\nstrength = 1e10\nsky = { sun_direction = [0, 1, 0] }");
        assert!(
            e.contains("(sky x strength) exceeds the maximum 1e15"),
            "{e}"
        );
        assert!(
            e.starts_with(&format!(
                "t.toml:{}:",
                line_of("[environment]\nstrength = 1e10\n", "strength")
            )),
            "{e}"
        );
    }

    fn cam(extra: &str) -> std::result::Result<Camera, String> {
        let text = format!(
            "[[camera]]\nname = \"c\"\nposition = [0, 0, 5]\nlook_at = [0, 0, 0]\n{extra}\n{}",
            &BASE[BASE.find("[[material]]").unwrap()..]
        );
        crate::load_str(&text, Path::new("."), Path::new("c.toml"))
            .map(|s| s.scene.cameras[0].clone())
            .map_err(|e| e.to_string())
    }

    #[test]
    fn camera_keys_and_defaults() {
        let c = cam("").unwrap();
        assert_eq!(c.name, "c");
        assert_eq!(c.position, Vec3::new(0.0, 0.0, 5.0));
        assert_eq!(c.forward, -Vec3::Z);
        assert_eq!(c.up, Vec3::Y);
        assert_eq!(c.right, Vec3::X);
        assert_eq!((c.fov_y_deg, c.width, c.height), (40.0, 512, 512));
        assert_eq!((c.aperture, c.focus_distance), (0.0, 5.0));
        let c = cam("up = [1, 0, 0]\nfov = 39.3\nresolution = [640, 360]\naperture = 0.1\nfocus_distance = 3")
            .unwrap();
        assert_eq!(c.up, Vec3::X);
        assert_eq!((c.fov_y_deg, c.width, c.height), (39.3, 640, 360));
        assert_eq!((c.aperture, c.focus_distance), (0.1, 3.0));
        assert_eq!(cam("resolution = [16384, 4096]").unwrap().width, 16384);
    }

    #[test]
    fn camera_errors_point_at_the_value() {
        for (extra, want) in [
            (
                "fov = 0",
                "c.toml:5:7: camera \"c\": fov must be in (0, 180)",
            ),
            ("fov = 180", "fov must be in (0, 180)"),
            ("fov = nan", "fov must be in (0, 180)"),
            (
                "resolution = [0, 100]",
                "c.toml:5:14: camera \"c\": absurd resolution 0x100",
            ),
            ("resolution = [100, 0]", "absurd resolution 100x0"),
            ("resolution = [16385, 10]", "absurd resolution 16385x10"),
            (
                "resolution = [16384, 16384]",
                "absurd resolution 16384x16384",
            ),
            ("aperture = -0.1", "aperture must be finite and >= 0"),
            ("aperture = inf", "aperture must be finite and >= 0"),
            (
                "focus_distance = 0",
                "focus_distance must be finite and > 0",
            ),
            (
                "focus_distance = -2",
                "focus_distance must be finite and > 0",
            ),
            (
                "up = [0, 0, 2]",
                "c.toml:5:6: camera \"c\": up [0, 0, 2] is zero or parallel",
            ),
            ("up = [0, 0, 0]", "is zero or parallel"),
            ("up = [0, nan, 0]", "up must be finite"),
            ("near_clip = -1", "near_clip must be finite and >= 0"),
            (
                "near_clip = 2\nfar_clip = 1",
                "far_clip must be greater than near_clip (2), got 1",
            ),
            ("far_clip = nan", "far_clip must be greater than near_clip"),
        ] {
            let e = cam(extra).unwrap_err();
            assert!(e.contains(want), "{extra}: {e}");
        }
        let e = cam("position = [0, 0, 0]").unwrap_err();
        assert!(e.contains("duplicate key") || e.contains("position"), "{e}");
        let text = "[[camera]]\nname = \"c\"\nposition = [1, 2, 3]\nlook_at = [1, 2, 3]\n";
        let e = crate::load_str(text, Path::new("."), Path::new("c.toml"))
            .unwrap_err()
            .to_string();
        assert!(
            e.contains("c.toml:4:11: camera \"c\": look_at must differ from position"),
            "{e}"
        );
        let text = "[[camera]]\nname = \"c\"\nposition = [inf, 2, 3]\nlook_at = [1, 2, 3]\n";
        let e = crate::load_str(text, Path::new("."), Path::new("c.toml"))
            .unwrap_err()
            .to_string();
        assert!(e.contains("c.toml:3:12: position must be finite"), "{e}");
    }

    #[test]
    fn cameras_need_unique_names_and_at_least_one_exists() {
        let extra = "[[camera]]\nname = \"main\"\nposition = [0, 0, 1]\nlook_at = [0, 0, 0]\n";
        let e = err(extra);
        assert!(e.contains("camera \"main\" is defined twice"), "{e}");
        assert!(
            e.starts_with(&format!(
                "t.toml:{}:",
                line_of(extra, "name = \"main\"\nposition = [0, 0, 1]")
            )),
            "{e}"
        );
        let s = ok(&extra.replace("main", "second"));
        assert_eq!(s.scene.cameras.len(), 2);
        assert_eq!(s.scene.cameras[1].name, "second");
        let no_cam = &BASE[BASE.find("[[material]]").unwrap()..];
        let e = crate::load_str(no_cam, Path::new("."), Path::new("n.toml")).unwrap_err();
        assert_eq!(
            e.to_string(),
            "n.toml: the scene has no [[camera]]; at least one is required"
        );
    }

    const BOX: &str = "\n[[material]]\nname = \"red\"\ncolor = [1, 0, 0]\n\
        [[geometry]]\nname = \"box\"\nshape = \"box\"\nmin = [0, 0, 0]\nmax = [1, 1, 1]\nmaterial = \"light\"\n";

    #[test]
    fn assign_sets_a_half_open_triangle_range() {
        let s = ok(&format!(
            "{BOX}[[assign]]\ngeometry = \"box\"\ntriangles = [2, 5]\nmaterial = \"red\"\n"
        ));
        let red = s
            .scene
            .materials
            .iter()
            .position(|m| m.name == "red")
            .unwrap() as u32;
        let light = 0;
        let ids: Vec<u32> = s.scene.material_ids[2..].to_vec();
        let mut want = vec![light; 12];
        want[2..5].fill(red);
        assert_eq!(ids, want);
        // The whole range is fine too.
        ok(&format!(
            "{BOX}[[assign]]\ngeometry = \"box\"\ntriangles = [0, 12]\nmaterial = \"red\"\n"
        ));
    }

    #[test]
    fn assign_errors() {
        for (tail, want) in [
            (
                "geometry = \"boxx\"\ntriangles = [0, 1]\nmaterial = \"red\"",
                "geometry \"boxx\" used by [[assign]] is not defined",
            ),
            (
                "geometry = \"box\"\ntriangles = [0, 13]\nmaterial = \"red\"",
                "triangle range [0, 13) is out of bounds",
            ),
            (
                "geometry = \"box\"\ntriangles = [3, 3]\nmaterial = \"red\"",
                "triangle range [3, 3) is out of bounds",
            ),
            (
                "geometry = \"box\"\ntriangles = [4, 2]\nmaterial = \"red\"",
                "triangle range [4, 2)",
            ),
            (
                "geometry = \"box\"\ntriangles = [0, 1]\nmaterial = \"blue\"",
                "material \"blue\" used by [[assign]] of geometry \"box\" is not defined",
            ),
            (
                "geometry = \"box\"\ntriangles = [-1, 1]\nmaterial = \"red\"",
                "-1",
            ),
            (
                "geometry = \"box\"\ntriangles = [0, 1, 2]\nmaterial = \"red\"",
                "length",
            ),
        ] {
            let extra = format!("{BOX}[[assign]]\n{tail}\n");
            let e = err(&extra);
            assert!(e.contains(want), "{tail}: {e}");
            let assign_line = line_of(&extra, "[[assign]]");
            let at: usize = e.split(':').nth(1).unwrap().parse().unwrap();
            assert!(at > assign_line && at <= assign_line + 3, "{e}");
        }
        assert!(err(&format!(
            "{BOX}[[assign]]\ngeometry = \"box\"\nmaterial = \"red\"\n"
        ))
        .contains("missing field `triangles`"));
    }

    #[test]
    fn render_table_keys() {
        let s = ok("[render]\nspp = 64\nintegrator = \"path\"\naccel = \"bvh\"\nmax_depth = 16\nseed = 7\nthreads = 2\naov = [\"albedo\", \"normal\"]\noutput = \"out.exr\"\ndenoiser = \"nlm:k=0.3\"");
        let r = s.render;
        assert_eq!(r.spp, Some(64));
        assert_eq!(r.integrator.as_deref(), Some("path"));
        assert_eq!(r.accel.as_deref(), Some("bvh"));
        assert_eq!(r.max_depth, Some(16));
        assert_eq!(r.seed, Some(7));
        assert_eq!(r.threads, Some(2));
        assert_eq!(
            r.aov,
            Some(vec!["albedo".to_string(), "normal".to_string()])
        );
        assert_eq!(r.output.as_deref(), Some("out.exr"));
        assert_eq!(r.denoiser.as_deref(), Some("nlm:k=0.3"));
        let r = ok("").render;
        assert!(r.spp.is_none() && r.integrator.is_none() && r.aov.is_none());
        assert!(r.denoiser.is_none());
        let extra = "[render]\ndenoiser = \" \"";
        let e = err(extra);
        assert!(
            e.starts_with(&format!("t.toml:{}:", line_of(extra, "denoiser")))
                && e.contains("denoiser must name a denoiser"),
            "{e}"
        );
        assert!(err("[render]\ndenoiser = 3").contains("expected a string"));
        assert!(err("[render]\nspp = 0").contains("spp must be at least 1"));
        assert!(err("[render]\nthreads = 0").contains("threads must be at least 1"));
        assert!(err("[render]\nspp = -4").contains("-4"));
        assert!(err("[render]\naov = \"albedo\"").contains("expected a sequence"));
        let e = err("[render]\nsamples = 4");
        assert!(e.contains("unknown field `samples`"), "{e}");
    }

    #[test]
    fn malformed_toml_names_file_line_and_column() {
        let e = err("[[material]\nname = \"x\"");
        assert!(
            e.starts_with(&format!(
                "t.toml:{}:",
                line_of("[[material]\n", "[[material]\n")
            )),
            "{e}"
        );
        let e = err("[[material]]\nname = \"x\"\ncolor = [0.5, 0.5, 0.5");
        assert!(e.contains("t.toml:"), "{e}");
        let extra = "[[material]]\nname = \"x\"\n  glossiness = 0.5\n";
        let e = err(extra);
        assert!(
            e.starts_with(&format!(
                "t.toml:{}:3: unknown field `glossiness`",
                line_of(extra, "glossiness")
            )),
            "{e}"
        );
    }

    #[test]
    fn warnings_for_unused_materials_and_missing_lights() {
        let s = ok("[[material]]\nname = \"spare\"\n");
        assert!(
            s.warnings
                .iter()
                .any(|w| w == "material \"spare\" is defined but never used"),
            "{:?}",
            s.warnings
        );
        let dark = BASE.replace("emission = [1, 1, 1]", "color = [0.5, 0.5, 0.5]");
        let s = crate::load_str(&dark, Path::new("."), Path::new("d.toml")).unwrap();
        assert!(
            s.warnings
                .iter()
                .any(|w| w.contains("the scene has no light")),
            "{:?}",
            s.warnings
        );
        assert!(ok("").warnings.is_empty(), "{:?}", ok("").warnings);
        assert_eq!(
            ok("").scene.lights().emitter_count(),
            2,
            "the light sampler sees both emissive triangles"
        );
    }

    #[test]
    fn materials_need_unique_names() {
        let extra = "[[material]]\nname = \"light\"\n";
        let e = err(extra);
        let text = format!("{BASE}{extra}");
        let line = text[..text.rfind("name = \"light\"").unwrap()]
            .matches('\n')
            .count()
            + 1;
        assert_eq!(
            e,
            format!("t.toml:{line}:8: material \"light\" is defined twice")
        );
    }
}
