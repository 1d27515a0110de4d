//! The span search both fitters share ([`super::fit`] for SDF contours,
//! [`super::cover`] for exact outlines): from where a piece's cover has got
//! to, the longest span one cubic fits, found by halving and bisecting; the
//! cubic for one span ([`fit_span`]: the piece's fitter and its checks, or
//! a straight chord), and the cubics of a loop gathered into a path.

use super::piece::{Guide, Piece, FIT_SAMPLES};
use kurbo::{BezPath, CubicBez, ParamCurve, Point, Vec2};
use std::ops::Range;

/// Appends the closed loop of consecutive `cubics` to `out` as one subpath
/// (straight ones as lines); nothing for none.
pub(super) fn append_loop(cubics: &[CubicBez], out: &mut BezPath) {
    let Some(first) = cubics.first() else {
        return;
    };
    out.move_to(first.p0);
    for c in cubics {
        if is_line(c) {
            out.line_to(c.p3);
        } else {
            out.curve_to(c.p1, c.p2, c.p3);
        }
    }
    out.close_path();
}

pub(super) fn is_line(c: &CubicBez) -> bool {
    c.p1 == c.p0.lerp(c.p3, 1.0 / 3.0) && c.p2 == c.p0.lerp(c.p3, 2.0 / 3.0)
}

pub(super) fn line_cubic(a: Point, b: Point) -> CubicBez {
    CubicBez::new(a, a.lerp(b, 1.0 / 3.0), a.lerp(b, 2.0 / 3.0), b)
}

/// Covers `piece` from `start` (a share of its length) with the longest
/// span up to `hi` that one cubic fits, pushed to `out`, and returns where
/// the span ends: the whole `start..hi` if it fits; else halved until one
/// fits, then bisected between that success and the failure above it down
/// to `share` of the span found (or half a pixel). When not even
/// [`MIN_SPAN_PX`] fits, the polygon over that length (it lies on what is
/// fitted).
///
/// The halving and bisection steps are taken on the
/// cheap half of the test alone ([`probe`]: the span's samples bend
/// gently enough, or its chord fits) and only the span they settle on is
/// fitted and checked in full; if it fails, it becomes the failure above
/// and the search goes on below it from the highest span that passed the
/// cheap test. Where both halves agree (most spans) this is the same
/// search, with one full fit per span instead of one per step that
/// succeeds.
pub(super) fn longest_span(
    piece: &Piece,
    start: f64,
    hi: f64,
    share: f64,
    accuracy: f64,
    out: &mut Vec<CubicBez>,
) -> f64 {
    if let Some(c) = fit_span(piece, start..hi, accuracy) {
        out.push(c);
        return hi;
    }
    let total = piece.length();
    let min_span = (MIN_SPAN_PX / total).min(1.0);
    let probe = |end: f64| probe(piece, start..end, accuracy);
    let mut fail = hi;
    // The ends found to pass so far below `fail` (ascending), with their
    // cubic once fitted.
    let mut goods: Vec<(f64, Known)> = Vec::new();
    loop {
        if goods.is_empty() {
            // Halve until one passes.
            let mut end = 0.5 * (start + fail);
            while end - start >= min_span {
                match probe(end) {
                    Probe::Fits(c) => goods.push((end, Known::Fits(c))),
                    Probe::Likely(samples) => goods.push((end, Known::Likely(samples))),
                    Probe::Fails => {
                        fail = end;
                        end = 0.5 * (start + end);
                        continue;
                    }
                }
                break;
            }
        }
        let Some((mut good, mut cubic)) = goods.last().cloned() else {
            // Nothing fits even a short span: the polygon up to there.
            let end = (start + min_span).min(1.0);
            polygon(piece, start..end, accuracy, out);
            return end;
        };
        // Bisect between the success and the failure above it.
        while (fail - good) * total > (share * (good - start) * total).max(0.5) {
            let mid = 0.5 * (good + fail);
            match probe(mid) {
                Probe::Fits(c) => (good, cubic) = (mid, Known::Fits(c)),
                Probe::Likely(samples) => (good, cubic) = (mid, Known::Likely(samples)),
                Probe::Fails => {
                    fail = mid;
                    continue;
                }
            }
            goods.push((good, cubic.clone()));
        }
        let fitted = match cubic {
            Known::Fits(c) => Some(c),
            Known::Likely(samples) => {
                // The samples the probe took: the same range.
                super::direct::fit_span_direct(piece, start..good, &samples, accuracy)
                    .or_else(|| chord_span(piece, start..good, accuracy))
            }
        };
        match fitted {
            Some(c) => {
                out.push(c);
                return good;
            }
            None => {
                // The cheap test passed, the fit did not.
                goods.pop();
                fail = good;
            }
        }
    }
}

