//! Signed edge tangent flow: a smooth, consistently signed direction field
//! that runs along the edges of an image.
//!
//! The method is Kang, Lee & Chui's edge tangent flow (ETF, 2007) with the
//! sign harmonization of Brushables (Lukáč et al. 2015, §3.1):
//!
//! 1. Sobel gradients `g` of the input; the initial tangent is `g` turned a
//!    quarter turn, `t⁰ = (−g_y, g_x) / |g|`, and `ĝ = |g| / max |g|`.
//! 2. **Sign harmonization.** Tangent fields are usually only defined up to
//!    sign, and the 180° flips where two signs meet break any synthesis that
//!    reads the direction. The pixel with the largest gradient keeps its
//!    sign; a breadth-first walk from it flips every tangent that disagrees
//!    with the tangent it was reached from (Brushables §3.1, Fig. 3).
//! 3. **Filtering.** `t^{i+1}(x) = Σ_y φ(x,y) t^i(y) w_m(x,y) w_d(x,y) / k`
//!    over a window of radius `r` (Kang et al. Eq. 1–4): `w_m = ½(1 +
//!    tanh(η(ĝ(y) − ĝ(x))))` lets strong edges steer weak ones, `w_d =
//!    |t(x)·t(y)|` favours aligned neighbours and `φ = sign(t(x)·t(y))`
//!    keeps each pixel's own sign. Because `φ` makes the filter symmetric in
//!    sign, harmonizing before filtering changes only signs, not directions
//!    (Brushables §3.1). The window is applied as a horizontal then a
//!    vertical pass, as in Kang et al.'s separable implementation.
//! 4. A second harmonization walk over the filtered field fixes the sign of
//!    pixels whose initial direction was noise (see [`edge_tangent_flow`]).
//!
//! Pixels without a gradient (flat areas) start with a zero tangent; they
//! take the `w_m`-weighted mean of their neighbours, so directions diffuse
//! into flat areas from the edges around them.

use crate::raster::Grid;
use rayon::prelude::*;
use std::cmp::Reverse;
use std::collections::BinaryHeap;

/// A unit direction per pixel, `[x, y]` in pixel axes (y down); `[0, 0]`
/// where no direction is defined.
pub type DirectionGrid = Grid<[f32; 2]>;

/// Parameters of the edge tangent flow.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct EtfOptions {
    /// Filter window radius `r`, in pixels. Default 5.
    pub radius: usize,
    /// Number of filter iterations. Default 3 (Kang et al. use 2–3).
    pub iterations: usize,
    /// Steepness `η` of the magnitude weight `w_m`. Default 1.
    pub eta: f32,
}

impl Default for EtfOptions {
    fn default() -> Self {
        EtfOptions {
            radius: 5,
            iterations: 3,
            eta: 1.0,
        }
    }
}

/// Gradients below this fraction of the largest one count as flat.
const FLAT: f32 = 1e-4;

/// Sobel gradient of `img` (borders clamped), in value units per pixel.
pub fn sobel(img: &Grid<f32>) -> Grid<[f32; 2]> {
    let (w, h) = (img.width(), img.height());
    let at = |x: isize, y: isize| -> f32 {
        let cx = x.clamp(0, w as isize - 1) as usize;
        let cy = y.clamp(0, h as isize - 1) as usize;
        img.get(cx, cy)
    };
    Grid::from_fn(w, h, |x, y| {
        let (x, y) = (x as isize, y as isize);
        let gx = (at(x + 1, y - 1) + 2.0 * at(x + 1, y) + at(x + 1, y + 1))
            - (at(x - 1, y - 1) + 2.0 * at(x - 1, y) + at(x - 1, y + 1));
        let gy = (at(x - 1, y + 1) + 2.0 * at(x, y + 1) + at(x + 1, y + 1))
            - (at(x - 1, y - 1) + 2.0 * at(x, y - 1) + at(x + 1, y - 1));
        [gx / 8.0, gy / 8.0]
    })
}

