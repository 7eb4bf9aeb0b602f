//! Mitsuba BSDFs as `[[material]]` tables of our format: `diffuse` and the microfacet family
//! keep their names and parameters (docs/scene-format.md, "The microfacet family"),
//! `plastic` becomes our `smoothplastic`, `twosided` a flag on what it wraps, `mask` the key
//! `opacity` on what it wraps, `bumpmap` and `normalmap` the keys `bump_map` (with
//! `bump_scale`) and `normal_map` on what they wrap, `blendbsdf` a `blendbsdf` table whose
//! two BSDFs become materials of their own ([`Converted::parts`]).

use rt_core::glam::DMat4;
use toml::{Table, Value};

use super::props::{Color, Props};
use super::spectrum::Role;
use super::xml::Node;
use crate::error::SceneError;

/// What a BSDF element becomes: a material table without its name.
pub(super) struct Converted {
    pub table: Table,
    /// The table's texture keys, whose file names are relative to the scene file.
    pub textures: Vec<TextureKey>,
    /// A `blendbsdf`'s two BSDFs, which the caller names and lists before the blend's table
    /// and names in its `bsdfs` key; empty for every other BSDF.
    pub parts: Vec<Converted>,
}

/// A texture key of a material table: a `bitmap`'s file and its options, or a
/// `checkerboard` table (docs/scene-format.md, "Textures").
pub(super) struct TextureKey {
    /// The material key (`texture`, `bump_map`, `normal_map`, or a textured parameter's name).
    pub key: &'static str,
    /// The bitmap's file; `None` for a checkerboard, which is `options` alone.
    file: Option<String>,
    options: Table,
}

impl TextureKey {
    /// The key's value, with the file name as `file_name` maps it.
    pub fn value(&self, file_name: &dyn Fn(&str) -> String) -> Value {
        let Some(file) = &self.file else {
            return Value::Table(self.options.clone());
        };
        if self.options.is_empty() {
            return file_name(file).into();
        }
        let mut t = self.options.clone();
        t.insert("file".into(), file_name(file).into());
        Value::Table(t)
    }
}

/// Which wrappers enclose the BSDF being converted.
#[derive(Clone, Copy, Default)]
struct Wrapped {
    two_sided: bool,
    /// A `bumpmap` or `normalmap`.
    perturbed: bool,
    /// A `blendbsdf`: what its BSDFs cannot be.
    blended: bool,
}

/// Converts `node` (a `<bsdf>`).
pub(super) fn convert<'a>(
    node: &'a Node,
    resolve: &dyn Fn(&'a Node) -> Result<&'a Node, SceneError>,
    warnings: &mut Vec<String>,
) -> Result<Converted, SceneError> {
    convert_in(node, resolve, Wrapped::default(), warnings)
}

/// A top-level BSDF without an id: no shape can refer to it, and Mitsuba 3 builds it and
/// leaves it unused (the staircase's `bumpmap`, whose nested BSDF the shapes name instead).
/// Converted to check it, and reported as one warning.
pub(super) fn unused<'a>(
    node: &'a Node,
    resolve: &dyn Fn(&'a Node) -> Result<&'a Node, SceneError>,
    warnings: &mut Vec<String>,
) -> Result<(), SceneError> {
    convert(node, resolve, warnings)?;
    warnings.push(node.at.warning(format!(
        "<bsdf type=\"{}\"> has no id, so no shape uses it (Mitsuba ignores it too)",
        node.plugin()?
    )));
    Ok(())
}

/// The one BSDF a wrapper holds, nested or referenced.
fn wrapped_one<'a>(
    p: &Props<'a>,
    resolve: &dyn Fn(&'a Node) -> Result<&'a Node, SceneError>,
) -> Result<&'a Node, SceneError> {
    let mut inner: Vec<&'a Node> = p.objects("bsdf");
    for r in p.refs() {
        // A `<ref>` to a texture is a parameter, read by name.
        let n = resolve(r)?;
        if n.tag == "bsdf" {
            inner.push(n);
        }
    }
    match inner.as_slice() {
        [one] => Ok(one),
        _ => Err(p.error(format!("wraps {} BSDFs, expected one", inner.len()))),
    }
}

