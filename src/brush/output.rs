//! Output of the brush pipeline (decobrush.txt §6–7, SPEC "Output SVG"):
//! each exemplar layer's SDF read through the synthesized coordinates onto
//! the query's canvas, traced to Béziers, one `<g>` per query in drawing
//! order with the layers' colours, bottom layer first.

use super::pipeline::{as_branch, brush_query, starts_on, QueryResult, Settings};
use super::query::{self, QuerySpine};
use super::synth::{self, Coord, Field};
use crate::brush::analysis::BrushStyle;
use crate::error::{Error, Result};
use crate::raster::{Grid, Sdf};
use crate::read::sketch::Sketch;
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

/// Rings (finest px) by which the coordinate field is continued beyond the
/// region the matched segments cover before it is read: one coarsest
/// pixel. The covered region is rasterized at the start level and
/// upsampled by whole parents, so its edge is a staircase of coarse pixels;
/// where an exemplar's ink reaches its rib outline the region edge would
/// clip it along that staircase (a saw-tooth on every stem).
pub fn border_rings(r: &QueryResult) -> usize {
    r.canvas.factor.max(1)
}

/// The field continued `rings` pixels beyond its covered region: ring by
/// ring, an uncovered pixel with covered 8-neighbours takes the
/// continuation `μ(q) + J(q)(p − q)` of the first of them in scan order
/// whose exemplar is the most common among them ([`synth::jacobian`]).
pub fn extend_field(style: &BrushStyle, field: &Field, rings: usize) -> Field {
    let mut f = field.clone();
    let (w, h) = (f.coords.width(), f.coords.height());
    // Only pixels next to the covered region can be reached: each ring
    // scans the covered pixels' box grown by one pixel (a tiny stroke's
    // ornament covers a small part of its canvas).
    let Some(mut bx) = covered_box(&f.coords) else {
        return f;
    };
    for _ in 0..rings {
        bx = [
            bx[0].saturating_sub(1),
            bx[1].saturating_sub(1),
            (bx[2] + 1).min(w - 1),
            (bx[3] + 1).min(h - 1),
        ];
        // Every pixel of a ring reads the field as it was before the ring
        // (the updates are gathered first, then written).
        let snap = &f;
        let rows: Vec<(usize, Vec<Continued>)> = (bx[1]..=bx[3])
            .into_par_iter()
            .map(|y| {
                let mut out = Vec::new();
                for x in bx[0]..=bx[2] {
                    if snap.coords.get(x, y).is_some() {
                        continue;
                    }
                    let mut best: Option<Continued> = None;
                    let mut counts: Vec<(u32, usize)> = Vec::new();
                    let mut preds: Vec<(u32, Coord, [f32; 2])> = Vec::new();
                    for (dx, dy) in NEIGHBOURS {
                        let (nx, ny) = (x as isize + dx, y as isize + dy);
                        let Some(c) = snap.coords.get_or(nx, ny, None) else {
                            continue;
                        };
                        let (nx, ny) = (nx as usize, ny as usize);
                        let Some(j) = synth::jacobian(style, snap, nx, ny) else {
                            continue;
                        };
                        let d = synth::apply(j, [-dx as f32, -dy as f32]);
                        let p = Coord {
                            exemplar: c.exemplar,
                            x: c.x + d[0],
                            y: c.y + d[1],
                        };
                        match counts.iter_mut().find(|(e, _)| *e == c.exemplar) {
                            Some(k) => k.1 += 1,
                            None => counts.push((c.exemplar, 1)),
                        }
                        preds.push((c.exemplar, p, snap.orient.get(nx, ny)));
                    }
                    let top = counts.iter().map(|c| c.1).max().unwrap_or(0);
                    if let Some((e, _)) = counts.iter().find(|c| c.1 == top) {
                        if let Some((_, p, o)) = preds.iter().find(|p| p.0 == *e) {
                            best = Some((x, *p, *o));
                        }
                    }
                    out.extend(best);
                }
                (y, out)
            })
            .collect();
        let mut any = false;
        for (y, row) in rows {
            for (x, c, o) in row {
                f.coords.set(x, y, Some(c));
                f.orient.set(x, y, o);
                any = true;
            }
        }
        if !any {
            break;
        }
    }
    f
}

/// A pixel the continuation reaches: its column, coordinate and
/// orientation.
type Continued = (usize, Coord, [f32; 2]);

