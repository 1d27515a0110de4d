//! Output of the brush pipeline (decobrush.txt §6–7, SPEC "Output SVG"):
//! each exemplar layer's SDF read from the finest exemplar level through
//! the synthesized coordinates, continued smoothly between canvas pixels,
//! onto the query's output grid ([`super::pipeline::output_subdivision`]),
//! traced to Béziers, one `<g>` per query in drawing order with the
//! layers' colours, bottom layer first.

use super::pieces::{in_pieces, layout, Layout, MAX_SKETCH_PIXELS};
use super::pipeline::{as_branch, brush_query, starts_on, to_finest, QueryResult, Settings};
use super::query::{self, QuerySpine};
use super::synth::{self, Coord, Field};
use crate::brush::analysis::facts::components;
use crate::brush::analysis::BrushStyle;
use crate::error::{Error, Result};
use crate::raster::{Bilinear, Grid, Sdf};
use crate::read::sketch::Sketch;
use crate::svg_out::{decimals_for, Color, Document, FillRule, Group, Shape};
use crate::trace::{trace_sdf, TraceOptions};
use rayon::prelude::*;
use std::collections::HashMap;

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

/// Rings (canvas px) by which the coordinate field is continued beyond
/// the region the matched segments cover before it is read: two
/// start-level pixels and two more, and [`REACH_MARGIN`] rounded up to
/// whole pixels past which ink is cut ([`Reach`]). The covered region is
/// rasterized at the start level and upsampled by whole parents, so its
/// edge is a staircase of coarse pixels; where an exemplar's ink reaches
/// its rib outline (a spike's tip, a curl's end) the region edge would
/// clip it along that staircase, in square steps.
pub fn border_rings(r: &QueryResult) -> usize {
    2 * r.canvas.factor.max(1) + 2 + REACH_MARGIN.ceil() as usize
}

/// [`extend_owned`] on a copy of `field`.
#[cfg(test)]
pub fn extend_field(style: &BrushStyle, field: &Field, rings: usize) -> Field {
    extend_owned(style, field.clone(), rings)
}

/// The field `f` continued `rings` pixels beyond its covered region: ring
/// by ring, an uncovered pixel `p` with covered or continued 8-neighbours
/// takes, from the first of them in scan order whose exemplar is the most
/// common among them, that neighbour's source `q` (a covered pixel: itself,
/// or the one it was continued from) and the continuation
/// `μ(q) + J(q)(p − q)` ([`synth::jacobian`], measured on the covered
/// field). Continuing from the covered source, not from the last ring,
/// keeps the continuation one affine patch per source: a Jacobian measured
/// again on continued pixels compounds its error ring by ring, and
/// squeezed patches map whole rings onto one spot of ink (blobs with
/// square steps beside the ornament).
fn extend_owned(style: &BrushStyle, mut f: Field, rings: usize) -> Field {
    let (w, h) = (f.coords.width(), f.coords.height());
    // Only pixels next to the covered region can be reached: each ring
    // scans the covered pixels' box grown by one pixel (a tiny stroke's
    // ornament covers a small part of its canvas).
    let Some(mut bx) = covered_box(&f.coords) else {
        return f;
    };
    // Continued pixels (row-major index) and their source.
    let mut carried: HashMap<usize, Origin> = HashMap::new();
    for _ in 0..rings {
        bx = [
            bx[0].saturating_sub(1),
            bx[1].saturating_sub(1),
            (bx[2] + 1).min(w - 1),
            (bx[3] + 1).min(h - 1),
        ];
        // Every pixel of a ring reads the field as it was before the ring
        // (the updates are gathered first, then written).
        let (snap, held) = (&f, &carried);
        let rows: Vec<(usize, Vec<Continued>)> = (bx[1]..=bx[3])
            .into_par_iter()
            .map(|y| {
                let mut out = Vec::new();
                let mut counts: Vec<(u32, usize)> = Vec::new();
                let mut firsts: Vec<(u32, (isize, isize))> = Vec::new();
                for x in bx[0]..=bx[2] {
                    if snap.coords.get(x, y).is_some() {
                        continue;
                    }
                    counts.clear();
                    firsts.clear();
                    for (dx, dy) in NEIGHBOURS {
                        let (nx, ny) = (x as isize + dx, y as isize + dy);
                        let Some(c) = snap.coords.get_or(nx, ny, None) else {
                            continue;
                        };
                        match counts.iter_mut().find(|(e, _)| *e == c.exemplar) {
                            Some(k) => k.1 += 1,
                            None => {
                                counts.push((c.exemplar, 1));
                                firsts.push((c.exemplar, (nx, ny)));
                            }
                        }
                    }
                    let top = counts.iter().map(|c| c.1).max().unwrap_or(0);
                    let Some((e, _)) = counts.iter().find(|c| c.1 == top) else {
                        continue;
                    };
                    let Some(&(_, (nx, ny))) = firsts.iter().find(|p| p.0 == *e) else {
                        continue;
                    };
                    let (nx, ny) = (nx as usize, ny as usize);
                    let src = match held.get(&(ny * w + nx)) {
                        Some(s) => *s,
                        None => {
                            let (Some(c), Some(j)) = (
                                snap.coords.get(nx, ny),
                                synth::jacobian(style, snap, nx, ny),
                            ) else {
                                continue;
                            };
                            Origin {
                                at: (nx, ny),
                                coord: c,
                                jac: j,
                                orient: snap.orient.get(nx, ny),
                            }
                        }
                    };
                    let d = synth::apply(
                        src.jac,
                        [x as f32 - src.at.0 as f32, y as f32 - src.at.1 as f32],
                    );
                    let c = Coord {
                        exemplar: src.coord.exemplar,
                        x: src.coord.x + d[0],
                        y: src.coord.y + d[1],
                    };
                    out.push((x, c, src));
                }
                (y, out)
            })
            .collect();
        let mut any = false;
        for (y, row) in rows {
            for (x, c, src) in row {
                f.coords.set(x, y, Some(c));
                f.orient.set(x, y, src.orient);
                carried.insert(y * w + x, src);
                any = true;
            }
        }
        if !any {
            break;
        }
    }
    f
}