/// [`convert`] inside the wrappers `wrapped`.
fn convert_in<'a>(
    node: &'a Node,
    resolve: &dyn Fn(&'a Node) -> Result<&'a Node, SceneError>,
    wrapped: Wrapped,
    warnings: &mut Vec<String>,
) -> Result<Converted, SceneError> {
    let p = Props::new(node);
    let ty = node.plugin()?;
    let mut t = Table::new();
    let mut textures = Vec::new();
    let two_sided = wrapped.two_sided;
    match ty {
        "twosided" => {
            let one = wrapped_one(&p, resolve)?;
            if two_sided {
                return Err(p.error("a twosided inside a twosided"));
            }
            p.finish(warnings)?;
            let inner = Wrapped {
                two_sided: true,
                ..wrapped
            };
            return convert_in(one, resolve, inner, warnings);
        }
        "mask" | "bumpmap" | "normalmap" | "blendbsdf" if wrapped.blended => {
            return Err(node.at.error(format!(
                "a {ty} inside a blendbsdf is not supported (wrap the blendbsdf instead)"
            )));
        }
        "blendbsdf" => {
            let (weight_texture, weight) = match p.named_texture("weight", resolve)? {
                Some(tex) => (Some(texture(tex, "weight", warnings)?), None),
                None => (None, p.float("weight")?),
            };
            let inner = blended_two(node, &p, resolve)?;
            t.insert("type".into(), "blendbsdf".into());
            match (weight_texture, weight) {
                (Some(tex), _) => textures.push(tex),
                (None, Some(w)) if !(0.0..=1.0).contains(&w) => {
                    return Err(p.error(format!("weight must be in [0, 1], got {w}")));
                }
                (None, Some(w)) => {
                    t.insert("weight".into(), w.into());
                }
                (None, None) => return Err(p.error("needs a `weight`")),
            }
            p.finish(warnings)?;
            let in_blend = Wrapped {
                blended: true,
                ..wrapped
            };
            let parts = inner
                .into_iter()
                .map(|n| convert_in(n, resolve, in_blend, warnings))
                .collect::<Result<Vec<_>, _>>()?;
            return Ok(Converted {
                table: t,
                textures,
                parts,
            });
        }
        "mask" => {
            // Mitsuba's default opacity is 0.5.
            let (texture_key, opacity) = match p.named_texture("opacity", resolve)? {
                Some(tex) => (Some(texture(tex, "opacity", warnings)?), 0.5),
                None => (None, p.float("opacity")?.unwrap_or(0.5)),
            };
            let one = wrapped_one(&p, resolve)?;
            p.finish(warnings)?;
            let mut c = convert_in(one, resolve, wrapped, warnings)?;
            if c.table.contains_key("opacity") || c.textures.iter().any(|t| t.key == "opacity") {
                return Err(node.at.error("a mask inside a mask is not supported"));
            }
            match texture_key {
                Some(t) => c.textures.push(t),
                None => {
                    c.table.insert("opacity".into(), opacity.into());
                }
            }
            return Ok(c);
        }
        "bumpmap" | "normalmap" => {
            let one = wrapped_one(&p, resolve)?;
            if wrapped.perturbed {
                return Err(p.error("a bumpmap or normalmap inside another"));
            }
            let maps = p.objects("texture");
            let map = match (ty, maps.as_slice()) {
                // Mitsuba's normalmap reads its texture by name; bumpmap takes any one.
                ("normalmap", _) => match p.color("normalmap", Role::Unbounded)? {
                    Some(Color::Texture(tex)) => tex,
                    _ => return Err(p.error("needs a texture named `normalmap`")),
                },
                (_, [one]) => *one,
                (_, many) => {
                    return Err(p.error(format!(
                        "has {} textures, expected one height map",
                        many.len()
                    )))
                }
            };
            let scale = if ty == "bumpmap" {
                p.float("scale")?
            } else {
                None
            };
            p.finish(warnings)?;
            let inner = Wrapped {
                perturbed: true,
                ..wrapped
            };
            let mut c = convert_in(one, resolve, inner, warnings)?;
            let key = if ty == "bumpmap" {
                "bump_map"
            } else {
                "normal_map"
            };
            c.textures.push(texture(map, key, warnings)?);
            if let Some(s) = scale {
                c.table.insert("bump_scale".into(), s.into());
            }
            return Ok(c);
        }
        "diffuse" => {
            t.insert("type".into(), "diffuse".into());
            match colour(&p, "reflectance", resolve)? {
                None => {
                    t.insert("color".into(), rgb([0.5; 3]));
                }
                Some(Color::Rgb(c)) => {
                    t.insert("color".into(), rgb(c));
                }
                Some(Color::Texture(tex)) => {
                    textures.push(texture(tex, "texture", warnings)?);
                    t.insert("color".into(), rgb([1.0; 3]));
                }
            }
            // Our diffuse surfaces shade both sides; a one-sided one differs only on back
            // faces (black in Mitsuba), which closed scenes do not show.
        }
        "conductor" | "roughconductor" => {
            t.insert("type".into(), ty.into());
            rough(
                &p,
                &mut t,
                &mut textures,
                ty == "roughconductor",
                resolve,
                warnings,
            )?;
            if let Some(m) = p.string("material")? {
                t.insert("material".into(), m.into());
            }
            for key in ["eta", "k"] {
                if let Some(tex) = p.named_texture(key, resolve)? {
                    textures.push(texture(tex, key, warnings)?);
                } else if let Some(c) = p.rgb(key, Role::Unbounded)? {
                    t.insert(key.into(), rgb(c));
                }
            }
            reflectance(
                &p,
                &mut t,
                &mut textures,
                "specular_reflectance",
                resolve,
                warnings,
            )?;
            if two_sided {
                t.insert("two_sided".into(), true.into());
            }
        }
        "dielectric" | "thindielectric" | "roughdielectric" => {
            t.insert("type".into(), ty.into());
            rough(
                &p,
                &mut t,
                &mut textures,
                ty == "roughdielectric",
                resolve,
                warnings,
            )?;
            iors(&p, &mut t)?;
            for key in ["specular_reflectance", "specular_transmittance"] {
                reflectance(&p, &mut t, &mut textures, key, resolve, warnings)?;
            }
        }
        "plastic" | "roughplastic" => {
            let rough_one = ty == "roughplastic";
            t.insert(
                "type".into(),
                if rough_one {
                    "roughplastic"
                } else {
                    "smoothplastic"
                }
                .into(),
            );
            rough(&p, &mut t, &mut textures, rough_one, resolve, warnings)?;
            iors(&p, &mut t)?;
            reflectance(
                &p,
                &mut t,
                &mut textures,
                "specular_reflectance",
                resolve,
                warnings,
            )?;
            match colour(&p, "diffuse_reflectance", resolve)? {
                None => {}
                Some(Color::Rgb(c)) => {
                    t.insert("diffuse_reflectance".into(), rgb(c));
                }
                Some(Color::Texture(tex)) => {
                    textures.push(texture(tex, "texture", warnings)?);
                    t.insert("diffuse_reflectance".into(), rgb([1.0; 3]));
                }
            }
            if let Some(b) = p.boolean("nonlinear")? {
                t.insert("nonlinear".into(), b.into());
            }
            if two_sided {
                t.insert("two_sided".into(), true.into());
            }
        }
        other => {
            return Err(node.at.error(format!(
            "bsdf \"{other}\" is not supported (supported: diffuse, dielectric, thindielectric, \
                 roughdielectric, conductor, roughconductor, plastic, roughplastic, twosided, \
                 mask, bumpmap, normalmap, blendbsdf)"
        )))
        }
    }
    p.finish(warnings)?;
    Ok(Converted {
        table: t,
        textures,
        parts: Vec::new(),
    })
}

