//! Centerline tracing: a drawing of lines (pen or pencil, scanned or
//! photographed) to open stroked paths along the lines' centres.
//!
//! The ink (coverage ≥ ½, pinholes of grain filled and specks dropped) is
//! thinned to a one-pixel skeleton (Zhang & Suen 1984, "A fast parallel
//! algorithm for thinning digital patterns"), read as a graph of edges
//! between junctions and ends, and cleaned as a draughtsman reads the
//! drawing: spurs shorter than the line width are dropped, junctions closer
//! than the line width are one, and at each junction the edges that
//! continue each other most straightly are paired, so an X crossing gives
//! two strokes that run straight through and a T junction ends its stem on
//! the bar. Free ends facing each other across a gap shorter than the line
//! width are bridged. Each stroke is smoothed and fitted with cubics within
//! the tolerance ([`super::cover::fit_open`]); its width is the ink's
//! measured width across it (coverage integrated along the normal), or the
//! caller's.

use super::cover::fit_open;
use crate::outline::chain::open_chain;
use crate::raster::edt::squared_edt;
use crate::raster::skeleton::{skeleton, RING as NEIGHBOURS};
use crate::raster::{Coverage, Grid};
use kurbo::{BezPath, Point, Vec2};

/// Two edges at a junction continue each other when the angle between
/// one's direction and the other's reversed is below this: 35°.
const CONTINUE_COS: f64 = 0.819;

/// Spurs shorter than this (px) are dropped whatever the line width.
const SPUR_FLOOR: f64 = 3.0;

/// Two free ends are bridged when each points at the other within this
/// angle: 40°.
const BRIDGE_COS: f64 = 0.766;

/// Slack on the bridging distance (px): a soft pencil tip fades under
/// half coverage up to half a pixel early on each side.
const BRIDGE_SLACK_PX: f64 = 1.0;

/// A traced line: its centre as a polyline and its width, in pixels.
#[derive(Clone, Debug)]
pub struct Line {
    /// Points along the centre (px, pixel centres at half-integers).
    pub points: Vec<Point>,
    /// Whether the line closes on itself (its last point joins its first).
    pub closed: bool,
    /// The measured width of the ink across the line (px).
    pub width: f64,
    /// Whether its first and its last point are free ends (not on a
    /// junction, not a closed line's).
    pub free: [bool; 2],
}

/// A stroke fitted with cubics: its path (px) and width (px).
#[derive(Clone, Debug)]
pub struct Stroke {
    /// The fitted centre line, open or closed.
    pub path: BezPath,
    /// Stroke width (px).
    pub width: f64,
}

/// The lines of the drawing of coverage `cov` (0 paper … 1 ink) fitted
/// with cubics within `tolerance` px of their smoothed centres; widths
/// measured, or `width` px when given. Ink islands under `min_area` px²
/// are dropped.
pub fn trace_lines(
    cov: &Coverage,
    width: Option<f64>,
    tolerance: f64,
    min_area: f64,
) -> Vec<Stroke> {
    centerlines(cov, min_area)
        .into_iter()
        .filter_map(|line| {
            let path = fit_line(&line, tolerance)?;
            Some(Stroke {
                path,
                width: width.unwrap_or(line.width),
            })
        })
        .collect()
}

/// Fits `line` with cubics within `tolerance` px; `None` when it has
/// fewer than two distinct points.
fn fit_line(line: &Line, tolerance: f64) -> Option<BezPath> {
    let mut pts = line.points.clone();
    if line.closed {
        pts.push(*pts.first()?);
    }
    let chain = open_chain(pts);
    let cubics = fit_open(&chain.points, &chain.tangents, &chain.corners, tolerance);
    let first = cubics.first()?;
    let mut path = BezPath::new();
    path.move_to(first.p0);
    for c in &cubics {
        path.curve_to(c.p1, c.p2, c.p3);
    }
    if line.closed {
        path.close_path();
    }
    Some(path)
}

