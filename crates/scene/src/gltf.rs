//! glTF 2.0 meshes (`.gltf` with external or embedded buffers, and binary `.glb`).
//!
//! The default scene (or the first scene) is walked depth first, children in the order the file
//! lists them, composing node matrices and TRS transforms; every triangle primitive
//! (`TRIANGLES`, `TRIANGLE_STRIP`, `TRIANGLE_FAN`) of every mesh instance is added, so a mesh
//! used by two nodes appears twice. Indices may be u8, u16, u32 or absent; sparse accessors are
//! resolved by `gltf`'s reader. glTF's uv origin is the top-left corner of the image; uvs are
//! flipped to our bottom-up convention (`v' = 1 − v`). Point and line primitives are skipped
//! with a warning.
//!
//! Materials: glTF 2.0's metallic-roughness BRDF (the specification's Appendix B) on GGX, with
//! `C = baseColorFactor.rgb` (times `baseColorTexture`) and `α = roughnessFactor²`: a blend
//! (`rt_core::microfacet::Blend`) of weight `metallicFactor` of
//! - the dielectric: a rough plastic (`roughplastic`, GGX α, coating ior 1.5 or
//!   `KHR_materials_ior`) over a Lambertian base C, the specification's `fresnel_mix` of a
//!   specular layer over `diffuse_brdf(C)`;
//! - the metal: a rough conductor (GGX α) that reflects everything (Mitsuba's `none`) times
//!   C, the specification's `conductor_fresnel(f0 = C)`.
//!
//! A metallic factor of 0 or 1 is the one BSDF. Both reflect from either face (glTF culls or
//! shades back faces; neither is black). Deviations: the plastic's coating uses the exact
//! dielectric Fresnel term and Mitsuba's internal-reflection model where the specification
//! uses Schlick's approximation and no inter-reflection; the metal is `F = 1` tinted by C where
//! the specification has Schlick's `C + (1 − C)(1 − cos)⁵`, which brightens toward white at
//! grazing angles only. `KHR_materials_transmission` factor > 0.5 is still the layered model's
//! glass (colour C, hardness `1 − roughness`, ior from `KHR_materials_ior`, default 1.5).
//! Emission: `emissiveFactor × KHR_materials_emissive_strength` (default 1); `doubleSided`
//! makes emission two-sided. Metallic-roughness, normal, occlusion and emissive textures are
//! ignored.

use crate::error::{Result, SceneError};
use crate::geometry::Mesh;
use crate::image_io::{texture_from_bytes, Textures};
use ::gltf::mesh::Mode;
use glam::{Mat4, Vec2, Vec3};
use rt_core::microfacet::{
    Blend, BlendPart, Distribution, DistributionKind, Microfacet, RoughConductor, RoughPlastic,
};
use rt_core::transform::Transform;
use rt_core::{Material, Rgb};
use std::collections::HashMap;
use std::path::Path;

/// Deepest node hierarchy followed (guards against cyclic files).
const MAX_DEPTH: usize = 256;

/// State of one file's load.
struct Loader<'a> {
    path: &'a Path,
    dir: &'a Path,
    buffers: Vec<::gltf::buffer::Data>,
    want_materials: bool,
    textures: &'a mut Textures,
    /// glTF material index → index in `mesh.materials`.
    material_slots: HashMap<usize, u32>,
    /// glTF image index → texture index.
    images: HashMap<usize, u32>,
    mesh: Mesh,
    skipped: usize,
    dropped_attributes: usize,
}

