//! Exemplars (swatches): colour layers as signed distance channels, the
//! composite colour, the source direction field, and whether the swatch is
//! a seamless tile.
//!
//! A swatch is read at `resolution` px on its longest side, each fill
//! colour a layer (art-pattern-level-sets §3: one SDF channel per layer,
//! each extending under the layers above it). What kind of swatch it is
//! is read from its pixels:
//!
//! - a **seamless tile**: ink reaches its border and every layer runs on
//!   across the seams (the change of coverage from its last column to its
//!   first is no larger than the changes between neighbouring columns
//!   inside it, likewise for rows). Lookups wrap (the tile is a torus); each layer's
//!   SDF is measured on the 3×3 repetition so distances see across the
//!   seams (§2, Fig. 1: the SDF of the feature curves).
//! - any other swatch (a panel with a border, a motif on paper, a piece cut
//!   from a larger ornament) is **not periodic**: its SDFs are its own and
//!   patches are copied only from inside it. A motif on paper (a border of
//!   paper all round) has a *shape* — its ink closed and with the holes
//!   filled — which is what the synthesis copies from (the paper around a
//!   motif is not part of the pattern) and what the Shape Hint reads as
//!   its edge (Brushables §3.3: the source mask `M_s`).
//!
//! Colours are gathered over all of a style's swatches ([`Palette`]):
//! colours closer than [`MERGE_DISTANCE`] are one layer and at most
//! [`MAX_LAYERS`] layers are kept (a swatch's gradients and anti-aliased
//! shades are quantized). A swatch coloured edge to edge has no paper: the
//! colour that covers most of it is its *ground*, which fills the region,
//! and the other colours are stacked over it as in the swatch.

use crate::error::{Error, Result};
use crate::field::{edge_tangent_flow, DirectionGrid, EtfOptions};
use crate::raster::edt::squared_edt;
use crate::raster::{Grid, Sdf};
use crate::read::ink::{self, ImageOptions};
use crate::svg_out::Color;
use kurbo::{Affine, Vec2};
use std::path::Path;

/// Most colour layers a fill style synthesizes; more colours are merged
/// into the nearest ones.
pub const MAX_LAYERS: usize = 8;

/// Colours nearer than this (Euclidean distance of 0–255 RGB) are one
/// layer: shades of one ink left by anti-aliasing or flattened gradients.
pub const MERGE_DISTANCE: f64 = 24.0;

/// Share of a style's swatch pixels that ink must cover for the style to
/// count as coloured edge to edge (no paper).
pub const NO_PAPER: f64 = 0.99;

/// White paper, what shows under a swatch's ink.
pub const PAPER: Color = Color::rgb(255, 255, 255);

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
    /// Signed distance, tile pixels, negative inside (periodic for a
    /// seamless tile).
    pub sdf: Grid<f32>,
}

