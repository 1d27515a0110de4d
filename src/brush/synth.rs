//! Hierarchical synthesis of exemplar coordinates (decobrush.txt §5.4,
//! after Lefebvre & Hoppe 2005): the field μ = (exemplar, x, y) per canvas
//! pixel is corrected with oriented 5×5 neighbourhoods and upsampled by
//! coordinate inheritance, coarse to fine.
//!
//! * **Correction** (§5.4.2). A pixel's query neighbourhood is read from the
//!   *appearance* of the current field (each pixel shows the exemplar's ink
//!   SDF at its μ), on the rotated lattice of
//!   [`crate::brush::analysis::neighbourhood`] with its up axis along the query
//!   orientation ω^q. Candidates are the pixel's own μ and the eight
//!   coherent ones: neighbour n's coordinate continued to p,
//!   `μ(n) + J(n) (p − n)` ([`jacobian`]). A candidate's distance is the
//!   SDF L² plus [`LAYER_WEIGHT`] per disagreeing top layer on the 3×3
//!   (the SDF sees all ink as one), multiplied by
//!   `1 + κ (8 − a) / 8` where `a` of the 8 neighbours hold its
//!   continuation ("strong coherence"). The nearest wins; near-equal ones
//!   (within a relative tie tolerance) are chosen by a hash of (seed,
//!   level, pass, pixel). In seam regions (around the graph cuts) the
//!   style's k-d tree also gives an approximate nearest neighbour over all
//!   exemplars, taken when the best coherent distance is 5× or more its
//!   distance (the paper's rule).
//! * **Sub-passes.** Pixels are corrected on a 2×2 lattice, four sub-passes
//!   per iteration; each sub-pass reads only the field left by the previous
//!   one and writes only its own lattice pixels, so the parallel loop gives
//!   the same field at any thread count.
//! * **Upsampling** (§5.4.3). Child `p + Δ` (Δ = (±½, ±½) fine px) of a
//!   parent p inherits `2 μ(p) + J Δ`. The paper's `J = J_e^T J_q` (the
//!   reflection matrices `[[ω_x, ω_y], [ω_y, −ω_x]]` of the query and
//!   exemplar orientations, a rotation) is used where the parent has no
//!   coherent neighbour; inside a patch `J` is the field's measured
//!   Jacobian, so a warped segment is continued as the warp it is.

use crate::brush::analysis::neighbourhood::{Neighbourhood, SIZE};
use crate::brush::analysis::style::PAPER_LAYER;
use crate::brush::analysis::{BrushStyle, ExemplarLevel};
use crate::raster::Grid;
use crate::rng;
use crate::svg_out::Color;
use rayon::prelude::*;

/// One exemplar coordinate: exemplar index and a pixel-space position in
/// that exemplar's pyramid level (pixel centres at half-integers).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Coord {
    /// Index of the exemplar in its style.
    pub exemplar: u32,
    /// Column, px of the level.
    pub x: f32,
    /// Row, px of the level.
    pub y: f32,
}

/// The synthesis state at one pyramid level, on the canvas of one query.
#[derive(Clone, Debug, PartialEq)]
pub struct Field {
    /// Level index (0 = coarsest).
    pub level: usize,
    /// μ per canvas pixel; `None` off the ornament.
    pub coords: Grid<Option<Coord>>,
    /// Query stroking orientation ω^q per pixel (unit, pixel axes, y down).
    pub orient: Grid<[f32; 2]>,
    /// Seam regions (overlaps of matched segments), where the ANN search
    /// runs.
    pub seam: Grid<bool>,
    /// Pixels a refinement sketch marked (§5.5), when there was one: the
    /// ink the user asked for there is kept even as a piece apart.
    pub user: Option<Grid<bool>>,
}

