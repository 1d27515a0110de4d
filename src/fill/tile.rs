//! Exemplar tiles: colour layers as periodic signed distance channels, the
//! composite colour, and the source direction field.
//!
//! Fill tiles are seamless, so every lookup wraps around (the tile is a
//! torus) and every pixel is a valid patch centre. Each layer's SDF is made
//! periodic by tracing its zero level on the 3×3 repetition of the tile and
//! measuring exact distances there (art-pattern-level-sets §2, Fig. 1: the
//! SDF of the feature curves); the centre copy is kept.

use crate::error::{Error, Result};
use crate::field::{edge_tangent_flow, DirectionGrid, EtfOptions};
use crate::raster::{Grid, Sdf};
use crate::read::ink::{self, ImageOptions};
use crate::svg_out::Color;
use kurbo::{Affine, Vec2};
use std::path::Path;

/// Where the tile's own direction comes from.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum SourceDirection {
    /// The signed edge tangent flow of the tile's luminance (Brushables §3.1).
    Etf,
    /// One direction everywhere, `[x, y]` in the tile's axes (y down).
    Constant([f64; 2]),
}

/// One colour layer of a tile.
#[derive(Clone, Debug)]
pub struct TileLayer {
    /// Fill colour.
    pub color: Color,
    /// Periodic signed distance, tile pixels, negative inside.
    pub sdf: Grid<f32>,
}

/// A tile at one resolution.
#[derive(Clone, Debug)]
pub struct Tile {
    /// Layers, bottom first; each covers its colour and those above it.
    pub layers: Vec<TileLayer>,
    /// Composite colour (0..1 RGB) over white paper.
    pub colour: Grid<[f32; 3]>,
    /// Source direction per pixel (unit, pixel axes).
    pub direction: DirectionGrid,
    /// Tile user units per tile pixel at this resolution.
    pub units_per_px: f64,
    /// Where the pattern meets a border (Shape Hint), with a constant
    /// source direction.
    pub edge: Option<EdgeLine>,
}

/// A straight line on the tile (a torus) along the source direction: the
/// tile's stand-in for an exemplar's outline in the Shape Hint
/// ([`super::shape`]). It runs through the middle of the ink (the deepest
/// mean of the bottom layer's SDF along it), so the band lying on it is
/// what the synthesis puts on a region's outline.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct EdgeLine {
    /// A point of the line, tile pixels.
    pub origin: [f64; 2],
    /// Unit direction, pixel axes.
    pub dir: [f64; 2],
}

impl EdgeLine {
    /// The line with the deepest ink of `sdf` (bottom layer, periodic)
    /// among the parallels to `dir` half a pixel apart; `None` when the
    /// line's copies would cover more than a quarter of the tile (a
    /// direction at an odd slope winds densely around the torus).
    pub fn deepest(sdf: &Grid<f32>, dir: [f64; 2]) -> Option<EdgeLine> {
        let l = dir[0].hypot(dir[1]);
        if l.is_nan() || l <= 1e-9 {
            return None;
        }
        let d = [dir[0] / l, dir[1] / l];
        let n = [-d[1], d[0]];
        let (w, h) = (sdf.width(), sdf.height());
        let mut best: Option<(f64, EdgeLine)> = None;
        for i in 0..2 * w.max(h) {
            let t = i as f64 * 0.5;
            let line = EdgeLine {
                origin: [t * n[0], t * n[1]],
                dir: d,
            };
            let mut sum = 0.0;
            let mut count = 0usize;
            line.walk(w, h, 0.5, |x, y| {
                sum -= sdf.get(x, y) as f64;
                count += 1;
            });
            let score = sum / count.max(1) as f64;
            if best.is_none_or(|(b, _)| score > b) {
                best = Some((score, line));
            }
        }
        let line = best?.1;
        let covered = line.raster(w, h).data().iter().filter(|&&e| e).count();
        (4 * covered <= w * h).then_some(line)
    }

    /// Calls `f` with the pixel under each point of the line `step` px
    /// apart over four times the tile's larger side (a line at a simple
    /// slope closes on the torus within that), wrapped to the tile.
    fn walk(&self, w: usize, h: usize, step: f64, mut f: impl FnMut(usize, usize)) {
        let n = (4 * w.max(h)) as f64 / step;
        for k in 0..n as usize {
            let s = k as f64 * step;
            let (x, y) = (
                self.origin[0] + s * self.dir[0],
                self.origin[1] + s * self.dir[1],
            );
            let px = (x.floor() as i64).rem_euclid(w as i64) as usize;
            let py = (y.floor() as i64).rem_euclid(h as i64) as usize;
            f(px, py);
        }
    }

    /// The line's pixels on a `w`×`h` tile.
    pub fn raster(&self, w: usize, h: usize) -> Grid<bool> {
        let mut g = Grid::new(w, h, false);
        self.walk(w, h, 0.25, |x, y| g.set(x, y, true));
        g
    }
}