/// The centre lines of the drawing of coverage `cov`, as smoothed
/// polylines with their measured widths (see the module comment).
pub fn centerlines(cov: &Coverage, min_area: f64) -> Vec<Line> {
    let (w, h) = (cov.width(), cov.height());
    let mut ink: Vec<bool> = cov.data().iter().map(|&c| c >= 0.5).collect();
    if !ink.contains(&true) {
        return Vec::new();
    }
    // A first width from the distance transform's ridge: pinholes smaller
    // than a line width's square are grain, ink islands smaller than it
    // are specks.
    let w0 = ridge_width(&ink, w, h);
    let small = (w0 * w0).max(2.0);
    clean_components(&mut ink, w, h, false, small);
    clean_components(&mut ink, w, h, true, small.max(min_area));
    let skel = match Grid::from_vec(w, h, ink) {
        Some(g) => skeleton(&g).data().to_vec(),
        None => return Vec::new(),
    };
    let mut g = Graph::from_skeleton(&skel, w, h);
    let width_of = |pts: &[Point]| median(line_widths(cov, pts, w0));
    let all: Vec<Point> = g.edges.iter().flat_map(|e| e.pts.clone()).collect();
    let lw = if all.is_empty() {
        w0
    } else {
        width_of(&all).max(1.0)
    };
    g.simplify(lw);
    let mut lines = g.strokes(lw, cov);
    lines.extend(g.cycles.iter().map(|c| Line {
        points: c.clone(),
        closed: true,
        width: 0.0,
        free: [false; 2],
    }));
    let lines = bridge(lines, lw);
    lines
        .into_iter()
        .filter(|l| l.closed || length(&l.points) >= lw)
        .map(|mut l| {
            l.points = smooth(&l.points, l.closed);
            l.width = (width_of(&l.points) * 100.0).round() / 100.0;
            if l.width.is_nan() || l.width <= 0.0 {
                l.width = (lw * 100.0).round() / 100.0;
            }
            l
        })
        .collect()
}

/// The median of `v` (0 when empty).
fn median(mut v: Vec<f64>) -> f64 {
    if v.is_empty() {
        return 0.0;
    }
    v.sort_by(f64::total_cmp);
    v[v.len() / 2]
}

/// Length (px) of a polyline.
fn length(pts: &[Point]) -> f64 {
    pts.windows(2).map(|p| p[0].distance(p[1])).sum()
}

/// A line width (px) read off the distance transform: twice the median
/// distance to the paper over the ink's ridge pixels (those at least as
/// far from the paper as their 8 neighbours), less a pixel.
fn ridge_width(ink: &[bool], w: usize, h: usize) -> f64 {
    let paper = Grid::from_fn(w, h, |x, y| !ink[y * w + x]);
    let d2 = squared_edt(&paper);
    let mut ridge = Vec::new();
    for y in 0..h {
        for x in 0..w {
            let d = d2.get(x, y);
            if d <= 0.0 {
                continue;
            }
            let top = (-1..=1)
                .all(|dy| (-1..=1).all(|dx| d2.get_or(x as isize + dx, y as isize + dy, 0.0) <= d));
            if top {
                ridge.push(f64::from(d).sqrt());
            }
        }
    }
    (2.0 * median(ridge) - 1.0).max(1.0)
}

/// Flips the 4-connected (paper, `ink` false) or 8-connected (ink, `ink`
/// true) components of `mask` of that value with fewer than `small`
/// pixels; paper touching the border is never filled.
fn clean_components(mask: &mut [bool], w: usize, h: usize, ink: bool, small: f64) {
    let mut seen = vec![false; w * h];
    let mut stack = Vec::new();
    let mut comp = Vec::new();
    for start in 0..w * h {
        if seen[start] || mask[start] != ink {
            continue;
        }
        seen[start] = true;
        stack.push(start);
        comp.clear();
        let mut border = false;
        while let Some(i) = stack.pop() {
            comp.push(i);
            let (x, y) = ((i % w) as isize, (i / w) as isize);
            for (dx, dy) in NEIGHBOURS {
                if !ink && dx != 0 && dy != 0 {
                    continue;
                }
                let (nx, ny) = (x + dx, y + dy);
                if nx < 0 || ny < 0 || nx >= w as isize || ny >= h as isize {
                    border = true;
                    continue;
                }
                let j = ny as usize * w + nx as usize;
                if !seen[j] && mask[j] == ink {
                    seen[j] = true;
                    stack.push(j);
                }
            }
        }
        if (comp.len() as f64) < small && (ink || !border) {
            for &i in &comp {
                mask[i] = !ink;
            }
        }
    }
}

