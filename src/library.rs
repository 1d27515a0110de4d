//! Style libraries: finding a style by name on a search path and loading
//! it as the kind its `style.toml` declares.
//!
//! A style is a folder holding `style.toml` and its exemplar files
//! (SPEC.md, "Style library"). Loading analyses it once: a brush library's
//! exemplars (DecoBrush §4, cached on disk), a fill style's tile, a pattern
//! example's elements (Barla et al. §2). A sketch's shapes may name another
//! style with `data-style="NAME"`; [`Library::load_named`] loads those, and
//! [`Styles`] hands a mode the default style with them.

use crate::brush::analysis::{AnalysisOptions, BrushStyle};
use crate::error::{Error, Result};
use crate::fill::FillStyle;
use crate::pattern::PatternStyle;
use crate::read::sketch::{Query, QueryKind, Sketch};
use crate::read::style::{self as toml, StyleKind, STYLE_FILE};
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::sync::Arc;

/// How a style is loaded.
#[derive(Clone, Debug)]
pub struct StyleOptions {
    /// Refuse a style of another kind before its exemplars are read
    /// (default `None`: any kind).
    pub kind: Option<StyleKind>,
    /// Fill: the tile's raster size, px on its longest side, in place of
    /// the style's `resolution` (8..=1024; default `None`: the style's).
    pub resolution: Option<u32>,
    /// Brush: the analysis cache folder (default `None`:
    /// `$FLOURISH_CACHE_DIR`, else the platform's cache folder).
    pub cache_dir: Option<PathBuf>,
    /// Brush: read and write the analysis cache (default `true`).
    pub use_cache: bool,
}

impl Default for StyleOptions {
    fn default() -> Self {
        StyleOptions {
            kind: None,
            resolution: None,
            cache_dir: None,
            use_cache: true,
        }
    }
}

impl StyleOptions {
    /// Checks every value's range.
    pub fn validate(&self) -> Result<()> {
        if let Some(r) = self.resolution {
            if !(8..=1024).contains(&r) {
                return Err(Error::Option {
                    name: "resolution",
                    reason: format!("{r} is not in 8..=1024 px"),
                });
            }
        }
        Ok(())
    }
}

/// A loaded style: analysed and ready for the mode of its kind. Cloning it
/// is cheap (the analysis is shared).
#[derive(Clone, Debug)]
pub struct Style {
    name: String,
    dir: PathBuf,
    files: Vec<PathBuf>,
    loaded: Arc<Loaded>,
}

/// A style's analysis, by kind.
#[derive(Debug)]
pub(crate) enum Loaded {
    Brush(BrushStyle),
    Fill(FillStyle),
    Pattern(Arc<PatternStyle>),
}

impl Style {
    /// Loads the style in folder `dir`; its name is the folder as given.
    pub fn load(dir: &Path, opts: &StyleOptions) -> Result<Style> {
        Self::load_named_as(&dir.display().to_string(), dir, opts)
    }

    /// Loads the style in `dir`, known by `name` in notes.
    fn load_named_as(name: &str, dir: &Path, opts: &StyleOptions) -> Result<Style> {
        opts.validate()?;
        let toml_path = dir.join(STYLE_FILE);
        if !crate::io::is_regular_file(&toml_path) {
            return Err(Error::invalid("not a regular file").in_file(toml_path));
        }
        let manifest = toml::load(dir)?;
        check_files(dir, &manifest)?;
        let kind = manifest.kind;
        if let Some(want) = opts.kind {
            wrong_kind(dir, kind, want)?;
        }
        let loaded = match kind {
            StyleKind::Brush => Loaded::Brush(BrushStyle::load(
                dir,
                &AnalysisOptions {
                    cache_dir: opts.cache_dir.clone(),
                    use_cache: opts.use_cache,
                    ..AnalysisOptions::default()
                },
            )?),
            StyleKind::Fill => Loaded::Fill(FillStyle::load(dir, opts.resolution)?),
            StyleKind::Pattern => Loaded::Pattern(Arc::new(PatternStyle::load(dir)?)),
        };
        let files = std::iter::once(dir.join(STYLE_FILE))
            .chain(manifest.exemplar.iter().map(|e| dir.join(&e.file)))
            .collect();
        Ok(Style {
            name: name.to_string(),
            dir: dir.to_path_buf(),
            files,
            loaded: Arc::new(loaded),
        })
    }

    /// The name it was loaded by.
    pub fn name(&self) -> &str {
        &self.name
    }

    /// Its folder.
    pub fn dir(&self) -> &Path {
        &self.dir
    }

