//! `[[material]]`: presets and layer stacks of the layered model (`rt_core::material`), and the
//! table of named materials that geometry and `[[assign]]` refer to.

use crate::desc::{LayerDesc, MaterialDesc};
use crate::error::Result;
use crate::load::{finite3, Ctx};
use crate::microfacet;
use rt_core::material::MaterialError;
use rt_core::spectral::{Dispersion, LAMBDA_D, PRESETS};
use rt_core::{Layer, Material, Rgb};
use std::collections::HashMap;
use std::ops::Range;
use toml::Spanned;

/// The material types a `type` key may name.
pub(crate) const TYPES: [&str; 7] = [
    "diffuse", "mirror", "glass", "glossy", "plastic", "metal", "layered",
];

/// Mitsuba's `blendbsdf` (`blend.rs`).
pub(crate) const BLEND: &str = "blendbsdf";

/// Colour when `color` is not given.
pub(crate) const DEFAULT_COLOR: Rgb = Rgb::splat(0.8);
/// Index of refraction when `ior` is not given.
pub(crate) const DEFAULT_IOR: f32 = 1.5;

/// Default hardness of the presets that take one.
pub(crate) fn default_hardness(kind: &str) -> Option<f32> {
    match kind {
        "glossy" => Some(0.6),
        "metal" => Some(0.85),
        "plastic" => Some(0.9),
        "glass" => Some(1.0),
        _ => None,
    }
}

/// Named materials in index order, with which of them something uses.
#[derive(Default)]
pub(crate) struct MaterialTable {
    list: Vec<Material>,
    by_name: HashMap<String, u32>,
    used: Vec<bool>,
}

impl MaterialTable {
    /// Adds `m` under its name; `None` if the name is taken.
    pub fn insert(&mut self, m: Material) -> Option<u32> {
        if self.by_name.contains_key(&m.name) {
            return None;
        }
        let id = self.list.len() as u32;
        self.by_name.insert(m.name.clone(), id);
        self.list.push(m);
        self.used.push(false);
        Some(id)
    }

    /// Index of the material called `name`, marking it used.
    pub fn lookup(&mut self, name: &str) -> Option<u32> {
        let id = *self.by_name.get(name)?;
        self.used[id as usize] = true;
        Some(id)
    }

    /// Material `id`.
    pub fn get(&self, id: u32) -> &Material {
        &self.list[id as usize]
    }

    /// Index of the material called `name`, without marking it used (an animation of a
    /// material does not make it appear in the image).
    pub fn find(&self, name: &str) -> Option<u32> {
        self.by_name.get(name).copied()
    }

    /// Names of the materials nothing refers to.
    pub fn unused(&self) -> impl Iterator<Item = &str> {
        self.list
            .iter()
            .zip(&self.used)
            .filter(|(_, &u)| !u)
            .map(|(m, _)| m.name.as_str())
    }

    /// The materials, in index order.
    pub fn into_vec(self) -> Vec<Material> {
        self.list
    }
}

/// Builds the material of one `[[material]]` table and checks it with `Material::validate`;
/// a blend finds the materials it blends in `mats`.
pub(crate) fn build(
    ctx: &mut Ctx,
    d: &Spanned<MaterialDesc>,
    mats: &mut MaterialTable,
) -> Result<Material> {
    let mut m = build_bsdf(ctx, d.get_ref(), mats)?;
    m.perturbation = crate::texture_desc::perturbation(ctx, d.get_ref())?;
    if let Some(v) = &d.get_ref().opacity {
        let name = d.get_ref().name.get_ref();
        match crate::param_desc::scalar(ctx, name, "opacity", v)? {
            crate::param_desc::Param::Const(o) if !(0.0..=1.0).contains(&o) => {
                return Err(ctx.src.error_at(
                    v.span(),
                    format!("material \"{name}\": opacity must be in [0, 1], got {o}"),
                ))
            }
            crate::param_desc::Param::Const(o) => m.opacity = Some(o),
            crate::param_desc::Param::Texture(t) => m.param_textures.opacity = Some(t),
        }
    }
    Ok(m)
}

