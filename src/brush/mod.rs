//! `flourish brush`: structured ornament along sketched paths, the DecoBrush
//! pipeline (Lu et al. 2014, decobrush.txt §5) with vector output.
//!
//! Stages, each in its own module and each tested against a reference:
//! - [`query`]: sketch paths → arc-length resampled spines with the
//!   per-sample features of the matching (turning angle, width, distance to
//!   the ends);
//! - [`matching`]: §5.1 piecewise matching, a dynamic programme over
//!   exemplar segments (oracle: exhaustive search on tiny inputs);
//! - [`ribs`]: the exemplars' ribs resampled at the query's pace with
//!   their matching features (stroke-width envelope, ink cross-sections);
//! - [`arap`]: §5.2 as-rigid-as-possible deformation of a segment's rib mesh
//!   onto the query spine (Igarashi et al. 2005), and the rasterized map back
//!   to exemplar coordinates;
//! - [`graphcut`]: §5.3 seams between overlapping warped segments, an exact
//!   s–t minimum cut of Eq. 1–2 (oracle: brute force on tiny grids), on
//!   the Boykov–Kolmogorov max-flow of [`maxflow`] (oracle: Dinic);
//! - [`synth`]: §5.4 hierarchical synthesis of exemplar coordinates
//!   (oriented-neighbourhood correction, coordinate upsampling);
//! - [`pipeline`]: the stages chained for one query, on its own canvas;
//! - [`pieces`]: a stroke too long for one canvas, on a chain of canvases
//!   along its spine;
//! - [`output`]: per-layer SDFs through the coordinates, traced to one
//!   `<g>` per query;
//! - [`baseline`]: the "art brush" reference, one exemplar stretched along
//!   the whole query.

pub mod analysis;
pub mod arap;
pub mod baseline;
pub mod graphcut;
pub mod matching;
pub mod maxflow;
#[cfg(test)]
pub(crate) mod measure;
pub mod output;
pub mod pieces;
pub mod pipeline;
pub mod query;
pub mod ribs;
pub mod swell;
pub mod synth;

use crate::error::{Error, Result};
use crate::read::sketch::Sketch;
use crate::svg_out::Output;
use analysis::BrushStyle;
use resvg::usvg;
use std::sync::Arc;

/// Most correction iterations per synthesis level (each costs about one
/// synthesis pass).
pub const MAX_ITERATIONS: usize = 100;

/// Options of [`crate::brush()`].
#[derive(Clone, Debug)]
pub struct BrushOptions {
    /// Seeds every choice among near-equal candidates: matching ties and
    /// synthesis candidates (default 0).
    pub seed: u64,
    /// Draw the art-brush baseline instead: one exemplar stretched along
    /// the whole path (default `false`).
    pub art_brush: bool,
    /// Correction iterations per synthesis level, 0..=[`MAX_ITERATIONS`]
    /// (0: the graph cut, upsampled; default 1).
    pub iterations: usize,
    /// A refinement sketch (DecoBrush §5.5): its black strokes add
    /// ornament, its white ones erase it (default `None`).
    pub refine: Option<Refinement>,
    /// Add a note per query with its matched segments, canvas size and
    /// synthesis energy; the energy costs about one correction pass per
    /// query (default `false`).
    pub measure: bool,
    /// Cancels the run from another thread: checked before each query,
    /// each piece of a long one, its synthesis and its tracing; the run
    /// then ends with [`Error::Cancelled`] (default `None`).
    pub cancel: Option<crate::Cancel>,
}

impl Default for BrushOptions {
    fn default() -> Self {
        BrushOptions {
            seed: 0,
            art_brush: false,
            iterations: 1,
            refine: None,
            measure: false,
            cancel: None,
        }
    }
}

impl BrushOptions {
    /// Checks every value's range.
    pub fn validate(&self) -> Result<()> {
        if self.iterations > MAX_ITERATIONS {
            return Err(Error::Option {
                name: "iterations",
                reason: format!("{} is not in 0..={MAX_ITERATIONS}", self.iterations),
            });
        }
        Ok(())
    }

    /// The pipeline's settings for these options.
    pub(crate) fn settings(&self) -> pipeline::Settings {
        pipeline::Settings {
            seed: self.seed,
            art_brush: self.art_brush,
            refine: self.refine.clone(),
            cancel: self.cancel.clone(),
            // Only a measuring run reads the fields after tracing.
            discard_fields: !self.measure,
            synth: synth::SynthOptions {
                iterations: self.iterations,
                ..Default::default()
            },
            ..pipeline::Settings::default()
        }
    }
}

/// A refinement sketch (DecoBrush §5.5): an SVG of the sketch's size and
/// viewBox whose opaque dark pixels add ornament and light ones erase it.
#[derive(Clone, Debug)]
pub struct Refinement {
    tree: Arc<usvg::Tree>,
}

impl Refinement {
    /// Parses refinement SVG bytes (plain or SVGZ).
    pub fn from_svg(bytes: &[u8]) -> Result<Refinement> {
        Ok(Refinement {
            tree: Arc::new(crate::read::svg::parse_svg(bytes)?),
        })
    }
}

/// Brushes every open path of `sketch` with `style` ([`crate::brush()`]).
pub fn run(style: &BrushStyle, sketch: &Sketch, opts: &BrushOptions) -> Result<Output> {
    opts.validate()?;
    let out = output::brush_sketch(style, sketch, &opts.settings())?;
    let mut notes = out.notes;
    // Exemplars whose spine had to be guessed: said before the sketch's
    // own warnings.
    let mut warnings: Vec<String> = style
        .exemplars
        .iter()
        .filter(|e| e.spine_source == analysis::SpineSource::Fallback)
        .map(|e| {
            format!(
                "style {}: {}: {}",
                style.name,
                e.file.display(),
                analysis::check::FALLBACK_WARNING
            )
        })
        .collect();
    warnings.extend(out.warnings);
    if opts.measure {
        for (i, q) in out.queries.iter().enumerate() {
            notes.push(format!(
                "query {} ({}): {} segments, canvas {}×{} px, energy {:.4}",
                i + 1,
                q.spine.query_id,
                q.segments.len(),
                q.canvas.width,
                q.canvas.height,
                q.energy(style)
            ));
        }
    }
    Ok(Output {
        document: out.document,
        warnings,
        notes,
    })
}

#[cfg(test)]
mod tests;
