//! Rasters: the [`Grid`] type, the exact Euclidean distance transform, the
//! signed distance field [`Sdf`] (the seam between every raster mode and the
//! tracer), and loading of raster and SVG inputs as ink coverage.

pub mod bitmap;
pub mod contour;
pub mod edt;
pub mod plain;
pub mod regions;
pub mod scan;
pub mod sdf;
pub mod skeleton;
pub mod vector;

pub use sdf::Sdf;

/// A dense row-major grid of samples; sample `(x, y)` sits at the pixel
/// centre `(x + 0.5, y + 0.5)` in pixel coordinates.
#[derive(Clone, Debug, PartialEq)]
pub struct Grid<T> {
    width: usize,
    height: usize,
    data: Vec<T>,
}

impl<T: Copy> Grid<T> {
    /// A `width`×`height` grid filled with `value`.
    pub fn new(width: usize, height: usize, value: T) -> Self {
        Grid {
            width,
            height,
            data: vec![value; width * height],
        }
    }

    /// A grid whose sample `(x, y)` is `f(x, y)`.
    pub fn from_fn(width: usize, height: usize, mut f: impl FnMut(usize, usize) -> T) -> Self {
        let mut data = Vec::with_capacity(width * height);
        for y in 0..height {
            for x in 0..width {
                data.push(f(x, y));
            }
        }
        Grid {
            width,
            height,
            data,
        }
    }

    /// Wraps row-major `data`; `None` when its length is not `width * height`.
    pub fn from_vec(width: usize, height: usize, data: Vec<T>) -> Option<Self> {
        (data.len() == width * height).then_some(Grid {
            width,
            height,
            data,
        })
    }

    /// Width in samples.
    pub fn width(&self) -> usize {
        self.width
    }

    /// Height in samples.
    pub fn height(&self) -> usize {
        self.height
    }

    /// The sample at `(x, y)`; panics when out of range (callers index
    /// within `width`×`height`).
    #[inline]
    pub fn get(&self, x: usize, y: usize) -> T {
        self.data[y * self.width + x]
    }

    /// The sample at signed `(x, y)`, or `outside` beyond the grid.
    #[inline]
    pub fn get_or(&self, x: isize, y: isize, outside: T) -> T {
        if x < 0 || y < 0 || x as usize >= self.width || y as usize >= self.height {
            outside
        } else {
            self.data[y as usize * self.width + x as usize]
        }
    }

    /// Sets the sample at `(x, y)`.
    #[inline]
    pub fn set(&mut self, x: usize, y: usize, v: T) {
        self.data[y * self.width + x] = v;
    }

    /// Row-major samples.
    pub fn data(&self) -> &[T] {
        &self.data
    }

    /// Row-major samples, mutable.
    pub fn data_mut(&mut self) -> &mut [T] {
        &mut self.data
    }

    /// A grid of `f` applied to every sample.
    pub fn map<U: Copy>(&self, f: impl Fn(T) -> U) -> Grid<U> {
        Grid {
            width: self.width,
            height: self.height,
            data: self.data.iter().map(|&v| f(v)).collect(),
        }
    }
}

impl Grid<f32> {
    /// Bilinear interpolation at a continuous pixel position (pixel centres
    /// at half-integers), clamped at the border.
    #[inline]
    pub fn sample(&self, x: f64, y: f64) -> f32 {
        self.read(&Bilinear::at(self.width, self.height, x, y))
    }

    /// The value `at` reads: its four samples blended by its weights (0
    /// where they fall outside the data, which a [`Bilinear`] made for
    /// this grid's size never does).
    #[inline]
    pub fn read(&self, at: &Bilinear) -> f32 {
        let Bilinear { i, dx, dy, tx, ty } = *at;
        let (Some(&a), Some(&b), Some(&c), Some(&d)) = (
            self.data.get(i),
            self.data.get(i + dx),
            self.data.get(i + dy),
            self.data.get(i + dy + dx),
        ) else {
            return 0.0;
        };
        let top = a * (1.0 - tx) + b * tx;
        let bottom = c * (1.0 - tx) + d * tx;
        top * (1.0 - ty) + bottom * ty
    }
}

/// Where a bilinear read at one continuous position falls on a grid of a
/// given size: the index of its top-left sample, the steps to the next
/// column and row (0 on the last one: clamped at the border) and the
/// weights. Made once, it reads every grid of that size
/// ([`Grid::read`]), as [`Grid::sample`] would at the same position.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Bilinear {
    i: usize,
    dx: usize,
    dy: usize,
    tx: f32,
    ty: f32,
}

