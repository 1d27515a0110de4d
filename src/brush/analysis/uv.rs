//! The uv parameterization of an exemplar stroke (DecoBrush §4.2–4.3,
//! following Lu et al. 2013): samples along the spine, each with a left and
//! a right outline point, and the per-pixel stroking orientation.
//!
//! * **Ribs.** The spine is resampled by arc length into 30–100 samples;
//!   at each one the rib runs along the spine's normal out to the farthest
//!   place where ink ends on that side (sphere tracing the ink's SDF, with
//!   sub-pixel crossings), as long as the point is still nearer to this
//!   sample's part of the spine than to any other (so ribs on the inside of
//!   a curl do not reach across into the next turn). A median of three
//!   neighbouring ribs removes single-sample spikes. The rib length is the
//!   stroke's local width.
//! * **Orientation.** The spine's orientation at sample `i` is
//!   `x̂_i − x̂_{i−1}`, the outline's is `⊥(l̂_i − x̂_i)` and `⊥(r̂_i − x̂_i)`
//!   turned to point along the stroke; each rib quad is split into
//!   triangles and the orientation of a pixel is the barycentric blend of
//!   its triangle's corners, normalized (§4.3). The pixels covered are the
//!   stroke region; outlines are pushed out by a margin so neighbourhoods
//!   at the outline are part of it.

use crate::raster::Grid;
use kurbo::{Point, Vec2};
use serde::{Deserialize, Serialize};

/// Fewest and most samples along a spine (DecoBrush §4.2).
pub const SAMPLES: (usize, usize) = (30, 100);

/// Rib samples: spine, left and right outline points, as parallel arrays of
/// pixel positions (`[x, y]`, y down) at one level's scale.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct Ribs {
    /// Spine points `x̂_i`, from the start to the end.
    pub spine: Vec<[f64; 2]>,
    /// Left outline points `l̂_i` (left of the direction of travel).
    pub left: Vec<[f64; 2]>,
    /// Right outline points `r̂_i`.
    pub right: Vec<[f64; 2]>,
}

impl Ribs {
    /// Number of samples.
    pub fn len(&self) -> usize {
        self.spine.len()
    }

    /// The same ribs with every point multiplied by `s` (e.g. from the
    /// finest level to a coarser one).
    pub fn scaled(&self, s: f64) -> Ribs {
        let sc = |v: &Vec<[f64; 2]>| v.iter().map(|p| [p[0] * s, p[1] * s]).collect();
        Ribs {
            spine: sc(&self.spine),
            left: sc(&self.left),
            right: sc(&self.right),
        }
    }

    /// Rib lengths `|l̂_i − r̂_i|` through the spine (local widths), px.
    pub fn widths(&self) -> Vec<f64> {
        (0..self.len())
            .map(|i| {
                pt(self.left[i]).distance(pt(self.spine[i]))
                    + pt(self.right[i]).distance(pt(self.spine[i]))
            })
            .collect()
    }
}

fn pt(p: [f64; 2]) -> Point {
    Point::new(p[0], p[1])
}

fn arr(p: Point) -> [f64; 2] {
    [p.x, p.y]
}

/// Per-sample features for matching query samples to exemplar samples
/// (DecoBrush §5.1 after Lu et al. 2013). Lengths in pixels of the finest
/// level, angles in radians.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct SampleFeatures {
    /// Signed turning angle at the sample: the angle from the incoming to
    /// the outgoing spine segment, positive clockwise on screen (y down);
    /// 0 at the ends.
    pub turning: f64,
    /// Stroke width: the rib length `|l̂ − x̂| + |r̂ − x̂|`, px.
    pub width: f64,
    /// Arc length along the spine from the start, px.
    pub from_start: f64,
    /// Arc length along the spine to the end, px.
    pub to_end: f64,
    /// Appearance: fraction (0–1) of the rib from `l̂` to `r̂` that lies on
    /// ink (any layer).
    pub ink: f32,
    /// Appearance per layer: fraction of the rib inside each layer
    /// (stacked layers, bottom first, as in the exemplar's layers).
    pub layer_ink: Vec<f32>,
}

