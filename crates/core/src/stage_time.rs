//! How long a build stage took, kept beside the data it built.

use std::time::Duration;

/// Wall-clock time a build step took (for `render --stats`). A plain measurement: it compares
/// and prints by value. Content hashes leave it out ([`crate::content_hash`]).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, PartialOrd, Ord)]
pub struct StageTime(pub Duration);
