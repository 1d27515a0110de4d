//! The main branch (spine) of an exemplar, from its two end points
//! (DecoBrush §4.2).
//!
//! Dijkstra's algorithm (as A*, with the straight distance to the end as a
//! consistent bound: same path, fewer pixels visited) runs on the pixel grid, each pixel linked to the
//! pixels at the 32 primitive offsets within a 7×7 window (directions
//! spread roughly uniformly around the circle). A link `v` costs
//! `w = |v| + w_f (1 − f^p) + w_c (1 − c)`: `f` is the cosine between `v`
//! and the edge tangent flow (Kang et al. 2007, signed as in Brushables
//! §3.1; [`crate::field::etf`]) at the link's midpoint, so the path runs
//! along the artwork's lines; `c` is the cosine between the flow at the
//! link's two ends, 1 where the flow does not turn across the link, so
//! `1 − c` grows with the flow's curvature and the path avoids places where
//! it bends sharply (our reading of the paper's "difference in curvature at
//! the ends of this edge"). With `p` even the sign of the flow does not
//! matter. The paper's constants are `w_f = 10`, `w_c = 3`, `p = 4`.
//!
//! A quartic polynomial fitted to the path's vertices gives the smooth main
//! branch. Ours keeps the user's end points exactly:
//! `x(t) = (1 − t) S + t E + t (1 − t) (a + b t + c t²)` with `t` the
//! normalized chord length, `a, b, c` by least squares (nalgebra).

use crate::error::{Error, Result};
use crate::field::etf::{edge_tangent_flow, DirectionGrid, EtfOptions};
use crate::raster::Grid;
use kurbo::{Point, Vec2};
use std::cmp::Reverse;
use std::collections::BinaryHeap;

/// Weights of the spine's path cost (DecoBrush §4.2).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SpineOptions {
    /// `w_f`, weight of following the flow. Default 10.
    pub w_flow: f64,
    /// `w_c`, weight of the flow's curvature. Default 3.
    pub w_curvature: f64,
    /// Exponent `p` of the flow alignment `f`. Default 4.
    pub power: i32,
}

impl Default for SpineOptions {
    fn default() -> Self {
        SpineOptions {
            w_flow: 10.0,
            w_curvature: 3.0,
            power: 4,
        }
    }
}

/// The 32 link offsets: every primitive `(dx, dy)` with `max(|dx|, |dy|) ≤ 3`.
pub fn link_offsets() -> Vec<(i32, i32)> {
    let mut out = Vec::with_capacity(32);
    for dy in -3i32..=3 {
        for dx in -3i32..=3 {
            if (dx, dy) != (0, 0) && gcd(dx.unsigned_abs(), dy.unsigned_abs()) == 1 {
                out.push((dx, dy));
            }
        }
    }
    out
}

fn gcd(a: u32, b: u32) -> u32 {
    if b == 0 {
        a
    } else {
        gcd(b, a % b)
    }
}

/// The image the flow is estimated from: the ink's coverage softened to a
/// 3 px ramp across the outline, from a signed distance grid (px).
pub fn flow_image(ink_sdf: &Grid<f32>) -> Grid<f32> {
    ink_sdf.map(|d| {
        let t = (0.5 - d / 3.0).clamp(0.0, 1.0);
        t * t * (3.0 - 2.0 * t)
    })
}

/// The signed edge tangent flow of an exemplar's ink (signed distances, px).
pub fn exemplar_flow(ink_sdf: &Grid<f32>) -> DirectionGrid {
    edge_tangent_flow(&flow_image(ink_sdf), &EtfOptions::default())
}

/// The pixel graph of the spine search over a flow field: every pixel
/// linked to the pixels at the 32 [`link_offsets`], each link costing
/// `|v| + w_f (1 − f^p) + w_c (1 − c)` (see the module docs).
pub struct LinkGraph<'a> {
    flow: &'a DirectionGrid,
    opts: SpineOptions,
    /// Offset, length and unit direction of each link.
    links: Vec<(i32, i32, f64, Vec2)>,
}

