//! The multiresolution EM loop of art-pattern-level-sets Alg. 1, with the
//! direction-aware matching and coherence-weighted voting of Brushables.
//!
//! Per level, coarse to fine: initialize (quilting at the coarsest level,
//! upsampling otherwise), then for each neighbourhood size and each of `N`
//! iterations: **M-step** — PatchMatch over all channels (Eq. 6 distance,
//! target patches rotated by the direction difference); **E-step** — every
//! SDF channel moved by the level set with the mean matched SDF as data
//! (Eq. 4) and curvature regularization (Eq. 5), weights `λ: 0.2 → 0.95`,
//! `μ: 0.8 → 0.05` in steps of `0.75/N` (Alg. 1); the colour channels
//! voted with the coherence and histogram weights of Brushables Eq. 7–8
//! (the histogram over each layer's ink and paper bins also weights the
//! SDF votes, so the mean of Eq. 2 keeps the tile's ink fraction).
//!
//! The energy (Eq. 6, with the Shape Hint term near a region's outline) of
//! the current image against the matches is recorded per level at its
//! start and after each M-step, so its decrease can be checked.

use super::atlas::Atlas;
use super::levelset::{self, Evolution};
use super::patchmatch::{
    patch_reach, Channels, Gather, Match, Nnf, Patch, Problem, ShapeTerm, Source,
};
use super::quilt::{block_reach, QuiltOptions, Quilter};
use super::shape::{self, Histogram, ShapeHint};
use super::tile::Tile;
use crate::field::DirectionGrid;
use crate::raster::{Bilinear, Grid};
use rayon::prelude::*;
use std::sync::OnceLock;

/// Parameters of the synthesis.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct EmParams {
    /// Colour weight `α` of Eq. 6 (SDF weight `1 − α`).
    pub alpha: f32,
    /// Finest patch radius `r` (patches are `(2r+1)²`).
    pub radius: usize,
    /// Pyramid levels (1 = finest only), at most: a level is only added
    /// while its tile [`represents_every_layer`].
    pub levels: usize,
    /// EM iterations `N` per neighbourhood size, fewer where a level's
    /// start is already close ([`iterations_at`]).
    pub iterations: usize,
    /// Level-set time steps per E-step (the paper uses 5).
    pub steps: usize,
    /// Seed of every random choice.
    pub seed: u64,
    /// Weight of the Shape Hint term (Brushables Eq. 6) per patch pixel:
    /// the χ² of two descriptors is weighted `shape · (2r+1)²` against the
    /// patch SSD. 0 leaves it out.
    pub shape: f32,
}

impl Default for EmParams {
    fn default() -> Self {
        EmParams {
            alpha: 0.25,
            radius: 4,
            levels: 3,
            iterations: 4,
            steps: 5,
            seed: 0,
            shape: 0.25,
        }
    }
}

/// The synthesized image at the finest level.
#[derive(Clone, Debug)]
pub struct Synthesis {
    /// One SDF per tile layer, target pixels, negative inside.
    pub layers: Vec<Grid<f32>>,
    /// Voted colour (0..1 RGB).
    #[cfg_attr(not(test), allow(dead_code))] // read by the tests
    pub colour: Grid<[f32; 3]>,
    /// Eq. 6 energy ([`interior_energy`]) per level used (coarse first): of the
    /// level's initial matches, then after each M-step, per neighbourhood
    /// size and iteration in order.
    pub energy: Vec<Vec<f64>>,
}

/// The image being synthesized at one level.
struct State {
    phi: Vec<Grid<f32>>,
    colour: Grid<[f32; 3]>,
}

/// Synthesizes a `width`×`height` image from `tile` (finest level), whose
/// texture follows `direction` (a unit vector per target pixel).
#[cfg(test)]
pub fn synthesize(tile: &Tile, direction: &DirectionGrid, params: &EmParams) -> Synthesis {
    synthesize_in(tile, direction, None, params)
}

/// [`synthesize`], searching and voting only the neighbourhoods that reach
/// `mask` (the region, same size as `direction`); pixels no neighbourhood
/// reaches keep their initial values. Energies count those neighbourhoods.
///
/// Prepares the tile on every call; to fill several regions from one tile
/// prepare it once ([`Prepared::new`]) and call [`Prepared::synthesize`].
#[cfg(test)]
pub fn synthesize_in(
    tile: &Tile,
    direction: &DirectionGrid,
    mask: Option<&Grid<bool>>,
    params: &EmParams,
) -> Synthesis {
    Prepared::new(std::slice::from_ref(tile), params).synthesize(direction, mask, params.seed)
}

/// The source side of a synthesis, which depends on the exemplars and the
/// parameters but not on the target or the seed, so every region filled
/// from one style shares it: the exemplar pyramid (halved while
/// [`represents_every_layer`]) and per level the exemplars laid out on one
/// atlas with their weighted channels, direction angles (radians) and
/// values interleaved for voting, the pooled ink fractions, and per
/// neighbourhood radius the rotated patch offsets, the allowed centres and
/// (made when first asked) the Shape Hint descriptors of the exemplars'
/// edges.
#[derive(Clone, Debug)]
pub struct Prepared {
    /// The parameters it was made for (the seed is given per synthesis).
    params: EmParams,
    /// Pyramid levels, finest first (of the thickened exemplars).
    levels: Vec<Level>,
    /// Per layer, how far (finest px) its ink was grown for synthesis
    /// ([`thickening`]); taken off the result.
    grown: Vec<f32>,
    /// Ink fraction of each layer of the finest exemplars as drawn.
    ink: Vec<f64>,
}

