//! `[[material]]` tables of the microfacet family (`rt_core::microfacet`): `conductor`,
//! `roughconductor`, `dielectric`, `roughdielectric`, with Mitsuba 3's parameter names and
//! defaults (a conductor without `eta`/`k` is Mitsuba's `material = "none"`, a perfect
//! mirror; distribution `beckmann`, `alpha` 0.1; `int_ior` BK7's 1.5046, `ext_ior` air's
//! 1.000277).

use crate::desc::MaterialDesc;
use crate::error::Result;
use crate::load::{finite3, Ctx};
use crate::param_desc::{self, Param};
use rt_core::microfacet::named::{CONDUCTORS, DIELECTRICS};
use rt_core::microfacet::{
    named_conductor, named_ior, AlphaTables, Distribution, DistributionKind, Microfacet,
    ParamTextures, Plastic, RoughConductor, RoughDielectric, RoughPlastic, ThinDielectric,
};
use rt_core::{Material, Rgb};
use std::ops::Range;

/// The material types of the family. `smoothplastic` is Mitsuba's `plastic`: our `plastic`
/// names the thesis' layered preset.
pub(crate) const TYPES: [&str; 7] = [
    "conductor",
    "roughconductor",
    "dielectric",
    "roughdielectric",
    "thindielectric",
    "smoothplastic",
    "roughplastic",
];

const DEFAULT_ALPHA: f32 = 0.1;
const BK7_IOR: f32 = 1.5046;
const AIR_IOR: f32 = 1.000277;
const POLYPROPYLENE_IOR: f32 = 1.49;

/// The family's keys present in `d`, with their spans.
fn keys(d: &MaterialDesc) -> Vec<(&'static str, Range<usize>)> {
    let mut out = Vec::new();
    macro_rules! key {
        ($($f:ident),*) => {$(
            if let Some(v) = &d.$f {
                out.push((stringify!($f), v.span()));
            }
        )*};
    }
    key!(
        distribution,
        alpha,
        alpha_u,
        alpha_v,
        eta,
        k,
        int_ior,
        ext_ior,
        specular_reflectance,
        specular_transmittance,
        diffuse_reflectance,
        nonlinear
    );
    out
}

/// The first key of the family in a table of another type, for its error.
pub(crate) fn stray_key(d: &MaterialDesc) -> Option<(&'static str, Range<usize>)> {
    keys(d).into_iter().next()
}

