//! Example strokes and element fitting (Barla et al. §2.1).
//!
//! An element is an oriented bounding box fitted to a set of points: the
//! eigenvectors of the points' covariance give the two elongation axes A
//! and B, and projecting the points on them gives the box's extent and
//! centre. The points are either the stroke skeleton (the gesture) or the
//! contour of the painted stroke ([`FitPoints`]).
//!
//! Boxes are treated as solid rectangles by the distance measures: the
//! directed Hausdorff distance from box P to box Q is the largest distance
//! from a corner of P to the solid Q (the distance to a convex set is convex,
//! so its maximum over P is reached at a corner).

use crate::error::{Error, Result};
use crate::read::style::FitPoints;
use crate::read::svg::{affine_of, paint_color, to_bezpath};
use crate::svg_out::{Color, FillRule, LineCap, LineJoin, Shape, Stroke};
use kurbo::{Affine, BezPath, ParamCurve, ParamCurveArclen, Point, Shape as _, Vec2};
use resvg::usvg;
use std::path::Path;

/// Largest number of strokes read from one example.
pub const MAX_EXAMPLE_STROKES: usize = 10_000;

/// One stroke of the example as drawn: its painted shapes and the points
/// its element box is fitted to.
#[derive(Clone, Debug)]
pub struct ExampleStroke {
    /// The shapes to write (fill then stroke, in paint order), in the
    /// reference frame's units.
    pub shapes: Vec<Shape>,
    /// The points the element box is fitted to (skeleton or contour).
    pub points: Vec<Point>,
    /// The stroke's colour as linear-free sRGB in 0..1 per channel.
    pub color: [f64; 3],
    /// How much the colour counts in an element's mean colour (the number
    /// of contour samples, proportional to its painted outline).
    pub weight: f64,
}

impl ExampleStroke {
    /// Applies a transform to geometry and fit points.
    pub fn transform(&mut self, a: Affine) {
        for s in &mut self.shapes {
            s.path.apply_affine(a);
        }
        for p in &mut self.points {
            *p = a * *p;
        }
    }
}

/// An element: a cluster of strokes and its oriented box.
#[derive(Clone, Debug, PartialEq)]
pub struct Element {
    /// Indices of its strokes in the example, in drawing order.
    pub strokes: Vec<usize>,
    /// Box centre, in reference-frame units.
    pub centre: Point,
    /// Unit principal axis A (the direction of largest spread).
    pub axis: Vec2,
    /// Half the box length along A.
    pub half_a: f64,
    /// Half the box length along B (A turned +90°).
    pub half_b: f64,
    /// Mean colour of the strokes, sRGB 0..1.
    pub color: [f64; 3],
}

impl Element {
    /// Fits the box of the strokes `ids` of `strokes` (§2.1).
    pub fn fit(strokes: &[ExampleStroke], ids: Vec<usize>) -> Element {
        let pts = ids.iter().flat_map(|&i| strokes[i].points.iter().copied());
        let (centre, axis, half_a, half_b) = fit_box(pts);
        let mut color = [0.0; 3];
        let mut w = 0.0;
        for &i in &ids {
            let s = &strokes[i];
            for (c, v) in color.iter_mut().zip(s.color) {
                *c += v * s.weight;
            }
            w += s.weight;
        }
        if w > 0.0 {
            for c in &mut color {
                *c /= w;
            }
        }
        Element {
            strokes: ids,
            centre,
            axis,
            half_a,
            half_b,
            color,
        }
    }

    /// The secondary axis B.
    pub fn axis_b(&self) -> Vec2 {
        Vec2::new(-self.axis.y, self.axis.x)
    }

    /// Length of the principal axis |A| (box length).
    pub fn length(&self) -> f64 {
        2.0 * self.half_a
    }

    /// Length of the secondary axis |B| (box thickness).
    pub fn thickness(&self) -> f64 {
        2.0 * self.half_b
    }

    /// Orientation of A in radians, in [0, π).
    pub fn angle(&self) -> f64 {
        self.axis
            .y
            .atan2(self.axis.x)
            .rem_euclid(std::f64::consts::PI)
    }

    /// The four corners of the box.
    pub fn corners(&self) -> [Point; 4] {
        let a = self.axis * self.half_a;
        let b = self.axis_b() * self.half_b;
        let c = self.centre;
        [c - a - b, c + a - b, c + a + b, c - a + b]
    }

    /// Distance from `p` to the solid box (0 inside).
    pub fn distance_to(&self, p: Point) -> f64 {
        let d = p - self.centre;
        let u = (d.dot(self.axis).abs() - self.half_a).max(0.0);
        let v = (d.dot(self.axis_b()).abs() - self.half_b).max(0.0);
        u.hypot(v)
    }
}

