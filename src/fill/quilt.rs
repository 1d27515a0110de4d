//! Initialization by image quilting (Efros & Freeman 2001), with the SDF
//! channels padded to every patch (art-pattern-level-sets §2).
//!
//! Blocks of `B×B` tile pixels are laid in raster order with an overlap of
//! `O` pixels. Each block is the best of a set of seeded candidate tile
//! positions by the SSD over the overlap (all channels, colour and SDF),
//! chosen at random among those within 10 % of the best; the seam through
//! the overlap is the minimum-error boundary cut, found by dynamic
//! programming over the squared differences (a path from one side to the
//! other, moving at most one pixel sideways per row).

use super::patchmatch::{angle_bin, Channels, ANGLE_BINS};
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
    /// Candidate positions tried per block; a tile with at most this many
    /// pixels is searched exhaustively.
    pub candidates: usize,
    /// Seed of the candidate positions and choices.
    pub seed: u64,
}

/// For every target pixel, the tile pixel it was copied from.
///
/// Blocks are copied turned by the direction difference `β = θ_s − θ_t`
/// (tile angle at the candidate, target angle at the block's centre), as
/// the M-step's patches are, so the initial image already follows the
/// target direction (pass zero angle grids for a plain quilt).
pub fn quilt(
    source: &Channels,
    source_angle: &Grid<f32>,
    target_angle: &Grid<f32>,
    o: &QuiltOptions,
) -> Grid<(u32, u32)> {
    Quilter::new(source, o.block).quilt(source, source_angle, target_angle, o)
}

/// What quilting from one tile with one block size needs whatever the
/// target: the block offsets turned by each quantized angle and the tile
/// padded by its own wrap-around. Made once, it serves every region
/// filled from that tile ([`Quilter::quilt`]).
#[derive(Clone, Debug)]
pub struct Quilter {
    /// Block side `B`, pixels (at least 2).
    block: usize,
    /// Per angle bin, per block offset (row-major): the turned offset, px.
    tables: Vec<Vec<(i64, i64)>>,
    /// The tile, padded.
    padded: Padded,
}

impl Quilter {
    /// Prepares quilting from `source` with blocks of `block` px a side.
    pub fn new(source: &Channels, block: usize) -> Quilter {
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
        let padded = Padded::new(source, &tables);
        Quilter {
            block: b,
            tables,
            padded,
        }
    }

    /// [`quilt`] with these tables: the same map. `source` must be the
    /// tile this was made for; when `o.block` or the tile's size differs
    /// from what it was made for, a matching one is made first.
    pub fn quilt(
        &self,
        source: &Channels,
        source_angle: &Grid<f32>,
        target_angle: &Grid<f32>,
        o: &QuiltOptions,
    ) -> Grid<(u32, u32)> {
        let fits = self.block == o.block.max(2)
            && self.padded.dims == (source.width, source.height, source.depth);
        if !fits {
            return Quilter::new(source, o.block).quilt(source, source_angle, target_angle, o);
        }
        quilt_blocks(self, source, source_angle, target_angle, o)
    }
}

