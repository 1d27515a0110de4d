//! The library's error type.
//!
//! Every error names the file it concerns (when there is one) and the cause,
//! so the command line can print it as one line: `path: cause`.

use std::path::PathBuf;

/// Result alias used throughout the library.
pub type Result<T, E = Error> = std::result::Result<T, E>;

/// Everything that can go wrong in flourish. Each error renders as one
/// line: the file it concerns (attached by whoever read the file, see
/// [`Error::in_file`]), the part of the input (a query, an exemplar), and
/// the cause, e.g. `sketch.svg: query q-1: 7672×7672 px exceeds the size
/// limit (…)`.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum Error {
    /// Reading or writing a file failed.
    #[error("{}: {source}", shown(path))]
    Io {
        /// The file concerned.
        path: PathBuf,
        /// The operating system's error.
        #[source]
        source: std::io::Error,
    },
    /// Something is wrong in a file.
    #[error("{}: {source}", shown(path))]
    File {
        /// The file concerned.
        path: PathBuf,
        /// What is wrong in it.
        #[source]
        source: Box<Error>,
    },
    /// Something is wrong in one part of the input: a query, an exemplar.
    #[error("{part}: {source}")]
    Part {
        /// The part, as the user knows it (e.g. `query q-1`).
        part: String,
        /// What is wrong with it.
        #[source]
        source: Box<Error>,
    },
    /// Raster bytes could not be decoded.
    #[error("not a readable image: {0}")]
    Image(String),
    /// SVG bytes could not be parsed.
    #[error("SVG does not parse: {0}")]
    Svg(String),
    /// An input or a canvas it asks for exceeds the resource limits.
    #[error("{} exceeds the size limit ({limit})", canvas_size(*width, *height))]
    TooLarge {
        /// Requested width in pixels.
        width: u64,
        /// Requested height in pixels.
        height: u64,
        /// The limit, in words (e.g. "16384 px per side, 64 Mpx in all").
        limit: String,
    },
    /// The input is well-formed but cannot be used (degenerate, empty,
    /// NaN…): the reason, in words.
    #[error("{0}")]
    Invalid(String),
    /// A computation's input is degenerate (a mesh with zero-area
    /// triangles, a matching with no candidates…).
    #[error("{subject}: {reason}")]
    Degenerate {
        /// What the input is (e.g. "ARAP mesh", "piecewise matching").
        subject: String,
        /// What is wrong with it.
        reason: String,
    },
    /// The run was cancelled through its options' [`crate::Cancel`]
    /// handle before it finished.
    #[error("cancelled")]
    Cancelled,
    /// An option has a value the library cannot use.
    #[error("invalid option {name}: {reason}")]
    Option {
        /// The option's field name (e.g. `tolerance`, `min_area`).
        name: &'static str,
        /// What is wrong with the value.
        reason: String,
    },
}

impl Error {
    /// An [`Error::Io`] for `path`.
    pub fn io(path: impl Into<PathBuf>, source: std::io::Error) -> Self {
        Error::Io {
            path: path.into(),
            source,
        }
    }

    /// An [`Error::Degenerate`] for `subject`.
    pub fn degenerate(subject: impl Into<String>, reason: impl Into<String>) -> Self {
        Error::Degenerate {
            subject: subject.into(),
            reason: reason.into(),
        }
    }

    /// An [`Error::Invalid`].
    pub fn invalid(reason: impl Into<String>) -> Self {
        Error::Invalid(reason.into())
    }

    /// This error as one in file `path`, unless it already names a file.
    pub fn in_file(self, path: impl Into<PathBuf>) -> Self {
        match self {
            Error::Io { .. } | Error::File { .. } => self,
            e => Error::File {
                path: path.into(),
                source: Box::new(e),
            },
        }
    }

    /// This error as one in `part` of the input (e.g. `query q-1`), unless
    /// it already names a file.
    pub fn in_part(self, part: impl Into<String>) -> Self {
        match self {
            Error::Io { .. } | Error::File { .. } => self,
            e => Error::Part {
                part: part.into(),
                source: Box::new(e),
            },
        }
    }

    /// The file this error names, if any.
    pub fn file(&self) -> Option<&std::path::Path> {
        match self {
            Error::Io { path, .. } | Error::File { path, .. } => Some(path),
            _ => None,
        }
    }

    /// The cause under the file and part that name where it happened.
    pub fn cause(&self) -> &Error {
        match self {
            Error::File { source, .. } | Error::Part { source, .. } => source.cause(),
            e => e,
        }
    }
}

/// A path for a one-line message: control characters (a newline in a file
/// name) written as escapes, so the message stays on one line.
fn shown(path: &std::path::Path) -> String {
    let text = path.display().to_string();
    if !text.chars().any(char::is_control) {
        return text;
    }
    text.chars()
        .map(|c| {
            if c.is_control() {
                c.escape_default().to_string()
            } else {
                c.to_string()
            }
        })
        .collect()
}

/// A canvas size for messages: `W×H px` up to a billion px per side, else
/// its order of magnitude (a saturated 2⁶⁴ − 1 from absurd coordinates
/// reads "over 10¹⁹ px per side").
fn canvas_size(width: u64, height: u64) -> String {
    let side = width.max(height);
    if side < 1_000_000_000 {
        return format!("{width}×{height} px");
    }
    const SUP: [char; 10] = ['⁰', '¹', '²', '³', '⁴', '⁵', '⁶', '⁷', '⁸', '⁹'];
    let digits: String = side
        .ilog10()
        .to_string()
        .chars()
        .filter_map(|c| c.to_digit(10))
        .map(|d| SUP[d as usize])
        .collect();
    format!("a canvas of over 10{digits} px per side")
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A file name with a newline or other control character is named
    /// on one line, its control characters escaped.
    #[test]
    fn file_names_are_shown_on_one_line() {
        let e = Error::invalid("bad").in_file("new\nline\t.svg");
        assert_eq!(e.to_string(), "new\\nline\\t.svg: bad");
        assert_eq!(
            Error::invalid("bad").in_file("plain ✓.svg").to_string(),
            "plain ✓.svg: bad"
        );
    }

    #[test]
    fn size_errors_read_well_for_sane_and_absurd_sizes() {
        let e = |width, height| {
            Error::TooLarge {
                width,
                height,
                limit: "L".into(),
            }
            .in_file("s.svg")
            .to_string()
        };
        assert_eq!(
            e(50_000, 20),
            "s.svg: 50000×20 px exceeds the size limit (L)"
        );
        assert_eq!(
            e(u64::MAX, 3),
            "s.svg: a canvas of over 10¹⁹ px per side exceeds the size limit (L)"
        );
    }
}