/// An edge of the skeleton graph: a run of skeleton pixels between two
/// nodes (their centres, px).
#[derive(Clone, Debug)]
struct Edge {
    /// Node at `pts`' first point.
    a: usize,
    /// Node at `pts`' last point.
    b: usize,
    /// Pixel centres from node `a` to node `b`.
    pts: Vec<Point>,
    /// False once pruned or contracted.
    alive: bool,
}

/// A node of the skeleton graph: a free end or a junction.
#[derive(Clone, Debug)]
struct Node {
    /// Centre (px).
    pos: Point,
    /// Distance (px) from the centre to the farthest pixel it stands for.
    radius: f64,
    /// Whether the node is a junction (3 or more edges met there).
    junction: bool,
}

/// The skeleton as a graph of edges between ends and junctions, and the
/// closed loops that touch no node.
struct Graph {
    nodes: Vec<Node>,
    edges: Vec<Edge>,
    /// Closed skeleton loops with no junction or end (pixel centres).
    cycles: Vec<Vec<Point>>,
}

/// The centre of pixel `i` of a `w`-wide grid.
fn centre(i: usize, w: usize) -> Point {
    Point::new((i % w) as f64 + 0.5, (i / w) as f64 + 0.5)
}

impl Graph {
    /// Reads skeleton `s` as a graph. Pixels are 8-adjacent, except that a
    /// diagonal step is left out when both pixels share a 4-neighbour on
    /// the skeleton (a staircase is a path, not a triangle); pixels with
    /// other than two neighbours are nodes, 8-adjacent junction pixels one
    /// node.
    fn from_skeleton(s: &[bool], w: usize, h: usize) -> Graph {
        let at = |x: isize, y: isize| {
            x >= 0 && y >= 0 && x < w as isize && y < h as isize && s[y as usize * w + x as usize]
        };
        let nbrs = |i: usize| -> Vec<usize> {
            let (x, y) = ((i % w) as isize, (i / w) as isize);
            NEIGHBOURS
                .iter()
                .filter(|&&(dx, dy)| {
                    at(x + dx, y + dy) && !(dx != 0 && dy != 0 && (at(x + dx, y) || at(x, y + dy)))
                })
                .map(|&(dx, dy)| (y + dy) as usize * w + (x + dx) as usize)
                .collect()
        };
        let mut node_of = vec![usize::MAX; w * h];
        let mut nodes: Vec<Node> = Vec::new();
        let pixels: Vec<usize> = (0..w * h).filter(|&i| s[i]).collect();
        let degree: Vec<(usize, usize)> = pixels.iter().map(|&i| (i, nbrs(i).len())).collect();
        // Junction clusters (flood over 8-adjacent junction pixels), then
        // ends.
        let is_junction = |i: usize, deg: &[(usize, usize)]| {
            deg.binary_search_by_key(&i, |&(p, _)| p)
                .is_ok_and(|k| deg[k].1 >= 3)
        };
        for &(i, d) in &degree {
            if d < 3 || node_of[i] != usize::MAX {
                continue;
            }
            let id = nodes.len();
            let mut members = vec![i];
            node_of[i] = id;
            let mut k = 0;
            while k < members.len() {
                let p = members[k];
                k += 1;
                let (x, y) = ((p % w) as isize, (p / w) as isize);
                for (dx, dy) in NEIGHBOURS {
                    if !at(x + dx, y + dy) {
                        continue;
                    }
                    let q = (y + dy) as usize * w + (x + dx) as usize;
                    if node_of[q] == usize::MAX && is_junction(q, &degree) {
                        node_of[q] = id;
                        members.push(q);
                    }
                }
            }
            let n = members.len() as f64;
            let pos = members
                .iter()
                .fold(Point::ZERO, |acc, &p| acc + centre(p, w).to_vec2() / n);
            let radius = members
                .iter()
                .map(|&p| centre(p, w).distance(pos))
                .fold(0.0, f64::max);
            nodes.push(Node {
                pos,
                radius,
                junction: true,
            });
        }
        for &(i, d) in &degree {
            if d == 1 {
                node_of[i] = nodes.len();
                nodes.push(Node {
                    pos: centre(i, w),
                    radius: 0.0,
                    junction: false,
                });
            }
        }
        let mut on_edge = vec![false; w * h];
        let mut used = std::collections::HashSet::new();
        let mut edges = Vec::new();
        for &(p, _) in &degree {
            let np = node_of[p];
            if np == usize::MAX {
                continue;
            }
            on_edge[p] = true;
            for q in nbrs(p) {
                if node_of[q] == np || used.contains(&(p, q)) {
                    continue;
                }
                used.insert((p, q));
                let mut pts = vec![centre(p, w)];
                let (mut prev, mut cur) = (p, q);
                let mut steps = 0;
                while node_of[cur] == usize::MAX && steps <= w * h {
                    on_edge[cur] = true;
                    pts.push(centre(cur, w));
                    let next = nbrs(cur).into_iter().find(|&r| r != prev);
                    match next {
                        Some(r) => (prev, cur) = (cur, r),
                        None => break,
                    }
                    steps += 1;
                }
                if node_of[cur] == usize::MAX {
                    continue;
                }
                used.insert((cur, prev));
                pts.push(centre(cur, w));
                edges.push(Edge {
                    a: np,
                    b: node_of[cur],
                    pts,
                    alive: true,
                });
            }
        }
        // Loops of two-neighbour pixels that meet no node.
        let mut cycles = Vec::new();
        for &(i, d) in &degree {
            if d != 2 || on_edge[i] {
                continue;
            }
            let mut pts = Vec::new();
            let (mut prev, mut cur) = (usize::MAX, i);
            while !on_edge[cur] {
                on_edge[cur] = true;
                pts.push(centre(cur, w));
                match nbrs(cur).into_iter().find(|&r| r != prev && !on_edge[r]) {
                    Some(r) => (prev, cur) = (cur, r),
                    None => break,
                }
            }
            if pts.len() >= 3 {
                cycles.push(pts);
            }
        }
        Graph {
            nodes,
            edges,
            cycles,
        }
    }