/// The covered pixel a continued pixel is continued from: its position
/// (canvas px), coordinate, Jacobian and orientation.
#[derive(Clone, Copy, Debug)]
struct Origin {
    at: (usize, usize),
    coord: Coord,
    jac: synth::Jacobian,
    orient: [f32; 2],
}

/// A pixel the continuation reaches: its column, coordinate and source.
type Continued = (usize, Coord, Origin);

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

/// How far the continuation may carry ink: the Euclidean distance from
/// the covered region (canvas px), and the distance at which ink is cut,
/// [`REACH_MARGIN`] inside the last continued ring. The rings grow by
/// 8-neighbours, so every pixel within `rings` px (Euclidean) of the
/// covered region is continued; a cut along this distance's level line is
/// smooth where the rings' own edge is a staircase of canvas pixels.
struct Reach {
    dist: Grid<f32>,
    cut: f32,
}

/// Canvas px inside the last continued ring at which ink is cut: one and
/// a half pixels, so the two canvas pixels every output pixel reads
/// across on each axis are continued wherever ink survives the cut.
const REACH_MARGIN: f32 = 1.5;

impl Reach {
    /// The reach of continuing `coords` by `rings` px.
    fn of(coords: &Grid<Option<Coord>>, rings: usize) -> Reach {
        let covered = coords.map(|c| c.is_some());
        Reach {
            dist: crate::raster::edt::squared_edt(&covered).map(f32::sqrt),
            cut: rings as f32 - REACH_MARGIN,
        }
    }

    /// Canvas px beyond the cut at canvas point `(x, y)` (pixel centres at
    /// half-integers), negative inside it.
    fn beyond(&self, x: f32, y: f32) -> f32 {
        self.dist.sample(x as f64, y as f64) - self.cut
    }
}

/// The Jacobians of a field's covered pixels ([`synth::jacobian`]), held
/// compactly: per pixel an index into the list of Jacobians
/// ([`NO_JACOBIAN`] for none), so a thin stroke across a large canvas does
/// not hold a Jacobian per canvas pixel.
struct Jacobians {
    width: usize,
    index: Vec<u32>,
    list: Vec<synth::Jacobian>,
}

/// The index of a pixel without a Jacobian.
const NO_JACOBIAN: u32 = u32::MAX;

impl Jacobians {
    /// Measures every covered pixel's Jacobian.
    fn of(style: &BrushStyle, field: &Field) -> Jacobians {
        let (w, h) = (field.coords.width(), field.coords.height());
        let rows: Vec<Vec<(usize, synth::Jacobian)>> = (0..h)
            .into_par_iter()
            .map(|y| {
                (0..w)
                    .filter_map(|x| synth::jacobian(style, field, x, y).map(|j| (x, j)))
                    .collect()
            })
            .collect();
        let mut index = vec![NO_JACOBIAN; w * h];
        let mut list = Vec::with_capacity(rows.iter().map(Vec::len).sum());
        for (y, row) in rows.into_iter().enumerate() {
            for (x, j) in row {
                index[y * w + x] = list.len().min(NO_JACOBIAN as usize - 1) as u32;
                list.push(j);
            }
        }
        Jacobians {
            width: w,
            index,
            list,
        }
    }

    /// The Jacobian of pixel `(x, y)`, if measured.
    fn get(&self, x: isize, y: isize) -> Option<synth::Jacobian> {
        if x < 0 || y < 0 || x as usize >= self.width {
            return None;
        }
        let i = *self.index.get(y as usize * self.width + x as usize)?;
        self.list.get(i as usize).copied()
    }
}

/// An output pixel beyond this many output px of all ink has every layer
/// written as the all-ink distance (a lower bound, and paper): no contour
/// runs through such a pixel's cells, and its layers need no reading.
const FAR: f32 = 4.0;

/// Where one exemplar's layers are read: its top level's scale to the
/// finest, and its finest all-ink SDF and SDF of each palette colour.
struct Source<'a> {
    to_fine: f32,
    ink: &'a Grid<f32>,
    layers: Vec<Option<&'a Grid<f32>>>,
}

/// An exemplar SDF `g` (finest px) at `(x, y)`, continued beyond the
/// exemplar's image: outside it, the distance at the nearest point of the
/// image's edge, no less than paper, combined with the distance to that
/// edge. Ink that touches the edge then ends there instead of running on
/// as a band of the edge's samples (a wedge of solid ink wherever a
/// continued coordinate leaves the image).
fn sample_beyond(g: &Grid<f32>, x: f32, y: f32) -> f32 {
    Beyond::at(g.width(), g.height(), x, y).read_sized(g)
}

