//! A brush style library analysed for synthesis: the one entry point is
//! [`BrushStyle::load`].
//!
//! For every exemplar (in parallel, results in `style.toml` order): the ink
//! pyramid ([`super::exemplar`]), the spine — hand-drawn (`id="spine"`) or
//! traced between `start` and `end` by Dijkstra over the edge tangent flow
//! and a quartic fit ([`super::spine`]) —, ribs, per-sample features and
//! per-pixel orientation ([`super::uv`]), and the oriented 5×5
//! neighbourhoods of every stroke-region pixel on every level. Then, per
//! level and over all exemplars, the neighbourhoods' PCA and search index
//! ([`crate::synth::neighbourhood`]). The result is cached
//! ([`super::cache`]).
//!
//! Units: ribs, spines and features are in pixels of the **finest** level
//! (`resolution` px on an exemplar's longest side); each [`ExemplarLevel`]
//! gives its `scale` relative to the finest (¼, ½, 1), and
//! [`Exemplar::ribs_at`] scales the ribs to a level. Pixel `(x, y)` of a grid
//! has its centre at `(x + 0.5, y + 0.5)`.

use super::cache::{self, CacheStatus};
use super::exemplar::{self, InkLevel, LEVELS};
use super::spine::{self, SpineOptions};
use super::uv::{self, OrientationField, Ribs, SampleFeatures};
use super::{StyleKind, StyleToml, STYLE_FILE};
use crate::error::{Error, Result};
use crate::synth::neighbourhood::{
    Neighbourhood, NeighbourhoodIndex, NeighbourhoodRef, NeighbourhoodSampler, Pca, PCA_DIMS, SIZE,
};
use kurbo::Point;
use rayon::prelude::*;
use serde::{Deserialize, Serialize};
use std::path::{Path, PathBuf};

/// How a brush style is analysed and cached.
#[derive(Clone, Debug)]
pub struct AnalysisOptions {
    /// Cache folder (`--cache DIR`); `None`: `$FLOURISH_CACHE_DIR`, else the
    /// platform cache folder.
    pub cache_dir: Option<PathBuf>,
    /// Read and write the cache (default true).
    pub use_cache: bool,
    /// Spine path weights (DecoBrush §4.2 defaults).
    pub spine: SpineOptions,
}

impl Default for AnalysisOptions {
    fn default() -> Self {
        AnalysisOptions {
            cache_dir: None,
            use_cache: true,
            spine: SpineOptions::default(),
        }
    }
}

/// Largest grid side on which the spine's Dijkstra search runs; finer
/// levels are searched on the largest level within it (the quartic fit is
/// then scaled to the finest level).
pub const DIJKSTRA_MAX_SIDE: usize = 256;

/// Margin by which the stroke region extends beyond the rib outline, in
/// pixels of each level.
pub const REGION_MARGIN: f64 = 2.0;

/// Default finest resolution of a brush style, px.
pub const DEFAULT_RESOLUTION: u32 = 256;

/// Where an exemplar's spine came from.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub enum SpineSource {
    /// A path with `id="spine"` in the exemplar.
    Drawn,
    /// Traced between `start` and `end` (Dijkstra + quartic).
    Traced,
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
}

impl ExemplarLevel {
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
    /// end ornaments ([`uv::extend_to_ink`]), by `extension` px.
    pub spine: Vec<[f64; 2]>,
    /// How far the ribs extend the spine beyond its start and its end,
    /// finest px.
    pub extension: [f64; 2],
    /// The raw Dijkstra path (finest px) when the spine was traced.
    pub path: Vec<[f64; 2]>,
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
    /// Per level (coarse to fine), the neighbourhoods of all exemplars'
    /// stroke regions, searchable.
    pub indexes: Vec<NeighbourhoodIndex>,
}

impl BrushStyle {
    /// Loads the brush style in folder `dir`: from the cache when it holds
    /// this content, else analysed (and cached).
    pub fn load(dir: &Path, opts: &AnalysisOptions) -> Result<BrushStyle> {
        Ok(Self::load_with_status(dir, opts)?.0)
    }

