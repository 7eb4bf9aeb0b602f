//! [`Renderer`]: build the acceleration structure, make a film, render. The stress cases and
//! the tests render through it, so they render the way `render` does: with the shipped
//! default structure ([`rt_accel::AccelSpec::default`]) unless told otherwise.

use rt_core::{Accel, Camera, Scene};
use rt_film::{Film, FilmBuffers};
use rt_integrators::{Ctx, Integrator, RenderOptions, RenderStats, SamplePass, Technique};
use std::sync::OnceLock;

/// A scene ready to render: a camera, an acceleration structure and a thread count.
pub struct Renderer<'a> {
    scene: &'a Scene,
    camera: Camera,
    /// Set by [`Renderer::with_accel`]; otherwise the default structure, built on first use.
    borrowed: Option<&'a dyn Accel>,
    owned: OnceLock<Box<dyn Accel>>,
    threads: Option<usize>,
}

impl<'a> Renderer<'a> {
    /// `scene`'s first camera, the default acceleration structure, the current thread pool.
    /// Panics if the scene has no camera.
    pub fn new(scene: &'a Scene) -> Self {
        Self {
            scene,
            camera: scene
                .cameras
                .first()
                .expect("the scene has a camera")
                .clone(),
            borrowed: None,
            owned: OnceLock::new(),
            threads: None,
        }
    }

    /// Renders through `camera` instead.
    pub fn with_camera(mut self, camera: Camera) -> Self {
        self.camera = camera;
        self
    }

    /// Traces rays in `accel` (built over the same scene) instead of the default structure.
    pub fn with_accel(mut self, accel: &'a dyn Accel) -> Self {
        self.borrowed = Some(accel);
        self
    }

    /// Renders on a pool of `threads` worker threads.
    pub fn threads(mut self, threads: usize) -> Self {
        self.threads = Some(threads);
        self
    }

    /// The acceleration structure rays are traced in.
    pub fn accel(&self) -> &dyn Accel {
        match self.borrowed {
            Some(a) => a,
            None => self
                .owned
                .get_or_init(|| crate::default_accel(self.scene))
                .as_ref(),
        }
    }

    /// The camera.
    pub fn camera(&self) -> &Camera {
        &self.camera
    }

    /// A film of the camera's size that keeps `buffers`.
    pub fn film(&self, buffers: impl Into<FilmBuffers>) -> Film {
        Film::new(self.camera.width, self.camera.height, buffers)
    }

    /// Renders `spp` samples per pixel with `seed` into a fresh film keeping `buffers`.
    pub fn render(
        &self,
        integrator: &dyn Integrator,
        buffers: impl Into<FilmBuffers>,
        spp: u32,
        seed: u32,
    ) -> (Film, RenderStats) {
        let mut film = self.film(buffers);
        let ctx = self.ctx();
        let stats = self.install(|| {
            rt_integrators::render(
                &ctx,
                integrator,
                &mut film,
                &RenderOptions { spp, seed },
                &|_| {},
            )
        });
        (film, stats)
    }

    /// Renders sample indices `0..spp` of any technique (light tracing too) with `seed` into
    /// a fresh film keeping `buffers`.
    pub fn render_technique(
        &self,
        technique: &dyn Technique,
        buffers: impl Into<FilmBuffers>,
        spp: u32,
        seed: u32,
    ) -> (Film, RenderStats) {
        let mut film = self.film(buffers);
        let stats = self.technique_pass(
            technique,
            &mut film,
            seed,
            &SamplePass {
                indices: 0..spp,
                stream: rt_core::SampleStream::Render,
                pixels: None,
                centre_first: false,
            },
        );
        (film, stats)
    }

    /// Renders the sample pass `pass` of any technique with `seed` into `film`.
    pub fn technique_pass(
        &self,
        technique: &dyn Technique,
        film: &mut Film,
        seed: u32,
        pass: &SamplePass,
    ) -> RenderStats {
        let ctx = self.ctx();
        self.install(|| technique.render_pass(&ctx, film, seed, pass, &|_| {}))
    }

    /// Renders the sample pass `pass` with `seed` into `film` (progressive rendering).
    pub fn render_pass(
        &self,
        integrator: &dyn Integrator,
        film: &mut Film,
        seed: u32,
        pass: &SamplePass,
    ) -> RenderStats {
        let ctx = self.ctx();
        self.install(|| rt_integrators::render_samples(&ctx, integrator, film, seed, pass, &|_| {}))
    }

    /// The integrators' context: scene, acceleration structure, camera.
    pub fn ctx(&self) -> Ctx<'_> {
        Ctx {
            scene: self.scene,
            accel: self.accel(),
            camera: &self.camera,
        }
    }

    fn install<R: Send>(&self, f: impl FnOnce() -> R + Send) -> R {
        match self.threads {
            None => f(),
            Some(n) => rayon::ThreadPoolBuilder::new()
                .num_threads(n)
                .build()
                .expect("thread pool")
                .install(f),
        }
    }
}
