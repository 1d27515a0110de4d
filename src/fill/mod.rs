//! `flourish fill`: art patterns inside closed shapes, synthesized from a
//! seamless tile and traced to vector.
//!
//! Method: Wu, Wang & Yu, *Example-Based Art Pattern Synthesis Using Level
//! Sets* (`shared/papers/art-pattern-level-sets.txt`, §2–3, Alg. 1) — one
//! signed distance channel per colour layer, PatchMatch M-steps, level-set
//! E-steps — with the direction awareness of Brushables (Lukáč et al. 2015,
//! §3.1–3.3: rotated patches, combing strokes, coherence-weighted voting)
//! and the jump-flooding PatchMatch of CaTS (§4.1).
//!
//! Stages, one module each:
//! - [`region`]: the sketch's filled shape on the synthesis grid, its exact
//!   boundary distance and the target direction field;
//! - [`tile`]: the exemplar's periodic SDF layers, colour and direction;
//! - [`quilt`]: image-quilting initialization;
//! - [`patchmatch`]: rotated-patch nearest neighbours;
//! - [`shape`]: the Shape Hint descriptors of the tile's edge and the
//!   region's outline;
//! - [`levelset`]: narrow-band evolution of the SDF channels;
//! - [`em`]: the multiresolution loop and voting;
//! - `continuity` (built for tests): band ends, forks and gap regularity
//!   of a result (the measure of the tears patch synthesis makes).
//!
//! Each layer's synthesized SDF is clipped to the region (`max(Φ, Φ_region)`,
//! exact since both are distances), kept under the layers above it, traced
//! with [`crate::trace::trace_sdf`] and written as one `<g>` per region.
//!
//! Near the region's outline the M-step adds the Shape Hint of Brushables
//! (Eq. 6, [`shape`]): the tile's edge is the line along its source
//! direction through the middle of the ink, so a band lands on the outline
//! and frames the region.
//!
//! Not done: the colour warp by the level-set deformation field (§2, last
//! paragraph), replaced by voting.

#[cfg(test)]
pub mod continuity;
pub mod em;
pub mod levelset;
pub mod patchmatch;
pub mod quilt;
pub mod region;
pub mod shape;
pub mod tile;

use crate::error::{Error, Result};
use crate::field::diffusion::constant_field;
use crate::raster::{Grid, Sdf};
use crate::read::sketch::{Query, QueryKind, Sketch};
use crate::read::style::{self, DirectionToml, StyleKind};
use crate::svg_out::{decimals_for, Document, FillRule, Group, Shape};
use crate::trace::{trace_sdf, TraceOptions};
use em::EmParams;
use kurbo::{BezPath, PathEl, Point, Shape as _};
use region::Region;
use std::path::Path;
use tile::{SourceDirection, Tile};

/// Options of [`crate::fill()`].
#[derive(Clone, Debug)]
pub struct FillOptions {
    /// Seeds every random choice (default 0).
    pub seed: u64,
    /// A sketch whose open stroked paths comb the direction of every
    /// region, as the paths inside a region comb its own (Brushables §3.2;
    /// default `None`).
    pub direction: Option<Sketch>,
    /// Largest distance of the traced curves from the synthesized outline,
    /// in synthesis pixels (0.01..=100; default 0.25).
    pub tolerance: f64,
    /// Multiplies the style's `scale`: the pattern drawn this many times
    /// larger in the sketch (0.01..=100; default 1).
    pub scale: f64,
}

impl Default for FillOptions {
    fn default() -> Self {
        FillOptions {
            seed: 0,
            direction: None,
            tolerance: 0.25,
            scale: 1.0,
        }
    }
}

impl FillOptions {
    /// Checks every value's range, and that a direction sketch combs.
    pub fn validate(&self) -> Result<()> {
        if !(self.scale.is_finite() && (0.01..=100.0).contains(&self.scale)) {
            return Err(Error::Option {
                name: "scale",
                reason: format!("{} is not in 0.01..=100", self.scale),
            });
        }
        if !(self.tolerance.is_finite() && (0.01..=100.0).contains(&self.tolerance)) {
            return Err(Error::Option {
                name: "tolerance",
                reason: format!("{} px is not in 0.01..=100", self.tolerance),
            });
        }
        if self
            .direction
            .as_ref()
            .is_some_and(|d| combing_strokes(d).is_empty())
        {
            return Err(Error::Option {
                name: "direction",
                reason: "no open stroked path to comb with".into(),
            });
        }
        Ok(())
    }
}

/// A loaded fill style.
#[derive(Clone, Debug)]
pub struct FillStyle {
    /// The tile at synthesis resolution.
    pub tile: Tile,
    /// Synthesis parameters (seed set per region).
    pub params: EmParams,
    /// Sketch units per tile user unit.
    pub scale: f64,
    /// What the tile's direction follows where no stroke combs the shape.
    pub flow: Flow,
}

/// A fill style's uncombed target field (the style's `flow` key).
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Flow {
    /// The outline's flow diffused inwards (Brushables §3.1).
    Outline,
    /// One direction everywhere, `[x, y]` in the sketch's axes (y down).
    Fixed([f64; 2]),
}

