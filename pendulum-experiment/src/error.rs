//! What went wrong with a run, and whose fault it was: every front end maps the three
//! kinds to its own signal (the CLI to exit statuses 2, 1 and 130; Python to `ValueError`,
//! `RuntimeError` and `KeyboardInterrupt`) and shows the same one-line message, the options
//! it names spelled its own way ([`crate::spelling`]).

use std::fmt;

use crate::spelling::Front;

/// A run's error: one line naming the bad value or the failure.
///
/// `Invalid`: a bad parameter, value or input file; nothing was computed.
/// `Failed`: the inputs were valid but the computation stopped (a step failed, a file
/// could not be written); what was written so far is valid.
/// `Interrupted`: the run was stopped on request (Ctrl-C) after writing valid files.
#[derive(Debug, Clone, PartialEq)]
pub enum Error {
    /// A bad parameter or input file.
    Invalid(String),
    /// A failure while computing or writing results.
    Failed(String),
    /// The run was stopped on request after writing valid files.
    Interrupted(String),
}

/// The result type of this crate.
pub type Result<T> = std::result::Result<T, Error>;

impl Error {
    /// A bad input, from anything printable.
    pub fn invalid(message: impl Into<String>) -> Self {
        Self::Invalid(message.into())
    }

    /// A run-time failure, from anything printable.
    pub fn failed(message: impl Into<String>) -> Self {
        Self::Failed(message.into())
    }

    /// A run stopped on request.
    pub fn interrupted(message: impl Into<String>) -> Self {
        Self::Interrupted(message.into())
    }

    /// The same error with `prefix: ` in front of its message (for example the input
    /// file a rejected value came from).
    pub fn context(self, prefix: impl fmt::Display) -> Self {
        match self {
            Self::Invalid(m) => Self::Invalid(format!("{prefix}: {m}")),
            Self::Failed(m) => Self::Failed(format!("{prefix}: {m}")),
            Self::Interrupted(m) => Self::Interrupted(format!("{prefix}: {m}")),
        }
    }

    /// The message on one line (newlines in wrapped errors become "; "), with the options
    /// it names spelled for `front` (the `Display` of an error is the command line's).
    pub fn message(&self, front: Front) -> String {
        let (Self::Invalid(m) | Self::Failed(m) | Self::Interrupted(m)) = self;
        front.spell(&m.trim().replace('\n', "; "))
    }
}

impl fmt::Display for Error {
    /// [`Error::message`] on the command line.
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(&self.message(Front::CommandLine))
    }
}

impl std::error::Error for Error {}

impl From<pendulum_core::Error> for Error {
    /// Errors of the core from building a chain, drive or state are bad inputs.
    fn from(e: pendulum_core::Error) -> Self {
        Self::Invalid(e.to_string())
    }
}

/// Maps an I/O error on `path` to a failure naming the file.
pub fn io_failed(action: &str, path: &std::path::Path, e: std::io::Error) -> Error {
    Error::failed(format!("cannot {action} {}: {e}", path.display()))
}
