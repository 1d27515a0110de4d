//! A binary bitmap's ink, packed with a border of paper: what a one-ink
//! raster is read as, and what the pixel outlines
//! ([`crate::outline::paths`]) are walked on.

use super::Coverage;
use super::Grid;
use rayon::prelude::*;

/// A binary bitmap's ink flags with a one-pixel border of paper, so a
/// cell's four corners are plain lookups; rows of `width + 2` bytes.
#[derive(Clone, Debug)]
pub struct Bitmap {
    width: usize,
    height: usize,
    /// `flags[(y + 1) * (width + 2) + x + 1]`: 1 when pixel (x, y) is ink.
    flags: Vec<u8>,
}

impl Bitmap {
    /// A `width` × `height` bitmap with ink where `ink(x, y)` (pixels).
    #[cfg(test)]
    pub fn from_fn(width: usize, height: usize, mut ink: impl FnMut(usize, usize) -> bool) -> Self {
        let pw = width + 2;
        let mut flags = vec![0u8; pw * (height + 2)];
        for (y, row) in flags.chunks_mut(pw).skip(1).take(height).enumerate() {
            for (x, f) in row.iter_mut().skip(1).take(width).enumerate() {
                *f = u8::from(ink(x, y));
            }
        }
        Bitmap {
            width,
            height,
            flags,
        }
    }

    /// How many pixels are ink.
    pub fn ink_count(&self) -> usize {
        self.flags.iter().map(|&f| usize::from(f)).sum()
    }

    /// The ink of coverage `cov`: pixels with coverage ≥ ½ (the rule of
    /// [`crate::outline::smooth`] and [`crate::outline::corridor`]).
    pub fn from_coverage(cov: &Coverage) -> Self {
        Self::from_rows(cov.width(), cov.height(), cov.data(), |&c| c >= 0.5)
    }

    /// A bitmap from `width`-long rows of `values` (row-major, at least
    /// `width · height` of them; missing ones are paper), ink where
    /// `ink(value)`. Rows are filled in parallel.
    pub fn from_rows<T: Sync>(
        width: usize,
        height: usize,
        values: &[T],
        ink: impl Fn(&T) -> bool + Sync + Send,
    ) -> Self {
        let pw = width + 2;
        let mut flags = vec![0u8; pw * (height + 2)];
        if width > 0 {
            let rows = values.par_chunks(width).take(height);
            flags
                .par_chunks_mut(pw)
                .skip(1)
                .zip(rows)
                .for_each(|(out, row)| {
                    for (f, v) in out.iter_mut().skip(1).zip(row) {
                        *f = u8::from(ink(v));
                    }
                });
        }
        Bitmap {
            width,
            height,
            flags,
        }
    }

    /// Width in pixels.
    pub fn width(&self) -> usize {
        self.width
    }

    /// Height in pixels.
    pub fn height(&self) -> usize {
        self.height
    }

    /// Whether pixel (x, y) is ink; pixels outside the bitmap are paper.
    pub fn ink(&self, x: isize, y: isize) -> bool {
        let (w, h) = (self.width as isize, self.height as isize);
        if x < -1 || y < -1 || x > w || y > h {
            return false;
        }
        let i = (y + 1) as usize * (self.width + 2) + (x + 1) as usize;
        self.flags.get(i).is_some_and(|&f| f != 0)
    }

    /// The padded flags, row by row (`width + 2` flags each, `height + 2`
    /// rows; 1 for ink).
    pub(crate) fn flags(&self) -> &[u8] {
        &self.flags
    }

    /// The padded rows (`width + 2` flags each, `height + 2` of them).
    pub(crate) fn padded_rows(&self) -> std::slice::Chunks<'_, u8> {
        self.flags.chunks(self.width + 2)
    }

    /// As coverage: 1 for ink, 0 for paper.
    pub fn to_coverage(&self) -> Coverage {
        Grid::from_fn(self.width, self.height, |x, y| {
            if self.ink(x as isize, y as isize) {
                1.0
            } else {
                0.0
            }
        })
    }
}
