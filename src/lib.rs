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
pub use library::{Library, Style, StyleEntry, StyleOptions, Styles, STYLES_ENV};
pub use pattern::PatternOptions;
pub use read::sketch::{Query, QueryKind, Sketch};
pub use read::style::StyleKind;
pub use read::ImageOptions;
pub use svg_out::{Color, Document, FillRule, Group, LineCap, LineJoin, Output, Shape, Stroke};
pub use trace::TraceOptions;

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
    in_px(sketch, |sk| brush::run(style, sk, opts)).map(finish)
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
    // A direction sketch overlays the sketch: the same units.
    let k = sketch.px_per_unit();
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
    let out = in_px(sketch, |sk| {
        let out = fill::fill_sketch(
            sk,
            |q| {
                let s = styles.of(q)?;
                Ok((s.name(), s.fill()?))
            },
            opts,
        )?;
        Ok(Output {
            document: out.to_document(),
            warnings: Vec::new(),
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
    let out = in_px(sketch, |sk| {
        let out = pattern::synthesize_sketch(sk, |q| Ok(styles.of(q)?.pattern()?.clone()), opts)?;
        Ok(Output::new(out.to_document()))
    })?;
    Ok(finish(out))
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
        Ok(Image {
            picture: read::ink::read_traceable(bytes, opts)?,
        })
    }
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
    trace::trace(&image.picture, opts).map(finish)
}

/// Runs a mode on `sketch` in CSS pixels: a sketch drawn in millimetres
/// or points is scaled to pixels first and the output scaled back, so
/// styles (whose sizes are pixels) give the same drawing whatever the
/// sketch's units.
fn in_px(sketch: &Sketch, run: impl FnOnce(&Sketch) -> Result<Output>) -> Result<Output> {
    let k = sketch.px_per_unit();
    if (k - 1.0).abs() <= 1e-9 {
        return run(sketch);
    }
    let mut out = run(&sketch.scaled(k))?;
    out.document = out.document.rescaled(1.0 / k, sketch.view_box);
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

/// Analyses a brush style for `flourish style check`: a report per
/// exemplar (spine, widths, thin lines) with warnings where the library
/// will not brush well.
pub fn check_style(style: &Style) -> Result<StyleReport> {
    Ok(brush::analysis::check::check(
        style.brush()?,
        &brush::analysis::check::CheckOptions::default(),
    ))
}

/// A brush style's diagnostics sheet as PNG bytes: per exemplar its ink,
/// stroke region, ribs, orientation field and spine.
pub fn style_sheet(style: &Style) -> Result<Vec<u8>> {
    brush::analysis::check::sheet_png(style.brush()?)
}

/// SVG text rendered on white as PNG bytes (documents under 512 px are
/// enlarged to 512 px): the `--preview` of every command.
pub fn preview_png(svg: &str) -> Result<Vec<u8>> {
    render::preview_png(svg)
}

/// Compares two SVG files by rendering them at the same size (the
/// expected one's, longest side 1024 px) and counting the pixels that
/// differ; errors name the file.
pub fn diff(expected: &Path, actual: &Path) -> Result<DiffReport> {
    diff::diff_files(expected, actual)
}
