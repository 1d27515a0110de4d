//! One cubic for one span of an outline or an SDF contour, fitted
//! directly (what [`super::span::longest_span`] fits for both
//! [`super::cover`] and [`super::fit`]).
//!
//! With the end points and end tangents fixed, a cubic has two free
//! numbers, its handle lengths. They are chosen so that the cubic encloses
//! the same signed area with the chord as the outline does, and has the
//! same first moment of that area along the chord (Levien, "Fitting cubic
//! Bézier curves", 2021: area and moment matching). In the frame where the
//! chord runs from (0, 0) to (1, 0), with the start tangent at angle θ₀
//! above the chord and the end tangent at θ₁ below it, the handles are
//! `p1 = d₀(cos θ₀, sin θ₀)` and `p2 = (1 − d₁ cos θ₁, d₁ sin θ₁)`; the
//! area `∫ y dx = 3/20 (2 d₀ sin θ₀ + 2 d₁ sin θ₁ − d₀ d₁ sin(θ₀ + θ₁))`
//! is bilinear, so it gives `d₁` from `d₀`, and the moment `∫ x y dx`
//! (quadratic in each handle) then becomes a quartic in `d₀`
//! ([`handle_lengths`], derived symbolically, checked against kurbo's
//! fitter in the tests). Each candidate is judged by what the piece is
//! fitted to: the piece's samples must lie near the curve and the curve
//! near the outline or the SDF's zero level (`Piece::holds`), which is all
//! the fitter is held to, so no separate error measure along normals is
//! needed (kurbo's fitter measures each candidate so, and the check would
//! repeat it).
//!
//! Of the candidates, the best ranked by a rough error ([`rough_error`],
//! long handles penalised) whose outline samples lie within reach of it,
//! in arc-length order (a discrete Fréchet test), is flattened into chords
//! of at most [`CURVE_SPACING`] along its control polygon and checked
//! against the outline at those points and the midpoints between them, in
//! one pass. The check is a pure predicate, so a point within the previous
//! point's slack of the segment that one was found near needs no search
//! (triangle inequality); the span's samples are taken in order, stepping
//! along the piece, and given up at the first pair of tangents too sharp
//! for one cubic.

use super::nearest::first_within;
use super::piece::{Piece, FIT_SAMPLES};
use kurbo::common::{factor_quartic_inner, solve_cubic, solve_quadratic};
use kurbo::{CubicBez, Point, Vec2};

