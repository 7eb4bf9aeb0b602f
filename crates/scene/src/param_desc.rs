//! A parameter of the microfacet family that is a constant or a texture, as Mitsuba 3's
//! `Texture` parameters are: a number (or `[r, g, b]` for a colour) is a constant; a file name
//! or a texture table (`texture_desc.rs`) is a texture, read as a colour or, for a scalar, as
//! its luminance ([`rt_core::microfacet::ParamTextures`]).

use toml::{Spanned, Value};

use crate::error::Result;
use crate::load::Ctx;
use rt_core::Rgb;

/// A constant or the index of a texture.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) enum Param<T> {
    Const(T),
    Texture(u32),
}

impl<T: Copy> Param<T> {
    /// The constant, or `placeholder` for a texture (which replaces it at every hit).
    pub fn constant_or(self, placeholder: T) -> T {
        match self {
            Param::Const(c) => c,
            Param::Texture(_) => placeholder,
        }
    }

    /// The texture's index, if it is one.
    pub fn texture(self) -> Option<u32> {
        match self {
            Param::Const(_) => None,
            Param::Texture(t) => Some(t),
        }
    }
}

/// Key `key` of material `name`: a number or a texture.
pub(crate) fn scalar(
    ctx: &mut Ctx,
    name: &str,
    key: &str,
    v: &Spanned<Value>,
) -> Result<Param<f32>> {
    match v.get_ref() {
        Value::Float(x) => Ok(Param::Const(*x as f32)),
        Value::Integer(i) => Ok(Param::Const(*i as f32)),
        Value::String(_) | Value::Table(_) => texture(ctx, name, v),
        _ => Err(ctx.src.error_at(
            v.span(),
            format!("material \"{name}\": `{key}` must be a number or a texture"),
        )),
    }
}

/// Key `key` of material `name`: `[r, g, b]` (finite) or a texture.
pub(crate) fn colour(
    ctx: &mut Ctx,
    name: &str,
    key: &str,
    v: &Spanned<Value>,
) -> Result<Param<Rgb>> {
    let bad = |ctx: &Ctx| {
        ctx.src.error_at(
            v.span(),
            format!(
                "material \"{name}\": `{key}` must be [r, g, b] of finite numbers or a texture"
            ),
        )
    };
    match v.get_ref() {
        Value::Array(a) if a.len() == 3 => {
            let mut c = [0.0f32; 3];
            for (x, y) in c.iter_mut().zip(a) {
                *x = match y {
                    Value::Float(f) => *f as f32,
                    Value::Integer(i) => *i as f32,
                    _ => return Err(bad(ctx)),
                };
            }
            if c.iter().all(|x| x.is_finite()) {
                Ok(Param::Const(Rgb::from(c)))
            } else {
                Err(bad(ctx))
            }
        }
        Value::String(_) | Value::Table(_) => texture(ctx, name, v),
        _ => Err(bad(ctx)),
    }
}

/// A conductor's `eta` or `k` (key `key` of material `name`): `[r, g, b]` of non-negative
/// numbers, or a texture read unclamped.
pub(crate) fn index(
    ctx: &mut Ctx,
    name: &str,
    key: &str,
    v: &Spanned<Value>,
) -> Result<Param<Rgb>> {
    if matches!(v.get_ref(), Value::String(_) | Value::Table(_)) {
        return crate::texture_desc::load_unbounded(ctx, name, v).map(Param::Texture);
    }
    match colour(ctx, name, key, v)? {
        Param::Const(c) if c.min_element() < 0.0 => Err(ctx.src.error_at(
            v.span(),
            format!("material \"{name}\": `{key}` must not be negative, got {c}"),
        )),
        p => Ok(p),
    }
}

fn texture<T>(ctx: &mut Ctx, name: &str, v: &Spanned<Value>) -> Result<Param<T>> {
    crate::texture_desc::load(ctx, name, v, false).map(Param::Texture)
}