    /// How many live edge ends meet at each node.
    fn degrees(&self) -> Vec<usize> {
        let mut deg = vec![0; self.nodes.len()];
        for e in self.edges.iter().filter(|e| e.alive) {
            deg[e.a] += 1;
            deg[e.b] += 1;
        }
        deg
    }

    /// Drops spurs (an edge from a junction to a free end reaching less
    /// than line width `lw` px, or [`SPUR_FLOOR`], beyond the junction) and specks (an edge
    /// between two free ends shorter than `lw`), and contracts edges
    /// shorter than `2 lw` between two junctions into one junction (an X
    /// crossing thins to two junctions a width or so apart); until
    /// nothing changes.
    fn simplify(&mut self, lw: f64) {
        // Thinning frays even a thin line's ends by a few pixels.
        let short = lw.max(SPUR_FLOOR);
        for _ in 0..8 {
            let mut changed = false;
            let deg = self.degrees();
            for e in &mut self.edges {
                if !e.alive {
                    continue;
                }
                let len = length(&e.pts);
                let (da, db) = (deg[e.a], deg[e.b]);
                let spur = (da == 1 && db >= 3 && len - self.nodes[e.b].radius < short)
                    || (db == 1 && da >= 3 && len - self.nodes[e.a].radius < short);
                let speck = da == 1 && db == 1 && len < lw;
                let small_loop = e.a == e.b && len < 3.0 * lw;
                if spur || speck || small_loop {
                    e.alive = false;
                    changed = true;
                }
            }
            if changed {
                continue;
            }
            // Junctions closer than a line width are one.
            let deg = self.degrees();
            let short = self.edges.iter().position(|e| {
                e.alive && e.a != e.b && deg[e.a] >= 3 && deg[e.b] >= 3 && length(&e.pts) < 2.0 * lw
            });
            let Some(k) = short else { break };
            let (a, b) = (self.edges[k].a, self.edges[k].b);
            self.edges[k].alive = false;
            let (pa, pb) = (self.nodes[a].pos, self.nodes[b].pos);
            let pos = pa.midpoint(pb);
            let radius = (self.nodes[a].radius + pos.distance(pa))
                .max(self.nodes[b].radius + pos.distance(pb));
            self.nodes[a].pos = pos;
            self.nodes[a].radius = radius;
            for e in &mut self.edges {
                if e.a == b {
                    e.a = a;
                }
                if e.b == b {
                    e.b = a;
                }
            }
        }
    }