/// The number of samples for a spine `length` px long at the finest level
/// when `coarse` is the coarsest level's scale relative to the finest (¼):
/// one sample per 2 coarse pixels, within [`SAMPLES`].
pub fn sample_count(length: f64, coarse: f64) -> usize {
    let n = (length * coarse / 2.0).round();
    if n.is_finite() {
        (n as usize).clamp(SAMPLES.0, SAMPLES.1)
    } else {
        SAMPLES.0
    }
}

/// `n ≥ 2` points spaced evenly by arc length along `poly`, ends included.
pub fn resample(poly: &[Point], n: usize) -> Vec<Point> {
    let n = n.max(2);
    let mut cum = vec![0.0];
    for w in poly.windows(2) {
        cum.push(cum[cum.len() - 1] + w[0].distance(w[1]));
    }
    let total = *cum.last().unwrap_or(&0.0);
    let first = poly.first().copied().unwrap_or(Point::ZERO);
    if poly.len() < 2 || total <= 0.0 {
        return vec![first; n];
    }
    let mut out = Vec::with_capacity(n);
    let mut k = 0;
    for i in 0..n {
        let s = total * i as f64 / (n - 1) as f64;
        while k + 2 < cum.len() && cum[k + 1] < s {
            k += 1;
        }
        let seg = cum[k + 1] - cum[k];
        let t = if seg > 0.0 {
            ((s - cum[k]) / seg).clamp(0.0, 1.0)
        } else {
            0.0
        };
        out.push(poly[k].lerp(poly[k + 1], t));
    }
    out
}

/// Unit tangents of a polyline (central differences, one-sided at ends).
pub fn tangents(p: &[Point]) -> Vec<Vec2> {
    let n = p.len();
    (0..n)
        .map(|i| {
            let a = p[i.saturating_sub(1)];
            let b = p[(i + 1).min(n - 1)];
            let d = b - a;
            let l = d.hypot();
            if l > 0.0 {
                d / l
            } else {
                Vec2::new(1.0, 0.0)
            }
        })
        .collect()
}

/// The left normal of a unit tangent (left of travel on screen, y down).
pub fn left_normal(t: Vec2) -> Vec2 {
    Vec2::new(t.y, -t.x)
}

fn dist_to_polyline(p: Point, poly: &[Point]) -> f64 {
    poly.windows(2)
        .map(|w| crate::raster::sdf::point_segment_distance(p, kurbo::Line::new(w[0], w[1])))
        .fold(f64::INFINITY, f64::min)
}

/// How far ink reaches from `x` along `dir` (unit), px: the last place the
/// ray leaves the ink within `reach`, while the ray point is nearer to
/// `x` than to any other part of `spine` (1 px slack). 0 when it meets no ink.
fn reach_of_ink(ink: &Grid<f32>, spine: &[Point], x: Point, dir: Vec2, reach: f64) -> f64 {
    let mut s = 0.0;
    let mut d = ink.sample(x.x, x.y) as f64;
    let mut out = 0.0;
    while s < reach {
        let step = (d.abs() - 0.5).max(0.5);
        let s2 = s + step;
        let q = x + dir * s2;
        if dist_to_polyline(q, spine) < s2 - 1.0 {
            break;
        }
        let d2 = ink.sample(q.x, q.y) as f64;
        if d < 0.0 && d2 >= 0.0 {
            out = s + step * (d / (d - d2));
        }
        s = s2;
        d = d2;
    }
    out
}

/// Ribs along `spine` (a polyline, px of the `ink` grid, which holds signed
/// distances in px): `n` samples by arc length, ribs reaching to the ink's
/// outline on each side (at least `min_half` px, at most `reach` px).
pub fn build_ribs(spine: &[Point], n: usize, ink: &Grid<f32>, min_half: f64, reach: f64) -> Ribs {
    let xs = resample(spine, n);
    let ts = tangents(&xs);
    let mut half: Vec<[f64; 2]> = xs
        .iter()
        .zip(&ts)
        .map(|(&x, &t)| {
            let nrm = left_normal(t);
            [
                reach_of_ink(ink, &xs, x, nrm, reach),
                reach_of_ink(ink, &xs, x, -nrm, reach),
            ]
        })
        .collect();
    // Median of three along the spine, per side.
    let raw = half.clone();
    for i in 1..raw.len().saturating_sub(1) {
        for side in 0..2 {
            let mut v = [raw[i - 1][side], raw[i][side], raw[i + 1][side]];
            v.sort_by(f64::total_cmp);
            half[i][side] = v[1];
        }
    }
    let mut ribs = Ribs::default();
    for ((x, t), h) in xs.iter().zip(&ts).zip(&half) {
        let nrm = left_normal(*t);
        ribs.spine.push(arr(*x));
        ribs.left.push(arr(*x + nrm * h[0].max(min_half)));
        ribs.right.push(arr(*x - nrm * h[1].max(min_half)));
    }
    ribs
}

