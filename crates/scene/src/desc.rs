//! The scene file as serde sees it: one `*Desc` struct per TOML table.
//!
//! These types only describe the syntax: which keys exist and their TOML types. Every struct
//! denies unknown keys, so a misspelt key is an error that names it, with its line and column.
//! Defaults, ranges and cross references are checked when the descriptions are turned into an
//! `rt_core::Scene` (`load.rs`, `material.rs`, `geometry.rs`), which is why many values are
//! wrapped in [`Spanned`]: the checks need to point at them. `docs/scene-format.md` documents
//! every key.

use serde::de::{self, Deserializer, SeqAccess, Visitor};
use serde::Deserialize;
use std::fmt;
use toml::Spanned;

/// A 3-vector in the file.
pub(crate) type V3 = Arr<f32, 3>;

/// A TOML array of exactly `N` values. Serde's own `[T; N]` silently ignores extra elements
/// with `toml`, so `position = [1, 2, 3, 4]` would load; this type rejects it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct Arr<T, const N: usize>(pub [T; N]);

impl<T, const N: usize> std::ops::Deref for Arr<T, N> {
    type Target = [T; N];
    fn deref(&self) -> &[T; N] {
        &self.0
    }
}

impl From<Arr<f32, 3>> for glam::Vec3 {
    fn from(a: Arr<f32, 3>) -> Self {
        glam::Vec3::from(a.0)
    }
}

impl From<Arr<f32, 2>> for glam::Vec2 {
    fn from(a: Arr<f32, 2>) -> Self {
        glam::Vec2::from(a.0)
    }
}

impl<'de, T: Deserialize<'de> + Copy + Default, const N: usize> Deserialize<'de> for Arr<T, N> {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        struct V<T, const N: usize>(std::marker::PhantomData<T>);
        impl<'de, T: Deserialize<'de> + Copy + Default, const N: usize> Visitor<'de> for V<T, N> {
            type Value = Arr<T, N>;
            fn expecting(&self, f: &mut fmt::Formatter) -> fmt::Result {
                write!(f, "an array of {N} numbers")
            }
            fn visit_seq<A: SeqAccess<'de>>(self, mut seq: A) -> Result<Arr<T, N>, A::Error> {
                let mut out = [T::default(); N];
                for (i, x) in out.iter_mut().enumerate() {
                    *x = seq
                        .next_element()?
                        .ok_or_else(|| de::Error::invalid_length(i, &self))?;
                }
                let mut extra = 0;
                while seq.next_element::<de::IgnoredAny>()?.is_some() {
                    extra += 1;
                }
                if extra > 0 {
                    return Err(de::Error::invalid_length(N + extra, &self));
                }
                Ok(Arr(out))
            }
        }
        d.deserialize_seq(V::<T, N>(std::marker::PhantomData))
    }
}

/// The whole file.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub(crate) struct SceneDesc {
    /// `[environment]`.
    #[serde(default)]
    pub environment: Option<Spanned<EnvironmentDesc>>,
    /// `[[camera]]`, the first is the default.
    #[serde(default)]
    pub camera: Vec<Spanned<CameraDesc>>,
    /// `[[material]]`.
    #[serde(default)]
    pub material: Vec<Spanned<MaterialDesc>>,
    /// `[[geometry]]`.
    #[serde(default)]
    pub geometry: Vec<Spanned<GeometryDesc>>,
    /// `[[assign]]`.
    #[serde(default)]
    pub assign: Vec<Spanned<AssignDesc>>,
    /// `[[instance]]`.
    #[serde(default)]
    pub instance: Vec<Spanned<InstanceDesc>>,
    /// `[[animation]]`.
    #[serde(default)]
    pub animation: Vec<Spanned<AnimationDesc>>,
    /// `[render]`.
    #[serde(default)]
    pub render: Option<RenderTableDesc>,
    /// `[[light]]`: point, spot and directional lights.
    #[serde(default)]
    pub light: Vec<Spanned<LightDesc>>,
}

/// `[[light]]`: a light of no extent. Which keys a kind takes is checked when it is built
/// (`lights.rs`).
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub(crate) struct LightDesc {
    /// `point`, `spot` or `directional`.
    #[serde(rename = "type")]
    pub kind: Spanned<String>,
    /// Where a point or spot light is.
    pub position: Option<Spanned<V3>>,
    /// A spot's axis, or the way a directional light's light travels.
    pub direction: Option<Spanned<V3>>,
    /// A point or spot light's radiant intensity (W/sr).
    pub intensity: Option<Spanned<V3>>,
    /// A directional light's irradiance (W/m²).
    pub irradiance: Option<Spanned<V3>>,
    /// A spot's half-angle of darkness beyond, degrees.
    pub cutoff_angle: Option<Spanned<f32>>,
    /// A spot's half-angle of full intensity, degrees.
    pub beam_width: Option<Spanned<f32>>,
}

