//! Thin-line ends of a binary bitmap's polygon, squared off (between steps 4
//! and 5 of [`crate::outline::smooth`]).
//!
//! The path through pixel-edge midpoints chamfers the end of a line one or
//! two pixels wide down to a single tip vertex half a pixel out. A straight
//! run may end at that tip (it passes within half a pixel of every vertex of
//! the side), so the optimal polygon reaches the tip from both sides, or
//! crosses the line's end on a slant, and smoothing then sharpens the line
//! into a needle several pixels long: the last pixel or two of every thin
//! line are lost, and the line narrows where the drawing keeps its width.
//! potrace's paths through pixel corners do not have this tip (its straight
//! runs cannot cut the end's corners, Selinger 2003, §2.2), and its polygon
//! keeps such an end square.
//!
//! Here, where the outline makes a U-turn (the least-squares lines of the
//! two sides run back along each other, within [`U_TURN`]) over a vertex or
//! a short edge, the turn is replaced by a cap across the line: each side's
//! line cut at the farthest point the path reaches in the line's direction
//! (the tip lies on the pixel edge that ends the line). The cap's vertices
//! stay corners in smoothing: the bitmap keeps a thin line's width to its
//! last pixel, where potrace's corner measure would round the end off.
//!
//! And where a thin line turns sharply (a zigzag's apex), the polygon has
//! a short edge between two half-turns that the corner measure reads as
//! smooth: [`mitre_short_edges`] replaces it by the mitre of its long
//! neighbours, cut square to the bisector where it would overshoot the
//! pixels by more than [`MITRE_OUT`] (convex) or [`MITRE_IN`] (concave).

use kurbo::{Point, Vec2};

/// Sides whose directions are within this angle (radians) of exactly
/// opposite make a U-turn: 12°. A line's two sides run parallel; a
/// tapering stroke's tip (the scroll's leaves: 17–28° on the samples) is
/// left a point.
const U_TURN: f64 = std::f64::consts::PI / 15.0;

/// Shortest side (px, and at least twice the cap's width) next to a cap:
/// a line, not a notch of a pixel or two (a thin zigzag's apex, a tiny
/// loop).
const MIN_SIDE: f64 = 3.0;

/// Widest line (px) whose end is squared off: a U-turn over an edge up to
/// this long, or sides this far apart. potrace's corner measure (step 5)
/// reads the corners of ends narrower than about 5 px as smooth and rounds
/// them over half the line's length.
const MAX_CAP: f64 = 3.5;

/// Farthest (px) a cap vertex may move from the vertex it replaces: beyond
/// it the sides' lines do not describe a line end (they are short or
/// skewed), and the polygon is left alone.
const MAX_MOVE: f64 = 1.5;

/// One U-turn: the polygon vertices it replaces (`first` and `last`, equal
/// for a single vertex) and the cap's two new vertices, on the incoming and
/// on the outgoing side.
struct Cap {
    first: usize,
    last: usize,
    into: Point,
    out_of: Point,
}