    /// The graph's edges joined into strokes: at each node where edges
    /// meet, the pairs that continue each other most straightly (within
    /// 35°; any two at a node of two) run on as one stroke, the others end
    /// there at the node's centre. Near a junction the skeleton bends
    /// towards it, so each edge is cut back by the junction's radius plus
    /// half the line width `lw` px there.
    fn strokes(&self, lw: f64, cov: &Coverage) -> Vec<Line> {
        let deg = self.degrees();
        let live: Vec<usize> = (0..self.edges.len())
            .filter(|&k| self.edges[k].alive)
            .collect();
        // Trimmed points of each live edge (in `live` order).
        // A junction whose spurs were all dropped but one is a free end.
        let junction = |n: usize| self.nodes[n].junction && deg[n] >= 2;
        let cut = |n: usize| {
            if junction(n) {
                let n = &self.nodes[n];
                n.radius + 0.5 * lw
            } else {
                0.0
            }
        };
        let trimmed: Vec<Vec<Point>> = live
            .iter()
            .map(|&k| {
                let e = &self.edges[k];
                let (na, nb) = (&self.nodes[e.a], &self.nodes[e.b]);
                let (ca, cb) = (cut(e.a), cut(e.b));
                let mut pts: Vec<Point> = e
                    .pts
                    .iter()
                    .copied()
                    .filter(|p| p.distance(na.pos) >= ca && p.distance(nb.pos) >= cb)
                    .collect();
                if pts.is_empty() {
                    pts = vec![na.pos.midpoint(nb.pos)];
                }
                pts
            })
            .collect();
        // Each end: (edge slot, side), the node it meets, and its direction
        // away from the node.
        let mut at_node: Vec<Vec<usize>> = vec![Vec::new(); self.nodes.len()];
        let mut dirs = vec![Vec2::ZERO; 2 * live.len()];
        for (slot, &k) in live.iter().enumerate() {
            let e = &self.edges[k];
            for side in 0..2 {
                let node = if side == 0 { e.a } else { e.b };
                let n = &self.nodes[node];
                let reach = n.radius + 1.5 * lw;
                let seq: Box<dyn Iterator<Item = &Point>> = if side == 0 {
                    Box::new(e.pts.iter())
                } else {
                    Box::new(e.pts.iter().rev())
                };
                let mut far = n.pos;
                for p in seq {
                    far = *p;
                    if p.distance(n.pos) >= reach {
                        break;
                    }
                }
                dirs[2 * slot + side] = unit(far - n.pos);
                at_node[node].push(2 * slot + side);
            }
        }
        let mut partner: Vec<Option<usize>> = vec![None; 2 * live.len()];
        for (node, ends) in at_node.iter().enumerate() {
            if deg[node] == 2 && ends.len() == 2 {
                partner[ends[0]] = Some(ends[1]);
                partner[ends[1]] = Some(ends[0]);
                continue;
            }
            let mut pairs = Vec::new();
            for (i, &ea) in ends.iter().enumerate() {
                for &eb in &ends[i + 1..] {
                    let c = dirs[ea].dot(dirs[eb]);
                    if c < -CONTINUE_COS {
                        pairs.push((c, ea, eb));
                    }
                }
            }
            pairs.sort_by(|x, y| x.0.total_cmp(&y.0));
            for (_, ea, eb) in pairs {
                if partner[ea].is_none() && partner[eb].is_none() {
                    partner[ea] = Some(eb);
                    partner[eb] = Some(ea);
                }
            }
        }
        let node_of_end = |end: usize| {
            let e = &self.edges[live[end / 2]];
            if end.is_multiple_of(2) {
                e.a
            } else {
                e.b
            }
        };
        walk(live.len(), &partner)
            .into_iter()
            .map(|(entries, closed)| {
                let mut points: Vec<Point> = Vec::new();
                for (i, &entry) in entries.iter().enumerate() {
                    let slot = entry / 2;
                    let pts = &trimmed[slot];
                    let node = node_of_end(entry);
                    // An end at a junction with no partner reaches the
                    // junction's centre.
                    if i == 0 && !closed && junction(node) {
                        points.push(self.nodes[node].pos);
                    }
                    if entry.is_multiple_of(2) {
                        points.extend(pts.iter().copied());
                    } else {
                        points.extend(pts.iter().rev().copied());
                    }
                    if i + 1 == entries.len() && !closed {
                        let exit = node_of_end(entry ^ 1);
                        if junction(exit) {
                            points.push(self.nodes[exit].pos);
                        }
                    }
                }
                points.dedup();
                let first_free = !closed && !junction(node_of_end(entries[0]));
                let last_free = !closed
                    && entries
                        .last()
                        .is_some_and(|&e| !junction(node_of_end(e ^ 1)));
                extend_ends(&mut points, first_free, last_free, lw, cov);
                Line {
                    points,
                    closed,
                    width: 0.0,
                    free: [first_free, last_free],
                }
            })
            .collect()
    }
}