/// A span's [`FIT_SAMPLES`] samples (position, px, and unit tangent).
type Samples = [(Point, Vec2); FIT_SAMPLES];

/// What [`longest_span`] knows of a span that passed a probe.
#[derive(Clone)]
enum Known {
    /// It fits: this cubic.
    Fits(CubicBez),
    /// It passed the cheap test with these samples.
    Likely(Box<Samples>),
}

/// What one step of [`longest_span`]'s search learns about a span.
enum Probe {
    /// It fits: this cubic.
    Fits(CubicBez),
    /// It passes the cheap test (these are the span's samples); whether it
    /// fits is found out only if the search settles on it.
    Likely(Box<Samples>),
    /// It does not fit.
    Fails,
}

/// One step of [`longest_span`]'s search over `range`: whether the span's
/// samples bend gently enough for a cubic ([`is_sharp`]; the fit itself is left
/// for later), else whether its chord fits (as [`fit_span`] does).
fn probe(piece: &Piece, range: Range<f64>, accuracy: f64) -> Probe {
    if let Some(samples) = piece.samples_while(range.clone(), |a, b| !is_sharp(a, b)) {
        return Probe::Likely(Box::new(samples));
    }
    chord_span(piece, range, accuracy).map_or(Probe::Fails, Probe::Fits)
}

/// One cubic for `range`: the fitted one if it passes [`fit_checked`], else
/// the straight chord if the outline and the level set stay within
/// [`CHORD_SHARE`] × `accuracy` of it (short
/// spans of a noisy outline, where the end tangents disagree with the
/// chord and no cubic passes, are usually this).
pub(super) fn fit_span(piece: &Piece, range: Range<f64>, accuracy: f64) -> Option<CubicBez> {
    fit_checked(piece, range.clone(), accuracy).or_else(|| chord_span(piece, range, accuracy))
}

/// The straight chord over `range` if the outline and the level set stay
/// within [`CHORD_SHARE`] × `accuracy` of it (see [`fit_span`]).
fn chord_span(piece: &Piece, range: Range<f64>, accuracy: f64) -> Option<CubicBez> {
    let s0 = range.start * piece.length();
    let s1 = range.end * piece.length();
    let a = piece.locate(s0).1;
    let b = piece.locate(s1).1;
    let chord = kurbo::Line::new(a, b);
    // The vertices strictly inside (s0, s1): `cum` ascends.
    let lo = piece.cum.partition_point(|&c| c <= s0);
    let hi = piece.cum.partition_point(|&c| c < s1).max(lo);
    let inner = piece.pts.get(lo..hi).unwrap_or(&[]);
    let near_chord = |&p: &Point| {
        crate::raster::sdf::point_segment_distance(p, chord) <= piece.reach(CHORD_SHARE * accuracy)
    };
    // Every eighth vertex first: a curved span strays from its chord
    // mid-way, and most spans reaching here are curved.
    let stride = (inner.len() / 8).max(1);
    let within = inner
        .iter()
        .skip(stride / 2)
        .step_by(stride)
        .all(near_chord)
        && inner.iter().all(near_chord);
    let on_level_set = || {
        // On an outline, as a cubic's (see `super::direct`).
        let m = match piece.guide {
            Guide::Outline(_) => super::direct::check_chords((b - a).hypot()),
            Guide::Field(_) => 64,
        };
        piece.holds(
            (1..m).map(|k| a.lerp(b, k as f64 / m as f64)),
            s0,
            s1,
            CHORD_SHARE * accuracy,
        )
    };
    (a != b && within && on_level_set()).then(|| line_cubic(a, b))
}

/// The share of the accuracy a straight chord may use (see [`fit_span`]).
pub(super) const CHORD_SHARE: f64 = 0.6;

