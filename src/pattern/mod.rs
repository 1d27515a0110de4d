//! `flourish pattern`: element patterns along paths and inside regions,
//! vector end to end (Barla et al., *Stroke Pattern Analysis and
//! Synthesis*, EG 2006; `shared/papers/stroke-pattern-synthesis.txt`).
//!
//! Stages, one module each:
//! - [`element`]: example strokes, oriented-box element fitting (§2.1);
//! - [`cluster`]: greedy grouping by proximity and continuation (§2.2);
//! - [`distribution`]: chains / unskewed Delaunay graphs, shift vectors (§2.3);
//! - [`seeds`]: 1-D seeds along a path, Lloyd relaxation in a region (§3.2);
//! - [`synth`]: neighbourhood matching, growth, variation (§3.1–3.3).
//!
//! The output is never rasterized: every element is a set of the example's
//! own strokes placed by a rigid transform (along a path, turned with the
//! local path direction), kept or dropped whole.
//!
//! Limits: elements are boxes (a centre and two axes), so long curved
//! strokes are matched by their box only (§5.1); the distribution is
//! quasi-uniform (§5.2). Group opacity, dashes, clips and masks of the
//! example are not carried over; gradients become their mean colour.

pub mod cluster;
pub mod distribution;
pub mod element;
pub mod seeds;
pub mod synth;

use crate::error::{Error, Result};
use crate::read::sketch::{Query, QueryKind, Sketch};
use crate::read::style::{self, FitPoints, StyleKind};
use crate::svg_out::{Document, Group, Shape};
use distribution::{Dim, Distribution, Graph};
use element::{Element, ExampleStroke};
use kurbo::{Affine, Point, Rect, Shape as _, Vec2};
use rayon::prelude::*;
use seeds::{Polyline, Region};
use std::path::Path;
use std::sync::Arc;
use synth::{Placed, Reference, Target};

/// Default largest number of elements synthesized for one query.
pub const DEFAULT_MAX_ELEMENTS: usize = 50_000;

/// Options of [`crate::pattern()`].
#[derive(Clone, Debug)]
pub struct PatternOptions {
    /// Seeds every random choice (default 0).
    pub seed: u64,
    /// Amount of the variation post-process (Barla et al. §3.3), 0..=1: 0
    /// puts the elements exactly on the Lloyd seeds, as matched (default 0).
    pub variation: f64,
    /// Largest number of elements one query may ask for; more is an error
    /// (default 50 000).
    pub max_elements: usize,
    /// Multiplies the style's size: its elements and their spacing drawn
    /// this many times larger in the sketch (0.01..=100; default 1).
    pub scale: f64,
}

impl Default for PatternOptions {
    fn default() -> Self {
        PatternOptions {
            seed: 0,
            variation: 0.0,
            max_elements: DEFAULT_MAX_ELEMENTS,
            scale: 1.0,
        }
    }
}

impl PatternOptions {
    /// Checks every value's range.
    pub fn validate(&self) -> Result<()> {
        if !(self.scale.is_finite() && (0.01..=100.0).contains(&self.scale)) {
            return Err(Error::Option {
                name: "scale",
                reason: format!("{} is not in 0.01..=100", self.scale),
            });
        }
        if !(self.variation.is_finite() && (0.0..=1.0).contains(&self.variation)) {
            return Err(Error::Option {
                name: "variation",
                reason: format!("{} is not in 0..=1", self.variation),
            });
        }
        Ok(())
    }
}

/// Analysis parameters of a pattern style (from `style.toml`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PatternParams {
    /// ε, example user units: strokes closer than this are one element.
    pub scale: f64,
    /// Neighbourhood rings used in matching (1..=6).
    pub rings: usize,
    /// Points the element boxes are fitted to.
    pub fit: FitPoints,
    /// Row or field; `None` detects it from the element centres.
    pub dimension: Option<Dim>,
    /// Maximum Lloyd iterations.
    pub lloyd_iterations: usize,
}

impl PatternParams {}

/// An analysed pattern style: the example's strokes in the reference frame
/// and the reference (elements, distribution, neighbourhoods).
#[derive(Clone, Debug)]
pub struct PatternStyle {
    /// Analysis parameters.
    pub params: PatternParams,
    /// The example's strokes, moved rigidly into the reference frame
    /// (centred; a row turned to run along +x).
    pub strokes: Vec<ExampleStroke>,
    /// Elements, distribution, neighbourhoods and measures.
    pub reference: Reference,
}

