//! A material's texture keys. A texture is a file name, or a table
//! `{ file = "...", filter = "bilinear" | "nearest", wrap = "repeat" | "mirror" | "clamp",
//! raw = false }` (Mitsuba's `bitmap` options; `raw` reads the values as linear data instead of
//! sRGB colours), or Mitsuba's checkerboard `{ type = "checkerboard", color0 = 0.4,
//! color1 = 0.2, to_uv = [[a, b, c], [d, e, f]] }` (colours a number or `[r, g, b]`; `to_uv`
//! maps `(u, v)` to `(a·u + b·v + c, d·u + e·v + f)`, the identity by default).
//! `bump_map` (with `bump_scale`, default 1) and `normal_map` bend the shading normal
//! ([`rt_core::bump`]); a normal map is raw unless it says otherwise.

use std::ops::Range;
use std::path::PathBuf;

use rt_core::bump::NormalPerturbation;
use rt_core::glam::Affine2;
use rt_core::texture::{Filter, Texture, Wrap};
use rt_core::Rgb;
use toml::{Spanned, Value};

use crate::desc::MaterialDesc;
use crate::error::Result;
use crate::image_io::TextureOptions;
use crate::load::Ctx;

/// Loads the texture `v` names for material `name`; `raw` is the default of its `raw` key.
pub(crate) fn load(ctx: &mut Ctx, name: &str, v: &Spanned<Value>, raw: bool) -> Result<u32> {
    load_in(ctx, name, v, raw, Texels::Reflectance)
}

/// [`load`] for a parameter that is not a reflectance (a conductor's `eta` and `k`): a
/// checkerboard's colours may exceed 1, and lookups read texels unclamped
/// ([`rt_core::texture::Texture::lookup_unbounded`]; float images hold such values).
pub(crate) fn load_unbounded(ctx: &mut Ctx, name: &str, v: &Spanned<Value>) -> Result<u32> {
    load_in(ctx, name, v, false, Texels::Unbounded)
}

/// The values a texture's texels may take.
#[derive(Clone, Copy, PartialEq, Eq)]
enum Texels {
    /// [0, 1].
    Reflectance,
    /// Any non-negative number.
    Unbounded,
}

fn load_in(
    ctx: &mut Ctx,
    name: &str,
    v: &Spanned<Value>,
    raw: bool,
    texels: Texels,
) -> Result<u32> {
    if let Some(t) = v.get_ref().as_table().filter(|t| t.contains_key("type")) {
        let texture = checkerboard(t, texels).map_err(|e| {
            ctx.src
                .error_at(v.span(), format!("material \"{name}\": {e}"))
        })?;
        return Ok(ctx.textures.add(texture));
    }
    let (path, options) = read(ctx, name, v, raw)?;
    ctx.textures.load(&path, options)
}

/// A `{ type = "checkerboard", ... }` table (the only texture type besides files).
fn checkerboard(t: &toml::Table, texels: Texels) -> std::result::Result<Texture, String> {
    let mut colors = [Rgb::splat(0.4), Rgb::splat(0.2)];
    let mut to_uv = Affine2::IDENTITY;
    for (key, value) in t {
        match key.as_str() {
            "type" => match value.as_str() {
                Some("checkerboard") => {}
                Some(other) => {
                    return Err(format!(
                        "texture type \"{other}\" is not supported (checkerboard is; an image \
                         is a file name or {{ file = ... }})"
                    ))
                }
                None => return Err("texture `type` must be a string".into()),
            },
            "color0" | "color1" => {
                let c = colour(value, texels).ok_or_else(|| match texels {
                    Texels::Reflectance => {
                        format!("checkerboard `{key}` must be a number or [r, g, b] in [0, 1]")
                    }
                    Texels::Unbounded => {
                        format!("checkerboard `{key}` must be a non-negative number or [r, g, b]")
                    }
                })?;
                colors[(key == "color1") as usize] = c;
            }
            "to_uv" => {
                to_uv = affine(value).ok_or_else(|| {
                    "checkerboard `to_uv` must be [[a, b, c], [d, e, f]] of finite numbers"
                        .to_string()
                })?
            }
            other => {
                return Err(format!(
                    "unknown checkerboard key `{other}` (the keys are type, color0, color1, to_uv)"
                ))
            }
        }
    }
    Ok(Texture::checkerboard(colors[0], colors[1], to_uv))
}

fn number(v: &Value) -> Option<f32> {
    let x = match v {
        Value::Float(x) => *x as f32,
        Value::Integer(i) => *i as f32,
        _ => return None,
    };
    x.is_finite().then_some(x)
}