/// Handle lengths `(d₀, d₁)` (in chord lengths, both ≥ 0) of the cubics
/// with unit chord, end tangents at `th0` above and `th1` below the chord
/// (given as `(sin, cos)` pairs), whose signed area with the chord is
/// `area` and whose moment `∫ x y dx` is `mx` (see the module docs).
/// Every real root of the quartic is a candidate; a complex pair
/// contributes its real part (the nearest miss). A root whose other handle
/// comes out negative becomes the one-handle cubic that still honours
/// both tangents: its handle at the apex of the tangent triangle.
pub(super) fn handle_lengths(
    (s0, c0): (f64, f64),
    (s1, c1): (f64, f64),
    area: f64,
    mx: f64,
) -> ([(f64, f64); 4], usize) {
    let (a, m) = (area, mx);
    let s01 = c0 * s1 + c1 * s0; // sin(θ₀ + θ₁)
                                 // The moment residual times (3 d₀ sin(θ₀+θ₁) − 6 sin θ₁)², scaled
                                 // by 280: coefficients of d₀⁰ … d₀⁴.
    let q0 = 240.0 * s1 * (25.0 * a * s1 - 25.0 * a * a * c1 - 42.0 * m * s1);
    let q1 = -48.0
        * (-75.0 * a * a * c1 * (c0 * s1 + c1 * s0)
            + 85.0 * a * c0 * s1 * s1
            + 70.0 * a * c1 * s0 * s1
            - 210.0 * m * s1 * (c0 * s1 + c1 * s0)
            + 12.0 * s0 * s1 * s1);
    let q2 = 36.0
        * (-5.0 * a * (3.0 * c0 * c0 * s1 * s1 + 4.0 * c0 * c1 * s0 * s1 + c1 * c1 * s0 * s0)
            - 70.0 * m * s01 * s01
            + 15.0 * c0 * s0 * s1 * s1
            + 9.0 * c1 * s0 * s0 * s1);
    let q3 = 36.0 * s01 * (15.0 * a * c0 * s01 - 2.0 * c0 * s0 * s1 + c1 * s0 * s0);
    let q4 = -27.0 * c0 * s0 * s01 * s01;
    let mut roots = [0.0; 4];
    let mut n = 0;
    let mut push = |r: f64| {
        if n < 4 {
            roots[n] = r;
            n += 1;
        }
    };
    const EPS: f64 = 1e-12;
    if q4.abs() > EPS {
        if let Some(quads) = factor_quartic_inner(q3 / q4, q2 / q4, q1 / q4, q0 / q4, false) {
            for (b, c) in quads {
                let rs = solve_quadratic(c, b, 1.0);
                if rs.is_empty() {
                    push(-0.5 * b);
                }
                for r in rs {
                    push(r);
                }
            }
        }
    } else if q3.abs() > EPS {
        solve_cubic(q0, q1, q2, q3).into_iter().for_each(&mut push);
    } else if q2.abs() > EPS || q1.abs() > EPS || q0.abs() > EPS {
        solve_quadratic(q0, q1, q2).into_iter().for_each(&mut push);
    } else {
        return (
            [(1.0 / 3.0, 1.0 / 3.0), (0.0, 0.0), (0.0, 0.0), (0.0, 0.0)],
            1,
        );
    }
    let mut out = [(0.0, 0.0); 4];
    let mut k = 0;
    for &d0 in &roots[..n] {
        let (d0, d1) = if d0 > 0.0 {
            // The area, solved for d₁.
            let d1 = (6.0 * d0 * s0 - 20.0 * a) / (3.0 * d0 * s01 - 6.0 * s1);
            if d1 > 0.0 {
                (d0, d1)
            } else {
                (s1 / s01, 0.0)
            }
        } else {
            (0.0, s0 / s01)
        };
        if d0 >= 0.0 && d1 >= 0.0 && d0.is_finite() && d1.is_finite() {
            out[k] = (d0, d1);
            k += 1;
        }
    }
    (out, k)
}

/// A span in the unit-chord frame of [`handle_lengths`].
struct Frame {
    /// End points (px).
    p0: Point,
    p3: Point,
    /// Unit chord direction and chord length (px).
    u: Vec2,
    chord: f64,
    /// `(sin, cos)` of the start tangent's angle above the chord and of the
    /// end tangent's below it.
    th0: (f64, f64),
    th1: (f64, f64),
    /// Signed area and x moment of the outline with the chord, in the
    /// frame (chord lengths² and ³).
    area: f64,
    mx: f64,
}

impl Frame {
    /// The frame of `range` of `piece`, `None` for a span without a chord.
    fn new(piece: &Piece, range: std::ops::Range<f64>) -> Option<Frame> {
        let (p0, t0) = piece.end_sample(range.start, true);
        let (p3, t1) = piece.end_sample(range.end, false);
        let d = p3 - p0;
        let chord2 = d.hypot2();
        if chord2 <= 1e-18 {
            return None;
        }
        let chord = chord2.sqrt();
        let u = d / chord;
        // The outline's integrals minus the chord's, taken about the start
        // point, the moment vector rotated onto the chord.
        let [area, mxx, myy] = piece.span_moments(range, p0, p3);
        Some(Frame {
            p0,
            p3,
            u,
            chord,
            th0: (u.cross(t0), u.dot(t0)),
            th1: (t1.cross(u), t1.dot(u)),
            area: area / chord2,
            mx: (u.x * mxx + u.y * myy) / (chord2 * chord),
        })
    }
}

