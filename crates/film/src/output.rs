//! Writing images: EXR for data, PNG for looking at. Both atomic.
//!
//! EXR: linear float32. The beauty image is in channels `R`, `G`, `B`; AOVs are channel groups
//! laid out as [`crate::NoisyFrame`] says (`albedo.{R,G,B}`, `normal.{X,Y,Z}`, `depth.Z`,
//! `variance.{R,G,B}`, `even.{R,G,B}`, the lighting split, ...), so a saved render reads back
//! as a frame. Pixels that saw no surface have zero first-hit AOVs.
//!
//! PNG: 8-bit sRGB. The tone map is deliberately simple and documented: multiply by
//! `2^exposure`, clamp each channel to [0, 1], apply the sRGB transfer curve.

use crate::{Film, NoisyFrame};
use exr::prelude::{
    AnyChannel, AnyChannels, Encoding, FlatSamples, Image, Layer, LayerAttributes, LineOrder,
    SmallVec, WritableImage,
};
use rt_core::{color::linear_to_srgb, Rgb, RgbImage};
use std::fs::File;
use std::io::{BufWriter, Write};
use std::path::{Path, PathBuf};

/// Errors from writing or reading images.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum FilmError {
    /// The extension is neither `.exr` nor `.png`.
    #[error("{0}: unsupported output format (use .exr or .png)")]
    Format(PathBuf),
    /// File-system trouble.
    #[error("{path}: {source}")]
    Io {
        /// The file.
        path: PathBuf,
        /// The cause.
        source: std::io::Error,
    },
    /// The encoder or decoder failed.
    #[error("{path}: {message}")]
    Codec {
        /// The file.
        path: PathBuf,
        /// What went wrong.
        message: String,
    },
}

/// How to write the film.
#[derive(Clone, Copy, Debug, Default)]
pub struct OutputOptions {
    /// PNG exposure in stops.
    pub exposure: f32,
}

/// Writes the film to `path`, choosing the format by extension (`.exr` or `.png`).
pub fn write_image(path: &Path, film: &Film, opts: &OutputOptions) -> Result<(), FilmError> {
    write_image_with(path, film, opts, &[])
}

/// [`write_image`] with further per-pixel channels (name, one value per pixel, row-major),
/// such as the stopping criterion's block map, which are not film buffers. EXR only: a PNG
/// holds the beauty image alone, so extra channels there are an error.
pub fn write_image_with(
    path: &Path,
    film: &Film,
    opts: &OutputOptions,
    extra: &[(&str, Vec<f32>)],
) -> Result<(), FilmError> {
    let pixels = film.width() as usize * film.height() as usize;
    if let Some((name, _)) = extra.iter().find(|(_, v)| v.len() != pixels) {
        return Err(codec(
            path,
            format!("channel {name} does not have one value per pixel"),
        ));
    }
    let ext = path
        .extension()
        .and_then(|e| e.to_str())
        .map(str::to_ascii_lowercase);
    match ext.as_deref() {
        Some("exr") => ExrImage::of_film(film, extra)
            .map_err(|message| codec(path, message))?
            .write(path),
        Some("png") if !extra.is_empty() => Err(FilmError::Codec {
            path: path.to_path_buf(),
            message: "a PNG holds only the beauty image; write an .exr for extra channels".into(),
        }),
        Some("png") => write_atomic(path, |w| {
            write_png(w, film.width(), film.height(), &film.mean_image(), opts)
        }),
        _ => Err(FilmError::Format(path.to_path_buf())),
    }
}

/// Writes a plain linear RGB image to `path`, by extension: `.exr` (channels `R`, `G`, `B`,
/// linear float) or `.png` (tone mapped as the film's beauty image). Atomic like
/// [`write_image`]. For images that are not a film, e.g. references and error maps.
pub fn write_rgb(path: &Path, image: &RgbImage, opts: &OutputOptions) -> Result<(), FilmError> {
    let (width, height, pixels) = (image.width(), image.height(), image.pixels());
    let size = match (u32::try_from(width), u32::try_from(height)) {
        (Ok(w), Ok(h)) => (w, h),
        _ => {
            return Err(FilmError::Codec {
                path: path.to_path_buf(),
                message: format!("a {width}x{height} image is too large to write"),
            })
        }
    };
    let ext = path
        .extension()
        .and_then(|e| e.to_str())
        .map(str::to_ascii_lowercase);
    match ext.as_deref() {
        Some("exr") => ExrImage::of_rgb(image).write(path),
        Some("png") => write_atomic(path, |w| write_png(w, size.0, size.1, pixels, opts)),
        _ => Err(FilmError::Format(path.to_path_buf())),
    }
}

