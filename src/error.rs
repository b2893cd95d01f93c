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
    /// Bytes or a document that are not what they claim to be, found by a decoder or a check
    /// that does not know the file ([`Error::in_file`] names it): input the user can replace.
    Malformed(String),
    /// A format's encoder could not write a table (a size or a value the format cannot hold):
    /// [`crate::format::write_files`]'s callers name the file.
    Encode(String),
    /// An error in the input read from a file, said with the file.
    InFile { path: PathBuf, source: Box<Error> },
}

impl Error {
    /// Whether the error is the user's input (the CLI exits with status 2 for those).
    #[must_use]
    pub fn is_usage(&self) -> bool {
        match self {
            Error::InvalidInput(_) | Error::Malformed(_) => true,
            Error::InFile { source, .. } => source.is_usage(),
            _ => false,
        }
    }

    /// The error said of the file at `path`: an input error or a malformed document is put in
    /// the file's context, and an error that names its file already is left as it is.
    #[must_use]
    pub fn in_file(self, path: &std::path::Path) -> Error {
        match self {
            Error::InvalidInput(_) | Error::Malformed(_) => Error::InFile {
                path: path.to_path_buf(),
                source: Box::new(self),
            },
            named => named,
        }
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
            Error::Malformed(message) | Error::Encode(message) => f.write_str(message),
            Error::InFile { path, source } => write!(f, "{}: {source}", escaped_path(path)),
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

/// A number computed from the user's (`alpha = r^2`) as a message shows it: [`shown`] of it
/// rounded to 12 significant digits (`0.058655027344`, not `0.058655027343999994`).
#[must_use]
pub fn brief(x: f64) -> String {
    let rounded = format!("{x:.11e}").parse::<f64>().unwrap_or(x);
    shown(rounded)
}

/// `1 table`, `3 tables`: a count with its noun, singular for one.
#[must_use]
pub fn count(n: usize, noun: &str) -> String {
    if n == 1 {
        format!("1 {noun}")
    } else {
        format!("{n} {noun}s")
    }
}

/// A number as a message shows it: plainly between 1e-4 and 1e6, in scientific notation beyond
/// (`1e155`, not 156 digits).
#[must_use]
pub fn shown(x: f64) -> String {
    if x == 0.0 || !x.is_finite() || (1e-4..1e6).contains(&x.abs()) {
        format!("{x}")
    } else {
        format!("{x:e}")
    }
}

/// Text from a file as a message quotes it: control characters (newlines, NUL, escape) and the
/// bidirectional overrides that reorder a terminal line shown escaped, at most 60 characters.
#[must_use]
pub fn quoted(text: &str) -> String {
    let mut out = String::new();
    for (n, c) in text.chars().enumerate() {
        if n == 60 {
            out.push('…');
            break;
        }
        if c.is_control() || is_bidi_control(c) {
            out.extend(c.escape_default());
        } else {
            out.push(c);
        }
    }
    format!("'{out}'")
}

/// A path as a message shows it, whole: control characters and bidirectional overrides
/// escaped as in [`quoted`] (a scene's `output.dir` is a file's text: issue 64, defect 9).
#[must_use]
pub fn escaped_path(path: &std::path::Path) -> String {
    escaped(&path.display().to_string())
}

/// Text from a file shown whole where it names something (a formula file's `name` and
/// `source`): control characters and bidirectional overrides escaped as in [`quoted`], no
/// quotes, no cut (issue 64, defect 7).
#[must_use]
pub fn escaped(text: &str) -> String {
    text.chars()
        .flat_map(|c| {
            let escape = c.is_control() || is_bidi_control(c);
            let (plain, escaped) = if escape {
                (None, Some(c.escape_default()))
            } else {
                (Some(c), None)
            };
            plain.into_iter().chain(escaped.into_iter().flatten())
        })
        .collect()
}

/// The Unicode bidirectional formatting characters (embeddings, overrides, isolates, marks),
/// which change how the text around them is displayed.
#[must_use]
pub fn is_bidi_control(c: char) -> bool {
    matches!(c, '\u{200e}' | '\u{200f}' | '\u{202a}'..='\u{202e}' | '\u{2066}'..='\u{2069}')
}
