//! Contours to cubic Béziers with kurbo's curve fitter.
//!
//! A contour (the marching-squares polygon of an SDF's zero level set) is
//! cut at its corners and each piece is presented to kurbo as a
//! `kurbo::ParamCurveFit` source: positions along the polygon by arc length, and
//! tangents perpendicular to the SDF gradient, which is smooth where the
//! outline is, so pieces join with G1 continuity. `fit_to_bezpath_opt`
//! then finds the fewest cubics within the tolerance. An outline known
//! exactly (a bitmap's smoothed or sub-pixel outline) is a `Piece` too,
//! covered by [`super::cover`] with its own tangents and corners, exact
//! moment integrals, and fitted by `super::direct` (no kurbo), each curve
//! checked against the outline itself (and a binary bitmap's corridor)
//! instead of an SDF. The span search both share is `super::span`; how a
//! piece is sampled and integrated is `super::sample`. Corners are the
//! vertices where the outline turns sharply within a pixel-scale window;
//! the curves meet there at an angle, so sharp corners stay sharp.

use super::corner::corners;
use super::nearest::{gallop_back_le, gallop_le as gallop, nearest_segment};
use super::sample::segment_moments;
use super::span::{append_loop, line_cubic, longest_span};
use crate::raster::corridor::Corridor;
use crate::raster::Sdf;
use kurbo::{BezPath, CubicBez, Point, Vec2};
use std::cell::Cell;

/// What a piece is fitted to: where its tangents come from and what the
/// fitted curves are checked against.
#[derive(Clone, Copy)]
pub(super) enum Guide<'a> {
    /// A marching-squares contour of this SDF's zero level set: tangents
    /// perpendicular to the gradient, curves checked by |SDF|.
    Field(&'a Sdf),
    /// An exact smooth outline (a binary bitmap's, see
    /// [`crate::raster::binary`]): tangents given per vertex, curves checked
    /// by their distance to the piece's own polyline, and, for a binary
    /// bitmap's outline, by the bitmap's [`Corridor`]: then a curve may
    /// stray up to [`Corridor::HALF_WIDTH`] further from the smooth outline
    /// as long as it stays within the accuracy of the corridor.
    Outline(Option<&'a Corridor<'a>>),
}

/// How far `p` (px) lies inside the canvas of `sdf`'s grid, negated: the
/// signed distance of the canvas rectangle `[0, w] × [0, h]`, negative
/// inside.
pub(super) fn canvas_value(sdf: &Sdf, p: Point) -> f64 {
    let (w, h) = (sdf.width() as f64, sdf.height() as f64);
    -(p.x.min(p.y).min(w - p.x).min(h - p.y))
}

/// The SDF of the ink clipped to the canvas, `max(Φ, canvas)`: marching
/// squares close ink that runs off the canvas along its border (the grid is
/// padded with outside samples), so that is the level set the contour
/// follows there, and a curve along the border fits it exactly.
fn clipped_value(sdf: &Sdf, p: Point) -> f64 {
    sdf.value(p).max(canvas_value(sdf, p))
}

/// One piece of a closed contour between corners (or the whole contour),
/// parameterized by normalized arc length.
pub(super) struct Piece<'a> {
    pub(super) pts: Vec<Point>,
    /// Unit tangent at each vertex ([`Guide::Outline`] only, else empty).
    pub(super) tangents: Vec<Vec2>,
    /// Cumulative arc length at each vertex.
    pub(super) cum: Vec<f64>,
    pub(super) guide: Guide<'a>,
    pub(super) corner_start: bool,
    pub(super) corner_end: bool,
    /// The fitter sees coordinates relative to this point: kurbo's moment
    /// integrals lose precision far from the origin.
    pub(super) origin: Vec2,
    /// Prefix sums of the exact area and moment integrals of the polyline's
    /// segments (relative to `origin`), for [`Guide::Outline`]; empty for
    /// SDF contours, which keep kurbo's quadrature.
    pub(super) moments: Vec<[f64; 3]>,
    /// The segment [`Self::locate`] found last: the fitter samples a span
    /// in ascending arc length, so the next one is usually this or the one
    /// after (a hint only, the answer does not depend on it).
    hint: Cell<usize>,
}

