//! Keyframe animation: transforms of instances and cameras, and the emission of materials, as
//! functions of time.
//!
//! A [`Motion`] holds keys sorted by strictly increasing time. Translation and scale interpolate
//! linearly and rotation by quaternion slerp (the shorter arc) between the two keys around `t`;
//! before the first key and after the last the end keys hold. A [`CameraMotion`] does the same
//! for a camera's position, look-at point, up vector and field of view (all linear: a camera
//! is keyed by points, not by an orientation). A [`MaterialMotion`] keys a material's emitted
//! radiance, linearly or as a step function ([`Interpolation::Step`]: each key holds until the
//! next, so a light switch is two keys).
//!
//! Validation (keys in order, finite values, positive scale, a camera that can look) happens
//! when a motion is built, with a typed [`AnimationError`]: a scene loader turns it into one
//! line naming the file and the target.

use crate::material::MAX_RADIANCE;
use crate::transform::Transform;
use crate::Rgb;
use glam::{Mat4, Quat, Vec3};

/// One keyframe of a rigid transform.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Key {
    /// Time in seconds.
    pub time: f32,
    /// Translation.
    pub translate: Vec3,
    /// Rotation (from degrees about x, then y, then z, as `Transform::from_trs`).
    pub rotate: Quat,
    /// Scale per axis.
    pub scale: Vec3,
}

impl Key {
    /// A key from the scene file's form: translation, degrees about x then y then z, scale.
    pub fn from_trs(time: f32, translate: Vec3, rotate_deg: Vec3, scale: Vec3) -> Self {
        Self {
            time,
            translate,
            rotate: Quat::from_rotation_z(rotate_deg.z.to_radians())
                * Quat::from_rotation_y(rotate_deg.y.to_radians())
                * Quat::from_rotation_x(rotate_deg.x.to_radians()),
            scale,
        }
    }
}

/// What is wrong with a list of keys.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum AnimationError {
    /// No keys at all.
    #[error("an animation needs at least one key")]
    NoKeys,
    /// Times not strictly increasing.
    #[error("key {index} at time {time} is not after the key before it (times must increase)")]
    OutOfOrder {
        /// Index of the offending key.
        index: usize,
        /// Its time.
        time: f32,
    },
    /// A NaN or infinite value.
    #[error("key {index} has a value that is not finite ({what})")]
    NotFinite {
        /// Index of the offending key.
        index: usize,
        /// Which value.
        what: &'static str,
    },
    /// A zero or negative scale component.
    #[error("key {index} has a scale that is not positive")]
    BadScale {
        /// Index of the offending key.
        index: usize,
    },
    /// An emission that is negative or too large.
    #[error("key {index} has emission {value:?}: each component must be >= 0 and at most {MAX_RADIANCE:e}")]
    BadEmission {
        /// Index of the offending key.
        index: usize,
        /// The emission.
        value: [f32; 3],
    },
    /// A camera key that cannot define a view.
    #[error("camera key {index}: {what}")]
    BadCamera {
        /// Index of the offending key.
        index: usize,
        /// What is wrong.
        what: &'static str,
    },
}

/// Checks that times are finite and strictly increasing.
fn check_times(times: impl Iterator<Item = f32>) -> Result<usize, AnimationError> {
    let mut prev = f32::NEG_INFINITY;
    let mut n = 0;
    for (index, time) in times.enumerate() {
        if !time.is_finite() {
            return Err(AnimationError::NotFinite {
                index,
                what: "time",
            });
        }
        if time <= prev {
            return Err(AnimationError::OutOfOrder { index, time });
        }
        prev = time;
        n += 1;
    }
    if n == 0 {
        return Err(AnimationError::NoKeys);
    }
    Ok(n)
}

/// True if the key times `times` (increasing, at least one) span part of `(t0, t1)`.
fn spans(times: &[f32], t0: f32, t1: f32) -> bool {
    times[0] < t1 && times[times.len() - 1] > t0
}

/// The two keys around `t` and the blend weight of the second: `(i, i, 0)` outside the keys.
fn bracket(times: &[f32], t: f32) -> (usize, usize, f32) {
    let last = times.len() - 1;
    if t.is_nan() || t <= times[0] {
        return (0, 0, 0.0);
    }
    if t >= times[last] {
        return (last, last, 0.0);
    }
    // First key strictly after t: times[j - 1] <= t < times[j].
    let j = times.partition_point(|&k| k <= t);
    let (a, b) = (times[j - 1], times[j]);
    (j - 1, j, ((t - a) / (b - a)).clamp(0.0, 1.0))
}

/// A keyframed rigid transform.
#[derive(Clone, Debug, PartialEq)]
pub struct Motion {
    keys: Vec<Key>,
    times: Vec<f32>,
}