/// Writes `bytes` to `path` atomically (a temporary file in the same directory, synced, then
/// renamed over `path`): for CSVs, reports and sidecars, so every file the renderer writes is
/// either whole or absent.
pub fn write_bytes_atomic(path: &Path, bytes: &[u8]) -> Result<(), FilmError> {
    write_atomic(path, |w| w.write_all(bytes).map_err(|e| e.to_string()))
}

/// Copies `from` to `to` atomically.
pub fn copy_atomic(from: &Path, to: &Path) -> Result<(), FilmError> {
    let bytes = std::fs::read(from).map_err(|source| FilmError::Io {
        path: from.to_path_buf(),
        source,
    })?;
    write_bytes_atomic(to, &bytes)
}

/// Writes through a temporary file in the same directory, then renames it over `path`, so
/// readers never see a half-written image and an interrupted run leaves the old file (or none).
fn write_atomic(
    path: &Path,
    write: impl FnOnce(&mut BufWriter<File>) -> Result<(), String>,
) -> Result<(), FilmError> {
    let io = |source| FilmError::Io {
        path: path.to_path_buf(),
        source,
    };
    let dir = match path.parent() {
        Some(d) if !d.as_os_str().is_empty() => d.to_path_buf(),
        _ => PathBuf::from("."),
    };
    let name = path
        .file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .unwrap_or_default();
    let tmp = dir.join(format!(".{name}.{}.tmp", std::process::id()));
    let result = (|| {
        let file = File::create(&tmp).map_err(io)?;
        let mut w = BufWriter::new(file);
        write(&mut w).map_err(|message| FilmError::Codec {
            path: path.to_path_buf(),
            message,
        })?;
        let file = w.into_inner().map_err(|e| io(e.into_error()))?;
        file.sync_all().map_err(io)?;
        std::fs::rename(&tmp, path).map_err(io)
    })();
    if result.is_err() {
        let _ = std::fs::remove_file(&tmp);
    }
    result
}

/// A codec error about `path`.
fn codec(path: &Path, message: String) -> FilmError {
    FilmError::Codec {
        path: path.to_path_buf(),
        message,
    }
}

/// No NaN or Inf may reach a file (the film rejects them on entry; this is the last guard):
/// such values become 0.
fn finite(values: &mut [f32]) {
    for v in values.iter_mut().filter(|v| !v.is_finite()) {
        *v = 0.0;
    }
}

fn write_exr_channels(
    w: &mut BufWriter<File>,
    size: (usize, usize),
    chans: SmallVec<[AnyChannel<FlatSamples>; 4]>,
) -> Result<(), String> {
    let layer = Layer::new(
        size,
        LayerAttributes::default(),
        // Tiles in increasing order: the file's bytes then depend on the image only, not on
        // which compression thread finished first (equal renders give equal files).
        Encoding {
            line_order: LineOrder::Increasing,
            ..Encoding::FAST_LOSSLESS
        },
        AnyChannels::sort(chans),
    );
    Image::from_layer(layer)
        .write()
        .to_buffered(w)
        .map_err(|e| e.to_string())
}

/// One linear channel as an 8-bit PNG value: scaled by `scale` (`2^exposure`), clamped to
/// [0, 1] (NaN and infinities to 0), sRGB transfer curve, rounded. The one tone map of PNG
/// outputs and of `render view`'s window.
pub fn srgb8(v: f32, scale: f32) -> u8 {
    let v = if v.is_finite() {
        (v * scale).clamp(0.0, 1.0)
    } else {
        0.0
    };
    (linear_to_srgb(v) * 255.0 + 0.5) as u8
}

