//! Generates flourish's own test artwork for the bitmap tracer (`flourish trace`).
//!
//! Everything here is drawn from scratch with kurbo geometry: no fonts, no
//! borrowed art, no randomness, so the output is byte-for-byte reproducible.
//!
//! What it draws (all black ink on no background unless noted):
//! * `glyph-a`, `glyph-g`, `glyph-s`: serif lower-case letters built from
//!   pen-contrast strokes (thick verticals, hairline horizontals), ball and
//!   flat terminals, bracketed serifs and closed bowls (holes).
//! * `ornament-scroll`: a mirror-symmetric filigree of logarithmic-spiral
//!   scrolls whose outlines are offset curves of a variable-width stroke,
//!   with pointed leaves, ball terminals and dots.
//! * `ornament-rosette`: a radially symmetric rosette (petals with vein holes,
//!   rings, beads).
//! * `thin-lines`: hairlines 1.0, 1.5, 2.0 and 3.0 px wide, straight, mitred
//!   and curved, as filled shapes.
//! * `holes`: nested holes and islands (even-odd fill), tiny holes, frames.
//! * `two-colour`: three stacked fill colours for the tracer's `--layers` mode.
//! * `ornament-2mp`: a 1414x1414 framed ornament (scroll border, rosette
//!   centre), thresholded to black/white, for benchmarking against potrace;
//!   `ornament-2mp-aa.png` is the same drawing anti-aliased, as a scan or a
//!   render reaches the tracer (no SVG of its own: `ornament-2mp.svg`).
//!
//! Each drawing is written as `NAME.svg` (ground truth) and `NAME.png`
//! (rendered with resvg on white, anti-aliased, 8-bit grayscale; RGB for
//! `two-colour`); a few also get a 50 % thresholded `NAME-binary.png`.
//!
//! Rerun with:
//!
//! ```text
//! cargo run --release -p flourish-tools --bin make_trace_samples -- samples/trace
//! ```

use std::f64::consts::{PI, TAU};
use std::fs::File;
use std::io::BufWriter;
use std::path::{Path, PathBuf};

use image::codecs::png::{CompressionType, FilterType, PngEncoder};
use image::{ExtendedColorType, ImageEncoder};
use kurbo::{
    Affine, BezPath, Circle, CubicBez, ParamCurve, ParamCurveDeriv, PathEl, Point, Rect,
    RoundedRect, Shape, Vec2,
};
use resvg::{tiny_skia, usvg};

/// Maximum deviation (px) between a fitted cubic and the exact offset curve.
const FIT_TOL: f64 = 0.03;

// ---------------------------------------------------------------------------
// Curve fitting: cubic Hermite interpolation of an exact parametric curve.
// ---------------------------------------------------------------------------

/// Appends cubics approximating `f` over `[0, 1]` to `out`, subdividing until
/// the fit is within [`FIT_TOL`]. Joins with a line if `f(0)` is not the
/// current point.
fn fit(out: &mut BezPath, f: &dyn Fn(f64) -> Point) {
    let p0 = f(0.0);
    if let Some(cur) = current_point(out) {
        if (cur - p0).hypot() > 1e-9 {
            out.line_to(p0);
        }
    } else {
        out.move_to(p0);
    }
    fit_range(out, f, 0.0, 1.0, 0);
}

fn fit_range(out: &mut BezPath, f: &dyn Fn(f64) -> Point, a: f64, b: f64, depth: u32) {
    let e = (b - a) * 1e-5;
    let p0 = f(a);
    let p3 = f(b);
    let d0 = (f(a + e) - p0) / e;
    let d3 = (p3 - f(b - e)) / e;
    let h = (b - a) / 3.0;
    let c = CubicBez::new(p0, p0 + d0 * h, p3 - d3 * h, p3);
    let err = [0.1, 0.3, 0.5, 0.7, 0.9]
        .iter()
        .map(|&t| (c.eval(t) - f(a + (b - a) * t)).hypot())
        .fold(0.0, f64::max);
    if depth < 18 && (depth < 1 || err > FIT_TOL) {
        let m = 0.5 * (a + b);
        fit_range(out, f, a, m, depth + 1);
        fit_range(out, f, m, b, depth + 1);
    } else {
        out.curve_to(c.p1, c.p2, c.p3);
    }
}

fn current_point(p: &BezPath) -> Option<Point> {
    match p.elements().last()? {
        PathEl::MoveTo(p) | PathEl::LineTo(p) => Some(*p),
        PathEl::QuadTo(_, p) => Some(*p),
        PathEl::CurveTo(_, _, p) => Some(*p),
        PathEl::ClosePath => None,
    }
}

fn unit(v: Vec2) -> Vec2 {
    let l = v.hypot();
    if l < 1e-12 {
        Vec2::new(1.0, 0.0)
    } else {
        v / l
    }
}

/// Left normal (in y-down screen space this points to the right of travel;
/// only consistency matters).
fn perp(t: Vec2) -> Vec2 {
    Vec2::new(-t.y, t.x)
}

/// Makes every subpath of `p` wind positively (`positive`) or negatively.
fn orient(p: BezPath, positive: bool) -> BezPath {
    if (p.area() > 0.0) == positive {
        p
    } else {
        p.reverse_subpaths()
    }
}

/// Applies `a`, keeping winding directions when `a` mirrors.
fn place(p: &BezPath, a: Affine) -> BezPath {
    let q = a * p.clone();
    if a.determinant() < 0.0 {
        q.reverse_subpaths()
    } else {
        q
    }
}

// ---------------------------------------------------------------------------
// Spines and variable-width strokes.
// ---------------------------------------------------------------------------

/// A parametric curve piece on `[0, 1]` returning point and derivative.
type Piece = Box<dyn Fn(f64) -> (Point, Vec2)>;
/// Half-width as a function of arc-length fraction `s` and unit tangent.
type Width<'a> = &'a dyn Fn(f64, Vec2) -> f64;