/// The spine extended straight beyond both ends, along its end tangents,
/// as far as ink lies beyond them: the end ornaments (curls, buds, leaves
/// past the points the user picked) become part of the parameterized
/// stroke, and the main branch is straightened towards the ends as
/// DecoBrush §4.2 describes. Ink counts for an end when it lies ahead of
/// the end's tangent, within `reach` px of its line, and nearer to the end
/// point than to any other part of the spine (1 px slack). Returns the
/// extended polyline and the two extension lengths (start, end), px.
pub fn extend_to_ink(spine: &[Point], ink: &Grid<f32>, reach: f64) -> (Vec<Point>, [f64; 2]) {
    let total: f64 = spine.windows(2).map(|w| w[0].distance(w[1])).sum();
    if spine.len() < 2 || total <= 0.0 {
        return (spine.to_vec(), [0.0, 0.0]);
    }
    let coarse = resample(spine, 64);
    // Tangents from a chord a few pixels long, for stability.
    let probe = (total / 4.0).min(8.0);
    let along = |pts: &[Point]| -> Vec2 {
        let a = pts[0];
        let mut acc = 0.0;
        for w in pts.windows(2) {
            acc += w[0].distance(w[1]);
            if acc >= probe {
                let d = a - w[1];
                return d / d.hypot().max(1e-12);
            }
        }
        let d = a - pts[pts.len() - 1];
        d / d.hypot().max(1e-12)
    };
    let rev: Vec<Point> = spine.iter().rev().copied().collect();
    let ends = [(spine[0], along(spine)), (rev[0], along(&rev))];
    let mut ext = [0.0f64; 2];
    for y in 0..ink.height() {
        for x in 0..ink.width() {
            if ink.get(x, y) >= 0.0 {
                continue;
            }
            let p = Point::new(x as f64 + 0.5, y as f64 + 0.5);
            for (k, &(e, t)) in ends.iter().enumerate() {
                let v = p - e;
                let s = v.dot(t);
                if s <= ext[k] || v.cross(t).abs() > reach {
                    continue;
                }
                if v.hypot() <= dist_to_polyline(p, &coarse) + 1.0 {
                    ext[k] = s;
                }
            }
        }
    }
    let mut out = Vec::with_capacity(spine.len() + 2);
    if ext[0] > 0.0 {
        out.push(ends[0].0 + ends[0].1 * ext[0]);
    }
    out.extend_from_slice(spine);
    if ext[1] > 0.0 {
        out.push(ends[1].0 + ends[1].1 * ext[1]);
    }
    (out, ext)
}

/// Fraction of the segment `a`–`b` where `sdf < 0`, from 17 samples.
fn ink_fraction(sdf: &Grid<f32>, a: Point, b: Point) -> f32 {
    let n = 17;
    let inside = (0..n)
        .filter(|&k| {
            let p = a.lerp(b, k as f64 / (n - 1) as f64);
            sdf.sample(p.x, p.y) < 0.0
        })
        .count();
    inside as f32 / n as f32
}

