//! Loading `trace` inputs as layers of ink, each a signed distance field.
//!
//! * Raster files (through `image`): ink coverage is the alpha channel when
//!   the image has transparency, else the darkness `1 − luminance`;
//!   anti-aliased edges are kept as fractional coverage and turned into a
//!   sub-pixel SDF ([`Sdf::from_coverage`]).
//! * SVG files (through usvg): rasterized so the longest side is
//!   `resolution` px; inside/outside is sampled at pixel centres and the
//!   SDF is the exact distance to the vector outline
//!   ([`Sdf::from_segments`]). Strokes count as ink (converted to fills).
//!
//! With `layers`, each distinct fill colour (SVG) or quantized colour
//! (raster) is its own layer; layers are stacked bottom to top and each one
//! extends under the layers above it, so stacked fills leave no seams.

pub use super::decode::decode_raster;
use super::decode::{pixel_coverage, raster_coverage, RasterCoverage};
use super::{Grid, Sdf};
use crate::error::{Error, Result};
use crate::io;
use crate::svg_out::Color;
use kurbo::{Affine, BezPath, Line, PathEl, Point};
use rayon::prelude::*;
use resvg::tiny_skia;
use resvg::usvg;
use std::path::Path;

/// How inputs are read.
#[derive(Clone, Debug)]
pub struct InputOptions {
    /// Longest side in pixels at which SVG input is rasterized (default
    /// 1024). Raster input is used at its own size.
    pub resolution: u32,
    /// Trace the paper instead of the ink.
    pub invert: bool,
    /// One layer per fill colour instead of one layer of all ink.
    pub layers: bool,
}

impl Default for InputOptions {
    fn default() -> Self {
        InputOptions {
            resolution: 1024,
            invert: false,
            layers: false,
        }
    }
}

/// One layer of ink.
#[derive(Clone, Debug)]
pub struct InkLayer {
    /// The layer's colour.
    pub color: Color,
    /// Its signed distance field.
    pub sdf: Sdf,
}

/// An input read as ink: its size in its own user units and its layers,
/// bottom first.
#[derive(Clone, Debug)]
pub struct Ink {
    /// Width in user units (pixels for raster input).
    pub width: f64,
    /// Height in user units.
    pub height: f64,
    /// Layers, bottom first.
    pub layers: Vec<InkLayer>,
    /// What the input held that is not ink here, one line each.
    pub warnings: Vec<String>,
    /// How the input was read, where it matters (for `--verbose`), one
    /// line each.
    pub notes: Vec<String>,
}

/// Reads `path` (raster or SVG, told apart by content) as ink.
pub fn load(path: &Path, opts: &InputOptions) -> Result<Ink> {
    let bytes = io::read_file(path)?;
    if looks_like_svg(&bytes) {
        load_svg(path, &bytes, opts)
    } else {
        load_raster(path, &bytes, opts)
    }
}

/// Whether `bytes` look like SVG (text starting with `<`, or gzip: SVGZ).
pub fn looks_like_svg(bytes: &[u8]) -> bool {
    let head = &bytes[..bytes.len().min(512)];
    let text = String::from_utf8_lossy(head);
    let t = text.trim_start_matches('\u{feff}').trim_start();
    t.starts_with('<') || bytes.starts_with(&[0x1f, 0x8b])
}

/// What `flourish trace` reads from a file: for SVG input, layers of ink
/// with an SDF each; for a raster, the outline of each layer's ink, fitted
/// directly (no SDF is built).
#[derive(Clone, Debug)]
pub enum Traceable {
    /// Layers with signed distance fields.
    Field(Ink),
    /// A raster's outlines, one layer per ink colour.
    Outline(OutlineInk),
}

/// A raster read as the outlines of its ink layers: a binary layer's smooth
/// outline (see [`super::binary`]), an anti-aliased layer's sub-pixel
/// outline (see [`super::sdf::subpixel_outline`]).
#[derive(Clone, Debug)]
pub struct OutlineInk {
    /// Width in pixels.
    pub width: f64,
    /// Height in pixels.
    pub height: f64,
    /// The layers, bottom first.
    pub layers: Vec<OutlineLayer>,
    /// What was done to the picture on the way (a photo's light evened
    /// out), one line each.
    pub notes: Vec<String>,
}