impl PatternStyle {
    /// Loads and analyses the pattern style in folder `dir`.
    pub fn load(dir: &Path) -> Result<PatternStyle> {
        let toml = style::load(dir)?;
        toml.expect_kind(dir, StyleKind::Pattern)?;
        let toml_path = dir.join(style::STYLE_FILE);
        let (Some(scale), Some(ex)) = (toml.scale, toml.exemplar.first()) else {
            return Err(
                Error::invalid("a pattern style needs scale and one exemplar").in_file(toml_path),
            );
        };
        let params = PatternParams {
            scale,
            rings: toml.rings.unwrap_or(2) as usize,
            fit: toml.fit.unwrap_or_default(),
            dimension: toml
                .dimension
                .map(|d| if d == 1 { Dim::One } else { Dim::Two }),
            lloyd_iterations: toml.lloyd_iterations.unwrap_or(60) as usize,
        };
        let path = dir.join(&ex.file);
        let data = crate::io::read_file(&path)?;
        PatternStyle::from_example(&path, &data, params)
    }

    /// Analyses example SVG bytes (§2); `path` names the file in errors.
    pub fn from_example(path: &Path, data: &[u8], params: PatternParams) -> Result<PatternStyle> {
        if !(params.scale.is_finite() && params.scale > 0.0) {
            return Err(Error::invalid(format!(
                "scale must be a positive number, got {}",
                params.scale
            ))
            .in_file(path));
        }
        let mut strokes = element::load_example(path, data, params.fit, params.scale)?;
        let clusters = cluster::cluster(&strokes, params.scale);
        let centres: Vec<Point> = clusters.iter().map(|e| e.centre).collect();
        let dim = params.dimension.unwrap_or_else(|| detect_dim(&centres));
        // The reference frame: centred on the centres' mean; a row is turned
        // so that its principal axis runs along +x (a rotation, never a
        // mirror, so copies stay rigid copies of the example).
        let (c, axis, _, _) = element::fit_box(centres.iter().copied());
        let mean =
            centres.iter().fold(Vec2::ZERO, |s, p| s + p.to_vec2()) / centres.len().max(1) as f64;
        let _ = c;
        let turn = match dim {
            Dim::One => {
                let a = axis.y.atan2(axis.x);
                -synth::wrap_half_turn(a)
            }
            Dim::Two => 0.0,
        };
        let frame = Affine::rotate(turn) * Affine::translate(-mean);
        for s in &mut strokes {
            s.transform(frame);
        }
        let mut elements: Vec<Element> = clusters
            .into_iter()
            .map(|e| Element::fit(&strokes, e.strokes))
            .collect();
        if dim == Dim::One {
            elements.sort_by(|a, b| a.centre.x.total_cmp(&b.centre.x));
        }
        let heights: Vec<f64> = elements
            .iter()
            .map(|e| 2.0 * (e.axis.y.abs() * e.half_a + e.axis.x.abs() * e.half_b))
            .collect();
        // A lone element repeats at its own diameter plus ε.
        let lone = elements
            .iter()
            .map(|e| e.length().max(e.thickness()))
            .fold(0.0, f64::max)
            + params.scale;
        let dist = Distribution::analyse(
            elements.iter().map(|e| e.centre).collect(),
            &heights,
            dim,
            lone,
        );
        let reference = Reference::new(elements, dist, params.rings);
        Ok(PatternStyle {
            params,
            strokes,
            reference,
        })
    }

    /// The reference elements.
    #[cfg(test)]
    pub fn elements(&self) -> &[Element] {
        &self.reference.elements
    }

    /// The shapes of reference element `i` in the reference frame.
    pub fn element_shapes(&self, i: usize) -> impl Iterator<Item = &Shape> {
        self.reference.elements[i]
            .strokes
            .iter()
            .flat_map(move |&s| self.strokes[s].shapes.iter())
    }

    /// Expected number of elements for a region of `area` (N_ref·A_tar/A_ref).
    pub fn expected_in_area(&self, area: f64) -> f64 {
        self.reference.elements.len() as f64 * area / self.reference.dist.area
    }
}

/// A row when the centres spread across the row by less than 0.3 of the
/// spacing between neighbours (or when there are fewer than three).
fn detect_dim(centres: &[Point]) -> Dim {
    if centres.len() < 3 {
        return Dim::One;
    }
    let (_, _, _, half_b) = element::fit_box(centres.iter().copied());
    let spacing = distribution::nearest_spacing(centres).unwrap_or(0.0);
    if half_b < 0.3 * spacing {
        Dim::One
    } else {
        Dim::Two
    }
}

