//! A colour picture cut into regions of one colour each, and the boundary
//! graph between them: what `flourish trace --layers --cutout` traces.
//!
//! Every pixel is read as a mix of two palette colours (its share of the
//! first, as the stacked layers read it) and belongs to the colour with
//! the larger share. Marching squares on these labels, with a border of
//! "outside" round the picture, puts one vertex on every link between
//! pixel centres of two colours, where the two colours' shares, linearly
//! interpolated along the link, are equal (on the picture's edge for a
//! link into the border; smoothed along its link where both pixels are
//! pure colours and so say nothing finer than the pixel). A cell whose
//! corners hold three or four colours (or two on its diagonals, a saddle
//! that the cell-centre shares do not resolve) gets a junction, where the
//! boundaries meet. Every boundary piece separates exactly two colours
//! and is made once: the chains between junctions (or closed loops
//! without one) are the edges of a planar graph whose faces are the
//! regions, so a region's outline is the chains round it, each shared
//! with the region on its other side (Bhattacharya and others call this
//! a multi-label marching squares; "multi-material" contouring in
//! meshing).
//!
//! A chain runs with the colour `left` on its left as seen on the screen
//! (y down) and `right` on its right; a region's boundary is its chains
//! with it on the left (those with it on the right reversed), linked at
//! the junctions sector by sector, so outer boundaries and holes turn
//! opposite ways and a non-zero fill of them is the region.

use super::contour::Link;
use kurbo::{Point, Vec2};
use std::collections::HashMap;

/// The label of the outside of the picture (never a colour).
pub const OUTSIDE: u8 = u8::MAX;

/// Most colours a partition holds (the palette's limit with room to spare).
pub const MAX_COLOURS: usize = 32;

/// A picture as regions: per pixel, its two nearest palette colours `a ≤ b`
/// and the share `t` of `a` (`1 − t` of `b`), and the colour it belongs
/// to.
#[derive(Clone, Debug)]
pub struct Partition {
    width: usize,
    height: usize,
    /// Per pixel, row by row: `(a, b, t)`.
    mixes: Vec<(u8, u8, f32)>,
    /// Per pixel: the colour it belongs to.
    labels: Vec<u8>,
    /// Number of colours (labels `0..colours`).
    colours: usize,
}

impl Partition {
    /// A `width` × `height` partition into `colours` colours (at most
    /// [`MAX_COLOURS`]) from each pixel's mix `(a, b, t)`; `None` when the
    /// sizes disagree or a mix names a colour out of range.
    pub fn new(
        width: usize,
        height: usize,
        colours: usize,
        mixes: Vec<(u8, u8, f32)>,
    ) -> Option<Partition> {
        if mixes.len() != width * height
            || colours == 0
            || colours > MAX_COLOURS
            || mixes
                .iter()
                .any(|&(a, b, t)| usize::from(a.max(b)) >= colours || !t.is_finite())
        {
            return None;
        }
        let labels = mixes
            .iter()
            .map(|&(a, b, t)| if t >= 0.5 { a } else { b })
            .collect();
        Some(Partition {
            width,
            height,
            mixes,
            labels,
            colours,
        })
    }

    /// Width in pixels.
    pub fn width(&self) -> usize {
        self.width
    }

    /// Height in pixels.
    pub fn height(&self) -> usize {
        self.height
    }

    /// Number of colours.
    pub fn colours(&self) -> usize {
        self.colours
    }

    /// The colour of pixel `(x, y)`, [`OUTSIDE`] beyond the picture.
    pub fn label(&self, x: i32, y: i32) -> u8 {
        if x < 0 || y < 0 || x as usize >= self.width || y as usize >= self.height {
            return OUTSIDE;
        }
        self.labels[y as usize * self.width + x as usize]
    }

    /// The share (0..=1) of colour `l` in pixel `(x, y)` (inside the
    /// picture).
    fn share(&self, x: i32, y: i32, l: u8) -> f32 {
        let (a, b, t) = self.mixes[y as usize * self.width + x as usize];
        let mut s = 0.0;
        if a == l {
            s += t;
        }
        if b == l {
            s += 1.0 - t;
        }
        s
    }

