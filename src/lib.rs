//! # flourish
//!
//! Decorative SVGs from rough sketches, by example, and a bitmap-to-Bézier
//! tracer. Every mode has one call shape: read the input, load a style,
//! call the mode with its options, get an [`Output`] (the document and what
//! to tell the user about it).
//!
//! | mode | input | style | call |
//! |---|---|---|---|
//! | ornament along open paths (DecoBrush) | [`Sketch`] | brush | [`brush()`] |
//! | art patterns inside closed shapes (level sets) | [`Sketch`] | fill | [`fill()`] |
//! | hand-drawn elements along paths and in shapes | [`Sketch`] | pattern | [`pattern()`] |
//! | bitmaps and SVGs to Bézier outlines | [`Image`] | — | [`trace()`] |
//! | a whole mixed sketch, the rest kept | [`Sketch`] | any, per shape | [`decorate()`] |
//!
//! Options carry values with documented defaults; each has a `validate()`
//! that checks every range. Errors are one [`Error`] enum; functions that
//! read bytes leave naming the file to their caller ([`Error::in_file`]).
//!
//! ```no_run
//! # fn main() -> flourish::Result<()> {
//! use flourish::{Library, Sketch, StyleOptions, FillOptions};
//!
//! let style = Library::shipped().load("knot", &StyleOptions::default())?;
//! let sketch = Sketch::from_svg(&std::fs::read("shapes.svg").unwrap())?;
//! let out = flourish::fill(&sketch, &style, &FillOptions::default())?;
//! std::fs::write("knot.svg", out.to_svg()).unwrap();
//! # Ok(())
//! # }
//! ```
//!
//! The raster modes meet in one type, a grid of signed distances per ink
//! layer (negative inside, in pixels) that the tracer turns into cubic
//! Béziers; `ARCHITECTURE.md` has the stage graph.

#![forbid(unsafe_code)]
#![warn(missing_docs)]

mod brush;
mod diff;
mod error;
mod field;
mod fill;
#[cfg(test)]
mod gallery;
pub mod io;
mod library;
pub mod memory;
mod outline;
mod pattern;
mod raster;
mod read;
mod render;
mod rng;
mod svg_out;
mod trace;

pub use brush::analysis::check::StyleReport;
pub use brush::analysis::init::InitReport;
pub use brush::{BrushOptions, Refinement, MAX_ITERATIONS};
pub use diff::DiffReport;
pub use error::{Error, Result};
pub use fill::FillOptions;
pub use io::Cancel;
pub use library::{Library, Style, StyleEntry, StyleOptions, Styles, STYLES_ENV};
pub use pattern::PatternOptions;
pub use read::sketch::{Query, QueryKind, Sketch};
pub use read::style::StyleKind;
pub use read::ImageOptions;
pub use svg_out::{Color, Document, FillRule, Group, LineCap, LineJoin, Output, Shape, Stroke};
pub use trace::TraceOptions;

use std::collections::BTreeMap;
use std::path::Path;

/// Grows ornament of a brush style along every open stroked path of
/// `sketch` (DecoBrush, decobrush.txt §5–7): piecewise matching of
/// exemplar segments, ARAP warping, graph-cut seams, hierarchical
/// synthesis, traced to one `<g>` per query. Shapes' `data-style` names
/// are not used by this mode.
///
/// ```no_run
/// # fn main() -> flourish::Result<()> {
/// use flourish::{BrushOptions, Library, Sketch, StyleOptions};
///
/// let vine = Library::shipped().load("vine", &StyleOptions::default())?;
/// let sketch = Sketch::from_svg(br#"<svg xmlns="http://www.w3.org/2000/svg"
///     width="400" height="200"><path d="M20 150 C120 20 280 180 380 50"
///     fill="none" stroke="black" stroke-width="24"/></svg>"#)?;
/// let out = flourish::brush(&sketch, &vine, &BrushOptions::default())?;
/// assert!(!out.document.groups.is_empty());
/// # Ok(())
/// # }
/// ```
pub fn brush<'a>(
    sketch: &Sketch,
    styles: impl Into<Styles<'a>>,
    opts: &BrushOptions,
) -> Result<Output> {
    let style = styles.into().default_style().brush()?;
    io::set_stage(format!("brush: {}", count(sketch, "stroke", true)));
    in_px(sketch, 1.0, |sk| brush::run(style, sk, opts)).map(finish)
}

