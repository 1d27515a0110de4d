//! style.toml on any text, beside one small exemplar of each kind: an
//! error naming the problem or a style that loads, never a panic.
#![no_main]

use flourish::{Style, StyleOptions};
use libfuzzer_sys::fuzz_target;
use std::path::PathBuf;

/// A private folder per process, holding the exemplar files any
/// style.toml may name.
fn folder() -> PathBuf {
    let dir = std::env::temp_dir().join(format!("flourish-fuzz-style-{}", std::process::id()));
    if !dir.exists() {
        std::fs::create_dir_all(&dir).expect("a temporary folder");
        let stroke = r##"<svg xmlns="http://www.w3.org/2000/svg" width="60" height="20"><path d="M4 10 C20 2 40 18 56 10" stroke="#000" stroke-width="4" fill="none"/></svg>"##;
        for name in ["a.svg", "b.svg", "tile.svg", "example.svg"] {
            std::fs::write(dir.join(name), stroke).expect("an exemplar");
        }
    }
    dir
}

fuzz_target!(|data: &[u8]| {
    let dir = folder();
    if std::fs::write(dir.join("style.toml"), data).is_err() {
        return;
    }
    let opts = StyleOptions {
        use_cache: false,
        ..StyleOptions::default()
    };
    if let Ok(style) = Style::load(&dir, &opts) {
        assert!(!style.files().is_empty());
    }
});