impl Bilinear {
    /// The read at `(x, y)` (px, pixel centres at half-integers) on a
    /// `w`×`h` grid (both at least 1), clamped at the border.
    #[inline]
    pub fn at(w: usize, h: usize, x: f64, y: f64) -> Bilinear {
        let fx = (x - 0.5).clamp(0.0, w.saturating_sub(1) as f64);
        let fy = (y - 0.5).clamp(0.0, h.saturating_sub(1) as f64);
        // Both are clamped to ≥ 0 (NaN becomes 0) and below the grid's
        // size, so truncation is floor and the signed cast is exact.
        let (xi, yi) = (fx as i64, fy as i64);
        let (x0, y0) = (xi as usize, yi as usize);
        Bilinear {
            i: y0 * w + x0,
            dx: usize::from(x0 + 1 < w),
            dy: if y0 + 1 < h { w } else { 0 },
            tx: (fx - xi as f64) as f32,
            ty: (fy - yi as f64) as f32,
        }
    }
}

/// The row-major indices of the 4-neighbours of pixel `i` of a `w`×`h`
/// grid that lie inside it: left, right, up, down.
pub fn neighbours4(i: usize, w: usize, h: usize) -> impl Iterator<Item = usize> {
    let (x, y) = (i % w, i / w);
    [
        (x > 0).then(|| i - 1),
        (x + 1 < w).then(|| i + 1),
        (y > 0).then(|| i - w),
        (y + 1 < h).then(|| i + w),
    ]
    .into_iter()
    .flatten()
}

/// `x` (finite, at least 0) rounded to the nearest integer, halves away
/// from zero, as `f32::round` does, without the library call that the
/// baseline x86-64 instruction set needs for it (the difference from the
/// truncation is exact for such `x`).
#[inline]
pub fn round_positive(x: f32) -> f32 {
    let t = x as i64 as f32;
    if x - t >= 0.5 {
        t + 1.0
    } else {
        t
    }
}

/// `x` held to 0..=255 and rounded half up, as [`round_positive`] rounds,
/// in one add and one saturating cast: adding the half is exact from 0.5
/// up (a value under 256 has at least 16 bits of fraction to spare);
/// below it, where the float just under 0.5 would round up to 1, the
/// answer is 0. NaN gives 0.
#[inline]
pub fn round_to_byte(x: f32) -> u8 {
    if x < 0.5 {
        0
    } else {
        (x + 0.5) as u8
    }
}

/// Ink coverage of one layer: 0 (paper) to 1 (ink) per pixel, anti-aliased
/// edges kept as fractional coverage.
pub type Coverage = Grid<f32>;

/// True when every coverage value is exactly 0 or 1: a binary bitmap,
/// whose edge lies anywhere within half a pixel of its staircase.
pub fn is_binary(cov: &Coverage) -> bool {
    cov.data().iter().all(|&c| c == 0.0 || c == 1.0)
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    proptest! {
        /// The rounding without the library call is `f32::round` on every
        /// non-negative value up to past where floats are all integers,
        /// halves and their neighbours included.
        #[test]
        fn round_positive_is_round(x in 0.0f32..2e7, k in 0u32..70_000) {
            prop_assert_eq!(round_positive(x), x.round());
            let half = k as f32 + 0.5;
            for v in [half, f32::from_bits(half.to_bits() - 1), f32::from_bits(half.to_bits() + 1)] {
                prop_assert_eq!(round_positive(v), v.round());
            }
        }

        /// Bilinear sampling reads the same bits as the textbook formula
        /// with the four corners clamped one by one, inside the grid, on
        /// its border and beyond it.
        #[test]
        fn sample_is_clamped_bilinear(
            w in 1usize..6,
            h in 1usize..6,
            x in -3.0f64..9.0,
            y in -3.0f64..9.0,
        ) {
            let g = Grid::from_fn(w, h, |i, j| ((i * 7 + j * 13) % 11) as f32 * 0.37 - 1.5);
            let fx = (x - 0.5).clamp(0.0, (w - 1) as f64);
            let fy = (y - 0.5).clamp(0.0, (h - 1) as f64);
            let (x0, y0) = (fx as usize, fy as usize);
            let (x1, y1) = ((x0 + 1).min(w - 1), (y0 + 1).min(h - 1));
            let tx = (fx - x0 as f64) as f32;
            let ty = (fy - y0 as f64) as f32;
            let top = g.get(x0, y0) * (1.0 - tx) + g.get(x1, y0) * tx;
            let bottom = g.get(x0, y1) * (1.0 - tx) + g.get(x1, y1) * tx;
            let want = top * (1.0 - ty) + bottom * ty;
            prop_assert_eq!(g.sample(x, y).to_bits(), want.to_bits());
        }
    }
}