impl<'a> Piece<'a> {
    pub(super) fn new(
        pts: Vec<Point>,
        tangents: Vec<Vec2>,
        guide: Guide<'a>,
        corner_start: bool,
        corner_end: bool,
    ) -> Self {
        let mut cum = Vec::with_capacity(pts.len());
        let mut s = 0.0;
        cum.push(0.0);
        for w in pts.windows(2) {
            s += (w[1] - w[0]).hypot();
            cum.push(s);
        }
        let origin = pts.first().map(|p| p.to_vec2()).unwrap_or_default();
        let moments = match guide {
            Guide::Outline(_) => {
                let mut acc = [0.0; 3];
                let mut m = Vec::with_capacity(pts.len());
                m.push(acc);
                for w in pts.windows(2) {
                    let s = segment_moments(w[0] - origin, w[1] - origin);
                    for k in 0..3 {
                        acc[k] += s[k];
                    }
                    m.push(acc);
                }
                m
            }
            Guide::Field(_) => Vec::new(),
        };
        Piece {
            pts,
            tangents,
            cum,
            guide,
            corner_start,
            corner_end,
            origin,
            moments,
            hint: Cell::new(0),
        }
    }

    /// How far (px) from the piece's own polyline a curve within
    /// `accuracy` of what it is fitted to may lie: `accuracy`, plus the
    /// corridor's half-width when a corridor decides.
    pub(super) fn reach(&self, accuracy: f64) -> f64 {
        match self.guide {
            Guide::Outline(Some(_)) => accuracy + Corridor::HALF_WIDTH,
            _ => accuracy,
        }
    }

    /// Number of vertices.
    pub(super) fn len(&self) -> usize {
        self.pts.len()
    }

    /// Arc length (px) from the first vertex to vertex `i`.
    pub(super) fn arc_at(&self, i: usize) -> f64 {
        self.cum[i]
    }

    /// Vertex `i`.
    pub(super) fn point(&self, i: usize) -> Point {
        self.pts[i]
    }

    pub(super) fn length(&self) -> f64 {
        *self.cum.last().unwrap_or(&0.0)
    }

