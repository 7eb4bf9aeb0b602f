//! How long a build stage took, kept beside the data it built.

use std::time::Duration;

/// Wall-clock time a build step took (for `render --stats`). It is a measurement, not part of
/// what was built: it prints as `StageTime(..)` and every two compare equal, so the `Debug`
/// text and the equality of the structures holding it (which content hashes such as the
/// reference cache's key rely on) do not change from run to run.
#[derive(Clone, Copy, Default)]
pub struct StageTime(pub Duration);

impl std::fmt::Debug for StageTime {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str("StageTime(..)")
    }
}

impl PartialEq for StageTime {
    fn eq(&self, _: &Self) -> bool {
        true
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn timings_do_not_show_in_debug_or_equality() {
        let (a, b) = (
            StageTime(Duration::from_millis(1)),
            StageTime(Duration::from_secs(2)),
        );
        assert_eq!(a, b);
        assert_eq!(format!("{a:?}"), format!("{b:?}"));
        assert_eq!(b.0, Duration::from_secs(2));
    }
}
