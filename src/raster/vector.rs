//! Vector outlines on the pixel grid: what the exact SDF of a drawing
//! ([`crate::raster::Sdf::from_segments`]) is built from.
//!
//! Shapes are flattened to segments ([`flatten_segments`]), curves far off
//! the canvas first becoming chords ([`cull_far_curves`]), so a huge shape
//! costs what its visible part costs. Pixel centres inside the union of a
//! layer's shapes come from exact scanline crossings ([`scan_inside`]); the
//! union's boundary keeps the segment pieces with ink on one side only
//! ([`union_boundary`], winding numbers read band by band). What both cost
//! is counted before either is done ([`ExactCost`]).

use crate::raster::Grid;
use kurbo::{BezPath, Line, PathEl, Point, Rect};

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

/// The line segments of `path` flattened to within `tolerance`, with open
/// subpaths closed (fills close them implicitly).
pub fn flatten_segments(path: &BezPath, tolerance: f64, out: &mut Vec<Line>) {
    let mut start = None;
    let mut last = Point::ZERO;
    kurbo::flatten(path, tolerance, |el| match el {
        PathEl::MoveTo(p) => {
            if let Some(s) = start {
                if last != s {
                    out.push(Line::new(last, s));
                }
            }
            start = Some(p);
            last = p;
        }
        PathEl::LineTo(p) => {
            out.push(Line::new(last, p));
            last = p;
        }
        PathEl::ClosePath => {
            if let Some(s) = start {
                if last != s {
                    out.push(Line::new(last, s));
                }
                last = s;
            }
        }
        _ => {}
    });
    if let Some(s) = start {
        if last != s {
            out.push(Line::new(last, s));
        }
    }
}

/// A shape flattened to line segments in pixel space, with its fill rule.
pub(crate) struct FlatShape {
    /// The outline's segments, closed loops, px.
    pub(crate) segments: Vec<Line>,
    even_odd: bool,
    bbox: kurbo::Rect,
    /// The segments by horizontal band, for [`FlatShape::winding`]; `None`
    /// for few segments or when banding would not help.
    bands: Option<Bands>,
}

/// A shape's segments sorted into horizontal bands of its bounding box: a
/// segment is listed in every band its y-range touches, so the segments
/// crossing a row `y` are all in the band of `y`. Reading only that band
/// keeps a winding number from costing every segment of the shape: with
/// one winding number per segment, that cost grows with the square of the
/// segments, which a long stroked polyline makes minutes.
struct Bands {
    /// Top of the first band, px.
    y0: f64,
    /// Height of a band, px.
    height: f64,
    /// Segment indices per band, top to bottom.
    bands: Vec<Vec<u32>>,
}

impl Bands {
    /// Fewest segments for which a shape is banded.
    const MIN_SEGMENTS: usize = 64;

    /// The bands of `segments` within `bbox`; `None` when there are few
    /// segments, the box is not finite, or the segments are so tall that
    /// the bands would list each of them many times over.
    fn new(segments: &[Line], bbox: kurbo::Rect) -> Option<Bands> {
        let (y0, y1) = (bbox.y0, bbox.y1);
        if segments.len() < Self::MIN_SEGMENTS || !(y0.is_finite() && y1.is_finite() && y1 > y0) {
            return None;
        }
        let n = (segments.len() / 4).clamp(1, 4096);
        let height = (y1 - y0) / n as f64;
        if !(height > 0.0 && height.is_finite()) {
            return None;
        }
        let mut bands = Bands {
            y0,
            height,
            bands: vec![Vec::new(); n],
        };
        let mut listed = 0usize;
        for (i, l) in segments.iter().enumerate() {
            let (a, b) = (l.p0.y.min(l.p1.y), l.p0.y.max(l.p1.y));
            // A segment with a NaN never counts in a winding number.
            if a.is_nan() || b.is_nan() {
                continue;
            }
            let (ka, kb) = (bands.band(a), bands.band(b));
            listed += kb + 1 - ka;
            if listed > 16 * segments.len() {
                return None;
            }
            for k in ka..=kb {
                bands.bands[k].push(i as u32);
            }
        }
        Some(bands)
    }

