//! Linear RGB to the window's pixels: the PNG rule of `render` (`rt_film::srgb8`), packed as
//! softbuffer's `0x00RRGGBB`.

use rayon::prelude::*;
use rt_core::Rgb;

/// One channel to 8 bits.
fn encode(v: f32, scale: f32) -> u32 {
    u32::from(rt_film::srgb8(v, scale))
}

/// One pixel as `0x00RRGGBB`.
pub fn pack(p: Rgb, scale: f32) -> u32 {
    (encode(p.x, scale) << 16) | (encode(p.y, scale) << 8) | encode(p.z, scale)
}

/// Writes the `width` x `height` image `pixels` (row-major) into `out`, a `out_width` x
/// `out_height` buffer, scaled to fill it by nearest neighbour (1:1 when the sizes agree).
pub fn blit(
    pixels: &[Rgb],
    (width, height): (usize, usize),
    out: &mut [u32],
    (out_width, out_height): (usize, usize),
    exposure: f32,
) {
    let scale = 2f32.powf(exposure);
    if width == 0 || height == 0 || out_width == 0 {
        return;
    }
    out.par_chunks_mut(out_width)
        .take(out_height)
        .enumerate()
        .for_each(|(y, row)| {
            let sy = (y * height / out_height).min(height - 1);
            let src = &pixels[sy * width..(sy + 1) * width];
            for (x, o) in row.iter_mut().enumerate() {
                *o = pack(src[(x * width / out_width).min(width - 1)], scale);
            }
        });
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn packs_like_the_png_rule() {
        assert_eq!(pack(Rgb::ZERO, 1.0), 0);
        assert_eq!(pack(Rgb::ONE, 1.0), 0x00ff_ffff);
        assert_eq!(
            pack(Rgb::new(f32::NAN, f32::INFINITY, 7.0), 1.0),
            0x0000_00ff
        );
        // 0.5 linear is 188 in sRGB; one stop down from 1.0 is the same.
        assert_eq!(pack(Rgb::new(0.5, 0.0, 0.0), 1.0), 188 << 16);
        assert_eq!(pack(Rgb::new(1.0, 0.0, 0.0), 0.5), 188 << 16);
    }

    #[test]
    fn blit_scales_by_nearest_neighbour() {
        let px = [Rgb::ZERO, Rgb::ONE];
        let mut out = [7u32; 8];
        blit(&px, (2, 1), &mut out, (4, 2), 0.0);
        let w = 0x00ff_ffff;
        assert_eq!(out, [0, 0, w, w, 0, 0, w, w]);
    }
}