/// One pyramid level of a [`Prepared`] source.
#[derive(Clone, Debug)]
struct Level {
    /// The exemplars at this level, in style order.
    tiles: Vec<Tile>,
    /// Their atlas, channels and angles.
    source: Source,
    /// Per atlas pixel: each layer's SDF, then the colour.
    texels: Vec<f32>,
    /// Number of SDF layers.
    layers: usize,
    /// Ink fraction of each layer over all exemplars' patterns.
    ink: Vec<f64>,
    /// Neighbourhood sizes in the order they run.
    scales: Vec<Scale>,
    /// Quilting tables (the coarsest level only).
    quilter: Option<Quilter>,
    /// Quilting's block side, pixels.
    block: usize,
}

/// One neighbourhood radius of a [`Level`].
#[derive(Clone, Debug)]
struct Scale {
    radius: usize,
    patch: Patch,
    gather: Gather,
    /// Allowed patch centres of the atlas for this radius.
    centres: Vec<(u32, u32)>,
    /// Shape Hint descriptors of every atlas pixel (ring `r`, bins `r/2`)
    /// and whether they hold everywhere (a swatch's own edge); `None` when
    /// no exemplar has an edge.
    hint: OnceLock<Option<(Grid<Histogram>, bool)>>,
}

impl Prepared {
    /// Prepares `tiles` (one per exemplar, all with the same layers) for
    /// synthesis with `params` (its seed is not used).
    pub fn new(tiles: &[Tile], params: &EmParams) -> Prepared {
        let layers = tiles.first().map_or(0, |t| t.layers.len());
        let area: usize = tiles.iter().map(Tile::area).sum();
        let ink = (0..layers)
            .map(|l| tiles.iter().map(|t| t.ink_px(l)).sum::<usize>() as f64 / area.max(1) as f64)
            .collect();
        let grown = thickening(tiles);
        let thick: Vec<Tile> = tiles.iter().map(|t| t.grown(&grown)).collect();
        let mut pyramid = vec![thick];
        while pyramid.len() < params.levels {
            let half: Vec<Tile> = pyramid[pyramid.len() - 1].iter().map(Tile::half).collect();
            let room = half
                .iter()
                .all(|t| t.periodic || t.width().min(t.height()) >= MIN_SWATCH_SIDE);
            if !represents_every_layer(&half) || !room {
                break;
            }
            pyramid.push(half);
        }
        let n = pyramid.len();
        let clamp = clamp_of(params);
        let levels = pyramid
            .into_iter()
            .enumerate()
            .map(|(level, ts)| Level::new(ts, level, n, params, clamp))
            .collect();
        Prepared {
            params: *params,
            levels,
            grown,
            ink,
        }
    }

    /// Fraction of the finest exemplars' pattern pixels inside layer `m`
    /// as drawn (0 for a layer they do not have).
    pub fn tile_ink(&self, m: usize) -> f64 {
        self.ink.get(m).copied().unwrap_or(0.0)
    }

    /// Synthesizes an image from these exemplars and parameters whose
    /// texture follows `direction` (a unit vector per target pixel),
    /// searching and voting only the neighbourhoods that reach `mask` (the
    /// region, same size as `direction`; pixels no neighbourhood reaches
    /// keep their initial values, and energies count only those
    /// neighbourhoods), with `seed` as the seed of every random choice:
    /// the same result, bit for bit, whichever regions were filled before.
    pub fn synthesize(
        &self,
        direction: &DirectionGrid,
        mask: Option<&Grid<bool>>,
        seed: u64,
    ) -> Synthesis {
        let params = EmParams {
            seed,
            ..self.params
        };
        let mut s = synthesize_levels(&self.levels, direction, mask, &params);
        for (l, &g) in s.layers.iter_mut().zip(&self.grown) {
            if g > 0.0 {
                for v in l.data_mut() {
                    *v += g;
                }
            }
        }
        s
    }
}

/// Half-width, finest pixels, below which a layer's ink is a line that is
/// grown for synthesis.
pub const LINE_DEPTH: f32 = 3.0;

/// How far to grow each layer's ink for synthesis: a layer whose ink is
/// nowhere deeper than [`LINE_DEPTH`] (lines up to 6 px wide) is grown
/// towards that depth, but never so far that its ink gets deeper than the
/// paper between it (a dense layer's narrow paper gaps would become the
/// lines that averaging wipes out). Averaging the signed distances of
/// neighbourhoods that disagree by a pixel or two wipes out a line one or
/// two pixels wide but only shifts the edges of a wide one; a line grown
/// by `g` and taken back by `g` after synthesis (both exact on a distance
/// field) keeps its drawn width (DecoBrush §4.1 thickens lines the same
/// way).
pub fn thickening(tiles: &[Tile]) -> Vec<f32> {
    let layers = tiles.first().map_or(0, |t| t.layers.len());
    (0..layers)
        .map(|l| {
            let extreme = |sign: f32| {
                tiles
                    .iter()
                    .map(|t| {
                        t.layers[l]
                            .sdf
                            .data()
                            .iter()
                            .map(|&d| d * sign)
                            .fold(0.0f32, f32::max)
                    })
                    .fold(0.0f32, f32::max)
            };
            let (depth, paper) = (extreme(-1.0), extreme(1.0));
            if depth > 0.0 && depth < LINE_DEPTH {
                (LINE_DEPTH - depth).min((paper - depth) / 2.0).max(0.0)
            } else {
                0.0
            }
        })
        .collect()
}