/// Directed Hausdorff distance d_H(P, Q) = max over p in P of the distance
/// to Q, between solid boxes, with P moved by `shift` (§2.2.1, §3.1).
pub fn directed_hausdorff(p: &Element, q: &Element, shift: Vec2) -> f64 {
    p.corners()
        .iter()
        .map(|&c| q.distance_to(c + shift))
        .fold(0.0, f64::max)
}

/// Oriented box of a point set: centre, unit principal axis, half extents.
/// The axes are the covariance eigenvectors (§2.1); for a 2×2 symmetric
/// matrix the principal angle is ½·atan2(2c_xy, c_xx − c_yy).
pub fn fit_box(points: impl Iterator<Item = Point> + Clone) -> (Point, Vec2, f64, f64) {
    let mut n = 0.0;
    let mut mean = Vec2::ZERO;
    for p in points.clone() {
        mean += p.to_vec2();
        n += 1.0;
    }
    if n == 0.0 {
        return (Point::ZERO, Vec2::new(1.0, 0.0), 0.0, 0.0);
    }
    mean /= n;
    let (mut cxx, mut cxy, mut cyy) = (0.0, 0.0, 0.0);
    for p in points.clone() {
        let d = p.to_vec2() - mean;
        cxx += d.x * d.x;
        cxy += d.x * d.y;
        cyy += d.y * d.y;
    }
    let theta = 0.5 * (2.0 * cxy).atan2(cxx - cyy);
    let axis = Vec2::new(theta.cos(), theta.sin());
    let b = Vec2::new(-axis.y, axis.x);
    let (mut amin, mut amax, mut bmin, mut bmax) = (f64::MAX, f64::MIN, f64::MAX, f64::MIN);
    for p in points {
        let d = p.to_vec2() - mean;
        let (u, v) = (d.dot(axis), d.dot(b));
        amin = amin.min(u);
        amax = amax.max(u);
        bmin = bmin.min(v);
        bmax = bmax.max(v);
    }
    let centre = (mean + axis * (0.5 * (amin + amax)) + b * (0.5 * (bmin + bmax))).to_point();
    (centre, axis, 0.5 * (amax - amin), 0.5 * (bmax - bmin))
}

/// Samples `path` about every `h` units along its segments (both ends of
/// each segment included), so that fitting weighs the shape, not the
/// density of its control points.
pub fn sample_path(path: &BezPath, h: f64) -> Vec<Point> {
    let mut out = Vec::new();
    for seg in path.segments() {
        let len = seg.arclen(h * 0.05);
        let n = ((len / h).ceil() as usize).clamp(1, 10_000);
        for i in 0..=n {
            out.push(seg.eval(i as f64 / n as f64));
        }
    }
    if out.is_empty() {
        // A lone move-to: a dot drawn as a zero-length path.
        if let Some(kurbo::PathEl::MoveTo(p)) = path.elements().first() {
            out.push(*p);
        }
    }
    out
}

/// Reads the strokes of an example SVG (any visible path with a fill or a
/// stroke; colours and widths kept as drawn). `scale` (ε) sets the
/// sampling step of the fit points.
pub fn load_example(
    path: &Path,
    data: &[u8],
    fit: FitPoints,
    scale: f64,
) -> Result<Vec<ExampleStroke>> {
    let tree = crate::read::svg::parse_svg(data).map_err(|e| e.in_file(path))?;
    let h = (scale / 16.0).max(1e-3);
    let mut strokes = Vec::new();
    collect(tree.root(), fit, h, &mut strokes);
    if strokes.is_empty() {
        return Err(
            Error::invalid("the pattern example has no visible strokes or filled shapes")
                .in_file(path),
        );
    }
    if strokes.len() > MAX_EXAMPLE_STROKES {
        return Err(Error::invalid(format!(
            "the pattern example has {} strokes, more than the limit of {MAX_EXAMPLE_STROKES}",
            strokes.len()
        ))
        .in_file(path));
    }
    Ok(strokes)
}

fn collect(g: &usvg::Group, fit: FitPoints, h: f64, out: &mut Vec<ExampleStroke>) {
    for node in g.children() {
        match node {
            usvg::Node::Group(g) => collect(g, fit, h, out),
            usvg::Node::Path(p) => {
                if !p.is_visible() || p.id() == "spine" {
                    continue;
                }
                if let Some(s) = stroke_of(p, fit, h) {
                    out.push(s);
                }
            }
            _ => {}
        }
    }
}