/// The polygon `vertices` (adjusted positions of path indices `poly`, edge
/// `e` from vertex `e` to `e + 1` with least-squares line `lines[e]`) with
/// every thin-line end replaced by a square cap (see the module docs), and
/// per vertex whether it is a cap's corner (smoothing must keep it sharp).
pub(super) fn square_line_ends(
    path: &[Point],
    poly: &[usize],
    lines: &[(Point, Vec2)],
    vertices: Vec<Point>,
) -> (Vec<Point>, Vec<bool>) {
    let k = vertices.len();
    if k < 3 || poly.len() != k || lines.len() != k {
        return (vertices, vec![false; k]);
    }
    let mut caps: Vec<Cap> = Vec::new();
    let mut taken = vec![false; k];
    for e in 0..k {
        if taken[e] {
            continue;
        }
        let prev = (e + k - 1) % k;
        let next = (e + 1) % k;
        // A U-turn at vertex e alone, or over the short edge e → e + 1.
        let candidate = if opposite(lines[prev].1, lines[e].1) {
            Some((e, prev, e))
        } else if (vertices[next] - vertices[e]).hypot() <= MAX_CAP
            && !taken[next]
            && k >= 4
            && opposite(lines[prev].1, lines[next].1)
        {
            Some((next, prev, next))
        } else {
            None
        };
        let Some((last, side_in, side_out)) = candidate else {
            continue;
        };
        if let Some(cap) = cap(path, poly, lines, &vertices, e, last, side_in, side_out) {
            taken[e] = true;
            taken[last] = true;
            caps.push(cap);
        }
    }
    if caps.is_empty() {
        return (vertices, vec![false; k]);
    }
    let mut replaced: Vec<Option<Vec<Point>>> = vec![None; k];
    for c in caps {
        if c.first == c.last {
            replaced[c.first] = Some(vec![c.into, c.out_of]);
        } else {
            replaced[c.first] = Some(vec![c.into]);
            replaced[c.last] = Some(vec![c.out_of]);
        }
    }
    let mut out = Vec::with_capacity(k + 4);
    let mut corner = Vec::with_capacity(k + 4);
    for (v, r) in vertices.into_iter().zip(replaced) {
        match r {
            Some(cap) => {
                corner.extend(cap.iter().map(|_| true));
                out.extend(cap);
            }
            None => {
                out.push(v);
                corner.push(false);
            }
        }
    }
    (out, corner)
}

/// Whether unit directions `a` and `b` are within [`U_TURN`] of opposite.
fn opposite(a: Vec2, b: Vec2) -> bool {
    a.dot(b) < -U_TURN.cos()
}

/// The square cap of the U-turn over polygon vertices `first..=last`
/// between side lines `lines[side_in]` and `lines[side_out]`, or None when
/// the cut would move a vertex more than [`MAX_MOVE`] or the cap be wider
/// than [`MAX_CAP`].
#[allow(clippy::too_many_arguments)]
fn cap(
    path: &[Point],
    poly: &[usize],
    lines: &[(Point, Vec2)],
    vertices: &[Point],
    first: usize,
    last: usize,
    side_in: usize,
    side_out: usize,
) -> Option<Cap> {
    let n = path.len();
    let (c0, d0) = lines[side_in];
    let (c1, d1) = lines[side_out];
    // The line's direction towards its end: the mean of the side coming in
    // and the reverse of the side going out.
    let axis = d0 - d1;
    let len = axis.hypot();
    if len < 1e-9 {
        return None;
    }
    let axis = axis / len;
    // The end: the farthest the path reaches along the axis around the
    // turn (its tip vertex, on the pixel edge that ends the line), a couple
    // of path vertices either side included in case the polygon vertex is
    // not the tip itself.
    let (a, b) = (poly[first], poly[last]);
    let span = (b + n - a) % n;
    let reach = (0..=span + 4)
        .map(|s| path[(a + n - 2 + s) % n].to_vec2().dot(axis))
        .fold(f64::NEG_INFINITY, f64::max);
    // Each side's line cut where it reaches the end.
    let cut = |c: Point, d: Vec2| -> Option<Point> {
        let along = d.dot(axis);
        (along.abs() > 0.5).then(|| c + d * ((reach - c.to_vec2().dot(axis)) / along))
    };
    let into = cut(c0, d0)?;
    let out_of = cut(c1, d1)?;
    let moved = (into - vertices[first])
        .hypot()
        .max((out_of - vertices[last]).hypot());
    let width = (out_of - into).hypot();
    let k = vertices.len();
    let side = (vertices[first] - vertices[side_in])
        .hypot()
        .min((vertices[(last + 1) % k] - vertices[last]).hypot());
    if side < MIN_SIDE.max(2.0 * width) {
        return None;
    }
    (moved <= MAX_MOVE && width <= MAX_CAP && into.is_finite() && out_of.is_finite()).then_some(
        Cap {
            first,
            last,
            into,
            out_of,
        },
    )
}