/// `[environment]`.
#[derive(Debug, Default, Deserialize)]
#[serde(deny_unknown_fields)]
pub(crate) struct EnvironmentDesc {
    /// Constant radiance; default black.
    pub color: Option<Spanned<V3>>,
    /// Equirectangular EXR, relative to the TOML file.
    pub map: Option<Spanned<String>>,
    /// Multiplies `color`, `map` or `sky`; default 1.
    pub strength: Option<Spanned<f32>>,
    /// The Preetham daylight sky with a sun.
    pub sky: Option<Spanned<SkyDesc>>,
    /// A rotation of `map` (3 rows): world directions into the map's frame.
    pub rotation: Option<Spanned<[[f32; 3]; 3]>>,
}

/// `[environment] sky = { ... }`: the sun by direction, or by date, time and place.
#[derive(Debug, Default, Deserialize)]
#[serde(deny_unknown_fields)]
pub(crate) struct SkyDesc {
    /// Towards the sun, +y up.
    pub sun_direction: Option<Spanned<V3>>,
    /// Degrees north.
    pub latitude: Option<Spanned<f64>>,
    /// Degrees east; with `hour`.
    pub longitude: Option<Spanned<f64>>,
    /// Degrees east of the time zone's meridian; with `hour`.
    pub standard_meridian: Option<Spanned<f64>>,
    /// Day of the year, 1–366.
    pub day: Option<Spanned<u32>>,
    /// Local standard (clock) time, hours.
    pub hour: Option<Spanned<f64>>,
    /// Local apparent solar time, hours (12 = solar noon).
    pub solar_time: Option<Spanned<f64>>,
    /// Default 3.
    pub turbidity: Option<Spanned<f32>>,
    /// Size of the tabulated sky; default 512 × 256.
    pub resolution: Option<Spanned<Arr<u32, 2>>>,
}

/// `[[camera]]`.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub(crate) struct CameraDesc {
    pub name: Spanned<String>,
    pub position: Spanned<V3>,
    pub look_at: Spanned<V3>,
    /// Default +y.
    pub up: Option<Spanned<V3>>,
    /// Vertical, degrees; default 40.
    pub fov: Option<Spanned<f32>>,
    /// `[width, height]`; default 512×512.
    pub resolution: Option<Spanned<Arr<u32, 2>>>,
    /// Thin-lens radius; default 0.
    pub aperture: Option<Spanned<f32>>,
    /// Default: distance from `position` to `look_at`.
    pub focus_distance: Option<Spanned<f32>>,
    /// `box` (default), `tent[:radius=R]`, `gaussian[:stddev=S]`.
    pub pixel_filter: Option<Spanned<String>>,
    /// `[x, y, width, height]`: the part of `resolution` rendered.
    pub crop: Option<Spanned<Arr<u32, 4>>>,
    /// Depth along the view axis where primary rays start; default 0.
    pub near_clip: Option<Spanned<f32>>,
    /// Depth beyond which nothing would be seen: checked to cut no geometry, not applied.
    pub far_clip: Option<Spanned<f32>>,
}

