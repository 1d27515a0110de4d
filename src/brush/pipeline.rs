//! The `flourish brush` pipeline for one sketch (decobrush.txt §5–7):
//! query spines → piecewise matching → ARAP per segment → coordinate fields
//! at the coarsest level → graph-cut seams in the overlaps → hierarchical
//! synthesis up to the level the output needs → per-layer SDFs read at
//! continuous coordinates onto the output grid → Bézier outlines, one `<g>`
//! per query ([`super::output`]).
//!
//! **Scales.** A query's stroke width `W_q` (sketch units) is mapped to the
//! style's exemplar width `W_e` (finest px), so the ornament is as wide as
//! the stroke: the exemplars' finest level has `W_e / W_q` px per unit, and
//! level `l` `2^(L−1−l)` times fewer. The cost follows the output, not the
//! exemplars' resolution:
//! - synthesis starts on the coarsest level where the stroke is at least
//!   [`MIN_SYNTH_WIDTH`] px wide ([`start_level`]) and stops on the
//!   coarsest where it is as wide as the output needs ([`top_level`]:
//!   about a pixel per sketch unit, [`SYNTH_WIDTH`] px at most); the
//!   query's [`Canvas`] is that top level;
//! - the output grid subdivides the canvas ([`QueryResult::sub`]) until it
//!   has [`OUT_PX_PER_UNIT`] px per sketch unit (the tracing tolerance,
//!   0.25 px, is then an eighth of a unit) and the style's thinnest line
//!   spans [`LINE_PX`] px ([`output_subdivision`]), never finer than the
//!   exemplars' finest level; the layers are read there from the finest
//!   exemplar level through the synthesized coordinates, continued
//!   smoothly between canvas pixels.
//!
//! **Branching** (§7). A stroke whose start lies on an earlier stroke (within
//! half its width of the earlier spine) grows out of it: its start is not
//! treated as an end by the matching, so no end ornament is forced there.

use super::arap::{rasterize_coords, Arap, RibMesh};
use super::baseline::art_brush_coords;
use super::graphcut::{seam, Cover, Label, SeamParams};
use super::matching::{match_query, MatchOptions, MatchedSegment, Matching, SpineFeatures};
use super::query::{QueryOptions, QuerySample, QuerySpine};
pub use super::ribs::exemplar_width;
use super::ribs::{exemplar_features, resample_ribs, Resampled};
use super::synth::{self, Coord, Field, SynthOptions};
use crate::brush::analysis::BrushStyle;
use crate::error::{Error, Result};
use crate::raster::Grid;
use kurbo::{Affine, Point, Vec2};

/// Everything the pipeline can be told: the face's [`crate::BrushOptions`] and
/// the stages' own settings, which tests and benchmarks reach.
#[derive(Clone, Debug, Default)]
pub struct Settings {
    /// Query spine resampling.
    pub query: QueryOptions,
    /// Piecewise matching (its `seed` is overwritten by [`Self::seed`]).
    pub matching: MatchOptions,
    /// Synthesis (its `seed` is overwritten by [`Self::seed`]).
    pub synth: SynthOptions,
    /// Seam energy weights.
    pub seams: SeamParams,
    /// Seed of every choice among near-equal candidates.
    pub seed: u64,
    /// Replace matching, ARAP, seams and synthesis by the art-brush
    /// baseline: the first exemplar stretched along the whole query.
    pub art_brush: bool,
    /// Pyramid level at which the graph cut initializes the synthesis
    /// (0 = coarsest); `None`: the coarsest level on which the exemplar
    /// strokes are at least [`MIN_SYNTH_WIDTH`] px wide.
    pub start_level: Option<usize>,
    /// Pyramid level at which the synthesis stops (at least the start
    /// level); `None`: the one the output needs ([`top_level`]).
    pub top_level: Option<usize>,
    /// A refinement sketch (§5.5, `--refine`): black strokes add ink,
    /// white ones erase it; same viewBox as the sketch.
    pub refine: Option<super::Refinement>,
    /// Drop each query's synthesized fields once it is traced: the
    /// [`QueryResult`]s of [`crate::brush::output::BrushOutput`] keep their
    /// spine, canvas and segments but an empty `field` and no `levels`, so
    /// a sketch of thousands of strokes needs the memory of the few being
    /// synthesized at a time, not of all of them (about 18 MB each for a
    /// 556×556 px canvas). The document is the same either way.
    pub discard_fields: bool,
    /// Synthesize every query in pieces of at most this many top-level
    /// canvas pixels ([`super::pieces`]); `None`: only a query whose
    /// whole canvas does not fit, in pieces of
    /// [`super::pieces::PIECE_PIXELS`].
    pub pieces: Option<u64>,
    /// Cancels the run between stages ([`crate::BrushOptions::cancel`]).
    pub cancel: Option<crate::Cancel>,
}

