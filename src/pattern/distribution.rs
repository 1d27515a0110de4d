//! Element distribution (Barla et al. §2.3): neighbour graphs over element
//! centres, k-ring neighbourhoods, shift vectors and densities.
//!
//! A row example (1-D) links its elements in a chain ordered along the
//! row; a field example (2-D) uses the Delaunay triangulation of the
//! centres, keeping only edges of at least one unskewed triangle (no angle
//! above 2π/3), so the long, thin triangles at the border add no false
//! neighbours. The same graph builder serves the synthesized seeds (§3.2).
//!
//! The shift vector of an element is how far it sits from the barycentre of
//! its neighbours; it is kept as the sum S = Σⱼ (cᵢ − cⱼ) = n·(cᵢ − c̄), so
//! that the paper's variation rule S_tar = S_ref·A_tar/(n·A_ref) (§3.3)
//! gives back the reference displacement when the neighbourhoods agree.

use kurbo::{Point, Vec2};
use spade::{DelaunayTriangulation, HasPosition, Point2, Triangulation};
use std::collections::{BTreeSet, VecDeque};
use std::f64::consts::{FRAC_PI_2, PI};

/// Whether a distribution is a row or a field.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Dim {
    /// Elements along a line (a chain of neighbours).
    One,
    /// Elements over an area (a Delaunay graph of neighbours).
    Two,
}

/// A vertex carrying its index, so spade's merges and reorderings never
/// confuse which point is which.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Indexed {
    pub pos: Point2<f64>,
    pub idx: usize,
}

impl HasPosition for Indexed {
    type Scalar = f64;
    fn position(&self) -> Point2<f64> {
        self.pos
    }
}

/// A neighbour graph over points.
#[derive(Clone, Debug, Default)]
pub struct Graph {
    /// Sorted neighbour lists, one per point.
    pub adj: Vec<Vec<usize>>,
    /// The area each point's 1-ring covers: in 2-D the kept triangles
    /// around it, in 1-D the length between its two neighbours.
    pub hood_area: Vec<f64>,
}

impl Graph {
    /// The chain 0–1–…–(n−1) (closed when `cyclic`), with lengths
    /// measured along x.
    pub fn chain(xs: &[f64], cyclic: bool, period: f64) -> Graph {
        let n = xs.len();
        let mut adj = vec![Vec::new(); n];
        for i in 0..n.saturating_sub(1) {
            adj[i].push(i + 1);
            adj[i + 1].push(i);
        }
        if cyclic && n > 2 {
            adj[0].push(n - 1);
            adj[n - 1].push(0);
        }
        for a in &mut adj {
            a.sort_unstable();
            a.dedup();
        }
        let hood_area = (0..n)
            .map(|i| {
                let gaps: Vec<f64> = adj[i]
                    .iter()
                    .map(|&j| {
                        let d = (xs[j] - xs[i]).abs();
                        if cyclic {
                            d.min(period - d)
                        } else {
                            d
                        }
                    })
                    .collect();
                match gaps.len() {
                    0 => 0.0,
                    1 => 2.0 * gaps[0],
                    _ => gaps.iter().sum(),
                }
            })
            .collect();
        Graph { adj, hood_area }
    }

    /// The Delaunay graph of `pts` restricted to edges of unskewed
    /// triangles (largest angle ≤ 2π/3), §2.3.
    pub fn delaunay(pts: &[Point]) -> Graph {
        let n = pts.len();
        let mut adj = vec![Vec::new(); n];
        let mut hood_area = vec![0.0; n];
        let verts: Vec<Indexed> = pts
            .iter()
            .enumerate()
            .filter(|(_, p)| p.x.is_finite() && p.y.is_finite())
            .map(|(idx, p)| Indexed {
                pos: Point2::new(p.x, p.y),
                idx,
            })
            .collect();
        let Ok(tri) = DelaunayTriangulation::<Indexed>::bulk_load(verts) else {
            return Graph { adj, hood_area };
        };
        let mut edges = BTreeSet::new();
        for f in tri.inner_faces() {
            let v = f.vertices();
            let ids = [v[0].data().idx, v[1].data().idx, v[2].data().idx];
            let p = ids.map(|i| pts[i]);
            if max_angle(p) > 2.0 * std::f64::consts::FRAC_PI_3 + 1e-9 {
                continue;
            }
            let area = 0.5 * (p[1] - p[0]).cross(p[2] - p[0]).abs();
            for k in 0..3 {
                let (a, b) = (ids[k], ids[(k + 1) % 3]);
                edges.insert((a.min(b), a.max(b)));
                hood_area[ids[k]] += area;
            }
        }
        for (a, b) in edges {
            adj[a].push(b);
            adj[b].push(a);
        }
        for a in &mut adj {
            a.sort_unstable();
        }
        Graph { adj, hood_area }
    }

