//! The fitting source: one piece of a closed outline between corners (or
//! the whole outline), what it is fitted to ([`Guide`]: an SDF's level set
//! or an exact outline), and how a curve fitter reads it: points and
//! tangents by normalized arc length (kurbo's [`ParamCurveFit`], and the
//! [`FIT_SAMPLES`] samples of a span that both fitters judge a range by),
//! the area and moment integrals a cubic is matched to (exact prefix sums
//! over an outline's segments; kurbo's quadrature for SDF contours), and
//! the check a fitted curve must pass ([`Piece::holds`]).

use super::nearest::{gallop_back_le, gallop_le as gallop, nearest_segment};
use crate::outline::corridor::Corridor;
use crate::raster::Sdf;
use kurbo::{CubicBez, CurveFitSample, ParamCurveFit, Point, Vec2};
use std::cell::Cell;
use std::ops::Range;

/// Number of samples (ends included) a range is checked at: kurbo's error
/// measure samples 20 interior points, so does [`super::direct`].
pub(super) const FIT_SAMPLES: usize = 22;

/// Extra distance (px) allowed between a fitted curve and the level set
/// beyond the fitting accuracy, for the bilinear interpolation of the SDF.
pub const CHECK_SLACK: f64 = 0.04;

/// Extra distance (px) allowed between a fitted curve and an exact outline
/// beyond the fitting accuracy: the outline's own flattening.
const OUTLINE_SLACK: f64 = 0.02;

