//! The library's error type: what went wrong, and whether it was the user's
//! mistake (exit code 2 at the command line) or a failure of the run.

use std::path::{Path, PathBuf};

/// Everything the library can fail with.
#[derive(Debug, thiserror::Error)]
pub enum Error {
    /// A value in an input file is wrong: the file, the key path, what was expected.
    #[error("{file}: {key}: {message}")]
    Invalid {
        file: String,
        key: String,
        message: String,
    },
    /// A user's mistake outside a file: a bad option, a missing renderer.
    #[error("{0}")]
    Usage(String),
    /// A file could not be read or written.
    #[error("{path}: {source}")]
    Io {
        path: PathBuf,
        source: std::io::Error,
    },
    /// An image could not be read or written.
    #[error("{path}: {message}")]
    Image { path: PathBuf, message: String },
    /// The run itself failed (every render of a generation failed, a worker
    /// could not start, ...). Not the user's input.
    #[error("{0}")]
    Run(String),
}

impl Error {
    /// An error about a key in an input file.
    pub fn invalid(
        file: impl Into<String>,
        key: impl Into<String>,
        message: impl Into<String>,
    ) -> Self {
        Error::Invalid {
            file: file.into(),
            key: key.into(),
            message: message.into(),
        }
    }

    /// An I/O error on `path`.
    pub fn io(path: &Path, source: std::io::Error) -> Self {
        Error::Io {
            path: path.to_path_buf(),
            source,
        }
    }

    /// True when the error is the user's to fix (exit code 2).
    pub fn is_user_error(&self) -> bool {
        !matches!(self, Error::Run(_))
    }
}

pub type Result<T, E = Error> = std::result::Result<T, E>;
