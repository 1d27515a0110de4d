//! The outline a binary bitmap stands for: optimal polygons smoothed into
//! curves, the interpretation potrace made standard (Selinger 2003, §2.2–2.3).
//!
//! A binary bitmap only says on which side of each pixel boundary the ink
//! is; the edge it was rendered from can lie anywhere within half a pixel
//! of the staircase. Building the SDF from the staircase itself (or from a
//! lightly smoothed one) makes every later stage follow the jaggies. Here
//! the staircase is replaced by the simplest curve consistent with it:
//!
//! 1. **Paths.** The boundary of the ink as closed loops through the
//!    midpoints of the pixel edges (the loops of marching squares on the
//!    ±½ field, ties joining the ink as everywhere in flourish), walked on
//!    the bits ([`paths`]).
//! 2. **Straight runs.** For every vertex `i`, the furthest vertex `j` such
//!    that a line from `i` passes through the L∞ box of half-side
//!    [`STRAIGHT_TOLERANCE`](super::polygon::STRAIGHT_TOLERANCE) round
//!    every vertex between them, every step advances along it, and the
//!    steps keep to two neighbouring directions of the eight (potrace's
//!    straight paths, Selinger 2003, §2.2.1, as its implementation anchors
//!    them; the direction rule keeps a run from turning round a line's
//!    end). A cone of admissible directions is
//!    narrowed from stretch to stretch of repeated steps, in exact integer
//!    arithmetic on doubled pixel coordinates.
//! 3. **Optimal polygon** (§2.2.2). Reaches made monotone (every
//!    sub-segment of a possible segment is possible), then the fewest
//!    segments round the loop and, of those, the least sum of potrace's
//!    penalties (chord length × r.m.s. distance of the path from the
//!    chord), by potrace's dynamic programme from the start whose greedy
//!    cover is shortest. (Steps 2–3: [`super::polygon`].)
//! 4. **Vertex adjustment** (§2.3.1). Each edge gets the least-squares line
//!    of its path vertices (the interior ones: the ends chamfer the
//!    corner); each vertex moves to the point of the box of half-side ½
//!    round its path vertex nearest to its two edges' lines
//!    ([`super::vertices`]). Where the outline makes a U-turn over a
//!    vertex or a short edge (the end of a line up to 3½ px wide), the turn
//!    becomes a square cap at the farthest pixel edge; a short edge at a
//!    sharp turn (a thin zigzag's apex) becomes a mitre, cut 1.5 px out
//!    ([`super::line_ends`]).
//! 5. **Smoothing.** Each vertex becomes either a corner or a cubic from
//!    the midpoint of its incoming edge to the midpoint of its outgoing
//!    edge, with control points a fraction `α` of the way to the vertex; `α`
//!    grows with how far the vertex sticks out of the chord of its
//!    neighbours, measured in pixel-square units, and a vertex with
//!    `α ≥` [`ALPHA_MAX`] stays a corner (potrace's `alphamax`).
//!
//! 6. **Relaxing.** The curves are flattened at `FLATTEN` (0.1 px), each
//!    point moved out so the chords keep the curve's area, and smoothed
//!    along their arc length between corners (a biweight of radius
//!    `RELAX_RADIUS`, with Taubin's inflating second pass so loops do not
//!    shrink): step 5's cubics bunch their turning next to the polygon
//!    vertices, and a fitter that follows them needs more curves than the
//!    drawing had.
//!    Tangents are taken as chords over ±`TANGENT_REACH` px.
//!
//! `flourish trace` fits Béziers to these loops directly
//! ([`bitmap_loops`]; the tracer's `trace_outline`); other modes that
//! read a binary bitmap get the SDF of the same curves ([`bitmap_sdf`]), with the
//! inside of pixel centres taken from the curves (not from the bitmap), so
//! the sign and the distance agree.

use super::line_ends;
use crate::outline::paths::{self, Bitmap};
use crate::outline::polygon::{optimal_polygon, possible_segments, straight_runs};
use crate::outline::vertices::{adjust_vertices, edge_lines};
use crate::raster::contour;
#[cfg(test)]
use crate::raster::Coverage;
use crate::raster::{Grid, Sdf};
use kurbo::{CubicBez, ParamCurve, ParamCurveDeriv, Point, Vec2};
use rayon::prelude::*;

/// Vertices with `α` at least this stay corners (potrace's default 1.0).
pub const ALPHA_MAX: f64 = 1.0;