impl Tile {
    /// Loads a tile (SVG or PNG) at `resolution` px on its longest side
    /// (SVG; raster tiles keep their size). Fails when it holds no ink.
    pub fn load(path: &Path, resolution: u32, dir: SourceDirection) -> Result<Tile> {
        let ink = ink::load(
            path,
            &ImageOptions {
                resolution,
                invert: false,
                layers: true,
            },
        )?;
        let first = ink.layers.first().ok_or_else(|| {
            Error::invalid("tile has no ink: draw the pattern in a fill colour").in_file(path)
        })?;
        let (w, h) = (first.sdf.width(), first.sdf.height());
        if w < 8 || h < 8 {
            return Err(
                Error::invalid(format!("tile is {w}×{h} px; it needs at least 8×8 px"))
                    .in_file(path),
            );
        }
        let units_per_px = 1.0 / first.sdf.px_per_unit();
        let layers: Vec<TileLayer> = ink
            .layers
            .iter()
            .map(|l| TileLayer {
                color: l.color,
                sdf: periodic_sdf(&l.sdf.dist),
            })
            .collect();
        let ink_px = layers[0].sdf.data().iter().filter(|&&d| d < 0.0).count();
        if ink_px == 0 {
            return Err(Error::invalid("tile has no ink at this resolution: draw the pattern larger or raise the style's resolution").in_file(path));
        }
        if ink_px == w * h {
            return Err(Error::invalid(
                "tile is ink everywhere: leave paper between the motifs (no background rectangle)",
            )
            .in_file(path));
        }
        Ok(Tile::assemble(layers, dir, units_per_px))
    }

    /// A tile from periodic layers (composite colour and direction derived).
    pub fn assemble(layers: Vec<TileLayer>, dir: SourceDirection, units_per_px: f64) -> Tile {
        let (w, h) = (layers[0].sdf.width(), layers[0].sdf.height());
        let colour = composite(&layers, w, h);
        let edge = match dir {
            SourceDirection::Constant(d) => EdgeLine::deepest(&layers[0].sdf, d),
            SourceDirection::Etf => None,
        };
        let direction = match dir {
            SourceDirection::Constant(d) => crate::field::diffusion::constant_field(w, h, d),
            SourceDirection::Etf => {
                // On the 3×3 repetition so the flow wraps like the tile.
                let lum = Grid::from_fn(3 * w, 3 * h, |x, y| {
                    let c = colour.get(x % w, y % h);
                    0.299 * c[0] + 0.587 * c[1] + 0.114 * c[2]
                });
                let etf = edge_tangent_flow(&lum, &EtfOptions::default());
                Grid::from_fn(w, h, |x, y| etf.get(x + w, y + h))
            }
        };
        Tile {
            layers,
            colour,
            direction,
            units_per_px,
            edge,
        }
    }

    /// Width, pixels.
    pub fn width(&self) -> usize {
        self.colour.width()
    }

    /// Height, pixels.
    pub fn height(&self) -> usize {
        self.colour.height()
    }

    /// Fraction of the tile's pixels inside layer `m` (the bottom layer
    /// holds all ink).
    pub fn ink_fraction(&self, m: usize) -> f64 {
        self.layers.get(m).map_or(0.0, |l| {
            l.sdf.data().iter().filter(|&&d| d < 0.0).count() as f64 / l.sdf.data().len() as f64
        })
    }

    /// The tile at half resolution: 2×2 box means (wrapping), distances
    /// halved to the new pixel unit and re-measured exactly from the new
    /// zero level (as the E-step's reinitialization measures the target),
    /// directions averaged and renormalized.
    pub fn half(&self) -> Tile {
        let (w, h) = ((self.width() / 2).max(1), (self.height() / 2).max(1));
        let (sw, sh) = (self.width(), self.height());
        let avg = |g: &Grid<f32>, x: usize, y: usize| {
            let (x0, y0, x1, y1) = (2 * x % sw, 2 * y % sh, (2 * x + 1) % sw, (2 * y + 1) % sh);
            0.25 * (g.get(x0, y0) + g.get(x1, y0) + g.get(x0, y1) + g.get(x1, y1))
        };
        let layers = self
            .layers
            .iter()
            .map(|l| TileLayer {
                color: l.color,
                sdf: periodic_sdf(&Grid::from_fn(w, h, |x, y| 0.5 * avg(&l.sdf, x, y))),
            })
            .collect::<Vec<_>>();
        let colour = composite(&layers, w, h);
        let direction = Grid::from_fn(w, h, |x, y| {
            let mut v = Vec2::ZERO;
            for (dx, dy) in [(0, 0), (1, 0), (0, 1), (1, 1)] {
                let d = self.direction.get((2 * x + dx) % sw, (2 * y + dy) % sh);
                v += Vec2::new(d[0] as f64, d[1] as f64);
            }
            let m = v.hypot();
            if m > 1e-9 {
                [(v.x / m) as f32, (v.y / m) as f32]
            } else {
                self.direction.get((2 * x) % sw, (2 * y) % sh)
            }
        });
        Tile {
            layers,
            colour,
            direction,
            units_per_px: self.units_per_px * 2.0,
            edge: self.edge.map(|e| EdgeLine {
                origin: [0.5 * e.origin[0], 0.5 * e.origin[1]],
                dir: e.dir,
            }),
        }
    }
}

