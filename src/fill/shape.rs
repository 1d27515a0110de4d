//! The Shape Hint of Brushables (Lukáč et al. 2015, §3.3, Eq. 6): a local
//! descriptor of where the boundary lies around a pixel, so that the
//! synthesis puts at the region's outline what the exemplar has at its
//! edge.
//!
//! Like a one-ring shape context, the descriptor counts edge pixels in
//! [`BINS`] bins around the pixel, oriented by the local direction (so a
//! source and a target descriptor are compared in the rotated frame of
//! Eq. 5); the bins are discs (one at the centre, the others on a ring of
//! radius `ρ`), so every bin's count at every pixel is one lookup in the
//! edge map convolved once with a disc of the bin radius. Two descriptors
//! are compared by the χ² distance of the histograms.
//!
//! A fill tile is seamless and has no outline of its own; its *edge* is the
//! straight line along the source direction through the middle of the ink
//! ([`super::tile::EdgeLine`]), where the pattern would be cut to meet a
//! border. Near the region's outline the hint then draws the band lying
//! on that line onto the outline; away from the outline the target
//! descriptor is empty and the term is left out (the tile's edge line
//! repeats across the torus, so an empty source descriptor is rare and an
//! empty target must not push the interior away from it).

use crate::raster::Grid;

/// Bins per descriptor: the centre and a ring of eight.
pub const BINS: usize = 9;

/// A descriptor: edge counts per bin, in units of one bin diameter of
/// edge (a straight edge through a bin's centre counts ≈ 1).
pub type Histogram = [f32; BINS];

/// Disc-convolved edge maps and the descriptor geometry.
#[derive(Clone, Debug)]
pub struct ShapeHint {
    /// Edge pixels within the bin radius of each pixel, normalized.
    counts: Grid<f32>,
    /// Lookups wrap (a tile) or clamp (a target).
    periodic: bool,
    /// Ring radius `ρ`, pixels.
    pub ring: f32,
}

impl ShapeHint {
    /// The hint of the edge map `edge` with bin radius `bin` px on a ring
    /// of radius `ring` px; `periodic` for a tile.
    pub fn new(edge: &Grid<bool>, periodic: bool, ring: f32, bin: f32) -> ShapeHint {
        let (w, h) = (edge.width(), edge.height());
        let b = bin.max(0.5);
        let reach = b.ceil() as isize;
        let disc: Vec<(isize, isize)> = (-reach..=reach)
            .flat_map(|dy| (-reach..=reach).map(move |dx| (dx, dy)))
            .filter(|&(dx, dy)| ((dx * dx + dy * dy) as f32) <= b * b)
            .collect();
        let norm = 1.0 / (2.0 * b + 1.0);
        let mut counts = Grid::new(w, h, 0.0f32);
        for y in 0..h {
            for x in 0..w {
                if !edge.get(x, y) {
                    continue;
                }
                for &(dx, dy) in &disc {
                    let (mut tx, mut ty) = (x as isize + dx, y as isize + dy);
                    if periodic {
                        tx = tx.rem_euclid(w as isize);
                        ty = ty.rem_euclid(h as isize);
                    } else if tx < 0 || ty < 0 || tx >= w as isize || ty >= h as isize {
                        continue;
                    }
                    let (tx, ty) = (tx as usize, ty as usize);
                    counts.set(tx, ty, counts.get(tx, ty) + norm);
                }
            }
        }
        ShapeHint {
            counts,
            periodic,
            ring,
        }
    }

    /// The descriptor at pixel `(x, y)` with its frame turned to `angle`
    /// radians (bin `k ≥ 1` at `ρ·(cos, sin)(angle + (k−1)·45°)`).
    pub fn histogram(&self, x: usize, y: usize, angle: f32) -> Histogram {
        let (w, h) = (self.counts.width() as isize, self.counts.height() as isize);
        let mut out = [0.0; BINS];
        for (k, v) in out.iter_mut().enumerate() {
            let (ox, oy) = if k == 0 {
                (0.0, 0.0)
            } else {
                let a = angle + (k - 1) as f32 * std::f32::consts::FRAC_PI_4;
                (self.ring * a.cos(), self.ring * a.sin())
            };
            let (mut px, mut py) = (
                (x as f32 + ox).round() as isize,
                (y as f32 + oy).round() as isize,
            );
            if self.periodic {
                px = px.rem_euclid(w);
                py = py.rem_euclid(h);
            } else {
                px = px.clamp(0, w - 1);
                py = py.clamp(0, h - 1);
            }
            *v = self.counts.get(px as usize, py as usize);
        }
        out
    }