struct Spine {
    pieces: Vec<Piece>,
    start: Vec<f64>,
    len: Vec<f64>,
    total: f64,
}

fn cubic_piece(c: CubicBez) -> Piece {
    let d = c.deriv();
    Box::new(move |u| (c.eval(u), d.eval(u).to_vec2()))
}

fn cubic(p0: Point, p1: Point, p2: Point, p3: Point) -> Piece {
    cubic_piece(CubicBez::new(p0, p1, p2, p3))
}

impl Spine {
    fn new(pieces: Vec<Piece>) -> Spine {
        let mut start = Vec::new();
        let mut len = Vec::new();
        let mut acc = 0.0;
        for p in &pieces {
            let mut l = 0.0;
            let mut prev = p(0.0).0;
            for k in 1..=256 {
                let q = p(k as f64 / 256.0).0;
                l += (q - prev).hypot();
                prev = q;
            }
            start.push(acc);
            len.push(l);
            acc += l;
        }
        Spine {
            pieces,
            start,
            len,
            total: acc,
        }
    }

    fn from_path(path: &BezPath) -> Spine {
        Spine::new(path.segments().map(|s| cubic_piece(s.to_cubic())).collect())
    }

    fn s(&self, i: usize, u: f64) -> f64 {
        (self.start[i] + u * self.len[i]) / self.total
    }

    /// Offset curve of piece `i` on side `side` (+1 left, -1 right).
    fn side<'a>(&'a self, i: usize, side: f64, hw: Width<'a>) -> impl Fn(f64) -> Point + 'a {
        move |u| {
            let (p, d) = (self.pieces[i])(u);
            let t = unit(d);
            p + perp(t) * (side * hw(self.s(i, u), t))
        }
    }

    fn frame(&self, at_end: bool) -> (Point, Vec2) {
        if at_end {
            let (p, d) = (self.pieces[self.pieces.len() - 1])(1.0);
            (p, unit(d))
        } else {
            let (p, d) = (self.pieces[0])(0.0);
            (p, unit(d))
        }
    }
}

#[derive(Clone, Copy, PartialEq)]
enum Cap {
    /// Flat cut across the stroke: two sharp corners.
    Butt,
    Round,
}

/// Continues `out` (currently at `p + perp(t) * h`) around the cap to
/// `p - perp(t) * h`.
fn cap(out: &mut BezPath, p: Point, t: Vec2, h: f64, kind: Cap) {
    let n = perp(t);
    if h < 1e-6 || kind == Cap::Butt {
        out.line_to(p - n * h);
    } else {
        fit(out, &|v: f64| {
            let a = PI * v;
            p + (n * a.cos() + t * a.sin()) * h
        });
    }
}

/// Outline of an open variable-width stroke, as one positively wound contour.
fn stroke(sp: &Spine, hw: Width, start: Cap, end: Cap) -> BezPath {
    let n = sp.pieces.len();
    let mut out = BezPath::new();
    for i in 0..n {
        fit(&mut out, &sp.side(i, 1.0, hw));
    }
    let (pe, te) = sp.frame(true);
    cap(&mut out, pe, te, hw(1.0, te), end);
    for i in (0..n).rev() {
        let f = sp.side(i, -1.0, hw);
        fit(&mut out, &|u| f(1.0 - u));
    }
    let (ps, ts) = sp.frame(false);
    cap(&mut out, ps, -ts, hw(0.0, ts), start);
    out.close_path();
    orient(out, true)
}

/// Outline of a stroke along a closed spine: outer contour positive, inner
/// contour (the hole) negative.
fn ring(sp: &Spine, hw: Width) -> BezPath {
    let n = sp.pieces.len();
    let mut a = BezPath::new();
    for i in 0..n {
        fit(&mut a, &sp.side(i, 1.0, hw));
    }
    a.close_path();
    let mut b = BezPath::new();
    for i in (0..n).rev() {
        let f = sp.side(i, -1.0, hw);
        fit(&mut b, &|u| f(1.0 - u));
    }
    b.close_path();
    let (outer, inner) = if a.area().abs() > b.area().abs() {
        (a, b)
    } else {
        (b, a)
    };
    let mut r = orient(outer, true);
    r.extend(orient(inner, false));
    r
}

fn dot(c: Point, r: f64) -> BezPath {
    orient(Circle::new(c, r).to_path(1e-3), true)
}

/// Annulus between radii `r0 < r1`.
fn annulus(c: Point, r0: f64, r1: f64) -> BezPath {
    let mut p = dot(c, r1);
    p.extend(orient(Circle::new(c, r0).to_path(1e-3), false));
    p
}

/// Swelling width profile: `w0` at the start, `wmax` at `peak`, `w1` at the
/// end (full widths; returns half-width).
fn swell(w0: f64, wmax: f64, w1: f64, peak: f64) -> impl Fn(f64, Vec2) -> f64 {
    move |s, _| {
        let w = if s < peak {
            let x = s / peak;
            w0 + (wmax - w0) * x * (2.0 - x)
        } else {
            let x = ((1.0 - s) / (1.0 - peak)).clamp(0.0, 1.0);
            w1 + (wmax - w1) * 0.5 * x * (3.0 - x * x)
        };
        0.5 * w
    }
}

/// Broad-nib contrast: thick where the stroke runs vertically (tilted by
/// `tilt` radians), hairline where it runs horizontally.
fn pen_w(thin: f64, thick: f64, tilt: f64, t: Vec2) -> f64 {
    let a = t.y.atan2(t.x) - tilt;
    0.5 * (thin + (thick - thin) * a.sin().abs().powf(1.6))
}

// ---------------------------------------------------------------------------
// Ornament vocabulary: volutes, scrolls, leaves.
// ---------------------------------------------------------------------------

/// A logarithmic spiral winding inwards from radius `r0` at polar angle
/// `th0` around `c`, `turns` times, in direction `dir` (+1 / -1, screen
/// angle), ending at radius `r0 * ratio`.
#[derive(Clone, Copy)]
struct Volute {
    c: Point,
    r0: f64,
    th0: f64,
    dir: f64,
    turns: f64,
    ratio: f64,
}