/// A query's canvas, at the synthesis's top level: pixel `(x, y)` has its
/// centre at sketch point `origin + (x + ½, y + ½) / px_per_unit`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Canvas {
    /// Sketch point at the canvas's top-left corner.
    pub origin: Point,
    /// Top-level canvas pixels per sketch unit.
    pub px_per_unit: f64,
    /// Top-level width, px.
    pub width: usize,
    /// Top-level height, px.
    pub height: usize,
    /// Top-level over start-level pixel size (`2^(top − start)`).
    pub factor: usize,
}

impl Canvas {
    /// Canvas pixel coordinates at level scale `s` (1 = the top level) of
    /// a sketch point.
    pub fn to_pixel(self, s: f64) -> Affine {
        Affine::scale(self.px_per_unit * s) * Affine::translate(-self.origin.to_vec2())
    }

    /// Sketch coordinates of a top-level pixel-space point.
    pub fn to_user(self) -> Affine {
        Affine::translate(self.origin.to_vec2()) * Affine::scale(1.0 / self.px_per_unit)
    }

    /// The same canvas with every pixel split into `sub` × `sub`.
    pub fn subdivided(self, sub: usize) -> Canvas {
        let k = sub.max(1);
        Canvas {
            origin: self.origin,
            px_per_unit: self.px_per_unit * k as f64,
            width: self.width * k,
            height: self.height * k,
            factor: self.factor * k,
        }
    }
}

/// Matched segments of a query: exemplar index and query sample range.
pub type Segments = Vec<(usize, std::ops::Range<usize>)>;

/// One query after synthesis.
#[derive(Clone, Debug)]
pub struct QueryResult {
    /// The query spine (after branching adjustments of its features).
    pub spine: QuerySpine,
    /// Its canvas (the synthesis's top level).
    pub canvas: Canvas,
    /// Output pixels per canvas pixel side ([`output_subdivision`]).
    pub sub: usize,
    /// The synthesized coordinate field at the top level.
    pub field: Field,
    /// Matched segments (exemplar index, query sample range); empty for the
    /// art-brush baseline.
    pub segments: Segments,
    /// The corrected field of every synthesis level, coarse to fine, when
    /// a refinement will read them (§5.5); else empty.
    pub levels: Vec<Field>,
}

impl QueryResult {
    /// The synthesis energy of the final field ([`synth::energy`]):
    /// computed on demand, it costs about one correction pass.
    pub fn energy(&self, style: &BrushStyle) -> f64 {
        synth::energy(style, &self.field)
    }

    /// The output grid: the canvas subdivided [`Self::sub`] times.
    pub fn out_canvas(&self) -> Canvas {
        self.canvas.subdivided(self.sub)
    }
}

/// Narrowest mean stroke width (px) at which a level's 5×5 neighbourhoods
/// still resolve the ornament's structure: on coarser levels a stroke is a
/// few pixels across, its lines sub-pixel, and correction trades them for
/// paper.
pub const MIN_SYNTH_WIDTH: f64 = 8.0;

/// The coarsest level whose mean stroke width is at least
/// [`MIN_SYNTH_WIDTH`] px (`ew`: the mean width at the finest level).
pub fn start_level(style: &BrushStyle, ew: f64) -> usize {
    level_at_least(style, ew, MIN_SYNTH_WIDTH)
}

/// Widest stroke, px, the synthesis needs: its 5×5 neighbourhoods then
/// span a fifth of the stroke, which places the ornament's pieces and
/// joins its lines; what is finer than a pixel there (hairlines, the
/// shapes of outlines) is read from the exemplars' finest level through
/// the synthesized coordinates ([`super::output`]).
pub const SYNTH_WIDTH: f64 = 24.0;

/// Synthesis pixels per sketch unit a stroke needs at most: a pixel per
/// unit, one output pixel at 100 %, under [`SYNTH_WIDTH`].
pub const SYNTH_PX_PER_UNIT: f64 = 1.0;

/// The level the synthesis stops on for a stroke `width` sketch units
/// wide: the coarsest whose stroke is as wide as the output needs,
/// `width` × [`SYNTH_PX_PER_UNIT`] px clamped to [`MIN_SYNTH_WIDTH`] ..=
/// [`SYNTH_WIDTH`], or the finest when none is that wide.
pub fn top_level(style: &BrushStyle, ew: f64, width: f64) -> usize {
    let want = (width * SYNTH_PX_PER_UNIT).clamp(MIN_SYNTH_WIDTH, SYNTH_WIDTH);
    level_at_least(style, ew, want)
}

/// The coarsest level on which a stroke `ew` finest px wide is at least
/// `px` px wide, else the finest.
fn level_at_least(style: &BrushStyle, ew: f64, px: f64) -> usize {
    let Some(e) = style.exemplars.first() else {
        return 0;
    };
    e.levels
        .iter()
        .position(|l| ew * l.scale >= px)
        .unwrap_or(e.levels.len().saturating_sub(1))
}

