//! Image files: textures (PNG, JPEG: sRGB decoded to linear unless raw; EXR and HDR: linear
//! floats) and environment maps (EXR, HDR).

use crate::error::{Result, SceneError};
use crate::files::FileAccess;
use rt_core::{
    texture::{Filter, Texture, Wrap},
    Rgb,
};
use std::collections::HashMap;
use std::path::{Path, PathBuf};

/// The scene's textures, loaded once per file, and the file policy every loader of the scene
/// reads through (it travels with the textures because every mesh loader takes them).
#[derive(Default)]
pub(crate) struct Textures {
    list: Vec<Texture>,
    by_path: HashMap<(PathBuf, TextureOptions), u32>,
    access: FileAccess,
}

impl Textures {
    /// No textures yet; files are read under `access`.
    pub fn new(access: FileAccess) -> Self {
        Self {
            access,
            ..Self::default()
        }
    }

    /// The file policy.
    pub fn access(&self) -> &FileAccess {
        &self.access
    }

    /// Index of the texture in `path` (bilinear, repeating, sRGB), loading it on first use.
    pub fn load_file(&mut self, path: &Path) -> Result<u32> {
        self.load(path, TextureOptions::default())
    }

    /// Index of the texture in `path` read with `options`, loading it on first use.
    pub fn load(&mut self, path: &Path, options: TextureOptions) -> Result<u32> {
        let canonical = std::fs::canonicalize(path).unwrap_or_else(|_| path.to_path_buf());
        let key = (canonical, options);
        if let Some(&i) = self.by_path.get(&key) {
            return Ok(i);
        }
        let mut t = if is_float_image(path) {
            // Linear floats (Mitsuba reads them so, `raw` or not); any non-negative value, for
            // parameters that are not reflectances (a conductor's `eta` and `k`).
            let (w, h, texels) = read_env_map(&self.access, path)?;
            Texture::new(w, h, texels)
        } else {
            let bytes = self.access.read(path, "")?;
            let decoded = if options.raw {
                rt_film::decode_raw(&bytes)
            } else {
                rt_film::decode_srgb(&bytes)
            };
            let img = decoded.map_err(|e| SceneError::file(path, e))?;
            Texture::new(img.width() as u32, img.height() as u32, img.into_pixels())
        };
        t.filter = options.filter;
        t.wrap = options.wrap;
        let i = self.add(t);
        self.by_path.insert(key, i);
        Ok(i)
    }

    /// Adds a texture that has no file of its own (an image inside a glTF file).
    pub fn add(&mut self, t: Texture) -> u32 {
        self.list.push(t);
        (self.list.len() - 1) as u32
    }

    /// Texture `i`.
    pub fn get(&self, i: u32) -> &Texture {
        &self.list[i as usize]
    }

    /// The textures, in index order.
    pub fn into_vec(self) -> Vec<Texture> {
        self.list
    }
}

/// How a texture file is read and looked up (Mitsuba's `bitmap` options).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub(crate) struct TextureOptions {
    pub filter: Filter,
    pub wrap: Wrap,
    /// Linear data (normal maps), not sRGB-encoded colours.
    pub raw: bool,
}

/// Decodes an encoded PNG or JPEG (a file's bytes, or an image inside a glTF file).
pub(crate) fn texture_from_bytes(bytes: &[u8]) -> std::result::Result<Texture, String> {
    let img = rt_film::decode_srgb(bytes)?;
    Ok(Texture::new(
        img.width() as u32,
        img.height() as u32,
        img.into_pixels(),
    ))
}

/// True for the float formats (OpenEXR, Radiance `.hdr`), read by [`read_env_map`].
fn is_float_image(path: &Path) -> bool {
    path.extension()
        .and_then(|e| e.to_str())
        .is_some_and(|e| e.eq_ignore_ascii_case("exr") || e.eq_ignore_ascii_case("hdr"))
}

