//! Styles made on the page from dropped exemplars: a draft per upload in
//! the server's private temporary folder, files stored under names the
//! server chooses (`exemplar-N.svg|png|jpg`, by their content, never the
//! client's name), then made a style: a brush library's ends found as
//! `flourish style init` finds them, a pattern or fill style with the
//! defaults of its kind; the style check's warnings go back to the page.

use super::Reply;
use flourish::{Style, StyleKind, StyleOptions};
use serde_json::json;
use std::collections::HashMap;
use std::path::PathBuf;
use std::sync::Mutex;

/// Most drafts a server holds; past it a new upload gets 507.
pub const MAX_DRAFTS: usize = 64;

/// Most files in one draft.
pub const MAX_FILES: usize = 32;

/// The element spacing ε of a pattern style made from an upload, px.
pub const PATTERN_SCALE: f64 = 12.0;

/// An upload being made a style.
struct Draft {
    /// Its folder in the private temporary folder.
    dir: PathBuf,
    /// Exemplar files stored so far.
    files: usize,
}

/// The drafts and the private folder holding them.
pub struct Uploads {
    /// The private temporary folder (owner-only), made on the first
    /// upload (`None` inside when it could not be made).
    root: std::sync::OnceLock<Option<tempfile::TempDir>>,
    /// Drafts by id, and the next id.
    drafts: Mutex<(HashMap<u64, Draft>, u64)>,
}

impl Uploads {
    /// An empty set of drafts.
    pub fn new() -> Uploads {
        Uploads {
            root: std::sync::OnceLock::new(),
            drafts: Mutex::new((HashMap::new(), 1)),
        }
    }

    /// `POST /api/uploads`: a new draft; its id.
    pub fn create(&self) -> Reply {
        let root = self.root.get_or_init(|| {
            tempfile::Builder::new()
                .prefix("flourish-serve-")
                .tempdir()
                .ok()
        });
        let Some(root) = root else {
            return Reply::error(507, "no temporary folder for uploads");
        };
        let Ok(mut d) = self.drafts.lock() else {
            return Reply::error(500, "uploads are unavailable");
        };
        if d.0.len() >= MAX_DRAFTS {
            return Reply::error(
                507,
                format!("the server holds {MAX_DRAFTS} uploads already"),
            );
        }
        let id = d.1;
        d.1 += 1;
        let dir = root.path().join(format!("upload-{id}"));
        if let Err(e) = std::fs::create_dir(&dir) {
            return Reply::error(500, format!("upload {id}: {e}"));
        }
        d.0.insert(id, Draft { dir, files: 0 });
        Reply::json(200, &json!({ "id": id }))
    }

    /// `POST /api/uploads/ID/files`: stores one exemplar (SVG, PNG or
    /// JPEG, told by its content).
    pub fn add_file(&self, id: u64, bytes: &[u8]) -> Reply {
        let ext = if bytes.starts_with(b"\x89PNG\r\n\x1a\n") {
            "png"
        } else if bytes.starts_with(&[0xff, 0xd8, 0xff]) {
            "jpg"
        } else if String::from_utf8_lossy(&bytes[..bytes.len().min(4096)]).contains("<svg") {
            "svg"
        } else {
            return Reply::error(415, "an exemplar is an SVG, PNG or JPEG file");
        };
        let Ok(mut d) = self.drafts.lock() else {
            return Reply::error(500, "uploads are unavailable");
        };
        let Some(draft) = d.0.get_mut(&id) else {
            return Reply::error(404, format!("no upload {id}"));
        };
        if draft.files >= MAX_FILES {
            return Reply::error(413, format!("an upload holds at most {MAX_FILES} files"));
        }
        draft.files += 1;
        let path = draft.dir.join(format!("exemplar-{:02}.{ext}", draft.files));
        match std::fs::write(&path, bytes) {
            Ok(()) => Reply::json(200, &json!({ "files": draft.files })),
            Err(e) => Reply::error(500, format!("upload {id}: {e}")),
        }
    }

    /// `GET /api/uploads/ID/zip`: the style made of upload ID as a zip of
    /// a folder `mine-ID/` (its `style.toml` and exemplars), ready for
    /// `flourish --styles`.
    pub fn zip(&self, id: u64) -> Reply {
        let dir = match self.drafts.lock() {
            Ok(d) => match d.0.get(&id) {
                Some(draft) => draft.dir.clone(),
                None => return Reply::error(404, format!("no upload {id}")),
            },
            Err(_) => return Reply::error(500, "uploads are unavailable"),
        };
        if !dir.join("style.toml").is_file() {
            return Reply::error(409, format!("upload {id} is not a style yet"));
        }
        match zip_folder(&dir, &format!("mine-{id}")) {
            Ok(body) => Reply {
                status: 200,
                content_type: "application/zip",
                body,
            },
            Err(e) => Reply::error(500, format!("upload {id}: {e}")),
        }
    }