impl Level {
    /// Level `level` of `n` (0 finest) made of `tiles`.
    fn new(tiles: Vec<Tile>, level: usize, n: usize, params: &EmParams, clamp: f32) -> Level {
        // Neighbourhood sizes: at the coarsest level a larger one first. A
        // patch of a swatch that is not periodic must fit inside it turned
        // any way with room to move: its reach at most a quarter of the
        // swatch's shorter side.
        let side = |periodic: bool| {
            tiles
                .iter()
                .filter(|t| periodic || !t.periodic)
                .map(|t| t.width().min(t.height()))
                .min()
        };
        let smallest = side(true).unwrap_or(1);
        let room = side(false).map(|s| s / 4);
        let fits = |reach: usize| room.is_none_or(|q| reach <= q);
        let mut max_r = (smallest / 4).max(1);
        while max_r > 1 && !fits(patch_reach(max_r)) {
            max_r -= 1;
        }
        let mut radii = vec![params.radius.min(max_r).max(1)];
        if level + 1 == n && n > 1 && 2 * radii[0] <= max_r {
            radii.insert(0, 2 * radii[0]);
        }
        let coarsest = level + 1 == n;
        let mut block = (4 * radii[0] + 2).min(smallest);
        while block > 2 && !fits(block_reach(block)) {
            block -= 1;
        }
        let r_max = radii.iter().copied().max().unwrap_or(1);
        // Enough margin for any turned patch, a Shape Hint's outer bins
        // (ring r, bins r/2) and, at the coarsest level, a quilting block.
        let mut margin = patch_reach(r_max).max(r_max + r_max.div_ceil(2) + 2);
        if coarsest {
            margin = margin.max(block_reach(block));
        }
        // A swatch's patch centres: its shape widened by the finest patch
        // radius of the level (a patch reaching the shape is allowed).
        let r_min = radii.iter().copied().min().unwrap_or(1) as f32;
        let blocks = tiles
            .iter()
            .map(|t| {
                let near = t.shape.as_ref().map(|s| {
                    let d2 = crate::raster::edt::squared_edt(s);
                    d2.map(|v| v <= r_min * r_min)
                });
                (t.width(), t.height(), t.periodic, near)
            })
            .collect();
        let atlas = Atlas::new(blocks, margin);
        // For every atlas pixel, the exemplar pixel it shows.
        let shows: Vec<Grid<(u32, u32)>> = tiles
            .iter()
            .map(|t| Grid::from_fn(t.width(), t.height(), |x, y| (x as u32, y as u32)))
            .collect();
        let shows = atlas.pad(&shows.iter().collect::<Vec<_>>(), (0, 0));
        let layers = tiles.first().map_or(0, |t| t.layers.len());
        let tile_channels: Vec<Channels> = tiles
            .iter()
            .map(|t| {
                channels_of(
                    &t.layers.iter().map(|l| l.sdf.clone()).collect::<Vec<_>>(),
                    &t.colour,
                    params.alpha,
                    clamp,
                )
            })
            .collect();
        let depth = layers + 3;
        let mut data = Vec::with_capacity(atlas.width * atlas.height * depth);
        let mut texels = Vec::with_capacity(atlas.width * atlas.height * depth);
        let mut angle = Grid::new(atlas.width, atlas.height, 0.0f32);
        for y in 0..atlas.height {
            let b = atlas.block_of(y);
            let t = &tiles[b];
            for x in 0..atlas.width {
                let (sx, sy) = shows.get(x, y);
                let (sx, sy) = (sx as usize, sy as usize);
                data.extend_from_slice(tile_channels[b].px(sx, sy));
                // The tile's layer distances and colour interleaved per
                // pixel: one cache line per vote instead of one per grid.
                texels.extend(t.layers.iter().map(|l| l.sdf.get(sx, sy)));
                texels.extend(t.colour.get(sx, sy));
                let d = t.direction.get(sx, sy);
                angle.set(x, y, d[1].atan2(d[0]));
            }
        }
        let source = Source {
            channels: Channels {
                width: atlas.width,
                height: atlas.height,
                depth,
                data,
            },
            angle,
            atlas,
        };
        let scales: Vec<Scale> = radii
            .into_iter()
            .map(|r| {
                let patch = Patch::new(r);
                let gather = Gather::new(&source, &patch);
                Scale {
                    radius: r,
                    centres: source.atlas.centres(patch_reach(r)),
                    patch,
                    gather,
                    hint: OnceLock::new(),
                }
            })
            .collect();
        let area: usize = tiles.iter().map(Tile::area).sum();
        let ink = (0..layers)
            .map(|l| tiles.iter().map(|t| t.ink_px(l)).sum::<usize>() as f64 / area.max(1) as f64)
            .collect();
        let quilter = coarsest.then(|| Quilter::new(&source, block));
        Level {
            tiles,
            source,
            texels,
            layers,
            ink,
            scales,
            quilter,
            block,
        }
    }