    /// [`BrushStyle::load`], also telling what the cache did.
    pub fn load_with_status(
        dir: &Path,
        opts: &AnalysisOptions,
    ) -> Result<(BrushStyle, CacheStatus)> {
        let toml_path = dir.join(STYLE_FILE);
        let toml_bytes = crate::io::read_file(&toml_path)?;
        let text = String::from_utf8(toml_bytes.clone())
            .map_err(|_| Error::invalid(&toml_path, "not UTF-8 text"))?;
        let toml = super::parse(&toml_path, &text)?;
        toml.expect_kind(dir, StyleKind::Brush)?;
        if toml.exemplar.is_empty() {
            return Err(Error::invalid(
                &toml_path,
                "exemplar: a brush style needs at least one [[exemplar]] table",
            ));
        }
        let files: Vec<PathBuf> = toml.exemplar.iter().map(|e| dir.join(&e.file)).collect();
        let key = cache::style_key(&toml_bytes, &files)?;
        let name = style_name(dir);
        let file = cache::cache_dir(opts.cache_dir.as_deref())
            .filter(|_| opts.use_cache)
            .map(|d| cache::cache_file(&d, &name, &key));
        let mut status = CacheStatus::Disabled;
        if let Some(f) = &file {
            match cache::read(f, &key) {
                cache::Read::Found(style) => return Ok((*style, CacheStatus::Hit)),
                cache::Read::Missing => status = CacheStatus::Miss,
                cache::Read::Unusable => status = CacheStatus::Rebuilt,
            }
        }
        let style = analyse(dir, &name, &toml, opts)?;
        if let Some(f) = &file {
            // A cache that cannot be written only costs time next run.
            let _ = cache::write(f, &key, &style);
        }
        Ok((style, status))
    }