/// One synthesized element of a query.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PlacedElement {
    /// Index of the reference element copied.
    pub element: usize,
    /// The rigid transform from the reference frame to the sketch.
    pub transform: Affine,
    /// The element's centre in the sketch.
    pub centre: Point,
}

/// The pattern made for one query.
#[derive(Clone, Debug)]
pub struct QueryPattern {
    /// The query's id (`q-N` or its own).
    pub id: String,
    /// The style it was made with.
    pub style: Arc<PatternStyle>,
    /// The elements, in seed order.
    pub elements: Vec<PlacedElement>,
}

/// The result of `flourish pattern` on one sketch, before writing.
#[derive(Clone, Debug)]
pub struct PatternOutput {
    /// Sketch width, px.
    pub width: f64,
    /// Sketch height, px.
    pub height: f64,
    /// Sketch viewBox, user units.
    pub view_box: Rect,
    /// One pattern per query, in document order.
    pub queries: Vec<QueryPattern>,
    /// One line per shape left out (nothing inside it).
    pub warnings: Vec<String>,
}

impl PatternOutput {
    /// The output document: one `<g>` per query, every element's strokes
    /// moved by its rigid transform, coordinates to 0.001 user units.
    pub fn to_document(&self) -> Document {
        let mut doc = Document::new(self.width, self.height, 3);
        doc.view_box = self.view_box;
        for q in &self.queries {
            let mut g = Group {
                id: q.id.clone(),
                shapes: Vec::new(),
            };
            for e in &q.elements {
                for s in q.style.element_shapes(e.element) {
                    let mut s = s.clone();
                    s.path.apply_affine(e.transform);
                    g.shapes.push(s);
                }
            }
            doc.groups.push(g);
        }
        doc
    }
}

/// Synthesizes the patterns for every query of a parsed sketch, each with
/// the style `style_of` gives it. Queries run in parallel; the result does
/// not depend on the thread count.
pub fn synthesize_sketch(
    sk: &Sketch,
    style_of: impl Fn(&Query) -> Result<Arc<PatternStyle>> + Sync,
    opts: &PatternOptions,
) -> Result<PatternOutput> {
    opts.validate()?;
    if sk.queries.is_empty() {
        return Err(Error::invalid(
            "no stroked path or filled shape to decorate",
        ));
    }
    let done = sk
        .queries
        .par_iter()
        .enumerate()
        .map(|(qi, q)| {
            let style = style_of(q)?;
            // A shape's own `data-seed` stands in for the run's.
            let key = [q.seed.unwrap_or(opts.seed), qi as u64];
            let elements = match &q.kind {
                QueryKind::Path { spine, width } => along_path(&style, spine, *width, opts, &key),
                QueryKind::Region { outline, fill_rule } => {
                    match Region::new(outline, *fill_rule, 0.05) {
                        Ok(region) => in_region(&style, &region, outline, opts, &key),
                        // A region with nothing inside is left out, not the run.
                        Err(r) if r == seeds::ZERO_AREA => {
                            return Ok(Err(format!("{}: {r}; it is left out", q.id)));
                        }
                        Err(r) => return Err(Error::invalid(format!("{}: {r}", q.id))),
                    }
                }
            }
            .map_err(|reason| Error::invalid(format!("{}: {reason}", q.id)))?;
            Ok(Ok(QueryPattern {
                id: q.id.clone(),
                style,
                elements,
            }))
        })
        .collect::<Result<Vec<_>>>()?;
    let mut queries = Vec::with_capacity(done.len());
    let mut warnings = Vec::new();
    for d in done {
        match d {
            Ok(q) => queries.push(q),
            Err(w) => warnings.push(w),
        }
    }
    if queries.is_empty() {
        return Err(Error::invalid(format!(
            "every shape has zero area ({})",
            warnings.len()
        )));
    }
    Ok(PatternOutput {
        width: sk.width,
        height: sk.height,
        view_box: sk.view_box,
        queries,
        warnings,
    })
}

fn too_many(n: f64, limit: usize) -> std::result::Result<(), String> {
    if n > limit as f64 {
        return Err(format!(
            "would need {n:.0} elements, more than the limit of {limit}; use a style with a larger spacing or a smaller shape"
        ));
    }
    Ok(())
}