    /// The Shape Hint descriptors of scale `sc` (ring `r`, bins `r/2`) of
    /// every atlas pixel, from each exemplar's edge: a swatch's shape
    /// outline (holding everywhere), else a tile's edge line; `None` when
    /// no exemplar has one.
    fn hints<'a>(&self, sc: &'a Scale) -> Option<&'a (Grid<Histogram>, bool)> {
        sc.hint
            .get_or_init(|| {
                let edges: Vec<Option<Grid<bool>>> = self
                    .tiles
                    .iter()
                    .map(|t| {
                        t.shape_edge()
                            .or_else(|| t.edge.map(|e| e.raster(t.width(), t.height())))
                    })
                    .collect();
                if edges.iter().all(Option::is_none) {
                    return None;
                }
                let everywhere = self.tiles.iter().any(|t| t.shape.is_some());
                let grids: Vec<Grid<bool>> = edges
                    .into_iter()
                    .zip(&self.tiles)
                    .map(|(e, t)| e.unwrap_or_else(|| Grid::new(t.width(), t.height(), false)))
                    .collect();
                let atlas = &self.source.atlas;
                let edge = atlas.pad(&grids.iter().collect::<Vec<_>>(), false);
                // A swatch's margin repeats its border, which is no edge.
                let edge = Grid::from_fn(atlas.width, atlas.height, |x, y| {
                    let (b, ex, ey) = atlas.block_pixel(x, y);
                    let bl = &atlas.blocks[b];
                    edge.get(x, y)
                        && (bl.periodic
                            || (ex >= 0 && ey >= 0 && ex < bl.w as i64 && ey < bl.h as i64))
                });
                let (ring, bin) = (sc.radius as f32, (sc.radius as f32 / 2.0).max(1.0));
                Some((
                    ShapeHint::new(&edge, false, ring, bin).histograms(&self.source.angle),
                    everywhere,
                ))
            })
            .as_ref()
    }
}

/// The SDF clamp `K` of [`channels_of`], pixels.
fn clamp_of(params: &EmParams) -> f32 {
    (params.radius as f32 + 1.0).max(2.0)
}

