//! Seeds: where the synthesized elements go (Barla et al. §3.2).
//!
//! **2-D.** Lloyd's method: start from a random distribution of N seeds in
//! the region, then repeatedly compute the Voronoi diagram of the seeds
//! (spade's Delaunay dual, with four far-away guard points so every real
//! cell is bounded), clip each cell to the region and move each seed to the
//! centroid of its clipped cell. The energy Σᵢ ∫_{Vᵢ∩Ω} |x − zᵢ|² dx never
//! increases and the seeds converge to a centroidal Voronoi tessellation.
//!
//! Clipping uses Sutherland–Hodgman of each region ring against the convex
//! cell. A ring's clipped polygon may contain zero-width bridges, but its
//! signed area integrals are exactly those of (ring interior ∩ cell), and
//! the region's indicator is Σ_rings sign·1_interior for non-crossing rings
//! (sign −1 for holes), so holes are respected. Area, first and second
//! moments come from the polygon's boundary by Green's theorem.
//!
//! **1-D.** The Lloyd fixed point for N seeds on an interval of length L is
//! known in closed form — equal cells of L/N with each seed at its cell's
//! middle, sᵢ = (i + ½)·L/N — so it is placed directly instead of iterated
//! (1-D Lloyd converges in O(N²) sweeps towards the same answer).

use super::distribution::{polygon_area, Indexed};
use crate::rng;
use crate::svg_out::FillRule;
use kurbo::{BezPath, PathEl, Point, Rect, Vec2};
use rayon::prelude::*;
use spade::{DelaunayTriangulation, Point2, Triangulation};

/// Why a region with nothing inside it is refused by [`Region::new`].
pub const ZERO_AREA: &str = "region has zero area";

/// One closed ring of a region's outline.
#[derive(Clone, Debug)]
pub struct Ring {
    /// Vertices as drawn (their orientation decides non-zero winding).
    pub drawn: Vec<Point>,
    /// Vertices with positive signed area (see [`polygon_area`]).
    pub pos: Vec<Point>,
    /// +1 when the ring's interior adds to the region, −1 for a hole, 0
    /// when it changes nothing (e.g. nested rings of equal winding).
    pub sign: f64,
    /// Bounding box.
    pub bbox: Rect,
}

/// A region: flattened rings with a fill rule.
#[derive(Clone, Debug)]
pub struct Region {
    /// The rings.
    pub rings: Vec<Ring>,
    /// Interior rule.
    pub rule: FillRule,
    /// Area in user units².
    pub area: f64,
    /// Bounding box of all rings.
    pub bbox: Rect,
}

