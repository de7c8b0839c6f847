//! Cross-crate closed-loop tests live in `tests/tests/`.