/// [`build`] without the bump or normal map.
fn build_bsdf(ctx: &mut Ctx, d: &MaterialDesc, mats: &mut MaterialTable) -> Result<Material> {
    let name = d.name.get_ref();
    let src = ctx.src;
    let err =
        |span: Range<usize>, msg: String| src.error_at(span, format!("material \"{name}\": {msg}"));
    if name.is_empty() || name.contains('/') {
        return Err(ctx.src.error_at(
            d.name.span(),
            format!(
                "material name \"{name}\" is invalid: it must be non-empty and must not contain \
                 '/' (reserved for materials loaded from mesh files)"
            ),
        ));
    }
    let kind = match (&d.kind, &d.layers) {
        (Some(k), _) => {
            let k_str = k.get_ref().as_str();
            if !TYPES.contains(&k_str) && !microfacet::TYPES.contains(&k_str) && k_str != BLEND {
                return Err(err(
                    k.span(),
                    format!(
                        "unknown material type \"{}\"; valid types are {}, {}, {BLEND}",
                        k.get_ref(),
                        TYPES.join(", "),
                        microfacet::TYPES.join(", ")
                    ),
                ));
            }
            k_str
        }
        (None, Some(_)) => "layered",
        (None, None) => "diffuse",
    };
    if kind == BLEND {
        return crate::blend::build(ctx, d, mats);
    }
    let blend_keys = [
        ("weight", d.weight.as_ref().map(|v| v.span())),
        ("bsdfs", d.bsdfs.as_ref().map(|v| v.span())),
    ];
    if let Some((key, Some(span))) = blend_keys.into_iter().find(|(_, s)| s.is_some()) {
        return Err(err(
            span,
            format!("`{key}` does not apply to type \"{kind}\" (it applies to {BLEND})"),
        ));
    }
    if microfacet::TYPES.contains(&kind) {
        return microfacet::build(ctx, d, kind);
    }
    if let Some((key, span)) = microfacet::stray_key(d) {
        return Err(err(
            span,
            format!(
                "`{key}` does not apply to type \"{kind}\" (it applies to {})",
                microfacet::TYPES.join(", ")
            ),
        ));
    }
    if let (Some(l), true) = (&d.layers, kind != "layered") {
        return Err(err(
            l.span(),
            format!("`layers` cannot be combined with type \"{kind}\"; omit `type` or set it to \"layered\""),
        ));
    }
    if kind == "layered" && d.layers.is_none() {
        let span = d.kind.as_ref().map_or(d.name.span(), |k| k.span());
        return Err(err(span, "type \"layered\" needs `layers`".into()));
    }
    // Keys that the chosen type does not use are errors, like unknown keys: they would be
    // silently ignored otherwise.
    let takes_hardness = default_hardness(kind).is_some();
    let takes_ior = matches!(kind, "glass" | "plastic");
    if let (Some(h), false) = (&d.hardness, takes_hardness) {
        return Err(err(
            h.span(),
            format!("`hardness` does not apply to type \"{kind}\" (it applies to glossy, metal, plastic and glass{})",
                if kind == "layered" { "; give it per layer" } else { "" }),
        ));
    }
    if let (Some(i), false) = (&d.ior, takes_ior) {
        return Err(err(
            i.span(),
            format!(
                "`ior` does not apply to type \"{kind}\" (it applies to glass and plastic{})",
                if kind == "layered" {
                    "; give it per layer"
                } else {
                    ""
                }
            ),
        ));
    }
    if let (Some(v), false) = (&d.dispersion, kind == "glass") {
        return Err(err(
            v.span(),
            format!(
                "`dispersion` does not apply to type \"{kind}\" (it applies to glass{})",
                if kind == "layered" {
                    "; give it per layer"
                } else {
                    ""
                }
            ),
        ));
    }
    if let (Some(v), Some(_)) = (&d.dispersion, &d.ior) {
        return Err(err(
            v.span(),
            "`ior` and `dispersion` exclude each other: a dispersive glass's index is n(λ)".into(),
        ));
    }
    let disp = match &d.dispersion {
        Some(v) => Some(dispersion(v.get_ref()).map_err(|e| err(v.span(), e))?),
        None => None,
    };
    let color = match &d.color {
        Some(c) => finite3(ctx, c, "color")?,
        None => DEFAULT_COLOR,
    };
    let hardness = d
        .hardness
        .as_ref()
        .map(|h| *h.get_ref())
        .or(default_hardness(kind))
        .unwrap_or(0.0);
    let ior = d.ior.as_ref().map_or(DEFAULT_IOR, |i| *i.get_ref());
    let mut m = match kind {
        "diffuse" => Material::diffuse(name, color),
        "mirror" => Material::mirror(name, color),
        "glass" => Material::glass(name, color, ior, hardness),
        "glossy" => Material::glossy(name, color, hardness),
        "plastic" => Material::plastic(name, color, hardness, ior),
        "metal" => Material::metal(name, color, hardness),
        _ => {
            let layers = d.layers.as_ref().expect("layered has layers");
            if layers.get_ref().is_empty() {
                return Err(err(
                    layers.span(),
                    "`layers` is empty; give at least one layer (a black diffuse material is \
                     color = [0, 0, 0])"
                        .into(),
                ));
            }
            let mut m = Material::diffuse(name, color);
            m.layers = layers
                .get_ref()
                .iter()
                .map(|l| layer(l.get_ref(), color).map_err(|e| err(l.span(), e)))
                .collect::<Result<_>>()?;
            m
        }
    };
    if let Some(disp) = disp {
        let l = &mut m.layers[0];
        l.dispersion = Some(disp);
        l.ior = disp.ior(LAMBDA_D);
    }
    if let Some(e) = &d.emission {
        m.emission = finite3(ctx, e, "emission")?;
    }
    m.two_sided = d.two_sided.unwrap_or(false);
    if let Some(t) = &d.texture {
        m.texture = Some(crate::texture_desc::load(ctx, name, t, false)?);
    }
    if let Err(e) = m.validate() {
        // Point at the value that is wrong.
        let span = match (&e, &d.layers) {
            (MaterialError::Emission(_), _) => d.emission.as_ref().map(|e| e.span()),
            (MaterialError::Layer { layer, .. }, Some(ls)) => {
                ls.get_ref().get(*layer).map(|l| l.span())
            }
            (MaterialError::Layer { what, .. }, None) => {
                if what.starts_with("color") {
                    d.color.as_ref().map(|c| c.span())
                } else if what.starts_with("hardness") {
                    d.hardness.as_ref().map(|c| c.span())
                } else if what.starts_with("ior") {
                    d.ior.as_ref().map(|c| c.span())
                } else if what.starts_with("dispersion") {
                    d.dispersion.as_ref().map(|c| c.span())
                } else {
                    None
                }
            }
            (_, Some(ls)) => Some(ls.span()),
            _ => None,
        };
        return Err(err(span.unwrap_or(d.name.span()), e.to_string()));
    }
    Ok(m)
}

