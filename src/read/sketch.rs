//! Sketch SVG → queries.
//!
//! usvg resolves transforms, `use`, groups and units; this module walks the
//! result and classifies every visible shape (SPEC.md, "Sketch SVG"):
//! - a shape with a fill is a **region query** (its outline and fill rule);
//! - a shape with a visible stroke and no fill is an **open query path**
//!   (its geometry is the spine, its stroke width the intended width).
//!
//! A shape (or an ancestor group) may carry `data-style="NAME"`,
//! `data-seed="N"` (its own seed, in place of the run's), and a filled one
//! `data-exemplar="FILE"` (one swatch of its fill style). An open path may
//! carry `data-widths` (its width along it, [`parse_widths`]). usvg
//! drops unknown attributes, so the raw XML is read first with roxmltree
//! (the parser usvg itself uses) and shapes without an `id` get a private
//! one, mapped back here.
//!
//! Query geometry is in the sketch's user units (its `viewBox` space), so an
//! output written with the sketch's `width`, `height` and `viewBox`
//! overlays it exactly.

use crate::error::{Error, Result};
use crate::read::svg::{affine_of, to_bezpath};
use crate::svg_out::{Backdrop, FillRule, Place};
use kurbo::{Affine, BezPath, Rect, Shape as _};
use resvg::usvg;
use std::collections::BTreeMap;
use std::sync::Arc;

/// Largest coordinate magnitude of a query, user units: sizes, lengths and
/// element counts are computed from the coordinates, and past this a
/// drawing's numbers (an arc of 1e308) only make them overflow.
pub const MAX_COORD: f64 = 1e9;

/// Most shapes a sketch may hand the modes (open paths and regions in
/// all); a sketch with more is refused before any is synthesized.
pub const MAX_QUERIES: usize = 100_000;

/// Prefix of the ids given to shapes without one, so each query can be
/// traced back to its element.
const PRIVATE_ID: &str = "flourish-ds-";

/// What a query asks for.
#[derive(Clone, Debug, PartialEq)]
pub enum QueryKind {
    /// An open query path: decorate along `spine`.
    Path {
        /// The spine in user units (may hold several subpaths).
        spine: BezPath,
        /// The stroke width in user units: the intended pattern width.
        width: f64,
    },
    /// A region query: decorate inside `outline`.
    Region {
        /// The outline in user units, holes included as subpaths.
        outline: BezPath,
        /// How the subpaths make the interior.
        fill_rule: FillRule,
    },
}

/// One thing in the sketch to decorate.
#[derive(Clone, Debug, PartialEq)]
pub struct Query {
    /// The element's own `id`, or `q-N` (N counting queries from 1).
    pub id: String,
    /// The `data-style` of the shape or its nearest ancestor, if any.
    pub style: Option<String>,
    /// The `data-seed` of the shape or its nearest ancestor: the seed of
    /// this query's choices in place of the run's (`None`: the run's).
    pub seed: Option<u64>,
    /// An open path's width along it (`data-widths`), user units: values
    /// at evenly spaced arc-length positions over the whole path, first at
    /// its start, last at its end, linear between; `None` when the width
    /// is the same all along (then it is [`QueryKind::Path`]'s `width`,
    /// which is otherwise the mean of these over the length).
    pub widths: Option<Vec<f64>>,
    /// Path or region, with its geometry.
    pub kind: QueryKind,
}

impl Query {
    /// The width of an open path at `share` (0 = start, 1 = end) of its
    /// length, user units; `None` for a region.
    pub fn width_at(&self, share: f64) -> Option<f64> {
        let QueryKind::Path { width, .. } = &self.kind else {
            return None;
        };
        Some(match &self.widths {
            Some(w) => profile_at(w, share),
            None => *width,
        })
    }
}

/// The value at `share` (clamped to 0..=1) of a profile of values at
/// evenly spaced positions, linear between them.
pub(crate) fn profile_at(values: &[f64], share: f64) -> f64 {
    match values {
        [] => 0.0,
        [one] => *one,
        _ => {
            let x = share.clamp(0.0, 1.0) * (values.len() - 1) as f64;
            let i = (x.floor() as usize).min(values.len() - 2);
            let f = x - i as f64;
            values[i] * (1.0 - f) + values[i + 1] * f
        }
    }
}