/// `v` scaled to length 1 (zero stays zero).
fn unit(v: Vec2) -> Vec2 {
    let l = v.hypot();
    if l > 1e-12 {
        v / l
    } else {
        Vec2::ZERO
    }
}

/// Joins items (edges, strokes) whose ends are paired: item `k` has ends
/// `2k` and `2k + 1`, `partner[end]` the end it continues into. Returns
/// each chain as the ends by which its items are entered, in order, and
/// whether it closes on itself; chains start at unpaired ends, loops at
/// their lowest item.
fn walk(items: usize, partner: &[Option<usize>]) -> Vec<(Vec<usize>, bool)> {
    let mut seen = vec![false; items];
    let mut out = Vec::new();
    let follow = |start: usize, seen: &mut Vec<bool>| {
        let mut entries = Vec::new();
        let mut cur = start;
        loop {
            seen[cur / 2] = true;
            entries.push(cur);
            match partner[cur ^ 1] {
                Some(next) if !seen[next / 2] => cur = next,
                Some(next) => return (entries, next == start),
                None => return (entries, false),
            }
        }
    };
    for end in 0..2 * items {
        if partner[end].is_none() && !seen[end / 2] {
            out.push(follow(end, &mut seen));
        }
    }
    for k in 0..items {
        if !seen[k] {
            out.push(follow(2 * k, &mut seen));
        }
    }
    out
}

/// Carries a free end of `points` on along its direction to the ink's
/// tip (where the coverage falls under ½ for a pixel), less half the line width `lw`
/// px, so a round cap of that width ends where the ink does; thinning
/// leaves the skeleton short of the tip.
fn extend_ends(points: &mut Vec<Point>, first: bool, last: bool, lw: f64, cov: &Coverage) {
    if last {
        extend_last(points, lw, cov);
    }
    if first {
        points.reverse();
        extend_last(points, lw, cov);
        points.reverse();
    }
}

