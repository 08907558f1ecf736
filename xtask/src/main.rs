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
        #[arg(long)]
        check: bool,
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
        Task::Reference { check } => xtask::regen::run(check),
        Task::Bench(options) => xtask::bench::run(&options),
    }
}