/// Synthesis parameters.
#[derive(Clone, Debug, PartialEq)]
pub struct SynthOptions {
    /// Correction iterations per level (each is four sub-passes; default 1:
    /// measured on long queries, each further iteration lowers the
    /// neighbourhood energy but adds line ends, the structure density
    /// drifting away from the exemplars'; 0 gives the graph cut upsampled
    /// without correction).
    pub iterations: usize,
    /// Seed of the choice among near-equal candidates.
    pub seed: u64,
    /// Relative L² difference under which candidates count as near-equal
    /// (default 0.02).
    pub tie: f32,
    /// The coherent candidate is kept unless its distance is this many
    /// times the ANN candidate's (default 5, decobrush.txt §5.4.2).
    pub ann_ratio: f32,
    /// Coherence weight κ: a candidate continuing none of a pixel's 8
    /// neighbours has its distance multiplied by `1 + κ`, one continuing
    /// `a` of them by `1 + κ (8 − a) / 8` (default 1).
    pub coherence: f32,
}

impl Default for SynthOptions {
    fn default() -> Self {
        SynthOptions {
            iterations: 1,
            seed: 0,
            tie: 0.02,
            ann_ratio: 5.0,
            coherence: 1.0,
        }
    }
}

/// SDF value shown by pixels off the ornament (paper, px).
const PAPER: f32 = 8.0;

/// Exemplar level `level` of exemplar `e`.
fn level_of(style: &BrushStyle, e: u32, level: usize) -> Option<&ExemplarLevel> {
    style.exemplars.get(e as usize)?.levels.get(level)
}

/// The exemplar pixel holding a coordinate, if inside its stroke region.
fn region_pixel(lv: &ExemplarLevel, c: Coord) -> Option<(usize, usize)> {
    if !(c.x >= 0.0 && c.y >= 0.0) {
        return None;
    }
    let (x, y) = (c.x as usize, c.y as usize);
    if x < lv.width() && y < lv.height() && lv.orientation.mask.get(x, y) {
        Some((x, y))
    } else {
        None
    }
}

/// The exemplar orientation ω^e at a coordinate (`None` outside the stroke
/// region).
pub fn exemplar_orientation(style: &BrushStyle, level: usize, c: Coord) -> Option<[f32; 2]> {
    let lv = level_of(style, c.exemplar, level)?;
    let (x, y) = region_pixel(lv, c)?;
    let d = lv.orientation.dir.get(x, y);
    (d != [0.0, 0.0]).then_some(d)
}

/// The exemplar neighbourhood at a coordinate, oriented along ω^e there.
pub fn exemplar_neighbourhood(style: &BrushStyle, level: usize, c: Coord) -> Option<Neighbourhood> {
    let lv = level_of(style, c.exemplar, level)?;
    let (x, y) = region_pixel(lv, c)?;
    let up = lv.orientation.dir.get(x, y);
    Some(
        style
            .sampler
            .sample(&lv.ink.ink, [c.x as f64, c.y as f64], up),
    )
}

/// `J_e^T J_q d`: a canvas displacement `d` (px) carried into exemplar
/// axes, for query orientation `q` and exemplar orientation `e`.
#[inline]
pub fn carry(q: [f32; 2], e: [f32; 2], d: [f32; 2]) -> [f32; 2] {
    let along = q[0] * d[0] + q[1] * d[1];
    let across = -q[1] * d[0] + q[0] * d[1];
    [along * e[0] - across * e[1], along * e[1] + across * e[0]]
}

/// Largest distance (px of the level) between a neighbour's coordinate and
/// the continuation of a pixel's coordinate to it under which the two count
/// as one coherent patch (the same exemplar region, copied without a seam).
pub const COHERENT: f32 = 1.0;

/// A 2×2 Jacobian `∂μ/∂p` (exemplar px per canvas px): `[column along
/// canvas x, column along canvas y]`.
pub type Jacobian = [[f32; 2]; 2];

/// `J d` for a Jacobian and a canvas displacement (px).
#[inline]
pub fn apply(j: Jacobian, d: [f32; 2]) -> [f32; 2] {
    [
        j[0][0] * d[0] + j[1][0] * d[1],
        j[0][1] * d[0] + j[1][1] * d[1],
    ]
}

/// The rigid Jacobian `J_e^T J_q` of a pixel (§5.4.3): the rotation taking
/// the query's stroke frame at `(x, y)` onto the exemplar's at `c`.
fn rigid(style: &BrushStyle, field: &Field, c: Coord, x: usize, y: usize) -> Jacobian {
    let q = field.orient.get(x, y);
    let e = exemplar_orientation(style, field.level, c).unwrap_or(q);
    [carry(q, e, [1.0, 0.0]), carry(q, e, [0.0, 1.0])]
}