    /// Whether pixel `(x, y)` is one pure colour.
    fn pure(&self, x: i32, y: i32) -> bool {
        let (a, b, t) = self.mixes[y as usize * self.width + x as usize];
        a == b || t == 0.0 || t == 1.0
    }

    /// The pixels of each colour, by label.
    pub fn areas(&self) -> Vec<usize> {
        let mut n = vec![0usize; self.colours];
        for &l in &self.labels {
            if let Some(c) = n.get_mut(usize::from(l)) {
                *c += 1;
            }
        }
        n
    }

    /// Gives every 4-connected region smaller than `min_area` pixels to
    /// the colour it borders most (specks and pinholes, as `--min-area`
    /// drops them from the stacked layers: here they may not leave a
    /// hole). Its pixels become pure pixels of that colour. Regions are
    /// visited in the order of their first pixel, row by row.
    pub fn merge_specks(&mut self, min_area: f64) {
        let (w, h) = (self.width, self.height);
        if min_area <= 1.0 || w == 0 || h == 0 {
            return;
        }
        let mut seen = vec![false; w * h];
        let mut stack = Vec::new();
        let mut region = Vec::new();
        for start in 0..w * h {
            if seen[start] {
                continue;
            }
            let l = self.labels[start];
            region.clear();
            stack.push(start);
            seen[start] = true;
            let mut borders = [0usize; MAX_COLOURS];
            while let Some(i) = stack.pop() {
                region.push(i);
                let mut visit = |j: usize| {
                    let m = self.labels[j];
                    if m == l {
                        if !seen[j] {
                            seen[j] = true;
                            stack.push(j);
                        }
                    } else if let Some(b) = borders.get_mut(usize::from(m)) {
                        *b += 1;
                    }
                };
                for j in super::neighbours4(i, w, h) {
                    visit(j);
                }
            }
            if (region.len() as f64) >= min_area {
                continue;
            }
            // The colour bordered most (the first of equals); none for a
            // region that fills the picture.
            let Some((to, _)) = borders
                .iter()
                .enumerate()
                .filter(|(_, &n)| n > 0)
                .max_by_key(|(k, &n)| (n, std::cmp::Reverse(*k)))
            else {
                continue;
            };
            for &i in &region {
                self.labels[i] = to as u8;
                self.mixes[i] = (to as u8, to as u8, 1.0);
            }
        }
    }

    /// The share of colour `l` in pixel `(x, y)`, 0 beyond the picture.
    fn share_or_0(&self, x: i32, y: i32, l: u8) -> f64 {
        if self.label(x, y) == OUTSIDE {
            0.0
        } else {
            f64::from(self.share(x, y, l))
        }
    }

    /// The straight edge of colour `l` in pixel `(x, y)` when the pixel
    /// holds part of it: its unit normal into the colour (the isotropic
    /// 3×3 gradient of the colour's share) and the signed distance from
    /// the pixel's centre to it, negative inside (the edge model of
    /// [`super::sdf`], Gustavson and Strand 2011, on the colour's share).
    fn edge(&self, x: i32, y: i32, l: u8) -> Option<(Vec2, f64)> {
        let c = self.share_or_0(x, y, l);
        if !(c > 0.5 / 255.0 && c < 1.0 - 0.5 / 255.0) {
            return None;
        }
        let n = super::sdf::edge_normal(|dx, dy| self.share_or_0(x + dx, y + dy, l))?;
        Some((n, super::sdf::edge_offset(n, c)))
    }

