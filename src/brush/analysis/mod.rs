//! A brush style library analysed for synthesis: the one entry point is
//! [`BrushStyle::load`].
//!
//! For every exemplar (in parallel, results in `style.toml` order): the ink
//! pyramid ([`exemplar`]), the spine — hand-drawn (`id="spine"`) or
//! traced between `start` and `end` by Dijkstra over the edge tangent flow
//! and a quartic fit ([`spine`]) —, ribs, per-sample features and
//! per-pixel orientation ([`uv`]), and the oriented 5×5
//! neighbourhoods of every stroke-region pixel on every level. Then, per
//! level and over all exemplars, the neighbourhoods' PCA and search index
//! ([`crate::brush::analysis::neighbourhood`]). The result is cached
//! ([`cache`]).
//!
//! Units: ribs, spines and features are in pixels of the **finest** level
//! (`resolution` px on an exemplar's longest side); each [`ExemplarLevel`]
//! gives its `scale` relative to the finest (¼, ½, 1), and
//! [`Exemplar::ribs_at`] scales the ribs to a level. Pixel `(x, y)` of a grid
//! has its centre at `(x + 0.5, y + 0.5)`.

pub mod cache;
pub mod check;
pub mod ends;
pub mod exemplar;
pub mod facts;
pub mod init;
pub mod neighbourhood;
pub mod spine;
pub mod style;
pub mod uv;

pub use style::{region_refs, BrushStyle, Exemplar, ExemplarLevel, SpineSource};

use self::cache::CacheStatus;
use self::exemplar::LEVELS;
use self::neighbourhood::{Neighbourhood, NeighbourhoodIndex, NeighbourhoodSampler, Pca, PCA_DIMS};
use self::spine::SpineOptions;
use crate::error::{Error, Result};
use crate::raster::Grid;
use crate::read::style::{StyleKind, StyleToml, STYLE_FILE};

use kurbo::Point;
use rayon::prelude::*;
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
            .map_err(|_| Error::invalid("not UTF-8 text").in_file(&toml_path))?;
        let toml = crate::read::style::parse(&toml_path, &text)?;
        toml.expect_kind(dir, StyleKind::Brush)?;
        if toml.exemplar.is_empty() {
            return Err(Error::invalid(
                "exemplar: a brush style needs at least one [[exemplar]] table",
            )
            .in_file(&toml_path));
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
            return Err(
                Error::invalid("internal: neighbourhoods and stroke region disagree").in_file(dir),
            );
        }
        let pca = Pca::fit(&all);
        let points: Vec<[f32; PCA_DIMS]> = all.par_iter().map(|v| pca.project(v)).collect();
        indexes.push(NeighbourhoodIndex::new(pca, points, refs));
    }
    let exemplars: Vec<Exemplar> = analysed.into_iter().map(|(e, _)| e).collect();
    Ok(BrushStyle {
        name: name.to_string(),
        resolution,
        sdf,
        sampler,
        facts: facts::StyleFacts::of(&exemplars),
        exemplars,
        indexes,
    })
}

fn analyse_exemplar(
    dir: &Path,
    toml_path: &Path,
    i: usize,
    ex: &crate::read::style::ExemplarToml,
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
                return Err(Error::invalid(format!(
                    "exemplar[{i}].{key}: [{x}, {y}] lies outside {} ({uw}×{uh} user units)",
                    ex.file.display()
                ))
                .in_file(toml_path));
            }
        }
    }
    let fine = ink
        .levels
        .last()
        .ok_or_else(|| Error::invalid("no pyramid levels").in_file(&path))?;
    let fine_ppu = fine.px_per_unit;
    let to_fine = |p: Point| Point::new(p.x * fine_ppu, p.y * fine_ppu);
    // The finest level within the Dijkstra size limit.
    let dl = (0..ink.levels.len())
        .rev()
        .find(|&l| {
            let g = &ink.levels[l].ink;
            g.width().max(g.height()) <= DIJKSTRA_MAX_SIDE
        })
        .unwrap_or(0);
    let dlv = &ink.levels[dl];
    let dppu = dlv.px_per_unit;
    // Traces the spine between two points of the Dijkstra level (px).
    let traced = |s: Point, e: Point| -> Result<(Vec<Point>, Vec<Point>)> {
        let (raw, fit) = spine::trace_spine(&dlv.ink, s, e, &opts.spine)
            .map_err(|e| Error::invalid(format!("spine: {e}")).in_file(&path))?;
        let k = fine_ppu / dppu;
        let up = |p: Point| Point::new(p.x * k, p.y * k);
        Ok((
            fit.polyline(400).into_iter().map(up).collect(),
            raw.into_iter().map(up).collect(),
        ))
    };
    let user = |p: Point, ppu: f64| [p.x / ppu, p.y / ppu];
    let (spine_source, spine, path_px, ends) = match (&ink.drawn_spine, ex.start, ex.end) {
        (Some(drawn), s, e) if drawn.len() >= 2 => {
            let mut pts: Vec<Point> = drawn.iter().map(|&p| to_fine(p)).collect();
            if let (Some([sx, sy]), Some(_)) = (s, e) {
                let s = to_fine(Point::new(sx, sy));
                let (a, b) = (pts[0], pts[pts.len() - 1]);
                if s.distance(b) < s.distance(a) {
                    pts.reverse();
                }
            }
            let ends = [user(pts[0], fine_ppu), user(pts[pts.len() - 1], fine_ppu)];
            (SpineSource::Drawn, pts, Vec::new(), ends)
        }
        (_, Some([sx, sy]), Some([ex_, ey])) => {
            let s = Point::new(sx * dppu, sy * dppu);
            let e = Point::new(ex_ * dppu, ey * dppu);
            let (spine, raw) = traced(s, e)?;
            (SpineSource::Traced, spine, raw, [[sx, sy], [ex_, ey]])
        }
        (_, None, None) => {
            let found = ends::find_ends(&dlv.ink, &opts.spine)
                .ok_or_else(|| Error::invalid("blank exemplar: it has no ink").in_file(&path))?;
            let source = match found.found {
                ends::Found::Branch => SpineSource::Found,
                ends::Found::Fallback => SpineSource::Fallback,
            };
            let (spine, raw) = traced(found.start, found.end)?;
            (
                source,
                spine,
                raw,
                [user(found.start, dppu), user(found.end, dppu)],
            )
        }
        _ => {
            return Err(Error::invalid(format!(
                "exemplar[{i}]: {} gives only one of start and end; give both, or neither to have them found",
                ex.file.display()
            ))
            .in_file(toml_path))
        }
    };
    let length: f64 = spine.windows(2).map(|w| w[0].distance(w[1])).sum();
    if length <= 0.0 {
        return Err(Error::invalid("the spine has no length").in_file(&path));
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
        let mut level = ExemplarLevel {
            scale,
            ink: lv,
            orientation: field,
            top: Grid::new(0, 0, 0),
        };
        level.index_layers();
        levels.push(level);
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
            ends,
            ribs,
            features,
            levels,
        },
        hoods,
    ))
}

#[cfg(test)]
mod tests;
