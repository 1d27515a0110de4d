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

use super::image::{pixel_coverage, raster_coverage, RasterCoverage};
pub use super::ImageOptions;
use crate::error::{Error, Result};
use crate::io;
use crate::raster::vector::{overlapping, scan_inside, union_boundary, ExactCost, FlatShape};
use crate::raster::Sdf;
use crate::read::svg::{paint_color, to_bezpath};
use crate::svg_out::Color;
use kurbo::Affine;
use rayon::prelude::*;
use resvg::tiny_skia;
use resvg::usvg;
#[cfg(test)]
use std::path::Path;

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
#[cfg(test)]
pub fn load(path: &Path, opts: &ImageOptions) -> Result<Ink> {
    let bytes = io::read_file(path)?;
    read(&bytes, opts).map_err(|e| e.in_file(path))
}

/// Reads raster or SVG bytes (told apart by content) as ink.
#[cfg(test)]
pub fn read(bytes: &[u8], opts: &ImageOptions) -> Result<Ink> {
    if looks_like_svg(bytes) {
        read_svg(bytes, opts)
    } else {
        read_raster(bytes, opts)
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
/// directly (no SDF is built); or, cut out, the regions of a picture's
/// colours.
#[derive(Clone, Debug)]
pub enum Traceable {
    /// Layers with signed distance fields.
    Field(Ink),
    /// A raster's outlines, one layer per ink colour.
    Outline(OutlineInk),
    /// A picture as regions of its colours, the paper's too.
    Regions(RegionInk),
    /// A drawing of lines, to be traced along their centres.
    Lines(LineInk),
}

/// A raster drawing read as one layer of ink coverage, for tracing the
/// centres of its lines ([`crate::trace::centerline`]).
#[derive(Clone, Debug)]
pub struct LineInk {
    /// The ink's coverage (0 paper … 1 ink), one sample per pixel.
    pub coverage: crate::raster::Coverage,
    /// The ink's colour.
    pub color: Color,
    /// Stroke width (px) given by the caller, or `None` to measure each
    /// line's.
    pub stroke_width: Option<f64>,
    /// What was done to the picture on the way (a photo's light evened
    /// out), one line each.
    pub notes: Vec<String>,
}

/// Reads raster bytes as a drawing of lines: all ink as one layer of
/// coverage (the darkest of the colour layers where a picture has
/// several), with a photo's uneven light divided out first. `stroke_width`
/// (px) is kept for the tracer. SVG input is refused: its lines are
/// already vectors.
pub fn read_lines(bytes: &[u8], opts: &ImageOptions, stroke_width: Option<f64>) -> Result<LineInk> {
    if looks_like_svg(bytes) {
        return Err(Error::Invalid(
            "centerline tracing reads a raster drawing (PNG, JPEG, …), not an SVG".into(),
        ));
    }
    if let Some(w) = stroke_width {
        if !(w.is_finite() && w > 0.0 && w <= 1000.0) {
            return Err(Error::Option {
                name: "width",
                reason: format!("{w} px is not in (0, 1000]"),
            });
        }
    }
    let opts = ImageOptions {
        layers: false,
        ..opts.clone()
    };
    let (coverage, lighting) = raster_coverage(bytes, &opts)?;
    let (coverage, color) = match coverage {
        RasterCoverage::Binary { color, bits, .. } => (bits.to_coverage(), color),
        RasterCoverage::Layers { w, h, layers } => {
            let color = layers.last().map_or(Color::BLACK, |l| l.0);
            let mut all = crate::raster::Grid::new(w, h, 0.0f32);
            for (_, cov) in &layers {
                for (a, &c) in all.data_mut().iter_mut().zip(cov.data()) {
                    *a = a.max(c);
                }
            }
            (all, color)
        }
    };
    Ok(LineInk {
        coverage,
        color,
        stroke_width,
        notes: lighting.iter().map(|l| l.note()).collect(),
    })
}

/// A picture read as regions of its colours ([`crate::raster::regions`]).
#[derive(Clone, Debug)]
pub struct RegionInk {
    /// Width in the input's units (pixels for a raster).
    pub width: f64,
    /// Height in the input's units.
    pub height: f64,
    /// The regions, in pixels.
    pub partition: crate::raster::regions::Partition,
    /// Each label's colour, the paper's first.
    pub colours: Vec<Color>,
    /// Maps pixel coordinates to the input's units.
    pub to_user: Affine,
    /// How the picture was read, one line each (for `--verbose`).
    pub notes: Vec<String>,
}

/// Reads raster or SVG bytes as the regions of their colours, for
/// `--layers --cutout`: a raster at its own size, an SVG rendered (as
/// browsers show it) at `opts.resolution` on its longest side.
pub fn read_regions(bytes: &[u8], opts: &ImageOptions) -> Result<RegionInk> {
    opts.validate()?;
    if opts.invert {
        return Err(Error::Option {
            name: "invert",
            reason: "a cut-out traces every colour, the paper's too".into(),
        });
    }
    if looks_like_svg(bytes) {
        let bytes = crate::read::svg::inflate_svgz(bytes)?;
        let tree = crate::read::svg::parse_svg(&bytes)?;
        let size = tree.size();
        let (uw, uh) = (size.width() as f64, size.height() as f64);
        let scale = opts.resolution as f64 / uw.max(uh);
        let (pw, ph) = ((uw * scale).ceil() as u64, (uh * scale).ceil() as u64);
        io::check_canvas(pw.max(1), ph.max(1))?;
        let (pw, ph) = (pw.max(1) as usize, ph.max(1) as usize);
        let mut pixmap = tiny_skia::Pixmap::new(pw as u32, ph as u32)
            .ok_or_else(|| Error::invalid("cannot allocate the render canvas"))?;
        // On white paper, as the drawing shows.
        pixmap.fill(tiny_skia::Color::WHITE);
        let canvas = tiny_skia::Transform::from_scale(scale as f32, scale as f32);
        resvg::render(&tree, canvas, &mut pixmap.as_mut());
        let px = rgba(&pixmap);
        let (partition, colours) = super::image::pixel_partition(&px, pw, ph)?;
        return Ok(RegionInk {
            width: uw,
            height: uh,
            partition,
            colours,
            to_user: Affine::scale(1.0 / scale),
            notes: Vec::new(),
        });
    }
    let (partition, colours, lighting) = super::image::raster_partition(bytes)?;
    Ok(RegionInk {
        width: partition.width() as f64,
        height: partition.height() as f64,
        partition,
        colours,
        to_user: Affine::IDENTITY,
        notes: lighting.iter().map(|l| l.note()).collect(),
    })
}

/// A raster read as the outlines of its ink layers: a binary layer's smooth
/// outline (see [`crate::outline::smooth`]), an anti-aliased layer's sub-pixel
/// outline (see [`crate::raster::sdf::subpixel_outline`]).
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
    /// ([`crate::outline::smooth::smooth_loop`]) and fitted one at a time, in
    /// parallel, by the tracer's `trace_bitmap`, with the corridor
    /// where its edge may lie ([`crate::outline::corridor`]); the smoothed loops
    /// are never all held at once.
    Bitmap(crate::outline::paths::Bitmap),
    /// An anti-aliased layer's sub-pixel outline, known to a fraction of a
    /// pixel, as closed loops in pixel coordinates.
    Loops(Vec<crate::outline::smooth::SmoothLoop>),
}

impl OutlineLayer {
    /// The layer of fractional coverage `cov`: its sub-pixel outline, or
    /// its ink when every value is 0 or 1 (a binary layer of a colour
    /// raster).
    fn coverage(color: Color, cov: &crate::raster::Coverage) -> OutlineLayer {
        let outline = if crate::raster::is_binary(cov) {
            LayerOutline::Bitmap(crate::outline::paths::Bitmap::from_coverage(cov))
        } else {
            LayerOutline::Loops(
                crate::raster::sdf::subpixel_outline(cov)
                    .into_par_iter()
                    .filter(|p| p.len() >= 3)
                    .map(crate::outline::smooth::polygon_loop)
                    .collect(),
            )
        };
        OutlineLayer { color, outline }
    }
}

/// Reads `path` for tracing: like [`load`], except that a raster comes back
/// as the outlines of its layers.
#[cfg(test)]
pub fn load_traceable(path: &Path, opts: &ImageOptions) -> Result<Traceable> {
    let bytes = io::read_file(path)?;
    read_traceable(&bytes, opts).map_err(|e| e.in_file(path))
}

/// Reads raster or SVG bytes for tracing: like `read`, except that a
/// raster comes back as the outlines of its layers.
pub fn read_traceable(bytes: &[u8], opts: &ImageOptions) -> Result<Traceable> {
    if looks_like_svg(bytes) {
        return read_svg(bytes, opts).map(Traceable::Field);
    }
    let (coverage, lighting) = raster_coverage(bytes, opts)?;
    something_to_trace(&coverage)?;
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

/// Refuses a picture with nothing to trace: no ink anywhere (blank
/// paper, a photo of it, or nothing but transparency), or one ink that
/// covers every pixel (a solid image has no shape to outline). Ink is
/// coverage ≥ ½, as the outlines read it.
fn something_to_trace(coverage: &RasterCoverage) -> Result<()> {
    let (pixels, inked, layers) = match coverage {
        RasterCoverage::Binary { w, h, bits, .. } => (w * h, bits.ink_count(), 1),
        RasterCoverage::Layers { w, h, layers } => {
            let inked = layers
                .iter()
                .map(|(_, cov)| cov.data().iter().filter(|&&c| c >= 0.5).count())
                .max()
                .unwrap_or(0);
            (w * h, inked, layers.len())
        }
    };
    if inked == 0 {
        return Err(Error::Invalid(
            "nothing to trace: no ink on the page (blank paper?)".into(),
        ));
    }
    if layers == 1 && inked == pixels {
        return Err(Error::Invalid(
            "nothing to trace: one ink covers the whole picture (a solid image has no shapes)"
                .into(),
        ));
    }
    Ok(())
}

/// Raster bytes (PNG, JPEG, …) read as ink, as `read` reads them.
pub fn read_raster(bytes: &[u8], opts: &ImageOptions) -> Result<Ink> {
    Ok(coverage_ink(
        raster_coverage(bytes, opts)?.0,
        Affine::IDENTITY,
    ))
}

/// Each layer's SDF: a binary layer's from its smooth outline, others
/// from their anti-aliased coverage; `to_user` maps pixels to the
/// input's units (the identity for raster files).
fn coverage_ink(coverage: RasterCoverage, to_user: Affine) -> Ink {
    let (w, h, layers) = match coverage {
        RasterCoverage::Binary { w, h, color, bits } => (
            w,
            h,
            vec![InkLayer {
                color,
                sdf: crate::outline::smooth::bitmap_sdf(&bits, to_user),
            }],
        ),
        RasterCoverage::Layers { w, h, layers } => (
            w,
            h,
            layers
                .into_iter()
                .map(|(color, cov)| InkLayer {
                    color,
                    sdf: Sdf::from_coverage(&cov, to_user),
                })
                .collect(),
        ),
    };
    Ink {
        width: w as f64,
        height: h as f64,
        layers,
        warnings: Vec::new(),
        notes: Vec::new(),
    }
}

/// One filled shape of an SVG, in pixel coordinates.
struct SvgShape {
    color: Color,
    /// The tiny-skia path and the transform placing it on the pixel canvas.
    path: tiny_skia::Path,
    transform: tiny_skia::Transform,
    rule: tiny_skia::FillRule,
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
                            color: paint_color(fill.paint()),
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
                                color: paint_color(stroke.paint()),
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
    tree: &usvg::Tree,
    opts: &ImageOptions,
    skip_id: Option<&str>,
    (pw, ph): (usize, usize),
    canvas: tiny_skia::Transform,
    to_user: Affine,
) -> Result<Ink> {
    let mut pixmap = tiny_skia::Pixmap::new(pw as u32, ph as u32)
        .ok_or_else(|| Error::invalid("cannot allocate the render canvas"))?;
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
    let px = rgba(&pixmap);
    let size = tree.size();
    Ok(Ink {
        width: size.width() as f64,
        height: size.height() as f64,
        ..coverage_ink(pixel_coverage(&px, pw, ph, opts), to_user)
    })
}

/// One layer's flattened shapes, with the shapes overlapping each
/// ([`overlapping`]).
struct LayerShapes<'a> {
    color: Color,
    members: Vec<&'a FlatShape>,
    others: Vec<Vec<usize>>,
}

fn read_svg(bytes: &[u8], opts: &ImageOptions) -> Result<Ink> {
    // Inflated once for both the tree and the text check.
    let bytes = crate::read::svg::inflate_svgz(bytes)?;
    let tree = crate::read::svg::parse_svg(&bytes)?;
    let mut ink = svg_ink(&tree, opts, None)?;
    ink.warnings
        .extend(crate::read::svg::text_left_out(&bytes).map(String::from));
    Ok(ink)
}

/// The ink of a parsed SVG `tree` as `read` reads SVG; paths whose `id` is `skip_id` are left out
/// (a brush exemplar's hand-drawn `id="spine"` is not ink).
pub fn svg_ink(tree: &usvg::Tree, opts: &ImageOptions, skip_id: Option<&str>) -> Result<Ink> {
    let size = tree.size();
    let (uw, uh) = (size.width() as f64, size.height() as f64);
    opts.validate()?;
    let scale = opts.resolution as f64 / uw.max(uh);
    let (pw, ph) = ((uw * scale).ceil() as u64, (uh * scale).ceil() as u64);
    io::check_canvas(pw.max(1), ph.max(1))?;
    let (pw, ph) = (pw.max(1) as usize, ph.max(1) as usize);
    svg_ink_on(tree, opts, skip_id, (pw, ph), (scale, scale))
}

/// The ink of a parsed SVG `tree` as [`svg_ink`] reads it, on a `size`
/// px canvas at `scale` px per user unit in x and y (so that a seamless
/// tile can fill whole pixels exactly: its pixel grid then ends where its
/// repeat does). The caller checks the canvas size.
pub fn svg_ink_on(
    tree: &usvg::Tree,
    opts: &ImageOptions,
    skip_id: Option<&str>,
    (pw, ph): (usize, usize),
    (sx, sy): (f64, f64),
) -> Result<Ink> {
    let size = tree.size();
    let (uw, uh) = (size.width() as f64, size.height() as f64);
    let canvas = tiny_skia::Transform::from_scale(sx as f32, sy as f32);
    let to_user = Affine::scale_non_uniform(1.0 / sx, 1.0 / sy);
    if needs_render(tree.root()) {
        return rendered_ink(tree, opts, skip_id, (pw, ph), canvas, to_user);
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
    let flat: Vec<FlatShape> = shapes
        .iter()
        .map(|s| {
            FlatShape::new(
                &to_bezpath(&s.path, s.transform),
                s.rule == tiny_skia::FillRule::EvenOdd,
                pw,
                ph,
            )
        })
        .collect();
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
        let mut ink = rendered_ink(tree, opts, skip_id, (pw, ph), canvas, to_user)?;
        ink.notes.push(format!(
            "outlines too dense for exact distances ({} segments cross {} rows of pixels); read from the anti-aliased render",
            flat.iter().map(|f| f.segments.len()).sum::<usize>(),
            cost.row_crossings
        ));
        return Ok(ink);
    }
    let mut layers = Vec::new();
    let mut notes = Vec::new();
    let gradients = gradient_fills(tree.root());
    if gradients > 0 {
        notes.push(format!(
            "{gradients} gradient fill(s) read as the mean colour of their stops"
        ));
    }
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
        notes,
    })
}

/// The visible fills and strokes of `group` painted with a gradient.
fn gradient_fills(group: &usvg::Group) -> usize {
    let grad = |p: &usvg::Paint| {
        matches!(
            p,
            usvg::Paint::LinearGradient(_) | usvg::Paint::RadialGradient(_)
        )
    };
    group
        .children()
        .iter()
        .map(|n| match n {
            usvg::Node::Group(g) => gradient_fills(g),
            usvg::Node::Path(p) if p.is_visible() => {
                usize::from(p.fill().is_some_and(|f| grad(f.paint())))
                    + usize::from(p.stroke().is_some_and(|s| grad(s.paint())))
            }
            _ => 0,
        })
        .sum()
}

/// The pixels of a rendered pixmap as straight (not premultiplied) RGBA.
fn rgba(pixmap: &tiny_skia::Pixmap) -> Vec<[u8; 4]> {
    pixmap
        .pixels()
        .iter()
        .map(|p| {
            let c = p.demultiply();
            [c.red(), c.green(), c.blue(), c.alpha()]
        })
        .collect()
}