/// Parses a `data-widths` attribute: one or more widths (positive, finite
/// numbers separated by white space or commas) at evenly spaced positions
/// along the path's length (SPEC.md, "Sketch SVG"); the reason in words
/// when it is not one.
pub fn parse_widths(text: &str) -> std::result::Result<Vec<f64>, String> {
    let mut out = Vec::new();
    for t in text
        .split(|c: char| c.is_whitespace() || c == ',')
        .filter(|t| !t.is_empty())
    {
        match t.parse::<f64>() {
            Ok(v) if v.is_finite() && v > 0.0 => out.push(v),
            Ok(_) => return Err(format!("width {t:?} is not a positive finite number")),
            Err(_) => return Err(format!("{t:?} is not a number")),
        }
    }
    if out.is_empty() {
        return Err("no width given".into());
    }
    Ok(out)
}

/// The arc-length mean of a width profile ([`profile_at`]): the
/// trapezoid rule over its evenly spaced values; the value itself when
/// they are all equal.
fn profile_mean(values: &[f64]) -> f64 {
    match values {
        [] => 0.0,
        [one] => *one,
        [first, .., last] if values.iter().all(|v| v == first) => *last,
        [first, inner @ .., last] => {
            (0.5 * (first + last) + inner.iter().sum::<f64>()) / (values.len() - 1) as f64
        }
    }
}

impl Query {
    /// The outline (user units) and fill rule of a region query; `None`
    /// for an open path.
    pub fn region(&self) -> Option<(&BezPath, FillRule)> {
        match &self.kind {
            QueryKind::Region { outline, fill_rule } => Some((outline, *fill_rule)),
            QueryKind::Path { .. } => None,
        }
    }
}

/// A parsed sketch.
#[derive(Clone, Debug)]
pub struct Sketch {
    /// The `width` of the sketch, in user units of its viewport (px).
    pub width: f64,
    /// The `height` of the sketch, in px.
    pub height: f64,
    /// The sketch's `viewBox` (user units); `0 0 width height` when absent.
    pub view_box: Rect,
    /// The queries in document order.
    pub queries: Vec<Query>,
    /// The `data-exemplar` of a region (of the shape or its nearest
    /// ancestor), by query id.
    pub exemplars: BTreeMap<String, String>,
    /// Things ignored, one line each, for `--verbose`.
    pub notes: Vec<String>,
    /// Shapes the designer drew that cannot be used (no length, zero
    /// stroke width), one line each, printed unless `--quiet`.
    pub warnings: Vec<String>,
    /// The text it was read from and where each query's element stands in
    /// it, for an output that keeps the rest of the sketch; `None` for a
    /// sketch made in code.
    pub(crate) backdrop: Option<Arc<Backdrop>>,
    /// The warning that the sketch draws text an output without the
    /// sketch leaves out.
    pub(crate) text_left_out: Option<&'static str>,
}

impl Sketch {
    /// Parses sketch SVG bytes (plain or SVGZ): every visible shape
    /// becomes a query, in document order (SPEC.md, "Sketch SVG").
    pub fn from_svg(bytes: &[u8]) -> Result<Sketch> {
        parse(bytes)
    }

    /// A sketch made in code of open stroked paths (`spine`, `width` in
    /// px) on a `width`×`height` px page, queries `q-1`, `q-2`, … in
    /// order, no styles named.
    pub fn from_strokes(width: f64, height: f64, strokes: Vec<(BezPath, f64)>) -> Sketch {
        Sketch {
            width,
            height,
            view_box: Rect::new(0.0, 0.0, width, height),
            queries: strokes
                .into_iter()
                .enumerate()
                .map(|(i, (spine, width))| Query {
                    id: format!("q-{}", i + 1),
                    style: None,
                    seed: None,
                    widths: None,
                    kind: QueryKind::Path { spine, width },
                })
                .collect(),
            exemplars: BTreeMap::new(),
            notes: Vec::new(),
            warnings: Vec::new(),
            backdrop: None,
            text_left_out: None,
        }
    }

