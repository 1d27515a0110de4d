//! Exemplar loading: an exemplar file (SVG or raster) read as ink layers at
//! the three levels of its pyramid (DecoBrush §4.1, §4.3).
//!
//! * SVG through usvg: each distinct fill colour is a layer (stroked shapes
//!   count as fills of their outline), the SDF is the exact distance to the
//!   vector outline ([`crate::read::ink::svg_ink`]); a path with
//!   `id="spine"` is the hand-drawn main branch and is not ink.
//! * Raster files through `image`: layers by quantized colour
//!   ([`load_raster`]), resampled to each level's size
//!   by area averaging of their coverage, SDF with sub-pixel edges
//!   ([`Sdf::from_coverage`]).
//!
//! Every level is rasterized from the source itself, not downsampled from
//! the level above, so each one is as sharp as its size allows. Levels are
//! ordered coarse to fine, the order synthesis visits them; the finest has
//! `resolution` px on the exemplar's longest side, each coarser one half
//! the one above (512/256/128 for `resolution = 512`).

use crate::error::{Error, Result};
use crate::io;
use crate::raster::plain::quantize_sdf;
use crate::raster::{Coverage, Grid, Sdf};
use crate::read::ink::{self, ImageOptions};
use crate::svg_out::Color;
use kurbo::{Affine, BezPath, PathEl, Point};
use resvg::usvg;
use serde::{Deserialize, Serialize};
use std::path::Path;

/// Number of pyramid levels (DecoBrush §4.3 uses three).
pub const LEVELS: usize = 3;

/// One fill colour of an exemplar at one level.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct Layer {
    /// The layer's colour.
    pub color: Color,
    /// Signed distance to the layer's outline, in pixels of its level,
    /// negative inside, rounded to 1/128 px and clamped to ±255 px
    /// ([`crate::raster::plain::quantize_sdf`], so the cache stores it
    /// exactly in 16 bits). Layers are stacked bottom first and each one
    /// extends under the layers above it (so their fills leave no seams).
    #[serde(with = "crate::raster::plain::sdf16")]
    pub sdf: Grid<f32>,
}

/// An exemplar's ink at one pyramid level.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct InkLevel {
    /// Pixels of this level per exemplar user unit.
    pub px_per_unit: f64,
    /// The layers, bottom first.
    pub layers: Vec<Layer>,
    /// Signed distance to the outline of all ink (every layer together),
    /// in pixels of this level, negative inside. Layers stack, so this is
    /// the bottom layer's SDF; the cache does not store it twice (see
    /// [`InkLevel::restore_ink`]).
    #[serde(skip, default = "empty_grid")]
    pub ink: Grid<f32>,
}

fn empty_grid() -> Grid<f32> {
    Grid::new(0, 0, 0.0)
}

impl InkLevel {
    /// Sets `ink` from the bottom layer (after decoding from the cache);
    /// `false` when there is no layer.
    pub fn restore_ink(&mut self) -> bool {
        match self.layers.first() {
            Some(l) => {
                self.ink = l.sdf.clone();
                true
            }
            None => false,
        }
    }
}

/// An exemplar file read as ink.
#[derive(Clone, Debug)]
pub struct ExemplarInk {
    /// Width and height in the exemplar's user units (pixels for rasters).
    pub size: [f64; 2],
    /// The pyramid, coarse to fine ([`LEVELS`] levels).
    pub levels: Vec<InkLevel>,
    /// The hand-drawn main branch (`<path id="spine">`) as a polyline in
    /// user units, when the SVG has one.
    pub drawn_spine: Option<Vec<Point>>,
}

/// Pixel size of level `l` (0 = coarsest) for a finest `resolution`.
pub fn level_resolution(resolution: u32, level: usize) -> u32 {
    (resolution >> (LEVELS - 1 - level.min(LEVELS - 1))).max(1)
}

/// Reads the exemplar at `path` at the pyramid of `resolution` (finest
/// level, px on the longest side). Blank exemplars (no ink) are an error.
pub fn load(path: &Path, resolution: u32) -> Result<ExemplarInk> {
    let bytes = io::read_file(path)?;
    let ex = if ink::looks_like_svg(&bytes) {
        load_svg(path, &bytes, resolution)?
    } else {
        load_raster(path, &bytes, resolution)?
    };
    let finest = ex
        .levels
        .last()
        .ok_or_else(|| Error::invalid("no pyramid levels").in_file(path))?;
    if finest.layers.is_empty() || finest.ink.data().iter().all(|&d| d >= 0.0) {
        return Err(Error::invalid("blank exemplar: it has no ink").in_file(path));
    }
    Ok(ex)
}