/// The features of every rib sample (ribs and grids at the same scale:
/// the finest level).
pub fn features(ribs: &Ribs, ink: &Grid<f32>, layers: &[&Grid<f32>]) -> Vec<SampleFeatures> {
    let n = ribs.len();
    let xs: Vec<Point> = ribs.spine.iter().map(|&p| pt(p)).collect();
    let mut cum = vec![0.0];
    for w in xs.windows(2) {
        cum.push(cum[cum.len() - 1] + w[0].distance(w[1]));
    }
    let total = *cum.last().unwrap_or(&0.0);
    let widths = ribs.widths();
    (0..n)
        .map(|i| {
            let turning = if i == 0 || i + 1 == n {
                0.0
            } else {
                let a = xs[i] - xs[i - 1];
                let b = xs[i + 1] - xs[i];
                a.cross(b).atan2(a.dot(b))
            };
            let (l, r) = (pt(ribs.left[i]), pt(ribs.right[i]));
            SampleFeatures {
                turning,
                width: widths[i],
                from_start: cum[i],
                to_end: total - cum[i],
                ink: ink_fraction(ink, l, r),
                layer_ink: layers.iter().map(|g| ink_fraction(g, l, r)).collect(),
            }
        })
        .collect()
}

/// The per-pixel stroking orientation and the stroke region of one level.
/// (Cached as the mask and the orientations of masked pixels only.)
#[derive(Clone, Debug, Serialize, Deserialize)]
#[serde(into = "SparseOrientation", try_from = "SparseOrientation")]
pub struct OrientationField {
    /// Unit orientation `ω = [ω_x, ω_y]` per pixel (pixel axes, y down):
    /// the direction of travel along the stroke; `[0, 0]` outside the
    /// stroke region.
    pub dir: Grid<[f32; 2]>,
    /// The stroke region: pixels covered by the rib quads (outlines pushed
    /// out by the margin).
    pub mask: Grid<bool>,
}

/// The cached form of an [`OrientationField`]: the mask, and the
/// orientations of the masked pixels in row-major order.
#[derive(Clone, Serialize, Deserialize)]
struct SparseOrientation {
    #[serde(with = "crate::raster::plain::bits")]
    mask: Grid<bool>,
    #[serde(with = "crate::raster::plain::vec")]
    dirs: Vec<[f32; 2]>,
}

impl From<OrientationField> for SparseOrientation {
    fn from(f: OrientationField) -> Self {
        let dirs = f
            .dir
            .data()
            .iter()
            .zip(f.mask.data())
            .filter(|(_, &m)| m)
            .map(|(d, _)| *d)
            .collect();
        SparseOrientation { mask: f.mask, dirs }
    }
}

impl TryFrom<SparseOrientation> for OrientationField {
    type Error = String;
    fn try_from(s: SparseOrientation) -> Result<Self, String> {
        let n = s.mask.data().iter().filter(|&&m| m).count();
        if n != s.dirs.len() {
            return Err("orientation count does not match the mask".into());
        }
        let mut dir = Grid::new(s.mask.width(), s.mask.height(), [0.0f32; 2]);
        let mut it = s.dirs.into_iter();
        for (d, &m) in dir.data_mut().iter_mut().zip(s.mask.data()) {
            if m {
                if let Some(v) = it.next() {
                    *d = v;
                }
            }
        }
        Ok(OrientationField { dir, mask: s.mask })
    }
}

/// The direction of travel implied by an outline rib `o − x`: the rib
/// turned a quarter turn, signed so a left rib (`side = 1`) and a right
/// rib (`side = −1`) both point along the stroke.
fn outline_orientation(x: Point, o: Point, side: f64, fallback: Vec2) -> Vec2 {
    let r = o - x;
    let l = r.hypot();
    if l < 1e-9 {
        return fallback;
    }
    // For a left rib r = (t.y, −t.x)·w: t = (−r.y, r.x)/w.
    Vec2::new(-r.y, r.x) * side / l
}

