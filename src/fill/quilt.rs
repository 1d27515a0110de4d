//! Initialization by image quilting (Efros & Freeman 2001), with the SDF
//! channels padded to every patch (art-pattern-level-sets §2).
//!
//! Blocks of `B×B` source pixels are laid in raster order with an overlap
//! of `O` pixels. Each block is the best of a set of seeded candidate
//! positions in any exemplar by the SSD over the overlap (all channels, colour and SDF),
//! chosen at random among those within 10 % of the best; the seam through
//! the overlap is the minimum-error boundary cut, found by dynamic
//! programming over the squared differences (a path from one side to the
//! other, moving at most one pixel sideways per row).

use super::atlas::Atlas;
#[cfg(test)]
use super::patchmatch::Channels;
use super::patchmatch::{angle_bin, Source, ANGLE_BINS};
use crate::raster::Grid;
use crate::rng;
use rayon::prelude::*;

/// Quilting parameters, pixels.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct QuiltOptions {
    /// Block side `B`.
    pub block: usize,
    /// Overlap `O` (< `B`).
    pub overlap: usize,
    /// Candidate positions tried per block; a source with at most this
    /// many allowed block centres is searched exhaustively.
    pub candidates: usize,
    /// Seed of the candidate positions and choices.
    pub seed: u64,
}

/// For every target pixel, the source (atlas) pixel it was copied from.
///
/// Blocks are copied turned by the direction difference `β = θ_s − θ_t`
/// (source angle at the candidate, target angle at the block's centre), as
/// the M-step's patches are, so the initial image already follows the
/// target direction (pass zero angle grids for a plain quilt). Candidate
/// block centres are the source's allowed centres for the block's reach
/// ([`block_reach`]); the atlas's margin must be at least that reach.
#[cfg(test)]
pub fn quilt(source: &Source, target_angle: &Grid<f32>, o: &QuiltOptions) -> Grid<(u32, u32)> {
    Quilter::new(source, o.block).quilt(source, target_angle, o)
}

/// How far a block of side `block` turned by any angle reaches from its
/// centre, pixels.
pub fn block_reach(block: usize) -> usize {
    ((block.max(2) / 2) as f64 * std::f64::consts::SQRT_2).ceil() as usize + 1
}

/// What quilting from one source with one block size needs whatever the
/// target: the block offsets turned by each quantized angle, as offsets
/// into the source's atlas, and the allowed block centres. Made once, it
/// serves every region filled from that source ([`Quilter::quilt`]).
#[derive(Clone, Debug)]
pub struct Quilter {
    /// Block side `B`, pixels (at least 2).
    block: usize,
    /// Per angle bin, per block offset (row-major): the turned offset, px.
    tables: Vec<Vec<(i64, i64)>>,
    /// Per angle bin, per block offset: the channel index offset.
    linear: Vec<Vec<isize>>,
    /// The atlas width and depth the offsets are for.
    dims: (usize, usize),
    /// Allowed block centres.
    centres: Vec<(u32, u32)>,
    /// How far a turned block reaches from its centre, pixels.
    reach: usize,
}

impl Quilter {
    /// Prepares quilting from `source` with blocks of `block` px a side.
    pub fn new(source: &Source, block: usize) -> Quilter {
        let b = block.max(2);
        let tables: Vec<Vec<(i64, i64)>> = (0..ANGLE_BINS)
            .map(|k| {
                let a = k as f32 * std::f32::consts::TAU / ANGLE_BINS as f32;
                let (sn, cs) = a.sin_cos();
                (0..b * b)
                    .map(|i| {
                        let (dx, dy) = (
                            (i % b) as f32 - (b / 2) as f32,
                            (i / b) as f32 - (b / 2) as f32,
                        );
                        (
                            (cs * dx - sn * dy).round() as i64,
                            (sn * dx + cs * dy).round() as i64,
                        )
                    })
                    .collect()
            })
            .collect();
        let (pw, d) = (source.channels.width, source.channels.depth);
        let linear = tables
            .iter()
            .map(|t| {
                t.iter()
                    .map(|&(rx, ry)| (ry as isize * pw as isize + rx as isize) * d as isize)
                    .collect()
            })
            .collect();
        Quilter {
            block: b,
            tables,
            linear,
            dims: (pw, d),
            centres: source.atlas.centres(block_reach(b)),
            reach: block_reach(b),
        }
    }

