//! `[[instance]]` and `[[animation]]`: geometries placed more than once, keyframed motion of
//! geometries, instances and cameras, and keyframed emission of materials
//! (`docs/scene-format.md`, "Instances and animation").
//!
//! Runs after the geometry and the material assignments are loaded. A geometry that an
//! instance places, or that an animation moves, becomes a prototype: its triangles (after its
//! own `transform`) leave the flat arrays and come back as instances' world copies at time 0,
//! after the static geometry. A geometry placed by instances is not rendered by itself (as a
//! shape group in Mitsuba); an animated geometry becomes one instance of its own name.

use crate::desc::{AnimationDesc, CameraDesc, InstanceDesc, KeyDesc};
use crate::error::Result;
use crate::geometry;
use crate::load::Ctx;
use crate::material::MaterialTable;
use glam::Vec3;
use rt_core::animation::{
    CameraKey, CameraMotion, EmissionKey, Interpolation, Key, MaterialMotion, Motion,
};
use rt_core::instance::Prototype;
use rt_core::scene::Object;
use rt_core::transform::Transform;
use rt_core::Scene;
use std::collections::{HashMap, HashSet};
use toml::Spanned;

/// What an animation's target names.
enum Target {
    Geometry,
    Instance,
    Camera(usize),
    Material(u32),
}