/// [`sample_beyond`] at one position prepared for every exemplar SDF of
/// one size (an exemplar's ink and its layers): the bilinear read at the
/// position, or at the nearest point of the image's edge with the
/// distance to it.
#[derive(Clone, Copy)]
struct Beyond {
    at: Bilinear,
    /// Distance from the position to the image (px), 0 inside it.
    out: f32,
    size: (usize, usize),
    x: f32,
    y: f32,
}

impl Beyond {
    /// The read at `(x, y)` (finest px) of a `w`×`h` image.
    fn at(w: usize, h: usize, x: f32, y: f32) -> Beyond {
        // Inside the image the clamp leaves the position as it is.
        let (cx, cy) = (x.clamp(0.0, w as f32), y.clamp(0.0, h as f32));
        Beyond {
            at: Bilinear::at(w, h, cx as f64, cy as f64),
            out: (x - cx).hypot(y - cy),
            size: (w, h),
            x,
            y,
        }
    }

    /// [`sample_beyond`] of `g` at this position.
    fn read(&self, g: &Grid<f32>) -> f32 {
        if (g.width(), g.height()) == self.size {
            self.read_sized(g)
        } else {
            sample_beyond(g, self.x, self.y)
        }
    }

    /// The read of `g`, which has this read's size.
    fn read_sized(&self, g: &Grid<f32>) -> f32 {
        let v = g.read(&self.at);
        if self.out > 0.0 {
            v.max(0.0).hypot(self.out)
        } else {
            v
        }
    }
}

/// The layers' SDFs (in the order of the style's palette, output px) read
/// through a synthesized (already extended) field onto the output grid,
/// the canvas subdivided `sub` times; `PAPER` off the ornament.
///
/// Every canvas pixel `q` continues its coordinate to any point `p` of the
/// plane, `μ(q) + J(q)(p − q)` (its patch carried on by its Jacobian,
/// [`synth::jacobian`]); an output pixel's centre `p` takes the exemplar
/// distances at the continuations of the four canvas pixels around it
/// (bilinear in the finest exemplar level), averaged with the bilinear
/// weights of `p` between their centres. Inside a coherent patch every
/// continuation is the same point and the read is the exemplar's own
/// outline at continuous coordinates, whatever the canvas resolution (no
/// pixel staircase); across a seam the two patches are cross-faded over a
/// canvas pixel, so outlines cross it without steps, and a lone pixel whose
/// μ landed on another layer's ink is outvoted (the output reading of
/// decobrush.txt §5.4: colours are read through μ, §7). A neighbour whose
/// exemplar lacks a colour gives paper for it. The field's Jacobians are
/// measured beforehand (`jac`). Every layer is intersected with the
/// continuation's reach ([`Reach`]), so ink the continuation carries out
/// of the covered region ends on a smooth line, not on the staircase of
/// its last ring.
fn read_layers(
    style: &BrushStyle,
    field: &Field,
    jac: &Jacobians,
    sub: usize,
    reach: &Reach,
) -> Vec<Grid<i16>> {
    let palette = &style.facts.palette;
    let g = &field.coords;
    let (w, h) = (g.width(), g.height());
    let k = sub.max(1);
    let (ow, oh) = (w * k, h * k);
    let sources: Vec<Option<Source>> = style
        .exemplars
        .iter()
        .map(|e| {
            let fine = e.finest()?;
            let lv = e.levels.get(field.level)?;
            Some(Source {
                to_fine: (1.0 / lv.scale) as f32,
                ink: &fine.ink.ink,
                layers: palette
                    .iter()
                    .map(|c| {
                        fine.ink
                            .layers
                            .iter()
                            .find(|l| l.color == *c)
                            .map(|l| &l.sdf)
                    })
                    .collect(),
            })
        })
        .collect();
    // Output px per finest exemplar px (the exemplars share their scales).
    let to_out = sources
        .iter()
        .flatten()
        .next()
        .map_or(1.0, |s| k as f32 / s.to_fine);
    let paper = PAPER * to_out;
    let n = palette.len();
    let src = |e: usize| sources.get(e).and_then(Option::as_ref);
    // The covered columns of each canvas row, `[lo, hi)`: an output row
    // reads only the span of the two canvas rows around it.
    let spans: Vec<(usize, usize)> = (0..h)
        .map(|y| {
            let row = &g.data()[y * w..(y + 1) * w];
            match (
                row.iter().position(Option::is_some),
                row.iter().rposition(Option::is_some),
            ) {
                (Some(a), Some(b)) => (a, b + 1),
                _ => (w, 0),
            }
        })
        .collect();
    let mut grids: Vec<Vec<i16>> = (0..n).map(|_| vec![pack(paper); ow * oh]).collect();
    // Row `oy` of every layer, to be written by one task.
    let mut rows: Vec<Vec<&mut [i16]>> = (0..oh).map(|_| Vec::with_capacity(n)).collect();
    for grid in &mut grids {
        for (row, chunk) in rows.iter_mut().zip(grid.chunks_mut(ow.max(1))) {
            row.push(chunk);
        }
    }
    rows.into_par_iter().enumerate().for_each(|(oy, mut out)| {
        let py = (oy as f32 + 0.5) / k as f32 - 0.5;
        let j0 = py.floor();
        let fy = py - j0;
        let j0 = j0 as isize;
        let span = |j: isize| {
            usize::try_from(j)
                .ok()
                .and_then(|j| spans.get(j).copied())
                .unwrap_or((w, 0))
        };
        let (a, b) = (span(j0), span(j0 + 1));
        let (lo, hi) = (a.0.min(b.0), a.1.max(b.1));
        if lo >= hi {
            return;
        }
        // Output columns whose four canvas pixels may reach the span.
        let (x0, x1) = ((lo * k).saturating_sub(k), ((hi + 1) * k).min(ow));
        // Continuations: exemplar, finest position, weight.
        let mut taps: Vec<(usize, Beyond, f32)> = Vec::with_capacity(4);
        for ox in x0..x1 {
            let px = (ox as f32 + 0.5) / k as f32 - 0.5;
            let i0 = px.floor();
            let fx = px - i0;
            let i0 = i0 as isize;
            taps.clear();
            for (di, dj, wt) in [
                (0isize, 0isize, (1.0 - fx) * (1.0 - fy)),
                (1, 0, fx * (1.0 - fy)),
                (0, 1, (1.0 - fx) * fy),
                (1, 1, fx * fy),
            ] {
                if wt <= 0.0 {
                    continue;
                }
                let (i, j) = (i0 + di, j0 + dj);
                let Some(c) = g.get_or(i, j, None) else {
                    continue;
                };
                let Some(jm) = jac.get(i, j) else {
                    continue;
                };
                let Some(s) = src(c.exemplar as usize) else {
                    continue;
                };
                let d = synth::apply(jm, [fx - di as f32, fy - dj as f32]);
                let (x, y) = ((c.x + d[0]) * s.to_fine, (c.y + d[1]) * s.to_fine);
                let at = Beyond::at(s.ink.width(), s.ink.height(), x, y);
                taps.push((c.exemplar as usize, at, wt));
            }
            if taps.is_empty() {
                continue;
            }
            let wsum: f32 = taps.iter().map(|t| t.2).sum();
            // Layer `l`, or all ink for `None`.
            let read = |l: Option<usize>| -> f32 {
                taps.iter()
                    .map(|&(e, at, wt)| {
                        wt * src(e)
                            .and_then(|s| match l {
                                None => Some(s.ink),
                                Some(l) => s.layers.get(l).copied().flatten(),
                            })
                            .map_or(PAPER, |g| at.read(g))
                    })
                    .sum::<f32>()
                    / wsum
                    * to_out
            };
            // Beyond the continuation's reach the ornament is cut along
            // a smooth line, output px.
            let cut = reach.beyond(px + 0.5, py + 0.5) * k as f32;
            let ink = read(None).max(cut);
            if ink >= FAR {
                for row in out.iter_mut() {
                    row[ox] = pack(ink);
                }
                continue;
            }
            for (l, row) in out.iter_mut().enumerate() {
                row[ox] = pack(read(Some(l)).max(cut));
            }
        }
    });
    grids
        .into_iter()
        .map(|data| Grid::from_vec(ow, oh, data).unwrap_or_else(|| Grid::new(ow, oh, pack(paper))))
        .collect()
}

