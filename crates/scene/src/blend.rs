//! `[[material]] type = "blendbsdf"`: Mitsuba 3's `blendbsdf` (`rt_core::microfacet::Blend`)
//! of two materials defined before it, named in `bsdfs`, with `weight` (a number in [0, 1] or
//! a texture) the weight of the second. The two must be of the microfacet family or
//! `diffuse`, without emission, opacity, bump or normal maps, and not blends themselves (a
//! blend inside a blend is not supported).

use crate::desc::MaterialDesc;
use crate::error::Result;
use crate::load::{finite3, Ctx};
use crate::material::MaterialTable;
use crate::param_desc::{self, Param};
use rt_core::microfacet::{Blend, BlendPart, Diffuse, Microfacet};
use rt_core::Material;
use std::ops::Range;

/// Builds material `d` of type `blendbsdf`, marking the two it blends used.
pub(crate) fn build(ctx: &mut Ctx, d: &MaterialDesc, mats: &mut MaterialTable) -> Result<Material> {
    let name = d.name.get_ref();
    let src = ctx.src;
    let err =
        |span: Range<usize>, msg: String| src.error_at(span, format!("material \"{name}\": {msg}"));
    let stray = [
        ("color", d.color.as_ref().map(|v| v.span())),
        ("hardness", d.hardness.as_ref().map(|v| v.span())),
        ("ior", d.ior.as_ref().map(|v| v.span())),
        ("texture", d.texture.as_ref().map(|v| v.span())),
        ("layers", d.layers.as_ref().map(|v| v.span())),
        ("dispersion", d.dispersion.as_ref().map(|v| v.span())),
    ]
    .into_iter()
    .filter_map(|(k, s)| Some((k, s?)))
    .chain(crate::microfacet::stray_key(d))
    .next();
    if let Some((key, span)) = stray {
        return Err(err(
            span,
            format!(
                "`{key}` does not apply to type \"blendbsdf\" (give it to the BSDFs it blends)"
            ),
        ));
    }
    let Some(w) = &d.weight else {
        return Err(err(
            d.name.span(),
            "type \"blendbsdf\" needs `weight`".into(),
        ));
    };
    let Some(names) = &d.bsdfs else {
        return Err(err(
            d.name.span(),
            "type \"blendbsdf\" needs `bsdfs`, the names of the two materials it blends".into(),
        ));
    };
    let [first, second] = names.get_ref().as_slice() else {
        return Err(err(
            names.span(),
            format!(
                "`bsdfs` names {} materials; a blend takes two",
                names.get_ref().len()
            ),
        ));
    };
    let mut part = |n: &toml::Spanned<String>| -> Result<BlendPart> {
        let m = mats
            .lookup(n.get_ref())
            .map(|id| mats.get(id))
            .ok_or_else(|| {
                err(
                    n.span(),
                    format!(
                        "no material \"{}\" is defined before this one (a blend's BSDFs are \
                         defined first)",
                        n.get_ref()
                    ),
                )
            })?;
        blend_part(m).map_err(|e| err(n.span(), format!("\"{}\" {e}", n.get_ref())))
    };
    let parts = [part(first)?, part(second)?];
    let mut blend = Blend::new(0.5, parts);
    match param_desc::scalar(ctx, name, "weight", w)? {
        Param::Const(x) if !(0.0..=1.0).contains(&x) => {
            return Err(err(
                w.span(),
                format!("blendbsdf weight must be in [0, 1], got {x}"),
            ))
        }
        Param::Const(x) => blend.weight = x,
        Param::Texture(t) => blend.weight_texture = Some(t),
    }
    let mut m = Material::blend(name, blend);
    if let Some(e) = &d.emission {
        m.emission = finite3(ctx, e, "emission")?;
    }
    m.two_sided = d.two_sided.unwrap_or(false);
    if let Err(e) = m.validate() {
        return Err(err(d.name.span(), e.to_string()));
    }
    Ok(m)
}

/// One of a blend's BSDFs from material `m`; the error says why `m` cannot be one.
fn blend_part(m: &Material) -> std::result::Result<BlendPart, &'static str> {
    if m.blend.is_some() {
        return Err("is a blendbsdf: a blend inside a blend is not supported");
    }
    if m.is_emissive()
        || m.opacity.is_some()
        || m.param_textures.opacity.is_some()
        || m.perturbation.is_some()
    {
        return Err(
            "has emission, opacity or a bump or normal map, which a blend's BSDFs cannot have \
             (give them to the blend)",
        );
    }
    if let Some(bsdf) = m.microfacet {
        return Ok(BlendPart {
            bsdf,
            textures: m.param_textures,
            texture: m.texture,
            alpha_tables: m.alpha_tables.clone(),
        });
    }
    match m.layers.as_slice() {
        [l] if l.weight == 1.0
            && l.hardness == 0.0
            && !l.transmission
            && !l.coat
            && l.color == l.color90 =>
        {
            let mut p = BlendPart::new(Microfacet::Diffuse(Diffuse {
                reflectance: l.color,
            }));
            p.texture = m.texture;
            Ok(p)
        }
        _ => Err("is a layered material: a blend takes the microfacet family and diffuse"),
    }
}