/// The two BSDFs a `blendbsdf` blends, nested or referenced, in the order they appear.
fn blended_two<'a>(
    node: &'a Node,
    p: &Props<'a>,
    resolve: &dyn Fn(&'a Node) -> Result<&'a Node, SceneError>,
) -> Result<[&'a Node; 2], SceneError> {
    // Marks them read.
    p.objects("bsdf");
    p.refs();
    let mut inner = Vec::new();
    for c in &node.children {
        match c.tag.as_str() {
            "bsdf" => inner.push(c),
            "ref" => {
                let n = resolve(c)?;
                if n.tag == "bsdf" {
                    inner.push(n);
                }
            }
            _ => {}
        }
    }
    match inner.as_slice() {
        [a, b] => Ok([a, b]),
        _ => Err(p.error(format!("blends {} BSDFs, expected two", inner.len()))),
    }
}

/// A colour parameter: a constant, a nested texture or a `<ref>` to one.
fn colour<'a>(
    p: &Props<'a>,
    key: &str,
    resolve: &dyn Fn(&'a Node) -> Result<&'a Node, SceneError>,
) -> Result<Option<Color<'a>>, SceneError> {
    match p.named_texture(key, resolve)? {
        Some(t) => Ok(Some(Color::Texture(t))),
        None => p.color(key, Role::Reflectance),
    }
}