    /// `POST /api/uploads/ID/style?kind=K`: makes the draft a style of
    /// kind K: its `style.toml` written, the style loaded and checked.
    /// Returns the style (to be offered as `name`) and the reply.
    pub fn make_style(&self, id: u64, kind: &str, name: &str) -> Result<(Style, Reply), Reply> {
        let kind = match kind {
            "brush" => StyleKind::Brush,
            "pattern" => StyleKind::Pattern,
            "fill" => StyleKind::Fill,
            other => {
                return Err(Reply::error(
                    400,
                    format!("kind {other:?} is not brush, pattern or fill"),
                ))
            }
        };
        let dir = {
            let d = self
                .drafts
                .lock()
                .map_err(|_| Reply::error(500, "uploads are unavailable"))?;
            let draft =
                d.0.get(&id)
                    .ok_or_else(|| Reply::error(404, format!("no upload {id}")))?;
            if draft.files == 0 {
                return Err(Reply::error(400, format!("upload {id} holds no exemplar")));
            }
            draft.dir.clone()
        };
        // Messages name the upload, not the server's folder.
        let shown = dir.display().to_string();
        let unusable = |e: flourish::Error| {
            Reply::error(422, e.to_string().replace(&shown, &format!("upload {id}")))
        };
        let mut warnings: Vec<String> = Vec::new();
        let toml = match kind {
            StyleKind::Brush => {
                let report = flourish::init_style(&dir, None).map_err(unusable)?;
                warnings.extend(report.skipped.iter().cloned());
                report.to_toml()
            }
            _ => {
                let mut files: Vec<String> = std::fs::read_dir(&dir)
                    .map_err(|e| Reply::error(500, format!("upload {id}: {e}")))?
                    .filter_map(|e| e.ok()?.file_name().into_string().ok())
                    .filter(|n| n.starts_with("exemplar-"))
                    .collect();
                files.sort();
                let mut t = format!("kind = \"{}\"\n", kind.name());
                if kind == StyleKind::Pattern {
                    // The element spacing ε in px (Barla et al. §3); a
                    // designer tunes it in the downloaded style.toml.
                    t.push_str(&format!("scale = {PATTERN_SCALE:.1}\n"));
                }
                for f in files {
                    t.push_str(&format!("\n[[exemplar]]\nfile = \"{f}\"\n"));
                }
                t
            }
        };
        std::fs::write(dir.join("style.toml"), toml)
            .map_err(|e| Reply::error(500, format!("upload {id}: {e}")))?;
        let style = Style::load(
            &dir,
            &StyleOptions {
                kind: Some(kind),
                ..StyleOptions::default()
            },
        )
        .map_err(unusable)?;
        let report = flourish::check_style(&style).map_err(unusable)?;
        warnings.extend(report.warnings().map(|(file, w)| format!("{file}: {w}")));
        for w in &mut warnings {
            *w = w.replace(&shown, &format!("upload {id}"));
        }
        let reply = Reply::json(
            200,
            &json!({
                "name": name,
                "kind": kind.name(),
                "exemplars": style.files().len().saturating_sub(1),
                "warnings": warnings,
            }),
        );
        Ok((style, reply))
    }
}

/// The regular files of `dir` (not its subfolders), deflated into a zip
/// under folder `name/`, in file-name order.
fn zip_folder(dir: &std::path::Path, name: &str) -> std::io::Result<Vec<u8>> {
    use std::io::Write;
    let mut files: Vec<(String, PathBuf)> = std::fs::read_dir(dir)?
        .filter_map(|e| {
            let e = e.ok()?;
            let meta = e.metadata().ok()?;
            (meta.is_file()).then(|| (e.file_name().into_string().ok(), e.path()))
        })
        .filter_map(|(n, p)| Some((n?, p)))
        .collect();
    files.sort();
    let mut zip = zip::ZipWriter::new(std::io::Cursor::new(Vec::new()));
    let opts = zip::write::SimpleFileOptions::default()
        .compression_method(zip::CompressionMethod::Deflated);
    for (file, path) in files {
        zip.start_file(format!("{name}/{file}"), opts)
            .map_err(std::io::Error::other)?;
        zip.write_all(&std::fs::read(path)?)?;
    }
    Ok(zip.finish().map_err(std::io::Error::other)?.into_inner())
}