impl Volute {
    fn b(&self) -> f64 {
        (1.0 / self.ratio).ln() / (self.turns * TAU)
    }
    fn start(&self) -> (Point, Vec2) {
        let b = self.b();
        let e = Vec2::new(self.th0.cos(), self.th0.sin());
        (self.c + e * self.r0, unit(e * -b + perp(e) * self.dir))
    }
    fn piece(self) -> Piece {
        let b = self.b();
        let span = self.turns * TAU;
        Box::new(move |u| {
            let phi = u * span;
            let r = self.r0 * (-b * phi).exp();
            let th = self.th0 + self.dir * phi;
            let e = Vec2::new(th.cos(), th.sin());
            let d = (e * -b + perp(e) * self.dir) * (r * span);
            (self.c + e * r, d)
        })
    }
}

/// A scroll: a cubic lead-in from `s` (direction `ts`) into volute `v`,
/// with a ball terminal of radius `ball` (0 for none).
#[allow(clippy::too_many_arguments)]
fn scroll(
    s: Point,
    ts: Vec2,
    h1: f64,
    h2: f64,
    v: Volute,
    hw: Width,
    start: Cap,
    ball: f64,
) -> BezPath {
    let (q, tq) = v.start();
    let ts = unit(ts);
    let sp = Spine::new(vec![cubic(s, s + ts * h1, q - tq * h2, q), v.piece()]);
    let mut p = stroke(&sp, hw, start, Cap::Round);
    if ball > 0.0 {
        p.extend(dot(sp.frame(true).0, ball));
    }
    p
}

/// A pointed leaf from `base` to `tip`, bowed sideways by `bend` (fraction
/// of its length), `width` at its widest; `vein` > 0 cuts a slim vein hole.
fn leaf(base: Point, tip: Point, bend: f64, width: f64, vein: f64) -> BezPath {
    let d = tip - base;
    let n = perp(d);
    let c = CubicBez::new(
        base,
        base + d / 3.0 + n * bend,
        base + d * (2.0 / 3.0) + n * bend,
        tip,
    );
    let sp = Spine::new(vec![cubic_piece(c)]);
    let hw = move |s: f64, _t: Vec2| {
        let a = PI * s;
        0.5 * width * a.sin() * (1.0 + 0.35 * a.cos()) / 1.07
    };
    let mut p = stroke(&sp, &hw, Cap::Round, Cap::Round);
    if vein > 0.0 {
        let (u0, u1) = (0.16, 0.78);
        let dc = c.deriv();
        let sub: Piece = Box::new(move |u| {
            let x = u0 + (u1 - u0) * u;
            (c.eval(x), dc.eval(x).to_vec2() * (u1 - u0))
        });
        let vs = Spine::new(vec![sub]);
        let vw = move |s: f64, _t: Vec2| 0.5 * vein * (PI * s).sin().powf(0.9);
        p.extend(orient(stroke(&vs, &vw, Cap::Round, Cap::Round), false));
    }
    p
}

fn polar(c: Point, r: f64, a: f64) -> Point {
    c + Vec2::new(a.cos(), a.sin()) * r
}

// ---------------------------------------------------------------------------
// Documents.
// ---------------------------------------------------------------------------

struct Layer {
    fill: &'static str,
    evenodd: bool,
    path: BezPath,
}

struct Art {
    w: u32,
    h: u32,
    layers: Vec<Layer>,
}

impl Art {
    fn new(w: u32, h: u32) -> Art {
        Art {
            w,
            h,
            layers: Vec::new(),
        }
    }

    /// Adds a positively wound shape (union with nonzero fill).
    fn add(&mut self, fill: &'static str, path: BezPath) {
        match self.layers.last_mut() {
            Some(l) if l.fill == fill && !l.evenodd => l.path.extend(path),
            _ => self.layers.push(Layer {
                fill,
                evenodd: false,
                path,
            }),
        }
    }

    fn add_evenodd(&mut self, fill: &'static str, path: BezPath) {
        self.layers.push(Layer {
            fill,
            evenodd: true,
            path,
        });
    }

    fn svg(&self) -> String {
        let mut s = format!(
            "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"{w}\" height=\"{h}\" \
             viewBox=\"0 0 {w} {h}\">\n\
             <!-- generated by flourish examples/make_trace_samples.rs -->\n",
            w = self.w,
            h = self.h
        );
        for l in &self.layers {
            let rule = if l.evenodd {
                " fill-rule=\"evenodd\""
            } else {
                ""
            };
            s += &format!(
                "<path fill=\"{}\"{} d=\"{}\"/>\n",
                l.fill,
                rule,
                path_data(&l.path)
            );
        }
        s += "</svg>\n";
        s
    }
}

fn num(x: f64) -> String {
    let s = format!("{:.2}", x);
    let s = s.trim_end_matches('0').trim_end_matches('.');
    if s == "-0" {
        "0".to_string()
    } else {
        s.to_string()
    }
}

fn path_data(p: &BezPath) -> String {
    let mut s = String::new();
    let pt = |p: Point| format!("{} {}", num(p.x), num(p.y));
    for el in p.elements() {
        match *el {
            PathEl::MoveTo(a) => s += &format!("M{}", pt(a)),
            PathEl::LineTo(a) => s += &format!("L{}", pt(a)),
            PathEl::QuadTo(a, b) => s += &format!("Q{} {}", pt(a), pt(b)),
            PathEl::CurveTo(a, b, c) => s += &format!("C{} {} {}", pt(a), pt(b), pt(c)),
            PathEl::ClosePath => s += "Z",
        }
    }
    s
}

// ---------------------------------------------------------------------------
// Glyphs.
// ---------------------------------------------------------------------------

const THIN: f64 = 11.0;
const THICK: f64 = 42.0;
const TILT: f64 = -0.2;

fn pen(_s: f64, t: Vec2) -> f64 {
    pen_w(THIN, THICK, TILT, t)
}