/// Appends the piece's polygon over `range` as straight cubics, simplified
/// to the fewest of its vertices that keep every other one within
/// `accuracy` px, each line also checked against what the piece is fitted
/// to (Douglas–Peucker). The span is a sharp turn no cubic follows (a thin
/// line's pointed end, a corner too tight to be found): its flattened
/// outline alone would be 5–10 lines a tenth of a pixel long.
pub(super) fn polygon(piece: &Piece, range: Range<f64>, accuracy: f64, out: &mut Vec<CubicBez>) {
    let s0 = range.start * piece.length();
    let s1 = range.end * piece.length();
    // The vertices with their arc lengths.
    let mut pts = vec![(piece.locate(s0).1, s0)];
    for (i, &c) in piece.cum.iter().enumerate() {
        if c > s0 && c < s1 {
            pts.push((piece.pts[i], c));
        }
    }
    let end = piece.locate(s1).1;
    if pts.last().map(|p| p.0) != Some(end) {
        pts.push((end, s1));
    }
    let mut keep = vec![false; pts.len()];
    keep[0] = true;
    keep[pts.len() - 1] = true;
    simplify(piece, &pts, 0, pts.len() - 1, accuracy, &mut keep);
    let mut prev = pts[0].0;
    for (&(p, _), _) in pts.iter().zip(&keep).skip(1).filter(|(_, &k)| k) {
        if p != prev {
            out.push(line_cubic(prev, p));
            prev = p;
        }
    }
}

/// Douglas–Peucker between kept vertices `a` and `b` of `pts` (points with
/// their arc lengths on the piece): the chord stands when every vertex
/// between is within `tol` px of it and it holds against the piece;
/// otherwise the vertex farthest from it is kept and both halves tried.
fn simplify(piece: &Piece, pts: &[(Point, f64)], a: usize, b: usize, tol: f64, keep: &mut [bool]) {
    if b <= a + 1 {
        return;
    }
    let chord = kurbo::Line::new(pts[a].0, pts[b].0);
    let (far, d) = (a + 1..b)
        .map(|i| {
            (
                i,
                crate::raster::sdf::point_segment_distance(pts[i].0, chord),
            )
        })
        .fold((a, -1.0), |best, x| if x.1 > best.1 { x } else { best });
    let holds = || {
        let samples = (1..16).map(|k| chord.eval(k as f64 / 16.0));
        piece.holds(samples, pts[a].1, pts[b].1, tol)
    };
    if d > tol || !holds() {
        keep[far] = true;
        simplify(piece, pts, a, far, tol, keep);
        simplify(piece, pts, far, b, tol, keep);
    }
}

/// Parameter span (of the piece's 0..1) below which a range is not split
/// further but kept as a polygon.
pub(super) const MIN_SPAN_PX: f64 = 1.5;

/// One cubic for `range` of the piece that passes the piece's checks: the
/// direct fit ([`super::direct`]), on an SDF contour within `accuracy` +
/// [`CHECK_SLACK`](super::piece::CHECK_SLACK) of the zero level and with
/// its handles on the canvas. The curve may not loop away (arc length at
/// most 1.5× the source's) and the range must not bend sharply between
/// samples (see [`is_sharp`]).
fn fit_checked(piece: &Piece, range: Range<f64>, accuracy: f64) -> Option<CubicBez> {
    let samples = piece.samples_while(range.clone(), |a, b| !is_sharp(a, b))?;
    super::direct::fit_span_direct(piece, range, &samples, accuracy)
}

/// True when these tangents of neighbouring samples are more than about
/// 11° apart: one cubic's source may not bend more sharply than that
/// between samples (kurbo's fitter calls such a range "spicy"); such
/// ranges are split first.
fn is_sharp(a: Vec2, b: Vec2) -> bool {
    b.cross(a).abs() > 0.2 * b.dot(a).abs()
}

#[cfg(test)]
mod tests {
    use super::*;
    use kurbo::ParamCurveNearest;

