//! Where the edge a binary bitmap was rendered from can lie.
//!
//! A binary pixel only says on which side of the edge its centre is. So the
//! edge passes between every ink centre and every paper centre next to it:
//! through the cells whose corners are the centres of a 2×2 block of
//! pixels of both colours ("mixed" cells), a band about one pixel wide
//! around the staircase, and not through the centres themselves (it is
//! kept [`Corridor::KEEP_OUT`] from them, so thin lines keep their width).
//! A curve inside that band renders (thresholded at the pixel centres) to
//! the same bitmap; the fitter lets curves stray the tolerance beyond it,
//! and the band does not say on which side of a centre next to two mixed
//! cells a curve passes, so the output's centres are not all the input's.
//! Holding every curve to the right side of each centre as well would
//! cost several times the segments and still not reach an IoU of 0.99, as
//! the smoothed outline the curves follow does not keep to it either.
//! potrace's polygon stage reads the bitmap the same way: a straight path
//! may pass anywhere within half a pixel of the boundary (Selinger 2003,
//! §2.2.1), and its curve optimization only asks the curves to stay
//! within a tolerance of that (§2.4).
//!
//! [`Corridor::reaches`] is the acceptance test the fitter uses for binary
//! outlines (the tracer's `cover`): a curve point is acceptable when a
//! mixed cell lies within the tolerance of it.

use super::paths::Bitmap;
#[cfg(test)]
use crate::raster::Coverage;
use kurbo::Point;
use std::borrow::Cow;

/// The mixed cells of a binary bitmap (see the module docs), read from the
/// bitmap's padded flags when asked ([`Corridor::reaches`] looks at a few
/// cells per curve point, far fewer than the bitmap's cells, so no grid of
/// them is built).
#[derive(Clone, Debug)]
pub struct Corridor<'a> {
    /// The ink flags, borrowed from the tracer's bitmap or owned.
    bits: Cow<'a, Bitmap>,
}

impl Corridor<'static> {
    /// The corridor of binary coverage `cov` (ink where coverage ≥ ½).
    #[cfg(test)]
    pub fn new(cov: &Coverage) -> Self {
        Corridor {
            bits: Cow::Owned(Bitmap::from_coverage(cov)),
        }
    }
}

impl<'a> Corridor<'a> {
    /// How far (px) the corridor reaches to either side of the staircase
    /// along the pixel axes: half a pixel, the whole uncertainty of a
    /// binary edge.
    pub const HALF_WIDTH: f64 = 0.5;

    /// The corridor of a bitmap's ink.
    pub fn from_bitmap(bits: &'a Bitmap) -> Self {
        Corridor {
            bits: Cow::Borrowed(bits),
        }
    }

    /// Whether the cell between the centres of pixels (ci − 1, cj − 1) and
    /// (ci, cj) has centres of both colours (pixels outside the bitmap are
    /// paper): its corners are padded flags (ci, cj) to (ci + 1, cj + 1).
    fn mixed(&self, ci: usize, cj: usize) -> bool {
        let pw = self.bits.width() + 2;
        let f = self.bits.flags();
        let i = cj * pw + ci;
        match (f.get(i), f.get(i + 1), f.get(i + pw), f.get(i + pw + 1)) {
            (Some(&a), Some(&b), Some(&c), Some(&d)) => (a | b | c | d) != (a & b & c & d),
            _ => false,
        }
    }

    /// How close (px) the edge may come to a pixel centre: it passes
    /// between the centres, and keeping it half a pixel from them keeps a
    /// one-pixel line at least a pixel wide and a one-pixel gap open.
    pub const KEEP_OUT: f64 = 0.5;

