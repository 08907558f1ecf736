//! The command's error: a one-line message and the exit status it maps to.

use std::fmt;
use std::process::ExitCode;

/// What went wrong, and whose fault it was.
///
/// `Usage` (exit status 2): a bad argument, value or input file; nothing was computed.
/// `Failed` (exit status 1): the inputs were valid but the computation stopped (a step
/// failed, a file could not be written); files written so far are valid.
/// `Interrupted` (exit status 130): Ctrl-C cut the run; the files written are valid and
/// say so.
#[derive(Debug, Clone, PartialEq)]
pub enum CliError {
    /// A bad argument or input file.
    Usage(String),
    /// A failure while computing or writing results.
    Failed(String),
    /// The run was cut by Ctrl-C after writing valid files.
    Interrupted(String),
}

/// The command's result type.
pub type CliResult<T> = Result<T, CliError>;

impl CliError {
    /// A usage error from anything printable.
    pub fn usage(message: impl Into<String>) -> Self {
        Self::Usage(message.into())
    }

    /// A run-time failure from anything printable.
    pub fn failed(message: impl Into<String>) -> Self {
        Self::Failed(message.into())
    }

    /// A run cut by Ctrl-C.
    pub fn interrupted(message: impl Into<String>) -> Self {
        Self::Interrupted(message.into())
    }

    /// The same error with `prefix: ` in front of its message (for example the input
    /// file a rejected value came from).
    pub fn context(self, prefix: impl fmt::Display) -> Self {
        match self {
            Self::Usage(m) => Self::Usage(format!("{prefix}: {m}")),
            Self::Failed(m) => Self::Failed(format!("{prefix}: {m}")),
            Self::Interrupted(m) => Self::Interrupted(format!("{prefix}: {m}")),
        }
    }

    /// 2 for usage errors, 1 for failures, 130 after Ctrl-C.
    pub fn exit_code(&self) -> ExitCode {
        match self {
            Self::Usage(_) => ExitCode::from(2),
            Self::Failed(_) => ExitCode::from(1),
            Self::Interrupted(_) => ExitCode::from(130),
        }
    }
}

impl fmt::Display for CliError {
    /// The message on one line (newlines in wrapped errors become "; ").
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let (Self::Usage(m) | Self::Failed(m) | Self::Interrupted(m)) = self;
        f.write_str(&m.trim().replace('\n', "; "))
    }
}

impl From<pendulum_core::Error> for CliError {
    /// Errors of the core from building a chain, drive or state are bad inputs.
    fn from(e: pendulum_core::Error) -> Self {
        Self::Usage(e.to_string())
    }
}

/// Maps an I/O error on `path` to a failure naming the file.
pub fn io_failed(action: &str, path: &std::path::Path, e: std::io::Error) -> CliError {
    CliError::failed(format!("cannot {action} {}: {e}", path.display()))
}