/// The box `[x0, y0, x1, y1]` (inclusive) of the covered pixels of a
/// coordinate grid, `None` when none is covered.
fn covered_box(coords: &Grid<Option<Coord>>) -> Option<[usize; 4]> {
    let w = coords.width();
    let mut bx: Option<[usize; 4]> = None;
    for (i, c) in coords.data().iter().enumerate() {
        if c.is_none() {
            continue;
        }
        let (x, y) = (i % w, i / w);
        bx = Some(match bx {
            None => [x, y, x, y],
            Some(b) => [b[0].min(x), b[1].min(y), b[2].max(x), b[3].max(y)],
        });
    }
    bx
}

/// Radius of the blended read, px.
const BLEND: isize = 2;
/// Binomial weights of the blended read.
const BINOMIAL: [f32; 5] = [1.0, 4.0, 6.0, 4.0, 1.0];

/// The 8-neighbour offsets in scan order.
const NEIGHBOURS: [(isize, isize); 8] = [
    (-1, -1),
    (0, -1),
    (1, -1),
    (-1, 0),
    (1, 0),
    (-1, 1),
    (0, 1),
    (1, 1),
];

/// The Jacobian of every pixel of a field ([`synth::jacobian`]), row-major.
fn jacobians(style: &BrushStyle, field: &Field) -> Vec<Option<synth::Jacobian>> {
    let (w, h) = (field.coords.width(), field.coords.height());
    (0..h)
        .into_par_iter()
        .flat_map_iter(|y| (0..w).map(move |x| synth::jacobian(style, field, x, y)))
        .collect()
}

