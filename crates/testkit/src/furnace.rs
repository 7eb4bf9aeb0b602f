//! White-furnace scenes: objects of one material under a constant environment of radiance
//! [`L`], placed so that light inter-reflects between them (a single convex object would be too
//! easy). The sphere is faceted: interpolated shading normals make any renderer lose (or gain)
//! energy, which is a different question. And the one-bounce furnace: a plane seen through a
//! narrow camera, whose one-bounce image is the environment times the directional albedo.

/// The environment's radiance.
pub const L: f32 = 0.5;

/// The environment of radiance [`L`], one camera and the material `m` (`material`: the TOML
/// body of a `[[material]]` table without its name): what both furnace scenes share.
fn header(material: &str, camera: &str) -> String {
    format!(
        "[environment]\ncolor = [{L}, {L}, {L}]\n\n[[camera]]\nname = \"c\"\n{camera}\n\n\
         [[material]]\nname = \"m\"\n{material}\n"
    )
}

/// The furnace scene with material `material`, a 24 × 24 camera.
pub fn scene_toml(material: &str) -> String {
    let camera = "position = [0.0, 1.2, 4.0]\nlook_at = [0.0, 0.5, 0.0]\nup = [0.0, 1.0, 0.0]\n\
                  fov = 40.0\nresolution = [24, 24]";
    header(material, camera)
        + r#"
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
}

/// The one-bounce furnace: the plane `z = 0` (normal +z, 200 across) of material `material`,
/// seen from polar angle `theta` through a 4 × 4 camera of 1° field of view, so that every
/// pixel's `wo` is within 0.5° of that angle and every bounce escapes to the environment.
pub fn one_bounce_plane_toml(material: &str, theta: f32) -> String {
    let (s, c) = theta.sin_cos();
    let camera = format!(
        "position = [{}, 0.0, {}]\nlook_at = [0.0, 0.0, 0.0]\nup = [0.0, 0.0, 1.0]\n\
         fov = 1.0\nresolution = [4, 4]",
        3.0 * s,
        3.0 * c
    );
    header(material, &camera)
        + r#"
[[geometry]]
name = "plane"
shape = "quad"
vertices = [[-100.0, -100.0, 0.0], [100.0, -100.0, 0.0], [100.0, 100.0, 0.0], [-100.0, 100.0, 0.0]]
material = "m"
"#
}

/// The furnace image's mean and its standard error for `material` at `spp`, from the path
/// tracer with light sampling, without it, and from the wavefront tracer (seeds 1, 2, 3).
pub fn tracer_means(material: &str, spp: u32) -> Vec<(f64, f64)> {
    use rt_integrators::{PathIntegrator, Wavefront, DEFAULT_LANES};
    let scene = crate::scene_from_toml(&scene_toml(material));
    let mean = crate::stats::image_mean;
    let mut out = vec![
        mean(&crate::render(&scene, &PathIntegrator::new(1000), spp, 1)),
        mean(&crate::render(
            &scene,
            &PathIntegrator::bsdf_only(1000),
            spp,
            2,
        )),
    ];
    let wavefront = Wavefront::new(PathIntegrator::new(1000), DEFAULT_LANES);
    let buffers = rt_film::FilmBuffers::for_outputs(rt_film::AovSet::default()).with_variance();
    let (film, _) = crate::Renderer::new(&scene)
        .threads(2)
        .render_technique(&wavefront, buffers, spp, 3);
    out.push(mean(&film));
    out
}

/// True if every tracer's furnace image of `material` (64 spp) is the environment [`L`] within
/// 4 standard errors.
pub fn lossless(material: &str) -> bool {
    tracer_means(material, 64)
        .iter()
        .all(|&(mean, se)| (mean - L as f64).abs() <= 4.0 * se + 1e-4)
}
