//! The signed distance field: distances in pixels at pixel centres, negative
//! inside ink, with the transform back to the input's units.
//!
//! DecoBrush §4.1 thickens lines and adds gradient information by working on
//! an SDF and thresholds it at the end; flourish builds its SDFs with
//! sub-pixel accuracy so the zero level set is the true outline:
//!
//! * from a vector outline ([`Sdf::from_segments`]): exact distance to the
//!   outline's segments in a band around it, inside/outside from the fill;
//! * from anti-aliased coverage ([`Sdf::from_coverage`]): each partially
//!   covered pixel is modelled as cut by a straight edge whose normal is the
//!   coverage gradient and whose offset reproduces the pixel's area coverage
//!   (the anti-aliased EDT of Gustavson & Strand 2011, derived in
//!   [`edge_offset`]); the edge crossings on the links between pixel centres
//!   form a sub-pixel polygon, and the SDF is the exact distance to it. On
//!   binary input, where coverage carries no sub-pixel information, the
//!   polygon vertices are smoothed along their links (never leaving them, so
//!   the topology of the bitmap is kept).
//!
//! Far from the outline (beyond [`BAND`] px) distances come from the exact
//! Euclidean distance transform to the nearest pixel of the other side,
//! which is accurate to half a pixel — the tracer only reads the band.

use super::edt::{squared_edt, FAR};
use super::{Coverage, Grid};
use crate::raster::contour::{self, clamp_t, Link};
use kurbo::{Affine, Line, Point, Vec2};
use rayon::prelude::*;

/// Half-width in pixels of the band around the outline where distances are
/// exact.
pub const BAND: f32 = 3.0;

/// The magnitude of an ink sample whose edge passes through its centre
/// (coverage exactly ½): small enough not to move the outline (contour
/// vertices are clamped 0.001 px from samples anyway), large enough to keep
/// the sample on the ink side of `v < 0`.
pub const MIN_INSIDE: f32 = 1e-3;

/// Slack, pixels, by which the exact band's scan passes [`BAND`]: more
/// than an `f32` rounding of a distance near it.
const SPARE: f64 = 1e-3;

/// A signed distance field: one layer of ink as distances (px) at pixel
/// centres, negative inside, plus the map from pixel coordinates to the
/// input's user units.
#[derive(Clone, Debug)]
pub struct Sdf {
    /// Signed distance in pixels at each pixel centre; negative inside ink.
    pub dist: Grid<f32>,
    /// Maps pixel coordinates (pixel centres at half-integers) to user units.
    pub to_user: Affine,
}

impl Sdf {
    /// Width in pixels.
    pub fn width(&self) -> usize {
        self.dist.width()
    }

    /// Height in pixels.
    pub fn height(&self) -> usize {
        self.dist.height()
    }

    /// Pixels per user unit (the scale of [`Sdf::to_user`] inverted).
    pub fn px_per_unit(&self) -> f64 {
        let det = self.to_user.determinant().abs();
        if det > 0.0 {
            1.0 / det.sqrt()
        } else {
            1.0
        }
    }

    /// Bilinearly interpolated distance at a pixel-space point.
    pub fn value(&self, p: Point) -> f64 {
        self.dist.sample(p.x, p.y) as f64
    }

    /// Gradient of the distance (pointing away from ink) at a pixel-space
    /// point, by central differences of the interpolated field.
    pub fn gradient(&self, p: Point) -> Vec2 {
        let h = 0.5;
        let gx = self.dist.sample(p.x + h, p.y) - self.dist.sample(p.x - h, p.y);
        let gy = self.dist.sample(p.x, p.y + h) - self.dist.sample(p.x, p.y - h);
        Vec2::new(gx as f64, gy as f64) / (2.0 * h)
    }

    /// The SDF of the outline made of `segments` (pixel coordinates), with
    /// `inside` telling which pixel centres are ink. Exact within [`BAND`].
    pub fn from_segments(inside: &Grid<bool>, segments: &[Line], to_user: Affine) -> Sdf {
        Sdf {
            dist: distance_to_segments(inside, segments),
            to_user,
        }
    }

    /// The SDF of anti-aliased (or binary) coverage, with sub-pixel edges
    /// recovered from the coverage values, thin lines read as one interval
    /// of ink across their run ([`subpixel_outline`]); see the module docs.
    pub fn from_coverage(cov: &Coverage, to_user: Affine) -> Sdf {
        Self::from_outline(cov, to_user, true)
    }

    /// The SDF of a clamped distance ramp `cov = clamp(½ − d, 0, 1)` (what
    /// re-measuring an SDF through coverage gives): each link's edge read
    /// on its own. Such a ramp is not an area, so the thin-run reading of
    /// [`Sdf::from_coverage`], which sums a run's coverage into a line's
    /// width, does not apply to it.
    pub fn from_distance_ramp(cov: &Coverage, to_user: Affine) -> Sdf {
        Self::from_outline(cov, to_user, false)
    }

    /// The SDF of [`outline_polygons`]' outline, signed by the same inside.
    fn from_outline(cov: &Coverage, to_user: Affine, thin_runs: bool) -> Sdf {
        let (inside, polygons) = outline_polygons(cov, thin_runs);
        let mut segments = Vec::new();
        for poly in &polygons {
            let n = poly.len();
            for i in 0..n {
                segments.push(Line::new(poly[i], poly[(i + 1) % n]));
            }
        }
        Sdf::from_segments(&inside, &segments, to_user)
    }
}