    /// The vertices `range` (inclusive) as a piece of their own.
    fn sub(&self, first: usize, last: usize, corner_start: bool, corner_end: bool) -> Piece<'a> {
        let tangents = if self.tangents.is_empty() {
            Vec::new()
        } else {
            self.tangents[first..=last].to_vec()
        };
        Piece::new(
            self.pts[first..=last].to_vec(),
            tangents,
            self.guide,
            corner_start,
            corner_end,
        )
    }

    /// The given tangents interpolated along segment `i` at arc length `s`.
    pub(super) fn given_tangent(&self, i: usize, s: f64) -> Option<Vec2> {
        let t0 = *self.tangents.get(i)?;
        let t1 = *self.tangents.get(i + 1)?;
        let seg = self.cum[i + 1] - self.cum[i];
        let f = if seg > 0.0 {
            ((s - self.cum[i]) / seg).clamp(0.0, 1.0)
        } else {
            0.0
        };
        let t = t0.lerp(t1, f);
        let l = t.hypot();
        (l > 1e-9).then(|| t / l)
    }

    /// For an SDF contour, whether the control points of `c` stay within a
    /// pixel of the canvas: ink running off the canvas is closed along its
    /// border (see [`clipped_value`]), where the contour is a straight run
    /// and kurbo may put a handle many pixels past the canvas's edge with
    /// the curve itself still on it.
    pub(super) fn keeps_handles_on_canvas(&self, c: &CubicBez) -> bool {
        let Guide::Field(sdf) = self.guide else {
            return true;
        };
        let (w, h) = (sdf.width() as f64, sdf.height() as f64);
        [c.p1, c.p2]
            .iter()
            .all(|p| p.x >= -1.0 && p.y >= -1.0 && p.x <= w + 1.0 && p.y <= h + 1.0)
    }

    /// Whether every point of `pts` lies within `limit` px of what the piece
    /// is fitted to, over arc lengths `s0..s1`: the SDF's zero level set, or
    /// the piece's own outline there (and a pixel either side).
    pub(super) fn holds(
        &self,
        pts: impl Iterator<Item = Point>,
        s0: f64,
        s1: f64,
        limit: f64,
    ) -> bool {
        match self.guide {
            Guide::Field(sdf) => {
                let limit = limit + CHECK_SLACK;
                let mut pts = pts;
                pts.all(|p| clipped_value(sdf, p).abs() <= limit)
            }
            Guide::Outline(corridor) => {
                let lo = self.locate(s0 - 1.0).0;
                let hi = self.locate(s1 + 1.0).0;
                // Within `limit` of the outline; or, with a corridor, within
                // `limit` of it and its half-width further from the outline
                // (where the outline itself leaves the corridor, the first
                // test still holds the curve to it).
                let near = limit + OUTLINE_SLACK;
                let far = if corridor.is_some() {
                    self.reach(limit) + OUTLINE_SLACK
                } else {
                    near
                };
                let mut cursor = lo;
                // The last point found within `near` of segment `cursor`
                // and how much further a point may be from it and still be
                // (the triangle inequality): consecutive points of a curve
                // mostly are, and need no search.
                let mut anchor: Option<(Point, f64)> = None;
                let mut pts = pts;
                pts.all(|p| {
                    if let Some((q, slack)) = anchor {
                        let step = (p - q).hypot();
                        if step <= slack {
                            anchor = Some((p, slack - step));
                            return true;
                        }
                    }
                    anchor = None;
                    // The cursor's own segment outright, as the search
                    // below would measure it first (most points lie
                    // within `near` of it), without the search's setup.
                    if cursor <= hi && cursor + 1 < self.pts.len() {
                        let seg = kurbo::Line::new(self.pts[cursor], self.pts[cursor + 1]);
                        let d = crate::raster::sdf::point_segment_distance(p, seg);
                        if d <= near {
                            anchor = Some((p, near - d));
                            return true;
                        }
                    }
                    // Ahead of the cursor first (where the curve goes on);
                    // a point within `far` there that the corridor admits
                    // passes without the search behind it.
                    let (found, mut best) =
                        nearest_segment(&self.pts, &self.cum, p, cursor, hi, near, far);
                    let mut admitted = None;
                    let found = match found {
                        None if cursor > lo => {
                            if best <= far {
                                let ok = corridor.is_some_and(|c| c.reaches(p, limit));
                                if ok {
                                    return true;
                                }
                                admitted = Some(ok);
                            }
                            let (j, d) =
                                nearest_segment(&self.pts, &self.cum, p, lo, cursor - 1, near, far);
                            best = best.min(d);
                            j
                        }
                        found => found,
                    };
                    if let Some(j) = found {
                        cursor = j;
                        anchor = Some((p, near - best));
                    }
                    best <= near
                        || best <= far
                            && admitted
                                .unwrap_or_else(|| corridor.is_some_and(|c| c.reaches(p, limit)))
                })
            }
        }
    }

    /// Segment index and position at arc length `s` (clamped to the
    /// piece): the segment `i` with `cum[i] ≤ s < cum[i + 1]` (the last one
    /// at the end), tried first at the last one found, then by galloping
    /// forwards or backwards from it.
    pub(super) fn locate(&self, s: f64) -> (usize, Point) {
        let n = self.pts.len();
        let s = s.clamp(0.0, self.length());
        let within = |i: usize| self.cum[i] <= s && (s < self.cum[i + 1] || i + 2 == n);
        let h = self.hint.get().min(n - 2);
        let i = if within(h) {
            h
        } else if self.cum[h] <= s {
            // Ahead of the hint: gallop forwards (samples step along).
            let ahead = self.cum.get(h + 1..).unwrap_or(&[]);
            (h + gallop(ahead, s)).min(n - 2)
        } else {
            // Behind it: gallop backwards (the next span starts where the
            // last one did).
            let behind = self.cum.get(..h).unwrap_or(&[]);
            gallop_back_le(behind, s).saturating_sub(1).min(n - 2)
        };
        self.hint.set(i);
        (i, self.point_on(i, s))
    }

    /// The point at arc length `s` (within the piece) on segment `i`.
    fn point_on(&self, i: usize, s: f64) -> Point {
        let seg = self.cum[i + 1] - self.cum[i];
        let t = if seg > 0.0 {
            (s - self.cum[i]) / seg
        } else {
            0.0
        };
        self.pts[i].lerp(self.pts[i + 1], t)
    }

    /// [`Self::locate`] for arc lengths visited in ascending order: from
    /// the segment `i` found for an earlier one, a step at a time.
    pub(super) fn locate_after(&self, i: usize, s: f64) -> (usize, Point) {
        let n = self.pts.len();
        let s = s.clamp(0.0, self.length());
        let mut i = i.min(n - 2);
        while i + 2 < n && self.cum[i + 1] <= s {
            i += 1;
        }
        (i, self.point_on(i, s))
    }

    pub(super) fn seg_dir(&self, i: usize) -> Vec2 {
        let d = self.pts[i + 1] - self.pts[i];
        let l = d.hypot();
        if l > 0.0 {
            d / l
        } else {
            Vec2::new(1.0, 0.0)
        }
    }

    /// Chord direction over about a pixel from arc length `s` towards the
    /// interior of the piece (`forward` from the start, else backwards).
    pub(super) fn chord_dir(&self, s: f64, forward: bool) -> Vec2 {
        let len = self.length();
        let reach = 1.0f64.min(len);
        let (a, b) = if forward {
            (self.locate(s).1, self.locate(s + reach).1)
        } else {
            (self.locate(s - reach).1, self.locate(s).1)
        };
        let d = b - a;
        let l = d.hypot();
        if l > 1e-9 {
            d / l
        } else {
            self.seg_dir(0)
        }
    }
}