fn load_svg(path: &Path, bytes: &[u8], resolution: u32) -> Result<ExemplarInk> {
    let tree = crate::read::svg::parse_svg(bytes).map_err(|e| e.in_file(path))?;
    let size = [tree.size().width() as f64, tree.size().height() as f64];
    let mut levels = Vec::with_capacity(LEVELS);
    for l in 0..LEVELS {
        let res = level_resolution(resolution, l);
        let opts = ImageOptions {
            resolution: res,
            invert: false,
            layers: true,
        };
        let mut layered =
            ink::svg_ink(&tree, &opts, Some(SPINE_ID)).map_err(|e| e.in_file(path))?;
        for l in &mut layered.layers {
            quantize_sdf(&mut l.sdf.dist);
        }
        // Layers stack: the bottom one holds every colour, i.e. all ink.
        let ink = match layered.layers.first() {
            Some(l) => l.sdf.dist.clone(),
            None => Grid::new(1, 1, 1.0),
        };
        levels.push(InkLevel {
            px_per_unit: res as f64 / size[0].max(size[1]).max(1e-9),
            layers: layered
                .layers
                .into_iter()
                .map(|l| Layer {
                    color: l.color,
                    sdf: l.sdf.dist,
                })
                .collect(),
            ink,
        });
    }
    Ok(ExemplarInk {
        size,
        levels,
        drawn_spine: find_spine(tree.root()).map(|p| polyline(&p)),
    })
}

/// The `id` of an exemplar's hand-drawn main branch.
pub const SPINE_ID: &str = "spine";

fn find_spine(group: &usvg::Group) -> Option<BezPath> {
    for node in group.children() {
        match node {
            usvg::Node::Group(g) => {
                if let Some(p) = find_spine(g) {
                    return Some(p);
                }
            }
            usvg::Node::Path(p) if p.id() == SPINE_ID => {
                return Some(crate::read::svg::to_bezpath(p.data(), p.abs_transform()));
            }
            _ => {}
        }
    }
    None
}

/// The first subpath of `path` flattened to 0.05 user units.
fn polyline(path: &BezPath) -> Vec<Point> {
    let mut pts: Vec<Point> = Vec::new();
    // Subpaths seen so far: only the first one is kept.
    let mut subpaths = 0;
    kurbo::flatten(path, 0.05, |el| match el {
        PathEl::MoveTo(p) => {
            subpaths += 1;
            if subpaths == 1 {
                pts.push(p);
            }
        }
        PathEl::LineTo(p) if subpaths == 1 && pts.last() != Some(&p) => pts.push(p),
        _ => {}
    });
    pts
}

fn load_raster(path: &Path, bytes: &[u8], resolution: u32) -> Result<ExemplarInk> {
    let native = ink::read_raster(
        bytes,
        &ImageOptions {
            resolution,
            invert: false,
            layers: true,
        },
    )
    .map_err(|e| e.in_file(path))?;
    let size = [native.width, native.height];
    let covs: Vec<(Color, Coverage)> = native
        .layers
        .iter()
        .map(|l| (l.color, l.sdf.dist.map(|d| (0.5 - d).clamp(0.0, 1.0))))
        .collect();
    let mut levels = Vec::with_capacity(LEVELS);
    for l in 0..LEVELS {
        let res = level_resolution(resolution, l) as f64;
        let scale = res / size[0].max(size[1]).max(1.0);
        let (w, h) = (
            (size[0] * scale).ceil().max(1.0) as usize,
            (size[1] * scale).ceil().max(1.0) as usize,
        );
        let to_user = Affine::scale(1.0 / scale);
        let layers = covs
            .iter()
            .map(|(color, c)| {
                let mut sdf = Sdf::from_coverage(&resample(c, w, h), to_user).dist;
                quantize_sdf(&mut sdf);
                Layer { color: *color, sdf }
            })
            .collect::<Vec<_>>();
        // Layers stack: the bottom one holds every colour, i.e. all ink.
        let ink = match layers.first() {
            Some(l) => l.sdf.clone(),
            None => Grid::new(w, h, 1.0),
        };
        levels.push(InkLevel {
            px_per_unit: scale,
            layers,
            ink,
        });
    }
    Ok(ExemplarInk {
        size,
        levels,
        drawn_spine: None,
    })
}

