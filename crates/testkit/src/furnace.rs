//! White-furnace scenes: objects of one material under a constant environment of radiance
//! [`L`], placed so that light inter-reflects between them (a single convex object would be too
//! easy). The sphere is faceted: interpolated shading normals make any renderer lose (or gain)
//! energy, which is a different question.

/// The environment's radiance.
pub const L: f32 = 0.5;

/// The furnace scene with material `material` (the TOML body of a `[[material]]` table without
/// its name), a 24 × 24 camera.
pub fn scene_toml(material: &str) -> String {
    format!(
        r#"
[environment]
color = [{L}, {L}, {L}]

[[camera]]
name = "c"
position = [0.0, 1.2, 4.0]
look_at = [0.0, 0.5, 0.0]
up = [0.0, 1.0, 0.0]
fov = 40.0
resolution = [24, 24]

[[material]]
name = "m"
{material}

[[geometry]]
name = "slab"
shape = "box"
min = [-1.5, -0.2, -1.5]
max = [1.5, 0.0, 1.5]
material = "m"

[[geometry]]
name = "ball"
shape = "sphere"
center = [-0.45, 0.45, 0.0]
radius = 0.45
subdivisions = 2
smooth = false
material = "m"

[[geometry]]
name = "block"
shape = "box"
min = [0.05, 0.0, -0.5]
max = [0.85, 1.2, 0.3]
material = "m"
"#
    )
}
