//! Exact outlines (a bitmap's smoothed or sub-pixel outline) to the fewest
//! cubic Béziers a greedy cover of each corner-free run finds.
//!
//! Each run between two corners (or a whole loop without corners) is one
//! fitting source (`Piece`, tangents given by the outline, exact area and
//! moment integrals of the polyline). From the start of what is left, the
//! longest span that one cubic fits is searched for (the direct fitter of
//! `super::direct`, which matches area and first moment under the end
//! tangents and judges each candidate by the outline itself both ways; see
//! `super::span::fit_span`), halving and then bisecting down to
//! `SEARCH_SHARE` of the span; the span is only capped by how much the outline turns
//! within it ([`MAX_SPAN_TURN`]), not cut into fixed pieces beforehand, so
//! a run costs no more cubics than its shape needs. When fitting is
//! monotone in the span (a sub-span of a span that fits, fits), extending
//! each span as far as it goes is optimal for the run (the classic greedy
//! argument for covering an interval), which is what potrace's opticurve
//! stage gets from its dynamic program over polygon vertices (Selinger
//! 2003, §2.4). Consecutive cubics meet with G1 continuity: both take the
//! outline's tangent at the join.
//!
//! What the curves are held to. An anti-aliased outline is known to a
//! fraction of a pixel, so curves stay within the accuracy of it. A binary
//! bitmap's smoothed outline is only one reading of the staircase: the
//! drawn edge may lie anywhere between the ink and paper pixel centres, so
//! there a curve point is accepted within the accuracy of the smoothed
//! outline, or within the accuracy of the corridor
//! ([`crate::outline::corridor`]: a mixed cell, at least 0.5 − accuracy px
//! from every pixel centre, so a 1-px line keeps its width and a 1-px gap
//! stays open) and no further than 0.5 + accuracy px from the smoothed
//! outline. This is potrace's reading: its polygon may pass anywhere within
//! half a pixel of the boundary, and opticurve only bounds the curves
//! against that. `outline_curves_stay_within_tolerance_of_their_reference`
//! (`src/trace/tests.rs`) checks each sampled curve point against this
//! reference at tolerance + 0.05 px.

use super::piece::{corner_runs, Guide, Piece};
use super::span::{append_loop, fit_span, line_cubic, longest_span, CHORD_SHARE, MIN_SPAN_PX};
use crate::outline::corridor::Corridor;
use kurbo::{BezPath, CubicBez, Point, Vec2};
use rayon::prelude::*;

/// Most turning (radians) one cubic is asked to follow: a half turn, about
/// what one cubic without an inflection can follow closely. A smaller cap
/// splits spans one cubic could take (more segments); a larger one lets a
/// cubic stray from the drawn outline.
pub const MAX_SPAN_TURN: f64 = std::f64::consts::PI;

/// Turning is accumulated between chords of about this many px, which
/// follow the outline's shape and not the sub-pixel wobble of its vertices.
const TURN_STEP: f64 = 3.0;

/// The search for the end of a span stops when the bracket between the
/// longest span that fits and the shortest that does not is below this
/// share of the span (or half a pixel): 3/16 saves one bisection step
/// against an eighth on most spans for about the same number of cubics,
/// while a quarter saves little more work and costs cubics.
const SEARCH_SHARE: f64 = 0.1875;

/// Fits a closed outline (pixel coordinates) with cubic Béziers within
/// `accuracy` px of it, appending a closed subpath to `out`: `tangents` are
/// the outline's unit tangents at its points and `corners` the indices
/// (ascending) where it turns sharply, where cubics meet at an angle. This
/// is the path for outlines known exactly (a binary bitmap's, see
/// [`crate::outline::smooth::SmoothLoop`]), with no SDF in between.
pub fn fit_outline(
    pts: &[Point],
    tangents: &[Vec2],
    corners: &[usize],
    accuracy: f64,
    corridor: Option<&Corridor>,
    out: &mut BezPath,
) {
    append_loop(
        &outline_cubics(pts, tangents, corners, accuracy, corridor),
        out,
    );
}

/// The cubics [`fit_outline`] closes into a loop, in order round it
/// (none for fewer than three points).
pub fn outline_cubics(
    pts: &[Point],
    tangents: &[Vec2],
    corners: &[usize],
    accuracy: f64,
    corridor: Option<&Corridor>,
) -> Vec<CubicBez> {
    let n = pts.len();
    if n < 3 || tangents.len() != n {
        return Vec::new();
    }
    let mut cs: Vec<usize> = corners.iter().copied().filter(|&c| c < n).collect();
    cs.dedup();
    let run = |idx: &[usize], corner: bool| {
        Piece::new(
            idx.iter().map(|&i| pts[i]).collect(),
            idx.iter().map(|&i| tangents[i]).collect(),
            Guide::Outline(corridor),
            corner,
            corner,
        )
    };
    let cubics: Vec<CubicBez> = if cs.is_empty() {
        // A smooth loop is one run from its first point around to it again:
        // the end tangents are the same, so the seam is a G1 join.
        let idx: Vec<usize> = (0..n).chain([0]).collect();
        let mut cubics = Vec::new();
        cover_run(&run(&idx, false), accuracy, &mut cubics);
        cubics
    } else {
        // The runs between corners are independent: covered in parallel
        // (a large loop holds most of a drawing's work), gathered in order.
        let runs = corner_runs(&cs, n);
        let covered: Vec<Vec<CubicBez>> = runs
            .par_iter()
            .map(|idx| {
                let mut cubics = Vec::new();
                cover_run(&run(idx, true), accuracy, &mut cubics);
                cubics
            })
            .collect();
        covered.into_iter().flatten().collect()
    };
    cubics
}

