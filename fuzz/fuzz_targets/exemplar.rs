//! Exemplar files on any bytes: a fill tile (SVG read by colour layer)
//! and a pattern example (SVG read stroke by stroke): an error or a style
//! that loads, never a panic.
#![no_main]

use flourish::{Style, StyleOptions};
use libfuzzer_sys::fuzz_target;
use std::path::PathBuf;

/// A private folder per process and kind, with its style.toml.
fn folder(kind: &str, toml: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!(
        "flourish-fuzz-exemplar-{kind}-{}",
        std::process::id()
    ));
    if !dir.exists() {
        std::fs::create_dir_all(&dir).expect("a temporary folder");
        std::fs::write(dir.join("style.toml"), toml).expect("style.toml");
    }
    dir
}

fuzz_target!(|data: &[u8]| {
    let opts = StyleOptions {
        use_cache: false,
        ..StyleOptions::default()
    };
    for (kind, toml) in [
        ("fill", "kind = \"fill\"\nresolution = 32\n[[exemplar]]\nfile = \"x.svg\"\n"),
        ("pattern", "kind = \"pattern\"\nscale = 4.0\n[[exemplar]]\nfile = \"x.svg\"\n"),
    ] {
        let dir = folder(kind, toml);
        if std::fs::write(dir.join("x.svg"), data).is_ok() {
            let _ = Style::load(&dir, &opts);
        }
    }
});
