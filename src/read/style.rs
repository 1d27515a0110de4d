//! A style's description: `style.toml`, read and validated ([`StyleToml`],
//! [`load`]). A style is a folder holding `style.toml` and its exemplar
//! files; finding one by name is [`crate::library::Library::find`], and
//! analysing it belongs to its mode: a brush library's exemplars in
//! [`crate::brush::analysis`] ([`crate::brush::analysis::BrushStyle::load`]),
//! a fill style's tile in [`crate::fill::tile`], a pattern example's
//! elements in [`crate::pattern::PatternStyle`].
//!
//! Every error names the `style.toml` file and, where there is one, the key.

use crate::error::{Error, Result};
use serde::Deserialize;
use std::path::{Path, PathBuf};

/// Most `[[exemplar]]` tables a style may list: each is analysed and held
/// in memory, and a library of a hundred is already large.
pub const MAX_EXEMPLARS: usize = 100;

/// The file name of a style's description inside its folder.
pub const STYLE_FILE: &str = "style.toml";

/// What a style library is for (`kind = "..."`).
#[derive(Clone, Copy, Debug, Deserialize, PartialEq, Eq)]
#[serde(rename_all = "lowercase")]
pub enum StyleKind {
    /// Decorative strokes along open paths.
    Brush,
    /// Art patterns inside closed shapes.
    Fill,
    /// Element patterns along paths and inside regions.
    Pattern,
}

impl StyleKind {
    /// The name used in `style.toml`.
    pub fn name(self) -> &'static str {
        match self {
            StyleKind::Brush => "brush",
            StyleKind::Fill => "fill",
            StyleKind::Pattern => "pattern",
        }
    }
}

/// Which points an element's oriented box is fitted to (Barla et al. §2.1).
#[derive(Clone, Copy, Debug, Default, Deserialize, PartialEq, Eq)]
#[serde(rename_all = "lowercase")]
pub enum FitPoints {
    /// The points of the stroke's centre line (the gesture).
    Skeleton,
    /// The points of the painted outline (stroke width and caps included).
    #[default]
    Contour,
}

/// One `[[exemplar]]` table.
#[derive(Clone, Debug, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct ExemplarToml {
    /// The exemplar file, relative to the style folder.
    pub file: PathBuf,
    /// Brush: spine start, in the exemplar's user units. With a drawn
    /// `id="spine"` path in the exemplar, the path is the spine and
    /// `start` only says which of its ends is the start.
    pub start: Option<[f64; 2]>,
    /// Brush: spine end, in the exemplar's user units (given with `start`).
    pub end: Option<[f64; 2]>,
}

/// The contents of `style.toml`. Fields that only some kinds use are
/// optional here and checked by [`StyleToml::validate`] for the kind at hand.
#[derive(Clone, Debug, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct StyleToml {
    /// `brush`, `fill` or `pattern`.
    pub kind: StyleKind,
    /// Raster modes: finest synthesis resolution of an exemplar, px (64..1024).
    pub resolution: Option<u32>,
    /// Raster modes: synthesize a signed distance field (true) or coverage.
    pub sdf: Option<bool>,
    /// The exemplar files.
    #[serde(default)]
    pub exemplar: Vec<ExemplarToml>,
    /// Pattern: ε, the distance in the example's user units below which
    /// strokes are perceived as one element (Barla et al. §2.2).
    /// Fill: sketch units per tile user unit (default 1).
    pub scale: Option<f64>,
    /// Pattern: neighbourhood size in rings of the neighbour graph used
    /// when matching (Barla et al. §3.1, 1..=6; default 2).
    pub rings: Option<u32>,
    /// Pattern: fit element boxes to the stroke `skeleton` or `contour`
    /// (default `contour`).
    pub fit: Option<FitPoints>,
    /// Pattern: whether the example is a row (1) or a field (2) of
    /// elements; detected from the element centres when absent.
    pub dimension: Option<u8>,
    /// Pattern: maximum Lloyd iterations for 2-D seeds (1..=1000; default 60).
    pub lloyd_iterations: Option<u32>,
    /// Fill: the tile's own direction, `"etf"` (estimated from the tile,
    /// Brushables §3.1) or a constant `[x, y]` in the tile's axes (y down).
    pub direction: Option<DirectionToml>,
    /// Fill: what the tile's `direction` follows in a shape that no stroke
    /// combs: `"outline"` (the outline's flow, Brushables §3.1; the
    /// default) or a constant `[x, y]` in the sketch's axes (y down), for
    /// patterns with one "up" such as scales, which cannot follow the vortex
    /// that the flow of a closed outline turns around.
    pub flow: Option<DirectionToml>,
    /// Fill: finest patch side in tile pixels (odd, 3..=33; default 9).
    pub patch: Option<u32>,
    /// Fill: pyramid levels (1..=5; default 3).
    pub levels: Option<u32>,
    /// Fill: EM iterations per level (1..=20; default 4).
    pub iterations: Option<u32>,
    /// Fill: colour weight α of the matching energy (0..=1; default 0.25).
    pub alpha: Option<f64>,
}