/// The local Jacobian `∂μ/∂p` of the field at pixel `(x, y)`, measured by
/// differences with the pixel's coherent 4-neighbours (same exemplar,
/// within [`COHERENT`] of the rigid continuation): central where both
/// sides cohere, one-sided where one does, the rigid `J_e^T J_q` where
/// neither does. Inside a warped segment this is the warp's own
/// stretch, so inheritance and coherent candidates continue the warp
/// instead of tiling it with rigid copies whose joints step by the stretch
/// error (a saw-tooth along every outline); at seams it falls back to the
/// paper's rotation (decobrush.txt §5.4.3).
pub fn jacobian(style: &BrushStyle, field: &Field, x: usize, y: usize) -> Option<Jacobian> {
    let c = field.coords.get(x, y)?;
    let r = rigid(style, field, c, x, y);
    let mut j = r;
    for (axis, col) in j.iter_mut().enumerate() {
        let a = if axis == 0 { (1isize, 0isize) } else { (0, 1) };
        let side = |s: isize| -> Option<[f32; 2]> {
            let n = field
                .coords
                .get_or(x as isize + s * a.0, y as isize + s * a.1, None)?;
            if n.exemplar != c.exemplar {
                return None;
            }
            let d = [(n.x - c.x) * s as f32, (n.y - c.y) * s as f32];
            let rc = r[axis];
            ((d[0] - rc[0]).hypot(d[1] - rc[1]) < COHERENT).then_some(d)
        };
        *col = match (side(1), side(-1)) {
            (Some(f), Some(b)) => [0.5 * (f[0] + b[0]), 0.5 * (f[1] + b[1])],
            (Some(f), None) => f,
            (None, Some(b)) => b,
            (None, None) => r[axis],
        };
    }
    Some(j)
}

/// The appearance of a field: per pixel, the exemplar's all-ink SDF at μ
/// (px), `PAPER` off the ornament.
pub fn appearance(style: &BrushStyle, field: &Field) -> Grid<f32> {
    let (w, h) = (field.coords.width(), field.coords.height());
    let rows: Vec<Vec<f32>> = (0..h)
        .into_par_iter()
        .map(|y| {
            (0..w)
                .map(|x| pixel_look(style, field.level, field.coords.get(x, y)))
                .collect()
        })
        .collect();
    Grid::from_vec(w, h, rows.concat()).unwrap_or_else(|| Grid::new(w, h, PAPER))
}

fn pixel_look(style: &BrushStyle, level: usize, c: Option<Coord>) -> f32 {
    c.and_then(|c| {
        let lv = level_of(style, c.exemplar, level)?;
        Some(lv.ink.ink.sample(c.x as f64, c.y as f64))
    })
    .unwrap_or(PAPER)
}

fn dist2(a: &Neighbourhood, b: &Neighbourhood) -> f32 {
    (0..SIZE).map(|k| (a[k] - b[k]) * (a[k] - b[k])).sum()
}

/// Weight of one layer disagreement in the neighbourhood distance, in the
/// units of the normalized SDF L² (a sample differing by the full clamp
/// range costs 1). The SDF neighbourhoods see all ink as one: a leaf's
/// inside and a stem's inside look alike, and correction would trade one
/// for the other, leaving stem-coloured specks in leaves. Comparing the
/// top layer on the 3×3 around the pixel keeps each layer's pixels on that
/// layer (the colour extension of §5.4.2 the paper sketches in §7).
pub const LAYER_WEIGHT: f32 = 1.0;

/// The offsets of the 3×3 layer comparison, row-major.
const LAYER_OFFSETS: [[f32; 2]; 9] = [
    [-1.0, -1.0],
    [0.0, -1.0],
    [1.0, -1.0],
    [-1.0, 0.0],
    [0.0, 0.0],
    [1.0, 0.0],
    [-1.0, 1.0],
    [0.0, 1.0],
    [1.0, 1.0],
];

