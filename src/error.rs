//! kiln's error type: what went wrong, with the value, the allowed range and what to do.

use std::path::PathBuf;

/// An error from kiln's library.
#[derive(Debug)]
pub enum Error {
    /// A user-supplied value is out of range or malformed; the message names it and the range.
    InvalidInput(String),
    /// Reading or writing a file failed.
    Io {
        path: PathBuf,
        action: &'static str,
        source: std::io::Error,
    },
    /// Encoding or decoding a file format failed.
    Format { path: PathBuf, message: String },
}

impl Error {
    /// Whether the error is the user's input (the CLI exits with status 2 for those).
    #[must_use]
    pub fn is_usage(&self) -> bool {
        matches!(self, Error::InvalidInput(_))
    }
}

impl std::fmt::Display for Error {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Error::InvalidInput(message) => f.write_str(message),
            Error::Io {
                path,
                action,
                source,
            } => {
                write!(f, "cannot {action} {}: {source}", path.display())
            }
            Error::Format { path, message } => write!(f, "{}: {message}", path.display()),
        }
    }
}

impl std::error::Error for Error {
    fn source(&self) -> Option<&(dyn std::error::Error + 'static)> {
        match self {
            Error::Io { source, .. } => Some(source),
            _ => None,
        }
    }
}

/// kiln's result type.
pub type Result<T> = std::result::Result<T, Error>;