/// Output pixels per sketch unit at least (tracing within 0.25 px is then
/// within an eighth of a unit).
pub const OUT_PX_PER_UNIT: f64 = 2.0;

/// Output pixels the style's thinnest line must span so that the output
/// grid's samples cannot miss it.
pub const LINE_PX: f64 = 2.0;

/// Most output pixels per canvas pixel side.
pub const MAX_SUB: usize = 16;

/// The output grid's subdivision of a canvas of `ppu` px per unit for a
/// stroke mapped at `fine` finest exemplar px per unit: the least whole
/// number that gives [`OUT_PX_PER_UNIT`] and [`LINE_PX`] across the
/// style's thinnest line, the latter never beyond the finest level's own
/// resolution, and never coarser than the canvas.
pub fn output_subdivision(style: &BrushStyle, ppu: f64, fine: f64) -> usize {
    let thin = style.facts.thinnest_line.max(1e-3);
    let line = (fine * LINE_PX / thin).min(fine);
    let want = OUT_PX_PER_UNIT.max(line);
    let k = (want / ppu.max(1e-9) - 1e-9).ceil();
    if k.is_finite() {
        (k.max(1.0) as usize).min(MAX_SUB)
    } else {
        1
    }
}

/// Largest canvas of one brush query, pixels in all (16 Mpx). Synthesis
/// and tracing hold about 115 bytes per canvas pixel (fields of every
/// level, Jacobians, layer SDFs): under the general 64 Mpx canvas limit
/// alone a thin diagonal stroke (one 1.45 units wide across a 200-unit
/// sketch, a 7900×7900 px canvas) would take over 7 GB and abort; 16 Mpx
/// is about 1.8 GB, twenty times the largest canvas of the shipped samples.
pub const MAX_BRUSH_PIXELS: u64 = 16 << 20;

/// Bytes a brush query holds per canvas pixel of its top level at its
/// peak (fields of every level, Jacobians, layer SDFs, the traced
/// output), for the memory budget's estimate.
pub const BYTES_PER_CANVAS_PX: u64 = 180;

/// Bytes one query may plan for: half the memory budget (two queries
/// are synthesized at once on two cores; each allocation is still
/// checked against what is left when it is made).
pub fn query_share() -> u64 {
    crate::memory::budget() / 2
}

/// Largest output grid of one brush query, pixels in all (32 Mpx, 2 bytes
/// per layer each for the layers' SDFs, plus the ink mask and the layer
/// being traced); a finer one is not
/// allocated, the subdivision is lowered instead.
pub const MAX_OUT_PIXELS: u64 = 32 << 20;

/// The canvas of a query spine: its bounding box grown by 1.5 stroke
/// widths (the farthest an ornament may reach from its spine; a smaller
/// margin cuts end curls and outer leaves flat on the canvas border),
/// at `ew / W_q` pixels per unit (`ew`: the stroke's width in pixels of
/// the canvas's level), a whole number of `factor` pixels; checked against
/// the canvas limits (and [`MAX_BRUSH_PIXELS`]) before anything is
/// allocated.
pub fn canvas_for(q: &QuerySpine, ew: f64, factor: usize) -> Result<Canvas> {
    let ppu = ew / q.width;
    let [x0, y0, x1, y1] = samples_box(&q.samples);
    let m = 1.5 * q.width;
    let f = factor.max(1) as f64;
    let cw = ((x1 - x0 + 2.0 * m) * ppu / f).ceil();
    let ch = ((y1 - y0 + 2.0 * m) * ppu / f).ceil();
    if !(cw.is_finite() && ch.is_finite() && cw >= 1.0 && ch >= 1.0) {
        return Err(Error::invalid("the stroke gives an empty canvas"));
    }
    let (width, height) = (
        (cw * f).min(u64::MAX as f64) as u64,
        (ch * f).min(u64::MAX as f64) as u64,
    );
    crate::io::check_canvas(width, height)?;
    if width.saturating_mul(height) > MAX_BRUSH_PIXELS {
        return Err(Error::TooLarge {
            width,
            height,
            limit: format!(
                "{} Mpx in all for a brush stroke; draw the stroke wider or shorter",
                MAX_BRUSH_PIXELS >> 20
            ),
        });
    }
    Ok(Canvas {
        origin: Point::new(x0 - m, y0 - m),
        px_per_unit: ppu,
        width: cw as usize * factor,
        height: ch as usize * factor,
        factor,
    })
}