    /// The search on an exact outline (cheap probes, one full fit where it
    /// settles) covers a spiral contiguously with cubics that each stay
    /// within the accuracy of the outline (measured by brute force at 64
    /// points against every segment), and with no more spans than a brute
    /// force greedy cover (the longest end on a grid of 1/256 of the
    /// length that `fit_span` accepts, tried from the top) needs, give or
    /// take one.
    #[test]
    fn probe_search_covers_a_spiral_like_brute_force() {
        use crate::raster::sdf::point_segment_distance;
        // r = 20 + 6θ over a turn and a half, at 0.5-px steps or so.
        let f = |t: f64| {
            let a = 3.0 * std::f64::consts::PI * t;
            let r = 20.0 + 6.0 * a;
            Point::new(60.0 + r * a.cos(), 60.0 + r * a.sin())
        };
        let df = |t: f64| {
            let a = 3.0 * std::f64::consts::PI * t;
            let r = 20.0 + 6.0 * a;
            Vec2::new(6.0 * a.cos() - r * a.sin(), 6.0 * a.sin() + r * a.cos()).normalize()
        };
        let n = 500;
        let ts: Vec<f64> = (0..=n).map(|i| i as f64 / n as f64).collect();
        let pts: Vec<Point> = ts.iter().map(|&t| f(t)).collect();
        let piece = Piece::new(
            pts.clone(),
            ts.iter().map(|&t| df(t)).collect(),
            Guide::Outline(None),
            false,
            false,
        );
        let accuracy = 0.25;
        let mut cubics = Vec::new();
        let mut start = 0.0;
        let mut spans = 0;
        while start < 1.0 {
            let before = cubics.len();
            let end = longest_span(&piece, start, 1.0, 0.125, accuracy, &mut cubics);
            assert!(end > start && cubics.len() > before);
            start = end;
            spans += 1;
        }
        for w in cubics.windows(2) {
            assert_eq!(w[0].p3, w[1].p0);
        }
        assert_eq!(cubics[0].p0, pts[0]);
        assert_eq!(cubics[cubics.len() - 1].p3, pts[n]);
        for c in &cubics {
            for k in 0..=64 {
                let q = c.eval(k as f64 / 64.0);
                let d = pts
                    .windows(2)
                    .map(|w| point_segment_distance(q, kurbo::Line::new(w[0], w[1])))
                    .fold(f64::INFINITY, f64::min);
                assert!(d <= accuracy + 0.05, "{q:?} is {d} px off");
            }
        }
        let grid = 256;
        let (mut at, mut greedy) = (0usize, 0usize);
        while at < grid {
            let end = (at + 1..=grid)
                .rev()
                .find(|&e| {
                    fit_span(
                        &piece,
                        at as f64 / grid as f64..e as f64 / grid as f64,
                        accuracy,
                    )
                    .is_some()
                })
                .unwrap_or(at + 1);
            at = end;
            greedy += 1;
        }
        assert!(spans <= greedy + 1, "{spans} spans, brute force {greedy}");
    }

    /// The fallback polygon over a tight turn (a flattened half circle of
    /// radius 0.4 px, 24 points) is a handful of lines, every vertex of the
    /// outline within the accuracy of them.
    #[test]
    fn fallback_polygon_is_simplified_within_accuracy() {
        let pts: Vec<Point> = (0..24)
            .map(|k| {
                let a = std::f64::consts::PI * k as f64 / 23.0;
                Point::new(10.0 + 0.4 * a.cos(), 10.0 + 0.4 * a.sin())
            })
            .collect();
        let tangents: Vec<Vec2> = (0..24)
            .map(|k| {
                let a = std::f64::consts::PI * k as f64 / 23.0;
                Vec2::new(-a.sin(), a.cos())
            })
            .collect();
        let piece = Piece::new(pts.clone(), tangents, Guide::Outline(None), false, false);
        let mut out = Vec::new();
        polygon(&piece, 0.0..1.0, 0.25, &mut out);
        assert!(out.len() <= 3, "{} lines", out.len());
        assert_eq!(out[0].p0, pts[0]);
        assert_eq!(out[out.len() - 1].p3, pts[23]);
        for p in &pts {
            let d = out
                .iter()
                .map(|c| (c.eval(c.nearest(*p, 1e-9).t) - *p).hypot())
                .fold(f64::INFINITY, f64::min);
            assert!(d <= 0.25 + 1e-9, "{p:?} {d} px from the polygon");
        }
    }
}