impl Region {
    /// Flattens `outline` to within `tolerance` and checks it: rings must
    /// not cross, and the area must be positive. The error is the reason.
    pub fn new(outline: &BezPath, rule: FillRule, tolerance: f64) -> Result<Region, String> {
        let mut rings_pts: Vec<Vec<Point>> = Vec::new();
        let mut cur: Vec<Point> = Vec::new();
        let finish = |cur: &mut Vec<Point>, out: &mut Vec<Vec<Point>>| {
            if cur.len() > 1 && cur.first() == cur.last() {
                cur.pop();
            }
            if cur.len() >= 3 {
                out.push(std::mem::take(cur));
            } else {
                cur.clear();
            }
        };
        let mut bad = false;
        kurbo::flatten(outline, tolerance, |el| match el {
            PathEl::MoveTo(p) => {
                finish(&mut cur, &mut rings_pts);
                cur.push(p);
            }
            PathEl::LineTo(p) => {
                if !(p.x.is_finite() && p.y.is_finite()) {
                    bad = true;
                }
                if cur.last() != Some(&p) {
                    cur.push(p);
                }
            }
            PathEl::ClosePath => finish(&mut cur, &mut rings_pts),
            _ => {}
        });
        finish(&mut cur, &mut rings_pts);
        if bad {
            return Err("outline has non-finite coordinates".into());
        }
        // Rings that cross are resolved by the fill rule into rings that
        // do not (outer boundaries and holes, nonzero = even-odd after).
        let (rings_pts, rule) = if first_crossing(&rings_pts).is_some() {
            (resolve_crossings(&rings_pts, rule), FillRule::NonZero)
        } else {
            (rings_pts, rule)
        };
        if rings_pts.is_empty() {
            return Err(ZERO_AREA.into());
        }
        let mut rings: Vec<Ring> = rings_pts
            .into_iter()
            .map(|drawn| {
                let mut pos = drawn.clone();
                if polygon_area(&pos) < 0.0 {
                    pos.reverse();
                }
                let bbox = drawn
                    .iter()
                    .fold(Rect::from_points(drawn[0], drawn[0]), |r, &p| r.union_pt(p));
                Ring {
                    drawn,
                    pos,
                    sign: 0.0,
                    bbox,
                }
            })
            .collect();
        let bbox = rings
            .iter()
            .map(|r| r.bbox)
            .reduce(|a, b| a.union(b))
            .unwrap_or(Rect::ZERO);
        let mut region = Region {
            rings: Vec::new(),
            rule,
            area: 0.0,
            bbox,
        };
        // The sign of each ring: does crossing it inward enter the region?
        let delta = (bbox.width().max(bbox.height()) * 1e-7).max(1e-9);
        let signs: Vec<f64> = {
            region.rings = rings.clone();
            rings
                .iter()
                .map(|r| {
                    let n = r.pos.len();
                    let (k, _) = (0..n)
                        .map(|k| (k, (r.pos[(k + 1) % n] - r.pos[k]).hypot2()))
                        .fold((0, -1.0), |best, x| if x.1 > best.1 { x } else { best });
                    let (a, b) = (r.pos[k], r.pos[(k + 1) % n]);
                    let d = b - a;
                    let len = d.hypot();
                    if len == 0.0 {
                        return 0.0;
                    }
                    // Positive orientation: the interior is to the left.
                    let left = Vec2::new(-d.y, d.x) / len;
                    let m = a.midpoint(b);
                    let inside = region.contains(m + left * delta) as i32 as f64;
                    let outside = region.contains(m - left * delta) as i32 as f64;
                    inside - outside
                })
                .collect()
        };
        for (r, s) in rings.iter_mut().zip(signs) {
            r.sign = s;
        }
        // Rings with sign 0 stay: they still count in the winding number.
        region.area = rings.iter().map(|r| r.sign * polygon_area(&r.pos)).sum();
        region.rings = rings;
        if region.area.is_nan() || region.area < (tolerance * tolerance).max(1e-12) {
            return Err(ZERO_AREA.into());
        }
        Ok(region)
    }

    /// True when `p` is inside by the fill rule (winding of the drawn rings).
    pub fn contains(&self, p: Point) -> bool {
        let mut w = 0i32;
        for r in &self.rings {
            w += winding(&r.drawn, p);
        }
        match self.rule {
            FillRule::NonZero => w != 0,
            FillRule::EvenOdd => w % 2 != 0,
        }
    }

    /// Area, first moments and polar second moment about `z` of the part of
    /// the convex polygon `cell` (positive orientation) inside the region.
    pub fn moments_in(&self, cell: &[Point], z: Point) -> Moments {
        let cb = cell
            .iter()
            .fold(Rect::from_points(cell[0], cell[0]), |r, &p| r.union_pt(p));
        let mut m = Moments::default();
        for r in &self.rings {
            if r.sign == 0.0 || !overlaps(r.bbox, cb) {
                continue;
            }
            let clipped = clip_convex(&r.pos, cell);
            if clipped.len() >= 3 {
                m.add(&Moments::of(&clipped, z), r.sign);
            }
        }
        m
    }
}

fn overlaps(a: Rect, b: Rect) -> bool {
    a.x0 <= b.x1 && b.x0 <= a.x1 && a.y0 <= b.y1 && b.y0 <= a.y1
}

