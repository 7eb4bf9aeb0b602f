//! SIGINT and SIGTERM as a job's stop flag: what `render --checkpoint` (and any program that
//! runs long jobs) needs so that an interrupted render keeps what it has. The first signal sets
//! the flag, which a job reads at its next pass; a second ends the process at once (exit
//! status 130).

use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};
use std::sync::Arc;

/// The stop flag and the signal that set it.
#[derive(Clone, Default)]
pub struct StopOnSignal {
    /// Set by the first SIGINT or SIGTERM; pass it to [`crate::RenderJob::run`].
    pub stop: Arc<AtomicBool>,
    which: Arc<AtomicUsize>,
}

impl StopOnSignal {
    /// Registers the handlers.
    pub fn watch() -> std::io::Result<Self> {
        use signal_hook::consts::{SIGINT, SIGTERM};
        let s = Self::default();
        for sig in [SIGINT, SIGTERM] {
            // Registered first, so it runs before `stop` is set by this same signal.
            signal_hook::flag::register_conditional_shutdown(sig, 130, s.stop.clone())?;
            signal_hook::flag::register(sig, s.stop.clone())?;
            signal_hook::flag::register_usize(sig, s.which.clone(), sig as usize)?;
        }
        Ok(s)
    }

    /// The name of the signal that set the flag (`"a signal"` if none did).
    pub fn signal_name(&self) -> &'static str {
        match self.which.load(Ordering::Relaxed) as i32 {
            signal_hook::consts::SIGINT => "SIGINT",
            signal_hook::consts::SIGTERM => "SIGTERM",
            _ => "a signal",
        }
    }
}