/// Rasterizes the rib quads of `ribs` (px of a `w`×`h` grid) into the
/// per-pixel orientation and the stroke region, outlines pushed out by
/// `margin` px (DecoBrush §4.3).
pub fn orientation_field(ribs: &Ribs, w: usize, h: usize, margin: f64) -> OrientationField {
    let mut dir = Grid::new(w, h, [0.0f32; 2]);
    let mut mask = Grid::new(w, h, false);
    let n = ribs.len();
    if n < 2 {
        return OrientationField { dir, mask };
    }
    let xs: Vec<Point> = ribs.spine.iter().map(|&p| pt(p)).collect();
    let spine_dir: Vec<Vec2> = (0..n)
        .map(|i| {
            let d = if i == 0 {
                xs[1] - xs[0]
            } else {
                xs[i] - xs[i - 1]
            };
            let l = d.hypot();
            if l > 0.0 {
                d / l
            } else {
                Vec2::new(1.0, 0.0)
            }
        })
        .collect();
    for (side, outline) in [(1.0, &ribs.left), (-1.0, &ribs.right)] {
        let os: Vec<(Point, Vec2)> = (0..n)
            .map(|i| {
                let o = pt(outline[i]);
                let r = o - xs[i];
                let l = r.hypot();
                let push = if l > 1e-9 {
                    r / l
                } else {
                    left_normal(spine_dir[i]) * side
                };
                (
                    o + push * margin,
                    outline_orientation(xs[i], o, side, spine_dir[i]),
                )
            })
            .collect();
        for i in 0..n - 1 {
            let a = (xs[i], spine_dir[i]);
            let b = (xs[i + 1], spine_dir[i + 1]);
            let c = os[i + 1];
            let d = os[i];
            fill_triangle(&mut dir, &mut mask, [a, b, c]);
            fill_triangle(&mut dir, &mut mask, [a, c, d]);
        }
    }
    OrientationField { dir, mask }
}