/// Longest polygon edge (px) that a mitre replaces.
const MITRE_EDGE: f64 = 2.0;

/// Farthest (px) a mitre's tip may lie from either vertex it replaces;
/// beyond, the turn is bevelled (both vertices kept as corners).
const MITRE_REACH: f64 = 4.0;

/// Farthest (px) a mitre may reach out beyond the middle of the short edge
/// it replaces; a longer one is cut square to its bisector there (SVG's
/// miter limit), so an acute apex does not overshoot the pixels by more.
const MITRE_OUT: f64 = 1.5;

/// Narrowest cut (px) across a mitre: a cut end narrower than a pixel is
/// not something a binary bitmap can show (its edges are uncertain by
/// half a pixel either way), and as a flat of its own it would cost a
/// cubic; such a mitre ends in the point in the middle of the cut
/// instead.
const MIN_CUT: f64 = 1.0;

/// [`MITRE_OUT`] for a concave turn (the notch inside a zigzag's apex),
/// whose tip reaches into the ink: longer, as the notch of a 1-px zigzag
/// reaches about 2 px past its pixels' edge and stays a sharp V.
const MITRE_IN: f64 = 2.5;

/// Least and greatest turn (degrees) over a short edge that makes a mitre:
/// less is a bend of a curve, more a U-turn (a line's end, see
/// [`square_line_ends`]).
const MITRE_TURN: (f64, f64) = (60.0, 150.0);

