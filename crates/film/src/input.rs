//! Reading an image as linear RGB: EXR as linear float, PNG and JPEG as sRGB decoded to linear.
//! Every error names the file.

use crate::output::{read_exr, ExrImage};
use crate::FilmError;
use rt_core::color::srgb_to_linear;
use rt_core::{Rgb, RgbImage};
use std::path::Path;

type Result<T> = std::result::Result<T, FilmError>;

/// A [`FilmError::Codec`] about `path`.
fn codec(path: &Path, message: impl Into<String>) -> FilmError {
    FilmError::Codec {
        path: path.to_path_buf(),
        message: message.into(),
    }
}

/// Reads `path` as linear RGB, choosing the decoder by extension.
///
/// EXR: the first layer's `R`, `G`, `B` channels; without them, the one channel group `P.R`,
/// `P.G`, `P.B` if exactly one prefix `P.` has all three; without any, a `Y` channel as grey.
/// Alpha and other channels are ignored. PNG/JPEG (8 or 16 bit, grey or colour, alpha ignored)
/// are taken to be sRGB-encoded; embedded colour profiles and gamma chunks are not read.
pub fn read_rgb(path: &Path) -> Result<RgbImage> {
    // Opening first turns a missing or unreadable file into the OS's own words, which the
    // decoders would otherwise wrap in their own.
    std::fs::File::open(path).map_err(|source| FilmError::Io {
        path: path.to_path_buf(),
        source,
    })?;
    let ext = path
        .extension()
        .and_then(|e| e.to_str())
        .map(str::to_ascii_lowercase);
    match ext.as_deref() {
        // `FilmError` already names the file and holds the cause.
        Some("exr") => exr_rgb(path, read_exr(path)?),
        Some("png" | "jpg" | "jpeg") => {
            let bytes = std::fs::read(path).map_err(|source| FilmError::Io {
                path: path.to_path_buf(),
                source,
            })?;
            decode_srgb(&bytes).map_err(|e| codec(path, e))
        }
        _ => Err(codec(
            path,
            "unsupported image format (use .exr, .png or .jpg)",
        )),
    }
}

/// Decodes a PNG or JPEG (any bit depth, grey or colour; alpha ignored) held in memory, taking
/// its values to be sRGB-encoded, to linear RGB: the one decoder for image files and for images
/// inside other files (glTF). Eight-bit values go through an exact table.
pub fn decode_srgb(bytes: &[u8]) -> std::result::Result<RgbImage, String> {
    decode(bytes, srgb_to_linear)
}

/// [`decode_srgb`] for images that hold data rather than colours (normal maps, Mitsuba's `raw`
/// bitmaps): values are read as they are, scaled to [0, 1].
pub fn decode_raw(bytes: &[u8]) -> std::result::Result<RgbImage, String> {
    decode(bytes, |v| v)
}

/// Decodes a PNG or JPEG, mapping each value in [0, 1] through `transfer`.
fn decode(bytes: &[u8], transfer: fn(f32) -> f32) -> std::result::Result<RgbImage, String> {
    let img = image::load_from_memory(bytes).map_err(|e| format!("cannot decode image: {e}"))?;
    let (width, height) = (img.width() as usize, img.height() as usize);
    let pixels = match img {
        image::DynamicImage::ImageLuma8(_)
        | image::DynamicImage::ImageLumaA8(_)
        | image::DynamicImage::ImageRgb8(_)
        | image::DynamicImage::ImageRgba8(_) => {
            let lut: Vec<f32> = (0..256).map(|i| transfer(i as f32 / 255.0)).collect();
            img.to_rgb8()
                .pixels()
                .map(|p| Rgb::new(lut[p[0] as usize], lut[p[1] as usize], lut[p[2] as usize]))
                .collect()
        }
        _ => img
            .to_rgb32f()
            .pixels()
            .map(|p| Rgb::from_array(p.0.map(|v| transfer(v.clamp(0.0, 1.0)))))
            .collect(),
    };
    RgbImage::new(width, height, pixels).map_err(|e| e.to_string())
}