impl Motion {
    /// A motion through `keys` (times strictly increasing, values finite, scales positive).
    pub fn new(keys: Vec<Key>) -> Result<Self, AnimationError> {
        check_times(keys.iter().map(|k| k.time))?;
        for (index, k) in keys.iter().enumerate() {
            if !k.translate.is_finite() {
                return Err(AnimationError::NotFinite {
                    index,
                    what: "translate",
                });
            }
            if !k.rotate.is_finite() {
                return Err(AnimationError::NotFinite {
                    index,
                    what: "rotate",
                });
            }
            if !k.scale.is_finite() {
                return Err(AnimationError::NotFinite {
                    index,
                    what: "scale",
                });
            }
            if k.scale.min_element() <= 0.0 {
                return Err(AnimationError::BadScale { index });
            }
        }
        let times = keys.iter().map(|k| k.time).collect();
        Ok(Self { keys, times })
    }

    /// The keys.
    pub fn keys(&self) -> &[Key] {
        &self.keys
    }

    /// The keyed transform at time `t`.
    pub fn at(&self, t: f32) -> Transform {
        Transform::from_mat4(self.matrix_at(t))
    }

    /// The keyed transform's matrix at time `t`, without the normal matrix [`Motion::at`]
    /// inverts for: what a structure interpolating a moving instance per ray needs.
    pub fn matrix_at(&self, t: f32) -> Mat4 {
        let (i, j, w) = bracket(&self.times, t);
        let (a, b) = (&self.keys[i], &self.keys[j]);
        let translate = a.translate.lerp(b.translate, w);
        let scale = a.scale.lerp(b.scale, w);
        let rotate = if i == j {
            a.rotate
        } else {
            a.rotate.slerp(b.rotate, w)
        };
        Mat4::from_scale_rotation_translation(scale, rotate.normalize(), translate)
    }

    /// True if the keys span part of the interval `(t0, t1)`: the transform may change
    /// within it (before the first key and after the last it holds).
    pub fn spans(&self, t0: f32, t1: f32) -> bool {
        spans(&self.times, t0, t1)
    }

    /// True if the transform is the same at every time (one key, or all keys equal).
    pub fn is_static(&self) -> bool {
        self.keys.windows(2).all(|w| {
            w[0].translate == w[1].translate
                && w[0].rotate == w[1].rotate
                && w[0].scale == w[1].scale
        })
    }
}

/// One keyframe of a camera.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CameraKey {
    /// Time in seconds.
    pub time: f32,
    /// Centre of projection.
    pub position: Vec3,
    /// Point looked at.
    pub look_at: Vec3,
    /// Up direction.
    pub up: Vec3,
    /// Vertical field of view, degrees.
    pub fov: f32,
}

/// A keyframed camera: its pose and field of view at any time.
#[derive(Clone, Debug, PartialEq)]
pub struct CameraMotion {
    /// Index of the camera in the scene.
    pub camera: usize,
    keys: Vec<CameraKey>,
    times: Vec<f32>,
}

impl CameraMotion {
    /// A motion of camera `camera` through `keys`: times increasing, values finite, the
    /// position away from the look-at point, `up` not along the view, fov in (0°, 180°).
    pub fn new(camera: usize, keys: Vec<CameraKey>) -> Result<Self, AnimationError> {
        check_times(keys.iter().map(|k| k.time))?;
        for (index, k) in keys.iter().enumerate() {
            let bad = |what| Err(AnimationError::BadCamera { index, what });
            if !(k.position.is_finite() && k.look_at.is_finite() && k.up.is_finite()) {
                return bad("position, look_at and up must be finite");
            }
            if !(k.fov > 0.0 && k.fov < 180.0) {
                return bad("fov must be between 0 and 180 degrees");
            }
            let forward = (k.look_at - k.position).normalize_or_zero();
            if forward == Vec3::ZERO {
                return bad("position and look_at are the same point");
            }
            if forward.cross(k.up.normalize_or_zero()).length() < 1e-4 {
                return bad("up is parallel to the view direction");
            }
        }
        let times = keys.iter().map(|k| k.time).collect();
        Ok(Self {
            camera,
            keys,
            times,
        })
    }

    /// True if the camera moves within `(t0, t1)`: it has two keys or more and they span part
    /// of the interval.
    pub fn spans(&self, t0: f32, t1: f32) -> bool {
        self.times.len() > 1 && spans(&self.times, t0, t1)
    }

    /// The keys.
    pub fn keys(&self) -> &[CameraKey] {
        &self.keys
    }

