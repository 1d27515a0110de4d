//! The SVG writer: documents of groups of filled (or stroked) Bézier paths,
//! written compactly.
//!
//! Path data uses relative commands (`m c l z`), implicit command
//! repetition, and coordinates quantized to a fixed number of decimals
//! chosen from the geometry's tolerance. Quantization happens on absolute
//! coordinates first and relative offsets are differences of quantized
//! integers, so rounding never accumulates along a path.

use kurbo::{Affine, BezPath, PathEl, Point, Rect};
use std::collections::BTreeMap;
use std::fmt::Write as _;
use std::ops::Range;
use std::sync::Arc;

/// An sRGB colour, 8 bits per channel.
#[derive(
    Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord, serde::Serialize, serde::Deserialize,
)]
pub struct Color {
    /// Red, 0–255.
    pub r: u8,
    /// Green, 0–255.
    pub g: u8,
    /// Blue, 0–255.
    pub b: u8,
}

impl Color {
    /// Black, the default ink.
    pub const BLACK: Color = Color { r: 0, g: 0, b: 0 };

    /// A colour from its three channels.
    pub const fn rgb(r: u8, g: u8, b: u8) -> Self {
        Color { r, g, b }
    }

    /// The colour as SVG wants it: `#rgb` when that is exact, else `#rrggbb`.
    pub fn to_hex(self) -> String {
        let short = |c: u8| c.is_multiple_of(17);
        if short(self.r) && short(self.g) && short(self.b) {
            format!("#{:x}{:x}{:x}", self.r / 17, self.g / 17, self.b / 17)
        } else {
            format!("#{:02x}{:02x}{:02x}", self.r, self.g, self.b)
        }
    }
}

/// How the interior of a path with several subpaths is decided.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum FillRule {
    /// Non-zero winding: holes must wind the other way (the tracer does).
    #[default]
    NonZero,
    /// Even-odd parity.
    EvenOdd,
}

/// A stroke: colour and width in user units.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Stroke {
    /// Stroke colour.
    pub color: Color,
    /// Stroke width in user units.
    pub width: f64,
    /// Line cap: `butt`, `round` or `square`.
    pub cap: LineCap,
    /// Line join: `miter`, `round` or `bevel`.
    pub join: LineJoin,
}

/// SVG `stroke-linecap`.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum LineCap {
    /// Flat end at the endpoint (SVG default).
    #[default]
    Butt,
    /// Half-disc end.
    Round,
    /// Half-square end.
    Square,
}

/// SVG `stroke-linejoin`.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum LineJoin {
    /// Sharp join (SVG default).
    #[default]
    Miter,
    /// Rounded join.
    Round,
    /// Cut-off join.
    Bevel,
}

/// One `<path>` element.
#[derive(Clone, Debug, PartialEq)]
pub struct Shape {
    /// Geometry in user units.
    pub path: BezPath,
    /// Fill colour, or `None` for `fill="none"`.
    pub fill: Option<Color>,
    /// Fill rule for paths with several subpaths.
    pub fill_rule: FillRule,
    /// Optional stroke.
    pub stroke: Option<Stroke>,
    /// Opacity in 0..=1 (1 is not written).
    pub opacity: f64,
}

impl Shape {
    /// A filled shape with the non-zero rule and no stroke.
    pub fn filled(path: BezPath, fill: Color) -> Self {
        Shape {
            path,
            fill: Some(fill),
            fill_rule: FillRule::NonZero,
            stroke: None,
            opacity: 1.0,
        }
    }
}

/// One `<g>` element: a query's output or one colour layer.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Group {
    /// The group's `id` (written only when non-empty).
    pub id: String,
    /// The paths, in drawing order.
    pub shapes: Vec<Shape>,
}

/// A whole output document.
#[derive(Clone, Debug, PartialEq)]
pub struct Document {
    /// `width` attribute, in user units.
    pub width: f64,
    /// `height` attribute, in user units.
    pub height: f64,
    /// The `viewBox`.
    pub view_box: Rect,
    /// Groups in drawing order.
    pub groups: Vec<Group>,
    /// Decimals written for coordinates: enough that rounding moves a
    /// point by at most a tenth of the tracing tolerance.
    pub decimals: u32,
    /// The sketch the groups are laid over, when the output keeps it.
    pub(crate) backdrop: Option<Arc<Backdrop>>,
}