/// The top layer (its colour) of an exemplar at a coordinate of a level;
/// `None` on paper or outside the exemplar.
pub fn layer_at(style: &BrushStyle, level: usize, c: Coord) -> Option<Color> {
    let lv = level_of(style, c.exemplar, level)?;
    if !(c.x >= 0.0 && c.y >= 0.0) {
        return None;
    }
    // The pixel holding the coordinate: a label needs no interpolation.
    let i = lv.top.get_or(c.x as isize, c.y as isize, PAPER_LAYER);
    lv.ink.layers.get(i as usize).map(|l| l.color)
}

/// The top layer shown by each pixel of a field (`None`: paper).
pub fn layer_look(style: &BrushStyle, field: &Field) -> Grid<Option<Color>> {
    let (w, h) = (field.coords.width(), field.coords.height());
    let rows: Vec<Vec<Option<Color>>> = (0..h)
        .into_par_iter()
        .map(|y| {
            (0..w)
                .map(|x| {
                    field
                        .coords
                        .get(x, y)
                        .and_then(|c| layer_at(style, field.level, c))
                })
                .collect()
        })
        .collect();
    Grid::from_vec(w, h, rows.concat()).unwrap_or_else(|| Grid::new(w, h, None))
}

/// The query's layers on the 3×3 around `(x, y)`.
fn query_layers(layers: &Grid<Option<Color>>, x: usize, y: usize) -> [Option<Color>; 9] {
    let mut out = [None; 9];
    for (k, o) in LAYER_OFFSETS.iter().enumerate() {
        out[k] = layers.get_or(x as isize + o[0] as isize, y as isize + o[1] as isize, None);
    }
    out
}

/// Layer disagreements between the query's 3×3 and candidate `c`'s
/// (the canvas offsets carried by the rigid `J_e^T J_q` of `c` at the
/// pixel), times [`LAYER_WEIGHT`].
fn layer_cost(
    style: &BrushStyle,
    field: &Field,
    q: &[Option<Color>; 9],
    c: Coord,
    x: usize,
    y: usize,
) -> f32 {
    let j = rigid(style, field, c, x, y);
    let mut n = 0;
    for (k, o) in LAYER_OFFSETS.iter().enumerate() {
        let d = apply(j, *o);
        let e = layer_at(
            style,
            field.level,
            Coord {
                exemplar: c.exemplar,
                x: c.x + d[0],
                y: c.y + d[1],
            },
        );
        if e != q[k] {
            n += 1;
        }
    }
    LAYER_WEIGHT * n as f32
}

/// The query neighbourhood of canvas pixel `(x, y)` in appearance `look`.
fn query_neighbourhood(
    style: &BrushStyle,
    look: &Grid<f32>,
    field: &Field,
    x: usize,
    y: usize,
) -> Neighbourhood {
    style.sampler.sample(
        look,
        [x as f64 + 0.5, y as f64 + 0.5],
        field.orient.get(x, y),
    )
}

/// The synthesis energy: mean squared L² distance between each covered
/// pixel's query neighbourhood and the exemplar neighbourhood at its μ
/// (pixels whose μ left the stroke region count as the largest distance).
pub fn energy(style: &BrushStyle, field: &Field) -> f64 {
    let look = appearance(style, field);
    let layers = layer_look(style, field);
    let (w, h) = (field.coords.width(), field.coords.height());
    let rows: Vec<(f64, usize)> = (0..h)
        .into_par_iter()
        .map(|y| {
            let mut acc = (0.0, 0);
            for x in 0..w {
                if let Some(c) = field.coords.get(x, y) {
                    let q = query_neighbourhood(style, &look, field, x, y);
                    let ql = query_layers(&layers, x, y);
                    let d = exemplar_neighbourhood(style, field.level, c)
                        .map(|e| dist2(&q, &e) + layer_cost(style, field, &ql, c, x, y))
                        .unwrap_or(4.0 * SIZE as f32);
                    acc.0 += d as f64;
                    acc.1 += 1;
                }
            }
            acc
        })
        .collect();
    let (s, n) = rows
        .into_iter()
        .fold((0.0, 0), |a, b| (a.0 + b.0, a.1 + b.1));
    if n == 0 {
        0.0
    } else {
        s / n as f64
    }
}