/// [`extend_ends`] at the last point. The skeleton's last line width
/// (where thinning frays it) is set aside, and the walk starts in the
/// direction taken over the two widths before it; each step keeps to the
/// middle of the ink across the walk (the coverage-weighted centre within
/// ±¾ of a width, moved at most [`STEER_PX`] per step), so a curving line
/// is followed to its tip rather than left along a tangent.
fn extend_last(points: &mut Vec<Point>, lw: f64, cov: &Coverage) {
    if length(points) < 3.0 * lw {
        return;
    }
    let Some(&end) = points.last() else { return };
    let keep = points
        .iter()
        .rposition(|p| p.distance(end) >= lw)
        .unwrap_or(0)
        .max(1);
    let from = points[keep];
    let back = points[..=keep]
        .iter()
        .rev()
        .find(|p| p.distance(from) >= 2.0 * lw)
        .copied()
        .unwrap_or(points[0]);
    let mut d = unit(from - back);
    if d == Vec2::ZERO {
        return;
    }
    let step = 0.25;
    let across: Vec<f64> = {
        let k = (0.75 * lw / 0.5).ceil() as i32;
        (-k..=k).map(|j| f64::from(j) * 0.5).collect()
    };
    // The tip is where the coverage, the most of three samples across
    // the line (±0.2 widths), stays under ½ for a pixel, so a grain of
    // paper inside the ink does not stop the walk.
    let mut walked = vec![from];
    let (mut p, mut paper) = (from, 0.0);
    while (walked.len() as f64) * step < 4.0 * lw + 4.0 && paper < 1.0 {
        let n = Vec2::new(-d.y, d.x);
        let mut q = p + d * step;
        let (mut weight, mut moment) = (0.0, 0.0);
        for &o in &across {
            let c = f64::from(cov.sample((q + n * o).x, (q + n * o).y));
            if c >= 0.25 {
                weight += c;
                moment += c * o;
            }
        }
        if weight > 0.0 {
            q += n * (moment / weight).clamp(-STEER_PX, STEER_PX);
        }
        let side = n * (0.2 * lw);
        let c = [q - side, q, q + side]
            .iter()
            .map(|r| cov.sample(r.x, r.y))
            .fold(0.0f32, f32::max);
        if c < 0.5 {
            paper += step;
        } else {
            paper = 0.0;
        }
        let turned = unit(q - p);
        if turned != Vec2::ZERO {
            d = unit(d * 3.0 + turned);
        }
        p = q;
        walked.push(p);
    }
    // Back off the paper walked and half a width (the round cap).
    let back_off = ((paper + 0.5 * lw) / step).round() as usize;
    let Some(last) = walked.len().checked_sub(back_off + 1) else {
        return;
    };
    let tip = walked[last];
    // Only ever carried on: a grain of paper at a thin line's end must not
    // cut the skeleton back.
    if tip.distance(from) > end.distance(from) + 0.25 {
        points.truncate(keep + 1);
        points.extend(walked[1..=last].iter().step_by(4).copied());
        if points.last() != Some(&tip) {
            points.push(tip);
        }
    }
}

/// How far a step of the tip walk may move across the line (px).
const STEER_PX: f64 = 0.1;

