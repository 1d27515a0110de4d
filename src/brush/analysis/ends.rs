//! The two ends of an exemplar's main branch, found when `style.toml`
//! gives none (DecoBrush §4.2 has the user place them): the farthest pair
//! of ink pixels along the edge-tangent-flow geodesic, the least-cost
//! distance of the spine search ([`super::spine::LinkGraph`]), so the
//! pair lies at the two ends of the longest line the drawing's flow runs
//! along.
//!
//! * **Farthest pair.** A double sweep: the ink pixel farthest from the
//!   deepest ink pixel is one end, the ink pixel farthest from that one the
//!   other (exact for a tree of lines, the diameter's usual estimate
//!   otherwise).
//! * **Placing each end.** The farthest pixel of a blunt tip is one of its
//!   corners. Each end starts from the line's middle near the tip (its
//!   deepest pixels), and is carried on along the line's direction to the
//!   outline: the middle of the tip, where a designer puts it.
//! * **No clear main branch.** A dot (its two ends less than three line
//!   thicknesses apart along the geodesic) or a ring (a second path between
//!   the ends, away from the first, costs under [`LOOP_RATIO`] times as
//!   much and strays far from it, [`LOOP_SPREAD`]) has no main branch to
//!   find; its ends are then taken across its longer side through the
//!   middle of its ink, and the caller warns.

use super::spine::{exemplar_flow, LinkGraph, SpineOptions};
use crate::raster::Grid;
use kurbo::{Point, Vec2};

/// A second path between the ends, kept away from the first, costing under
/// this many times the first makes the drawing a loop.
pub const LOOP_RATIO: f64 = 1.3;

/// The share of the path's cost by which a ring's two halves stray apart
/// at least (a ring of radius `r`: `2r` over `πr`, 0.64).
pub const LOOP_SPREAD: f64 = 0.35;

/// A main branch shorter than this many line thicknesses along the
/// geodesic is a dot.
pub const MIN_ELONGATION: f64 = 3.0;

/// How the ends were found.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Found {
    /// At the two ends of the main branch.
    Branch,
    /// The drawing has no clear main branch (a dot, a ring): across its
    /// longer side.
    Fallback,
}

/// Two ends (pixel coordinates of the grid searched) and how they were
/// found; `start` is the left one (the upper one of a vertical pair).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Ends {
    /// The start.
    pub start: Point,
    /// The end.
    pub end: Point,
    /// How they were found.
    pub found: Found,
}

/// How far (px) outside the ink the geodesic may run: a rasterized
/// hairline broken for a pixel or two stays one line.
pub const REACH: f32 = 1.5;

/// The ends of the main branch of the ink `sdf` (px, negative inside);
/// `None` when there is no ink. The geodesic runs within [`REACH`] of the
/// ink, so it cannot cut across the paper between a spiral's turns.
pub fn find_ends(sdf: &Grid<f32>, opts: &SpineOptions) -> Option<Ends> {
    let (w, h) = (sdf.width(), sdf.height());
    let ink: Vec<usize> = (0..w * h).filter(|&i| sdf.data()[i] < 0.0).collect();
    let deepest = *ink
        .iter()
        .min_by(|&&a, &&b| sdf.data()[a].total_cmp(&sdf.data()[b]).then(a.cmp(&b)))?;
    let half = -sdf.data()[deepest] as f64;
    let flow = exemplar_flow(sdf);
    let graph = LinkGraph::new(&flow, opts);
    let paper: Vec<bool> = sdf.data().iter().map(|&d| d > REACH).collect();
    let farthest = |d: &[f64]| {
        ink.iter()
            .copied()
            .filter(|&i| d[i].is_finite())
            .max_by(|&a, &b| d[a].total_cmp(&d[b]).then(b.cmp(&a)))
    };
    let d0 = graph.distances(deepest, Some(&paper));
    let a = farthest(&d0)?;
    let da = graph.distances(a, Some(&paper));
    let b = farthest(&da)?;
    let db = graph.distances(b, Some(&paper));
    let length = da[b];
    let branch =
        length >= MIN_ELONGATION * 2.0 * half.max(0.5) && !is_loop(&graph, &paper, &da, a, b, half);
    if !branch {
        let (s, e) = across(sdf, &ink);
        return Some(ordered(s, e, Found::Fallback));
    }
    let tip = |far: usize, d: &[f64]| tip_point(sdf, &ink, d, far, half);
    Some(ordered(tip(a, &db), tip(b, &da), Found::Branch))
}