/// The box `[x0, y0, x1, y1]` of the samples' positions, sketch units
/// (inverted, min above max, when there are none).
pub(crate) fn samples_box(samples: &[QuerySample]) -> [f64; 4] {
    let (mut x0, mut y0, mut x1, mut y1) = (f64::MAX, f64::MAX, f64::MIN, f64::MIN);
    for s in samples {
        (x0, y0) = (x0.min(s.pos.x), y0.min(s.pos.y));
        (x1, y1) = (x1.max(s.pos.x), y1.max(s.pos.y));
    }
    [x0, y0, x1, y1]
}

/// The query orientation ω^q of a coordinate field from one warped
/// exemplar: `ω^q ∝ J⁻¹ ω^e` with `J = ∂μ/∂p` by finite differences.
fn orient_of(style: &BrushStyle, level: usize, g: &Patch, x: usize, y: usize) -> Option<[f32; 2]> {
    let e = g.exemplar;
    let at = |dx: isize, dy: isize| g.get_or(x as isize + dx, y as isize + dy);
    let c = at(0, 0)?;
    let diff =
        |a: Option<Point>, b: Option<Point>, span: f64| -> Option<Vec2> { Some((a? - b?) / span) };
    let jx = diff(at(1, 0), at(-1, 0), 2.0)
        .or_else(|| diff(at(1, 0), Some(c), 1.0))
        .or_else(|| diff(Some(c), at(-1, 0), 1.0))?;
    let jy = diff(at(0, 1), at(0, -1), 2.0)
        .or_else(|| diff(at(0, 1), Some(c), 1.0))
        .or_else(|| diff(Some(c), at(0, -1), 1.0))?;
    let coord = Coord {
        exemplar: e,
        x: c.x as f32,
        y: c.y as f32,
    };
    let oe = synth::exemplar_orientation(style, level, coord)?;
    let det = jx.cross(jy);
    if det.abs() < 1e-9 {
        return None;
    }
    // Solve [jx jy] w = ω^e.
    let (ex, ey) = (oe[0] as f64, oe[1] as f64);
    let wx = (ex * jy.y - ey * jy.x) / det;
    let wy = (jx.x * ey - jx.y * ex) / det;
    let l = wx.hypot(wy);
    (l > 0.0).then(|| [(wx / l) as f32, (wy / l) as f32])
}

/// Pixels (at the start level) by which the seam regions, where the ANN
/// search runs, extend on either side of the graph-cut seams: the radius
/// of a 5×5 neighbourhood, so exactly the pixels whose neighbourhood
/// straddles a cut (the "red curves" of decobrush.txt Fig. 6c, §5.4.2).
/// Elsewhere every pixel's neighbourhood lies in one warped segment and
/// only the coherent candidates are searched: ANN picks there seed
/// pixel-sized patches that break lines.
pub const SEAM_MARGIN: isize = 2;

/// One warped exemplar segment's coordinates on the canvas (exemplar
/// px, `None` off its mesh), held only over the box its mesh covers.
pub(crate) struct Patch {
    /// The exemplar.
    pub(crate) exemplar: u32,
    /// Canvas column of the box's left side.
    pub(crate) x0: usize,
    /// Canvas row of the box's top side.
    pub(crate) y0: usize,
    /// The coordinates over the box.
    pub(crate) grid: Grid<Option<Point>>,
}

impl Patch {
    /// The coordinate at canvas pixel `(x, y)`.
    fn get(&self, x: usize, y: usize) -> Option<Point> {
        self.get_or(x as isize, y as isize)
    }

    /// The coordinate at canvas pixel `(x, y)`, `None` outside the box.
    fn get_or(&self, x: isize, y: isize) -> Option<Point> {
        self.grid
            .get_or(x - self.x0 as isize, y - self.y0 as isize, None)
    }

    /// The box `[x0, y0, x1, y1)` on the canvas.
    fn bounds(&self) -> [usize; 4] {
        [
            self.x0,
            self.y0,
            self.x0 + self.grid.width(),
            self.y0 + self.grid.height(),
        ]
    }
}

/// The coordinate patch of a deformed rib mesh (`deformed`: positions in
/// pixels of a `width` × `height` canvas): rasterized over the box of its
/// vertices clipped to the canvas ([`rasterize_coords`]).
fn rasterize_patch(
    exemplar: u32,
    mesh: &RibMesh,
    deformed: &[Point],
    width: usize,
    height: usize,
) -> Result<Patch> {
    let (mut x0, mut y0, mut x1, mut y1) = (f64::MAX, f64::MAX, f64::MIN, f64::MIN);
    for p in deformed {
        (x0, y0) = (x0.min(p.x), y0.min(p.y));
        (x1, y1) = (x1.max(p.x), y1.max(p.y));
    }
    let clip = |v: f64, hi: usize| {
        if v.is_finite() {
            v.clamp(0.0, hi as f64) as usize
        } else {
            0
        }
    };
    let (bx0, by0) = (clip(x0.floor(), width), clip(y0.floor(), height));
    let (bx1, by1) = (clip(x1.ceil() + 1.0, width), clip(y1.ceil() + 1.0, height));
    let (bw, bh) = (
        bx1.saturating_sub(bx0).max(1),
        by1.saturating_sub(by0).max(1),
    );
    let shift = Affine::translate((-(bx0 as f64), -(by0 as f64)));
    Ok(Patch {
        exemplar,
        x0: bx0,
        y0: by0,
        grid: rasterize_coords(mesh, deformed, bw, bh, shift)?,
    })
}