fn bez(pts: &[(f64, f64)]) -> BezPath {
    // pts: start, then triples of cubic points.
    let mut p = BezPath::new();
    p.move_to(pts[0]);
    for c in pts[1..].chunks(3) {
        p.curve_to(c[0], c[1], c[2]);
    }
    p
}

fn ellipse_spine(c: (f64, f64), rx: f64, ry: f64) -> Spine {
    let c = Point::from(c);
    let piece: Piece = Box::new(move |u| {
        // Start at the right, go round once.
        let a = u * TAU;
        (
            c + Vec2::new(rx * a.cos(), ry * a.sin()),
            Vec2::new(-rx * a.sin(), ry * a.cos()) * TAU,
        )
    });
    Spine::new(vec![piece])
}

fn glyph_a() -> BezPath {
    // Arch from a ball terminal over the shoulder into the stem.
    let arch = bez(&[
        (206.0, 206.0),
        (214.0, 178.0),
        (236.0, 163.0),
        (268.0, 163.0),
        (308.0, 163.0),
        (330.0, 186.0),
        (330.0, 232.0),
        (330.0, 290.0),
        (330.0, 340.0),
        (330.0, 388.0),
    ]);
    let sp = Spine::from_path(&arch);
    let hw = |s: f64, t: Vec2| pen(s, t) * (0.6 + 0.4 * (s / 0.12).min(1.0));
    let mut g = stroke(&sp, &hw, Cap::Round, Cap::Butt);
    g.extend(dot(Point::new(212.0, 206.0), 24.0));
    // Bowl: a closed ring whose right side hides in the stem.
    g.extend(ring(&ellipse_spine((272.0, 334.0), 58.0, 62.0), &pen));
    // Bracketed foot serif.
    let mut serif = BezPath::new();
    serif.move_to((294.0, 400.0));
    serif.line_to((384.0, 400.0));
    serif.line_to((384.0, 392.0));
    serif.curve_to((366.0, 390.0), (351.0, 384.0), (351.0, 360.0));
    serif.line_to((309.0, 360.0));
    serif.curve_to((309.0, 382.0), (302.0, 390.0), (294.0, 392.0));
    serif.close_path();
    g.extend(orient(serif, true));
    g
}

fn glyph_g() -> BezPath {
    let mut g = ring(&ellipse_spine((256.0, 226.0), 56.0, 62.0), &pen);
    // Ear with a flat (butt) terminal.
    let ear = Spine::from_path(&bez(&[
        (296.0, 190.0),
        (310.0, 176.0),
        (326.0, 168.0),
        (352.0, 170.0),
    ]));
    let ear_w = |s: f64, _t: Vec2| 0.5 * (7.0 + 12.0 * s * s);
    g.extend(stroke(&ear, &ear_w, Cap::Round, Cap::Butt));
    // Link from the upper bowl down-left, then along the top of the loop.
    let link = Spine::from_path(&bez(&[
        (240.0, 284.0),
        (204.0, 292.0),
        (184.0, 318.0),
        (206.0, 334.0),
        (222.0, 345.0),
        (248.0, 346.0),
        (272.0, 346.0),
    ]));
    let link_w = |_s: f64, t: Vec2| pen_w(THIN, 24.0, TILT, t);
    g.extend(stroke(&link, &link_w, Cap::Round, Cap::Round));
    // Lower loop.
    g.extend(ring(&ellipse_spine((262.0, 412.0), 94.0, 66.0), &pen));
    g
}

fn glyph_s() -> BezPath {
    let spine = bez(&[
        (322.0, 214.0),
        (322.0, 182.0),
        (294.0, 163.0),
        (258.0, 163.0),
        (222.0, 163.0),
        (200.0, 184.0),
        (200.0, 214.0),
        (200.0, 248.0),
        (226.0, 266.0),
        (257.0, 280.0),
        (288.0, 294.0),
        (314.0, 312.0),
        (314.0, 346.0),
        (314.0, 376.0),
        (292.0, 397.0),
        (256.0, 397.0),
        (220.0, 397.0),
        (192.0, 378.0),
        (192.0, 346.0),
    ]);
    let sp = Spine::from_path(&spine);
    let hw = |s: f64, t: Vec2| {
        let spine_boost = 0.9 * (-((s - 0.5) / 0.15).powi(2)).exp();
        let a = t.y.atan2(t.x) - TILT;
        let dir = a.sin().abs().powf(1.6);
        let k = 1.0 - (1.0 - dir) * (1.0 - spine_boost);
        let e = smoothstep((1.0 - (2.0 * s - 1.0).abs()) / 0.3);
        0.5 * (THIN + (THICK - THIN) * k) * (0.6 + 0.4 * e)
    };
    let mut g = stroke(&sp, &hw, Cap::Butt, Cap::Butt);
    // Vertical serifs at both terminals (a point-symmetric pair): a bar
    // flush with the outer edge of the flat terminal, bracketed below.
    let mut bar = BezPath::new();
    bar.move_to((327.0, 164.0));
    bar.line_to((335.0, 164.0));
    bar.line_to((335.0, 214.0));
    bar.line_to((318.0, 214.0));
    bar.curve_to((324.0, 206.0), (327.0, 194.0), (327.0, 164.0));
    bar.close_path();
    let bar = orient(bar, true);
    g.extend(place(
        &bar,
        Affine::rotate_about(PI, Point::new(257.0, 280.0)),
    ));
    g.extend(bar);
    g
}

fn smoothstep(x: f64) -> f64 {
    let x = x.clamp(0.0, 1.0);
    x * x * (3.0 - 2.0 * x)
}

fn glyph_art(g: BezPath) -> Art {
    let scale = 1.35;
    let bb = (Affine::scale(scale) * g.clone()).bounding_box();
    let c = bb.center();
    let a = Affine::translate((256.0 - c.x, 256.0 - c.y)) * Affine::scale(scale);
    let mut art = Art::new(512, 512);
    art.add("#000", place(&g, a));
    art
}