/// A sketch's own SVG text, and where the element of each query stands in
/// it: what an output that keeps the sketch is written into.
#[derive(Clone, Debug, Default, PartialEq)]
pub(crate) struct Backdrop {
    /// The sketch's SVG text (SVGZ inflated).
    pub(crate) text: String,
    /// Byte offset of the root element's closing tag: where ornament that
    /// has no place of its own goes.
    pub(crate) end: usize,
    /// By query id, the element the query was read from.
    pub(crate) places: BTreeMap<String, Place>,
}

/// Where a query's element stands in its sketch's text.
#[derive(Clone, Debug, PartialEq)]
pub(crate) struct Place {
    /// Its bytes, start tag to end tag.
    pub(crate) range: Range<usize>,
    /// Its `transform` attribute as written, if any.
    pub(crate) transform: Option<String>,
    /// Its own coordinates (with that transform) to the sketch's user
    /// units.
    pub(crate) to_user: Affine,
}

/// Most `<path>` elements an output holds before the shapes of a group
/// that look alike are merged (renderers refuse documents of a million
/// elements; rsvg's limit).
pub const MAX_ELEMENTS: usize = 200_000;

impl Document {
    /// The document with its drawing scaled by `f` and its view box set
    /// to `view_box`: every path and stroke width, with the decimals
    /// that keep the same precision.
    pub(crate) fn rescaled(mut self, f: f64, view_box: Rect) -> Document {
        let to = kurbo::Affine::scale(f);
        for g in &mut self.groups {
            for s in &mut g.shapes {
                s.path.apply_affine(to);
                if let Some(st) = &mut s.stroke {
                    st.width *= f;
                }
            }
        }
        self.view_box = view_box;
        let more = (-f.log10()).ceil();
        if more.is_finite() && more > 0.0 {
            self.decimals = (self.decimals + more as u32).min(15);
        }
        self
    }

    /// Merges the shapes of each group that share fill, fill rule, stroke
    /// and opacity into one path each, when the document holds more than
    /// `MAX_ELEMENTS` (200 000) shapes; returns the note saying so, if it did. The
    /// drawing is unchanged: the shapes' subpaths keep their own
    /// orientation, so holes stay holes under their fill rule.
    pub fn merge_past_limit(&mut self) -> Option<String> {
        let before: usize = self.groups.iter().map(|g| g.shapes.len()).sum();
        if before <= MAX_ELEMENTS {
            return None;
        }
        for g in &mut self.groups {
            let mut merged: Vec<Shape> = Vec::new();
            for s in g.shapes.drain(..) {
                match merged.iter_mut().find(|m| m.looks_like(&s)) {
                    Some(m) => m.path.extend(s.path),
                    None => merged.push(s),
                }
            }
            g.shapes = merged;
        }
        let after: usize = self.groups.iter().map(|g| g.shapes.len()).sum();
        Some(format!(
            "{before} shapes merged into {after} paths (one per colour and group), under the limit of {MAX_ELEMENTS} elements"
        ))
    }
}

impl Shape {
    /// Whether `other` is painted the same way (fill, rule, stroke,
    /// opacity), so both can be one path.
    fn looks_like(&self, other: &Shape) -> bool {
        self.fill == other.fill
            && self.fill_rule == other.fill_rule
            && self.stroke == other.stroke
            && self.opacity == other.opacity
    }
}

/// What a mode makes of its input: the document, and what to tell the
/// user about it.
#[derive(Clone, Debug)]
pub struct Output {
    /// The output SVG document (the size and viewBox of the input).
    pub document: Document,
    /// What the input held that the output leaves out, one line each (the
    /// command line prints them unless `--quiet`).
    pub warnings: Vec<String>,
    /// How the input was read and made, one line each (the command line
    /// prints them under `--verbose`).
    pub notes: Vec<String>,
}