/// Flattening tolerance (px) of the smoothed curves. The points are moved
/// out so the chords straddle the curve ([`smooth_polygon`]), so a coarse
/// flattening costs no ink, and the relaxing and tangent passes and the
/// fit run over fewer points than at a fine one, for about the same
/// segments, IoU and deviation.
const FLATTEN: f64 = 0.1;

/// One closed loop of a binary bitmap's smoothed outline, flattened: the
/// points (pixel coordinates), the unit tangent of the smooth curve at each
/// point (direction of travel), and which points are corners (where the
/// smoothing kept the polygon vertex, `α ≥` [`ALPHA_MAX`]; the tangent
/// stored there is the outgoing edge's).
#[derive(Clone, Debug, Default)]
pub struct SmoothLoop {
    /// Points along the loop, in order, without repeating the first.
    pub points: Vec<Point>,
    /// Unit tangent at each point.
    pub tangents: Vec<Vec2>,
    /// Indices into `points` of the corners, ascending.
    pub corners: Vec<usize>,
    /// The signed area (px²) of what the loop stands for, positive for
    /// outer loops: for a bitmap's loop the pixels its path bounds
    /// ([`paths::pixel_area`], so a 2 × 2 dot is 4 px² however its curve
    /// rounds it), for a [`polygon_loop`] the polygon's own. The speck
    /// threshold (`--min-area`) reads this.
    pub area: f64,
}

/// The smoothed outline of binary coverage `cov` as [`SmoothLoop`]s with
/// tangents and corners: what `flourish trace` fits Béziers to directly.
/// Outer loops are counter-clockwise in the y-down sense of
/// [`crate::raster::contour::Contour::signed_area`] > 0, holes the other way.
#[cfg(test)]
pub fn smooth_loops(cov: &Coverage) -> Vec<SmoothLoop> {
    bitmap_loops(&Bitmap::from_coverage(cov))
}

/// The smoothed outline of a bitmap's ink as [`SmoothLoop`]s with
/// tangents and corners: what `flourish trace` fits Béziers to directly.
/// Outer loops are counter-clockwise in the y-down sense of
/// [`crate::raster::contour::Contour::signed_area`] > 0, holes the other way.
pub fn bitmap_loops(bits: &Bitmap) -> Vec<SmoothLoop> {
    paths::paths(bits)
        .par_iter()
        .map(|p| smooth_loop(p))
        .filter(|l| l.points.len() >= 3)
        .collect()
}

/// The smoothed outline of binary coverage `cov`: closed polylines in pixel
/// coordinates (outer loops counter-clockwise in the y-down sense of
/// [`crate::raster::contour::Contour::signed_area`] > 0, holes the other way).
#[cfg(test)]
pub fn smooth_outline(cov: &Coverage) -> Vec<Vec<Point>> {
    smooth_loops(cov).into_iter().map(|l| l.points).collect()
}

/// Steps 2–6 for one closed path of a bitmap's ink (pixel coordinates, as
/// [`paths::paths`] gives them): its smoothed loop. A loop of fewer than
/// three points is too small to keep.
pub fn smooth_loop(path: &[Point]) -> SmoothLoop {
    let n = path.len();
    let mut l = if n < 4 {
        polyline_loop(path)
    } else {
        let ahead = possible_segments(&straight_runs(path));
        let poly = optimal_polygon(path, &ahead);
        if poly.len() < 3 {
            polyline_loop(path)
        } else {
            let lines = edge_lines(path, &poly);
            let vertices = adjust_vertices(path, &poly, &lines);
            let (vertices, caps) = line_ends::square_line_ends(path, &poly, &lines, vertices);
            let (vertices, caps) = line_ends::mitre_short_edges(vertices, caps);
            smooth_polygon(&vertices, &caps)
        }
    };
    l.area = paths::pixel_area(path);
    l
}

/// A loop too small to smooth, kept as its polygon: every vertex a corner.
fn polyline_loop(path: &[Point]) -> SmoothLoop {
    let n = path.len();
    let tangents = (0..n).map(|i| unit(path[(i + 1) % n] - path[i])).collect();
    SmoothLoop {
        points: path.to_vec(),
        tangents,
        corners: (0..n).collect(),
        area: contour::signed_area(path),
    }
}

/// `v` scaled to unit length (x axis for a zero vector).
fn unit(v: Vec2) -> Vec2 {
    let l = v.hypot();
    if l > 1e-12 {
        v / l
    } else {
        Vec2::new(1.0, 0.0)
    }
}

