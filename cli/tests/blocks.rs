//! `render --error V --aov blocks`: the stopping criterion's final blocks as EXR channels
//! `blocks.index`, `blocks.spp` and `blocks.converged`, read back and checked for what a block
//! map must be: every block a rectangle whose pixels took the same number of samples, every
//! block converged when the render says so, and unconverged blocks at the cap.

use std::collections::HashMap;
use std::process::Command;

mod common;

fn scene_dir() -> tempfile::TempDir {
    let dir = tempfile::tempdir().unwrap();
    let scene = format!(
        "[[camera]]\nname = \"main\"\nposition = [0.0, 1.0, 3.0]\nlook_at = [0.0, 0.5, 0.0]\n\
         fov = 45.0\nresolution = [64, 48]\n{}\n[render]\nmax_depth = 3\n",
        common::FLOOR_AND_LAMP
    );
    std::fs::write(dir.path().join("scene.toml"), scene).unwrap();
    dir
}

fn render(dir: &tempfile::TempDir, args: &[&str]) -> std::process::Output {
    Command::new(env!("CARGO_BIN_EXE_render"))
        .current_dir(dir.path())
        .arg("scene.toml")
        .args(args)
        .output()
        .unwrap()
}

/// Per block index: its pixels' bounding box, pixel count, sample counts and converged flags.
struct BlockSeen {
    min: (usize, usize),
    max: (usize, usize),
    pixels: usize,
    spp: Vec<f32>,
    converged: Vec<f32>,
}

fn blocks_of(path: &std::path::Path) -> (Vec<BlockSeen>, usize) {
    let exr = rt_film::read_exr(path).unwrap();
    let ch = |n: &str| {
        exr.channel(n)
            .unwrap_or_else(|| panic!("no channel {n}"))
            .to_vec()
    };
    let (index, spp, converged) = (ch("blocks.index"), ch("blocks.spp"), ch("blocks.converged"));
    let mut seen: HashMap<u32, BlockSeen> = HashMap::new();
    for (i, &b) in index.iter().enumerate() {
        let (x, y) = (i % exr.width, i / exr.width);
        let e = seen.entry(b as u32).or_insert(BlockSeen {
            min: (x, y),
            max: (x, y),
            pixels: 0,
            spp: Vec::new(),
            converged: Vec::new(),
        });
        e.min = (e.min.0.min(x), e.min.1.min(y));
        e.max = (e.max.0.max(x), e.max.1.max(y));
        e.pixels += 1;
        e.spp.push(spp[i]);
        e.converged.push(converged[i]);
    }
    (seen.into_values().collect(), exr.width * exr.height)
}

fn check_rectangles_of_equal_samples(blocks: &[BlockSeen], pixels: usize) {
    let mut covered = 0;
    for b in blocks {
        let area = (b.max.0 - b.min.0 + 1) * (b.max.1 - b.min.1 + 1);
        assert_eq!(b.pixels, area, "a block is not a rectangle");
        assert!(
            b.spp.iter().all(|&s| s == b.spp[0] && s > 0.0),
            "{:?}",
            b.spp
        );
        assert!(b.converged.iter().all(|&c| c == b.converged[0]));
        covered += b.pixels;
    }
    assert_eq!(covered, pixels);
}

#[test]
fn block_map_of_a_converged_render() {
    let dir = scene_dir();
    let o = render(
        &dir,
        &[
            "--error", "2e-3", "--spp", "512", "--aov", "blocks", "-o", "b.exr",
        ],
    );
    let out = String::from_utf8_lossy(&o.stdout);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    assert!(out.contains("converged"), "{out}");
    let (blocks, pixels) = blocks_of(&dir.path().join("b.exr"));
    check_rectangles_of_equal_samples(&blocks, pixels);
    assert!(blocks.len() > 1, "the criterion never split");
    assert!(blocks.iter().all(|b| b.converged[0] == 1.0));
    let spp: Vec<f32> = blocks.iter().map(|b| b.spp[0]).collect();
    assert!(
        spp.iter().any(|&s| s != spp[0]),
        "every block stopped at the same count: {spp:?}"
    );
}