/// Reads an environment map (or a float texture) as row-major linear radiance (row 0 at the top): the first
/// RGB(A) layer of an OpenEXR file, or a Radiance RGBE (`.hdr`) file. Rejects empty images
/// and NaN, infinite or negative texels, naming the first bad one.
pub(crate) fn read_env_map(access: &FileAccess, path: &Path) -> Result<(u32, u32, Vec<Rgb>)> {
    access.check(path)?;
    let ext = path
        .extension()
        .and_then(|e| e.to_str())
        .map(str::to_ascii_lowercase);
    let (w, h, texels) = match ext.as_deref() {
        Some("exr") => {
            let img = rt_film::read_rgb(path).map_err(|e| {
                let why = match e {
                    rt_film::FilmError::Io { source, .. } => format!("cannot open: {source}"),
                    rt_film::FilmError::Codec { message, .. } => {
                        format!("cannot read as an RGB EXR image: {message}")
                    }
                    other => format!("cannot read as an RGB EXR image: {other}"),
                };
                SceneError::file(path, why)
            })?;
            (img.width(), img.height(), img.into_pixels())
        }
        Some("hdr") => read_rgbe(&access.read(path, "")?).map_err(|e| SceneError::file(path, e))?,
        _ => {
            return Err(SceneError::file(
                path,
                "an environment map must be an .exr or .hdr file",
            ))
        }
    };
    if w == 0 || h == 0 {
        return Err(SceneError::file(path, "the image is empty"));
    }
    if let Some(i) = texels
        .iter()
        .position(|t| !t.is_finite() || t.min_element() < 0.0)
    {
        return Err(SceneError::file(
            path,
            format!(
                "texel ({}, {}) is {:?}: environment radiance must be finite and non-negative",
                i % w,
                i / w,
                texels[i].to_array()
            ),
        ));
    }
    Ok((w as u32, h as u32, texels))
}

/// Decodes a Radiance RGBE image.
fn read_rgbe(bytes: &[u8]) -> std::result::Result<(usize, usize, Vec<Rgb>), String> {
    let img = image::load_from_memory_with_format(bytes, image::ImageFormat::Hdr)
        .map_err(|e| format!("cannot read as a Radiance .hdr image: {e}"))?
        .into_rgb32f();
    let (w, h) = (img.width() as usize, img.height() as usize);
    let texels = img.pixels().map(|p| Rgb::new(p[0], p[1], p[2])).collect();
    Ok((w, h, texels))
}

#[cfg(test)]
mod tests {

    /// A texture file read as a scene's texture (bilinear, repeat, sRGB).
    fn read_texture(access: &FileAccess, path: &Path) -> Result<Texture> {
        let mut t = Textures::new(access.clone());
        let i = t.load_file(path)?;
        Ok(t.into_vec().swap_remove(i as usize))
    }
    use super::*;

    #[test]
    fn png_texture_is_srgb_decoded_and_row_zero_is_the_top() {
        let dir = tempfile::tempdir().unwrap();
        let p = dir.path().join("t.png");
        let mut img = image::RgbImage::new(2, 2);
        img.put_pixel(0, 0, image::Rgb([255, 0, 0]));
        img.put_pixel(1, 0, image::Rgb([188, 188, 188]));
        img.save(&p).unwrap();
        let t = read_texture(&FileAccess::open(), &p).unwrap();
        assert_eq!((t.width, t.height), (2, 2));
        assert_eq!(t.texels[0], Rgb::new(1.0, 0.0, 0.0));
        // sRGB 188 is about 0.5 linear.
        assert!((t.texels[1].x - 0.5029).abs() < 1e-3, "{}", t.texels[1]);
        assert_eq!(t.texels[3], Rgb::ZERO);

        let mut tex = Textures::default();
        let a = tex.load_file(&p).unwrap();
        let b = tex.load_file(&dir.path().join(".").join("t.png")).unwrap();
        assert_eq!(a, b, "the same file is loaded once");
        assert_eq!(tex.into_vec().len(), 1);
    }