/// The part of `l` inside `r` (Liang–Barsky: the parameter interval where
/// all four half-plane conditions hold), or `None` when it misses `r`.
/// A clipped end is put on the boundary it was clipped at, exactly, so a
/// segment with coordinates of 10³⁰ still clips to the right place.
fn clip_line(l: Line, r: kurbo::Rect) -> Option<Line> {
    if !(l.p0.is_finite() && l.p1.is_finite()) {
        return None;
    }
    let d = l.p1 - l.p0;
    // Each end: its parameter and, when clipped, the boundary (axis, value).
    let (mut t0, mut t1) = ((0.0f64, None), (1.0f64, None));
    for (p, q, axis, bound) in [
        (-d.x, l.p0.x - r.x0, 0, r.x0),
        (d.x, r.x1 - l.p0.x, 0, r.x1),
        (-d.y, l.p0.y - r.y0, 1, r.y0),
        (d.y, r.y1 - l.p0.y, 1, r.y1),
    ] {
        if p == 0.0 {
            if q < 0.0 {
                return None;
            }
        } else {
            let t = q / p;
            if p < 0.0 && t > t0.0 {
                t0 = (t, Some((axis, bound)));
            } else if p > 0.0 && t < t1.0 {
                t1 = (t, Some((axis, bound)));
            }
        }
    }
    let at = |edge: Option<(usize, f64)>, end: Point| match edge {
        None => end,
        Some((0, x)) => Point::new(x, l.p0.y + (x - l.p0.x) * (d.y / d.x)),
        Some((_, y)) => Point::new(l.p0.x + (y - l.p0.y) * (d.x / d.y), y),
    };
    (t0.0 <= t1.0).then(|| Line::new(at(t0.1, l.p0), at(t1.1, l.p1)))
}

/// Signed distances to `segments`: exact within [`BAND`], from the EDT
/// beyond; sign from `inside`.
fn distance_to_segments(inside: &Grid<bool>, segments: &[Line]) -> Grid<f32> {
    let (w, h) = (inside.width(), inside.height());
    // Split long segments so each touches a small window of pixels.
    // Only the part of a segment within BAND of the grid can be the nearest
    // one within BAND of a pixel: the rest is clipped away first, so a
    // segment kilometres long costs what its visible part costs.
    let reach = BAND as f64 + 1.0;
    let window = kurbo::Rect::new(-reach, -reach, w as f64 + reach, h as f64 + reach);
    let mut pieces: Vec<Line> = Vec::with_capacity(segments.len());
    for s in segments.iter().filter_map(|s| clip_line(*s, window)) {
        let len = s.length();
        if !len.is_finite() {
            continue;
        }
        let n = (len / 2.0).ceil().max(1.0) as usize;
        for k in 0..n {
            let a = s.p0.lerp(s.p1, k as f64 / n as f64);
            let b = s.p0.lerp(s.p1, (k + 1) as f64 / n as f64);
            pieces.push(Line::new(a, b));
        }
    }
    // Bucket pieces into horizontal strips so strips fill in parallel.
    const STRIP: usize = 16;
    let strips = h.div_ceil(STRIP).max(1);
    let band = BAND as f64;
    let mut buckets: Vec<Vec<u32>> = vec![Vec::new(); strips];
    for (i, l) in pieces.iter().enumerate() {
        let y0 = (l.p0.y.min(l.p1.y) - band - 0.5).floor().max(0.0) as usize / STRIP;
        let y1 =
            ((l.p0.y.max(l.p1.y) + band - 0.5).ceil().max(0.0) as usize / STRIP).min(strips - 1);
        for b in buckets.iter_mut().take(y1 + 1).skip(y0) {
            b.push(i as u32);
        }
    }
    // Least distance per pixel; a segment's square root is taken only
    // when its squared distance is below the square of the one held (an
    // `f32` squared is exact in `f64`, so the test loses nothing).
    let mut near = vec![f32::INFINITY; w * h];
    near.par_chunks_mut(STRIP * w.max(1))
        .enumerate()
        .for_each(|(strip, rows)| {
            let row0 = strip * STRIP;
            let nrows = rows.len() / w.max(1);
            for &i in &buckets[strip] {
                let l = pieces[i as usize];
                let x0 = (l.p0.x.min(l.p1.x) - band - 0.5).floor().max(0.0) as usize;
                let x1 = ((l.p0.x.max(l.p1.x) + band - 0.5).ceil().max(0.0) as usize)
                    .min(w.saturating_sub(1));
                let y0 = ((l.p0.y.min(l.p1.y) - band - 0.5).floor().max(0.0) as usize).max(row0);
                let y1 = ((l.p0.y.max(l.p1.y) + band - 0.5).ceil().max(0.0) as usize)
                    .min(row0 + nrows - 1);
                let d = l.p1 - l.p0;
                let len2 = d.hypot2();
                let (lx0, lx1) = (l.p0.x.min(l.p1.x), l.p0.x.max(l.p1.x));
                let (ly0, ly1) = (l.p0.y.min(l.p1.y), l.p0.y.max(l.p1.y));
                for y in y0..=y1 {
                    // Only distances within BAND are kept (the rest come
                    // from the EDT): a pixel centre farther than BAND from
                    // the segment's bounding box is farther from the
                    // segment, so each row visits the centres within BAND
                    // of the box (with a hair to spare for rounding).
                    let cy = y as f64 + 0.5;
                    let gy = (ly0 - cy).max(cy - ly1).max(0.0);
                    if gy > band + SPARE {
                        continue;
                    }
                    let half = (band * band - gy * gy).max(0.0).sqrt() + SPARE;
                    let xa = ((lx0 - half - 0.5).ceil().max(0.0) as usize).max(x0);
                    let xb = ((lx1 + half - 0.5).floor().max(0.0) as usize).min(x1);
                    if xa > xb {
                        continue;
                    }
                    let row = &mut rows[(y - row0) * w..(y - row0 + 1) * w];
                    for (x, slot) in row.iter_mut().enumerate().take(xb + 1).skip(xa) {
                        let p = Point::new(x as f64 + 0.5, y as f64 + 0.5);
                        let d2 = point_segment_distance2(p, l.p0, d, len2);
                        let held = *slot as f64;
                        if d2 < held * held {
                            let d = d2.sqrt() as f32;
                            if d < *slot {
                                *slot = d;
                            }
                        }
                    }
                }
            }
        });
    let to_out = squared_edt(&inside.map(|i| !i));
    let to_in = squared_edt(inside);
    let data = near
        .par_iter()
        .enumerate()
        .map(|(i, &d)| {
            let is_in = inside.data()[i];
            let far2 = if is_in {
                to_out.data()[i]
            } else {
                to_in.data()[i]
            };
            let mag = if d <= BAND {
                d
            } else if far2 >= FAR {
                // No pixel of the other side anywhere: a blank or full canvas.
                (w.max(h) as f32).max(BAND)
            } else {
                (far2.sqrt() - 0.5).max(BAND)
            };
            if is_in {
                // A pixel at exactly half coverage has its edge through its
                // centre; it is still ink, so its value stays negative.
                -mag.max(MIN_INSIDE)
            } else {
                mag
            }
        })
        .collect();
    Grid::from_vec(w, h, data).expect("sizes match by construction")
}