/// A coordinate field from several warped exemplar segments: owners,
/// orientation and seam mask.
fn compose(
    style: &BrushStyle,
    level: usize,
    fields: &[Patch],
    owner: &Grid<Option<usize>>,
) -> Field {
    let (w, h) = (owner.width(), owner.height());
    let mut coords = Grid::new(w, h, None);
    let mut orient = Grid::new(w, h, [0.0f32; 2]);
    let mut seam = Grid::new(w, h, false);
    for y in 0..h {
        for x in 0..w {
            let Some(k) = owner.get(x, y) else { continue };
            let Some(g) = fields.get(k) else {
                continue;
            };
            if let Some(c) = g.get(x, y) {
                coords.set(
                    x,
                    y,
                    Some(Coord {
                        exemplar: g.exemplar,
                        x: c.x as f32,
                        y: c.y as f32,
                    }),
                );
                if let Some(o) = orient_of(style, level, g, x, y) {
                    orient.set(x, y, o);
                }
            }
            let me = owner.get(x, y);
            let cut = [(1isize, 0isize), (0, 1)].iter().any(|&(dx, dy)| {
                let o = owner.get_or(x as isize + dx, y as isize + dy, None);
                o.is_some() && o != me
            });
            if cut {
                for dy in -SEAM_MARGIN..=SEAM_MARGIN {
                    for dx in -SEAM_MARGIN..=SEAM_MARGIN {
                        let (nx, ny) = (x as isize + dx, y as isize + dy);
                        if nx >= 0 && ny >= 0 && (nx as usize) < w && (ny as usize) < h {
                            seam.set(nx as usize, ny as usize, true);
                        }
                    }
                }
            }
        }
    }
    fill_orientation(&mut orient, &coords);
    Field {
        level,
        coords,
        orient,
        seam,
        user: None,
    }
}

/// Pixels on the ornament whose orientation could not be estimated take
/// a neighbour's (a few sweeps).
fn fill_orientation(orient: &mut Grid<[f32; 2]>, coords: &Grid<Option<Coord>>) {
    let (w, h) = (orient.width(), orient.height());
    for _ in 0..4 {
        let snapshot = orient.clone();
        let mut missing = false;
        for y in 0..h {
            for x in 0..w {
                if coords.get(x, y).is_none() || snapshot.get(x, y) != [0.0, 0.0] {
                    continue;
                }
                missing = true;
                let mut acc = [0.0f32; 2];
                for (dx, dy) in [(1isize, 0isize), (-1, 0), (0, 1), (0, -1)] {
                    let o = snapshot.get_or(x as isize + dx, y as isize + dy, [0.0, 0.0]);
                    acc = [acc[0] + o[0], acc[1] + o[1]];
                }
                let l = acc[0].hypot(acc[1]);
                if l > 0.0 {
                    orient.set(x, y, [acc[0] / l, acc[1] / l]);
                }
            }
        }
        if !missing {
            break;
        }
    }
}

/// Paper-ness (0 ink … 1 paper) of a warped segment at a pixel, for the
/// seam energy.
fn paper(style: &BrushStyle, level: usize, e: u32, c: Option<Point>) -> Option<f32> {
    let c = c?;
    let lv = style.exemplars.get(e as usize)?.levels.get(level)?;
    Some((0.5 + lv.ink.ink.sample(c.x, c.y)).clamp(0.0, 1.0))
}