/// Handles longer than this share of the chord make a candidate's error
/// count for more (long handles are where a cubic starts to loop).
const HANDLE_ELBOW: f64 = 0.65;

/// How much more: the error scales by `1 + 2 (d − elbow)` beyond it.
const HANDLE_SLOPE: f64 = 2.0;

/// Most chords a candidate is flattened into (and points it is checked
/// at, with the midpoints between them).
const CURVE_POINTS: usize = 64;

/// Fewest chords a candidate is flattened into.
const MIN_CURVE_POINTS: usize = 16;

/// Longest chord (px, measured on the control polygon, which bounds the
/// arc length from above) a candidate is flattened into, between
/// [`MIN_CURVE_POINTS`] and [`CURVE_POINTS`]: the outline check at points
/// this far apart along a curve that stays nearly parallel to the outline
/// misses less than a hundredth of a pixel between them, and a short span
/// needs far fewer than 64 points (the spans of the 2 Mpx ornament are
/// about 10 px long).
const CURVE_SPACING: f64 = 0.4;

/// The cubic matching `piece`'s area and moment over `range` (shares of its
/// length) that lies within `accuracy` of the outline both ways: each of
/// the outline's [`FIT_SAMPLES`] samples (`samples`, interior ones used)
/// within the piece's reach of the curve, and the curve within `accuracy`
/// of the outline (`Piece::holds`, which also admits the corridor; on an
/// SDF contour, with the handles on the canvas), checked
/// on the best ranked candidate that keeps the samples within reach
/// (ranked by [`rough_error`], long handles penalised as above; the others
/// are not tried in the last check: they are the loops and hooks, and
/// would cost thin-line art accuracy).
pub(super) fn fit_span_direct(
    piece: &Piece,
    range: std::ops::Range<f64>,
    samples: &[(Point, Vec2); FIT_SAMPLES],
    accuracy: f64,
) -> Option<CubicBez> {
    let f = Frame::new(piece, range.clone())?;
    let (p0, p3, u, chord, th0, th1) = (f.p0, f.p3, f.u, f.chord, f.th0, f.th1);
    let reach = piece.reach(accuracy);
    let (cands, k) = handle_lengths(th0, th1, f.area, f.mx);
    let v = Vec2::new(-u.y, u.x);
    let to_world = |x: f64, y: f64| p0 + chord * (x * u + y * v);
    let scale = |d: f64| 1.0 + (d - HANDLE_ELBOW).max(0.0) * HANDLE_SLOPE;
    // The candidates with their handle penalty, ranked by a rough error
    // (a few samples against a coarse flattening, see [`rough_error`]):
    // only the best ranked is flattened and measured in full, the next
    // only if it fails. Measuring every candidate in full and keeping the
    // smallest error picks the same cubic in most fits (most have one
    // candidate that passes), for about as many cubics and much more of
    // the fit's work.
    let mut ranked = [(0.0, f64::INFINITY, CubicBez::new(p0, p0, p0, p0)); 4];
    for (r, &(d0, d1)) in ranked.iter_mut().zip(&cands[..k]) {
        let c = CubicBez::new(
            p0,
            to_world(d0 * th0.1, d0 * th0.0),
            to_world(1.0 - d1 * th1.1, d1 * th1.0),
            p3,
        );
        let scale = scale(d0).max(scale(d1));
        // A lone candidate needs no rank.
        let rough = if k > 1 {
            rough_error(&c, samples) * scale
        } else {
            0.0
        };
        *r = (scale, rough, c);
    }
    let ranked = ranked.get_mut(..k).unwrap_or(&mut []);
    ranked.sort_by(|a, b| a.1.total_cmp(&b.1));
    let mut pts = CurvePoints::empty();
    let c = ranked.iter().find_map(|&(scale, _, c)| {
        pts.set(&c);
        outline_to_curve(&pts, samples, reach / scale).map(|_| c)
    })?;
    let pts = &pts;
    let len = piece.length() * (range.end - range.start);
    let (s0, s1) = (range.start * piece.length(), range.end * piece.length());
    // Every point with the midpoints between them, in order: the
    // distance to the outline can grow by half the spacing between two
    // points that pass, which a curve crossing a corner of the outline or
    // of the corridor uses (a one-handle cubic can stray about half a
    // pixel between points 0.4 px apart). A midpoint within the slack its
    // neighbour left costs no search (`Piece::holds`). In one pass: a
    // coarse pass over every eighth point first (each a search of its
    // own) costs more on the curves that pass, nearly all of those
    // checked here, than it saves on the few that fail.
    let m = pts.m;
    let mut halves = Steps::new(&c, 2 * m);
    let fine = (1..2 * m).map(move |j| {
        let q = halves.next_point();
        if j % 2 == 0 {
            pts.pts.get(j / 2).copied().unwrap_or(c.p3)
        } else {
            q
        }
    });
    // The flattened length bounds the arc length from below, the control
    // polygon from above.
    let polygon = (c.p1 - c.p0).hypot() + (c.p2 - c.p1).hypot() + (c.p3 - c.p2).hypot();
    let short = polygon <= 1.5 * len + 0.5
        || pts.cum[pts.m] <= 1.5 * len + 0.5
            && kurbo::ParamCurveArclen::arclen(&c, 0.01) <= 1.5 * len + 0.5;
    (short && piece.keeps_handles_on_canvas(&c) && piece.holds(fine, s0, s1, accuracy)).then_some(c)
}