/// Fills every filled shape of `sketch` with an art pattern synthesized
/// from a fill style's tile (Wu et al., art-pattern-level-sets.txt §2–3,
/// with the direction field of Brushables §3): open paths inside a shape
/// comb the pattern's direction. One `<g>` per shape.
///
/// ```no_run
/// # fn main() -> flourish::Result<()> {
/// use flourish::{FillOptions, Library, Sketch, StyleOptions};
///
/// let scales = Library::shipped().load("scales", &StyleOptions::default())?;
/// let sketch = Sketch::from_svg(br#"<svg xmlns="http://www.w3.org/2000/svg"
///     width="200" height="200"><circle cx="100" cy="100" r="80"
///     fill="black"/></svg>"#)?;
/// let out = flourish::fill(&sketch, &scales, &FillOptions::default())?;
/// assert_eq!(out.document.groups.len(), 1);
/// # Ok(())
/// # }
/// ```
pub fn fill<'a>(
    sketch: &Sketch,
    styles: impl Into<Styles<'a>>,
    opts: &FillOptions,
) -> Result<Output> {
    let styles = styles.into();
    opts.validate()?;
    io::set_stage(format!("fill: {}", count(sketch, "region", false)));
    // A direction sketch overlays the sketch: the same units.
    let k = sketch.px_per_unit() / opts.scale;
    let scaled;
    let opts = if (k - 1.0).abs() > 1e-9 && opts.direction.is_some() {
        scaled = FillOptions {
            direction: opts.direction.as_ref().map(|d| d.scaled(k)),
            ..opts.clone()
        };
        &scaled
    } else {
        opts
    };
    let out = in_px(sketch, opts.scale, |sk| {
        let out = fill::fill_document(
            sk,
            |q| {
                let s = styles.of(q)?;
                Ok((s.name(), s.fill()?))
            },
            opts,
        )?;
        Ok(Output {
            document: out.to_document(),
            warnings: out.warnings,
            notes: out.notes,
        })
    })?;
    Ok(finish(out))
}

/// Arranges the hand-drawn elements of a pattern style along every
/// stroked path and inside every filled shape of `sketch` (Barla et al.,
/// stroke-pattern-synthesis.txt §2–3): each element an exact rigid copy of
/// one in the example. One `<g>` per query.
///
/// ```no_run
/// # fn main() -> flourish::Result<()> {
/// use flourish::{Library, PatternOptions, Sketch, StyleOptions};
///
/// let stipple = Library::shipped().load("stipple", &StyleOptions::default())?;
/// let sketch = Sketch::from_svg(br#"<svg xmlns="http://www.w3.org/2000/svg"
///     width="300" height="100"><path d="M10 50 H290" fill="none"
///     stroke="black" stroke-width="30"/></svg>"#)?;
/// let out = flourish::pattern(&sketch, &stipple, &PatternOptions::default())?;
/// assert!(!out.document.groups[0].shapes.is_empty());
/// # Ok(())
/// # }
/// ```
pub fn pattern<'a>(
    sketch: &Sketch,
    styles: impl Into<Styles<'a>>,
    opts: &PatternOptions,
) -> Result<Output> {
    let styles = styles.into();
    opts.validate()?;
    io::set_stage(format!("pattern: {} shapes", sketch.queries.len()));
    let out = in_px(sketch, opts.scale, |sk| {
        let out = pattern::synthesize_sketch(sk, |q| Ok(styles.of(q)?.pattern()?.clone()), opts)?;
        let document = out.to_document();
        Ok(Output {
            warnings: out.warnings,
            ..Output::new(document)
        })
    })?;
    Ok(finish(out))
}

