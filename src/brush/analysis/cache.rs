//! The analysis cache: a brush style's analysis stored in one file, keyed
//! by a content hash, reused while nothing changed.
//!
//! * Key: blake3 of [`ANALYSIS_VERSION`], `style.toml` and every exemplar
//!   file (name and bytes, in `style.toml` order). Editing any of them, or
//!   a new analysis version, gives a new key and a new file.
//! * File: `NAME-KEY.bin` in the cache folder: a magic tag, the version,
//!   the full key, a blake3 checksum of the body, then as the body the
//!   analysis in postcard with grids as byte
//!   strings ([`crate::raster::plain`]) so it loads at memory speed; each
//!   exemplar and each level's index is its own postcard blob, so they
//!   decode in parallel.
//! * Folder: [`AnalysisOptions::cache_dir`](super::AnalysisOptions::cache_dir)
//!   (`--cache DIR`), else `$FLOURISH_CACHE_DIR`, else the platform's cache
//!   folder (`~/.cache/flourish/styles` on Linux).
//! * A file that is missing, not a regular file (a FIFO or device is never
//!   opened), of another version or key, whose body does not match its
//!   checksum, truncated, corrupt or inconsistent (sizes that disagree, see
//!   [`super::style::BrushStyle::validate`]) is never trusted: the style is
//!   analysed again and the file rewritten atomically. Failing to write the
//!   cache (read-only folder) is not an error.

use super::facts::StyleFacts;
use super::style::{BrushStyle, Exemplar};
use crate::brush::analysis::neighbourhood::{NeighbourhoodIndex, NeighbourhoodSampler};
use crate::error::Result;
use crate::io;
use rayon::prelude::*;
use serde::{Deserialize, Serialize};
use std::path::{Path, PathBuf};

/// Version of the analysis; bump it whenever the analysis or the cached
/// types change so old caches are rebuilt.
pub const ANALYSIS_VERSION: u32 = 7;

/// Environment variable naming the cache folder (below `--cache`).
pub const CACHE_ENV: &str = "FLOURISH_CACHE_DIR";

const MAGIC: &[u8; 8] = b"FLRSHBRU";

/// What happened to the cache on a load.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum CacheStatus {
    /// A valid cache file was used.
    Hit,
    /// There was no cache file for this content: analysed and stored.
    Miss,
    /// A cache file was there but unusable (corrupt, truncated,
    /// inconsistent): analysed and rewritten.
    Rebuilt,
    /// Caching is off or no cache folder could be found: analysed.
    Disabled,
}

/// The cache folder: `explicit`, else `$FLOURISH_CACHE_DIR`, else the
/// platform cache folder; `None` when none can be found.
pub fn cache_dir(explicit: Option<&Path>) -> Option<PathBuf> {
    if let Some(d) = explicit {
        return Some(d.to_path_buf());
    }
    if let Some(d) = std::env::var_os(CACHE_ENV).filter(|d| !d.is_empty()) {
        return Some(PathBuf::from(d));
    }
    directories::ProjectDirs::from("", "", "flourish").map(|p| p.cache_dir().join("styles"))
}

/// The content key of a style: `style.toml`'s bytes and each exemplar's
/// name and bytes, with the analysis version. Reading an exemplar fails
/// with the file's own error (e.g. a missing exemplar).
pub fn style_key(toml_bytes: &[u8], exemplars: &[PathBuf]) -> Result<[u8; 32]> {
    let mut h = blake3::Hasher::new();
    h.update(MAGIC);
    h.update(&ANALYSIS_VERSION.to_le_bytes());
    h.update(&(toml_bytes.len() as u64).to_le_bytes());
    h.update(toml_bytes);
    for p in exemplars {
        let bytes = io::read_file(p)?;
        let name = p
            .file_name()
            .map(|n| n.to_string_lossy().into_owned())
            .unwrap_or_default();
        h.update(&(name.len() as u64).to_le_bytes());
        h.update(name.as_bytes());
        h.update(&(bytes.len() as u64).to_le_bytes());
        h.update(&bytes);
    }
    Ok(*h.finalize().as_bytes())
}

/// The cache file of style `name` with content `key` in `dir`.
pub fn cache_file(dir: &Path, name: &str, key: &[u8; 32]) -> PathBuf {
    let safe: String = name
        .chars()
        .map(|c| {
            if c.is_ascii_alphanumeric() || c == '-' || c == '_' {
                c
            } else {
                '_'
            }
        })
        .collect();
    let hex: String = key[..12].iter().map(|b| format!("{b:02x}")).collect();
    dir.join(format!("{safe}-{hex}.bin"))
}

/// Outcome of reading a cache file.
pub enum Read {
    /// No file.
    Missing,
    /// A file that cannot be trusted.
    Unusable,
    /// The stored analysis.
    Found(Box<BrushStyle>),
}

/// Length of the file's header: tag, version, key and checksum.
const HEAD_LEN: usize = MAGIC.len() + 4 + 32 + 32;