/// The points of a cubic at parameters k/m, k = 1, 2, …, by forward
/// differences of its power form (three additions a point instead of an
/// evaluation; they agree with evaluation far below the checks'
/// hundredths of a pixel).
struct Steps {
    p: Vec2,
    d1: Vec2,
    d2: Vec2,
    d3: Vec2,
}

impl Steps {
    /// Stepping `c` from its start in `m` equal steps of the parameter.
    fn new(c: &CubicBez, m: usize) -> Self {
        let (p0, p1, p2, p3) = (
            c.p0.to_vec2(),
            c.p1.to_vec2(),
            c.p2.to_vec2(),
            c.p3.to_vec2(),
        );
        let a = p3 - 3.0 * p2 + 3.0 * p1 - p0;
        let b = 3.0 * (p2 - 2.0 * p1 + p0);
        let d = 3.0 * (p1 - p0);
        let h = 1.0 / m.max(1) as f64;
        let (h2, h3) = (h * h, h * h * h);
        Steps {
            p: p0,
            d1: a * h3 + b * h2 + d * h,
            d2: 6.0 * h3 * a + 2.0 * h2 * b,
            d3: 6.0 * h3 * a,
        }
    }

    /// The next point.
    fn next_point(&mut self) -> Point {
        self.p += self.d1;
        self.d1 += self.d2;
        self.d2 += self.d3;
        self.p.to_point()
    }
}

/// Chords of the coarse flattening [`rough_error`] measures against.
const RANK_CHORDS: usize = 8;

/// Every how many interior samples [`rough_error`] measures.
const RANK_STRIDE: usize = 4;

