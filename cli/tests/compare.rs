//! End-to-end tests of `render compare`: the printed metrics against hand-computed values, the
//! JSON form, the error image, and one clean error line (exit code 1, no panic) for each kind of
//! bad input.

use rt_core::Rgb;
use std::path::{Path, PathBuf};
use std::process::{Command, Output};

struct Dir(tempfile::TempDir);

impl Dir {
    fn new() -> Self {
        Self(tempfile::tempdir().unwrap())
    }

    fn path(&self, name: &str) -> PathBuf {
        self.0.path().join(name)
    }

    /// Writes a linear image as EXR or PNG (by extension) through the renderer's own writer.
    fn image(&self, name: &str, w: usize, h: usize, f: impl Fn(usize, usize) -> Rgb) -> PathBuf {
        let px: Vec<Rgb> = (0..h)
            .flat_map(|y| (0..w).map(move |x| (x, y)))
            .map(|(x, y)| f(x, y))
            .collect();
        let p = self.path(name);
        let image = rt_core::RgbImage::new(w, h, px).unwrap();
        rt_film::write_rgb(&p, &image, &Default::default()).unwrap();
        p
    }

    fn render(&self, args: &[&str]) -> Output {
        Command::new(env!("CARGO_BIN_EXE_render"))
            .current_dir(self.0.path())
            .args(args)
            .output()
            .unwrap()
    }

    fn files(&self) -> usize {
        std::fs::read_dir(self.0.path()).unwrap().count()
    }
}

/// Runs `render compare ARGS`, expects success and returns `name → value` from the text output,
/// checking the keys and their order.
fn metrics(d: &Dir, args: &[&str]) -> Vec<(String, f64)> {
    let out = d.render(&[&["compare"], args].concat());
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let rows: Vec<(String, f64)> = stdout
        .lines()
        .map(|l| {
            let (k, v) = l
                .split_once(' ')
                .unwrap_or_else(|| panic!("bad line {l:?}"));
            (
                k.to_string(),
                v.parse().unwrap_or_else(|_| panic!("bad value {l:?}")),
            )
        })
        .collect();
    let keys: Vec<&str> = rows.iter().map(|(k, _)| k.as_str()).collect();
    assert_eq!(
        keys,
        [
            "mse",
            "relmse",
            "rmse",
            "psnr",
            "ssim",
            "relmse_epsilon",
            "psnr_peak"
        ]
    );
    rows
}

fn get(rows: &[(String, f64)], key: &str) -> f64 {
    rows.iter().find(|(k, _)| k == key).unwrap().1
}

/// Runs `render compare ARGS` and expects exit code 1 with one error line containing `needles`
/// and nothing on stdout.
fn expect_error(d: &Dir, args: &[&str], needles: &[&str]) {
    let out = d.render(&[&["compare"], args].concat());
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(1), "stderr: {err}");
    assert!(!err.contains("panicked"), "{err}");
    assert_eq!(
        err.lines().count(),
        1,
        "expected one error line, got: {err}"
    );
    assert!(err.starts_with("error: "), "{err}");
    assert!(
        err.matches("os error").count() <= 1,
        "cause repeated: {err}"
    );
    for n in needles {
        assert!(err.contains(n), "error should mention {n:?}: {err}");
    }
    assert!(
        out.stdout.is_empty(),
        "{}",
        String::from_utf8_lossy(&out.stdout)
    );
}

fn gradient(x: usize, y: usize) -> Rgb {
    Rgb::new(x as f32 / 16.0, y as f32 / 12.0, 0.5)
}

#[test]
fn identical_images_have_zero_error_and_ssim_one() {
    let d = Dir::new();
    d.image("a.exr", 16, 12, gradient);
    let rows = metrics(&d, &["a.exr", "a.exr"]);
    assert_eq!(get(&rows, "mse"), 0.0);
    assert_eq!(get(&rows, "relmse"), 0.0);
    assert_eq!(get(&rows, "rmse"), 0.0);
    assert_eq!(get(&rows, "psnr"), f64::INFINITY);
    assert_eq!(get(&rows, "ssim"), 1.0);
    let out = String::from_utf8(d.render(&["compare", "a.exr", "a.exr"]).stdout).unwrap();
    assert!(
        out.starts_with("mse 0\nrelmse 0\nrmse 0\npsnr inf\nssim 1\n"),
        "{out}"
    );
}

