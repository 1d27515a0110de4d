//! `flourish brush` on sketches of many small strokes: the output stage
//! measures the style once per sketch and continues each query's field only
//! around its ornament, and both give what the per-query, whole-canvas
//! reading gives.

use super::vine;
use crate::brush::analysis::BrushStyle;
use crate::brush::output::{brush_sketch, extend_field, trace_query};
use crate::brush::pipeline::Settings;
use crate::brush::synth::{self, Coord, Field};
use crate::raster::Grid;
use crate::trace::TraceOptions;

/// The 8-neighbour offsets in scan order (as the output stage reads them).
const NEIGHBOURS: [(isize, isize); 8] = [
    (-1, -1),
    (0, -1),
    (1, -1),
    (-1, 0),
    (1, 0),
    (-1, 1),
    (0, 1),
    (1, 1),
];

/// The documented continuation, ring by ring over the whole canvas from a
/// copy of the field, each continued pixel keeping the covered pixel it
/// was continued from: the oracle for [`extend_field`].
fn extend_naive(style: &BrushStyle, field: &Field, rings: usize) -> Field {
    let mut f = field.clone();
    let (w, h) = (f.coords.width(), f.coords.height());
    // Per pixel, the covered source it was continued from: position,
    // coordinate, Jacobian, orientation.
    type From = ((usize, usize), Coord, synth::Jacobian, [f32; 2]);
    let mut from: Vec<Option<From>> = vec![None; w * h];
    for _ in 0..rings {
        let snap = f.clone();
        let held = from.clone();
        let mut any = false;
        for y in 0..h {
            for x in 0..w {
                if snap.coords.get(x, y).is_some() {
                    continue;
                }
                let mut counts: Vec<(u32, usize)> = Vec::new();
                let mut firsts: Vec<(u32, (usize, usize))> = Vec::new();
                for (dx, dy) in NEIGHBOURS {
                    let (nx, ny) = (x as isize + dx, y as isize + dy);
                    let Some(c) = snap.coords.get_or(nx, ny, None) else {
                        continue;
                    };
                    match counts.iter_mut().find(|(e, _)| *e == c.exemplar) {
                        Some(k) => k.1 += 1,
                        None => {
                            counts.push((c.exemplar, 1));
                            firsts.push((c.exemplar, (nx as usize, ny as usize)));
                        }
                    }
                }
                let top = counts.iter().map(|c| c.1).max().unwrap_or(0);
                let Some((e, _)) = counts.iter().find(|c| c.1 == top) else {
                    continue;
                };
                let Some(&(_, (nx, ny))) = firsts.iter().find(|p| p.0 == *e) else {
                    continue;
                };
                let src = match held[ny * w + nx] {
                    Some(s) => s,
                    None => {
                        let (Some(c), Some(j)) = (
                            snap.coords.get(nx, ny),
                            synth::jacobian(style, &snap, nx, ny),
                        ) else {
                            continue;
                        };
                        ((nx, ny), c, j, snap.orient.get(nx, ny))
                    }
                };
                let (at, c, j, o) = src;
                let d = synth::apply(j, [x as f32 - at.0 as f32, y as f32 - at.1 as f32]);
                f.coords.set(
                    x,
                    y,
                    Some(Coord {
                        exemplar: c.exemplar,
                        x: c.x + d[0],
                        y: c.y + d[1],
                    }),
                );
                f.orient.set(x, y, o);
                from[y * w + x] = Some(src);
                any = true;
            }
        }
        if !any {
            break;
        }
    }
    f
}

