//! Uneven lighting of a photographed sketch, measured and divided out
//! before the ink is read (by the raster decoder, [`crate::read::image`]).
//!
//! A phone photo of a drawing is brighter where the lamp was and falls off
//! towards the corners: the paper in a dim corner can be darker than one
//! half, and one threshold over the whole picture fills that corner with
//! ink. What the camera sees is the paper's and the ink's reflectance times
//! the light falling there, so the light is a smooth surface that divides
//! out. It is measured where the paper shows: the picture is cut into
//! blocks, each block's paper is its brightest tenth (ink covers less than
//! nine tenths of nearly every block of a line drawing), and a smooth
//! surface (a cubic polynomial in x and y) is fitted to the blocks by least
//! squares, dropping the blocks that lie well below it (blocks filled with
//! ink) and fitting again until none changes. This is the background
//! estimation of document binarization (a smooth surface fitted to the
//! background's samples, as in Lu, Su and Tan 2010 for degraded documents;
//! a polynomial surface, as photometric flat-fielding uses for vignetting).
//!
//! Evenly lit pictures (scans, renders: every sample the project ships)
//! are left exactly as they are: the surface is used only when it varies
//! by more than [`UNEVEN`] of the full scale over the picture.

use nalgebra::{SMatrix, SVector};
use rayon::prelude::*;

/// Smallest change of the paper's brightness over the picture (share of
/// full scale, 13 of 255 grey levels) that is divided out: under it the
/// ink scale's own paper allowance covers the difference.
pub const UNEVEN: f64 = 0.05;

/// Share of a block's pixels, brightest first, that is taken for its paper.
const PAPER_SHARE: f64 = 0.1;

/// How far (share of full scale) a block's paper may lie below the fitted
/// surface and still count as paper: further down, ink fills the block.
const BELOW: f64 = 0.06;

/// Blocks across the picture's longer side.
const BLOCKS: usize = 32;

/// Fewest pixels along a block's side.
const MIN_BLOCK: usize = 8;

/// Pixels read along a block's side, about (see [`block_paper`]).
const SAMPLES_ACROSS: usize = 4;

/// Rounds of fitting and dropping blocks, at most.
const ROUNDS: usize = 12;

/// Terms of the cubic surface: 1, u, v, u², uv, v², u³, u²v, uv², v³.
const TERMS: usize = 10;

/// The light over a picture, as the paper's brightness (0..=1, relative
/// luminance) at each point: a cubic polynomial in the picture's
/// coordinates scaled to −1..=1.
#[derive(Clone, Debug, PartialEq)]
pub struct Lighting {
    width: usize,
    height: usize,
    coef: [f64; TERMS],
    /// The brightest paper over the picture: what all the paper is evened
    /// out to.
    brightest: f64,
    /// The darkest paper over the picture.
    darkest: f64,
}

/// The cubic surface's terms at (u, v).
fn terms(u: f64, v: f64) -> [f64; TERMS] {
    [
        1.0,
        u,
        v,
        u * u,
        u * v,
        v * v,
        u * u * u,
        u * u * v,
        u * v * v,
        v * v * v,
    ]
}

impl Lighting {
    /// Measures the light of a `width` × `height` picture from its
    /// luminance `luma(x, y)` (0 black to 255 white). `None` when the
    /// picture is evenly lit (the paper varies by less than [`UNEVEN`]),
    /// too small to cut into blocks, or shows too little paper to fit.
    pub fn measure(
        width: usize,
        height: usize,
        luma: impl Fn(usize, usize) -> u8 + Sync,
    ) -> Option<Lighting> {
        let side = (width.max(height) / BLOCKS).max(MIN_BLOCK);
        let (bx, by) = (width.div_ceil(side), height.div_ceil(side));
        if width == 0 || height == 0 || bx * by < 4 * TERMS {
            return None;
        }
        let stride = (side / SAMPLES_ACROSS).max(1);
        let blocks = block_paper(&luma, width, height, side, stride);
        // Each block's centre in −1..=1 and its paper level.
        let to_u = |x: f64, n: usize| 2.0 * x / n as f64 - 1.0;
        let samples: Vec<([f64; TERMS], f64)> = blocks
            .iter()
            .enumerate()
            .map(|(k, &paper)| {
                let (i, j) = (k % bx, k / bx);
                let cx = ((i * side) as f64 + ((i + 1) * side).min(width) as f64) / 2.0;
                let cy = ((j * side) as f64 + ((j + 1) * side).min(height) as f64) / 2.0;
                (terms(to_u(cx, width), to_u(cy, height)), paper)
            })
            .collect();
        let mut keep = vec![true; samples.len()];
        let mut coef = fit(&samples, &keep)?;
        for _ in 0..ROUNDS {
            let next: Vec<bool> = samples
                .iter()
                .map(|(t, paper)| *paper >= eval(&coef, t) - BELOW)
                .collect();
            if next == keep {
                break;
            }
            keep = next;
            coef = fit(&samples, &keep)?;
        }
        // The surface's range over the paper it was fitted to.
        let (mut darkest, mut brightest) = (f64::INFINITY, f64::NEG_INFINITY);
        for ((t, _), _) in samples.iter().zip(&keep).filter(|(_, &k)| k) {
            let s = eval(&coef, t);
            darkest = darkest.min(s);
            brightest = brightest.max(s);
        }
        let lighting = Lighting {
            width,
            height,
            coef,
            brightest: brightest.min(1.0),
            darkest,
        };
        (darkest > 0.0 && brightest - darkest >= UNEVEN).then_some(lighting)
    }