/// How many of the 8 neighbours of `(x, y)` hold the continuation of
/// candidate `c` (same exemplar, within [`COHERENT`] of `c + J (n − p)`
/// with the rigid `J_e^T J_q` of `c`): the candidate's coherence with its
/// surroundings.
fn agreement(style: &BrushStyle, field: &Field, c: Coord, x: usize, y: usize) -> usize {
    let j = rigid(style, field, c, x, y);
    let mut n = 0;
    for (k, o) in LAYER_OFFSETS.iter().enumerate() {
        if k == 4 {
            continue;
        }
        let Some(m) =
            field
                .coords
                .get_or(x as isize + o[0] as isize, y as isize + o[1] as isize, None)
        else {
            continue;
        };
        let d = apply(j, *o);
        if m.exemplar == c.exemplar && (c.x + d[0] - m.x).hypot(c.y + d[1] - m.y) < COHERENT {
            n += 1;
        }
    }
    n
}

/// Largest difference (px of the level, along each axis) between two
/// candidate coordinates weighed as one: their neighbourhoods differ by
/// under a quarter of a pixel's shift, well inside [`COHERENT`].
pub const SAME: f32 = 0.25;

/// The corrected coordinate of one pixel (see the module docs).
fn correct_pixel(
    style: &BrushStyle,
    field: &Field,
    (look, layers): (&Grid<f32>, &Grid<Option<Color>>),
    opts: &SynthOptions,
    pass: u64,
    x: usize,
    y: usize,
) -> Option<Coord> {
    let cur = field.coords.get(x, y)?;
    let q = query_neighbourhood(style, look, field, x, y);
    let ql = query_layers(layers, x, y);
    let cost = |n: &Neighbourhood, c: Coord| dist2(&q, n) + layer_cost(style, field, &ql, c, x, y);
    let l = field.level;
    let mut cands: Vec<(f32, Coord)> = Vec::with_capacity(10);
    if let Some(n) = exemplar_neighbourhood(style, l, cur) {
        let c0 = cost(&n, cur);
        // An exact match keeps its coordinate (an exemplar copy is a fixed
        // point): no candidate can do better.
        if c0 == 0.0 {
            return Some(cur);
        }
        cands.push((c0, cur));
    }
    let (w, h) = (
        field.coords.width() as isize,
        field.coords.height() as isize,
    );
    for dy in -1isize..=1 {
        for dx in -1isize..=1 {
            let (nx, ny) = (x as isize + dx, y as isize + dy);
            if (dx == 0 && dy == 0) || nx < 0 || ny < 0 || nx >= w || ny >= h {
                continue;
            }
            let (nx, ny) = (nx as usize, ny as usize);
            let Some(cn) = field.coords.get(nx, ny) else {
                continue;
            };
            let Some(jn) = jacobian(style, field, nx, ny) else {
                continue;
            };
            let d = apply(jn, [-dx as f32, -dy as f32]);
            let c = Coord {
                exemplar: cn.exemplar,
                x: cn.x + d[0],
                y: cn.y + d[1],
            };
            // A continuation within [`SAME`] of a candidate already
            // weighed reads the same neighbourhood: inside a coherent patch
            // every neighbour continues to the pixel's own coordinate.
            let same = |o: &Coord| {
                o.exemplar == c.exemplar && (o.x - c.x).abs() < SAME && (o.y - c.y).abs() < SAME
            };
            if cands.iter().any(|(_, o)| same(o)) {
                continue;
            }
            if let Some(n) = exemplar_neighbourhood(style, l, c) {
                cands.push((cost(&n, c), c));
            }
        }
    }
    let best = cands.iter().map(|c| c.0).fold(f32::INFINITY, f32::min);
    // Coherence (§5.4.2, "strong coherence"): a candidate's distance grows
    // with the share of the 8 neighbours it does not continue.
    let scored: Vec<(f32, Coord)> = cands
        .iter()
        .map(|&(d, c)| {
            let apart = 8 - agreement(style, field, c, x, y);
            (d * (1.0 + opts.coherence * apart as f32 / 8.0), c)
        })
        .collect();
    let top = scored.iter().map(|c| c.0).fold(f32::INFINITY, f32::min);
    let near: Vec<Coord> = scored
        .iter()
        .filter(|c| c.0 <= top * (1.0 + opts.tie))
        .map(|c| c.1)
        .collect();
    // Near-equal candidates are chosen by the seed.
    let mut pick = match near.len() {
        0 => cur,
        1 => near[0],
        n => near[rng::index(&[opts.seed, l as u64, pass, x as u64, y as u64], n)],
    };
    if field.seam.get(x, y) {
        if let Some(index) = style.indexes.get(l) {
            if let Some((r, _)) = index.approx_nearest(&q) {
                let c = Coord {
                    exemplar: r.exemplar,
                    x: r.x as f32 + 0.5,
                    y: r.y as f32 + 0.5,
                };
                if let Some(n) = exemplar_neighbourhood(style, l, c) {
                    let da = cost(&n, c);
                    if !best.is_finite() || best > opts.ann_ratio * da {
                        pick = c;
                    }
                }
            }
        }
    }
    Some(pick)
}