    /// After decoding from the cache: the all-ink grids and the index
    /// references, which are not stored twice; `false` when the decoded
    /// data cannot provide them.
    pub fn restore(&mut self) -> bool {
        let inks = self
            .exemplars
            .iter_mut()
            .flat_map(|e| e.levels.iter_mut())
            .all(|l| l.ink.restore_ink());
        let exemplars: Vec<&Exemplar> = self.exemplars.iter().collect();
        let refs: Vec<Vec<NeighbourhoodRef>> = (0..self.indexes.len())
            .map(|l| region_refs(&exemplars, l))
            .collect();
        for (idx, r) in self.indexes.iter_mut().zip(refs) {
            idx.refs = r;
        }
        inks
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

fn style_name(dir: &Path) -> String {
    std::fs::canonicalize(dir)
        .ok()
        .and_then(|p| p.file_name().map(|n| n.to_string_lossy().into_owned()))
        .or_else(|| dir.file_name().map(|n| n.to_string_lossy().into_owned()))
        .unwrap_or_else(|| "style".into())
}

/// Analyses every exemplar of `toml` (from folder `dir`) and indexes them.
pub fn analyse(
    dir: &Path,
    name: &str,
    toml: &StyleToml,
    opts: &AnalysisOptions,
) -> Result<BrushStyle> {
    let resolution = toml.resolution.unwrap_or(DEFAULT_RESOLUTION);
    let sdf = toml.sdf.unwrap_or(true);
    let sampler = NeighbourhoodSampler {
        sdf,
        ..NeighbourhoodSampler::default()
    };
    let toml_path = dir.join(STYLE_FILE);
    let analysed: Vec<(Exemplar, Vec<Vec<Neighbourhood>>)> = toml
        .exemplar
        .par_iter()
        .enumerate()
        .map(|(i, ex)| analyse_exemplar(dir, &toml_path, i, ex, resolution, &sampler, opts))
        .collect::<Result<Vec<_>>>()?;
    let exemplars: Vec<&Exemplar> = analysed.iter().map(|(e, _)| e).collect();
    let mut indexes = Vec::with_capacity(LEVELS);
    for l in 0..LEVELS {
        // Neighbourhoods in the order of `region_refs`: exemplar by
        // exemplar, masked pixels row-major.
        let all: Vec<Neighbourhood> = analysed
            .iter()
            .flat_map(|(_, hoods)| hoods.get(l).into_iter().flatten().copied())
            .collect();
        let refs = region_refs(&exemplars, l);
        if refs.len() != all.len() {
            return Err(Error::invalid(
                dir,
                "internal: neighbourhoods and stroke region disagree",
            ));
        }
        let pca = Pca::fit(&all);
        let points: Vec<[f32; PCA_DIMS]> = all.par_iter().map(|v| pca.project(v)).collect();
        indexes.push(NeighbourhoodIndex::new(pca, points, refs));
    }
    Ok(BrushStyle {
        name: name.to_string(),
        resolution,
        sdf,
        sampler,
        exemplars: analysed.into_iter().map(|(e, _)| e).collect(),
        indexes,
    })
}

fn analyse_exemplar(
    dir: &Path,
    toml_path: &Path,
    i: usize,
    ex: &super::ExemplarToml,
    resolution: u32,
    sampler: &NeighbourhoodSampler,
    opts: &AnalysisOptions,
) -> Result<(Exemplar, Vec<Vec<Neighbourhood>>)> {
    let path = dir.join(&ex.file);
    let ink = exemplar::load(&path, resolution)?;
    let [uw, uh] = ink.size;
    for (key, p) in [("start", ex.start), ("end", ex.end)] {
        if let Some([x, y]) = p {
            if !(0.0..=uw).contains(&x) || !(0.0..=uh).contains(&y) {
                return Err(Error::invalid(
                    toml_path,
                    format!(
                        "exemplar[{i}].{key}: [{x}, {y}] lies outside {} ({uw}×{uh} user units)",
                        ex.file.display()
                    ),
                ));
            }
        }
    }
    let fine = ink
        .levels
        .last()
        .ok_or_else(|| Error::invalid(&path, "no pyramid levels"))?;
    let fine_ppu = fine.px_per_unit;
    let to_fine = |p: Point| Point::new(p.x * fine_ppu, p.y * fine_ppu);
    let (spine_source, spine, path_px) = match (&ink.drawn_spine, ex.start, ex.end) {
        (Some(drawn), s, e) if drawn.len() >= 2 => {
            let mut pts: Vec<Point> = drawn.iter().map(|&p| to_fine(p)).collect();
            if let (Some([sx, sy]), Some(_)) = (s, e) {
                let s = to_fine(Point::new(sx, sy));
                let (a, b) = (pts[0], pts[pts.len() - 1]);
                if s.distance(b) < s.distance(a) {
                    pts.reverse();
                }
            }
            (SpineSource::Drawn, pts, Vec::new())
        }
        (_, Some([sx, sy]), Some([ex_, ey])) => {
            // The finest level within the Dijkstra size limit.
            let l = (0..ink.levels.len())
                .rev()
                .find(|&l| {
                    let g = &ink.levels[l].ink;
                    g.width().max(g.height()) <= DIJKSTRA_MAX_SIDE
                })
                .unwrap_or(0);
            let lv = &ink.levels[l];
            let s = Point::new(sx * lv.px_per_unit, sy * lv.px_per_unit);
            let e = Point::new(ex_ * lv.px_per_unit, ey * lv.px_per_unit);
            let (raw, fit) = spine::trace_spine(&lv.ink, s, e, &opts.spine)
                .map_err(|e| Error::invalid(&path, format!("spine: {e}")))?;
            let k = fine_ppu / lv.px_per_unit;
            let up = |p: Point| Point::new(p.x * k, p.y * k);
            (
                SpineSource::Traced,
                fit.polyline(400).into_iter().map(up).collect(),
                raw.into_iter().map(up).collect(),
            )
        }
        _ => {
            return Err(Error::invalid(
                toml_path,
                format!(
                    "exemplar[{i}]: {} has no path id=\"spine\"; give start and end",
                    ex.file.display()
                ),
            ))
        }
    };
    let length: f64 = spine.windows(2).map(|w| w[0].distance(w[1])).sum();
    if length <= 0.0 {
        return Err(Error::invalid(&path, "the spine has no length"));
    }
    let coarse = ink.levels[0].px_per_unit / fine_ppu;
    let reach = 0.5 * fine.ink.width().max(fine.ink.height()) as f64;
    let (extended, extension) = uv::extend_to_ink(&spine, &fine.ink, reach);
    let n = uv::sample_count(length + extension[0] + extension[1], coarse);
    let ribs = uv::build_ribs(&extended, n, &fine.ink, 1.0 / coarse, reach);
    let layer_grids: Vec<&crate::raster::Grid<f32>> = fine.layers.iter().map(|l| &l.sdf).collect();
    let features = uv::features(&ribs, &fine.ink, &layer_grids);
    let mut levels = Vec::with_capacity(LEVELS);
    let mut hoods = Vec::with_capacity(LEVELS);
    for lv in ink.levels {
        let scale = lv.px_per_unit / fine_ppu;
        let field = uv::orientation_field(
            &ribs.scaled(scale),
            lv.ink.width(),
            lv.ink.height(),
            REGION_MARGIN,
        );
        let mut v = Vec::new();
        for y in 0..field.mask.height() {
            for x in 0..field.mask.width() {
                if field.mask.get(x, y) {
                    v.push(sampler.sample(
                        &lv.ink,
                        [x as f64 + 0.5, y as f64 + 0.5],
                        field.dir.get(x, y),
                    ));
                }
            }
        }
        hoods.push(v);
        levels.push(ExemplarLevel {
            scale,
            ink: lv,
            orientation: field,
        });
    }
    let arr = |p: &Point| [p.x, p.y];
    Ok((
        Exemplar {
            file: ex.file.clone(),
            size: ink.size,
            spine_source,
            spine: spine.iter().map(arr).collect(),
            extension,
            path: path_px.iter().map(arr).collect(),
            ribs,
            features,
            levels,
        },
        hoods,
    ))
}
