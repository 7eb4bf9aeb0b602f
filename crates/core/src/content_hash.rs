//! Hashing what a scene renders as, for content-keyed caches (the reference cache of
//! `rt-experiment`): every value that reaches the renderer, floats by their bits, sequences
//! with their lengths, so two scenes hash alike exactly when they hold the same data. Derived
//! data (the light sampler, the environment's importance map) and measurements (build times)
//! are left out: they follow from the rest or do not change the image.
//!
//! The hash function is the caller's: [`ContentHash::content_hash`] feeds bytes to a sink, which
//! may be SHA-256 (stable across Rust releases, unlike `std`'s `DefaultHasher`).
//! Implementations destructure their type completely, so a field added later does not compile
//! until it is hashed or said not to matter.

use glam::{Vec2, Vec3};

/// A sink of bytes, e.g. a hash's `update`.
pub type Sink<'a> = dyn FnMut(&[u8]) + 'a;

/// Values that can feed their rendered content to a hash.
pub trait ContentHash {
    /// Feeds `self` to `out`.
    fn content_hash(&self, out: &mut Sink<'_>);
}

impl ContentHash for f32 {
    fn content_hash(&self, out: &mut Sink<'_>) {
        out(&self.to_bits().to_le_bytes());
    }
}

impl ContentHash for u32 {
    fn content_hash(&self, out: &mut Sink<'_>) {
        out(&self.to_le_bytes());
    }
}

impl ContentHash for u64 {
    fn content_hash(&self, out: &mut Sink<'_>) {
        out(&self.to_le_bytes());
    }
}

impl ContentHash for usize {
    fn content_hash(&self, out: &mut Sink<'_>) {
        (*self as u64).content_hash(out);
    }
}

impl ContentHash for bool {
    fn content_hash(&self, out: &mut Sink<'_>) {
        out(&[u8::from(*self)]);
    }
}

impl ContentHash for str {
    fn content_hash(&self, out: &mut Sink<'_>) {
        self.len().content_hash(out);
        out(self.as_bytes());
    }
}

impl ContentHash for String {
    fn content_hash(&self, out: &mut Sink<'_>) {
        self.as_str().content_hash(out);
    }
}

impl ContentHash for Vec2 {
    fn content_hash(&self, out: &mut Sink<'_>) {
        self.x.content_hash(out);
        self.y.content_hash(out);
    }
}

impl ContentHash for Vec3 {
    fn content_hash(&self, out: &mut Sink<'_>) {
        self.x.content_hash(out);
        self.y.content_hash(out);
        self.z.content_hash(out);
    }
}

impl<T: ContentHash, const N: usize> ContentHash for [T; N] {
    fn content_hash(&self, out: &mut Sink<'_>) {
        for v in self {
            v.content_hash(out);
        }
    }
}

impl<T: ContentHash> ContentHash for Option<T> {
    fn content_hash(&self, out: &mut Sink<'_>) {
        match self {
            None => out(&[0]),
            Some(v) => {
                out(&[1]);
                v.content_hash(out);
            }
        }
    }
}

impl<T: ContentHash> ContentHash for [T] {
    fn content_hash(&self, out: &mut Sink<'_>) {
        self.len().content_hash(out);
        for v in self {
            v.content_hash(out);
        }
    }
}

impl<T: ContentHash> ContentHash for Vec<T> {
    fn content_hash(&self, out: &mut Sink<'_>) {
        self.as_slice().content_hash(out);
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::{Camera, Material, Rgb, Scene};

    fn digest(v: &impl ContentHash) -> Vec<u8> {
        let mut bytes = Vec::new();
        v.content_hash(&mut |b: &[u8]| bytes.extend_from_slice(b));
        bytes
    }

    fn scene() -> Scene {
        let mut s = Scene::empty();
        s.materials.push(Material::diffuse("m", Rgb::splat(0.5)));
        s.push_triangle([Vec3::ZERO, Vec3::X, Vec3::Y], 0);
        s.cameras.push(Camera::look_at(
            "c",
            Vec3::Z,
            Vec3::ZERO,
            Vec3::Y,
            40.0,
            4,
            2,
            0.0,
            1.0,
        ));
        s.build_lights();
        s
    }

    #[test]
    fn equal_content_hashes_alike_and_every_change_shows() {
        let base = digest(&scene());
        assert_eq!(base, digest(&scene()));
        let mut moved = scene();
        moved.triangles[0][1].x = f32::from_bits(1.0f32.to_bits() + 1);
        assert_ne!(base, digest(&moved), "one ulp of one vertex");
        let mut brighter = scene();
        brighter.materials[0].emission = Rgb::splat(1e-30);
        assert_ne!(base, digest(&brighter));
        let mut wider = scene();
        wider.cameras[0].width = 5;
        assert_ne!(base, digest(&wider));
        // -0.0 and 0.0 differ by their bits, and so may render differently (1/x).
        assert_ne!(digest(&0.0f32), digest(&-0.0f32));
        // Lengths are part of the hash: ["ab"] and ["a", "b"] differ.
        assert_ne!(
            digest(&vec!["ab".to_string()]),
            digest(&vec!["a".to_string(), "b".into()])
        );
    }
}