    /// `quilt` with these tables: the same map. `source` must be the
    /// source this was made for; when `o.block` or the atlas differs from
    /// what it was made for, a matching one is made first.
    pub fn quilt(
        &self,
        source: &Source,
        target_angle: &Grid<f32>,
        o: &QuiltOptions,
    ) -> Grid<(u32, u32)> {
        let fits = self.block == o.block.max(2)
            && self.dims == (source.channels.width, source.channels.depth);
        if !fits {
            return Quilter::new(source, o.block).quilt(source, target_angle, o);
        }
        quilt_blocks(self, source, target_angle, o)
    }
}

/// The quilting loop of `quilt`.
fn quilt_blocks(
    q: &Quilter,
    source: &Source,
    target_angle: &Grid<f32>,
    o: &QuiltOptions,
) -> Grid<(u32, u32)> {
    let (width, height) = (target_angle.width(), target_angle.height());
    let ch = &source.channels;
    let d = ch.depth;
    let atlas = &source.atlas;
    let b = q.block;
    let ov = o.overlap.min(b - 1);
    let step = b - ov;
    let mut map = Grid::new(width, height, (0u32, 0u32));
    let mut filled = Grid::new(width, height, false);
    let tables = &q.tables;
    // Source pixel for block offset (x, y) of a block centred on source
    // (sx, sy): wrapped within a tile, within a swatch as it is.
    let rot = |sx: usize, sy: usize, x: usize, y: usize, bin: usize| -> (usize, usize) {
        let (rx, ry) = tables[bin][y * b + x];
        let k = atlas.block_of(sy);
        let (px, py) = atlas.bring_in(k, sx as i64 + rx, sy as i64 + ry, 0);
        (px as usize, py as usize)
    };
    let mut by = 0;
    let mut bi = 0u64;
    while by < height {
        let mut bx = 0;
        while bx < width {
            let bw = b.min(width - bx);
            let bh = b.min(height - by);
            let ta = target_angle.get((bx + b / 2).min(width - 1), (by + b / 2).min(height - 1));
            let beta = |sx: usize, sy: usize| angle_bin(source.angle.get(sx, sy) - ta);
            // The overlap's pixels that earlier blocks filled (they reach
            // only the left and top overlaps), in row-major order: each
            // one's block offset (index into the tables) and the channels
            // already there.
            let mut offsets: Vec<usize> = Vec::new();
            let mut present: Vec<f32> = Vec::new();
            for y in 0..bh {
                let xs = if y < ov { bw } else { ov.min(bw) };
                for x in 0..xs {
                    if !filled.get(bx + x, by + y) {
                        continue;
                    }
                    let (ox, oy) = map.get(bx + x, by + y);
                    offsets.push(y * b + x);
                    present.extend_from_slice(ch.px(ox as usize, oy as usize));
                }
            }
            // Overlap error of a candidate centre (sx, sy), summed in
            // row-major order, read from the padded atlas; once it is over
            // `bound` the rest is skipped and infinity returned (the sum
            // only grows).
            let overlap_err = |sx: usize, sy: usize, bound: f32| -> f32 {
                let lin = &q.linear[beta(sx, sy)];
                let base = (sy * ch.width + sx) * d;
                let o = Overlap {
                    data: &ch.data,
                    base,
                    linear: lin,
                    offsets: &offsets,
                    present: &present,
                };
                match d {
                    4 => o.error::<4>(bound),
                    5 => o.error::<5>(bound),
                    6 => o.error::<6>(bound),
                    7 => o.error::<7>(bound),
                    _ => o.error_any(d, bound),
                }
            };
            // Every allowed centre when there are few, else a seeded
            // sample. A candidate is kept only when its error is within
            // 10 % of the best, so one whose partial error is already over
            // that much of the best seen so far (in its chunk, or among the
            // continuations below) is out: its error is left infinite,
            // which changes neither the best nor the kept ones.
            let n = q.centres.len();
            let count = if n <= o.candidates {
                n
            } else {
                o.candidates.max(1)
            };
            let position = |k: usize| {
                let (x, y) = if n <= o.candidates {
                    q.centres[k]
                } else {
                    Atlas::pick(&q.centres, &[o.seed, bi, k as u64])
                };
                (x as usize, y as usize)
            };
            // The continuations of the blocks already laid (a tile's own
            // repeat; allowed centres, so among the candidates when every
            // centre is one) are scored first: the best of them bounds
            // every chunk's search from the start, since no candidate over
            // `keep_bound` of it can be within 10 % of the overall best.
            let continued: Vec<(usize, usize, f32)> = {
                let bring = |ox: u32, oy: u32, rx: i64, ry: i64| {
                    let k = atlas.block_of(oy as usize);
                    let (x, y) = atlas.bring_in(k, ox as i64 + rx, oy as i64 + ry, q.reach);
                    atlas.allowed(x, y).then_some((x as usize, y as usize))
                };
                let angle = |x: u32, y: u32| source.angle.get(x as usize, y as usize);
                continuations(&map, &filled, (bx, by), b, ta, angle, bring)
                    .into_iter()
                    .map(|(sx, sy)| (sx, sy, overlap_err(sx, sy, f32::INFINITY)))
                    .collect()
            };
            let start = continued
                .iter()
                .filter(|c| n > o.candidates || q.centres.contains(&(c.0 as u32, c.1 as u32)))
                .map(|c| c.2)
                .fold(f32::INFINITY, f32::min);
            let chunks: Vec<Vec<(usize, usize, f32)>> = (0..count.div_ceil(CHUNK))
                .into_par_iter()
                .map(|c| {
                    let mut best = start;
                    (c * CHUNK..((c + 1) * CHUNK).min(count))
                        .map(|k| {
                            let (sx, sy) = position(k);
                            let e = overlap_err(sx, sy, keep_bound(best));
                            best = best.min(e);
                            (sx, sy, e)
                        })
                        .collect()
                })
                .collect();
            let mut cands: Vec<(usize, usize, f32)> = chunks.into_iter().flatten().collect();
            if n > o.candidates {
                cands.extend(continued);
            }
            let best = cands.iter().map(|c| c.2).fold(f32::INFINITY, f32::min);
            let good: Vec<&(usize, usize, f32)> =
                cands.iter().filter(|c| c.2 <= keep_bound(best)).collect();
            let &(sx, sy, _) = good[rng::index(&[o.seed, bi, 0xC401CE], good.len())];
            // Error surfaces over the left and top overlaps, and their cuts.
            let be = beta(sx, sy);
            let diff = |x: usize, y: usize| -> f32 {
                let (ox, oy) = map.get(bx + x, by + y);
                let a = ch.px(ox as usize, oy as usize);
                let (cx, cy) = rot(sx, sy, x, y, be);
                let c = ch.px(cx, cy);
                a.iter().zip(c).map(|(p, q)| (p - q) * (p - q)).sum()
            };
            let left = bx > 0 && ov > 0;
            let top = by > 0 && ov > 0;
            let lw = ov.min(bw);
            let th = ov.min(bh);
            let vcut = left.then(|| {
                let err: Vec<f32> = (0..bh)
                    .flat_map(|y| (0..lw).map(move |x| (x, y)))
                    .map(|(x, y)| diff(x, y))
                    .collect();
                min_vertical_cut(&err, lw, bh)
            });
            let hcut = top.then(|| {
                // Transposed: rows of the surface are columns of the block.
                let err: Vec<f32> = (0..bw)
                    .flat_map(|x| (0..th).map(move |y| (x, y)))
                    .map(|(x, y)| diff(x, y))
                    .collect();
                min_vertical_cut(&err, th, bw)
            });
            for y in 0..bh {
                for x in 0..bw {
                    let new_side_v = vcut.as_ref().is_none_or(|c| x >= c[y]);
                    let new_side_h = hcut.as_ref().is_none_or(|c| y >= c[x]);
                    if !filled.get(bx + x, by + y) || (new_side_v && new_side_h) {
                        let (cx, cy) = rot(sx, sy, x, y, be);
                        map.set(bx + x, by + y, (cx as u32, cy as u32));
                        filled.set(bx + x, by + y, true);
                    }
                }
            }
            bi += 1;
            bx += step;
        }
        by += step;
    }
    map
}