fn write_png(
    w: &mut BufWriter<File>,
    width: u32,
    height: u32,
    pixels: &[Rgb],
    opts: &OutputOptions,
) -> Result<(), String> {
    let scale = 2f32.powf(opts.exposure);
    let bytes: Vec<u8> = pixels
        .iter()
        .flat_map(|p| p.to_array())
        .map(|v| srgb8(v, scale))
        .collect();
    let img = image::RgbImage::from_raw(width, height, bytes).ok_or("image size mismatch")?;
    img.write_to(w, image::ImageFormat::Png)
        .map_err(|e| e.to_string())?;
    w.flush().map_err(|e| e.to_string())
}

/// An EXR's image in memory: named float channels of equal size. What a render's EXR output
/// holds is made as one ([`ExrImage::of_film`], [`ExrImage::of_rgb`]) and then written
/// ([`ExrImage::write`]) or handed over as it is (the Python module's arrays), so the two are
/// the same bits; [`read_exr`] reads a file back as one.
#[derive(Clone, Debug, PartialEq)]
pub struct ExrImage {
    /// Width.
    pub width: usize,
    /// Height.
    pub height: usize,
    /// Channels by full name (e.g. `R`, `albedo.G`), row-major.
    pub channels: Vec<(String, Vec<f32>)>,
}

impl ExrImage {
    /// The image an EXR of `chans` (name, one value per pixel of `size`, row-major) holds:
    /// non-finite values are 0 and the channels are in the file's order (by name), as
    /// [`read_exr`] would read the file back. Refuses a channel without one value per pixel.
    pub fn from_channels(
        size: (usize, usize),
        mut chans: Vec<(String, Vec<f32>)>,
    ) -> Result<ExrImage, String> {
        let pixels = size.0 * size.1;
        if let Some((name, _)) = chans.iter().find(|(_, v)| v.len() != pixels) {
            return Err(format!("channel {name} does not have one value per pixel"));
        }
        for (_, values) in &mut chans {
            finite(values);
        }
        // The order `AnyChannels::sort` gives the file: by name, byte by byte.
        chans.sort_by(|a, b| a.0.cmp(&b.0));
        Ok(ExrImage {
            width: size.0,
            height: size.1,
            channels: chans,
        })
    }

    /// What an EXR output of `film` holds ([`write_image_with`]): the beauty image and the
    /// film's AOVs as [`NoisyFrame`] lays them out, then the `extra` channels.
    pub fn of_film(film: &Film, extra: &[(&str, Vec<f32>)]) -> Result<ExrImage, String> {
        // Sample records are never written: do not copy them into the frame.
        let aovs = crate::AovSet {
            samples: false,
            ..film.aovs()
        };
        NoisyFrame::from_film(film, aovs).exr_image(extra)
    }

    /// What an EXR output of a plain RGB image holds ([`write_rgb`]): channels `R`, `G`, `B`.
    pub fn of_rgb(image: &RgbImage) -> ExrImage {
        let pixels = image.pixels();
        let chans = ["R", "G", "B"]
            .iter()
            .enumerate()
            .map(|(c, n)| (n.to_string(), pixels.iter().map(|p| p[c]).collect()))
            .collect();
        Self::from_channels((image.width(), image.height()), chans).expect("one value per pixel")
    }

    /// Writes the image to `path` as an EXR (float32, lossless), atomically.
    pub fn write(self, path: &Path) -> Result<(), FilmError> {
        let size = (self.width, self.height);
        let pixels = size.0 * size.1;
        if let Some((name, _)) = self.channels.iter().find(|(_, v)| v.len() != pixels) {
            let message = format!("channel {name} does not have one value per pixel");
            return Err(codec(path, message));
        }
        let chans = self
            .channels
            .into_iter()
            .map(|(name, mut values)| {
                finite(&mut values);
                AnyChannel::new(name.as_str(), FlatSamples::F32(values))
            })
            .collect();
        write_atomic(path, |w| write_exr_channels(w, size, chans))
    }

    /// A channel by name.
    pub fn channel(&self, name: &str) -> Option<&[f32]> {
        self.channels
            .iter()
            .find(|(n, _)| n == name)
            .map(|(_, v)| v.as_slice())
    }