fn rgb(c: [f64; 3]) -> Value {
    Value::Array(c.iter().map(|&v| Value::Float(v)).collect())
}

/// A reflectance parameter copied under the same name: a constant, or a texture (nested or
/// `<ref>`).
fn reflectance<'a>(
    p: &Props<'a>,
    t: &mut Table,
    textures: &mut Vec<TextureKey>,
    key: &'static str,
    resolve: &dyn Fn(&'a Node) -> Result<&'a Node, SceneError>,
    warnings: &mut Vec<String>,
) -> Result<(), SceneError> {
    if let Some(tex) = p.named_texture(key, resolve)? {
        textures.push(texture(tex, key, warnings)?);
    } else if let Some(c) = p.rgb(key, Role::Reflectance)? {
        t.insert(key.into(), rgb(c));
    }
    Ok(())
}

/// `distribution`, `alpha` or `alpha_u` and `alpha_v` of the rough ones (numbers or
/// textures).
fn rough<'a>(
    p: &Props<'a>,
    t: &mut Table,
    textures: &mut Vec<TextureKey>,
    is_rough: bool,
    resolve: &dyn Fn(&'a Node) -> Result<&'a Node, SceneError>,
    warnings: &mut Vec<String>,
) -> Result<(), SceneError> {
    if !is_rough {
        return Ok(());
    }
    if let Some(d) = p.string("distribution")? {
        t.insert("distribution".into(), d.into());
    }
    for key in ["alpha", "alpha_u", "alpha_v"] {
        if let Some(tex) = p.named_texture(key, resolve)? {
            textures.push(texture(tex, key, warnings)?);
        } else if let Some(v) = p.float(key)? {
            t.insert(key.into(), v.into());
        }
    }
    // GGX is sampled from its visible normals either way: the same expectation.
    p.accept("sample_visible");
    Ok(())
}

/// `int_ior` and `ext_ior`: numbers or Mitsuba's names.
fn iors(p: &Props, t: &mut Table) -> Result<(), SceneError> {
    for key in ["int_ior", "ext_ior"] {
        let v = match p.string(key) {
            Ok(Some(name)) => Some(Value::String(name.into())),
            Ok(None) => None,
            Err(_) => p.float(key)?.map(Value::Float),
        };
        if let Some(v) = v {
            t.insert(key.into(), v);
        }
    }
    Ok(())
}