/// The multiresolution EM over prepared levels (finest first).
fn synthesize_levels(
    tiles: &[Level],
    direction: &DirectionGrid,
    mask: Option<&Grid<bool>>,
    params: &EmParams,
) -> Synthesis {
    let (width, height) = (direction.width(), direction.height());
    let levels = tiles.len();
    let mut state: Option<State> = None;
    // The field and the atlas it points into.
    let mut nnf: Option<(Nnf, &Atlas)> = None;
    let mut energy = Vec::new();
    for level in (0..levels).rev() {
        let lv = &tiles[level];
        let f = 1usize << level;
        let (w, h) = (width.div_ceil(f).max(1), height.div_ceil(f).max(1));
        let target_angle = Grid::from_fn(w, h, |x, y| {
            let d = direction.get(
                (x * f + f / 2).min(width - 1),
                (y * f + f / 2).min(height - 1),
            );
            d[1].atan2(d[0])
        });
        // Squared distance to the region at this level (any pixel of a
        // block counts).
        let level_mask = mask.map(|m| {
            Grid::from_fn(w, h, |x, y| {
                (y * f..((y + 1) * f).min(height))
                    .any(|yy| (x * f..((x + 1) * f).min(width)).any(|xx| m.get(xx, yy)))
            })
        });
        let near = level_mask.as_ref().map(crate::raster::edt::squared_edt);
        let first_r = lv.scales.first().map_or(1, |s| s.radius);
        let clamp = clamp_of(params);
        let source = &lv.source;
        let atlas = &source.atlas;
        let stride = lv.layers + 3;
        let texel = |x: u32, y: u32| {
            let i = (y as usize * atlas.width + x as usize) * stride;
            &lv.texels[i..i + stride]
        };
        let mut st = match state.take() {
            None => {
                let qo = QuiltOptions {
                    block: lv.block,
                    overlap: (lv.block / 4).max(1),
                    candidates: 4096,
                    seed: params.seed,
                };
                let map = match &lv.quilter {
                    Some(q) => q.quilt(source, &target_angle, &qo),
                    None => Quilter::new(source, lv.block).quilt(source, &target_angle, &qo),
                };
                let phi = (0..lv.layers)
                    .map(|l| {
                        Grid::from_fn(w, h, |x, y| {
                            let (sx, sy) = map.get(x, y);
                            texel(sx, sy)[l]
                        })
                    })
                    .collect();
                let colour = Grid::from_fn(w, h, |x, y| {
                    let (sx, sy) = map.get(x, y);
                    let t = texel(sx, sy);
                    [t[lv.layers], t[lv.layers + 1], t[lv.layers + 2]]
                });
                let spacing = spacing_of(first_r);
                let (cols, rows) = Nnf::shape(w, h, spacing);
                let reach = patch_reach(first_r);
                let matches = (0..cols * rows)
                    .map(|k| {
                        let (sx, sy) = map.get(
                            ((k % cols) * spacing).min(w - 1),
                            ((k / cols) * spacing).min(h - 1),
                        );
                        let (x, y) = atlas.bring_in(
                            atlas.block_of(sy as usize),
                            sx as i64,
                            sy as i64,
                            reach,
                        );
                        Match {
                            x,
                            y,
                            cost: f32::INFINITY,
                        }
                    })
                    .collect();
                nnf = Some((
                    Nnf {
                        cols,
                        rows,
                        spacing,
                        matches,
                    },
                    atlas,
                ));
                State { phi, colour }
            }
            Some(prev) => upsample(&prev, w, h),
        };
        let mut level_energy = Vec::new();
        for (ri, sc) in lv.scales.iter().enumerate() {
            let r = sc.radius;
            let patch = &sc.patch;
            let spacing = spacing_of(r);
            let mut field = resample_nnf(nnf.take(), atlas, w, h, spacing, patch_reach(r));
            let n = iterations_at(level, levels, params.iterations);
            // Shape Hint descriptors (ring of radius r, bins r/2) of the
            // exemplars' edges and of the region's outline.
            let hints = match &level_mask {
                Some(lm) if params.shape > 0.0 => lv.hints(sc).map(|(src, everywhere)| {
                    let (ring, bin) = (r as f32, (r as f32 / 2.0).max(1.0));
                    let tgt = ShapeHint::new(&shape::outline(lm), false, ring, bin);
                    (src, tgt.histograms(&target_angle), *everywhere)
                }),
                _ => None,
            };
            // Alg. 1's weights, λ from 0.2 and μ from 0.8 in steps of
            // 0.75/N; a level run with fewer iterations (one whose start is
            // already close) takes the schedule's last ones.
            let full = params.iterations.max(n);
            let skipped = (full - n) as f32 * 0.75 / full as f32;
            let (mut lambda, mut mu) = (0.2 + skipped, 0.8 - skipped);
            // The level set moves where an active neighbourhood's patch
            // reaches, with a pixel to spare.
            let live = near.as_ref().map(|d| levelset::Live {
                near: d,
                reach2: (r as f32 * std::f32::consts::SQRT_2 + 1.0 + patch_reach(r) as f32 + 1.0)
                    .powi(2),
            });
            for it in 0..n {
                let target = channels_of(&st.phi, &st.colour, params.alpha, clamp);
                let reach = (r as f32 * std::f32::consts::SQRT_2 + 1.0).powi(2);
                let active: Option<Vec<bool>> = near.as_ref().map(|d| {
                    (0..field.matches.len())
                        .map(|k| {
                            let (x, y) = field.centre(k);
                            d.get(x.min(w - 1), y.min(h - 1)) <= reach
                        })
                        .collect()
                });
                let mut pb = Problem::with_gather(
                    source,
                    &target,
                    &target_angle,
                    patch,
                    &sc.gather,
                    &sc.centres,
                );
                if let Some(a) = &active {
                    pb = pb.with_active(a);
                }
                if let Some((src, tgt, everywhere)) = &hints {
                    pb = pb.with_shape(ShapeTerm {
                        source: src,
                        target: tgt,
                        weight: params.shape * ((2 * r + 1) * (2 * r + 1)) as f32,
                        everywhere: *everywhere,
                    });
                }
                pb.refresh(&mut field);
                if ri == 0 && it == 0 {
                    // The level's starting energy: the initial matches
                    // against the quilted or upsampled image.
                    level_energy.push(interior_energy(&field, r, w, h, active.as_deref()));
                }
                let round = ((level * 8 + ri) * 64 + it) as u64;
                pb.improve(&mut field, params.seed, round);
                level_energy.push(interior_energy(&field, r, w, h, active.as_deref()));
                // E-step.
                let hist = histogram_weights(&st.phi, &lv.ink, near.as_ref());
                let votes = vote(&pb, &field, lv, &hist, w, h);
                // Eq. 4 sums the data force over the |s_x| overlapping
                // neighbourhoods; the level set uses their mean, so the
                // curvature weight is divided by |s_x| to keep Eq. 5's balance.
                let overlap = ((2 * r + 1) as f32 / spacing as f32).powi(2);
                let mu_level = mu / overlap;
                let ev = Evolution {
                    lambda,
                    mu: mu_level,
                    dt: 0.2,
                    steps: params.steps,
                    band: r as f32 + 2.0,
                };
                // Layers evolve independently: one task each, as many at
                // once as the memory allowance for them holds.
                let k = super::layers_at_once(st.phi.len(), w * h);
                for (phis, sdfs) in st.phi.chunks_mut(k).zip(votes.sdf.chunks(k)) {
                    phis.par_iter_mut()
                        .zip(sdfs)
                        .for_each(|(phi, (mean, count))| {
                            levelset::evolve(phi, mean, count, &ev, live);
                        });
                }

                st.colour = votes.colour;
                lambda += 0.75 / full as f32;
                mu -= 0.75 / full as f32;
            }
            nnf = Some((field, atlas));
        }
        energy.push(level_energy);
        state = Some(st);
    }
    let st = state.unwrap_or_else(|| State {
        phi: Vec::new(),
        colour: Grid::new(width, height, [1.0; 3]),
    });
    Synthesis {
        layers: st.phi,
        colour: st.colour,
        energy,
    }
}

/// EM iterations per neighbourhood size at pyramid level `level` (0
/// finest) of `levels`, given `N` = `iterations`: fewer where the level
/// starts close to its result, as CaTS §4.1 reduces them at finer levels.
/// The finest level of a pyramid (the upsampled coarser result) runs a
/// quarter of `N`; a coarsest level at half the finest resolution (a
/// pyramid of two) half of `N`: it starts from quilting's copy of the
/// exemplar, whose energy is near zero and which Alg. 1's E-steps raise,
/// yet they still mend the quilt's seams and follow the field's turns. A
/// coarsest level at a quarter of the resolution or coarser, which lays
/// out the whole pattern at little cost, the middle levels, whose
/// upsampled start is still far, and a single level run all `N`. At least
/// one everywhere.
pub fn iterations_at(level: usize, levels: usize, iterations: usize) -> usize {
    let n = if levels > 1 && level == 0 {
        iterations.div_ceil(4)
    } else if levels == 2 && level == 1 {
        iterations.div_ceil(2)
    } else {
        iterations
    };
    n.max(1)
}

