//! Apexes of an anti-aliased outline, sharpened (before the corners of
//! [`super::smooth::polygon_loop`] are found).
//!
//! Where a thin stroke turns sharply (a mitred zigzag's apex, inside and
//! out, a pointed leaf's tip), the pixels round the point are only partly
//! covered, and the outline at half coverage cuts the point off: a flat, or
//! a blunt and lopsided end, a pixel or two across between two straight
//! sides. The corner finder then sees two corners close together, or only
//! one of them, and the fitter spends a short curve between them on what
//! the drawing had as a point (a thin zigzag then costs nearly twice the
//! cubics of its thresholded bitmap, whose polygon gets mitres,
//! [`super::line_ends`]).
//!
//! Here a stretch of the outline at most [`MAX_CUT`] px long
//! whose sides before and after are straight for [`SIDE`] px and turn by
//! [`TURN`] between them is replaced by the point where the sides, extended,
//! meet, when that lies within [`MITRE_LIMIT`] of the stretch. The point
//! turns by the whole apex angle within a pixel, so the corner finder keeps
//! it as one corner: fewer cubics, sharp points where the drawing has
//! them, and the same IoU.

use crate::raster::contour::wrap_once;
use kurbo::{Point, Vec2};

/// Longest stretch (px of arc) that may be replaced by a point: the cut
/// of a one-pixel stroke's apex is under a pixel across, a three-pixel
/// stroke's up to two or three pixels of outline.
const MAX_CUT: f64 = 3.0;

/// Length (px of arc) of each side that must be straight.
const SIDE: f64 = 2.5;

/// How far (px) a straight side's points may lie from its chord: the
/// sub-pixel outline's own scatter, which is largest along one-pixel
/// strokes (a circle of radius 5 px bends further over a side's length,
/// so round shapes have no sides here).
const STRAIGHT: f64 = 0.15;

/// Turning (degrees) between the two sides of an apex: from about a right
/// angle (a square corner that half coverage rounds off) to 150°, a point
/// of 30°. Narrower points (the scroll's leaves, 17–28°) keep their cut:
/// their sides curve in, and the chords extended overshoot the drawn point
/// (a larger upper bound moves the scroll's outline away from its
/// drawing).
const TURN: (f64, f64) = (80.0, 150.0);

/// Farthest (px) the sharpened point may lie from the middle of the stretch
/// it replaces: a cut 1.2 px across a 40° apex is 1.65 px short of the
/// point, and the cut of a one-pixel zigzag's inner apex reaches 2 px.
const MITRE_LIMIT: f64 = 2.5;

/// The closed polygon `pts` by arc length.
struct Arc<'a> {
    pts: &'a [Point],
    /// `cum[i]`: arc length to vertex `i`; `cum[n]` the loop's length.
    cum: Vec<f64>,
    total: f64,
}

impl<'a> Arc<'a> {
    fn new(pts: &'a [Point]) -> Self {
        let cum = crate::raster::contour::closed_arc_lengths(pts);
        let total = cum.last().copied().unwrap_or(0.0);
        Arc { pts, cum, total }
    }

    /// The point at arc length `s` (wrapping round the loop).
    fn at(&self, s: f64) -> Point {
        let n = self.pts.len();
        let s = wrap_once(s, self.total);
        let i = self
            .cum
            .partition_point(|&c| c <= s)
            .saturating_sub(1)
            .min(n - 1);
        let seg = self.cum[i + 1] - self.cum[i];
        let t = if seg > 0.0 {
            (s - self.cum[i]) / seg
        } else {
            0.0
        };
        self.pts[i].lerp(self.pts[(i + 1) % n], t)
    }

    /// The side of [`SIDE`] px starting at vertex `i`, walking forwards
    /// (`dir` = 1) or backwards (−1), as a chord `(far end, vertex)` when
    /// every vertex along it lies within [`STRAIGHT`] of the chord (a
    /// polyline strays furthest from a chord at a vertex).
    fn side(&self, i: usize, forwards: bool) -> Option<(Point, Point)> {
        let n = self.pts.len();
        let s0 = self.cum[i];
        let end = if forwards { s0 + SIDE } else { s0 - SIDE };
        let (a, b) = (self.at(end), self.pts[i]);
        let chord = kurbo::Line::new(a, b);
        let mut j = i;
        let mut walked = 0.0;
        loop {
            let k = if forwards {
                (j + 1) % n
            } else {
                (j + n - 1) % n
            };
            walked += (self.pts[k] - self.pts[j]).hypot();
            if walked >= SIDE {
                return Some((a, b));
            }
            if crate::raster::sdf::point_segment_distance(self.pts[k], chord) > STRAIGHT {
                return None;
            }
            j = k;
        }
    }
}

/// One apex found: the stretch of outline from vertex `first` to vertex
/// `last` (arc lengths `s0 < s1`, unwrapped) and the point replacing it.
#[derive(Clone, Copy, Debug)]
struct Apex {
    first: usize,
    s0: f64,
    s1: f64,
    turn: f64,
    point: Point,
}