/// A number or `[r, g, b]`, each non-negative, and at most 1 for a reflectance.
fn colour(v: &Value, texels: Texels) -> Option<Rgb> {
    let c = match v {
        Value::Array(a) if a.len() == 3 => Rgb::new(number(&a[0])?, number(&a[1])?, number(&a[2])?),
        other => Rgb::splat(number(other)?),
    };
    let max = match texels {
        Texels::Reflectance => 1.0,
        Texels::Unbounded => f32::MAX,
    };
    (c.min_element() >= 0.0 && c.max_element() <= max).then_some(c)
}

/// `[[a, b, c], [d, e, f]]`: `(u, v) ↦ (a·u + b·v + c, d·u + e·v + f)`.
fn affine(v: &Value) -> Option<Affine2> {
    let rows = v.as_array().filter(|r| r.len() == 2)?;
    let mut m = [[0.0f32; 3]; 2];
    for (row, r) in m.iter_mut().zip(rows) {
        let r = r.as_array().filter(|r| r.len() == 3)?;
        for (x, y) in row.iter_mut().zip(r) {
            *x = number(y)?;
        }
    }
    let [[a, b, c], [d, e, f]] = m;
    Some(Affine2::from_cols_array(&[a, d, b, e, c, f]))
}

/// The file (resolved against the scene's directory) and options of texture value `v` of
/// material `name`.
fn read(ctx: &Ctx, name: &str, v: &Spanned<Value>, raw: bool) -> Result<(PathBuf, TextureOptions)> {
    let (file, options) = parse(v.get_ref(), raw).map_err(|e| {
        ctx.src
            .error_at(v.span(), format!("material \"{name}\": {e}"))
    })?;
    Ok((ctx.resolve(&file), options))
}

/// The file and options of a texture value.
fn parse(v: &Value, raw: bool) -> std::result::Result<(String, TextureOptions), String> {
    let mut options = TextureOptions {
        raw,
        ..TextureOptions::default()
    };
    let t = match v {
        Value::String(f) => return Ok((f.clone(), options)),
        Value::Table(t) => t,
        _ => {
            return Err(
                "a texture is a file name or a table { file, filter, wrap, raw }".to_string(),
            )
        }
    };
    let mut file = None;
    for (key, value) in t {
        let text = || {
            value
                .as_str()
                .ok_or_else(|| format!("texture `{key}` must be a string"))
        };
        match key.as_str() {
            "file" => file = Some(text()?.to_string()),
            "filter" => {
                options.filter = match text()? {
                    "bilinear" => Filter::Bilinear,
                    "nearest" => Filter::Nearest,
                    f => return Err(format!("texture filter \"{f}\" is not bilinear or nearest")),
                }
            }
            "wrap" => {
                options.wrap = match text()? {
                    "repeat" => Wrap::Repeat,
                    "mirror" => Wrap::Mirror,
                    "clamp" => Wrap::Clamp,
                    w => {
                        return Err(format!(
                            "texture wrap \"{w}\" is not repeat, mirror or clamp"
                        ))
                    }
                }
            }
            "raw" => {
                options.raw = value
                    .as_bool()
                    .ok_or_else(|| "texture `raw` must be true or false".to_string())?
            }
            other => {
                return Err(format!(
                    "unknown texture key `{other}` (the keys are file, filter, wrap, raw)"
                ))
            }
        }
    }
    let file = file.ok_or_else(|| "a texture table needs a `file`".to_string())?;
    Ok((file, options))
}

/// The bump or normal map of a material table.
pub(crate) fn perturbation(ctx: &mut Ctx, d: &MaterialDesc) -> Result<Option<NormalPerturbation>> {
    let name = d.name.get_ref();
    let err = |ctx: &Ctx, span: Range<usize>, msg: &str| {
        ctx.src
            .error_at(span, format!("material \"{name}\": {msg}"))
    };
    match (&d.bump_map, &d.normal_map, &d.bump_scale) {
        (Some(_), Some(n), _) => Err(err(
            ctx,
            n.span(),
            "`bump_map` and `normal_map` exclude each other",
        )),
        (None, _, Some(s)) => Err(err(ctx, s.span(), "`bump_scale` needs a `bump_map`")),
        (Some(b), None, scale) => {
            let scale = match scale {
                Some(s) if !s.get_ref().is_finite() => {
                    return Err(err(ctx, s.span(), "`bump_scale` must be a finite number"))
                }
                Some(s) => *s.get_ref(),
                None => 1.0,
            };
            let texture = load(ctx, name, b, false)?;
            Ok(Some(NormalPerturbation::Bump { texture, scale }))
        }
        (None, Some(n), None) => {
            let texture = load(ctx, name, n, true)?;
            Ok(Some(NormalPerturbation::NormalMap { texture }))
        }
        (None, None, None) => Ok(None),
    }
}