/// Coverage resampled to `w`×`h` by averaging `k`×`k` bilinear samples per
/// target pixel (`k` = the reduction factor, so every source pixel counts).
pub fn resample(cov: &Coverage, w: usize, h: usize) -> Coverage {
    if cov.width() == w && cov.height() == h {
        return cov.clone();
    }
    let sx = cov.width() as f64 / w.max(1) as f64;
    let sy = cov.height() as f64 / h.max(1) as f64;
    let k = sx.max(sy).ceil().clamp(1.0, 8.0) as usize;
    Grid::from_fn(w, h, |x, y| {
        let mut sum = 0.0;
        for j in 0..k {
            for i in 0..k {
                let px = (x as f64 + (i as f64 + 0.5) / k as f64) * sx;
                let py = (y as f64 + (j as f64 + 0.5) / k as f64) * sy;
                sum += cov.sample(px, py);
            }
        }
        sum / (k * k) as f32
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn write(dir: &Path, name: &str, text: &str) -> std::path::PathBuf {
        let p = dir.join(name);
        std::fs::write(&p, text).unwrap();
        p
    }

    #[test]
    fn svg_exemplar_has_a_pyramid_layers_and_a_drawn_spine() {
        let dir = tempfile::tempdir().unwrap();
        let p = write(
            dir.path(),
            "a.svg",
            r##"<svg xmlns="http://www.w3.org/2000/svg" width="200" height="100">
              <path id="spine" d="M4 50 L196 50" stroke="red" stroke-width="8" fill="none"/>
              <rect x="10" y="40" width="180" height="20" fill="#000"/>
              <circle cx="100" cy="50" r="5" fill="#0a0"/>
              <path d="M20 80 L180 80" stroke="#000" stroke-width="4"/>
            </svg>"##,
        );
        let ex = load(&p, 128).unwrap();
        assert_eq!(ex.size, [200.0, 100.0]);
        let sizes: Vec<_> = ex.levels.iter().map(|l| l.ink.width()).collect();
        assert_eq!(sizes, vec![32, 64, 128]);
        let fine = &ex.levels[2];
        assert_eq!(fine.layers.len(), 2);
        assert_eq!(fine.layers[1].color, Color::rgb(0, 0xaa, 0));
        // The red spine stroke is not ink: left of the rect (x < 10) only
        // the spine's stroke would cover (6, 50).
        let s = fine.px_per_unit;
        let cap = fine.ink.sample(6.0 * s, 50.0 * s);
        assert!(cap > 0.0, "spine stroke counted as ink: {cap}");
        // The stroked line is ink (stroke converted to a fill).
        assert!(fine.ink.sample(100.0 * s, 80.0 * s) < 0.0);
        let spine = ex.drawn_spine.unwrap();
        assert_eq!(spine.first().copied(), Some(Point::new(4.0, 50.0)));
        assert_eq!(spine.last().copied(), Some(Point::new(196.0, 50.0)));
    }

    #[test]
    fn blank_and_missing_exemplars_are_errors() {
        let dir = tempfile::tempdir().unwrap();
        let p = write(
            dir.path(),
            "blank.svg",
            r#"<svg xmlns="http://www.w3.org/2000/svg" width="100" height="100"/>"#,
        );
        let e = load(&p, 64).unwrap_err().to_string();
        assert!(e.contains("blank exemplar"), "{e}");
        let e = load(&dir.path().join("none.svg"), 64)
            .unwrap_err()
            .to_string();
        assert!(e.contains("none.svg"), "{e}");
    }

    #[test]
    fn raster_exemplar_is_resampled_per_level() {
        let dir = tempfile::tempdir().unwrap();
        let img = image::GrayImage::from_fn(100, 50, |x, y| {
            let ink = (10..90).contains(&x) && (20..30).contains(&y);
            image::Luma([if ink { 0 } else { 255 }])
        });
        let p = dir.path().join("a.png");
        img.save(&p).unwrap();
        let ex = load(&p, 64).unwrap();
        let sizes: Vec<_> = ex
            .levels
            .iter()
            .map(|l| (l.ink.width(), l.ink.height()))
            .collect();
        assert_eq!(sizes, vec![(16, 8), (32, 16), (64, 32)]);
        let fine = &ex.levels[2];
        // The band's half-height is 5 px = 3.2 level px; its centre is inside.
        let d = fine.ink.sample(32.0, 25.0 * 0.64);
        assert!((d + 3.2).abs() < 0.6, "{d}");
    }
}