/// The polygon with every short edge at a sharp turn replaced by a mitre:
/// the apex of a thin zigzag (or the notch inside it) is a pixel or two
/// wide in the bitmap, so the polygon has a short edge there between two
/// vertices that each turn by half the angle; potrace's corner measure
/// reads both as smooth and the apex comes out as a round blob. The two
/// vertices become the point where the polygon's arms either side meet
/// (the turn's mitre: [`arm`], the straight run of edges beyond the
/// neighbouring edge), kept as a corner. `keep` marks the corners of
/// [`square_line_ends`]' caps, which are left alone; it is returned
/// updated.
pub(super) fn mitre_short_edges(v: Vec<Point>, keep: Vec<bool>) -> (Vec<Point>, Vec<bool>) {
    let k = v.len();
    if k < 5 || keep.len() != k {
        return (v, keep);
    }
    // merged[i]: vertex i and i + 1 become this tip (or cut tip).
    let mut merged: Vec<Option<Vec<Point>>> = vec![None; k];
    let mut used = vec![false; k];
    let mut bevel = vec![false; k];
    // The loop's orientation: a turn the same way is convex.
    let area: f64 = (0..k)
        .map(|i| v[i].to_vec2().cross(v[(i + 1) % k].to_vec2()))
        .sum();
    let turn_at = |i: usize| turn_deg(v[(i + k - 1) % k], v[i], v[(i + 1) % k]);
    for i in 0..k {
        let j = (i + 1) % k;
        if used[i] || used[j] || keep[i] || keep[j] {
            continue;
        }
        let (p, q) = (v[i], v[j]);
        if (q - p).hypot() > MITRE_EDGE {
            continue;
        }
        // A mitre when the neighbouring edges are long enough, and both
        // vertices turn the same way, by a sharp turn in all, with the
        // turning gathered here (not spread along a curve): `t0` is the
        // first vertex's turn (its sign says convex or concave).
        let mitres = |a: Point, b: Point| -> Option<f64> {
            let (d0, e, d1) = (p - a, q - p, b - q);
            let side = d0.hypot().min(d1.hypot());
            let (t0, t1) = (d0.cross(e), e.cross(d1));
            let signed = turn_deg(a, p, b + (p - q));
            let turn = signed.abs();
            let ok = side >= MIN_SIDE.max(2.0 * e.hypot())
                && t0 * t1 > 0.0
                && (MITRE_TURN.0..=MITRE_TURN.1).contains(&turn)
                && !spread(signed, [turn_at((i + k - 1) % k), turn_at((i + 2) % k)]);
            ok.then_some(t0)
        };
        // Measured on the neighbouring edges; failing that, at a thin
        // line's apex, on the arms beyond them: next to the apex the
        // staircase shortens the neighbouring edges to a pixel or two and
        // bends them over (the 1-px zigzag's top turns by 153° over them,
        // drawn at 140°).
        let (a, b) = (v[(i + k - 1) % k], v[(i + 2) % k]);
        let thin = turn_deg(a, p, b + (p - q)).abs() > THIN_APEX;
        let near = mitres(a, b);
        if near.is_none() && !thin {
            continue;
        }
        let arms = (arm(&v, i, false), arm(&v, j, true));
        let Some(t0) = near.or_else(|| mitres(arms.0, arms.1)) else {
            continue;
        };
        // Where the arms' lines meet: next to a thin line's apex the
        // neighbouring edges are a pixel or two long, as its staircase
        // steps, and point up to 20° off the line (their lines would put a
        // thin zigzag's notch deeper than drawn).
        let (d0, d1) = (p - arms.0, arms.1 - q);
        let det = d0.cross(d1);
        if det.abs() < 1e-9 {
            continue;
        }
        let tip = p + d0 * ((q - p).cross(d1) / det);
        if (tip - p).hypot() > MITRE_REACH || (tip - q).hypot() > MITRE_REACH {
            // Too far out of the pixels: a bevel, both vertices corners.
            bevel[i] = true;
            bevel[j] = true;
        } else {
            // A convex turn's tip is cut shorter (it overshoots onto the
            // paper) than a concave one's.
            merged[i] = Some(mitre(
                p,
                q,
                tip,
                if t0 * area > 0.0 { MITRE_OUT } else { MITRE_IN },
            ));
        }
        used[i] = true;
        used[j] = true;
        used[(i + k - 1) % k] = true;
        used[(i + 2) % k] = true;
    }
    // A single vertex at such a turn between long arms is a mitre already:
    // kept a corner (the corner measure reads a 1-px zigzag's apex, whose
    // neighbouring vertices sit a few pixels down the arms, as smooth),
    // unless the turning is spread along a curve. The arms, not the
    // neighbouring edges, are measured: next to the apex the staircase may
    // put a vertex 2.7 px down one arm, which goes on straight.
    for i in 0..k {
        let signed = turn_at(i);
        let turn = signed.abs();
        if !used[i]
            && turn >= MITRE_TURN.0
            && turn <= MITRE_TURN.1
            && !spread(signed, [turn_at((i + k - 1) % k), turn_at((i + 1) % k)])
        {
            let p = v[i];
            let (a, b) = (arm(&v, i, false), arm(&v, i, true));
            bevel[i] = (p - a).hypot().min((b - p).hypot()) >= MIN_SIDE;
        }
    }
    if merged.iter().all(Option::is_none) {
        let keep = keep.iter().zip(&bevel).map(|(&a, &b)| a || b).collect();
        return (v, keep);
    }
    let mut drop = vec![false; k];
    for (i, m) in merged.iter().enumerate() {
        if m.is_some() {
            drop[(i + 1) % k] = true;
        }
    }
    let mut out = Vec::with_capacity(k);
    let mut corner = Vec::with_capacity(k);
    for i in 0..k {
        if drop[i] {
            continue;
        }
        match &merged[i] {
            Some(tip) => {
                out.extend(tip.iter().copied());
                corner.extend(tip.iter().map(|_| true));
            }
            None => {
                out.push(v[i]);
                corner.push(keep[i] || bevel[i]);
            }
        }
    }
    (out, corner)
}

/// Turn (degrees) over a short edge from which it is read as a thin
/// line's apex, and measured along the arms either side ([`arm`]) rather
/// than its neighbouring edges, which the staircase next to the apex
/// shortens to a pixel or two and bends by up to 20°.
const THIN_APEX: f64 = 120.0;

/// Largest turn (degrees) at a vertex that an arm goes straight on over.
const ARM_TURN: f64 = 20.0;

/// Length (px) after which an arm stops.
const ARM_LENGTH: f64 = 12.0;

