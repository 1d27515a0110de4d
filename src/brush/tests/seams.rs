//! Hairlines across seams: a library whose only drawing is a hairline
//! lattice, brushed along a query several exemplars long so that the
//! matching has to join segments, must give one connected piece of ink
//! from end to end (decobrush.txt §5.3: the seam runs where both segments
//! agree; a line one synthesis pixel wide must not break there).

use crate::brush::analysis::facts::components;
use crate::brush::analysis::{AnalysisOptions, BrushStyle};
use crate::brush::measure::{at, ink};
use crate::brush::output::brush_sketch;
use crate::brush::pipeline::Settings;
use crate::read::sketch::Sketch;
use kurbo::{BezPath, Point};
use std::fmt::Write as _;
use std::path::Path;

/// Exemplar side, units: a 100 × 24 drawing.
const SIDE: f64 = 100.0;

/// Thickness of every line, units: at resolution 256 it is 2 finest px,
/// one pixel on the level the synthesis stops on for a 12-unit stroke.
const LINE: f64 = 0.8;

/// A hairline ladder: rails along y = `top` and y = `bottom` from x = 2
/// to 98, joined by rungs every `step` units from `phase` on and at both
/// ends (one connected piece), and a drawn spine along y = 12 (not ink).
fn ladder(top: f64, bottom: f64, step: f64, phase: f64) -> String {
    let h = LINE / 2.0;
    let mut d = String::new();
    for y in [top, bottom] {
        let _ = write!(d, "M2 {a}H98V{b}H2Z", a = y - h, b = y + h);
    }
    let mut xs = vec![2.0 + h, 98.0 - h];
    let mut x = 6.0 + phase;
    while x < 95.0 {
        xs.push(x);
        x += step;
    }
    for x in xs {
        let _ = write!(
            d,
            "M{l} {t}H{r}V{b}H{l}Z",
            l = x - h,
            r = x + h,
            t = top,
            b = bottom
        );
    }
    format!(
        r##"<svg xmlns="http://www.w3.org/2000/svg" width="{SIDE}" height="24" viewBox="0 0 {SIDE} 24"><path fill="#000" fill-rule="nonzero" d="{d}"/><path id="spine" d="M2 12H98" stroke="red" stroke-width="1" fill="none"/></svg>"##
    )
}

/// A two-exemplar hairline library in `dir`: ladders whose rails lie a
/// line thickness and a quarter apart (B's are 1 unit further out on each
/// side) and whose rungs differ in rhythm, so that wherever a segment of
/// one meets a segment of the other, the rails cross the seam offset by
/// about a synthesis pixel.
fn hairline_style(dir: &Path) -> BrushStyle {
    std::fs::create_dir_all(dir).expect("style folder");
    std::fs::write(dir.join("a.svg"), ladder(8.0, 16.0, 8.0, 0.0)).expect("a.svg");
    std::fs::write(dir.join("b.svg"), ladder(7.0, 17.0, 11.0, 3.0)).expect("b.svg");
    std::fs::write(
        dir.join("style.toml"),
        "kind = \"brush\"\nresolution = 256\n\n\
         [[exemplar]]\nfile = \"a.svg\"\n\n\
         [[exemplar]]\nfile = \"b.svg\"\n",
    )
    .expect("style.toml");
    let opts = AnalysisOptions {
        use_cache: false,
        ..AnalysisOptions::default()
    };
    BrushStyle::load(dir, &opts).expect("the hairline style loads")
}

/// The ink pieces of every query of `sketch` and, per query, whether the
/// largest piece reaches within half a width of every spine sample.
fn pieces(style: &BrushStyle, sketch: &Sketch) -> Vec<(usize, usize, bool)> {
    let out = brush_sketch(style, sketch, &Settings::default()).expect("brushes");
    out.queries
        .iter()
        .map(|r| {
            // A seam between the two exemplars, whose rails are offset.
            assert!(
                r.segments.iter().any(|s| s.0 == 0) && r.segments.iter().any(|s| s.0 == 1),
                "no seam between the exemplars: {:?}",
                r.segments
            );
            let mask = ink(style, r);
            let comps = components(&mask);
            let w = mask.width();
            let Some(body) = comps.iter().max_by_key(|c| c.len()) else {
                return (r.segments.len(), 0, false);
            };
            let pts: Vec<Point> = body.iter().map(|&i| at(r, i % w, i / w)).collect();
            let reach = 0.5 * r.spine.width;
            let whole = r
                .spine
                .samples
                .iter()
                .all(|s| pts.iter().any(|p| p.distance(s.pos) <= reach));
            (r.segments.len(), comps.len(), whole)
        })
        .collect()
}

#[test]
fn hairline_stays_one_piece_across_seams() {
    let tmp = tempfile::tempdir().expect("temporary folder");
    let style = hairline_style(&tmp.path().join("hairline"));
    // Straight and curved strokes of about 27 widths: the exemplars are
    // about nine widths long, so every stroke holds seams.
    let mut straight = BezPath::new();
    straight.move_to((40.0, 100.0));
    straight.line_to((360.0, 100.0));
    let mut curve = BezPath::new();
    curve.move_to((40.0, 300.0));
    curve.curve_to((140.0, 180.0), (260.0, 420.0), (360.0, 300.0));
    let sketch = Sketch::from_strokes(400.0, 400.0, vec![(straight, 12.0), (curve, 12.0)]);
    let got = pieces(&style, &sketch);
    for (q, &(segments, n, whole)) in got.iter().enumerate() {
        assert!(
            n == 1 && whole,
            "query {q}: {segments} segments give {n} ink pieces (one spans the stroke: {whole})"
        );
    }
}