/// The styles of a whole-sketch decoration ([`decorate()`]): a shape's
/// `data-style` names its style in `named`; other stroked paths take
/// `strokes` and other filled shapes `regions`. A shape with no style is
/// kept as drawn.
#[derive(Clone, Copy, Debug)]
pub struct Decoration<'a> {
    /// Style of stroked paths without `data-style`: brush or pattern.
    pub strokes: Option<&'a Style>,
    /// Style of filled shapes without `data-style`: fill or pattern.
    pub regions: Option<&'a Style>,
    /// The styles shapes name, by name ([`Library::load_every_named`]).
    pub named: &'a BTreeMap<String, Style>,
}

impl Decoration<'_> {
    /// Checks that `strokes` is a brush or pattern style and `regions` a
    /// fill or pattern style.
    pub fn validate(&self) -> Result<()> {
        for (name, style, wrong, takes) in [
            (
                "strokes",
                self.strokes,
                StyleKind::Fill,
                "a brush or pattern style",
            ),
            (
                "regions",
                self.regions,
                StyleKind::Brush,
                "a fill or pattern style",
            ),
        ] {
            if let Some(s) = style.filter(|s| s.kind() == wrong) {
                return Err(Error::Option {
                    name,
                    reason: format!(
                        "{} is a {} style; {name} take {takes}",
                        s.name(),
                        wrong.name()
                    ),
                });
            }
        }
        Ok(())
    }
}

/// Options of the modes a decoration runs, each with its own defaults.
#[derive(Clone, Debug, Default)]
pub struct DecorateOptions {
    /// For shapes decorated with a brush style.
    pub brush: BrushOptions,
    /// For shapes decorated with a fill style.
    pub fill: FillOptions,
    /// For shapes decorated with a pattern style.
    pub pattern: PatternOptions,
}

impl DecorateOptions {
    /// Checks every mode's options.
    pub fn validate(&self) -> Result<()> {
        self.brush.validate()?;
        self.fill.validate()?;
        self.pattern.validate()
    }
}