/// How much less (degrees) the polyline may turn between the start of an
/// apex's incoming side and the end of its outgoing side than the sides'
/// chords do: the sides wobble by up to [`STRAIGHT`] about their chords,
/// which tilts their first and last segments.
const TURN_SLACK: f64 = 30.0;

/// For each vertex `i`, the polyline's signed turning (degrees) over the
/// arc from [`SIDE`] before it to [`MAX_CUT`] + [`SIDE`] after it: the
/// reach of every apex whose stretch starts at `i` (a sliding window over
/// the loop taken three times round, so windows may wrap either way).
fn window_turning(arc: &Arc) -> Vec<f64> {
    let pts = arc.pts;
    let n = pts.len();
    let dir: Vec<f64> = (0..n)
        .map(|k| {
            let d = pts[(k + 1) % n] - pts[k];
            d.y.atan2(d.x).to_degrees()
        })
        .collect();
    // turn[k]: at vertex k, from segment k − 1 to segment k.
    let turn: Vec<f64> = (0..n)
        .map(|k| wrap_once(dir[k] - dir[(k + n - 1) % n] + 180.0, 360.0) - 180.0)
        .collect();
    let mut prefix = vec![0.0; 3 * n + 1];
    for (k, t) in turn.iter().cycle().take(3 * n).enumerate() {
        prefix[k + 1] = prefix[k] + t;
    }
    // Arc length at vertex k of the tripled loop (k < 3n; the rounds
    // picked by comparison, not division).
    let s = |k: usize| {
        if k < n {
            arc.cum[k]
        } else if k < 2 * n {
            arc.cum[k - n] + arc.total
        } else {
            arc.cum[k - 2 * n] + 2.0 * arc.total
        }
    };
    let (mut lo, mut hi) = (0usize, 0usize);
    (0..n)
        .map(|i| {
            // Vertex i in the middle round.
            let c = s(n + i);
            lo = lo.max(i + 1);
            while s(lo) < c - SIDE {
                lo += 1;
            }
            hi = hi.max(n + i);
            while hi + 1 < 3 * n && s(hi + 1) <= c + MAX_CUT + SIDE {
                hi += 1;
            }
            prefix[hi + 1] - prefix[lo]
        })
        .collect()
}

/// Where lines `a + t·u` and `b − r·w` meet with `t, r ≥ 0` (ahead of `a`,
/// before `b`).
fn meet(a: Point, u: Vec2, b: Point, w: Vec2) -> Option<Point> {
    let den = u.cross(w);
    if den.abs() < 1e-9 {
        return None;
    }
    // a + t u = b − r w  ⇒  t u + r w = b − a.
    let d = b - a;
    let t = d.cross(w) / den;
    let r = u.cross(d) / den;
    (t >= 0.0 && r >= 0.0).then(|| a + u * t)
}

