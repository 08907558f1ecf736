//! The hand-written reference cases of `pendulum-reference/tests/fixtures`, for the unit tests.

use std::path::PathBuf;

use crate::case::{Case, load_all};

/// Every fixture case, planar by `n`, then spatial by `n` (as [`load_all`] orders them).
pub(super) fn fixtures() -> Vec<Case> {
    let root = PathBuf::from(env!("CARGO_MANIFEST_DIR"));
    load_all(&root.join("../pendulum-reference/tests/fixtures")).unwrap()
}