/// Fits a closed contour (pixel coordinates) of `sdf`'s zero level set with
/// cubic Béziers within `accuracy` px, appending a closed subpath to `out`.
/// Corners are found by [`corners`].
pub fn fit_contour(pts: &[Point], sdf: &Sdf, accuracy: f64, out: &mut BezPath) {
    if pts.len() < 3 {
        return;
    }
    fit_loop(pts, &corners(pts), sdf, accuracy, out);
}

/// The vertex indices of each run of a closed loop of `n` vertices between
/// consecutive corners `cs` (both corners included; the last run wraps
/// around to the first corner).
pub(super) fn corner_runs(cs: &[usize], n: usize) -> Vec<Vec<usize>> {
    (0..cs.len())
        .map(|k| {
            let (a, b) = (cs[k], cs[(k + 1) % cs.len()]);
            let mut idx = vec![a];
            let mut i = (a + 1) % n;
            loop {
                idx.push(i);
                if i == b {
                    break;
                }
                i = (i + 1) % n;
            }
            idx
        })
        .collect()
}

/// The closed contour `pts` of `sdf` cut at `cs` into pieces, each fitted.
fn fit_loop(pts: &[Point], cs: &[usize], sdf: &Sdf, accuracy: f64, out: &mut BezPath) {
    let n = pts.len();
    let guide = Guide::Field(sdf);
    let mut pieces: Vec<Piece> = Vec::new();
    if cs.is_empty() {
        // A smooth loop is fitted as two open halves (kurbo's fitter needs
        // distinct end points); the tangents at the joins come from the
        // guide, so the halves meet with G1 continuity.
        let h = n / 2;
        let first: Vec<usize> = (0..=h).collect();
        let second: Vec<usize> = (h..n).chain([0]).collect();
        for idx in [first, second] {
            let p = idx.iter().map(|&i| pts[i]).collect();
            pieces.push(Piece::new(p, Vec::new(), guide, false, false));
        }
    } else {
        for idx in corner_runs(cs, n) {
            let p = idx.iter().map(|&i| pts[i]).collect();
            pieces.push(Piece::new(p, Vec::new(), guide, true, true));
        }
    }
    let mut cubics = Vec::new();
    for piece in pieces.iter().flat_map(split_by_turning) {
        if piece.length() > 1e-9 {
            fit_piece(&piece, accuracy, &mut cubics);
        }
    }
    append_loop(&cubics, out);
}