/// A rough outline-to-curve error of `c` (px), to rank candidates by: the
/// largest distance from every [`RANK_STRIDE`]th interior sample to `c`
/// flattened into [`RANK_CHORDS`] chords, each sample against the chord at
/// its share of the length and the two beside it (a candidate that does
/// not follow the outline in order ranks low, as the full measure's order
/// test would reject it).
fn rough_error(c: &CubicBez, samples: &[(Point, Vec2); FIT_SAMPLES]) -> f64 {
    let mut pts = [c.p0; RANK_CHORDS + 1];
    let mut steps = Steps::new(c, RANK_CHORDS);
    for p in pts.iter_mut().skip(1) {
        *p = steps.next_point();
    }
    pts[RANK_CHORDS] = c.p3;
    let last = FIT_SAMPLES - 1;
    (RANK_STRIDE / 2..last)
        .step_by(RANK_STRIDE)
        .map(|i| {
            let q = samples.get(i).map_or(c.p0, |s| s.0);
            let j = i * RANK_CHORDS / last;
            let lo = j.saturating_sub(1);
            let hi = (j + 1).min(RANK_CHORDS - 1);
            (lo..=hi)
                .filter_map(|j| {
                    let (a, b) = (pts.get(j)?, pts.get(j + 1)?);
                    Some(crate::raster::sdf::point_segment_distance(
                        q,
                        kurbo::Line::new(*a, *b),
                    ))
                })
                .fold(f64::INFINITY, f64::min)
        })
        .fold(0.0, f64::max)
}

/// A cubic flattened at `m` + 1 evenly spaced parameters (`m` chords of
/// at most about [`CURVE_SPACING`] px), with the cumulative length (px)
/// of the chords; entries past `m` are unused.
struct CurvePoints {
    pts: [Point; CURVE_POINTS + 1],
    cum: [f64; CURVE_POINTS + 1],
    m: usize,
}

/// How many chords a curve of (at most) `length` px is checked along:
/// chords of about [`CURVE_SPACING`] px, between [`MIN_CURVE_POINTS`] and
/// [`CURVE_POINTS`] of them (a NaN length casts to 0: the fewest).
pub(super) fn check_chords(length: f64) -> usize {
    ((length / CURVE_SPACING).ceil() as usize).clamp(MIN_CURVE_POINTS, CURVE_POINTS)
}

impl CurvePoints {
    /// No flattening yet (one chord at the origin).
    fn empty() -> Self {
        CurvePoints {
            pts: [Point::ORIGIN; CURVE_POINTS + 1],
            cum: [0.0; CURVE_POINTS + 1],
            m: 1,
        }
    }

    /// Flattens `c` in place.
    fn set(&mut self, c: &CubicBez) {
        let polygon = (c.p1 - c.p0).hypot() + (c.p2 - c.p1).hypot() + (c.p3 - c.p2).hypot();
        let m = check_chords(polygon);
        // The interior points stepped along, the end point exact; each
        // length the one before plus the chord to the new point.
        let mut steps = Steps::new(c, m);
        let (mut prev, mut acc) = (c.p0, 0.0);
        self.pts[0] = prev;
        self.cum[0] = acc;
        let inner = 1..m;
        for (p, s) in self.pts[inner.clone()].iter_mut().zip(&mut self.cum[inner]) {
            let q = steps.next_point();
            acc += (q - prev).hypot();
            (*p, *s, prev) = (q, acc, q);
        }
        self.pts[m] = c.p3;
        self.cum[m] = acc + (c.p3 - prev).hypot();
        self.m = m;
    }

    /// The flattened points, `m` + 1 of them.
    fn points(&self) -> &[Point] {
        self.pts.get(..=self.m).unwrap_or(&[])
    }

    /// Their cumulative lengths (px).
    fn lengths(&self) -> &[f64] {
        self.cum.get(..=self.m).unwrap_or(&[])
    }
}

/// How far (share of the curve's length, beyond twice the distance
/// allowed) a sample may land along the curve from where its share of the
/// outline's length puts it.
const STEP_SLACK: f64 = 0.15;

