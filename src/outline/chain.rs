//! Open polylines as fitting sources: a boundary between two junctions of
//! a cut-out picture, a stroke along a line's centre. Their ends are fixed
//! (a junction, a stroke's end) and count as corners; between them,
//! corners are found and tangents taken as for a closed outline
//! ([`super::corner`], [`super::smooth`]), with the windows cut short at
//! the ends.

use kurbo::{Point, Vec2};

/// Half-width (px) of the window the turning at a vertex is measured over
/// (as [`super::corner`]'s).
const CORNER_WINDOW: f64 = 1.25;

/// Turning (radians) above which a vertex is a corner: 55°.
const CORNER_ANGLE: f64 = 55.0 * std::f64::consts::PI / 180.0;

/// Corners closer than this (px) along the chain are one (the sharper).
const CORNER_SEPARATION: f64 = 0.9;

/// How far (px) to either side of a point its tangent chord reaches.
const TANGENT_REACH: f64 = 1.5;

/// An open polyline with a unit tangent at each point and its corners
/// (indices, ascending; the first and last point among them).
#[derive(Clone, Debug, Default)]
pub struct OpenChain {
    /// The points, in order.
    pub points: Vec<Point>,
    /// Unit tangent at each point (direction of travel).
    pub tangents: Vec<Vec2>,
    /// Indices of the corners, ascending, both ends included.
    pub corners: Vec<usize>,
}

/// The point at arc length `s` (clamped to the chain).
fn at(pts: &[Point], cum: &[f64], s: f64) -> Point {
    let n = pts.len();
    let s = s.clamp(0.0, cum[n - 1]);
    let i = cum
        .partition_point(|&c| c <= s)
        .saturating_sub(1)
        .min(n - 2);
    let seg = cum[i + 1] - cum[i];
    let t = if seg > 0.0 { (s - cum[i]) / seg } else { 0.0 };
    pts[i].lerp(pts[i + 1], t)
}

fn unit(v: Vec2) -> Vec2 {
    let l = v.hypot();
    if l > 1e-12 {
        v / l
    } else {
        Vec2::new(1.0, 0.0)
    }
}

/// `points` (repeated points dropped) as an [`OpenChain`]: corners where
/// the chain turns by more than 55° within ±1.25 px (the sharpest of
/// those within 0.9 px of each other, none within a window of an end),
/// and tangents as chords over ±1.5 px, one-sided next to a corner or an
/// end.
pub fn open_chain(points: Vec<Point>) -> OpenChain {
    let mut pts: Vec<Point> = Vec::with_capacity(points.len());
    for p in points {
        if pts.last() != Some(&p) {
            pts.push(p);
        }
    }
    let n = pts.len();
    if n < 2 {
        return OpenChain {
            tangents: vec![Vec2::new(1.0, 0.0); n],
            corners: (0..n).collect(),
            points: pts,
        };
    }
    let cum = crate::raster::contour::open_arc_lengths(&pts);
    let total = cum[n - 1];
    let turn: Vec<f64> = (0..n)
        .map(|i| {
            if cum[i] < CORNER_WINDOW || total - cum[i] < CORNER_WINDOW {
                return 0.0;
            }
            let p = pts[i];
            let a = p - at(&pts, &cum, cum[i] - CORNER_WINDOW);
            let b = at(&pts, &cum, cum[i] + CORNER_WINDOW) - p;
            a.cross(b).atan2(a.dot(b)).abs()
        })
        .collect();
    let mut corners = vec![0];
    for i in 1..n - 1 {
        if turn[i] < CORNER_ANGLE {
            continue;
        }
        let near = |j: usize| (cum[j] - cum[i]).abs() < CORNER_SEPARATION;
        let rival = (i + 1..n)
            .take_while(|&j| near(j))
            .any(|j| turn[j] > turn[i])
            || (0..i)
                .rev()
                .take_while(|&j| near(j))
                .any(|j| turn[j] >= turn[i]);
        if !rival {
            corners.push(i);
        }
    }
    corners.push(n - 1);
    let mut is_corner = vec![false; n];
    for &c in &corners {
        is_corner[c] = true;
    }
    // Walks from i up to the reach or the next corner (an end is one).
    let walk = |i: usize, forward: bool| -> Point {
        let mut j = i;
        let mut d = 0.0;
        loop {
            let k = if forward { j + 1 } else { j.wrapping_sub(1) };
            let Some(&q) = pts.get(k) else {
                return pts[j];
            };
            let step = (q - pts[j]).hypot();
            if d + step >= TANGENT_REACH {
                let f = if step > 0.0 {
                    (TANGENT_REACH - d) / step
                } else {
                    0.0
                };
                return pts[j].lerp(q, f);
            }
            d += step;
            j = k;
            if is_corner[j] {
                return pts[j];
            }
        }
    };
    let tangents = (0..n)
        .map(|i| {
            let (a, b) = if is_corner[i] {
                // At a corner or an end: the side that follows (the one
                // before at the last point).
                if i + 1 < n {
                    (pts[i], walk(i, true))
                } else {
                    (walk(i, false), pts[i])
                }
            } else {
                (walk(i, false), walk(i, true))
            };
            unit(b - a)
        })
        .collect();
    OpenChain {
        points: pts,
        tangents,
        corners,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// An L of two straight arms has one corner besides its ends, and
    /// tangents along its arms; a smooth arc has none.
    #[test]
    fn corners_and_tangents_of_open_chains() {
        let mut l: Vec<Point> = (0..=20).map(|k| Point::new(k as f64 * 0.5, 0.0)).collect();
        l.extend((1..=20).map(|k| Point::new(10.0, k as f64 * 0.5)));
        let c = open_chain(l);
        assert_eq!(c.corners, vec![0, 20, 40]);
        assert!((c.tangents[5] - Vec2::new(1.0, 0.0)).hypot() < 1e-9);
        assert!((c.tangents[30] - Vec2::new(0.0, 1.0)).hypot() < 1e-9);
        let arc: Vec<Point> = (0..=60)
            .map(|k| {
                let a = k as f64 / 60.0 * 2.0;
                Point::new(20.0 * a.cos(), 20.0 * a.sin())
            })
            .collect();
        let c = open_chain(arc);
        assert_eq!(c.corners, vec![0, 60]);
        for (k, t) in c.tangents.iter().enumerate().skip(2).take(56) {
            let a = k as f64 / 60.0 * 2.0;
            assert!(
                (*t - Vec2::new(-a.sin(), a.cos())).hypot() < 0.01,
                "{k}: {t:?}"
            );
        }
    }
}
