//! Scene text and helpers shared by the CLI's integration tests.

// Each test binary compiles this module and uses part of it.
#![allow(dead_code)]

/// A white floor two units across under a small square lamp two units above it, without a
/// camera: each test puts its own `[[camera]]` (and any `[render]` table) around it.
pub const FLOOR_AND_LAMP: &str = r#"
[[material]]
name = "white"
color = [0.7, 0.7, 0.7]

[[material]]
name = "lamp"
emission = [5.0, 5.0, 5.0]

[[geometry]]
name = "floor"
shape = "quad"
vertices = [[-1, 0, 1], [1, 0, 1], [1, 0, -1], [-1, 0, -1]]
material = "white"

[[geometry]]
name = "light"
shape = "quad"
vertices = [[-0.3, 2, -0.3], [0.3, 2, -0.3], [0.3, 2, 0.3], [-0.3, 2, 0.3]]
material = "lamp"
"#;

/// A box that slides and turns across a lit floor between keys at 0 and 2 s, seen by a
/// 12 × 8 camera: the animated scene of the `--frames`, `--shutter` and `bench-anim` tests.
pub const MOVING_BOX: &str = r#"
[[camera]]
name = "cam"
position = [0, 1, 3]
look_at = [0, 0.5, 0]
resolution = [12, 8]

[[material]]
name = "white"
color = [0.7, 0.7, 0.7]

[[material]]
name = "lamp"
emission = [5, 5, 5]

[[geometry]]
name = "floor"
shape = "quad"
vertices = [[-2, 0, 2], [2, 0, 2], [2, 0, -2], [-2, 0, -2]]
material = "white"

[[geometry]]
name = "light"
shape = "quad"
vertices = [[-0.3, 2, -0.3], [0.3, 2, -0.3], [0.3, 2, 0.3], [-0.3, 2, 0.3]]
material = "lamp"

[[geometry]]
name = "box"
shape = "box"
min = [-0.3, 0, -0.3]
max = [0.3, 0.6, 0.3]
material = "white"

[[animation]]
target = "box"
keys = [ { time = 0.0, translate = [-1, 0, 0] }, { time = 2.0, translate = [1, 0, 0], rotate = [0, 90, 0] } ]
"#;

/// Runs `render ARGS` in `dir`.
pub fn render(dir: &std::path::Path, args: &[&str]) -> std::process::Output {
    std::process::Command::new(env!("CARGO_BIN_EXE_render"))
        .current_dir(dir)
        .args(args)
        .output()
        .unwrap()
}

/// Checks that `out` failed with status 1 and one error line, no panic; returns the line.
pub fn one_error_line(out: &std::process::Output) -> String {
    assert_eq!(out.status.code(), Some(1), "{out:?}");
    let err = String::from_utf8_lossy(&out.stderr).into_owned();
    assert_eq!(err.lines().count(), 1, "{err}");
    assert!(!err.contains("panicked"), "{err}");
    err
}