impl Output {
    /// A document with nothing to tell.
    pub fn new(document: Document) -> Self {
        Output {
            document,
            warnings: Vec::new(),
            notes: Vec::new(),
        }
    }

    /// The document as SVG text.
    pub fn to_svg(&self) -> String {
        self.document.to_svg()
    }
}

/// The number of decimals needed so that rounding moves a point by at most a
/// tenth of `tolerance` (both in user units), clamped to 0..=6.
pub fn decimals_for(tolerance: f64) -> u32 {
    if !(tolerance.is_finite() && tolerance > 0.0) {
        return 3;
    }
    let d = (-(tolerance / 10.0).log10()).ceil();
    d.clamp(0.0, 6.0) as u32
}

impl Document {
    /// An empty document of the given size whose viewBox is `0 0 w h`.
    pub fn new(width: f64, height: f64, decimals: u32) -> Self {
        Document {
            width,
            height,
            view_box: Rect::new(0.0, 0.0, width, height),
            groups: Vec::new(),
            decimals,
            backdrop: None,
        }
    }

    /// Number of drawing segments (lines and curves) in all paths, the
    /// figure compared with potrace.
    pub fn segment_count(&self) -> usize {
        self.groups
            .iter()
            .flat_map(|g| &g.shapes)
            .map(|s| count_segments(&s.path))
            .sum()
    }

    /// Serializes the document: on its own, or laid over the sketch it
    /// keeps, each group in place of the shape it decorates.
    pub fn to_svg(&self) -> String {
        if let Some(b) = &self.backdrop {
            return self.laid_over(b);
        }
        let mut out = String::with_capacity(4096);
        let vb = &self.view_box;
        // Sizes keep four significant digits however small the document
        // (a size rounded to 0 is an SVG renderers refuse).
        let smallest = [self.width, self.height, vb.width(), vb.height()]
            .into_iter()
            .filter(|v| *v > 0.0 && v.is_finite())
            .fold(f64::INFINITY, f64::min);
        let needed = if smallest.is_finite() {
            (4.0 - smallest.log10().floor() - 1.0).clamp(0.0, 15.0) as u32
        } else {
            0
        };
        let d = self.decimals.max(2).max(needed);
        let _ = writeln!(
            out,
            "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"{}\" height=\"{}\" viewBox=\"{} {} {} {}\">",
            fmt_num(self.width, d),
            fmt_num(self.height, d),
            fmt_num(vb.x0, d),
            fmt_num(vb.y0, d),
            fmt_num(vb.width(), d),
            fmt_num(vb.height(), d),
        );
        for g in &self.groups {
            if g.id.is_empty() {
                out.push_str("<g>\n");
            } else {
                let _ = writeln!(out, "<g id=\"{}\">", escape_attr(&g.id));
            }
            self.write_shapes(&g.shapes, d, &mut out);
            out.push_str("</g>\n");
        }
        out.push_str("</svg>\n");
        out
    }

    /// Writes `shapes` as `<path>` elements, stroke widths with `d`
    /// decimals.
    fn write_shapes(&self, shapes: &[Shape], d: u32, out: &mut String) {
        for s in shapes {
            let data = path_data(&s.path, self.decimals);
            if data.is_empty() {
                continue;
            }
            out.push_str("<path");
            match s.fill {
                Some(c) => {
                    let _ = write!(out, " fill=\"{}\"", c.to_hex());
                    let rule = match s.fill_rule {
                        FillRule::NonZero => "nonzero",
                        FillRule::EvenOdd => "evenodd",
                    };
                    let _ = write!(out, " fill-rule=\"{rule}\"");
                }
                None => out.push_str(" fill=\"none\""),
            }
            if let Some(st) = &s.stroke {
                let _ = write!(
                    out,
                    " stroke=\"{}\" stroke-width=\"{}\"",
                    st.color.to_hex(),
                    fmt_num(st.width, d)
                );
                match st.cap {
                    LineCap::Butt => {}
                    LineCap::Round => out.push_str(" stroke-linecap=\"round\""),
                    LineCap::Square => out.push_str(" stroke-linecap=\"square\""),
                }
                match st.join {
                    LineJoin::Miter => {}
                    LineJoin::Round => out.push_str(" stroke-linejoin=\"round\""),
                    LineJoin::Bevel => out.push_str(" stroke-linejoin=\"bevel\""),
                }
            }
            if s.opacity < 1.0 {
                let _ = write!(out, " opacity=\"{}\"", fmt_num(s.opacity.max(0.0), 3));
            }
            let _ = writeln!(out, " d=\"{data}\"/>");
        }
    }

