//! Step 4 of [`crate::outline::smooth`]: the optimal polygon's vertices
//! moved off the path (Selinger 2003, §2.3.1). Each polygon edge gets the
//! least-squares line of the path vertices it replaces; each vertex moves
//! to the point of the box of half-side ½ round its path vertex nearest
//! (in summed squared distance) to its two edges' lines, as potrace does.

use kurbo::{Point, Vec2};

/// The least-squares line (centroid, unit direction from the edge's start
/// to its end) of each polygon edge's path vertices, the chamfered ends
/// left out: edge `e` runs from `poly[e]` to `poly[e + 1]`.
pub(super) fn edge_lines(path: &[Point], poly: &[usize]) -> Vec<(Point, Vec2)> {
    let n = path.len();
    let k = poly.len();
    (0..k)
        .map(|e| {
            let a = poly[e];
            let b = poly[(e + 1) % k];
            let count = (b + n - a) % n + 1;
            // The end vertices are where the path rounds the polygon's
            // corners (midpoints of pixel edges chamfer every pixel corner
            // by half a pixel): they belong to neither edge's line.
            let at = |s: usize| path[(a + s) % n];
            let chamfer = |end: usize, inner: usize, next: usize| {
                let d0 = at(inner) - at(end);
                let d1 = at(next) - at(inner);
                let diagonal = (d0.x.abs() - 0.5).abs() < 1e-9 && (d0.y.abs() - 0.5).abs() < 1e-9;
                let axis = (d1.x.abs() - 1.0).abs() < 1e-9 || (d1.y.abs() - 1.0).abs() < 1e-9;
                count >= 4 && diagonal && axis
            };
            let first = usize::from(count >= 4 && chamfer(0, 1, 2));
            let last = usize::from(count >= 4 && chamfer(count - 1, count - 2, count - 3));
            let pts = (first..count - last).map(at);
            fit_line(pts, path[a], path[b])
        })
        .collect()
}

/// Step 4: each polygon vertex moved to the point of the box of half-side
/// ½ round its path vertex that is nearest, in summed squared distance, to
/// the least-squares lines of its two edges ([`edge_lines`]): their
/// intersection when it lies in the box, else the minimum of that
/// quadratic on the box's sides and corners (Selinger 2003, §2.3.1).
/// Clamping the intersection instead would throw the vertex to a corner
/// of the box wherever two nearly parallel lines meet far off.
pub(super) fn adjust_vertices(
    path: &[Point],
    poly: &[usize],
    lines: &[(Point, Vec2)],
) -> Vec<Point> {
    let k = poly.len();
    (0..k)
        .map(|e| {
            let v = path[poly[e]];
            let (c0, d0) = lines[(e + k - 1) % k];
            let (c1, d1) = lines[e];
            box_minimum(v, &[(c0, d0), (c1, d1)])
        })
        .collect()
}

/// The point of the box of half-side ½ round `v` with the least sum of
/// squared distances to the `lines` (point, unit direction); a line
/// through `v` across the others is added when they are parallel, so the
/// minimum is unique (as potrace does).
fn box_minimum(v: Point, lines: &[(Point, Vec2)]) -> Point {
    // Q(p) = Σ (n·(p − c))² = pᵀ A p − 2 bᵀ p + const, with n the normal.
    let (mut a, mut b) = ([0.0f64; 3], [0.0f64; 2]); // a: xx, xy, yy
    let add = |a: &mut [f64; 3], b: &mut [f64; 2], c: Point, n: Vec2| {
        let off = n.dot(c.to_vec2());
        a[0] += n.x * n.x;
        a[1] += n.x * n.y;
        a[2] += n.y * n.y;
        b[0] += n.x * off;
        b[1] += n.y * off;
    };
    for &(c, d) in lines {
        add(&mut a, &mut b, c, Vec2::new(-d.y, d.x));
    }
    let mut det = a[0] * a[2] - a[1] * a[1];
    if det.abs() < 1e-6 {
        // Parallel lines: also stay close to v across them.
        let d = lines.first().map_or(Vec2::new(1.0, 0.0), |l| l.1);
        add(&mut a, &mut b, v, d);
        det = a[0] * a[2] - a[1] * a[1];
    }
    let q = |p: Point| {
        p.x * p.x * a[0] + 2.0 * p.x * p.y * a[1] + p.y * p.y * a[2]
            - 2.0 * (b[0] * p.x + b[1] * p.y)
    };
    if det.abs() >= 1e-12 {
        let w = Point::new(
            (b[0] * a[2] - b[1] * a[1]) / det,
            (a[0] * b[1] - a[1] * b[0]) / det,
        );
        if (w.x - v.x).abs() <= 0.5 && (w.y - v.y).abs() <= 0.5 {
            return w;
        }
    }
    // On the box's boundary: each side's 1-D minimum (clamped to the side)
    // and the corners.
    let mut best = v;
    let mut best_q = q(v);
    let mut consider = |p: Point| {
        let qp = q(p);
        if qp < best_q {
            best = p;
            best_q = qp;
        }
    };
    for z in [-0.5, 0.5] {
        let y = v.y + z;
        if a[0] > 1e-12 {
            let x = ((b[0] - a[1] * y) / a[0]).clamp(v.x - 0.5, v.x + 0.5);
            consider(Point::new(x, y));
        }
        let x = v.x + z;
        if a[2] > 1e-12 {
            let y = ((b[1] - a[1] * x) / a[2]).clamp(v.y - 0.5, v.y + 0.5);
            consider(Point::new(x, y));
        }
        for z2 in [-0.5, 0.5] {
            consider(Point::new(v.x + z, v.y + z2));
        }
    }
    best
}