fn exr_rgb(path: &Path, exr: ExrImage) -> Result<RgbImage> {
    let n = exr.width * exr.height;
    let has = |c: &str| exr.channel(c).is_some();
    let prefixes: Vec<&str> = exr
        .channels
        .iter()
        .filter_map(|(c, _)| c.strip_suffix('R'))
        .filter(|p| p.is_empty() || p.ends_with('.'))
        .filter(|p| has(&format!("{p}G")) && has(&format!("{p}B")))
        .collect();
    let prefix = match prefixes.as_slice() {
        _ if prefixes.contains(&"") => "",
        [one] => one,
        [] => return exr_grey(path, &exr),
        many => {
            return Err(codec(
                path,
                format!(
                    "no plain R, G, B channels and several groups with them ({}); \
                     cannot tell which to compare",
                    many.join(", ")
                ),
            ))
        }
    };
    for c in ["R", "G", "B"] {
        let len = exr.channel(&format!("{prefix}{c}")).map_or(0, <[f32]>::len);
        if len != n {
            let (w, h) = (exr.width, exr.height);
            return Err(codec(
                path,
                format!("channel {prefix}{c} has {len} values for a {w}x{h} image (subsampled?)"),
            ));
        }
    }
    let pixels = exr
        .rgb(prefix)
        .ok_or_else(|| codec(path, format!("missing {prefix}R, {prefix}G or {prefix}B")))?;
    RgbImage::new(exr.width, exr.height, pixels).map_err(|e| codec(path, e.to_string()))
}

/// A grey EXR (one `Y` channel), as RGB.
fn exr_grey(path: &Path, exr: &ExrImage) -> Result<RgbImage> {
    match exr.channel("Y") {
        Some(y) if y.len() == exr.width * exr.height => {
            let pixels = y.iter().map(|&v| Rgb::splat(v)).collect();
            RgbImage::new(exr.width, exr.height, pixels).map_err(|e| codec(path, e.to_string()))
        }
        _ => {
            let names: Vec<&str> = exr.channels.iter().map(|(c, _)| c.as_str()).collect();
            Err(codec(
                path,
                format!("no R, G, B channels (it has {})", names.join(", ")),
            ))
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn exr(channels: &[&str]) -> ExrImage {
        ExrImage {
            width: 2,
            height: 1,
            channels: channels
                .iter()
                .enumerate()
                .map(|(i, c)| (c.to_string(), vec![i as f32; 2]))
                .collect(),
        }
    }

    #[test]
    fn exr_channel_choice() {
        let p = Path::new("x.exr");
        let plain = exr_rgb(
            p,
            exr(&["A", "B", "G", "R", "albedo.B", "albedo.G", "albedo.R"]),
        )
        .unwrap();
        assert_eq!(plain.pixel(0, 0), Rgb::new(3.0, 2.0, 1.0));
        let layer = exr_rgb(p, exr(&["beauty.B", "beauty.G", "beauty.R", "Z"])).unwrap();
        assert_eq!(layer.pixel(1, 0), Rgb::new(2.0, 1.0, 0.0));
        let grey = exr_rgb(p, exr(&["Y"])).unwrap();
        assert_eq!(grey.pixel(0, 0), Rgb::ZERO);
        let e = exr_rgb(p, exr(&["a.B", "a.G", "a.R", "b.B", "b.G", "b.R"])).unwrap_err();
        assert!(e.to_string().contains("a., b."), "{e}");
        let e = exr_rgb(p, exr(&["Z", "R"])).unwrap_err();
        assert_eq!(e.to_string(), "x.exr: no R, G, B channels (it has Z, R)");
        let mut short = exr(&["B", "G", "R"]);
        short.channels[0].1.pop();
        assert!(exr_rgb(p, short)
            .unwrap_err()
            .to_string()
            .contains("channel B has 1 values"));
    }
}