/// One ink layer of an [`OutlineInk`].
#[derive(Clone, Debug)]
pub struct OutlineLayer {
    /// The ink's colour.
    pub color: Color,
    /// What the layer's outline is read from.
    pub outline: LayerOutline,
}

/// What an [`OutlineLayer`]'s outline is read from.
#[derive(Clone, Debug)]
pub enum LayerOutline {
    /// A binary layer's ink. Its paths are smoothed
    /// ([`super::binary::smooth_loop`]) and fitted one at a time, in
    /// parallel, by [`crate::trace::trace_bitmap`], with the corridor
    /// where its edge may lie ([`super::corridor`]); the smoothed loops
    /// are never all held at once.
    Bitmap(super::paths::Bitmap),
    /// An anti-aliased layer's sub-pixel outline, known to a fraction of a
    /// pixel, as closed loops in pixel coordinates.
    Loops(Vec<super::binary::SmoothLoop>),
}

impl OutlineLayer {
    /// The layer of fractional coverage `cov`: its sub-pixel outline, or
    /// its ink when every value is 0 or 1 (a binary layer of a colour
    /// raster).
    fn coverage(color: Color, cov: &super::Coverage) -> OutlineLayer {
        let outline = if super::binary::is_binary(cov) {
            LayerOutline::Bitmap(super::paths::Bitmap::from_coverage(cov))
        } else {
            LayerOutline::Loops(
                super::sdf::subpixel_outline(cov)
                    .into_par_iter()
                    .filter(|p| p.len() >= 3)
                    .map(super::binary::polygon_loop)
                    .collect(),
            )
        };
        OutlineLayer { color, outline }
    }
}

/// Reads `path` for tracing: like [`load`], except that a raster comes back
/// as the outlines of its layers.
pub fn load_traceable(path: &Path, opts: &InputOptions) -> Result<Traceable> {
    let bytes = io::read_file(path)?;
    if looks_like_svg(&bytes) {
        return load_svg(path, &bytes, opts).map(Traceable::Field);
    }
    let (coverage, lighting) = raster_coverage(path, &bytes, opts)?;
    let (w, h, layers) = match coverage {
        RasterCoverage::Binary { w, h, color, bits } => (
            w,
            h,
            vec![OutlineLayer {
                color,
                outline: LayerOutline::Bitmap(bits),
            }],
        ),
        RasterCoverage::Layers { w, h, layers } => (
            w,
            h,
            layers
                .par_iter()
                .map(|(color, cov)| OutlineLayer::coverage(*color, cov))
                .collect(),
        ),
    };
    Ok(Traceable::Outline(OutlineInk {
        width: w as f64,
        height: h as f64,
        layers,
        notes: lighting.iter().map(|l| l.note()).collect(),
    }))
}

/// Raster bytes (PNG, JPEG, …) read from `path` as ink, as [`load`] reads them.
pub fn load_raster(path: &Path, bytes: &[u8], opts: &InputOptions) -> Result<Ink> {
    Ok(raster_coverage(path, bytes, opts)?
        .0
        .into_ink(Affine::IDENTITY))
}

/// One filled shape of an SVG, in pixel coordinates.
struct SvgShape {
    color: Color,
    /// The tiny-skia path and the transform placing it on the pixel canvas.
    path: tiny_skia::Path,
    transform: tiny_skia::Transform,
    rule: tiny_skia::FillRule,
}

fn paint_colour(paint: &usvg::Paint) -> Color {
    let c = match paint {
        usvg::Paint::Color(c) => *c,
        usvg::Paint::LinearGradient(g) => g
            .stops()
            .first()
            .map(|s| s.color())
            .unwrap_or(usvg::Color::black()),
        usvg::Paint::RadialGradient(g) => g
            .stops()
            .first()
            .map(|s| s.color())
            .unwrap_or(usvg::Color::black()),
        usvg::Paint::Pattern(_) => usvg::Color::black(),
    };
    Color::rgb(c.red, c.green, c.blue)
}