    /// The band of row `y` (monotone in `y`; clamped to the bands).
    fn band(&self, y: f64) -> usize {
        let k = ((y - self.y0) / self.height).floor();
        if k.is_nan() || k < 0.0 {
            0
        } else {
            (k as usize).min(self.bands.len() - 1)
        }
    }
}

impl FlatShape {
    /// Flattens `outline` (px, with its fill rule) for a canvas of
    /// `width` × `height` px: curves far outside it become chords
    /// ([`cull_far_curves`]).
    pub(crate) fn new(outline: &BezPath, even_odd: bool, width: usize, height: usize) -> Self {
        let side = width.max(height) as f64;
        let window = kurbo::Rect::new(0.0, 0.0, width as f64, height as f64).inflate(side, side);
        let mut segments = Vec::new();
        flatten_segments(&cull_far_curves(outline, window), FLATTEN_PX, &mut segments);
        FlatShape::from_segments(segments, even_odd)
    }

    /// The shape bounded by `segments` (closed loops, px), banded.
    fn from_segments(segments: Vec<Line>, even_odd: bool) -> Self {
        let mut bbox = kurbo::Rect::new(f64::MAX, f64::MAX, f64::MIN, f64::MIN);
        for l in &segments {
            bbox = bbox.union_pt(l.p0).union_pt(l.p1);
        }
        let bands = Bands::new(&segments, bbox);
        FlatShape {
            segments,
            even_odd,
            bbox,
            bands,
        }
    }

    /// Winding number of the outline around `p` (crossings of a ray to +x).
    /// Only segments whose y-range holds `p.y` can cross the ray: with
    /// [`Bands`], only those of `p`'s band are read (the same sum).
    fn winding(&self, p: Point) -> i32 {
        let crossing = |l: &Line| -> i32 {
            let (a, b) = (l.p0, l.p1);
            if (a.y <= p.y) != (b.y <= p.y) {
                let x = a.x + (p.y - a.y) / (b.y - a.y) * (b.x - a.x);
                if x > p.x {
                    return if b.y > a.y { 1 } else { -1 };
                }
            }
            0
        };
        match &self.bands {
            // No segment crosses a row outside the box (or a NaN row).
            Some(_) if !(p.y >= self.bbox.y0 && p.y <= self.bbox.y1) => 0,
            Some(b) => b.bands[b.band(p.y)]
                .iter()
                .filter_map(|&i| self.segments.get(i as usize))
                .map(crossing)
                .sum(),
            None => self.segments.iter().map(crossing).sum(),
        }
    }

    /// How many segments [`FlatShape::winding`] reads at row `y`.
    fn band_len(&self, y: f64) -> u64 {
        match &self.bands {
            Some(b) => b.bands[b.band(y)].len() as u64,
            None => self.segments.len() as u64,
        }
    }

    /// How many segments a winding number reads on average over the rows
    /// (the mean band length; all segments when unbanded).
    fn mean_band_len(&self) -> u64 {
        match &self.bands {
            Some(b) => {
                let listed: usize = b.bands.iter().map(Vec::len).sum();
                (listed / b.bands.len().max(1)) as u64 + 1
            }
            None => self.segments.len() as u64,
        }
    }

    fn contains(&self, p: Point) -> bool {
        if !self.bbox.contains(p) {
            return false;
        }
        let w = self.winding(p);
        if self.even_odd {
            w % 2 != 0
        } else {
            w != 0
        }
    }
}

/// Flattening tolerance for SVG outlines, in pixels.
const FLATTEN_PX: f64 = 0.01;

