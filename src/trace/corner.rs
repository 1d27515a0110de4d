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
    // Point at arc length s along the closed polygon (wrapping), on the
    // last segment starting at or before it. The arc lengths asked for
    // climb with the vertex, so each of the two reads keeps a cursor that
    // steps forwards (searching afresh only where the loop wraps).
    let at = |s: f64, cursor: &mut usize| -> Point {
        let s = super::contour::wrap_once(s, total);
        let mut i = *cursor;
        if cum[i] > s {
            i = cum[..n].partition_point(|&c| c <= s).saturating_sub(1);
        }
        while i + 1 < n && cum[i + 1] <= s {
            i += 1;
        }
        *cursor = i;
        let seg = cum[i + 1] - cum[i];
        let t = if seg > 0.0 { (s - cum[i]) / seg } else { 0.0 };
        pts[i].lerp(pts[(i + 1) % n], t)
    };
    let (mut behind, mut ahead) = (0usize, 0usize);
    let turn: Vec<f64> = (0..n)
        .map(|i| {
            let p = pts[i];
            let a = p - at(cum[i] - CORNER_WINDOW, &mut behind);
            let b = at(cum[i] + CORNER_WINDOW, &mut ahead) - p;
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
        while j != i && super::contour::wrap_once(cum[j] - cum[i], total) < CORNER_SEPARATION {
            if turn[j] > turn[i] {
                is_max = false;
            }
            j = (j + 1) % n;
        }
        let mut j = (i + n - 1) % n;
        while j != i && super::contour::wrap_once(cum[i] - cum[j], total) < CORNER_SEPARATION {
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
