//! `cargo xtask bench --ensembles`: the batches of `pendulum-core/benches/ensembles.rs`
//! against the single-chain calls, from one run: `docs/ensembles-speed.md` (the times per
//! chain, the ratios and the targets, each checked) and `docs/ensembles-speed.svg`
//! (the ratios as bars).
//!
//! Every benchmark of that file times the same 64 chains and declares its throughput in
//! chains (or chain-steps), so a time per element is a time per chain (or chain-step).

mod measured;
mod plot;
mod report;
mod rows;

pub use measured::{Measured, Timing};
pub use plot::svg;
pub use report::markdown;
pub use rows::{Check, MUJOCO_ROLLOUT_NS, Row, SECTIONS, checks, missing, rows};
