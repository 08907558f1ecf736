//! The chain the shared chain options describe (`--n --masses --lengths --gravity`), for
//! every command that takes them.

use nalgebra::Dyn;
use pendulum_core::Chain;

use crate::args::ChainOptions;
use crate::error::{CliError, CliResult};
use crate::spec::{expand, per_link};

/// The chain the shared chain options describe (default 3 links).
pub fn chain_of(options: &ChainOptions) -> CliResult<Chain<Dyn>> {
    let (masses, lengths) = per_link_values(options)?;
    Ok(Chain::<Dyn>::new(&masses, &lengths, options.gravity)?)
}

/// The masses and lengths of the shared chain options, one per link: `--n`, else the
/// length of a `--masses` or `--lengths` list, else 3 links. Errors name the option.
pub fn per_link_values(options: &ChainOptions) -> CliResult<(Vec<f64>, Vec<f64>)> {
    let masses = per_link("--masses", &options.masses)?;
    let lengths = per_link("--lengths", &options.lengths)?;
    let n = match options.n {
        Some(0) => return Err(CliError::invalid("--n: a chain needs at least 1 link, got 0")),
        Some(n) => n,
        None => [masses.len(), lengths.len()].into_iter().find(|&len| len > 1).unwrap_or(3),
    };
    Ok((expand("--masses", masses, n)?, expand("--lengths", lengths, n)?))
}