/// Pixel centres inside the union of `shapes`, by exact scanline crossing
/// counts with each shape's own fill rule.
pub(crate) fn scan_inside(w: usize, h: usize, shapes: &[&FlatShape]) -> Grid<bool> {
    let mut grid = Grid::new(w, h, false);
    for shape in shapes {
        super::scan::fill(
            &mut grid,
            shape.segments.iter().map(|l| (l.p0, l.p1)),
            shape.even_odd,
        );
    }
    grid
}

/// For each of `shapes`, the others whose boxes meet its box (ascending):
/// the shapes that can bury its edges. A sweep over the boxes sorted by
/// their left sides compares only boxes whose x-ranges meet, not every
/// pair, so many scattered small shapes cost about what they hold.
pub(crate) fn overlapping(shapes: &[&FlatShape]) -> Vec<Vec<usize>> {
    let meet = |a: kurbo::Rect, b: kurbo::Rect| a.intersect(b).area() >= 0.0 && overlaps(a, b);
    let mut order: Vec<usize> = (0..shapes.len()).collect();
    order.sort_by(|&i, &j| shapes[i].bbox.x0.total_cmp(&shapes[j].bbox.x0));
    let mut out: Vec<Vec<usize>> = vec![Vec::new(); shapes.len()];
    for (k, &i) in order.iter().enumerate() {
        let a = shapes[i].bbox;
        // Boxes to the right start at or after `a`'s left side; past its
        // right side none meets it (nor does any later one).
        for &j in &order[k + 1..] {
            let b = shapes[j].bbox;
            // (A NaN side meets nothing.)
            use std::cmp::Ordering::{Equal, Less};
            if !matches!(b.x0.partial_cmp(&a.x1), Some(Less | Equal)) {
                break;
            }
            if meet(a, b) {
                out[i].push(j);
                out[j].push(i);
            }
        }
    }
    for list in &mut out {
        list.sort_unstable();
    }
    out
}

/// The parts of the shapes' outlines that bound their union: a segment piece
/// whose two sides are both inside (an edge of one shape buried in another,
/// or in itself) or both outside is dropped. `others` lists, per shape, the
/// shapes that overlap it ([`overlapping`]).
pub(crate) fn union_boundary(shapes: &[&FlatShape], others: &[Vec<usize>]) -> Vec<Line> {
    use rayon::prelude::*;
    shapes
        .par_iter()
        .zip(others)
        .flat_map_iter(|(shape, others)| {
            let others: Vec<&FlatShape> = others.iter().map(|&j| shapes[j]).collect();
            let lonely = others.is_empty();
            shape.segments.iter().filter_map(move |l| {
                let d = l.p1 - l.p0;
                let len = d.hypot();
                if len <= 0.0 {
                    return None;
                }
                let m = l.p0.midpoint(l.p1);
                let nrm = kurbo::Vec2::new(-d.y, d.x) / len * 0.05;
                if lonely && !shape.even_odd {
                    // A lone nonzero shape: only self-overlaps can bury edges.
                    let (a, b) = (shape.winding(m + nrm), shape.winding(m - nrm));
                    return ((a == 0) != (b == 0)).then_some(*l);
                }
                let side = |p: Point| shape.contains(p) || others.iter().any(|o| o.contains(p));
                (side(m + nrm) != side(m - nrm)).then_some(*l)
            })
        })
        .collect()
}

/// Most segment reads the exact union boundary may take ([`ExactCost`]):
/// a few seconds on one core. Past it, a drawing's outlines cross so densely
/// (a scribble of thousands of strokes over the whole canvas, where every
/// row meets every segment) that the winding numbers would take minutes.
const MAX_WINDING_READS: u64 = 600_000_000;

/// Most row crossings the exact scanline fill may hold (16 bytes each, so
/// about 320 MB).
const MAX_ROW_CROSSINGS: u64 = 20_000_000;