// ---------------------------------------------------------------------------
// Ornaments.
// ---------------------------------------------------------------------------

/// Right half of the scroll filigree, centred on x = 0, y = 0 (the spot
/// where the main scrolls leave the central motif). Units: px at 768 wide.
fn scroll_half() -> Vec<BezPath> {
    let mut out = Vec::new();
    // Main scroll: sweeps right and curls up into a big volute.
    let big = Volute {
        c: Point::new(214.0, -64.0),
        r0: 86.0,
        th0: PI / 2.0,
        dir: -1.0,
        turns: 1.45,
        ratio: 0.2,
    };
    let main_start = Point::new(6.0, 40.0);
    let main_dir = Vec2::new(1.0, 0.22);
    let main_w = swell(0.0, 15.0, 3.0, 0.3);
    out.push(scroll(
        main_start,
        main_dir,
        70.0,
        80.0,
        big,
        &main_w,
        Cap::Round,
        6.0,
    ));
    let (q, tq) = big.start();
    let lead = CubicBez::new(
        main_start,
        main_start + unit(main_dir) * 70.0,
        q - tq * 80.0,
        q,
    );
    let on_main = |u: f64| (lead.eval(u), unit(lead.deriv().eval(u).to_vec2()));
    // Secondary scroll branching off below, curling down.
    let (bq, btan) = on_main(0.42);
    let small = Volute {
        c: Point::new(150.0, 118.0),
        r0: 38.0,
        th0: -PI / 2.0,
        dir: 1.0,
        turns: 1.35,
        ratio: 0.24,
    };
    let small_w = swell(2.0, 10.0, 2.4, 0.32);
    out.push(scroll(
        bq,
        btan,
        30.0,
        40.0,
        small,
        &small_w,
        Cap::Round,
        4.6,
    ));
    // Upper tendril: from the main stroke up and curling left.
    let (tq0, ttan) = on_main(0.3);
    let tendril = Volute {
        c: Point::new(104.0, -80.0),
        r0: 26.0,
        th0: 0.0,
        dir: -1.0,
        turns: 1.2,
        ratio: 0.28,
    };
    let tw = swell(1.5, 7.5, 2.0, 0.3);
    out.push(scroll(tq0, ttan, 36.0, 50.0, tendril, &tw, Cap::Round, 3.6));
    // Leaves sprouting from the strokes.
    let (b1, _) = on_main(0.64);
    out.push(leaf(b1, b1 + Vec2::new(44.0, 40.0), 0.12, 18.0, 1.8));
    out.push(leaf(
        Point::new(226.0, 24.0),
        Point::new(296.0, 50.0),
        0.13,
        20.0,
        2.0,
    ));
    let (b2, _) = on_main(0.12);
    out.push(leaf(b2, b2 + Vec2::new(34.0, 46.0), -0.1, 16.0, 1.6));
    // Pearl trail around the big volute.
    for (i, r) in [5.0, 4.0, 3.0].iter().enumerate() {
        let a = -2.55 + 0.3 * i as f64;
        out.push(dot(polar(big.c, 106.0, a), *r));
    }
    out
}

/// The full filigree (both halves and the central palmette) in a 768x512
/// box.
fn scroll_composition() -> Vec<BezPath> {
    let mut out = Vec::new();
    let origin = Affine::translate((384.0, 272.0));
    let mirror = Affine::translate((384.0, 272.0)) * Affine::scale_non_uniform(-1.0, 1.0);
    let flip = Affine::translate((768.0, 0.0)) * Affine::scale_non_uniform(-1.0, 1.0);
    for p in scroll_half() {
        out.push(place(&p, origin));
        out.push(place(&p, mirror));
    }
    // Central motif: palmette of three leaves, a pendant and buds.
    let c = Point::new(384.0, 318.0);
    out.push(leaf(c, Point::new(384.0, 150.0), 0.0, 46.0, 3.0));
    let side = leaf(
        Point::new(378.0, 316.0),
        Point::new(334.0, 206.0),
        -0.12,
        24.0,
        2.0,
    );
    out.push(place(&side, flip));
    out.push(side);
    out.push(dot(Point::new(384.0, 132.0), 7.0));
    out.push(dot(Point::new(384.0, 114.0), 4.0));
    out.push(leaf(
        c + Vec2::new(0.0, 4.0),
        Point::new(384.0, 392.0),
        0.0,
        20.0,
        0.0,
    ));
    out.push(dot(Point::new(384.0, 406.0), 4.5));
    out
}

fn ornament_scroll() -> Art {
    let mut art = Art::new(768, 512);
    for p in scroll_composition() {
        art.add("#000", p);
    }
    art
}

fn rosette(c: Point, k: f64) -> Vec<BezPath> {
    let mut out = Vec::new();
    out.push(dot(c, 14.0 * k));
    out.push(annulus(c, 24.0 * k, 32.0 * k));
    for i in 0..8 {
        let a = i as f64 * TAU / 8.0 - PI / 2.0;
        out.push(leaf(
            polar(c, 40.0 * k, a),
            polar(c, 116.0 * k, a),
            0.0,
            36.0 * k,
            3.0 * k,
        ));
        let b = a + TAU / 16.0;
        out.push(leaf(
            polar(c, 46.0 * k, b),
            polar(c, 88.0 * k, b),
            0.0,
            16.0 * k,
            0.0,
        ));
        out.push(dot(polar(c, 104.0 * k, b), 4.5 * k));
    }
    out.push(annulus(c, 124.0 * k, 131.0 * k));
    for i in 0..16 {
        let a = i as f64 * TAU / 16.0 - PI / 2.0;
        // Teardrop lobes: pointed inside, round outside.
        let sp = Spine::new(vec![cubic(
            polar(c, 140.0 * k, a),
            polar(c, 160.0 * k, a),
            polar(c, 180.0 * k, a),
            polar(c, 196.0 * k, a),
        )]);
        let hw = move |s: f64, _t: Vec2| {
            0.5 * 30.0 * k * (s * (2.0 - s)).powf(1.1).min(1.0) * 0.5 + 0.5 * 30.0 * k * 0.5 * s
        };
        let mut lobe = stroke(&sp, &hw, Cap::Round, Cap::Round);
        lobe.extend(orient(
            Circle::new(polar(c, 182.0 * k, a), 5.0 * k).to_path(1e-3),
            false,
        ));
        out.push(lobe);
        let b = a + TAU / 32.0;
        out.push(dot(polar(c, 148.0 * k, b), 3.5 * k));
    }
    for i in 0..48 {
        let a = i as f64 * TAU / 48.0;
        out.push(dot(polar(c, 222.0 * k, a), 5.0 * k));
    }
    out.push(annulus(c, 232.0 * k, 236.0 * k));
    out
}

