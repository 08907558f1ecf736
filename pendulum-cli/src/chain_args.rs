//! The chain the shared chain options describe (`--n --masses --lengths --gravity`), for
//! every command that takes them.

use nalgebra::Dyn;
use pendulum_core::Chain;

use crate::args::ChainOptions;
use crate::error::CliResult;
use crate::spec::per_link;

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
    let (_, masses, lengths) = pendulum_experiment::options::links(options.n, masses, lengths)?;
    Ok((masses, lengths))
}

/// The chain in one line for a command's header, with `damping` (N·m·s per link) when
/// given.
pub fn header(chain: &Chain<Dyn>, damping: Option<&[f64]>) -> String {
    let undamped = vec![0.0; chain.links()];
    pendulum_experiment::words::chain_words(
        chain.masses().as_slice(),
        chain.lengths().as_slice(),
        chain.gravity(),
        damping.unwrap_or(&undamped),
    )
}