/// Winding number contribution of a closed polygon around `p`.
fn winding(poly: &[Point], p: Point) -> i32 {
    let n = poly.len();
    let mut w = 0;
    for i in 0..n {
        let (a, b) = (poly[i], poly[(i + 1) % n]);
        if a.y <= p.y {
            if b.y > p.y && (b - a).cross(p - a) > 0.0 {
                w += 1;
            }
        } else if b.y <= p.y && (b - a).cross(p - a) < 0.0 {
            w -= 1;
        }
    }
    w
}

/// The first proper crossing between edges of the rings (edges sharing a
/// vertex in the same ring excepted), found through a uniform grid.
fn first_crossing(rings: &[Vec<Point>]) -> Option<Point> {
    let mut edges: Vec<(usize, usize, Point, Point)> = Vec::new();
    for (ri, r) in rings.iter().enumerate() {
        for i in 0..r.len() {
            edges.push((ri, i, r[i], r[(i + 1) % r.len()]));
        }
    }
    if edges.is_empty() {
        return None;
    }
    let bb = edges
        .iter()
        .fold(Rect::from_points(edges[0].2, edges[0].2), |r, e| {
            r.union_pt(e.2).union_pt(e.3)
        });
    let cells = ((edges.len() as f64).sqrt().ceil() as usize).clamp(1, 512);
    let cw = (bb.width() / cells as f64).max(1e-12);
    let ch = (bb.height() / cells as f64).max(1e-12);
    let cell_of = |x: f64, y: f64| {
        (
            (((x - bb.x0) / cw) as usize).min(cells - 1),
            (((y - bb.y0) / ch) as usize).min(cells - 1),
        )
    };
    let mut grid: Vec<Vec<usize>> = vec![Vec::new(); cells * cells];
    for (k, e) in edges.iter().enumerate() {
        let (x0, y0) = cell_of(e.2.x.min(e.3.x), e.2.y.min(e.3.y));
        let (x1, y1) = cell_of(e.2.x.max(e.3.x), e.2.y.max(e.3.y));
        for gy in y0..=y1 {
            for gx in x0..=x1 {
                grid[gy * cells + gx].push(k);
            }
        }
    }
    let mut best: Option<(usize, usize, Point)> = None;
    for bucket in &grid {
        for (ii, &a) in bucket.iter().enumerate() {
            for &b in &bucket[ii + 1..] {
                let (ea, eb) = (&edges[a], &edges[b]);
                if ea.0 == eb.0 {
                    let n = rings[ea.0].len();
                    if (ea.1 + 1) % n == eb.1 || (eb.1 + 1) % n == ea.1 {
                        continue;
                    }
                }
                if let Some(p) = proper_crossing(ea.2, ea.3, eb.2, eb.3) {
                    let key = (a.min(b), a.max(b), p);
                    if best.is_none_or(|bst| (key.0, key.1) < (bst.0, bst.1)) {
                        best = Some(key);
                    }
                }
            }
        }
    }
    best.map(|b| b.2)
}

/// The rings bounding what `rings` cover under `rule`, crossing nowhere:
/// outer boundaries and holes of opposite orientation, which touch at
/// most at vertices (the Boolean union of a polygon with itself, as
/// vector editors compute it).
fn resolve_crossings(rings: &[Vec<Point>], rule: FillRule) -> Vec<Vec<Point>> {
    use i_overlay::core::fill_rule::FillRule as Rule;
    use i_overlay::float::simplify::SimplifyShape as _;
    let contours: Vec<Vec<[f64; 2]>> = rings
        .iter()
        .map(|r| r.iter().map(|p| [p.x, p.y]).collect())
        .collect();
    let rule = match rule {
        FillRule::NonZero => Rule::NonZero,
        FillRule::EvenOdd => Rule::EvenOdd,
    };
    contours
        .simplify_shape(rule)
        .into_iter()
        .flatten()
        .filter(|c| c.len() >= 3)
        .map(|c| c.into_iter().map(|[x, y]| Point::new(x, y)).collect())
        .collect()
}