    /// Where the boundary between the colours of the two ends of `l`
    /// crosses it (pixel coordinates), and whether the pixels placed it
    /// (else it sits half way, to be smoothed): where the straight edges
    /// of the first end's colour, read from its share in the pixels at
    /// both ends, cross the link (as [`super::sdf`] reads an anti-aliased
    /// outline), else where the share, interpolated along the link, is
    /// one half.
    fn crossing(&self, l: Link) -> (Point, bool) {
        let ((x0, y0), (x1, y1)) = l.ends();
        let (a, b) = (self.label(x0, y0), self.label(x1, y1));
        if a == OUTSIDE || b == OUTSIDE {
            // On the picture's edge, half way between the centres.
            return (l.point(0.5), true);
        }
        if self.pure(x0, y0) && self.pure(x1, y1) {
            return (l.point(0.5), false);
        }
        let e = l.direction();
        // The second end's edge model counts when it faces the first end
        // (a far pixel's edge of something beyond is not this boundary).
        let m0 = self.edge(x0, y0, a);
        let m1 = self.edge(x1, y1, a).filter(|m| m.0.dot(e) < 0.5);
        let oblique = |m: &(Vec2, f64)| m.0.dot(e).abs() > 0.2;
        let t = match (m0, m1) {
            (Some(p), Some(q)) if p.1 * q.1 <= 0.0 && p.1 != q.1 => Some(p.1 / (p.1 - q.1)),
            (Some(p), _) if oblique(&p) => Some(p.1 / p.0.dot(e)),
            (_, Some(q)) if oblique(&q) => Some(1.0 + q.1 / q.0.dot(e)),
            _ => None,
        };
        let t = match t {
            Some(t) if t.is_finite() => t,
            _ => {
                let f0 = self.share(x0, y0, a) - self.share(x0, y0, b);
                let f1 = self.share(x1, y1, a) - self.share(x1, y1, b);
                if f0 - f1 > 1e-6 {
                    f64::from(f0 / (f0 - f1))
                } else {
                    0.5
                }
            }
        };
        (l.point(t.clamp(0.05, 0.95)), true)
    }
}

/// One boundary between two colours: a polyline from junction to
/// junction, or a closed loop (its first point not repeated).
#[derive(Clone, Debug)]
pub struct Chain {
    /// The points in order (pixel coordinates).
    pub points: Vec<Point>,
    /// Whether it is a closed loop.
    pub closed: bool,
    /// The colour on its left (as seen on the screen, y down) and on its
    /// right; either may be [`OUTSIDE`].
    pub left: u8,
    /// See [`Chain::left`].
    pub right: u8,
    /// Where an open chain starts and ends: `(junction, side)`, the side
    /// being the cell edge (0 top, 1 right, 2 bottom, 3 left) it leaves
    /// or enters the junction's cell through.
    pub ends: Option<[(usize, u8); 2]>,
}

/// The boundary graph of a partition: its chains, and per junction and
/// colour the sectors of that colour round it, as pairs of cell edges
/// `(in, out)`: a boundary of the colour arriving through edge `in`
/// leaves through edge `out`.
#[derive(Clone, Debug, Default)]
pub struct Boundaries {
    /// The chains.
    pub chains: Vec<Chain>,
    /// Junction points (pixel coordinates).
    pub junctions: Vec<Point>,
    /// Per junction, `(colour, in, out)` for each sector.
    pub sectors: Vec<Vec<(u8, u8, u8)>>,
}

/// A node of the boundary graph while it is built: a link's crossing or a
/// junction.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
enum Node {
    Crossing(Link),
    Junction(usize),
}

/// One directed piece of boundary (`from` to `to`, `left` on its left).
#[derive(Clone, Copy, Debug)]
struct Piece {
    from: Node,
    to: Node,
    left: u8,
    right: u8,
    /// The junction end's cell edge, for a piece into or out of one.
    edge: u8,
}

/// Rounds of smoothing of the vertices that pure pixels leave half way
/// along their links (as [`super::sdf`] smooths a binary outline).
const SMOOTHING_ROUNDS: usize = 12;

