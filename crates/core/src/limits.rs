//! The renderer's limits, in one place: every crate that checks a sample count, a thread
//! count or an image size checks it against these, so a scene, a flag, an experiment file and
//! a part file accept the same values.

/// Most samples per pixel one render takes.
pub const MAX_SPP: u32 = 1 << 20;

/// Most worker threads a render or a benchmark may ask for.
pub const MAX_THREADS: usize = 1024;

/// Largest image side, in pixels (a camera's resolution, a size override, a part file, a
/// benchmark's ray grid).
pub const MAX_IMAGE_SIDE: u32 = 16_384;

/// Most pixels of one image: 64 Mpixels, a film of a few GiB with its buffers.
pub const MAX_IMAGE_PIXELS: u64 = 1 << 26;