fn collect_shapes(
    group: &usvg::Group,
    canvas: tiny_skia::Transform,
    skip_id: Option<&str>,
    out: &mut Vec<SvgShape>,
) {
    for node in group.children() {
        match node {
            usvg::Node::Group(g) => collect_shapes(g, canvas, skip_id, out),
            usvg::Node::Path(p) if skip_id.is_some_and(|id| p.id() == id) => {}
            usvg::Node::Path(p) if p.is_visible() => {
                let transform = p.abs_transform().post_concat(canvas);
                if let Some(fill) = p.fill() {
                    if fill.opacity().get() > 0.0 {
                        let rule = match fill.rule() {
                            usvg::FillRule::NonZero => tiny_skia::FillRule::Winding,
                            usvg::FillRule::EvenOdd => tiny_skia::FillRule::EvenOdd,
                        };
                        out.push(SvgShape {
                            color: paint_colour(fill.paint()),
                            path: p.data().clone(),
                            transform,
                            rule,
                        });
                    }
                }
                if let Some(stroke) = p.stroke() {
                    if stroke.opacity().get() > 0.0 {
                        let res = transform
                            .get_scale()
                            .0
                            .max(transform.get_scale().1)
                            .max(1e-3);
                        if let Some(outline) = p.data().stroke(&stroke.to_tiny_skia(), res) {
                            out.push(SvgShape {
                                color: paint_colour(stroke.paint()),
                                path: outline,
                                transform,
                                rule: tiny_skia::FillRule::Winding,
                            });
                        }
                    }
                }
            }
            _ => {}
        }
    }
}

/// Whether drawing `group` takes more than filling and stroking its paths:
/// a clip path, a mask or a filter on it or anywhere below it. The exact
/// outline route reads fills and strokes only, so such a drawing is
/// rendered instead ([`rendered_ink`]).
fn needs_render(group: &usvg::Group) -> bool {
    group.clip_path().is_some()
        || group.mask().is_some()
        || !group.filters().is_empty()
        || group.children().iter().any(|n| match n {
            usvg::Node::Group(g) => needs_render(g),
            _ => false,
        })
}

/// The ink of an SVG drawn with clip paths, masks or filters: the drawing
/// rendered (resvg, anti-aliased) on a `size` canvas with `canvas` placing
/// it, and read as a transparent raster is (alpha as coverage, colour
/// layers with `--layers`); `to_user` maps the canvas back to the SVG's
/// units. With `skip_id`, the top-level nodes are rendered one by one and
/// the one with that id is left out.
fn rendered_ink(
    path: &Path,
    tree: &usvg::Tree,
    opts: &InputOptions,
    skip_id: Option<&str>,
    (pw, ph): (usize, usize),
    canvas: tiny_skia::Transform,
    to_user: Affine,
) -> Result<Ink> {
    let mut pixmap = tiny_skia::Pixmap::new(pw as u32, ph as u32)
        .ok_or_else(|| Error::invalid(path, "cannot allocate the render canvas"))?;
    match skip_id {
        None => resvg::render(tree, canvas, &mut pixmap.as_mut()),
        Some(id) => {
            for node in tree.root().children().iter().filter(|n| n.id() != id) {
                // `render_node` draws a node at its layer box's origin.
                if let Some(b) = node.abs_layer_bounding_box() {
                    let at = canvas.pre_translate(b.x(), b.y());
                    let _ = resvg::render_node(node, at, &mut pixmap.as_mut());
                }
            }
        }
    }
    let px: Vec<[u8; 4]> = pixmap
        .pixels()
        .iter()
        .map(|p| {
            let c = p.demultiply();
            [c.red(), c.green(), c.blue(), c.alpha()]
        })
        .collect();
    let size = tree.size();
    Ok(Ink {
        width: size.width() as f64,
        height: size.height() as f64,
        ..pixel_coverage(&px, pw, ph, opts).into_ink(to_user)
    })
}