    /// CSS pixels per user unit: how large the sketch's units are drawn
    /// (3.78 for a sketch in millimetres, 1.33 in points, 1 in px). The
    /// mean of the two axes' scales when its aspect is not kept.
    pub fn px_per_unit(&self) -> f64 {
        let (vw, vh) = (self.view_box.width(), self.view_box.height());
        let k = ((self.width / vw) * (self.height / vh)).sqrt();
        if k.is_finite() && k > 0.0 {
            k
        } else {
            1.0
        }
    }

    /// The sketch with its user units scaled by `k`: every query's
    /// geometry and width, and the view box; the drawn size stays.
    pub(crate) fn scaled(&self, k: f64) -> Sketch {
        let to = kurbo::Affine::scale(k);
        let mut out = self.clone();
        out.view_box = Rect::new(
            k * self.view_box.x0,
            k * self.view_box.y0,
            k * self.view_box.x1,
            k * self.view_box.y1,
        );
        for q in &mut out.queries {
            match &mut q.kind {
                QueryKind::Path { spine, width } => {
                    spine.apply_affine(to);
                    *width *= k;
                    if let Some(w) = &mut q.widths {
                        w.iter_mut().for_each(|v| *v *= k);
                    }
                }
                QueryKind::Region { outline, .. } => outline.apply_affine(to),
            }
        }
        out
    }

    /// Widens the stroke queries of a sketch traced from a raster drawing
    /// (see [`DRAWN_WIDTH_SHARE`]): every width times one factor, so the
    /// median stroke (by count) becomes [`DRAWN_WIDTH_SHARE`] of the
    /// page's shorter side; lines already that wide, and sketches without
    /// strokes, stay. Returns the median width before and after (px) when
    /// it widened.
    pub(crate) fn widen_drawn_lines(&mut self) -> Option<(f64, f64)> {
        let mut widths: Vec<f64> = self
            .queries
            .iter()
            .filter_map(|q| match q.kind {
                QueryKind::Path { width, .. } => Some(width),
                QueryKind::Region { .. } => None,
            })
            .filter(|w| w.is_finite() && *w > 0.0)
            .collect();
        widths.sort_by(f64::total_cmp);
        let median = *widths.get(widths.len() / 2)?;
        let target = DRAWN_WIDTH_SHARE * self.width.min(self.height);
        let k = target / median;
        if !(k.is_finite() && k > 1.0) {
            return None;
        }
        for q in &mut self.queries {
            if let QueryKind::Path { width, .. } = &mut q.kind {
                *width *= k;
            }
            if let Some(w) = &mut q.widths {
                w.iter_mut().for_each(|v| *v *= k);
            }
        }
        Some((median, target))
    }
}

/// Share of the page's shorter side a raster drawing's median line is
/// widened to when it becomes a sketch without `--width`
/// ([`Sketch::widen_drawn_lines`]): a pencil line is 2–5 px wide on a
/// photo thousands of pixels across, which as an ornament's width gives
/// ornament too small to see at the page's size. A 24th of the shorter
/// side is about 9 mm on an A4 sheet, 25 px on a 600-px scan: near the
/// shipped brush sketches' widths (a 6th to a 12th of their shorter side,
/// one or two strokes each) scaled for a page holding a whole drawing.
/// The lines keep their widths relative to each other.
pub const DRAWN_WIDTH_SHARE: f64 = 1.0 / 24.0;

/// Reads and parses a sketch SVG file; errors name it.
#[cfg(test)]
pub fn load(path: &std::path::Path) -> Result<Sketch> {
    let data = crate::io::read_file(path)?;
    parse(&data).map_err(|e| e.in_file(path))
}

