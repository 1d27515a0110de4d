//! A brush style's figures as a whole, measured once when it is analysed
//! (and cached with it), so that no stroke pays for them: the exemplar
//! width the canvas scale follows, the smallest drawn element (the debris
//! threshold of the output), the thinnest drawn line (what the output grid
//! must resolve) and the palette of layer colours.

use super::style::Exemplar;
use crate::raster::Grid;
use crate::svg_out::Color;
use serde::{Deserialize, Serialize};

/// Percentile of the style's rib widths taken as "the exemplar width".
pub const WIDTH_PERCENTILE: f64 = 0.8;

/// Percentile of the exemplars' line thicknesses taken as their thinnest
/// line: low enough to hold a style's hairlines, high enough that the last
/// pixels of tapered tips (which thin to nothing) do not decide it.
pub const THIN_PERCENTILE: f64 = 0.1;

/// Smallest ink component counted as a drawn element, px² (the tracer's
/// default `min_area`: smaller ones are rasterization specks).
pub const SPECK: usize = 4;

/// How deep (px) inside its outline some pixel of a drawn element lies: a
/// piece with no pixel centre a pixel from its edge is under 2 px thick
/// everywhere, a fragment of a hairline tip broken up by rasterization
/// (the scroll's tapering spikes leave 1–4 px dots at 512 px), not
/// something the artist drew.
pub const ELEMENT_DEPTH: f32 = 1.0;

/// A style's figures (see the module docs); lengths in finest-level px.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct StyleFacts {
    /// The exemplar width, finest px: the [`WIDTH_PERCENTILE`] of all rib
    /// widths (ribs reach the farthest ink, leaves and curls included, so a
    /// high percentile keeps the ornament within the stroke the designer
    /// drew). A query's stroke width is mapped to it; 0 when no exemplar
    /// has a rib width.
    pub width: f64,
    /// The area of the smallest drawn element of any exemplar, finest px²:
    /// a component of its ink of at least [`SPECK`] px² that is at least
    /// [`ELEMENT_DEPTH`] deep somewhere. Ornament pieces smaller than this
    /// are synthesis debris.
    pub smallest_piece: usize,
    /// The thinnest drawn line, finest px: the [`THIN_PERCENTILE`] of the
    /// line thicknesses ([`ridge_thicknesses`]) of every exemplar.
    pub thinnest_line: f64,
    /// The distinct layer colours, in order of first appearance (exemplar
    /// order, then each exemplar's layers bottom first).
    pub palette: Vec<Color>,
}

impl StyleFacts {
    /// The figures of analysed exemplars.
    pub fn of(exemplars: &[Exemplar]) -> StyleFacts {
        let mut widths: Vec<f64> = exemplars
            .iter()
            .flat_map(|e| e.ribs.widths())
            .filter(|w| w.is_finite() && *w > 0.0)
            .collect();
        let mut thick: Vec<f64> = exemplars
            .iter()
            .filter_map(|e| e.finest())
            .flat_map(|lv| ridge_thicknesses(&lv.ink.ink))
            .collect();
        let mut palette: Vec<Color> = Vec::new();
        for e in exemplars {
            if let Some(lv) = e.finest() {
                for l in &lv.ink.layers {
                    if !palette.contains(&l.color) {
                        palette.push(l.color);
                    }
                }
            }
        }
        StyleFacts {
            width: percentile(&mut widths, WIDTH_PERCENTILE).unwrap_or(0.0),
            smallest_piece: exemplars
                .iter()
                .filter_map(|e| e.finest())
                .flat_map(|lv| drawn_elements(&lv.ink.ink))
                .min()
                .unwrap_or(SPECK),
            thinnest_line: percentile(&mut thick, THIN_PERCENTILE).unwrap_or(1.0),
            palette,
        }
    }
}

/// The `p` quantile (0–1, nearest rank) of a sample, sorting it.
fn percentile(v: &mut [f64], p: f64) -> Option<f64> {
    v.sort_by(f64::total_cmp);
    let k = ((v.len() as f64 - 1.0) * p).round().max(0.0) as usize;
    v.get(k).copied()
}

