//! The library's error type.
//!
//! Every error names the file it concerns (when there is one) and the cause,
//! so the command line can print it as one line: `path: cause`.

use std::path::PathBuf;

/// Result alias used throughout the library.
pub type Result<T, E = Error> = std::result::Result<T, E>;

/// Everything that can go wrong in flourish. Each variant renders as one
/// line, `file: cause`, suitable for stderr.
#[derive(Debug, thiserror::Error)]
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
    /// A raster file could not be decoded.
    #[error("{}: not a readable image: {reason}", shown(path))]
    Image {
        /// The file concerned.
        path: PathBuf,
        /// The decoder's explanation.
        reason: String,
    },
    /// An SVG file could not be parsed.
    #[error("{}: SVG does not parse: {reason}", shown(path))]
    Svg {
        /// The file concerned.
        path: PathBuf,
        /// The parser's explanation.
        reason: String,
    },
    /// An input or requested canvas exceeds the resource limits.
    #[error("{}: {} exceeds the size limit ({limit})", shown(path), canvas_size(*width, *height))]
    TooLarge {
        /// The file concerned.
        path: PathBuf,
        /// Requested width in pixels.
        width: u64,
        /// Requested height in pixels.
        height: u64,
        /// The limit, in words (e.g. "16384 px per side, 64 Mpx in all").
        limit: String,
    },
    /// The input is well-formed but cannot be used (degenerate, empty, NaN…).
    #[error("{}: {reason}", shown(path))]
    Invalid {
        /// The file concerned.
        path: PathBuf,
        /// What is wrong with it.
        reason: String,
    },
    /// A computation's input is degenerate and no file is concerned (a mesh
    /// with zero-area triangles, a matching with no candidates…).
    #[error("{subject}: {reason}")]
    Degenerate {
        /// What the input is (e.g. "ARAP mesh", "piecewise matching").
        subject: String,
        /// What is wrong with it.
        reason: String,
    },
    /// An option has a value the library cannot use.
    #[error("invalid option {name}: {reason}")]
    Option {
        /// The option's name as the user knows it (e.g. `--tolerance`).
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

    /// An [`Error::Invalid`] for `path`.
    pub fn invalid(path: impl Into<PathBuf>, reason: impl Into<String>) -> Self {
        Error::Invalid {
            path: path.into(),
            reason: reason.into(),
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
        let e = Error::invalid("new\nline\t.svg", "bad");
        assert_eq!(e.to_string(), "new\\nline\\t.svg: bad");
        assert_eq!(
            Error::invalid("plain ✓.svg", "bad").to_string(),
            "plain ✓.svg: bad"
        );
    }

    #[test]
    fn size_errors_read_well_for_sane_and_absurd_sizes() {
        let e = |width, height| {
            Error::TooLarge {
                path: "s.svg".into(),
                width,
                height,
                limit: "L".into(),
            }
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
