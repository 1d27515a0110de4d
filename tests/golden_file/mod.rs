//! The read-or-update step every golden test shares: with `UPDATE_GOLDEN`
//! set the actual output is written as the new golden file; otherwise the
//! golden file's text comes back for the test's own comparison.

use std::path::PathBuf;

/// The golden file `golden/DIR/NAME`'s text, or `None` after writing
/// `actual` there when `UPDATE_GOLDEN` is set. A missing file panics with
/// how to create it.
pub fn expected(dir: &str, name: &str, actual: &str) -> Option<String> {
    let path = PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("golden")
        .join(dir)
        .join(name);
    if std::env::var_os("UPDATE_GOLDEN").is_some() {
        std::fs::create_dir_all(path.parent().unwrap()).unwrap();
        std::fs::write(&path, actual).unwrap();
        return None;
    }
    Some(
        std::fs::read_to_string(&path)
            .unwrap_or_else(|e| panic!("{}: {e}; run with UPDATE_GOLDEN=1", path.display())),
    )
}