    /// The paper's brightness (0..=1) at the centre of pixel (x, y).
    #[cfg(test)]
    pub fn paper_at(&self, x: usize, y: usize) -> f64 {
        let u = 2.0 * (x as f64 + 0.5) / self.width as f64 - 1.0;
        let v = 2.0 * (y as f64 + 0.5) / self.height as f64 - 1.0;
        eval(&self.coef, &terms(u, v))
    }

    /// One line for `--verbose`: what was evened out.
    pub fn note(&self) -> String {
        format!(
            "uneven light evened out: the paper measured from {:.0} % to {:.0} % of white",
            100.0 * self.darkest,
            100.0 * self.brightest
        )
    }

    /// The factor pixel (x, y)'s values are multiplied by to light it as
    /// the brightest paper is lit.
    #[cfg(test)]
    fn gain(&self, x: usize, y: usize) -> f32 {
        // The fitted surface stays positive over the paper it was fitted
        // to; between blocks filled with ink it may not, where it is held
        // to the darkest paper measured.
        let paper = self.paper_at(x, y).max(self.darkest);
        (self.brightest / paper) as f32
    }

    /// Each column's `u` coordinate (−1..=1 across the picture, at the
    /// pixel's centre), worked out once for all rows.
    fn columns(&self) -> Vec<f64> {
        let w = self.width as f64;
        (0..self.width)
            .map(|x| 2.0 * (x as f64 + 0.5) / w - 1.0)
            .collect()
    }

    /// The gains of row `y` (see `Lighting::gain`), pixel by pixel, at the
    /// columns' coordinates `us` ([`Lighting::columns`]): the surface
    /// along a row is a cubic in `u` whose coefficients are read off the
    /// two-variable one once per row and evaluated by Horner's rule (the
    /// same polynomial, to rounding).
    ///
    /// Written into `gains` (one per column) in a loop of its own, which
    /// the compiler vectorizes; the pixels are then scaled in another.
    fn fill_row_gains(&self, y: usize, us: &[f64], gains: &mut [f32]) {
        let v = 2.0 * (y as f64 + 0.5) / self.height as f64 - 1.0;
        let c = &self.coef;
        let a0 = c[0] + v * (c[2] + v * (c[5] + v * c[9]));
        let a1 = c[1] + v * (c[4] + v * c[8]);
        let a2 = c[3] + v * c[7];
        let a3 = c[6];
        let (darkest, brightest) = (self.darkest, self.brightest);
        for (g, &u) in gains.iter_mut().zip(us) {
            let paper = (a0 + u * (a1 + u * (a2 + u * a3))).max(darkest);
            *g = (brightest / paper) as f32;
        }
    }

    /// Evens out the light of grey pixels (0..=255, row by row) in place.
    pub fn flatten_grey(&self, grey: &mut [u8]) {
        let w = self.width.max(1);
        let us = self.columns();
        grey.par_chunks_mut(w).enumerate().for_each_init(
            || vec![0f32; w],
            |gains, (y, row)| {
                self.fill_row_gains(y, &us, gains);
                for (v, &g) in row.iter_mut().zip(gains.iter()) {
                    *v = scaled(*v, g);
                }
            },
        );
    }

