//! Every exemplar of a fill style at one pyramid level, laid out in one
//! padded image (the *atlas*), so that a patch of any exemplar is a gather
//! at fixed linear offsets and one nearest-neighbour field can point into
//! any of them (art-pattern-level-sets §2: the M-step searches the input
//! for the most similar neighbourhood; here the input is all exemplars, and
//! the energy decides which one each neighbourhood comes from).
//!
//! Exemplars (*blocks*) are stacked top to bottom, each with a margin of
//! [`Atlas::margin`] pixels on every side. A seamless tile's margin holds
//! its own wrap-around, so a patch centred anywhere in it reads the
//! periodic tile. Any other swatch is not periodic: its margin repeats its
//! edge pixels but is never read, because a patch centre is only allowed
//! where the whole (turned) patch lies inside the swatch, and only near the
//! swatch's shape (its ink with the holes filled) — the paper around a
//! motif is not part of its pattern.

use crate::raster::Grid;
use crate::rng;

/// One exemplar's place in an atlas.
#[derive(Clone, Debug)]
pub struct Block {
    /// Column of the exemplar's pixel (0, 0) in the atlas.
    pub x0: usize,
    /// Row of the exemplar's pixel (0, 0) in the atlas.
    pub y0: usize,
    /// Width, exemplar pixels.
    pub w: usize,
    /// Height, exemplar pixels.
    pub h: usize,
    /// A seamless tile: lookups wrap around.
    pub periodic: bool,
    /// For a swatch that is not periodic: the exemplar pixels a patch
    /// centre may take for its shape (its shape dilated by the patch
    /// radius); `None` allows every pixel.
    pub near_shape: Option<Grid<bool>>,
}

impl Block {
    /// The exemplar pixel `(x, y)` (in exemplar coordinates, any integers)
    /// brought into the exemplar: wrapped for a tile, clamped to the
    /// pixels `reach` or more from the edge otherwise (the middle pixel
    /// when the exemplar is narrower than that).
    #[inline]
    pub fn bring_in(&self, x: i64, y: i64, reach: usize) -> (usize, usize) {
        if self.periodic {
            (
                x.rem_euclid(self.w as i64) as usize,
                y.rem_euclid(self.h as i64) as usize,
            )
        } else {
            let clamp = |v: i64, n: usize| {
                if 2 * reach >= n {
                    n / 2
                } else {
                    v.clamp(reach as i64, (n - 1 - reach) as i64) as usize
                }
            };
            (clamp(x, self.w), clamp(y, self.h))
        }
    }

    /// Whether exemplar pixel `(x, y)` may be a patch centre.
    #[inline]
    pub fn allowed(&self, x: usize, y: usize) -> bool {
        self.near_shape.as_ref().is_none_or(|m| m.get(x, y))
    }
}

/// The layout of a level's exemplars in one padded image.
#[derive(Clone, Debug)]
pub struct Atlas {
    /// Width, pixels.
    pub width: usize,
    /// Height, pixels.
    pub height: usize,
    /// Padding on every side of every block, pixels.
    pub margin: usize,
    /// The exemplars, in style order.
    pub blocks: Vec<Block>,
    /// Per atlas row, the block whose padded band holds it.
    owner: Vec<u32>,
}

impl Atlas {
    /// Lays out blocks of the given sizes (`(w, h, periodic, near_shape)`)
    /// top to bottom, each padded by `margin`.
    pub fn new(blocks: Vec<(usize, usize, bool, Option<Grid<bool>>)>, margin: usize) -> Atlas {
        let width = blocks.iter().map(|b| b.0).max().unwrap_or(1) + 2 * margin;
        let mut y = 0;
        let mut owner = Vec::new();
        let mut out = Vec::new();
        for (k, (w, h, periodic, near_shape)) in blocks.into_iter().enumerate() {
            out.push(Block {
                x0: margin,
                y0: y + margin,
                w,
                h,
                periodic,
                near_shape,
            });
            owner.extend(std::iter::repeat_n(k as u32, h + 2 * margin));
            y += h + 2 * margin;
        }
        Atlas {
            width,
            height: y.max(1),
            margin,
            blocks: out,
            owner,
        }
    }