/// Step 5: corners and cubics through the edge midpoints, flattened, with
/// the curve's tangent at every point; vertices marked in `keep` (the
/// square caps of thin-line ends) stay corners.
fn smooth_polygon(v: &[Point], keep: &[bool]) -> SmoothLoop {
    let k = v.len();
    let mut out = SmoothLoop::default();
    let push = |out: &mut SmoothLoop, p: Point, t: Vec2, corner: bool| {
        if let Some(&last) = out.points.last() {
            if (p - last).hypot() < 1e-9 {
                // The same point again (an edge midpoint shared by two
                // vertices' curves): a corner wins.
                if corner {
                    out.corners.push(out.points.len() - 1);
                    if let Some(lt) = out.tangents.last_mut() {
                        *lt = t;
                    }
                }
                return;
            }
        }
        if corner {
            out.corners.push(out.points.len());
        }
        out.points.push(p);
        out.tangents.push(t);
    };
    for j in 0..k {
        let a = v[(j + k - 1) % k];
        let p = v[j];
        let b = v[(j + 1) % k];
        let m1 = a.midpoint(p);
        let m2 = p.midpoint(b);
        let alpha = corner_alpha(a, p, b);
        if alpha >= ALPHA_MAX || is_line_end(a, p, b) || keep.get(j).copied().unwrap_or(false) {
            push(&mut out, m1, unit(p - a), false);
            push(&mut out, p, unit(b - p), true);
        } else {
            let alpha = alpha.clamp(0.55, 1.0);
            let c = CubicBez::new(m1, m1 + (p - m1) * alpha, m2 + (p - m2) * alpha, m2);
            let steps = cubic_steps(&c);
            let c1 = c.deriv();
            let c2 = c1.deriv();
            let h = 1.0 / steps as f64;
            for s in 0..steps {
                let t = s as f64 / steps as f64;
                let d = c1.eval(t).to_vec2();
                // At a degenerate end the chord of the edge is the tangent.
                let d = if d.hypot() > 1e-9 {
                    d
                } else if s == 0 {
                    p - a
                } else {
                    b - p
                };
                let u = unit(d);
                let mut q = c.eval(t);
                if s > 0 {
                    // The chords either side cut inside the curve by its
                    // sagitta, about |B''_n| h² / 8 for a parameter step h
                    // (B''_n: the second derivative's normal part); the
                    // area between a chord and its arc is 2/3 of sagitta ×
                    // chord, so moving each point out by 2/3 of the sagitta
                    // keeps the area the curve encloses.
                    let dd = c2.eval(t).to_vec2();
                    let n = dd - u * dd.dot(u);
                    q -= n * (h * h / 8.0 * 2.0 / 3.0);
                }
                push(&mut out, q, u, false);
            }
        }
    }
    // The loop closes on its first point.
    if out.points.len() > 1 {
        let first = out.points[0];
        let last = out.points[out.points.len() - 1];
        if (first - last).hypot() < 1e-9 {
            out.points.pop();
            out.tangents.pop();
            let n = out.points.len();
            if out.corners.last() == Some(&n) {
                out.corners.pop();
                if !out.corners.contains(&0) {
                    out.corners.insert(0, 0);
                }
            }
        }
    }
    relax(&mut out);
    smooth_tangents(&mut out);
    out
}

/// Radius (px of arc length) of the smoothing kernel that relaxes the
/// smoothed outline between corners (a biweight of this radius has a
/// standard deviation of about 1.5 px).
const RELAX_RADIUS: f64 = 4.0;