/// A swatch at one resolution, ready for synthesis.
#[derive(Clone, Debug)]
pub struct Tile {
    /// Layers, bottom first; each covers its colour and those above it.
    /// The ground of a swatch without paper is not among them.
    pub layers: Vec<TileLayer>,
    /// Composite colour (0..1 RGB) over the paper.
    pub colour: Grid<[f32; 3]>,
    /// Source direction per pixel (unit, pixel axes).
    pub direction: DirectionGrid,
    /// Swatch user units per pixel at this resolution.
    pub units_per_px: f64,
    /// Where the pattern meets a border (Shape Hint), for a seamless tile
    /// with a constant source direction.
    pub edge: Option<EdgeLine>,
    /// A seamless tile (lookups wrap).
    pub periodic: bool,
    /// For a motif on paper (a swatch whose border is paper), its shape:
    /// its ink closed and with the holes filled; `None` for a tile or a
    /// piece cut from a larger pattern (all of it is pattern).
    pub shape: Option<Grid<bool>>,
    /// What shows where no layer has ink: white paper, or the ground.
    pub paper: Color,
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

/// A swatch file as read: its colours and each one's visible coverage.
#[derive(Clone, Debug)]
pub struct Swatch {
    /// The colours in stacking order (first appearance), each with the
    /// coverage (0..1 per pixel) of its visible part.
    pub colours: Vec<(Color, Grid<f32>)>,
    /// Swatch user units per pixel.
    pub units_per_px: f64,
    /// How it was read, for `--verbose`.
    pub notes: Vec<String>,
}

impl Swatch {
    /// Reads `path` (SVG or raster) at `resolution` px on its longest
    /// side (a raster keeps its size). Fails, naming the file, when it
    /// holds no ink or is smaller than 8×8 px.
    pub fn read(path: &Path, resolution: u32) -> Result<Swatch> {
        let opts = ImageOptions {
            resolution,
            invert: false,
            layers: true,
        };
        let bytes = crate::io::read_file(path)?;
        let ink = if ink::looks_like_svg(&bytes) {
            read_svg_fitted(&bytes, &opts)
        } else {
            ink::read_raster(&bytes, &opts)
        }
        .map_err(|e| e.in_file(path))?;
        let first = ink.layers.first().ok_or_else(|| {
            Error::invalid("swatch has no ink: draw the pattern in a fill colour").in_file(path)
        })?;
        let (w, h) = (first.sdf.width(), first.sdf.height());
        if w < 8 || h < 8 {
            return Err(Error::invalid(format!(
                "swatch is {w}×{h} px; it needs at least 8×8 px (draw it larger or raise the style's resolution)"
            ))
            .in_file(path));
        }
        let units_per_px = 1.0 / first.sdf.px_per_unit();
        // Each ink layer covers its colour and those above it: a colour's
        // visible part is its layer less the next one.
        let cov: Vec<Grid<f32>> = ink
            .layers
            .iter()
            .map(|l| l.sdf.dist.map(|d| (0.5 - d).clamp(0.0, 1.0)))
            .collect();
        let colours = ink
            .layers
            .iter()
            .enumerate()
            .map(|(k, l)| {
                let own = match cov.get(k + 1) {
                    Some(above) => {
                        Grid::from_fn(w, h, |x, y| (cov[k].get(x, y) - above.get(x, y)).max(0.0))
                    }
                    None => cov[k].clone(),
                };
                (l.color, own)
            })
            .collect();
        let name = path
            .file_name()
            .map(|n| n.to_string_lossy().into_owned())
            .unwrap_or_default();
        let notes = ink
            .notes
            .iter()
            .map(|n| format!("swatch {name}: {n}"))
            .collect();
        Ok(Swatch {
            colours,
            units_per_px,
            notes,
        })
    }

    /// Width, pixels.
    pub fn width(&self) -> usize {
        self.colours.first().map_or(0, |c| c.1.width())
    }

    /// Height, pixels.
    pub fn height(&self) -> usize {
        self.colours.first().map_or(0, |c| c.1.height())
    }

