//! Output of the brush pipeline (decobrush.txt §6–7, SPEC "Output SVG"):
//! each exemplar layer's SDF read through the synthesized coordinates onto
//! the query's canvas, traced to Béziers, one `<g>` per query in drawing
//! order with the layers' colours, bottom layer first.

use super::pipeline::{as_branch, brush_query, starts_on, BrushOptions, QueryResult};
use super::query::{self, QuerySpine};
use crate::error::{Error, Result};
use crate::raster::{Grid, Sdf};
use crate::sketch::Sketch;
use crate::style::brush::BrushStyle;
use crate::svg_out::{decimals_for, Color, Document, FillRule, Group, Shape};
use crate::trace::{trace_sdf, TraceOptions};
use rayon::prelude::*;

/// Signed distance written off the ornament, px (paper).
const PAPER: f32 = 8.0;

/// The brush result for a whole sketch.
#[derive(Clone, Debug)]
pub struct BrushOutput {
    /// The output document (same size and viewBox as the sketch).
    pub document: Document,
    /// Per query spine, in drawing order.
    pub queries: Vec<QueryResult>,
    /// Skipped paths and other warnings, one line each.
    pub warnings: Vec<String>,
    /// Notes for `--verbose`.
    pub notes: Vec<String>,
}

/// The distinct layer colours of a style, in order of first appearance
/// (exemplar order, then each exemplar's layers bottom first).
pub fn palette(style: &BrushStyle) -> Vec<Color> {
    let mut out: Vec<Color> = Vec::new();
    for e in &style.exemplars {
        if let Some(lv) = e.finest() {
            for l in &lv.ink.layers {
                if !out.contains(&l.color) {
                    out.push(l.color);
                }
            }
        }
    }
    out
}

/// The canvas SDF of one layer colour (or of all ink, `None`) for a
/// synthesized query: per pixel, the exemplar's finest-level SDF at μ, px;
/// [`PAPER`] off the ornament or where the exemplar lacks that colour.
pub fn layer_sdf(style: &BrushStyle, r: &QueryResult, color: Option<Color>) -> Grid<f32> {
    let g = &r.field.coords;
    let (w, h) = (g.width(), g.height());
    let level = r.field.level;
    let rows: Vec<Vec<f32>> = (0..h)
        .into_par_iter()
        .map(|y| {
            (0..w)
                .map(|x| {
                    g.get(x, y)
                        .and_then(|c| {
                            let lv = style
                                .exemplars
                                .get(c.exemplar as usize)?
                                .levels
                                .get(level)?;
                            let grid = match color {
                                None => &lv.ink.ink,
                                Some(col) => &lv.ink.layers.iter().find(|l| l.color == col)?.sdf,
                            };
                            Some(grid.sample(c.x as f64, c.y as f64))
                        })
                        .unwrap_or(PAPER)
                })
                .collect()
        })
        .collect();
    Grid::from_vec(w, h, rows.concat()).unwrap_or_else(|| Grid::new(w, h, PAPER))
}

/// One pass of a 3×3 binomial filter over an SDF: per-pixel coordinate
/// choices leave a staircase of sub-pixel steps along outlines that the
/// fitter would otherwise follow; a distance field stays a distance field
/// (up to its curvature) under this small blur.
pub fn smooth(g: &Grid<f32>) -> Grid<f32> {
    let (w, h) = (g.width(), g.height());
    let k = [1.0f32, 2.0, 1.0];
    Grid::from_fn(w, h, |x, y| {
        let mut acc = 0.0;
        for (j, ky) in k.iter().enumerate() {
            for (i, kx) in k.iter().enumerate() {
                acc += kx
                    * ky
                    * g.get_or(
                        x as isize + i as isize - 1,
                        y as isize + j as isize - 1,
                        g.get(x, y),
                    );
            }
        }
        acc / 16.0
    })
}

/// Traces a synthesized query into one group of filled shapes, bottom
/// layer first.
pub fn trace_query(style: &BrushStyle, r: &QueryResult, id: String, opts: &TraceOptions) -> Group {
    let to_user = r.canvas.to_user();
    let mut shapes = Vec::new();
    for color in palette(style) {
        let sdf = Sdf {
            dist: smooth(&layer_sdf(style, r, Some(color))),
            to_user,
        };
        for p in trace_sdf(&sdf, opts) {
            shapes.push(Shape {
                fill_rule: FillRule::NonZero,
                ..Shape::filled(p, color)
            });
        }
    }
    Group { id, shapes }
}

/// The query spines of a sketch with branching applied (§7): a stroke
/// starting on an earlier one has its start treated as a middle.
pub fn prepared_spines(
    sketch: &Sketch,
    opts: &BrushOptions,
) -> Result<(Vec<QuerySpine>, Vec<String>, Vec<String>)> {
    let set = query::spines(sketch, &opts.query)?;
    if set.spines.is_empty() {
        return Err(Error::invalid(
            &sketch.path,
            "no open paths to brush along (draw stroked paths without fill)",
        ));
    }
    let mut spines: Vec<QuerySpine> = Vec::with_capacity(set.spines.len());
    let mut notes = set.notes;
    for mut q in set.spines {
        if starts_on(&q, &spines) {
            notes.push(format!(
                "{}: query {} starts on an earlier stroke and branches from it",
                sketch.path.display(),
                q.query_id
            ));
            as_branch(&mut q);
        }
        spines.push(q);
    }
    Ok((spines, set.warnings, notes))
}

/// Runs the brush pipeline on every open path of `sketch` (queries in
/// parallel, results in drawing order) and writes the document.
pub fn brush_sketch(
    style: &BrushStyle,
    sketch: &Sketch,
    opts: &BrushOptions,
) -> Result<BrushOutput> {
    let (spines, warnings, notes) = prepared_spines(sketch, opts)?;
    let results: Vec<QueryResult> = spines
        .par_iter()
        .map(|q| brush_query(style, q, opts))
        .collect::<Result<Vec<_>>>()?;
    let trace = TraceOptions::default();
    let ppu = results
        .iter()
        .map(|r| r.canvas.px_per_unit)
        .fold(0.0f64, f64::max);
    let mut document = Document::new(
        sketch.width,
        sketch.height,
        decimals_for(trace.tolerance / ppu.max(1e-9)),
    );
    document.view_box = sketch.view_box;
    let groups: Vec<Group> = results
        .par_iter()
        .map(|r| {
            let id = if r.spine.query_id.is_empty() {
                "q".to_string()
            } else {
                r.spine.query_id.clone()
            };
            trace_query(style, r, id, &trace)
        })
        .collect();
    // Subpaths of one query share its group.
    for g in groups {
        match document.groups.last_mut() {
            Some(last) if last.id == g.id => last.shapes.extend(g.shapes),
            _ => document.groups.push(g),
        }
    }
    Ok(BrushOutput {
        document,
        queries: results,
        warnings,
        notes,
    })
}