/// Smoothing of the points along the loop with a biweight kernel over arc
/// length (corners fixed, and no averaging across them), with Taubin's
/// shrink-free second pass: the per-vertex cubics of step 5 concentrate
/// their turning near the polygon vertices; relaxing spreads it as the
/// drawn curve would.
fn relax(l: &mut SmoothLoop) {
    let n = l.points.len();
    if n < 5 {
        return;
    }
    let is_corner = corner_mask(l);
    let pass = |pts: &[Point], factor: f64| -> Vec<Point> {
        // gap[k]: the length of the segment from vertex k to k + 1.
        let gap: Vec<f64> = (0..n)
            .map(|k| (pts[(k + 1) % n] - pts[k]).hypot())
            .collect();
        let r2 = RELAX_RADIUS * RELAX_RADIUS;
        (0..n)
            .map(|i| {
                if is_corner[i] {
                    return pts[i];
                }
                let mut sum = Vec2::ZERO;
                let mut wsum = 0.0;
                for forward in [true, false] {
                    let mut j = i;
                    let mut d = 0.0;
                    loop {
                        let k = adjacent(j, forward, n);
                        d += if forward { gap[j] } else { gap[k] };
                        if d >= RELAX_RADIUS || k == i {
                            break;
                        }
                        let u = 1.0 - d * d / r2;
                        let w = u * u;
                        sum += (pts[k] - pts[i]) * w;
                        wsum += w;
                        j = k;
                        if is_corner[k] {
                            break;
                        }
                    }
                }
                if wsum > 0.0 {
                    pts[i] + sum * (factor / (1.0 + wsum))
                } else {
                    pts[i]
                }
            })
            .collect()
    };
    // Only a corner-free loop can be moved out as a whole (see keep_area).
    let before = l
        .corners
        .is_empty()
        .then(|| contour::signed_area(&l.points));
    let a = pass(&l.points, 1.0);
    l.points = pass(&a, -1.0 / 0.9);
    if let Some(area) = before {
        keep_area(&mut l.points, area);
    }
}

/// Moves a corner-free closed loop out along its normals, by the same
/// distance everywhere, until it encloses `area` (px², signed) again if
/// relaxing shrank it. Taubin's second pass undoes the first pass's
/// shrinking only where the kernel is small beside the loop: without this,
/// a dot of 2×2 pixels (5 px round) would shrink to a speck a third of
/// its size.
fn keep_area(points: &mut [Point], area: f64) {
    let n = points.len();
    for _ in 0..2 {
        let now = contour::signed_area(points);
        // Only a loop that lost area, without turning inside out.
        if now * area <= 0.0 || now.abs() >= area.abs() {
            return;
        }
        // ∂A/∂p_i = ½ (y_{i+1} − y_{i−1}, x_{i−1} − x_{i+1}) points out of
        // the loop's area; moving every point a distance δ along it grows
        // |A| by P δ + π δ² (Steiner's formula for a simple loop of
        // perimeter P ≈ Σ |∂A/∂p_i|).
        let grad: Vec<Vec2> = (0..n)
            .map(|i| {
                let d = points[(i + 1) % n] - points[(i + n - 1) % n];
                Vec2::new(0.5 * d.y, -0.5 * d.x)
            })
            .collect();
        let total: f64 = grad.iter().map(|g| g.hypot()).sum();
        if total < 1e-12 {
            return;
        }
        let pi = std::f64::consts::PI;
        let gain = area.abs() - now.abs();
        let delta = area.signum() * ((total * total + 4.0 * pi * gain).sqrt() - total) / (2.0 * pi);
        for (p, g) in points.iter_mut().zip(&grad) {
            let l = g.hypot();
            if l > 1e-12 {
                *p += *g * (delta / l);
            }
        }
    }
}

/// The neighbour of vertex `j` on a closed loop of `n` vertices, ahead or
/// behind.
fn adjacent(j: usize, forward: bool, n: usize) -> usize {
    // Compares, not `%`: this is the inner step of the relaxing and tangent
    // walks, and an integer division costs more than the rest of a step.
    if forward {
        if j + 1 >= n {
            0
        } else {
            j + 1
        }
    } else if j == 0 {
        n.saturating_sub(1)
    } else {
        j - 1
    }
}

/// Per point of the loop: whether it is a corner.
fn corner_mask(l: &SmoothLoop) -> Vec<bool> {
    let mut v = vec![false; l.points.len()];
    for &c in &l.corners {
        if let Some(x) = v.get_mut(c) {
            *x = true;
        }
    }
    v
}

/// A closed polygon that follows an outline closely (an anti-aliased
/// bitmap's sub-pixel outline) as a [`SmoothLoop`]: apexes that half
/// coverage cut off given their points back (`super::tips`), corners where
/// it turns sharply within a pixel or so ([`crate::outline::corner::corners`]),
/// chord tangents elsewhere.
pub fn polygon_loop(points: Vec<Point>) -> SmoothLoop {
    let points = super::tips::sharpen(points);
    let corners = crate::outline::corner::corners(&points);
    let n = points.len();
    let tangents = (0..n)
        .map(|i| unit(points[(i + 1) % n] - points[i]))
        .collect();
    let area = contour::signed_area(&points);
    let mut l = SmoothLoop {
        points,
        tangents,
        corners,
        area,
    };
    smooth_tangents(&mut l);
    l
}

