//! Invariants every reader's output keeps, checked by the fuzz targets.

use flourish::{Document, Group, Output, QueryKind, Shape, Sketch};
use resvg::usvg;

/// Largest coordinate a sketch keeps (flourish skips shapes beyond it).
const MAX_COORD: f64 = 1e9;

/// A parsed sketch: finite sizes, every query named, finite geometry
/// within the coordinate limit, positive finite widths; laid over itself
/// with a shape per query, it is still an SVG usvg reads.
pub fn sketch(sk: &Sketch) {
    assert!(sk.width.is_finite() && sk.width > 0.0, "width {}", sk.width);
    assert!(sk.height.is_finite() && sk.height > 0.0, "height {}", sk.height);
    for q in &sk.queries {
        assert!(!q.id.is_empty());
        let path = match &q.kind {
            QueryKind::Path { spine, width } => {
                assert!(width.is_finite() && *width > 0.0, "width {width}");
                spine
            }
            QueryKind::Region { outline, .. } => outline,
        };
        let b = kurbo::Shape::bounding_box(path);
        for v in [b.x0, b.y0, b.x1, b.y1] {
            assert!(v.is_finite() && v.abs() <= MAX_COORD * 1.01, "coordinate {v}");
        }
    }
    let mut doc = Document::new(sk.width, sk.height, 3);
    doc.view_box = sk.view_box;
    doc.groups = sk
        .queries
        .iter()
        .map(|q| Group {
            id: q.id.clone(),
            shapes: vec![Shape::filled(
                kurbo::Shape::to_path(&kurbo::Rect::new(0.0, 0.0, 1.0, 1.0), 0.1),
                flourish::Color { r: 0, g: 0, b: 0 },
            )],
        })
        .collect();
    readable(&Output::new(doc).over(sk).to_svg());
}

/// A generated output: its SVG text holds no NaN or infinity and usvg
/// reads it.
pub fn output(out: &Output) {
    let svg = out.to_svg();
    assert!(!svg.contains("NaN") && !svg.contains("inf"), "non-finite number");
    readable(&svg);
}

/// SVG text usvg reads.
fn readable(svg: &str) {
    usvg::Tree::from_str(svg, &usvg::Options::default()).expect("the output is an SVG usvg reads");
}