impl<'a> LinkGraph<'a> {
    /// The graph of `flow` with the path weights `opts`.
    pub fn new(flow: &'a DirectionGrid, opts: &SpineOptions) -> Self {
        let links = link_offsets()
            .into_iter()
            .map(|(dx, dy)| {
                let v = Vec2::new(dx as f64, dy as f64);
                (dx, dy, v.hypot(), v / v.hypot())
            })
            .collect();
        LinkGraph {
            flow,
            opts: *opts,
            links,
        }
    }

    /// Grid width, px.
    pub fn width(&self) -> usize {
        self.flow.width()
    }

    /// Grid height, px.
    pub fn height(&self) -> usize {
        self.flow.height()
    }

    /// The flow at a pixel, clamped to the grid.
    fn at(&self, x: i32, y: i32) -> Vec2 {
        let (w, h) = (self.width() as i32, self.height() as i32);
        let d = self
            .flow
            .get(x.clamp(0, w - 1) as usize, y.clamp(0, h - 1) as usize);
        Vec2::new(d[0] as f64, d[1] as f64)
    }

    /// Calls `visit(j, cost)` for every link out of pixel `i`.
    pub fn links_from(&self, i: usize, mut visit: impl FnMut(usize, f64)) {
        let (w, h) = (self.width(), self.height());
        let unit = |v: Vec2| {
            let n = v.hypot();
            if n > 1e-9 {
                v / n
            } else {
                Vec2::ZERO
            }
        };
        let (x, y) = ((i % w) as i32, (i / w) as i32);
        let here = unit(self.at(x, y));
        for &(dx, dy, len, dir) in &self.links {
            let (nx, ny) = (x + dx, y + dy);
            if nx < 0 || ny < 0 || nx >= w as i32 || ny >= h as i32 {
                continue;
            }
            let j = ny as usize * w + nx as usize;
            // The flow is unit or zero per pixel; sampled at a link's
            // midpoint (a half-integer position) it is the mean of the 2 or
            // 4 pixels around it, exactly what bilinear interpolation gives
            // there: floor and ceil of x + dx/2, y + dy/2.
            let (mx0, mx1) = ((2 * x + dx).div_euclid(2), (2 * x + dx + 1).div_euclid(2));
            let (my0, my1) = ((2 * y + dy).div_euclid(2), (2 * y + dy + 1).div_euclid(2));
            let mid =
                unit(self.at(mx0, my0) + self.at(mx1, my0) + self.at(mx0, my1) + self.at(mx1, my1));
            let there = unit(self.at(nx, ny));
            let f = dir.dot(mid).abs();
            let c = here.dot(there).abs();
            let o = &self.opts;
            visit(
                j,
                len + o.w_flow * (1.0 - f.powi(o.power)) + o.w_curvature * (1.0 - c),
            );
        }
    }

    /// The least-cost distance from pixel `from` to every pixel, with the
    /// pixels where `blocked` is true left out (Dijkstra's algorithm);
    /// infinite where none reaches.
    pub fn distances(&self, from: usize, blocked: Option<&[bool]>) -> Vec<f64> {
        let n = self.width() * self.height();
        let mut dist = vec![f64::INFINITY; n];
        let Some(d0) = dist.get_mut(from) else {
            return dist;
        };
        *d0 = 0.0;
        let mut heap = BinaryHeap::new();
        heap.push((Reverse(Cost(0.0)), from));
        while let Some((Reverse(Cost(d)), i)) = heap.pop() {
            if d > dist[i] {
                continue;
            }
            self.links_from(i, |j, cost| {
                if blocked.is_some_and(|b| b.get(j).copied().unwrap_or(true)) {
                    return;
                }
                let nd = d + cost;
                if nd < dist[j] {
                    dist[j] = nd;
                    heap.push((Reverse(Cost(nd)), j));
                }
            });
        }
        dist
    }
}