    /// The backdrop's text with each group in place of its query's
    /// element, wrapped in the inverse of that element's placement so the
    /// group's user-unit paths land where the element was drawn; groups
    /// without a place go last, before the root's closing tag. Paint that
    /// the group would inherit from its ancestors is reset.
    fn laid_over(&self, b: &Backdrop) -> String {
        const RESET: &str =
            "fill-opacity=\"1\" stroke=\"none\" stroke-opacity=\"1\" stroke-dasharray=\"none\"";
        let d = self.decimals.max(2);
        let mut placed: Vec<(Range<usize>, String)> = Vec::new();
        let mut last = String::new();
        for g in &self.groups {
            let id = if g.id.is_empty() {
                String::new()
            } else {
                format!(" id=\"{}\"", escape_attr(&g.id))
            };
            let place = b
                .places
                .get(&g.id)
                .filter(|p| p.to_user.determinant().abs() > 1e-12);
            let mut text = String::new();
            match place {
                Some(p) => {
                    // The placement is read in single precision: six
                    // decimals of its linear part and four of its offset
                    // (in user units) hold all it knows.
                    let c = p.to_user.inverse().as_coeffs();
                    let m: Vec<String> = (0..6)
                        .map(|i| fmt_num(c[i], if i < 4 { 6 } else { 4 }))
                        .collect();
                    let matrix = if m == ["1", "0", "0", "1", "0", "0"] {
                        String::new()
                    } else {
                        format!(" transform=\"matrix({})\"", m.join(" "))
                    };
                    let mut close = "</g>";
                    // The element's own transform, as written, then the
                    // inverse of where it placed the element.
                    match &p.transform {
                        Some(t) if matrix.is_empty() => {
                            let t = escape_attr(t);
                            let _ = writeln!(text, "<g{id} transform=\"{t}\" {RESET}>");
                        }
                        Some(t) => {
                            let t = escape_attr(t);
                            let _ = writeln!(text, "<g{id} transform=\"{t}\" {RESET}><g{matrix}>");
                            close = "</g></g>";
                        }
                        None => {
                            let _ = writeln!(text, "<g{id}{matrix} {RESET}>");
                        }
                    }
                    self.write_shapes(&g.shapes, d, &mut text);
                    text.push_str(close);
                    placed.push((p.range.clone(), text));
                }
                None => {
                    let _ = writeln!(last, "<g{id} {RESET}>");
                    self.write_shapes(&g.shapes, d, &mut last);
                    last.push_str("</g>\n");
                }
            }
        }
        placed.sort_by_key(|(r, _)| r.start);
        let mut out = String::with_capacity(
            b.text.len() + placed.iter().map(|p| p.1.len()).sum::<usize>() + last.len(),
        );
        let mut at = 0;
        for (r, text) in &placed {
            if r.start < at || r.end > b.end {
                continue;
            }
            out.push_str(&b.text[at..r.start]);
            out.push_str(text);
            at = r.end;
        }
        out.push_str(&b.text[at..b.end]);
        out.push_str(&last);
        out.push_str(&b.text[b.end..]);
        out
    }
}

fn escape_attr(s: &str) -> String {
    s.replace('&', "&amp;")
        .replace('"', "&quot;")
        .replace('<', "&lt;")
        .replace('>', "&gt;")
}

