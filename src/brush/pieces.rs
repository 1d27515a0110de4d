//! Long strokes in pieces: a stroke whose canvas (its bounding box) would
//! not fit the size limit or the memory budget even at the start level —
//! a thin line across a whole drawing — is synthesized on a chain of small
//! canvases that follow its spine, at the level the output asks for.
//!
//! The whole stroke is matched once (§5.1), so its ends, and only its ends,
//! get end ornament. The spine's samples are cut into consecutive pieces;
//! each piece's canvas covers its own samples, an overlap into the next
//! piece and some context, on one pixel lattice shared by all pieces (so
//! the fields of two pieces line up pixel for pixel at every level). A
//! piece is initialized from the warped segments that reach it (§5.2–5.3)
//! and synthesized level by level (§5.4) like a whole query, except that
//! the pixels the previous piece owns are locked to the previous piece's
//! coordinates at every level, as the user's unchanged pixels are in a
//! refinement (§5.5): the new piece grows out of the old one coherently.
//! Each piece keeps the pixels nearest to its own samples and half the
//! overlap; in that half both pieces hold the same coordinates, so the
//! traced ornament of the two overlaps itself exactly and shows no joint.

use super::analysis::BrushStyle;
use super::pipeline::{
    init_field, matched, query_share, samples_box, Canvas, Plan, QueryResult, Settings,
    BYTES_PER_CANVAS_PX, SEAM_MARGIN,
};
use super::query::QuerySpine;
use super::synth::{self, Field, SynthOptions};
use crate::error::{Error, Result};
use crate::raster::Grid;
use kurbo::Point;

/// Largest canvas of one piece, top-level pixels in all (1 Mpx: a piece of
/// a diagonal stroke 24 px wide is then about 40 widths long).
pub const PIECE_PIXELS: u64 = 1 << 20;

/// Most top-level canvas pixels of all the strokes of one sketch
/// together, pieces included (64 Mpx): the command's time grows with
/// them, so a sketch that needs more is refused, with the figure and its
/// largest stroke named, before any synthesis.
pub const MAX_SKETCH_PIXELS: u64 = 64 << 20;

/// Stroke widths by which a piece reaches into the next: the next piece
/// locks them to this piece's coordinates.
const OVERLAP_WIDTHS: f64 = 1.0;

/// Stroke widths a piece synthesizes beyond its overlap, so that the
/// locked pixels are interior to the piece they come from.
const CONTEXT_WIDTHS: f64 = 1.0;

/// Distance from the spine, stroke widths, within which a pixel belongs to
/// its nearest sample: beyond the ornament's reach (1.5 widths, the canvas
/// margin) with room to spare.
const LABEL_WIDTHS: f64 = 2.0;

/// Label of a pixel too far from every sample.
const NO_SAMPLE: u32 = u32::MAX;

/// One piece of a long stroke: its canvas, and the samples its canvas
/// covers (`lo..=hi`) and keeps in its output (`keep`: from its first
/// own sample to half the overlap into the next piece).
#[derive(Clone, Debug, PartialEq)]
pub struct Piece {
    canvas: Canvas,
    lo: usize,
    hi: usize,
    keep: std::ops::Range<usize>,
    /// Samples below this one are the previous piece's: locked.
    locked: usize,
}

/// A piece once synthesized: what the next one reads.
struct Done {
    canvas: Canvas,
    /// Corrected fields, start level to top.
    levels: Vec<Field>,
}

/// How a query is synthesized: on one canvas, or in pieces.
#[derive(Clone, Debug, PartialEq)]
pub enum Layout {
    /// One canvas ([`super::pipeline::brush_query`]) of this many pixels.
    Whole(u64),
    /// These pieces ([`in_pieces`]).
    Pieces(Vec<Piece>),
}

impl Layout {
    /// Top-level canvas pixels in all (the cost the sketch's budget
    /// counts).
    pub fn pixels(&self) -> u64 {
        match self {
            Layout::Whole(n) => *n,
            Layout::Pieces(pieces) => pieces
                .iter()
                .map(|p| p.canvas.width as u64 * p.canvas.height as u64)
                .sum(),
        }
    }
}

/// How `q` is synthesized under `opts`: whole when its canvas fits (at
/// the level the output asks for or a coarser one), else in pieces at
/// the level the output asks for ([`Settings::pieces`] forces pieces).
pub fn layout(style: &BrushStyle, q: &QuerySpine, opts: &Settings) -> Result<Layout> {
    let plan = Plan::of(style, q, opts)?;
    if opts.pieces.is_none() {
        match plan.whole_canvas(style, q) {
            Ok((c, _)) => return Ok(Layout::Whole(c.width as u64 * c.height as u64)),
            Err(e) if opts.art_brush => return Err(e),
            Err(_) => {}
        }
    }
    let (ppu, factor) = piece_scale(style, q, plan);
    Ok(Layout::Pieces(cut(q, ppu, factor, piece_pixels(opts))?))
}