/// Fits an open polyline (pixel coordinates) from its first point to its
/// last with cubic Béziers within `accuracy` px of it: `tangents` at its
/// points, `corners` (ascending, both ends among them) where cubics meet
/// at an angle. Each run between corners is covered as a closed
/// outline's is; the ends stay where they are.
pub fn fit_open(
    pts: &[Point],
    tangents: &[Vec2],
    corners: &[usize],
    accuracy: f64,
) -> Vec<CubicBez> {
    let n = pts.len();
    if n < 2 || tangents.len() != n {
        return Vec::new();
    }
    let mut cs: Vec<usize> = corners.iter().copied().filter(|&c| c < n).collect();
    cs.sort_unstable();
    cs.dedup();
    if cs.first() != Some(&0) {
        cs.insert(0, 0);
    }
    if cs.last() != Some(&(n - 1)) {
        cs.push(n - 1);
    }
    let mut cubics = Vec::new();
    for w in cs.windows(2) {
        let (a, b) = (w[0], w[1]);
        let piece = Piece::new(
            pts[a..=b].to_vec(),
            tangents[a..=b].to_vec(),
            Guide::Outline(None),
            true,
            true,
        );
        let before = cubics.len();
        cover_run(&piece, accuracy, &mut cubics);
        if cubics.len() == before && pts[a] != pts[b] {
            cubics.push(line_cubic(pts[a], pts[b]));
        }
        // The run's ends exactly where its corners are.
        if let Some(c) = cubics.get_mut(before) {
            c.p0 = pts[a];
        }
        let len = cubics.len();
        if len > before {
            cubics[len - 1].p3 = pts[b];
        }
    }
    cubics
}

/// Accumulated turning (radians) of the piece at each vertex, measured
/// between chords of about [`TURN_STEP`] px.
fn turning(piece: &Piece) -> Vec<f64> {
    let n = piece.len();
    let mut acc = vec![0.0; n];
    let mut anchor = 0usize;
    let mut prev_dir: Option<f64> = None;
    let mut total = 0.0;
    for (i, a) in acc.iter_mut().enumerate().skip(1) {
        if piece.arc_at(i) - piece.arc_at(anchor) >= TURN_STEP || i == n - 1 {
            let d = (piece.point(i) - piece.point(anchor)).atan2();
            if let Some(p) = prev_dir {
                let t = crate::raster::contour::wrap_once(
                    d - p + std::f64::consts::PI,
                    std::f64::consts::TAU,
                ) - std::f64::consts::PI;
                total += t.abs();
            }
            prev_dir = Some(d);
            anchor = i;
        }
        *a = total;
    }
    acc
}

/// Covers one run with as few cubics as the greedy longest-span search
/// finds (see the module docs). Spans shorter than [`MIN_SPAN_PX`] that
/// still do not fit fall back to the outline's polygon.
fn cover_run(piece: &Piece, accuracy: f64, out: &mut Vec<CubicBez>) {
    let n = piece.len();
    let total = piece.length();
    if n < 2 || total <= 1e-9 {
        return;
    }
    // A run as straight as its chord is that chord, held to the share of
    // the accuracy any straight chord gets (`span::fit_span`): a straight
    // side allowed the whole tolerance sits a quarter pixel off along its
    // whole length, a sixth of a 1.5-px line's weight.
    let (a, b) = (piece.point(0), piece.point(n - 1));
    let chord = kurbo::Line::new(a, b);
    let limit = CHORD_SHARE * accuracy;
    if a != b
        && (0..n)
            .all(|i| crate::raster::sdf::point_segment_distance(piece.point(i), chord) <= limit)
    {
        out.push(line_cubic(a, b));
        return;
    }
    let acc = turning(piece);
    let param = |i: usize| piece.arc_at(i) / total;
    let min_span = (MIN_SPAN_PX / total).min(1.0);
    let mut start = 0.0;
    let mut first_vertex = 0usize; // the first vertex at or after `start`
    let before = out.len();
    // Where the last two spans started (shares of the run's length).
    let mut starts = [0.0f64; 2];
    while start < 1.0 {
        starts = [starts[1], start];
        while first_vertex + 1 < n && param(first_vertex) < start {
            first_vertex += 1;
        }
        // The longest span considered ends where the turning since the
        // start reaches the cap (at least one vertex on).
        let base = acc[first_vertex.saturating_sub(1)];
        let mut last = first_vertex;
        while last + 1 < n && acc[last + 1] - base <= MAX_SPAN_TURN {
            last += 1;
        }
        let hi = if last + 1 >= n {
            1.0
        } else {
            param(last.max(first_vertex)).max(start + min_span).min(1.0)
        };
        start = longest_span(piece, start, hi, SEARCH_SHARE, accuracy, out);
    }
    merge_remainder(piece, starts, out.len() - before, accuracy, out);
}

/// The greedy cover's last span is what is left of the run, and the search
/// stops each span short of the longest by up to [`SEARCH_SHARE`]: a short
/// remainder (under half the span before it) is often one cubic with
/// that span. When one cubic fits both (`starts`: where they begin, as
/// shares of the run; `count` cubics were pushed for the run), it
/// replaces them.
fn merge_remainder(
    piece: &Piece,
    starts: [f64; 2],
    count: usize,
    accuracy: f64,
    out: &mut Vec<CubicBez>,
) {
    let [prev, last] = starts;
    if count < 2 || 1.0 - last >= 1.0 * (last - prev) {
        return;
    }
    if let Some(c) = fit_span(piece, prev..1.0, accuracy) {
        out.truncate(out.len() - 2);
        out.push(c);
    }
}