/// `[[material]]`.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub(crate) struct MaterialDesc {
    pub name: Spanned<String>,
    /// Preset name; default `diffuse`, or `layered` when `layers` is given.
    #[serde(rename = "type")]
    pub kind: Option<Spanned<String>>,
    pub color: Option<Spanned<V3>>,
    pub hardness: Option<Spanned<f32>>,
    pub ior: Option<Spanned<f32>>,
    /// A file name or a table of options (`texture_desc.rs`).
    pub texture: Option<Spanned<toml::Value>>,
    pub bump_map: Option<Spanned<toml::Value>>,
    pub bump_scale: Option<Spanned<f32>>,
    pub normal_map: Option<Spanned<toml::Value>>,
    pub emission: Option<Spanned<V3>>,
    pub two_sided: Option<bool>,
    pub layers: Option<Spanned<Vec<Spanned<LayerDesc>>>>,
    /// A preset name or an inline table; `material.rs` reads it (its forms are easier to
    /// explain in an error there than through an untagged serde enum).
    pub dispersion: Option<Spanned<toml::Value>>,
    // The microfacet family (`microfacet.rs`), with Mitsuba's parameter names.
    pub distribution: Option<Spanned<String>>,
    /// Numbers or textures (`param_desc.rs`).
    pub alpha: Option<Spanned<toml::Value>>,
    pub alpha_u: Option<Spanned<toml::Value>>,
    pub alpha_v: Option<Spanned<toml::Value>>,
    /// `[r, g, b]` or textures read unclamped (`param_desc::index`).
    pub eta: Option<Spanned<toml::Value>>,
    pub k: Option<Spanned<toml::Value>>,
    /// A number or one of Mitsuba's named indices (`"water"`, `"bk7"`, ...).
    pub int_ior: Option<Spanned<toml::Value>>,
    pub ext_ior: Option<Spanned<toml::Value>>,
    /// A conductor's named metal (`"Au"`, ...), as Mitsuba's `material`.
    pub material: Option<Spanned<String>>,
    /// Colours or textures (`param_desc.rs`).
    pub specular_reflectance: Option<Spanned<toml::Value>>,
    pub specular_transmittance: Option<Spanned<toml::Value>>,
    pub diffuse_reflectance: Option<Spanned<V3>>,
    pub nonlinear: Option<Spanned<bool>>,
    /// Mitsuba's `mask`: a number in [0, 1] or a texture (`param_desc.rs`); any type.
    pub opacity: Option<Spanned<toml::Value>>,
    /// `blendbsdf`: the weight of its second BSDF, a number in [0, 1] or a texture.
    pub weight: Option<Spanned<toml::Value>>,
    /// `blendbsdf`: the names of the two materials it blends.
    pub bsdfs: Option<Spanned<Vec<Spanned<String>>>>,
}

/// One entry of a material's `layers` array.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub(crate) struct LayerDesc {
    pub weight: Option<f32>,
    pub color: Option<V3>,
    pub color90: Option<V3>,
    pub hardness: Option<f32>,
    pub transmission: Option<bool>,
    pub ior: Option<f32>,
    pub coat: Option<bool>,
    pub dispersion: Option<toml::Value>,
}

/// `[[geometry]]`: a mesh file, an inline shape or an inline triangle mesh. Which keys are
/// allowed depends on the kind; `geometry.rs` checks that.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub(crate) struct GeometryDesc {
    pub name: Spanned<String>,
    pub material: Option<Spanned<String>>,
    pub transform: Option<Spanned<TransformDesc>>,
    // Mesh file.
    pub file: Option<Spanned<String>>,
    /// Which mesh of a Mitsuba `.serialized` file (default 0).
    pub shape_index: Option<Spanned<u32>>,
    // Inline shape.
    pub shape: Option<Spanned<String>>,
    pub vertices: Option<Spanned<Vec<V3>>>,
    pub min: Option<Spanned<V3>>,
    pub max: Option<Spanned<V3>>,
    pub center: Option<Spanned<V3>>,
    pub radius: Option<Spanned<f32>>,
    pub subdivisions: Option<Spanned<u32>>,
    pub smooth: Option<Spanned<bool>>,
    pub normal: Option<Spanned<V3>>,
    pub segments: Option<Spanned<u32>>,
    pub p0: Option<Spanned<V3>>,
    pub p1: Option<Spanned<V3>>,
    /// Any kind: reverse every triangle's winding and negate its vertex normals.
    pub flip_normals: Option<Spanned<bool>>,
    /// A mesh file or inline mesh: texture coordinates `(u, v)` become `(u, 1 - v)`.
    pub flip_v: Option<Spanned<bool>>,
    // Inline triangle mesh.
    pub positions: Option<Spanned<Vec<V3>>>,
    pub indices: Option<Spanned<Vec<Arr<u32, 3>>>>,
    pub normals: Option<Spanned<Vec<V3>>>,
    pub uvs: Option<Spanned<Vec<Arr<f32, 2>>>>,
}

/// `transform = { translate, rotate, scale }`.
#[derive(Debug, Default, Deserialize)]
#[serde(deny_unknown_fields)]
pub(crate) struct TransformDesc {
    pub translate: Option<V3>,
    /// Degrees about x, then y, then z.
    pub rotate: Option<V3>,
    pub scale: Option<ScaleDesc>,
    /// A general affine map as 4 rows of 4 (the last `[0, 0, 0, 1]`), instead of the above.
    pub matrix: Option<[[f32; 4]; 4]>,
}

