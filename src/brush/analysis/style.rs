//! An analysed brush style: its exemplars at every pyramid level (ink,
//! spine, ribs, orientation) and the neighbourhood index of each level.
//! What [`super::cache`] stores and [`super::BrushStyle::load`] returns.

use super::exemplar::{InkLevel, Layer, LEVELS};
use super::facts::StyleFacts;
#[cfg(test)]
use super::neighbourhood::Neighbourhood;
use super::neighbourhood::{
    NeighbourhoodIndex, NeighbourhoodRef, NeighbourhoodSampler, PCA_DIMS, SIZE,
};
use super::uv::{OrientationField, Ribs, SampleFeatures};
use crate::raster::Grid;
use rayon::prelude::*;
use serde::{Deserialize, Serialize};
use std::path::PathBuf;

/// Where an exemplar's spine came from.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub enum SpineSource {
    /// A path with `id="spine"` in the exemplar.
    Drawn,
    /// Traced between `start` and `end` (Dijkstra + quartic).
    Traced,
    /// Traced between ends found at the two ends of the main branch
    /// ([`super::ends`]), `style.toml` giving none.
    Found,
    /// Traced across the exemplar's longer side: `style.toml` gives no
    /// ends and the drawing has no clear main branch (a dot, a ring).
    Fallback,
}

impl SpineSource {
    /// One word for reports.
    pub fn word(self) -> &'static str {
        match self {
            SpineSource::Drawn => "drawn",
            SpineSource::Traced => "traced",
            SpineSource::Found => "found",
            SpineSource::Fallback => "fallback",
        }
    }
}

/// One exemplar at one pyramid level.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct ExemplarLevel {
    /// This level's pixels per finest-level pixel (¼, ½ or 1).
    pub scale: f64,
    /// Ink: the layers with their colours and the all-ink SDF (px of this
    /// level, negative inside).
    pub ink: InkLevel,
    /// Per-pixel stroking orientation and the stroke-region mask.
    pub orientation: OrientationField,
    /// Per pixel, the index of the top layer with ink there (in
    /// `ink.layers`), [`PAPER_LAYER`] on paper: one read instead of a
    /// search through the layers ([`ExemplarLevel::index_layers`]; derived,
    /// not cached).
    #[serde(skip, default = "no_layers")]
    pub top: Grid<u8>,
}

/// The [`ExemplarLevel::top`] index of paper.
pub const PAPER_LAYER: u8 = u8::MAX;

fn no_layers() -> Grid<u8> {
    Grid::new(0, 0, PAPER_LAYER)
}

/// Per pixel of a `w`×`h` level, the index of the topmost of `layers`
/// (bottom first) with ink there (negative distance), [`PAPER_LAYER`]
/// where none has; layers beyond the 255th count as the 255th, and a
/// layer grid smaller than the level is paper beyond its edge.
fn top_layers(layers: &[Layer], w: usize, h: usize) -> Grid<u8> {
    let mut top = vec![PAPER_LAYER; w * h];
    // Each layer written over the ones below leaves the topmost.
    for (i, l) in layers.iter().enumerate().filter(|_| w > 0) {
        let index = i.min(PAPER_LAYER as usize - 1) as u8;
        let cols = w.min(l.sdf.width());
        if cols == 0 {
            continue;
        }
        let rows = l.sdf.data().chunks_exact(l.sdf.width());
        for (row, dist) in top.chunks_exact_mut(w).zip(rows) {
            for (t, &d) in row[..cols].iter_mut().zip(&dist[..cols]) {
                if d < 0.0 {
                    *t = index;
                }
            }
        }
    }
    Grid::from_vec(w, h, top).unwrap_or_else(no_layers)
}

impl ExemplarLevel {
    /// Sets [`ExemplarLevel::top`] from the layers (layers beyond the
    /// 255th count as the 255th).
    pub fn index_layers(&mut self) {
        let (w, h) = (self.ink.ink.width(), self.ink.ink.height());
        self.top = top_layers(&self.ink.layers, w, h);
    }

    /// Width in pixels.
    pub fn width(&self) -> usize {
        self.ink.ink.width()
    }

    /// Height in pixels.
    pub fn height(&self) -> usize {
        self.ink.ink.height()
    }
}