/// `pts` (a closed sub-pixel outline, pixel coordinates) with each cut-off
/// apex replaced by its point (see the module docs).
pub fn sharpen(pts: Vec<Point>) -> Vec<Point> {
    let n = pts.len();
    if n < 4 {
        return pts;
    }
    let arc = Arc::new(&pts);
    if arc.total < 4.0 * (MAX_CUT + SIDE) {
        return pts;
    }
    let turning = window_turning(&arc);
    // Each vertex's forward side, measured once: the stretches from the
    // vertices up to MAX_CUT before it all ask for it.
    let mut forward: Vec<Option<Option<(Point, Point)>>> = vec![None; n];
    let mut found = Vec::new();
    for (i, t) in turning.iter().enumerate() {
        // Only where the outline turns enough round the stretch and its
        // sides (most of it is smooth) are the sides measured.
        if t.abs() < TURN.0 - TURN_SLACK {
            continue;
        }
        let Some((a0, a1)) = arc.side(i, false) else {
            continue;
        };
        let u = a1 - a0;
        // Stretches from vertex i to a vertex up to MAX_CUT further on.
        let mut j = i;
        let mut s1 = arc.cum[i];
        loop {
            let k = (j + 1) % n;
            s1 += (pts[k] - pts[j]).hypot();
            j = k;
            if s1 - arc.cum[i] > MAX_CUT || j == i {
                break;
            }
            let side = *forward[j].get_or_insert_with(|| arc.side(j, true));
            let Some((b1, b0)) = side else {
                continue;
            };
            let w = b1 - b0;
            let turn = u.cross(w).atan2(u.dot(w)).to_degrees();
            if !(TURN.0..=TURN.1).contains(&turn.abs()) {
                continue;
            }
            let Some(point) = meet(a1, u, b0, w) else {
                continue;
            };
            let s0 = arc.cum[i];
            if (point - arc.at(0.5 * (s0 + s1))).hypot() <= MITRE_LIMIT {
                found.push(Apex {
                    first: i,
                    s0,
                    s1,
                    turn,
                    point,
                });
            }
        }
    }
    if found.is_empty() {
        return pts;
    }
    // The sharpest apex of those that overlap, then the shortest stretch,
    // then the first: the vertices round one cut find nearly the same
    // apex many times over.
    found.sort_by(|a, b| {
        b.turn
            .abs()
            .total_cmp(&a.turn.abs())
            .then((a.s1 - a.s0).total_cmp(&(b.s1 - b.s0)))
            .then(a.s0.total_cmp(&b.s0))
    });
    let mut kept: Vec<Apex> = Vec::new();
    for a in found {
        // Neither stretch may reach into the other's stretch or sides.
        let clear = kept.iter().all(|k| {
            let d = wrap_once(a.s0 - k.s0, arc.total);
            let (len_a, len_k) = (a.s1 - a.s0, k.s1 - k.s0);
            d >= len_k + SIDE && arc.total - d >= len_a + SIDE
        });
        if clear {
            kept.push(a);
        }
    }
    // The vertices strictly inside a kept stretch give way to its point,
    // which follows the stretch's first vertex. A stretch's vertices are
    // the ones after its first, up to where its arc ends: marked by
    // walking each stretch (the stretches are disjoint), not by testing
    // every vertex against every stretch.
    let mut inside = vec![false; n];
    let mut point_after: Vec<Option<Point>> = vec![None; n];
    for a in &kept {
        if let Some(slot) = point_after.get_mut(a.first) {
            *slot = Some(a.point);
        }
        let mut j = a.first;
        for _ in 1..n {
            j = if j + 1 == n { 0 } else { j + 1 };
            // How far past the stretch's start (mod the loop) vertex j is:
            // strictly inside until the stretch's end.
            let d = wrap_once(arc.cum[j] - a.s0, arc.total);
            if d >= a.s1 - a.s0 {
                break;
            }
            inside[j] |= d > 0.0;
        }
    }
    let mut out = Vec::with_capacity(n);
    for (i, &p) in pts.iter().enumerate() {
        if inside[i] {
            continue;
        }
        out.push(p);
        if let Some(q) = point_after[i] {
            out.push(q);
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The outline of a wedge with its point cut off by a flat `cut` px
    /// across, sampled every `step` px.
    fn cut_wedge(apex_deg: f64, cut: f64, step: f64) -> (Vec<Point>, Point) {
        // Point at the origin, opening downwards (y grows), sides 20 px.
        let half = (apex_deg / 2.0).to_radians();
        let (sx, sy) = (half.sin(), half.cos());
        let tip = Point::new(50.0, 20.0);
        let depth = cut / 2.0 / half.tan();
        let left_top = tip + Vec2::new(-cut / 2.0, depth);
        let right_top = tip + Vec2::new(cut / 2.0, depth);
        let left_bot = tip + Vec2::new(-20.0 * sx, 20.0 * sy);
        let right_bot = tip + Vec2::new(20.0 * sx, 20.0 * sy);
        let corners = [right_top, left_top, left_bot, right_bot];
        let mut pts = Vec::new();
        for k in 0..4 {
            let (a, b) = (corners[k], corners[(k + 1) % 4]);
            let m = ((b - a).hypot() / step).ceil().max(1.0) as usize;
            for j in 0..m {
                pts.push(a.lerp(b, j as f64 / m as f64));
            }
        }
        (pts, tip)
    }

    #[test]
    fn a_cut_apex_gets_its_point_back() {
        for (deg, cut) in [(40.0, 0.8), (40.0, 1.2), (60.0, 1.5), (30.0, 0.6)] {
            let (pts, tip) = cut_wedge(deg, cut, 0.3);
            let out = sharpen(pts);
            let nearest = out
                .iter()
                .map(|p| (*p - tip).hypot())
                .fold(f64::INFINITY, f64::min);
            assert!(nearest < 1e-6, "{deg}° cut {cut}: nearest {nearest}");
        }
    }

    #[test]
    fn round_shapes_and_line_ends_are_left_alone() {
        // A disc of radius 3 px and a 2-px line's square end.
        let disc: Vec<Point> = (0..60)
            .map(|k| {
                let a = k as f64 / 60.0 * std::f64::consts::TAU;
                Point::new(10.0 + 3.0 * a.cos(), 10.0 + 3.0 * a.sin())
            })
            .collect();
        assert_eq!(sharpen(disc.clone()), disc);
        let mut line = Vec::new();
        for k in 0..=40 {
            line.push(Point::new(k as f64 * 0.5, 0.0));
        }
        for k in 0..=4 {
            line.push(Point::new(20.0, k as f64 * 0.5));
        }
        for k in (0..40).rev() {
            line.push(Point::new(k as f64 * 0.5, 2.0));
        }
        assert_eq!(sharpen(line.clone()), line);
    }
}
