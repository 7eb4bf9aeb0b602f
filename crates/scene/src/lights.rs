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

#[cfg(test)]
mod tests {
    use crate::load::tests::{err, line_of, ok};
    use glam::Vec3;
    use rt_core::delta_light::DeltaLight;

    fn light(toml: &str) -> DeltaLight {
        let s = ok(&format!("[[light]]\n{toml}"));
        assert_eq!(s.scene.delta_lights.len(), 1);
        s.scene.delta_lights[0]
    }

    #[test]
    fn each_kind_with_its_keys_and_defaults() {
        let p = light("type = \"point\"\nposition = [1, 2, 3]\nintensity = [4, 5, 6]");
        assert_eq!(
            p,
            DeltaLight::Point {
                position: Vec3::new(1.0, 2.0, 3.0),
                intensity: Vec3::new(4.0, 5.0, 6.0)
            }
        );
        // Intensity defaults to 1; the spot's angles to Mitsuba's 20° and ¾ of the cutoff.
        let DeltaLight::Spot {
            axis,
            intensity,
            cutoff,
            beam_width,
            ..
        } = light("type = \"spot\"\nposition = [0, 0, 0]\ndirection = [0, -2, 0]")
        else {
            panic!("not a spot")
        };
        assert_eq!((axis, intensity), (Vec3::NEG_Y, Vec3::ONE));
        assert_eq!(
            (cutoff, beam_width),
            (20f32.to_radians(), 15f32.to_radians())
        );
        let DeltaLight::Spot { beam_width, .. } = light(
            "type = \"spot\"\nposition = [0, 0, 0]\ndirection = [0, -1, 0]\ncutoff_angle = 40",
        ) else {
            panic!("not a spot")
        };
        assert_eq!(beam_width, 30f32.to_radians());
        let d = light("type = \"directional\"\ndirection = [0, 0, 3]\nirradiance = [1, 2, 3]");
        assert_eq!(
            d,
            DeltaLight::Directional {
                direction: Vec3::Z,
                irradiance: Vec3::new(1.0, 2.0, 3.0)
            }
        );
        // Two lights, in file order, and the scene counts them as light sources.
        let s = ok("[[light]]\ntype = \"point\"\nposition = [0, 1, 0]\n[[light]]\ntype = \"directional\"\ndirection = [0, -1, 0]");
        assert_eq!(s.scene.delta_lights.len(), 2);
        assert!(s.scene.has_light_sources());
    }

    #[test]
    fn bad_lights_are_one_line_at_the_value() {
        let cases = [
            ("type = \"area\"", "type", "light type \"area\" is unknown"),
            (
                "type = \"point\"\nposition = [0, 1, 0]\nirradiance = [1, 1, 1]",
                "irradiance",
                "a point light has no `irradiance`",
            ),
            (
                "type = \"directional\"\nposition = [0, 1, 0]\ndirection = [0, -1, 0]",
                "position",
                "a directional light has no `position`",
            ),
            ("type = \"point\"", "[[light]]", "a point light needs a `position`"),
            (
                "type = \"directional\"",
                "[[light]]",
                "a directional light needs a `direction`",
            ),
            (
                "type = \"directional\"\ndirection = [0, 0, 0]",
                "direction",
                "light direction must not be zero",
            ),
            (
                "type = \"point\"\nposition = [0, nan, 0]",
                "position",
                "light position must be finite",
            ),
            (
                "type = \"point\"\nposition = [0, 1, 0]\nintensity = [1, -1, 1]",
                "intensity",
                "light intensity must be in [0, 1e15]",
            ),
            (
                "type = \"spot\"\nposition = [0, 1, 0]\ndirection = [0, -1, 0]\ncutoff_angle = 0",
                "cutoff_angle",
                "light cutoff_angle must be in (0, 180] degrees",
            ),
            (
                "type = \"spot\"\nposition = [0, 1, 0]\ndirection = [0, -1, 0]\ncutoff_angle = 30\nbeam_width = 31",
                "beam_width",
                "light beam_width must be in [0, cutoff_angle = 30] degrees",
            ),
            ("type = \"point\"\ncolor = [1, 1, 1]", "color", "unknown field `color`"),
        ];
        for (body, key, want) in cases {
            let extra = format!("[[light]]\n{body}\n");
            let e = err(&extra);
            assert!(e.contains(want), "{body}: {e}");
            // The key's line within the table (the base scene has a `position` of its own).
            let line = line_of(&extra, "[[light]]")
                + body
                    .find(&format!("{key} ="))
                    .map_or(0, |i| body[..i].matches('\n').count() + 1);
            assert!(
                e.starts_with(&format!("t.toml:{line}:")),
                "{body}: {e} (line {line})"
            );
        }
    }
}