/// One candidate block's overlap with what earlier blocks laid: the
/// atlas channels, the candidate centre's channel index, the turned
/// offsets' channel index offsets, the overlap's block offsets (indices
/// into `linear`) and the channels already there (`depth` per offset).
struct Overlap<'a> {
    data: &'a [f32],
    base: usize,
    linear: &'a [isize],
    offsets: &'a [usize],
    present: &'a [f32],
}

impl Overlap<'_> {
    /// The squared channel difference summed in row-major order, one
    /// pixel's `D` channels at a time; infinity once over `bound` (the sum
    /// only grows) or where an offset leaves the atlas.
    #[inline]
    fn error<const D: usize>(&self, bound: f32) -> f32 {
        let mut e = 0.0f32;
        for (&i, a) in self.offsets.iter().zip(self.present.chunks_exact(D)) {
            let at = self.base.wrapping_add_signed(self.linear[i]);
            let (Some(c), Ok(a)) = (
                self.data
                    .get(at..at.wrapping_add(D))
                    .and_then(|s| <&[f32; D]>::try_from(s).ok()),
                <&[f32; D]>::try_from(a),
            ) else {
                return f32::INFINITY;
            };
            let mut px = 0.0f32;
            for k in 0..D {
                let t = a[k] - c[k];
                px += t * t;
            }
            e += px;
            if e > bound {
                return f32::INFINITY;
            }
        }
        e
    }

    /// [`Overlap::error`] for any depth.
    fn error_any(&self, d: usize, bound: f32) -> f32 {
        let mut e = 0.0f32;
        for (&i, a) in self.offsets.iter().zip(self.present.chunks_exact(d)) {
            let at = self.base.wrapping_add_signed(self.linear[i]);
            let Some(c) = self.data.get(at..at.wrapping_add(d)) else {
                return f32::INFINITY;
            };
            e += a.iter().zip(c).map(|(p, q)| (p - q) * (p - q)).sum::<f32>();
            if e > bound {
                return f32::INFINITY;
            }
        }
        e
    }
}