fn ornament_rosette() -> Art {
    let mut art = Art::new(512, 512);
    for p in rosette(Point::new(256.0, 256.0), 1.0) {
        art.add("#000", p);
    }
    art
}

// ---------------------------------------------------------------------------
// Test sheets.
// ---------------------------------------------------------------------------

/// Butt-capped, mitre-joined outline of a polyline of constant width.
fn polyline(pts: &[Point], w: f64) -> BezPath {
    let h = 0.5 * w;
    let offset = |side: f64| -> Vec<Point> {
        let mut v = Vec::new();
        for i in 0..pts.len() {
            let pt = pts[i];
            if i == 0 || i == pts.len() - 1 {
                let (a, b) = if i == 0 {
                    (pts[0], pts[1])
                } else {
                    (pts[i - 1], pts[i])
                };
                v.push(pt + perp(unit(b - a)) * (side * h));
            } else {
                let t0 = unit(pts[i] - pts[i - 1]);
                let t1 = unit(pts[i + 1] - pts[i]);
                let m = unit(perp(t0) + perp(t1));
                let l = h / m.dot(perp(t0));
                v.push(pt + m * (side * l));
            }
        }
        v
    };
    let left = offset(1.0);
    let right = offset(-1.0);
    let mut p = BezPath::new();
    p.move_to(left[0]);
    for q in &left[1..] {
        p.line_to(*q);
    }
    for q in right.iter().rev() {
        p.line_to(*q);
    }
    p.close_path();
    orient(p, true)
}

fn thin_lines() -> Art {
    let mut art = Art::new(512, 512);
    for (row, w) in [1.0, 1.5, 2.0, 3.0].iter().enumerate() {
        let y = 62.0 + row as f64 * 100.0;
        // Horizontal and vertical on the pixel grid, plus a diagonal.
        art.add(
            "#000",
            orient(
                Rect::new(20.0, y - w / 2.0, 140.0, y + w / 2.0).to_path(0.1),
                true,
            ),
        );
        art.add(
            "#000",
            orient(
                Rect::new(150.0 - w / 2.0, y - 40.0, 150.0 + w / 2.0, y + 40.0).to_path(0.1),
                true,
            ),
        );
        art.add(
            "#000",
            polyline(
                &[Point::new(164.0, y + 38.0), Point::new(230.0, y - 38.0)],
                *w,
            ),
        );
        // A mitred zig-zag with sharp corners.
        art.add(
            "#000",
            polyline(
                &[
                    Point::new(244.0, y + 30.0),
                    Point::new(266.0, y - 30.0),
                    Point::new(288.0, y + 30.0),
                    Point::new(310.0, y - 30.0),
                ],
                *w,
            ),
        );
        // A sine wave (curved hairline).
        let wave: Piece = Box::new(move |u| {
            let x = 322.0 + 170.0 * u;
            let a = u * TAU * 1.5;
            (
                Point::new(x, y + 28.0 * a.sin()),
                Vec2::new(170.0, 28.0 * a.cos() * TAU * 1.5),
            )
        });
        let hw = move |_s: f64, _t: Vec2| 0.5 * w;
        art.add(
            "#000",
            stroke(&Spine::new(vec![wave]), &hw, Cap::Butt, Cap::Butt),
        );
    }
    // Rings (circular hairlines with holes) of each width.
    for (i, w) in [1.0, 1.5, 2.0, 3.0].iter().enumerate() {
        let c = Point::new(70.0 + i as f64 * 124.0, 452.0);
        art.add("#000", annulus(c, 34.0 - w / 2.0, 34.0 + w / 2.0));
        art.add(
            "#000",
            leaf(
                c + Vec2::new(-24.0, 14.0),
                c + Vec2::new(24.0, -14.0),
                0.3,
                w * 3.0,
                0.0,
            ),
        );
    }
    art
}