/// Which segment each pixel of a `w` × `h` canvas takes its coordinate
/// from: the first covering one, then the graph-cut seam between each
/// consecutive pair (§5.3).
fn seams(
    style: &BrushStyle,
    level: usize,
    fields: &[Patch],
    (w, h): (usize, usize),
    params: &SeamParams,
) -> Result<Grid<Option<usize>>> {
    if fields.is_empty() {
        return Err(Error::degenerate("brush", "no matched segments"));
    }
    let mut owner: Grid<Option<usize>> = Grid::new(w, h, None);
    for (k, f) in fields.iter().enumerate() {
        let [x0, y0, x1, y1] = f.bounds();
        for y in y0..y1.min(h) {
            for x in x0..x1.min(w) {
                if owner.get(x, y).is_none() && f.get(x, y).is_some() {
                    owner.set(x, y, Some(k));
                }
            }
        }
    }
    for k in 0..fields.len().saturating_sub(1) {
        let (ga, gb) = (&fields[k], &fields[k + 1]);
        let (ea, eb) = (ga.exemplar, gb.exemplar);
        let (ba, bb) = (ga.bounds(), gb.bounds());
        let (mut x0, mut y0, mut x1, mut y1) = (usize::MAX, usize::MAX, 0, 0);
        for y in ba[1].max(bb[1])..ba[3].min(bb[3]).min(h) {
            for x in ba[0].max(bb[0])..ba[2].min(bb[2]).min(w) {
                if ga.get(x, y).is_some() && gb.get(x, y).is_some() {
                    (x0, y0, x1, y1) = (x0.min(x), y0.min(y), x1.max(x), y1.max(y));
                }
            }
        }
        if x0 > x1 {
            continue;
        }
        let (x0, y0) = (x0.saturating_sub(2), y0.saturating_sub(2));
        let (x1, y1) = ((x1 + 2).min(w - 1), (y1 + 2).min(h - 1));
        let (cw, ch) = (x1 - x0 + 1, y1 - y0 + 1);
        let cover = Grid::from_fn(cw, ch, |x, y| {
            match (
                ga.get(x + x0, y + y0).is_some(),
                gb.get(x + x0, y + y0).is_some(),
            ) {
                (true, true) => Cover::Both,
                (true, false) => Cover::A,
                (false, true) => Cover::B,
                (false, false) => Cover::None,
            }
        });
        let a = Grid::from_fn(cw, ch, |x, y| {
            paper(style, level, ea, ga.get(x + x0, y + y0)).unwrap_or(1.0)
        });
        let b = Grid::from_fn(cw, ch, |x, y| {
            paper(style, level, eb, gb.get(x + x0, y + y0)).unwrap_or(1.0)
        });
        let s = seam(&a, &b, &cover, params)?;
        for y in 0..ch {
            for x in 0..cw {
                let (gx, gy) = (x + x0, y + y0);
                match s.labels.get(x, y) {
                    Label::A if owner.get(gx, gy) == Some(k + 1) => owner.set(gx, gy, Some(k)),
                    Label::B if cover.get(x, y) == Cover::Both => owner.set(gx, gy, Some(k + 1)),
                    _ => {}
                }
            }
        }
    }
    Ok(owner)
}

/// Whether the spine starts on an earlier one (within half its width).
pub fn starts_on(q: &QuerySpine, earlier: &[QuerySpine]) -> bool {
    let Some(start) = q.samples.first().map(|s| s.pos) else {
        return false;
    };
    earlier.iter().any(|e| {
        e.samples
            .iter()
            .any(|s| s.pos.distance(start) <= 0.5 * e.width.max(q.width))
    })
}

/// Marks a branching spine's start as a middle: its end distances from the
/// start are pushed beyond any end zone.
pub fn as_branch(q: &mut QuerySpine) {
    let far = 1e3 * q.width;
    for s in &mut q.samples {
        s.dist_start += far;
    }
}

/// Synthesizes one query spine (see the module docs).
pub fn brush_query(style: &BrushStyle, q: &QuerySpine, opts: &Settings) -> Result<QueryResult> {
    run_query(style, q, opts, false)
}

fn run_query(
    style: &BrushStyle,
    q: &QuerySpine,
    opts: &Settings,
    stop_at_init: bool,
) -> Result<QueryResult> {
    let plan = Plan::of(style, q, opts)?;
    let (canvas, top) = plan.whole_canvas(style, q)?;
    let sub = plan.subdivision(style, q, canvas);
    if opts.art_brush {
        return art_brush(style, q, canvas, top, sub);
    }
    let (ribs, m) = matched(style, q, opts, plan.ew)?;
    let (init, segments) = init_field(
        style,
        q,
        plan.start,
        canvas,
        &ribs,
        &m.segments,
        &opts.seams,
    )?;
    if stop_at_init {
        return Ok(QueryResult {
            spine: q.clone(),
            canvas,
            sub,
            field: init,
            segments,
            levels: Vec::new(),
        });
    }
    crate::io::check(&opts.cancel)?;
    let sopts = SynthOptions {
        seed: opts.seed,
        ..opts.synth.clone()
    };
    let mut levels = synth::synthesize_levels(style, init, top, &sopts);
    // Only a refinement reads the levels again (the top one included).
    let field = if opts.refine.is_some() {
        levels.last().cloned()
    } else {
        let top = levels.pop();
        levels.clear();
        top
    }
    .ok_or_else(|| Error::degenerate("brush", "synthesis produced no level"))?;
    Ok(QueryResult {
        spine: q.clone(),
        canvas,
        sub,
        field,
        segments,
        levels,
    })
}

