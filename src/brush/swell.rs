//! A stroke's width along it (SPEC.md, "Sketch SVG": pen pressure in the
//! live page, `data-widths` in a sketch): the ornament is synthesized at
//! the stroke's mean width, then every point of its traced outlines is
//! moved away from (or towards) the spine by the width there over that
//! mean, [`QuerySample::swell`]: a point `p` whose nearest spine point is
//! `f` goes to `f + k (p − f)`. Across the spine that scales the offset
//! along the normal, as DecoBrush's deformation of an exemplar along a
//! query does for its width (decobrush.txt §6); beyond an end the end
//! ornament scales about the end point, so the map stays continuous
//! there. Where the swell is 1 everywhere the outlines are not touched.

use super::query::{QuerySample, QuerySpine};
use crate::svg_out::Shape;
use kurbo::{BezPath, PathEl, Point};
use std::collections::HashMap;

/// Whether any sample of `spine` asks for another width than the one it
/// was synthesized at.
pub fn varies(spine: &QuerySpine) -> bool {
    spine.samples.iter().any(|s| s.swell != 1.0)
}

/// The nearest-point map onto a spine polyline, with a bucket grid of its
/// segments so a point looks at the few segments near it.
pub struct Swell<'a> {
    /// The spine samples (positions in sketch units, swell factors).
    samples: &'a [QuerySample],
    /// Side of a bucket, sketch units.
    cell: f64,
    /// Segment indices (segment `i` joins samples `i` and `i + 1`) by
    /// the buckets their bounding boxes meet.
    buckets: HashMap<(i64, i64), Vec<u32>>,
}