/// A tiny-skia path as a kurbo path with `transform` applied.
pub fn to_kurbo(path: &tiny_skia::Path, transform: tiny_skia::Transform) -> BezPath {
    let t = transform;
    let affine = Affine::new([
        t.sx as f64,
        t.ky as f64,
        t.kx as f64,
        t.sy as f64,
        t.tx as f64,
        t.ty as f64,
    ]);
    let pt = |p: tiny_skia::Point| Point::new(p.x as f64, p.y as f64);
    let mut out = BezPath::new();
    for seg in path.segments() {
        match seg {
            tiny_skia::PathSegment::MoveTo(p) => out.move_to(pt(p)),
            tiny_skia::PathSegment::LineTo(p) => out.line_to(pt(p)),
            tiny_skia::PathSegment::QuadTo(a, b) => out.quad_to(pt(a), pt(b)),
            tiny_skia::PathSegment::CubicTo(a, b, c) => out.curve_to(pt(a), pt(b), pt(c)),
            tiny_skia::PathSegment::Close => out.close_path(),
        }
    }
    affine * out
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
struct FlatShape {
    segments: Vec<Line>,
    even_odd: bool,
    bbox: kurbo::Rect,
    /// The segments by horizontal band, for [`FlatShape::winding`]; `None`
    /// for few segments or when banding would not help.
    bands: Option<Bands>,
}

/// A shape's segments sorted into horizontal bands of its bounding box: a
/// segment is listed in every band its y-range touches, so the segments
/// crossing a row `y` are all in the band of `y`. Reading only that band
/// keeps a winding number from costing every segment of the shape (with
/// one winding number per segment, a 40 000-segment stroked polyline took
/// half a minute to trace, quadratically longer as it grew).
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
    /// Flattens `shape` for a canvas of `width` × `height` px: curves far
    /// outside it become chords ([`super::cull::cull_far_curves`]).
    fn new(shape: &SvgShape, width: usize, height: usize) -> Self {
        let side = width.max(height) as f64;
        let window = kurbo::Rect::new(0.0, 0.0, width as f64, height as f64).inflate(side, side);
        let mut segments = Vec::new();
        flatten_segments(
            &super::cull::cull_far_curves(&to_kurbo(&shape.path, shape.transform), window),
            FLATTEN_PX,
            &mut segments,
        );
        FlatShape::from_segments(segments, shape.rule == tiny_skia::FillRule::EvenOdd)
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
fn scan_inside(w: usize, h: usize, shapes: &[&FlatShape]) -> Grid<bool> {
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
/// their left sides compares only boxes whose x-ranges meet (50 000
/// scattered dots: 7 M pairs, not 2.5 G).
fn overlapping(shapes: &[&FlatShape]) -> Vec<Vec<usize>> {
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
fn union_boundary(shapes: &[&FlatShape], others: &[Vec<usize>]) -> Vec<Line> {
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

/// One layer's flattened shapes, with the shapes overlapping each
/// ([`overlapping`]).
struct LayerShapes<'a> {
    color: Color,
    members: Vec<&'a FlatShape>,
    others: Vec<Vec<usize>>,
}

/// Most segment reads the exact union boundary may take ([`ExactCost`]):
/// about 2 s on one core. Past it, a drawing's outlines cross so densely
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
struct ExactCost {
    winding_reads: u64,
    row_crossings: u64,
}

impl ExactCost {
    /// The cost of [`scan_inside`] and [`union_boundary`] on `shapes`
    /// (with their `others`) on a canvas `h` px tall.
    fn of(shapes: &[&FlatShape], others: &[Vec<usize>], h: usize) -> ExactCost {
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
    fn plus(self, other: ExactCost) -> ExactCost {
        ExactCost {
            winding_reads: self.winding_reads.saturating_add(other.winding_reads),
            row_crossings: self.row_crossings.saturating_add(other.row_crossings),
        }
    }

    fn affordable(self) -> bool {
        self.winding_reads <= MAX_WINDING_READS && self.row_crossings <= MAX_ROW_CROSSINGS
    }
}

fn overlaps(a: kurbo::Rect, b: kurbo::Rect) -> bool {
    a.x0 <= b.x1 && b.x0 <= a.x1 && a.y0 <= b.y1 && b.y0 <= a.y1
}

fn load_svg(path: &Path, bytes: &[u8], opts: &InputOptions) -> Result<Ink> {
    // Inflated once for both the tree and the text check.
    let bytes = io::inflate_svgz(path, bytes)?;
    let tree = io::parse_svg(path, &bytes)?;
    let mut ink = svg_ink(path, &tree, opts, None)?;
    ink.warnings
        .extend(io::text_left_out(&bytes).map(String::from));
    Ok(ink)
}

/// The ink of a parsed SVG `tree` (read from `path`, named in errors) as
/// [`load`] reads SVG files; paths whose `id` is `skip_id` are left out
/// (a brush exemplar's hand-drawn `id="spine"` is not ink).
pub fn svg_ink(
    path: &Path,
    tree: &usvg::Tree,
    opts: &InputOptions,
    skip_id: Option<&str>,
) -> Result<Ink> {
    let size = tree.size();
    let (uw, uh) = (size.width() as f64, size.height() as f64);
    if opts.resolution == 0 {
        return Err(Error::Option {
            name: "--resolution",
            reason: "must be at least 1 px".into(),
        });
    }
    let scale = opts.resolution as f64 / uw.max(uh);
    let (pw, ph) = ((uw * scale).ceil() as u64, (uh * scale).ceil() as u64);
    io::check_canvas(path, pw.max(1), ph.max(1))?;
    let (pw, ph) = (pw.max(1) as usize, ph.max(1) as usize);
    let canvas = tiny_skia::Transform::from_scale(scale as f32, scale as f32);
    let to_user = Affine::scale(1.0 / scale);
    if needs_render(tree.root()) {
        return rendered_ink(path, tree, opts, skip_id, (pw, ph), canvas, to_user);
    }
    let mut shapes = Vec::new();
    collect_shapes(tree.root(), canvas, skip_id, &mut shapes);
    // Colours in order of first appearance: the stacking order.
    let mut colours: Vec<Color> = Vec::new();
    for s in &shapes {
        if !colours.contains(&s.color) {
            colours.push(s.color);
        }
    }
    // Each layer's shapes, as indices into `shapes`.
    let layer_sets: Vec<(Color, Vec<usize>)> = if opts.layers && !opts.invert {
        (0..colours.len())
            .map(|k| {
                let above = &colours[k..];
                (
                    colours[k],
                    (0..shapes.len())
                        .filter(|&i| above.contains(&shapes[i].color))
                        .collect(),
                )
            })
            .collect()
    } else if shapes.is_empty() && !opts.invert {
        Vec::new()
    } else {
        let colour = if colours.len() == 1 && !opts.invert {
            colours[0]
        } else {
            Color::BLACK
        };
        vec![(colour, (0..shapes.len()).collect())]
    };
    // Each shape flattened once, then grouped by layer.
    let flat: Vec<FlatShape> = shapes.iter().map(|s| FlatShape::new(s, pw, ph)).collect();
    let sets: Vec<LayerShapes> = layer_sets
        .into_iter()
        .map(|(color, set)| {
            let members: Vec<&FlatShape> = set.iter().map(|&k| &flat[k]).collect();
            let others = overlapping(&members);
            LayerShapes {
                color,
                members,
                others,
            }
        })
        .collect();
    let cost = sets.iter().fold(ExactCost::default(), |acc, set| {
        acc.plus(ExactCost::of(&set.members, &set.others, ph))
    });
    if !cost.affordable() {
        // Too dense to measure exactly: read the drawing's render, as a
        // raster's anti-aliased coverage is read.
        let mut ink = rendered_ink(path, tree, opts, skip_id, (pw, ph), canvas, to_user)?;
        ink.notes.push(format!(
            "outlines too dense for exact distances ({} segments cross {} rows of pixels); read from the anti-aliased render",
            flat.iter().map(|f| f.segments.len()).sum::<usize>(),
            cost.row_crossings
        ));
        return Ok(ink);
    }
    let mut layers = Vec::new();
    for LayerShapes {
        color,
        members,
        others,
    } in sets
    {
        let mut inside = scan_inside(pw, ph, &members);
        if opts.invert {
            inside = inside.map(|i| !i);
        }
        let segments = union_boundary(&members, &others);
        layers.push(InkLayer {
            color,
            sdf: Sdf::from_segments(&inside, &segments, to_user),
        });
    }
    Ok(Ink {
        width: uw,
        height: uh,
        layers,
        warnings: Vec::new(),
        notes: Vec::new(),
    })
}

#[cfg(test)]
mod tests {
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