/// The boundary graph of `p` (see the module docs).
pub fn boundaries(p: &Partition) -> Boundaries {
    let (w, h) = (p.width as i32, p.height as i32);
    let mut out = Boundaries::default();
    if w == 0 || h == 0 {
        return out;
    }
    let mut pieces: Vec<Piece> = Vec::new();
    // Cells by their top-left sample (x, y), x in -1..w, y in -1..h;
    // corners clockwise from the top left, edge k from corner k to k + 1.
    for y in -1..h {
        for x in -1..w {
            let c = [
                p.label(x, y),
                p.label(x + 1, y),
                p.label(x + 1, y + 1),
                p.label(x, y + 1),
            ];
            if c[0] == c[1] && c[1] == c[2] && c[2] == c[3] {
                continue;
            }
            let edges = Link::around(x, y);
            let crossed: Vec<usize> = (0..4).filter(|&k| c[k] != c[(k + 1) % 4]).collect();
            let mut distinct = c.to_vec();
            distinct.sort_unstable();
            distinct.dedup();
            let saddle = crossed.len() == 4 && distinct.len() == 2;
            // The runs of equal corners clockwise: `(label, first, last)`,
            // each bounded by the crossed edges before `first` and after
            // `last`.
            let sectors = sectors(&c);
            if distinct.len() == 2 && !saddle {
                // One boundary across the cell: each colour's sector
                // from the edge entering it to the edge leaving it.
                for &(l, first, last) in &sectors {
                    let (e_in, e_out) = ((first + 3) % 4, last);
                    let m = c[(last + 1) % 4];
                    if l < m {
                        pieces.push(Piece {
                            from: Node::Crossing(edges[e_in]),
                            to: Node::Crossing(edges[e_out]),
                            left: l,
                            right: m,
                            edge: 0,
                        });
                    }
                }
                continue;
            }
            if saddle {
                // Two colours on the diagonals: the one whose shares at
                // the four corners add up to more joins across the centre
                // (a tie joins the lower label), the other's corners are
                // cut off one by one.
                let (l, m) = (distinct[0], distinct[1]);
                let total = |lab: u8| -> f32 {
                    (0..4)
                        .map(|k| {
                            let (cx, cy) = [(x, y), (x + 1, y), (x + 1, y + 1), (x, y + 1)][k];
                            if p.label(cx, cy) == OUTSIDE {
                                0.0
                            } else {
                                p.share(cx, cy, lab)
                            }
                        })
                        .sum()
                };
                let joined = if total(l) >= total(m) { l } else { m };
                // Each corner of the other colour is cut off by the piece
                // from the edge before it to the edge after it.
                for (k, &corner) in c.iter().enumerate() {
                    if corner == joined {
                        continue;
                    }
                    let (e_in, e_out) = ((k + 3) % 4, k);
                    let (left, right) = (corner, joined);
                    let (from, to, left, right) = if left < right {
                        (edges[e_in], edges[e_out], left, right)
                    } else {
                        (edges[e_out], edges[e_in], right, left)
                    };
                    pieces.push(Piece {
                        from: Node::Crossing(from),
                        to: Node::Crossing(to),
                        left,
                        right,
                        edge: 0,
                    });
                }
                continue;
            }
            // Three or four colours: a junction, with a piece from every
            // crossed edge into it. Its point is the mean of the crossings,
            // put on the picture's edge when the cell straddles it.
            let j = out.junctions.len();
            let mut at = Vec2::ZERO;
            let mut n = 0.0;
            for &k in &crossed {
                let ((x0, y0), (x1, y1)) = edges[k].ends();
                if p.label(x0, y0) == OUTSIDE || p.label(x1, y1) == OUTSIDE {
                    continue;
                }
                at += p.crossing(edges[k]).0.to_vec2();
                n += 1.0;
            }
            let mut point = if n > 0.0 {
                (at / n).to_point()
            } else {
                Point::new(x as f64 + 1.0, y as f64 + 1.0)
            };
            if y == -1 {
                point.y = 0.0;
            } else if y == h - 1 {
                point.y = h as f64;
            }
            if x == -1 {
                point.x = 0.0;
            } else if x == w - 1 {
                point.x = w as f64;
            }
            out.junctions.push(point);
            let mut own = Vec::new();
            for &(l, first, last) in &sectors {
                let (e_in, e_out) = ((first + 3) % 4, last);
                own.push((l, e_in as u8, e_out as u8));
                // The piece into the junction through the edge entering
                // the sector, with the colour before it on its right.
                let before = c[(first + 3) % 4];
                if l < before {
                    pieces.push(Piece {
                        from: Node::Crossing(edges[e_in]),
                        to: Node::Junction(j),
                        left: l,
                        right: before,
                        edge: e_in as u8,
                    });
                }
                let after = c[(last + 1) % 4];
                if l < after {
                    pieces.push(Piece {
                        from: Node::Junction(j),
                        to: Node::Crossing(edges[e_out]),
                        left: l,
                        right: after,
                        edge: e_out as u8,
                    });
                }
            }
            out.sectors.push(own);
        }
    }
    out.chains = chain_pieces(p, &pieces, &out.junctions);
    out
}