/// A fill style's `direction`: a named estimate or a constant vector.
#[derive(Clone, Debug, Deserialize, PartialEq)]
#[serde(untagged)]
pub enum DirectionToml {
    /// A constant direction `[x, y]`.
    Vector([f64; 2]),
    /// A named estimate: `"etf"`.
    Named(String),
}

/// Checks a fill style's direction-like key: a finite non-zero `[x, y]` or
/// the one accepted name.
fn check_direction(
    path: &Path,
    key: &str,
    value: &Option<DirectionToml>,
    name: &str,
) -> Result<()> {
    let why = match value {
        Some(DirectionToml::Vector(v))
            if !(v[0].is_finite() && v[1].is_finite() && v[0].hypot(v[1]) > 1e-9) =>
        {
            format!("must be a non-zero vector, got {v:?}")
        }
        Some(DirectionToml::Named(n)) if n != name => {
            format!("must be \"{name}\" or [x, y], got \"{n}\"")
        }
        _ => return Ok(()),
    };
    Err(Error::invalid(format!("{key}: {why}")).in_file(path))
}

/// Parses `style.toml` text; `path` names the file in errors.
pub fn parse(path: &Path, text: &str) -> Result<StyleToml> {
    let parsed: StyleToml = toml::from_str(text).map_err(|e| {
        // toml's own rendering spans several lines; keep one: line + message.
        let line = e
            .span()
            .map(|s| text[..s.start.min(text.len())].matches('\n').count() + 1);
        let msg = e.message().replace('\n', " ");
        match line {
            Some(l) => Error::invalid(format!("line {l}: {}", msg.trim())).in_file(path),
            None => Error::invalid(msg.trim().to_string()).in_file(path),
        }
    })?;
    parsed.validate(path)?;
    Ok(parsed)
}

/// Reads and parses `dir/style.toml`.
pub fn load(dir: &Path) -> Result<StyleToml> {
    let path = dir.join(STYLE_FILE);
    let bytes = crate::io::read_file(&path)?;
    let text =
        String::from_utf8(bytes).map_err(|_| Error::invalid("not UTF-8 text").in_file(&path))?;
    parse(&path, &text)
}