    /// The camera's key values at time `t`. Between two keys that are valid views the blend
    /// can still be degenerate (position crossing look_at); the caller keeps the last good
    /// camera then.
    pub fn at(&self, t: f32) -> CameraKey {
        let (i, j, w) = bracket(&self.times, t);
        let (a, b) = (&self.keys[i], &self.keys[j]);
        CameraKey {
            time: t,
            position: a.position.lerp(b.position, w),
            look_at: a.look_at.lerp(b.look_at, w),
            up: a.up.lerp(b.up, w),
            fov: a.fov + (b.fov - a.fov) * w,
        }
    }
}

/// How a keyed value moves between two keys.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Interpolation {
    /// Linearly from one key's value to the next.
    #[default]
    Linear,
    /// Each key's value holds until the next key's time, where it jumps: a switch.
    Step,
}

/// One keyframe of a material's emission.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct EmissionKey {
    /// Time in seconds.
    pub time: f32,
    /// Emitted radiance.
    pub emission: Rgb,
}

/// A material whose emitted radiance is keyed over time (a lamp that dims or switches).
#[derive(Clone, Debug, PartialEq)]
pub struct MaterialMotion {
    /// Index of the material in the scene.
    pub material: usize,
    keys: Vec<EmissionKey>,
    times: Vec<f32>,
    interpolation: Interpolation,
}

impl MaterialMotion {
    /// A motion of material `material`'s emission through `keys`: times strictly increasing,
    /// every emission finite, non-negative and at most [`MAX_RADIANCE`] (what
    /// [`crate::Material::validate`] allows).
    pub fn new(
        material: usize,
        keys: Vec<EmissionKey>,
        interpolation: Interpolation,
    ) -> Result<Self, AnimationError> {
        check_times(keys.iter().map(|k| k.time))?;
        for (index, k) in keys.iter().enumerate() {
            if !k.emission.is_finite() {
                return Err(AnimationError::NotFinite {
                    index,
                    what: "emission",
                });
            }
            if k.emission.min_element() < 0.0 || k.emission.max_element() > MAX_RADIANCE {
                return Err(AnimationError::BadEmission {
                    index,
                    value: k.emission.to_array(),
                });
            }
        }
        let times = keys.iter().map(|k| k.time).collect();
        Ok(Self {
            material,
            keys,
            times,
            interpolation,
        })
    }

    /// The keys.
    pub fn keys(&self) -> &[EmissionKey] {
        &self.keys
    }

    /// How values move between keys.
    pub fn interpolation(&self) -> Interpolation {
        self.interpolation
    }

    /// The emission at time `t`. With [`Interpolation::Step`] a key's value holds from its
    /// time (inclusive) until the next key's.
    pub fn at(&self, t: f32) -> Rgb {
        let (i, j, w) = bracket(&self.times, t);
        let (a, b) = (self.keys[i].emission, self.keys[j].emission);
        match self.interpolation {
            Interpolation::Step => a,
            // The end keys exactly, not a blend that rounds away from them.
            Interpolation::Linear if w == 0.0 => a,
            Interpolation::Linear => a.lerp(b, w).max(Rgb::ZERO),
        }
    }

    /// True if the emission changes within `(t0, t1)`: a linear blend between two different
    /// values overlaps it, or a step to a different value falls inside it (a step at `t0`
    /// itself has happened when the shutter opens).
    pub fn spans(&self, t0: f32, t1: f32) -> bool {
        self.keys.windows(2).any(|w| {
            let (a, b) = (&w[0], &w[1]);
            a.emission != b.emission
                && match self.interpolation {
                    Interpolation::Step => b.time > t0 && b.time < t1,
                    Interpolation::Linear => a.time < t1 && b.time > t0,
                }
        })
    }
}

impl crate::content_hash::ContentHash for Motion {
    fn content_hash(&self, out: &mut crate::content_hash::Sink<'_>) {
        for k in &self.keys {
            k.time.content_hash(out);
            k.translate.content_hash(out);
            k.rotate.to_array().content_hash(out);
            k.scale.content_hash(out);
        }
        self.keys.len().content_hash(out);
    }
}

impl crate::content_hash::ContentHash for CameraMotion {
    fn content_hash(&self, out: &mut crate::content_hash::Sink<'_>) {
        self.camera.content_hash(out);
        for k in &self.keys {
            k.time.content_hash(out);
            k.position.content_hash(out);
            k.look_at.content_hash(out);
            k.up.content_hash(out);
            k.fov.content_hash(out);
        }
        self.keys.len().content_hash(out);
    }
}