/// Decorates a whole sketch in one go: each stroked path and filled shape
/// with its style (by `data-style`, else the defaults of `styles`), by the
/// mode of that style's kind, and the ornament laid over the sketch in
/// place of the shapes it decorates, so text, images and undecorated
/// shapes stay where they are in drawing order. Open paths that no style
/// decorates still comb the direction of fill patterns around them.
/// A brush style on a filled shape, or a fill style on a stroked path,
/// leaves the shape as drawn, with a warning.
///
/// ```no_run
/// # fn main() -> flourish::Result<()> {
/// use flourish::{Decoration, DecorateOptions, Library, Sketch, StyleOptions};
///
/// let lib = Library::shipped();
/// let vine = lib.load("vine", &StyleOptions::default())?;
/// let knot = lib.load("knot", &StyleOptions::default())?;
/// let sketch = Sketch::from_svg(&std::fs::read("card.svg").unwrap())?;
/// let named = lib.load_every_named(&sketch, &StyleOptions::default())?;
/// let styles = Decoration { strokes: Some(&vine), regions: Some(&knot), named: &named };
/// let out = flourish::decorate(&sketch, styles, &DecorateOptions::default())?;
/// std::fs::write("card-decorated.svg", out.to_svg()).unwrap();
/// # Ok(())
/// # }
/// ```
pub fn decorate(sketch: &Sketch, styles: Decoration, opts: &DecorateOptions) -> Result<Output> {
    opts.validate()?;
    styles.validate()?;
    let mut warnings = Vec::new();
    // The styles in the order they first appear, and each query's.
    let mut runs: Vec<&Style> = Vec::new();
    let mut run_of: Vec<Option<usize>> = vec![None; sketch.queries.len()];
    for (i, q) in sketch.queries.iter().enumerate() {
        let style = match &q.style {
            Some(name) => Some(styles.named.get(name).ok_or_else(|| {
                Error::invalid(format!("data-style \"{name}\" was not loaded")).in_part(&q.id)
            })?),
            None => match q.kind {
                QueryKind::Path { .. } => styles.strokes,
                QueryKind::Region { .. } => styles.regions,
            },
        };
        let Some(style) = style else { continue };
        let fits = match (style.kind(), &q.kind) {
            (StyleKind::Brush, QueryKind::Region { .. }) => Some("strokes"),
            (StyleKind::Fill, QueryKind::Path { .. }) => Some("filled shapes"),
            _ => None,
        };
        if let Some(what) = fits {
            warnings.push(format!(
                "{}: style {} decorates {what} only; the shape is kept as drawn",
                q.id,
                style.name()
            ));
            continue;
        }
        run_of[i] = Some(match runs.iter().position(|s| std::ptr::eq(*s, style)) {
            Some(r) => r,
            None => {
                runs.push(style);
                runs.len() - 1
            }
        });
    }
    let mut notes = Vec::new();
    let mut groups: BTreeMap<String, std::collections::VecDeque<Group>> = BTreeMap::new();
    let mut decimals = 0;
    for (r, style) in runs.iter().enumerate() {
        let mut part = sketch.clone();
        part.notes.clear();
        part.warnings.clear();
        part.text_left_out = None;
        part.queries = sketch
            .queries
            .iter()
            .enumerate()
            .filter(|(i, q)| match run_of[*i] {
                Some(own) => own == r,
                None => style.kind() == StyleKind::Fill && matches!(q.kind, QueryKind::Path { .. }),
            })
            .map(|(_, q)| Query {
                style: None,
                ..q.clone()
            })
            .collect();
        let out = match style.kind() {
            StyleKind::Brush => brush(&part, *style, &opts.brush)?,
            StyleKind::Fill => fill(&part, *style, &opts.fill)?,
            StyleKind::Pattern => pattern(&part, *style, &opts.pattern)?,
        };
        warnings.extend(out.warnings);
        notes.extend(out.notes);
        decimals = decimals.max(out.document.decimals);
        for g in out.document.groups {
            groups.entry(g.id.clone()).or_default().push_back(g);
        }
    }
    let mut document = Document::new(sketch.width, sketch.height, decimals.max(2));
    document.view_box = sketch.view_box;
    document.groups = sketch
        .queries
        .iter()
        .filter_map(|q| groups.get_mut(&q.id)?.pop_front())
        .collect();
    let out = Output {
        document,
        warnings,
        notes,
    };
    Ok(out.over(sketch))
}

impl Output {
    /// This output laid over the sketch it was made from: each group in
    /// place of the shape it decorates (its query's element), and every
    /// other element of the sketch kept in drawing order. A sketch made in
    /// code has no text to keep: the output is unchanged.
    pub fn over(mut self, sketch: &Sketch) -> Output {
        if sketch.backdrop.is_some() {
            self.warnings
                .retain(|w| Some(w.as_str()) != sketch.text_left_out);
        }
        self.document.backdrop = sketch.backdrop.clone();
        self
    }
}

/// A picture to trace: a raster (PNG, JPEG, BMP, GIF, TIFF, WebP) or an
/// SVG, read as layers of ink.
#[derive(Clone, Debug)]
pub struct Image {
    picture: read::ink::Traceable,
}

impl Image {
    /// Reads raster or SVG bytes (told apart by their content) as ink.
    pub fn from_bytes(bytes: &[u8], opts: &ImageOptions) -> Result<Image> {
        io::set_stage("reading the picture");
        Ok(Image {
            picture: read::ink::read_traceable(bytes, opts)?,
        })
    }