/// Number of lines and curves in a path (moves and closes excluded).
pub fn count_segments(path: &BezPath) -> usize {
    path.elements()
        .iter()
        .filter(|e| {
            matches!(
                e,
                PathEl::LineTo(_) | PathEl::QuadTo(..) | PathEl::CurveTo(..)
            )
        })
        .count()
}

/// Formats `v` with at most `decimals` decimals, trailing zeros and a
/// leading zero dropped (`0.5` → `.5`).
pub fn fmt_num(v: f64, decimals: u32) -> String {
    let scale = 10f64.powi(decimals as i32);
    let q = (v * scale).round();
    fmt_fixed(q as i64, decimals)
}

/// Formats the integer `q` as a decimal with `decimals` implied decimals.
fn fmt_fixed(q: i64, decimals: u32) -> String {
    let mut s = String::new();
    push_fixed(&mut s, q, decimals, 10u64.pow(decimals));
    s
}

/// Appends `q / 10^decimals` to `out` in the compact form of [`fmt_fixed`],
/// writing the digits straight into `out` (no intermediate `String`);
/// `scale` is `10^decimals`.
fn push_fixed(out: &mut String, q: i64, decimals: u32, scale: u64) {
    let a = q.unsigned_abs();
    let int = a / scale;
    let mut frac = a % scale;
    if q < 0 && a != 0 {
        out.push('-');
    }
    if int != 0 || frac == 0 {
        push_digits(out, int, 1);
    }
    if frac != 0 {
        let mut digits = decimals as usize;
        while frac.is_multiple_of(10) {
            frac /= 10;
            digits -= 1;
        }
        out.push('.');
        push_digits(out, frac, digits);
    }
}

/// Appends the decimal digits of `v` to `out`, left-padded with zeros to at
/// least `min_digits` digits.
fn push_digits(out: &mut String, mut v: u64, min_digits: usize) {
    let mut buf = [b'0'; 20];
    let mut n = 0;
    while (v != 0 || n < min_digits) && n < buf.len() {
        buf[n] = b'0' + (v % 10) as u8;
        v /= 10;
        n += 1;
    }
    for &b in buf.iter().take(n).rev() {
        out.push(char::from(b));
    }
}

/// Appends numbers to path data with the fewest separators SVG allows.
struct DataWriter {
    out: String,
    last_cmd: Option<char>,
    last_has_dot: bool,
    decimals: u32,
    /// `10^decimals`: one unit of the written numbers' last digit.
    scale: u64,
}

impl DataWriter {
    fn cmd(&mut self, c: char) {
        // `m` is followed by implicit `l`s; other commands repeat themselves.
        let implicit = match self.last_cmd {
            Some('m') => c == 'l',
            Some(prev) => prev == c && c != 'z' && c != 'm',
            None => false,
        };
        if !implicit {
            self.out.push(c);
            self.last_has_dot = false;
        }
        self.last_cmd = Some(c);
        if c == 'z' {
            self.last_cmd = Some('z');
        }
    }

    fn num(&mut self, q: i64) {
        // The text's first character and whether it has a dot follow from
        // the value alone (see `push_fixed`), so no intermediate string.
        let a = q.unsigned_abs();
        let has_dot = !a.is_multiple_of(self.scale);
        let starts_minus = q < 0;
        let starts_dot = !starts_minus && a < self.scale && has_dot;
        let needs_sep = match self.out.as_bytes().last() {
            None => false,
            Some(ch) if ch.is_ascii_alphabetic() => false,
            Some(_) => !(starts_minus || (starts_dot && self.last_has_dot)),
        };
        if needs_sep {
            self.out.push(' ');
        }
        self.last_has_dot = has_dot;
        push_fixed(&mut self.out, q, self.decimals, self.scale);
    }
}

