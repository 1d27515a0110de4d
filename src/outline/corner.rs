//! Corners of a closed outline: where it turns sharply within a
//! pixel-scale window. The fitters cut contours there, so cubics meet at an
//! angle and sharp corners stay sharp (the tracer's `fit` and `cover`).

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

/// How much further (radians) than a circle of the loop's length would
/// turn within the window a corner must turn, on top of
/// [`CORNER_ANGLE`]: 23°. Only loops under 14 px long notice (a circle
/// that long turns 32° between the chords to a window either side), where
/// a round dot's wobbling outline turns past [`CORNER_ANGLE`] within most
/// windows. On anti-aliased discs, squares and diamonds 1.8–8 px across
/// at sub-pixel offsets: no disc gets a corner, 4-px squares keep all four
/// at most offsets, and squares and diamonds under 3 px become round.
const EXCESS: f64 = 0.4;

/// Indices of the corner vertices of a closed polygon: turning by more
/// than `CORNER_ANGLE` within ±`CORNER_WINDOW` px, the sharpest vertex
/// of each such stretch, and by `EXCESS` (0.4 rad) more than a circle of the
/// loop's length: a dot of the 2 Mpx ornament's dotted rings (1–1.5 px
/// across) is two or three cubics, not an octagon of lines between
/// corners found wherever its outline's wobble peaks, while a 4-px square
/// keeps its corners.
pub fn corners(pts: &[Point]) -> Vec<usize> {
    let n = pts.len();
    if n < 4 {
        return Vec::new();
    }
    let cum = crate::raster::contour::closed_arc_lengths(pts);
    let total = cum[n];
    if total < 4.0 * CORNER_WINDOW {
        return Vec::new();
    }
    // Point at arc length s along the closed polygon (wrapping), on the
    // last segment starting at or before it. The arc lengths asked for
    // climb with the vertex, so each of the two reads keeps a cursor that
    // steps forwards (searching afresh only where the loop wraps).
    let at = |s: f64, cursor: &mut usize| -> Point {
        let s = crate::raster::contour::wrap_once(s, total);
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
    // How far a circle as long as the loop turns between the chords to
    // the points a window before and after each of its points.
    let round = std::f64::consts::TAU * CORNER_WINDOW / total;
    let threshold = CORNER_ANGLE.max(round + EXCESS);
    let mut out = Vec::new();
    for i in 0..n {
        if turn[i] < threshold {
            continue;
        }
        // Local maximum within the window (ties broken by index).
        let mut is_max = true;
        let mut j = (i + 1) % n;
        while j != i
            && crate::raster::contour::wrap_once(cum[j] - cum[i], total) < CORNER_SEPARATION
        {
            if turn[j] > turn[i] {
                is_max = false;
            }
            j = (j + 1) % n;
        }
        let mut j = (i + n - 1) % n;
        while j != i
            && crate::raster::contour::wrap_once(cum[i] - cum[j], total) < CORNER_SEPARATION
        {
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

#[cfg(test)]
mod tests {
    use crate::outline::smooth as binary;
    use crate::raster::{sdf, Grid};

    /// The corners of the outline of an anti-aliased shape (coverage
    /// supersampled 16×16 per pixel) centred at (8, 8) + `offset`.
    fn corner_counts(inside: impl Fn(f64, f64) -> bool, offset: (f64, f64)) -> Vec<usize> {
        let cov = Grid::from_fn(16, 16, |x, y| {
            let mut c = 0;
            for a in 0..16 {
                for b in 0..16 {
                    let px = x as f64 + (a as f64 + 0.5) / 16.0 - 8.0 - offset.0;
                    let py = y as f64 + (b as f64 + 0.5) / 16.0 - 8.0 - offset.1;
                    c += u32::from(inside(px, py));
                }
            }
            c as f32 / 256.0
        });
        sdf::subpixel_outline(&cov)
            .into_iter()
            .map(|p| binary::polygon_loop(p).corners.len())
            .collect()
    }

    const OFFSETS: [(f64, f64); 4] = [(0.3, -0.1), (0.17, 0.41), (0.33, 0.08), (0.45, 0.21)];

    /// Round dots 1.8–4 px across have no corners (their outlines, 8–16
    /// vertices, wobble; the 55° test alone finds corners on every dot
    /// under about 3 px, which would then trace as polygons of lines).
    #[test]
    fn small_round_dots_have_no_corners() {
        for r in [0.9, 1.1, 1.3, 1.6, 2.0] {
            for o in OFFSETS {
                let n = corner_counts(|x, y| x * x + y * y <= r * r, o);
                assert_eq!(n, vec![0], "disc of radius {r} at {o:?}");
            }
        }
    }

    /// Squares keep their four corners from 4 px across up.
    #[test]
    fn small_squares_keep_their_corners() {
        for half in [2.0, 3.0, 5.0] {
            for o in [(0.3, -0.1), (0.0, 0.0), (0.33, 0.08)] {
                let n = corner_counts(|x, y| x.abs() <= half && y.abs() <= half, o);
                assert_eq!(n, vec![4], "square of side {} at {o:?}", 2.0 * half);
            }
        }
    }
}