    /// Its files: `style.toml`, then the exemplars it lists.
    pub fn files(&self) -> &[PathBuf] {
        &self.files
    }

    /// What it is for.
    pub fn kind(&self) -> StyleKind {
        match &*self.loaded {
            Loaded::Brush(_) => StyleKind::Brush,
            Loaded::Fill(_) => StyleKind::Fill,
            Loaded::Pattern(_) => StyleKind::Pattern,
        }
    }

    /// The brush analysis, or the error a brush command gives for
    /// another kind.
    pub(crate) fn brush(&self) -> Result<&BrushStyle> {
        match &*self.loaded {
            Loaded::Brush(b) => Ok(b),
            _ => Err(self.refused(StyleKind::Brush)),
        }
    }

    /// The fill analysis (see [`Style::brush`]).
    pub(crate) fn fill(&self) -> Result<&FillStyle> {
        match &*self.loaded {
            Loaded::Fill(f) => Ok(f),
            _ => Err(self.refused(StyleKind::Fill)),
        }
    }

    /// The pattern analysis (see [`Style::brush`]).
    pub(crate) fn pattern(&self) -> Result<&Arc<PatternStyle>> {
        match &*self.loaded {
            Loaded::Pattern(p) => Ok(p),
            _ => Err(self.refused(StyleKind::Pattern)),
        }
    }

    fn refused(&self, want: StyleKind) -> Error {
        match wrong_kind(&self.dir, self.kind(), want) {
            Err(e) => e,
            Ok(()) => Error::invalid("the style is of the right kind"),
        }
    }
}

/// Checks that every exemplar `toml` lists is a regular file inside the
/// style folder `dir` once symbolic links are followed: a link may not
/// lead a style out of its folder (to `/etc/passwd`, say), and a FIFO or a
/// device would block or never end when read. Errors name the key.
fn check_files(dir: &Path, toml: &toml::StyleToml) -> Result<()> {
    let toml_path = dir.join(STYLE_FILE);
    let bad = |i: usize, why: String| {
        Err(Error::invalid(format!("exemplar[{i}].file: {why}")).in_file(&toml_path))
    };
    let home = std::fs::canonicalize(dir).map_err(|e| Error::io(dir, e))?;
    for (i, ex) in toml.exemplar.iter().enumerate() {
        let path = dir.join(&ex.file);
        let Ok(real) = std::fs::canonicalize(&path) else {
            return bad(i, format!("{} does not exist", ex.file.display()));
        };
        if !real.starts_with(&home) {
            return bad(
                i,
                format!("{} leads out of the style folder", ex.file.display()),
            );
        }
        if !crate::io::is_regular_file(&real) {
            return bad(i, format!("{} is not a regular file", ex.file.display()));
        }
    }
    Ok(())
}

/// The error for a style of kind `is` where `want` is needed, naming its
/// `style.toml`.
fn wrong_kind(dir: &Path, is: StyleKind, want: StyleKind) -> Result<()> {
    if is == want {
        return Ok(());
    }
    Err(Error::invalid(format!(
        "kind: is \"{}\", this command needs \"{}\"",
        is.name(),
        want.name()
    ))
    .in_file(dir.join(STYLE_FILE)))
}

/// The styles a mode decorates a sketch with: `default` for every query,
/// and for a query whose shape names another with `data-style="NAME"`,
/// the style loaded under that name.
#[derive(Clone, Copy, Debug)]
pub struct Styles<'a> {
    default: &'a Style,
    named: Option<&'a BTreeMap<String, Style>>,
}

impl<'a> Styles<'a> {
    /// `default`, and `named` for the shapes that name one
    /// ([`Library::load_named`]).
    pub fn new(default: &'a Style, named: &'a BTreeMap<String, Style>) -> Self {
        Styles {
            default,
            named: Some(named),
        }
    }

    /// The default style.
    pub(crate) fn default_style(&self) -> &'a Style {
        self.default
    }

    /// The style of query `q` and the name it goes by.
    pub(crate) fn of(&self, q: &Query) -> Result<&'a Style> {
        match &q.style {
            None => Ok(self.default),
            Some(name) => self.named.and_then(|m| m.get(name)).ok_or_else(|| {
                Error::invalid(format!("data-style \"{name}\" was not loaded")).in_part(&q.id)
            }),
        }
    }
}

impl<'a> From<&'a Style> for Styles<'a> {
    fn from(default: &'a Style) -> Self {
        Styles {
            default,
            named: None,
        }
    }
}

/// Where named styles are found: folders searched in order.
#[derive(Clone, Debug)]
pub struct Library {
    dirs: Vec<PathBuf>,
}

