//! `rt-parts`: rendering on many machines, and resuming on one, without changing a bit.
//!
//! A render is cut into parts by sample range and by pixel region ([`Plan`]); each part is
//! rendered anywhere and written as a [`Part`] file: a header saying what it is (scene content
//! hash, renderer build, every setting that changes the image, frame, region, samples) and the
//! film's exact sums for its region. [`merge`] checks that the parts belong together and cover
//! the render exactly once, then adds them into the film of the whole render, which is the
//! same, bit for bit, as the film a single machine would have (the film's sums are integers:
//! `rt_film`'s `fixed` module). A checkpoint is the same file for the samples taken so far.
//!
//! Depends on `rt-film` (the film and its encoded sums), `serde_json` (headers and plans) and
//! `sha2` (checksums and hashes). The renderer's `render plan`, `render part`, `render merge`,
//! `--checkpoint` and `--resume` are thin layers over this crate.
//!
//! ```
//! use rt_film::{AovSet, Film, Rect};
//! use rt_parts::{merge, Part, PartHeader, PartKind, FORMAT};
//! // Two sample ranges of a 2x1 image, rendered apart.
//! let header = |samples: [u32; 2]| PartHeader {
//!     format: FORMAT, kind: PartKind::Part, binary: "b".into(), scene: "s".into(),
//!     scene_hash: "h".into(), settings: Default::default(), frame: None, width: 2, height: 1,
//!     spp: 4, region: [0, 0, 2, 1], samples, aovs: vec![], variance: true, halves: false,
//!     job: serde_json::json!({}), seconds: 0.0,
//! };
//! let render = |samples: [u32; 2]| {
//!     let mut film = Film::new(2, 1, rt_film::FilmBuffers::for_outputs(AovSet::default()).with_variance());
//!     for i in samples[0]..samples[1] {
//!         film.add_sample(i % 2, 0, i, rt_core::Rgb::splat(0.1 * i as f32), None);
//!     }
//!     ("part".to_string(), Part { sums: film.encode_sums(Rect::full(2, 1)), header: header(samples) })
//! };
//! let whole = merge(&[render([0, 4])], None).unwrap();
//! let split = merge(&[render([2, 4]), render([0, 2])], None).unwrap();
//! assert_eq!(split.film.mean_image(), whole.film.mean_image());
//! assert_eq!(split.film.variance_image(), whole.film.variance_image());
//! ```

mod file;
mod hash;
mod merge;
mod plan;

pub use file::{Part, PartError, PartHeader, PartKind, FORMAT, MAGIC, MAX_SIDE};
pub use hash::{binary_id, content_hash};
pub use merge::{check_belongs, merge, MergeError, Merged};
pub use plan::{
    Plan, PlanError, PlanRequest, PlannedOutput, PlannedPart, PlannedRender, MAX_PARTS, PLAN_FORMAT,
};