/// Shortest side, pixels, of a swatch that is not periodic at any pyramid
/// level: smaller, its patches would have no room to move in it.
pub const MIN_SWATCH_SIDE: usize = 48;

/// Least depth, pixels, that every layer's ink must reach somewhere in a
/// pyramid level's tile: half a pixel, a stroke one pixel wide.
pub const MIN_LEVEL_DEPTH: f32 = 0.5;

/// Whether (halved) exemplars still hold every layer: each layer's SDF
/// reaches [`MIN_LEVEL_DEPTH`] inside in one of them. Strokes thinner than a pixel break
/// into dots or vanish at that level (the scales' 2.4-unit arcs in a 96 px
/// tile at quarter resolution), and the coarsest level, which lays out the
/// whole pattern (Alg. 1), would lay it out from debris.
pub fn represents_every_layer(tiles: &[Tile]) -> bool {
    let layers = tiles.first().map_or(0, |t| t.layers.len());
    (0..layers).all(|l| {
        tiles.iter().any(|t| {
            let deepest = t.layers[l]
                .sdf
                .data()
                .iter()
                .copied()
                .fold(0.0f32, f32::min);
            -deepest >= MIN_LEVEL_DEPTH
        })
    })
}

/// Eq. 6 over the neighbourhoods that lie inside the grid (those crossing
/// its edge compare clamped pixels and are not neighbourhoods of `X`).
/// With `active`, only the flagged neighbourhoods count.
pub fn interior_energy(nnf: &Nnf, r: usize, w: usize, h: usize, active: Option<&[bool]>) -> f64 {
    nnf.matches
        .iter()
        .enumerate()
        .filter(|(k, _)| {
            let (x, y) = nnf.centre(*k);
            let on = active.is_none_or(|a| a.get(*k).copied().unwrap_or(true));
            on && x >= r && y >= r && x + r < w && y + r < h
        })
        .map(|(_, m)| m.cost as f64)
        .sum()
}

/// Centre spacing `w/4` of art-pattern-level-sets §2 (at least 1).
fn spacing_of(r: usize) -> usize {
    ((2 * r + 1) / 4).max(1)
}

/// The weighted channel image: `√(1−α)·clamp(Φ/K)` per layer, then
/// `√α·rgb`, so a plain SSD is the Eq. 6 energy.
pub fn channels_of(phi: &[Grid<f32>], colour: &Grid<[f32; 3]>, alpha: f32, clamp: f32) -> Channels {
    let (w, h) = (colour.width(), colour.height());
    let (wd, wa) = ((1.0 - alpha).max(0.0).sqrt(), alpha.max(0.0).sqrt());
    let depth = phi.len() + 3;
    let mut data = Vec::with_capacity(w * h * depth);
    for y in 0..h {
        for x in 0..w {
            for p in phi {
                data.push(wd * p.get(x, y).clamp(-clamp, clamp) / clamp);
            }
            data.extend(colour.get(x, y).map(|c| wa * c));
        }
    }
    Channels {
        width: w,
        height: h,
        depth,
        data,
    }
}

/// The previous field (with the atlas it points into) brought to a new
/// spacing or resolution on `atlas`: each new centre takes the match of
/// the nearest old centre (scaled by 2 across a level, CaTS Alg. 2)
/// shifted by the offset between them, in the same exemplar, brought in
/// for patches reaching `reach` px.
fn resample_nnf(
    old: Option<(Nnf, &Atlas)>,
    atlas: &Atlas,
    w: usize,
    h: usize,
    spacing: usize,
    reach: usize,
) -> Nnf {
    let (cols, rows) = Nnf::shape(w, h, spacing);
    let matches = match &old {
        None => {
            let (x, y) = atlas.centres(reach)[0];
            vec![
                Match {
                    x,
                    y,
                    cost: f32::INFINITY
                };
                cols * rows
            ]
        }
        Some((o, from)) => {
            // Old target extent in pixels decides the scale factor.
            let old_w = (o.cols - 1) * o.spacing + 1;
            let scale = if old_w * 2 <= w + 2 * o.spacing { 2 } else { 1 };
            (0..cols * rows)
                .map(|k| {
                    let (qx, qy) = ((k % cols) * spacing, (k / cols) * spacing);
                    let (cx, cy) = (qx / scale, qy / scale);
                    let i = ((cx + o.spacing / 2) / o.spacing).min(o.cols - 1);
                    let j = ((cy + o.spacing / 2) / o.spacing).min(o.rows - 1);
                    let m = o.matches[j * o.cols + i];
                    let ox = qx as i64 - (i * o.spacing * scale) as i64;
                    let oy = qy as i64 - (j * o.spacing * scale) as i64;
                    let (b, ex, ey) = from.block_pixel(m.x as usize, m.y as usize);
                    let bl = &atlas.blocks[b];
                    let (x, y) = atlas.bring_in(
                        b,
                        bl.x0 as i64 + ex * scale as i64 + ox,
                        bl.y0 as i64 + ey * scale as i64 + oy,
                        reach,
                    );
                    Match {
                        x,
                        y,
                        cost: f32::INFINITY,
                    }
                })
                .collect()
        }
    };
    Nnf {
        cols,
        rows,
        spacing,
        matches,
    }
}