    #[test]
    fn bad_texture_files_name_the_file() {
        let dir = tempfile::tempdir().unwrap();
        let p = dir.path().join("missing.png");
        let e = read_texture(&FileAccess::open(), &p)
            .unwrap_err()
            .to_string();
        assert!(e.contains("missing.png: cannot open"), "{e}");
        let p = dir.path().join("junk.png");
        std::fs::write(&p, b"not a png").unwrap();
        let e = read_texture(&FileAccess::open(), &p)
            .unwrap_err()
            .to_string();
        assert!(e.contains("junk.png: cannot decode image"), "{e}");
    }

    #[test]
    fn exr_maps_are_read_and_bad_texels_rejected() {
        let dir = tempfile::tempdir().unwrap();
        let p = dir.path().join("env.exr");
        exr::prelude::write_rgb_file(&p, 4, 2, |x, y| (x as f32, y as f32, 0.5f32)).unwrap();
        let (w, h, t) = read_env_map(&FileAccess::open(), &p).unwrap();
        assert_eq!((w, h), (4, 2));
        assert_eq!(t[4 + 3], Rgb::new(3.0, 1.0, 0.5));

        for (bad, what) in [(f32::NAN, "NaN"), (f32::INFINITY, "inf"), (-1.0, "-1.0")] {
            exr::prelude::write_rgb_file(&p, 4, 2, |x, y| {
                (if (x, y) == (2, 1) { bad } else { 1.0f32 }, 1.0f32, 1.0f32)
            })
            .unwrap();
            let e = read_env_map(&FileAccess::open(), &p)
                .unwrap_err()
                .to_string();
            assert!(e.contains("env.exr: texel (2, 1)"), "{e}");
            assert!(e.contains(what), "{e}");
        }
        let e = read_env_map(&FileAccess::open(), &dir.path().join("none.exr"))
            .unwrap_err()
            .to_string();
        assert!(e.contains("none.exr: cannot open"), "{e}");
        std::fs::write(&p, b"garbage").unwrap();
        let e = read_env_map(&FileAccess::open(), &p)
            .unwrap_err()
            .to_string();
        assert!(e.contains("env.exr: cannot read"), "{e}");
    }

    #[test]
    fn radiance_hdr_maps_are_read_linear_with_row_zero_at_the_top() {
        let dir = tempfile::tempdir().unwrap();
        let p = dir.path().join("env.hdr");
        // Powers of two are exact in RGBE's shared-exponent encoding.
        let pixels: Vec<image::Rgb<f32>> = (0..8)
            .map(|i| image::Rgb([i as f32, 0.5, 2.0f32.powi(i - 2)]))
            .collect();
        let mut bytes = Vec::new();
        image::codecs::hdr::HdrEncoder::new(&mut bytes)
            .encode(&pixels, 4, 2)
            .unwrap();
        std::fs::write(&p, &bytes).unwrap();
        let (w, h, t) = read_env_map(&FileAccess::open(), &p).unwrap();
        assert_eq!((w, h), (4, 2));
        for (i, px) in pixels.iter().enumerate() {
            let want = Rgb::new(px[0], px[1], px[2]);
            assert!(
                (t[i] - want).abs().max_element() <= 0.01 * want.max_element(),
                "{i}"
            );
        }
        std::fs::write(&p, b"#?RADIANCE\ngarbage").unwrap();
        let e = read_env_map(&FileAccess::open(), &p)
            .unwrap_err()
            .to_string();
        assert!(
            e.contains("env.hdr: cannot read as a Radiance .hdr image"),
            "{e}"
        );
        let e = read_env_map(&FileAccess::open(), &dir.path().join("env.png"))
            .unwrap_err()
            .to_string();
        assert!(e.contains("must be an .exr or .hdr file"), "{e}");
    }
}