/// Top-level px per sketch unit and top over start pixel size of `q`'s
/// pieces.
fn piece_scale(style: &BrushStyle, q: &QuerySpine, plan: Plan) -> (f64, usize) {
    let factor = 1usize << (plan.top - plan.start);
    (plan.width_at(style, plan.top) / q.width, factor)
}

/// Largest piece under `opts`, top-level px: [`PIECE_PIXELS`], or
/// fewer when [`query_share`] of the memory budget does not hold that
/// many.
fn piece_pixels(opts: &Settings) -> u64 {
    let share = query_share() / BYTES_PER_CANVAS_PX;
    opts.pieces.unwrap_or(PIECE_PIXELS).min(share).max(1)
}

/// Synthesizes `q` piece by piece on `pieces` (its [`layout`]; see the
/// module docs), handing each piece's result to `emit` as soon as it is
/// done, so only two pieces' fields are held at a time.
pub fn in_pieces(
    style: &BrushStyle,
    q: &QuerySpine,
    opts: &Settings,
    pieces: &[Piece],
    emit: &mut dyn FnMut(QueryResult),
) -> Result<()> {
    let plan = Plan::of(style, q, opts)?;
    let (start, top) = (plan.start, plan.top);
    let factor = 1usize << (top - start);
    let (ribs, m) = matched(style, q, opts, plan.ew)?;
    let sopts = SynthOptions {
        seed: opts.seed,
        ..opts.synth.clone()
    };
    let mut prev: Option<Done> = None;
    for p in pieces {
        crate::io::check(&opts.cancel)?;
        let c = p.canvas;
        let what = format!(
            "the {}×{} px canvas of a piece of query {}",
            c.width, c.height, q.query_id
        );
        crate::memory::check(
            &what,
            (c.width as u64 * c.height as u64).saturating_mul(BYTES_PER_CANVAS_PX),
        )?;
        let segs: Vec<_> = m
            .segments
            .iter()
            .filter(|s| s.query.start <= p.hi && s.query.end > p.lo)
            .cloned()
            .collect();
        let (init, segments) = init_field(style, q, start, c, &ribs, &segs, &opts.seams)?;
        let labels = nearest_samples(q, p, c, plan.width_at(style, start));
        let levels = synthesize(style, init, top, &sopts, &labels, p, prev.as_ref());
        let top_field = levels
            .last()
            .ok_or_else(|| Error::degenerate("brush", "synthesis produced no level"))?;
        let field = kept(top_field, &labels, &p.keep, factor);
        let result = QueryResult {
            spine: sub_spine(q, &p.keep),
            canvas: c,
            sub: plan.subdivision(style, q, c),
            field,
            segments: segments
                .into_iter()
                .filter(|(_, r)| r.start < p.keep.end && r.end > p.keep.start)
                .map(|(e, r)| {
                    let a = r.start.max(p.keep.start) - p.keep.start;
                    let b = r.end.min(p.keep.end) - p.keep.start;
                    (e, a..b)
                })
                .collect(),
            levels: if opts.refine.is_some() {
                levels.clone()
            } else {
                Vec::new()
            },
        };
        emit(result);
        prev = Some(Done { canvas: c, levels });
    }
    Ok(())
}