/// Bilinear upsampling to the next level: distances doubled (pixel unit
/// halves), colours interpolated. Each pixel's read position on the
/// coarser grid is found once and read from every layer and channel.
fn upsample(prev: &State, w: usize, h: usize) -> State {
    let (pw, ph) = (prev.colour.width(), prev.colour.height());
    let chans: Vec<Grid<f32>> = (0..3).map(|k| prev.colour.map(|c| c[k])).collect();
    let mut phi: Vec<Vec<f32>> = prev.phi.iter().map(|_| Vec::with_capacity(w * h)).collect();
    let colour = Grid::from_fn(w, h, |x, y| {
        let at = Bilinear::at(
            pw,
            ph,
            (x as f64 + 0.5) * pw as f64 / w as f64,
            (y as f64 + 0.5) * ph as f64 / h as f64,
        );
        for (out, g) in phi.iter_mut().zip(&prev.phi) {
            out.push(2.0 * g.read(&at));
        }
        [chans[0].read(&at), chans[1].read(&at), chans[2].read(&at)]
    });
    let phi = phi
        .into_iter()
        .map(|v| Grid::from_vec(w, h, v).expect("one value per pixel by construction"))
        .collect();
    State { phi, colour }
}

/// What the matched neighbourhoods say about each pixel.
struct Votes {
    /// Per layer: mean matched SDF (tile px ≡ target px) and count.
    sdf: Vec<(Grid<f32>, Grid<f32>)>,
    /// Coherence-weighted colour (Brushables Eq. 7).
    colour: Grid<[f32; 3]>,
}

/// Steepness of the histogram weight.
const HISTOGRAM_GAMMA: f32 = 4.0;

/// The histogram weight `w_h` of Brushables Eq. 7 (Kopf et al. 2007) for
/// the ink and paper bins of each layer: a bin over-represented in the
/// current image relative to the tile (`H_s/H_e − 1 > 0`) has its
/// candidates weighted `1/(1 + γ·(H_s/H_e − 1))`, so voting does not drift
/// away from the tile's ink fraction (`tile_ink`, per layer). Counted over
/// the region (`near` = 0) when there is one.
fn histogram_weights(
    phi: &[Grid<f32>],
    tile_ink: &[f64],
    near: Option<&Grid<f32>>,
) -> Vec<[f32; 2]> {
    phi.iter()
        .enumerate()
        .map(|(l, g)| {
            let (mut ink, mut all) = (0usize, 0usize);
            for (i, &v) in g.data().iter().enumerate() {
                if near.is_none_or(|d| d.data().get(i).is_some_and(|&e| e == 0.0)) {
                    all += 1;
                    ink += usize::from(v < 0.0);
                }
            }
            let hs_ink = if all > 0 {
                ink as f32 / all as f32
            } else {
                0.0
            };
            let he_ink = tile_ink.get(l).copied().unwrap_or(0.0) as f32;
            let w = |hs: f32, he: f32| {
                if he > 0.0 {
                    1.0 / (1.0 + HISTOGRAM_GAMMA * (hs / he - 1.0).max(0.0))
                } else {
                    1.0
                }
            };
            [w(hs_ink, he_ink), w(1.0 - hs_ink, 1.0 - he_ink)]
        })
        .collect()
}

/// `exp(−d²/2σ_c²)` of Brushables Eq. 8 for the whole squared pixel
/// distances `d² < 64` (torus offsets are whole pixels).
static COHERENCE_EXP: std::sync::LazyLock<Vec<f32>> =
    std::sync::LazyLock::new(|| (0..64).map(|k| (-(k as f32) / (2.0 * 2.0)).exp()).collect());

/// Brushables Eq. 8: how well the rigid maps of neighbouring centres agree
/// with centre `k`'s own (σ_c² = 2), averaged, plus a floor.
fn coherence(pb: &Problem, nnf: &Nnf, k: usize) -> f32 {
    let r = pb.patch.radius;
    let (qx, qy) = nnf.centre(k);
    let m = nnf.matches[k];
    let atlas = &pb.source.atlas;
    let (ci, cj) = (k % nnf.cols, k / nnf.cols);
    let reach = (r / nnf.spacing).max(1);
    // Neighbours lie within the patch: their rotated offsets are in the
    // patch's table for the centre's angle bin.
    let table = pb.patch.table(pb.bin(m.x as usize, m.y as usize, qx, qy));
    let side = 2 * r as i32 + 1;
    let (mut sum, mut n) = (0.0f32, 0u32);
    for j in cj.saturating_sub(reach)..=(cj + reach).min(nnf.rows - 1) {
        for i in ci.saturating_sub(reach)..=(ci + reach).min(nnf.cols - 1) {
            if (i, j) == (ci, cj) {
                continue;
            }
            let o = nnf.matches[j * nnf.cols + i];
            let (dx, dy) = (
                (i * nnf.spacing) as i32 - qx as i32,
                (j * nnf.spacing) as i32 - qy as i32,
            );
            let Some(e) = table.get(((dy + r as i32) * side + dx + r as i32) as usize) else {
                continue;
            };
            // Distance between the two images of the neighbour (on the
            // torus within a tile, far across exemplars).
            let d2 = atlas.d2(
                (m.x as i64 + e.2 as i64, m.y as i64 + e.3 as i64),
                (o.x as i64, o.y as i64),
            );
            sum += COHERENCE_EXP
                .get(d2 as usize)
                .copied()
                .unwrap_or_else(|| (-d2 / (2.0 * 2.0)).exp());
            n += 1;
        }
    }
    1e-3 + if n > 0 { sum / n as f32 } else { 1.0 }
}