/// Loads a `.gltf` or `.glb` file.
pub(crate) fn load(
    path: &Path,
    want_materials: bool,
    textures: &mut Textures,
    warnings: &mut Vec<String>,
) -> Result<Mesh> {
    let bytes = textures.access().read(path, "")?;
    let malformed = |e: String| SceneError::file(path, format!("malformed glTF: {e}"));
    // Parsed without the gltf crate's validation, whose POSITION check indexes the accessors
    // before checking the index (a panic fuzzing found); validated once that is checked.
    let ::gltf::Gltf { document, blob } = ::gltf::Gltf::from_slice_without_validation(&bytes)
        .map_err(|e| malformed(e.to_string()))?;
    let json = document.into_json();
    check_attribute_accessors(&json).map_err(malformed)?;
    let document = ::gltf::Document::from_json(json).map_err(|e| malformed(e.to_string()))?;
    let dir = path.parent().unwrap_or(Path::new(""));
    // The gltf crate opens external buffers itself: check them first.
    for b in document.buffers() {
        if let ::gltf::buffer::Source::Uri(uri) = b.source() {
            if !uri.starts_with("data:") {
                textures.access().check(&dir.join(percent_decode(uri)))?;
            }
        }
    }
    let buffers = ::gltf::import_buffers(&document, Some(dir), blob)
        .map_err(|e| SceneError::file(path, format!("cannot load buffer data: {e}")))?;
    let mut l = Loader {
        path,
        dir,
        buffers,
        want_materials,
        textures,
        material_slots: HashMap::new(),
        images: HashMap::new(),
        mesh: Mesh::default(),
        skipped: 0,
        dropped_attributes: 0,
    };
    match document
        .default_scene()
        .or_else(|| document.scenes().next())
    {
        Some(scene) => {
            for node in scene.nodes() {
                l.node(&node, Mat4::IDENTITY, 0)?;
            }
        }
        None => {
            warnings.push(format!(
                "{}: has no scene; every mesh is placed once, untransformed",
                path.display()
            ));
            for m in document.meshes() {
                l.mesh(&m, &Mat4::IDENTITY)?;
            }
        }
    }
    if l.skipped > 0 {
        warnings.push(format!(
            "{}: skipped {} point or line primitives",
            path.display(),
            l.skipped
        ));
    }
    if l.dropped_attributes > 0 {
        warnings.push(format!(
            "{}: ignored normals or uvs of {} primitives whose counts differ from their \
             positions",
            path.display(),
            l.dropped_attributes
        ));
    }
    Ok(l.mesh)
}

