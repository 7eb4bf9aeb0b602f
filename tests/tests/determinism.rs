//! The same scene, seed and settings give a bit-identical image whatever the thread count.

use rt_film::{AovSet, Film};
use rt_integrators::PathIntegrator;
use rt_testkit::{shipped_scene, Renderer, SceneExt};

#[test]
fn images_do_not_depend_on_thread_count() {
    let scene = shipped_scene("cornell-box.toml").with_resolution(24, 24);
    let integrator = PathIntegrator::new(8);
    let render = |seed, threads| -> Film {
        let buffers = rt_film::FilmBuffers::from(AovSet::default()).with_variance();
        let r = Renderer::new(&scene).threads(threads);
        r.render(&integrator, buffers, 16, seed).0
    };
    let one = render(5, 1);
    let three = render(5, 3);
    assert_eq!(one.mean_image(), three.mean_image());
    assert!(one.variance_image().is_some());
    assert_eq!(one.variance_image(), three.variance_image());
    let other_seed = render(6, 3);
    assert_ne!(one.mean_image(), other_seed.mean_image());
}