impl FillStyle {
    /// Loads the style in `dir` (`kind = "fill"`), its tile rasterized at
    /// `resolution` px when given, else the style's (default 96).
    pub fn load(dir: &Path, resolution: Option<u32>) -> Result<FillStyle> {
        let toml = style::load(dir)?;
        toml.expect_kind(dir, StyleKind::Fill)?;
        let ex = toml.exemplar.first().ok_or_else(|| {
            Error::invalid("exemplar: missing").in_file(dir.join(style::STYLE_FILE))
        })?;
        let source = match &toml.direction {
            Some(DirectionToml::Vector(v)) => SourceDirection::Constant(*v),
            _ => SourceDirection::Etf,
        };
        let tile = Tile::load(
            &dir.join(&ex.file),
            resolution.or(toml.resolution).unwrap_or(96),
            source,
        )?;
        let flow = match toml.flow {
            Some(DirectionToml::Vector(v)) => Flow::Fixed(v),
            _ => Flow::Outline,
        };
        let defaults = EmParams::default();
        let params = EmParams {
            alpha: toml.alpha.unwrap_or(0.25) as f32,
            radius: (toml.patch.unwrap_or(9) / 2) as usize,
            levels: toml.levels.unwrap_or(3) as usize,
            iterations: toml.iterations.unwrap_or(4) as usize,
            // The Shape Hint takes the tile's edge to be a line along its
            // direction, so it frames an outline only where the field runs
            // along it: under a fixed flow it would pull bands across the
            // outline and tear the pattern there.
            shape: match flow {
                Flow::Outline => defaults.shape,
                Flow::Fixed(_) => 0.0,
            },
            ..defaults
        };
        Ok(FillStyle {
            tile,
            params,
            scale: toml.scale.unwrap_or(1.0),
            flow,
        })
    }

    /// Synthesis pixels per sketch unit.
    pub fn px_per_unit(&self) -> f64 {
        1.0 / (self.tile.units_per_px * self.scale)
    }
}

/// One filled region of the output: what was synthesized and traced, with
/// the figures the tests measure it by.
#[derive(Clone, Debug)]
#[cfg_attr(not(test), allow(dead_code))] // the grids and figures are read by the tests
pub struct RegionFill {
    /// The query's id.
    pub id: String,
    /// The region on its grid.
    pub region: Region,
    /// Clipped layer SDFs (bottom first), region grid pixels.
    pub layers: Vec<Grid<f32>>,
    /// Layer colours.
    pub colors: Vec<crate::svg_out::Color>,
    /// Traced layers, sketch units.
    pub paths: Vec<Vec<BezPath>>,
    /// Ink fraction of the tile's bottom layer (all ink).
    pub tile_ink: f64,
    /// Eq. 6 energies per level (see [`em::Synthesis::energy`]).
    pub energy: Vec<Vec<f64>>,
}

impl RegionFill {
    /// Fraction of the region's pixels under ink (bottom layer).
    #[cfg(test)]
    pub fn ink_fraction(&self) -> f64 {
        let Some(l) = self.layers.first() else {
            return 0.0;
        };
        let ink = l
            .data()
            .iter()
            .zip(self.region.mask.data())
            .filter(|(d, m)| **m && **d < 0.0)
            .count();
        ink as f64 / self.region.area.max(1) as f64
    }
}

/// The result of `flourish fill` on one sketch.
#[derive(Clone, Debug)]
pub struct FillOutput {
    /// Sketch width, px.
    pub width: f64,
    /// Sketch height, px.
    pub height: f64,
    /// Sketch view box.
    pub view_box: kurbo::Rect,
    /// Regions in document order.
    pub regions: Vec<RegionFill>,
    /// Decimals for the output numbers.
    pub decimals: u32,
    /// One line per thing worth telling with `--verbose`.
    pub notes: Vec<String>,
}

impl FillOutput {
    /// The output document: one `<g id=QUERY>` per region, layers bottom
    /// first in the tile's colours.
    pub fn to_document(&self) -> Document {
        let mut doc = Document::new(self.width, self.height, self.decimals);
        doc.view_box = self.view_box;
        for r in &self.regions {
            let mut g = Group {
                id: r.id.clone(),
                shapes: Vec::new(),
            };
            for (paths, &color) in r.paths.iter().zip(&r.colors) {
                for p in paths {
                    g.shapes.push(Shape {
                        fill_rule: FillRule::NonZero,
                        ..Shape::filled(p.clone(), color)
                    });
                }
            }
            doc.groups.push(g);
        }
        doc
    }
}

/// The open stroked paths of a sketch as polylines with their widths.
fn combing_strokes(sk: &Sketch) -> Vec<(Vec<Point>, f64)> {
    sk.queries
        .iter()
        .filter_map(|q| match &q.kind {
            QueryKind::Path { spine, width } => Some((polyline(spine), *width)),
            QueryKind::Region { .. } => None,
        })
        .collect()
}