    /// Descriptors of every pixel of `angle`'s grid (same size as the
    /// hint), each in the frame of its own angle.
    pub fn histograms(&self, angle: &Grid<f32>) -> Grid<Histogram> {
        Grid::from_fn(angle.width(), angle.height(), |x, y| {
            self.histogram(x, y, angle.get(x, y))
        })
    }
}

/// Whether a descriptor sees any edge.
pub fn is_empty(h: &Histogram) -> bool {
    h.iter().all(|&v| v <= 0.0)
}

/// The χ² distance `Σ (a − b)² / (a + b)` of Brushables Eq. 6 (bins empty
/// in both count 0).
pub fn chi2(a: &Histogram, b: &Histogram) -> f32 {
    a.iter()
        .zip(b)
        .map(|(&p, &q)| {
            let s = p + q;
            if s > 0.0 {
                (p - q) * (p - q) / s
            } else {
                0.0
            }
        })
        .sum()
}

/// The outline pixels of a mask: inside pixels with a 4-neighbour outside
/// (or on the grid's border).
pub fn outline(mask: &Grid<bool>) -> Grid<bool> {
    Grid::from_fn(mask.width(), mask.height(), |x, y| {
        mask.get(x, y)
            && [(-1, 0), (1, 0), (0, -1), (0, 1)]
                .iter()
                .any(|&(dx, dy)| !mask.get_or(x as isize + dx, y as isize + dy, false))
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_straight_edge_is_seen_on_its_side_and_at_its_depth() {
        // Edge: the row y = 20 of a 40×40 grid.
        let edge = Grid::from_fn(40, 40, |_, y| y == 20);
        let hint = ShapeHint::new(&edge, false, 6.0, 2.0);
        // On the edge the centre bin counts ≈ 1; the bins straight up and
        // down (90° and 270° of a frame along +x) are empty.
        let on = hint.histogram(20, 20, 0.0);
        assert!((on[0] - 1.0).abs() < 0.05, "{on:?}");
        assert_eq!(on[3], 0.0);
        assert_eq!(on[7], 0.0);
        // 6 px above the edge the bin at 90° (down, +y) lies on it.
        let above = hint.histogram(20, 14, 0.0);
        assert_eq!(above[0], 0.0);
        assert!(above[3] > 0.9 && above[7] == 0.0, "{above:?}");
        // The same place seen in a frame turned by 180° has it at 270°.
        let turned = hint.histogram(20, 14, std::f32::consts::PI);
        assert!((turned[7] - above[3]).abs() < 1e-6);
        // Far away: empty.
        assert!(is_empty(&hint.histogram(20, 2, 0.0)));
        // χ²: identical 0, depth mismatch positive, symmetric.
        assert_eq!(chi2(&above, &above), 0.0);
        assert!(chi2(&above, &on) > 1.0);
        assert_eq!(chi2(&above, &on), chi2(&on, &above));
    }

    #[test]
    fn disc_counts_match_brute_force_and_wrap_on_a_tile() {
        let edge = Grid::from_fn(16, 12, |x, y| (x * 7 + y * 3) % 11 == 0);
        let b = 2.5f32;
        let hint = ShapeHint::new(&edge, true, 4.0, b);
        for y in 0..12 {
            for x in 0..16 {
                let mut n = 0;
                for ey in 0..12 {
                    for ex in 0..16 {
                        // Torus offsets.
                        let dx = (ex as i32 - x as i32).rem_euclid(16);
                        let dy = (ey as i32 - y as i32).rem_euclid(12);
                        let (dx, dy) = (dx.min(16 - dx), dy.min(12 - dy));
                        if edge.get(ex, ey) && ((dx * dx + dy * dy) as f32) <= b * b {
                            n += 1;
                        }
                    }
                }
                let want = n as f32 / (2.0 * b + 1.0);
                let got = hint.histogram(x, y, 0.0)[0];
                assert!((got - want).abs() < 1e-5, "({x}, {y}): {got} vs {want}");
            }
        }
    }
}
