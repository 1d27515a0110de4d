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

pub mod atlas;
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
use crate::svg_out::{decimals_for, Color, Document, FillRule, Group, Shape};
use crate::trace::{trace_sdf, TraceOptions};
use em::EmParams;
use kurbo::{BezPath, PathEl, Point, Shape as _};
use rayon::prelude::*;
use region::Region;
use std::path::Path;
use tile::{Palette, SourceDirection, Swatch, Tile};

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
    /// Synthesize every region from this one swatch of its style (its
    /// file name as `style.toml` lists it) instead of from all of them,
    /// unless the region pins another with `data-exemplar` (default
    /// `None`).
    pub exemplar: Option<String>,
    /// Cancels the run from another thread: checked before each region;
    /// the run then ends with [`Error::Cancelled`] (default `None`).
    pub cancel: Option<crate::Cancel>,
}

impl Default for FillOptions {
    fn default() -> Self {
        FillOptions {
            seed: 0,
            direction: None,
            tolerance: 0.25,
            scale: 1.0,
            exemplar: None,
            cancel: None,
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

/// A loaded fill style: every swatch at synthesis resolution, with the
/// parameters they are synthesized with.
#[derive(Clone, Debug)]
pub struct FillStyle {
    /// One tile per swatch, in `style.toml` order, all with the same
    /// layers (the style's [`Palette`] without its ground).
    pub tiles: Vec<Tile>,
    /// The swatch files as `style.toml` lists them.
    pub files: Vec<String>,
    /// The colour that fills the whole region under the layers, for
    /// swatches coloured edge to edge.
    pub ground: Option<Color>,
    /// Synthesis parameters (seed set per region).
    pub params: EmParams,
    /// How large the pattern is drawn in the sketch.
    pub size: Size,
    /// What the swatches' direction follows where no stroke combs the shape.
    pub flow: Flow,
    /// How the swatches were read, for `--verbose`.
    pub notes: Vec<String>,
}

/// How large a fill style's pattern is drawn in a sketch.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Size {
    /// `scale` sketch units per user unit of the first swatch.
    Scale(f64),
    /// Each swatch's longest side spans the style's own `resolution` px
    /// (CSS px) of the sketch: this many sketch px per synthesis px (1
    /// unless `--resolution` overrides the style's).
    Auto(f64),
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
    /// Loads the style in `dir` (`kind = "fill"`), each swatch rasterized
    /// at `resolution` px on its longest side when given, else at the
    /// style's (default 96). Errors name the file at fault.
    pub fn load(dir: &Path, resolution: Option<u32>) -> Result<FillStyle> {
        let toml = style::load(dir)?;
        toml.expect_kind(dir, StyleKind::Fill)?;
        let own = toml.resolution.unwrap_or(96);
        let res = resolution.unwrap_or(own);
        let source = match &toml.direction {
            Some(DirectionToml::Named(_)) => SourceDirection::Etf,
            Some(DirectionToml::Vector(v)) => SourceDirection::Constant(*v),
            None => SourceDirection::Constant([1.0, 0.0]),
        };
        let mut swatches = Vec::with_capacity(toml.exemplar.len());
        let mut notes = Vec::new();
        for ex in &toml.exemplar {
            let path = dir.join(&ex.file);
            let sw = Swatch::read(&path, res)?;
            // A swatch that is one flat colour is a fault of that file.
            Palette::of(std::slice::from_ref(&sw))
                .map_err(|why| Error::invalid(why).in_file(&path))?;
            notes.extend(sw.notes.iter().cloned());
            swatches.push(sw);
        }
        let palette = Palette::of(&swatches)
            .map_err(|why| Error::invalid(why).in_file(dir.join(style::STYLE_FILE)))?;
        if let Some(n) = &palette.note {
            notes.push(format!("style {}: {n}", dir.display()));
        }
        let tiles: Vec<Tile> = swatches
            .iter()
            .map(|sw| Tile::from_swatch(sw, &palette, source))
            .collect();
        let files = toml
            .exemplar
            .iter()
            .map(|e| e.file.to_string_lossy().into_owned())
            .collect();
        let flow = match toml.flow {
            Some(DirectionToml::Named(_)) => Flow::Outline,
            Some(DirectionToml::Vector(v)) => Flow::Fixed(v),
            None => Flow::Fixed([1.0, 0.0]),
        };
        let defaults = EmParams::default();
        // A tile's edge line is a line along its direction, so it frames an
        // outline only where the field runs along it: under a fixed flow
        // it would pull bands across the outline and tear the pattern
        // there. A swatch's own edge is compared in both frames and holds
        // under any flow.
        let swatch_edge = tiles.iter().any(|t| t.shape.is_some());
        let params = EmParams {
            alpha: toml.alpha.unwrap_or(0.25) as f32,
            radius: (toml.patch.unwrap_or(9) / 2) as usize,
            levels: toml.levels.unwrap_or(3) as usize,
            iterations: toml.iterations.unwrap_or(4) as usize,
            shape: match flow {
                Flow::Fixed(_) if !swatch_edge => 0.0,
                _ => defaults.shape,
            },
            ..defaults
        };
        let size = match toml.scale {
            Some(s) => Size::Scale(s),
            None => Size::Auto(own as f64 / res as f64),
        };
        Ok(FillStyle {
            tiles,
            files,
            ground: palette.ground,
            params,
            size,
            flow,
            notes,
        })
    }

    /// Synthesis pixels per user unit of `sketch`.
    pub fn px_per_unit(&self, sketch: &Sketch) -> f64 {
        match self.size {
            Size::Scale(s) => 1.0 / (self.tiles[0].units_per_px * s),
            Size::Auto(sketch_px_per_px) => {
                let css_per_unit = sketch.width / sketch.view_box.width().max(1e-12);
                css_per_unit / sketch_px_per_px
            }
        }
    }

    /// The index of the swatch whose file is `name` (as `style.toml` lists
    /// it, or its file name alone).
    pub fn exemplar(&self, name: &str) -> Option<usize> {
        self.files.iter().position(|f| {
            f == name
                || Path::new(f)
                    .file_name()
                    .is_some_and(|n| n.to_string_lossy() == name)
        })
    }
}

/// One filled region of the output: what was synthesized and traced, with
/// the figures the tests measure it by.
#[derive(Clone, Debug)]
#[cfg_attr(not(test), allow(dead_code))] // the grids and figures are read by the tests
pub struct RegionFill {
    /// The query's id.
    pub id: String,
    /// The region on its grid (its grids empty from [`fill_document`]).
    pub region: Region,
    /// Clipped layer SDFs (bottom first, the ground not among them),
    /// region grid pixels (none from [`fill_document`]).
    pub layers: Vec<Grid<f32>>,
    /// Layer colours.
    pub colors: Vec<Color>,
    /// The ground's colour: the region's own outline is drawn in it under
    /// the layers.
    pub ground: Option<Color>,
    /// The region's outline, sketch units (what the ground draws).
    pub outline: BezPath,
    /// The outline's fill rule.
    pub fill_rule: FillRule,
    /// Traced layers, sketch units.
    pub paths: Vec<Vec<BezPath>>,
    /// Ink fraction of the swatches' bottom layer (all ink over the
    /// paper or ground).
    pub tile_ink: f64,
    /// The swatches it was synthesized from (indices into the style's).
    pub exemplars: Vec<usize>,
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
    /// One line per region left out (too small to fill).
    pub warnings: Vec<String>,
}

impl FillOutput {
    /// The output document: one `<g id=QUERY>` per region, the ground (the
    /// region's outline) first when the swatches have one, then the layers
    /// bottom first in their colours.
    pub fn to_document(&self) -> Document {
        let mut doc = Document::new(self.width, self.height, self.decimals);
        doc.view_box = self.view_box;
        for r in &self.regions {
            let mut g = Group {
                id: r.id.clone(),
                shapes: Vec::new(),
            };
            if let Some(c) = r.ground {
                g.shapes.push(Shape {
                    fill_rule: r.fill_rule,
                    ..Shape::filled(r.outline.clone(), c)
                });
            }
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

/// The swatches a region is synthesized from: the one it pins with
/// `data-exemplar`, else the one `--exemplar` pins, else all of them.
fn exemplars_of(
    sk: &Sketch,
    q: &Query,
    name: &str,
    st: &FillStyle,
    opts: &FillOptions,
) -> Result<Vec<usize>> {
    let own = sk.exemplars.get(&q.id);
    let Some(pin) = own.or(opts.exemplar.as_ref()) else {
        return Ok((0..st.tiles.len()).collect());
    };
    match st.exemplar(pin) {
        Some(k) => Ok(vec![k]),
        None => {
            let how = if own.is_some() {
                "data-exemplar"
            } else {
                "--exemplar"
            };
            Err(Error::invalid(format!(
                "{how} \"{pin}\" is not a swatch of style {name} ({})",
                st.files.join(", ")
            ))
            .in_part(&q.id))
        }
    }
}

/// Fills every region query of a parsed sketch, each with the style
/// `style_of` gives it (with its name, for the notes); open paths inside a
/// region (and those of `opts.direction`) comb its direction field.
#[cfg_attr(not(test), allow(dead_code))] // the tests and the gallery read the grids
pub fn fill_sketch<'s>(
    sk: &Sketch,
    style_of: impl Fn(&Query) -> Result<(&'s str, &'s FillStyle)>,
    opts: &FillOptions,
) -> Result<FillOutput> {
    fill_regions(sk, style_of, opts, true)
}

/// [`fill_sketch`] for its document alone: each region's grids (its
/// [`RegionFill::region`] rasters and [`RegionFill::layers`]) are let go
/// once it is traced, so a sketch of many regions holds one region's
/// grids at a time; they are left empty in the output.
pub fn fill_document<'s>(
    sk: &Sketch,
    style_of: impl Fn(&Query) -> Result<(&'s str, &'s FillStyle)>,
    opts: &FillOptions,
) -> Result<FillOutput> {
    fill_regions(sk, style_of, opts, false)
}

/// [`fill_sketch`], keeping each region's grids in the output when
/// `keep_grids`.
fn fill_regions<'s>(
    sk: &Sketch,
    style_of: impl Fn(&Query) -> Result<(&'s str, &'s FillStyle)>,
    opts: &FillOptions,
    keep_grids: bool,
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
    // Each style's swatches (all, or the one a region pins) are prepared
    // for synthesis once per sketch, then shared by every region that uses
    // them.
    let mut prepared_styles: Vec<(&FillStyle, Vec<usize>, em::Prepared)> = Vec::new();
    let mut out = Vec::new();
    let mut notes = Vec::new();
    let mut warnings = Vec::new();
    let mut max_ppu = 1.0f64;
    let tally = crate::io::Tally::new("fill: regions filled", regions.len());
    for (qi, (q, outline, rule)) in regions.into_iter().enumerate() {
        crate::io::check(&opts.cancel)?;
        if qi > 0 {
            tally.tick();
        }
        let (name, st) = style_of(q)?;
        let which = exemplars_of(sk, q, name, st, opts)?;
        let margin = st.params.radius + 2;
        check_memory(&q.id, outline, st.px_per_unit(sk), margin, &which, st)?;
        let k = match prepared_styles
            .iter()
            .position(|(s, w, _)| std::ptr::eq(*s, st) && *w == which)
        {
            Some(k) => k,
            None => {
                if !prepared_styles.iter().any(|(s, _, _)| std::ptr::eq(*s, st)) {
                    notes.extend(st.notes.iter().cloned());
                }
                let tiles: Vec<Tile> = which.iter().map(|&i| st.tiles[i].clone()).collect();
                let prepared = em::Prepared::new(&tiles, &st.params);
                prepared_styles.push((st, which.clone(), prepared));
                prepared_styles.len() - 1
            }
        };
        let prepared = &prepared_styles[k].2;
        let ppu = st.px_per_unit(sk);
        max_ppu = max_ppu.max(ppu);
        let mut region = match Region::rasterize(&q.id, outline, rule, ppu, margin) {
            Ok(r) => r,
            // A speck (no pixel centre inside) is left out, not the run.
            Err(Error::Degenerate { subject, reason }) => {
                warnings.push(format!("{subject}: {reason}; it is left out"));
                continue;
            }
            Err(e) => return Err(e),
        };
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
        let from = if which.len() == st.tiles.len() {
            format!("{} swatch(es)", which.len())
        } else {
            format!("swatch {}", st.files[which[0]])
        };
        notes.push(format!(
            "{}: style {name} ({from}), {}×{} px grid, {} px inside, {combed} combing stroke(s)",
            q.id,
            region.width(),
            region.height(),
            region.area
        ));
        // A shape's own `data-seed` stands in for the run's.
        let seed = crate::rng::hash(&[q.seed.unwrap_or(opts.seed), qi as u64]);
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
        // Layers trace independently, one task each (as many at once as
        // the memory allowance for them holds), in layer order.
        let k = layers_at_once(layers.len(), region.width() * region.height());
        let paths = layers
            .chunks(k.max(1))
            .flat_map(|group| {
                group
                    .par_iter()
                    .map(|l| {
                        trace_sdf(
                            &Sdf {
                                dist: l.clone(),
                                to_user: region.sdf.to_user,
                            },
                            &topts,
                        )
                    })
                    .collect::<Vec<_>>()
            })
            .collect();
        let (region, layers) = if keep_grids {
            (region, layers)
        } else {
            (region.without_grids(), Vec::new())
        };
        out.push(RegionFill {
            id: q.id.clone(),
            colors: st.tiles[0].layers.iter().map(|l| l.color).collect(),
            ground: st.ground,
            outline: outline.clone(),
            fill_rule: rule,
            tile_ink: prepared.tile_ink(0),
            exemplars: which,
            region,
            layers,
            paths,
            energy: syn.energy,
        });
    }
    if out.is_empty() {
        return Err(Error::invalid(format!(
            "every filled shape is smaller than one tile pixel ({}); draw them larger or raise the style's resolution",
            warnings.len()
        )));
    }
    Ok(FillOutput {
        width: sk.width,
        height: sk.height,
        view_box: sk.view_box,
        regions: out,
        decimals: decimals_for(opts.tolerance / max_ppu),
        notes,
        warnings,
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

/// One line per swatch of `style` for `flourish style check`: its file,
/// raster size, whether it repeats (a seamless tile), is a motif on paper
/// or a piece of a larger pattern, and each colour layer, bottom first,
/// with the share of the swatch it covers (a layer covers the layers above
/// it too).
pub fn check(style: &FillStyle) -> Vec<String> {
    let mut lines: Vec<String> = style
        .files
        .iter()
        .zip(&style.tiles)
        .map(|(file, t)| {
            let (w, h) = (t.colour.width(), t.colour.height());
            let repeat = if t.periodic {
                "seamless tile"
            } else if t.shape.is_some() {
                "motif on paper"
            } else {
                "piece of a larger pattern"
            };
            let layers: Vec<String> = t
                .layers
                .iter()
                .map(|l| {
                    let inside = l.sdf.data().iter().filter(|d| **d < 0.0).count();
                    let share = inside as f64 / l.sdf.data().len().max(1) as f64;
                    format!("{} {:.0}%", l.color.to_hex(), share * 100.0)
                })
                .collect();
            format!(
                "{file}: {w}×{h} px, {repeat}, {} layer{} bottom first ({}) on {}",
                t.layers.len(),
                if t.layers.len() == 1 { "" } else { "s" },
                layers.join(", "),
                t.paper.to_hex()
            )
        })
        .collect();
    lines.extend(style.notes.iter().cloned());
    lines
}

/// Bytes one colour layer's E-step or tracing holds per pixel of the
/// region's grid while it runs: the stepped copy, the reinitialization's
/// contour, inside mask, band distances and two distance transforms, or
/// the traced copy with its coverage and outline.
const LAYER_BYTES_PER_PX: u64 = 40;

/// The share of the memory budget (one part in this many) that colour
/// layers running side by side may take beyond the first: 64 MB of the
/// default 1 GiB, so a run's peak stays near that of one layer at a time.
const PARALLEL_LAYERS_SHARE: u64 = 16;

/// How many of `layers` colour layers of a grid of `px` pixels evolve or
/// trace at once: one, plus as many more as fit in the allowance
/// ([`PARALLEL_LAYERS_SHARE`] of the budget, and what is left of it) at
/// [`LAYER_BYTES_PER_PX`]. The result does not depend on it (layers are
/// independent and collected in order).
pub fn layers_at_once(layers: usize, px: usize) -> usize {
    layers_within(layers, px, crate::memory::budget(), crate::memory::held())
}

/// [`layers_at_once`] under a budget of `budget` bytes of which `held`
/// are taken.
fn layers_within(layers: usize, px: usize, budget: u64, held: u64) -> usize {
    let each = (px as u64).saturating_mul(LAYER_BYTES_PER_PX).max(1);
    let room = (budget / PARALLEL_LAYERS_SHARE).min(budget.saturating_sub(held));
    let more = usize::try_from(room / each).unwrap_or(usize::MAX);
    more.saturating_add(1).min(layers.max(1))
}

/// Bytes a region's synthesis holds per pixel of its grid and of its
/// swatches at their peak (pyramids, patch features, nearest-neighbour
/// fields, layer SDFs), for the memory budget's estimate.
const BYTES_PER_PX: u64 = 180;

/// Refuses, before its grid is allocated, a region whose synthesis would
/// not fit the memory budget ([`crate::memory`]): its grid at `ppu` with
/// `margin` and the swatches `which` of `st`.
fn check_memory(
    id: &str,
    outline: &BezPath,
    ppu: f64,
    margin: usize,
    which: &[usize],
    st: &FillStyle,
) -> Result<()> {
    let bb = outline.bounding_box();
    let side = |l: f64| (l * ppu).ceil().clamp(0.0, 1e9) as u64 + 2 * margin as u64;
    let (gw, gh) = (side(bb.width()), side(bb.height()));
    let grid = gw.saturating_mul(gh);
    if gw > region::MAX_FILL_SIDE || gh > region::MAX_FILL_SIDE || grid > region::MAX_FILL_PIXELS {
        // Over the size limit: the grid's own check says so.
        return Ok(());
    }
    let swatches: u64 = which
        .iter()
        .filter_map(|&i| st.tiles.get(i))
        .filter_map(|t| t.layers.first())
        .map(|l| (l.sdf.width() as u64) * (l.sdf.height() as u64))
        .sum();
    let what = format!("region {id}: a {gw}×{gh} px grid with {swatches} swatch px");
    crate::memory::check(
        &what,
        grid.saturating_add(swatches).saturating_mul(BYTES_PER_PX),
    )
    .map_err(|e| Error::invalid(format!("{e}; lower --resolution")))
}