/// Applies the file's instances and animations to `scene`; returns the material animations,
/// which the caller sets on the scene once its materials are in place.
pub(crate) fn apply(
    ctx: &Ctx,
    instances: &[Spanned<InstanceDesc>],
    animations: &[Spanned<AnimationDesc>],
    cameras: &[Spanned<CameraDesc>],
    materials: &MaterialTable,
    scene: &mut Scene,
) -> Result<Vec<MaterialMotion>> {
    if instances.is_empty() && animations.is_empty() {
        return Ok(Vec::new());
    }
    let geometries: HashSet<&str> = scene.objects.iter().map(|o| o.name.as_str()).collect();
    let camera_index: HashMap<&str, usize> = cameras
        .iter()
        .enumerate()
        .map(|(i, c)| (c.get_ref().name.get_ref().as_str(), i))
        .collect();
    // Instance names: unique, and distinct from geometry and camera names (animation targets
    // must be unambiguous).
    let mut instance_names = HashSet::new();
    for i in instances {
        let d = i.get_ref();
        let (name, g) = (d.name.get_ref(), d.geometry.get_ref());
        if name.is_empty() {
            return Err(ctx
                .src
                .error_at(d.name.span(), "instance name must not be empty"));
        }
        if geometries.contains(name.as_str()) || camera_index.contains_key(name.as_str()) {
            return Err(ctx.src.error_at(
                d.name.span(),
                format!("instance \"{name}\" has the name of a geometry or camera; animation targets must be unambiguous"),
            ));
        }
        if !instance_names.insert(name.as_str()) {
            return Err(ctx.src.error_at(
                d.name.span(),
                format!("instance \"{name}\" is defined twice"),
            ));
        }
        if !geometries.contains(g.as_str()) {
            return Err(ctx.src.error_at(
                d.geometry.span(),
                format!("geometry \"{g}\" placed by instance \"{name}\" is not defined"),
            ));
        }
    }
    let instanced: HashSet<&str> = instances
        .iter()
        .map(|i| i.get_ref().geometry.get_ref().as_str())
        .collect();

    // Animations by target.
    let mut motions: HashMap<String, Motion> = HashMap::new();
    let mut camera_motions = Vec::new();
    let mut material_motions: Vec<MaterialMotion> = Vec::new();
    let mut animated_geometries = Vec::new();
    for a in animations {
        let d = a.get_ref();
        let t = d.target.get_ref();
        // Emission keys make a material animation; so does a target that only a material has.
        let emission_keys = d
            .keys
            .get_ref()
            .iter()
            .any(|k| k.get_ref().emission.is_some());
        let other_target = camera_index.contains_key(t.as_str())
            || instance_names.contains(t.as_str())
            || geometries.contains(t.as_str());
        let target = if emission_keys || !other_target {
            match materials.find(t) {
                Some(m) => Target::Material(m),
                None if emission_keys => {
                    return Err(ctx.src.error_at(
                        d.target.span(),
                        format!("animation target \"{t}\" has emission keys but is not a [[material]] (emission animates a material; geometries, instances and cameras take transform or camera keys)"),
                    ))
                }
                None => {
                    return Err(ctx.src.error_at(
                        d.target.span(),
                        format!("animation target \"{t}\" is not a geometry, instance, camera or material"),
                    ))
                }
            }
        } else if let Some(&c) = camera_index.get(t.as_str()) {
            Target::Camera(c)
        } else if instance_names.contains(t.as_str()) {
            Target::Instance
        } else if geometries.contains(t.as_str()) {
            if instanced.contains(t.as_str()) {
                return Err(ctx.src.error_at(
                    d.target.span(),
                    format!("geometry \"{t}\" is placed by [[instance]] entries and is not rendered by itself; animate its instances instead"),
                ));
            }
            Target::Geometry
        } else {
            unreachable!("other_target holds for one of the three");
        };
        let twice = match target {
            Target::Material(m) => material_motions.iter().any(|x| x.material == m as usize),
            _ => {
                motions.contains_key(t)
                    || camera_motions
                        .iter()
                        .any(|m: &CameraMotion| Some(&m.camera) == camera_index.get(t.as_str()))
            }
        };
        if twice {
            return Err(ctx
                .src
                .error_at(d.target.span(), format!("\"{t}\" is animated twice")));
        }
        let at = |msg: String| {
            ctx.src
                .error_at(d.keys.span(), format!("animation of \"{t}\": {msg}"))
        };
        let interpolation = interpolation(ctx, t, d, matches!(target, Target::Material(_)))?;
        match target {
            Target::Material(m) => {
                let keys = emission_keys_of(ctx, t, &d.keys)?;
                material_motions.push(
                    MaterialMotion::new(m as usize, keys, interpolation)
                        .map_err(|e| at(e.to_string()))?,
                );
            }
            Target::Camera(c) => {
                let keys = camera_keys(ctx, t, &d.keys, cameras[c].get_ref())?;
                camera_motions.push(CameraMotion::new(c, keys).map_err(|e| at(e.to_string()))?);
            }
            Target::Geometry | Target::Instance => {
                let keys = transform_keys(ctx, t, &d.keys)?;
                motions.insert(t.clone(), Motion::new(keys).map_err(|e| at(e.to_string()))?);
                if matches!(target, Target::Geometry) {
                    animated_geometries.push(t.clone());
                }
            }
        }
    }

    // Prototypes leave the flat arrays, in object order.
    let prototype_names: HashSet<&str> = instanced
        .iter()
        .copied()
        .chain(animated_geometries.iter().map(String::as_str))
        .collect();
    let mut prototype_of: HashMap<String, u32> = HashMap::new();
    let extracted = extract_prototypes(scene, &prototype_names);
    for p in extracted {
        let name = p.name.clone();
        prototype_of.insert(name, scene.add_prototype(p));
    }
    for i in instances {
        let d = i.get_ref();
        let base = match &d.transform {
            Some(t) => geometry::transform(ctx, t)?.unwrap_or_default(),
            None => Transform::default(),
        };
        let name = d.name.get_ref();
        let proto = prototype_of[d.geometry.get_ref().as_str()];
        let motion = motions.remove(name.as_str());
        check_placement(
            ctx,
            scene,
            proto,
            &base,
            motion.as_ref(),
            name,
            d.name.span(),
        )?;
        scene.add_instance(name.clone(), proto, base, motion);
    }
    for g in animated_geometries {
        let proto = prototype_of[g.as_str()];
        let motion = motions.remove(g.as_str());
        scene.add_instance(g, proto, Transform::default(), motion);
    }
    scene.camera_motions = camera_motions;
    scene.set_time(0.0);
    Ok(material_motions)
}