impl crate::content_hash::ContentHash for MaterialMotion {
    fn content_hash(&self, out: &mut crate::content_hash::Sink<'_>) {
        self.material.content_hash(out);
        for k in &self.keys {
            k.time.content_hash(out);
            k.emission.content_hash(out);
        }
        self.keys.len().content_hash(out);
        (self.interpolation == Interpolation::Step).content_hash(out);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn key(time: f32, x: f32, ry: f32) -> Key {
        Key::from_trs(
            time,
            Vec3::new(x, 0.0, 0.0),
            Vec3::new(0.0, ry, 0.0),
            Vec3::ONE,
        )
    }

    #[test]
    fn ends_hold_and_the_middle_interpolates() {
        let m = Motion::new(vec![key(0.0, 0.0, 0.0), key(2.0, 4.0, 90.0)]).unwrap();
        let p = |t| m.at(t).point(Vec3::Z);
        assert!((p(-1.0) - Vec3::Z).length() < 1e-6);
        assert!((p(5.0) - Vec3::new(5.0, 0.0, 0.0)).length() < 1e-5);
        // Halfway: translated by 2, rotated by 45° about y (slerp, not a lerp of matrices,
        // which would shrink the rotated vector).
        let h = p(1.0);
        let s = std::f32::consts::FRAC_1_SQRT_2;
        assert!((h - Vec3::new(2.0 + s, 0.0, s)).length() < 1e-5, "{h}");
    }

    #[test]
    fn bad_keys_are_refused() {
        assert_eq!(Motion::new(vec![]), Err(AnimationError::NoKeys));
        assert!(matches!(
            Motion::new(vec![key(1.0, 0.0, 0.0), key(1.0, 1.0, 0.0)]),
            Err(AnimationError::OutOfOrder { index: 1, .. })
        ));
        assert!(matches!(
            Motion::new(vec![key(f32::NAN, 0.0, 0.0)]),
            Err(AnimationError::NotFinite { .. })
        ));
        let mut k = key(0.0, 0.0, 0.0);
        k.scale = Vec3::new(1.0, 0.0, 1.0);
        assert_eq!(
            Motion::new(vec![k]),
            Err(AnimationError::BadScale { index: 0 })
        );
        let c = CameraKey {
            time: 0.0,
            position: Vec3::ZERO,
            look_at: Vec3::Y,
            up: Vec3::Y,
            fov: 40.0,
        };
        assert!(matches!(
            CameraMotion::new(0, vec![c]),
            Err(AnimationError::BadCamera { .. })
        ));
    }

    fn lamp(interpolation: Interpolation) -> MaterialMotion {
        let key = |time, e| EmissionKey {
            time,
            emission: Rgb::splat(e),
        };
        MaterialMotion::new(
            0,
            vec![key(1.0, 8.0), key(2.0, 0.0), key(4.0, 4.0)],
            interpolation,
        )
        .unwrap()
    }

    #[test]
    fn step_holds_each_key_until_the_next_and_linear_blends() {
        let (step, linear) = (lamp(Interpolation::Step), lamp(Interpolation::Linear));
        for (t, s, l) in [
            (0.0, 8.0, 8.0), // before the first key: it holds
            (1.0, 8.0, 8.0),
            (1.5, 8.0, 4.0),     // halfway between 8 and 0
            (1.999, 8.0, 0.008), // a step holds until the next key
            (2.0, 0.0, 0.0),     // and jumps at its time
            (3.0, 0.0, 2.0),
            (9.0, 4.0, 4.0), // after the last key: it holds
        ] {
            assert_eq!(step.at(t), Rgb::splat(s), "step at {t}");
            assert!(
                (linear.at(t) - Rgb::splat(l)).abs().max_element() < 1e-3,
                "linear at {t}: {}",
                linear.at(t)
            );
        }
        assert!(step.spans(1.9, 2.1) && !step.spans(2.0, 2.1) && !step.spans(2.1, 3.9));
        assert!(linear.spans(2.1, 2.2) && linear.spans(3.9, 5.0) && !linear.spans(4.0, 5.0));
    }

    #[test]
    fn bad_emission_keys_are_refused() {
        let key = |time, e: Rgb| EmissionKey { time, emission: e };
        let new = |keys| MaterialMotion::new(0, keys, Interpolation::Step);
        assert_eq!(
            new(vec![key(0.0, Rgb::new(1.0, -0.5, 1.0))]),
            Err(AnimationError::BadEmission {
                index: 0,
                value: [1.0, -0.5, 1.0]
            })
        );
        assert_eq!(
            new(vec![
                key(0.0, Rgb::ONE),
                key(1.0, Rgb::new(f32::INFINITY, 0.0, 0.0))
            ]),
            Err(AnimationError::NotFinite {
                index: 1,
                what: "emission"
            })
        );
        assert!(matches!(
            new(vec![key(1.0, Rgb::ONE), key(0.5, Rgb::ONE)]),
            Err(AnimationError::OutOfOrder { index: 1, .. })
        ));
        assert_eq!(new(vec![]), Err(AnimationError::NoKeys));
    }
}