/// Output px per unit of a layer distance as [`read_layers`] holds it:
/// each layer of a query's output grid is kept in 16 bits (distances to
/// ±128 px in steps of 1/256 px, far below the tracing tolerance), half
/// the memory of 32-bit floats, and widened one layer at a time for
/// tracing.
const LAYER_STEP: f32 = 1.0 / 256.0;

/// A layer distance (output px) in [`LAYER_STEP`]s, clamped to 16 bits,
/// with its sign kept: ink (below zero) stays ink however close to the
/// outline, so the ink mask, and what is measured on it, is the same as
/// the unrounded layer's.
fn pack(v: f32) -> i16 {
    let q = (v / LAYER_STEP)
        .round()
        .clamp(f32::from(i16::MIN), f32::from(i16::MAX)) as i16;
    if v < 0.0 {
        q.min(-1)
    } else {
        q.max(0)
    }
}

/// A layer's distances in output px.
fn unpack(g: &Grid<i16>) -> Grid<f32> {
    g.map(|v| f32::from(v) * LAYER_STEP)
}

/// The final per-layer SDFs of a query on its output grid (see
/// [`final_layers_with`]).
#[cfg(test)]
pub fn final_layers(style: &BrushStyle, r: &QueryResult) -> Vec<(Color, Grid<f32>)> {
    final_layers_with(style, r, r.field.clone())
        .into_iter()
        .map(|(c, g)| (c, unpack(&g)))
        .collect()
}

/// Output px per finest exemplar px of a query's output grid.
pub fn out_per_fine(style: &BrushStyle, r: &QueryResult) -> f64 {
    let s = style
        .exemplars
        .first()
        .and_then(|e| e.levels.get(r.field.level))
        .map_or(1.0, |lv| lv.scale);
    r.sub.max(1) as f64 * s
}