/// Squared Euclidean distance from `p` to the segment from `p0` along
/// `d` (`len2` = `|d|²`), with the nearest point found as in
/// [`point_segment_distance`].
#[inline]
fn point_segment_distance2(p: Point, p0: Point, d: kurbo::Vec2, len2: f64) -> f64 {
    let t = if len2 > 0.0 {
        ((p - p0).dot(d) / len2).clamp(0.0, 1.0)
    } else {
        0.0
    };
    let e = p - (p0 + d * t);
    e.x * e.x + e.y * e.y
}

/// Euclidean distance from `p` to the segment `l`.
pub fn point_segment_distance(p: Point, l: Line) -> f64 {
    let d = l.p1 - l.p0;
    let len2 = d.hypot2();
    let t = if len2 > 0.0 {
        ((p - l.p0).dot(d) / len2).clamp(0.0, 1.0)
    } else {
        0.0
    };
    (p - l.p0.lerp(l.p1, t)).hypot()
}

/// Coverage below this (or above one minus this) counts as empty (full).
const COVERAGE_EPS: f32 = 0.5 / 255.0;

/// The straight-edge model of one partially covered pixel.
#[derive(Clone, Copy, Debug)]
struct EdgeModel {
    /// Unit normal pointing into the ink.
    n: Vec2,
    /// Signed distance from the pixel centre to the edge, negative when the
    /// centre is inside.
    d: f64,
}

/// The signed distance from a pixel's centre to a straight edge with unit
/// normal `n` (pointing into ink) that covers the fraction `a` of the unit
/// pixel; negative when the centre is inside.
///
/// The projection `u = n·x` of a uniform point in the unit square has a
/// trapezoidal density (the convolution of uniforms of widths `g1 = max|n_i|`
/// and `g2 = min|n_i|`), so the covered area `A(d) = P(u ≥ d)` is quadratic
/// in the two tails and linear in the middle; this inverts it.
pub fn edge_offset(n: Vec2, a: f64) -> f64 {
    let (ax, ay) = (n.x.abs(), n.y.abs());
    let (g1, g2) = if ax >= ay { (ax, ay) } else { (ay, ax) };
    let a = a.clamp(0.0, 1.0);
    if g1 <= 0.0 {
        return 0.5 - a;
    }
    let h = 0.5 * (g1 + g2);
    let a_tail = 0.5 * g2 / g1;
    if a < a_tail {
        h - (2.0 * g1 * g2 * a).sqrt()
    } else if a > 1.0 - a_tail {
        -h + (2.0 * g1 * g2 * (1.0 - a)).sqrt()
    } else {
        g1 * (0.5 - a)
    }
}

/// The edge model of pixel `(x, y)`, when it is partially covered and its
/// coverage gradient is well defined.
/// The unit normal of a straight edge through a pixel, into the ink: the
/// isotropic 3×3 gradient (weights 1, √2, 1) of the coverage `at(dx, dy)`
/// of the pixel's neighbours; `None` where it is flat.
pub fn edge_normal(at: impl Fn(i32, i32) -> f64) -> Option<Vec2> {
    let r2 = std::f64::consts::SQRT_2;
    let gx = at(1, -1) + r2 * at(1, 0) + at(1, 1) - at(-1, -1) - r2 * at(-1, 0) - at(-1, 1);
    let gy = at(-1, 1) + r2 * at(0, 1) + at(1, 1) - at(-1, -1) - r2 * at(0, -1) - at(1, -1);
    let g = Vec2::new(gx, gy);
    let len = g.hypot();
    if len < 1e-3 {
        return None;
    }
    let n = g / len;
    Some(n)
}

fn edge_model(cov: &Coverage, x: i32, y: i32) -> Option<EdgeModel> {
    let c = cov.get_or(x as isize, y as isize, 0.0);
    if !(c > COVERAGE_EPS && c < 1.0 - COVERAGE_EPS) {
        return None;
    }
    // The 3×3 neighbourhood (paper outside the grid), read by row slices
    // away from the border.
    let (w, h) = (cov.width() as i32, cov.height() as i32);
    let mut near = [[0f64; 3]; 3];
    if x >= 1 && y >= 1 && x + 1 < w && y + 1 < h {
        let data = cov.data();
        for (r, dy) in near.iter_mut().zip(-1..=1) {
            let i = ((y + dy) * w + x - 1) as usize;
            if let Some(row) = data.get(i..i + 3) {
                *r = [row[0] as f64, row[1] as f64, row[2] as f64];
            }
        }
    } else {
        for (r, dy) in near.iter_mut().zip(-1..=1) {
            for (v, dx) in r.iter_mut().zip(-1..=1) {
                *v = cov.get_or((x + dx) as isize, (y + dy) as isize, 0.0) as f64;
            }
        }
    }
    let n = edge_normal(|dx, dy| near[(dy + 1) as usize][(dx + 1) as usize])?;
    Some(EdgeModel {
        n,
        d: edge_offset(n, c as f64),
    })
}