/// The crossing point of segments ab and cd when they cross properly (or
/// overlap along a stretch), `None` otherwise.
fn proper_crossing(a: Point, b: Point, c: Point, d: Point) -> Option<Point> {
    let (r, s) = (b - a, d - c);
    let den = r.cross(s);
    let scale = r.hypot() * s.hypot();
    if scale == 0.0 {
        return None;
    }
    if den.abs() <= 1e-12 * scale {
        // Parallel: an overlap of collinear edges is a crossing too.
        if (c - a).cross(r).abs() > 1e-9 * r.hypot() * (c - a).hypot().max(1.0) {
            return None;
        }
        let rr = r.hypot2();
        let (t0, t1) = ((c - a).dot(r) / rr, (d - a).dot(r) / rr);
        let (lo, hi) = (t0.min(t1).max(0.0), t0.max(t1).min(1.0));
        return (hi - lo > 1e-9).then(|| a + r * ((lo + hi) / 2.0));
    }
    let t = (c - a).cross(s) / den;
    let u = (c - a).cross(r) / den;
    let eps = 1e-9;
    (t > eps && t < 1.0 - eps && u > eps && u < 1.0 - eps).then(|| a + r * t)
}

/// Sutherland–Hodgman: `subject` clipped by the convex `clip` (both with
/// positive orientation).
pub fn clip_convex(subject: &[Point], clip: &[Point]) -> Vec<Point> {
    let mut out: Vec<Point> = subject.to_vec();
    let n = clip.len();
    for i in 0..n {
        if out.is_empty() {
            break;
        }
        let (a, b) = (clip[i], clip[(i + 1) % n]);
        let e = b - a;
        let inside = |p: Point| e.cross(p - a) >= 0.0;
        let input = std::mem::take(&mut out);
        let m = input.len();
        for k in 0..m {
            let (p, q) = (input[k], input[(k + 1) % m]);
            let (pi, qi) = (inside(p), inside(q));
            if pi {
                out.push(p);
            }
            if pi != qi {
                let (dp, dq) = (e.cross(p - a), e.cross(q - a));
                let t = dp / (dp - dq);
                out.push(p + (q - p) * t);
            }
        }
    }
    out
}

/// Area integrals of a polygon region about a point z.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Moments {
    /// ∫ 1 dx (area).
    pub area: f64,
    /// ∫ (x − z) dx.
    pub first: Vec2,
    /// ∫ |x − z|² dx.
    pub second: f64,
}

impl Moments {
    /// The moments of a simple polygon (positive orientation) by Green's
    /// theorem on its edges, taken about `z`.
    pub fn of(poly: &[Point], z: Point) -> Moments {
        let n = poly.len();
        let mut m = Moments::default();
        for i in 0..n {
            let (p, q) = (poly[i] - z, poly[(i + 1) % n] - z);
            let c = p.cross(q);
            m.area += c;
            m.first += (p + q) * c;
            m.second += (p.x * p.x + p.x * q.x + q.x * q.x + p.y * p.y + p.y * q.y + q.y * q.y) * c;
        }
        m.area /= 2.0;
        m.first /= 6.0;
        m.second /= 12.0;
        m
    }

    fn add(&mut self, o: &Moments, sign: f64) {
        self.area += sign * o.area;
        self.first += o.first * sign;
        self.second += sign * o.second;
    }
}

/// The result of Lloyd's method.
#[derive(Clone, Debug)]
pub struct Lloyd {
    /// Final seed positions, all inside the region.
    pub points: Vec<Point>,
    /// The CVT energy before each iteration's move (non-increasing).
    #[cfg_attr(not(test), allow(dead_code))] // read by the tests
    pub energy: Vec<f64>,
}