impl Loader<'_> {
    fn error(&self, msg: String) -> SceneError {
        SceneError::file(self.path, msg)
    }

    fn node(&mut self, node: &::gltf::Node, parent: Mat4, depth: usize) -> Result<()> {
        if depth > MAX_DEPTH {
            return Err(self.error(format!(
                "node hierarchy deeper than {MAX_DEPTH} (cyclic?) at node {}",
                node.index()
            )));
        }
        let world = parent * Mat4::from_cols_array_2d(&node.transform().matrix());
        if let Some(m) = node.mesh() {
            self.mesh(&m, &world)?;
        }
        for child in node.children() {
            self.node(&child, world, depth + 1)?;
        }
        Ok(())
    }

    fn mesh(&mut self, m: &::gltf::Mesh, world: &Mat4) -> Result<()> {
        let t = Transform::from_mat4(*world);
        for prim in m.primitives() {
            self.primitive(m, &prim, &t)?;
        }
        Ok(())
    }

    fn primitive(
        &mut self,
        m: &::gltf::Mesh,
        prim: &::gltf::Primitive,
        t: &Transform,
    ) -> Result<()> {
        let mode = prim.mode();
        if !matches!(
            mode,
            Mode::Triangles | Mode::TriangleStrip | Mode::TriangleFan
        ) {
            self.skipped += 1;
            return Ok(());
        }
        let what = format!(
            "mesh {} (\"{}\") primitive {}",
            m.index(),
            m.name().unwrap_or(""),
            prim.index()
        );
        let buffers = &self.buffers;
        let reader = prim.reader(|b| buffers.get(b.index()).map(|d| &d.0[..]));
        let positions: Vec<Vec3> = reader
            .read_positions()
            .ok_or_else(|| self.error(format!("{what} has no readable POSITION data")))?
            .map(Vec3::from)
            .collect();
        let n = positions.len();
        let mut normals: Option<Vec<Vec3>> =
            reader.read_normals().map(|it| it.map(Vec3::from).collect());
        let mut uvs: Option<Vec<Vec2>> = reader
            .read_tex_coords(0)
            .map(|it| it.into_f32().map(|[u, v]| Vec2::new(u, 1.0 - v)).collect());
        if normals.as_ref().is_some_and(|v| v.len() != n) {
            normals = None;
            self.dropped_attributes += 1;
        }
        if uvs.as_ref().is_some_and(|v| v.len() != n) {
            uvs = None;
            self.dropped_attributes += 1;
        }
        // The gltf crate's reader has no case for other index types (`unreachable!`).
        if let Some(a) = prim.indices() {
            use ::gltf::accessor::{DataType, Dimensions};
            let integer = matches!(a.data_type(), DataType::U8 | DataType::U16 | DataType::U32);
            if !integer || a.dimensions() != Dimensions::Scalar {
                return Err(self.error(format!(
                    "{what}: indices must be unsigned integer scalars, not {:?} {:?}",
                    a.data_type(),
                    a.dimensions()
                )));
            }
        }
        let indices: Vec<u32> = match reader.read_indices() {
            Some(ix) => ix.into_u32().collect(),
            None => (0..n as u32).collect(),
        };
        if let Some(&bad) = indices.iter().find(|&&i| i as usize >= n) {
            return Err(self.error(format!(
                "{what}: index {bad} is out of range (the primitive has {n} vertices)"
            )));
        }
        let tris: Vec<[u32; 3]> = match mode {
            Mode::Triangles => indices
                .chunks_exact(3)
                .map(|c| [c[0], c[1], c[2]])
                .collect(),
            // Every other strip triangle is reversed to keep a consistent winding.
            Mode::TriangleStrip => (0..indices.len().saturating_sub(2))
                .map(|i| {
                    let (a, b, c) = (indices[i], indices[i + 1], indices[i + 2]);
                    if i % 2 == 0 {
                        [a, b, c]
                    } else {
                        [b, a, c]
                    }
                })
                .collect(),
            _ => (1..indices.len().saturating_sub(1))
                .map(|i| [indices[i], indices[i + 1], indices[0]])
                .collect(),
        };
        let mat = match (self.want_materials, prim.material().index()) {
            (true, Some(i)) => Some(self.material_slot(&prim.material(), i)?),
            _ => None,
        };
        let flip = t.flips_handedness();
        for ix in tris {
            let mut ix = ix.map(|i| i as usize);
            if flip {
                ix.swap(1, 2);
            }
            let v = ix.map(|i| t.point(positions[i]));
            let nm = normals.as_ref().map(|ns| ix.map(|i| t.normal(ns[i])));
            let uv = uvs.as_ref().map(|u| ix.map(|i| u[i]));
            self.mesh.push(v, nm, uv, mat);
        }
        Ok(())
    }

    /// Index in `mesh.materials` of glTF material `index`, converting it on first use.
    fn material_slot(&mut self, m: &::gltf::Material, index: usize) -> Result<u32> {
        if let Some(&s) = self.material_slots.get(&index) {
            return Ok(s);
        }
        let name = m
            .name()
            .map_or_else(|| format!("material{index}"), str::to_string);
        let mat = self.convert(m, &name)?;
        self.mesh.materials.push(mat);
        let slot = (self.mesh.materials.len() - 1) as u32;
        self.material_slots.insert(index, slot);
        Ok(slot)
    }

    /// Maps a glTF material onto GGX (see the module docs).
    fn convert(&mut self, m: &::gltf::Material, name: &str) -> Result<Material> {
        let pbr = m.pbr_metallic_roughness();
        let [r, g, b, _] = pbr.base_color_factor();
        let fix = |c: Rgb| if c.is_finite() { c } else { Rgb::ZERO };
        let color = fix(Rgb::new(r, g, b)).clamp(Rgb::ZERO, Rgb::ONE);
        let unit = |x: f32, default: f32| {
            if x.is_finite() {
                x.clamp(0.0, 1.0)
            } else {
                default
            }
        };
        let roughness = unit(pbr.roughness_factor(), 1.0);
        let metallic = unit(pbr.metallic_factor(), 1.0);
        let ior = m.ior().filter(|i| i.is_finite() && *i > 1.0).unwrap_or(1.5);
        let texture = match pbr.base_color_texture() {
            Some(info) => Some(self.image(&info.texture().source())?),
            None => None,
        };
        let transmission = m.transmission().map_or(0.0, |t| t.transmission_factor());
        let mut out = if transmission > 0.5 {
            let mut glass = Material::glass(name, color, ior, 1.0 - roughness);
            glass.texture = texture;
            glass
        } else {
            metallic_roughness(name, color, texture, roughness, metallic, ior)
        };
        let strength = m.emissive_strength().unwrap_or(1.0);
        out.emission = fix(Rgb::from(m.emissive_factor()) * strength).max(Rgb::ZERO);
        out.two_sided = m.double_sided();
        Ok(out)
    }

    /// Texture index of a glTF image, decoding it on first use.
    fn image(&mut self, image: &::gltf::Image) -> Result<u32> {
        let index = image.index();
        if let Some(&t) = self.images.get(&index) {
            return Ok(t);
        }
        let bytes: Vec<u8> = match image.source() {
            ::gltf::image::Source::View { view, .. } => {
                let data = &self.buffers[view.buffer().index()].0;
                data.get(view.offset()..view.offset() + view.length())
                    .ok_or_else(|| self.error(format!("image {index}: buffer view out of range")))?
                    .to_vec()
            }
            ::gltf::image::Source::Uri { uri, .. } => {
                if let Some(rest) = uri.strip_prefix("data:") {
                    let (_, data) = rest.split_once(";base64,").ok_or_else(|| {
                        self.error(format!("image {index}: unsupported data URI"))
                    })?;
                    base64_decode(data)
                        .ok_or_else(|| self.error(format!("image {index}: invalid base64 data")))?
                } else {
                    let p = self.dir.join(percent_decode(uri));
                    self.textures.access().check(&p)?;
                    std::fs::read(&p).map_err(|e| {
                        SceneError::file(
                            &p,
                            format!(
                                "cannot open (image {index} of {}): {e}",
                                self.path.display()
                            ),
                        )
                    })?
                }
            }
        };
        let texture =
            texture_from_bytes(&bytes).map_err(|e| self.error(format!("image {index}: {e}")))?;
        let t = self.textures.add(texture);
        self.images.insert(index, t);
        Ok(t)
    }
}