    /// Reads raster or SVG bytes as the regions of their colours, the
    /// paper's too, for a cut-out trace (`--layers --cutout`): [`trace()`]
    /// then makes each region a closed shape of its own colour, and
    /// neighbouring regions share exactly the same boundary curves, so
    /// they cover the picture with no gap and no overlap. A raster is read
    /// at its own size, an SVG rendered at `opts.resolution`; `opts.invert`
    /// is refused.
    pub fn regions_from_bytes(bytes: &[u8], opts: &ImageOptions) -> Result<Image> {
        Ok(Image {
            picture: read::ink::Traceable::Regions(read::ink::read_regions(bytes, opts)?),
        })
    }
}

impl Image {
    /// Reads a raster drawing of lines (pen or pencil, scanned or
    /// photographed) for centerline tracing: [`trace()`] then gives open
    /// stroked paths along the lines' centres, `stroke-width` each line's
    /// measured width or `stroke_width` px when given.
    pub fn lines_from_bytes(
        bytes: &[u8],
        opts: &ImageOptions,
        stroke_width: Option<f64>,
    ) -> Result<Image> {
        io::set_stage("reading the picture");
        Ok(Image {
            picture: read::ink::Traceable::Lines(read::ink::read_lines(bytes, opts, stroke_width)?),
        })
    }
}

/// Whether `bytes` look like SVG (or SVGZ) text rather than a raster.
pub fn looks_like_svg(bytes: &[u8]) -> bool {
    read::ink::looks_like_svg(bytes)
}

/// Reads a raster drawing (PNG, JPEG, …; a pen or pencil drawing, scanned
/// or photographed) as a sketch: its lines traced along their centres
/// ([`Image::lines_from_bytes`]) become open stroked path queries,
/// `stroke_width` px wide when given, else as wide as their lines scaled
/// up together until the median line is a 24th of the page's shorter side
/// (so the ornament shows at the page's size; see
/// `read::sketch::DRAWN_WIDTH_SHARE`). A drawing with no lines (blank
/// paper) is an error.
pub fn sketch_from_drawing(bytes: &[u8], stroke_width: Option<f64>) -> Result<Sketch> {
    let ink = read::ink::read_lines(bytes, &ImageOptions::default(), stroke_width)?;
    let opts = TraceOptions::default();
    let strokes = trace::centerline::trace_lines(
        &ink.coverage,
        ink.stroke_width,
        opts.tolerance,
        opts.min_area,
    );
    if strokes.is_empty() {
        return Err(Error::Invalid(
            "no lines found in the drawing (blank paper?)".into(),
        ));
    }
    let (w, h) = (ink.coverage.width() as f64, ink.coverage.height() as f64);
    let mut sketch = Sketch::from_strokes(
        w,
        h,
        strokes.into_iter().map(|s| (s.path, s.width)).collect(),
    );
    sketch.notes = ink.notes;
    if stroke_width.is_none() {
        if let Some((from, to)) = sketch.widen_drawn_lines() {
            sketch.notes.push(format!(
                "lines widened for the ornament: median {from:.1} px to {to:.1} px \
                 (a 24th of the page's shorter side; --width sets every line's width)"
            ));
        }
    }
    Ok(sketch)
}

/// Traces a picture's ink into compact filled Bézier outlines, one
/// `<g id="layer-N">` per ink layer: a raster's outline is smoothed as
/// potrace reads a bitmap (Selinger 2003) or read to a fraction of a pixel
/// from its anti-aliasing, an SVG's from the exact distance to its shapes,
/// and fitted with the fewest cubics within `opts.tolerance`.
///
/// ```
/// # fn main() -> flourish::Result<()> {
/// use flourish::{Image, ImageOptions, TraceOptions};
///
/// let svg = br#"<svg xmlns="http://www.w3.org/2000/svg" width="64" height="64">
///     <circle cx="32" cy="32" r="20"/></svg>"#;
/// let image = Image::from_bytes(svg, &ImageOptions::default())?;
/// let out = flourish::trace(&image, &TraceOptions::default())?;
/// assert_eq!(out.document.groups.len(), 1);
/// # Ok(())
/// # }
/// ```
pub fn trace(image: &Image, opts: &TraceOptions) -> Result<Output> {
    io::set_stage("tracing");
    trace::trace(&image.picture, opts).map(finish)
}