/// The pair with the left (else upper) one first.
fn ordered(p: Point, q: Point, found: Found) -> Ends {
    let swap = if (p.x - q.x).abs() > 1e-9 {
        q.x < p.x
    } else {
        q.y < p.y
    };
    let (start, end) = if swap { (q, p) } else { (p, q) };
    Ends { start, end, found }
}

/// Whether the ends `a` and `b` are joined by two paths of nearly the
/// same cost far apart (a ring): the least-cost path from `b` back to `a`
/// (one path, even where two tie) is widened by a line half-width `half`
/// and blocked, and the search runs again within the ink (`paper` stays
/// blocked); the second path is a ring's other half when it costs under
/// [`LOOP_RATIO`] times the first and strays from it by more than
/// [`LOOP_SPREAD`] of its cost (a lattice or a wide band has parallel
/// paths too, within its width).
fn is_loop(graph: &LinkGraph, paper: &[bool], da: &[f64], a: usize, b: usize, half: f64) -> bool {
    let (w, h) = (graph.width(), graph.height());
    let best = da[b];
    let first = back_path(graph, da, a, b);
    let r = (half.ceil() as isize).max(1) + 1;
    let mut blocked = paper.to_vec();
    let mark = |blocked: &mut Vec<bool>, i: usize, v: bool| {
        let (x, y) = ((i % w) as isize, (i / w) as isize);
        for dy in -r..=r {
            for dx in -r..=r {
                let (nx, ny) = (x + dx, y + dy);
                if nx >= 0 && ny >= 0 && (nx as usize) < w && (ny as usize) < h {
                    let j = ny as usize * w + nx as usize;
                    blocked[j] = v || paper[j];
                }
            }
        }
    };
    for &i in &first {
        mark(&mut blocked, i, true);
    }
    // The ends themselves and their surroundings stay open.
    for &e in &[a, b] {
        mark(&mut blocked, e, false);
    }
    let sa = graph.distances(a, Some(&blocked));
    if sa[b].is_nan() || sa[b] >= LOOP_RATIO * best {
        return false;
    }
    let second = back_path(graph, &sa, a, b);
    let at = |i: usize| Point::new((i % w) as f64, (i / w) as f64);
    let spread = second
        .iter()
        .map(|&j| {
            first
                .iter()
                .map(|&i| at(i).distance(at(j)))
                .fold(f64::INFINITY, f64::min)
        })
        .fold(0.0f64, f64::max);
    spread > LOOP_SPREAD * best
}

/// The least-cost path from `a` to `b` as pixel indices, `b` first: from
/// `b`, each step goes to the linked pixel whose distance `d` from `a`
/// plus the link's cost is least (link costs are symmetric), until `a`.
fn back_path(graph: &LinkGraph, d: &[f64], a: usize, b: usize) -> Vec<usize> {
    let mut path = vec![b];
    let mut i = b;
    while i != a && path.len() <= d.len() {
        let mut best: Option<(f64, usize)> = None;
        graph.links_from(i, |j, cost| {
            let v = d[j] + cost;
            if d[j] < d[i] && best.is_none_or(|(bv, _)| v < bv) {
                best = Some((v, j));
            }
        });
        match best {
            Some((_, j)) => {
                path.push(j);
                i = j;
            }
            None => break,
        }
    }
    path
}

/// Share of the tip's greatest depth that its medial pixels reach.
const MEDIAL: f32 = 0.8;