/// Bridges gaps: two free ends of open lines closer than twice the line
/// width `lw` px and [`BRIDGE_SLACK_PX`] (a gap in the ink shorter than
/// `lw`, the ends sitting half a width back from the tips), each pointing
/// at the other within 40°, are joined, nearest first.
fn bridge(lines: Vec<Line>, lw: f64) -> Vec<Line> {
    let n = lines.len();
    let end = |e: usize| -> (Point, Vec2) {
        let pts = &lines[e / 2].points;
        let m = pts.len();
        let (p, back) = if e.is_multiple_of(2) {
            (pts[0], pts[(m - 1).min(lw.ceil() as usize + 1)])
        } else {
            (pts[m - 1], pts[m.saturating_sub(lw.ceil() as usize + 2)])
        };
        (p, unit(p - back))
    };
    let mut pairs = Vec::new();
    let free = |e: usize| lines[e / 2].free[e % 2] && lines[e / 2].points.len() >= 2;
    for a in 0..2 * n {
        if !free(a) {
            continue;
        }
        for b in a + 1..2 * n {
            if !free(b) || b == (a ^ 1) {
                continue;
            }
            let ((pa, da), (pb, db)) = (end(a), end(b));
            let d = pa.distance(pb);
            if d >= 2.0 * lw + BRIDGE_SLACK_PX {
                continue;
            }
            let ab = unit(pb - pa);
            if d < 0.5 || (da.dot(ab) > BRIDGE_COS && db.dot(-ab) > BRIDGE_COS) {
                pairs.push((d, a, b));
            }
        }
    }
    pairs.sort_by(|x, y| x.0.total_cmp(&y.0));
    let mut partner: Vec<Option<usize>> = vec![None; 2 * n];
    for (_, a, b) in pairs {
        if partner[a].is_none() && partner[b].is_none() {
            partner[a] = Some(b);
            partner[b] = Some(a);
        }
    }
    // Closed lines keep their own ends apart.
    walk(n, &partner)
        .into_iter()
        .map(|(entries, closed)| {
            if entries.len() == 1 {
                return lines[entries[0] / 2].clone();
            }
            let mut points = Vec::new();
            let last = entries[entries.len() - 1] ^ 1;
            let free = [
                !closed && lines[entries[0] / 2].free[entries[0] % 2],
                !closed && lines[last / 2].free[last % 2],
            ];
            for &e in &entries {
                let pts = &lines[e / 2].points;
                if e.is_multiple_of(2) {
                    points.extend(pts.iter().copied());
                } else {
                    points.extend(pts.iter().rev().copied());
                }
            }
            points.dedup();
            Line {
                points,
                closed,
                width: 0.0,
                free,
            }
        })
        .collect()
}

/// Smooths a pixel-centre polyline's staircase: two passes of the
/// (¼, ½, ¼) kernel, an open line's ends kept.
fn smooth(pts: &[Point], closed: bool) -> Vec<Point> {
    let n = pts.len();
    if n < 3 {
        return pts.to_vec();
    }
    let mut cur = pts.to_vec();
    for _ in 0..2 {
        let prev = cur.clone();
        for i in 0..n {
            let (a, b) = if closed {
                ((i + n - 1) % n, (i + 1) % n)
            } else if i == 0 || i + 1 == n {
                continue;
            } else {
                (i - 1, i + 1)
            };
            cur[i] = Point::new(
                0.25 * prev[a].x + 0.5 * prev[i].x + 0.25 * prev[b].x,
                0.25 * prev[a].y + 0.5 * prev[i].y + 0.25 * prev[b].y,
            );
        }
    }
    cur
}

/// The ink's width (px) across a polyline at each of its points: the
/// coverage integrated along the normal (tangent over ±2 points), outwards
/// from the point on each side until it falls under 0.05, at most
/// `3 w0 + 3` px.
fn line_widths(cov: &Coverage, pts: &[Point], w0: f64) -> Vec<f64> {
    let n = pts.len();
    let reach = 3.0 * w0 + 3.0;
    let step = 0.25;
    (0..n)
        .filter_map(|i| {
            let t = unit(pts[(i + 2).min(n - 1)] - pts[i.saturating_sub(2)]);
            if t == Vec2::ZERO {
                return None;
            }
            let nrm = Vec2::new(-t.y, t.x);
            let p = pts[i];
            let mut sum = f64::from(cov.sample(p.x, p.y)) * step;
            for dir in [1.0, -1.0] {
                let mut s = step;
                while s <= reach {
                    let q = p + nrm * (dir * s);
                    let c = f64::from(cov.sample(q.x, q.y));
                    if c < 0.05 {
                        break;
                    }
                    sum += c * step;
                    s += step;
                }
            }
            Some(sum)
        })
        .collect()
}