/// What reading a layer's shapes exactly costs: the segments the union
/// boundary's winding numbers read, and the row crossings of the scanline
/// fill. Counted from the bands, before any of it is done.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub(crate) struct ExactCost {
    winding_reads: u64,
    /// Row crossings of the scanline fill.
    pub(crate) row_crossings: u64,
}

impl ExactCost {
    /// The cost of [`scan_inside`] and [`union_boundary`] on `shapes`
    /// (with their `others`) on a canvas `h` px tall.
    pub(crate) fn of(shapes: &[&FlatShape], others: &[Vec<usize>], h: usize) -> ExactCost {
        let mut cost = ExactCost::default();
        let means: Vec<u64> = shapes.iter().map(|s| s.mean_band_len()).collect();
        for (shape, others) in shapes.iter().zip(others) {
            let rest: u64 = others.iter().map(|&j| means[j]).sum();
            for l in &shape.segments {
                let (lo, hi) = (l.p0.y.min(l.p1.y), l.p0.y.max(l.p1.y));
                if lo < hi {
                    let r0 = (lo - 0.5).ceil().clamp(0.0, h as f64);
                    let r1 = (hi - 0.5).ceil().clamp(0.0, h as f64);
                    cost.row_crossings += (r1 - r0) as u64;
                }
                // Two probes per segment, each reading its band of this
                // shape and of every overlapping one.
                let m = l.p0.midpoint(l.p1);
                let own = shape.band_len(m.y);
                cost.winding_reads = cost.winding_reads.saturating_add(2 * (own + rest));
            }
        }
        cost
    }

    /// The cost of both (saturating).
    pub(crate) fn plus(self, other: ExactCost) -> ExactCost {
        ExactCost {
            winding_reads: self.winding_reads.saturating_add(other.winding_reads),
            row_crossings: self.row_crossings.saturating_add(other.row_crossings),
        }
    }

    /// Within [`MAX_WINDING_READS`] and [`MAX_ROW_CROSSINGS`].
    pub(crate) fn affordable(self) -> bool {
        self.winding_reads <= MAX_WINDING_READS && self.row_crossings <= MAX_ROW_CROSSINGS
    }
}