/// The far end of the arm of polygon `v` from vertex `i`, backwards or
/// forwards: the vertices on from `i` while the polygon goes on about
/// straight (turning under [`ARM_TURN`] at each), until the arm is
/// [`ARM_LENGTH`] long.
fn arm(v: &[Point], i: usize, forwards: bool) -> Point {
    let k = v.len();
    let step = |j: usize| {
        if forwards {
            (j + 1) % k
        } else {
            (j + k - 1) % k
        }
    };
    let mut j = step(i);
    let mut len = (v[j] - v[i]).hypot();
    for _ in 0..k {
        let n = step(j);
        let t = turn_deg(v[(j + k - 1) % k], v[j], v[(j + 1) % k]);
        if t.abs() >= ARM_TURN || len >= ARM_LENGTH || n == i {
            break;
        }
        len += (v[n] - v[j]).hypot();
        j = n;
    }
    v[j]
}

/// The signed turn (degrees, counter-clockwise positive in the y-up sense
/// of `Vec2::cross`) of a polygon at `p` from `a` on to `b`.
fn turn_deg(a: Point, p: Point, b: Point) -> f64 {
    let (d0, d1) = (p - a, b - p);
    d0.cross(d1).atan2(d0.dot(d1)).to_degrees()
}

/// Whether a sharp turn of `signed` degrees is spread along a curve rather
/// than gathered at an apex: a neighbouring vertex (`neighbours`' turns)
/// turns the same way by at least half as much, and the two together turn
/// by less than [`SPREAD_TURN`]. A dot a few pixels across is a
/// polygon of five to eight vertices turning 45–72° each: read as mitres
/// or bevels, each would make a corner on a round dot, a kink and a cubic
/// more. A square line end's two vertices turn 90° each, 180° together:
/// still an apex.
fn spread(signed: f64, neighbours: [f64; 2]) -> bool {
    let turn = signed.abs();
    neighbours
        .iter()
        .any(|&nt| nt * signed > 0.0 && nt.abs() >= 0.5 * turn && nt.abs() + turn < SPREAD_TURN)
}

/// Most turning (degrees) of two neighbouring vertices that [`spread`]
/// reads as a curve: a 6-px dot's polygon turns 90° and 63° at two
/// neighbours (153°), a square line end 90° and 85–90° (175–180°).
const SPREAD_TURN: f64 = 160.0;

/// The mitre over the short edge `p → q` whose neighbouring edges meet at
/// `tip`: the tip itself, or, when it reaches more than `limit` px beyond
/// the edge's middle, the two points where the cut square to the bisector
/// at that distance crosses the edges' lines (the cut's middle when they
/// are less than [`MIN_CUT`] apart).
fn mitre(p: Point, q: Point, tip: Point, limit: f64) -> Vec<Point> {
    let m = p.midpoint(q);
    let out = tip - m;
    let h = out.hypot();
    if h <= limit {
        return vec![tip];
    }
    let u = out / h;
    // On the line through `from` and the tip, the point at height MITRE_OUT
    // along u (measured from m).
    let cut = |from: Point| -> Point {
        let rise = (tip - from).dot(u);
        if rise.abs() < 1e-9 {
            return from;
        }
        from + (tip - from) * ((limit - (from - m).dot(u)) / rise)
    };
    let (a, b) = (cut(p), cut(q));
    if (b - a).hypot() < MIN_CUT {
        // Too narrow to show: the point in the middle of the cut.
        return vec![a.midpoint(b)];
    }
    vec![a, b]
}

#[cfg(test)]
mod tests {
    use crate::outline::smooth::smooth_loops;
    use crate::raster::{Coverage, Grid};
    use kurbo::{Point, Rect};