    /// Coverage of all ink, per pixel.
    fn union(&self) -> Grid<f32> {
        Grid::from_fn(self.width(), self.height(), |x, y| {
            self.colours
                .iter()
                .map(|c| c.1.get(x, y))
                .sum::<f32>()
                .min(1.0)
        })
    }
}

/// An SVG swatch read at `opts.resolution` px on its longest side, on a
/// canvas of whole pixels that ends where the drawing does (each axis
/// scaled to a whole number of pixels, within half a pixel of the
/// uniform scale), so a seamless tile's last pixel row meets its first.
fn read_svg_fitted(bytes: &[u8], opts: &ImageOptions) -> Result<ink::Ink> {
    let bytes = crate::read::svg::inflate_svgz(bytes)?;
    let tree = crate::read::svg::parse_svg(&bytes)?;
    let size = tree.size();
    let (uw, uh) = (size.width() as f64, size.height() as f64);
    let s = opts.resolution as f64 / uw.max(uh);
    let (pw, ph) = ((uw * s).round().max(1.0), (uh * s).round().max(1.0));
    crate::io::check_canvas(pw as u64, ph as u64)?;
    ink::svg_ink_on(
        &tree,
        opts,
        None,
        (pw as usize, ph as usize),
        (pw / uw, ph / uh),
    )
}

/// The layers of a style: its swatches' colours merged and ordered, and
/// the ground of a style without paper.
#[derive(Clone, Debug, PartialEq)]
pub struct Palette {
    /// Every colour met, with the layer colour it is drawn in.
    pub map: Vec<(Color, Color)>,
    /// Layer colours, bottom first (without the ground).
    pub layers: Vec<Color>,
    /// The colour that fills the region, for swatches coloured edge to edge.
    pub ground: Option<Color>,
    /// How the colours were quantized, for `--verbose` (empty when they
    /// were kept as drawn).
    pub note: Option<String>,
}

fn distance(a: Color, b: Color) -> f64 {
    let d = |p: u8, q: u8| (p as f64 - q as f64).powi(2);
    (d(a.r, b.r) + d(a.g, b.g) + d(a.b, b.b)).sqrt()
}

impl Palette {
    /// The palette of `swatches`: colours in order of first appearance,
    /// the nearest two (by covered area, the smaller into the larger)
    /// merged while any two are nearer than [`MERGE_DISTANCE`] or there
    /// are more than [`MAX_LAYERS`]; when ink covers [`NO_PAPER`] of the
    /// swatches, the colour covering most is the ground. Fails when no
    /// colour is left over the ground (a swatch of one flat colour).
    pub fn of(swatches: &[Swatch]) -> std::result::Result<Palette, String> {
        // (colour, area) in order of first appearance.
        let mut seen: Vec<(Color, f64)> = Vec::new();
        let (mut inked, mut all) = (0.0f64, 0.0f64);
        for s in swatches {
            for (c, cov) in &s.colours {
                let a: f64 = cov.data().iter().map(|&v| v as f64).sum();
                match seen.iter_mut().find(|e| e.0 == *c) {
                    Some(e) => e.1 += a,
                    None => seen.push((*c, a)),
                }
            }
            inked += s.union().data().iter().map(|&v| v as f64).sum::<f64>();
            all += (s.width() * s.height()) as f64;
        }
        let drawn = seen.len();
        let mut map: Vec<(Color, Color)> = seen.iter().map(|e| (e.0, e.0)).collect();
        let mut groups = seen.clone();
        loop {
            let mut nearest: Option<(f64, usize, usize)> = None;
            for i in 0..groups.len() {
                for j in i + 1..groups.len() {
                    let d = distance(groups[i].0, groups[j].0);
                    if nearest.is_none_or(|n| d < n.0) {
                        nearest = Some((d, i, j));
                    }
                }
            }
            let Some((d, i, j)) = nearest else { break };
            if d >= MERGE_DISTANCE && groups.len() <= MAX_LAYERS {
                break;
            }
            let (keep, gone) = if groups[i].1 >= groups[j].1 {
                (i, j)
            } else {
                (j, i)
            };
            let (kc, gc) = (groups[keep].0, groups[gone].0);
            groups[keep].1 += groups[gone].1;
            for m in &mut map {
                if m.1 == gc {
                    m.1 = kc;
                }
            }
            groups.remove(gone);
        }
        let ground = (all > 0.0 && inked >= NO_PAPER * all).then(|| {
            groups
                .iter()
                .fold((Color::BLACK, -1.0), |b, g| if g.1 > b.1 { *g } else { b })
                .0
        });
        let layers: Vec<Color> = groups
            .iter()
            .map(|g| g.0)
            .filter(|&c| Some(c) != ground)
            .collect();
        if layers.is_empty() {
            return Err(match ground {
                Some(_) => {
                    "swatch is one flat colour edge to edge: there is no pattern to synthesize"
                        .into()
                }
                None => "swatch has no ink".into(),
            });
        }
        let note = (groups.len() < drawn).then(|| {
            format!(
                "{drawn} colours quantized to {} layer(s) (shades nearer than {MERGE_DISTANCE} merged, at most {MAX_LAYERS})",
                groups.len()
            )
        });
        Ok(Palette {
            map,
            layers,
            ground,
            note,
        })
    }