    /// The k-ring around `i` (breadth first, `i` excluded), in BFS order.
    pub fn ring(&self, i: usize, k: usize) -> Vec<usize> {
        let mut seen = BTreeSet::from([i]);
        let mut out = Vec::new();
        let mut q = VecDeque::from([(i, 0usize)]);
        while let Some((v, d)) = q.pop_front() {
            if d == k {
                continue;
            }
            for &w in &self.adj[v] {
                if seen.insert(w) {
                    out.push(w);
                    q.push_back((w, d + 1));
                }
            }
        }
        out
    }

    /// Mean edge length.
    pub fn mean_edge(&self, pts: &[Point]) -> Option<f64> {
        let mut sum = 0.0;
        let mut n = 0usize;
        for (i, a) in self.adj.iter().enumerate() {
            for &j in a {
                if j > i {
                    sum += (pts[j] - pts[i]).hypot();
                    n += 1;
                }
            }
        }
        (n > 0).then(|| sum / n as f64)
    }
}

/// Largest interior angle of a triangle, radians.
pub fn max_angle(p: [Point; 3]) -> f64 {
    (0..3)
        .map(|k| {
            let (a, b, c) = (p[k], p[(k + 1) % 3], p[(k + 2) % 3]);
            let (u, v) = (b - a, c - a);
            let (lu, lv) = (u.hypot(), v.hypot());
            if lu == 0.0 || lv == 0.0 {
                return std::f64::consts::PI;
            }
            (u.dot(v) / (lu * lv)).clamp(-1.0, 1.0).acos()
        })
        .fold(0.0, f64::max)
}

/// The reference distribution of an example's elements.
#[derive(Clone, Debug)]
pub struct Distribution {
    /// Row or field.
    pub dim: Dim,
    /// Element centres in the reference frame.
    pub centres: Vec<Point>,
    /// The 1-ring graph.
    pub graph: Graph,
    /// Shift vectors S = Σⱼ (cᵢ − cⱼ) over the 1-ring; `None` when isolated.
    pub shift: Vec<Option<Vec2>>,
    /// Mean neighbour distance, reference units.
    pub spacing: f64,
    /// Distance between rows when a row example fills a region: the mean
    /// height of the elements across the row plus half a spacing. Equal to
    /// `spacing` for a field.
    pub pitch: f64,
    /// The area (2-D) the elements cover, A_ref: for a field, the convex
    /// hull of the centres grown by half a spacing (hull + perimeter·s/2 +
    /// π·s²/4); for a row, N·spacing·pitch (stacked rows).
    pub area: f64,
}

impl Distribution {
    /// Analyses centres already expressed in the reference frame (for a
    /// row, x runs along it); `heights` are the elements' extents across
    /// the row (along y); `lone_spacing` is the spacing used when there is
    /// no second element to measure one from.
    pub fn analyse(
        centres: Vec<Point>,
        heights: &[f64],
        dim: Dim,
        lone_spacing: f64,
    ) -> Distribution {
        let n = centres.len();
        let (graph, spacing) = match dim {
            Dim::One => {
                // Elements are already sorted along x by the caller.
                let xs: Vec<f64> = centres.iter().map(|c| c.x).collect();
                let g = Graph::chain(&xs, false, 0.0);
                let along = if n > 1 {
                    (xs[n - 1] - xs[0]).abs() / (n - 1) as f64
                } else {
                    0.0
                };
                (g, along)
            }
            Dim::Two => {
                let g = Graph::delaunay(&centres);
                let s = g.mean_edge(&centres).unwrap_or(0.0);
                (g, s)
            }
        };
        // A lone element, or a degenerate field: fall back to the box size
        // so densities stay finite.
        let spacing = if spacing > 0.0 {
            spacing
        } else {
            nearest_spacing(&centres).unwrap_or(lone_spacing)
        };
        // Only surrounded elements have a meaningful shift: at the border
        // of the example the neighbours all lie on one side and the
        // "displacement" would just point outward.
        let shift = (0..n)
            .map(|i| {
                let a = &graph.adj[i];
                let offsets = a.iter().map(|&j| centres[j] - centres[i]);
                surrounded(offsets, dim).then(|| {
                    a.iter()
                        .fold(Vec2::ZERO, |s, &j| s + (centres[i] - centres[j]))
                })
            })
            .collect();
        let hull = convex_hull(&centres);
        let (ha, hp) = (polygon_area(&hull).abs(), polygon_perimeter(&hull));
        let pitch = match dim {
            Dim::Two => spacing,
            Dim::One => heights.iter().sum::<f64>() / heights.len().max(1) as f64 + 0.5 * spacing,
        };
        let area = match dim {
            Dim::Two => ha + hp * spacing / 2.0 + std::f64::consts::PI * spacing * spacing / 4.0,
            Dim::One => n as f64 * spacing * pitch,
        };
        Distribution {
            dim,
            pitch,
            centres,
            graph,
            shift,
            spacing,
            area,
        }
    }