/// One analysed exemplar.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct Exemplar {
    /// The exemplar file, relative to the style folder.
    pub file: PathBuf,
    /// Width and height in the exemplar's user units.
    pub size: [f64; 2],
    /// How the spine was found.
    pub spine_source: SpineSource,
    /// The smooth spine as a dense polyline from start to end, finest px.
    /// The ribs run along it extended straight beyond both ends over the
    /// end ornaments ([`super::uv::extend_to_ink`]), by `extension` px.
    pub spine: Vec<[f64; 2]>,
    /// How far the ribs extend the spine beyond its start and its end,
    /// finest px.
    pub extension: [f64; 2],
    /// The raw Dijkstra path (finest px) when the spine was traced.
    pub path: Vec<[f64; 2]>,
    /// The spine's start and end in the exemplar's user units: as given,
    /// drawn, or found ([`SpineSource`]).
    pub ends: [[f64; 2]; 2],
    /// Rib samples (30–100), finest px.
    pub ribs: Ribs,
    /// Per-sample features, parallel to the ribs.
    pub features: Vec<SampleFeatures>,
    /// The pyramid, coarse to fine.
    pub levels: Vec<ExemplarLevel>,
}

impl Exemplar {
    /// The finest level.
    pub fn finest(&self) -> Option<&ExemplarLevel> {
        self.levels.last()
    }

    /// The ribs in pixels of level `l` (0 = coarsest).
    pub fn ribs_at(&self, l: usize) -> Ribs {
        let s = self.levels.get(l).map(|lv| lv.scale).unwrap_or(1.0);
        self.ribs.scaled(s)
    }

    /// Spine length along the rib samples, finest px.
    pub fn spine_length(&self) -> f64 {
        self.features.last().map(|f| f.from_start).unwrap_or(0.0)
    }
}

/// An analysed brush style.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct BrushStyle {
    /// The style's name (its folder's name).
    pub name: String,
    /// Finest resolution, px on an exemplar's longest side.
    pub resolution: u32,
    /// Synthesize signed distances (`true`) or coverage.
    pub sdf: bool,
    /// How neighbourhoods are read (use the same for query neighbourhoods).
    pub sampler: NeighbourhoodSampler,
    /// The exemplars in `style.toml` order.
    pub exemplars: Vec<Exemplar>,
    /// The style's figures as a whole (exemplar width, smallest element,
    /// thinnest line, palette).
    pub facts: StyleFacts,
    /// Per level (coarse to fine), the neighbourhoods of all exemplars'
    /// stroke regions, searchable.
    pub indexes: Vec<NeighbourhoodIndex>,
}

impl BrushStyle {
    /// After decoding from the cache: the all-ink grids and the index
    /// references, which are not stored twice; `false` when the decoded
    /// data cannot provide them.
    pub fn restore(&mut self) -> bool {
        let inks = self
            .exemplars
            .iter_mut()
            .flat_map(|e| e.levels.iter_mut())
            .all(|l| l.ink.restore_ink());
        self.index_layers();
        let exemplars: Vec<&Exemplar> = self.exemplars.iter().collect();
        let refs: Vec<Vec<NeighbourhoodRef>> = (0..self.indexes.len())
            .map(|l| region_refs(&exemplars, l))
            .collect();
        for (idx, r) in self.indexes.iter_mut().zip(refs) {
            idx.refs = r;
        }
        inks
    }

    /// Sets every level's top-layer index ([`ExemplarLevel::index_layers`]).
    pub fn index_layers(&mut self) {
        self.exemplars
            .par_iter_mut()
            .flat_map(|e| e.levels.par_iter_mut())
            .for_each(ExemplarLevel::index_layers);
    }