/// How far (px) to either side of a point its tangent chord reaches.
const TANGENT_REACH: f64 = 1.5;

/// Replaces each tangent by the chord over ±[`TANGENT_REACH`] px of arc
/// length (one-sided next to a corner): the curve's own derivative carries
/// the curvature concentration of the smoothing's cubics, which a fitter
/// would follow; the chord has the direction the pixels support.
fn smooth_tangents(l: &mut SmoothLoop) {
    let n = l.points.len();
    if n < 3 {
        return;
    }
    // seg[k]: the length of the segment from point k to k + 1, computed
    // once (walking back over it gives the same number: only the signs of
    // the difference's components change).
    let seg: Vec<f64> = (0..n)
        .map(|k| (l.points[adjacent(k, true, n)] - l.points[k]).hypot())
        .collect();
    let total = seg.iter().fold(0.0, |s, &g| s + g);
    let is_corner = corner_mask(l);
    let reach = TANGENT_REACH.min(total / 4.0);
    // Walks from i along the loop (dir = ±1) up to `reach` px or a corner.
    let walk = |i: usize, forward: bool| -> Point {
        let mut j = i;
        let mut d = 0.0;
        loop {
            let k = adjacent(j, forward, n);
            let step = if forward { seg[j] } else { seg[k] };
            if d + step >= reach {
                let f = if step > 0.0 { (reach - d) / step } else { 0.0 };
                return l.points[j].lerp(l.points[k], f);
            }
            d += step;
            j = k;
            if is_corner[j] || j == i {
                return l.points[j];
            }
        }
    };
    let tangents: Vec<Vec2> = (0..n)
        .map(|i| {
            if is_corner[i] {
                return l.tangents[i];
            }
            let a = walk(i, false);
            let b = walk(i, true);
            let t = b - a;
            if t.hypot() > 1e-9 {
                unit(t)
            } else {
                l.tangents[i]
            }
        })
        .collect();
    l.tangents = tangents;
}

/// Longest edge (px) that can be the end of a thin line.
const LINE_END_EDGE: f64 = 1.5;

/// Whether polygon vertex `p` (between `a` and `b`) is a corner of a thin
/// line's end: one of its edges at most [`LINE_END_EDGE`] long and the
/// outline turning there by more than 80°. potrace's corner measure reads
/// such a vertex as smooth (it sticks out of the chord to the far end of
/// the line by less than a pixel) and the curve then rounds the line's end
/// off over half its length; the bitmap says the line runs to its end.
fn is_line_end(a: Point, p: Point, b: Point) -> bool {
    let (u, w) = (p - a, b - p);
    let short = u.hypot().min(w.hypot()) <= LINE_END_EDGE;
    let turn = u.cross(w).atan2(u.dot(w)).abs();
    short && turn > 80f64.to_radians()
}

/// Potrace's corner measure: how far the vertex `p` sticks out of the line
/// through its neighbours `a` and `b`, in units of the pixel square's
/// extent across that line, mapped so that `α = 4/3 (1 − 1/dd)`.
fn corner_alpha(a: Point, p: Point, b: Point) -> f64 {
    let chord = b - a;
    // The unit-square extent across the chord: |n_x| + |n_y| for the
    // chord's unit normal, times the chord length (the L∞ normal).
    let denom = chord.x.abs() + chord.y.abs();
    if denom < 1e-12 {
        return ALPHA_MAX;
    }
    let dd = ((p - a).cross(chord)).abs() / denom;
    let alpha = if dd > 1.0 { 1.0 - 1.0 / dd } else { 0.0 };
    alpha / 0.75
}

/// Points per cubic for a flattening within [`FLATTEN`] px.
fn cubic_steps(c: &CubicBez) -> usize {
    // Second differences bound the deviation of a chord: 1/8 · max |B''| / n².
    let dd1 = ((c.p2 - c.p1) - (c.p1 - c.p0)).hypot();
    let dd2 = ((c.p3 - c.p2) - (c.p2 - c.p1)).hypot();
    let m = 6.0 * dd1.max(dd2);
    ((m / (8.0 * FLATTEN)).sqrt().ceil() as usize).clamp(1, 64)
}