/// Cuts `q`'s samples into pieces whose canvases (at `ppu` top-level px
/// per unit, whole multiples of `factor` px) hold at most `most` pixels,
/// each as long as fits.
fn cut(q: &QuerySpine, ppu: f64, factor: usize, most: u64) -> Result<Vec<Piece>> {
    let n = q.samples.len();
    let per_width = q.width / q.spacing.max(1e-12);
    let overlap = ((OVERLAP_WIDTHS * per_width).ceil() as usize).max(2);
    let pad = overlap + ((CONTEXT_WIDTHS * per_width).ceil() as usize).max(1);
    let anchor = q.samples.first().map_or(Point::ZERO, |s| s.pos);
    let canvas = |lo: usize, hi: usize| lattice_canvas(q, lo, hi, ppu, factor, anchor);
    let fits = |c: &Canvas| {
        c.width as u64 * c.height as u64 <= most
            && crate::io::check_canvas(c.width as u64, c.height as u64).is_ok()
    };
    let mut cuts = vec![0usize];
    let mut t = 0;
    while t + 1 < n {
        let lo = t.saturating_sub(pad);
        // The longest own range t..e whose canvas fits (at least `overlap`
        // samples, so that pieces advance past each other's overlap).
        let first = (t + overlap).min(n);
        let (mut good, mut bad) = (first, n + 1);
        if canvas(lo, n - 1).is_some_and(|c| fits(&c)) {
            good = n;
        } else {
            while bad - good > 1 {
                let mid = (good + bad) / 2;
                match canvas(lo, (mid + pad).min(n - 1)) {
                    Some(c) if fits(&c) => good = mid,
                    _ => bad = mid,
                }
            }
        }
        cuts.push(good);
        t = good;
    }
    let last = cuts.len() - 1;
    let mut pieces = Vec::with_capacity(last);
    for k in 0..last {
        let (a, b) = (cuts[k], cuts[k + 1]);
        let (lo, hi) = (a.saturating_sub(pad), (b + pad).min(n - 1));
        let keep_end = if k + 1 == last { n } else { b + overlap / 2 };
        let c = canvas(lo, hi).ok_or_else(|| {
            Error::invalid(format!(
                "query {}: a piece gives an empty canvas",
                q.query_id
            ))
        })?;
        crate::io::check_canvas(c.width as u64, c.height as u64)?;
        pieces.push(Piece {
            canvas: c,
            lo,
            hi,
            keep: a..keep_end,
            // What the previous piece keeps beyond its own samples (half
            // the overlap) lies inside what this one locks (all of it).
            locked: if k == 0 { 0 } else { a + overlap },
        });
    }
    Ok(pieces)
}

/// The canvas of samples `lo..=hi` grown by 1.5 stroke widths (as
/// [`super::pipeline::canvas_for`]), its corner on the lattice of
/// `factor` px steps through `anchor`.
fn lattice_canvas(
    q: &QuerySpine,
    lo: usize,
    hi: usize,
    ppu: f64,
    factor: usize,
    anchor: Point,
) -> Option<Canvas> {
    let [x0, y0, x1, y1] = samples_box(q.samples.get(lo..=hi)?);
    let m = 1.5 * q.width;
    let step = factor.max(1) as f64 / ppu;
    let ox = anchor.x + ((x0 - m - anchor.x) / step).floor() * step;
    let oy = anchor.y + ((y0 - m - anchor.y) / step).floor() * step;
    let cw = ((x1 + m - ox) / step).ceil();
    let ch = ((y1 + m - oy) / step).ceil();
    if !(cw.is_finite() && ch.is_finite() && cw >= 1.0 && ch >= 1.0 && cw * ch < 1e12) {
        return None;
    }
    Some(Canvas {
        origin: Point::new(ox, oy),
        px_per_unit: ppu,
        width: cw as usize * factor,
        height: ch as usize * factor,
        factor,
    })
}

/// Per start-level pixel of `c`, the index of the nearest of the piece's
/// samples within [`LABEL_WIDTHS`] stroke widths ([`NO_SAMPLE`] when
/// none is that near); `w` is the stroke's width in start-level px.
fn nearest_samples(q: &QuerySpine, p: &Piece, c: Canvas, w: f64) -> Grid<u32> {
    let div = c.factor.max(1);
    let to_px = c.to_pixel(1.0 / div as f64);
    let (cw, ch) = (c.width / div, c.height / div);
    let mut label = Grid::new(cw, ch, NO_SAMPLE);
    let mut best = Grid::new(cw, ch, f64::INFINITY);
    let r = LABEL_WIDTHS * w;
    for i in p.lo..=p.hi {
        let Some(s) = q.samples.get(i) else { break };
        let at = to_px * s.pos;
        let clip = |v: f64, hi: usize| v.clamp(0.0, hi as f64) as usize;
        let (x0, x1) = (clip((at.x - r).floor(), cw), clip((at.x + r).ceil(), cw));
        let (y0, y1) = (clip((at.y - r).floor(), ch), clip((at.y + r).ceil(), ch));
        for y in y0..y1 {
            for x in x0..x1 {
                let d = Point::new(x as f64 + 0.5, y as f64 + 0.5).distance_squared(at);
                if d <= r * r && d < best.get(x, y) {
                    best.set(x, y, d);
                    label.set(x, y, i as u32);
                }
            }
        }
    }
    label
}