/// Where the outline crosses link `l` (first end inside, or second end
/// inside), as a fraction from its first end, and whether coverage informed
/// the estimate.
fn link_crossing(cov: &Coverage, l: Link, thin: Option<(&Grid<bool>, &ThinRuns)>) -> (f64, bool) {
    let ((x0, y0), (x1, y1)) = l.ends();
    let (w, h) = (cov.width() as i32, cov.height() as i32);
    let off = |x: i32, y: i32| x < 0 || y < 0 || x >= w || y >= h;
    if off(x0, y0) || off(x1, y1) {
        return (0.5, true);
    }
    if let Some(t) = thin.and_then(|(inside, runs)| thin_run_crossing(cov, inside, runs, l)) {
        return (clamp_t(t), true);
    }
    let e = l.direction();
    // The ink lies ahead along the link when its second end is inside. An
    // outside pixel whose edge model's normal (into its ink) points back
    // away from the inside end holds the edge of something beyond it, not
    // the one crossed here: read as the dot's, the faint underside of a
    // line a pixel above a dot would put the dot's top at the faint
    // pixel's centre, a spike a pixel long (the 2 Mpx anti-aliased
    // ornament's dotted rings).
    let inside_at = |x: i32, y: i32| {
        thin.map_or(cov.get(x as usize, y as usize) >= 0.5, |(inside, _)| {
            inside.get_or(x as isize, y as isize, false)
        })
    };
    let (in0, in1) = (inside_at(x0, y0), inside_at(x1, y1));
    let ahead = if in1 && !in0 { 1.0 } else { -1.0 };
    let own_edge = |m: &EdgeModel, inside: bool| inside || m.n.dot(e) * ahead > -0.5;
    let m0 = edge_model(cov, x0, y0).filter(|m| own_edge(m, in0));
    let m1 = edge_model(cov, x1, y1).filter(|m| own_edge(m, in1));
    let oblique = |m: &EdgeModel| m.n.dot(e).abs() > 0.2;
    let t = match (m0, m1) {
        (Some(a), Some(b)) if a.d * b.d <= 0.0 && a.d != b.d => Some(a.d / (a.d - b.d)),
        (Some(a), _) if oblique(&a) => Some(a.d / a.n.dot(e)),
        (_, Some(b)) if oblique(&b) => Some(1.0 + b.d / b.n.dot(e)),
        _ => None,
    };
    match t {
        Some(t) if t.is_finite() => (clamp_t(t), true),
        _ => {
            // One-dimensional mass balance: along a link the ink of both
            // pixels, less the half pixel up to the first centre, is the
            // edge's distance from the inside centre.
            let c0 = cov.get(x0 as usize, y0 as usize) as f64;
            let c1 = cov.get(x1 as usize, y1 as usize) as f64;
            let t = if c0 >= 0.5 {
                c0 - 0.5 + c1
            } else {
                1.0 - (c1 - 0.5 + c0)
            };
            (clamp_t(t), c0 > 0.0 && c0 < 1.0 || c1 > 0.0 && c1 < 1.0)
        }
    }
}

/// Longest run of inked pixels (px) read as a thin line by
/// [`thin_run_crossing`].
const THIN_RUN: i32 = 3;

/// Where the outline crosses link `l` when the link lies across a thin line:
/// along the link's axis, a run of at most [`THIN_RUN`] inked pixels with
/// paper on both sides. One straight edge per pixel (the edge model) cannot
/// describe such a run: a hairline straddling two rows covers each half
/// (the model puts both its edges at the rows' centres, half its width),
/// and a diagonal 1-px line's pixels hold parts of both its edges (the
/// model loses 10–15 % of its weight). Read along the axis, the ink is one
/// interval, and each end pixel's coverage says how far into it the
/// interval reaches: `[first + ½ − c_first, last − ½ + c_last]`, so the
/// interval holds exactly the run's ink. Returns the fraction of the link
/// from its first end, or `None` when the link is not across a thin run.
fn thin_run_crossing(cov: &Coverage, inside: &Grid<bool>, runs: &ThinRuns, l: Link) -> Option<f64> {
    let ((x0, y0), (x1, y1)) = l.ends();
    let (dx, dy) = if l.horizontal { (1, 0) } else { (0, 1) };
    // The run through the inside end; steps counted from the first end.
    let in0 = inside.get_or(x0 as isize, y0 as isize, false);
    let (x, y, shift) = if in0 { (x0, y0, 0) } else { (x1, y1, 1) };
    let (first, last) = runs.get(
        usize::try_from(x).ok()?,
        usize::try_from(y).ok()?,
        l.horizontal,
    )?;
    let c_first = f64::from(coverage_at(cov, x + first * dx, y + first * dy));
    let c_last = f64::from(coverage_at(cov, x + last * dx, y + last * dy));
    let (first, last) = (f64::from(first + shift), f64::from(last + shift));
    let (lo, hi) = if first == last {
        // One pixel: the interval is centred on it.
        (first - 0.5 * c_first, first + 0.5 * c_first)
    } else {
        (first + 0.5 - c_first, last - 0.5 + c_last)
    };
    // Ink up to hi and paper after when the first end is inside; else the
    // crossing is where the ink starts.
    Some(if in0 { hi } else { lo })
}

/// Coverage of pixel `(x, y)`, paper outside the grid.
fn coverage_at(cov: &Coverage, x: i32, y: i32) -> f32 {
    cov.get_or(x as isize, y as isize, 0.0)
}

/// The run of inked pixels along the axis `(dx, dy)` through pixel
/// `(x, y)`, as steps from it `(first ≤ 0, last ≥ 0)`, when it is thin: at
/// most [`THIN_RUN`] pixels, paper (or the outside of the grid) at both
/// ends.
#[cfg(test)]
fn thin_run(cov: &Coverage, x: i32, y: i32, dx: i32, dy: i32) -> Option<(i32, i32)> {
    let inked = |j: i32| coverage_at(cov, x + j * dx, y + j * dy) > COVERAGE_EPS;
    if !inked(0) {
        return None;
    }
    let (mut first, mut last) = (0, 0);
    while last - first < THIN_RUN && inked(last + 1) {
        last += 1;
    }
    while last - first < THIN_RUN && inked(first - 1) {
        first -= 1;
    }
    (last - first < THIN_RUN && !inked(last + 1) && !inked(first - 1)).then_some((first, last))
}

/// The thin run through every pixel along each pixel axis (a run of at
/// most [`THIN_RUN`] inked pixels, paper or the grid's outside at both
/// ends), found for all pixels in one pass along the rows and one down the
/// columns, rather than walked out from every pixel (which costs a large
/// share of a trace). The walk is kept as the tests' oracle.
struct ThinRuns {
    width: usize,
    /// Per pixel: its run along x, if thin, packed by [`ThinRuns::pack`]
    /// (0 for none: the buffers start zeroed, which the allocator hands out
    /// untouched, and only the pages holding a thin run are written).
    along_x: Vec<u8>,
    /// The same along y.
    along_y: Vec<u8>,
}