/// Largest debris, as a share of a stroke width: a piece under a square
/// this many widths on a side is a speck beside the stroke, whatever the
/// exemplars' pieces measure. In a library of single-piece exemplars (a
/// hairline lattice, a scroll) the smallest drawn element is a whole
/// exemplar, larger than a stroke width squared, and a seam that leaves a
/// stretch of line apart leaves a piece smaller than that: by the
/// exemplars' pieces alone, whole stretches of the stroke would be
/// cleared.
pub const DEBRIS_WIDTH: f64 = 0.5;

/// The area under which an output piece is debris, finest px²: the
/// exemplars' smallest drawn element
/// ([`crate::brush::analysis::facts::StyleFacts::smallest_piece`]), at
/// most a square of [`DEBRIS_WIDTH`] exemplar widths.
pub fn debris_area(style: &BrushStyle) -> f64 {
    let side = DEBRIS_WIDTH * style.facts.width;
    (style.facts.smallest_piece as f64).min(side * side)
}

/// The final per-layer SDFs of a query on its output grid (output px),
/// bottom layer first, with their colours: each layer read through the
/// continued field ([`read_layers`]); then a last, documented cleanup: ink
/// components smaller than [`debris_area`] (the threshold taken from the
/// style, not a constant) are synthesis debris and are cleared; the
/// query's largest piece is its body and always stays. `field` is the
/// query's field (or a copy of it), used up.
fn final_layers_with(style: &BrushStyle, r: &QueryResult, field: Field) -> Vec<(Color, Grid<i16>)> {
    let rings = border_rings(r);
    let field_user = field.user.clone();
    let reach = Reach::of(&field.coords, rings);
    let field = extend_owned(style, field, rings);
    let jac = Jacobians::of(style, &field);
    let read = read_layers(style, &field, &jac, r.sub, &reach);
    drop(reach);
    drop(jac);
    let mut layers: Vec<(Color, Grid<i16>)> =
        style.facts.palette.iter().copied().zip(read).collect();
    let Some((_, first)) = layers.first() else {
        return layers;
    };
    let (w, h) = (first.width(), first.height());
    let scale = out_per_fine(style, r);
    let ink_pieces = |layers: &[(Color, Grid<i16>)]| {
        components(&Grid::from_fn(w, h, |x, y| {
            layers.iter().any(|(_, g)| g.get(x, y) < 0)
        }))
    };
    let mut comps = ink_pieces(&layers);
    if bridge_fragments(style, &mut layers, &comps, scale) {
        comps = ink_pieces(&layers);
    }
    // A query shorter than every exemplar can have a body smaller than
    // the exemplars' smallest piece: the largest piece always stays.
    let largest = comps.iter().map(Vec::len).max().unwrap_or(0);
    let smallest = (debris_area(style) * scale * scale).round() as usize;
    let min = smallest.min(largest);
    // A piece drawn where a refinement sketch asked for ink is the
    // user's, not debris.
    let sub = r.sub.max(1);
    let asked = |i: usize| {
        field_user
            .as_ref()
            .is_some_and(|u| u.get_or(((i % w) / sub) as isize, ((i / w) / sub) as isize, false))
    };
    for comp in comps {
        if comp.len() >= min || comp.iter().any(|&i| asked(i)) {
            continue;
        }
        for (_, g) in &mut layers {
            for &i in &comp {
                if let Some(v) = g.data_mut().get_mut(i) {
                    *v = (*v).max(pack(0.5));
                }
            }
        }
    }
    layers
}

/// How far a fragment's nearest ink may lie for [`bridge_fragments`] to
/// join them, in the style's thinnest lines: a seam that cuts a line
/// leaves its two ends about a line apart.
pub const BRIDGE_LINES: f64 = 3.0;

/// Joins each fragment to the ink it was cut from: an ink piece smaller
/// than the exemplars' smallest drawn element
/// ([`crate::brush::analysis::facts::StyleFacts::smallest_piece`]) is a
/// stretch of line a seam left apart (decobrush.txt §5 cuts between
/// patches wherever they differ least, which on a hairline is across it).
/// Its nearest ink of another piece, if within [`BRIDGE_LINES`] of the
/// style's thinnest lines, is joined to it ([`bridge`]). Pieces as large
/// as an exemplar element are never joined, so separate leaves and dots
/// stay apart; specks under [`debris_area`] are left to the cleanup.
/// `scale`: output px per finest exemplar px.
/// `comps`: the layers' ink pieces ([`components`]). True when a bar was
/// drawn.
fn bridge_fragments(
    style: &BrushStyle,
    layers: &mut [(Color, Grid<i16>)],
    comps: &[Vec<usize>],
    scale: f64,
) -> bool {
    let px = |a: f64| (a * scale * scale).round() as usize;
    let sizes = Fragments {
        fragment: px(style.facts.smallest_piece as f64),
        speck: px(debris_area(style)),
        line: (style.facts.thinnest_line * scale).max(1.0),
    };
    bridge(layers, comps, sizes)
}

/// What [`bridge`] joins, output px.
#[derive(Clone, Copy, Debug)]
struct Fragments {
    /// Pieces smaller than this many px² are fragments.
    fragment: usize,
    /// Pieces smaller than this many px² are specks, cleared rather
    /// than joined, and never a fragment's target.
    speck: usize,
    /// The thinnest line's thickness, px.
    line: f64,
}