#[test]
fn a_field_is_continued_as_a_whole_canvas_scan_continues_it() {
    let style = vine();
    // A blob of two exemplars' coordinates touching the canvas's left and
    // top edges, with a hole, on a canvas larger than it.
    let (w, h) = (40, 30);
    let coords = Grid::from_fn(w, h, |x, y| {
        let (dx, dy) = (x as f32 - 6.0, y as f32 - 5.0);
        let r2 = dx * dx + 0.6 * dy * dy;
        (r2 < 90.0 && r2 > 4.0).then(|| Coord {
            exemplar: u32::from(x > 8),
            x: 120.0 + 0.9 * x as f32 + 0.2 * y as f32,
            y: 240.0 + 1.1 * y as f32,
        })
    });
    let field = Field {
        level: 2,
        orient: Grid::from_fn(
            w,
            h,
            |x, _| if x % 3 == 0 { [0.6, 0.8] } else { [1.0, 0.0] },
        ),
        seam: Grid::new(w, h, false),
        user: None,
        coords,
    };
    for rings in [1, 4, 12] {
        assert_eq!(
            extend_field(style, &field, rings),
            extend_naive(style, &field, rings),
            "{rings} rings"
        );
    }
    // Nothing covered: nothing to continue.
    let empty = Field {
        coords: Grid::new(w, h, None),
        ..field
    };
    assert_eq!(extend_field(style, &empty, 4), empty);
}

#[test]
fn many_small_strokes_each_trace_as_alone() {
    let style = vine();
    let mut body = String::new();
    for i in 0..6 {
        let (x, y) = (15.0 + 23.0 * i as f64, 20.0 + 9.0 * (i % 3) as f64);
        body.push_str(&format!(
            r#"<path d="M{x} {y} l {} 3" fill="none" stroke="black" stroke-width="2"/>"#,
            1 + i
        ));
    }
    let svg = format!(
        r#"<svg xmlns="http://www.w3.org/2000/svg" width="160" height="60" viewBox="0 0 160 60">{body}</svg>"#
    );
    let sk = crate::read::sketch::parse(svg.as_bytes()).expect("parses");
    let out = brush_sketch(style, &sk, &Settings::default()).expect("brushes");
    assert_eq!(out.queries.len(), 6);
    assert_eq!(out.document.groups.len(), 6);
    for (r, g) in out.queries.iter().zip(&out.document.groups) {
        assert!(!g.shapes.is_empty(), "{}: no ink", g.id);
        // The style measured once for the sketch gives what measuring it
        // for this query alone gives.
        let alone = trace_query(style, r, g.id.clone(), &TraceOptions::default());
        assert_eq!(&alone, g, "{}", g.id);
    }
}

#[test]
fn continued_ink_ends_within_the_continuations_reach() {
    use crate::brush::output::{border_rings, final_layers};
    let style = vine();
    let svg = r#"<svg xmlns="http://www.w3.org/2000/svg" width="200" height="120" viewBox="0 0 200 120"><path d="M20 80 C 60 10, 120 10, 180 70" fill="none" stroke="black" stroke-width="16"/></svg>"#;
    let sk = crate::read::sketch::parse(svg.as_bytes()).expect("parses");
    let keep = Settings {
        discard_fields: false,
        ..Settings::default()
    };
    let out = brush_sketch(style, &sk, &keep).expect("brushes");
    let r = &out.queries[0];
    let covered = r.field.coords.map(|c| c.is_some());
    let dist = crate::raster::edt::squared_edt(&covered).map(f32::sqrt);
    let k = r.sub.max(1);
    // The last continued ring less the documented margin, and the cross-
    // fade of one canvas pixel beyond it.
    let reach = border_rings(r) as f32 - 1.5 + 1.0;
    let (mut inked, mut beyond) = (0usize, 0usize);
    for (_, g) in final_layers(style, r) {
        for oy in 0..g.height() {
            for ox in 0..g.width() {
                if g.get(ox, oy) >= 0.0 {
                    continue;
                }
                inked += 1;
                let d = dist.get(ox / k, oy / k);
                if d > reach {
                    beyond += 1;
                }
            }
        }
    }
    assert!(inked > 0);
    assert_eq!(beyond, 0, "{beyond} of {inked} ink px beyond the reach");
}
