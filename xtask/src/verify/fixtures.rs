//! The hand-written reference cases of `xtask/tests/fixtures`, for the unit tests.

use std::path::PathBuf;

use crate::case::{Case, load_all};

/// Every fixture case, planar by `n`, then spatial by `n` (as [`load_all`] orders them).
pub(super) fn fixtures() -> Vec<Case> {
    load_all(&PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("tests").join("fixtures")).unwrap()
}