/// The bounded Voronoi cells of `pts` (positive orientation); an empty cell
/// for a point that coincides with an earlier one.
pub fn voronoi_cells(pts: &[Point], bbox: Rect) -> Vec<Vec<Point>> {
    let n = pts.len();
    let mut cells = vec![Vec::new(); n];
    let c = bbox.center();
    let r = (bbox.width().max(bbox.height()) + 1.0) * 10.0;
    let mut verts: Vec<Indexed> = pts
        .iter()
        .enumerate()
        .map(|(idx, p)| Indexed {
            pos: Point2::new(p.x, p.y),
            idx,
        })
        .collect();
    for (k, (dx, dy)) in [(-1.0, -1.0), (1.0, -1.0), (1.0, 1.0), (-1.0, 1.0)]
        .into_iter()
        .enumerate()
    {
        verts.push(Indexed {
            pos: Point2::new(c.x + dx * r, c.y + dy * r),
            idx: n + k,
        });
    }
    let Ok(tri) = DelaunayTriangulation::<Indexed>::bulk_load_stable(verts) else {
        return cells;
    };
    for v in tri.vertices() {
        let idx = v.data().idx;
        if idx >= n {
            continue;
        }
        let mut poly = Vec::new();
        for e in v.out_edges() {
            if let Some(f) = e.face().as_inner() {
                let cc = f.circumcenter();
                poly.push(Point::new(cc.x, cc.y));
            }
        }
        if polygon_area(&poly) < 0.0 {
            poly.reverse();
        }
        cells[idx] = poly;
    }
    cells
}

/// Runs Lloyd's method for `n` seeds in `region` for at most `max_iter`
/// iterations (stopping once no seed moves more than 10⁻³ of the seed
/// spacing), from a random start drawn from `seed`.
pub fn lloyd(region: &Region, n: usize, seed: u64, max_iter: usize) -> Lloyd {
    let mut pts = initial_seeds(region, n, seed);
    let mut energy = Vec::new();
    if pts.is_empty() {
        return Lloyd {
            points: pts,
            energy,
        };
    }
    let spacing = (region.area / pts.len() as f64).sqrt();
    let mut last_inside = pts.clone();
    for _ in 0..max_iter {
        let cells = voronoi_cells(&pts, region.bbox);
        let moved: Vec<(Point, f64)> = cells
            .par_iter()
            .zip(pts.par_iter())
            .map(|(cell, &z)| {
                if cell.len() < 3 {
                    return (z, 0.0);
                }
                let m = region.moments_in(cell, z);
                if m.area <= 0.0 {
                    return (z, 0.0);
                }
                (z + m.first / m.area, m.second)
            })
            .collect();
        energy.push(moved.iter().map(|m| m.1).sum());
        let mut max_move: f64 = 0.0;
        for (i, (p, _)) in moved.into_iter().enumerate() {
            max_move = max_move.max((p - pts[i]).hypot());
            pts[i] = p;
            if region.contains(p) {
                last_inside[i] = p;
            }
        }
        if max_move < 1e-3 * spacing {
            break;
        }
    }
    // A centroid of a cell of a non-convex region can fall outside it; such
    // a seed stays where it last was inside.
    for (p, q) in pts.iter_mut().zip(&last_inside) {
        if !region.contains(*p) {
            *p = *q;
        }
    }
    Lloyd {
        points: pts,
        energy,
    }
}

/// A random start: one jittered point per cell of a grid sized for about n
/// points inside, trimmed to n by a seeded shuffle, topped up by rejection
/// sampling when the grid falls short.
pub fn initial_seeds(region: &Region, n: usize, seed: u64) -> Vec<Point> {
    if n == 0 {
        return Vec::new();
    }
    let bb = region.bbox;
    let g = (region.area / n as f64).sqrt() * 0.95;
    let (nx, ny) = (
        (bb.width() / g).ceil() as u64,
        (bb.height() / g).ceil() as u64,
    );
    let mut cand: Vec<(u64, Point)> = Vec::new();
    if nx.saturating_mul(ny) <= 64 * n as u64 + 1024 {
        for iy in 0..ny {
            for ix in 0..nx {
                let p = Point::new(
                    bb.x0 + (ix as f64 + rng::unit(&[seed, 1, ix, iy])) * g,
                    bb.y0 + (iy as f64 + rng::unit(&[seed, 2, ix, iy])) * g,
                );
                if region.contains(p) {
                    cand.push((rng::hash(&[seed, 3, ix, iy]), p));
                }
            }
        }
    }
    if cand.len() > n {
        cand.sort_by_key(|c| c.0);
        cand.truncate(n);
        // Back to grid order, so the result does not depend on hash order.
        cand.sort_by(|a, b| a.1.y.total_cmp(&b.1.y).then(a.1.x.total_cmp(&b.1.x)));
    }
    let mut pts: Vec<Point> = cand.into_iter().map(|c| c.1).collect();
    let mut k = 0u64;
    while pts.len() < n && k < 1000 * n as u64 + 10_000 {
        let p = Point::new(
            bb.x0 + rng::unit(&[seed, 4, k]) * bb.width(),
            bb.y0 + rng::unit(&[seed, 5, k]) * bb.height(),
        );
        if region.contains(p) {
            pts.push(p);
        }
        k += 1;
    }
    pts
}

