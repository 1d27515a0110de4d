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
use crate::pattern::rng;
use crate::raster::Grid;
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
    let (width, height) = (target_angle.width(), target_angle.height());
    let (sw, sh) = (source.width, source.height);
    let b = o.block.max(2);
    let ov = o.overlap.min(b - 1);
    let step = b - ov;
    let mut map = Grid::new(width, height, (0u32, 0u32));
    let mut filled = Grid::new(width, height, false);
    // Block offsets turned by each quantized angle (the M-step's bins).
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
    // Tile pixel for block offset (x, y) of a block centred on tile (sx, sy).
    let rot = |sx: usize, sy: usize, x: usize, y: usize, bin: usize| -> (usize, usize) {
        let (rx, ry) = tables[bin][y * b + x];
        (
            (sx as i64 + rx).rem_euclid(sw as i64) as usize,
            (sy as i64 + ry).rem_euclid(sh as i64) as usize,
        )
    };
    let mut by = 0;
    let mut bi = 0u64;
    while by < height {
        let mut bx = 0;
        while bx < width {
            let bw = b.min(width - bx);
            let bh = b.min(height - by);
            let ta = target_angle.get((bx + b / 2).min(width - 1), (by + b / 2).min(height - 1));
            let beta = |sx: usize, sy: usize| angle_bin(source_angle.get(sx, sy) - ta);
            // Overlap error of a candidate tile origin (sx, sy).
            let overlap_err = |sx: usize, sy: usize| -> f32 {
                let be = beta(sx, sy);
                let mut e = 0.0f32;
                // Earlier blocks reach only the left and top overlaps.
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
            // Every tile position when the tile is small, else a seeded sample.
            let cands: Vec<(usize, usize, f32)> = if sw * sh <= o.candidates {
                (0..sw * sh)
                    .into_par_iter()
                    .map(|i| (i % sw, i / sw, overlap_err(i % sw, i / sw)))
                    .collect()
            } else {
                (0..o.candidates.max(1))
                    .into_par_iter()
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