/// Colour over white paper: each layer, bottom first, laid over the ones
/// below with its anti-aliased coverage `clamp(½ − φ, 0, 1)`.
pub fn composite(layers: &[TileLayer], w: usize, h: usize) -> Grid<[f32; 3]> {
    Grid::from_fn(w, h, |x, y| {
        let mut c = [1.0f32; 3];
        for l in layers {
            let a = (0.5 - l.sdf.get(x, y)).clamp(0.0, 1.0);
            let lc = [l.color.r, l.color.g, l.color.b].map(|v| v as f32 / 255.0);
            for k in 0..3 {
                c[k] += a * (lc[k] - c[k]);
            }
        }
        c
    })
}

/// The SDF of `d`'s ink repeated periodically. Distances near the tile's
/// border may be to the wrong copy of the ink, so the 3×3 repetition is
/// re-measured from its anti-aliased coverage `clamp(½ − d, 0, 1)` (exact
/// where the input was within half a pixel of an edge, saturated beyond),
/// and the centre copy is kept.
pub fn periodic_sdf(d: &Grid<f32>) -> Grid<f32> {
    let (w, h) = (d.width(), d.height());
    let cov = Grid::from_fn(3 * w, 3 * h, |x, y| {
        (0.5 - d.get(x % w, y % h)).clamp(0.0, 1.0)
    });
    let sdf = Sdf::from_distance_ramp(&cov, Affine::IDENTITY);
    Grid::from_fn(w, h, |x, y| sdf.dist.get(x + w, y + h))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn etf_source_direction_runs_along_the_stripes() {
        // Vertical ink stripes 4 px wide every 8 px: the signed ETF of the
        // tile runs vertically at the stripes' edges.
        let sdf = periodic_sdf(&Grid::from_fn(32, 32, |x, _| {
            let u = (x % 8) as f32 + 0.5;
            (u - 4.0).max(-u)
        }));
        let layers = vec![TileLayer {
            color: Color::BLACK,
            sdf,
        }];
        let t = Tile::assemble(layers, SourceDirection::Etf, 1.0);
        for y in [3, 16, 29] {
            for x in [4, 12, 20] {
                let d = t.direction.get(x, y);
                assert!(d[1].abs() > 0.9, "({x}, {y}): {d:?}");
            }
        }
        assert!((t.ink_fraction(0) - 0.5).abs() < 0.01);
    }

    #[test]
    fn the_edge_line_runs_down_the_middle_of_a_stripe() {
        let sdf = periodic_sdf(&Grid::from_fn(32, 32, |x, _| {
            let u = (x % 8) as f32 + 0.5;
            (u - 4.0).max(-u)
        }));
        let line = EdgeLine::deepest(&sdf, [0.0, 2.0]).unwrap();
        assert_eq!(line.dir, [0.0, 1.0]);
        let r = line.raster(32, 32);
        let px: Vec<(usize, usize)> = (0..32 * 32)
            .map(|i| (i % 32, i / 32))
            .filter(|&(x, y)| r.get(x, y))
            .collect();
        // One whole column, in a stripe's middle.
        assert_eq!(px.len(), 32);
        assert!(px
            .iter()
            .all(|&(x, y)| sdf.get(x, y) < -1.0 && x == px[0].0));
        // It halves with the tile.
        let layers = vec![TileLayer {
            color: Color::BLACK,
            sdf,
        }];
        let t = Tile::assemble(layers, SourceDirection::Constant([0.0, 1.0]), 1.0);
        let h = t.half();
        let e = h.edge.unwrap();
        let hr = e.raster(16, 16);
        assert!((0..16).all(|y| (0..16).any(|x| hr.get(x, y) && h.layers[0].sdf.get(x, y) < 0.0)));
        // An ETF source has no edge line.
        let etf = Tile::assemble(t.layers.clone(), SourceDirection::Etf, 1.0);
        assert!(etf.edge.is_none());
    }

    #[test]
    fn periodic_sdf_sees_across_the_seam() {
        // A vertical band at x in [0, 2) of a 16-wide tile: pixel 15 is
        // 1 px from the band's copy to its right, not 13.
        let d = Grid::from_fn(16, 8, |x, _| {
            let xc = x as f32 + 0.5;
            (xc - 2.0).max(-xc)
        });
        let p = periodic_sdf(&d);
        assert!((p.get(15, 3) - 0.5).abs() < 0.05, "{}", p.get(15, 3));
        assert!((p.get(8, 3) - 6.5).abs() < 0.05, "{}", p.get(8, 3));
        assert!(p.get(0, 3) < 0.0);
    }
}