/// The quilting loop of [`quilt`].
fn quilt_blocks(
    q: &Quilter,
    source: &Channels,
    source_angle: &Grid<f32>,
    target_angle: &Grid<f32>,
    o: &QuiltOptions,
) -> Grid<(u32, u32)> {
    let (width, height) = (target_angle.width(), target_angle.height());
    let (sw, sh, d) = (source.width, source.height, source.depth);
    let b = q.block;
    let ov = o.overlap.min(b - 1);
    let step = b - ov;
    let mut map = Grid::new(width, height, (0u32, 0u32));
    let mut filled = Grid::new(width, height, false);
    let tables = &q.tables;
    let padded = &q.padded;
    // Tile pixel for block offset (x, y) of a block centred on tile (sx, sy).
    let rot = |sx: usize, sy: usize, x: usize, y: usize, bin: usize| -> (usize, usize) {
        let (rx, ry) = tables[bin][y * b + x];
        (
            (sx as i64 + rx).rem_euclid(sw as i64) as usize,
            (sy as i64 + ry).rem_euclid(sh as i64) as usize,
        )
    };
    // The candidates' overlap errors read the source through a copy padded
    // by its own wrap-around, at per-bin linear offsets: no wrapping per
    // pixel.
    let mut by = 0;
    let mut bi = 0u64;
    while by < height {
        let mut bx = 0;
        while bx < width {
            let bw = b.min(width - bx);
            let bh = b.min(height - by);
            let ta = target_angle.get((bx + b / 2).min(width - 1), (by + b / 2).min(height - 1));
            let beta = |sx: usize, sy: usize| angle_bin(source_angle.get(sx, sy) - ta);
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
                    present.extend_from_slice(source.px(ox as usize, oy as usize));
                }
            }
            // Overlap error of a candidate tile origin (sx, sy), summed in
            // row-major order; once it is over `bound` the rest is skipped
            // and infinity returned (the sum only grows).
            let overlap_err = |sx: usize, sy: usize, bound: f32| -> f32 {
                let lin = &padded.linear[beta(sx, sy)];
                let base = padded.base(sx, sy);
                let mut e = 0.0f32;
                for (&i, a) in offsets.iter().zip(present.chunks_exact(d)) {
                    let at = base.wrapping_add_signed(lin[i]);
                    let c = &padded.data[at..at + d];
                    e += a.iter().zip(c).map(|(p, q)| (p - q) * (p - q)).sum::<f32>();
                    if e > bound {
                        return f32::INFINITY;
                    }
                }
                e
            };
            // Every tile position when the tile is small, else a seeded
            // sample. A candidate is kept only when its error is within
            // 10 % of the best, so one whose partial error is already over
            // that much of the best seen so far (in its chunk) is out: its
            // error is left infinite, which changes neither the best nor
            // the kept ones.
            let count = if sw * sh <= o.candidates {
                sw * sh
            } else {
                o.candidates.max(1)
            };
            let position = |k: usize| {
                if sw * sh <= o.candidates {
                    (k % sw, k / sw)
                } else {
                    (
                        rng::index(&[o.seed, bi, k as u64, 0], sw),
                        rng::index(&[o.seed, bi, k as u64, 1], sh),
                    )
                }
            };
            let chunks: Vec<Vec<(usize, usize, f32)>> = (0..count.div_ceil(CHUNK))
                .into_par_iter()
                .map(|c| {
                    let mut best = f32::INFINITY;
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
            let cands: Vec<(usize, usize, f32)> = chunks.into_iter().flatten().collect();
            let best = cands.iter().map(|c| c.2).fold(f32::INFINITY, f32::min);
            let good: Vec<&(usize, usize, f32)> =
                cands.iter().filter(|c| c.2 <= keep_bound(best)).collect();
            let &(sx, sy, _) = good[rng::index(&[o.seed, bi, 0xC401CE], good.len())];
            // Error surfaces over the left and top overlaps, and their cuts.
            let be = beta(sx, sy);
            let diff = |x: usize, y: usize| -> f32 {
                let (ox, oy) = map.get(bx + x, by + y);
                let a = source.px(ox as usize, oy as usize);
                let (cx, cy) = rot(sx, sy, x, y, be);
                let c = source.px(cx, cy);
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

/// Candidates whose overlap errors one task computes, with a running best.
const CHUNK: usize = 256;

/// The largest overlap error of a candidate kept for the random choice
/// when the best is `best` (within 10 %, and a little more for zero).
#[inline]
fn keep_bound(best: f32) -> f32 {
    best * 1.1 + 1e-6
}

/// A source padded by its own wrap-around by the reach of the rotated
/// block offsets, with each angle bin's offsets as linear indices.
#[derive(Clone, Debug)]
struct Padded {
    /// The source's width, height and depth.
    dims: (usize, usize, usize),
    data: Vec<f32>,
    width: usize,
    depth: usize,
    margin: usize,
    /// Per bin, per block offset: the channel index offset.
    linear: Vec<Vec<isize>>,
}

impl Padded {
    fn new(source: &Channels, tables: &[Vec<(i64, i64)>]) -> Padded {
        let reach = tables
            .iter()
            .flatten()
            .map(|&(x, y)| x.unsigned_abs().max(y.unsigned_abs()))
            .max()
            .unwrap_or(0) as usize;
        let margin = reach;
        let (w, h, d) = (source.width, source.height, source.depth);
        let (pw, ph) = (w + 2 * margin, h + 2 * margin);
        let mut data = Vec::with_capacity(pw * ph * d);
        for y in 0..ph {
            let sy = (y + h * (margin / h + 1) - margin) % h;
            for x in 0..pw {
                let sx = (x + w * (margin / w + 1) - margin) % w;
                data.extend_from_slice(source.px(sx, sy));
            }
        }
        let linear = tables
            .iter()
            .map(|t| {
                t.iter()
                    .map(|&(rx, ry)| (ry as isize * pw as isize + rx as isize) * d as isize)
                    .collect()
            })
            .collect();
        Padded {
            dims: (w, h, d),
            data,
            width: pw,
            depth: d,
            margin,
            linear,
        }
    }

    /// Index of tile pixel `(x, y)`'s first channel.
    #[inline]
    fn base(&self, x: usize, y: usize) -> usize {
        ((y + self.margin) * self.width + x + self.margin) * self.depth
    }
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
                    (0..o.candidates.max(1))
                        .map(|k| {
                            let sx = rng::index(&[o.seed, bi, k as u64, 0], sw);
                            let sy = rng::index(&[o.seed, bi, k as u64, 1], sh);
                            (sx, sy, overlap_err(sx, sy))
                        })
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
            let want = reference(&src, &sa, &ta, &o);
            assert_eq!(quilt(&src, &sa, &ta, &o).data(), want.data(), "seed {seed}");
            // One quilter serves several targets (and another seed).
            let q = Quilter::new(&src, block);
            for s in [seed, seed + 10] {
                let o = QuiltOptions { seed: s, ..o };
                let want = reference(&src, &sa, &ta, &o);
                assert_eq!(q.quilt(&src, &sa, &ta, &o).data(), want.data(), "seed {s}");
            }
            // A quilter made for another block size is not misused.
            let other = Quilter::new(&src, block + 2);
            assert_eq!(other.quilt(&src, &sa, &ta, &o).data(), want.data());
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
        let map = quilt(
            &src,
            &zero,
            &Grid::new(40, 30, 0.0),
            &QuiltOptions {
                block: 10,
                overlap: 3,
                candidates: 20,
                seed: 1,
            },
        );
        let (ax, ay) = map.get(5, 5);
        let (bx, by) = map.get(6, 5);
        assert_eq!(((ax + 1) % 16, ay), (bx, by));
        assert_eq!(apply(&src, &map).data.len(), 40 * 30);
    }
}
