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

/// The 4-connected components of a mask, as lists of pixel indices
/// (row-major), in scan order.
pub fn components(mask: &Grid<bool>) -> Vec<Vec<usize>> {
    let (w, h) = (mask.width(), mask.height());
    let mut seen = vec![false; w * h];
    let mut out = Vec::new();
    for start in 0..w * h {
        if seen[start] || !mask.data()[start] {
            continue;
        }
        seen[start] = true;
        let mut comp = vec![start];
        let mut k = 0;
        while let Some(&i) = comp.get(k) {
            k += 1;
            let (x, y) = (i % w, i / w);
            let mut visit = |j: usize| {
                if !seen[j] && mask.data()[j] {
                    seen[j] = true;
                    comp.push(j);
                }
            };
            if x > 0 {
                visit(i - 1);
            }
            if x + 1 < w {
                visit(i + 1);
            }
            if y > 0 {
                visit(i - w);
            }
            if y + 1 < h {
                visit(i + w);
            }
        }
        out.push(comp);
    }
    out
}

/// Smallest ink component counted as a drawn element, px² (the tracer's
/// default `min_area`: smaller ones are rasterization specks).
pub const SPECK: usize = 4;

/// The area (finest px²) of the smallest ink component of any exemplar of
/// the style (specks under [`SPECK`] aside): ornament pieces smaller than
/// this are synthesis debris.
pub fn smallest_exemplar_component(style: &BrushStyle) -> usize {
    style
        .exemplars
        .iter()
        .filter_map(|e| e.finest())
        .flat_map(|lv| {
            components(&lv.ink.ink.map(|d| d < 0.0))
                .into_iter()
                .map(|c| c.len())
        })
        .filter(|&n| n >= SPECK)
        .min()
        .unwrap_or(SPECK)
}

/// The final per-layer canvas SDFs of a query, bottom layer first, with
/// their colours: smoothed, and with debris removed — ink components
/// smaller than the exemplars' smallest, except pieces of at least an
/// eighth of that on the spine's core band.
pub fn final_layers(style: &BrushStyle, r: &QueryResult) -> Vec<(Color, Grid<f32>)> {
    let mut layers: Vec<(Color, Grid<f32>)> = palette(style)
        .into_iter()
        .map(|c| (c, smooth(&layer_sdf(style, r, Some(c)))))
        .collect();
    let Some((_, first)) = layers.first() else {
        return layers;
    };
    let (w, h) = (first.width(), first.height());
    let ink = Grid::from_fn(w, h, |x, y| layers.iter().any(|(_, g)| g.get(x, y) < 0.0));
    let min = smallest_exemplar_component(style);
    // The spine's core band (a quarter width): a piece there of at least
    // an eighth of the smallest exemplar piece is part of the ornament's
    // body, broken off or not, and stays.
    let to_px = r.canvas.to_pixel(1.0);
    let spine: Vec<kurbo::Point> = r.spine.samples.iter().map(|s| to_px * s.pos).collect();
    let core = 0.25 * r.spine.width * r.canvas.px_per_unit;
    let on_core = |i: usize| {
        let p = kurbo::Point::new((i % w) as f64 + 0.5, (i / w) as f64 + 0.5);
        spine.iter().any(|q| q.distance(p) <= core)
    };
    for comp in components(&ink) {
        if comp.len() >= min || (8 * comp.len() >= min && comp.iter().any(|&i| on_core(i))) {
            continue;
        }
        for (_, g) in &mut layers {
            for &i in &comp {
                if let Some(v) = g.data_mut().get_mut(i) {
                    *v = v.max(0.5);
                }
            }
        }
    }
    layers
}

/// Traces a synthesized query into one group of filled shapes, bottom
/// layer first.
pub fn trace_query(style: &BrushStyle, r: &QueryResult, id: String, opts: &TraceOptions) -> Group {
    let to_user = r.canvas.to_user();
    let mut shapes = Vec::new();
    for (color, dist) in final_layers(style, r) {
        let sdf = Sdf { dist, to_user };
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
        let skipped = match set.warnings.first() {
            Some(w) => format!(" ({} skipped; first: {w})", set.warnings.len()),
            None => String::new(),
        };
        return Err(Error::invalid(
            &sketch.path,
            format!("no open paths to brush along (draw stroked paths without fill){skipped}"),
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

/// Applies a refinement sketch to every synthesized query (§5.5): the
/// sketch is rendered onto each query's canvas; opaque dark pixels add ink,
/// opaque light ones erase it; the mask is those pixels dilated by 2 px.
fn refine_all(
    style: &BrushStyle,
    results: Vec<QueryResult>,
    path: &std::path::Path,
    opts: &BrushOptions,
) -> Result<Vec<QueryResult>> {
    let tree = crate::io::load_svg(path)?;
    let sopts = crate::brush::synth::SynthOptions {
        seed: opts.seed,
        ..opts.synth.clone()
    };
    let mut out = Vec::with_capacity(results.len());
    for mut r in results {
        let (w, h) = (r.canvas.width, r.canvas.height);
        let Some(mut pixmap) = resvg::tiny_skia::Pixmap::new(w as u32, h as u32) else {
            out.push(r);
            continue;
        };
        let c = r.canvas.to_pixel(1.0).as_coeffs();
        let t = resvg::tiny_skia::Transform::from_row(
            c[0] as f32,
            c[1] as f32,
            c[2] as f32,
            c[3] as f32,
            c[4] as f32,
            c[5] as f32,
        );
        resvg::render(&tree, t, &mut pixmap.as_mut());
        let px = pixmap.pixels();
        // +1 add, −1 erase, 0 untouched.
        let marks = Grid::from_fn(w, h, |x, y| {
            let p = px[y * w + x];
            if p.alpha() < 128 {
                0i8
            } else {
                let l = (p.red() as u32 + p.green() as u32 + p.blue() as u32) * 255
                    / (3 * p.alpha() as u32).max(1);
                if l < 128 {
                    1
                } else {
                    -1
                }
            }
        });
        if marks.data().iter().all(|m| *m == 0) {
            out.push(r);
            continue;
        }
        let mut target = crate::brush::synth::appearance(style, &r.field);
        let mask = Grid::from_fn(w, h, |x, y| {
            (-2isize..=2).any(|dy| {
                (-2isize..=2).any(|dx| marks.get_or(x as isize + dx, y as isize + dy, 0) != 0)
            })
        });
        for y in 0..h {
            for x in 0..w {
                match marks.get(x, y) {
                    1 => target.set(x, y, -2.0),
                    -1 => target.set(x, y, PAPER),
                    _ => {}
                }
            }
        }
        if let Some(f) = crate::brush::synth::refine(style, &r.levels, &target, &mask, &sopts) {
            r.energy = crate::brush::synth::energy(style, &f);
            r.field = f;
        }
        out.push(r);
    }
    Ok(out)
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
        .map(|q| {
            brush_query(style, q, opts).map_err(|e| match e {
                Error::TooLarge {
                    width,
                    height,
                    limit,
                    ..
                } => Error::TooLarge {
                    path: format!("{}: query {}", sketch.path.display(), q.query_id).into(),
                    width,
                    height,
                    limit,
                },
                Error::Degenerate { subject, reason } => Error::Degenerate {
                    subject: format!("{}: {subject}", sketch.path.display()),
                    reason,
                },
                other => other,
            })
        })
        .collect::<Result<Vec<_>>>()?;
    let results = match &opts.refine {
        Some(path) => refine_all(style, results, path, opts)?,
        None => results,
    };
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
