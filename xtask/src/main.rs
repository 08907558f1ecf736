//! `cargo xtask <task>`: see `cargo xtask --help`.

use clap::{Parser, Subcommand};

#[derive(Parser)]
#[command(name = "xtask", about = "Tasks of the pendulum workspace")]
struct Cli {
    #[command(subcommand)]
    task: Task,
}

#[derive(Subcommand)]
enum Task {
    /// Every test, Rust and Python: `cargo test --workspace`, then the Python package
    /// built into a virtual environment (target/python) and its pytest suite and stub
    /// check. The README's test command.
    Test(xtask::test::Options),
    /// Compare the generated and generic models (and the document's printed
    /// equations) against the sympy reference at many random states.
    Verify(xtask::verify::Options),
    /// Benchmark generated vs generic vs closed-form vs O(n) models (criterion) and write
    /// docs/bench.md and docs/bench.svg from this one run (`--quick`: a smoke run that
    /// leaves docs/ alone).
    Bench(xtask::bench::Options),
    /// Regenerate the sympy reference in reference/cases (needs python3 with sympy 1.14.0).
    Reference {
        /// Regenerate into a scratch directory and fail, naming the files, if the
        /// committed ones differ.
        #[arg(long, conflicts_with = "claims")]
        check: bool,
        /// Instead: have sympy prove each entry of this claims file's claims (and
        /// corrected forms) that agree numerically, for every derived case up to --links
        /// links (`reference/CLAIMS.md`).
        #[arg(long, value_name = "FILE")]
        claims: Option<std::path::PathBuf>,
        /// With --claims: the largest chain proven.
        #[arg(long, default_value_t = 3, requires = "claims")]
        links: usize,
    },
}

fn main() -> anyhow::Result<()> {
    match Cli::parse().task {
        Task::Verify(options) => match &options.claims {
            Some(path) => {
                let cases = xtask::case::load_all(&xtask::cases_dir())?;
                xtask::claims::run(path, &cases, options.states, options.seed).map(|_| ())
            }
            None => xtask::verify::run(&options),
        },
        Task::Reference { claims: Some(path), links, .. } => {
            let cases = xtask::case::load_all(&xtask::cases_dir())?;
            xtask::claims_proof::run(&path, &cases, links, 20, xtask::verify::DEFAULT_SEED)
        }
        Task::Reference { check, .. } => xtask::regen::run(check),
        Task::Bench(options) => xtask::bench::run(&options),
        Task::Test(options) => xtask::test::run(&options),
    }
}
