//! What SVGF keeps from one frame for the next: the features its reprojection tests compare, the
//! reflected hits its searches match against, and the filtered colour, the luminance moments and
//! the history length of both signals.

use super::features::{Class, Features};
use rt_core::glam::Vec3;
use rt_core::Rgb;
use rt_film::GuideBuffers;

/// The previous frame, flat in row-major order.
#[derive(Clone, Debug)]
pub struct History {
    pub w: usize,
    pub h: usize,
    pub class: Vec<Class>,
    /// Primary view depth.
    pub depth: Vec<f32>,
    /// Primary shading normal.
    pub normal: Vec<Vec3>,
    pub object: Vec<u32>,
    /// Primary hit position (origin of the representative ray).
    pub position: Vec<Vec3>,
    pub reflected_position: Vec<Vec3>,
    pub reflected_direction: Vec<Vec3>,
    /// 0 where the pixel has no reflection.
    pub reflected_distance: Vec<f32>,
    /// Demodulated colour of the direct and indirect signal (the feedback tap's output).
    pub colour: [Vec<Rgb>; 2],
    /// Temporally accumulated luminance moments.
    pub moments: [Vec<[f32; 2]>; 2],
    pub length: Vec<f32>,
}

impl History {
    /// The part of a history that comes from the frame's features and guides; colour, moments
    /// and lengths are filled by the caller.
    pub fn from_frame(f: &Features, g: &GuideBuffers) -> Self {
        let n = f.w * f.h;
        let (rp, rd, rt) = match &g.reflected {
            Some(r) => (
                r.position.pixels().to_vec(),
                r.direction.pixels().to_vec(),
                r.distance.pixels().to_vec(),
            ),
            None => (vec![Vec3::ZERO; n], vec![Vec3::ZERO; n], vec![0.0; n]),
        };
        Self {
            w: f.w,
            h: f.h,
            class: f.class.clone(),
            depth: f.primary_depth.clone(),
            normal: g.normal.pixels().to_vec(),
            object: f.object.clone(),
            position: g.position.pixels().to_vec(),
            reflected_position: rp,
            reflected_direction: rd,
            reflected_distance: rt,
            colour: [vec![Rgb::ZERO; n], vec![Rgb::ZERO; n]],
            moments: [vec![[0.0; 2]; n], vec![[0.0; 2]; n]],
            length: vec![0.0; n],
        }
    }

    /// Overwrites the part [`History::from_frame`] makes with frame `f`'s, reusing the
    /// buffers (a history of the same size).
    pub fn refill(&mut self, f: &Features, g: &GuideBuffers) {
        assert_eq!((self.w, self.h), (f.w, f.h), "history of another size");
        self.class.copy_from_slice(&f.class);
        self.depth.copy_from_slice(&f.primary_depth);
        self.normal.copy_from_slice(g.normal.pixels());
        self.object.copy_from_slice(&f.object);
        self.position.copy_from_slice(g.position.pixels());
        match &g.reflected {
            Some(r) => {
                self.reflected_position.copy_from_slice(r.position.pixels());
                self.reflected_direction
                    .copy_from_slice(r.direction.pixels());
                self.reflected_distance.copy_from_slice(r.distance.pixels());
            }
            None => {
                self.reflected_position.fill(Vec3::ZERO);
                self.reflected_direction.fill(Vec3::ZERO);
                self.reflected_distance.fill(0.0);
            }
        }
    }
}