/// The middle of the tip at pixel `far` (see the module docs): `d` is the
/// distance from the other end, `half` the deepest line half-width. The
/// line's middle near the tip is the farthest (along `d`) of the tip's
/// pixels at least [`MEDIAL`] as deep as its deepest (within three
/// half-widths of the farthest distance); from it the line is carried on
/// along its direction (from the centroid of the ink two to four
/// half-widths back along `d`) to the outline, through the last ink
/// within a pixel and a half of that direction.
fn tip_point(sdf: &Grid<f32>, ink: &[usize], d: &[f64], far: usize, half: f64) -> Point {
    let w = sdf.width();
    let centre = |i: usize| Point::new((i % w) as f64 + 0.5, (i / w) as f64 + 0.5);
    let top = d[far];
    let band = half.max(1.0);
    let near: Vec<usize> = ink
        .iter()
        .copied()
        .filter(|&i| d[i].is_finite() && d[i] >= top - 3.0 * band)
        .collect();
    let deepest = near.iter().map(|&i| sdf.data()[i]).fold(0.0f32, f32::min);
    let Some(&m) = near
        .iter()
        .filter(|&&i| sdf.data()[i] <= MEDIAL * deepest)
        .max_by(|&&a, &&b| d[a].total_cmp(&d[b]).then(b.cmp(&a)))
    else {
        return centre(far);
    };
    let mid = centre(m);
    let (mut sx, mut sy, mut n) = (0.0, 0.0, 0usize);
    for &i in ink {
        if d[i] >= d[m] - 4.0 * band && d[i] <= d[m] - 2.0 * band {
            let p = centre(i);
            (sx, sy, n) = (sx + p.x, sy + p.y, n + 1);
        }
    }
    let dir = if n > 0 {
        mid - Point::new(sx / n as f64, sy / n as f64)
    } else {
        centre(far) - mid
    };
    if dir.hypot() <= 1e-9 {
        return mid;
    }
    let dir = dir / dir.hypot();
    // The last ink ahead along that direction, carried on to the outline
    // by its own distance to it.
    let (ahead, inside) = ink
        .iter()
        .map(|&i| (centre(i) - mid, sdf.data()[i]))
        .filter(|(v, _)| v.cross(dir).abs() <= 1.5 && v.hypot() <= 4.0 * band)
        .map(|(v, s)| (v.dot(dir), -s as f64))
        .fold((0.0f64, 0.0f64), |a, b| if b.0 > a.0 { b } else { a });
    mid + dir * (ahead + inside.clamp(0.0, 1.0))
}