/// The least-cost path from `start` to `end` (pixel coordinates of `flow`'s
/// grid) over the 32-neighbour pixel graph; its first and last vertices are
/// `start` and `end` themselves, the others pixel centres.
pub fn shortest_path(
    flow: &DirectionGrid,
    start: Point,
    end: Point,
    opts: &SpineOptions,
) -> Result<Vec<Point>> {
    let (w, h) = (flow.width(), flow.height());
    if w == 0 || h == 0 {
        return Err(Error::invalid("empty exemplar grid").in_file("spine"));
    }
    let pixel = |p: Point| -> usize {
        let x = (p.x.floor().max(0.0) as usize).min(w - 1);
        let y = (p.y.floor().max(0.0) as usize).min(h - 1);
        y * w + x
    };
    let (s, e) = (pixel(start), pixel(end));
    let graph = LinkGraph::new(flow, opts);
    let mut dist = vec![f64::INFINITY; w * h];
    let mut parent = vec![usize::MAX; w * h];
    // A*: every link costs at least its length, so the straight distance
    // to the end is a consistent lower bound and the path found is the
    // same least-cost path Dijkstra's algorithm finds, from fewer pixels.
    let (ex, ey) = ((e % w) as f64, (e / w) as f64);
    let to_end = |j: usize| ((j % w) as f64 - ex).hypot((j / w) as f64 - ey);
    let mut heap = BinaryHeap::new();
    dist[s] = 0.0;
    heap.push((Reverse(Cost(to_end(s))), Reverse(Cost(0.0)), s));
    while let Some((_, Reverse(Cost(d)), i)) = heap.pop() {
        if i == e {
            break;
        }
        if d > dist[i] {
            continue;
        }
        graph.links_from(i, |j, cost| {
            let nd = d + cost;
            if nd < dist[j] {
                dist[j] = nd;
                parent[j] = i;
                heap.push((Reverse(Cost(nd + to_end(j))), Reverse(Cost(nd)), j));
            }
        });
    }
    if !dist[e].is_finite() {
        return Err(Error::invalid("no path between start and end").in_file("spine"));
    }
    let mut idx = vec![e];
    let mut i = e;
    while i != s {
        i = parent[i];
        if i == usize::MAX || idx.len() > w * h {
            return Err(Error::invalid("broken path").in_file("spine"));
        }
        idx.push(i);
    }
    idx.reverse();
    let mut pts: Vec<Point> = idx
        .iter()
        .map(|&i| Point::new((i % w) as f64 + 0.5, (i / w) as f64 + 0.5))
        .collect();
    if let Some(p) = pts.first_mut() {
        *p = start;
    }
    if pts.len() == 1 {
        pts.push(end);
    } else if let Some(p) = pts.last_mut() {
        *p = end;
    }
    Ok(pts)
}

/// A total order on finite path costs for the heap.
#[derive(Clone, Copy, PartialEq)]
pub(crate) struct Cost(pub(crate) f64);

impl Eq for Cost {}

impl PartialOrd for Cost {
    fn partial_cmp(&self, other: &Self) -> Option<std::cmp::Ordering> {
        Some(self.cmp(other))
    }
}

impl Ord for Cost {
    fn cmp(&self, other: &Self) -> std::cmp::Ordering {
        self.0.total_cmp(&other.0)
    }
}

/// A quartic curve through fixed end points:
/// `x(t) = (1 − t) S + t E + t (1 − t) (a + b t + c t²)`, `t ∈ [0, 1]`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Quartic {
    /// `S`, the start.
    pub start: Point,
    /// `E`, the end.
    pub end: Point,
    /// `a, b, c` (one vector each).
    pub coeffs: [Vec2; 3],
}