    /// The layer colour `c` is drawn in.
    fn layer_of(&self, c: Color) -> Color {
        self.map.iter().find(|m| m.0 == c).map_or(c, |m| m.1)
    }
}

/// Whether coverage `cov` runs on across its own seams: the mean change
/// of coverage from its last column to its first is no larger than the
/// largest mean change between two neighbouring columns inside it (plus
/// 0.03), and likewise for rows. A seam through a drawing that does not
/// repeat compares two unrelated columns, a larger change than any inside
/// it.
fn seams_continue(cov: &Grid<f32>) -> bool {
    let (w, h) = (cov.width(), cov.height());
    if w < 2 || h < 2 {
        return false;
    }
    let col_step = |a: usize, b: usize| {
        (0..h)
            .map(|y| (cov.get(a, y) - cov.get(b, y)).abs() as f64)
            .sum::<f64>()
            / h as f64
    };
    let row_step = |a: usize, b: usize| {
        (0..w)
            .map(|x| (cov.get(x, a) - cov.get(x, b)).abs() as f64)
            .sum::<f64>()
            / w as f64
    };
    let inner_x = (0..w - 1).map(|x| col_step(x, x + 1)).fold(0.0, f64::max);
    let inner_y = (0..h - 1).map(|y| row_step(y, y + 1)).fold(0.0, f64::max);
    col_step(w - 1, 0) <= inner_x + 0.03 && row_step(h - 1, 0) <= inner_y + 0.03
}

/// The share of border pixels that are more than half ink.
fn border_ink(cov: &Grid<f32>) -> f64 {
    let (w, h) = (cov.width(), cov.height());
    let mut n = 0usize;
    let mut all = 0usize;
    let mut at = |x: usize, y: usize| {
        all += 1;
        n += usize::from(cov.get(x, y) > 0.5);
    };
    for x in 0..w {
        at(x, 0);
        at(x, h - 1);
    }
    for y in 1..h.saturating_sub(1) {
        at(0, y);
        at(w - 1, y);
    }
    n as f64 / all.max(1) as f64
}

/// Share of border ink below which a swatch is a motif on paper: its
/// shape is its ink with the holes filled, not the whole swatch.
const ON_PAPER: f64 = 0.05;

/// A swatch's shape: its ink (over half covered) closed by a disc of a
/// sixteenth of its longest side (so the paper between neighbouring
/// motifs counts as pattern, not as the swatch's outside), with the holes
/// filled (paper not 4-connected to the border). Outside the swatch counts
/// as paper for the closing.
pub fn shape_of(cov: &Grid<f32>) -> Grid<bool> {
    let (w, h) = (cov.width(), cov.height());
    let r = (w.max(h) as f32 / 16.0).max(1.0);
    let pad = r.ceil() as usize + 1;
    let (pw, ph) = (w + 2 * pad, h + 2 * pad);
    let ink = Grid::from_fn(pw, ph, |x, y| {
        x >= pad && y >= pad && x < w + pad && y < h + pad && cov.get(x - pad, y - pad) > 0.5
    });
    let grown = squared_edt(&ink).map(|d| d <= r * r);
    let closed = squared_edt(&grown.map(|g| !g)).map(|d| d > r * r);
    let mut outside = Grid::new(w, h, false);
    let inside = |x: usize, y: usize| closed.get(x + pad, y + pad);
    let mut stack = Vec::new();
    for x in 0..w {
        stack.push((x, 0));
        stack.push((x, h - 1));
    }
    for y in 0..h {
        stack.push((0, y));
        stack.push((w - 1, y));
    }
    while let Some((x, y)) = stack.pop() {
        if outside.get(x, y) || inside(x, y) {
            continue;
        }
        outside.set(x, y, true);
        if x > 0 {
            stack.push((x - 1, y));
        }
        if y > 0 {
            stack.push((x, y - 1));
        }
        if x + 1 < w {
            stack.push((x + 1, y));
        }
        if y + 1 < h {
            stack.push((x, y + 1));
        }
    }
    outside.map(|o| !o)
}

impl Tile {
    /// The tile of `swatch` with the layers of `palette` (each layer
    /// covering its colour and those above it), its source direction
    /// `dir`.
    pub fn from_swatch(swatch: &Swatch, palette: &Palette, dir: SourceDirection) -> Tile {
        let (w, h) = (swatch.width(), swatch.height());
        let union = swatch.union();
        let on_paper = border_ink(&union) < ON_PAPER;
        let periodic = !on_paper
            && swatch.colours.iter().all(|c| seams_continue(&c.1))
            && seams_continue(&union);
        // Each layer's own coverage (its colours merged), then cumulative
        // from the top down.
        let n = palette.layers.len();
        let mut own: Vec<Grid<f32>> = vec![Grid::new(w, h, 0.0); n];
        for (c, cov) in &swatch.colours {
            let lc = palette.layer_of(*c);
            if let Some(k) = palette.layers.iter().position(|&l| l == lc) {
                for (a, &b) in own[k].data_mut().iter_mut().zip(cov.data()) {
                    *a += b;
                }
            }
        }
        let mut acc = Grid::new(w, h, 0.0f32);
        let mut layers: Vec<TileLayer> = Vec::with_capacity(n);
        for k in (0..n).rev() {
            for (a, &b) in acc.data_mut().iter_mut().zip(own[k].data()) {
                *a = (*a + b).min(1.0);
            }
            layers.push(TileLayer {
                color: palette.layers[k],
                sdf: if periodic {
                    periodic_sdf_of_coverage(&acc)
                } else {
                    Sdf::from_distance_ramp(&acc, Affine::IDENTITY).dist
                },
            });
        }
        layers.reverse();
        // A motif on paper: its shape. A piece cut from a larger pattern:
        // all of it.
        let shape = on_paper.then(|| shape_of(&union));
        Tile::assemble_with(
            layers,
            dir,
            swatch.units_per_px,
            periodic,
            shape,
            palette.ground.unwrap_or(PAPER),
        )
    }