/// Parses sketch SVG bytes (plain or SVGZ).
pub fn parse(data: &[u8]) -> Result<Sketch> {
    let data = &*crate::read::svg::inflate_svgz(data)?;
    let text = std::str::from_utf8(data).map_err(|_| Error::Svg("not UTF-8 text".into()))?;
    let pre = preprocess(text)?;
    let tree = crate::read::svg::parse_svg(pre.text.as_bytes())?;
    let size = tree.size();
    let (width, height) = (size.width() as f64, size.height() as f64);
    let view_box = pre.view_box.unwrap_or(Rect::new(0.0, 0.0, width, height));
    // usvg maps the viewBox onto the viewport; undo it so queries are in
    // user units (SVG 1.1 §7.8, preserveAspectRatio).
    let to_user = viewport_to_user(view_box, width, height, &pre.aspect);
    let mut sketch = Sketch {
        width,
        height,
        view_box,
        queries: Vec::new(),
        exemplars: BTreeMap::new(),
        notes: Vec::new(),
        warnings: Vec::new(),
        backdrop: None,
        text_left_out: None,
    };
    let mut read = Read {
        styles: &pre.styles,
        exemplars: &pre.exemplars,
        seeds: &pre.seeds,
        widths: &pre.widths,
        elements: &pre.elements,
        placed: std::collections::BTreeSet::new(),
        backdrop: Backdrop {
            text: text.to_string(),
            end: pre.end,
            places: BTreeMap::new(),
        },
    };
    walk(tree.root(), to_user, &mut read, &mut sketch)?;
    if sketch.queries.len() > MAX_QUERIES {
        return Err(Error::invalid(format!(
            "{} shapes to decorate, more than the limit of {MAX_QUERIES}",
            sketch.queries.len()
        )));
    }
    sketch.backdrop = Some(Arc::new(read.backdrop));
    sketch.text_left_out = crate::read::svg::text_left_out(data);
    Ok(sketch)
}

struct Preprocessed {
    text: String,
    view_box: Option<Rect>,
    aspect: String,
    /// element id → data-style
    styles: BTreeMap<String, String>,
    /// element id → data-exemplar
    exemplars: BTreeMap<String, String>,
    /// element id → data-seed (of the shape or its nearest ancestor)
    seeds: BTreeMap<String, String>,
    /// element id → data-widths (of the shape itself)
    widths: BTreeMap<String, String>,
    /// element id → where it stands in the text, for elements that can be
    /// replaced in place (drawn where they stand, their id unique)
    elements: BTreeMap<String, Element>,
    /// byte offset of the root's closing tag
    end: usize,
}

/// A shape element of the sketch's text.
struct Element {
    /// Its bytes, start tag to end tag.
    range: std::ops::Range<usize>,
    /// Its `transform` attribute as written.
    transform: Option<String>,
}

/// What the walk over usvg's tree reads from and writes to besides the
/// sketch.
struct Read<'a> {
    styles: &'a BTreeMap<String, String>,
    exemplars: &'a BTreeMap<String, String>,
    seeds: &'a BTreeMap<String, String>,
    widths: &'a BTreeMap<String, String>,
    elements: &'a BTreeMap<String, Element>,
    /// The elements a query has already taken the place of.
    placed: std::collections::BTreeSet<String>,
    backdrop: Backdrop,
}

/// Elements whose content is drawn only where it is used, elsewhere.
const REFERENCED: [&str; 6] = ["defs", "symbol", "clipPath", "mask", "pattern", "marker"];

const SHAPES: [&str; 7] = [
    "path", "rect", "circle", "ellipse", "line", "polyline", "polygon",
];

