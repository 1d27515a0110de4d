//! Embeds the shipped styles (`styles/`) in the binary, so an installed
//! `flourish` finds them wherever it runs: `$OUT_DIR/shipped_styles.rs`
//! lists every file's path (relative to `styles/`) and bytes, and a hash
//! of them all names the folder they are unpacked into.

use std::hash::{Hash, Hasher};
use std::path::{Path, PathBuf};

fn files(dir: &Path, out: &mut Vec<PathBuf>) {
    let Ok(entries) = std::fs::read_dir(dir) else {
        return;
    };
    let mut paths: Vec<PathBuf> = entries.filter_map(|e| e.ok().map(|e| e.path())).collect();
    paths.sort();
    for p in paths {
        if p.is_dir() {
            files(&p, out);
        } else if p.is_file() {
            out.push(p);
        }
    }
}

fn main() {
    let root = PathBuf::from(std::env::var("CARGO_MANIFEST_DIR").expect("cargo sets it"));
    let styles = root.join("styles");
    println!("cargo:rerun-if-changed=styles");
    let mut list = Vec::new();
    files(&styles, &mut list);
    let mut hasher = std::collections::hash_map::DefaultHasher::new();
    let mut code = String::from("/// The shipped styles: path under `styles/`, bytes.\n");
    code.push_str("pub(crate) static SHIPPED: &[(&str, &[u8])] = &[\n");
    for p in &list {
        println!("cargo:rerun-if-changed={}", p.display());
        let rel = p
            .strip_prefix(&styles)
            .expect("under styles/")
            .to_string_lossy()
            .replace('\\', "/");
        let bytes = std::fs::read(p).expect("a shipped style file reads");
        rel.hash(&mut hasher);
        bytes.hash(&mut hasher);
        code.push_str(&format!(
            "    ({rel:?}, include_bytes!({:?})),\n",
            p.display().to_string()
        ));
    }
    code.push_str("];\n");
    code.push_str(&format!(
        "/// A hash of every shipped file's path and bytes.\npub(crate) const SHIPPED_HASH: u64 = {};\n",
        hasher.finish()
    ));
    let out =
        PathBuf::from(std::env::var("OUT_DIR").expect("cargo sets it")).join("shipped_styles.rs");
    std::fs::write(out, code).expect("OUT_DIR is writable");
}