/// The block centres that continue the blocks laid to the left of and
/// above the block at `(bx, by)` (side `b`): the source of the filled
/// pixel in the middle of each overlap, moved by that pixel's offset to
/// the block's centre turned as a block from there is (target angle `ta`,
/// source angles `angle`), brought into its exemplar by `bring` (`None`
/// when it may not be a centre). A random sample of centres can miss a
/// tile's own repeat; these are it.
fn continuations(
    map: &Grid<(u32, u32)>,
    filled: &Grid<bool>,
    (bx, by): (usize, usize),
    b: usize,
    ta: f32,
    angle: impl Fn(u32, u32) -> f32,
    bring: impl Fn(u32, u32, i64, i64) -> Option<(usize, usize)>,
) -> Vec<(usize, usize)> {
    let (w, h) = (map.width(), map.height());
    let (cx, cy) = (bx + b / 2, by + b / 2);
    let mut out = Vec::new();
    for (px, py) in [(bx, cy.min(h - 1)), (cx.min(w - 1), by)] {
        if !filled.get(px, py) {
            continue;
        }
        let (ox, oy) = map.get(px, py);
        let bin = angle_bin(angle(ox, oy) - ta);
        let a = bin as f32 * std::f32::consts::TAU / ANGLE_BINS as f32;
        let (sn, cs) = a.sin_cos();
        let (dx, dy) = (cx as f32 - px as f32, cy as f32 - py as f32);
        let rx = (cs * dx - sn * dy).round() as i64;
        let ry = (sn * dx + cs * dy).round() as i64;
        if let Some(p) = bring(ox, oy, rx, ry) {
            if !out.contains(&p) {
                out.push(p);
            }
        }
    }
    out
}

/// Candidates whose overlap errors one task computes, with a running best.
const CHUNK: usize = 256;

/// The largest overlap error of a candidate kept for the random choice
/// when the best is `best` (within 10 %, and a little more for zero).
#[inline]
fn keep_bound(best: f32) -> f32 {
    best * 1.1 + 1e-6
}

