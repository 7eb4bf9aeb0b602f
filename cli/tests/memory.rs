//! `render --max-memory`: a render whose estimated film, per-sample records and structure
//! exceed the limit is refused with one line giving the estimate, before anything is rendered
//! or written; a render within it runs; sizes that do not parse are one line too.

mod common;

use common::{one_error_line, render};

fn scene(dir: &std::path::Path, resolution: &str) {
    let camera = format!(
        "[[camera]]\nname = \"c\"\nposition = [0.0, 1.0, 2.5]\nlook_at = [0.0, 0.0, 0.0]\nresolution = {resolution}\n"
    );
    std::fs::write(
        dir.join("s.toml"),
        format!("{camera}{}", common::FLOOR_AND_LAMP),
    )
    .unwrap();
}

#[test]
fn renders_that_cannot_fit_are_refused_before_they_start() {
    let d = tempfile::tempdir().unwrap();
    let dir = d.path();
    scene(dir, "[64, 48]");
    // 64 × 48 pixels: a 16-byte mean per pixel is 48 KiB; every AOV and the records of 256
    // samples per pixel (56 B each) are far more.
    let o = render(
        dir,
        &[
            "s.toml",
            "--spp",
            "2",
            "--max-memory",
            "1M",
            "-q",
            "-o",
            "a.exr",
        ],
    );
    assert!(o.status.success(), "{o:?}");
    let o = render(
        dir,
        &["s.toml", "--spp", "2", "--max-memory", "20K", "-o", "b.exr"],
    );
    let e = one_error_line(&o);
    assert!(
        e.contains("needs an estimated") && e.contains("(--max-memory)"),
        "{e}"
    );
    assert!(!dir.join("b.exr").exists());
    let o = render(
        dir,
        &[
            "s.toml",
            "--spp",
            "256",
            "--denoiser",
            "sbmf",
            "--max-memory",
            "16M",
            "-o",
            "c.exr",
        ],
    );
    let e = one_error_line(&o);
    assert!(e.contains("per-sample records 42.0 MiB"), "{e}");
    // A film of 2^26 pixels with every AOV is tens of GiB: refused at once, nothing allocated.
    scene(dir, "[8192, 8192]");
    let o = render(
        dir,
        &[
            "s.toml",
            "--spp",
            "1",
            "--aov",
            "denoise",
            "--max-memory",
            "2G",
            "-o",
            "d.exr",
        ],
    );
    let e = one_error_line(&o);
    assert!(e.contains("GiB (film"), "{e}");
    for bad in ["lots", "0", "3X"] {
        let o = render(dir, &["s.toml", "--max-memory", bad, "-o", "e.exr"]);
        let e = one_error_line(&o);
        assert!(e.contains(&format!("--max-memory {bad}")), "{e}");
    }
}