/// Joins each fragment (a piece of `sizes.speck` ..
/// `sizes.fragment` px², never the largest) to the nearest pixel of
/// another piece that is not a speck, if within [`BRIDGE_LINES`] lines,
/// by a bar as thick as the thinner of the two pieces there and no wider
/// than the gap is long (ends that nearly touch get a thin join, not a
/// knob), drawn into the layer that inks the fragment at its end: the
/// union of that layer's distance and the bar's. `comps`: the layers'
/// ink pieces ([`components`]). True when a bar was drawn.
fn bridge(layers: &mut [(Color, Grid<i16>)], comps: &[Vec<usize>], sizes: Fragments) -> bool {
    let Some((_, first)) = layers.first() else {
        return false;
    };
    let (w, h) = (first.width(), first.height());
    let Fragments {
        fragment,
        speck: specks,
        line,
    } = sizes;
    // A short query's body can be smaller than the exemplars' smallest
    // piece; it is never a fragment.
    let largest = comps.iter().map(Vec::len).max().unwrap_or(0);
    let is_fragment = |c: &Vec<usize>| c.len() >= specks && c.len() < fragment.min(largest);
    if !comps.iter().any(is_fragment) {
        return false;
    }
    let reach = BRIDGE_LINES * line;
    // The layer that inks a pixel most deeply, which a bar from it is
    // drawn into.
    let colour = |i: usize| {
        (0..layers.len())
            .min_by_key(|&l| layers[l].1.data()[i])
            .unwrap_or(0)
    };
    // How deep a pixel lies in ink, px.
    let depth_at = |i: usize| {
        layers
            .iter()
            .map(|(_, g)| -f64::from(g.data()[i]) * f64::from(LAYER_STEP))
            .fold(0.0f64, f64::max)
    };
    let mut label = vec![u32::MAX; w * h];
    for (k, c) in comps.iter().enumerate() {
        for &i in c {
            label[i] = k as u32;
        }
    }
    let mut bars = Vec::new();
    for (k, c) in comps.iter().enumerate() {
        if !is_fragment(c) {
            continue;
        }
        if let Some((p, q, gap)) = nearest_other(c, k, &label, comps, specks, w, h, reach) {
            // The bar is as thick as the thinner of the two lines it joins.
            let depth = |piece: &[usize], at: usize| {
                let (ax, ay) = ((at % w) as f64, (at / w) as f64);
                piece
                    .iter()
                    .filter(|&&i| {
                        let (dx, dy) = ((i % w) as f64 - ax, (i / w) as f64 - ay);
                        dx * dx + dy * dy <= reach * reach
                    })
                    .map(|&i| depth_at(i))
                    .fold(0.0f64, f64::max)
            };
            // and no wider than the gap is long, so that ends which nearly
            // touch get a thin join, not a knob; at least 1.5 px across, so
            // that ends touching only at a pixel's corner join edge to edge.
            let radius = depth(c, p)
                .min(depth(&comps[label[q] as usize], q))
                .min(0.5 * gap)
                .max(0.75);
            bars.push((p, q, radius, colour(p)));
        }
    }
    let drawn = !bars.is_empty();
    for (p, q, radius, l) in bars {
        let (px, py) = ((p % w) as f64 + 0.5, (p / w) as f64 + 0.5);
        let (qx, qy) = ((q % w) as f64 + 0.5, (q / w) as f64 + 0.5);
        let Some((_, g)) = layers.get_mut(l) else {
            continue;
        };
        let pad = radius + 1.0;
        let x0 = (px.min(qx) - pad).floor().max(0.0) as usize;
        let y0 = (py.min(qy) - pad).floor().max(0.0) as usize;
        let x1 = ((px.max(qx) + pad).ceil() as usize).min(w);
        let y1 = ((py.max(qy) + pad).ceil() as usize).min(h);
        let seg = kurbo::Line::new((px, py), (qx, qy));
        for y in y0..y1 {
            for x in x0..x1 {
                let c = kurbo::Point::new(x as f64 + 0.5, y as f64 + 0.5);
                let d = crate::raster::sdf::point_segment_distance(c, seg) - radius;
                let v = &mut g.data_mut()[y * w + x];
                *v = (*v).min(pack(d as f32));
            }
        }
    }
    drawn
}