/// The line thicknesses of an ink SDF (px, negative inside): twice the
/// depth of every ridge pixel, an ink pixel at least as deep as both its
/// neighbours along x or along y and deeper than one of them (the medial
/// axis, where the distance to the outline is half the line's thickness).
pub fn ridge_thicknesses(sdf: &Grid<f32>) -> Vec<f64> {
    let mut out = Vec::new();
    for y in 0..sdf.height() {
        for x in 0..sdf.width() {
            let d = sdf.get(x, y);
            if d >= 0.0 {
                continue;
            }
            let g = |dx: isize, dy: isize| sdf.get_or(x as isize + dx, y as isize + dy, 1.0);
            let ridge = |a: f32, b: f32| d <= a && d <= b && (d < a || d < b);
            if ridge(g(-1, 0), g(1, 0)) || ridge(g(0, -1), g(0, 1)) {
                out.push(-2.0 * d as f64);
            }
        }
    }
    out
}

/// The areas (px²) of the drawn elements of an ink SDF: its 4-connected
/// ink components of at least [`SPECK`] px² that reach [`ELEMENT_DEPTH`]
/// inside somewhere.
fn drawn_elements(sdf: &Grid<f32>) -> Vec<usize> {
    components(&sdf.map(|d| d < 0.0))
        .into_iter()
        .filter(|c| {
            c.iter()
                .any(|&i| sdf.data().get(i).is_some_and(|&d| d <= -ELEMENT_DEPTH))
        })
        .map(|c| c.len())
        .filter(|&n| n >= SPECK)
        .collect()
}

/// The 4-connected components of a mask, as lists of pixel indices
/// (row-major), in scan order.
pub fn components(mask: &Grid<bool>) -> Vec<Vec<usize>> {
    let (w, h) = (mask.width(), mask.height());
    let mut seen = vec![false; w * h];
    let mut out = Vec::new();
    for start in 0..w * h {
        if seen[start] || !mask.data()[start] {
            continue;
        }
        seen[start] = true;
        let mut comp = vec![start];
        let mut k = 0;
        while let Some(&i) = comp.get(k) {
            k += 1;
            let mut visit = |j: usize| {
                if !seen[j] && mask.data()[j] {
                    seen[j] = true;
                    comp.push(j);
                }
            };
            for j in crate::raster::neighbours4(i, w, h) {
                visit(j);
            }
        }
        out.push(comp);
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The signed distance to a band `x ∈ [5, 35]`, `y ∈ [y0, y1]` (px).
    fn band(w: usize, h: usize, y0: f64, y1: f64) -> Grid<f32> {
        Grid::from_fn(w, h, |x, y| {
            let (cx, cy) = (x as f64 + 0.5, y as f64 + 0.5);
            (y0 - cy).max(cy - y1).max(5.0 - cx).max(cx - 35.0) as f32
        })
    }

    #[test]
    fn a_band_is_as_thick_as_drawn_and_one_element() {
        let sdf = band(40, 30, 10.0, 16.0);
        let mut t = ridge_thicknesses(&sdf);
        // Its medial axis: the two middle rows (pixel centres half a pixel
        // off the middle line: 5 px) and the diagonals into its corners.
        let along = t.iter().filter(|v| (*v - 5.0).abs() < 0.01).count();
        assert!(along >= 2 * 24, "{along} of {}", t.len());
        assert!(t.iter().all(|v| *v > 0.0 && *v <= 5.0), "{t:?}");
        assert_eq!(percentile(&mut t, 0.5), Some(5.0));
        assert_eq!(drawn_elements(&sdf), vec![30 * 6]);
    }

    #[test]
    fn specks_and_shallow_dots_are_not_elements() {
        // A 6-px band and a 1-px line: the line is under 2 px thick
        // everywhere, so it is no drawn element.
        let sdf = Grid::from_fn(40, 30, |x, y| {
            let c = y as f64 + 0.5;
            let a = (10.0 - c).max(c - 16.0);
            let b = (22.0 - c).max(c - 23.0) + if x < 20 { 0.0 } else { 100.0 };
            let dot = if (x, y) == (30, 27) { -0.5 } else { 9.0 };
            a.min(b).min(dot) as f32
        });
        assert_eq!(drawn_elements(&sdf), vec![40 * 6]);
    }

    #[test]
    fn percentiles_take_the_nearest_rank() {
        let mut v = vec![5.0, 1.0, 4.0, 2.0, 3.0];
        assert_eq!(percentile(&mut v, 0.0), Some(1.0));
        assert_eq!(percentile(&mut v, 0.5), Some(3.0));
        assert_eq!(percentile(&mut v, 1.0), Some(5.0));
        assert_eq!(percentile(&mut [], 0.5), None);
    }
}
