//! Writes the small HDR sky that `scenes/environment.toml` is lit by.
//!
//! ```text
//! cargo run -p rt-scene --example make_sky -- scenes/sky.exr
//! ```
//!
//! A 256×128 equirectangular map in the renderer's orientation (`rt_core::environment`: row 0
//! is the zenith, +y up, the centre column looks along −z, `u` grows towards +x): a blue sky
//! that brightens towards the horizon, a darker ground below it, and a sun disk of 3° radius
//! at 35° elevation, behind the default camera's right shoulder (towards +x, +z). Each texel
//! is the mean of 4×4 samples so the sun's edge is antialiased. RGB, 32-bit float, ZIP.

// `exr`'s pixel position type is named apart from glam's `Vec2`.
use exr::math::Vec2 as Vec2Usize;
use exr::prelude::*;
use glam::{Vec2, Vec3};
use rt_core::environment::uv_to_dir;

const WIDTH: usize = 256;
const HEIGHT: usize = 128;
/// Angular radius of the sun disk, degrees. The real sun's 0.27° would be a fraction of a
/// texel at this resolution.
const SUN_RADIUS_DEG: f32 = 3.0;
/// Sun radiance. The disk covers 2π(1 − cos 3°) ≈ 0.0086 sr, so at 35° elevation it gives the
/// ground an irradiance of about 0.0049 × L ≈ 2.9, twice what the sky (mean radiance ≈ 0.5,
/// irradiance ≈ 1.5) gives: clear shadows that the sky still fills, and a mid-grey ground
/// that stays below 1 (no clipping) without exposure tricks.
const SUN_RADIANCE: Vec3 = Vec3::new(640.0, 580.0, 500.0);

fn sun_direction() -> Vec3 {
    let elevation = 35f32.to_radians();
    // Azimuth measured from -z towards +x: 135° puts the sun behind-right of a camera that
    // looks along -z.
    let azimuth = 135f32.to_radians();
    Vec3::new(
        elevation.cos() * azimuth.sin(),
        elevation.sin(),
        -elevation.cos() * azimuth.cos(),
    )
}

/// Sky radiance towards direction `d` (unit).
fn radiance(d: Vec3) -> Vec3 {
    let sun = sun_direction();
    let base = if d.y >= 0.0 {
        // Zenith blue to a pale horizon.
        let t = (1.0 - d.y).powi(3);
        let zenith = Vec3::new(0.18, 0.32, 0.75);
        let horizon = Vec3::new(0.85, 0.9, 1.0);
        zenith.lerp(horizon, t)
    } else {
        // Ground: a warm grey, darker straight down.
        let t = (-d.y).powf(0.5);
        Vec3::new(0.32, 0.28, 0.24).lerp(Vec3::new(0.12, 0.11, 0.1), t)
    };
    // A soft glow around the sun, then the disk.
    let cos = d.dot(sun);
    let glow = Vec3::new(1.0, 0.9, 0.7) * 0.6 * cos.max(0.0).powi(64);
    let disk = if cos >= SUN_RADIUS_DEG.to_radians().cos() {
        SUN_RADIANCE
    } else {
        Vec3::ZERO
    };
    base + glow + disk
}

fn main() {
    let out = std::env::args()
        .nth(1)
        .unwrap_or_else(|| "scenes/sky.exr".to_string());
    const SS: usize = 4;
    let mut texels = vec![Vec3::ZERO; WIDTH * HEIGHT];
    for y in 0..HEIGHT {
        for x in 0..WIDTH {
            let mut sum = Vec3::ZERO;
            for j in 0..SS {
                for i in 0..SS {
                    let uv = Vec2::new(
                        (x as f32 + (i as f32 + 0.5) / SS as f32) / WIDTH as f32,
                        (y as f32 + (j as f32 + 0.5) / SS as f32) / HEIGHT as f32,
                    );
                    sum += radiance(uv_to_dir(uv));
                }
            }
            texels[y * WIDTH + x] = sum / (SS * SS) as f32;
        }
    }
    let channels = SpecificChannels::rgb(|Vec2Usize(x, y): Vec2Usize<usize>| {
        let t = texels[y * WIDTH + x];
        (t.x, t.y, t.z)
    });
    Image::from_encoded_channels((WIDTH, HEIGHT), Encoding::SMALL_LOSSLESS, channels)
        .write()
        .to_file(&out)
        .unwrap_or_else(|e| panic!("cannot write {out}: {e}"));
    println!(
        "wrote {out} ({WIDTH}x{HEIGHT}), sun towards {}",
        sun_direction()
    );
}