/// The levels a query is synthesized on: from `start` (the graph cut's)
/// to `top` (the one the output asks for), `ew` the exemplars' mean width
/// in finest px.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Plan {
    /// Level of the graph cut.
    pub(crate) start: usize,
    /// Level the output asks for.
    pub(crate) top: usize,
    /// Exemplars' mean width, finest px.
    pub(crate) ew: f64,
}

impl Plan {
    /// The plan of `q` under `opts`.
    pub(crate) fn of(style: &BrushStyle, q: &QuerySpine, opts: &Settings) -> Result<Plan> {
        let levels = style.exemplars.first().map(|e| e.levels.len()).unwrap_or(0);
        if levels == 0 || q.samples.len() < 2 {
            return Err(Error::degenerate("brush", "nothing to synthesize"));
        }
        let ew = exemplar_width(style)?;
        let start = opts
            .start_level
            .unwrap_or_else(|| start_level(style, ew))
            .min(levels - 1);
        let top = opts
            .top_level
            .unwrap_or_else(|| top_level(style, ew, q.width))
            .clamp(start, levels - 1);
        Ok(Plan { start, top, ew })
    }

    /// Stroke width, canvas px, at level `l`.
    pub(crate) fn width_at(self, style: &BrushStyle, l: usize) -> f64 {
        let scale = style
            .exemplars
            .first()
            .and_then(|e| e.levels.get(l))
            .map_or(1.0, |lv| lv.scale);
        self.ew * scale
    }

    /// The canvas of the whole query and the level it stops on: a stroke
    /// too long for its canvas at the level the output asks for is
    /// synthesized at a coarser level that fits the size limit and
    /// [`query_share`]; at the start level it is refused with the canvas
    /// named (then [`super::pieces`] cuts it into pieces). The choice
    /// depends on the budget, never on what other threads hold, so the
    /// output is the same at any thread count.
    pub(crate) fn whole_canvas(
        self,
        style: &BrushStyle,
        q: &QuerySpine,
    ) -> Result<(Canvas, usize)> {
        let mut top = self.top;
        loop {
            let fits =
                canvas_for(q, self.width_at(style, top), 1 << (top - self.start)).and_then(|c| {
                    let bytes = (c.width as u64)
                        .saturating_mul(c.height as u64)
                        .saturating_mul(BYTES_PER_CANVAS_PX);
                    if bytes <= query_share() {
                        return Ok(c);
                    }
                    Err(Error::invalid(format!(
                        "the {}×{} px canvas of query {} needs about {}, more than the {} one stroke may take (half the memory budget, --max-memory)",
                        c.width,
                        c.height,
                        q.query_id,
                        crate::memory::in_words(bytes),
                        crate::memory::in_words(query_share())
                    )))
                });
            match fits {
                Err(_) if top > self.start => top -= 1,
                other => return other.map(|c| (c, top)),
            }
        }
    }

    /// The output subdivision of `canvas` ([`output_subdivision`]) under
    /// [`MAX_OUT_PIXELS`].
    pub(crate) fn subdivision(self, style: &BrushStyle, q: &QuerySpine, canvas: Canvas) -> usize {
        // Finest exemplar px per sketch unit.
        let fine = self.ew / q.width;
        let sub = output_subdivision(style, canvas.px_per_unit, fine);
        let canvas_px = (canvas.width as u64).saturating_mul(canvas.height as u64);
        let most = ((MAX_OUT_PIXELS / canvas_px.max(1)) as f64).sqrt().floor() as usize;
        sub.min(most.max(1))
    }
}

/// The exemplars' ribs resampled at the query's pace and the piecewise
/// matching of the query against them (§4).
pub(crate) fn matched(
    style: &BrushStyle,
    q: &QuerySpine,
    opts: &Settings,
    ew: f64,
) -> Result<(Vec<Resampled>, Matching)> {
    let fine = ew / q.width;
    let h = q.spacing * fine;
    // Samples closer than a quarter exemplar pixel: a stroke far wider
    // than it is long, or so short it was sampled below its width's pace.
    if !(h.is_finite() && h >= 0.25) {
        return Err(Error::degenerate(
            format!("query {}", q.query_id),
            format!(
                "too short for its stroke width ({:.3} long, {:.3} wide)",
                q.length, q.width
            ),
        ));
    }
    let mut ribs = Vec::with_capacity(style.exemplars.len());
    for e in 0..style.exemplars.len() {
        ribs.push(resample_ribs(style, e, h).ok_or_else(|| {
            Error::degenerate(
                format!("style {}", style.name),
                format!("exemplar {e} has no ribs"),
            )
        })?);
    }
    let feats: Vec<SpineFeatures> = ribs
        .iter()
        .map(|r| exemplar_features(r, 1.0 / fine, ew))
        .collect();
    let mopts = MatchOptions {
        seed: opts.seed,
        ..opts.matching.clone()
    };
    let qf = SpineFeatures::from_query(q);
    // The beam keeps the best state of every run length, so a complete
    // segmentation survives to the last sample (no exhaustive retry).
    let m = match_query(&qf, &feats, &mopts)?;
    Ok((ribs, m))
}