impl ThinRuns {
    /// A run as steps `(first ≤ 0, last ≥ 0)` from a pixel, at most
    /// [`THIN_RUN`] long, as one byte: `1 + 3·(−first) + last`.
    fn pack(first: usize, last: usize) -> u8 {
        (1 + 3 * first + last) as u8
    }

    fn new(cov: &Coverage) -> Self {
        let (w, h) = (cov.width(), cov.height());
        let inked = |c: f32| c > COVERAGE_EPS;
        // Every maximal run of inked pixels at most THIN_RUN long, given by
        // its first index and length, marks each of its pixels.
        let mark = |out: &mut dyn FnMut(usize, u8), start: usize, len: usize| {
            if len as i32 <= THIN_RUN {
                for k in 0..len {
                    out(start + k, Self::pack(k, len - 1 - k));
                }
            }
        };
        let mut along_x = vec![0u8; w * h];
        along_x
            .par_chunks_mut(w.max(1))
            .zip(cov.data().par_chunks(w.max(1)))
            .for_each(|(out, row)| {
                let mut start = None;
                for x in 0..=w {
                    let ink = row.get(x).is_some_and(|&c| inked(c));
                    match (ink, start) {
                        (true, None) => start = Some(x),
                        (false, Some(s)) => {
                            mark(&mut |i, r| out[i] = r, s, x - s);
                            start = None;
                        }
                        _ => {}
                    }
                }
            });
        // Columns: each column's open run carried down the rows.
        let mut along_y = vec![0u8; w * h];
        let mut start: Vec<Option<usize>> = vec![None; w];
        for y in 0..=h {
            for (x, st) in start.iter_mut().enumerate() {
                let ink = y < h && inked(cov.get(x, y));
                match (ink, *st) {
                    (true, None) => *st = Some(y),
                    (false, Some(s)) => {
                        mark(&mut |j, r| along_y[j * w + x] = r, s, y - s);
                        *st = None;
                    }
                    _ => {}
                }
            }
        }
        ThinRuns {
            width: w,
            along_x,
            along_y,
        }
    }

    /// The thin run through pixel `(x, y)` along x (`along_x`) or y, as
    /// steps from it `(first ≤ 0, last ≥ 0)`.
    fn get(&self, x: usize, y: usize, along_x: bool) -> Option<(i32, i32)> {
        let runs = if along_x {
            &self.along_x
        } else {
            &self.along_y
        };
        match runs.get(y * self.width + x).copied() {
            None | Some(0) => None,
            Some(c) => {
                let c = i32::from(c) - 1;
                Some((-(c / 3), c % 3))
            }
        }
    }
}

/// The ink (px) of the thin runs pixel `(x, y)` lies in (the most over
/// the two pixel axes; a run of at most [`THIN_RUN`] inked pixels between
/// paper), and whether it is a ridge: it carries a thin line no pixel of
/// which is half covered, the run's ink being at least one half and this
/// its most covered pixel (the first of equals). A 1-px line straddling
/// two rows at 8-bit precision covers each 127/255: thresholded at one
/// half it vanishes, and a wave drawn with it breaks at every trough. A
/// ridge counts as ink, and [`thin_run_crossing`] then places the line's
/// edges by its run's ink.
fn thin_mass(cov: &Coverage, runs: &ThinRuns, x: usize, y: usize) -> (f32, bool) {
    let (mut best, mut ridge) = (0.0f32, false);
    for (along_x, (dx, dy)) in [(true, (1, 0)), (false, (0, 1))] {
        let Some((first, last)) = runs.get(x, y, along_x) else {
            continue;
        };
        let at = |j: i32| coverage_at(cov, x as i32 + j * dx, y as i32 + j * dy);
        // In order along the run, as the sum and the first maximum are
        // defined.
        let (mut most, mut mass, mut first_most) = (f32::NEG_INFINITY, 0.0f32, first);
        for j in first..=last {
            let c = at(j);
            mass += c;
            if c > most {
                most = c;
                first_most = j;
            }
        }
        best = best.max(mass);
        // This pixel is the first of the most covered.
        ridge |= most < 0.5 && mass >= 0.5 && first_most == 0;
    }
    (best, ridge)
}

/// Rounds of constrained smoothing for vertices that coverage did not place.
const SMOOTHING_ROUNDS: usize = 12;

/// The sub-pixel outline of coverage `cov` as closed polygons in pixel
/// coordinates: one vertex per crossed link (the marching-squares topology
/// of `cov ≥ 0.5`), placed by the edge model, or smoothed along its link
/// where the coverage is binary.
pub fn subpixel_outline(cov: &Coverage) -> Vec<Vec<Point>> {
    outline_polygons(cov, true).1
}