/// Compact relative path data for `path` with `decimals` decimals.
pub fn path_data(path: &BezPath, decimals: u32) -> String {
    let scale = 10f64.powi(decimals as i32);
    let quant =
        |p: Point| -> (i64, i64) { ((p.x * scale).round() as i64, (p.y * scale).round() as i64) };
    // Half a quantum: control points this close to the chord make a line.
    let line_eps = 0.5 / scale;
    let mut w = DataWriter {
        out: String::new(),
        last_cmd: None,
        last_has_dot: false,
        decimals,
        scale: 10u64.pow(decimals),
    };
    let mut cur = (0i64, 0i64);
    let mut start = (0i64, 0i64);
    let mut cur_pt = Point::ZERO;
    let els = path.elements();
    for (i, el) in els.iter().enumerate() {
        match *el {
            PathEl::MoveTo(p) => {
                let q = quant(p);
                w.cmd('m');
                w.num(q.0 - cur.0);
                w.num(q.1 - cur.1);
                cur = q;
                start = q;
                cur_pt = p;
            }
            PathEl::LineTo(p) => {
                let q = quant(p);
                let closes_next = q == start && matches!(els.get(i + 1), Some(PathEl::ClosePath));
                if q != cur && !closes_next {
                    w.cmd('l');
                    w.num(q.0 - cur.0);
                    w.num(q.1 - cur.1);
                }
                cur = q;
                cur_pt = p;
            }
            PathEl::QuadTo(p1, p2) => {
                let c1 = cur_pt + (p1 - cur_pt) * (2.0 / 3.0);
                let c2 = p2 + (p1 - p2) * (2.0 / 3.0);
                emit_cubic(
                    &mut w,
                    &mut cur,
                    start,
                    cur_pt,
                    c1,
                    c2,
                    p2,
                    &quant,
                    line_eps,
                    els.get(i + 1),
                );
                cur_pt = p2;
            }
            PathEl::CurveTo(p1, p2, p3) => {
                emit_cubic(
                    &mut w,
                    &mut cur,
                    start,
                    cur_pt,
                    p1,
                    p2,
                    p3,
                    &quant,
                    line_eps,
                    els.get(i + 1),
                );
                cur_pt = p3;
            }
            PathEl::ClosePath => {
                w.cmd('z');
                cur = start;
            }
        }
    }
    w.out
}

#[allow(clippy::too_many_arguments)]
fn emit_cubic(
    w: &mut DataWriter,
    cur: &mut (i64, i64),
    start: (i64, i64),
    p0: Point,
    p1: Point,
    p2: Point,
    p3: Point,
    quant: &impl Fn(Point) -> (i64, i64),
    line_eps: f64,
    next: Option<&PathEl>,
) {
    let q3 = quant(p3);
    if is_straight(p0, p1, p2, p3, line_eps) {
        let closes_next = q3 == start && matches!(next, Some(PathEl::ClosePath));
        if q3 != *cur && !closes_next {
            w.cmd('l');
            w.num(q3.0 - cur.0);
            w.num(q3.1 - cur.1);
        }
    } else {
        let q1 = quant(p1);
        let q2 = quant(p2);
        w.cmd('c');
        for q in [q1, q2, q3] {
            w.num(q.0 - cur.0);
            w.num(q.1 - cur.1);
        }
    }
    *cur = q3;
}

