//! Scene text shared by the CLI's integration tests.

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