/// The closest pair (fragment pixel, pixel of another piece, their
/// distance in px) for piece `k` (pixel indices `piece`, labels `label`
/// on a `w` × `h` grid), the other piece's pixel at most `reach` px from
/// the fragment's: a
/// breadth-first sweep over paper from all the piece's pixels, each
/// visited pixel carrying its nearest piece pixel.
#[allow(clippy::too_many_arguments)]
fn nearest_other(
    piece: &[usize],
    k: usize,
    label: &[u32],
    comps: &[Vec<usize>],
    specks: usize,
    w: usize,
    h: usize,
    reach: f64,
) -> Option<(usize, usize, f64)> {
    let r = reach.ceil() as usize + 1;
    let (mut x0, mut y0, mut x1, mut y1) = (usize::MAX, usize::MAX, 0, 0);
    for &i in piece {
        let (x, y) = (i % w, i / w);
        x0 = x0.min(x);
        y0 = y0.min(y);
        x1 = x1.max(x);
        y1 = y1.max(y);
    }
    let (bx0, by0) = (x0.saturating_sub(r), y0.saturating_sub(r));
    let (bx1, by1) = ((x1 + r + 1).min(w), (y1 + r + 1).min(h));
    let bw = bx1 - bx0;
    let local = |i: usize| (i / w - by0) * bw + (i % w - bx0);
    let mut src = vec![usize::MAX; bw * (by1 - by0)];
    let mut queue = std::collections::VecDeque::new();
    for &i in piece {
        src[local(i)] = i;
        queue.push_back(i);
    }
    let dist2 = |a: usize, b: usize| {
        let (dx, dy) = (
            (a % w) as f64 - (b % w) as f64,
            (a / w) as f64 - (b / w) as f64,
        );
        dx * dx + dy * dy
    };
    let mut best: Option<(f64, usize, usize)> = None;
    while let Some(i) = queue.pop_front() {
        let s = src[local(i)];
        let (x, y) = (i % w, i / w);
        for (dx, dy) in [
            (-1, 0),
            (1, 0),
            (0, -1),
            (0, 1),
            (-1, -1),
            (1, -1),
            (-1, 1),
            (1, 1),
        ] {
            let (nx, ny) = (x as isize + dx, y as isize + dy);
            if nx < bx0 as isize || ny < by0 as isize || nx >= bx1 as isize || ny >= by1 as isize {
                continue;
            }
            let j = ny as usize * w + nx as usize;
            let d2 = dist2(s, j);
            if d2 > reach * reach {
                continue;
            }
            if label[j] != u32::MAX && label[j] as usize != k {
                if comps[label[j] as usize].len() >= specks && best.is_none_or(|(b, _, _)| d2 < b) {
                    best = Some((d2, s, j));
                }
                continue;
            }
            let lj = local(j);
            if label[j] == u32::MAX && src[lj] == usize::MAX {
                src[lj] = s;
                queue.push_back(j);
            }
        }
    }
    best.map(|(d2, p, q)| (p, q, d2.sqrt()))
}

/// Traces a synthesized query into one group of filled shapes, bottom
/// layer first.
pub fn trace_query(style: &BrushStyle, r: &QueryResult, id: String, opts: &TraceOptions) -> Group {
    trace_field(style, r, r.field.clone(), id, opts)
}