/// glTF's metallic-roughness material on GGX (see the module docs): base colour `color`
/// (times the texture `texture`), `roughness` and `metallic` in [0, 1], the dielectric's `ior`.
pub(crate) fn metallic_roughness(
    name: &str,
    color: Rgb,
    texture: Option<u32>,
    roughness: f32,
    metallic: f32,
    ior: f32,
) -> Material {
    let ggx = Distribution::new(
        DistributionKind::Ggx,
        roughness * roughness,
        roughness * roughness,
    );
    let mut plastic = RoughPlastic::new(ggx, color, Rgb::ONE, ior, false);
    plastic.two_sided = true;
    let metal = Microfacet::Conductor(RoughConductor {
        distribution: Some(ggx),
        eta: Rgb::ZERO,
        k: Rgb::ONE,
        specular_reflectance: color,
        two_sided: true,
    });
    let plastic = Microfacet::RoughPlastic(plastic);
    let mut out = match metallic {
        0.0 => Material::microfacet(name, plastic),
        1.0 => Material::microfacet(name, metal),
        _ => {
            let part = |bsdf| BlendPart {
                texture,
                ..BlendPart::new(bsdf)
            };
            Material::blend(name, Blend::new(metallic, [part(plastic), part(metal)]))
        }
    };
    if out.blend.is_none() {
        out.texture = texture;
    }
    out
}

/// Decodes `%XX` escapes of a relative URI.
fn percent_decode(s: &str) -> String {
    let b = s.as_bytes();
    let mut out = Vec::with_capacity(b.len());
    let mut i = 0;
    while i < b.len() {
        let hex = |c: u8| (c as char).to_digit(16);
        if b[i] == b'%' && i + 2 < b.len() {
            if let (Some(h), Some(l)) = (hex(b[i + 1]), hex(b[i + 2])) {
                out.push((h * 16 + l) as u8);
                i += 3;
                continue;
            }
        }
        out.push(b[i]);
        i += 1;
    }
    String::from_utf8_lossy(&out).into_owned()
}

/// Standard base64 (with or without padding); `None` on invalid input.
pub(crate) fn base64_decode(s: &str) -> Option<Vec<u8>> {
    let val = |c: u8| -> Option<u32> {
        Some(match c {
            b'A'..=b'Z' => c - b'A',
            b'a'..=b'z' => c - b'a' + 26,
            b'0'..=b'9' => c - b'0' + 52,
            b'+' | b'-' => 62,
            b'/' | b'_' => 63,
            _ => return None,
        } as u32)
    };
    let s = s.trim_end_matches('=');
    let mut out = Vec::with_capacity(s.len() * 3 / 4);
    let (mut acc, mut bits) = (0u32, 0);
    for c in s.bytes() {
        acc = (acc << 6) | val(c)?;
        bits += 6;
        if bits >= 8 {
            bits -= 8;
            out.push((acc >> bits) as u8);
            acc &= (1 << bits) - 1;
        }
    }
    Some(out)
}

/// Every primitive attribute names an accessor that exists (checked before the gltf crate's
/// validation, which indexes POSITION's accessor without checking it).
fn check_attribute_accessors(json: &::gltf::json::Root) -> std::result::Result<(), String> {
    let n = json.accessors.len();
    for (m, mesh) in json.meshes.iter().enumerate() {
        for (p, prim) in mesh.primitives.iter().enumerate() {
            let refs = prim.attributes.values().chain(prim.indices.as_ref());
            if let Some(bad) = refs.map(|i| i.value()).find(|&i| i >= n) {
                return Err(format!(
                    "mesh {m} primitive {p} names accessor {bad}, but there are {n}"
                ));
            }
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn base64_and_percent_decoding() {
        assert_eq!(base64_decode("TWFu").unwrap(), b"Man");
        assert_eq!(base64_decode("TWE=").unwrap(), b"Ma");
        assert_eq!(base64_decode("TQ==").unwrap(), b"M");
        assert!(base64_decode("T*==").is_none());
        assert_eq!(percent_decode("a%20b.png"), "a b.png");
        assert_eq!(percent_decode("100%"), "100%");
    }
}