impl Quartic {
    /// The least-squares fit to `pts` (chord-length parameters), keeping
    /// the first and last points exactly.
    pub fn fit(pts: &[Point]) -> Quartic {
        let (start, end) = match (pts.first(), pts.last()) {
            (Some(&a), Some(&b)) => (a, b),
            _ => (Point::ZERO, Point::ZERO),
        };
        let mut q = Quartic {
            start,
            end,
            coeffs: [Vec2::ZERO; 3],
        };
        if pts.len() < 3 {
            return q;
        }
        let mut cum = vec![0.0];
        for w in pts.windows(2) {
            cum.push(cum[cum.len() - 1] + w[0].distance(w[1]));
        }
        let total = cum[cum.len() - 1];
        if total <= 0.0 {
            return q;
        }
        let mut ata = nalgebra::Matrix3::<f64>::zeros();
        let mut atb = nalgebra::Matrix3x2::<f64>::zeros();
        for (p, s) in pts.iter().zip(&cum) {
            let t = s / total;
            let base = start.to_vec2() * (1.0 - t) + end.to_vec2() * t;
            let r = p.to_vec2() - base;
            let g = t * (1.0 - t);
            let phi = nalgebra::Vector3::new(g, g * t, g * t * t);
            ata += phi * phi.transpose();
            for k in 0..3 {
                atb[(k, 0)] += phi[k] * r.x;
                atb[(k, 1)] += phi[k] * r.y;
            }
        }
        // Tiny ridge: a well-posed solve even for a handful of points.
        ata += nalgebra::Matrix3::identity() * 1e-12;
        if let Some(sol) = ata.cholesky().map(|c| c.solve(&atb)) {
            for k in 0..3 {
                q.coeffs[k] = Vec2::new(sol[(k, 0)], sol[(k, 1)]);
            }
        }
        q
    }

    /// The point at parameter `t`.
    pub fn eval(&self, t: f64) -> Point {
        let g = t * (1.0 - t);
        let poly = self.coeffs[0] + self.coeffs[1] * t + self.coeffs[2] * (t * t);
        (self.start.to_vec2() * (1.0 - t) + self.end.to_vec2() * t + poly * g).to_point()
    }

    /// `n + 1` points at evenly spaced parameters.
    pub fn polyline(&self, n: usize) -> Vec<Point> {
        let n = n.max(1);
        (0..=n).map(|i| self.eval(i as f64 / n as f64)).collect()
    }
}