/// Synthesis along every subpath of `spine` within the band of the stroke
/// width.
///
/// When the band holds fewer than 1.5 rows of elements (rows = width /
/// pitch; 2 rows for a row example), it is 1-D: seeds in a chain at the
/// example's [chain spacing](Distribution::chain_spacing) (those that would
/// come closer than [`CROWDED`] spacings to another where the path turns
/// back on itself are left out), elements turned with the path, variation
/// never moving a centre more than width/2 off the path. A wider band is filled in 2-D in path coordinates (arc
/// length, offset): the band is straightened into a length × width
/// rectangle, synthesized like a region and bent back along the path.
pub fn along_path(
    style: &PatternStyle,
    spine: &kurbo::BezPath,
    width: f64,
    opts: &PatternOptions,
    key: &[u64],
) -> std::result::Result<Vec<PlacedElement>, String> {
    let r = &style.reference;
    let spacing = r.dist.chain_spacing();
    let lines = Polyline::from_path(spine, 0.05);
    // A row example is meant as a row: it stacks only when two fit.
    let rows = width / r.dist.pitch;
    let band = match r.dist.dim {
        Dim::One => rows >= 2.0,
        Dim::Two => rows >= 1.5,
    };
    let total: f64 = lines
        .iter()
        .map(|l| {
            if band {
                style.expected_in_area(l.length() * width)
            } else {
                l.length() / spacing
            }
        })
        .sum();
    too_many(total, opts.max_elements)?;
    let half = width / 2.0;
    let mut out = Vec::new();
    for (li, line) in lines.iter().enumerate() {
        let k = [key, &[li as u64]].concat();
        let placed = if band {
            let rect = Rect::new(0.0, -half, line.length(), half).to_path(0.1);
            let region = Region::new(&rect, crate::svg_out::FillRule::NonZero, 0.05)?;
            fill(style, &region, &rect, opts, &k)?
        } else {
            let s =
                seeds::thin_crowded(line, &seeds::seeds_along(line, spacing), CROWDED * spacing);
            let closed = line.closed;
            let target = Target {
                pos: s.iter().map(|&x| Point::new(x, 0.0)).collect(),
                graph: Graph::chain(&s, closed, line.length()),
                period: closed.then(|| line.length()),
                dim: Dim::One,
            };
            let assigned = synth::synthesize(r, &target, &k);
            synth::vary(r, &target, &assigned, opts.variation, &k, &|p: Point| {
                p.y.abs() <= half
            })
        };
        for p in placed {
            let t = line.tangent(p.pos.x, spacing / 2.0);
            let normal = Vec2::new(-t.y, t.x);
            let at = line.at(p.pos.x) + normal * p.pos.y;
            out.push(place(style, p, at, t.y.atan2(t.x)));
        }
    }
    Ok(out)
}

/// 2-D synthesis inside `region` (whose curves are `outline`): N_tar =
/// N_ref·A_tar/A_ref Lloyd seeds, matched and varied.
pub fn in_region(
    style: &PatternStyle,
    region: &Region,
    outline: &kurbo::BezPath,
    opts: &PatternOptions,
    key: &[u64],
) -> std::result::Result<Vec<PlacedElement>, String> {
    Ok(fill(style, region, outline, opts, key)?
        .into_iter()
        .map(|p| place(style, p, p.pos, 0.0))
        .collect())
}