/// Fills every region query of a parsed sketch, each with the style
/// `style_of` gives it (with its name, for the notes); open paths inside a
/// region (and those of `opts.direction`) comb its direction field.
pub fn fill_sketch<'s>(
    sk: &Sketch,
    style_of: impl Fn(&Query) -> Result<(&'s str, &'s FillStyle)>,
    opts: &FillOptions,
) -> Result<FillOutput> {
    opts.validate()?;
    let mut strokes: Vec<(Vec<Point>, f64)> = Vec::new();
    let mut regions = Vec::new();
    for q in &sk.queries {
        match &q.kind {
            QueryKind::Path { spine, width } => strokes.push((polyline(spine), *width)),
            QueryKind::Region { outline, fill_rule } => regions.push((q, outline, *fill_rule)),
        }
    }
    if regions.is_empty() {
        return Err(Error::invalid("no filled closed shape to fill: the sketch has only open paths (give the shapes a fill)"));
    }
    let global = opts
        .direction
        .as_ref()
        .map(combing_strokes)
        .unwrap_or_default();
    // Each style's tile is prepared for synthesis once per sketch, then
    // shared by every region that uses it.
    let mut prepared_styles: Vec<(&FillStyle, em::Prepared)> = Vec::new();
    let mut out = Vec::new();
    let mut notes = Vec::new();
    let mut max_ppu = 1.0f64;
    for (qi, (q, outline, rule)) in regions.into_iter().enumerate() {
        let (name, st) = style_of(q)?;
        let k = match prepared_styles
            .iter()
            .position(|(s, _)| std::ptr::eq(*s, st))
        {
            Some(k) => k,
            None => {
                prepared_styles.push((st, em::Prepared::new(&st.tile, &st.params)));
                prepared_styles.len() - 1
            }
        };
        let prepared = &prepared_styles[k].1;
        let ppu = st.px_per_unit();
        max_ppu = max_ppu.max(ppu);
        let margin = st.params.radius + 2;
        let mut region = Region::rasterize(&q.id, outline, rule, ppu, margin)?;
        if let Flow::Fixed(d) = st.flow {
            region.direction = constant_field(region.width(), region.height(), d);
        }
        let combing: Vec<(&[Point], f64)> = strokes
            .iter()
            .filter(|(pts, _)| mostly_inside(outline, rule, pts))
            .chain(&global)
            .map(|(pts, width)| (pts.as_slice(), *width))
            .collect();
        region.comb_all(&combing);
        let combed = combing.len();
        notes.push(format!(
            "{}: style {name}, {}×{} px grid, {} px inside, {combed} combing stroke(s)",
            q.id,
            region.width(),
            region.height(),
            region.area
        ));
        let seed = crate::rng::hash(&[opts.seed, qi as u64]);
        let syn = prepared.synthesize(&region.direction, Some(&region.mask), seed);
        let mut layers = syn.layers;
        // Occlusion order: each layer extends under the layers above it.
        for k in (1..layers.len()).rev() {
            let (lo, hi) = layers.split_at_mut(k);
            for (a, &b) in lo[k - 1].data_mut().iter_mut().zip(hi[0].data()) {
                *a = a.min(b);
            }
        }
        for l in &mut layers {
            for (a, &b) in l.data_mut().iter_mut().zip(region.sdf.dist.data()) {
                *a = a.max(b);
            }
        }
        let topts = TraceOptions {
            tolerance: opts.tolerance,
            min_area: 2.0,
        };
        let paths = layers
            .iter()
            .map(|l| {
                trace_sdf(
                    &Sdf {
                        dist: l.clone(),
                        to_user: region.sdf.to_user,
                    },
                    &topts,
                )
            })
            .collect();
        out.push(RegionFill {
            id: q.id.clone(),
            colors: st.tile.layers.iter().map(|l| l.color).collect(),
            tile_ink: prepared.tile_ink(0),
            region,
            layers,
            paths,
            energy: syn.energy,
        });
    }
    Ok(FillOutput {
        width: sk.width,
        height: sk.height,
        view_box: sk.view_box,
        regions: out,
        decimals: decimals_for(opts.tolerance / max_ppu),
        notes,
    })
}

/// A path's points (curves flattened to 0.1 units), subpaths joined.
fn polyline(p: &BezPath) -> Vec<Point> {
    let mut pts = Vec::new();
    kurbo::flatten(p, 0.1, |el| match el {
        PathEl::MoveTo(a) | PathEl::LineTo(a) => pts.push(a),
        _ => {}
    });
    pts
}

/// True when most of a stroke's points lie inside the outline.
fn mostly_inside(outline: &BezPath, rule: FillRule, pts: &[Point]) -> bool {
    let inside = pts
        .iter()
        .filter(|&&p| {
            let w = outline.winding(p);
            match rule {
                FillRule::NonZero => w != 0,
                FillRule::EvenOdd => w % 2 != 0,
            }
        })
        .count();
    !pts.is_empty() && 2 * inside > pts.len()
}

#[cfg(test)]
mod tests;
