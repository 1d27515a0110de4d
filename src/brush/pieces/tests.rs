//! Long strokes in pieces: consecutive pieces hold the same coordinates
//! where they overlap, the pieces together draw what the whole canvas
//! draws, a stroke too long for one canvas is brushed without a gap, and
//! a sketch past the budget is refused before any synthesis.

use super::{MAX_SKETCH_PIXELS, PIECE_PIXELS};
use crate::brush::analysis::BrushStyle;
use crate::brush::measure::{at, ink};
use crate::brush::output::brush_sketch;
use crate::brush::pipeline::{QueryResult, Settings};
use crate::brush::tests::vine;
use std::path::PathBuf;

fn s_curve() -> crate::read::sketch::Sketch {
    let root = PathBuf::from(env!("CARGO_MANIFEST_DIR"));
    crate::read::sketch::load(&root.join("samples/brush/s-curve.svg")).expect("sample loads")
}

fn keeping(pieces: Option<u64>) -> Settings {
    Settings {
        pieces,
        discard_fields: false,
        ..Settings::default()
    }
}

/// Top-level pixel offset of `b`'s pixels in `a`.
fn shift(a: &QueryResult, b: &QueryResult) -> (isize, isize) {
    let d = (b.canvas.origin - a.canvas.origin) * a.canvas.px_per_unit;
    (d.x.round() as isize, d.y.round() as isize)
}

#[test]
fn consecutive_pieces_hold_the_same_coordinates_where_they_overlap() {
    let style = vine();
    let out = brush_sketch(style, &s_curve(), &keeping(Some(20_000))).expect("brushed");
    let q = &out.queries;
    assert!(q.len() >= 4, "{} pieces", q.len());
    for k in 1..q.len() {
        let (a, b) = (&q[k - 1], &q[k]);
        assert_eq!(a.canvas.px_per_unit, b.canvas.px_per_unit);
        let (dx, dy) = shift(a, b);
        let (mut shared, mut differ) = (0, 0);
        for y in 0..b.field.coords.height() {
            for x in 0..b.field.coords.width() {
                let Some(cb) = b.field.coords.get(x, y) else {
                    continue;
                };
                let Some(ca) = a
                    .field
                    .coords
                    .get_or(x as isize + dx, y as isize + dy, None)
                else {
                    continue;
                };
                shared += 1;
                if ca != cb {
                    differ += 1;
                }
            }
        }
        assert!(shared > 50, "pieces {k}: {shared} shared pixels");
        assert_eq!(differ, 0, "pieces {k}: {differ} of {shared} differ");
    }
}

/// Sketch points of the ink of `results`, on a grid of `cell` units.
fn ink_cells(
    style: &BrushStyle,
    results: &[QueryResult],
    cell: f64,
) -> std::collections::HashSet<(i64, i64)> {
    let mut cells = std::collections::HashSet::new();
    for r in results {
        let m = ink(style, r);
        for y in 0..m.height() {
            for x in 0..m.width() {
                if m.get(x, y) {
                    let p = at(r, x, y);
                    cells.insert(((p.x / cell).floor() as i64, (p.y / cell).floor() as i64));
                }
            }
        }
    }
    cells
}

#[test]
fn pieces_draw_what_the_whole_canvas_draws() {
    let style = vine();
    let whole = brush_sketch(style, &s_curve(), &keeping(None)).expect("whole");
    let pieces = brush_sketch(style, &s_curve(), &keeping(Some(40_000))).expect("pieces");
    assert_eq!(whole.queries.len(), 1);
    assert!(pieces.queries.len() >= 2, "{}", pieces.queries.len());
    let cell = 1.0;
    let a = ink_cells(style, &whole.queries, cell);
    let b = ink_cells(style, &pieces.queries, cell);
    let both = a.intersection(&b).count() as f64;
    let iou = both / (a.len() + b.len()) as f64 * 2.0;
    assert!(
        iou > 0.8,
        "Dice {iou:.3} of {} and {} cells",
        a.len(),
        b.len()
    );
}

#[test]
fn a_stroke_too_long_for_one_canvas_is_brushed_whole_without_a_gap() {
    // 2 units wide, 9000 long: 36 000 px at the start level, past the
    // 16 384 px a canvas side may have.
    let svg = br##"<svg xmlns="http://www.w3.org/2000/svg" width="9100" height="100">
        <path id="line" d="M50 50 H9050" stroke="#000" stroke-width="2" fill="none"/></svg>"##;
    let sketch = crate::read::sketch::parse(svg).expect("sketch");
    let style = vine();
    let out = brush_sketch(style, &sketch, &keeping(None)).expect("brushed in pieces");
    assert!(out.queries.len() >= 2, "{} pieces", out.queries.len());
    assert!(out
        .queries
        .iter()
        .all(|r| (r.canvas.width * r.canvas.height) as u64 <= PIECE_PIXELS));
    // Ink within every width-long stretch of the line.
    let cells = ink_cells(style, &out.queries, 2.0);
    let xs: std::collections::HashSet<i64> = cells.iter().map(|c| c.0).collect();
    // (Three widths short of each end, where the end ornament may stop.)
    let missing: Vec<i64> = (28..4522).filter(|x| !xs.contains(x)).collect();
    assert!(
        missing.is_empty(),
        "no ink at x = {:?}",
        &missing[..missing.len().min(10)]
    );
    // One group for the one path.
    assert_eq!(out.document.groups.len(), 1);
}

#[test]
fn a_sketch_past_the_canvas_budget_is_refused_before_synthesis() {
    // Ten hairlines across the page: about 8 Mpx of pieces each.
    let mut svg =
        String::from(r#"<svg xmlns="http://www.w3.org/2000/svg" width="100" height="100">"#);
    for k in 0..10 {
        svg += &format!(
            r##"<path d="M0 {k} L100 {}" stroke="#000" stroke-width="0.1" fill="none"/>"##,
            90 + k
        );
    }
    svg += "</svg>";
    let sketch = crate::read::sketch::parse(svg.as_bytes()).expect("sketch");
    let e = brush_sketch(vine(), &sketch, &Settings::default())
        .expect_err("past the budget")
        .to_string();
    assert!(
        e.contains("Mpx of canvas") && e.contains(&format!("{} Mpx", MAX_SKETCH_PIXELS >> 20)),
        "{e}"
    );
    assert!(!e.contains('\n'), "{e}");
}
