//! The span search both fitters share ([`super::fit`] for SDF contours,
//! [`super::cover`] for exact outlines): from where a piece's cover has got
//! to, the longest span one cubic fits, found by halving and bisecting; the
//! cubic for one span ([`fit_span`]: the piece's fitter and its checks, or
//! a straight chord), and the cubics of a loop gathered into a path.

use super::fit::{Guide, Piece};
use kurbo::{Affine, BezPath, CubicBez, ParamCurve, ParamCurveArclen, Point, Vec2};
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
    // Halve until one cubic fits.
    let mut fail = hi;
    let mut ok: Option<(f64, CubicBez)> = None;
    let mut end = 0.5 * (start + fail);
    while end - start >= min_span {
        if let Some(c) = fit_span(piece, start..end, accuracy) {
            ok = Some((end, c));
            break;
        }
        fail = end;
        end = 0.5 * (start + end);
    }
    let Some((mut good, mut cubic)) = ok else {
        // Nothing fits even a short span: the polygon up to there.
        let end = (start + min_span).min(1.0);
        polygon(piece, start..end, out);
        return end;
    };
    // Bisect between the success and the failure above it.
    while (fail - good) * total > (share * (good - start) * total).max(0.5) {
        let mid = 0.5 * (good + fail);
        match fit_span(piece, start..mid, accuracy) {
            Some(c) => {
                good = mid;
                cubic = c;
            }
            None => fail = mid,
        }
    }
    out.push(cubic);
    good
}

/// One cubic for `range`: the fitted one if it passes [`fit_checked`], else
/// the straight chord if the outline and the level set stay within
/// [`CHORD_SHARE`] × `accuracy` of it (short
/// spans of a noisy outline, where the end tangents disagree with the
/// chord and no cubic passes, are usually this).
pub(super) fn fit_span(piece: &Piece, range: Range<f64>, accuracy: f64) -> Option<CubicBez> {
    fit_checked(piece, range.clone(), accuracy).or_else(|| {
        let s0 = range.start * piece.length();
        let s1 = range.end * piece.length();
        let a = piece.locate(s0).1;
        let b = piece.locate(s1).1;
        let chord = kurbo::Line::new(a, b);
        // The vertices strictly inside (s0, s1): `cum` ascends.
        let lo = piece.cum.partition_point(|&c| c <= s0);
        let hi = piece.cum.partition_point(|&c| c < s1).max(lo);
        let within = piece.pts[lo..hi].iter().all(|&p| {
            crate::raster::sdf::point_segment_distance(p, chord)
                <= piece.reach(CHORD_SHARE * accuracy)
        });
        let on_level_set = || {
            piece.holds(
                (1..64).map(|k| a.lerp(b, k as f64 / 64.0)),
                s0,
                s1,
                CHORD_SHARE * accuracy,
            )
        };
        (a != b && within && on_level_set()).then(|| line_cubic(a, b))
    })
}

/// The share of the accuracy a straight chord may use (see [`fit_span`]).
const CHORD_SHARE: f64 = 0.6;

/// Appends the piece's polygon over `range` as straight cubics.
pub(super) fn polygon(piece: &Piece, range: Range<f64>, out: &mut Vec<CubicBez>) {
    let s0 = range.start * piece.length();
    let s1 = range.end * piece.length();
    let mut prev = piece.locate(s0).1;
    for (i, &c) in piece.cum.iter().enumerate() {
        if c > s0 && c < s1 {
            out.push(line_cubic(prev, piece.pts[i]));
            prev = piece.pts[i];
        }
    }
    let end = piece.locate(s1).1;
    if end != prev {
        out.push(line_cubic(prev, end));
    }
}

/// Parameter span (of the piece's 0..1) below which a range is not split
/// further but kept as a polygon.
pub(super) const MIN_SPAN_PX: f64 = 1.5;

/// One cubic for `range` of the piece that passes the piece's checks: for
/// an exact outline the direct fit ([`super::direct`]); for an SDF contour
/// kurbo's fitter, with the curve also within `accuracy` + [`CHECK_SLACK`]
/// of the SDF's zero level at 63 points. Either way the curve may not loop
/// away (arc length at most 1.5× the source's) and the range must not be
/// "spicy" (see [`is_spicy`]).
fn fit_checked(piece: &Piece, range: Range<f64>, accuracy: f64) -> Option<CubicBez> {
    let samples = piece.samples(range.clone());
    if is_spicy(&samples) {
        return None;
    }
    if let Guide::Outline(_) = piece.guide {
        return super::direct::fit_span_direct(piece, range, &samples, accuracy);
    }
    let len = piece.length() * (range.end - range.start);
    let (c, _) = kurbo::fit_to_cubic(piece, range.clone(), piece.reach(accuracy))?;
    let c = Affine::translate(piece.origin) * c;
    let s0 = range.start * piece.length();
    let s1 = range.end * piece.length();
    let ok = piece.holds((1..64).map(|k| c.eval(k as f64 / 64.0)), s0, s1, accuracy)
        && c.arclen(0.01) <= 1.5 * len + 0.5
        && piece.keeps_handles_on_canvas(&c);
    ok.then_some(c)
}

/// Number of samples (ends included) a range is checked at: kurbo's error
/// measure samples 20 interior points, so does [`super::direct`].
pub(super) const FIT_SAMPLES: usize = 22;

/// True when kurbo would judge the range "spicy" (tangents of neighbouring
/// error samples more than about 11° apart) and fall back to measuring
/// error by arc length at 1e-9 accuracy, which is very slow; such ranges
/// are split first. The outline path keeps the same limit on how sharply
/// one cubic's source may bend between samples.
fn is_spicy(samples: &[(Point, Vec2); FIT_SAMPLES]) -> bool {
    samples
        .windows(2)
        .any(|w| w[1].1.cross(w[0].1).abs() > 0.2 * w[1].1.dot(w[0].1).abs())
}