/// Reads the analysis stored in `path` for `key`, checking that it is a
/// regular file (before opening it), then tag, version, key, the body's
/// checksum, decoding and consistency.
pub fn read(path: &Path, key: &[u8; 32]) -> Read {
    match std::fs::metadata(path) {
        Ok(m) if m.is_file() => {}
        Ok(_) => return Read::Unusable,
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => return Read::Missing,
        Err(_) => return Read::Unusable,
    }
    let bytes = match std::fs::read(path) {
        Ok(b) => b,
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => return Read::Missing,
        Err(_) => return Read::Unusable,
    };
    let head = HEAD_LEN;
    if bytes.len() < head
        || &bytes[..8] != MAGIC
        || bytes[8..12] != ANALYSIS_VERSION.to_le_bytes()
        || &bytes[12..44] != key
        || bytes[44..76] != *blake3::hash(&bytes[head..]).as_bytes()
    {
        return Read::Unusable;
    }
    match decode(&bytes[head..]) {
        Some(mut style) => {
            if style.restore() && style.validate() {
                Read::Found(Box::new(style))
            } else {
                Read::Unusable
            }
        }
        None => Read::Unusable,
    }
}

/// Writes `style` for `key` to `path` atomically (creating the folder).
pub fn write(path: &Path, key: &[u8; 32], style: &BrushStyle) -> Result<()> {
    if let Some(dir) = path.parent() {
        std::fs::create_dir_all(dir).map_err(|e| crate::error::Error::io(dir, e))?;
    }
    let body = encode(style).map_err(|e| {
        crate::error::Error::invalid(format!("cannot encode the analysis: {e}")).in_file(path)
    })?;
    let mut bytes = Vec::with_capacity(HEAD_LEN + body.len());
    bytes.extend_from_slice(MAGIC);
    bytes.extend_from_slice(&ANALYSIS_VERSION.to_le_bytes());
    bytes.extend_from_slice(key);
    bytes.extend_from_slice(blake3::hash(&body).as_bytes());
    bytes.extend_from_slice(&body);
    io::write_atomic(path, &bytes)?;
    remove_stale(path);
    Ok(())
}

/// Removes the style's other cache files (older content or versions) from
/// `path`'s folder, so edits do not pile up stale analyses. Best effort.
fn remove_stale(path: &Path) {
    let (Some(dir), Some(name)) = (path.parent(), path.file_name().and_then(|n| n.to_str())) else {
        return;
    };
    // `NAME-` + 24 hex digits + `.bin`.
    let Some(stem) = name
        .strip_suffix(".bin")
        .and_then(|n| n.get(..n.len().saturating_sub(24)))
    else {
        return;
    };
    let Ok(entries) = std::fs::read_dir(dir) else {
        return;
    };
    for entry in entries.flatten() {
        let p = entry.path();
        let Some(other) = p.file_name().and_then(|n| n.to_str()) else {
            continue;
        };
        let is_sibling = other != name
            && other.len() == name.len()
            && other.starts_with(stem)
            && other.ends_with(".bin")
            && other[stem.len()..other.len() - 4]
                .bytes()
                .all(|b| b.is_ascii_hexdigit());
        if is_sibling {
            let _ = std::fs::remove_file(&p);
        }
    }
}

/// The style's small fields.
#[derive(Serialize, Deserialize)]
struct Head {
    name: String,
    resolution: u32,
    sdf: bool,
    sampler: NeighbourhoodSampler,
    facts: StyleFacts,
}

/// The file body: the head and one blob per exemplar and per index.
#[derive(Serialize, Deserialize)]
struct Body<'a> {
    #[serde(borrow)]
    head: &'a [u8],
    #[serde(borrow)]
    exemplars: Vec<&'a [u8]>,
    #[serde(borrow)]
    indexes: Vec<&'a [u8]>,
}

fn encode(style: &BrushStyle) -> postcard::Result<Vec<u8>> {
    let head = postcard::to_stdvec(&Head {
        name: style.name.clone(),
        resolution: style.resolution,
        sdf: style.sdf,
        sampler: style.sampler,
        facts: style.facts.clone(),
    })?;
    let exemplars = style
        .exemplars
        .par_iter()
        .map(postcard::to_stdvec)
        .collect::<postcard::Result<Vec<_>>>()?;
    let indexes = style
        .indexes
        .par_iter()
        .map(postcard::to_stdvec)
        .collect::<postcard::Result<Vec<_>>>()?;
    postcard::to_stdvec(&Body {
        head: &head,
        exemplars: exemplars.iter().map(|v| v.as_slice()).collect(),
        indexes: indexes.iter().map(|v| v.as_slice()).collect(),
    })
}

fn decode(bytes: &[u8]) -> Option<BrushStyle> {
    let body: Body = postcard::from_bytes(bytes).ok()?;
    let head: Head = postcard::from_bytes(body.head).ok()?;
    let exemplars = body
        .exemplars
        .par_iter()
        .map(|b| postcard::from_bytes::<Exemplar>(b).ok())
        .collect::<Option<Vec<_>>>()?;
    let indexes = body
        .indexes
        .par_iter()
        .map(|b| postcard::from_bytes::<NeighbourhoodIndex>(b).ok())
        .collect::<Option<Vec<_>>>()?;
    Some(BrushStyle {
        name: head.name,
        resolution: head.resolution,
        sdf: head.sdf,
        sampler: head.sampler,
        facts: head.facts,
        exemplars,
        indexes,
    })
}
