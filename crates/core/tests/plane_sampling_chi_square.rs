//! χ² goodness of fit of plane sampling (Dammertz 2011, §6.4.2; digest §1.9, claims 15–16),
//! the start of every light path from the environment (`LightSampler::sample_emission`, which
//! the light tracer, BDPT and the partitioned renderer's VPL walks call): the travel
//! directions follow the environment's pdf (reversed: the map is indexed towards the sky),
//! the start points are uniform over the covering rectangle perpendicular to the direction,
//! the rectangle covers the box's projection and lies upstream of it, and the particle's
//! throughput is `L / (p(y) p(ω))` with the pdfs it reports.
//!
//! The scene has an environment map and one emissive triangle, so the environment is chosen
//! half the time and that choice is tested too. Samples are independent (`rt_testkit::Rng`),
//! as in `light_sampling.rs`; the two χ² tests are judged at a Šidák-corrected level.

use rt_core::environment::{EnvMap, Environment};
use rt_core::frame::Frame;
use rt_core::glam::Vec3;
use rt_core::{Aabb, Material, Rgb, Scene};
use rt_testkit::chi2;
use rt_testkit::Rng;

const FAMILY_ALPHA: f64 = 0.01;
const TESTS: usize = 2;
/// Light paths drawn (about half from the environment).
const N: usize = 600_000;
/// Cells per side of the start-point test over the rectangle.
const GRID: usize = 20;

/// The map of `light_sampling.rs`: a broad bright patch and a dark band, far from uniform.
fn sky() -> Environment {
    let (w, h) = (64u32, 32u32);
    let texels = (0..w * h)
        .map(|i| {
            let (x, y) = ((i % w) as f32 / w as f32, (i / w) as f32 / h as f32);
            let patch = (-((x - 0.5).powi(2) + (y - 0.3).powi(2)) / 0.01).exp() * 8.0;
            let band = if (0.6..0.7).contains(&y) { 0.05 } else { 1.0 };
            Rgb::new(
                0.4 + patch,
                0.5 + 0.8 * patch,
                0.7 * (1.0 - y) + 0.5 * patch,
            ) * band
        })
        .collect();
    Environment::Map(EnvMap::new(w, h, texels))
}

fn scene() -> Scene {
    let mut scene = Scene::empty();
    let mut m = Material::diffuse("light", Rgb::splat(0.5));
    m.emission = Rgb::splat(2.0);
    scene.materials.push(m);
    scene.push_triangle(
        [
            Vec3::new(-1.0, 0.0, 2.0),
            Vec3::new(1.0, 0.0, 2.0),
            Vec3::new(0.0, 0.5, 3.0),
        ],
        0,
    );
    scene.environment = sky();
    scene.build_lights();
    scene
}

/// The box's projection along `dir` in `Frame::from_normal(dir)`: (min x, min y, max x, max y)
/// and the most upstream corner's depth.
fn projection(bounds: &Aabb, dir: Vec3) -> ([f32; 4], f32) {
    let frame = Frame::from_normal(dir);
    let mut r = [f32::INFINITY, f32::INFINITY, -f32::INFINITY, -f32::INFINITY];
    let mut upstream = f32::INFINITY;
    for i in 0..8 {
        let c = Vec3::new(
            if i & 1 == 0 {
                bounds.min.x
            } else {
                bounds.max.x
            },
            if i & 2 == 0 {
                bounds.min.y
            } else {
                bounds.max.y
            },
            if i & 4 == 0 {
                bounds.min.z
            } else {
                bounds.max.z
            },
        );
        let l = frame.to_local(c);
        r = [r[0].min(l.x), r[1].min(l.y), r[2].max(l.x), r[3].max(l.y)];
        upstream = upstream.min(l.z);
    }
    (r, upstream)
}