/// The runs of equal labels round a cell's corners `c` (clockwise), as
/// `(label, first corner, last corner)`; none when all four are equal.
fn sectors(c: &[u8; 4]) -> Vec<(u8, usize, usize)> {
    // Start at a corner whose predecessor differs, so no run wraps.
    let Some(s) = (0..4).find(|&k| c[(k + 3) % 4] != c[k]) else {
        return Vec::new();
    };
    let mut out: Vec<(u8, usize, usize)> = Vec::new();
    for step in 0..4 {
        let k = (s + step) % 4;
        match out.last_mut() {
            Some(run) if run.0 == c[k] => run.2 = k,
            _ => out.push((c[k], k, k)),
        }
    }
    out
}

/// Links the pieces into chains: through every crossing (where exactly
/// one piece arrives and one leaves), from junction to junction, or round
/// a closed loop. Points are the crossings and the junctions; vertices
/// the shares did not place are smoothed along their links.
fn chain_pieces(p: &Partition, pieces: &[Piece], junctions: &[Point]) -> Vec<Chain> {
    let mut next: HashMap<Node, usize> = HashMap::with_capacity(pieces.len());
    for (i, piece) in pieces.iter().enumerate() {
        next.insert(piece.from, i);
    }
    let mut used = vec![false; pieces.len()];
    let mut chains = Vec::new();
    // Chains from a junction first, then the closed loops that are left.
    let starts = (0..pieces.len())
        .filter(|&i| matches!(pieces[i].from, Node::Junction(_)))
        .chain(0..pieces.len());
    for start in starts {
        if used[start] {
            continue;
        }
        let first = pieces[start];
        let mut nodes = vec![first.from];
        let mut cur = start;
        let mut end_edge = None;
        loop {
            used[cur] = true;
            let piece = pieces[cur];
            nodes.push(piece.to);
            match piece.to {
                Node::Junction(_) => {
                    end_edge = Some(piece.edge);
                    break;
                }
                Node::Crossing(_) => match next.get(&piece.to) {
                    Some(&k) if !used[k] => cur = k,
                    _ => break,
                },
            }
        }
        let closed = nodes.first() == nodes.last() && !matches!(first.from, Node::Junction(_));
        if closed {
            nodes.pop();
        }
        let ends = match (first.from, nodes.last(), end_edge) {
            (Node::Junction(a), Some(&Node::Junction(b)), Some(e)) => {
                Some([(a, first.edge), (b, e)])
            }
            _ => None,
        };
        let points = smoothed_points(p, &nodes, junctions, closed);
        chains.push(Chain {
            points,
            closed,
            left: first.left,
            right: first.right,
            ends,
        });
    }
    chains
}