    /// Whether `p` (pixel coordinates) is within `reach` px of where the
    /// edge may be: a mixed cell lies within `reach` of it (Euclidean), and
    /// it is at least [`Self::KEEP_OUT`] − `reach` from every pixel centre.
    pub fn reaches(&self, p: Point, reach: f64) -> bool {
        if !(p.x.is_finite() && p.y.is_finite()) {
            return false;
        }
        let reach = reach.max(0.0);
        // Not within the keep-out of a pixel centre (the nearest one).
        let c = Point::new((p.x - 0.5).round() + 0.5, (p.y - 0.5).round() + 0.5);
        let keep = Self::KEEP_OUT - reach;
        if keep > 0.0 && (p - c).hypot2() < keep * keep {
            return false;
        }
        // Cell (ci, cj) spans x from ci − ½ to ci + ½ (centres of pixels
        // ci − 1 and ci), likewise y.
        let (w, h) = (
            self.bits.width() as isize + 1,
            self.bits.height() as isize + 1,
        );
        let lo = |v: f64| (v - reach + 0.5).floor() as isize;
        let hi = |v: f64| (v + reach + 0.5).floor() as isize;
        for cj in lo(p.y).max(0)..=hi(p.y).min(h - 1) {
            for ci in lo(p.x).max(0)..=hi(p.x).min(w - 1) {
                if !self.mixed(ci as usize, cj as usize) {
                    continue;
                }
                let x0 = ci as f64 - 0.5;
                let y0 = cj as f64 - 0.5;
                let dx = (x0 - p.x).max(p.x - (x0 + 1.0)).max(0.0);
                let dy = (y0 - p.y).max(p.y - (y0 + 1.0)).max(0.0);
                if dx * dx + dy * dy <= reach * reach {
                    return true;
                }
            }
        }
        false
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::raster::Grid;

    /// Brute force: the distance from `p` to the nearest mixed cell, from
    /// pixel centres directly (infinite within the keep-out of a centre,
    /// measured over every centre of the grid and around it).
    fn brute(cov: &Coverage, p: Point, reach: f64) -> f64 {
        let (w, h) = (cov.width() as isize, cov.height() as isize);
        let ink = |x: isize, y: isize| {
            x >= 0 && y >= 0 && x < w && y < h && cov.get(x as usize, y as usize) >= 0.5
        };
        let mut nearest_centre = f64::INFINITY;
        for j in -3..h + 3 {
            for i in -3..w + 3 {
                let c = Point::new(i as f64 + 0.5, j as f64 + 0.5);
                nearest_centre = nearest_centre.min((p - c).hypot());
            }
        }
        if nearest_centre < Corridor::KEEP_OUT - reach {
            return f64::INFINITY;
        }
        let mut best = f64::INFINITY;
        for j in -1..h {
            for i in -1..w {
                let c = [ink(i, j), ink(i + 1, j), ink(i, j + 1), ink(i + 1, j + 1)];
                if c.iter().all(|&v| v == c[0]) {
                    continue;
                }
                // The cell spans the centres: x from i + ½ to i + 1½.
                let (x0, y0) = (i as f64 + 0.5, j as f64 + 0.5);
                let dx = (x0 - p.x).max(p.x - (x0 + 1.0)).max(0.0);
                let dy = (y0 - p.y).max(p.y - (y0 + 1.0)).max(0.0);
                best = best.min(dx.hypot(dy));
            }
        }
        best
    }

    #[test]
    fn reaches_agrees_with_brute_force() {
        let cov = Grid::from_fn(12, 10, |x, y| {
            let d = (x as f64 + 0.5 - 6.0).hypot(y as f64 + 0.5 - 5.0);
            if d < 3.2 || (x == 1 && y == 8) {
                1.0
            } else {
                0.0
            }
        });
        let c = Corridor::new(&cov);
        let mut seed = 12345u64;
        let mut rnd = || {
            seed ^= seed << 13;
            seed ^= seed >> 7;
            seed ^= seed << 17;
            (seed >> 11) as f64 / (1u64 << 53) as f64
        };
        for _ in 0..4000 {
            let p = Point::new(rnd() * 14.0 - 1.0, rnd() * 12.0 - 1.0);
            let reach = rnd() * 1.5;
            let d = brute(&cov, p, reach);
            // Away from the boundary of the test the answers agree.
            if (d - reach).abs() > 1e-9 {
                assert_eq!(c.reaches(p, reach), d <= reach, "{p:?} reach {reach} d {d}");
            }
        }
        // The staircase itself (a pixel edge between ink and paper) is
        // always inside, paper far away never.
        assert!(c.reaches(Point::new(6.0, 5.0 - 3.0), 0.0));
        assert!(!c.reaches(Point::new(11.5, 0.5), 0.3));
    }
}