/// Reads `viewBox`, `preserveAspectRatio` and `data-style` from the raw XML
/// and gives styled shapes without an id a private one.
fn preprocess(text: &str) -> Result<Preprocessed> {
    let doc = crate::read::svg::parse_xml(text)?;
    let root = doc.root_element();
    let view_box = root.attribute("viewBox").and_then(parse_view_box);
    let aspect = root
        .attribute("preserveAspectRatio")
        .unwrap_or("xMidYMid meet")
        .to_string();
    let mut styles = BTreeMap::new();
    let mut exemplars = BTreeMap::new();
    let mut seeds = BTreeMap::new();
    let mut widths = BTreeMap::new();
    let mut elements = BTreeMap::new();
    let mut seen = std::collections::BTreeSet::new();
    let mut twice = std::collections::BTreeSet::new();
    // (byte offset just after the tag name, id to insert)
    let mut inserts: Vec<(usize, String)> = Vec::new();
    for node in root.descendants().filter(|n| n.is_element()) {
        if let Some(id) = node.attribute("id") {
            // An id given twice names no one element.
            if !seen.insert(id) {
                twice.insert(id.to_string());
                elements.remove(id);
            }
        }
        if !SHAPES.contains(&node.tag_name().name()) {
            continue;
        }
        let inherited = |name: &str| {
            node.ancestors()
                .filter(|a| a.is_element())
                .find_map(|a| a.attribute(name))
        };
        let (style, exemplar) = (inherited("data-style"), inherited("data-exemplar"));
        let id = match node.attribute("id") {
            Some(id) if !id.is_empty() => id.to_string(),
            _ => {
                let id = format!("{PRIVATE_ID}{}", inserts.len());
                let start = node.range().start;
                // `<` + tag name as written (with any prefix).
                let tag_len = text[start + 1..]
                    .find(|c: char| c.is_whitespace() || c == '/' || c == '>')
                    .unwrap_or(0);
                inserts.push((start + 1 + tag_len, id.clone()));
                id
            }
        };
        if let Some(e) = exemplar {
            exemplars.insert(id.clone(), e.to_string());
        }
        if let Some(style) = style {
            styles.insert(id.clone(), style.to_string());
        }
        if let Some(seed) = inherited("data-seed") {
            seeds.insert(id.clone(), seed.to_string());
        }
        if let Some(w) = node.attribute("data-widths") {
            widths.insert(id.clone(), w.to_string());
        }
        let referenced = node
            .ancestors()
            .any(|a| REFERENCED.contains(&a.tag_name().name()));
        if !referenced && !twice.contains(&id) {
            elements.insert(
                id,
                Element {
                    range: node.range(),
                    transform: node.attribute("transform").map(str::to_string),
                },
            );
        }
    }
    let mut out = String::with_capacity(text.len() + inserts.len() * 24);
    let mut last = 0;
    for (at, id) in &inserts {
        out.push_str(&text[last..*at]);
        out.push_str(&format!(" id=\"{id}\""));
        last = *at;
    }
    out.push_str(&text[last..]);
    Ok(Preprocessed {
        text: out,
        view_box,
        aspect,
        styles,
        exemplars,
        seeds,
        widths,
        elements,
        end: closing_tag(text, root.range()),
    })
}

/// The byte offset of the closing tag of the element spanning `range` (its
/// end when it closes itself).
fn closing_tag(text: &str, range: std::ops::Range<usize>) -> usize {
    let own = &text[range.clone()];
    if own.ends_with("/>") {
        return range.end;
    }
    own.rfind("</").map_or(range.end, |i| range.start + i)
}

fn parse_view_box(s: &str) -> Option<Rect> {
    let v: Vec<f64> = s
        .split(|c: char| c.is_whitespace() || c == ',')
        .filter(|t| !t.is_empty())
        .map(|t| t.parse::<f64>())
        .collect::<Result<_, _>>()
        .ok()?;
    if v.len() != 4 || !v.iter().all(|x| x.is_finite()) || v[2] <= 0.0 || v[3] <= 0.0 {
        return None;
    }
    Some(Rect::new(v[0], v[1], v[0] + v[2], v[1] + v[3]))
}

/// The inverse of the viewBox → viewport mapping of SVG 1.1 §7.8.
fn viewport_to_user(vb: Rect, width: f64, height: f64, aspect: &str) -> Affine {
    let (sx, sy) = (width / vb.width(), height / vb.height());
    let words: Vec<&str> = aspect
        .split_whitespace()
        .filter(|w| *w != "defer")
        .collect();
    let align = words.first().copied().unwrap_or("xMidYMid");
    let slice = words.get(1) == Some(&"slice");
    let to_viewport = if align == "none" {
        Affine::new([sx, 0.0, 0.0, sy, -vb.x0 * sx, -vb.y0 * sy])
    } else {
        let s = if slice { sx.max(sy) } else { sx.min(sy) };
        let fx = if align.starts_with("xMin") {
            0.0
        } else if align.starts_with("xMax") {
            1.0
        } else {
            0.5
        };
        let fy = if align.ends_with("YMin") {
            0.0
        } else if align.ends_with("YMax") {
            1.0
        } else {
            0.5
        };
        let tx = -vb.x0 * s + (width - vb.width() * s) * fx;
        let ty = -vb.y0 * s + (height - vb.height() * s) * fy;
        Affine::new([s, 0.0, 0.0, s, tx, ty])
    };
    to_viewport.inverse()
}