    /// Evens out the light of RGBA pixels (row by row) in place: each
    /// colour channel times the same gain, so hues stay.
    pub fn flatten_rgba(&self, px: &mut [[u8; 4]]) {
        let w = self.width.max(1);
        let us = self.columns();
        px.par_chunks_mut(w).enumerate().for_each_init(
            || vec![0f32; w],
            |gains, (y, row)| {
                self.fill_row_gains(y, &us, gains);
                for (p, &g) in row.iter_mut().zip(gains.iter()) {
                    let [r, gr, b, a] = *p;
                    *p = [scaled(r, g), scaled(gr, g), scaled(b, g), a];
                }
            },
        );
    }
}

/// `v` times `gain` (positive), rounded half up and held to 0..=255
/// ([`crate::raster::round_to_byte`]).
fn scaled(v: u8, gain: f32) -> u8 {
    crate::raster::round_to_byte(f32::from(v) * gain)
}

/// The surface `coef` at terms `t`.
fn eval(coef: &[f64; TERMS], t: &[f64; TERMS]) -> f64 {
    coef.iter().zip(t).map(|(c, t)| c * t).sum()
}

/// Least squares surface through the kept samples (normal equations,
/// Cholesky), `None` when too few are kept or they do not fix the surface.
fn fit(samples: &[([f64; TERMS], f64)], keep: &[bool]) -> Option<[f64; TERMS]> {
    let mut ata = SMatrix::<f64, TERMS, TERMS>::zeros();
    let mut atb = SVector::<f64, TERMS>::zeros();
    let mut n = 0usize;
    for ((t, paper), _) in samples.iter().zip(keep).filter(|(_, &k)| k) {
        let t = SVector::<f64, TERMS>::from_column_slice(t);
        ata += t * t.transpose();
        atb += t * *paper;
        n += 1;
    }
    if n < 2 * TERMS {
        return None;
    }
    let x = ata.cholesky()?.solve(&atb);
    let mut coef = [0.0; TERMS];
    coef.copy_from_slice(x.as_slice());
    coef.iter().all(|c| c.is_finite()).then_some(coef)
}