    /// The index of the block whose band holds atlas row `y`.
    #[inline]
    pub fn block_of(&self, y: usize) -> usize {
        self.owner.get(y).copied().unwrap_or(0) as usize
    }

    /// Atlas pixel `(x, y)` as (block, exemplar x, exemplar y); the
    /// exemplar coordinates may lie in the margin (negative or past the
    /// edge).
    #[inline]
    pub fn block_pixel(&self, x: usize, y: usize) -> (usize, i64, i64) {
        let b = self.block_of(y);
        let bl = &self.blocks[b];
        (b, x as i64 - bl.x0 as i64, y as i64 - bl.y0 as i64)
    }

    /// Exemplar pixel `(x, y)` of block `b` as an atlas pixel.
    #[inline]
    pub fn pixel_of(&self, b: usize, x: usize, y: usize) -> (u32, u32) {
        let bl = &self.blocks[b];
        ((bl.x0 + x) as u32, (bl.y0 + y) as u32)
    }

    /// The patch centre that atlas position `(x, y)` (any integers, in
    /// the frame of block `b`) stands for: wrapped into a tile, clamped
    /// `reach` from a swatch's edge. Not checked against the swatch's
    /// shape (see [`Atlas::allowed`]).
    #[inline]
    pub fn bring_in(&self, b: usize, x: i64, y: i64, reach: usize) -> (u32, u32) {
        let bl = &self.blocks[b];
        let (ex, ey) = bl.bring_in(x - bl.x0 as i64, y - bl.y0 as i64, reach);
        ((bl.x0 + ex) as u32, (bl.y0 + ey) as u32)
    }

    /// Whether atlas pixel `(x, y)` (a pixel of its block) may be a patch
    /// centre by its block's shape.
    #[inline]
    pub fn allowed(&self, x: u32, y: u32) -> bool {
        let (b, ex, ey) = self.block_pixel(x as usize, y as usize);
        let bl = &self.blocks[b];
        ex >= 0
            && ey >= 0
            && (ex as usize) < bl.w
            && (ey as usize) < bl.h
            && bl.allowed(ex as usize, ey as usize)
    }

    /// Squared distance between two atlas pixels as images of one
    /// neighbour (Brushables Eq. 8): on the torus within a tile, plain
    /// within a swatch, and far apart across blocks.
    #[inline]
    pub fn d2(&self, a: (i64, i64), b: (i64, i64)) -> f32 {
        let ba = self.block_of(a.1.clamp(0, self.height as i64 - 1) as usize);
        let bb = self.block_of(b.1.clamp(0, self.height as i64 - 1) as usize);
        if ba != bb {
            return 1e6;
        }
        let bl = &self.blocks[ba];
        let (mut dx, mut dy) = ((a.0 - b.0).abs(), (a.1 - b.1).abs());
        if bl.periodic {
            dx %= bl.w as i64;
            dy %= bl.h as i64;
            dx = dx.min(bl.w as i64 - dx);
            dy = dy.min(bl.h as i64 - dy);
        }
        (dx * dx + dy * dy) as f32
    }

    /// Every allowed patch centre `reach` or more from a swatch's edge
    /// (every pixel of a tile), in block order then row-major; each block
    /// holds at least one (its middle pixel when nothing else is allowed).
    pub fn centres(&self, reach: usize) -> Vec<(u32, u32)> {
        let mut out = Vec::new();
        for (b, bl) in self.blocks.iter().enumerate() {
            let start = out.len();
            let r = if bl.periodic { 0 } else { reach };
            if 2 * r < bl.w && 2 * r < bl.h {
                for y in r..bl.h - r {
                    for x in r..bl.w - r {
                        if bl.allowed(x, y) {
                            out.push(self.pixel_of(b, x, y));
                        }
                    }
                }
            }
            if out.len() == start {
                out.push(self.pixel_of(b, bl.w / 2, bl.h / 2));
            }
        }
        out
    }