/// The E-step's gathering: every pixel collects the tile values its
/// overlapping matched neighbourhoods put there. Rows are gathered in
/// parallel, each scanning the centres whose patches cross it.
fn vote(pb: &Problem, nnf: &Nnf, lv: &Level, hist: &[[f32; 2]], w: usize, h: usize) -> Votes {
    let per_centre: Vec<(f32, usize)> = (0..nnf.matches.len())
        .into_par_iter()
        .map(|k| {
            if !pb.is_active(k) {
                return (0.0, 0);
            }
            let (qx, qy) = nnf.centre(k);
            let m = nnf.matches[k];
            (
                coherence(pb, nnf, k),
                pb.bin(m.x as usize, m.y as usize, qx, qy),
            )
        })
        .collect();
    let r = pb.patch.radius as i64;
    let s = nnf.spacing as i64;
    let side = 2 * r + 1;
    let layers = lv.layers;
    let aw = lv.source.atlas.width as i64;
    let stride = layers + 3;
    let tv = &lv.texels;
    // Each row gathers its sums and writes its means straight into the
    // result (the layers' means interleaved per pixel), so no more than a
    // row's sums per thread are held beside it.
    let lw = layers.max(1);
    let mut means = vec![0.0f32; w * h * lw];
    let mut counts = vec![0.0f32; w * h];
    let mut colours = vec![[1.0f32; 3]; w * h];
    means
        .par_chunks_mut((w * lw).max(1))
        .zip(counts.par_chunks_mut(w.max(1)))
        .zip(colours.par_chunks_mut(w.max(1)))
        .enumerate()
        .for_each(|(y, ((mean_row, count_row), colour_row))| {
            let mut row = RowVote {
                sdf: vec![0.0; w * layers],
                sdf_weight: vec![0.0; w * layers],
                count: vec![0.0; w],
                colour: vec![[0.0; 3]; w],
                weight: vec![0.0; w],
            };
            let y = y as i64;
            let (j0, j1) = (
                ((y - r).max(0) + s - 1) / s,
                ((y + r) / s).min(nnf.rows as i64 - 1),
            );
            for j in j0..=j1 {
                let dy = y - j * s;
                for i in 0..nnf.cols as i64 {
                    let k = (j * nnf.cols as i64 + i) as usize;
                    if !pb.is_active(k) {
                        continue;
                    }
                    let m = nnf.matches[k];
                    let (wc, b) = per_centre[k];
                    let table = pb.patch.table(b);
                    let qx = i * s;
                    let (x0, x1) = ((qx - r).max(0), (qx + r).min(w as i64 - 1));
                    for x in x0..=x1 {
                        let e = table[((dy + r) * side + x - qx + r) as usize];
                        // The atlas's margin holds a tile's wrap-around.
                        let sx = m.x as i64 + e.2 as i64;
                        let sy = m.y as i64 + e.3 as i64;
                        let xu = x as usize;
                        let base = ((sy * aw + sx) as usize) * stride;
                        let Some(px) = tv.get(base..base + stride) else {
                            continue;
                        };
                        let mut wh0 = 1.0;
                        let o = xu * layers;
                        let sums = row.sdf[o..o + layers]
                            .iter_mut()
                            .zip(&mut row.sdf_weight[o..o + layers]);
                        for (l, ((s, sw), (&v, hl))) in
                            sums.zip(px[..layers].iter().zip(hist)).enumerate()
                        {
                            let wh = hl[usize::from(v >= 0.0)];
                            if l == 0 {
                                wh0 = wh;
                            }
                            *s += wh * v;
                            *sw += wh;
                        }
                        row.count[xu] += 1.0;
                        let wv = wc * wh0;
                        for (acc, v) in row.colour[xu].iter_mut().zip(&px[layers..]) {
                            *acc += wv * v;
                        }
                        row.weight[xu] += wv;
                    }
                }
            }
            for x in 0..w {
                let n = row.count[x];
                for l in 0..layers {
                    let (i, o) = (x * layers + l, x * lw + l);
                    mean_row[o] = if n > 0.0 && row.sdf_weight[i] > 0.0 {
                        row.sdf[i] / row.sdf_weight[i]
                    } else {
                        0.0
                    };
                }
                count_row[x] = n;
                let ws = row.weight[x];
                colour_row[x] = if ws > 0.0 {
                    row.colour[x].map(|c| c / ws)
                } else {
                    [1.0; 3]
                };
            }
        });
    let count = Grid::from_vec(w, h, counts).unwrap_or_else(|| Grid::new(w, h, 0.0));
    let sdf: Vec<(Grid<f32>, Grid<f32>)> = if layers == 1 {
        let mean = Grid::from_vec(w, h, means).unwrap_or_else(|| Grid::new(w, h, 0.0));
        vec![(mean, count)]
    } else {
        (0..layers)
            .map(|l| {
                let mean = Grid::from_fn(w, h, |x, y| means[(y * w + x) * lw + l]);
                (mean, count.clone())
            })
            .collect()
    };
    let colour = Grid::from_vec(w, h, colours).unwrap_or_else(|| Grid::new(w, h, [1.0; 3]));
    Votes { sdf, colour }
}

/// One row's vote sums.
struct RowVote {
    sdf: Vec<f32>,
    sdf_weight: Vec<f32>,
    count: Vec<f32>,
    colour: Vec<[f32; 3]>,
    weight: Vec<f32>,
}