impl StyleToml {
    /// Checks value ranges that serde cannot express; errors name the key.
    pub fn validate(&self, path: &Path) -> Result<()> {
        let bad =
            |key: &str, why: String| Err(Error::invalid(format!("{key}: {why}")).in_file(path));
        if self.exemplar.len() > MAX_EXEMPLARS {
            return bad(
                "exemplar",
                format!(
                    "{} exemplars, more than the limit of {MAX_EXEMPLARS}",
                    self.exemplar.len()
                ),
            );
        }
        if let Some(r) = self.resolution {
            if !(64..=1024).contains(&r) {
                return bad("resolution", format!("must be within 64..1024 px, got {r}"));
            }
        }
        if let Some(s) = self.scale {
            if !(s.is_finite() && s > 0.0) {
                return bad("scale", format!("must be a positive number, got {s}"));
            }
        }
        if let Some(r) = self.rings {
            if !(1..=6).contains(&r) {
                return bad("rings", format!("must be within 1..6, got {r}"));
            }
        }
        if let Some(d) = self.dimension {
            if d != 1 && d != 2 {
                return bad(
                    "dimension",
                    format!("must be 1 (a row) or 2 (a field), got {d}"),
                );
            }
        }
        if let Some(n) = self.lloyd_iterations {
            if !(1..=1000).contains(&n) {
                return bad(
                    "lloyd_iterations",
                    format!("must be within 1..1000, got {n}"),
                );
            }
        }
        for (i, ex) in self.exemplar.iter().enumerate() {
            if ex.file.is_absolute()
                || ex
                    .file
                    .components()
                    .any(|c| matches!(c, std::path::Component::ParentDir))
            {
                return bad(
                    &format!("exemplar[{i}].file"),
                    format!(
                        "{} must be a path inside the style folder",
                        ex.file.display()
                    ),
                );
            }
        }
        if self.kind == StyleKind::Brush {
            // (An empty library is refused by the brush analysis itself, so
            // other commands report the wrong kind first.)
            for (i, ex) in self.exemplar.iter().enumerate() {
                for (key, p) in [("start", ex.start), ("end", ex.end)] {
                    if let Some([x, y]) = p {
                        if !(x.is_finite() && y.is_finite()) {
                            return bad(
                                &format!("exemplar[{i}].{key}"),
                                format!("must be two finite numbers, got [{x}, {y}]"),
                            );
                        }
                    }
                }
                match (ex.start, ex.end) {
                    (Some(a), Some(b)) if a == b => {
                        return bad(
                            &format!("exemplar[{i}].end"),
                            format!(
                                "equals start [{}, {}]; the spine needs two ends",
                                a[0], a[1]
                            ),
                        );
                    }
                    (Some(_), None) | (None, Some(_)) => {
                        let missing = if ex.start.is_none() { "start" } else { "end" };
                        return bad(
                            &format!("exemplar[{i}].{missing}"),
                            "missing; give both start and end (or neither, with a path id=\"spine\" in the exemplar)".into(),
                        );
                    }
                    _ => {}
                }
            }
        }
        if self.kind == StyleKind::Fill {
            self.validate_fill(path)?;
        }
        if self.kind == StyleKind::Pattern {
            if self.scale.is_none() {
                return bad(
                    "scale",
                    "missing; a pattern style needs scale = ε (e.g. 12.0)".into(),
                );
            }
            if self.exemplar.len() != 1 {
                return bad(
                    "exemplar",
                    format!(
                        "a pattern style takes exactly one example SVG, found {}",
                        self.exemplar.len()
                    ),
                );
            }
        }
        Ok(())
    }

    /// The fill keys: ranges, and exactly one tile.
    fn validate_fill(&self, path: &Path) -> Result<()> {
        let bad =
            |key: &str, why: String| Err(Error::invalid(format!("{key}: {why}")).in_file(path));
        check_direction(path, "direction", &self.direction, "etf")?;
        check_direction(path, "flow", &self.flow, "outline")?;
        if let Some(p) = self.patch {
            if !(3..=33).contains(&p) || p % 2 == 0 {
                return bad("patch", format!("must be odd and within 3..33 px, got {p}"));
            }
        }
        if let Some(l) = self.levels {
            if !(1..=5).contains(&l) {
                return bad("levels", format!("must be within 1..5, got {l}"));
            }
        }
        if let Some(n) = self.iterations {
            if !(1..=20).contains(&n) {
                return bad("iterations", format!("must be within 1..20, got {n}"));
            }
        }
        if let Some(a) = self.alpha {
            if !(0.0..=1.0).contains(&a) {
                return bad("alpha", format!("must be within 0..1, got {a}"));
            }
        }
        if self.exemplar.len() != 1 {
            return bad(
                "exemplar",
                format!(
                    "a fill style takes exactly one tile (SVG or PNG), found {}",
                    self.exemplar.len()
                ),
            );
        }
        Ok(())
    }