/// One entry of `layers`; `color` is the material's `color` (the default layer colour).
fn layer(l: &LayerDesc, color: Rgb) -> std::result::Result<Layer, String> {
    let c = l.color.map_or(color, Rgb::from);
    let dispersion = match &l.dispersion {
        Some(v) => {
            if l.ior.is_some() {
                return Err(
                    "`ior` and `dispersion` exclude each other: a dispersive layer's index is n(λ)"
                        .into(),
                );
            }
            Some(dispersion(v)?)
        }
        None => None,
    };
    Ok(Layer {
        weight: l.weight.unwrap_or(1.0),
        color: c,
        color90: l.color90.map_or(c, Rgb::from),
        hardness: l.hardness.unwrap_or(0.0),
        transmission: l.transmission.unwrap_or(false),
        ior: dispersion.map_or(l.ior.unwrap_or(DEFAULT_IOR), |d| d.ior(LAMBDA_D)),
        coat: l.coat.unwrap_or(false),
        dispersion,
    })
}

/// The forms of `dispersion`: a preset name, `{ cauchy = [A, B] }` or `[A, B, C]`, or
/// `{ sellmeier = { b = [B1, B2, B3], c = [C1, C2, C3] } }` (λ in µm). Ranges are checked by
/// `Material::validate`.
fn dispersion(v: &toml::Value) -> std::result::Result<Dispersion, String> {
    let presets = || {
        PRESETS
            .iter()
            .map(|(n, _)| format!("\"{n}\""))
            .collect::<Vec<_>>()
            .join(", ")
    };
    let forms = "`dispersion` must be a preset name, { cauchy = [A, B] } or [A, B, C], or \
                 { sellmeier = { b = [B1, B2, B3], c = [C1, C2, C3] } }";
    let numbers =
        |v: &toml::Value, what: &str, lens: &[usize]| -> std::result::Result<Vec<f32>, String> {
            let a = v
                .as_array()
                .ok_or_else(|| format!("dispersion {what} must be an array of numbers"))?;
            let xs: Option<Vec<f32>> = a
                .iter()
                .map(|x| {
                    x.as_float()
                        .or_else(|| x.as_integer().map(|i| i as f64))
                        .map(|f| f as f32)
                })
                .collect();
            let xs = xs.ok_or_else(|| format!("dispersion {what} must be an array of numbers"))?;
            if !lens.contains(&xs.len()) {
                let n: Vec<_> = lens.iter().map(|l| l.to_string()).collect();
                return Err(format!(
                    "dispersion {what} needs {} numbers, got {}",
                    n.join(" or "),
                    xs.len()
                ));
            }
            Ok(xs)
        };
    match v {
        toml::Value::String(name) => Dispersion::preset(name).ok_or_else(|| {
            format!(
                "unknown dispersion preset \"{name}\"; the presets are {}",
                presets()
            )
        }),
        toml::Value::Table(t) if t.len() == 1 => {
            let (key, v) = t.iter().next().expect("one entry");
            match key.as_str() {
                "cauchy" => {
                    let x = numbers(v, "`cauchy`", &[2, 3])?;
                    Ok(Dispersion::Cauchy {
                        a: x[0],
                        b: x[1],
                        c: x.get(2).copied().unwrap_or(0.0),
                    })
                }
                "sellmeier" => {
                    let t = v
                        .as_table()
                        .filter(|t| t.len() == 2 && t.contains_key("b") && t.contains_key("c"))
                        .ok_or_else(|| {
                            "dispersion `sellmeier` must be { b = [B1, B2, B3], c = [C1, C2, C3] }"
                                .to_string()
                        })?;
                    let b = numbers(&t["b"], "`sellmeier.b`", &[3])?;
                    let c = numbers(&t["c"], "`sellmeier.c`", &[3])?;
                    Ok(Dispersion::Sellmeier {
                        b: [b[0], b[1], b[2]],
                        c: [c[0], c[1], c[2]],
                    })
                }
                other => Err(format!("unknown dispersion model `{other}`; {forms}")),
            }
        }
        _ => Err(forms.into()),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::desc::SceneDesc;
    use crate::error::Source;
    use crate::image_io::Textures;
    use std::path::Path;

    /// Builds the materials of `text` and returns the last, or the error message.
    fn mat(text: &str) -> std::result::Result<(Material, usize), String> {
        mat_in(Path::new("."), text).map(|(m, t)| (m, t.len()))
    }

    /// [`mat`] with texture files read from `base`; the scene's textures too.
    fn mat_in(
        base: &Path,
        text: &str,
    ) -> std::result::Result<(Material, Vec<rt_core::texture::Texture>), String> {
        let d: SceneDesc = toml::from_str(text).map_err(|e| e.to_string())?;
        let mut ctx = Ctx {
            src: Source {
                name: Path::new("m.toml"),
                text,
            },
            base,
            textures: Textures::default(),
            warnings: vec![],
        };
        let mut mats = MaterialTable::default();
        let mut m = None;
        for d in &d.material {
            let built = build(&mut ctx, d, &mut mats).map_err(|e| e.to_string())?;
            m = Some(built.clone());
            mats.insert(built);
        }
        let m = m.expect("a material");
        Ok((m, ctx.textures.into_vec()))
    }

    fn ok(body: &str) -> Material {
        mat(&format!("[[material]]\nname = \"m\"\n{body}"))
            .unwrap()
            .0
    }

    fn bad(body: &str) -> String {
        mat(&format!("[[material]]\nname = \"m\"\n{body}")).unwrap_err()
    }

    #[test]
    fn type_selects_the_preset_with_its_default_hardness() {
        let c = Rgb::new(0.2, 0.4, 0.6);
        let col = "color = [0.2, 0.4, 0.6]";
        assert_eq!(ok(""), Material::diffuse("m", DEFAULT_COLOR));
        assert_eq!(
            ok(&format!("type = \"diffuse\"\n{col}")),
            Material::diffuse("m", c)
        );
        assert_eq!(
            ok(&format!("type = \"mirror\"\n{col}")),
            Material::mirror("m", c)
        );
        assert_eq!(
            ok(&format!("type = \"glass\"\n{col}")),
            Material::glass("m", c, 1.5, 1.0)
        );
        assert_eq!(
            ok(&format!("type = \"glossy\"\n{col}")),
            Material::glossy("m", c, 0.6)
        );
        assert_eq!(
            ok(&format!("type = \"metal\"\n{col}")),
            Material::metal("m", c, 0.85)
        );
        assert_eq!(
            ok(&format!("type = \"plastic\"\n{col}")),
            Material::plastic("m", c, 0.9, 1.5)
        );
    }

    #[test]
    fn hardness_and_ior_apply_where_they_mean_something() {
        assert_eq!(
            ok("type = \"glass\"\nhardness = 0.7\nior = 1.33"),
            Material::glass("m", DEFAULT_COLOR, 1.33, 0.7)
        );
        assert_eq!(
            ok("type = \"plastic\"\nhardness = 0.5\nior = 1.4"),
            Material::plastic("m", DEFAULT_COLOR, 0.5, 1.4)
        );
        assert_eq!(
            ok("type = \"glossy\"\nhardness = 0.3").layers[0].hardness,
            0.3
        );
        assert_eq!(
            ok("type = \"metal\"\nhardness = 0.3").layers[0].hardness,
            0.3
        );
        let e = bad("type = \"diffuse\"\nhardness = 0.5");
        assert!(
            e.contains(
                "m.toml:4:12: material \"m\": `hardness` does not apply to type \"diffuse\""
            ),
            "{e}"
        );
        let e = bad("type = \"metal\"\nior = 1.5");
        assert!(e.contains("`ior` does not apply to type \"metal\""), "{e}");
        let e = bad("type = \"glossy\"\nhardness = 1.5");
        assert!(
            e.contains("m.toml:4:12: material \"m\": layer 0: hardness must be in [0, 1]"),
            "{e}"
        );
        let e = bad("type = \"glass\"\nior = -1");
        assert!(
            e.contains("m.toml:4:7:") && e.contains("ior must be a positive number"),
            "{e}"
        );
    }

    #[test]
    fn unknown_type_lists_the_valid_ones() {
        let e = bad("type = \"velvet\"");
        assert!(
            e.starts_with("m.toml:3:8: material \"m\": unknown material type \"velvet\""),
            "{e}"
        );
        assert!(
            e.contains("diffuse, mirror, glass, glossy, plastic, metal, layered"),
            "{e}"
        );
    }

    #[test]
    fn color_emission_and_two_sided() {
        let m = ok("color = [0.1, 0.2, 0.3]\nemission = [17, 12, 4]\ntwo_sided = true");
        assert_eq!(m.layers[0].color, Rgb::new(0.1, 0.2, 0.3));
        assert_eq!(m.emission, Rgb::new(17.0, 12.0, 4.0));
        assert!(m.two_sided && m.is_emissive());
        assert!(!ok("").two_sided);
        assert_eq!(ok("").emission, Rgb::ZERO);
        let e = bad("color = [1.5, 0, 0]");
        assert!(
            e.contains("m.toml:3:9:") && e.contains("color must be in [0, 1]"),
            "{e}"
        );
        let e = bad("color = [nan, 0, 0]");
        assert!(
            e.contains("m.toml:3:9:") && e.contains("color must be finite"),
            "{e}"
        );
        let e = bad("emission = [1, -1, 0]");
        assert!(
            e.contains("m.toml:3:12:") && e.contains("emission must be finite, non-negative"),
            "{e}"
        );
        let e = bad("emission = [1e30, 1, 0]");
        assert!(
            e.contains("m.toml:3:12:") && e.contains("at most 1e15"),
            "{e}"
        );
        let e = bad("emission = [inf, 1, 0]");
        assert!(
            e.contains("m.toml:3:12:") && e.contains("emission must be finite"),
            "{e}"
        );
    }

    #[test]
    fn layers_build_a_custom_stack_with_defaults() {
        let m = ok("color = [0.5, 0.5, 0.5]\nlayers = [\n  { weight = 0.3, color = [1, 1, 1], hardness = 0.8, coat = true, ior = 1.6 },\n  { weight = 0.7 },\n  { weight = 0.3, color = [0.9, 0.9, 0.9], color90 = [1, 1, 1], transmission = true, hardness = 1 },\n]");
        assert_eq!(m.layers.len(), 3);
        assert_eq!(
            m.layers[0],
            Layer {
                weight: 0.3,
                color: Rgb::ONE,
                color90: Rgb::ONE,
                hardness: 0.8,
                transmission: false,
                ior: 1.6,
                coat: true,
                dispersion: None,
            }
        );
        assert_eq!(m.layers[1], Layer::new(0.7, Rgb::splat(0.5), 0.0));
        assert_eq!(m.layers[2].color90, Rgb::ONE);
        assert!(m.layers[2].transmission && m.layers[2].ior == 1.5);
        // Explicit "layered" type is the same thing.
        let m2 = ok("type = \"layered\"\nlayers = [{ weight = 1 }]");
        assert_eq!(m2.layers, vec![Layer::new(1.0, DEFAULT_COLOR, 0.0)]);
        let e = bad("layers = [{ weight = 0.7 }, { weight = 0.7, hardness = 0.5 }]");
        assert!(
            e.contains("m.toml:3:10:") && e.contains("sum to 1.4"),
            "{e}"
        );
        let e = bad("layers = [{ weight = 0.5 }, { hardness = 2 }]");
        assert!(
            e.contains("m.toml:3:29:") && e.contains("layer 1: hardness"),
            "{e}"
        );
        let e = bad("type = \"glossy\"\nlayers = [{ weight = 1 }]");
        assert!(e.contains("cannot be combined with type \"glossy\""), "{e}");
        let e = bad("layers = []");
        assert!(e.contains("`layers` is empty"), "{e}");
        let e = bad("type = \"layered\"");
        assert!(e.contains("needs `layers`") || e.contains("layers"), "{e}");
        let e = bad("layers = [{ weight = 1 }]\nhardness = 0.5");
        assert!(e.contains("give it per layer"), "{e}");
    }

    #[test]
    fn dispersion_presets_tables_and_errors() {
        let bk7 = Dispersion::preset("bk7").unwrap();
        let m = ok("type = \"glass\"\ndispersion = \"BK7\"");
        assert_eq!(m.layers[0].dispersion, Some(bk7));
        assert!((m.layers[0].ior - 1.5168).abs() < 1e-4, "ior holds n_d");
        let m = ok("type = \"glass\"\ndispersion = { cauchy = [1.5046, 0.0042] }");
        assert_eq!(
            m.layers[0].dispersion,
            Some(Dispersion::Cauchy {
                a: 1.5046,
                b: 0.0042,
                c: 0.0
            })
        );
        let m = ok("type = \"glass\"\ndispersion = { sellmeier = { b = [1.03961212, 0.231792344, 1.01046945], c = [0.00600069867, 0.0200179144, 103.560653] } }");
        assert_eq!(m.layers[0].dispersion, Some(bk7));
        let m = ok("layers = [{ transmission = true, hardness = 1, dispersion = \"sf11\" }]");
        assert_eq!(m.layers[0].dispersion, Dispersion::preset("sf11"));
        let e = bad("type = \"glass\"\ndispersion = \"crown\"");
        assert!(
            e.contains("m.toml:4:14: material \"m\": unknown dispersion preset \"crown\"; the presets are \"bk7\", \"sf11\", \"fused-silica\""),
            "{e}"
        );
        let e = bad("type = \"glass\"\ndispersion = { sellmeier = { b = [1, 0.2, 1], c = [0.006, 0.25, 100] } }");
        assert!(
            e.contains("m.toml:4:14: material \"m\": layer 0: dispersion: Sellmeier c = 0.25")
                && e.contains("500 nm"),
            "{e}"
        );
        let e = bad("type = \"glass\"\ndispersion = { cauchy = [1.5] }");
        assert!(e.contains("`cauchy` needs 2 or 3 numbers, got 1"), "{e}");
        let e = bad("type = \"glass\"\ndispersion = { abbe = 60 }");
        assert!(e.contains("unknown dispersion model `abbe`"), "{e}");
        let e = bad("type = \"glass\"\nior = 1.6\ndispersion = \"bk7\"");
        assert!(
            e.contains("`ior` and `dispersion` exclude each other"),
            "{e}"
        );
        let e = bad("type = \"glass\"\nhardness = 0.5\ndispersion = \"bk7\"");
        assert!(e.contains("smooth transmitting layers only"), "{e}");
        let e = bad("type = \"mirror\"\ndispersion = \"bk7\"");
        assert!(
            e.contains("`dispersion` does not apply to type \"mirror\""),
            "{e}"
        );
        let e = bad("layers = [{ dispersion = \"bk7\" }]");
        assert!(
            e.contains("m.toml:3:11:") && e.contains("smooth transmitting layers only"),
            "{e}"
        );
        let e = bad("layers = [{ transmission = true, hardness = 1, dispersion = { cauchy = [0.9, 0.01] } }]");
        assert!(
            e.contains("m.toml:3:11:")
                && e.contains("dispersion: index of refraction must be in (1, 4]"),
            "{e}"
        );
    }

    #[test]
    fn names_are_checked() {
        let e = mat("[[material]]\nname = \"a/b\"").unwrap_err();
        assert!(e.contains("must not contain '/'"), "{e}");
        let e = mat("[[material]]\nname = \"\"").unwrap_err();
        assert!(e.contains("must be non-empty"), "{e}");
    }

    #[test]
    fn texture_is_loaded_relative_to_the_scene_and_missing_ones_are_errors() {
        let dir = tempfile::tempdir().unwrap();
        image::RgbImage::from_pixel(2, 2, image::Rgb([255, 128, 0]))
            .save(dir.path().join("t.png"))
            .unwrap();
        let text = "[[material]]\nname = \"m\"\ntexture = \"t.png\"";
        let d: SceneDesc = toml::from_str(text).unwrap();
        let mut ctx = Ctx {
            src: Source {
                name: Path::new("m.toml"),
                text,
            },
            base: dir.path(),
            textures: Textures::default(),
            warnings: vec![],
        };
        let m = build(&mut ctx, &d.material[0], &mut MaterialTable::default()).unwrap();
        assert_eq!(m.texture, Some(0));
        let t = ctx.textures.into_vec();
        assert_eq!(
            t[0].texels[0],
            Rgb::new(1.0, rt_core::color::srgb_to_linear(128.0 / 255.0), 0.0)
        );
        let e = bad("texture = \"nope.png\"");
        assert!(e.contains("nope.png: cannot open"), "{e}");
    }

    /// Texture tables carry Mitsuba's bitmap options; `bump_map` and `normal_map` bend the
    /// normal of any type (a normal map reads raw data unless told otherwise); each mistake is
    /// one line naming the key.
    #[test]
    fn texture_options_and_bump_and_normal_maps() {
        use rt_core::bump::NormalPerturbation;
        use rt_core::texture::{Filter, Wrap};
        let dir = tempfile::tempdir().unwrap();
        image::RgbImage::from_pixel(2, 2, image::Rgb([128, 128, 255]))
            .save(dir.path().join("t.png"))
            .unwrap();
        let load = |body: &str| mat_in(dir.path(), &format!("[[material]]\nname = \"m\"\n{body}"));
        let (m, t) = load(
            "texture = { file = \"t.png\", filter = \"nearest\", wrap = \"clamp\" }\n\
             bump_map = \"t.png\"\nbump_scale = 0.5",
        )
        .unwrap();
        assert_eq!(m.texture, Some(0));
        assert_eq!((t[0].filter, t[0].wrap), (Filter::Nearest, Wrap::Clamp));
        // The same file with other options is another texture.
        assert_eq!(
            m.perturbation,
            Some(NormalPerturbation::Bump {
                texture: 1,
                scale: 0.5
            })
        );
        let srgb = rt_core::color::srgb_to_linear(128.0 / 255.0);
        assert_eq!(t[1].texels[0].x, srgb);
        let (m, t) = load("type = \"roughplastic\"\nnormal_map = \"t.png\"").unwrap();
        assert_eq!(
            m.perturbation,
            Some(NormalPerturbation::NormalMap { texture: 0 })
        );
        assert_eq!(t[0].texels[0].x, 128.0 / 255.0, "raw by default");
        let (_, t) = load("normal_map = { file = \"t.png\", raw = false }").unwrap();
        assert_eq!(t[0].texels[0].x, srgb);
        for (body, want) in [
            (
                "texture = { file = \"t.png\", wrap = \"border\" }",
                "material \"m\": texture wrap \"border\" is not repeat, mirror or clamp",
            ),
            (
                "texture = { file = \"t.png\", filtr = \"nearest\" }",
                "unknown texture key `filtr` (the keys are file, filter, wrap, raw)",
            ),
            (
                "texture = { wrap = \"clamp\" }",
                "a texture table needs a `file`",
            ),
            ("texture = 3", "a texture is a file name or a table"),
            ("bump_scale = 2.0", "`bump_scale` needs a `bump_map`"),
            (
                "bump_map = \"t.png\"\nnormal_map = \"t.png\"",
                "`bump_map` and `normal_map` exclude each other",
            ),
            ("bump_map = \"nope.png\"", "nope.png: cannot open"),
        ] {
            let e = load(body).unwrap_err();
            assert!(e.contains(want), "{body}: got {e}, want {want}");
        }
    }

    #[test]
    fn microfacet_types_take_mitsubas_parameters_and_defaults() {
        use rt_core::microfacet::{DistributionKind, Microfacet};
        let m = ok("type = \"roughconductor\"");
        let Some(Microfacet::Conductor(c)) = m.microfacet else {
            panic!("{m:?}")
        };
        let d = c.distribution.expect("rough");
        assert_eq!(
            (d.kind, d.alpha_x, d.alpha_y),
            (DistributionKind::Beckmann, 0.1, 0.1)
        );
        assert_eq!((c.eta, c.k), (Rgb::ZERO, Rgb::ONE));
        assert!(m.layers.is_empty());
        let m = ok("type = \"roughdielectric\"\ndistribution = \"ggx\"\nalpha_u = 0.1\nalpha_v = 0.3\nint_ior = 1.33\next_ior = 1.0");
        let Some(Microfacet::Dielectric(g)) = m.microfacet else {
            panic!("{m:?}")
        };
        let d = g.distribution.expect("rough");
        assert_eq!(
            (d.kind, d.alpha_x, d.alpha_y, g.eta),
            (DistributionKind::Ggx, 0.1, 0.3, 1.33)
        );
        assert!(ok("type = \"dielectric\"")
            .microfacet
            .is_some_and(|m| m.distribution().is_none()));
        // Named metals and indices are Mitsuba's (tools/reference/mitsuba_named_iors.py).
        let Some(Microfacet::Conductor(au)) =
            ok("type = \"conductor\"\nmaterial = \"Au\"").microfacet
        else {
            panic!()
        };
        assert!(
            (au.eta.x - 0.143).abs() < 1e-3 && (au.k.x - 3.983).abs() < 1e-3,
            "{au:?}"
        );
        let Some(Microfacet::Dielectric(w)) =
            ok("type = \"dielectric\"\nint_ior = \"water\"\next_ior = \"vacuum\"").microfacet
        else {
            panic!()
        };
        assert_eq!(w.eta, 1.333);
        let Some(Microfacet::Plastic(p)) = ok("type = \"smoothplastic\"").microfacet else {
            panic!()
        };
        assert_eq!(
            (p.diffuse, p.specular, p.nonlinear),
            (Rgb::splat(0.5), Rgb::ONE, false)
        );
        assert!((p.eta - 1.49 / 1.000277).abs() < 1e-6);
        let Some(Microfacet::ThinDielectric(t)) = ok("type = \"thindielectric\"").microfacet else {
            panic!()
        };
        assert!((t.eta - 1.5046 / 1.000277).abs() < 1e-6);
        assert!(bad("type = \"thindielectric\"\nalpha = 0.1").contains("`alpha` does not apply"));
        let Some(Microfacet::RoughPlastic(r)) =
            ok("type = \"roughplastic\"\ndistribution = \"ggx\"\nalpha = 0.3\ndiffuse_reflectance = [0.2, 0.3, 0.4]\nnonlinear = true").microfacet
        else {
            panic!()
        };
        assert_eq!(
            (r.distribution.alpha_x, r.diffuse, r.nonlinear),
            (0.3, Rgb::new(0.2, 0.3, 0.4), true)
        );
        assert!((r.eta - 1.49 / 1.000277).abs() < 1e-6);
    }

    #[test]
    fn microfacet_keys_are_checked() {
        for (body, says) in [
            (
                "type = \"conductor\"\nalpha = 0.2",
                "`alpha` does not apply to type \"conductor\"",
            ),
            (
                "type = \"roughconductor\"\nint_ior = 1.5",
                "`int_ior` does not apply",
            ),
            (
                "type = \"roughdielectric\"\neta = [1, 1, 1]",
                "`eta` does not apply",
            ),
            (
                "type = \"conductor\"\nk = [-1, 0, 0]",
                "`k` must not be negative",
            ),
            (
                "type = \"conductor\"\neta = { type = \"checkerboard\", color0 = -1 }",
                "checkerboard `color0` must be a non-negative number or [r, g, b]",
            ),
            (
                "type = \"roughdielectric\"\neta = { type = \"checkerboard\" }",
                "`eta` does not apply",
            ),
            (
                "type = \"roughconductor\"\ncolor = [1, 1, 1]",
                "use specular_reflectance",
            ),
            (
                "type = \"roughconductor\"\ndistribution = \"phong\"",
                "unknown distribution \"phong\"",
            ),
            (
                "type = \"roughconductor\"\nalpha = 0.1\nalpha_u = 0.2\nalpha_v = 0.2",
                "not both",
            ),
            ("type = \"roughconductor\"\nalpha_u = 0.2", "needs both"),
            ("type = \"roughconductor\"\nalpha = -1", "positive"),
            (
                "type = \"dielectric\"\nint_ior = 1.0\next_ior = 1.0",
                "other than 1",
            ),
            (
                "type = \"conductor\"\nspecular_reflectance = [2, 1, 1]",
                "specular_reflectance must be in [0, 1]",
            ),
            (
                "type = \"diffuse\"\nalpha = 0.2",
                "`alpha` does not apply to type \"diffuse\"",
            ),
            (
                "type = \"smoothplastic\"\nalpha = 0.1",
                "`alpha` does not apply to type \"smoothplastic\"",
            ),
            (
                "type = \"roughplastic\"\nalpha_u = 0.1\nalpha_v = 0.3",
                "roughplastic is isotropic",
            ),
            (
                "type = \"roughconductor\"\ntexture = \"t.png\"",
                "a texture multiplies the plastics' diffuse_reflectance only",
            ),
            (
                "type = \"roughconductor\"\ndiffuse_reflectance = [1, 1, 1]",
                "`diffuse_reflectance` does not apply",
            ),
            (
                "type = \"conductor\"\nmaterial = \"Xx\"",
                "unknown conductor \"Xx\"; Mitsuba's named conductors are a-C, Ag",
            ),
            (
                "type = \"conductor\"\nmaterial = \"Au\"\nk = [1, 1, 1]",
                "not both",
            ),
            (
                "type = \"dielectric\"\nint_ior = \"glas\"",
                "unknown index of refraction \"glas\"",
            ),
        ] {
            let e = bad(body);
            assert!(e.contains(says), "{body}: {e}");
            assert!(e.contains("m.toml"), "{e}");
        }
    }

    const PARTS: &str =
        "[[material]]\nname = \"gold\"\ntype = \"roughconductor\"\nmaterial = \"Au\"\n\
                         [[material]]\nname = \"base\"\ncolor = [0.2, 0.4, 0.6]\n";

    fn blend(body: &str) -> std::result::Result<Material, String> {
        mat(&format!(
            "{PARTS}[[material]]\nname = \"m\"\ntype = \"blendbsdf\"\n{body}"
        ))
        .map(|(m, _)| m)
    }

    #[test]
    fn a_blend_names_two_materials_defined_before_it() {
        use rt_core::microfacet::{Diffuse, Microfacet};
        let m = blend("weight = 0.25\nbsdfs = [\"gold\", \"base\"]").unwrap();
        let b = m.blend.as_ref().expect("a blend");
        assert_eq!(b.weight, 0.25);
        assert!(matches!(b.parts[0].bsdf, Microfacet::Conductor(_)));
        assert_eq!(
            b.parts[1].bsdf,
            Microfacet::Diffuse(Diffuse {
                reflectance: Rgb::new(0.2, 0.4, 0.6)
            })
        );
        let cases = [
            (
                "weight = 1.5\nbsdfs = [\"gold\", \"base\"]",
                "m.toml:11:10: material \"m\": blendbsdf weight must be in [0, 1], got 1.5",
            ),
            (
                "weight = -0.1\nbsdfs = [\"gold\", \"base\"]",
                "blendbsdf weight must be in [0, 1], got -0.1",
            ),
            (
                "bsdfs = [\"gold\", \"base\"]",
                "type \"blendbsdf\" needs `weight`",
            ),
            (
                "weight = 0.5\nbsdfs = [\"gold\"]",
                "`bsdfs` names 1 materials; a blend takes two",
            ),
            (
                "weight = 0.5\nbsdfs = [\"gold\", \"later\"]",
                "no material \"later\" is defined before this one",
            ),
            (
                "weight = 0.5\nbsdfs = [\"gold\", \"base\"]\nalpha = 0.2",
                "`alpha` does not apply to type \"blendbsdf\"",
            ),
        ];
        for (body, want) in cases {
            let e = blend(body).unwrap_err();
            assert!(e.contains(want), "{body}: {e}");
            assert_eq!(e.lines().count(), 1, "{e}");
        }
        // What cannot be blended: a layered material, a blend, an emitter.
        let e = mat(&format!(
            "{PARTS}[[material]]\nname = \"g\"\ntype = \"glossy\"\n\
             [[material]]\nname = \"m\"\ntype = \"blendbsdf\"\nweight = 0.5\nbsdfs = [\"gold\", \"g\"]"
        ))
        .unwrap_err();
        assert!(e.contains("\"g\" is a layered material"), "{e}");
        let e = mat(&format!(
            "{PARTS}[[material]]\nname = \"b\"\ntype = \"blendbsdf\"\nweight = 0.5\nbsdfs = [\"gold\", \"base\"]\n\
             [[material]]\nname = \"m\"\ntype = \"blendbsdf\"\nweight = 0.5\nbsdfs = [\"gold\", \"b\"]"
        ))
        .unwrap_err();
        assert!(e.contains("a blend inside a blend is not supported"), "{e}");
        // The blend's keys on another type.
        let e = bad("type = \"diffuse\"\nweight = 0.5");
        assert!(
            e.contains("`weight` does not apply to type \"diffuse\" (it applies to blendbsdf)"),
            "{e}"
        );
    }
}
