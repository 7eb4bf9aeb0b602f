//! An acceleration structure that follows a scene from frame to frame ([`FollowingAccel`]):
//! after the scene moved to a frame's time it is updated in place when it can (two-level
//! structures follow rigid motion), and rebuilt otherwise. What a job's frames
//! ([`crate::RenderJob::each_frame`]) and the [`crate::SequenceRenderer`] share.

use rt_accel::{AccelSpec, BuildError, BuildInput};
use rt_core::{Accel, Scene};

/// A structure over a moving scene, built on first use.
pub struct FollowingAccel {
    spec: AccelSpec,
    accel: Option<Box<dyn Accel>>,
}

impl FollowingAccel {
    /// No structure yet; the first [`FollowingAccel::follow`] builds one from `spec`.
    pub fn new(spec: AccelSpec) -> Self {
        Self { spec, accel: None }
    }

    /// The structure asked for.
    pub fn spec(&self) -> &AccelSpec {
        &self.spec
    }

    /// Moves the structure to `input`'s scene as it is now: the last one updated in place if
    /// it can follow, else a new one built from `input` (a [`BuildInput::SceneToReorder`] lets
    /// IOSP reorder the scene's triangles rather than store an index map).
    pub fn follow(&mut self, input: BuildInput<'_>) -> Result<(), BuildError> {
        let scene: Option<&Scene> = match &input {
            BuildInput::Scene(s) => Some(s),
            BuildInput::SceneToReorder(s) => Some(s),
            BuildInput::Triangles(_) => None,
        };
        let updated = match (self.accel.as_mut(), scene) {
            (Some(a), Some(s)) => a.update(s),
            _ => false,
        };
        if !updated {
            self.accel = Some(self.spec.build(input)?);
        }
        Ok(())
    }

    /// The structure as the last [`FollowingAccel::follow`] left it (`None` before the first).
    pub fn current(&self) -> Option<&dyn Accel> {
        self.accel.as_deref()
    }
}
