//! End-to-end tests of `render --gree`: the composite, label map and error maps are written,
//! the samples traced are reported, and bad combinations are one error line.

mod common;

use common::{one_error_line, render};

#[test]
fn gree_writes_its_outputs_and_refuses_what_it_cannot_do() {
    let d = tempfile::tempdir().unwrap();
    let dir = d.path();
    let camera = "[[camera]]\nname = \"c\"\nposition = [0.0, 1.0, 2.5]\nlook_at = [0.0, 0.0, 0.0]\nfov = 50.0\nresolution = [32, 24]\n";
    std::fs::write(
        dir.join("s.toml"),
        format!("{camera}{}", common::FLOOR_AND_LAMP),
    )
    .unwrap();
    std::fs::write(
        dir.join("bank.toml"),
        "denoisers = [\"box:radius=0\", \"box:radius=1\", \"box:radius=4\"]\n",
    )
    .unwrap();
    let out = render(
        dir,
        &[
            "s.toml",
            "--spp",
            "8",
            "--gree",
            "sparsity=0.9",
            "--bank",
            "bank.toml",
            "-o",
            "g.exr",
            "--labels",
            "labels.png",
            "--error-maps",
            "maps",
        ],
    );
    assert!(out.status.success(), "{out:?}");
    let text = String::from_utf8_lossy(&out.stdout);
    // b = 8, n = 7, s = 0.9: c = (8 - 0.9·7)/0.1 = 17 spp at round(0.1·768) = 77 caches.
    let traced = 7 * 768 + 77 * 17;
    assert!(text.contains(&format!("{traced} samples traced")), "{text}");
    assert!(text.contains("n=7 spp, 77 caches x 17 spp"), "{text}");
    let composite = rt_film::read_rgb(&dir.join("g.exr")).unwrap();
    assert_eq!((composite.width(), composite.height()), (32, 24));
    assert!(composite.pixels().iter().all(|p| p.is_finite()));
    assert!(dir.join("labels.png").exists());
    let maps = std::fs::read_dir(dir.join("maps")).unwrap().count();
    assert_eq!(maps, 6, "an EXR and a PNG per filter");

    for (args, says) in [
        (vec!["--gree", "kappa=2"], "kappa"),
        (vec!["--gree", "--integrator", "light"], "cannot"),
        (vec!["--gree", "--aov", "albedo"], "composite only"),
        (vec!["--gree", "--bank", "missing.toml"], "missing.toml"),
    ] {
        let all = [vec!["s.toml", "--spp", "8", "-o", "x.exr"], args.clone()].concat();
        let err = one_error_line(&render(dir, &all));
        assert!(err.contains(says), "{args:?}: {err}");
    }
    assert!(!dir.join("x.exr").exists());
}