fn overlaps(a: kurbo::Rect, b: kurbo::Rect) -> bool {
    a.x0 <= b.x1 && b.x0 <= a.x1 && a.y0 <= b.y1 && b.y0 <= a.y1
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::raster::vector::flatten_segments;
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

#[cfg(test)]
mod exact_tests {
    use super::*;

    fn polygon(pts: &[(f64, f64)]) -> Vec<Line> {
        (0..pts.len())
            .map(|i| {
                let (a, b) = (pts[i], pts[(i + 1) % pts.len()]);
                Line::new(a, b)
            })
            .collect()
    }

    fn cost(shapes: &[FlatShape], h: usize) -> ExactCost {
        let refs: Vec<&FlatShape> = shapes.iter().collect();
        ExactCost::of(&refs, &overlapping(&refs), h)
    }

    #[test]
    fn exact_cost_of_a_square_counts_its_probes_and_rows() {
        let sq = polygon(&[(2.25, 2.25), (12.25, 2.25), (12.25, 12.25), (2.25, 12.25)]);
        let c = cost(&[FlatShape::from_segments(sq, false)], 20);
        // Unbanded: 4 segments, two probes each, each reading all 4.
        assert_eq!(c.winding_reads, 32);
        // Each side edge crosses the rows with centres 2.5 ..= 11.5.
        assert_eq!(c.row_crossings, 20);
        // Rows off the canvas are not crossed.
        assert_eq!(
            cost(
                &[FlatShape::from_segments(
                    polygon(&[(2.25, 2.25), (12.25, 2.25), (12.25, 12.25), (2.25, 12.25)]),
                    false
                )],
                5
            )
            .row_crossings,
            6
        );
    }

    #[test]
    fn exact_cost_grows_with_the_square_of_segments_crossing_the_same_rows() {
        // A zigzag whose every segment spans the whole height: banding
        // cannot help, each probe reads every segment.
        let zigzag = |n: usize| {
            let mut pts: Vec<(f64, f64)> = (0..n)
                .map(|i| (i as f64, if i % 2 == 0 { 0.0 } else { 100.0 }))
                .collect();
            pts.push((n as f64, 200.0));
            FlatShape::from_segments(polygon(&pts), false)
        };
        let (small, large) = (cost(&[zigzag(200)], 200), cost(&[zigzag(400)], 200));
        assert_eq!(small.winding_reads, 2 * 201 * 201);
        assert_eq!(large.winding_reads, 2 * 401 * 401);
        assert!(small.affordable());
        let huge = cost(&[zigzag(20_000)], 200);
        assert!(!huge.affordable(), "{huge:?}");
        // A tall shape of many short segments is banded: far fewer reads.
        let circle: Vec<(f64, f64)> = (0..20_000)
            .map(|i| {
                let a = i as f64 / 20_000.0 * std::f64::consts::TAU;
                (500.0 + 400.0 * a.cos(), 500.0 + 400.0 * a.sin())
            })
            .collect();
        let round = cost(&[FlatShape::from_segments(polygon(&circle), false)], 1000);
        assert!(round.winding_reads < 2 * 20_000 * 100, "{round:?}");
        assert!(round.affordable());
    }

    /// The sweep finds exactly the pairs of meeting boxes that comparing
    /// every pair finds.
    #[test]
    fn overlapping_boxes_are_found_by_the_sweep() {
        let mut state = 0x9e37_79b9_7f4a_7c15u64;
        let mut next = || {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            (state >> 11) as f64 / (1u64 << 53) as f64
        };
        let mut shapes: Vec<FlatShape> = (0..300)
            .map(|_| {
                let (x, y) = (100.0 * next(), 100.0 * next());
                let (w, h) = (8.0 * next(), 8.0 * next());
                FlatShape::from_segments(
                    polygon(&[(x, y), (x + w, y), (x + w, y + h), (x, y + h)]),
                    false,
                )
            })
            .collect();
        // Touching edges meet; a shape with no segments meets nothing.
        shapes.push(FlatShape::from_segments(
            polygon(&[(200.0, 0.0), (210.0, 0.0), (210.0, 5.0), (200.0, 5.0)]),
            false,
        ));
        shapes.push(FlatShape::from_segments(
            polygon(&[(210.0, 5.0), (220.0, 5.0), (220.0, 9.0), (210.0, 9.0)]),
            false,
        ));
        shapes.push(FlatShape::from_segments(Vec::new(), false));
        let refs: Vec<&FlatShape> = shapes.iter().collect();
        let brute: Vec<Vec<usize>> = (0..refs.len())
            .map(|i| {
                (0..refs.len())
                    .filter(|&j| {
                        let (a, b) = (refs[i].bbox, refs[j].bbox);
                        j != i && a.intersect(b).area() >= 0.0 && overlaps(a, b)
                    })
                    .collect()
            })
            .collect();
        let swept = overlapping(&refs);
        assert_eq!(swept, brute);
        assert!(swept.iter().map(Vec::len).sum::<usize>() > 100);
        assert_eq!(swept[300], vec![301]);
        assert!(swept[302].is_empty());
    }

    #[test]
    fn exact_cost_counts_the_overlapping_shapes_each_probe_reads() {
        let sq = |x: f64| {
            FlatShape::from_segments(
                polygon(&[(x, 0.0), (x + 10.0, 0.0), (x + 10.0, 10.0), (x, 10.0)]),
                false,
            )
        };
        // Apart: each probe reads its own 4 segments.
        assert_eq!(cost(&[sq(0.0), sq(20.0)], 10).winding_reads, 2 * 32);
        // Overlapping: each probe also reads the other's 4.
        assert_eq!(cost(&[sq(0.0), sq(5.0)], 10).winding_reads, 2 * 64);
    }
}