/// A flattened open or closed subpath with arc-length lookup.
#[derive(Clone, Debug)]
pub struct Polyline {
    /// Vertices.
    pub pts: Vec<Point>,
    /// Cumulative length at each vertex.
    pub cum: Vec<f64>,
    /// Whether the subpath closes on itself.
    pub closed: bool,
}

impl Polyline {
    /// Flattens every subpath of `path` to within `tolerance`.
    pub fn from_path(path: &BezPath, tolerance: f64) -> Vec<Polyline> {
        let mut out = Vec::new();
        let mut cur: Vec<Point> = Vec::new();
        let mut closed = false;
        let push = |cur: &mut Vec<Point>, closed: bool, out: &mut Vec<Polyline>| {
            let pts = std::mem::take(cur);
            if pts.len() < 2 {
                return;
            }
            let mut cum = vec![0.0];
            for w in pts.windows(2) {
                let l = cum[cum.len() - 1] + (w[1] - w[0]).hypot();
                cum.push(l);
            }
            if cum[cum.len() - 1] > 0.0 && cum[cum.len() - 1].is_finite() {
                out.push(Polyline { pts, cum, closed });
            }
        };
        kurbo::flatten(path, tolerance, |el| match el {
            PathEl::MoveTo(p) => {
                push(&mut cur, closed, &mut out);
                closed = false;
                cur.push(p);
            }
            PathEl::LineTo(p) if cur.last() != Some(&p) => cur.push(p),
            PathEl::ClosePath => {
                if let (Some(&f), Some(&l)) = (cur.first(), cur.last()) {
                    if f != l {
                        cur.push(f);
                    }
                }
                closed = true;
                push(&mut cur, true, &mut out);
                closed = false;
            }
            _ => {}
        });
        push(&mut cur, closed, &mut out);
        out
    }

    /// Total length.
    pub fn length(&self) -> f64 {
        self.cum[self.cum.len() - 1]
    }

    /// The point at arc length `s` (wrapped when closed, clamped when open).
    pub fn at(&self, s: f64) -> Point {
        let l = self.length();
        let s = if self.closed {
            s.rem_euclid(l)
        } else {
            s.clamp(0.0, l)
        };
        let i = self
            .cum
            .partition_point(|&c| c <= s)
            .clamp(1, self.pts.len() - 1);
        let (c0, c1) = (self.cum[i - 1], self.cum[i]);
        let t = if c1 > c0 { (s - c0) / (c1 - c0) } else { 0.0 };
        self.pts[i - 1].lerp(self.pts[i], t)
    }

    /// The unit tangent at `s`, averaged over ±`window` so that it turns
    /// smoothly across the flattening's corners.
    pub fn tangent(&self, s: f64, window: f64) -> Vec2 {
        let d = self.at(s + window) - self.at(s - window);
        let len = d.hypot();
        if len > 0.0 {
            return d / len;
        }
        let d = self.pts[self.pts.len() - 1] - self.pts[0];
        if d.hypot() > 0.0 {
            d.normalize()
        } else {
            Vec2::new(1.0, 0.0)
        }
    }
}

/// 1-D seeds: arc lengths of the CVT of n = round(L/spacing) seeds (at
/// least one) along the polyline: (i + ½)·L/n.
pub fn seeds_along(line: &Polyline, spacing: f64) -> Vec<f64> {
    let l = line.length();
    let n = ((l / spacing).round() as usize).max(1);
    (0..n).map(|i| (i as f64 + 0.5) * l / n as f64).collect()
}