    /// Fails unless the style is of `kind`.
    pub fn expect_kind(&self, path: &Path, kind: StyleKind) -> Result<()> {
        if self.kind != kind {
            return Err(Error::invalid(format!(
                "kind: is \"{}\", this command needs \"{}\"",
                self.kind.name(),
                kind.name()
            ))
            .in_file(path.join(STYLE_FILE)));
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn pattern_style_parses() {
        let s = parse(
            Path::new("s/style.toml"),
            "kind = \"pattern\"\nscale = 12.0\n[[exemplar]]\nfile = \"ex.svg\"\n",
        )
        .unwrap();
        assert_eq!(s.kind, StyleKind::Pattern);
        assert_eq!(s.scale, Some(12.0));
    }

    #[test]
    fn fill_style_keys_parse_and_are_checked() {
        let ok = parse(
            Path::new("s/style.toml"),
            "kind = \"fill\"\ndirection = \"etf\"\npatch = 7\nlevels = 2\n[[exemplar]]\nfile = \"t.svg\"\n",
        )
        .unwrap();
        assert_eq!(ok.direction, Some(DirectionToml::Named("etf".into())));
        for (extra, key) in [
            ("direction = [0.0, 0.0]", "direction"),
            ("direction = \"north\"", "direction"),
            ("flow = [0.0, 0.0]", "flow"),
            ("flow = \"vortex\"", "flow"),
            ("patch = 8", "patch"),
            ("levels = 9", "levels"),
            ("iterations = 0", "iterations"),
            ("alpha = 2.0", "alpha"),
        ] {
            let e = parse(
                Path::new("s/style.toml"),
                &format!("kind = \"fill\"\n{extra}\n[[exemplar]]\nfile = \"t.svg\"\n"),
            )
            .unwrap_err()
            .to_string();
            assert!(e.starts_with("s/style.toml: ") && e.contains(key), "{e}");
        }
        let e = parse(Path::new("s/style.toml"), "kind = \"fill\"\n")
            .unwrap_err()
            .to_string();
        assert!(e.contains("exemplar"), "{e}");
    }

    #[test]
    fn bad_values_name_file_and_key() {
        for (text, key) in [
            (
                "kind = \"pattern\"\nscale = -1.0\n[[exemplar]]\nfile = \"a.svg\"\n",
                "scale",
            ),
            (
                "kind = \"pattern\"\nscale = nan\n[[exemplar]]\nfile = \"a.svg\"\n",
                "scale",
            ),
            (
                "kind = \"pattern\"\n[[exemplar]]\nfile = \"a.svg\"\n",
                "scale",
            ),
            (
                "kind = \"pattern\"\nscale = 2.0\nrings = 9\n[[exemplar]]\nfile = \"a.svg\"\n",
                "rings",
            ),
            ("kind = \"pattern\"\nscale = 2.0\nbogus = 1\n", "bogus"),
            (
                "kind = \"pattern\"\nscale = 2.0\n[[exemplar]]\nfile = \"../x.svg\"\n",
                "exemplar[0].file",
            ),
        ] {
            let e = parse(Path::new("s/style.toml"), text)
                .unwrap_err()
                .to_string();
            assert!(e.starts_with("s/style.toml: "), "{e}");
            assert!(e.contains(key), "{e}");
            assert!(!e.contains('\n'), "{e}");
        }
    }
}