/// A texture as material key `key`: a `bitmap` or a `checkerboard`.
fn texture(
    tex: &Node,
    key: &'static str,
    warnings: &mut Vec<String>,
) -> Result<TextureKey, SceneError> {
    match tex.plugin()? {
        "bitmap" => bitmap(tex, key, warnings),
        "checkerboard" => checkerboard(tex, key, warnings),
        other => Err(Props::new(tex).error(format!(
            "texture \"{other}\" is not supported (bitmap and checkerboard are)"
        ))),
    }
}

/// A `checkerboard`: its constant colours (Mitsuba's defaults 0.4 and 0.2) and the 2-D part
/// of `to_uv` (`(u, v) ↦ (m00·u + m01·v + m03, m10·u + m11·v + m13)`, as Mitsuba 3.9 reads
/// it).
fn checkerboard(
    tex: &Node,
    key: &'static str,
    warnings: &mut Vec<String>,
) -> Result<TextureKey, SceneError> {
    let p = Props::new(tex);
    let mut options = Table::new();
    options.insert("type".into(), "checkerboard".into());
    // A conductor's index of refraction is not a reflectance: its colours are not clamped.
    let role = match key {
        "eta" | "k" => Role::Unbounded,
        _ => Role::Reflectance,
    };
    for c in ["color0", "color1"] {
        if let Some(v) = p.rgb(c, role)? {
            options.insert(c.into(), rgb(v));
        }
    }
    // Mitsuba's checkerboard reads Mitsuba's uv, whose v is 1 − ours on every shape (see the
    // shapes in `scene.rs`): `to_uv` after `(u, v) ↦ (u, 1 − v)`.
    let m = p.transform("to_uv")?.unwrap_or(DMat4::IDENTITY);
    let row = |r: usize| rgb([m.col(0)[r], -m.col(1)[r], m.col(1)[r] + m.col(3)[r]]);
    options.insert("to_uv".into(), Value::Array(vec![row(0), row(1)]));
    p.finish(warnings)?;
    Ok(TextureKey {
        key,
        file: None,
        options,
    })
}

/// A `bitmap` texture as material key `key`: its file and the options it sets (Mitsuba's
/// defaults are ours: bilinear, repeat, sRGB).
fn bitmap(
    tex: &Node,
    key: &'static str,
    warnings: &mut Vec<String>,
) -> Result<TextureKey, SceneError> {
    let p = Props::new(tex);
    let file = p
        .string("filename")?
        .ok_or_else(|| p.error("has no filename"))?
        .to_string();
    let mut options = Table::new();
    if let Some(f) = p.string("filter_type")? {
        if !matches!(f, "bilinear" | "nearest") {
            return Err(p.error(format!(
                "filter_type \"{f}\" is not supported (bilinear and nearest are)"
            )));
        }
        if f != "bilinear" {
            options.insert("filter".into(), f.into());
        }
    }
    if let Some(w) = p.string("wrap_mode")? {
        if !matches!(w, "repeat" | "mirror" | "clamp") {
            return Err(p.error(format!(
                "wrap_mode \"{w}\" is not supported (repeat, mirror and clamp are)"
            )));
        }
        if w != "repeat" {
            options.insert("wrap".into(), w.into());
        }
    }
    // Mitsuba reads every bitmap as sRGB unless told `raw`, normal maps too; our normal maps
    // default to raw, so the choice is always written for them.
    let raw = p.boolean("raw")?.unwrap_or(false);
    if raw || key == "normal_map" {
        options.insert("raw".into(), raw.into());
    }
    p.finish(warnings)?;
    Ok(TextureKey {
        key,
        file: Some(file),
        options,
    })
}