/// Largest turning (radians) of one piece handed to the fitter: a quarter
/// turn, which one cubic can follow closely. Longer turns make kurbo's
/// optimizer fall back to slow arc-length error measures.
const MAX_PIECE_TURN: f64 = std::f64::consts::FRAC_PI_2;

/// Splits a piece where its accumulated turning exceeds [`MAX_PIECE_TURN`];
/// the cuts keep SDF tangents on both sides, so they are G1 joins.
fn split_by_turning<'a>(piece: &Piece<'a>) -> Vec<Piece<'a>> {
    let n = piece.pts.len();
    if n < 4 {
        return vec![piece.sub(0, n - 1, piece.corner_start, piece.corner_end)];
    }
    // Turning is accumulated between chords of about 3 px, which follow the
    // outline's shape and not the sub-pixel wobble of its vertices.
    const STEP: f64 = 3.0;
    let mut acc = vec![0.0; n];
    let mut anchor = 0usize;
    let mut prev_dir: Option<f64> = None;
    let mut total = 0.0;
    #[allow(clippy::needless_range_loop)] // i indexes cum, pts and acc alike
    for i in 1..n {
        if piece.cum[i] - piece.cum[anchor] >= STEP || i == n - 1 {
            let d = (piece.pts[i] - piece.pts[anchor]).atan2();
            if let Some(p) = prev_dir {
                let mut t = d - p;
                while t > std::f64::consts::PI {
                    t -= std::f64::consts::TAU;
                }
                while t < -std::f64::consts::PI {
                    t += std::f64::consts::TAU;
                }
                total += t.abs();
            }
            prev_dir = Some(d);
            anchor = i;
        }
        acc[i] = total;
    }
    // Equal shares of turning, each at most a quarter turn.
    let parts = (acc[n - 1] / MAX_PIECE_TURN).ceil().max(1.0) as usize;
    let mut cuts = vec![0usize];
    for k in 1..parts {
        let target = acc[n - 1] * k as f64 / parts as f64;
        let i = acc.partition_point(|&a| a < target).clamp(1, n - 2);
        if i > cuts[cuts.len() - 1] + 1 && i + 1 < n - 1 {
            cuts.push(i);
        }
    }
    cuts.push(n - 1);
    cuts.windows(2)
        .map(|w| {
            piece.sub(
                w[0],
                w[1],
                w[0] == 0 && piece.corner_start,
                w[1] == n - 1 && piece.corner_end,
            )
        })
        .collect()
}

/// Extra distance (px) allowed between a fitted curve and the level set
/// beyond the fitting accuracy, for the bilinear interpolation of the SDF.
pub const CHECK_SLACK: f64 = 0.04;

/// Extra distance (px) allowed between a fitted curve and an exact outline
/// beyond the fitting accuracy: the outline's own flattening.
const OUTLINE_SLACK: f64 = 0.02;

