//! Scene text shared by tests.

/// A 32 × 24 camera looking at a white floor six units across under a square lamp, with a
/// white and a red material defined for the objects a test adds (the animation and motion
/// blur tests put moving boxes on it).
pub const LIT_FLOOR: &str = r#"
[[camera]]
name = "cam"
position = [0, 1.5, 4]
look_at = [0, 0.4, 0]
resolution = [32, 24]

[[material]]
name = "white"
color = [0.7, 0.7, 0.7]

[[material]]
name = "red"
color = [0.8, 0.2, 0.1]

[[material]]
name = "lamp"
emission = [6, 6, 6]

[[geometry]]
name = "floor"
shape = "quad"
vertices = [[-3, 0, 3], [3, 0, 3], [3, 0, -3], [-3, 0, -3]]
material = "white"

[[geometry]]
name = "light"
shape = "quad"
vertices = [[-0.5, 2.5, -0.5], [0.5, 2.5, -0.5], [0.5, 2.5, 0.5], [-0.5, 2.5, 0.5]]
material = "lamp"
"#;