/// Each block's paper (0..=1): the level above which lies the brightest
/// [`PAPER_SHARE`] of its pixels, read on a lattice of every `stride`th
/// pixel each way (about 16 per block: the light changes over many blocks
/// and the fit averages them, so reading more pixels buys nothing and
/// costs a visible share of a trace). Blocks are `side` px square (cut
/// short at the right and bottom edges), row by row.
fn block_paper(
    luma: &(impl Fn(usize, usize) -> u8 + Sync),
    width: usize,
    height: usize,
    side: usize,
    stride: usize,
) -> Vec<f64> {
    let bx = width.div_ceil(side);
    let by = height.div_ceil(side);
    (0..by)
        .into_par_iter()
        .flat_map_iter(|j| {
            let rows = (j * side..((j + 1) * side).min(height)).step_by(stride);
            (0..bx)
                .map(|i| {
                    let mut hist = [0u32; 256];
                    for y in rows.clone() {
                        for x in (i * side..((i + 1) * side).min(width)).step_by(stride) {
                            hist[usize::from(luma(x, y))] += 1;
                        }
                    }
                    let total: u32 = hist.iter().sum();
                    let wanted = ((f64::from(total) * PAPER_SHARE).ceil() as u32).max(1);
                    let mut seen = 0u32;
                    for v in (0..256).rev() {
                        seen += hist[v];
                        if seen >= wanted {
                            return v as f64 / 255.0;
                        }
                    }
                    0.0
                })
                .collect::<Vec<f64>>()
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A picture lit by `light` (0..=1 at each pixel) holding white paper
    /// (240) with dark strokes (30) on a grid of lines and one solid black
    /// square (ink filling several blocks).
    fn photo(w: usize, h: usize, light: impl Fn(f64, f64) -> f64) -> Vec<u8> {
        let mut out = vec![0u8; w * h];
        for y in 0..h {
            for x in 0..w {
                let stroke = x % 37 < 3 || y % 53 < 2;
                let solid = (100..180).contains(&x) && (60..140).contains(&y);
                let r = if stroke || solid { 30.0 } else { 240.0 };
                let l = light(x as f64 / w as f64, y as f64 / h as f64);
                out[y * w + x] = (r * l).round() as u8;
            }
        }
        out
    }

    /// Reads pixel (x, y) of a `w`-wide picture.
    fn at(img: &[u8], w: usize) -> impl Fn(usize, usize) -> u8 + Sync + '_ {
        move |x, y| img[y * w + x]
    }

    #[test]
    fn an_evenly_lit_picture_is_left_alone() {
        let img = photo(400, 300, |_, _| 1.0);
        assert_eq!(Lighting::measure(400, 300, at(&img, 400)), None);
        // A gentle fall-off (3 %) is within the ink scale's allowance.
        let img = photo(400, 300, |u, _| 1.0 - 0.03 * u);
        assert_eq!(Lighting::measure(400, 300, at(&img, 400)), None);
    }

    #[test]
    fn a_light_falling_off_is_measured_on_the_paper_and_divided_out() {
        // Light from 1 in the top-left corner to 0.45 in the bottom-right,
        // curved (as a lamp's fall-off is).
        let light = |u: f64, v: f64| 1.0 - 0.55 * (0.6 * u + 0.4 * v * v);
        let (w, h) = (400, 300);
        let mut img = photo(w, h, light);
        let l = Lighting::measure(w, h, at(&img, w)).expect("uneven");
        // The surface follows the paper (240 × light) to 1.5 % everywhere,
        // the solid square included (its blocks were dropped).
        for y in (0..h).step_by(7) {
            for x in (0..w).step_by(7) {
                let want = 240.0 / 255.0 * light(x as f64 / w as f64, y as f64 / h as f64);
                let got = l.paper_at(x, y);
                assert!((got - want).abs() < 0.015, "({x}, {y}): {got} vs {want}");
            }
        }
        // Evened out, paper is paper and ink is ink everywhere: the paper
        // within 8 levels (3 %) of its level in the light, the ink at least
        // 150 below it.
        l.flatten_grey(&mut img);
        let clean = photo(w, h, |_, _| 1.0);
        for (k, (&v, &c)) in img.iter().zip(&clean).enumerate() {
            if c == 240 {
                assert!(v >= 232, "paper at {k}: {v}");
            } else {
                assert!(v <= 90, "ink at {k}: {v}");
            }
        }
    }

    #[test]
    fn colours_keep_their_hue() {
        let (w, h) = (200, 200);
        let luma = photo(w, h, |u, _| 1.0 - 0.5 * u);
        let l = Lighting::measure(w, h, at(&luma, w)).expect("uneven");
        let mut px = vec![[100u8, 50, 25, 255]; w * h];
        l.flatten_rgba(&mut px);
        for p in &px {
            // Channels scaled alike: ratios within rounding.
            let r = f64::from(p[0]);
            assert!((f64::from(p[1]) - r / 2.0).abs() <= 1.0, "{p:?}");
            assert!((f64::from(p[2]) - r / 4.0).abs() <= 1.0, "{p:?}");
            assert_eq!(p[3], 255);
        }
    }

    /// The gains a row is evened out by are the surface's, pixel by pixel
    /// (to float rounding).
    #[test]
    fn row_gains_are_the_surface() {
        let (w, h) = (173, 97);
        let light = |u: f64, v: f64| 0.95 - 0.5 * (0.7 * u * u * u + 0.3 * v - 0.2 * u * v * v);
        let img = photo(w, h, light);
        let l = Lighting::measure(w, h, at(&img, w)).expect("uneven");
        let mut gains = vec![0f32; w];
        for y in 0..h {
            l.fill_row_gains(y, &l.columns(), &mut gains);
            for (x, &g) in gains.iter().enumerate() {
                let want = l.gain(x, y);
                assert!((g - want).abs() <= 1e-6 * want, "({x}, {y}): {g} vs {want}");
            }
        }
    }

    /// The scaled value is `round_positive` of the clamped product, for
    /// every byte, at gains putting the product on a half and one ulp
    /// either side of it, and at a few plain gains.
    #[test]
    fn scaled_rounds_as_round_positive() {
        let check = |v: u8, g: f32| {
            let want = crate::raster::round_positive((f32::from(v) * g).clamp(0.0, 255.0)) as u8;
            assert_eq!(scaled(v, g), want, "{v} × {g}");
        };
        for v in 0..=255u8 {
            for g in [0.3f32, 0.5, 1.0, 1.0 / 3.0, 1.25, 1.5, 7.9] {
                check(v, g);
            }
            for t in 0..=255u32 {
                let g = (t as f32 + 0.5) / f32::from(v.max(1));
                for g in [
                    g,
                    f32::from_bits(g.to_bits() - 1),
                    f32::from_bits(g.to_bits() + 1),
                ] {
                    check(v, g);
                }
            }
        }
    }

    #[test]
    fn tiny_pictures_are_not_measured() {
        assert_eq!(Lighting::measure(2, 2, at(&[0, 255, 0, 255], 2)), None);
        assert_eq!(Lighting::measure(0, 0, |_, _| 255), None);
        assert_eq!(Lighting::measure(0, 100, |_, _| 255), None);
    }
}