/// [`trace_query`] with the query's field (or a copy of it) used up.
fn trace_field(
    style: &BrushStyle,
    r: &QueryResult,
    field: Field,
    id: String,
    opts: &TraceOptions,
) -> Group {
    let to_user = r.out_canvas().to_user();
    let mut shapes = Vec::new();
    for (color, layer) in final_layers_with(style, r, field) {
        let sdf = Sdf {
            dist: unpack(&layer),
            to_user,
        };
        drop(layer);
        for p in trace_sdf(&sdf, opts) {
            shapes.push(Shape {
                fill_rule: FillRule::NonZero,
                ..Shape::filled(p, color)
            });
        }
    }
    super::swell::apply(&r.spine, &mut shapes);
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
    r: QueryResult,
    tree: &resvg::usvg::Tree,
    opts: &Settings,
) -> QueryResult {
    let sopts = crate::brush::synth::SynthOptions {
        seed: opts.seed,
        ..opts.synth.clone()
    };
    let mut r = to_finest(style, r);
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

/// Refines (when asked) and traces one synthesized query, dropping its
/// fields when [`Settings::discard_fields`] says so.
fn finish_query(
    style: &BrushStyle,
    r: QueryResult,
    refine: Option<&resvg::usvg::Tree>,
    opts: &Settings,
    trace: &TraceOptions,
) -> (QueryResult, Group) {
    let mut r = match refine {
        Some(tree) => refine_one(style, r, tree, opts),
        None => r,
    };
    let id = if r.spine.query_id.is_empty() {
        "q".to_string()
    } else {
        r.spine.query_id.clone()
    };
    let group = if opts.discard_fields {
        let empty = Field {
            level: r.field.level,
            coords: Grid::new(0, 0, None),
            orient: Grid::new(0, 0, [0.0; 2]),
            seam: Grid::new(0, 0, false),
            user: None,
        };
        let field = std::mem::replace(&mut r.field, empty);
        r.levels = Vec::new();
        trace_field(style, &r, field, id, trace)
    } else {
        trace_query(style, &r, id, trace)
    };
    (r, group)
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
    // The cost is stated before any synthesis: the canvases of all the
    // strokes together.
    fn part(q: &QuerySpine) -> impl Fn(Error) -> Error + '_ {
        move |e| e.in_part(format!("query {}", q.query_id))
    }
    let layouts = spines
        .iter()
        .map(|q| layout(style, q, opts).map_err(part(q)))
        .collect::<Result<Vec<_>>>()?;
    let mut total = 0u64;
    let mut largest = (0u64, "");
    for (q, l) in spines.iter().zip(&layouts) {
        let px = l.pixels();
        total = total.saturating_add(px);
        if px > largest.0 {
            largest = (px, &q.query_id);
        }
    }
    if total > MAX_SKETCH_PIXELS {
        return Err(Error::invalid(format!(
            "its strokes need {} Mpx of canvas (query {}: {} Mpx), more than the {} Mpx one sketch may take (brush fewer, shorter or wider strokes)",
            total >> 20,
            largest.1,
            largest.0 >> 20,
            MAX_SKETCH_PIXELS >> 20
        )));
    }
    let tally = crate::io::Tally::new("brush: strokes synthesized", spines.len());
    let done: Vec<Vec<(QueryResult, Group)>> = spines
        .par_iter()
        .zip(&layouts)
        .map(|(q, l)| {
            // A shape's own `data-seed` stands in for the run's.
            let own;
            let opts = match q.seed {
                Some(seed) if seed != opts.seed => {
                    own = Settings {
                        seed,
                        ..opts.clone()
                    };
                    &own
                }
                _ => opts,
            };
            crate::io::check(&opts.cancel)?;
            let mut out = Vec::new();
            let mut finish =
                |r: QueryResult| out.push(finish_query(style, r, refine, opts, &trace));
            match l {
                Layout::Whole(_) => {
                    let r = brush_query(style, q, opts).map_err(part(q))?;
                    crate::io::check(&opts.cancel)?;
                    finish(r)
                }
                Layout::Pieces(pieces) => {
                    in_pieces(style, q, opts, pieces, &mut finish).map_err(part(q))?
                }
            }
            tally.tick();
            Ok(out)
        })
        .collect::<Result<Vec<_>>>()?;
    let done: Vec<(QueryResult, Group)> = done.into_iter().flatten().collect();
    let ppu = done
        .iter()
        .map(|(r, _)| r.out_canvas().px_per_unit)
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

#[cfg(test)]
mod bridge_tests {
    use super::*;

    /// One layer on a 60 × 20 grid: horizontal lines `[x0, x1] × [7, 9]`
    /// (px, a 2-px line), as exact signed distances packed like
    /// [`read_layers`]'s.
    fn lines(spans: &[(f64, f64)]) -> Vec<(Color, Grid<i16>)> {
        let g = Grid::from_fn(60, 20, |x, y| {
            let (cx, cy) = (x as f64 + 0.5, y as f64 + 0.5);
            let d = spans
                .iter()
                .map(|&(x0, x1)| {
                    let dx = (x0 - cx).max(cx - x1);
                    let dy = (7.0 - cy).max(cy - 9.0);
                    if dx > 0.0 && dy > 0.0 {
                        dx.hypot(dy)
                    } else {
                        dx.max(dy)
                    }
                })
                .fold(f64::MAX, f64::min);
            pack(d as f32)
        });
        vec![(Color::BLACK, g)]
    }

    fn ink_pieces(layers: &[(Color, Grid<i16>)]) -> Vec<Vec<usize>> {
        let g = &layers[0].1;
        components(&Grid::from_fn(g.width(), g.height(), |x, y| {
            g.get(x, y) < 0
        }))
    }

    fn pieces(layers: &[(Color, Grid<i16>)]) -> Vec<usize> {
        ink_pieces(layers).iter().map(Vec::len).collect()
    }

    const SIZES: Fragments = Fragments {
        fragment: 40,
        speck: 6,
        line: 2.0,
    };

    /// A stretch of line cut off by a gap under [`BRIDGE_LINES`] lines is
    /// joined to the line it was cut from, by a bar that inks only the gap
    /// on the line's rows; distances elsewhere are untouched.
    #[test]
    fn a_fragment_near_its_line_is_joined() {
        let mut layers = lines(&[(2.0, 40.0), (44.0, 56.0)]);
        let before = layers[0].1.clone();
        assert_eq!(pieces(&layers), vec![76, 24]);
        let comps = ink_pieces(&layers);
        assert!(bridge(&mut layers, &comps, SIZES));
        assert_eq!(pieces(&layers).len(), 1);
        let g = &layers[0].1;
        for y in 0..20 {
            for x in 0..60 {
                let inked = g.get(x, y) < 0 && before.get(x, y) >= 0;
                // New ink only between the two ends, on the line's rows.
                assert!(
                    !inked || ((40..=43).contains(&x) && (7..=8).contains(&y)),
                    "ink off the gap at {x},{y}"
                );
                // Distances change only around the bar.
                let changed = g.get(x, y) != before.get(x, y);
                assert!(
                    !changed || ((37..=46).contains(&x) && (5..=10).contains(&y)),
                    "{x},{y}"
                );
            }
        }
    }

    /// Nothing is joined across a gap wider than [`BRIDGE_LINES`] lines,
    /// to a speck, or between two pieces of an exemplar element's size.
    #[test]
    fn far_pieces_specks_and_elements_stay_apart() {
        for (spans, sizes) in [
            // 8 px apart: more than three 2-px lines.
            (vec![(2.0, 40.0), (48.0, 56.0)], SIZES),
            // The near piece is a speck (4 px²).
            (vec![(2.0, 40.0), (43.0, 45.0)], SIZES),
            // Both pieces are at least an element.
            (
                vec![(2.0, 40.0), (44.0, 56.0)],
                Fragments {
                    fragment: 24,
                    ..SIZES
                },
            ),
        ] {
            let mut layers = lines(&spans);
            let before = layers[0].1.clone();
            let comps = ink_pieces(&layers);
            assert!(!bridge(&mut layers, &comps, sizes));
            assert_eq!(layers[0].1, before, "{spans:?}");
        }
    }
}