    /// Distance (px) from `p` to the boundary of `r`.
    fn to_boundary(r: Rect, p: Point) -> f64 {
        let dx = (p.x - r.x0).abs().min((p.x - r.x1).abs());
        let dy = (p.y - r.y0).abs().min((p.y - r.y1).abs());
        if (r.x0..=r.x1).contains(&p.x) && (r.y0..=r.y1).contains(&p.y) {
            dx.min(dy)
        } else {
            let cx = p.x.clamp(r.x0, r.x1);
            let cy = p.y.clamp(r.y0, r.y1);
            (p.x - cx).hypot(p.y - cy)
        }
    }

    #[test]
    fn lines_one_to_three_pixels_wide_keep_square_ends() {
        for w in 1..=3usize {
            let r = Rect::new(5.0, 5.0, 5.0 + w as f64, 35.0);
            let cov: Coverage = Grid::from_fn(12, 40, |x, y| {
                let inside = (5..5 + w).contains(&x) && (5..35).contains(&y);
                if inside {
                    1.0
                } else {
                    0.0
                }
            });
            let loops = smooth_loops(&cov);
            assert_eq!(loops.len(), 1, "width {w}");
            let l = &loops[0];
            // The outline is the rectangle the pixels fill: full length and
            // width to the last pixel (the ends neither narrow to a needle
            // several pixels long nor round off).
            let worst = l
                .points
                .iter()
                .map(|&p| to_boundary(r, p))
                .fold(0.0, f64::max);
            assert!(worst < 1e-6, "width {w}: {worst} px off the rectangle");
            for corner in [(r.x0, r.y0), (r.x1, r.y0), (r.x1, r.y1), (r.x0, r.y1)] {
                let c = Point::new(corner.0, corner.1);
                let i = l.points.iter().position(|&p| (p - c).hypot() < 1e-6);
                let i = i.unwrap_or_else(|| panic!("width {w}: no vertex at {c:?}"));
                assert!(l.corners.contains(&i), "width {w}: {c:?} is not a corner");
            }
        }
    }

    /// A diagonal line 1.5 px wide, its pixels those whose centre lies
    /// within the stroke: both ends keep within a pixel of the drawn end,
    /// across the stroke as well as along it.
    #[test]
    fn a_diagonal_line_reaches_its_ends() {
        let (a, b) = (Point::new(8.3, 31.7), Point::new(33.6, 6.2));
        let dir = (b - a) / (b - a).hypot();
        let half = 0.75;
        let cov: Coverage = Grid::from_fn(42, 40, |x, y| {
            let p = Point::new(x as f64 + 0.5, y as f64 + 0.5) - a;
            let along = p.dot(dir);
            let across = p.cross(dir).abs();
            if (0.0..=(b - a).hypot()).contains(&along) && across <= half {
                1.0
            } else {
                0.0
            }
        });
        let loops = smooth_loops(&cov);
        assert_eq!(loops.len(), 1);
        let along: Vec<f64> = loops[0].points.iter().map(|&p| (p - a).dot(dir)).collect();
        let lo = along.iter().cloned().fold(f64::INFINITY, f64::min);
        let hi = along.iter().cloned().fold(f64::NEG_INFINITY, f64::max);
        let len = (b - a).hypot();
        assert!(lo < 0.6 && lo > -1.0, "start {lo:.2} px from the drawn end");
        assert!(
            hi > len - 0.6 && hi < len + 1.0,
            "end {:.2} px short",
            len - hi
        );
        // Near each end the outline is still about as wide as the stroke:
        // where the cross-section at `s` px along meets the outline.
        let pts = &loops[0].points;
        let width_at = |s: f64| {
            let mut across = Vec::new();
            for i in 0..pts.len() {
                let (p, q) = ((pts[i] - a), (pts[(i + 1) % pts.len()] - a));
                let (sp, sq) = (p.dot(dir) - s, q.dot(dir) - s);
                if sp * sq <= 0.0 && sp != sq {
                    let t = sp / (sp - sq);
                    across.push(p.lerp(q, t).cross(dir));
                }
            }
            let max = across.iter().cloned().fold(f64::NEG_INFINITY, f64::max);
            let min = across.iter().cloned().fold(f64::INFINITY, f64::min);
            max - min
        };
        for s in [1.5, len - 1.5] {
            let w = width_at(s);
            assert!(w > 0.8, "{w:.2} px wide at {s:.1} px along");
        }
    }