fn holes() -> Art {
    let mut p = BezPath::new();
    // Target: disc, ring hole, island ring, hole, dot.
    let c = Point::new(130.0, 130.0);
    for r in [100.0, 78.0, 56.0, 34.0, 14.0] {
        p.extend(Circle::new(c, r).to_path(1e-3));
    }
    // Frame with a diamond island holding a round hole and a dot.
    p.extend(Rect::new(290.0, 30.0, 482.0, 222.0).to_path(0.1));
    p.extend(Rect::new(312.0, 52.0, 460.0, 200.0).to_path(0.1));
    let dc = Point::new(386.0, 126.0);
    let mut diamond = BezPath::new();
    diamond.move_to(dc + Vec2::new(0.0, -64.0));
    diamond.line_to(dc + Vec2::new(64.0, 0.0));
    diamond.line_to(dc + Vec2::new(0.0, 64.0));
    diamond.line_to(dc + Vec2::new(-64.0, 0.0));
    diamond.close_path();
    p.extend(diamond);
    p.extend(Circle::new(dc, 30.0).to_path(1e-3));
    p.extend(Circle::new(dc, 11.0).to_path(1e-3));
    // Swiss cheese: rounded plate with holes from large to 2 px.
    p.extend(RoundedRect::new(30.0, 262.0, 240.0, 482.0, 24.0).to_path(1e-3));
    for (x, y, r) in [
        (80.0, 312.0, 28.0),
        (150.0, 306.0, 16.0),
        (200.0, 300.0, 9.0),
        (196.0, 344.0, 5.0),
        (214.0, 372.0, 3.0),
        (190.0, 392.0, 2.0),
        (214.0, 410.0, 1.5),
        (120.0, 360.0, 12.0),
    ] {
        p.extend(Circle::new((x, y), r).to_path(1e-3));
    }
    // Triangle hole and star hole (sharp corners).
    let mut tri = BezPath::new();
    tri.move_to((60.0, 460.0));
    tri.line_to((110.0, 380.0));
    tri.line_to((140.0, 460.0));
    tri.close_path();
    p.extend(tri);
    let sc = Point::new(190.0, 440.0);
    let mut star = BezPath::new();
    for i in 0..10 {
        let r = if i % 2 == 0 { 30.0 } else { 12.0 };
        let q = polar(sc, r, i as f64 * PI / 5.0 - PI / 2.0);
        if i == 0 {
            star.move_to(q);
        } else {
            star.line_to(q);
        }
    }
    star.close_path();
    p.extend(star);
    // Plate with two slots separated by narrow bridges (3 px and 1.5 px),
    // and a keyhole.
    p.extend(Rect::new(272.0, 262.0, 482.0, 482.0).to_path(0.1));
    p.extend(Rect::new(292.0, 282.0, 375.5, 330.0).to_path(0.1));
    p.extend(Rect::new(378.5, 282.0, 462.0, 330.0).to_path(0.1));
    p.extend(Rect::new(292.0, 344.0, 376.25, 360.0).to_path(0.1));
    p.extend(Rect::new(377.75, 344.0, 462.0, 360.0).to_path(0.1));
    let kc = Point::new(377.0, 400.0);
    let mut key = BezPath::new();
    let a0 = (12.0f64 / 22.0).asin();
    key.move_to(polar(kc, 22.0, PI / 2.0 - a0));
    key.line_to(kc + Vec2::new(22.0, 64.0));
    key.line_to(kc + Vec2::new(-22.0, 64.0));
    key.line_to(polar(kc, 22.0, PI / 2.0 + a0));
    // Arc the long way round (over the top) back to the start.
    let arc = kurbo::Arc::new(kc, (22.0, 22.0), PI / 2.0 + a0, TAU - 2.0 * a0, 0.0);
    arc.to_cubic_beziers(1e-3, |p1, p2, p3| key.curve_to(p1, p2, p3));
    key.close_path();
    p.extend(key);
    let mut art = Art::new(512, 512);
    art.add_evenodd("#000", p);
    art
}

fn two_colour() -> Art {
    let mut art = Art::new(512, 512);
    let c = Point::new(256.0, 256.0);
    art.add("#d9a521", dot(c, 150.0));
    for i in 0..4 {
        let a = i as f64 * TAU / 4.0 - PI / 4.0;
        art.add(
            "#8c1c13",
            leaf(polar(c, 20.0, a), polar(c, 236.0, a), 0.0, 92.0, 6.0),
        );
        let b = a + TAU / 8.0;
        art.add(
            "#8c1c13",
            leaf(polar(c, 60.0, b), polar(c, 170.0, b), 0.0, 34.0, 0.0),
        );
    }
    art.add("#1f4d2b", annulus(c, 40.0, 50.0));
    art.add("#1f4d2b", dot(c, 24.0));
    for i in 0..8 {
        let a = i as f64 * TAU / 8.0 - PI / 8.0 + TAU / 16.0;
        art.add("#1f4d2b", dot(polar(c, 186.0, a), 9.0));
    }
    art
}

/// A running border vine along the x axis: `n` periods of a gentle wave
/// with a curl in every hollow, alternating sides.
fn vine(n: usize, period: f64, amp: f64) -> Vec<BezPath> {
    let mut out = Vec::new();
    let len = n as f64 * period;
    let k = TAU / period;
    let spine: Piece = Box::new(move |u| {
        let x = u * len;
        (
            Point::new(x, amp * (k * x).sin()),
            Vec2::new(len, amp * k * (k * x).cos() * len),
        )
    });
    let hw = swell(0.0, 6.0, 0.0, 0.5);
    let hw = move |s: f64, t: Vec2| hw(s, t).clamp(0.0, 3.0) * (s * 40.0).min(1.0);
    out.push(stroke(
        &Spine::new(vec![spine]),
        &hw,
        Cap::Round,
        Cap::Round,
    ));
    // One curl, above the first trough; the next is its point reflection.
    let wave = |x: f64| Point::new(x, amp * (k * x).sin());
    let slope = |x: f64| unit(Vec2::new(1.0, amp * k * (k * x).cos()));
    let x0 = 0.04 * period;
    let v = Volute {
        c: Point::new(0.3 * period, -0.3 * amp),
        r0: 0.95 * amp,
        th0: -PI / 2.0,
        dir: 1.0,
        turns: 1.15,
        ratio: 0.3,
    };
    let sw = swell(1.2, 5.0, 1.6, 0.3);
    let curl = scroll(
        wave(x0),
        slope(x0) + Vec2::new(0.0, -0.9),
        0.5 * amp,
        0.6 * amp,
        v,
        &sw,
        Cap::Round,
        2.6,
    );
    let xl = 0.62 * period;
    let leaf0 = leaf(
        wave(xl),
        wave(xl) + Vec2::new(0.16 * period, 0.55 * amp),
        -0.12,
        9.0,
        0.0,
    );
    for i in 0..n {
        let base = Affine::translate((i as f64 * period, 0.0));
        let half = base * Affine::rotate_about(PI, Point::new(0.5 * period, 0.0));
        for p in [&curl, &leaf0] {
            out.push(place(p, base));
            out.push(place(p, half));
        }
    }
    out
}