/// Runs `opts.iterations` correction iterations on `field` (§5.4.2).
pub fn correct(style: &BrushStyle, field: &mut Field, opts: &SynthOptions) {
    correct_in(style, field, opts, None);
}

/// [`correct`] restricted to the pixels where `only` is true (all when
/// `None`); the others are locked (§5.5).
pub fn correct_in(
    style: &BrushStyle,
    field: &mut Field,
    opts: &SynthOptions,
    only: Option<&Grid<bool>>,
) {
    let (w, h) = (field.coords.width(), field.coords.height());
    let mut look = appearance(style, field);
    let mut layers = layer_look(style, field);
    for it in 0..opts.iterations {
        for (k, (ox, oy)) in [(0usize, 0usize), (1, 1), (1, 0), (0, 1)]
            .into_iter()
            .enumerate()
        {
            let pass = (it * 4 + k) as u64;
            let snapshot: &Field = field;
            let updates: Vec<(usize, usize, Option<Coord>)> = (oy..h)
                .step_by(2)
                .collect::<Vec<_>>()
                .into_par_iter()
                .flat_map_iter(|y| {
                    let look = &look;
                    let layers = &layers;
                    (ox..w).step_by(2).filter_map(move |x| {
                        let cur = snapshot.coords.get(x, y);
                        cur?;
                        if only.is_some_and(|m| !m.get(x, y)) {
                            return None;
                        }
                        let new = correct_pixel(style, snapshot, (look, layers), opts, pass, x, y);
                        (new != cur).then_some((x, y, new))
                    })
                })
                .collect();
            for (x, y, c) in updates {
                field.coords.set(x, y, c);
                look.set(x, y, pixel_look(style, field.level, c));
                layers.set(x, y, c.and_then(|c| layer_at(style, field.level, c)));
            }
        }
    }
}

/// Upsamples `field` to the next finer level (§5.4.3): a canvas twice as
/// large, each child inheriting its parent's coordinate doubled and offset
/// by the rotated half-pixel displacement; orientation and seam mask are
/// inherited as they are.
pub fn upsample(style: &BrushStyle, field: &Field) -> Field {
    let (w, h) = (field.coords.width() * 2, field.coords.height() * 2);
    let l = field.level;
    let coords = Grid::from_fn(w, h, |x, y| {
        let (px, py) = (x / 2, y / 2);
        let c = field.coords.get(px, py)?;
        let delta = [
            if x % 2 == 0 { -0.5 } else { 0.5 },
            if y % 2 == 0 { -0.5 } else { 0.5 },
        ];
        let d = apply(jacobian(style, field, px, py)?, delta);
        Some(Coord {
            exemplar: c.exemplar,
            x: 2.0 * c.x + d[0],
            y: 2.0 * c.y + d[1],
        })
    });
    Field {
        level: l + 1,
        coords,
        orient: Grid::from_fn(w, h, |x, y| field.orient.get(x / 2, y / 2)),
        seam: Grid::from_fn(w, h, |x, y| field.seam.get(x / 2, y / 2)),
        user: field
            .user
            .as_ref()
            .map(|u| Grid::from_fn(w, h, |x, y| u.get(x / 2, y / 2))),
    }
}