impl<'a> Swell<'a> {
    /// The map of `spine` (at least two samples, else points stay).
    pub fn new(spine: &'a QuerySpine) -> Swell<'a> {
        let cell = (2.0 * spine.width).max(spine.spacing).max(1e-9);
        let mut buckets: HashMap<(i64, i64), Vec<u32>> = HashMap::new();
        let key = |v: f64| (v / cell).floor().clamp(-1e15, 1e15) as i64;
        for (i, w) in spine.samples.windows(2).enumerate() {
            let (a, b) = (w[0].pos, w[1].pos);
            for x in key(a.x.min(b.x))..=key(a.x.max(b.x)) {
                for y in key(a.y.min(b.y))..=key(a.y.max(b.y)) {
                    buckets.entry((x, y)).or_default().push(i as u32);
                }
            }
        }
        Swell {
            samples: &spine.samples,
            cell,
            buckets,
        }
    }

    /// The nearest point of segment `i` to `p`: (squared distance, foot,
    /// swell at the foot).
    fn on_segment(&self, i: usize, p: Point) -> Option<(f64, Point, f64)> {
        let (a, b) = (self.samples.get(i)?, self.samples.get(i + 1)?);
        let ab = b.pos - a.pos;
        let len2 = ab.hypot2();
        let u = if len2 > 0.0 {
            ((p - a.pos).dot(ab) / len2).clamp(0.0, 1.0)
        } else {
            0.0
        };
        let foot = a.pos.lerp(b.pos, u);
        Some(((p - foot).hypot2(), foot, a.swell * (1.0 - u) + b.swell * u))
    }

    /// The nearest spine point to `p` and the swell there; ties go to the
    /// earlier segment, so the map is the same whatever the bucket order.
    fn nearest(&self, p: Point) -> Option<(Point, f64)> {
        let mut best: Option<(f64, usize, Point, f64)> = None;
        let consider = |i: usize, best: &mut Option<(f64, usize, Point, f64)>| {
            if let Some((d, foot, k)) = self.on_segment(i, p) {
                if best.is_none_or(|(bd, bi, ..)| d < bd || d == bd && i < bi) {
                    *best = Some((d, i, foot, k));
                }
            }
        };
        let (cx, cy) = (
            (p.x / self.cell).floor().clamp(-1e15, 1e15) as i64,
            (p.y / self.cell).floor().clamp(-1e15, 1e15) as i64,
        );
        for dx in -1..=1 {
            for dy in -1..=1 {
                for &i in self.buckets.get(&(cx + dx, cy + dy)).into_iter().flatten() {
                    consider(i as usize, &mut best);
                }
            }
        }
        // A segment within one cell of `p` meets one of the nine buckets;
        // a farther point looks at them all.
        if best.is_none_or(|(d, ..)| d > self.cell * self.cell) {
            for i in 0..self.samples.len().saturating_sub(1) {
                consider(i, &mut best);
            }
        }
        best.map(|(_, _, foot, k)| (foot, k))
    }

    /// Where `p` (sketch units) goes: `f + k (p − f)`.
    pub fn point(&self, p: Point) -> Point {
        match self.nearest(p) {
            Some((foot, k)) => foot + (p - foot) * k,
            None => p,
        }
    }

    /// `path` with every point (control points included) moved.
    pub fn path(&self, path: &BezPath) -> BezPath {
        path.elements()
            .iter()
            .map(|el| match *el {
                PathEl::MoveTo(a) => PathEl::MoveTo(self.point(a)),
                PathEl::LineTo(a) => PathEl::LineTo(self.point(a)),
                PathEl::QuadTo(a, b) => PathEl::QuadTo(self.point(a), self.point(b)),
                PathEl::CurveTo(a, b, c) => {
                    PathEl::CurveTo(self.point(a), self.point(b), self.point(c))
                }
                PathEl::ClosePath => PathEl::ClosePath,
            })
            .collect()
    }
}

/// Moves the outlines of `shapes`, traced along `spine`, to the stroke's
/// width along it; nothing changes when the width does not vary.
pub fn apply(spine: &QuerySpine, shapes: &mut [Shape]) {
    if !varies(spine) {
        return;
    }
    let map = Swell::new(spine);
    for s in shapes {
        s.path = map.path(&s.path);
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::brush::query::features;

    /// A straight spine from (0, 0) to (100, 0), width 10, with swell
    /// `k(x)` at each sample.
    fn spine(k: impl Fn(f64) -> f64) -> QuerySpine {
        let pts: Vec<Point> = (0..=50).map(|i| Point::new(i as f64 * 2.0, 0.0)).collect();
        let mut samples = features(&pts, 10.0, 100.0);
        for s in &mut samples {
            s.swell = k(s.pos.x);
        }
        QuerySpine {
            query_id: "q".into(),
            subpath: 0,
            style: None,
            seed: None,
            width: 10.0,
            spacing: 2.0,
            length: 100.0,
            samples,
        }
    }

    /// Against the brute-force nearest point: offsets across a straight
    /// spine scale by the interpolated swell, points beyond an end scale
    /// about it, and a far point still finds its foot.
    #[test]
    fn scales_offsets_by_the_width_there() {
        let sp = spine(|x| 0.5 + x / 100.0);
        let map = Swell::new(&sp);
        let close = |a: Point, b: Point| (a - b).hypot() < 1e-9;
        // Across the spine at x = 31: k = 0.81.
        assert!(close(
            map.point(Point::new(31.0, 6.0)),
            Point::new(31.0, 6.0 * 0.81)
        ));
        assert!(close(
            map.point(Point::new(31.0, -6.0)),
            Point::new(31.0, -6.0 * 0.81)
        ));
        // Beyond the end (100, 0), k = 1.5: about the end point.
        assert!(close(
            map.point(Point::new(104.0, 3.0)),
            Point::new(106.0, 4.5)
        ));
        // Beyond the start, k = 0.5.
        assert!(close(
            map.point(Point::new(-4.0, 2.0)),
            Point::new(-2.0, 1.0)
        ));
        // Far from the spine (past the buckets) it still projects.
        assert!(close(
            map.point(Point::new(50.0, 80.0)),
            Point::new(50.0, 80.0)
        ));
        let brute = |p: Point| {
            let mut best = (f64::MAX, Point::ZERO, 0.0);
            for i in 0..sp.samples.len() - 1 {
                let (d, f, k) = map.on_segment(i, p).unwrap();
                if d < best.0 {
                    best = (d, f, k);
                }
            }
            best.1 + (p - best.1) * best.2
        };
        for i in 0..500u64 {
            let p = Point::new(
                crate::rng::unit(&[7, i, 0]) * 140.0 - 20.0,
                crate::rng::unit(&[7, i, 1]) * 60.0 - 30.0,
            );
            assert!(close(map.point(p), brute(p)), "{p:?}");
        }
    }

    /// A constant width leaves outlines as they are.
    #[test]
    fn a_constant_width_changes_nothing() {
        let sp = spine(|_| 1.0);
        assert!(!varies(&sp));
        let mut path = BezPath::new();
        path.move_to((10.0, 3.0));
        path.curve_to((20.0, 4.0), (30.0, -4.0), (40.0, 2.0));
        let mut shapes = vec![Shape::filled(path.clone(), crate::svg_out::Color::BLACK)];
        apply(&sp, &mut shapes);
        assert_eq!(shapes[0].path, path);
    }
}