    /// Structural consistency (sizes agree everywhere, references in
    /// range): what a cache file must pass before it is trusted.
    pub fn validate(&self) -> bool {
        let ok_ex = self.exemplars.iter().all(|e| {
            let n = e.ribs.len();
            e.levels.len() == LEVELS
                && e.ribs.left.len() == n
                && e.ribs.right.len() == n
                && e.features.len() == n
                && e.levels.iter().all(|l| {
                    let (w, h) = (l.width(), l.height());
                    let same = |g_w: usize, g_h: usize| g_w == w && g_h == h;
                    l.scale.is_finite()
                        && l.ink
                            .layers
                            .iter()
                            .all(|ly| same(ly.sdf.width(), ly.sdf.height()))
                        && same(l.orientation.dir.width(), l.orientation.dir.height())
                        && same(l.orientation.mask.width(), l.orientation.mask.height())
                })
        });
        let ok_idx = self.indexes.len() == LEVELS
            && self.indexes.iter().enumerate().all(|(l, idx)| {
                idx.points.len() == idx.refs.len()
                    && idx.pca.mean.len() == SIZE
                    && idx.pca.axes.len() == PCA_DIMS
                    && idx.refs.iter().all(|r| {
                        self.exemplars
                            .get(r.exemplar as usize)
                            .and_then(|e| e.levels.get(l))
                            .is_some_and(|lv| {
                                (r.x as usize) < lv.width() && (r.y as usize) < lv.height()
                            })
                    })
            });
        ok_ex && ok_idx && !self.exemplars.is_empty()
    }

    /// The neighbourhood of exemplar `r.exemplar` at pixel `(r.x, r.y)` of
    /// level `level`, oriented along its per-pixel orientation.
    #[cfg(test)]
    pub fn neighbourhood(&self, level: usize, r: NeighbourhoodRef) -> Option<Neighbourhood> {
        let lv = self.exemplars.get(r.exemplar as usize)?.levels.get(level)?;
        let (x, y) = (r.x as usize, r.y as usize);
        if x >= lv.width() || y >= lv.height() {
            return None;
        }
        let up = lv.orientation.dir.get(x, y);
        Some(
            self.sampler
                .sample(&lv.ink.ink, [x as f64 + 0.5, y as f64 + 0.5], up),
        )
    }
}

/// The pixels of every exemplar's stroke region at level `l`, exemplar by
/// exemplar, row-major: the order of a level's [`NeighbourhoodIndex`].
pub fn region_refs(exemplars: &[&Exemplar], l: usize) -> Vec<NeighbourhoodRef> {
    let mut refs = Vec::new();
    for (i, ex) in exemplars.iter().enumerate() {
        let Some(lv) = ex.levels.get(l) else { continue };
        let mask = &lv.orientation.mask;
        for y in 0..mask.height() {
            for x in 0..mask.width() {
                if mask.get(x, y) {
                    refs.push(NeighbourhoodRef {
                        exemplar: i as u32,
                        x: x as u32,
                        y: y as u32,
                    });
                }
            }
        }
    }
    refs
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::svg_out::Color;

    /// The per-pixel definition: the last layer with ink at the pixel.
    fn top_by_search(layers: &[Layer], w: usize, h: usize) -> Grid<u8> {
        Grid::from_fn(w, h, |x, y| {
            layers
                .iter()
                .rposition(|l| l.sdf.get_or(x as isize, y as isize, 1.0) < 0.0)
                .map_or(PAPER_LAYER, |i| i.min(PAPER_LAYER as usize - 1) as u8)
        })
    }

    #[test]
    fn top_layers_match_a_search_through_the_layers() {
        let layer = |lw: usize, lh: usize, seed: usize| Layer {
            color: Color { r: 0, g: 0, b: 0 },
            sdf: Grid::from_fn(lw, lh, |x, y| {
                ((x * 7 + y * 13 + seed * 5) % 11) as f32 - 5.0
            }),
        };
        // Layers of the level's size, smaller and larger than it.
        let layers = vec![
            layer(9, 6, 0),
            layer(5, 4, 1),
            layer(12, 8, 2),
            layer(9, 6, 3),
        ];
        for (w, h) in [(9, 6), (1, 1), (0, 0), (11, 3)] {
            let fast = top_layers(&layers, w, h);
            let slow = top_by_search(&layers, w, h);
            assert_eq!((fast.width(), fast.height()), (w, h));
            assert_eq!(fast.data(), slow.data(), "{w}×{h}");
        }
        assert!(top_layers(&[], 3, 2)
            .data()
            .iter()
            .all(|&t| t == PAPER_LAYER));
    }
}