/// Which pixel centres are inside, and the closed polygons of
/// [`subpixel_outline`], reading thin runs across links as thin lines
/// ([`thin_run_crossing`]) when `thin_runs` (a ridge pixel of a hairline is
/// then inside although its coverage is under one half).
fn outline_polygons(cov: &Coverage, thin_runs: bool) -> (Grid<bool>, Vec<Vec<Point>>) {
    // Marching squares on 0.5 − coverage, inside where negative; reading
    // thin runs, a pixel of a thin line counts as covered by its run's
    // whole ink (so a ridge pixel is inside, and the two pixels of a
    // diagonal step of a hairline join at their saddle).
    let runs = thin_runs.then(|| ThinRuns::new(cov));
    let w = cov.width();
    let mut values = vec![0.0f32; w * cov.height()];
    values
        .par_chunks_mut(w.max(1))
        .zip(cov.data().par_chunks(w.max(1)))
        .enumerate()
        .for_each(|(y, (row, cov_row))| {
            for (x, (v, &c)) in row.iter_mut().zip(cov_row).enumerate() {
                let (mass, ridge) = match &runs {
                    Some(r) if c > COVERAGE_EPS => thin_mass(cov, r, x, y),
                    _ => (0.0, false),
                };
                *v = if c >= 0.5 || ridge {
                    -(c.max(mass) - 0.5).max(1e-6)
                } else {
                    0.5 - c
                };
            }
        });
    let values =
        Grid::from_vec(w, cov.height(), values).unwrap_or_else(|| Grid::new(w, cov.height(), 0.0));
    let inside = values.map(|v| v < 0.0);
    let thin = runs.as_ref().map(|r| (&inside, r));
    let contours = contour::extract(&values);
    let polygons = contours
        .par_iter()
        .map(|c| {
            let est: Vec<(f64, bool)> = c
                .links
                .iter()
                .map(|&l| link_crossing(cov, l, thin))
                .collect();
            let mut t: Vec<f64> = est.iter().map(|e| e.0).collect();
            let n = t.len();
            if est.iter().any(|e| !e.1) {
                for _ in 0..SMOOTHING_ROUNDS {
                    let pts: Vec<Point> =
                        c.links.iter().zip(&t).map(|(l, &t)| l.point(t)).collect();
                    let mut next = t.clone();
                    for i in 0..n {
                        if est[i].1 {
                            continue;
                        }
                        let mid = pts[(i + n - 1) % n].midpoint(pts[(i + 1) % n]);
                        let l = c.links[i];
                        let t_mid = (mid - l.point(0.0)).dot(l.direction());
                        next[i] = t_mid.clamp(0.05, 0.95);
                    }
                    t = next;
                }
            }
            c.links.iter().zip(&t).map(|(l, &t)| l.point(t)).collect()
        })
        .collect();
    (inside, polygons)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The runs found in one pass per axis are the runs walked out from
    /// each pixel, on random grids of sparse strokes (runs of every length
    /// up to past [`THIN_RUN`], touching the grid's edges).
    #[test]
    fn thin_runs_match_the_walk_from_each_pixel() {
        let mut state = 99u64;
        let mut rnd = || {
            state = state
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            (state >> 33) as f64 / (1u64 << 31) as f64
        };
        for trial in 0..40 {
            let (w, h) = (1 + trial % 13, 1 + (trial * 7) % 11);
            let density = 0.2 + 0.6 * rnd();
            let cov = Grid::from_fn(w, h, |_, _| {
                if rnd() < density {
                    (rnd() as f32).max(0.01)
                } else {
                    0.0
                }
            });
            let runs = ThinRuns::new(&cov);
            for y in 0..h {
                for x in 0..w {
                    for (along_x, (dx, dy)) in [(true, (1, 0)), (false, (0, 1))] {
                        assert_eq!(
                            runs.get(x, y, along_x),
                            thin_run(&cov, x as i32, y as i32, dx, dy),
                            "{w}x{h} pixel ({x}, {y}) along x: {along_x}"
                        );
                    }
                }
            }
        }
    }

    /// A dot a pixel below a thin line (the 2 Mpx anti-aliased ornament's
    /// dotted ring, as rendered): the faint pixel between them holds the
    /// line's underside, and its edge model faces the line; read as the
    /// dot's, it would put the dot's top at that pixel's centre, a spike a
    /// pixel long. The dot's outline stays on its own side of the gap, and
    /// the line's underside where it is.
    #[test]
    fn a_dot_under_a_line_is_not_drawn_up_to_it() {
        // Darkness 0..=255, rows 3..=11 of columns 5..=14 of the render.
        let rows: [[u8; 10]; 9] = [
            [0, 0, 0, 0, 0, 0, 0, 0, 0, 0],
            [0, 0, 0, 0, 0, 0, 0, 0, 0, 0],
            [0, 0, 0, 0, 0, 0, 0, 16, 63, 63],
            [48, 95, 127, 191, 223, 255, 255, 255, 224, 192],
            [224, 192, 128, 80, 48, 0, 0, 0, 0, 0],
            [0, 0, 0, 32, 127, 32, 0, 0, 0, 0],
            [0, 0, 0, 192, 255, 176, 0, 0, 0, 0],
            [0, 0, 0, 144, 255, 112, 0, 0, 0, 0],
            [0, 0, 0, 0, 0, 0, 0, 0, 0, 0],
        ];
        let cov = Grid::from_fn(10, 9, |x, y| f32::from(rows[y][x]) / 255.0);
        let polys = subpixel_outline(&cov);
        // The dot: the loop whose points all lie below the line's rows.
        let dot = polys
            .iter()
            .find(|p| p.iter().all(|q| q.y > 4.5))
            .expect("the dot is a loop of its own");
        let top = dot.iter().map(|q| q.y).fold(f64::INFINITY, f64::min);
        // Its top pixel (column 4, row 5) is half covered: the top edge is
        // near that pixel's centre (y = 5.5), not at the faint pixel's (4.5).
        assert!(top > 5.2, "dot's top at y = {top:.2}");
        // The line's underside over the dot stays a pixel above it.
        let line = polys
            .iter()
            .find(|p| p.iter().any(|q| q.y < 3.5))
            .expect("the line");
        let under = line
            .iter()
            .filter(|q| (q.x - 4.5).abs() < 0.01 && q.y > 3.5)
            .map(|q| q.y)
            .fold(f64::NEG_INFINITY, f64::max);
        assert!(
            (under - 4.1).abs() < 0.2,
            "line's underside at y = {under:.2}"
        );
    }

    #[test]
    fn clip_line_keeps_exactly_the_part_inside() {
        // Against sampling: a point of the segment is inside the rectangle
        // exactly when it lies on the clipped piece.
        let r = kurbo::Rect::new(-2.0, -1.0, 10.0, 7.0);
        let mut state = 12345u64;
        let mut rnd = || {
            state = state
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            ((state >> 11) as f64 / (1u64 << 53) as f64) * 30.0 - 10.0
        };
        for _ in 0..500 {
            let l = Line::new((rnd(), rnd()), (rnd(), rnd()));
            let c = clip_line(l, r);
            for k in 0..=200 {
                let p = l.p0.lerp(l.p1, k as f64 / 200.0);
                let inside = r.x0 <= p.x && p.x <= r.x1 && r.y0 <= p.y && p.y <= r.y1;
                let on = c.is_some_and(|c| point_segment_distance(p, c) < 1e-9);
                assert_eq!(inside, on, "{l:?} clipped to {c:?} at {p:?}");
            }
        }
        // Kilometres long and NaN.
        let far = Line::new((-1e30, 3.0), (1e30, 3.0));
        let c = clip_line(far, r).unwrap();
        assert!(
            (c.p0.x + 2.0).abs() < 1e-6 && (c.p1.x - 10.0).abs() < 1e-6,
            "{c:?}"
        );
        assert!(clip_line(Line::new((f64::NAN, 0.0), (1.0, 1.0)), r).is_none());
    }

    #[test]
    fn a_segment_far_longer_than_the_grid_costs_only_its_visible_part() {
        // One edge of a triangle 10¹² px tall; the exact distances near the
        // visible edge are those of the unclipped line.
        let inside = Grid::from_fn(16, 16, |x, _| x < 8);
        let segs = [Line::new((8.0, -1e12), (8.0, 1e12))];
        let sdf = Sdf::from_segments(&inside, &segs, Affine::IDENTITY);
        for y in 0..16 {
            for x in 0..16 {
                let want = (x as f32 + 0.5 - 8.0).min(BAND + 1.0);
                let got = sdf.dist.get(x, y);
                if want.abs() <= BAND {
                    assert!((got - want).abs() < 1e-4, "({x}, {y}): {got} vs {want}");
                }
            }
        }
    }

    /// Exact area coverage of a shape by 16×16 supersampling.
    fn coverage(w: usize, h: usize, inside: impl Fn(f64, f64) -> bool + Sync) -> Coverage {
        Grid::from_fn(w, h, |x, y| {
            let mut n = 0;
            for j in 0..16 {
                for i in 0..16 {
                    let px = x as f64 + (i as f64 + 0.5) / 16.0;
                    let py = y as f64 + (j as f64 + 0.5) / 16.0;
                    n += inside(px, py) as u32;
                }
            }
            n as f32 / 256.0
        })
    }

    fn max_error_near_boundary(sdf: &Sdf, truth: impl Fn(f64, f64) -> f64) -> f64 {
        let mut worst: f64 = 0.0;
        for y in 0..sdf.height() {
            for x in 0..sdf.width() {
                let (px, py) = (x as f64 + 0.5, y as f64 + 0.5);
                let t = truth(px, py);
                if t.abs() <= 2.0 {
                    worst = worst.max((sdf.dist.get(x, y) as f64 - t).abs());
                }
            }
        }
        worst
    }

    #[test]
    fn edge_offset_matches_supersampled_half_planes() {
        for k in 0..24 {
            let ang = k as f64 * 0.2618 + 0.05;
            let n = Vec2::new(ang.cos(), ang.sin());
            for j in 0..9 {
                let d = -0.6 + j as f64 * 0.15;
                // Area of {n·x ≥ d} in the unit square centred at 0.
                let mut cnt = 0u32;
                let m = 200;
                for a in 0..m {
                    for b in 0..m {
                        let x = Vec2::new(
                            (a as f64 + 0.5) / m as f64 - 0.5,
                            (b as f64 + 0.5) / m as f64 - 0.5,
                        );
                        cnt += (n.dot(x) >= d) as u32;
                    }
                }
                let area = cnt as f64 / (m * m) as f64;
                if area > 0.001 && area < 0.999 {
                    let got = edge_offset(n, area);
                    assert!((got - d).abs() < 0.01, "angle {ang} d {d}: got {got}");
                }
            }
        }
    }

    #[test]
    fn disc_from_coverage_within_a_tenth() {
        let (cx, cy, r) = (20.3, 19.7, 11.4);
        let cov = coverage(40, 40, |x, y| (x - cx).hypot(y - cy) <= r);
        let sdf = Sdf::from_coverage(&cov, Affine::IDENTITY);
        let err = max_error_near_boundary(&sdf, |x, y| (x - cx).hypot(y - cy) - r);
        assert!(err <= 0.1, "max error {err}");
    }

    #[test]
    fn rectangle_from_coverage_within_a_tenth() {
        let (x0, y0, x1, y1) = (6.3, 5.8, 30.55, 21.2);
        let cov = coverage(36, 28, |x, y| x >= x0 && x <= x1 && y >= y0 && y <= y1);
        let sdf = Sdf::from_coverage(&cov, Affine::IDENTITY);
        let truth = |x: f64, y: f64| {
            let dx = (x0 - x).max(x - x1);
            let dy = (y0 - y).max(y - y1);
            if dx <= 0.0 && dy <= 0.0 {
                dx.max(dy)
            } else {
                dx.max(0.0).hypot(dy.max(0.0))
            }
        };
        // Corners are rounded by any per-pixel edge model; the requirement is
        // measured along the sides, away from the four corner pixels.
        let mut worst: f64 = 0.0;
        for y in 0..28 {
            for x in 0..36 {
                let (px, py) = (x as f64 + 0.5, y as f64 + 0.5);
                let near_corner = [(x0, y0), (x1, y0), (x0, y1), (x1, y1)]
                    .iter()
                    .any(|&(cx, cy)| (px - cx).hypot(py - cy) < 2.5);
                let t = truth(px, py);
                if t.abs() <= 2.0 && !near_corner {
                    worst = worst.max((sdf.dist.get(x, y) as f64 - t).abs());
                }
            }
        }
        assert!(worst <= 0.1, "max error {worst}");
    }

    #[test]
    fn ring_from_coverage_within_a_tenth() {
        let (cx, cy) = (24.6, 25.2);
        let cov = coverage(50, 50, |x, y| {
            let r = (x - cx).hypot(y - cy);
            (8.3..=19.1).contains(&r)
        });
        let sdf = Sdf::from_coverage(&cov, Affine::IDENTITY);
        let err = max_error_near_boundary(&sdf, |x, y| {
            let r = (x - cx).hypot(y - cy);
            (r - 19.1).max(8.3 - r)
        });
        assert!(err <= 0.1, "max error {err}");
    }

    #[test]
    fn disc_from_segments_is_exact() {
        let (cx, cy, r) = (15.2, 14.9, 9.3);
        let n = 720;
        let pts: Vec<Point> = (0..n)
            .map(|i| {
                let a = i as f64 / n as f64 * std::f64::consts::TAU;
                Point::new(cx + r * a.cos(), cy + r * a.sin())
            })
            .collect();
        let segs: Vec<Line> = (0..n)
            .map(|i| Line::new(pts[i], pts[(i + 1) % n]))
            .collect();
        let inside = Grid::from_fn(30, 30, |x, y| {
            (x as f64 + 0.5 - cx).hypot(y as f64 + 0.5 - cy) <= r
        });
        let sdf = Sdf::from_segments(&inside, &segs, Affine::IDENTITY);
        let err = max_error_near_boundary(&sdf, |x, y| (x - cx).hypot(y - cy) - r);
        assert!(err <= 0.01, "max error {err}");
    }

    #[test]
    fn binary_staircase_is_smoothed_within_its_links() {
        // A binary half-plane with slope 1/4: the smoothed outline must be
        // close to the true line, closer than the raw midpoint polygon.
        let f = |x: f64, y: f64| y - (10.0 + 0.25 * x);
        let cov = Grid::from_fn(40, 30, |x, y| {
            if f(x as f64 + 0.5, y as f64 + 0.5) >= 0.0 {
                1.0
            } else {
                0.0
            }
        });
        let polys = subpixel_outline(&cov);
        assert_eq!(polys.len(), 1);
        let len = (1.0f64 + 0.0625).sqrt();
        let worst = polys[0]
            .iter()
            .filter(|p| p.x > 3.0 && p.x < 37.0 && p.y > 1.0 && p.y < 29.0)
            .map(|p| f(p.x, p.y).abs() / len)
            .fold(0.0, f64::max);
        assert!(worst < 0.3, "worst {worst}");
    }

    /// A horizontal band from y = `top` to `bottom` (px), x from 4 to 36,
    /// as exact area coverage on a 40 × 16 grid.
    fn band(top: f64, bottom: f64) -> Coverage {
        Grid::from_fn(40, 16, |x, y| {
            let (y0, y1) = (y as f64, y as f64 + 1.0);
            let v = (y1.min(bottom) - y0.max(top)).max(0.0);
            if (4..36).contains(&x) {
                v as f32
            } else {
                0.0
            }
        })
    }

    /// Hairlines keep their weight: the sub-pixel outline of an
    /// anti-aliased line 1, 1.5 or 2 px wide, at any offset against the
    /// pixel rows (a 1-px line straddling two rows covers each half), has
    /// the line's edges within 0.05 px.
    #[test]
    fn thin_lines_keep_their_width() {
        for width in [1.0, 1.5, 2.0] {
            for offset in [0.0, 0.25, 0.5, 0.75] {
                let top = 6.0 + offset;
                let cov = band(top, top + width);
                let loops = subpixel_outline(&cov);
                assert_eq!(loops.len(), 1, "width {width} offset {offset}");
                // Away from the ends, the outline's points lie on the two
                // edges.
                for p in loops[0].iter().filter(|p| (8.0..32.0).contains(&p.x)) {
                    let d = (p.y - top).abs().min((p.y - top - width).abs());
                    assert!(d < 0.05, "width {width} offset {offset}: {p:?}");
                }
            }
        }
    }

    /// A 1-px line straddling two rows at 8-bit precision (127/255 =
    /// 0.498 each, so neither pixel is half covered) is still a line: one
    /// loop with its edges on the rows' outer halves; and the same line
    /// stepping down a row halfway stays one loop (the diagonal step of a
    /// hairline joins at its saddle).
    #[test]
    fn a_hairline_under_half_coverage_stays_whole() {
        let c = 1.0 - 128.0 / 255.0;
        let straight = Grid::from_fn(40, 16, |x, y| {
            if (4..36).contains(&x) && (y == 6 || y == 7) {
                c
            } else {
                0.0
            }
        });
        let loops = subpixel_outline(&straight);
        assert_eq!(loops.len(), 1);
        for p in loops[0].iter().filter(|p| (8.0..32.0).contains(&p.x)) {
            let d = (p.y - 6.5).abs().min((p.y - 7.5).abs());
            assert!(d < 0.05, "{p:?}");
        }
        let stepped = Grid::from_fn(40, 16, |x, y| {
            let top = if x < 20 { 6 } else { 7 };
            if (4..36).contains(&x) && (y == top || y == top + 1) {
                c
            } else {
                0.0
            }
        });
        assert_eq!(subpixel_outline(&stepped).len(), 1);
        // The SDF keeps it: negative all along the line (the ridge pixels
        // are inside, as the outline has them; read edge by edge, no pixel
        // of it would be). Its zero level may still part at the step: the
        // line's edges pass through the pixel centres there, and a field
        // sampled at the centres cannot say more.
        let sdf = Sdf::from_coverage(&stepped, Affine::IDENTITY);
        for x in 5..35 {
            let ink = (0..16).map(|y| sdf.dist.get(x, y)).fold(f32::MAX, f32::min);
            assert!(ink < 0.0, "column {x}: nearest {ink}");
        }
    }

    /// [`Sdf::from_distance_ramp`] reads a clamped distance as distance:
    /// the ramp of a 1.5-px band's exact SDF gives the band back within a
    /// tenth of a pixel.
    #[test]
    fn a_distance_ramp_gives_its_distance_back() {
        let (top, bottom) = (6.3, 7.8);
        let d = |y: f64| (top - y).max(y - bottom);
        let ramp = Grid::from_fn(40, 16, |x, y| {
            let yc = y as f64 + 0.5;
            let dx = (4.0 - (x as f64 + 0.5)).max(x as f64 + 0.5 - 36.0);
            (0.5 - d(yc).max(dx)).clamp(0.0, 1.0) as f32
        });
        let sdf = Sdf::from_distance_ramp(&ramp, Affine::IDENTITY);
        for x in 8..32 {
            for y in 4..10 {
                let want = d(y as f64 + 0.5);
                let got = f64::from(sdf.dist.get(x, y));
                assert!((got - want).abs() < 0.1, "({x}, {y}): {got} vs {want}");
            }
        }
    }
}