    /// Distance between neighbours when the elements are laid in a chain
    /// along a path, reference units: a row keeps its own spacing; a field's
    /// chain takes the field's mean nearest-neighbour distance, so that each
    /// element meets its nearest neighbour as close as in the example (the
    /// Delaunay edges of a field are longer than its nearest neighbours).
    pub fn chain_spacing(&self) -> f64 {
        match self.dim {
            Dim::One => self.spacing,
            Dim::Two => nearest_spacing(&self.centres).unwrap_or(self.spacing),
        }
    }
}

/// True when neighbours at `offsets` surround their element: in 1-D one
/// on each side, in 2-D no angular gap between them wider than 0.8π.
pub fn surrounded(offsets: impl Iterator<Item = Vec2>, dim: Dim) -> bool {
    let mut angles: Vec<f64> = offsets.map(|o| o.y.atan2(o.x)).collect();
    match dim {
        Dim::One => {
            angles.iter().any(|a| a.abs() < FRAC_PI_2) && angles.iter().any(|a| a.abs() > FRAC_PI_2)
        }
        Dim::Two => {
            if angles.len() < 3 {
                return false;
            }
            angles.sort_by(f64::total_cmp);
            let wrap = angles[0] + 2.0 * PI - angles[angles.len() - 1];
            let max_gap = angles.windows(2).map(|w| w[1] - w[0]).fold(wrap, f64::max);
            max_gap < 0.8 * PI
        }
    }
}

/// Mean distance to the nearest other centre (brute force; examples are small).
pub fn nearest_spacing(c: &[Point]) -> Option<f64> {
    if c.len() < 2 {
        return None;
    }
    let mut sum = 0.0;
    for (i, a) in c.iter().enumerate() {
        let d = c
            .iter()
            .enumerate()
            .filter(|(j, _)| *j != i)
            .map(|(_, b)| (*b - *a).hypot())
            .fold(f64::MAX, f64::min);
        sum += d;
    }
    let s = sum / c.len() as f64;
    (s > 0.0).then_some(s)
}

/// Convex hull (Andrew's monotone chain), counter-clockwise.
pub fn convex_hull(pts: &[Point]) -> Vec<Point> {
    let mut p: Vec<Point> = pts.to_vec();
    p.sort_by(|a, b| a.x.total_cmp(&b.x).then(a.y.total_cmp(&b.y)));
    p.dedup();
    if p.len() < 3 {
        return p;
    }
    let cross = |o: Point, a: Point, b: Point| (a - o).cross(b - o);
    let mut lower: Vec<Point> = Vec::new();
    for &q in &p {
        while lower.len() >= 2 && cross(lower[lower.len() - 2], lower[lower.len() - 1], q) <= 0.0 {
            lower.pop();
        }
        lower.push(q);
    }
    let mut upper: Vec<Point> = Vec::new();
    for &q in p.iter().rev() {
        while upper.len() >= 2 && cross(upper[upper.len() - 2], upper[upper.len() - 1], q) <= 0.0 {
            upper.pop();
        }
        upper.push(q);
    }
    lower.pop();
    upper.pop();
    lower.extend(upper);
    lower
}

/// Signed area of a closed polygon (positive counter-clockwise in a y-up
/// frame, i.e. clockwise on screen).
pub fn polygon_area(p: &[Point]) -> f64 {
    let n = p.len();
    (0..n)
        .map(|i| p[i].to_vec2().cross(p[(i + 1) % n].to_vec2()))
        .sum::<f64>()
        / 2.0
}

/// Perimeter of a closed polygon (for two points: twice their distance).
pub fn polygon_perimeter(p: &[Point]) -> f64 {
    let n = p.len();
    if n < 2 {
        return 0.0;
    }
    (0..n).map(|i| (p[(i + 1) % n] - p[i]).hypot()).sum()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn skewed_border_triangles_are_dropped() {
        // A square grid plus one point far out on the side: the sliver
        // triangles it makes are skewed and their long edges dropped.
        let mut pts: Vec<Point> = (0..3)
            .flat_map(|i| (0..3).map(move |j| Point::new(i as f64 * 10.0, j as f64 * 10.0)))
            .collect();
        pts.push(Point::new(10.0, -1.0));
        let g = Graph::delaunay(&pts);
        // (0,0)–(20,0) would pass under the outlier through a flat triangle.
        assert!(!g.adj[0].contains(&6), "{:?}", g.adj);
        assert!(g.adj[4].len() >= 4);
    }

    #[test]
    fn ring_grows_by_hops() {
        let g = Graph::chain(&[0.0, 1.0, 2.0, 3.0, 4.0], false, 0.0);
        assert_eq!(g.ring(2, 1), vec![1, 3]);
        assert_eq!(g.ring(2, 2), vec![1, 3, 0, 4]);
        assert_eq!(g.hood_area[0], 2.0);
    }
}