/// The signed edge tangent flow of `img` (a grey image, a coverage grid or a
/// signed distance grid): unit tangents along its edges, with consistent
/// signs, `[0, 0]` only where the whole image is flat.
pub fn edge_tangent_flow(img: &Grid<f32>, opts: &EtfOptions) -> DirectionGrid {
    let grad = sobel(img);
    let (tangent, magnitude) = initial_tangents(&grad);
    let mut t = tangent;
    harmonize_signs(&mut t, &magnitude);
    for _ in 0..opts.iterations {
        t = filter_pass(&t, &magnitude, opts, Axis::X);
        t = filter_pass(&t, &magnitude, opts, Axis::Y);
    }
    // A pixel whose initial tangent was noise (on a ridge, where the
    // gradient vanishes) keeps that noise's sign through the filter, since
    // `φ` follows the pixel's own sign; a last walk gives it its
    // neighbours' sign.
    harmonize_signs(&mut t, &magnitude);
    t
}

/// Step 1: tangents `(−g_y, g_x)/|g|` and normalized magnitudes `ĝ ∈ [0, 1]`.
fn initial_tangents(grad: &Grid<[f32; 2]>) -> (DirectionGrid, Grid<f32>) {
    let max = grad
        .data()
        .iter()
        .map(|g| g[0].hypot(g[1]))
        .fold(0.0f32, f32::max);
    let scale = if max > 0.0 { 1.0 / max } else { 0.0 };
    let magnitude = grad.map(|g| g[0].hypot(g[1]) * scale);
    let tangent = grad.map(|g| {
        let m = g[0].hypot(g[1]);
        if m * scale > FLAT {
            [-g[1] / m, g[0] / m]
        } else {
            [0.0, 0.0]
        }
    });
    (tangent, magnitude)
}

/// Step 2 (Brushables §3.1): flip tangents so that each agrees in sign with
/// the one it is reached from in a walk over 4-neighbours that starts at the
/// largest gradient.
///
/// The walk is ordered by confidence: the next pixel is always the one
/// reached through the strongest link (link strength = the smaller `ĝ` of
/// its two pixels, i.e. Prim's maximum spanning tree), and the direction a
/// pixel passes on is its own only when its gradient is at least half as
/// strong as the reference it received (which otherwise passes on, fading
/// by [`REFERENCE_FADE`] per step). A plain FIFO walk lets signs travel
/// through ridge pixels, whose gradient is nearly zero and whose direction
/// is noise, and flips whole stripes; this one carries a measured direction
/// across them. Flat pixels pass the reference on unchanged.
pub fn harmonize_signs(t: &mut DirectionGrid, magnitude: &Grid<f32>) {
    let (w, h) = (t.width(), t.height());
    if w == 0 || h == 0 {
        return;
    }
    // First index of the maximum: deterministic on ties.
    let mut start = 0;
    for (i, &m) in magnitude.data().iter().enumerate() {
        if m > magnitude.data()[start] {
            start = i;
        }
    }
    let mag = magnitude.data();
    let mut seen = vec![false; w * h];
    // The direction each visited pixel passes on to its neighbours.
    let mut passed = vec![([0.0f32; 2], 0.0f32); w * h];
    passed[start] = (t.data()[start], mag[start]);
    // (link strength, Reverse(pixel) for deterministic ties, parent pixel).
    let mut heap = BinaryHeap::new();
    heap.push((Strength(f32::INFINITY), Reverse(start), start));
    while let Some((_, Reverse(i), parent)) = heap.pop() {
        if seen[i] {
            continue;
        }
        seen[i] = true;
        let (reference, strength) = passed[parent];
        let (x, y) = (i % w, i / w);
        let mut here = t.data()[i];
        if dot(here, reference) < 0.0 {
            here = [-here[0], -here[1]];
            t.data_mut()[i] = here;
        }
        passed[i] = if here != [0.0, 0.0] && mag[i] >= 0.5 * strength {
            (here, mag[i])
        } else {
            (reference, strength * REFERENCE_FADE)
        };
        let neighbours = [
            (x > 0).then(|| i - 1),
            (x + 1 < w).then(|| i + 1),
            (y > 0).then(|| i - w),
            (y + 1 < h).then(|| i + w),
        ];
        for j in neighbours.into_iter().flatten() {
            if !seen[j] {
                heap.push((Strength(mag[i].min(mag[j])), Reverse(j), i));
            }
        }
    }
}