/// The largest distance (px) from the interior outline samples to the
/// flattened curve, or `None` once one
/// exceeds `limit`. Each sample's first chord within `limit` is searched
/// from the last one found (samples and curve both run from start to end;
/// see [`first_within`]), then followed downhill to a local minimum: an
/// upper bound of the distance, exact where the curve is smooth.
fn outline_to_curve(curve: &CurvePoints, samples: &[(Point, Vec2)], limit: f64) -> Option<f64> {
    let (pts, cum) = (curve.points(), curve.lengths());
    let m = curve.m;
    let dist = |q: Point, j: usize| {
        crate::raster::sdf::point_segment_distance(q, kurbo::Line::new(pts[j], pts[j + 1]))
    };
    let last = m - 1;
    let mut cursor = 0usize;
    let mut worst: f64 = 0.0;
    let interior = samples
        .get(1..samples.len().saturating_sub(1))
        .unwrap_or(&[]);
    let total = cum[m];
    let slack = 2.0 * limit + STEP_SLACK * total;
    for (i, &(q, _)) in interior.iter().enumerate() {
        let (mut j, mut best) = first_within(pts, cum, q, 0, cursor, last, limit)?;
        // Downhill to the nearest chord around it: the closer neighbour
        // (ahead on a tie) while it is closer, and on in that direction
        // only (the chord just left is farther than the new one).
        let fwd = if j < last {
            dist(q, j + 1)
        } else {
            f64::INFINITY
        };
        let back = if j > 0 { dist(q, j - 1) } else { f64::INFINITY };
        if fwd < best && fwd <= back {
            best = fwd;
            j += 1;
            while j < last {
                let d = dist(q, j + 1);
                if d >= best {
                    break;
                }
                best = d;
                j += 1;
            }
        } else if back < best {
            best = back;
            j -= 1;
            while j > 0 {
                let d = dist(q, j - 1);
                if d >= best {
                    break;
                }
                best = d;
                j -= 1;
            }
        }
        // Where along the curve the sample landed, against where it would
        // at the same share of the curve's length: a curve that doubles
        // back can lie close to the outline both ways and still not follow
        // it in order (a discrete Fréchet test).
        let seg = pts[j + 1] - pts[j];
        let along =
            cum[j] + (q - pts[j]).dot(seg).clamp(0.0, seg.hypot2()) / seg.hypot().max(1e-12);
        let share = (i + 1) as f64 / (interior.len() + 1) as f64;
        if (along - share * total).abs() > slack {
            return None;
        }
        cursor = j;
        worst = worst.max(best);
    }
    Some(worst)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::trace::piece::Guide;
    use kurbo::ParamCurve;

    /// A piece along `f(t)`, t in 0..1, at `n` + 1 points, with the exact
    /// tangents `df`.
    fn analytic(n: usize, f: impl Fn(f64) -> Point, df: impl Fn(f64) -> Vec2) -> Piece<'static> {
        let ts = (0..=n).map(|i| i as f64 / n as f64);
        Piece::new(
            ts.clone().map(&f).collect(),
            ts.map(|t| df(t).normalize()).collect(),
            Guide::Outline(None),
            false,
            false,
        )
    }

    /// Handle lengths (chord lengths) of a cubic.
    fn handles(c: &CubicBez) -> (f64, f64) {
        let chord = (c.p3 - c.p0).hypot();
        ((c.p1 - c.p0).hypot() / chord, (c.p3 - c.p2).hypot() / chord)
    }

    /// kurbo's fitter, given the same source, finds one of our candidates.
    fn agrees_with_kurbo(piece: &Piece, range: std::ops::Range<f64>) {
        let (kc, _) = kurbo::fit_to_cubic(piece, range.clone(), 1.0).expect("kurbo fits");
        let (k0, k1) = handles(&kc);
        let f = Frame::new(piece, range.clone()).expect("a chord");
        let (cands, n) = handle_lengths(f.th0, f.th1, f.area, f.mx);
        assert!(
            cands[..n]
                .iter()
                .any(|&(d0, d1)| (d0 - k0).abs() < 1e-6 && (d1 - k1).abs() < 1e-6),
            "{range:?}: kurbo ({k0}, {k1}), ours {:?}",
            &cands[..n]
        );
    }

    /// The flattening by forward differences lands on the curve's own
    /// points at every parameter k/m, for short and long cubics far from
    /// the origin (the accumulated rounding stays far below the checks'
    /// hundredths of a pixel).
    #[test]
    fn flattening_matches_evaluation() {
        let cubics = [
            CubicBez::new((1.0, 2.0), (3.0, 7.0), (6.0, -1.0), (9.0, 2.5)),
            CubicBez::new(
                (1500.0, 900.0),
                (1540.0, 860.0),
                (1495.0, 830.0),
                (1510.0, 880.0),
            ),
            CubicBez::new((0.0, 0.0), (0.0, 0.0), (40.0, 0.0), (40.0, 0.0)),
        ];
        for c in cubics {
            for m in [8, 33, 128] {
                let mut steps = Steps::new(&c, m);
                for k in 1..=m {
                    let (p, q) = (steps.next_point(), c.eval(k as f64 / m as f64));
                    assert!(
                        (p - q).hypot() < 1e-9,
                        "{m} steps, {k}: {p:?} against {q:?}"
                    );
                }
            }
            let mut f = CurvePoints::empty();
            f.set(&c);
            assert!(f.m >= MIN_CURVE_POINTS && f.m <= CURVE_POINTS);
            let mut len = 0.0;
            for (k, p) in f.points().iter().enumerate() {
                let q = c.eval(k as f64 / f.m as f64);
                assert!((*p - q).hypot() < 1e-9, "{k}: {p:?} against {q:?}");
                if k > 0 {
                    len += (q - c.eval((k - 1) as f64 / f.m as f64)).hypot();
                }
                assert!((f.lengths()[k] - len).abs() < 1e-9);
            }
        }
    }

    #[test]
    fn circular_arcs_match_kurbo() {
        for (r, sweep) in [(40.0, 1.0), (10.0, 2.0), (200.0, 0.3), (25.0, 2.8)] {
            let piece = analytic(
                400,
                |t| Point::new(300.0 + r * (sweep * t).cos(), 200.0 + r * (sweep * t).sin()),
                |t| Vec2::new(-(sweep * t).sin(), (sweep * t).cos()),
            );
            agrees_with_kurbo(&piece, 0.0..1.0);
            agrees_with_kurbo(&piece, 0.2..0.7);
        }
    }

    #[test]
    fn sine_polyline_matches_kurbo() {
        // Asymmetric end tangents, an inflection-free stretch and one
        // with an inflection (the quartic's other roots).
        let piece = analytic(
            300,
            |t| Point::new(10.0 + 60.0 * t, 50.0 + 12.0 * (3.0 * t).sin()),
            |t| Vec2::new(60.0, 36.0 * (3.0 * t).cos()),
        );
        for range in [0.0..0.5, 0.1..0.45, 0.3..0.9, 0.0..1.0] {
            agrees_with_kurbo(&piece, range);
        }
    }

    #[test]
    fn a_circular_arc_is_fitted_within_the_accuracy() {
        // A quarter circle of radius 50 px: one cubic is within 0.014 px.
        let piece = analytic(
            500,
            |t| {
                Point::new(
                    100.0 + 50.0 * (1.5 * t).cos(),
                    100.0 + 50.0 * (1.5 * t).sin(),
                )
            },
            |t| Vec2::new(-(1.5 * t).sin(), (1.5 * t).cos()),
        );
        let samples = piece.samples(0.0..1.0);
        let c = fit_span_direct(&piece, 0.0..1.0, &samples, 0.1).expect("fits");
        for k in 0..=100 {
            let p = c.eval(k as f64 / 100.0);
            assert!(((p - Point::new(100.0, 100.0)).hypot() - 50.0).abs() < 0.03);
        }
        // A wavy source is not one cubic.
        let wavy = analytic(
            600,
            |t| Point::new(10.0 + 100.0 * t, 50.0 + 8.0 * (9.0 * t).sin()),
            |t| Vec2::new(100.0, 72.0 * (9.0 * t).cos()),
        );
        let samples = wavy.samples(0.0..1.0);
        assert!(fit_span_direct(&wavy, 0.0..1.0, &samples, 0.25).is_none());
    }
}