impl Library {
    /// The library of the folders `dirs`, searched in order.
    pub fn new<P: Into<PathBuf>>(dirs: impl IntoIterator<Item = P>) -> Library {
        Library {
            dirs: dirs.into_iter().map(Into::into).collect(),
        }
    }

    /// The styles shipped with flourish (they travel inside the binary).
    pub fn shipped() -> Library {
        Library::new([shipped_dir()])
    }

    /// The command line's search path: the folders `extra` (`--styles
    /// DIR`), then those of `$FLOURISH_STYLES` (separated like `PATH`),
    /// then the shipped styles.
    pub fn search<P: Into<PathBuf>>(extra: impl IntoIterator<Item = P>) -> Library {
        let mut dirs: Vec<PathBuf> = extra.into_iter().map(Into::into).collect();
        if let Some(env) = std::env::var_os(STYLES_ENV) {
            dirs.extend(std::env::split_paths(&env).filter(|d| !d.as_os_str().is_empty()));
        }
        dirs.push(shipped_dir());
        Library { dirs }
    }

    /// Every style the library's folders hold, by name (a name found in an
    /// earlier folder hides the same name in later ones), sorted by name.
    pub fn styles(&self) -> Vec<StyleEntry> {
        let mut seen: BTreeMap<String, StyleEntry> = BTreeMap::new();
        for d in &self.dirs {
            let Ok(entries) = std::fs::read_dir(d) else {
                continue;
            };
            for e in entries.filter_map(|e| e.ok()) {
                let dir = e.path();
                let name = e.file_name().to_string_lossy().into_owned();
                if seen.contains_key(&name) || !dir.join(STYLE_FILE).is_file() {
                    continue;
                }
                let summary = std::fs::read_to_string(dir.join(STYLE_FILE))
                    .ok()
                    .and_then(|t| ::toml::from_str::<Summary>(&t).ok());
                seen.insert(
                    name.clone(),
                    StyleEntry {
                        name,
                        kind: summary.as_ref().map(|s| s.kind),
                        exemplars: summary.map_or(0, |s| s.exemplar.len()),
                        dir,
                    },
                );
            }
        }
        seen.into_values().collect()
    }

    /// The folder of `style`: `style` itself when it is a folder holding
    /// `style.toml`, else the first folder of the library holding a style
    /// of that name.
    pub fn find(&self, style: &str) -> Result<PathBuf> {
        let direct = Path::new(style);
        if direct.join(STYLE_FILE).is_file() {
            return Ok(direct.to_path_buf());
        }
        let candidates: Vec<PathBuf> = self.dirs.iter().map(|d| d.join(style)).collect();
        if let Some(found) = candidates.iter().find(|d| d.join(STYLE_FILE).is_file()) {
            return Ok(found.clone());
        }
        let tried: Vec<String> = std::iter::once(direct)
            .chain(candidates.iter().map(PathBuf::as_path))
            .map(|d| d.join(STYLE_FILE).display().to_string())
            .collect();
        let tried = match tried.as_slice() {
            [a, b] => format!("neither {a} nor {b} exists"),
            _ => format!("none of {} exists", tried.join(", ")),
        };
        let close = close_names(style, &self.styles());
        let hint = if close.is_empty() {
            String::new()
        } else {
            format!(" (did you mean {}?)", close.join(", "))
        };
        Err(Error::invalid(format!("style not found: {tried}{hint}")).in_file(direct))
    }

    /// Finds `style` ([`Library::find`]) and loads it under that name.
    pub fn load(&self, style: &str, opts: &StyleOptions) -> Result<Style> {
        Style::load_named_as(style, &self.find(style)?, opts)
    }

    /// The styles that the shapes of `sketch` name with
    /// `data-style="NAME"`, for the queries a mode of `kind` decorates
    /// (fill: regions; pattern: every query; brush: none), by name. A NAME
    /// is a bare folder name looked up in the library's folders only, so a
    /// sketch cannot make flourish read files elsewhere (`/etc`, `../x`);
    /// errors name the query.
    pub fn load_named(
        &self,
        sketch: &Sketch,
        kind: StyleKind,
        opts: &StyleOptions,
    ) -> Result<BTreeMap<String, Style>> {
        let mut named = BTreeMap::new();
        for q in &sketch.queries {
            let decorated = match (kind, &q.kind) {
                (StyleKind::Brush, _) => false,
                (StyleKind::Fill, QueryKind::Region { .. }) => true,
                (StyleKind::Fill, QueryKind::Path { .. }) => false,
                (StyleKind::Pattern, _) => true,
            };
            let Some(name) = q.style.as_ref().filter(|_| decorated) else {
                continue;
            };
            if !named.contains_key(name) {
                let dir = self.find_named(&q.id, name)?;
                named.insert(name.clone(), Style::load_named_as(name, &dir, opts)?);
            }
        }
        Ok(named)
    }