fn walk(group: &usvg::Group, to_user: Affine, read: &mut Read, sk: &mut Sketch) -> Result<()> {
    for node in group.children() {
        match node {
            usvg::Node::Group(g) => walk(g, to_user, read, sk)?,
            usvg::Node::Image(_) => sk.notes.push("an image is ignored".into()),
            usvg::Node::Text(_) => sk.notes.push("a text element is ignored".into()),
            usvg::Node::Path(p) => add_path(p, to_user, read, sk)?,
        }
    }
    Ok(())
}

impl Read<'_> {
    /// Records that query `id` was read from element `element`, drawn
    /// with `to_user`: the first query of an element takes its place (a
    /// `<use>` may draw it again elsewhere).
    fn place(&mut self, id: &str, element: &str, to_user: Affine) {
        let Some(el) = self.elements.get(element) else {
            return;
        };
        if !self.placed.insert(element.to_string()) {
            return;
        }
        self.backdrop.places.insert(
            id.to_string(),
            Place {
                range: el.range.clone(),
                transform: el.transform.clone(),
                to_user,
            },
        );
    }
}

fn add_path(p: &usvg::Path, to_user: Affine, read: &mut Read, sk: &mut Sketch) -> Result<()> {
    let label = if p.id().is_empty() || p.id().starts_with(PRIVATE_ID) {
        "an unnamed shape".to_string()
    } else {
        format!("shape {}", p.id())
    };
    if !p.is_visible() {
        sk.notes.push(format!("{label} is invisible and ignored"));
        return Ok(());
    }
    let abs = to_user * affine_of(p.abs_transform());
    let geom = abs * to_bezpath(p.data(), usvg::Transform::identity());
    let hull = geom.control_box();
    let far = [hull.x0, hull.y0, hull.x1, hull.y1]
        .into_iter()
        .find(|v| v.is_nan() || v.abs() > MAX_COORD);
    if let Some(v) = far.filter(|_| !geom.elements().is_empty()) {
        sk.warnings.push(format!(
            "{label} has a coordinate of {v:e}, beyond ±{MAX_COORD:e} units, and is skipped"
        ));
        return Ok(());
    }
    if geom.elements().is_empty() || geom.bounding_box().area() == 0.0 && geom.perimeter(0.1) == 0.0
    {
        sk.warnings
            .push(format!("{label} has no length and is skipped"));
        return Ok(());
    }
    let n = sk.queries.len() + 1;
    let id = if p.id().is_empty() || p.id().starts_with(PRIVATE_ID) {
        format!("q-{n}")
    } else {
        p.id().to_string()
    };
    let style = read.styles.get(p.id()).cloned();
    let seed = match read.seeds.get(p.id()) {
        Some(t) => Some(t.trim().parse::<u64>().map_err(|_| {
            Error::invalid(format!(
                "shape {id}: data-seed {t:?} is not a whole number from 0 to {}",
                u64::MAX
            ))
        })?),
        None => None,
    };
    read.place(&id, p.id(), abs);
    if let Some(fill) = p.fill() {
        let fill_rule = match fill.rule() {
            usvg::FillRule::NonZero => FillRule::NonZero,
            usvg::FillRule::EvenOdd => FillRule::EvenOdd,
        };
        if let Some(e) = read.exemplars.get(p.id()) {
            sk.exemplars.insert(id.clone(), e.clone());
        }
        if read.widths.contains_key(p.id()) {
            sk.notes
                .push(format!("shape {id} is filled; its data-widths are ignored"));
        }
        sk.queries.push(Query {
            id,
            style,
            seed,
            widths: None,
            kind: QueryKind::Region {
                outline: geom,
                fill_rule,
            },
        });
    } else if let Some(stroke) = p.stroke() {
        // Stroke width is scaled like lengths under the (near-uniform)
        // transform: by the square root of its determinant.
        let scale = abs.determinant().abs().sqrt();
        let width = stroke.width().get() as f64 * scale;
        if width.is_nan() || width <= 0.0 {
            sk.warnings
                .push(format!("{label} has a zero stroke width and is skipped"));
            return Ok(());
        }
        // data-widths are scaled like the stroke width and replace it: the
        // path's width is then their mean over its length.
        let (width, widths) = match read.widths.get(p.id()) {
            Some(t) => {
                let mut w = parse_widths(t)
                    .map_err(|r| Error::invalid(format!("shape {id}: data-widths: {r}")))?;
                w.iter_mut().for_each(|v| *v *= scale);
                if w.iter().any(|v| !(v.is_finite() && *v > 0.0)) {
                    return Err(Error::invalid(format!(
                        "shape {id}: data-widths: a width is out of range once transformed"
                    )));
                }
                let mean = profile_mean(&w);
                (mean, w.iter().any(|v| *v != mean).then_some(w))
            }
            None => (width, None),
        };
        sk.queries.push(Query {
            id,
            style,
            seed,
            widths,
            kind: QueryKind::Path { spine: geom, width },
        });
    } else {
        sk.notes.push(format!(
            "{label} has neither fill nor stroke and is ignored"
        ));
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    /// One factor widens every stroke until the median one is
    /// [`DRAWN_WIDTH_SHARE`] of the shorter side; wide lines stay.
    #[test]
    fn drawn_lines_are_widened_together_to_the_page_share() {
        let line = |y: f64| {
            BezPath::from_vec(vec![
                kurbo::PathEl::MoveTo((10.0, y).into()),
                kurbo::PathEl::LineTo((200.0, y).into()),
            ])
        };
        let mut sk = Sketch::from_strokes(
            600.0,
            480.0,
            vec![(line(10.0), 2.0), (line(50.0), 4.0), (line(90.0), 3.0)],
        );
        let (from, to) = sk.widen_drawn_lines().expect("widened");
        assert_eq!((from, to), (3.0, 20.0));
        let got: Vec<f64> = sk
            .queries
            .iter()
            .filter_map(|q| match q.kind {
                QueryKind::Path { width, .. } => Some(width),
                QueryKind::Region { .. } => None,
            })
            .collect();
        let want = [2.0, 4.0, 3.0].map(|w| w * 20.0 / 3.0);
        for (g, w) in got.iter().zip(want) {
            assert!((g - w).abs() < 1e-12, "{got:?}");
        }
        let mut wide = Sketch::from_strokes(600.0, 480.0, vec![(line(10.0), 30.0)]);
        assert_eq!(wide.widen_drawn_lines(), None);
        let mut empty = Sketch::from_strokes(600.0, 480.0, Vec::new());
        assert_eq!(empty.widen_drawn_lines(), None);
    }

    #[test]
    fn classifies_paths_and_regions() {
        let svg = r##"<svg xmlns="http://www.w3.org/2000/svg" width="200" height="100" viewBox="0 0 400 200">
            <path id="spine" d="M10 10 L300 10" stroke="#000" stroke-width="8" fill="none"/>
            <g data-style="stipple"><rect x="10" y="50" width="100" height="100" fill="#f00"/></g>
            <circle cx="300" cy="100" r="40" fill="none" stroke="none"/>
        </svg>"##;
        let s = parse(svg.as_bytes()).unwrap();
        assert_eq!(s.view_box, Rect::new(0.0, 0.0, 400.0, 200.0));
        assert_eq!(s.queries.len(), 2);
        assert_eq!(s.queries[0].id, "spine");
        match &s.queries[0].kind {
            QueryKind::Path { width, spine } => {
                assert!((width - 8.0).abs() < 1e-4, "{width}");
                let bb = spine.bounding_box();
                assert!((bb.x1 - 300.0).abs() < 1e-3, "user units kept: {bb:?}");
            }
            k => panic!("{k:?}"),
        }
        assert_eq!(s.queries[1].id, "q-2");
        assert_eq!(s.queries[1].style.as_deref(), Some("stipple"));
        assert!(matches!(s.queries[1].kind, QueryKind::Region { .. }));
        assert!(s.exemplars.is_empty());
    }

    #[test]
    fn a_region_may_pin_an_exemplar() {
        let svg = r##"<svg xmlns="http://www.w3.org/2000/svg" width="200" height="100">
            <g data-exemplar="b.svg"><rect x="10" y="10" width="50" height="50" fill="#f00"/></g>
            <circle id="c" cx="150" cy="50" r="30" fill="#00f" data-exemplar="a.svg" data-style="s"/>
            <rect x="80" y="10" width="20" height="20" fill="#0f0"/>
        </svg>"##;
        let s = parse(svg.as_bytes()).unwrap();
        assert_eq!(s.queries.len(), 3);
        assert_eq!(s.exemplars.get("q-1").map(String::as_str), Some("b.svg"));
        assert_eq!(s.exemplars.get("c").map(String::as_str), Some("a.svg"));
        assert_eq!(s.queries[1].style.as_deref(), Some("s"));
        assert!(!s.exemplars.contains_key("q-3"));
    }

    /// `data-widths` are scaled like the stroke width, their mean over the
    /// length becomes the path's width, equal widths are none, and a
    /// group's `data-seed` reaches its shapes.
    #[test]
    fn data_widths_and_seeds_are_read() {
        let svg = r##"<svg xmlns="http://www.w3.org/2000/svg" width="200" height="100">
            <g transform="scale(2)" data-seed="9">
              <path id="a" d="M10 10 L90 10" stroke="#000" stroke-width="5" fill="none" data-widths="2, 4 8"/>
            </g>
            <path id="b" d="M10 50 L190 50" stroke="#000" stroke-width="5" fill="none" data-widths="6 6 6" data-seed="3"/>
            <rect id="c" x="10" y="60" width="20" height="20" fill="#000" data-widths="1 2"/>
        </svg>"##;
        let s = parse(svg.as_bytes()).unwrap();
        let q = &s.queries;
        assert_eq!(q[0].widths, Some(vec![4.0, 8.0, 16.0]));
        assert!(matches!(q[0].kind, QueryKind::Path { width, .. } if (width - 9.0).abs() < 1e-12));
        assert_eq!(q[0].width_at(0.25), Some(6.0));
        assert_eq!(q[0].seed, Some(9));
        assert_eq!(q[1].widths, None);
        assert!(matches!(q[1].kind, QueryKind::Path { width, .. } if width == 6.0));
        assert_eq!(q[1].seed, Some(3));
        assert_eq!(q[2].widths, None);
        assert!(s
            .notes
            .iter()
            .any(|n| n.contains("shape c") && n.contains("data-widths")));
        assert_eq!(profile_at(&[1.0, 3.0], 2.0), 3.0);
        assert_eq!(profile_mean(&[1.0, 3.0, 1.0]), 2.0);
    }

    /// A shape whose coordinates run past `MAX_COORD` (an arc of 1e308, a
    /// point at 3.4e38) is skipped with a warning before anything is
    /// measured on it; the rest of the sketch stays.
    #[test]
    fn far_coordinates_are_skipped_with_a_warning() {
        let svg = r##"<svg xmlns="http://www.w3.org/2000/svg" width="100" height="100">
            <path d="M10 10 L3.4e38 20" stroke="#000" stroke-width="2" fill="none"/>
            <path d="M10 10 A1e308 1e308 0 0 1 1e308 30" fill="#000"/>
            <path d="M10 50 L90 50" stroke="#000" stroke-width="2" fill="none"/>
        </svg>"##;
        let s = parse(svg.as_bytes()).unwrap();
        assert_eq!(s.queries.len(), 1, "{:?}", s.warnings);
        assert!(
            s.warnings
                .iter()
                .any(|w| w.contains("3.39") && w.contains("beyond")),
            "{:?}",
            s.warnings
        );
    }
}