/// `scale = 2.0` or `scale = [1, 2, 1]`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct ScaleDesc(pub [f32; 3]);

impl<'de> Deserialize<'de> for ScaleDesc {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        struct V;
        impl<'de> Visitor<'de> for V {
            type Value = ScaleDesc;
            fn expecting(&self, f: &mut fmt::Formatter) -> fmt::Result {
                f.write_str("a number or an array of 3 numbers")
            }
            fn visit_f64<E: de::Error>(self, v: f64) -> Result<ScaleDesc, E> {
                Ok(ScaleDesc([v as f32; 3]))
            }
            fn visit_i64<E: de::Error>(self, v: i64) -> Result<ScaleDesc, E> {
                Ok(ScaleDesc([v as f32; 3]))
            }
            fn visit_u64<E: de::Error>(self, v: u64) -> Result<ScaleDesc, E> {
                Ok(ScaleDesc([v as f32; 3]))
            }
            fn visit_seq<A: SeqAccess<'de>>(self, mut seq: A) -> Result<ScaleDesc, A::Error> {
                let mut s = [0.0f32; 3];
                for (i, c) in s.iter_mut().enumerate() {
                    *c = seq
                        .next_element()?
                        .ok_or_else(|| de::Error::invalid_length(i, &self))?;
                }
                if seq.next_element::<f32>()?.is_some() {
                    return Err(de::Error::invalid_length(4, &self));
                }
                Ok(ScaleDesc(s))
            }
        }
        d.deserialize_any(V)
    }
}

/// `[[assign]]`.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub(crate) struct AssignDesc {
    pub geometry: Spanned<String>,
    /// Half-open `[start, end)`.
    pub triangles: Spanned<Arr<u32, 2>>,
    pub material: Spanned<String>,
}

/// `[[instance]]`: a geometry placed once more, by its own transform.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub(crate) struct InstanceDesc {
    pub name: Spanned<String>,
    pub geometry: Spanned<String>,
    pub transform: Option<Spanned<TransformDesc>>,
}

/// `[[animation]]`: keyframes of a geometry, an instance, a camera or a material's emission.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub(crate) struct AnimationDesc {
    pub target: Spanned<String>,
    pub keys: Spanned<Vec<Spanned<KeyDesc>>>,
    /// `"linear"` (default) or `"step"`; material animations only.
    pub interpolate: Option<Spanned<String>>,
}

/// One key: `time` and either transform values (geometries, instances), camera values or a
/// material's emission.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub(crate) struct KeyDesc {
    pub time: f32,
    pub translate: Option<V3>,
    /// Degrees about x, then y, then z.
    pub rotate: Option<V3>,
    pub scale: Option<ScaleDesc>,
    pub position: Option<V3>,
    pub look_at: Option<V3>,
    pub up: Option<V3>,
    pub fov: Option<f32>,
    pub emission: Option<V3>,
}

/// `[render]`: defaults for the renderer's command-line options.
#[derive(Debug, Default, Deserialize)]
#[serde(deny_unknown_fields)]
pub(crate) struct RenderTableDesc {
    pub spp: Option<Spanned<u32>>,
    pub integrator: Option<String>,
    pub accel: Option<String>,
    pub max_depth: Option<u32>,
    pub seed: Option<u64>,
    pub threads: Option<Spanned<usize>>,
    pub aov: Option<Vec<String>>,
    pub output: Option<String>,
    pub denoiser: Option<Spanned<String>>,
}

