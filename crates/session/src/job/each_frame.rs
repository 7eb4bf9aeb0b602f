//! The frame loop of a job, once: per frame the scene moves to the frame's time, the job's
//! camera is looked up again (cameras move) at the job's size, and the structure follows the
//! scene when the caller asks for it ([`JobFrame::ctx`]): updated in place when it can,
//! rebuilt otherwise ([`FollowingAccel`]). [`RenderJob::run`] renders each frame in it, a
//! temporally denoised job its [`crate::SequenceRenderer`]
//! ([`RenderJob::render_sequence`]), and an experiment's sequence references look each frame
//! up in their cache before they render it.

use super::{JobError, RenderJob};
use crate::following::FollowingAccel;
use crate::frame_seed;
use rt_accel::BuildInput;
use rt_core::{Camera, Scene};
use rt_integrators::Ctx;
use std::path::Path;

/// One frame of a job over a scene the caller holds ([`RenderJob::each_frame`]).
pub struct JobFrame<'a> {
    /// The frame (`None`: a still, the scene as loaded).
    pub frame: Option<u32>,
    /// The frame's seed: [`frame_seed`] of the job's for a frame, the job's for a still.
    pub seed: u32,
    /// The job's camera in the scene at the frame's time, at the job's size.
    pub camera: Camera,
    scene: &'a mut Scene,
    structure: &'a mut FollowingAccel,
    path: &'a Path,
}

impl JobFrame<'_> {
    /// The scene at the frame's time.
    pub fn scene(&self) -> &Scene {
        self.scene
    }

    /// The scene, for a renderer that follows it with a structure of its own.
    pub fn scene_mut(&mut self) -> &mut Scene {
        self.scene
    }

    /// What a render of the frame reads: the scene, the structure following it, the camera.
    /// The structure may reorder the scene's triangles (IOSP stores nothing beyond them).
    pub fn ctx(&mut self) -> Result<Ctx<'_>, JobError> {
        self.follow(true)
    }

    /// [`JobFrame::ctx`] keeping the scene's triangles in their order, for a caller that
    /// reads the scene again afterwards (a cache key hashes it).
    pub fn ctx_in_order(&mut self) -> Result<Ctx<'_>, JobError> {
        self.follow(false)
    }

    fn follow(&mut self, reorder: bool) -> Result<Ctx<'_>, JobError> {
        let input = if reorder {
            BuildInput::SceneToReorder(self.scene)
        } else {
            BuildInput::Scene(self.scene)
        };
        self.structure.follow(input).map_err(|e| {
            JobError::Refused(format!(
                "{}: --accel {}: {e}",
                self.path.display(),
                self.structure.spec()
            ))
        })?;
        Ok(Ctx {
            scene: self.scene,
            accel: self.structure.current().expect("followed above"),
            camera: &self.camera,
        })
    }
}

impl RenderJob {
    /// Calls `each` with every frame of the job over `scene` (which the caller loaded, and
    /// which is left at the last frame's time), in order; one structure follows the scene
    /// from frame to frame.
    pub fn each_frame<E: From<JobError>>(
        &self,
        scene: &mut Scene,
        each: &mut dyn FnMut(&mut JobFrame<'_>) -> Result<(), E>,
    ) -> Result<(), E> {
        let mut structure = FollowingAccel::new(self.settings.accel);
        for frame in self.frame_list() {
            let seed = match frame {
                Some(f) => {
                    scene.set_time((f64::from(f) / self.fps) as f32);
                    frame_seed(self.settings.seed, f)
                }
                None => self.settings.seed,
            };
            let camera = self.camera_in(scene)?;
            each(&mut JobFrame {
                frame,
                seed,
                camera,
                scene,
                structure: &mut structure,
                path: &self.scene,
            })?;
        }
        Ok(())
    }
}