/// Builds a material of type `kind` (one of [`TYPES`]).
pub(crate) fn build(ctx: &mut Ctx, d: &MaterialDesc, kind: &str) -> Result<Material> {
    let name = d.name.get_ref();
    // A copy of the source, so that loading textures (which needs `ctx`) can come between.
    let src = ctx.src;
    let err =
        |span: Range<usize>, msg: String| src.error_at(span, format!("material \"{name}\": {msg}"));
    // Keys of the layered model have no meaning here.
    let layered = [
        ("color", d.color.as_ref().map(|v| v.span())),
        ("hardness", d.hardness.as_ref().map(|v| v.span())),
        ("ior", d.ior.as_ref().map(|v| v.span())),
        ("dispersion", d.dispersion.as_ref().map(|v| v.span())),
        ("layers", d.layers.as_ref().map(|v| v.span())),
        (
            "texture",
            d.texture
                .as_ref()
                .filter(|_| !kind.ends_with("plastic"))
                .map(|v| v.span()),
        ),
    ];
    for (key, span) in layered {
        if let Some(span) = span {
            let hint = match key {
                "ior" => " (use int_ior and ext_ior)",
                "color" => " (use specular_reflectance)",
                "hardness" => " (use alpha)",
                "texture" => " (a texture multiplies the plastics' diffuse_reflectance only)",
                _ => "",
            };
            return Err(err(
                span,
                format!("`{key}` does not apply to type \"{kind}\"{hint}"),
            ));
        }
    }
    let mut textures = ParamTextures::default();
    let rough = kind.starts_with("rough");
    let conductor = kind.ends_with("conductor");
    let plastic = kind == "smoothplastic" || kind == "roughplastic";
    for (key, span) in keys(d) {
        let applies = match key {
            "distribution" | "alpha" | "alpha_u" | "alpha_v" => rough,
            "eta" | "k" | "material" => conductor,
            "int_ior" | "ext_ior" => !conductor,
            "specular_transmittance" => !conductor && !plastic,
            "diffuse_reflectance" | "nonlinear" => plastic,
            _ => true,
        };
        if !applies {
            return Err(err(
                span,
                format!("`{key}` does not apply to type \"{kind}\""),
            ));
        }
    }
    let distribution = if rough {
        let kind_d = match d
            .distribution
            .as_ref()
            .map(|s| (s.get_ref().as_str(), s.span()))
        {
            None | Some(("beckmann", _)) => DistributionKind::Beckmann,
            Some(("ggx", _)) => DistributionKind::Ggx,
            Some((other, span)) => {
                return Err(err(
                    span,
                    format!("unknown distribution \"{other}\"; valid are \"beckmann\" and \"ggx\""),
                ))
            }
        };
        if let (Some(a), Some(_)) = (&d.alpha, d.alpha_u.as_ref().or(d.alpha_v.as_ref())) {
            return Err(err(
                a.span(),
                "give `alpha` or `alpha_u` and `alpha_v`, not both".into(),
            ));
        }
        if d.alpha_u.is_some() != d.alpha_v.is_some() {
            let span = d
                .alpha_u
                .as_ref()
                .or(d.alpha_v.as_ref())
                .map(|v| v.span())
                .expect("one of them");
            return Err(err(
                span,
                "an anisotropic surface needs both `alpha_u` and `alpha_v`".into(),
            ));
        }
        let (au, av) = match &d.alpha {
            Some(_) => (&d.alpha, &d.alpha),
            None => (&d.alpha_u, &d.alpha_v),
        };
        let (au, av) = (alpha(ctx, d, au)?, alpha(ctx, d, av)?);
        textures.alpha_u = au.texture();
        textures.alpha_v = av.texture();
        Some(Distribution::new(
            kind_d,
            au.constant_or(DEFAULT_ALPHA),
            av.constant_or(DEFAULT_ALPHA),
        ))
    } else {
        None
    };
    // Keys a type does not take were refused above, so reading them gives their defaults.
    let reflectance = colour(ctx, d, &d.specular_reflectance, "specular_reflectance")?;
    let transmittance = colour(ctx, d, &d.specular_transmittance, "specular_transmittance")?;
    let rgb = |v: &Option<toml::Spanned<crate::desc::V3>>, what: &str, default: Rgb| match v {
        Some(v) => finite3(ctx, v, what),
        None => Ok(default),
    };
    textures.specular_reflectance = reflectance.texture();
    textures.specular_transmittance = transmittance.texture();
    let (reflectance, transmittance) = (
        reflectance.constant_or(Rgb::ONE),
        transmittance.constant_or(Rgb::ONE),
    );
    // Interior over exterior index, with the interior's default.
    let eta = |default_int: f32| -> Result<f32> {
        let int = ior(&d.int_ior, "int_ior", default_int).map_err(|(s, e)| err(s, e))?;
        let ext = ior(&d.ext_ior, "ext_ior", AIR_IOR).map_err(|(s, e)| err(s, e))?;
        Ok(int / ext)
    };
    // Reflection from both faces (Mitsuba's `twosided`) for the reflecting types; for every
    // type it also makes an emitter emit from both.
    let two_sided = d.two_sided.unwrap_or(false);
    let mut alpha_tables = None;
    let bsdf = if conductor {
        let (eta, k) = match &d.material {
            Some(named) => {
                if let Some(v) = d.eta.as_ref().or(d.k.as_ref()) {
                    return Err(err(
                        v.span(),
                        "give `material` or `eta` and `k`, not both".into(),
                    ));
                }
                named_conductor(named.get_ref()).ok_or_else(|| {
                    let names: Vec<&str> = CONDUCTORS.iter().map(|(n, _, _)| *n).collect();
                    err(
                        named.span(),
                        format!(
                            "unknown conductor \"{}\"; Mitsuba's named conductors are {}",
                            named.get_ref(),
                            names.join(", ")
                        ),
                    )
                })?
            }
            None => {
                let (eta, k) = (
                    index(ctx, d, &d.eta, "eta", Rgb::ZERO)?,
                    index(ctx, d, &d.k, "k", Rgb::ONE)?,
                );
                textures.eta = eta.texture();
                textures.k = k.texture();
                // A texture's placeholder: a valid constant, replaced at every hit.
                (eta.constant_or(Rgb::ZERO), k.constant_or(Rgb::ONE))
            }
        };
        Microfacet::Conductor(RoughConductor {
            distribution,
            eta,
            k,
            specular_reflectance: reflectance,
            two_sided,
        })
    } else if kind == "thindielectric" {
        Microfacet::ThinDielectric(ThinDielectric {
            eta: eta(BK7_IOR)?,
            reflectance,
            transmittance,
        })
    } else if plastic {
        let diffuse = rgb(
            &d.diffuse_reflectance,
            "diffuse_reflectance",
            Rgb::splat(0.5),
        )?;
        let nonlinear = d.nonlinear.as_ref().is_some_and(|v| *v.get_ref());
        let eta = eta(POLYPROPYLENE_IOR)?;
        match distribution {
            Some(dist) => {
                if dist.alpha_x != dist.alpha_y {
                    let span = d.alpha_u.as_ref().map_or(d.name.span(), |a| a.span());
                    return Err(err(
                        span,
                        "roughplastic is isotropic: give `alpha`, not `alpha_u` and `alpha_v`"
                            .into(),
                    ));
                }
                let mut p = RoughPlastic::new(dist, diffuse, reflectance, eta, nonlinear);
                p.two_sided = two_sided;
                // A textured roughness: the coating's tables over the texture's range.
                if let Some(t) = textures.alpha_u {
                    let (lo, hi) = ctx.textures.get(t).luminance_range();
                    alpha_tables = Some(AlphaTables::new(&p, lo, hi));
                }
                Microfacet::RoughPlastic(p)
            }
            None => Microfacet::Plastic(Plastic {
                diffuse,
                specular: reflectance,
                eta,
                nonlinear,
                two_sided,
            }),
        }
    } else {
        Microfacet::Dielectric(RoughDielectric {
            distribution,
            eta: eta(BK7_IOR)?,
            reflectance,
            transmittance,
        })
    };
    let mut m = Material::microfacet(name, bsdf);
    m.param_textures = textures;
    m.alpha_tables = alpha_tables;
    if let Some(e) = &d.emission {
        m.emission = finite3(ctx, e, "emission")?;
    }
    m.two_sided = d.two_sided.unwrap_or(false);
    if let Some(t) = &d.texture {
        m.texture = Some(crate::texture_desc::load(ctx, name, t, false)?);
    }
    if let Err(e) = m.validate() {
        return Err(err(d.name.span(), e.to_string()));
    }
    Ok(m)
}