    /// A seamless tile from periodic layers over white paper (composite
    /// colour and direction derived).
    #[cfg(test)]
    pub fn assemble(layers: Vec<TileLayer>, dir: SourceDirection, units_per_px: f64) -> Tile {
        Tile::assemble_with(layers, dir, units_per_px, true, None, PAPER)
    }

    /// A tile from its layers and kind (composite colour and direction
    /// derived; the edge line for a tile with a constant direction).
    pub fn assemble_with(
        layers: Vec<TileLayer>,
        dir: SourceDirection,
        units_per_px: f64,
        periodic: bool,
        shape: Option<Grid<bool>>,
        paper: Color,
    ) -> Tile {
        let (w, h) = (layers[0].sdf.width(), layers[0].sdf.height());
        let colour = composite(&layers, paper, w, h);
        let edge = match dir {
            SourceDirection::Constant(d) if periodic => EdgeLine::deepest(&layers[0].sdf, d),
            _ => None,
        };
        let direction = match dir {
            SourceDirection::Constant(d) => crate::field::diffusion::constant_field(w, h, d),
            SourceDirection::Etf if periodic => {
                // On the 3×3 repetition so the flow wraps like the tile.
                let lum = Grid::from_fn(3 * w, 3 * h, |x, y| luminance(colour.get(x % w, y % h)));
                let etf = edge_tangent_flow(&lum, &EtfOptions::default());
                Grid::from_fn(w, h, |x, y| etf.get(x + w, y + h))
            }
            SourceDirection::Etf => {
                edge_tangent_flow(&colour.map(luminance), &EtfOptions::default())
            }
        };
        Tile {
            layers,
            colour,
            direction,
            units_per_px,
            edge,
            periodic,
            shape,
            paper,
        }
    }