    /// The `R`, `G`, `B` channels (with optional `prefix`, e.g. `"variance."`) as pixels.
    pub fn rgb(&self, prefix: &str) -> Option<Vec<Rgb>> {
        let r = self.channel(&format!("{prefix}R"))?;
        let g = self.channel(&format!("{prefix}G"))?;
        let b = self.channel(&format!("{prefix}B"))?;
        Some((0..r.len()).map(|i| Rgb::new(r[i], g[i], b[i])).collect())
    }
}

/// How many times its size in bytes an EXR file may claim to decode to. Real files compress
/// by far less (ZIP and PIZ by a few times; a constant image by deflate's limit, about 1000);
/// a header that claims more is refused before the decoder allocates what it claims.
const EXR_MAX_EXPANSION: u64 = 1024;
/// What any EXR file may claim to decode to, however small: 64 MiB.
const EXR_MIN_BUDGET: u64 = 64 << 20;

/// Refuses an EXR file whose headers claim far more samples than its bytes could hold (the
/// decoder would allocate them all up front; fuzzing found a 500-byte file claiming 13 TB).
fn check_exr_claims(path: &Path) -> Result<(), FilmError> {
    let codec = |message: String| FilmError::Codec {
        path: path.to_path_buf(),
        message,
    };
    let file_len = std::fs::metadata(path)
        .map_err(|source| FilmError::Io {
            path: path.to_path_buf(),
            source,
        })?
        .len();
    let meta =
        exr::meta::MetaData::read_from_file(path, false).map_err(|e| codec(e.to_string()))?;
    let claimed = meta.headers.iter().fold(0u64, |sum, h| {
        let area = (h.layer_size.0 as u64).saturating_mul(h.layer_size.1 as u64);
        let channels = h.channels.list.len() as u64;
        sum.saturating_add(area.saturating_mul(channels).saturating_mul(4))
    });
    let budget = file_len
        .saturating_mul(EXR_MAX_EXPANSION)
        .max(EXR_MIN_BUDGET);
    if claimed > budget {
        return Err(codec(format!(
            "the header claims {claimed} bytes of samples, more than a {file_len}-byte file can hold"
        )));
    }
    Ok(())
}