/// The SDF of the layer of colour `color` (`None`: all ink) read through
/// a synthesized (already extended) field, px; `PAPER` off the ornament.
/// Each pixel `p` blends the predictions of its 3×3 neighbourhood:
/// neighbour `q` predicts the coordinate `μ(q) + J(q)(p − q)` (its patch
/// continued to `p`, [`synth::jacobian`]) and gives the exemplar's SDF
/// there (bilinear); the values are averaged with binomial weights 1-2-1
/// (a neighbour whose exemplar lacks the colour gives paper). Inside a
/// coherent patch every prediction is `μ(p)` itself and the read is
/// exact; across a seam the two patches' fields are cross-faded over
/// three pixels, so outlines cross seams without steps or spurs, and a
/// lone pixel whose μ landed on another layer's ink (a speck) is outvoted
/// by its neighbours (the output reading of decobrush.txt §5.4: colours
/// are read through μ, §7). The field's Jacobians are measured beforehand
/// (`jac`, from [`jacobians`]): the layers of one query share them.
fn blended_sdf_with(
    style: &BrushStyle,
    field: &Field,
    jac: &[Option<synth::Jacobian>],
    color: Option<Color>,
) -> Grid<f32> {
    let g = &field.coords;
    let (w, h) = (g.width(), g.height());
    let level = field.level;
    let read = |c: Coord| -> f32 {
        style
            .exemplars
            .get(c.exemplar as usize)
            .and_then(|e| e.levels.get(level))
            .and_then(|lv| match color {
                None => Some(&lv.ink.ink),
                Some(col) => lv
                    .ink
                    .layers
                    .iter()
                    .find(|l| l.color == col)
                    .map(|l| &l.sdf),
            })
            .map(|grid| grid.sample(c.x as f64, c.y as f64))
            .unwrap_or(PAPER)
    };
    let rows: Vec<Vec<f32>> = (0..h)
        .into_par_iter()
        .map(|y| {
            (0..w)
                .map(|x| {
                    if g.get(x, y).is_none() {
                        return PAPER;
                    }
                    let (mut acc, mut wsum) = (0.0f32, 0.0f32);
                    for dy in -BLEND..=BLEND {
                        for dx in -BLEND..=BLEND {
                            let (nx, ny) = (x as isize + dx, y as isize + dy);
                            let Some(c) = g.get_or(nx, ny, None) else {
                                continue;
                            };
                            let Some(j) = jac.get(ny as usize * w + nx as usize).copied().flatten()
                            else {
                                continue;
                            };
                            let d = synth::apply(j, [-dx as f32, -dy as f32]);
                            let wt =
                                BINOMIAL[(dx + BLEND) as usize] * BINOMIAL[(dy + BLEND) as usize];
                            let p = Coord {
                                exemplar: c.exemplar,
                                x: c.x + d[0],
                                y: c.y + d[1],
                            };
                            acc += wt * read(p);
                            wsum += wt;
                        }
                    }
                    if wsum > 0.0 {
                        acc / wsum
                    } else {
                        PAPER
                    }
                })
                .collect()
        })
        .collect();
    Grid::from_vec(w, h, rows.concat()).unwrap_or_else(|| Grid::new(w, h, PAPER))
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

/// How deep (px) inside its outline some pixel of a drawn element lies: a
/// piece with no pixel centre a pixel from its edge is under 2 px thick
/// everywhere, a fragment of a hairline tip broken up by rasterization
/// (the scroll's tapering spikes leave 1–4 px dots at 512 px), not
/// something the artist drew.
pub const ELEMENT_DEPTH: f32 = 1.0;

/// The area (finest px²) of the smallest drawn element of any exemplar of
/// the style: a component of its ink of at least [`SPECK`] px² that is at
/// least [`ELEMENT_DEPTH`] deep somewhere. Ornament pieces smaller than
/// this are synthesis debris.
pub fn smallest_exemplar_component(style: &BrushStyle) -> usize {
    style
        .exemplars
        .iter()
        .filter_map(|e| e.finest())
        .flat_map(|lv| {
            let sdf = &lv.ink.ink;
            components(&sdf.map(|d| d < 0.0))
                .into_iter()
                .filter(|c| {
                    c.iter()
                        .any(|&i| sdf.data().get(i).is_some_and(|&d| d <= -ELEMENT_DEPTH))
                })
                .map(|c| c.len())
        })
        .filter(|&n| n >= SPECK)
        .min()
        .unwrap_or(SPECK)
}

/// [`final_layers_with`], measuring the style's facts first.
#[cfg(test)]
pub fn final_layers(style: &BrushStyle, r: &QueryResult) -> Vec<(Color, Grid<f32>)> {
    final_layers_with(style, r, &StyleFacts::of(style))
}

/// What the output stage needs to know about a style, measured once per
/// sketch instead of once per query: the smallest drawn element scans
/// every exemplar's finest ink, a large share of a short stroke's cost.
#[derive(Clone, Debug)]
struct StyleFacts {
    /// The layer colours ([`palette`]).
    palette: Vec<Color>,
    /// [`smallest_exemplar_component`].
    smallest_piece: usize,
}

impl StyleFacts {
    fn of(style: &BrushStyle) -> StyleFacts {
        StyleFacts {
            palette: palette(style),
            smallest_piece: smallest_exemplar_component(style),
        }
    }
}

/// The final per-layer canvas SDFs of a query, bottom layer first, with
/// their colours: each layer read through the continued field with the
/// blended read ([`blended_sdf_with`]); then a last, documented cleanup: ink
/// components smaller than the exemplars' smallest piece
/// ([`smallest_exemplar_component`], the threshold taken from the style,
/// not a constant) are synthesis debris and are cleared; the query's
/// largest piece is its body and always stays. The style's facts
/// (`facts`) are measured once per sketch.
fn final_layers_with(
    style: &BrushStyle,
    r: &QueryResult,
    facts: &StyleFacts,
) -> Vec<(Color, Grid<f32>)> {
    let field = extend_field(style, &r.field, border_rings(r));
    let jac = jacobians(style, &field);
    let mut layers: Vec<(Color, Grid<f32>)> = facts
        .palette
        .iter()
        .map(|&c| (c, blended_sdf_with(style, &field, &jac, Some(c))))
        .collect();
    drop(jac);
    let Some((_, first)) = layers.first() else {
        return layers;
    };
    let (w, h) = (first.width(), first.height());
    let ink = Grid::from_fn(w, h, |x, y| layers.iter().any(|(_, g)| g.get(x, y) < 0.0));
    let comps = components(&ink);
    // A query shorter than every exemplar can have a body smaller than
    // the exemplars' smallest piece: the largest piece always stays.
    let largest = comps.iter().map(Vec::len).max().unwrap_or(0);
    let min = facts.smallest_piece.min(largest);
    for comp in comps {
        if comp.len() >= min {
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

/// [`trace_query_with`], measuring the style's facts first.
#[cfg(test)]
pub fn trace_query(style: &BrushStyle, r: &QueryResult, id: String, opts: &TraceOptions) -> Group {
    trace_query_with(style, r, id, opts, &StyleFacts::of(style))
}

/// Traces a synthesized query into one group of filled shapes, bottom
/// layer first; the style's facts (`facts`) are measured once per sketch.
fn trace_query_with(
    style: &BrushStyle,
    r: &QueryResult,
    id: String,
    opts: &TraceOptions,
    facts: &StyleFacts,
) -> Group {
    let to_user = r.canvas.to_user();
    let mut shapes = Vec::new();
    for (color, dist) in final_layers_with(style, r, facts) {
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
    opts: &Settings,
) -> Result<(Vec<QuerySpine>, Vec<String>, Vec<String>)> {
    let set = query::spines(sketch, &opts.query)?;
    if set.spines.is_empty() {
        let skipped = match set.warnings.first() {
            Some(w) => format!(" ({} skipped; first: {w})", set.warnings.len()),
            None => String::new(),
        };
        return Err(Error::invalid(format!(
            "no open paths to brush along (draw stroked paths without fill){skipped}"
        )));
    }
    let mut spines: Vec<QuerySpine> = Vec::with_capacity(set.spines.len());
    let mut notes = set.notes;
    for mut q in set.spines {
        if starts_on(&q, &spines) {
            notes.push(format!(
                "query {} starts on an earlier stroke and branches from it",
                q.query_id
            ));
            as_branch(&mut q);
        }
        spines.push(q);
    }
    Ok((spines, set.warnings, notes))
}

/// Applies a refinement sketch (already parsed, `tree`) to one synthesized
/// query (§5.5): the sketch is rendered onto the query's canvas; opaque dark
/// pixels add ink, opaque light ones erase it; the mask is those pixels
/// dilated by 2 px.
fn refine_one(
    style: &BrushStyle,
    mut r: QueryResult,
    tree: &resvg::usvg::Tree,
    opts: &Settings,
) -> QueryResult {
    let sopts = crate::brush::synth::SynthOptions {
        seed: opts.seed,
        ..opts.synth.clone()
    };
    let (w, h) = (r.canvas.width, r.canvas.height);
    let Some(mut pixmap) = resvg::tiny_skia::Pixmap::new(w as u32, h as u32) else {
        return r;
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
    resvg::render(tree, t, &mut pixmap.as_mut());
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
        return r;
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
        r.field = f;
    }
    r
}

/// Runs the brush pipeline on every open path of `sketch` (queries in
/// parallel, results in drawing order) and writes the document. Each query
/// is synthesized, refined and traced in one go, so with
/// [`Settings::discard_fields`] only the queries in flight hold their
/// fields.
pub fn brush_sketch(style: &BrushStyle, sketch: &Sketch, opts: &Settings) -> Result<BrushOutput> {
    let (spines, warnings, notes) = prepared_spines(sketch, opts)?;
    let refine = opts.refine.as_ref().map(|r| &*r.tree);
    let trace = TraceOptions::default();
    let facts = StyleFacts::of(style);
    let done: Vec<(QueryResult, Group)> = spines
        .par_iter()
        .map(|q| {
            let r = brush_query(style, q, opts)
                .map_err(|e| e.in_part(format!("query {}", q.query_id)))?;
            let mut r = match &refine {
                Some(tree) => refine_one(style, r, tree, opts),
                None => r,
            };
            let id = if r.spine.query_id.is_empty() {
                "q".to_string()
            } else {
                r.spine.query_id.clone()
            };
            let group = trace_query_with(style, &r, id, &trace, &facts);
            if opts.discard_fields {
                r.field = Field {
                    level: r.field.level,
                    coords: Grid::new(0, 0, None),
                    orient: Grid::new(0, 0, [0.0; 2]),
                    seam: Grid::new(0, 0, false),
                };
                r.levels = Vec::new();
            }
            Ok((r, group))
        })
        .collect::<Result<Vec<_>>>()?;
    let ppu = done
        .iter()
        .map(|(r, _)| r.canvas.px_per_unit)
        .fold(0.0f64, f64::max);
    let mut document = Document::new(
        sketch.width,
        sketch.height,
        decimals_for(trace.tolerance / ppu.max(1e-9)),
    );
    document.view_box = sketch.view_box;
    let mut results = Vec::with_capacity(done.len());
    // Subpaths of one query share its group.
    for (r, g) in done {
        results.push(r);
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