/// The points of a chain's nodes: junctions where they are, crossings
/// where the shares put them, and the crossings between pure pixels
/// smoothed along their links towards the midpoint of their neighbours
/// (the ends of an open chain stay).
fn smoothed_points(p: &Partition, nodes: &[Node], junctions: &[Point], closed: bool) -> Vec<Point> {
    let n = nodes.len();
    let mut free = vec![false; n];
    let mut t = vec![0.5f64; n];
    let mut pts: Vec<Point> = nodes
        .iter()
        .enumerate()
        .map(|(i, node)| match *node {
            Node::Junction(j) => junctions.get(j).copied().unwrap_or(Point::ORIGIN),
            Node::Crossing(l) => {
                let (q, informed) = p.crossing(l);
                free[i] = !informed;
                t[i] = (q - l.point(0.0)).dot(l.direction());
                q
            }
        })
        .collect();
    if n < 3 || !free.iter().any(|&f| f) {
        return pts;
    }
    for _ in 0..SMOOTHING_ROUNDS {
        let mut moved = t.clone();
        for i in 0..n {
            let Node::Crossing(l) = nodes[i] else {
                continue;
            };
            if !free[i] || (!closed && (i == 0 || i + 1 == n)) {
                continue;
            }
            let (a, b) = (pts[(i + n - 1) % n], pts[(i + 1) % n]);
            let mid = a.midpoint(b);
            moved[i] = (mid - l.point(0.0)).dot(l.direction()).clamp(0.05, 0.95);
        }
        t = moved;
        for i in 0..n {
            if let Node::Crossing(l) = nodes[i] {
                if free[i] {
                    pts[i] = l.point(t[i]);
                }
            }
        }
    }
    pts
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A partition of pure pixels labelled by `f(x, y)`.
    fn pure(w: usize, h: usize, colours: usize, f: impl Fn(usize, usize) -> u8) -> Partition {
        let mixes = (0..w * h)
            .map(|i| {
                let l = f(i % w, i / w);
                (l, l, 1.0)
            })
            .collect();
        Partition::new(w, h, colours, mixes).expect("valid")
    }

    /// Each colour's boundary, assembled from the chains (with the colour
    /// on their left, reversed when on their right), as directed
    /// segments between rounded points.
    fn segments_of(b: &Boundaries, l: u8) -> Vec<((i64, i64), (i64, i64))> {
        let key = |q: Point| ((q.x * 1e6).round() as i64, (q.y * 1e6).round() as i64);
        let mut out = Vec::new();
        for c in &b.chains {
            let mut pts = c.points.clone();
            if c.closed {
                pts.push(pts[0]);
            }
            if c.right == l {
                pts.reverse();
            } else if c.left != l {
                continue;
            }
            for s in pts.windows(2) {
                out.push((key(s[0]), key(s[1])));
            }
        }
        out
    }

    /// Every colour's boundary pieces form closed loops (each point left
    /// as often as entered), and every piece of one colour's boundary is
    /// a piece of exactly one other colour's (or the outside's), reversed:
    /// on a random picture of four colours.
    #[test]
    fn boundaries_close_and_are_shared_reversed() {
        let mut state = 7u64;
        let mut rnd = || {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            state
        };
        for trial in 0..30 {
            let (w, h) = (3 + trial % 11, 2 + (trial * 5) % 13);
            let cells: Vec<u8> = (0..w * h).map(|_| (rnd() % 4) as u8).collect();
            let p = pure(w, h, 4, |x, y| cells[y * w + x]);
            let b = boundaries(&p);
            let all: Vec<Vec<_>> = (0..4u8).map(|l| segments_of(&b, l)).collect();
            let outside = segments_of(&b, OUTSIDE);
            for (l, segs) in all.iter().enumerate() {
                let mut degree: HashMap<(i64, i64), i64> = HashMap::new();
                for &(a, c) in segs {
                    *degree.entry(a).or_default() += 1;
                    *degree.entry(c).or_default() -= 1;
                }
                assert!(
                    degree.values().all(|&d| d == 0),
                    "colour {l} of trial {trial} is not closed"
                );
                for &(a, c) in segs {
                    let others = all
                        .iter()
                        .chain(std::iter::once(&outside))
                        .enumerate()
                        .filter(|&(m, _)| m != l)
                        .filter(|(_, s)| s.contains(&(c, a)))
                        .count();
                    assert_eq!(others, 1, "piece {a:?}-{c:?} of colour {l}, trial {trial}");
                }
            }
        }
    }

    /// A speck smaller than the threshold goes to the colour round it; a
    /// region as large stays.
    #[test]
    fn specks_join_their_surroundings() {
        let mut p = pure(10, 10, 3, |x, y| match (x, y) {
            (2, 2) => 1,
            (6..=7, 6..=7) => 2,
            _ => 0,
        });
        p.merge_specks(4.0);
        assert_eq!(p.label(2, 2), 0);
        assert_eq!(p.label(6, 6), 2);
        assert_eq!(p.areas(), vec![96, 0, 4]);
    }
}