/// "N strokes" (`paths`) or "N regions" of `sketch`, for a stage line.
fn count(sketch: &Sketch, what: &str, paths: bool) -> String {
    let n = sketch
        .queries
        .iter()
        .filter(|q| matches!(q.kind, QueryKind::Path { .. }) == paths)
        .count();
    format!("{n} {what}{}", if n == 1 { "" } else { "s" })
}

/// Runs a mode on `sketch` in CSS pixels: a sketch drawn in millimetres
/// or points is scaled to pixels first and the output scaled back, so
/// styles (whose sizes are pixels) give the same drawing whatever the
/// sketch's units; and `scale` times smaller, so the style's pattern comes
/// out `scale` times larger.
fn in_px(
    sketch: &Sketch,
    scale: f64,
    run: impl FnOnce(&Sketch) -> Result<Output>,
) -> Result<Output> {
    let k = sketch.px_per_unit() / scale;
    let mut out = if (k - 1.0).abs() <= 1e-9 {
        run(sketch)?
    } else {
        let mut out = run(&sketch.scaled(k))?;
        out.document = out.document.rescaled(1.0 / k, sketch.view_box);
        out
    };
    out.warnings.extend(sketch.text_left_out.map(String::from));
    Ok(out)
}

/// A mode's output made safe to render: past [`svg_out::MAX_ELEMENTS`]
/// paths, the shapes of a group painted alike are merged, with a note.
fn finish(mut out: Output) -> Output {
    if let Some(note) = out.document.merge_past_limit() {
        out.notes.push(note);
    }
    out
}

/// Reads a folder of exemplar drawings (SVG or raster) for `flourish
/// style init`: each one's main branch ends found (the farthest pair
/// along the edge-tangent-flow geodesic), at `resolution` px (default
/// 256). [`InitReport::to_toml`] is the library's `style.toml`.
pub fn init_style(dir: &Path, resolution: Option<u32>) -> Result<InitReport> {
    brush::analysis::init::init(dir, resolution)
}

/// Analyses a style for `flourish style check`: for a brush style a
/// report per exemplar (spine, widths, thin lines) with warnings where the
/// library will not brush well; for a fill style each swatch's size,
/// repeat and colour layers with their coverage; for a pattern style its
/// elements, arrangement and spacing.
pub fn check_style(style: &Style) -> Result<StyleReport> {
    Ok(match style.kind() {
        StyleKind::Brush => brush::analysis::check::check(
            style.brush()?,
            &brush::analysis::check::CheckOptions::default(),
        ),
        StyleKind::Fill => StyleReport::summary(style.name(), "fill", fill::check(style.fill()?)),
        StyleKind::Pattern => {
            StyleReport::summary(style.name(), "pattern", pattern::check(style.pattern()?))
        }
    })
}

/// A brush style's diagnostics sheet as PNG bytes: per exemplar its ink,
/// stroke region, ribs, orientation field and spine.
pub fn style_sheet(style: &Style) -> Result<Vec<u8>> {
    brush::analysis::check::sheet_png(style.brush()?)
}

/// SVG text rendered on white as PNG bytes (documents under 512 px are
/// enlarged to 512 px): the `--preview` of every command.
pub fn preview_png(svg: &str) -> Result<Vec<u8>> {
    io::set_stage("rendering the preview");
    render::preview_png(svg)
}

/// Compares two SVG files by rendering them at the same size (the
/// expected one's, longest side 1024 px) and counting the pixels that
/// differ; errors name the file.
pub fn diff(expected: &Path, actual: &Path) -> Result<DiffReport> {
    diff::diff_files(expected, actual)
}