    /// The folder of a shape's `data-style="NAME"`: NAME must be a bare
    /// name (no folder separators, not `.` or `..`).
    fn find_named(&self, query_id: &str, name: &str) -> Result<PathBuf> {
        let in_query = |reason: String| Error::invalid(reason).in_part(query_id);
        let mut parts = Path::new(name).components();
        let bare = matches!(
            (parts.next(), parts.next()),
            (Some(std::path::Component::Normal(n)), None) if n == std::ffi::OsStr::new(name)
        );
        let folders: Vec<String> = self.dirs.iter().map(|d| d.display().to_string()).collect();
        if !bare {
            return Err(in_query(format!(
                "data-style \"{name}\" is not a style name (a folder name in {}, without slashes)",
                folders.join(" or ")
            )));
        }
        let candidates: Vec<PathBuf> = self.dirs.iter().map(|d| d.join(name)).collect();
        if let Some(found) = candidates.iter().find(|d| d.join(STYLE_FILE).is_file()) {
            return Ok(found.clone());
        }
        let missing: Vec<String> = candidates
            .iter()
            .map(|d| d.join(STYLE_FILE).display().to_string())
            .collect();
        Err(in_query(format!(
            "data-style \"{name}\": style not found: {} does not exist",
            missing.join(", ")
        )))
    }
}

/// One style of a library, as `flourish style list` shows it.
#[derive(Clone, Debug, PartialEq)]
pub struct StyleEntry {
    /// Its folder's name, the name it is loaded by.
    pub name: String,
    /// Its folder.
    pub dir: PathBuf,
    /// What it is for (`None` when its `style.toml` does not say).
    pub kind: Option<StyleKind>,
    /// How many `[[exemplar]]` tables it lists.
    pub exemplars: usize,
}

/// What `style list` reads of a `style.toml`, without checking the rest.
#[derive(serde::Deserialize)]
struct Summary {
    kind: StyleKind,
    #[serde(default)]
    exemplar: Vec<::toml::Value>,
}

/// The names of `styles` close to `name`: at most two edits away (or
/// three for long names), or holding it, best first.
fn close_names(name: &str, styles: &[StyleEntry]) -> Vec<String> {
    let wanted = name.rsplit('/').next().unwrap_or(name).to_lowercase();
    let limit = if wanted.chars().count() > 8 { 3 } else { 2 };
    let mut close: Vec<(usize, String)> = styles
        .iter()
        .filter_map(|s| {
            let d = edits(&wanted, &s.name.to_lowercase());
            let holds = !wanted.is_empty() && s.name.to_lowercase().contains(&wanted);
            (d <= limit || holds).then(|| (d, s.name.clone()))
        })
        .collect();
    close.sort();
    close.into_iter().take(3).map(|(_, n)| n).collect()
}

/// The Levenshtein distance between `a` and `b`, in characters.
fn edits(a: &str, b: &str) -> usize {
    let b: Vec<char> = b.chars().collect();
    let mut row: Vec<usize> = (0..=b.len()).collect();
    for (i, ca) in a.chars().enumerate() {
        let mut prev = row[0];
        row[0] = i + 1;
        for (j, &cb) in b.iter().enumerate() {
            let next = (prev + usize::from(ca != cb))
                .min(row[j] + 1)
                .min(row[j + 1] + 1);
            prev = row[j + 1];
            row[j + 1] = next;
        }
    }
    row[b.len()]
}

include!(concat!(env!("OUT_DIR"), "/shipped_styles.rs"));

/// Environment variable holding more style folders, separated like `PATH`.
pub const STYLES_ENV: &str = "FLOURISH_STYLES";

/// The folder holding the shipped styles, which travel inside the binary:
/// unpacked once into the cache folder (a folder per content, so an older
/// or newer binary's stay as they were; written whole, then renamed into
/// place), or into the temporary folder when there is no cache folder.
pub(crate) fn shipped_dir() -> PathBuf {
    use std::sync::OnceLock;
    static DIR: OnceLock<PathBuf> = OnceLock::new();
    DIR.get_or_init(|| {
        let base = directories::ProjectDirs::from("", "", "flourish")
            .map(|p| p.cache_dir().to_path_buf())
            .unwrap_or_else(|| std::env::temp_dir().join("flourish"));
        let dir = base.join(format!("shipped-{SHIPPED_HASH:016x}"));
        if dir.is_dir() || unpack(&base, &dir).is_ok() {
            dir
        } else {
            // Unwritable cache: a private copy in the temporary folder.
            let tmp = std::env::temp_dir().join(format!(
                "flourish-shipped-{SHIPPED_HASH:016x}-{}",
                std::process::id()
            ));
            let _ = unpack(&std::env::temp_dir(), &tmp);
            tmp
        }
    })
    .clone()
}