    /// A seeded choice among `centres` (from [`Atlas::centres`]).
    #[inline]
    pub fn pick(centres: &[(u32, u32)], words: &[u64]) -> (u32, u32) {
        centres[rng::index(words, centres.len().max(1)).min(centres.len().saturating_sub(1))]
    }

    /// The blocks' grids (one per block, its exemplar's size) laid out on
    /// the atlas: a tile's margin holds its wrap-around, a swatch's its
    /// nearest edge pixel; `outside` elsewhere.
    pub fn pad<T: Copy>(&self, grids: &[&Grid<T>], outside: T) -> Grid<T> {
        let mut g = Grid::new(self.width, self.height, outside);
        let m = self.margin as i64;
        for (bl, src) in self.blocks.iter().zip(grids) {
            for y in -m..bl.h as i64 + m {
                for x in -m..bl.w as i64 + m {
                    let (sx, sy) = if bl.periodic {
                        (
                            x.rem_euclid(bl.w as i64) as usize,
                            y.rem_euclid(bl.h as i64) as usize,
                        )
                    } else {
                        (
                            x.clamp(0, bl.w as i64 - 1) as usize,
                            y.clamp(0, bl.h as i64 - 1) as usize,
                        )
                    };
                    g.set(
                        (bl.x0 as i64 + x) as usize,
                        (bl.y0 as i64 + y) as usize,
                        src.get(sx, sy),
                    );
                }
            }
        }
        g
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn blocks_stack_with_their_margins_and_pad_by_kind() {
        let a = Atlas::new(vec![(4, 3, true, None), (5, 2, false, None)], 2);
        assert_eq!((a.width, a.height), (9, 3 + 4 + 2 + 4));
        assert_eq!((a.blocks[0].x0, a.blocks[0].y0), (2, 2));
        assert_eq!((a.blocks[1].x0, a.blocks[1].y0), (2, 9));
        assert_eq!(a.block_of(6), 0);
        assert_eq!(a.block_of(7), 1);
        let t = Grid::from_fn(4, 3, |x, y| (10 * y + x) as i32);
        let s = Grid::from_fn(5, 2, |x, y| (100 + 10 * y + x) as i32);
        let p = a.pad(&[&t, &s], -1);
        // The tile wraps: left of its column 0 is its column 3.
        assert_eq!(p.get(1, 2), 3);
        assert_eq!(p.get(0, 0), t.get(2, 1));
        // The swatch repeats its edge.
        assert_eq!(p.get(0, 9), 100);
        assert_eq!(p.get(8, 12), 114);
        // Wrapping and clamping of centres.
        assert_eq!(a.bring_in(0, 1, 2, 1), (5, 2));
        assert_eq!(a.bring_in(1, 0, 9, 1), (3, 10));
        // Distances: torus in a tile, none across blocks.
        assert_eq!(a.d2((2, 2), (5, 2)), 1.0);
        assert!(a.d2((2, 2), (2, 9)) > 1e5);
        // Centres: every tile pixel; the narrow swatch its middle.
        let c = a.centres(1);
        assert_eq!(c.len(), 12 + 1);
    }

    #[test]
    fn a_swatch_allows_only_centres_near_its_shape_and_inside() {
        let shape = Grid::from_fn(10, 10, |x, _| x < 5);
        let a = Atlas::new(vec![(10, 10, false, Some(shape))], 3);
        let c = a.centres(2);
        assert!(c
            .iter()
            .all(|&(x, y)| (5..8).contains(&(x as usize)) && (5..11).contains(&(y as usize))));
        assert_eq!(c.len(), 3 * 6);
        assert!(a.allowed(5, 5) && !a.allowed(9, 5));
    }
}