/// Fits one piece with as few cubics as a greedy cover finds: from the
/// start of what is left, the longest span that one cubic fits (kurbo's
/// single-cubic fitter, `fit_to_cubic`, which matches area and moment to the
/// source and measures the error along normals; every cubic also checked
/// against the SDF itself) is found by halving until a fit succeeds and then
/// bisecting between that success and the failure above it. Extending each
/// span as far as it goes is what an optimal cover does when fitting is
/// monotone in the span, and it needs no merging pass afterwards. Spans
/// shorter than [`MIN_SPAN_PX`](super::span::MIN_SPAN_PX) that still do not fit fall back to the
/// polygon, which lies on the level set.
fn fit_piece(piece: &Piece, accuracy: f64, out: &mut Vec<CubicBez>) {
    let n = piece.pts.len();
    let a = piece.pts[0];
    let b = piece.pts[n - 1];
    let chord = kurbo::Line::new(a, b);
    if a != b
        && piece
            .pts
            .iter()
            .all(|&p| crate::raster::sdf::point_segment_distance(p, chord) <= accuracy)
    {
        out.push(line_cubic(a, b));
        return;
    }
    let mut start = 0.0;
    while start < 1.0 {
        // Down to an eighth of the span found (or half a pixel): a longer
        // search buys little length and costs a fit per step.
        start = longest_span(piece, start, 1.0, 0.125, accuracy, out);
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::raster::Grid;
    use crate::trace::contour;
    use kurbo::{Affine, ParamCurve};

    pub(crate) fn disc_sdf(size: usize, cx: f64, cy: f64, r: f64) -> Sdf {
        Sdf {
            dist: Grid::from_fn(size, size, |x, y| {
                ((x as f64 + 0.5 - cx).hypot(y as f64 + 0.5 - cy) - r) as f32
            }),
            to_user: Affine::IDENTITY,
        }
    }

    proptest::proptest! {
        /// Stepping on from an earlier arc length's segment finds what a
        /// search from scratch does (zero-length segments included).
        #[test]
        fn locate_after_agrees_with_locate(
            gaps in proptest::collection::vec(proptest::sample::select(vec![0.0, 0.3, 1.0, 2.5]), 1..30),
            a in 0.0f64..1.1,
            b in 0.0f64..1.1,
        ) {
            let mut pts = vec![Point::new(3.0, 4.0)];
            for (k, g) in gaps.iter().enumerate() {
                let last = pts[pts.len() - 1];
                pts.push(last + Vec2::new(*g, 0.1 * (k % 3) as f64 * g));
            }
            let piece = Piece::new(pts, Vec::new(), Guide::Outline(None), false, false);
            let len = piece.length();
            let (s1, s2) = (a.min(b) * len, a.max(b) * len);
            let (j, _) = piece.locate(s1);
            proptest::prop_assert_eq!(piece.locate_after(j, s2), piece.locate(s2));
        }
    }

    #[test]
    fn large_disc_needs_few_cubics() {
        let sdf = disc_sdf(660, 330.0, 330.0, 307.0);
        let cs = contour::extract(&sdf.dist);
        assert_eq!(cs.len(), 1);
        let mut path = BezPath::new();
        fit_contour(&cs[0].points, &sdf, 0.25, &mut path);
        let n = crate::svg_out::count_segments(&path);
        assert!(n <= 8, "{n} segments");
    }

    #[test]
    fn ink_running_off_the_canvas_is_closed_by_a_few_lines_on_the_border() {
        // A disc centred on the canvas's top-left corner and one covering
        // the whole canvas: the contour runs along the border, where the
        // SDF is far from zero, and each border stretch must still be one
        // segment (it was one per marching-squares edge: 800 for the
        // full canvas).
        for (cx, cy, r, most) in [(0.0, 0.0, 60.0, 8), (50.0, 50.0, 500.0, 12)] {
            let sdf = disc_sdf(100, cx, cy, r);
            let cs = contour::extract(&sdf.dist);
            assert_eq!(cs.len(), 1);
            let mut path = BezPath::new();
            fit_contour(&cs[0].points, &sdf, 0.25, &mut path);
            let n = crate::svg_out::count_segments(&path);
            assert!(n <= most, "disc at ({cx}, {cy}) r {r}: {n} segments");
            // And the curves follow the clipped level set.
            for seg in path.segments() {
                for k in 0..=20 {
                    let p = seg.eval(k as f64 / 20.0);
                    let v = clipped_value(&sdf, p);
                    assert!(v.abs() <= 0.25 + CHECK_SLACK + 0.05, "{p:?}: {v}");
                }
            }
        }
    }
}