/// Writes the shipped styles into a fresh folder in `base` and renames it
/// to `dir` (another process doing the same at once is harmless).
fn unpack(base: &Path, dir: &Path) -> std::io::Result<()> {
    std::fs::create_dir_all(base)?;
    let tmp = tempfile::Builder::new()
        .prefix(".shipped-")
        .tempdir_in(base)?;
    for (rel, bytes) in SHIPPED {
        let path = tmp.path().join(rel);
        if let Some(parent) = path.parent() {
            std::fs::create_dir_all(parent)?;
        }
        std::fs::write(path, bytes)?;
    }
    match std::fs::rename(tmp.path(), dir) {
        Ok(()) => {
            let _ = tmp.keep();
            Ok(())
        }
        Err(_) if dir.is_dir() => Ok(()),
        Err(e) => Err(e),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A shape's `data-style` is a name in the library's folders, never a
    /// path: absolute, relative, parent and empty names are refused with
    /// the query named; a missing name says so.
    #[test]
    fn data_style_is_a_name_in_the_styles_folder() {
        let lib = Library::shipped();
        assert_eq!(
            lib.find_named("q-1", "knot").expect("shipped"),
            shipped_dir().join("knot")
        );
        for bad in [
            "/etc",
            "../styles/knot",
            "knot/",
            "./knot",
            "..",
            ".",
            "",
            "a/b",
        ] {
            let e = lib.find_named("q-1", bad).expect_err(bad).to_string();
            assert!(
                e.starts_with("q-1: data-style") && !e.contains('\n'),
                "{bad:?}: {e}"
            );
        }
        let e = lib
            .find_named("q-2", "no-such-style")
            .expect_err("missing")
            .to_string();
        assert!(
            e.starts_with("q-2: data-style \"no-such-style\": style not found"),
            "{e}"
        );
    }

    /// A style's files are regular files inside its folder: a symbolic link
    /// out of it, a FIFO and a missing exemplar are refused before anything
    /// is read, naming the key.
    #[cfg(unix)]
    #[test]
    fn style_files_stay_in_their_folder() {
        let tmp = tempfile::tempdir().expect("temp dir");
        let dir = tmp.path().join("s");
        std::fs::create_dir_all(&dir).expect("folder");
        let write_toml = |file: &str| {
            std::fs::write(
                dir.join(STYLE_FILE),
                format!("kind = \"pattern\"\nscale = 2.0\n[[exemplar]]\nfile = \"{file}\"\n"),
            )
            .expect("writes");
        };
        let refused = |file: &str, why: &str| {
            write_toml(file);
            let e = Style::load(&dir, &StyleOptions::default())
                .expect_err(file)
                .to_string();
            assert!(e.contains("exemplar[0].file") && e.contains(why), "{e}");
        };
        std::os::unix::fs::symlink("/etc/passwd", dir.join("passwd.svg")).expect("link");
        refused("passwd.svg", "leads out of the style folder");
        let fifo = dir.join("fifo.svg");
        let made = std::process::Command::new("mkfifo")
            .arg(&fifo)
            .status()
            .is_ok_and(|s| s.success());
        if made {
            refused("fifo.svg", "not a regular file");
        }
        refused("missing.svg", "does not exist");
    }

    /// A name is found in the first folder that holds it; one that no
    /// folder holds names every place looked.
    #[test]
    fn styles_are_found_along_the_search_path() {
        let tmp = tempfile::tempdir().expect("temp dir");
        let own = tmp.path().join("knot");
        std::fs::create_dir_all(&own).expect("folder");
        std::fs::write(own.join(STYLE_FILE), "kind = \"fill\"\n").expect("writes");
        let lib = Library::new([tmp.path().to_path_buf(), shipped_dir()]);
        assert_eq!(lib.find("knot").expect("found"), own);
        assert_eq!(lib.find("vine").expect("found"), shipped_dir().join("vine"));
        let e = lib.find("nowhere").expect_err("missing").to_string();
        assert!(e.starts_with("nowhere: style not found: none of"), "{e}");
        let e = Library::shipped().find("nowhere").expect_err("missing");
        assert!(
            e.to_string()
                .contains("style not found: neither nowhere/style.toml nor"),
            "{e}"
        );
    }
}
