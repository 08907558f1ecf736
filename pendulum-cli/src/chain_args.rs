//! The chain of `pendulum modes` and `pendulum steady`, built from the shared chain options.

use nalgebra::Dyn;
use pendulum_core::Chain;

use crate::args::ChainOptions;
use crate::error::{CliError, CliResult};
use crate::spec::{expand, per_link};

/// The chain the shared chain options describe (default 3 links).
pub fn chain_of(options: &ChainOptions) -> CliResult<Chain<Dyn>> {
    let masses = per_link("--masses", &options.masses)?;
    let lengths = per_link("--lengths", &options.lengths)?;
    let n = match options.n {
        Some(0) => return Err(CliError::usage("--n: a chain needs at least 1 link, got 0")),
        Some(n) => n,
        None => [masses.len(), lengths.len()].into_iter().find(|&len| len > 1).unwrap_or(3),
    };
    let masses = expand("--masses", masses, n)?;
    let lengths = expand("--lengths", lengths, n)?;
    Ok(Chain::<Dyn>::new(&masses, &lengths, options.gravity)?)
}