/// The fallback ends: across the ink's longer side, through its centroid,
/// at the ink's extent.
fn across(sdf: &Grid<f32>, ink: &[usize]) -> (Point, Point) {
    let w = sdf.width();
    let pts: Vec<Point> = ink
        .iter()
        .map(|&i| Point::new((i % w) as f64 + 0.5, (i / w) as f64 + 0.5))
        .collect();
    let n = pts.len().max(1) as f64;
    let c = Point::new(
        pts.iter().map(|p| p.x).sum::<f64>() / n,
        pts.iter().map(|p| p.y).sum::<f64>() / n,
    );
    let (x0, x1) = pts
        .iter()
        .fold((f64::MAX, f64::MIN), |(a, b), p| (a.min(p.x), b.max(p.x)));
    let (y0, y1) = pts
        .iter()
        .fold((f64::MAX, f64::MIN), |(a, b), p| (a.min(p.y), b.max(p.y)));
    let dir = if x1 - x0 >= y1 - y0 {
        Vec2::new(1.0, 0.0)
    } else {
        Vec2::new(0.0, 1.0)
    };
    let reach = |s: f64| {
        pts.iter()
            .map(|p| (*p - c).dot(dir) * s)
            .fold(0.0f64, f64::max)
    };
    (c - dir * reach(-1.0), c + dir * reach(1.0))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::raster::sdf::point_segment_distance;
    use kurbo::Line;

    /// Signed distance to a polyline band of half-width `r` on an `n`²
    /// grid (flat, not rounded, beyond its ends when `flat`).
    fn band(n: usize, centre: &[Point], r: f64) -> Grid<f32> {
        Grid::from_fn(n, n, |x, y| {
            let p = Point::new(x as f64 + 0.5, y as f64 + 0.5);
            let d = centre
                .windows(2)
                .map(|w| point_segment_distance(p, Line::new(w[0], w[1])))
                .fold(f64::INFINITY, f64::min);
            (d - r) as f32
        })
    }

    fn length(pts: &[Point]) -> f64 {
        pts.windows(2).map(|w| w[0].distance(w[1])).sum()
    }

    /// The found ends lie within 2 % of the spine's length of the
    /// hand-placed ones (the tips of the drawn centre line).
    fn check(centre: &[Point], r: f64, hand: (Point, Point)) {
        let sdf = band(160, centre, r);
        let e = find_ends(&sdf, &SpineOptions::default()).expect("ink");
        assert_eq!(e.found, Found::Branch);
        let l = length(centre);
        let (ds, de) = (e.start.distance(hand.0), e.end.distance(hand.1));
        assert!(
            ds <= 0.02 * l && de <= 0.02 * l,
            "start {:?} ({ds:.2} px off), end {:?} ({de:.2} px off), spine {l:.0} px",
            e.start,
            e.end
        );
    }

    #[test]
    fn a_straight_band_has_its_ends_at_its_tips() {
        let centre = [Point::new(20.0, 80.3), Point::new(140.0, 80.3)];
        // Round caps: the tips lie a half-width beyond the centre line.
        check(
            &centre,
            6.0,
            (Point::new(14.0, 80.3), Point::new(146.0, 80.3)),
        );
    }

    #[test]
    fn an_s_band_has_its_ends_at_its_tips() {
        let centre: Vec<Point> = (0..=100)
            .map(|i| {
                let t = i as f64 / 100.0;
                Point::new(
                    20.0 + 120.0 * t,
                    80.0 + 35.0 * (2.0 * std::f64::consts::PI * t).sin(),
                )
            })
            .collect();
        let tip = |p: Point, q: Point| p + (p - q) / p.distance(q) * 5.0;
        let hand = (tip(centre[0], centre[1]), tip(centre[100], centre[99]));
        check(&centre, 5.0, hand);
    }

    #[test]
    fn a_spiral_band_has_its_ends_at_its_tips() {
        // One and a half turns of an Archimedean spiral, turns 20 px apart.
        let centre: Vec<Point> = (0..=300)
            .map(|i| {
                let a = 3.0 * std::f64::consts::PI * i as f64 / 300.0 + 1.0;
                let r = 20.0 * a / (2.0 * std::f64::consts::PI) + 8.0;
                Point::new(80.0 + r * a.cos(), 80.0 + r * a.sin())
            })
            .collect();
        let tip = |p: Point, q: Point| p + (p - q) / p.distance(q) * 4.0;
        let hand = (tip(centre[0], centre[1]), tip(centre[300], centre[299]));
        let (a, b) = if hand.0.x <= hand.1.x {
            hand
        } else {
            (hand.1, hand.0)
        };
        check(&centre, 4.0, (a, b));
    }

    #[test]
    fn a_dot_and_a_ring_have_no_main_branch() {
        let dot = Grid::from_fn(60, 60, |x, y| {
            (Point::new(x as f64 + 0.5, y as f64 + 0.5).distance(Point::new(30.0, 30.0)) - 12.0)
                as f32
        });
        let e = find_ends(&dot, &SpineOptions::default()).expect("ink");
        assert_eq!(e.found, Found::Fallback);
        // Across the dot, through its middle.
        assert!(
            (e.start.y - 30.0).abs() < 1.0 && (e.end.y - 30.0).abs() < 1.0,
            "{e:?}"
        );
        assert!(e.end.x - e.start.x > 20.0, "{e:?}");
        let ring = Grid::from_fn(100, 100, |x, y| {
            let d = Point::new(x as f64 + 0.5, y as f64 + 0.5).distance(Point::new(50.0, 50.0));
            ((d - 35.0).abs() - 3.0) as f32
        });
        let e = find_ends(&ring, &SpineOptions::default()).expect("ink");
        assert_eq!(e.found, Found::Fallback, "{e:?}");
        assert!(find_ends(&Grid::new(10, 10, 1.0), &SpineOptions::default()).is_none());
    }
}
