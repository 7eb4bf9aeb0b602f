//! Mitsuba BSDFs as `[[material]]` tables of our format: `diffuse` and the microfacet family
//! keep their names and parameters (docs/scene-format.md, "The microfacet family"),
//! `plastic` becomes our `smoothplastic`, `twosided` a flag on what it wraps.

use toml::{Table, Value};

use super::props::{Color, Props};
use super::spectrum::Role;
use super::xml::Node;
use crate::error::SceneError;

/// What a BSDF element becomes: a material table without its name.
pub(super) struct Converted {
    pub table: Table,
    /// Texture file names the table refers to (relative to the scene file).
    pub texture: Option<String>,
}

/// Converts `node` (a `<bsdf>`); `two_sided` when a `twosided` wraps it.
pub(super) fn convert<'a>(
    node: &'a Node,
    resolve: &dyn Fn(&'a Node) -> Result<&'a Node, SceneError>,
    two_sided: bool,
    warnings: &mut Vec<String>,
) -> Result<Converted, SceneError> {
    let p = Props::new(node);
    let ty = node.plugin()?;
    let mut t = Table::new();
    let mut texture = None;
    match ty {
        "twosided" => {
            let mut inner: Vec<&'a Node> = p.objects("bsdf");
            for r in p.refs() {
                inner.push(resolve(r)?);
            }
            let [one] = inner.as_slice() else {
                return Err(p.error(format!("wraps {} BSDFs, expected one", inner.len())));
            };
            if two_sided {
                return Err(p.error("a twosided inside a twosided"));
            }
            p.finish(warnings)?;
            return convert(one, resolve, true, warnings);
        }
        "diffuse" => {
            t.insert("type".into(), "diffuse".into());
            match p.color("reflectance", Role::Reflectance)? {
                None => {
                    t.insert("color".into(), rgb([0.5; 3]));
                }
                Some(Color::Rgb(c)) => {
                    t.insert("color".into(), rgb(c));
                }
                Some(Color::Texture(tex)) => {
                    texture = Some(bitmap(tex, warnings)?);
                    t.insert("color".into(), rgb([1.0; 3]));
                }
            }
            // Our diffuse surfaces shade both sides; a one-sided one differs only on back
            // faces (black in Mitsuba), which closed scenes do not show.
        }
        "conductor" | "roughconductor" => {
            t.insert("type".into(), ty.into());
            rough(&p, &mut t, ty == "roughconductor")?;
            if let Some(m) = p.string("material")? {
                t.insert("material".into(), m.into());
            }
            for key in ["eta", "k"] {
                if let Some(c) = p.rgb(key, Role::Unbounded)? {
                    t.insert(key.into(), rgb(c));
                }
            }
            reflectance(&p, &mut t, "specular_reflectance")?;
            if two_sided {
                t.insert("two_sided".into(), true.into());
            }
        }
        "dielectric" | "thindielectric" | "roughdielectric" => {
            t.insert("type".into(), ty.into());
            rough(&p, &mut t, ty == "roughdielectric")?;
            iors(&p, &mut t)?;
            reflectance(&p, &mut t, "specular_reflectance")?;
            reflectance(&p, &mut t, "specular_transmittance")?;
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
            rough(&p, &mut t, rough_one)?;
            iors(&p, &mut t)?;
            reflectance(&p, &mut t, "specular_reflectance")?;
            match p.color("diffuse_reflectance", Role::Reflectance)? {
                None => {}
                Some(Color::Rgb(c)) => {
                    t.insert("diffuse_reflectance".into(), rgb(c));
                }
                Some(Color::Texture(tex)) => {
                    texture = Some(bitmap(tex, warnings)?);
                    t.insert("diffuse_reflectance".into(), rgb([1.0; 3]));
                }
            }
            if let Some(b) = p.boolean("nonlinear")? {
                t.insert("nonlinear".into(), b.into());
            }
        }
        other => {
            return Err(node.at.error(format!(
            "bsdf \"{other}\" is not supported (supported: diffuse, dielectric, thindielectric, \
                 roughdielectric, conductor, roughconductor, plastic, roughplastic, twosided)"
        )))
        }
    }
    p.finish(warnings)?;
    Ok(Converted { table: t, texture })
}

fn rgb(c: [f64; 3]) -> Value {
    Value::Array(c.iter().map(|&v| Value::Float(v)).collect())
}

/// A constant reflectance parameter copied under the same name.
fn reflectance(p: &Props, t: &mut Table, key: &str) -> Result<(), SceneError> {
    if let Some(c) = p.rgb(key, Role::Reflectance)? {
        t.insert(key.into(), rgb(c));
    }
    Ok(())
}

/// `distribution`, `alpha` or `alpha_u` and `alpha_v` of the rough ones.
fn rough(p: &Props, t: &mut Table, is_rough: bool) -> Result<(), SceneError> {
    if !is_rough {
        return Ok(());
    }
    if let Some(d) = p.string("distribution")? {
        t.insert("distribution".into(), d.into());
    }
    for key in ["alpha", "alpha_u", "alpha_v"] {
        if let Some(v) = p.float(key)? {
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

/// A `bitmap` texture's file, after checking that our textures do what it asks: sRGB
/// 8-bit images looked up bilinearly with repeat wrapping.
fn bitmap(tex: &Node, warnings: &mut Vec<String>) -> Result<String, SceneError> {
    let p = Props::new(tex);
    if tex.plugin()? != "bitmap" {
        return Err(p.error("only bitmap textures are supported"));
    }
    let file = p
        .string("filename")?
        .ok_or_else(|| p.error("has no filename"))?
        .to_string();
    if let Some(f) = p.string("filter_type")? {
        if f != "bilinear" {
            return Err(p.error(format!(
                "filter_type \"{f}\" is not supported (bilinear is)"
            )));
        }
    }
    if let Some(w) = p.string("wrap_mode")? {
        if w != "repeat" {
            return Err(p.error(format!("wrap_mode \"{w}\" is not supported (repeat is)")));
        }
    }
    if p.boolean("raw")? == Some(true) {
        return Err(p.error("raw (linear) 8-bit data is not supported (sRGB is)"));
    }
    p.finish(warnings)?;
    Ok(file)
}
