//! `[[light]]`: point, spot and directional lights ([`rt_core::delta_light`]), with Mitsuba's
//! parameters and defaults (docs/scene-format.md).

use crate::desc::{LightDesc, V3};
use crate::error::Result;
use crate::load::{finite3, Ctx};
use rt_core::delta_light::DeltaLight;
use rt_core::material::MAX_RADIANCE;
use toml::Spanned;

/// Mitsuba's default spot cutoff, degrees.
const DEFAULT_CUTOFF: f32 = 20.0;

/// Every `[[light]]` table.
pub(crate) fn build_all(ctx: &Ctx, descs: &[Spanned<LightDesc>]) -> Result<Vec<DeltaLight>> {
    descs.iter().map(|d| build(ctx, d)).collect()
}

fn build(ctx: &Ctx, d: &Spanned<LightDesc>) -> Result<DeltaLight> {
    let l = d.get_ref();
    let kind = l.kind.get_ref().as_str();
    // The keys each kind takes; any other given is an error, not silently ignored.
    let allowed: &[&str] = match kind {
        "point" => &["position", "intensity"],
        "spot" => &[
            "position",
            "direction",
            "intensity",
            "cutoff_angle",
            "beam_width",
        ],
        "directional" => &["direction", "irradiance"],
        other => {
            return Err(ctx.src.error_at(
                l.kind.span(),
                format!("light type \"{other}\" is unknown (point, spot or directional)"),
            ))
        }
    };
    let given = [
        ("position", l.position.as_ref().map(Spanned::span)),
        ("direction", l.direction.as_ref().map(Spanned::span)),
        ("intensity", l.intensity.as_ref().map(Spanned::span)),
        ("irradiance", l.irradiance.as_ref().map(Spanned::span)),
        ("cutoff_angle", l.cutoff_angle.as_ref().map(Spanned::span)),
        ("beam_width", l.beam_width.as_ref().map(Spanned::span)),
    ];
    for (key, span) in given {
        if let (Some(span), false) = (span, allowed.contains(&key)) {
            return Err(ctx
                .src
                .error_at(span, format!("a {kind} light has no `{key}`")));
        }
    }
    let colour = |v: &Option<Spanned<V3>>, key: &str| -> Result<rt_core::Rgb> {
        let Some(v) = v else {
            return Ok(rt_core::Rgb::ONE);
        };
        let c = finite3(ctx, v, &format!("light {key}"))?;
        if c.min_element() < 0.0 || c.max_element() > MAX_RADIANCE {
            return Err(ctx.src.error_at(
                v.span(),
                format!(
                    "light {key} must be in [0, {MAX_RADIANCE:e}], got {:?}",
                    c.to_array()
                ),
            ));
        }
        Ok(c)
    };
    let direction = || -> Result<glam::Vec3> {
        let Some(v) = &l.direction else {
            return Err(ctx
                .src
                .error_at(d.span(), format!("a {kind} light needs a `direction`")));
        };
        let dir = finite3(ctx, v, "light direction")?;
        dir.try_normalize().ok_or_else(|| {
            ctx.src
                .error_at(v.span(), "light direction must not be zero")
        })
    };
    let position = || -> Result<glam::Vec3> {
        match &l.position {
            Some(v) => finite3(ctx, v, "light position"),
            None => Err(ctx
                .src
                .error_at(d.span(), format!("a {kind} light needs a `position`"))),
        }
    };
    Ok(match kind {
        "point" => DeltaLight::Point {
            position: position()?,
            intensity: colour(&l.intensity, "intensity")?,
        },
        "spot" => {
            let cutoff = l.cutoff_angle.as_ref();
            let cutoff_deg = cutoff.map_or(DEFAULT_CUTOFF, |c| *c.get_ref());
            if !(cutoff_deg > 0.0 && cutoff_deg <= 180.0) {
                let span = cutoff.map_or(d.span(), Spanned::span);
                return Err(ctx.src.error_at(
                    span,
                    format!("light cutoff_angle must be in (0, 180] degrees, got {cutoff_deg}"),
                ));
            }
            let beam = l.beam_width.as_ref();
            let beam_deg = beam.map_or(cutoff_deg * 0.75, |b| *b.get_ref());
            if !(beam_deg >= 0.0 && beam_deg <= cutoff_deg) {
                let span = beam.map_or(d.span(), Spanned::span);
                return Err(ctx.src.error_at(
                    span,
                    format!(
                        "light beam_width must be in [0, cutoff_angle = {cutoff_deg}] degrees, got {beam_deg}"
                    ),
                ));
            }
            DeltaLight::Spot {
                position: position()?,
                axis: direction()?,
                intensity: colour(&l.intensity, "intensity")?,
                cutoff: cutoff_deg.to_radians(),
                beam_width: beam_deg.to_radians(),
            }
        }
        _ => DeltaLight::Directional {
            direction: direction()?,
            irradiance: colour(&l.irradiance, "irradiance")?,
        },
    })
}
