//! The command's error: the run library's [`Error`](pendulum_experiment::Error), one line, and
//! the exit status each kind maps to.

use std::process::ExitCode;

pub use pendulum_experiment::error::io_failed;

/// What went wrong, and whose fault it was: `Invalid` (exit status 2) a bad argument,
/// value or input file, nothing computed; `Failed` (exit status 1) the inputs were valid
/// but the computation stopped, files written so far are valid; `Interrupted` (exit
/// status 130) Ctrl-C cut the run, the files written are valid and say so.
pub type CliError = pendulum_experiment::Error;

/// The command's result type.
pub type CliResult<T> = Result<T, CliError>;

/// 2 for bad input, 1 for failures, 130 after Ctrl-C.
pub fn exit_code(e: &CliError) -> ExitCode {
    match e {
        CliError::Invalid(_) => ExitCode::from(2),
        CliError::Failed(_) => ExitCode::from(1),
        CliError::Interrupted(_) => ExitCode::from(130),
    }
}
