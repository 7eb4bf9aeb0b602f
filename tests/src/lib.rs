//! Cross-crate end-to-end checks (statistical image tests). See `tests/tests/`.