/// The whole §5.4 pipeline from an initialized coarsest field: correct,
/// upsample, correct, … up to level `top` (at most the style's finest),
/// keeping the corrected field of every level visited, coarse to fine.
pub fn synthesize_levels(
    style: &BrushStyle,
    init: Field,
    top: usize,
    opts: &SynthOptions,
) -> Vec<Field> {
    let levels = style.exemplars.first().map(|e| e.levels.len()).unwrap_or(1);
    let last = top.min(levels.saturating_sub(1));
    let mut out = Vec::new();
    let mut field = init;
    loop {
        correct(style, &mut field, opts);
        if field.level >= last {
            out.push(field);
            return out;
        }
        let next = upsample(style, &field);
        out.push(field);
        field = next;
    }
}

/// Gives every `mask`ed pixel of `field` the exemplar coordinate whose
/// neighbourhood is nearest to the `target` appearance there (`target` is
/// at the finest level, `down` finest pixels per pixel of `field`), with
/// no coherence: the seed of a refined region (§5.5).
fn seed_from_target(
    style: &BrushStyle,
    field: &mut Field,
    target: &Grid<f32>,
    mask: &Grid<bool>,
    down: usize,
) -> Option<()> {
    let mut look = appearance(style, field);
    for y in 0..look.height() {
        for x in 0..look.width() {
            if mask.get_or(x as isize, y as isize, false) {
                let t = target.get_or(
                    (x * down + down / 2) as isize,
                    (y * down + down / 2) as isize,
                    PAPER,
                );
                look.set(x, y, t / down as f32);
            }
        }
    }
    let index = style.indexes.get(field.level)?;
    for y in 0..look.height() {
        for x in 0..look.width() {
            if !mask.get_or(x as isize, y as isize, false) {
                continue;
            }
            let q = query_neighbourhood(style, &look, field, x, y);
            if let Some((r, _)) = index.nearest(&q) {
                field.coords.set(
                    x,
                    y,
                    Some(Coord {
                        exemplar: r.exemplar,
                        x: r.x as f32 + 0.5,
                        y: r.y as f32 + 0.5,
                    }),
                );
            }
        }
    }
    Some(())
}

/// User-guided refinement (decobrush.txt §5.5). `levels` are a synthesis's
/// fields coarse to fine; `target` the finest-level appearance the user
/// asks for (ink SDF, px: the synthesized one with added strokes inked and
/// erased ones cleared) and `mask` the dilated refined pixels. At every
/// level, coarse to fine, the masked pixels take the nearest exemplar
/// neighbourhood of the target (no coherence) and are then corrected
/// inside the mask only; outside it the original coordinates stay locked.
/// The refined field remembers the mask ([`Field::user`]).
pub fn refine(
    style: &BrushStyle,
    levels: &[Field],
    target: &Grid<f32>,
    mask: &Grid<bool>,
    opts: &SynthOptions,
) -> Option<Field> {
    let first = levels.first()?;
    let n = levels.len();
    let down = |k: usize| 1usize << (n - 1 - k);
    let mask_at = |k: usize, f: &Field| {
        let d = down(k);
        Grid::from_fn(f.coords.width(), f.coords.height(), |x, y| {
            (0..d).any(|j| {
                (0..d).any(|i| mask.get_or((x * d + i) as isize, (y * d + j) as isize, false))
            })
        })
    };
    let mut field = first.clone();
    let m0 = mask_at(0, &field);
    seed_from_target(style, &mut field, target, &m0, down(0))?;
    correct_in(style, &mut field, opts, Some(&m0));
    for (k, original) in levels.iter().enumerate().skip(1) {
        let mut next = upsample(style, &field);
        let mk = mask_at(k, original);
        for y in 0..next.coords.height() {
            for x in 0..next.coords.width() {
                if !mk.get(x, y) {
                    next.coords
                        .set(x, y, original.coords.get_or(x as isize, y as isize, None));
                }
            }
        }
        // The user's strokes guide every level, not only the coarsest:
        // corrected on its own, a finer level pulls the thin added seed back
        // to what the neighbourhoods around it expect (the original).
        seed_from_target(style, &mut next, target, &mk, down(k))?;
        correct_in(style, &mut next, opts, Some(&mk));
        field = next;
    }
    if field.coords.width() == mask.width() && field.coords.height() == mask.height() {
        field.user = Some(mask.clone());
    }
    Some(field)
}
