//! The "art brush" baseline: one exemplar stretched along the whole query,
//! as Illustrator's Art Brush does (DESIGN.md, "How quality is judged").
//!
//! A point of the exemplar at arc length `s` along its spine and signed
//! offset `t` across it (in the spine's tangent/normal frame) goes to the
//! query point at arc length `s · L_q / L_e`, offset by `t · W_q / W_e`
//! along the query's normal there (`L` spine lengths, `W` widths). Applied
//! to the vertices of a [`RibMesh`] it gives a deformed mesh, so
//! [`rasterize_coords`] turns it into the same coordinate field as the
//! ARAP stage, which the brush pipeline and its tests compare against.

use crate::brush::analysis::uv::tangents;
use crate::brush::arap::{rasterize_coords, RibMesh};
use crate::error::{Error, Result};
use crate::raster::Grid;
use kurbo::{Affine, Point, Vec2};

/// The left-hand normal of a unit tangent (the same convention on both
/// spines, so left stays left).
fn normal(t: Vec2) -> Vec2 {
    Vec2::new(-t.y, t.x)
}

/// Position and unit tangent of a polyline at arc length `s`, linearly
/// extrapolated along the end tangents beyond its ends.
fn at(pts: &[Point], arc: &[f64], tan: &[Vec2], s: f64) -> (Point, Vec2) {
    let n = pts.len();
    let total = arc[n - 1];
    if s <= 0.0 {
        return (pts[0] + tan[0] * s, tan[0]);
    }
    if s >= total {
        return (pts[n - 1] + tan[n - 1] * (s - total), tan[n - 1]);
    }
    // The edge holding s (binary search over the cumulative lengths).
    let i = arc.partition_point(|&a| a <= s).clamp(1, n - 1);
    let (a, b) = (arc[i - 1], arc[i]);
    let f = if b > a { (s - a) / (b - a) } else { 0.0 };
    let t = tan[i - 1] * (1.0 - f) + tan[i] * f;
    let l = t.hypot();
    (
        pts[i - 1].lerp(pts[i], f),
        if l > 0.0 { t / l } else { tan[i] },
    )
}

/// The art-brush image of every vertex of `mesh` (exemplar units) along
/// the `query` polyline (canvas units) drawn at width `query_width`.
pub fn art_brush_positions(
    mesh: &RibMesh,
    query: &[Point],
    query_width: f64,
) -> Result<Vec<Point>> {
    let bad = |r: &str| Err(Error::degenerate("art brush", r));
    let spine: Vec<Point> = mesh
        .spine
        .iter()
        .filter_map(|&v| mesh.rest.get(v).copied())
        .collect();
    if spine.len() < 2 || spine.len() != mesh.spine.len() {
        return bad("the exemplar mesh has fewer than two ribs");
    }
    let per = mesh.per_rib;
    if per == 0 || mesh.rest.len() != per * spine.len() {
        return bad("the mesh is not a rib mesh (vertex count ≠ ribs × per_rib)");
    }
    if query.len() < 2 || !query.iter().all(|p| p.x.is_finite() && p.y.is_finite()) {
        return bad("the query needs at least two finite points");
    }
    if !(query_width.is_finite() && query_width > 0.0) {
        return bad("the query width must be positive");
    }
    let (se, te) = (
        crate::raster::contour::open_arc_lengths(&spine),
        tangents(&spine),
    );
    let (sq, tq) = (
        crate::raster::contour::open_arc_lengths(query),
        tangents(query),
    );
    let (le, lq) = (se[se.len() - 1], sq[sq.len() - 1]);
    if !(le > 0.0 && lq > 0.0) {
        return bad("a spine has zero length");
    }
    // Exemplar width: mean outline-to-outline rib length.
    let we = (0..spine.len())
        .filter_map(|i| {
            Some(
                mesh.rest
                    .get(i * per)?
                    .distance(*mesh.rest.get(i * per + per - 1)?),
            )
        })
        .sum::<f64>()
        / spine.len() as f64;
    if we.is_nan() || we <= 0.0 {
        return bad("the exemplar has zero width");
    }
    let (ks, kt) = (lq / le, query_width / we);
    let mut out = Vec::with_capacity(mesh.rest.len());
    for (v, p) in mesh.rest.iter().enumerate() {
        let i = (v / per).min(spine.len() - 1);
        let d = *p - spine[i];
        let (along, across) = (d.dot(te[i]), d.dot(normal(te[i])));
        let (q, t) = at(query, &sq, &tq, (se[i] + along) * ks);
        out.push(q + normal(t) * (across * kt));
    }
    Ok(out)
}