/// The animation's `interpolate` option: linear by default; step only for materials.
fn interpolation(
    ctx: &Ctx,
    target: &str,
    d: &AnimationDesc,
    material: bool,
) -> Result<Interpolation> {
    let Some(i) = &d.interpolate else {
        return Ok(Interpolation::Linear);
    };
    let value = match i.get_ref().as_str() {
        "linear" => Interpolation::Linear,
        "step" => Interpolation::Step,
        other => {
            return Err(ctx.src.error_at(
                i.span(),
                format!("animation of \"{target}\": interpolate = \"{other}\" is not \"linear\" or \"step\""),
            ))
        }
    };
    if !material && value != Interpolation::Linear {
        return Err(ctx.src.error_at(
            i.span(),
            format!("animation of \"{target}\": interpolate = \"step\" applies to material (emission) animations only; transforms and cameras interpolate linearly"),
        ));
    }
    Ok(value)
}

/// The keys of a material's animation: `time` and `emission`, nothing else.
fn emission_keys_of(
    ctx: &Ctx,
    target: &str,
    keys: &Spanned<Vec<Spanned<KeyDesc>>>,
) -> Result<Vec<EmissionKey>> {
    keys.get_ref()
        .iter()
        .map(|k| {
            let d = k.get_ref();
            let other = [
                ("translate", d.translate.is_some()),
                ("rotate", d.rotate.is_some()),
                ("scale", d.scale.is_some()),
                ("position", d.position.is_some()),
                ("look_at", d.look_at.is_some()),
                ("up", d.up.is_some()),
                ("fov", d.fov.is_some()),
            ];
            if let Some((name, _)) = other.iter().find(|(_, set)| *set) {
                return Err(ctx.src.error_at(
                    k.span(),
                    format!("animation of material \"{target}\": `{name}` is not a material key; a material takes time and emission (animate a geometry's motion in an [[animation]] of its own)"),
                ));
            }
            let Some(e) = d.emission else {
                return Err(ctx.src.error_at(
                    k.span(),
                    format!("animation of material \"{target}\": a key at time {} has no emission", d.time),
                ));
            };
            Ok(EmissionKey {
                time: d.time,
                emission: Vec3::from(e),
            })
        })
        .collect()
}

/// Refuses a placement whose world copy overflows at some key.
fn check_placement(
    ctx: &Ctx,
    scene: &Scene,
    proto: u32,
    base: &Transform,
    motion: Option<&Motion>,
    name: &str,
    span: std::ops::Range<usize>,
) -> Result<()> {
    let p = &scene.prototypes[proto as usize];
    let transforms: Vec<Transform> = match motion {
        Some(m) => m.keys().iter().map(|k| m.at(k.time).then(base)).collect(),
        None => vec![*base],
    };
    for t in transforms {
        if p.triangles
            .iter()
            .any(|v| v.iter().any(|q| !t.point(*q).is_finite()))
        {
            return Err(ctx.src.error_at(
                span,
                format!("instance \"{name}\": its triangles are not finite after the transform (overflow)"),
            ));
        }
    }
    Ok(())
}