/// Sets every not yet set pixel centre inside the triangle to the
/// barycentric blend of its corner orientations.
fn fill_triangle(dir: &mut Grid<[f32; 2]>, mask: &mut Grid<bool>, t: [(Point, Vec2); 3]) {
    let (w, h) = (dir.width(), dir.height());
    let [(p0, v0), (p1, v1), (p2, v2)] = t;
    let area = (p1 - p0).cross(p2 - p0);
    if area.abs() < 1e-12 || !area.is_finite() {
        return;
    }
    let xmin = p0.x.min(p1.x).min(p2.x);
    let xmax = p0.x.max(p1.x).max(p2.x);
    let ymin = p0.y.min(p1.y).min(p2.y);
    let ymax = p0.y.max(p1.y).max(p2.y);
    let x0 = (xmin - 0.5).ceil().max(0.0) as usize;
    let y0 = (ymin - 0.5).ceil().max(0.0) as usize;
    let x1 = ((xmax - 0.5).floor().max(-1.0) + 1.0).min(w as f64) as usize;
    let y1 = ((ymax - 0.5).floor().max(-1.0) + 1.0).min(h as f64) as usize;
    for y in y0..y1 {
        for x in x0..x1 {
            if mask.get(x, y) {
                continue;
            }
            let p = Point::new(x as f64 + 0.5, y as f64 + 0.5);
            let b0 = (p1 - p).cross(p2 - p) / area;
            let b1 = (p2 - p).cross(p0 - p) / area;
            let b2 = 1.0 - b0 - b1;
            if b0 < -1e-9 || b1 < -1e-9 || b2 < -1e-9 {
                continue;
            }
            let v = v0 * b0 + v1 * b1 + v2 * b2;
            let l = v.hypot();
            if l < 1e-9 {
                continue;
            }
            dir.set(x, y, [(v.x / l) as f32, (v.y / l) as f32]);
            mask.set(x, y, true);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A horizontal band of half-width `r` (px) at `y = cy`.
    fn band(w: usize, h: usize, cy: f64, r: f64) -> Grid<f32> {
        Grid::from_fn(w, h, |x, y| {
            let py = y as f64 + 0.5;
            let px = x as f64 + 0.5;
            let dy = (py - cy).abs() - r;
            let dx = (10.0 - px).max(px - (w as f64 - 10.0));
            dy.max(dx) as f32
        })
    }

    #[test]
    fn rib_widths_of_a_band_are_its_width() {
        let ink = band(200, 80, 40.3, 7.6);
        let spine = [Point::new(20.0, 40.3), Point::new(180.0, 40.3)];
        let ribs = build_ribs(&spine, 40, &ink, 1.0, 60.0);
        assert_eq!(ribs.len(), 40);
        for w in ribs.widths() {
            assert!((w - 15.2).abs() < 1.0, "{w}");
        }
        // Left is above (y down), right below.
        assert!(ribs.left[5][1] < 40.3 && ribs.right[5][1] > 40.3);
        let f = features(&ribs, &ink, &[&ink]);
        assert!(f.iter().all(|s| s.ink > 0.9 && s.turning.abs() < 1e-9));
        assert!((f[0].to_end - 160.0).abs() < 1e-6 && f[39].from_start > 159.9);
    }

    #[test]
    fn ribs_do_not_reach_into_the_next_turn_of_a_curl() {
        // Two parallel bands 30 px apart and a spine along the lower one:
        // ribs on the upper side stop halfway, not at the far band.
        let ink = Grid::from_fn(200, 100, |x, y| {
            let py = y as f64 + 0.5;
            let _ = x;
            ((py - 60.0).abs() - 4.0).min((py - 30.0).abs() - 4.0) as f32
        });
        let spine = [
            Point::new(20.0, 60.0),
            Point::new(180.0, 60.0),
            Point::new(180.0, 30.0),
            Point::new(20.0, 30.0),
        ];
        let ribs = build_ribs(&spine, 60, &ink, 1.0, 80.0);
        let w = ribs.widths();
        assert!((w[10] - 8.0).abs() < 1.0, "{}", w[10]);
    }

    #[test]
    fn orientation_follows_the_ribs_and_masks_the_stroke() {
        // An arc of ribs: orientation is tangential everywhere in the mask.
        let c = Point::new(64.0, 64.0);
        let mut ribs = Ribs::default();
        for i in 0..40 {
            let a = std::f64::consts::PI * i as f64 / 39.0;
            let u = Vec2::new(a.cos(), -a.sin());
            // Travel counter-clockwise on screen: from (r, 0) over the top.
            let x = c + u * 40.0;
            ribs.spine.push(arr(x));
            ribs.left.push(arr(c + u * 30.0));
            ribs.right.push(arr(c + u * 50.0));
        }
        let f = orientation_field(&ribs, 128, 128, 0.0);
        let mut n = 0;
        for y in 0..128 {
            for x in 0..128 {
                if !f.mask.get(x, y) {
                    continue;
                }
                n += 1;
                let p = Point::new(x as f64 + 0.5, y as f64 + 0.5);
                let r = p - c;
                assert!((30.0 - 1.0..50.0 + 1.0).contains(&r.hypot()));
                // Tangent of counter-clockwise travel on screen (y down).
                let t = Vec2::new(r.y, -r.x) / r.hypot();
                let d = f.dir.get(x, y);
                let cos = t.x * d[0] as f64 + t.y * d[1] as f64;
                assert!(cos > 0.99, "{x},{y}: {d:?} vs {t:?}");
            }
        }
        // Half an annulus 30..50: π (50² − 30²) / 2 ≈ 2513 px.
        assert!((2300..2700).contains(&n), "{n}");
    }

    #[test]
    fn spines_extend_over_end_ornaments() {
        // A band from x = 10 to 190 and a spine from 50 to 150: extended to
        // the band's last pixel centres, 10.5 and 189.5.
        let ink = band(200, 80, 40.0, 6.0);
        let spine = [Point::new(50.0, 40.0), Point::new(150.0, 40.0)];
        let (ext, len) = extend_to_ink(&spine, &ink, 60.0);
        assert_eq!(ext.len(), 4);
        assert!(
            (ext[0].x - 10.5).abs() < 1.0 && (ext[3].x - 189.5).abs() < 1.0,
            "{ext:?}"
        );
        assert!(
            (len[0] - 39.5).abs() < 1.0 && (len[1] - 39.5).abs() < 1.0,
            "{len:?}"
        );
    }

    #[test]
    fn sample_counts_stay_within_the_papers_range() {
        assert_eq!(sample_count(10.0, 0.25), 30);
        assert_eq!(sample_count(400.0 * 4.0, 0.25), 100);
        assert_eq!(sample_count(f64::NAN, 0.25), 30);
        assert_eq!(
            resample(&[Point::new(0.0, 0.0), Point::new(10.0, 0.0)], 3)[1],
            Point::new(5.0, 0.0)
        );
    }
}
