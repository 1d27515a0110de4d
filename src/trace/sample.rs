//! Sampling a [`Piece`] the way a curve fitter reads its source: points
//! and tangents by normalized arc length (kurbo's [`ParamCurveFit`], and
//! the [`FIT_SAMPLES`] samples of a span that both fitters judge a range
//! by), and the area and moment integrals a cubic is matched to (exact
//! prefix sums over an outline's segments; kurbo's quadrature for SDF
//! contours).

use super::fit::{canvas_value, Guide, Piece};
use super::span::FIT_SAMPLES;
use crate::raster::Sdf;
use kurbo::{CurveFitSample, ParamCurveFit, Point, Vec2};
use std::ops::Range;

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
    /// derivative), kept for SDF contours so their output does not change.
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