/// Moves the named objects' triangles and attributes out of the flat arrays into prototypes
/// (in object order) and compacts the arrays and the object list.
fn extract_prototypes(scene: &mut Scene, names: &HashSet<&str>) -> Vec<Prototype> {
    let has_normals = !scene.normals.is_empty();
    let has_uvs = !scene.uvs.is_empty();
    let objects = std::mem::take(&mut scene.objects);
    let triangles = std::mem::take(&mut scene.triangles);
    let normals = std::mem::take(&mut scene.normals);
    let uvs = std::mem::take(&mut scene.uvs);
    let material_ids = std::mem::take(&mut scene.material_ids);
    let mut prototypes = Vec::new();
    let mut covered = 0usize;
    let keep = |scene: &mut Scene, r: std::ops::Range<usize>| {
        scene.triangles.extend_from_slice(&triangles[r.clone()]);
        scene
            .material_ids
            .extend_from_slice(&material_ids[r.clone()]);
        if has_normals {
            scene.normals.extend_from_slice(&normals[r.clone()]);
        }
        if has_uvs {
            scene.uvs.extend_from_slice(&uvs[r]);
        }
    };
    for o in objects {
        let r = o.first as usize..(o.first + o.count) as usize;
        // Triangles outside every object (none from the loader) stay where they were.
        keep(scene, covered..r.start);
        covered = r.end;
        if names.contains(o.name.as_str()) {
            let all_none = |v: &[Option<[Vec3; 3]>]| v.iter().all(Option::is_none);
            let n = if has_normals {
                normals[r.clone()].to_vec()
            } else {
                Vec::new()
            };
            let uv = if has_uvs {
                uvs[r.clone()].to_vec()
            } else {
                Vec::new()
            };
            prototypes.push(Prototype {
                name: o.name.clone(),
                triangles: triangles[r.clone()].to_vec(),
                normals: if all_none(&n) { Vec::new() } else { n },
                uvs: if uv.iter().all(Option::is_none) {
                    Vec::new()
                } else {
                    uv
                },
                material_ids: material_ids[r].to_vec(),
            });
        } else {
            let first = scene.triangles.len() as u32;
            keep(scene, r);
            scene.objects.push(Object {
                name: o.name,
                first,
                count: o.count,
            });
        }
    }
    keep(scene, covered..triangles.len());
    prototypes
}

/// The keys of a geometry's or instance's animation.
fn transform_keys(
    ctx: &Ctx,
    target: &str,
    keys: &Spanned<Vec<Spanned<KeyDesc>>>,
) -> Result<Vec<Key>> {
    keys.get_ref()
        .iter()
        .map(|k| {
            let d = k.get_ref();
            if d.position.is_some() || d.look_at.is_some() || d.up.is_some() || d.fov.is_some() {
                return Err(ctx.src.error_at(
                    k.span(),
                    format!("animation of \"{target}\": position, look_at, up and fov are camera keys; a geometry or instance takes translate, rotate and scale"),
                ));
            }
            Ok(Key::from_trs(
                d.time,
                d.translate.map_or(Vec3::ZERO, Vec3::from),
                d.rotate.map_or(Vec3::ZERO, Vec3::from),
                Vec3::from(d.scale.map_or([1.0; 3], |s| s.0)),
            ))
        })
        .collect()
}

/// The keys of a camera's animation; values a key leaves out are the camera's own.
fn camera_keys(
    ctx: &Ctx,
    target: &str,
    keys: &Spanned<Vec<Spanned<KeyDesc>>>,
    camera: &CameraDesc,
) -> Result<Vec<CameraKey>> {
    let position = Vec3::from(*camera.position.get_ref());
    let look_at = Vec3::from(*camera.look_at.get_ref());
    let up = camera
        .up
        .as_ref()
        .map_or(Vec3::Y, |u| Vec3::from(*u.get_ref()));
    let fov = camera.fov.as_ref().map_or(40.0, |f| *f.get_ref());
    keys.get_ref()
        .iter()
        .map(|k| {
            let d = k.get_ref();
            if d.translate.is_some() || d.rotate.is_some() || d.scale.is_some() {
                return Err(ctx.src.error_at(
                    k.span(),
                    format!("animation of camera \"{target}\": translate, rotate and scale are geometry keys; a camera takes position, look_at, up and fov"),
                ));
            }
            Ok(CameraKey {
                time: d.time,
                position: d.position.map_or(position, Vec3::from),
                look_at: d.look_at.map_or(look_at, Vec3::from),
                up: d.up.map_or(up, Vec3::from),
                fov: d.fov.unwrap_or(fov),
            })
        })
        .collect()
}
