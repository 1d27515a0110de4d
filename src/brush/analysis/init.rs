//! `flourish style init`: a folder of exemplar drawings made a brush
//! library in one command. Every SVG or raster file of the folder is read
//! as an exemplar ([`super::exemplar::load`]) and its main branch's ends
//! are found ([`super::ends`]); the `style.toml` text lists them, so the
//! designer can check them on `style check`'s sheet and move them.

use super::ends::{find_ends, Found};
use super::exemplar;
use super::spine::SpineOptions;
use super::{DEFAULT_RESOLUTION, DIJKSTRA_MAX_SIDE};
use crate::error::{Error, Result};
use std::fmt::Write as _;
use std::path::{Path, PathBuf};

/// File extensions read as exemplars (lower case).
pub const EXEMPLAR_EXTENSIONS: [&str; 8] =
    ["svg", "svgz", "png", "jpg", "jpeg", "bmp", "gif", "webp"];

/// Most exemplars one folder may hold.
pub const MAX_EXEMPLARS: usize = 1000;

/// One exemplar of a new library.
#[derive(Clone, Debug, PartialEq)]
pub struct InitExemplar {
    /// The file, relative to the folder.
    pub file: PathBuf,
    /// Its spine's start and end, user units; `None` when the drawing has
    /// its own `id="spine"` path.
    pub ends: Option<[[f64; 2]; 2]>,
    /// Whether the ends are a fallback (no clear main branch).
    pub fallback: bool,
}

/// What `style init` found in a folder.
#[derive(Clone, Debug, PartialEq)]
pub struct InitReport {
    /// The library's finest resolution, px.
    pub resolution: u32,
    /// The exemplars, in file-name order.
    pub exemplars: Vec<InitExemplar>,
    /// Files passed over, one line each (file and cause).
    pub skipped: Vec<String>,
}

impl InitReport {
    /// The `style.toml` text of the library.
    pub fn to_toml(&self) -> String {
        let mut s = String::new();
        let _ = writeln!(
            s,
            "# A brush library written by `flourish style init` from the drawings in this folder.\n\
             # Each exemplar's start and end were found at the two ends of its main branch:\n\
             # check them on the sheet of `flourish style check DIR --sheet sheet.png`\n\
             # and move them where they should be (exemplar user units, y down).\n\
             kind = \"brush\"\nresolution = {}",
            self.resolution
        );
        for e in &self.exemplars {
            let _ = writeln!(s, "\n[[exemplar]]");
            if e.fallback {
                let _ = writeln!(
                    s,
                    "# no clear main branch (a dot or a ring?): these ends run across its longer side"
                );
            }
            let _ = writeln!(s, "file = {}", toml_string(&e.file.to_string_lossy()));
            match e.ends {
                Some([a, b]) => {
                    let _ = writeln!(s, "start = [{:.1}, {:.1}]", a[0], a[1]);
                    let _ = writeln!(s, "end = [{:.1}, {:.1}]", b[0], b[1]);
                }
                None => {
                    let _ = writeln!(
                        s,
                        "# the drawing's own path id=\"spine\" is its main branch"
                    );
                }
            }
        }
        s
    }
}

/// A TOML basic string.
fn toml_string(v: &str) -> String {
    let mut out = String::from("\"");
    for c in v.chars() {
        match c {
            '"' => out.push_str("\\\""),
            '\\' => out.push_str("\\\\"),
            c if (c as u32) < 0x20 || c == '\u{7f}' => {
                let _ = write!(out, "\\u{:04X}", c as u32);
            }
            c => out.push(c),
        }
    }
    out.push('"');
    out
}

/// The exemplar files of `dir` (by extension), sorted by name.
pub fn exemplar_files(dir: &Path) -> Result<Vec<PathBuf>> {
    let entries = std::fs::read_dir(dir).map_err(|e| Error::io(dir, e))?;
    let mut files: Vec<PathBuf> = entries
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| p.is_file())
        .filter(|p| {
            p.extension()
                .and_then(|e| e.to_str())
                .is_some_and(|e| EXEMPLAR_EXTENSIONS.contains(&e.to_ascii_lowercase().as_str()))
        })
        .collect();
    files.sort();
    Ok(files)
}

/// Reads every exemplar file of `dir` at `resolution` (px, the finest
/// level; `None`: [`DEFAULT_RESOLUTION`]) and finds its ends. Files that
/// cannot be read as exemplars (not a drawing, no ink) are passed over
/// with a line in [`InitReport::skipped`]; a folder with none is an error.
pub fn init(dir: &Path, resolution: Option<u32>) -> Result<InitReport> {
    let resolution = resolution.unwrap_or(DEFAULT_RESOLUTION);
    if !(64..=1024).contains(&resolution) {
        return Err(Error::Option {
            name: "resolution",
            reason: format!("{resolution} is not in 64..=1024 px"),
        });
    }
    let files = exemplar_files(dir)?;
    if files.len() > MAX_EXEMPLARS {
        return Err(Error::invalid(format!(
            "{} drawings: more than {MAX_EXEMPLARS} exemplars in one library",
            files.len()
        ))
        .in_file(dir));
    }
    let found: Vec<std::result::Result<InitExemplar, String>> = {
        use rayon::prelude::*;
        files
            .par_iter()
            .map(|path| init_one(dir, path, resolution).map_err(|e| e.in_file(path).to_string()))
            .collect()
    };
    let mut report = InitReport {
        resolution,
        exemplars: Vec::new(),
        skipped: Vec::new(),
    };
    for f in found {
        match f {
            Ok(e) => report.exemplars.push(e),
            Err(why) => report.skipped.push(why),
        }
    }
    if report.exemplars.is_empty() {
        let why = match report.skipped.first() {
            Some(w) => format!(" ({} passed over; first: {w})", report.skipped.len()),
            None => String::new(),
        };
        return Err(Error::invalid(format!(
            "no exemplar drawings (SVG or raster files with ink) in the folder{why}"
        ))
        .in_file(dir));
    }
    Ok(report)
}

/// One exemplar: its drawing read and its ends found.
fn init_one(dir: &Path, path: &Path, resolution: u32) -> Result<InitExemplar> {
    let ink = exemplar::load(path, resolution)?;
    let file = path.strip_prefix(dir).unwrap_or(path).to_path_buf();
    if ink.drawn_spine.as_ref().is_some_and(|s| s.len() >= 2) {
        return Ok(InitExemplar {
            file,
            ends: None,
            fallback: false,
        });
    }
    let level = ink
        .levels
        .iter()
        .rev()
        .find(|l| l.ink.width().max(l.ink.height()) <= DIJKSTRA_MAX_SIDE)
        .or(ink.levels.first())
        .ok_or_else(|| Error::invalid("no pyramid levels"))?;
    let ends = find_ends(&level.ink, &SpineOptions::default())
        .ok_or_else(|| Error::invalid("blank exemplar: it has no ink"))?;
    let user = |p: kurbo::Point| {
        [
            (p.x / level.px_per_unit).clamp(0.0, ink.size[0]),
            (p.y / level.px_per_unit).clamp(0.0, ink.size[1]),
        ]
    };
    Ok(InitExemplar {
        file,
        ends: Some([user(ends.start), user(ends.end)]),
        fallback: ends.found == Found::Fallback,
    })
}