/// How much a received reference direction weakens per pixel it is passed
/// through without being replaced (see [`harmonize_signs`]).
pub const REFERENCE_FADE: f32 = 0.9;

/// A totally ordered link strength (magnitudes are finite or +inf).
#[derive(Clone, Copy, PartialEq)]
struct Strength(f32);

impl Eq for Strength {}

impl PartialOrd for Strength {
    fn partial_cmp(&self, other: &Self) -> Option<std::cmp::Ordering> {
        Some(self.cmp(other))
    }
}

impl Ord for Strength {
    fn cmp(&self, other: &Self) -> std::cmp::Ordering {
        self.0.total_cmp(&other.0)
    }
}

#[derive(Clone, Copy)]
enum Axis {
    X,
    Y,
}

/// Step 3: one separable pass of the ETF filter along `axis`.
fn filter_pass(
    t: &DirectionGrid,
    magnitude: &Grid<f32>,
    opts: &EtfOptions,
    axis: Axis,
) -> DirectionGrid {
    let (w, h) = (t.width(), t.height());
    let r = opts.radius as isize;
    let mut out = vec![[0.0f32; 2]; w * h];
    out.par_chunks_mut(w.max(1))
        .enumerate()
        .for_each(|(y, row)| {
            for (x, o) in row.iter_mut().enumerate() {
                let tx = t.get(x, y);
                let gx = magnitude.get(x, y);
                let flat = tx == [0.0, 0.0];
                let mut sum = [0.0f32; 2];
                for k in -r..=r {
                    let (nx, ny) = match axis {
                        Axis::X => (x as isize + k, y as isize),
                        Axis::Y => (x as isize, y as isize + k),
                    };
                    if nx < 0 || ny < 0 || nx >= w as isize || ny >= h as isize {
                        continue;
                    }
                    let ty = t.get(nx as usize, ny as usize);
                    let gy = magnitude.get(nx as usize, ny as usize);
                    let wm = 0.5 * (1.0 + (opts.eta * (gy - gx)).tanh());
                    let d = dot(tx, ty);
                    // A flat pixel has no sign or direction of its own: it
                    // takes its neighbours as they are.
                    let (phi, wd) = if flat {
                        (1.0, 1.0)
                    } else {
                        (if d < 0.0 { -1.0 } else { 1.0 }, d.abs())
                    };
                    let wgt = phi * wm * wd;
                    sum[0] += wgt * ty[0];
                    sum[1] += wgt * ty[1];
                }
                let n = sum[0].hypot(sum[1]);
                *o = if n > 1e-12 {
                    [sum[0] / n, sum[1] / n]
                } else {
                    tx
                };
            }
        });
    // from_vec only fails on a size mismatch, which cannot happen here.
    Grid::from_vec(w, h, out).unwrap_or_else(|| t.clone())
}