fn stroke_of(p: &usvg::Path, fit: FitPoints, h: f64) -> Option<ExampleStroke> {
    let abs = p.abs_transform();
    let affine = affine_of(abs);
    let geom = to_bezpath(p.data(), abs);
    if geom.elements().is_empty() {
        return None;
    }
    let scale = affine.determinant().abs().sqrt();
    let mut shapes = Vec::new();
    let mut points = Vec::new();
    let mut color_sum = [0.0; 3];
    let mut weight = 0.0;
    let mut add_color = |c: Color, w: f64| {
        color_sum[0] += c.r as f64 / 255.0 * w;
        color_sum[1] += c.g as f64 / 255.0 * w;
        color_sum[2] += c.b as f64 / 255.0 * w;
        w
    };
    let fill_shape = p.fill().map(|f| {
        let c = paint_color(f.paint());
        let pts = sample_path(&geom, h);
        // The contour of a filled shape is its outline; so is its skeleton
        // as far as a box fit can tell.
        weight += add_color(c, pts.len() as f64);
        points.extend(pts);
        Shape {
            path: geom.clone(),
            fill: Some(c),
            fill_rule: match f.rule() {
                usvg::FillRule::NonZero => FillRule::NonZero,
                usvg::FillRule::EvenOdd => FillRule::EvenOdd,
            },
            stroke: None,
            opacity: f.opacity().get() as f64,
        }
    });
    let stroke_shape = p.stroke().and_then(|s| {
        let width = s.width().get() as f64 * scale;
        if width.is_nan() || width <= 0.0 {
            return None;
        }
        let c = paint_color(s.paint());
        let pts = match fit {
            FitPoints::Skeleton => sample_path(&geom, h),
            FitPoints::Contour => {
                // The painted outline, caps and joins included (tiny-skia's
                // stroker, in the path's own units, then transformed).
                let outline = p
                    .data()
                    .stroke(&s.to_tiny_skia(), 1.0)
                    .map(|o| to_bezpath(&o, abs))
                    .unwrap_or_else(|| geom.clone());
                sample_path(&outline, h)
            }
        };
        weight += add_color(c, pts.len() as f64);
        points.extend(pts);
        Some(Shape {
            path: geom.clone(),
            fill: None,
            fill_rule: FillRule::NonZero,
            stroke: Some(Stroke {
                color: c,
                width,
                cap: match s.linecap() {
                    usvg::LineCap::Butt => LineCap::Butt,
                    usvg::LineCap::Round => LineCap::Round,
                    usvg::LineCap::Square => LineCap::Square,
                },
                join: match s.linejoin() {
                    usvg::LineJoin::Round => LineJoin::Round,
                    usvg::LineJoin::Bevel => LineJoin::Bevel,
                    _ => LineJoin::Miter,
                },
            }),
            opacity: s.opacity().get() as f64,
        })
    });
    let fill_first = !matches!(p.paint_order(), usvg::PaintOrder::StrokeAndFill);
    match (fill_shape, stroke_shape) {
        (Some(f), Some(s)) if fill_first => shapes.extend([f, s]),
        (Some(f), Some(s)) => shapes.extend([s, f]),
        (Some(f), None) => shapes.push(f),
        (None, Some(s)) => shapes.push(s),
        (None, None) => return None,
    }
    if points.is_empty() || weight <= 0.0 {
        return None;
    }
    let color = [
        color_sum[0] / weight,
        color_sum[1] / weight,
        color_sum[2] / weight,
    ];
    // Bounding boxes of degenerate geometry are still finite: guard NaN.
    if !points.iter().all(|p| p.x.is_finite() && p.y.is_finite())
        || !geom.bounding_box().is_finite()
    {
        return None;
    }
    Some(ExampleStroke {
        shapes,
        points,
        color,
        weight,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn box_of_a_tilted_segment() {
        let pts: Vec<Point> = (0..=10).map(|i| Point::new(i as f64, i as f64)).collect();
        let (c, a, ha, hb) = fit_box(pts.iter().copied());
        assert!((c - Point::new(5.0, 5.0)).hypot() < 1e-9);
        assert!((a.x.abs() - a.y.abs()).abs() < 1e-9);
        assert!((ha - 50f64.sqrt()).abs() < 1e-9);
        assert!(hb < 1e-9);
    }

    #[test]
    fn hausdorff_of_nested_boxes_is_zero_one_way() {
        let mk = |ha, hb| Element {
            strokes: vec![],
            centre: Point::ZERO,
            axis: Vec2::new(1.0, 0.0),
            half_a: ha,
            half_b: hb,
            color: [0.0; 3],
        };
        let (big, small) = (mk(10.0, 10.0), mk(2.0, 1.0));
        assert_eq!(directed_hausdorff(&small, &big, Vec2::ZERO), 0.0);
        assert!((directed_hausdorff(&big, &small, Vec2::ZERO) - (8f64.hypot(9.0))).abs() < 1e-9);
    }
}