fn ornament_2mp() -> Art {
    let size = 1414.0;
    let mut art = Art::new(1414, 1414);
    let frame = |inset: f64, w: f64| {
        let mut p = orient(
            Rect::new(inset, inset, size - inset, size - inset).to_path(0.1),
            true,
        );
        p.extend(orient(
            Rect::new(inset + w, inset + w, size - inset - w, size - inset - w).to_path(0.1),
            false,
        ));
        p
    };
    art.add("#000", frame(40.0, 10.0));
    art.add("#000", frame(58.0, 3.0));
    art.add("#000", frame(196.0, 3.0));
    // Vines along the four edges, between corner rosettes.
    let (n, period) = (5, 170.0);
    let v = vine(n, period, 22.0);
    for q in 0..4 {
        let rot = Affine::rotate_about(q as f64 * PI / 2.0, Point::new(707.0, 707.0));
        let a = rot * Affine::translate((707.0 - 0.5 * n as f64 * period, 127.0));
        for p in &v {
            art.add("#000", place(p, a));
        }
    }
    for (x, y) in [
        (127.0, 127.0),
        (1287.0, 127.0),
        (127.0, 1287.0),
        (1287.0, 1287.0),
    ] {
        for p in rosette(Point::new(x, y), 0.26) {
            art.add("#000", p);
        }
    }
    // Centre rosette with the filigree above and (turned) below.
    for p in rosette(Point::new(707.0, 707.0), 0.98) {
        art.add("#000", p);
    }
    let comp = scroll_composition();
    let top = Affine::translate((707.0 - 0.8 * 384.0, 150.0)) * Affine::scale(0.8);
    let bottom = Affine::rotate_about(PI, Point::new(707.0, 707.0)) * top;
    for p in &comp {
        art.add("#000", place(p, top));
        art.add("#000", place(p, bottom));
    }
    art
}

// ---------------------------------------------------------------------------
// Output.
// ---------------------------------------------------------------------------

fn render(art: &Art) -> tiny_skia::Pixmap {
    let tree = usvg::Tree::from_str(&art.svg(), &usvg::Options::default()).expect("valid SVG");
    let mut pm = tiny_skia::Pixmap::new(art.w, art.h).expect("non-empty");
    pm.fill(tiny_skia::Color::WHITE);
    resvg::render(&tree, tiny_skia::Transform::identity(), &mut pm.as_mut());
    pm
}

fn save_png(path: &Path, w: u32, h: u32, data: &[u8], ty: ExtendedColorType) {
    let f = BufWriter::new(File::create(path).expect("create PNG"));
    PngEncoder::new_with_quality(f, CompressionType::Best, FilterType::Adaptive)
        .write_image(data, w, h, ty)
        .expect("write PNG");
}

#[derive(Clone, Copy, PartialEq)]
enum Out {
    /// Anti-aliased grayscale PNG.
    Gray,
    /// Anti-aliased grayscale PNG plus a thresholded `-binary` PNG.
    GrayAndBinary,
    /// Anti-aliased RGB PNG.
    Rgb,
    /// Thresholded black/white PNG only.
    BinaryOnly,
    /// Anti-aliased grayscale PNG only, no SVG (another name's drawing).
    GrayOnly,
}

fn emit(dir: &Path, name: &str, art: &Art, out: Out) {
    if out != Out::GrayOnly {
        std::fs::write(dir.join(format!("{name}.svg")), art.svg()).expect("write SVG");
    }
    let pm = render(art);
    let px = pm.data();
    let gray: Vec<u8> = px
        .chunks_exact(4)
        .map(|p| {
            let y = 0.2126 * p[0] as f64 + 0.7152 * p[1] as f64 + 0.0722 * p[2] as f64;
            y.round().clamp(0.0, 255.0) as u8
        })
        .collect();
    let binary: Vec<u8> = gray
        .iter()
        .map(|&v| if v < 128 { 0 } else { 255 })
        .collect();
    let (w, h) = (art.w, art.h);
    match out {
        Out::Gray | Out::GrayAndBinary | Out::GrayOnly => {
            save_png(
                &dir.join(format!("{name}.png")),
                w,
                h,
                &gray,
                ExtendedColorType::L8,
            );
            if out == Out::GrayAndBinary {
                save_png(
                    &dir.join(format!("{name}-binary.png")),
                    w,
                    h,
                    &binary,
                    ExtendedColorType::L8,
                );
            }
        }
        Out::Rgb => {
            let rgb: Vec<u8> = px
                .chunks_exact(4)
                .flat_map(|p| [p[0], p[1], p[2]])
                .collect();
            save_png(
                &dir.join(format!("{name}.png")),
                w,
                h,
                &rgb,
                ExtendedColorType::Rgb8,
            );
        }
        Out::BinaryOnly => save_png(
            &dir.join(format!("{name}.png")),
            w,
            h,
            &binary,
            ExtendedColorType::L8,
        ),
    }
    println!("wrote {name}");
}

fn main() {
    let dir = PathBuf::from(
        std::env::args()
            .nth(1)
            .unwrap_or_else(|| "samples/trace".to_string()),
    );
    std::fs::create_dir_all(&dir).expect("create output directory");
    emit(&dir, "glyph-a", &glyph_art(glyph_a()), Out::GrayAndBinary);
    emit(&dir, "glyph-g", &glyph_art(glyph_g()), Out::Gray);
    emit(&dir, "glyph-s", &glyph_art(glyph_s()), Out::Gray);
    emit(
        &dir,
        "ornament-scroll",
        &ornament_scroll(),
        Out::GrayAndBinary,
    );
    emit(&dir, "ornament-rosette", &ornament_rosette(), Out::Gray);
    emit(&dir, "thin-lines", &thin_lines(), Out::GrayAndBinary);
    emit(&dir, "holes", &holes(), Out::Gray);
    emit(&dir, "two-colour", &two_colour(), Out::Rgb);
    emit(&dir, "ornament-2mp", &ornament_2mp(), Out::BinaryOnly);
    // The same drawing anti-aliased; its truth is `ornament-2mp.svg`.
    emit(&dir, "ornament-2mp-aa", &ornament_2mp(), Out::GrayOnly);
}