/// A roughness key: a positive number or a texture; [`DEFAULT_ALPHA`] when absent.
fn alpha(
    ctx: &mut Ctx,
    d: &MaterialDesc,
    v: &Option<toml::Spanned<toml::Value>>,
) -> Result<Param<f32>> {
    let Some(v) = v else {
        return Ok(Param::Const(DEFAULT_ALPHA));
    };
    let name = d.name.get_ref();
    match param_desc::scalar(ctx, name, "alpha", v)? {
        Param::Const(a) if !(a.is_finite() && a > 0.0) => Err(ctx.src.error_at(
            v.span(),
            format!("material \"{name}\": roughness must be a positive number, got {a}"),
        )),
        p => Ok(p),
    }
}

/// A colour key: `[r, g, b]` or a texture; white when absent.
fn colour(
    ctx: &mut Ctx,
    d: &MaterialDesc,
    v: &Option<toml::Spanned<toml::Value>>,
    key: &str,
) -> Result<Param<Rgb>> {
    match v {
        None => Ok(Param::Const(Rgb::ONE)),
        Some(v) => param_desc::colour(ctx, d.name.get_ref(), key, v),
    }
}

/// A conductor's `eta` or `k`: a colour or a texture, `default` when absent.
fn index(
    ctx: &mut Ctx,
    d: &MaterialDesc,
    v: &Option<toml::Spanned<toml::Value>>,
    key: &str,
    default: Rgb,
) -> Result<Param<Rgb>> {
    match v {
        None => Ok(Param::Const(default)),
        Some(v) => param_desc::index(ctx, d.name.get_ref(), key, v),
    }
}

/// An index of refraction: a positive number or one of Mitsuba's names; `default` when absent.
fn ior(
    v: &Option<toml::Spanned<toml::Value>>,
    key: &str,
    default: f32,
) -> std::result::Result<f32, (Range<usize>, String)> {
    let Some(v) = v else {
        return Ok(default);
    };
    let x = match v.get_ref() {
        toml::Value::Float(x) => *x as f32,
        toml::Value::Integer(i) => *i as f32,
        toml::Value::String(name) => named_ior(name).ok_or_else(|| {
            let names: Vec<&str> = DIELECTRICS.iter().map(|(n, _)| *n).collect();
            (
                v.span(),
                format!(
                    "unknown index of refraction \"{name}\" for `{key}`; Mitsuba's names are {}",
                    names.join(", ")
                ),
            )
        })?,
        _ => return Err((v.span(), format!("`{key}` must be a number or a name"))),
    };
    if !(x.is_finite() && x > 0.0) {
        return Err((
            v.span(),
            format!("`{key}` must be a positive number, got {x}"),
        ));
    }
    Ok(x)
}
