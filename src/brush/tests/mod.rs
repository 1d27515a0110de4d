//! Tests of the brush pipeline as a whole: the stages chained on a real
//! sketch, every shipped style on every sample, and sketches of many
//! strokes.

mod end_to_end;
mod many;
mod seams;
mod stages;

use crate::brush::analysis::{AnalysisOptions, BrushStyle};
use std::sync::OnceLock;

/// The shipped vine style, analysed once per test run (cache in the
/// temporary folder).
pub(crate) fn vine() -> &'static BrushStyle {
    static STYLE: OnceLock<BrushStyle> = OnceLock::new();
    STYLE.get_or_init(|| {
        let opts = AnalysisOptions {
            cache_dir: Some(
                std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("target/test-cache"),
            ),
            ..AnalysisOptions::default()
        };
        let root = std::path::PathBuf::from(env!("CARGO_MANIFEST_DIR"));
        BrushStyle::load(&root.join("styles/vine"), &opts).expect("style loads")
    })
}