/// Total least squares line through `pts`: centroid and principal direction
/// (oriented from `a` to `b`).
/// The points are walked twice (centroid, then moments about it) rather
/// than collected.
fn fit_line(pts: impl Iterator<Item = Point> + Clone, a: Point, b: Point) -> (Point, Vec2) {
    let (count, sum) = pts
        .clone()
        .fold((0usize, Vec2::ZERO), |(k, s), p| (k + 1, s + p.to_vec2()));
    let m = count.max(1) as f64;
    let c = sum / m;
    let (mut sxx, mut sxy, mut syy) = (0.0, 0.0, 0.0);
    for p in pts {
        let d = p.to_vec2() - c;
        sxx += d.x * d.x;
        sxy += d.x * d.y;
        syy += d.y * d.y;
    }
    let angle = 0.5 * (2.0 * sxy).atan2(sxx - syy);
    let mut d = Vec2::new(angle.cos(), angle.sin());
    let chord = b - a;
    if chord.hypot() > 1e-9 && d.dot(chord) < 0.0 {
        d = -d;
    }
    if count < 2 || !d.x.is_finite() {
        let l = chord.hypot();
        d = if l > 1e-9 {
            chord / l
        } else {
            Vec2::new(1.0, 0.0)
        };
    }
    (c.to_point(), d)
}

#[cfg(test)]
mod tests {
    use super::*;

    proptest::proptest! {
        /// The box minimum is the least of the quadratic over a fine grid
        /// of the box (and lies in the box), for any two lines.
        #[test]
        fn box_minimum_beats_a_grid_search(
            v in (-5.0f64..5.0, -5.0f64..5.0),
            l0 in (-6.0f64..6.0, -6.0f64..6.0, 0.0f64..std::f64::consts::TAU),
            l1 in (-6.0f64..6.0, -6.0f64..6.0, 0.0f64..std::f64::consts::TAU),
        ) {
            let v = Point::new(v.0, v.1);
            let lines = [l0, l1].map(|(x, y, a)| (Point::new(x, y), Vec2::new(a.cos(), a.sin())));
            let q = |p: Point| -> f64 {
                lines.iter().map(|&(c, d)| d.cross(p - c).powi(2)).sum()
            };
            let m = box_minimum(v, &lines);
            proptest::prop_assert!((m.x - v.x).abs() <= 0.5 + 1e-9 && (m.y - v.y).abs() <= 0.5 + 1e-9);
            let parallel = lines[0].1.cross(lines[1].1).abs() < 1e-3;
            proptest::prop_assume!(!parallel);
            let steps = 200;
            let mut best = f64::INFINITY;
            for i in 0..=steps {
                for j in 0..=steps {
                    let p = Point::new(
                        v.x - 0.5 + i as f64 / steps as f64,
                        v.y - 0.5 + j as f64 / steps as f64,
                    );
                    best = best.min(q(p));
                }
            }
            proptest::prop_assert!(q(m) <= best + 1e-9, "{} > {}", q(m), best);
        }
    }

    /// Two lines meeting inside the box: their intersection.
    #[test]
    fn lines_meeting_in_the_box_give_their_intersection() {
        let lines = [
            (Point::new(0.0, 0.2), Vec2::new(1.0, 0.0)),
            (Point::new(0.1, 0.0), Vec2::new(0.0, 1.0)),
        ];
        let m = box_minimum(Point::new(0.3, -0.1), &lines);
        assert!((m - Point::new(0.1, 0.2)).hypot() < 1e-12, "{m:?}");
    }
}