/// The SDF of a bitmap's ink read as its smoothed outline: distances to
/// the curves of [`bitmap_loops`], inside taken from the same curves.
pub fn bitmap_sdf(bits: &Bitmap, to_user: kurbo::Affine) -> Sdf {
    let loops: Vec<Vec<Point>> = bitmap_loops(bits).into_iter().map(|l| l.points).collect();
    let inside = inside(bits.width(), bits.height(), &loops);
    let mut segments = Vec::new();
    for poly in &loops {
        let n = poly.len();
        for i in 0..n {
            segments.push(kurbo::Line::new(poly[i], poly[(i + 1) % n]));
        }
    }
    Sdf::from_segments(&inside, &segments, to_user)
}

/// Pixel centres inside the closed polylines `loops` (nonzero winding).
pub fn inside(w: usize, h: usize, loops: &[Vec<Point>]) -> Grid<bool> {
    let mut grid = Grid::new(w, h, false);
    let edges = loops
        .iter()
        .flat_map(|poly| (0..poly.len()).map(move |i| (poly[i], poly[(i + 1) % poly.len()])));
    crate::raster::scan::fill(&mut grid, edges, false);
    grid
}

#[cfg(test)]
mod tests {
    use super::*;

    fn disc(n: usize, cx: f64, cy: f64, r: f64) -> Coverage {
        Grid::from_fn(n, n, |x, y| {
            let d = (x as f64 + 0.5 - cx).hypot(y as f64 + 0.5 - cy);
            if d <= r {
                1.0
            } else {
                0.0
            }
        })
    }

    #[test]
    fn a_rasterized_disc_becomes_a_round_curve() {
        let (cx, cy, r) = (40.3, 39.7, 25.0);
        let loops = smooth_outline(&disc(80, cx, cy, r));
        assert_eq!(loops.len(), 1);
        // Within about half a pixel of the true circle everywhere (the
        // bitmap's own uncertainty, up to √2/2 along diagonals), and far
        // closer on average.
        let dev: Vec<f64> = loops[0]
            .iter()
            .map(|p| ((p.x - cx).hypot(p.y - cy) - r).abs())
            .collect();
        let max = dev.iter().cloned().fold(0.0, f64::max);
        let mean = dev.iter().sum::<f64>() / dev.len() as f64;
        assert!(max < 0.6, "max {max}");
        assert!(mean < 0.2, "mean {mean}");
    }

    #[test]
    fn a_square_keeps_its_corners() {
        let cov = Grid::from_fn(40, 40, |x, y| {
            if (10..30).contains(&x) && (10..30).contains(&y) {
                1.0
            } else {
                0.0
            }
        });
        let loops = smooth_outline(&cov);
        assert_eq!(loops.len(), 1);
        // The four corners (10,10) … (30,30) are on the outline.
        for c in [(10.0, 10.0), (30.0, 10.0), (30.0, 30.0), (10.0, 30.0)] {
            let c = Point::new(c.0, c.1);
            let d = loops[0]
                .iter()
                .map(|p| (*p - c).hypot())
                .fold(f64::INFINITY, f64::min);
            assert!(d < 0.75, "corner {c:?} missed by {d}");
        }
        // Inside test: the pixel centres of the square, and only them.
        let ins = inside(40, 40, &loops);
        for y in 0..40 {
            for x in 0..40 {
                assert_eq!(ins.get(x, y), cov.get(x, y) == 1.0, "{x},{y}");
            }
        }
    }

    /// A dot of 2×2 pixels, and a hole of 2×2 pixels, stay about a pixel
    /// round (relaxing alone would shrink the dot to a speck no cubic can
    /// fit, traced as polygon segments a tenth of a pixel long).
    #[test]
    fn small_dots_and_holes_keep_their_size() {
        let dot: Coverage = Grid::from_fn(10, 10, |x, y| {
            if (4..6).contains(&x) && (4..6).contains(&y) {
                1.0
            } else {
                0.0
            }
        });
        let hole: Coverage = dot.map(|c| if c > 0.5 { 0.0 } else { 1.0 });
        for (name, cov) in [("dot", dot), ("hole", hole)] {
            let loops = smooth_loops(&cov);
            let small = loops
                .iter()
                .find(|l| l.points.iter().all(|p| (p.x - 5.0).abs() < 2.0))
                .unwrap_or_else(|| panic!("{name}: no loop round the centre"));
            let r: Vec<f64> = small
                .points
                .iter()
                .map(|p| (p.x - 5.0).hypot(p.y - 5.0))
                .collect();
            let min = r.iter().cloned().fold(f64::INFINITY, f64::min);
            let max = r.iter().cloned().fold(0.0, f64::max);
            assert!(min > 0.8 && max < 1.3, "{name}: radius {min:.2}..{max:.2}");
        }
    }
}