/// Drops the 1-D seeds (arc lengths along `line`, in order) that would sit
/// closer than `min_gap` units, in the plane, to a seed kept before them:
/// where a path turns back on itself (a tight spiral, a hairpin) the
/// elements of neighbouring turns would otherwise crowd or overlap, while
/// the example's elements keep their spacing in every direction. Seeds are
/// looked up in a grid of `min_gap` cells, so the cost is linear.
pub fn thin_crowded(line: &Polyline, seeds: &[f64], min_gap: f64) -> Vec<f64> {
    if min_gap.is_nan() || min_gap <= 0.0 {
        return seeds.to_vec();
    }
    let cell = |p: Point| {
        (
            (p.x / min_gap).floor() as i64,
            (p.y / min_gap).floor() as i64,
        )
    };
    let mut grid: std::collections::HashMap<(i64, i64), Vec<Point>> = Default::default();
    let mut kept = Vec::with_capacity(seeds.len());
    for &s in seeds {
        let p = line.at(s);
        let (cx, cy) = cell(p);
        let crowded = (cx - 1..=cx + 1).any(|x| {
            (cy - 1..=cy + 1).any(|y| {
                grid.get(&(x, y))
                    .is_some_and(|v| v.iter().any(|q| q.distance(p) < min_gap))
            })
        });
        if !crowded {
            grid.entry((cx, cy)).or_default().push(p);
            kept.push(s);
        }
    }
    kept
}

#[cfg(test)]
mod tests {
    use super::*;

    fn square(s: f64) -> BezPath {
        kurbo::Shape::to_path(&kurbo::Rect::new(0.0, 0.0, s, s), 0.1)
    }

    #[test]
    fn moments_of_unit_square() {
        let sq = [
            Point::new(0.0, 0.0),
            Point::new(1.0, 0.0),
            Point::new(1.0, 1.0),
            Point::new(0.0, 1.0),
        ];
        let m = Moments::of(&sq, Point::new(0.5, 0.5));
        assert!((m.area - 1.0).abs() < 1e-12);
        assert!(m.first.hypot() < 1e-12);
        assert!((m.second - 1.0 / 6.0).abs() < 1e-12);
    }

    #[test]
    fn holes_are_subtracted() {
        let mut p = square(10.0);
        // An inner square drawn the other way: a hole under non-zero.
        p.move_to((2.0, 2.0));
        p.line_to((2.0, 8.0));
        p.line_to((8.0, 8.0));
        p.line_to((8.0, 2.0));
        p.close_path();
        let r = Region::new(&p, FillRule::NonZero, 0.1).unwrap();
        assert!((r.area - 64.0).abs() < 1e-9, "{}", r.area);
        assert!(!r.contains(Point::new(5.0, 5.0)));
        assert!(r.contains(Point::new(1.0, 5.0)));
    }

    #[test]
    fn a_bowtie_is_two_triangles() {
        let mut p = BezPath::new();
        p.move_to((0.0, 0.0));
        p.line_to((10.0, 10.0));
        p.line_to((10.0, 0.0));
        p.line_to((0.0, 10.0));
        p.close_path();
        for rule in [FillRule::NonZero, FillRule::EvenOdd] {
            let r = Region::new(&p, rule, 0.1).unwrap();
            assert_eq!(r.rings.len(), 2);
            assert!((r.area - 50.0).abs() < 1e-6, "{}", r.area);
            assert!(r.contains(Point::new(1.0, 5.0)) && r.contains(Point::new(9.0, 5.0)));
            assert!(!r.contains(Point::new(5.0, 1.0)) && !r.contains(Point::new(5.0, 9.0)));
        }
    }