/// Reads every channel of the first layer of an EXR file as f32.
pub fn read_exr(path: &Path) -> Result<ExrImage, FilmError> {
    use exr::prelude::{read, ReadChannels, ReadLayers};
    let err = |e: exr::error::Error| FilmError::Codec {
        path: path.to_path_buf(),
        message: e.to_string(),
    };
    check_exr_claims(path)?;
    let img = read()
        .no_deep_data()
        .largest_resolution_level()
        .all_channels()
        .first_valid_layer()
        .all_attributes()
        .from_file(path)
        .map_err(err)?;
    let layer = img.layer_data;
    let channels = layer
        .channel_data
        .list
        .into_iter()
        .map(|c| {
            let v: Vec<f32> = c.sample_data.values_as_f32().collect();
            (c.name.to_string(), v)
        })
        .collect();
    Ok(ExrImage {
        width: layer.size.0,
        height: layer.size.1,
        channels,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::{AovSet, FirstHit};

    fn small_film() -> Film {
        let mut film = Film::new(
            4,
            3,
            AovSet {
                albedo: true,
                depth: true,
                variance: true,
                ..Default::default()
            },
        );
        for mut s in film.stripes_mut(1) {
            for x in 0..4 {
                let y = s.y0;
                let hit = FirstHit {
                    albedo: Rgb::splat(0.5),
                    depth: 3.0,
                    ..Default::default()
                };
                s.add_sample(x, y, 0, Rgb::new(x as f32, y as f32, 1.0), Some(&hit));
                s.add_sample(x, y, 1, Rgb::new(x as f32, y as f32, 3.0), Some(&hit));
            }
        }
        film
    }

    #[test]
    fn exr_bytes_do_not_depend_on_compression_threads() {
        // 64 tiles compressed in parallel: without a fixed line order the tiles land in the
        // file in completion order, so equal images gave different files.
        let (w, h) = (512, 512);
        let pixels: Vec<Rgb> = (0..w * h)
            .map(|i| Rgb::new((i % 7) as f32, (i % 13) as f32 * 0.5, (i / w) as f32))
            .collect();
        let dir = tempfile::tempdir().unwrap();
        let files: Vec<Vec<u8>> = (0..6)
            .map(|k| {
                let p = dir.path().join(format!("{k}.exr"));
                write_rgb(
                    &p,
                    &RgbImage::new(w, h, pixels.clone()).unwrap(),
                    &OutputOptions::default(),
                )
                .unwrap();
                std::fs::read(p).unwrap()
            })
            .collect();
        assert!(files.windows(2).all(|f| f[0] == f[1]));
    }

    #[test]
    fn exr_round_trips_beauty_and_aovs() {
        let dir = tempfile::tempdir().unwrap();
        let p = dir.path().join("a.exr");
        write_image(&p, &small_film(), &OutputOptions::default()).unwrap();
        let img = read_exr(&p).unwrap();
        assert_eq!((img.width, img.height), (4, 3));
        let rgb = img.rgb("").unwrap();
        assert_eq!(rgb[4 + 2], Rgb::new(2.0, 1.0, 2.0));
        assert_eq!(img.channel("depth.Z").unwrap()[5], 3.0);
        assert_eq!(img.rgb("albedo.").unwrap()[0], Rgb::splat(0.5));
        assert_eq!(img.rgb("variance.").unwrap()[0].z, 1.0);
        assert!(img.channel("normal.X").is_none());
        // No temporary file is left behind.
        assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 1);
    }

    #[test]
    fn the_image_in_memory_is_the_one_the_exr_reads_back() {
        // Extra channels out of name order, one of them not finite: the file holds them
        // sorted, the NaN as 0; the image in memory must say the same.
        let film = small_film();
        let extra = [
            ("zeta", (0..12).map(|i| i as f32).collect()),
            ("blocks.spp", vec![f32::NAN; 12]),
        ];
        let dir = tempfile::tempdir().unwrap();
        let p = dir.path().join("a.exr");
        write_image_with(&p, &film, &OutputOptions::default(), &extra).unwrap();
        let memory = ExrImage::of_film(&film, &extra).unwrap();
        assert_eq!(memory, read_exr(&p).unwrap());
        assert_eq!(memory.channel("blocks.spp"), Some(&[0.0; 12][..]));
        let image = RgbImage::new(4, 3, film.mean_image()).unwrap();
        write_rgb(&p, &image, &OutputOptions::default()).unwrap();
        assert_eq!(ExrImage::of_rgb(&image), read_exr(&p).unwrap());
    }

    #[test]
    fn png_is_written_and_bad_extension_or_directory_fail_cleanly() {
        let dir = tempfile::tempdir().unwrap();
        write_image(
            &dir.path().join("a.png"),
            &small_film(),
            &OutputOptions::default(),
        )
        .unwrap();
        let img = image::open(dir.path().join("a.png")).unwrap().to_rgb8();
        assert_eq!(img.get_pixel(1, 0).0, [255, 0, 255]);
        assert!(matches!(
            write_image(
                &dir.path().join("a.jpg"),
                &small_film(),
                &OutputOptions::default()
            ),
            Err(FilmError::Format(_))
        ));
        let e = write_image(
            &dir.path().join("nope/a.exr"),
            &small_film(),
            &OutputOptions::default(),
        );
        assert!(e.unwrap_err().to_string().contains("nope/a.exr"));
    }

    #[test]
    fn plain_rgb_images_round_trip() {
        let dir = tempfile::tempdir().unwrap();
        let px: Vec<Rgb> = (0..6).map(|i| Rgb::new(i as f32 / 5.0, 0.5, 1.0)).collect();
        let opts = OutputOptions::default();
        let image = RgbImage::new(3, 2, px.clone()).unwrap();
        write_rgb(&dir.path().join("a.exr"), &image, &opts).unwrap();
        let img = read_exr(&dir.path().join("a.exr")).unwrap();
        assert_eq!((img.width, img.height), (3, 2));
        assert_eq!(img.rgb("").unwrap(), px);
        write_rgb(&dir.path().join("a.png"), &image, &opts).unwrap();
        let png = image::open(dir.path().join("a.png")).unwrap().to_rgb8();
        assert_eq!(png.dimensions(), (3, 2));
        assert_eq!(png.get_pixel(2, 1).0, [255, 188, 255]);
        assert!(write_rgb(&dir.path().join("b.tga"), &image, &opts).is_err());
        assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 2);
    }
}