#[test]
fn a_known_pair_gives_the_hand_computed_values() {
    let d = Dir::new();
    // A is 0.5 everywhere; B's four pixels are grey 0.5, 0.75, 0.25 and 1 (exact in f32).
    d.image("a.exr", 2, 2, |_, _| Rgb::splat(0.5));
    let b = [0.5, 0.75, 0.25, 1.0];
    d.image("b.exr", 2, 2, |x, y| Rgb::splat(b[y * 2 + x]));
    let mse = (0.0 + 0.0625 + 0.0625 + 0.25) / 4.0;
    let rel = |eps: f64| {
        (0.0 + 0.0625 / (0.5625 + eps) + 0.0625 / (0.0625 + eps) + 0.25 / (1.0 + eps)) / 4.0
    };
    let close = |a: f64, b: f64| (a - b).abs() <= 1e-12 * b.abs();
    let rows = metrics(&d, &["a.exr", "b.exr"]);
    assert!(close(get(&rows, "mse"), mse), "{rows:?}");
    assert!(close(get(&rows, "relmse"), rel(0.01)), "{rows:?}");
    assert!(close(get(&rows, "rmse"), mse.sqrt()), "{rows:?}");
    assert!(
        close(get(&rows, "psnr"), 10.0 * (1.0 / mse).log10()),
        "{rows:?}"
    );
    assert_eq!(get(&rows, "relmse_epsilon"), 0.01);
    assert!(get(&rows, "ssim") < 1.0);
    // The options change exactly what they should.
    let rows = metrics(&d, &["a.exr", "b.exr", "--epsilon", "1", "--peak", "2"]);
    assert!(close(get(&rows, "relmse"), rel(1.0)), "{rows:?}");
    assert!(
        close(get(&rows, "psnr"), 10.0 * (4.0 / mse).log10()),
        "{rows:?}"
    );
    assert_eq!(
        (get(&rows, "relmse_epsilon"), get(&rows, "psnr_peak")),
        (1.0, 2.0)
    );
    // B is the reference: swapping the images changes relMSE but not MSE.
    let swapped = metrics(&d, &["b.exr", "a.exr"]);
    assert!(close(get(&swapped, "mse"), mse));
    let rel_swapped = (0.0625 + 0.0625 + 0.25) / 4.0 / (0.25 + 0.01);
    assert!(close(get(&swapped, "relmse"), rel_swapped), "{swapped:?}");
}

#[test]
fn json_output_has_the_five_keys() {
    let d = Dir::new();
    d.image("a.exr", 16, 12, gradient);
    d.image("b.exr", 16, 12, |x, y| gradient(x, y) * 0.9);
    let out = d.render(&["compare", "a.exr", "b.exr", "--json"]);
    assert!(out.status.success());
    let text = String::from_utf8(out.stdout).unwrap();
    assert_eq!(text.lines().count(), 1, "{text}");
    let v: serde_json::Value = serde_json::from_str(&text).unwrap();
    let obj = v.as_object().unwrap();
    for k in ["mse", "relmse", "rmse", "psnr", "ssim", "relmse_epsilon"] {
        assert!(obj[k].as_f64().is_some_and(f64::is_finite), "{k} in {text}");
    }
    assert_eq!(obj["relmse_epsilon"].as_f64(), Some(0.01));
    // Identical images: PSNR is infinite, which JSON spells null.
    let out = d.render(&["compare", "a.exr", "a.exr", "--json"]);
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert!(v["psnr"].is_null());
    assert_eq!(v["mse"].as_f64(), Some(0.0));
    assert_eq!(v["ssim"].as_f64(), Some(1.0));
}

#[test]
fn error_image_is_written_atomically_at_the_right_size() {
    let d = Dir::new();
    d.image("a.exr", 20, 10, gradient);
    d.image("b.exr", 20, 10, |x, y| {
        gradient(x, y) + Rgb::splat(if x < 10 { 0.0 } else { 0.3 })
    });
    metrics(&d, &["a.exr", "b.exr", "--error-image", "err.png"]);
    let png = image::open(d.path("err.png")).unwrap().to_rgb8();
    assert_eq!(png.dimensions(), (20, 10));
    // Zero error (left half) and large error (right half) get different ends of the map.
    assert_ne!(png.get_pixel(0, 0), png.get_pixel(19, 0));
    metrics(&d, &["a.exr", "b.exr", "--error-image", "err.exr"]);
    let exr = rt_film::read_exr(&d.path("err.exr")).unwrap();
    assert_eq!((exr.width, exr.height), (20, 10));
    // The two inputs and the two error images; no temporary files.
    assert_eq!(d.files(), 4);
    expect_error(
        &d,
        &["a.exr", "b.exr", "--error-image", "missing-dir/e.png"],
        &["missing-dir/e.png: No such file"],
    );
    expect_error(
        &d,
        &["a.exr", "b.exr", "--error-image", "e.tga"],
        &["e.tga", "unsupported"],
    );
}