/// The minimum-error boundary cut through an error surface `err` of
/// `w` columns and `h` rows (row-major): one column per row, neighbouring
/// rows at most one column apart, least total error. Ties go to the
/// leftmost column.
pub fn min_vertical_cut(err: &[f32], w: usize, h: usize) -> Vec<usize> {
    if w == 0 || h == 0 {
        return vec![0; h];
    }
    // cost[y][x]: least error of a path from row 0 ending at (x, y).
    let mut cost = err[..w].to_vec();
    let mut from = vec![0usize; w * h];
    for y in 1..h {
        let mut next = vec![0.0f32; w];
        for x in 0..w {
            let mut bx = x;
            let mut bc = cost[x];
            for cx in [x.wrapping_sub(1), x + 1] {
                if cx < w && (cost[cx] < bc || (cost[cx] == bc && cx < bx)) {
                    bc = cost[cx];
                    bx = cx;
                }
            }
            next[x] = bc + err[y * w + x];
            from[y * w + x] = bx;
        }
        cost = next;
    }
    let mut x = 0;
    for c in 1..w {
        if cost[c] < cost[x] {
            x = c;
        }
    }
    let mut path = vec![0; h];
    for y in (0..h).rev() {
        path[y] = x;
        x = from[y * w + x];
    }
    path
}