/// True when the cubic's control points lie on its chord, between its ends.
fn is_straight(p0: Point, p1: Point, p2: Point, p3: Point, eps: f64) -> bool {
    let chord = p3 - p0;
    let len2 = chord.hypot2();
    if len2 < eps * eps {
        return (p1 - p0).hypot() < eps && (p2 - p0).hypot() < eps;
    }
    let len = len2.sqrt();
    [p1, p2].iter().all(|&p| {
        let v = p - p0;
        let along = v.dot(chord) / len2;
        let off = v.cross(chord).abs() / len;
        off <= eps && (-1e-9..=1.0 + 1e-9).contains(&along)
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A document a ten-thousandth of a unit high keeps its size (four
    /// significant digits), so renderers accept it.
    #[test]
    fn tiny_documents_keep_their_size() {
        let doc = Document::new(0.0001, 0.00025, 2);
        let svg = doc.to_svg();
        assert!(
            svg.contains(r#"width=".0001" height=".00025" viewBox="0 0 .0001 .00025""#),
            "{svg}"
        );
    }

    /// Past the element limit, the shapes of a group painted alike become
    /// one path each (their subpaths kept), and it is said.
    #[test]
    fn shapes_past_the_limit_are_merged_per_colour() {
        let mut doc = Document::new(10.0, 10.0, 2);
        let square = |x: f64| kurbo::Shape::to_path(&kurbo::Rect::new(x, 0.0, x + 1.0, 1.0), 0.1);
        let (a, b) = (Color::rgb(1, 2, 3), Color::rgb(4, 5, 6));
        doc.groups.push(Group {
            id: "q".into(),
            shapes: (0..MAX_ELEMENTS + 2)
                .map(|i| Shape::filled(square(i as f64 % 8.0), if i % 2 == 0 { a } else { b }))
                .collect(),
        });
        let note = doc.merge_past_limit().expect("merged");
        assert!(note.contains("into 2 paths"), "{note}");
        assert_eq!(doc.groups[0].shapes.len(), 2);
        let moves = |s: &Shape| {
            s.path
                .elements()
                .iter()
                .filter(|e| matches!(e, kurbo::PathEl::MoveTo(_)))
                .count()
        };
        assert_eq!(
            moves(&doc.groups[0].shapes[0]) + moves(&doc.groups[0].shapes[1]),
            MAX_ELEMENTS + 2
        );
        assert!(doc.merge_past_limit().is_none(), "under the limit now");
    }

    #[test]
    fn numbers_are_compact() {
        assert_eq!(fmt_num(0.5, 2), ".5");
        assert_eq!(fmt_num(-0.5, 2), "-.5");
        assert_eq!(fmt_num(12.0, 2), "12");
        assert_eq!(fmt_num(12.345, 2), "12.35");
        assert_eq!(fmt_num(-0.001, 2), "0");
        assert_eq!(fmt_num(1.10, 3), "1.1");
    }

    #[test]
    fn path_data_is_relative_and_closed() {
        let mut p = BezPath::new();
        p.move_to((10.0, 10.0));
        p.line_to((20.0, 10.0));
        p.curve_to((25.0, 10.0), (25.0, 20.0), (20.0, 20.0));
        p.line_to((10.0, 10.0));
        p.close_path();
        p.move_to((12.5, 12.5));
        p.line_to((13.5, 12.5));
        p.line_to((13.5, 13.5));
        p.close_path();
        let d = path_data(&p, 2);
        assert_eq!(d, "m10 10 10 0c5 0 5 10 0 10zm2.5 2.5 1 0 0 1z");
    }

    #[test]
    fn straight_cubics_become_lines() {
        let mut p = BezPath::new();
        p.move_to((0.0, 0.0));
        p.curve_to((1.0, 1.0), (2.0, 2.0), (3.0, 3.0));
        p.curve_to((4.0, 3.0), (5.0, 3.0), (6.0, 3.0));
        assert_eq!(path_data(&p, 2), "m0 0 3 3 3 0");
    }

    #[test]
    fn rounding_does_not_drift() {
        // Many small steps of 0.004 rounded at 2 decimals must still land at
        // the true end point.
        let mut p = BezPath::new();
        p.move_to((0.0, 0.0));
        for i in 1..=1000 {
            p.line_to((i as f64 * 0.004, 0.0));
        }
        let d = path_data(&p, 2);
        let total: f64 = d
            .trim_start_matches("m0 0")
            .split(' ')
            .filter(|s| !s.is_empty())
            .step_by(2)
            .map(|s| s.parse::<f64>().unwrap())
            .sum();
        assert!((total - 4.0).abs() < 1e-9, "{total}");
    }

    #[test]
    fn colours() {
        assert_eq!(Color::rgb(255, 0, 0).to_hex(), "#f00");
        assert_eq!(Color::rgb(18, 52, 86).to_hex(), "#123456");
    }

    #[test]
    fn decimals_follow_tolerance() {
        assert_eq!(decimals_for(0.25), 2);
        assert_eq!(decimals_for(1.0), 1);
        assert_eq!(decimals_for(0.01), 3);
    }
}