/// The start-level field of `segs` on `canvas` (§5.2–5.3): each matched
/// segment's rib mesh deformed by ARAP onto its query samples and
/// rasterized, then the graph-cut seams between consecutive ones.
pub(crate) fn init_field(
    style: &BrushStyle,
    q: &QuerySpine,
    start: usize,
    canvas: Canvas,
    ribs: &[Resampled],
    segs: &[MatchedSegment],
    params: &SeamParams,
) -> Result<(Field, Segments)> {
    let div = canvas.factor;
    let coarse = canvas.to_pixel(1.0 / div as f64);
    let (cw, ch) = (canvas.width / div, canvas.height / div);
    let mut fields = Vec::with_capacity(segs.len());
    let mut segments = Vec::with_capacity(segs.len());
    for seg in segs {
        let r = ribs
            .get(seg.exemplar)
            .ok_or_else(|| Error::degenerate("brush", "matched exemplar out of range"))?;
        let s0 = style.exemplars[seg.exemplar].levels[start].scale;
        let er = seg.exemplar_samples.clone();
        let sc = |v: &[Point]| {
            v.iter()
                .map(|p| (p.to_vec2() * s0).to_point())
                .collect::<Vec<_>>()
        };
        let (Some(sp), Some(le), Some(ri)) = (
            r.spine.get(er.clone()),
            r.left.get(er.clone()),
            r.right.get(er),
        ) else {
            return Err(Error::degenerate("brush", "matched samples out of range"));
        };
        let mesh = RibMesh::from_ribs(&sc(sp), &sc(le), &sc(ri), 2)?;
        let arap = Arap::new(&mesh, &mesh.spine)?;
        let pins: Vec<Point> = q
            .samples
            .get(seg.query.clone())
            .unwrap_or(&[])
            .iter()
            .map(|s| coarse * s.pos)
            .collect();
        let out = arap.solve(&pins)?;
        fields.push(rasterize_patch(seg.exemplar as u32, &mesh, &out, cw, ch)?);
        segments.push((seg.exemplar, seg.query.clone()));
    }
    let owner = seams(style, start, &fields, (cw, ch), params)?;
    Ok((compose(style, start, &fields, &owner), segments))
}

/// A synthesized query carried to the finest level, for refinement (§5.5:
/// the user's strokes guide every level up to the exemplars' own
/// resolution): the levels above its top are its top field upsampled
/// ([`synth::upsample`], no correction, so what the refinement leaves
/// alone reads as before), on the canvas subdivided to match.
pub fn to_finest(style: &BrushStyle, mut r: QueryResult) -> QueryResult {
    let finest = style
        .exemplars
        .first()
        .map_or(0, |e| e.levels.len().saturating_sub(1));
    let top = r.field.level;
    if top >= finest {
        return r;
    }
    let mut field = r.field.clone();
    while field.level < finest {
        field = synth::upsample(style, &field);
        r.levels.push(field.clone());
    }
    let k = 1usize << (finest - top);
    r.canvas = r.canvas.subdivided(k);
    r.sub = r.sub.div_ceil(k).max(1);
    r.field = field;
    r
}

/// The art-brush baseline at level `top`: the first exemplar's whole rib
/// mesh stretched along the query (no matching, seams or synthesis).
fn art_brush(
    style: &BrushStyle,
    q: &QuerySpine,
    canvas: Canvas,
    top: usize,
    sub: usize,
) -> Result<QueryResult> {
    let ex = style
        .exemplars
        .first()
        .ok_or_else(|| Error::degenerate("brush", "the style has no exemplars"))?;
    let p = |v: &[[f64; 2]]| v.iter().map(|a| Point::new(a[0], a[1])).collect::<Vec<_>>();
    let r = ex.ribs_at(top);
    let mesh = RibMesh::from_ribs(&p(&r.spine), &p(&r.left), &p(&r.right), 2)?;
    let pts: Vec<Point> = q.samples.iter().map(|s| s.pos).collect();
    let grid = art_brush_coords(
        &mesh,
        &pts,
        q.width,
        canvas.width,
        canvas.height,
        canvas.to_pixel(1.0),
    )?;
    let owner = Grid::from_fn(canvas.width, canvas.height, |x, y| {
        grid.get(x, y).map(|_| 0)
    });
    let fields = [Patch {
        exemplar: 0,
        x0: 0,
        y0: 0,
        grid,
    }];
    let field = compose(style, top, &fields, &owner);
    Ok(QueryResult {
        spine: q.clone(),
        canvas,
        sub,
        field,
        segments: Vec::new(),
        levels: Vec::new(),
    })
}