/// The channels of a quilted map.
#[cfg(test)]
pub fn apply(source: &Channels, map: &Grid<(u32, u32)>) -> Channels {
    let mut data = Vec::with_capacity(map.data().len() * source.depth);
    for &(x, y) in map.data() {
        data.extend_from_slice(source.px(x as usize, y as usize));
    }
    Channels {
        width: map.width(),
        height: map.height(),
        depth: source.depth,
        data,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn path_cost(err: &[f32], w: usize, p: &[usize]) -> f32 {
        p.iter().enumerate().map(|(y, &x)| err[y * w + x]).sum()
    }

    /// Every admissible path, by enumeration.
    fn brute(err: &[f32], w: usize, h: usize) -> f32 {
        fn go(err: &[f32], w: usize, h: usize, y: usize, x: usize, acc: f32, best: &mut f32) {
            let acc = acc + err[y * w + x];
            if y + 1 == h {
                *best = best.min(acc);
                return;
            }
            for nx in [x.wrapping_sub(1), x, x + 1] {
                if nx < w {
                    go(err, w, h, y + 1, nx, acc, best);
                }
            }
        }
        let mut best = f32::INFINITY;
        for x in 0..w {
            go(err, w, h, 0, x, 0.0, &mut best);
        }
        best
    }

    #[test]
    fn seams_are_minimal_error_paths() {
        for seed in 0..200u64 {
            let (w, h) = (1 + rng::index(&[seed, 1], 4), 1 + rng::index(&[seed, 2], 6));
            let err: Vec<f32> = (0..w * h)
                .map(|i| (rng::unit(&[seed, 3, i as u64]) * 10.0).round() as f32)
                .collect();
            let p = min_vertical_cut(&err, w, h);
            assert!(p.windows(2).all(|s| s[0].abs_diff(s[1]) <= 1), "{p:?}");
            assert_eq!(
                path_cost(&err, w, &p),
                brute(&err, w, h),
                "seed {seed}: {err:?} {p:?}"
            );
        }
    }

    /// The quilt as first written: every candidate's whole overlap error,
    /// wrapping each tile lookup, tables made per call. The reference
    /// for the padded, pruned and shared [`Quilter`].
    fn reference(
        source: &Channels,
        source_angle: &Grid<f32>,
        target_angle: &Grid<f32>,
        o: &QuiltOptions,
    ) -> Grid<(u32, u32)> {
        let (width, height) = (target_angle.width(), target_angle.height());
        let (sw, sh) = (source.width, source.height);
        let b = o.block.max(2);
        let ov = o.overlap.min(b - 1);
        let step = b - ov;
        let mut map = Grid::new(width, height, (0u32, 0u32));
        let mut filled = Grid::new(width, height, false);
        let tables: Vec<Vec<(i64, i64)>> = (0..ANGLE_BINS)
            .map(|k| {
                let a = k as f32 * std::f32::consts::TAU / ANGLE_BINS as f32;
                let (sn, cs) = a.sin_cos();
                (0..b * b)
                    .map(|i| {
                        let (dx, dy) = (
                            (i % b) as f32 - (b / 2) as f32,
                            (i / b) as f32 - (b / 2) as f32,
                        );
                        (
                            (cs * dx - sn * dy).round() as i64,
                            (sn * dx + cs * dy).round() as i64,
                        )
                    })
                    .collect()
            })
            .collect();
        let rot = |sx: usize, sy: usize, x: usize, y: usize, bin: usize| -> (usize, usize) {
            let (rx, ry) = tables[bin][y * b + x];
            (
                (sx as i64 + rx).rem_euclid(sw as i64) as usize,
                (sy as i64 + ry).rem_euclid(sh as i64) as usize,
            )
        };
        let (mut by, mut bi) = (0, 0u64);
        while by < height {
            let mut bx = 0;
            while bx < width {
                let (bw, bh) = (b.min(width - bx), b.min(height - by));
                let ta =
                    target_angle.get((bx + b / 2).min(width - 1), (by + b / 2).min(height - 1));
                let beta = |sx: usize, sy: usize| angle_bin(source_angle.get(sx, sy) - ta);
                let overlap_err = |sx: usize, sy: usize| -> f32 {
                    let be = beta(sx, sy);
                    let mut e = 0.0f32;
                    for y in 0..bh {
                        let xs = if y < ov { bw } else { ov.min(bw) };
                        for x in 0..xs {
                            if !filled.get(bx + x, by + y) {
                                continue;
                            }
                            let (ox, oy) = map.get(bx + x, by + y);
                            let a = source.px(ox as usize, oy as usize);
                            let (cx, cy) = rot(sx, sy, x, y, be);
                            let c = source.px(cx, cy);
                            e += a.iter().zip(c).map(|(p, q)| (p - q) * (p - q)).sum::<f32>();
                        }
                    }
                    e
                };
                let cands: Vec<(usize, usize, f32)> = if sw * sh <= o.candidates {
                    (0..sw * sh)
                        .map(|i| (i % sw, i / sw, overlap_err(i % sw, i / sw)))
                        .collect()
                } else {
                    let bring = |ox: u32, oy: u32, rx: i64, ry: i64| {
                        Some((
                            (ox as i64 + rx).rem_euclid(sw as i64) as usize,
                            (oy as i64 + ry).rem_euclid(sh as i64) as usize,
                        ))
                    };
                    let angle = |x: u32, y: u32| source_angle.get(x as usize, y as usize);
                    (0..o.candidates.max(1))
                        .map(|k| {
                            let i = rng::index(&[o.seed, bi, k as u64], sw * sh);
                            (i % sw, i / sw)
                        })
                        .chain(continuations(&map, &filled, (bx, by), b, ta, angle, bring))
                        .map(|(sx, sy)| (sx, sy, overlap_err(sx, sy)))
                        .collect()
                };
                let best = cands.iter().map(|c| c.2).fold(f32::INFINITY, f32::min);
                let good: Vec<&(usize, usize, f32)> =
                    cands.iter().filter(|c| c.2 <= best * 1.1 + 1e-6).collect();
                let &(sx, sy, _) = good[rng::index(&[o.seed, bi, 0xC401CE], good.len())];
                let be = beta(sx, sy);
                let diff = |x: usize, y: usize| -> f32 {
                    let (ox, oy) = map.get(bx + x, by + y);
                    let a = source.px(ox as usize, oy as usize);
                    let (cx, cy) = rot(sx, sy, x, y, be);
                    let c = source.px(cx, cy);
                    a.iter().zip(c).map(|(p, q)| (p - q) * (p - q)).sum()
                };
                let (lw, th) = (ov.min(bw), ov.min(bh));
                let vcut = (bx > 0 && ov > 0).then(|| {
                    let err: Vec<f32> = (0..bh)
                        .flat_map(|y| (0..lw).map(move |x| (x, y)))
                        .map(|(x, y)| diff(x, y))
                        .collect();
                    min_vertical_cut(&err, lw, bh)
                });
                let hcut = (by > 0 && ov > 0).then(|| {
                    let err: Vec<f32> = (0..bw)
                        .flat_map(|x| (0..th).map(move |y| (x, y)))
                        .map(|(x, y)| diff(x, y))
                        .collect();
                    min_vertical_cut(&err, th, bw)
                });
                for y in 0..bh {
                    for x in 0..bw {
                        let new_v = vcut.as_ref().is_none_or(|c| x >= c[y]);
                        let new_h = hcut.as_ref().is_none_or(|c| y >= c[x]);
                        if !filled.get(bx + x, by + y) || (new_v && new_h) {
                            let (cx, cy) = rot(sx, sy, x, y, be);
                            map.set(bx + x, by + y, (cx as u32, cy as u32));
                            filled.set(bx + x, by + y, true);
                        }
                    }
                }
                bi += 1;
                bx += step;
            }
            by += step;
        }
        map
    }

    #[test]
    fn pruned_and_shared_quilting_matches_the_exhaustive_reference() {
        // Smooth multi-channel tiles (so errors tie and near-tie, and the
        // 10 % band holds several candidates), turning target angles,
        // exhaustive (20×16 ≤ 400) and sampled (40×36 > 400) candidates,
        // blocks whose turned offsets reach past a small tile's side.
        for (seed, (sw, sh), block) in [(1u64, (20, 16), 10), (2, (40, 36), 12), (3, (9, 8), 8)] {
            let src = Channels {
                width: sw,
                height: sh,
                depth: 3,
                data: (0..sw * sh * 3)
                    .map(|i| {
                        let (x, y) = ((i / 3) % sw, (i / 3) / sw);
                        let a =
                            std::f32::consts::TAU * (x as f32 / sw as f32 + (i % 3) as f32 * 0.3);
                        (a.sin() + (y as f32 * 0.7).cos()).round() * 0.5
                            + rng::unit(&[seed, i as u64]) as f32 * 0.01
                    })
                    .collect(),
            };
            let sa = Grid::from_fn(sw, sh, |x, y| (x + 2 * y) as f32 * 0.05);
            let ta = Grid::from_fn(53, 47, |x, y| (x as f32 - y as f32) * 0.03);
            let o = QuiltOptions {
                block,
                overlap: block / 4 + 1,
                candidates: 400,
                seed,
            };
            let m = block_reach(block + 2);
            let source = Source::tile(&src, &sa, m);
            // Atlas pixels back to tile pixels.
            let tile = |g: Grid<(u32, u32)>| g.map(|(x, y)| (x - m as u32, y - m as u32));
            let want = reference(&src, &sa, &ta, &o);
            assert_eq!(
                tile(quilt(&source, &ta, &o)).data(),
                want.data(),
                "seed {seed}"
            );
            // One quilter serves several targets (and another seed).
            let q = Quilter::new(&source, block);
            for s in [seed, seed + 10] {
                let o = QuiltOptions { seed: s, ..o };
                let want = reference(&src, &sa, &ta, &o);
                assert_eq!(
                    tile(q.quilt(&source, &ta, &o)).data(),
                    want.data(),
                    "seed {s}"
                );
            }
            // A quilter made for another block size is not misused.
            let other = Quilter::new(&source, block + 2);
            assert_eq!(tile(other.quilt(&source, &ta, &o)).data(), want.data());
        }
    }

    #[test]
    fn quilting_a_tile_reproduces_its_pixels() {
        // Every output pixel is copied from the tile, and block interiors
        // are contiguous copies.
        let src = Channels {
            width: 16,
            height: 16,
            depth: 1,
            data: (0..256).map(|i| rng::unit(&[9, i]) as f32).collect(),
        };
        let zero = Grid::new(16, 16, 0.0);
        let source = Source::tile(&src, &zero, block_reach(10));
        let map = quilt(
            &source,
            &Grid::new(40, 30, 0.0),
            &QuiltOptions {
                block: 10,
                overlap: 3,
                candidates: 20,
                seed: 1,
            },
        );
        let m = block_reach(10) as u32;
        let (ax, ay) = map.get(5, 5);
        let (bx, by) = map.get(6, 5);
        assert_eq!(((ax - m + 1) % 16 + m, ay), (bx, by));
        assert_eq!(apply(&source.channels, &map).data.len(), 40 * 30);
    }
}