#[test]
fn plane_sampled_starts_follow_the_environment_pdf_and_cover_the_box_uniformly() {
    let scene = scene();
    let lights = scene.lights();
    let env = &scene.environment;
    // An asymmetric, flat box: its projection changes shape a lot with the direction.
    let bounds = Aabb::new(Vec3::new(-1.0, 0.0, 2.0), Vec3::new(3.0, 0.5, 4.0));
    let alpha = chi2::sidak(FAMILY_ALPHA, TESTS);

    let mut rng = Rng::new(0x91a7e);
    let mut dirs = vec![0.0; chi2::THETA_BINS * chi2::PHI_BINS];
    let mut starts = vec![0.0; GRID * GRID];
    let (mut from_env, mut outside, mut downstream, mut bad_area, mut bad_beta) = (0, 0, 0, 0, 0);
    for _ in 0..N {
        let (u_sel, u_pos, u_dir) = (rng.f32(), rng.vec2(), rng.vec2());
        let Some(e) = lights.sample_emission(&scene, &bounds, u_sel, u_pos, u_dir) else {
            continue;
        };
        if e.point.is_some() {
            continue;
        }
        from_env += 1;
        // The environment is looked up towards the sky: against the travel direction.
        let towards_sky = -e.dir;
        dirs[chi2::bin_of(towards_sky)] += 1.0;

        let (r, upstream) = projection(&bounds, e.dir);
        let l = Frame::from_normal(e.dir).to_local(e.origin);
        let s = (l.x - r[0]) / (r[2] - r[0]);
        let t = (l.y - r[1]) / (r[3] - r[1]);
        // The rectangle is the projection grown by a relative 1e-4 of the box's extent.
        let slack = 1e-3;
        if !(-slack..=1.0 + slack).contains(&s) || !(-slack..=1.0 + slack).contains(&t) {
            outside += 1;
        }
        let cell = |x: f32| ((x.clamp(0.0, 1.0) * GRID as f32) as usize).min(GRID - 1);
        starts[cell(t) * GRID + cell(s)] += 1.0;
        if l.z >= upstream {
            downstream += 1;
        }
        let area = (r[2] - r[0]) * (r[3] - r[1]);
        if (e.pdf_position * area - 1.0).abs() > 1e-2 {
            bad_area += 1;
        }
        // beta = L / (p(y) p(ω)), with the pdfs the particle reports (p(ω) includes the
        // choice of the environment).
        let l_env = env.radiance(towards_sky);
        let back = e.beta * (e.pdf_position * e.pdf_direction);
        if ((back - l_env).abs() / l_env.max_element()).max_element() > 1e-3 {
            bad_beta += 1;
        }
    }

    // The environment is chosen half the time (the light sampler's rule when both emit).
    let p = 0.5;
    let sd = (N as f64 * p * (1.0 - p)).sqrt();
    eprintln!(
        "{from_env} of {N} from the environment (expect {:.0} ± {sd:.0})",
        N as f64 * p
    );
    assert!(
        (from_env as f64 - N as f64 * p).abs() < 5.0 * sd,
        "{from_env} of {N} light paths from the environment"
    );
    assert_eq!(outside, 0, "start points outside the box's projection");
    assert_eq!(downstream, 0, "start points not upstream of the box");
    assert_eq!(bad_area, 0, "1 / pdf_position is not the rectangle's area");
    assert_eq!(
        bad_beta, 0,
        "beta · p(y) · p(ω) is not the environment's radiance"
    );

    let expected = chi2::expected(|d| env.pdf(d) as f64, 8);
    let total: f64 = expected.iter().sum();
    assert!((total - 1.0).abs() < 1e-2, "pdf integrates to {total}");
    let r = chi2::test(&dirs, &expected, from_env);
    eprintln!("directions: {r:?}, α {alpha:.2e}");
    assert!(
        r.passes(alpha),
        "plane-sampled directions do not follow the environment's pdf: {r:?}"
    );

    let uniform = vec![1.0 / (GRID * GRID) as f64; GRID * GRID];
    let r = chi2::test(&starts, &uniform, from_env);
    eprintln!("start points: {r:?}, α {alpha:.2e}");
    assert!(
        r.passes(alpha),
        "start points are not uniform over the rectangle: {r:?}"
    );
}