fn dot(a: [f32; 2], b: [f32; 2]) -> f32 {
    a[0] * b[0] + a[1] * b[1]
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::f32::consts::PI;

    /// Radial stripes (Brushables Fig. 3): a fan of spokes, intensity
    /// `cos(k·θ)` around a centre `below` pixels under the image. Edges run
    /// along the radii; an unsigned ETF flips by 180° across every stripe,
    /// the harmonized one must not. (With the centre inside the image no
    /// signing is free of seams: a line through a source singularity points
    /// outward on one side and inward on the other.)
    fn radial_stripes(n: usize, spokes: f32, below: f32) -> Grid<f32> {
        let (cx, cy) = (n as f32 / 2.0, n as f32 + below);
        Grid::from_fn(n, n, |x, y| {
            let (dx, dy) = (x as f32 + 0.5 - cx, y as f32 + 0.5 - cy);
            (spokes * dy.atan2(dx)).cos()
        })
    }

    fn count_flips(t: &DirectionGrid, skip: impl Fn(usize, usize) -> bool) -> usize {
        let mut flips = 0;
        for y in 0..t.height() {
            for x in 0..t.width() {
                if skip(x, y) {
                    continue;
                }
                let a = t.get(x, y);
                if x + 1 < t.width() && !skip(x + 1, y) && dot(a, t.get(x + 1, y)) < -0.5 {
                    flips += 1;
                }
                if y + 1 < t.height() && !skip(x, y + 1) && dot(a, t.get(x, y + 1)) < -0.5 {
                    flips += 1;
                }
            }
        }
        flips
    }

    #[test]
    fn radial_stripes_have_no_flips_and_follow_the_radii() {
        let (n, below) = (96, 24.0);
        let img = radial_stripes(n, 24.0, below);
        let t = edge_tangent_flow(&img, &EtfOptions::default());
        assert_eq!(count_flips(&t, |_, _| false), 0);
        // Direction: along the radius, within 10°, and all one way.
        let (cx, cy) = (n as f32 / 2.0, n as f32 + below);
        let mut aligned = 0;
        let mut signs = [0usize; 2];
        for y in 0..n {
            for x in 0..n {
                let (dx, dy) = (x as f32 + 0.5 - cx, y as f32 + 0.5 - cy);
                let r = dx.hypot(dy);
                let v = t.get(x, y);
                let c = (v[0] * dx + v[1] * dy) / r;
                if c.abs() > (10.0 * PI / 180.0).cos() {
                    aligned += 1;
                }
                signs[(c > 0.0) as usize] += 1;
            }
        }
        assert!(
            aligned as f32 > 0.95 * (n * n) as f32,
            "{aligned}/{}",
            n * n
        );
        assert!(signs[0] == 0 || signs[1] == 0, "{signs:?}");
    }

    #[test]
    fn unharmonized_tangents_do_flip() {
        // The same stripes without harmonization: the test above can fail.
        let img = radial_stripes(64, 24.0, 24.0);
        let (t, _) = initial_tangents(&sobel(&img));
        assert!(count_flips(&t, |_, _| false) > 10);
    }

    #[test]
    fn concentric_rings_give_a_consistent_vortex() {
        let n = 80;
        let c = n as f32 / 2.0;
        let img = Grid::from_fn(n, n, |x, y| {
            let r = (x as f32 + 0.5 - c).hypot(y as f32 + 0.5 - c);
            (r * 0.6).sin()
        });
        let t = edge_tangent_flow(&img, &EtfOptions::default());
        let mut signs = [0usize; 2];
        for y in 0..n {
            for x in 0..n {
                let (dx, dy) = (x as f32 + 0.5 - c, y as f32 + 0.5 - c);
                let r = dx.hypot(dy);
                if !(8.0..c - 2.0).contains(&r) {
                    continue;
                }
                let v = t.get(x, y);
                // Tangential component: (−dy, dx)/r.
                let s = (-v[0] * dy + v[1] * dx) / r;
                assert!(s.abs() > 0.9, "not tangential at {x},{y}: {v:?}");
                signs[(s > 0.0) as usize] += 1;
            }
        }
        // One sense of rotation everywhere.
        assert!(signs[0] == 0 || signs[1] == 0, "{signs:?}");
    }

    #[test]
    fn flat_image_and_empty_grid_do_not_panic() {
        let t = edge_tangent_flow(&Grid::new(8, 8, 0.5), &EtfOptions::default());
        assert!(t.data().iter().all(|v| *v == [0.0, 0.0]));
        let t = edge_tangent_flow(&Grid::new(0, 0, 0.0), &EtfOptions::default());
        assert_eq!(t.width(), 0);
    }

    #[test]
    fn directions_diffuse_into_flat_areas() {
        // A single horizontal edge in the middle; the flat areas above and
        // below take its direction.
        let img = Grid::from_fn(32, 32, |_, y| if y < 16 { 0.0 } else { 1.0 });
        let t = edge_tangent_flow(&img, &EtfOptions::default());
        for y in 10..22 {
            for x in 0..32 {
                let v = t.get(x, y);
                assert!(v[0].abs() > 0.99, "{x},{y}: {v:?}");
            }
        }
    }
}