    /// A 1-px zigzag's apex (sides of slope ±2.5, as on the thin-lines
    /// sample) comes out as a mitre wherever it falls on the pixel grid: a
    /// corner at the outer apex, the outline never more than
    /// [`super::MITRE_OUT`] (plus the pixel's own half) beyond the ink. (At
    /// some offsets the pixels next to the apex bend its neighbouring
    /// edges over to a U-turn of 153°; the mitre reads the arms beyond
    /// them, [`super::arm`], so the apex does not come out a round blob.)
    #[test]
    fn a_thin_zigzag_apex_is_mitred() {
        for k in 0..16 {
            thin_zigzag_apex(Point::new(
                20.0 + k as f64 / 16.0,
                6.0 + (k % 4) as f64 / 4.0,
            ));
        }
    }

    fn thin_zigzag_apex(apex: Point) {
        let cov: Coverage = Grid::from_fn(42, 40, |x, y| {
            let (px, py) = (x as f64 + 0.5, y as f64 + 0.5);
            let dy = py - apex.y;
            let arm =
                |s: f64| ((px - apex.x) - s * dy / 2.5).abs() * 2.5 / 2.5f64.hypot(1.0) <= 0.5;
            if (0.0..30.0).contains(&dy) && (arm(1.0) || arm(-1.0)) {
                1.0
            } else {
                0.0
            }
        });
        let loops = smooth_loops(&cov);
        assert_eq!(loops.len(), 1);
        let l = &loops[0];
        let near_apex: Vec<Point> = l
            .corners
            .iter()
            .map(|&c| l.points[c])
            .filter(|p| (p.x - apex.x).abs() < 3.0 && p.y < apex.y + 5.0)
            .collect();
        assert!(!near_apex.is_empty(), "apex at {apex:?}: no corner");
        let ink = |x: f64, y: f64| cov.get_or(x as isize, y as isize, 0.0) > 0.5;
        for p in &l.points {
            // The nearest ink pixel, searched within 3 px.
            let mut d = f64::INFINITY;
            for dy in -3..=3 {
                for dx in -3..=3 {
                    let (cx, cy) = (p.x.floor() + dx as f64, p.y.floor() + dy as f64);
                    if cx >= 0.0 && cy >= 0.0 && ink(cx, cy) {
                        let r = Rect::new(cx, cy, cx + 1.0, cy + 1.0);
                        let inside = r.contains(*p);
                        d = d.min(if inside { 0.0 } else { to_boundary(r, *p) });
                    }
                }
            }
            assert!(
                d <= super::MITRE_OUT + 0.5,
                "apex at {apex:?}: {p:?} is {d:.2} px off the ink"
            );
        }
    }

    /// Round dots 4–14 px across (pixel discs at sub-pixel offsets) come
    /// out without a corner: their polygons turn 45–90° at every vertex,
    /// which the mitre and bevel rules read as apexes unless the turning
    /// is seen to be spread (`spread`; without it, many of these dots get
    /// a corner or two).
    #[test]
    fn round_dots_have_no_corners_and_line_ends_stay_square() {
        for step in 0..=20 {
            let r = 2.0 + step as f64 * 0.25;
            let c = Point::new(12.3 + 0.07 * step as f64, 12.6 - 0.05 * step as f64);
            let cov: Coverage = Grid::from_fn(26, 26, |x, y| {
                let p = Point::new(x as f64 + 0.5, y as f64 + 0.5);
                if (p - c).hypot() <= r {
                    1.0
                } else {
                    0.0
                }
            });
            let loops = smooth_loops(&cov);
            assert_eq!(loops.len(), 1, "radius {r}");
            let corners: Vec<Point> = loops[0]
                .corners
                .iter()
                .map(|&i| loops[0].points[i])
                .collect();
            assert!(corners.is_empty(), "radius {r}: corners at {corners:?}");
        }
    }
}
