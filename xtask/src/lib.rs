//! Project tasks behind `cargo xtask`: the sympy reference, `verify`, benchmarks.
//!
//! One module per task or concern; `main.rs` is a flat match on subcommands.

pub mod bench;
pub mod claims_proof;
pub mod regen;
pub mod test;
pub mod verify;

// The sympy reference cases, their expressions, the sample states and the claims checker
// live in `pendulum-reference` (the Python package checks claims with them too).
pub use pendulum_reference::{case, claims, expr, sample};

use std::path::PathBuf;

/// The workspace root (the parent of this crate's directory).
pub fn workspace_root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .parent()
        .expect("xtask lives in the workspace root")
        .to_path_buf()
}

/// Where the committed reference case files live.
pub fn cases_dir() -> PathBuf {
    workspace_root().join("reference").join("cases")
}