/// What a piece is fitted to: where its tangents come from and what the
/// fitted curves are checked against.
#[derive(Clone, Copy)]
pub(super) enum Guide<'a> {
    /// A marching-squares contour of this SDF's zero level set: tangents
    /// perpendicular to the gradient, curves checked by |SDF|.
    Field(&'a Sdf),
    /// An exact smooth outline (a binary bitmap's, see
    /// [`crate::outline::smooth`]): tangents given per vertex, curves checked
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
pub(super) fn clipped_value(sdf: &Sdf, p: Point) -> f64 {
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
        let cum = crate::raster::contour::open_arc_lengths(&pts);
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
    pub(super) fn sub(
        &self,
        first: usize,
        last: usize,
        corner_start: bool,
        corner_end: bool,
    ) -> Piece<'a> {
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
    /// and a fit may put a handle many pixels past the canvas's edge with
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

/// Distance (px) from a corner within which tangents come from the polygon
/// instead of the SDF gradient.
const CORNER_REACH: f64 = 1.5;

/// The gradient of `super::fit`'s `clipped_value` (the SDF clipped to the
/// canvas): the border's outward normal where
/// the canvas term is the larger.
fn clipped_gradient(sdf: &Sdf, p: Point) -> Vec2 {
    let (w, h) = (sdf.width() as f64, sdf.height() as f64);
    let c = canvas_value(sdf, p);
    if c < sdf.value(p) {
        return sdf.gradient(p);
    }
    let (ex, ey) = (Vec2::new(1.0, 0.0), Vec2::new(0.0, 1.0));
    let d = [(p.x, -ex), (p.y, -ey), (w - p.x, ex), (h - p.y, ey)];
    d.iter()
        .min_by(|a, b| a.0.total_cmp(&b.0))
        .map_or(Vec2::ZERO, |&(_, n)| n)
}

impl ParamCurveFit for Piece<'_> {
    fn sample_pt_tangent(&self, t: f64, sign: f64) -> CurveFitSample {
        let located = self.locate(t * self.length());
        self.sample_at(t, sign, located)
    }

    fn sample_pt_deriv(&self, t: f64) -> (Point, Vec2) {
        let s = t * self.length();
        let (i, p) = self.locate(s);
        (p - self.origin, self.seg_dir(i) * self.length())
    }

    fn moment_integrals(&self, range: Range<f64>) -> (f64, f64, f64) {
        if self.moments.len() != self.pts.len() {
            return self.quadrature_moments(range);
        }
        // Exact: the integrals of y dx, x y dx and y² dx over the polyline,
        // partial segments at both ends and prefix sums between.
        let len = self.length();
        let (i0, p0) = self.locate(range.start * len);
        let (i1, p1) = self.locate(range.end * len);
        let o = self.origin;
        let m = if i0 == i1 {
            segment_moments(p0 - o, p1 - o)
        } else {
            let a = segment_moments(p0 - o, self.pts[i0 + 1] - o);
            let b = segment_moments(self.pts[i1] - o, p1 - o);
            let (lo, hi) = (self.moments[i0 + 1], self.moments[i1]);
            [0, 1, 2].map(|k| a[k] + (hi[k] - lo[k]) + b[k])
        };
        (m[0], m[1], m[2])
    }

    fn break_cusp(&self, _range: Range<f64>) -> Option<f64> {
        // Corners were cut before fitting.
        None
    }
}

impl Piece<'_> {
    /// The sample at `t` (a share of the length; `sign` picks the side at
    /// a corner) on the located segment and point `(i, p)`.
    pub(super) fn sample_at(&self, t: f64, sign: f64, (i, p): (usize, Point)) -> CurveFitSample {
        let s = t * self.length();
        let travel = || self.seg_dir(i);
        let at_start = t <= 0.0;
        let at_end = t >= 1.0;
        let len = self.length();
        let near_start = self.corner_start && s < CORNER_REACH;
        let near_end = self.corner_end && len - s < CORNER_REACH;
        let given = match self.guide {
            Guide::Outline(_) => self.given_tangent(i, s),
            Guide::Field(_) => None,
        };
        let tangent = if (at_start && self.corner_start) || (at_end && self.corner_end) {
            // At a corner the gradient is undefined: use the side's chord.
            self.chord_dir(s, at_start || sign > 0.0 && !at_end)
        } else if let Some(t) = given {
            t
        } else if near_start || near_end {
            // Near a convex corner the distance field rounds off (its
            // gradient points at the corner), so the polygon's own
            // direction is the better tangent there.
            self.chord_dir(s, near_start)
        } else if let Guide::Field(sdf) = self.guide {
            let g = clipped_gradient(sdf, p);
            let perp = Vec2::new(-g.y, g.x);
            let l = perp.hypot();
            if l > 1e-6 {
                let d = perp / l;
                if d.dot(travel()) < 0.0 {
                    -d
                } else {
                    d
                }
            } else {
                travel()
            }
        } else {
            travel()
        };
        CurveFitSample {
            p: p - self.origin,
            tangent,
        }
    }

    /// Position (px) and unit tangent at `t` (a share of the length) for
    /// each of [`FIT_SAMPLES`] points evenly spread over `range`, where
    /// kurbo's fitter samples them.
    #[cfg(test)]
    pub(super) fn samples(&self, range: Range<f64>) -> [(Point, Vec2); FIT_SAMPLES] {
        let all = self.samples_while(range, |_, _| true);
        all.unwrap_or([(Point::ORIGIN, Vec2::ZERO); FIT_SAMPLES])
    }

    /// Position (px) and unit tangent at `t` (a share of the length) for
    /// each of [`FIT_SAMPLES`] points evenly spread over `range`, where
    /// kurbo's fitter samples them, taken in order and given up (`None`)
    /// as soon as `ok` rejects the tangents of two neighbouring samples: a
    /// span the fitter refuses for bending too sharply costs only the
    /// samples up to the bend.
    pub(super) fn samples_while(
        &self,
        range: Range<f64>,
        ok: impl Fn(Vec2, Vec2) -> bool,
    ) -> Option<[(Point, Vec2); FIT_SAMPLES]> {
        let step = (range.end - range.start) / (FIT_SAMPLES - 1) as f64;
        let mut out = [(Point::ORIGIN, Vec2::ZERO); FIT_SAMPLES];
        if let (Guide::Outline(_), true) = (self.guide, step >= 0.0) {
            if self.tangents.len() == self.pts.len() && self.pts.len() >= 2 {
                return self
                    .outline_samples_while(range.start, step, ok, &mut out)
                    .then_some(out);
            }
        }
        let mut prev: Option<Vec2> = None;
        // The samples ascend: each segment is found by stepping on from
        // the last one.
        let mut seg = None;
        for (i, o) in out.iter_mut().enumerate() {
            let t = range.start + i as f64 * step;
            let located = match seg {
                Some(j) if step >= 0.0 => self.locate_after(j, t * self.length()),
                _ => self.locate(t * self.length()),
            };
            seg = Some(located.0);
            let s = self.sample_at(t, 1.0, located);
            if prev.is_some_and(|t| !ok(t, s.tangent)) {
                return None;
            }
            prev = Some(s.tangent);
            *o = (s.p + self.origin, s.tangent);
        }
        Some(out)
    }

    /// [`Self::samples_while`] on an outline with its tangents given, for
    /// ascending samples from `start` by `step` (shares of the length):
    /// the same samples written into `out` (false once `ok` rejects two
    /// neighbours), [`Self::sample_at`]'s outline branch written out on
    /// one cursor over the segments, so a sample costs a step along the
    /// outline and an interpolated tangent.
    fn outline_samples_while(
        &self,
        start: f64,
        step: f64,
        ok: impl Fn(Vec2, Vec2) -> bool,
        out: &mut [(Point, Vec2); FIT_SAMPLES],
    ) -> bool {
        let (pts, cum, tangents) = (&self.pts[..], &self.cum[..], &self.tangents[..]);
        let n = pts.len();
        let len = self.length();
        let o = self.origin;
        let mut i = self.locate(start * len).0;
        let mut prev: Option<Vec2> = None;
        for (k, slot) in out.iter_mut().enumerate() {
            let t = start + k as f64 * step;
            let raw = t * len;
            let s = raw.clamp(0.0, len);
            while i + 2 < n && cum[i + 1] <= s {
                i += 1;
            }
            let c0 = cum[i];
            let seg = cum[i + 1] - c0;
            let f = if seg > 0.0 { (s - c0) / seg } else { 0.0 };
            let p = pts[i].lerp(pts[i + 1], f);
            let at_start = t <= 0.0;
            let at_end = t >= 1.0;
            let tangent = if (at_start && self.corner_start) || (at_end && self.corner_end) {
                self.chord_dir(raw, at_start || !at_end)
            } else {
                // The tangents' share of the segment: the point's own
                // where the arc length needed no clamping.
                let g = if seg > 0.0 {
                    if raw == s {
                        f.clamp(0.0, 1.0)
                    } else {
                        ((raw - c0) / seg).clamp(0.0, 1.0)
                    }
                } else {
                    0.0
                };
                let v = tangents[i].lerp(tangents[i + 1], g);
                let l = v.hypot();
                if l > 1e-9 {
                    v / l
                } else if self.corner_start && raw < CORNER_REACH
                    || self.corner_end && len - raw < CORNER_REACH
                {
                    self.chord_dir(raw, self.corner_start && raw < CORNER_REACH)
                } else {
                    self.seg_dir(i)
                }
            };
            if prev.is_some_and(|q| !ok(q, tangent)) {
                return false;
            }
            prev = Some(tangent);
            *slot = ((p - o) + o, tangent);
        }
        true
    }

    /// Position (px) and unit tangent at the start (`at_start`) or end of
    /// a span at `t`, the tangents the span's cubic takes there.
    pub(super) fn end_sample(&self, t: f64, at_start: bool) -> (Point, Vec2) {
        let s = self.sample_pt_tangent(t, if at_start { 1.0 } else { -1.0 });
        let l = s.tangent.hypot();
        let tan = if l > 1e-12 { s.tangent / l } else { s.tangent };
        (s.p + self.origin, tan)
    }

    /// Signed area `∫ y dx` and moments `∫ x y dx`, `½ ∫ y² dx` (px², px³)
    /// of the closed loop made of the outline over `range` and the chord
    /// back from `p3` to `p0`, about `p0` (the integrals of a closed loop
    /// shift with the origin by the area times the shift).
    pub(super) fn span_moments(&self, range: Range<f64>, p0: Point, p3: Point) -> [f64; 3] {
        let o = self.origin;
        let (a, x, y) = self.moment_integrals(range);
        let c = segment_moments(p0 - o, p3 - o);
        let (a, x, y) = (a - c[0], x - c[1], y - c[2]);
        let q = p0 - o;
        [a, x - q.x * a, 0.5 * y - q.y * a]
    }

    /// kurbo's default moment integrals (16-point Gauss–Legendre on the
    /// derivative), for SDF contours (their pieces keep no prefix sums).
    fn quadrature_moments(&self, range: Range<f64>) -> (f64, f64, f64) {
        let t0 = 0.5 * (range.start + range.end);
        let dt = 0.5 * (range.end - range.start);
        let (mut a, mut x, mut y) = (0.0, 0.0, 0.0);
        for &(wi, xi) in kurbo::common::GAUSS_LEGENDRE_COEFFS_16 {
            let (p, d) = self.sample_pt_deriv(t0 + xi * dt);
            let ai = wi * d.x * p.y;
            a += ai;
            x += p.x * ai;
            y += p.y * ai;
        }
        (a * dt, x * dt, y * dt)
    }
}

/// The integrals ∫ y dx, ∫ x y dx and ∫ y² dx along the straight segment
/// from `a` to `b` (what kurbo's fitter matches: signed area and its first
/// moments, kurbo `ParamCurveFit::moment_integrals`).
pub(super) fn segment_moments(a: Point, b: Point) -> [f64; 3] {
    let d = b - a;
    [
        d.x * (a.y + 0.5 * d.y),
        d.x * (a.x * a.y + 0.5 * (a.x * d.y + a.y * d.x) + d.x * d.y / 3.0),
        d.x * (a.y * a.y + a.y * d.y + d.y * d.y / 3.0),
    ]
}