/// Parses the TOML text into a [`SceneDesc`].
pub(crate) fn parse(text: &str) -> Result<SceneDesc, toml::de::Error> {
    toml::from_str(text)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn err(text: &str) -> String {
        parse(text).unwrap_err().message().to_string()
    }

    #[test]
    fn every_top_level_table_parses_and_unknown_tables_are_rejected() {
        let d = parse(
            r#"
            [environment]
            color = [0.1, 0.2, 0.3]
            [[camera]]
            name = "a"
            position = [0, 0, 1]
            look_at = [0, 0, 0]
            [[material]]
            name = "m"
            [[geometry]]
            name = "g"
            shape = "quad"
            [[assign]]
            geometry = "g"
            triangles = [0, 1]
            material = "m"
            [render]
            spp = 4
            "#,
        )
        .unwrap();
        assert_eq!(
            d.environment
                .unwrap()
                .into_inner()
                .color
                .unwrap()
                .into_inner()
                .0[2],
            0.3
        );
        assert_eq!(d.camera.len(), 1);
        assert_eq!(d.material.len(), 1);
        assert_eq!(d.geometry.len(), 1);
        assert_eq!(d.assign[0].get_ref().triangles.get_ref().0, [0, 1]);
        assert!(err("[[cameras]]\nname = \"x\"").contains("unknown field `cameras`"));
    }

    #[test]
    fn unknown_keys_are_rejected_in_every_table() {
        for (table, key) in [
            ("[environment]", "colour = [0, 0, 0]"),
            (
                "[[camera]]\nname = \"c\"\nposition = [0, 0, 1]\nlook_at = [0, 0, 0]",
                "fovy = 30",
            ),
            ("[[material]]\nname = \"m\"", "roughness = 0.5"),
            ("[[geometry]]\nname = \"g\"", "mesh = \"a.obj\""),
            (
                "[[assign]]\ngeometry = \"g\"\ntriangles = [0, 1]\nmaterial = \"m\"",
                "count = 1",
            ),
            ("[render]", "samples = 4"),
        ] {
            let text = format!("{table}\n{key}\n");
            let e = parse(&text).unwrap_err();
            let name = key.split(' ').next().unwrap();
            assert!(
                e.message().contains(&format!("unknown field `{name}`")),
                "{text}: {}",
                e.message()
            );
            // The span points at the key's line.
            let line = text[..e.span().unwrap().start].matches('\n').count();
            assert_eq!(line, text.lines().count() - 1, "{text}");
        }
        // Inside inline tables too.
        let e = err("[[material]]\nname = \"m\"\nlayers = [{ weight = 1, gloss = 2 }]");
        assert!(e.contains("unknown field `gloss`"), "{e}");
        let e = err("[[geometry]]\nname = \"g\"\ntransform = { translate = [0, 0, 0], turn = 1 }");
        assert!(e.contains("unknown field `turn`"), "{e}");
        let e = err("[environment]\nsky = { sun_direction = [0, 1, 0], scale = 2 }");
        assert!(e.contains("unknown field `scale`"), "{e}");
    }

    #[test]
    fn scale_is_a_number_or_three_numbers() {
        let t: TransformDesc = toml::from_str("scale = 2").unwrap();
        assert_eq!(t.scale, Some(ScaleDesc([2.0; 3])));
        let t: TransformDesc = toml::from_str("scale = 0.5").unwrap();
        assert_eq!(t.scale, Some(ScaleDesc([0.5; 3])));
        let t: TransformDesc = toml::from_str("scale = [1, -2, 3.5]").unwrap();
        assert_eq!(t.scale, Some(ScaleDesc([1.0, -2.0, 3.5])));
        for bad in ["scale = [1, 2]", "scale = [1, 2, 3, 4]", "scale = \"big\""] {
            let e = toml::from_str::<TransformDesc>(bad).unwrap_err();
            assert!(
                e.message().contains("a number or an array of 3 numbers"),
                "{bad}: {e}"
            );
        }
    }

    #[test]
    fn integers_are_accepted_where_numbers_are_expected_and_types_are_checked() {
        let c: CameraDesc =
            toml::from_str("name = \"c\"\nposition = [0, 1, 2]\nlook_at = [0, 0, 0]\nfov = 40")
                .unwrap();
        assert_eq!(c.position.into_inner().0, [0.0, 1.0, 2.0]);
        assert_eq!(c.fov.unwrap().into_inner(), 40.0);
        let e =
            toml::from_str::<CameraDesc>("name = \"c\"\nposition = [0, 1]\nlook_at = [0, 0, 0]")
                .unwrap_err();
        assert!(
            e.message()
                .contains("invalid length 2, expected an array of 3 numbers"),
            "{e}"
        );
        let e = toml::from_str::<CameraDesc>(
            "name = \"c\"\nposition = [0, 1, 2, 3]\nlook_at = [0, 0, 0]",
        )
        .unwrap_err();
        assert!(
            e.message()
                .contains("invalid length 4, expected an array of 3 numbers"),
            "{e}"
        );
        let e = toml::from_str::<CameraDesc>(
            "name = \"c\"\nposition = [0, 1, 2]\nlook_at = [0, 0, 0]\nresolution = [-1, 5]",
        )
        .unwrap_err();
        assert!(e.message().contains("-1"), "{e}");
    }

    /// The field names serde's derive gives a struct: its `Deserialize` impl passes them to
    /// `deserialize_struct`, where this deserializer records them and stops.
    fn fields_of<'de, T: Deserialize<'de>>() -> Vec<&'static str> {
        struct Fields(Vec<&'static str>);
        #[derive(Debug)]
        struct Stop;
        impl std::fmt::Display for Stop {
            fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
                f.write_str("stop")
            }
        }
        impl std::error::Error for Stop {}
        impl de::Error for Stop {
            fn custom<M: std::fmt::Display>(_: M) -> Self {
                Stop
            }
        }
        impl<'de> de::Deserializer<'de> for &mut Fields {
            type Error = Stop;
            fn deserialize_any<V: de::Visitor<'de>>(self, _: V) -> Result<V::Value, Stop> {
                Err(Stop)
            }
            fn deserialize_struct<V: de::Visitor<'de>>(
                self,
                _: &'static str,
                fields: &'static [&'static str],
                _: V,
            ) -> Result<V::Value, Stop> {
                self.0.extend_from_slice(fields);
                Err(Stop)
            }
            serde::forward_to_deserialize_any! {
                bool i8 i16 i32 i64 i128 u8 u16 u32 u64 u128 f32 f64 char str string bytes
                byte_buf option unit unit_struct newtype_struct seq tuple tuple_struct map enum
                identifier ignored_any
            }
        }
        let mut f = Fields(Vec::new());
        let _ = T::deserialize(&mut f);
        assert!(
            !f.0.is_empty(),
            "{} has no fields",
            std::any::type_name::<T>()
        );
        f.0
    }

    /// `docs/scene-format.md` has a table row naming every key of every `*Desc` type (in
    /// backticks), the key list taken from the types themselves, so a key added without
    /// documentation fails here; so does every value of `shape`.
    #[test]
    fn every_desc_field_is_documented_in_a_table_row() {
        let path = concat!(env!("CARGO_MANIFEST_DIR"), "/../../docs/scene-format.md");
        let doc = std::fs::read_to_string(path).unwrap();
        let rows: Vec<&str> = doc.lines().filter(|l| l.starts_with('|')).collect();
        let types: [(&str, Vec<&str>); 14] = [
            ("SceneDesc", fields_of::<SceneDesc>()),
            ("EnvironmentDesc", fields_of::<EnvironmentDesc>()),
            ("SkyDesc", fields_of::<SkyDesc>()),
            ("CameraDesc", fields_of::<CameraDesc>()),
            ("MaterialDesc", fields_of::<MaterialDesc>()),
            ("LayerDesc", fields_of::<LayerDesc>()),
            ("GeometryDesc", fields_of::<GeometryDesc>()),
            ("TransformDesc", fields_of::<TransformDesc>()),
            ("AssignDesc", fields_of::<AssignDesc>()),
            ("RenderTableDesc", fields_of::<RenderTableDesc>()),
            ("InstanceDesc", fields_of::<InstanceDesc>()),
            ("AnimationDesc", fields_of::<AnimationDesc>()),
            ("KeyDesc", fields_of::<KeyDesc>()),
            ("LightDesc", fields_of::<LightDesc>()),
        ];
        // The top level's fields are the tables; each must be one of the types above.
        assert_eq!(
            types[0].1,
            [
                "environment",
                "camera",
                "material",
                "geometry",
                "assign",
                "instance",
                "animation",
                "render",
                "light"
            ],
            "a new top-level table needs its *Desc type in this list"
        );
        let mut missing = Vec::new();
        for (ty, fields) in &types[1..] {
            for k in fields {
                let tick = format!("`{k}`");
                if !rows.iter().any(|r| r.contains(&tick)) {
                    missing.push(format!("{ty}.{k}"));
                }
            }
        }
        assert!(
            missing.is_empty(),
            "docs/scene-format.md has no table row for: {}",
            missing.join(", ")
        );
        // The shapes (values of `shape`) have rows too.
        for shape in crate::geometry::SHAPES {
            let tick = format!("| `{shape}`");
            assert!(
                doc.contains(&tick),
                "docs/scene-format.md has no row for shape {shape}"
            );
        }
        // And the tables themselves are documented (as headings).
        for table in [
            "[environment]",
            "[[camera]]",
            "[[material]]",
            "[[geometry]]",
            "[[assign]]",
            "[render]",
            "[[light]]",
        ] {
            assert!(
                doc.contains(table),
                "docs/scene-format.md does not document {table}"
            );
        }
    }
}