/// The piece's levels from its start-level field `init` to `top`: correct,
/// upsample, correct, … ([`synth::synthesize_levels`]), with the pixels
/// the previous piece owns (labelled before this piece's own samples plus
/// the overlap, and on the previous canvas) locked to its coordinates at
/// every level.
fn synthesize(
    style: &BrushStyle,
    init: Field,
    top: usize,
    opts: &SynthOptions,
    labels: &Grid<u32>,
    p: &Piece,
    prev: Option<&Done>,
) -> Vec<Field> {
    let lock = prev.map(|d| {
        let (dx, dy) = offset(d.canvas, p.canvas);
        let (pw, ph) = (
            (d.canvas.width / d.canvas.factor.max(1)) as isize,
            (d.canvas.height / d.canvas.factor.max(1)) as isize,
        );
        let until = p.locked as u32;
        let mask = Grid::from_fn(labels.width(), labels.height(), |x, y| {
            let l = labels.get(x, y);
            let (px, py) = (x as isize + dx, y as isize + dy);
            l != NO_SAMPLE && l < until && px >= 0 && py >= 0 && px < pw && py < ph
        });
        (mask, (dx, dy))
    });
    let mut field = init;
    let mut out = Vec::new();
    let mut j = 0usize;
    loop {
        let only = lock.as_ref().and_then(|(mask, (dx, dy))| {
            let pf = prev?.levels.get(j)?;
            let (w, h) = (field.coords.width(), field.coords.height());
            let free = Grid::from_fn(w, h, |x, y| !mask.get(x >> j, y >> j));
            for y in 0..h {
                for x in 0..w {
                    if free.get(x, y) {
                        continue;
                    }
                    let (px, py) = (x as isize + (dx << j), y as isize + (dy << j));
                    field.coords.set(x, y, pf.coords.get_or(px, py, None));
                    field.orient.set(x, y, pf.orient.get_or(px, py, [0.0; 2]));
                    field.seam.set(x, y, false);
                }
            }
            if j == 0 {
                mark_seam(&mut field, &free);
            }
            Some(free)
        });
        synth::correct_in(style, &mut field, opts, only.as_ref());
        if field.level >= top {
            out.push(field);
            return out;
        }
        let next = synth::upsample(style, &field);
        out.push(field);
        field = next;
        j += 1;
    }
}

/// Start-level pixel offset of canvas `b`'s pixels in canvas `a`: pixel
/// `(x, y)` of `b` is pixel `(x + dx, y + dy)` of `a` (both on one
/// lattice of start-level pixels).
fn offset(a: Canvas, b: Canvas) -> (isize, isize) {
    let step = a.factor.max(1) as f64 / a.px_per_unit;
    let d = (b.origin - a.origin) / step;
    (d.x.round() as isize, d.y.round() as isize)
}

/// Marks as seam (where the ANN search runs) the free pixels within
/// [`SEAM_MARGIN`] of a locked one: the lock's edge is where this piece's
/// own field meets the previous piece's.
fn mark_seam(field: &mut Field, free: &Grid<bool>) {
    let (w, h) = (free.width(), free.height());
    for y in 0..h {
        for x in 0..w {
            if !free.get(x, y) {
                continue;
            }
            let near = (-SEAM_MARGIN..=SEAM_MARGIN).any(|dy| {
                (-SEAM_MARGIN..=SEAM_MARGIN)
                    .any(|dx| !free.get_or(x as isize + dx, y as isize + dy, true))
            });
            if near {
                field.seam.set(x, y, true);
            }
        }
    }
}

/// The top field with every pixel whose nearest sample (at the start
/// level, `factor` top px per start px) is outside `keep` cleared.
fn kept(top: &Field, labels: &Grid<u32>, keep: &std::ops::Range<usize>, factor: usize) -> Field {
    let mut f = top.clone();
    let f_ = factor.max(1);
    for y in 0..f.coords.height() {
        for x in 0..f.coords.width() {
            let l = labels.get_or((x / f_) as isize, (y / f_) as isize, NO_SAMPLE);
            if l == NO_SAMPLE || !keep.contains(&(l as usize)) {
                f.coords.set(x, y, None);
            }
        }
    }
    f
}

/// The samples `keep` of `q` as a spine of their own (same id, width and
/// spacing; arc lengths still measured on the whole stroke).
fn sub_spine(q: &QuerySpine, keep: &std::ops::Range<usize>) -> QuerySpine {
    let samples = q.samples.get(keep.clone()).unwrap_or(&[]).to_vec();
    QuerySpine {
        query_id: q.query_id.clone(),
        subpath: q.subpath,
        style: q.style.clone(),
        seed: q.seed,
        width: q.width,
        spacing: q.spacing,
        length: q.spacing * samples.len().saturating_sub(1) as f64,
        samples,
    }
}

#[cfg(test)]
mod tests;