/// The fitted main branch between `start` and `end` (pixel coordinates of
/// the ink grid `ink_sdf`, signed distances in px): the least-cost path
/// through the flow, smoothed by a [`Quartic`]. Returns the raw path and
/// the fit.
pub fn trace_spine(
    ink_sdf: &Grid<f32>,
    start: Point,
    end: Point,
    opts: &SpineOptions,
) -> Result<(Vec<Point>, Quartic)> {
    let flow = exemplar_flow(ink_sdf);
    let path = shortest_path(&flow, start, end, opts)?;
    let fit = Quartic::fit(&path);
    Ok((path, fit))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::raster::sdf::point_segment_distance;
    use kurbo::Line;

    #[test]
    fn there_are_32_link_directions_spread_around_the_circle() {
        let l = link_offsets();
        assert_eq!(l.len(), 32);
        let mut angles: Vec<f64> = l.iter().map(|&(x, y)| (y as f64).atan2(x as f64)).collect();
        angles.sort_by(f64::total_cmp);
        let gaps: Vec<f64> = angles.windows(2).map(|w| w[1] - w[0]).collect();
        let max_gap = gaps.iter().cloned().fold(0.0, f64::max);
        assert!(max_gap < 0.33, "{max_gap}"); // uniform would be 0.196
    }

    /// Signed distance to a polyline band of half-width `r`.
    fn band_sdf(n: usize, centre: &[Point], r: f64) -> Grid<f32> {
        Grid::from_fn(n, n, |x, y| {
            let p = Point::new(x as f64 + 0.5, y as f64 + 0.5);
            let d = centre
                .windows(2)
                .map(|w| point_segment_distance(p, Line::new(w[0], w[1])))
                .fold(f64::INFINITY, f64::min);
            (d - r) as f32
        })
    }

    fn dist_to(centre: &[Point], p: Point) -> f64 {
        centre
            .windows(2)
            .map(|w| point_segment_distance(p, Line::new(w[0], w[1])))
            .fold(f64::INFINITY, f64::min)
    }

    #[test]
    fn a_straight_band_gets_a_straight_centred_spine() {
        let centre = [Point::new(20.0, 64.3), Point::new(108.0, 64.3)];
        let sdf = band_sdf(128, &centre, 8.0);
        let (path, fit) = trace_spine(
            &sdf,
            Point::new(24.0, 64.3),
            Point::new(104.0, 64.3),
            &SpineOptions::default(),
        )
        .unwrap();
        assert!(path.len() > 5);
        for p in fit.polyline(100) {
            assert!((p.y - 64.3).abs() < 1.0, "{p:?}");
        }
    }

    #[test]
    fn an_s_shaped_band_gets_a_spine_that_follows_the_s() {
        let centre: Vec<Point> = (0..=100)
            .map(|i| {
                let t = i as f64 / 100.0;
                Point::new(
                    16.0 + 96.0 * t,
                    64.0 + 26.0 * (2.0 * std::f64::consts::PI * t).sin(),
                )
            })
            .collect();
        let sdf = band_sdf(128, &centre, 6.0);
        let (path, fit) =
            trace_spine(&sdf, centre[2], centre[98], &SpineOptions::default()).unwrap();
        // The raw path stays in the band, the fit near its centre line, and
        // the fit really is an S: above the middle first, then below.
        for p in &path {
            assert!(dist_to(&centre, *p) < 6.0, "{p:?}");
        }
        let pts = fit.polyline(200);
        let mean: f64 = pts.iter().map(|p| dist_to(&centre, *p)).sum::<f64>() / pts.len() as f64;
        let worst = pts.iter().map(|p| dist_to(&centre, *p)).fold(0.0, f64::max);
        assert!(mean < 2.0 && worst < 6.0, "mean {mean}, worst {worst}");
        assert!(fit.eval(0.25).y > 80.0 && fit.eval(0.75).y < 48.0);
    }

    #[test]
    fn the_flow_term_pulls_the_path_along_the_lines() {
        // Two points on a ring: the path follows the ring rather than the
        // chord through the empty middle.
        let (c, r) = (Point::new(64.0, 64.0), 40.0);
        let sdf = Grid::from_fn(128, 128, |x, y| {
            let p = Point::new(x as f64 + 0.5, y as f64 + 0.5);
            ((p.distance(c) - r).abs() - 4.0) as f32
        });
        let a = Point::new(24.0, 64.0);
        let b = Point::new(104.0, 64.0);
        let flow = exemplar_flow(&sdf);
        let path = shortest_path(&flow, a, b, &SpineOptions::default()).unwrap();
        let off = path
            .iter()
            .filter(|p| ((p.distance(c) - r).abs()) > 5.0)
            .count();
        assert!(off * 10 < path.len(), "{off} of {}", path.len());
    }

    #[test]
    fn quartic_reproduces_a_quartic_and_keeps_the_ends() {
        let truth = Quartic {
            start: Point::new(0.0, 0.0),
            end: Point::new(100.0, 10.0),
            coeffs: [
                Vec2::new(0.0, 40.0),
                Vec2::new(0.0, 20.0),
                Vec2::new(0.0, -60.0),
            ],
        };
        // Sample at chord-length-uniform parameters so the fit's `t` agrees.
        let dense = truth.polyline(4000);
        let mut cum = vec![0.0];
        for w in dense.windows(2) {
            cum.push(cum[cum.len() - 1] + w[0].distance(w[1]));
        }
        let total = cum[cum.len() - 1];
        let pts: Vec<Point> = (0..=60)
            .map(|i| {
                let s = total * i as f64 / 60.0;
                let k = cum.partition_point(|&c| c < s).min(dense.len() - 1);
                dense[k]
            })
            .collect();
        let fit = Quartic::fit(&pts);
        assert_eq!(fit.start, pts[0]);
        assert_eq!(fit.end, pts[60]);
        for p in &pts {
            let d = fit
                .polyline(400)
                .iter()
                .map(|q| q.distance(*p))
                .fold(f64::INFINITY, f64::min);
            assert!(d < 0.5, "{d}");
        }
    }
}