#[test]
fn block_map_at_the_sample_cap() {
    let dir = scene_dir();
    let o = render(
        &dir,
        &[
            "--error", "1e-6", "--spp", "8", "--aov", "blocks", "-o", "b.exr",
        ],
    );
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let (blocks, pixels) = blocks_of(&dir.path().join("b.exr"));
    check_rectangles_of_equal_samples(&blocks, pixels);
    assert!(blocks
        .iter()
        .all(|b| b.converged[0] == 0.0 && b.spp[0] == 8.0));
}

#[test]
fn block_map_needs_the_criterion_and_an_exr() {
    let dir = scene_dir();
    for (args, message) in [
        (
            &["--aov", "blocks", "--spp", "2", "-o", "b.exr"][..],
            "--aov blocks writes the stopping criterion's blocks: it needs --error",
        ),
        (
            &["--aov", "blocks", "--error", "1e-2", "-o", "b.png"][..],
            "b.png: AOVs need an .exr output",
        ),
    ] {
        let o = render(&dir, args);
        let err = String::from_utf8_lossy(&o.stderr);
        assert!(!o.status.success());
        assert!(err.contains(message), "{err}");
        assert_eq!(err.lines().count(), 1, "{err}");
    }
}

/// The image of `scene.toml` (or `scene`, if given, written first) rendered with `args`, as an
/// estimate: the pixel means and the variances of those means (the `variance` AOV).
fn estimate(
    dir: &tempfile::TempDir,
    scene: Option<&str>,
    args: &[&str],
) -> rt_validate::stress::compare::Estimate {
    if let Some(text) = scene {
        std::fs::write(dir.path().join("scene.toml"), text).unwrap();
    }
    let o = render(dir, &[args, &["--aov", "variance", "-o", "e.exr"]].concat());
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let img = rt_film::read_exr(&dir.path().join("e.exr")).unwrap();
    rt_validate::stress::compare::Estimate {
        mean: img.rgb("").unwrap(),
        variance: img.rgb("variance.").unwrap(),
        runs: None,
    }
}

/// Adaptive stopping (`--error`) decides from the samples a block has seen when to stop, which
/// could bias what it stops at; the result must agree with a uniform render within noise (the
/// block z-test of `render stress`, 8 × 8 blocks and the whole image, α = 10⁻³, variances from
/// each render's own `variance` AOV). Control: the uniform render with the lamp 2 % brighter
/// must fail the same test, so a bias of that size would be seen.
#[test]
fn adaptive_renders_agree_with_a_uniform_render_within_noise() {
    use rt_validate::stress::compare::{compare_estimates, ALPHA};
    let dir = scene_dir();
    let text = std::fs::read_to_string(dir.path().join("scene.toml")).unwrap();
    let adaptive = estimate(&dir, None, &["--error", "2e-3", "--spp", "512"]);
    let uniform = estimate(&dir, None, &["--spp", "256", "--seed", "9"]);
    let c = compare_estimates(&adaptive, &uniform, 64, 8, ALPHA);
    eprintln!("adaptive against uniform: {c:?}");
    assert!(c.same_within_noise(), "adaptive render biased: {c:?}");
    let brighter = text.replace("emission = [5.0, 5.0, 5.0]", "emission = [5.1, 5.1, 5.1]");
    assert_ne!(brighter, text);
    let control = estimate(&dir, Some(&brighter), &["--spp", "256", "--seed", "9"]);
    let c = compare_estimates(&adaptive, &control, 64, 8, ALPHA);
    eprintln!("control, lamp 2 % brighter: {c:?}");
    assert!(
        !c.same_within_noise(),
        "control: a 2 % brighter lamp passes: {c:?}"
    );
}