#[test]
fn png_inputs_are_decoded_to_linear() {
    let d = Dir::new();
    d.image("a.exr", 8, 8, |_, _| Rgb::new(0.5, 0.2, 0.9));
    // The PNG stores the same linear values sRGB-encoded in 8 bits.
    d.image("a.png", 8, 8, |_, _| Rgb::new(0.5, 0.2, 0.9));
    let rows = metrics(&d, &["a.png", "a.exr"]);
    assert!(get(&rows, "mse") < 1e-5, "{rows:?}");
    assert!(get(&rows, "ssim") > 0.9999, "{rows:?}");
}

#[test]
fn size_mismatch_is_one_error_line() {
    let d = Dir::new();
    d.image("a.exr", 4, 3, gradient);
    d.image("b.exr", 2, 2, gradient);
    expect_error(&d, &["a.exr", "b.exr"], &["a.exr is 4x3 but b.exr is 2x2"]);
    expect_error(
        &d,
        &["a.exr", "b.exr", "--error-image", "e.png"],
        &["a.exr is 4x3 but b.exr is 2x2"],
    );
    assert!(!d.path("e.png").exists());
}

fn exr_with_nan(path: &Path) {
    exr::prelude::write_rgb_file(path, 4, 3, |x, y| {
        let g = if (x, y) == (2, 1) { f32::NAN } else { 0.5 };
        (0.5f32, g, 0.5f32)
    })
    .unwrap();
}

#[test]
fn non_finite_values_are_one_error_line_naming_the_file_and_pixel() {
    let d = Dir::new();
    d.image("a.exr", 4, 3, gradient);
    exr_with_nan(&d.path("nan.exr"));
    expect_error(
        &d,
        &["nan.exr", "a.exr"],
        &["nan.exr has a non-finite value (NaN) at pixel (2, 1), channel G"],
    );
    expect_error(&d, &["a.exr", "nan.exr"], &["nan.exr", "(2, 1)"]);
}

#[test]
fn unreadable_inputs_are_one_error_line_naming_the_file() {
    let d = Dir::new();
    d.image("a.exr", 4, 3, gradient);
    std::fs::write(d.path("junk.exr"), "not an exr").unwrap();
    std::fs::write(d.path("junk.png"), "not a png").unwrap();
    std::fs::write(d.path("a.tiff"), "").unwrap();
    expect_error(&d, &["a.exr", "missing.exr"], &["missing.exr"]);
    expect_error(&d, &["junk.exr", "a.exr"], &["junk.exr"]);
    expect_error(&d, &["junk.png", "a.exr"], &["junk.png"]);
    expect_error(&d, &["a.tiff", "a.exr"], &["a.tiff", "unsupported"]);
    // Alpha is ignored.
    exr::prelude::write_rgba_file(d.path("z.exr"), 2, 2, |_, _| {
        (0.0f32, 0.0f32, 0.0f32, 1.0f32)
    })
    .unwrap();
    let out = d.render(&["compare", "z.exr", "z.exr"]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    // Bad option values are usage errors (exit 2).
    let out = d.render(&["compare", "a.exr", "a.exr", "--epsilon", "-1"]);
    assert_eq!(out.status.code(), Some(2));
}

#[test]
fn region_measures_only_its_pixels() {
    let d = Dir::new();
    // B is flat; A differs from it by 0.5 in the left half only.
    d.image("b.exr", 8, 4, |_, _| Rgb::splat(0.5));
    d.image("a.exr", 8, 4, |x, _| {
        Rgb::splat(if x < 4 { 1.0 } else { 0.5 })
    });
    let mse = |args: &[&str]| metrics(&d, &[&["a.exr", "b.exr"], args].concat())[0].1;
    assert_eq!(mse(&["--region", "4,0,8,4"]), 0.0);
    assert!((mse(&["--region", "0,1,4,3"]) - 0.25).abs() < 1e-12);
    assert!((mse(&[]) - 0.125).abs() < 1e-12);
    expect_error(
        &d,
        &["a.exr", "b.exr", "--region", "2,0,9,4"],
        &["--region 2,0,9,4", "8x4 image a.exr"],
    );
    expect_error(
        &d,
        &["a.exr", "b.exr", "--region", "3,0,3,4"],
        &["non-empty"],
    );
}
