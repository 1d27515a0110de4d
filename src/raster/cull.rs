//! Geometry far off the canvas, made cheap: curves whose control points
//! all lie outside a window become their chords before flattening, so a
//! huge shape costs what its visible part costs.

use kurbo::{BezPath, PathEl, Point, Rect};

/// `path` with every curve piece whose control points all lie outside
/// `window` replaced by its chord, so that a huge curve (a circle of radius
/// 10¹⁹ px, say) costs a few dozen segments to flatten instead of billions.
/// A curve lies within the hull of its control points, so for a point
/// inside `window` the chord changes neither the winding number nor any
/// distance shorter than the gap between the point and the hull. Curves are
/// halved (de Casteljau) until their hull is outside `window` or no larger
/// than four times it; curves already that small are kept as they are.
pub fn cull_far_curves(path: &BezPath, window: Rect) -> BezPath {
    use kurbo::{CubicBez, ParamCurve, QuadBez};
    let limit = 4.0 * window.width().max(window.height());
    let hull = |pts: &[Point]| {
        pts.iter()
            .fold(Rect::from_points(pts[0], pts[0]), |r, &p| r.union_pt(p))
    };
    let near =
        |r: Rect| r.x0 <= window.x1 && window.x0 <= r.x1 && r.y0 <= window.y1 && window.y0 <= r.y1;
    fn halve(c: CubicBez, depth: u32, keep: &dyn Fn(&CubicBez) -> Option<bool>, out: &mut BezPath) {
        match keep(&c) {
            Some(true) => out.curve_to(c.p1, c.p2, c.p3),
            None if depth < 64 => {
                halve(c.subsegment(0.0..0.5), depth + 1, keep, out);
                halve(c.subsegment(0.5..1.0), depth + 1, keep, out);
            }
            None => out.curve_to(c.p1, c.p2, c.p3),
            Some(false) => out.line_to(c.p3),
        }
    }
    // Some(true): keep the curve; Some(false): its chord; None: halve it.
    let keep = |c: &CubicBez| {
        let r = hull(&[c.p0, c.p1, c.p2, c.p3]);
        if !near(r) {
            Some(false)
        } else if r.width().max(r.height()) <= limit {
            Some(true)
        } else {
            None
        }
    };
    let mut out = BezPath::new();
    let mut last = Point::ZERO;
    let mut start = Point::ZERO;
    for el in path.elements() {
        match *el {
            PathEl::MoveTo(p) => {
                out.move_to(p);
                (last, start) = (p, p);
            }
            PathEl::LineTo(p) => {
                out.line_to(p);
                last = p;
            }
            PathEl::QuadTo(a, b) => {
                let c = QuadBez::new(last, a, b).raise();
                match keep(&c) {
                    Some(true) => out.quad_to(a, b),
                    _ => halve(c, 0, &keep, &mut out),
                }
                last = b;
            }
            PathEl::CurveTo(a, b, c) => {
                halve(CubicBez::new(last, a, b, c), 0, &keep, &mut out);
                last = c;
            }
            PathEl::ClosePath => {
                out.close_path();
                last = start;
            }
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::raster::input::flatten_segments;
    use kurbo::Shape as _;

    #[test]
    fn far_curves_become_chords_and_keep_the_winding_in_the_window() {
        let window = Rect::new(-100.0, -100.0, 200.0, 200.0);
        // Circles of radius 10¹² px: one far away, one whose top runs
        // through the window, one around it; and a small one inside.
        let mut path = BezPath::new();
        for (c, r) in [
            ((1e13, 5.0), 1e12),
            ((50.0, 1e12), 1e12 - 50.0),
            ((50.0, 50.0), 1e12),
            ((20.0, 20.0), 10.0),
        ] {
            path.extend(kurbo::Circle::new(c, r).path_elements(0.1));
        }
        let culled = cull_far_curves(&path, window);
        let n = culled.elements().len();
        assert!(n < 600, "{n} elements");
        // Same winding at points all over the window (kurbo's exact
        // winding against the original curves).
        for j in 0..=30 {
            for i in 0..=30 {
                let p = Point::new(-100.0 + 10.0 * i as f64, -100.0 + 10.0 * j as f64 + 0.37);
                assert_eq!(culled.winding(p), path.winding(p), "at {p:?}");
            }
        }
        // The small circle is kept exactly.
        let small: Vec<PathEl> = kurbo::Circle::new((20.0, 20.0), 10.0)
            .path_elements(0.1)
            .collect();
        let tail = &culled.elements()[n - small.len()..];
        assert_eq!(tail, &small[..]);
        // And flattening it takes a few thousand segments, not billions.
        let mut segs = Vec::new();
        flatten_segments(&culled, 0.01, &mut segs);
        assert!(segs.len() < 100_000, "{} segments", segs.len());
    }
}
