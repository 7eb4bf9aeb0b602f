//! A material's texture keys. A texture is a file name, or a table
//! `{ file = "...", filter = "bilinear" | "nearest", wrap = "repeat" | "mirror" | "clamp",
//! raw = false }` (Mitsuba's `bitmap` options; `raw` reads the values as linear data instead of
//! sRGB colours). `bump_map` (with `bump_scale`, default 1) and `normal_map` bend the shading
//! normal ([`rt_core::bump`]); a normal map is raw unless it says otherwise.

use std::ops::Range;
use std::path::PathBuf;

use rt_core::bump::NormalPerturbation;
use rt_core::texture::{Filter, Wrap};
use toml::{Spanned, Value};

use crate::desc::MaterialDesc;
use crate::error::Result;
use crate::image_io::TextureOptions;
use crate::load::Ctx;

/// Loads the texture `v` names for material `name`; `raw` is the default of its `raw` key.
pub(crate) fn load(ctx: &mut Ctx, name: &str, v: &Spanned<Value>, raw: bool) -> Result<u32> {
    let (path, options) = read(ctx, name, v, raw)?;
    ctx.textures.load(&path, options)
}

/// The file (resolved against the scene's directory) and options of texture value `v` of
/// material `name`.
pub(crate) fn read(
    ctx: &Ctx,
    name: &str,
    v: &Spanned<Value>,
    raw: bool,
) -> Result<(PathBuf, TextureOptions)> {
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
