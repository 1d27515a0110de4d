//! Corners of a closed outline: where it turns sharply within a
//! pixel-scale window. The fitters cut contours there, so cubics meet at an
//! angle and sharp corners stay sharp ([`super::fit`], [`super::cover`]).

use kurbo::Point;

/// Half-width in pixels of the window over which turning is measured when
/// looking for corners.
const CORNER_WINDOW: f64 = 1.25;

/// Turning (radians) above which a vertex is a corner: 55°.
const CORNER_ANGLE: f64 = 55.0 * std::f64::consts::PI / 180.0;

/// Corners closer than this (px) along the outline are one corner (the
/// sharper one): less than a pixel, so both corners of a 1-px line's end
/// survive.
const CORNER_SEPARATION: f64 = 0.9;

/// Indices of the corner vertices of a closed polygon: turning by more
/// than `CORNER_ANGLE` within ±`CORNER_WINDOW` px, the sharpest vertex
/// of each such stretch.
pub fn corners(pts: &[Point]) -> Vec<usize> {
    let n = pts.len();
    if n < 4 {
        return Vec::new();
    }
    let cum = super::contour::closed_arc_lengths(pts);
    let total = cum[n];
    if total < 4.0 * CORNER_WINDOW {
        return Vec::new();
    }
    // Point at arc length s along the closed polygon (wrapping).
    let at = |s: f64| -> Point {
        let s = s.rem_euclid(total);
        let i = match cum.binary_search_by(|c: &f64| c.total_cmp(&s)) {
            Ok(i) => i.min(n - 1),
            Err(i) => i.saturating_sub(1).min(n - 1),
        };
        let seg = cum[i + 1] - cum[i];
        let t = if seg > 0.0 { (s - cum[i]) / seg } else { 0.0 };
        pts[i].lerp(pts[(i + 1) % n], t)
    };
    let turn: Vec<f64> = (0..n)
        .map(|i| {
            let p = pts[i];
            let a = p - at(cum[i] - CORNER_WINDOW);
            let b = at(cum[i] + CORNER_WINDOW) - p;
            a.cross(b).atan2(a.dot(b)).abs()
        })
        .collect();
    let mut out = Vec::new();
    for i in 0..n {
        if turn[i] < CORNER_ANGLE {
            continue;
        }
        // Local maximum within the window (ties broken by index).
        let mut is_max = true;
        let mut j = (i + 1) % n;
        while j != i && (cum[j] - cum[i]).rem_euclid(total) < CORNER_SEPARATION {
            if turn[j] > turn[i] {
                is_max = false;
            }
            j = (j + 1) % n;
        }
        let mut j = (i + n - 1) % n;
        while j != i && (cum[i] - cum[j]).rem_euclid(total) < CORNER_SEPARATION {
            if turn[j] >= turn[i] {
                is_max = false;
            }
            j = (j + n - 1) % n;
        }
        if is_max {
            out.push(i);
        }
    }
    out
}