    /// The tile with each layer's ink grown by `by[l]` pixels (its SDF
    /// lowered by as much), the composite colour redrawn.
    pub fn grown(&self, by: &[f32]) -> Tile {
        if by.iter().all(|&g| g == 0.0) {
            return self.clone();
        }
        let layers: Vec<TileLayer> = self
            .layers
            .iter()
            .zip(by.iter().chain(std::iter::repeat(&0.0)))
            .map(|(l, &g)| TileLayer {
                color: l.color,
                sdf: l.sdf.map(|d| d - g),
            })
            .collect();
        let colour = composite(&layers, self.paper, self.width(), self.height());
        Tile {
            layers,
            colour,
            ..self.clone()
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

    /// Pixels of the pattern: the whole tile, or a swatch's shape.
    pub fn area(&self) -> usize {
        match &self.shape {
            Some(s) => s.data().iter().filter(|&&v| v).count(),
            None => self.width() * self.height(),
        }
    }

    /// Pixels of the pattern inside layer `m`.
    pub fn ink_px(&self, m: usize) -> usize {
        self.layers.get(m).map_or(0, |l| match &self.shape {
            Some(s) => l
                .sdf
                .data()
                .iter()
                .zip(s.data())
                .filter(|(&d, &i)| i && d < 0.0)
                .count(),
            None => l.sdf.data().iter().filter(|&&d| d < 0.0).count(),
        })
    }

    /// Fraction of the pattern's pixels (the tile, or a swatch's shape)
    /// inside layer `m` (the bottom layer holds all ink over the paper).
    #[cfg(test)]
    pub fn ink_fraction(&self, m: usize) -> f64 {
        self.ink_px(m) as f64 / self.area().max(1) as f64
    }

    /// A swatch's edge: the pixels of its shape's outline (4-neighbours)
    /// that are not on the swatch's border (a cut is not an edge); `None`
    /// for a tile.
    pub fn shape_edge(&self) -> Option<Grid<bool>> {
        let s = self.shape.as_ref()?;
        let (w, h) = (s.width(), s.height());
        Some(Grid::from_fn(w, h, |x, y| {
            s.get(x, y)
                && x > 0
                && y > 0
                && x + 1 < w
                && y + 1 < h
                && [(-1, 0), (1, 0), (0, -1), (0, 1)]
                    .iter()
                    .any(|&(dx, dy)| !s.get_or(x as isize + dx, y as isize + dy, false))
        }))
    }

    /// The tile at half resolution: 2×2 box means (wrapping for a tile,
    /// clamped for a swatch), distances halved to the new pixel unit and
    /// re-measured exactly from the new zero level (as the E-step's
    /// reinitialization measures the target), directions averaged and
    /// renormalized, a swatch's shape kept where 2 of 4 pixels were.
    pub fn half(&self) -> Tile {
        let (w, h) = ((self.width() / 2).max(1), (self.height() / 2).max(1));
        let (sw, sh) = (self.width(), self.height());
        let at = |x: usize, y: usize| -> (usize, usize) {
            if self.periodic {
                (x % sw, y % sh)
            } else {
                (x.min(sw - 1), y.min(sh - 1))
            }
        };
        let quad = |x: usize, y: usize| {
            [(0, 0), (1, 0), (0, 1), (1, 1)].map(|(dx, dy)| at(2 * x + dx, 2 * y + dy))
        };
        let layers = self
            .layers
            .iter()
            .map(|l| {
                let halved = Grid::from_fn(w, h, |x, y| {
                    0.5 * 0.25
                        * quad(x, y)
                            .iter()
                            .map(|&(a, b)| l.sdf.get(a, b))
                            .sum::<f32>()
                });
                TileLayer {
                    color: l.color,
                    sdf: if self.periodic {
                        periodic_sdf(&halved)
                    } else {
                        let cov = halved.map(|d| (0.5 - d).clamp(0.0, 1.0));
                        Sdf::from_distance_ramp(&cov, Affine::IDENTITY).dist
                    },
                }
            })
            .collect::<Vec<_>>();
        let colour = composite(&layers, self.paper, w, h);
        let direction = Grid::from_fn(w, h, |x, y| {
            let mut v = Vec2::ZERO;
            for (a, b) in quad(x, y) {
                let d = self.direction.get(a, b);
                v += Vec2::new(d[0] as f64, d[1] as f64);
            }
            let m = v.hypot();
            if m > 1e-9 {
                [(v.x / m) as f32, (v.y / m) as f32]
            } else {
                let (a, b) = at(2 * x, 2 * y);
                self.direction.get(a, b)
            }
        });
        let shape = self.shape.as_ref().map(|s| {
            Grid::from_fn(w, h, |x, y| {
                quad(x, y).iter().filter(|&&(a, b)| s.get(a, b)).count() >= 2
            })
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
            periodic: self.periodic,
            shape,
            paper: self.paper,
        }
    }
}

/// Luminance of a 0..1 RGB colour.
fn luminance(c: [f32; 3]) -> f32 {
    0.299 * c[0] + 0.587 * c[1] + 0.114 * c[2]
}

/// Colour over `paper`: each layer, bottom first, laid over the ones
/// below with its anti-aliased coverage `clamp(½ − φ, 0, 1)`.
pub fn composite(layers: &[TileLayer], paper: Color, w: usize, h: usize) -> Grid<[f32; 3]> {
    let base = [paper.r, paper.g, paper.b].map(|v| v as f32 / 255.0);
    Grid::from_fn(w, h, |x, y| {
        let mut c = base;
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
    periodic_sdf_of_coverage(&d.map(|v| (0.5 - v).clamp(0.0, 1.0)))
}

/// The periodic SDF of coverage `cov` (a distance ramp, see
/// [`periodic_sdf`]), measured on its 3×3 repetition.
pub fn periodic_sdf_of_coverage(cov: &Grid<f32>) -> Grid<f32> {
    let (w, h) = (cov.width(), cov.height());
    let rep = Grid::from_fn(3 * w, 3 * h, |x, y| cov.get(x % w, y % h));
    let sdf = Sdf::from_distance_ramp(&rep, Affine::IDENTITY);
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

    fn swatch(colours: Vec<(Color, Grid<f32>)>) -> Swatch {
        Swatch {
            colours,
            units_per_px: 1.0,
            notes: Vec::new(),
        }
    }

    fn disc(w: usize, cx: f32, cy: f32, r: f32) -> Grid<f32> {
        Grid::from_fn(w, w, |x, y| {
            (r + 0.5 - (x as f32 + 0.5 - cx).hypot(y as f32 + 0.5 - cy)).clamp(0.0, 1.0)
        })
    }

    #[test]
    fn seamless_tiles_wrap_and_motifs_on_paper_do_not() {
        // Stripes crossing the tile: seamless.
        let stripes = Grid::from_fn(32, 32, |x, _| if x % 8 < 4 { 1.0 } else { 0.0 });
        let red = Color::rgb(200, 0, 0);
        let s = swatch(vec![(red, stripes.clone())]);
        let p = Palette::of(std::slice::from_ref(&s)).unwrap();
        let t = Tile::from_swatch(&s, &p, SourceDirection::Constant([1.0, 0.0]));
        assert!(t.periodic && t.shape.is_none());
        // A disc cut by the right border, nothing at the left: the seam
        // jumps.
        let cut = disc(32, 32.0, 16.0, 10.0);
        let s = swatch(vec![(red, cut)]);
        let t = Tile::from_swatch(&s, &p, SourceDirection::Constant([1.0, 0.0]));
        assert!(!t.periodic);
        // A ring on paper: not periodic, its shape the filled disc, its
        // edge the disc's outline.
        let ring = Grid::from_fn(40, 40, |x, y| {
            (disc(40, 20.0, 20.0, 15.0).get(x, y) - disc(40, 20.0, 20.0, 10.0).get(x, y)).max(0.0)
        });
        let s = swatch(vec![(red, ring)]);
        let t = Tile::from_swatch(&s, &p, SourceDirection::Constant([1.0, 0.0]));
        assert!(!t.periodic);
        let shape = t.shape.as_ref().unwrap();
        assert!(shape.get(20, 20) && !shape.get(2, 2));
        let edge = t.shape_edge().unwrap();
        let n = edge.data().iter().filter(|&&e| e).count();
        assert!((70..120).contains(&n), "{n}");
        // Ink fraction over the shape: the ring's area over the disc's.
        let want = (15.0f64.powi(2) - 10.0f64.powi(2)) / 15.0f64.powi(2);
        assert!(
            (t.ink_fraction(0) - want).abs() < 0.05,
            "{}",
            t.ink_fraction(0)
        );
        let h = t.half();
        assert!(!h.periodic && h.shape.is_some());
    }

    #[test]
    fn a_swatch_without_paper_has_a_ground_and_one_colour_is_refused() {
        // Blue everywhere but a yellow square: blue is the ground.
        let (blue, yellow) = (Color::rgb(0, 0, 200), Color::rgb(240, 220, 0));
        let sq = Grid::from_fn(32, 32, |x, y| {
            if (8..16).contains(&x) && (8..16).contains(&y) {
                1.0
            } else {
                0.0
            }
        });
        let rest = sq.map(|v| 1.0 - v);
        let s = swatch(vec![(yellow, sq), (blue, rest.clone())]);
        let p = Palette::of(std::slice::from_ref(&s)).unwrap();
        assert_eq!(p.ground, Some(blue));
        assert_eq!(p.layers, vec![yellow]);
        let t = Tile::from_swatch(&s, &p, SourceDirection::Constant([1.0, 0.0]));
        assert_eq!(t.layers.len(), 1);
        assert!((t.ink_fraction(0) - 64.0 / 1024.0).abs() < 1e-3);
        assert_eq!(t.paper, blue);
        // The composite shows blue where the square is not.
        assert!(t.colour.get(0, 0)[2] > 0.7);
        // One flat colour: nothing to synthesize.
        let flat = swatch(vec![(blue, Grid::new(16, 16, 1.0))]);
        let e = Palette::of(&[flat]).unwrap_err();
        assert!(e.contains("one flat colour"), "{e}");
    }

    #[test]
    fn near_shades_merge_and_many_colours_are_capped() {
        // Twelve colours in stripes: two near-identical reds merge, and
        // the rest are merged down to MAX_LAYERS.
        let mut colours = Vec::new();
        for k in 0..12usize {
            let c = Color::rgb((k * 20) as u8, 255 - (k * 20) as u8, (k * 7) as u8);
            colours.push((
                c,
                Grid::from_fn(48, 48, |x, _| if x / 4 == k { 1.0 } else { 0.0 }),
            ));
        }
        let s = swatch(colours);
        let p = Palette::of(std::slice::from_ref(&s)).unwrap();
        assert!(p.layers.len() + usize::from(p.ground.is_some()) <= MAX_LAYERS);
        assert!(p.note.is_some());
        // Every colour maps to a layer (or the ground).
        for (c, to) in &p.map {
            assert!(
                p.layers.contains(to) || p.ground == Some(*to),
                "{c:?} → {to:?}"
            );
        }
    }
}