    #[test]
    fn a_pentagram_fills_by_its_rule() {
        // Drawn in one stroke: nonzero fills the centre, even-odd leaves
        // it out. Area of the centre pentagon and of the five tips, exact
        // from the crossing points, against the resolved rings' area.
        let pts = [
            (50.0, 0.0),
            (21.0, 90.0),
            (98.0, 35.0),
            (2.0, 35.0),
            (79.0, 90.0),
        ];
        let mut p = BezPath::new();
        p.move_to(pts[0]);
        for &q in &pts[1..] {
            p.line_to(q);
        }
        p.close_path();
        let centre = Point::new(50.0, 50.0);
        let nz = Region::new(&p, FillRule::NonZero, 0.1).unwrap();
        let eo = Region::new(&p, FillRule::EvenOdd, 0.1).unwrap();
        assert!(nz.contains(centre) && !eo.contains(centre));
        for tip in [Point::new(50.0, 10.0), Point::new(90.0, 37.0)] {
            assert!(nz.contains(tip) && eo.contains(tip));
        }
        // The inner pentagon's area by the shoelace formula on the five
        // crossings of the star's edges.
        let cross = |a: (f64, f64), b: (f64, f64), c: (f64, f64), d: (f64, f64)| {
            let (a, b, c, d) = (
                Point::from(a),
                Point::from(b),
                Point::from(c),
                Point::from(d),
            );
            let (r, s) = (b - a, d - c);
            let t = (c - a).cross(s) / r.cross(s);
            a + r * t
        };
        let e = |i: usize| (pts[i % 5], pts[(i + 1) % 5]);
        let mut inner: Vec<Point> = (0..5)
            .map(|i| {
                let (a, b) = e(i);
                let (c, d) = e(i + 2);
                cross(a, b, c, d)
            })
            .collect();
        // In order around the centre, so the shoelace formula applies.
        let mid = inner.iter().fold(Vec2::ZERO, |m, p| m + p.to_vec2()) / 5.0;
        inner.sort_by(|p, q| {
            let (u, v) = (*p - mid.to_point(), *q - mid.to_point());
            u.atan2().total_cmp(&v.atan2())
        });
        let pent = polygon_area(&inner).abs();
        assert!(
            (nz.area - eo.area - pent).abs() < 1e-3,
            "{} {} {pent}",
            nz.area,
            eo.area
        );
    }

    #[test]
    fn clipped_cells_tile_the_region() {
        let r = Region::new(&square(100.0), FillRule::NonZero, 0.1).unwrap();
        let pts = initial_seeds(&r, 50, 3);
        assert_eq!(pts.len(), 50);
        let cells = voronoi_cells(&pts, r.bbox);
        let total: f64 = cells
            .iter()
            .zip(&pts)
            .map(|(c, &z)| r.moments_in(c, z).area)
            .sum();
        assert!((total - 10_000.0).abs() < 1e-6, "{total}");
    }

    #[test]
    fn seeds_on_a_hairpin_keep_their_distance_in_the_plane() {
        // Two legs 12 units apart, joined by a half turn; seeds 20 apart
        // along the path would face each other across the gap.
        let mut p = BezPath::new();
        p.move_to((0.0, 0.0));
        p.line_to((200.0, 0.0));
        p.line_to((200.0, 12.0));
        p.line_to((0.0, 12.0));
        let line = &Polyline::from_path(&p, 0.05)[0];
        let all = seeds_along(line, 20.0);
        let kept = thin_crowded(line, &all, 16.0);
        assert!(kept.len() < all.len() && kept.len() >= all.len() / 2);
        // Brute force: every kept pair is far enough apart, and every
        // dropped seed is too close to one kept before it.
        let at = |s: f64| line.at(s);
        for (i, &a) in kept.iter().enumerate() {
            for &b in &kept[i + 1..] {
                assert!(at(a).distance(at(b)) >= 16.0, "{a} {b}");
            }
        }
        for &s in all.iter().filter(|s| !kept.contains(s)) {
            assert!(kept.iter().any(|&k| k < s && at(k).distance(at(s)) < 16.0));
        }
        // A straight run loses nothing.
        let mut q = BezPath::new();
        q.move_to((0.0, 0.0));
        q.line_to((200.0, 0.0));
        let straight = &Polyline::from_path(&q, 0.05)[0];
        let s = seeds_along(straight, 20.0);
        assert_eq!(thin_crowded(straight, &s, 16.0), s);
    }
}