/// The art-brush coordinate field: for every pixel centre covered by the
/// stretched exemplar, its exemplar coordinates (see
/// [`rasterize_coords`], whose conventions it shares).
pub fn art_brush_coords(
    mesh: &RibMesh,
    query: &[Point],
    query_width: f64,
    width: usize,
    height: usize,
    to_pixel: Affine,
) -> Result<Grid<Option<Point>>> {
    let deformed = art_brush_positions(mesh, query, query_width)?;
    rasterize_coords(mesh, &deformed, width, height, to_pixel)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::brush::arap::{mean_distortion, Arap};

    fn straight_mesh(n: usize, h: f64, w: f64) -> RibMesh {
        let spine: Vec<Point> = (0..n).map(|i| Point::new(i as f64 * h, 0.0)).collect();
        let left: Vec<Point> = spine.iter().map(|p| *p + Vec2::new(0.0, w)).collect();
        let right: Vec<Point> = spine.iter().map(|p| *p + Vec2::new(0.0, -w)).collect();
        RibMesh::from_ribs(&spine, &left, &right, 2).unwrap()
    }

    #[test]
    fn straight_query_stretches_proportionally() {
        let mesh = straight_mesh(11, 1.0, 2.0); // 10 long, 4 wide
        let query = [Point::new(5.0, 5.0), Point::new(25.0, 5.0)]; // 20 long
        let pos = art_brush_positions(&mesh, &query, 8.0).unwrap();
        for (p, r) in pos.iter().zip(&mesh.rest) {
            let want = Point::new(5.0 + 2.0 * r.x, 5.0 + 2.0 * r.y);
            assert!((*p - want).hypot() < 1e-9, "{p:?} vs {want:?}");
        }
        let grid = art_brush_coords(&mesh, &query, 8.0, 32, 16, Affine::IDENTITY).unwrap();
        let mut n = 0;
        for y in 0..16 {
            for x in 0..32 {
                if let Some(c) = grid.get(x, y) {
                    n += 1;
                    let want =
                        Point::new((x as f64 + 0.5 - 5.0) / 2.0, (y as f64 + 0.5 - 5.0) / 2.0);
                    assert!((c - want).hypot() < 1e-9);
                }
            }
        }
        assert_eq!(n, 20 * 8, "the 20 × 8 ribbon");
    }

    #[test]
    fn bent_query_keeps_the_spine_on_the_path() {
        let mesh = straight_mesh(60, 1.0, 4.0);
        let radius = 59.0 / std::f64::consts::FRAC_PI_2;
        let query: Vec<Point> = (0..200)
            .map(|i| {
                let a = i as f64 / 199.0 * std::f64::consts::FRAC_PI_2;
                Point::new(radius * a.sin(), radius * (1.0 - a.cos()))
            })
            .collect();
        let pos = art_brush_positions(&mesh, &query, 8.0).unwrap();
        let centre = Point::new(0.0, radius);
        for &v in &mesh.spine {
            assert!((pos[v].distance(centre) - radius).abs() < 0.01);
        }
        // Outline vertices sit at the rib half-width from the arc.
        for (i, &v) in mesh.spine.iter().enumerate() {
            let l = pos[v - 2].distance(centre) - radius;
            let r = pos[v + 2].distance(centre) - radius;
            assert!(
                (l.abs() - 4.0).abs() < 0.01 && (r.abs() - 4.0).abs() < 0.01,
                "rib {i}"
            );
        }
        // On a smooth bend the art brush and ARAP distort alike (both about
        // w/2R); the baseline's weakness is elsewhere (exemplar stretch,
        // folds on tight bends), which the pipeline's tests measure.
        let arap = Arap::new(&mesh, &mesh.spine).unwrap();
        let pins: Vec<Point> = mesh.spine.iter().map(|&v| pos[v]).collect();
        let d_arap = mean_distortion(&mesh, &arap.solve(&pins).unwrap());
        let d_art = mean_distortion(&mesh, &pos);
        assert!(d_arap < 0.1 && d_art < 0.1, "{d_arap} {d_art}");
    }

    #[test]
    fn arap_folds_less_than_the_art_brush_on_tight_bends() {
        // Half-width 4 bent at radius 4: the normal-offset map collapses
        // the inner side; ARAP lets the inner outline slide and folds less.
        let mesh = straight_mesh(40, 1.0, 4.0);
        let radius = 4.0;
        let q: Vec<Point> = (0..40)
            .map(|i| {
                let a = i as f64 / radius;
                Point::new(radius * a.sin(), radius * (1.0 - a.cos()))
            })
            .collect();
        let art = art_brush_positions(&mesh, &q, 8.0).unwrap();
        let arap = Arap::new(&mesh, &mesh.spine).unwrap().solve(&q).unwrap();
        let flips = |pos: &[Point]| {
            let sign = |p: [Point; 3]| (p[1] - p[0]).cross(p[2] - p[0]).signum();
            mesh.triangles
                .iter()
                .filter(|t| sign(t.map(|v| mesh.rest[v])) != sign(t.map(|v| pos[v])))
                .count()
        };
        let (fa, fr) = (flips(&art), flips(&arap));
        assert!(fr * 2 < fa, "ARAP folds {fr}, art brush {fa}");
        assert!(mean_distortion(&mesh, &arap) < mean_distortion(&mesh, &art));
    }

    #[test]
    fn bad_input_is_an_error() {
        let mesh = straight_mesh(5, 1.0, 1.0);
        let p = Point::new(1.0, 1.0);
        assert!(art_brush_positions(&mesh, &[p], 1.0).is_err());
        assert!(art_brush_positions(&mesh, &[p, p], 1.0).is_err());
        assert!(art_brush_positions(&mesh, &[p, Point::new(2.0, 1.0)], 0.0).is_err());
        assert!(art_brush_positions(&mesh, &[p, Point::new(f64::NAN, 1.0)], 1.0).is_err());
    }
}