/// The 2-D pipeline in the pattern frame.
///
/// A row example fills a region with rows: Lloyd runs in a space squeezed
/// across the rows by spacing/pitch, where the CVT is isotropic, and the
/// seeds are stretched back — an anisotropic CVT with the row's spacing
/// along x and its pitch along y.
///
/// The count starts from the area (Barla et al. §3.2, N_ref·A_tar/A_ref).
/// Where a field's region is narrower than a few spacings (the bars of a
/// letter, a ring) that count spreads the seeds along the shape farther
/// apart than the example's elements, so while the seeds' mean
/// nearest-neighbour distance is over [`SPARSE`] times the example's, the
/// count is raised by that ratio (the spacing of seeds in a band falls as
/// one over their count) and the seeds placed again, a few times at most.
fn fill(
    style: &PatternStyle,
    region: &Region,
    outline: &kurbo::BezPath,
    opts: &PatternOptions,
    key: &[u64],
) -> std::result::Result<Vec<Placed>, String> {
    let r = &style.reference;
    let expected = style.expected_in_area(region.area);
    too_many(expected, opts.max_elements)?;
    let mut n = (expected.round() as usize).max(1);
    let squeeze = r.dist.spacing / r.dist.pitch;
    let field = (squeeze - 1.0).abs() < 1e-9;
    let squeezed = if field {
        None
    } else {
        Some(Region::new(
            &(Affine::scale_non_uniform(1.0, squeeze) * outline.clone()),
            region.rule,
            0.05,
        )?)
    };
    let place_seeds = |n: usize| {
        let mut points = seeds::lloyd(
            squeezed.as_ref().unwrap_or(region),
            n,
            crate::rng::hash(key),
            style.params.lloyd_iterations,
        )
        .points;
        for p in &mut points {
            p.y /= squeeze;
        }
        // Squeezing back can land a seed outside only through the two
        // flattenings' difference (≤ 0.1 units); such a seed is dropped whole.
        points.retain(|&p| region.contains(p));
        points
    };
    let mut points = place_seeds(n);
    let own = distribution::nearest_spacing(&r.dist.centres);
    if let (true, Dim::Two, Some(own)) = (field, r.dist.dim, own) {
        for _ in 0..4 {
            let Some(m) = mean_nearest(&points) else {
                break;
            };
            let more = (n as f64 * m / own).ceil();
            if m <= SPARSE * own || more > opts.max_elements as f64 {
                break;
            }
            n = more as usize;
            points = place_seeds(n);
        }
    }
    let squeezed_pts: Vec<Point> = points
        .iter()
        .map(|p| Point::new(p.x, p.y * squeeze))
        .collect();
    let graph = Graph::delaunay(&squeezed_pts);
    let target = Target {
        graph,
        pos: points,
        period: None,
        dim: Dim::Two,
    };
    let assigned = synth::synthesize(r, &target, key);
    Ok(synth::vary(
        r,
        &target,
        &assigned,
        opts.variation,
        key,
        &|p| region.contains(p),
    ))
}

/// The least distance, as a fraction of the chain spacing, between two
/// elements of one chain anywhere in the plane: the gallery's spacing
/// tolerance (within 20 % of the example's).
const CROWDED: f64 = 0.8;

/// How much farther apart than the example's elements (mean nearest
/// neighbour distance, ratio) a field's seeds may be before their count
/// is raised.
const SPARSE: f64 = 1.1;

/// Mean distance from each point to its nearest other point, taken among
/// its Delaunay neighbours (the nearest is one of them); `None` for fewer
/// than two points.
fn mean_nearest(pts: &[Point]) -> Option<f64> {
    if pts.len() < 2 {
        return None;
    }
    if pts.len() < 4 {
        return distribution::nearest_spacing(pts);
    }
    let g = Graph::delaunay(pts);
    let sum: f64 = g
        .adj
        .iter()
        .enumerate()
        .map(|(i, a)| {
            a.iter()
                .map(|&j| pts[i].distance(pts[j]))
                .fold(f64::INFINITY, f64::min)
        })
        .filter(|d| d.is_finite())
        .sum();
    Some(sum / pts.len() as f64)
}

/// The rigid transform putting reference element `p.element`'s centre at
/// `at`, turned by `angle + p.rotation`.
fn place(style: &PatternStyle, p: Placed, at: Point, angle: f64) -> PlacedElement {
    let c = style.reference.elements[p.element].centre;
    let transform = Affine::translate(at.to_vec2())
        * Affine::rotate(angle + p.rotation)
        * Affine::translate(-c.to_vec2());
    PlacedElement {
        element: p.element,
        transform,
        centre: at,
    }
}

#[cfg(test)]
mod tests;

/// One line for `flourish style check`: the example's elements (how many,
/// their sizes), whether they form a row or a field, and their spacing,
/// in example units.
pub fn check(style: &PatternStyle) -> Vec<String> {
    let els = &style.reference.elements;
    let (lo, hi) = els
        .iter()
        .map(|e| e.length().max(e.thickness()))
        .fold((f64::INFINITY, 0.0f64), |(lo, hi), s| {
            (lo.min(s), hi.max(s))
        });
    let dim = match style.reference.dist.dim {
        Dim::One => "a row",
        Dim::Two => "a field",
    };
    vec![format!(
        "{} elements in {dim}, {:.1}–{:.1} units across, spacing {:.1} units (ε = {})",
        els.len(),
        if lo.is_finite() { lo } else { 0.0 },
        hi,
        style.reference.dist.spacing,
        style.params.scale
    )]
}
