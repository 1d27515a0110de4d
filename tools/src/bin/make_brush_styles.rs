//! Generates flourish's own brush style libraries (exemplar art).
//!
//! Three DecoBrush-style libraries are drawn procedurally, each with ten
//! horizontal-ish exemplar strokes that fit a 512×512 viewBox:
//!
//! * `vine/`: a floral vine. A dark green stem of varying width carries
//!   alternating pointed leaves (with a cut-out midrib on the larger ones),
//!   tapering spiral tendrils and small berry clusters; it starts in a
//!   tendril curl or a bud and ends in a leaf or a curl. Two layers:
//!   stem `#2f5d3a`, leaves `#6b9a45`.
//! * `scroll/`: calligraphic scrolls and wings in black. Every stroke is
//!   drawn with a simulated broad-nib pen (width follows the stroke
//!   direction), ending in ball-tipped volutes or hairline points, with
//!   feather-like wing strokes branching off some of them.
//! * `doodle/`: a continuous pen line of loops and crossings (telephone
//!   cord, cursive e-loops) in dark ink, of near-uniform width, ending in a
//!   ball or a small hook.
//!
//! All ink is written as filled outlines: variable-width strokes are the
//! centre line offset left and right by a width profile (inner sides are
//! clamped to the local radius of curvature so outlines never fold), closed
//! with round caps or tapered points, then fitted with cubic Béziers. Each
//! SVG also carries the exemplar's main branch as an invisible
//! `<path id="spine">`, and `style.toml` lists each file with the spine's
//! start and end point (both verified to lie on the ink).
//!
//! The output is deterministic (a fixed-seed LCG supplies the jitter).
//! Regenerate with:
//!
//! ```text
//! cargo run --release -p flourish-tools --bin make_brush_styles -- styles/
//! ```
//!
//! An optional second argument (`vine`, `scroll` or `doodle`) writes just
//! that style. Set `BRUSH_ART_DEBUG=DIR` to also get a full-size PNG of
//! every exemplar with its spine drawn in red.
//!
//! Besides the exemplars, each style folder gets a `sheet.png` preview
//! (all exemplars on white, spine in red) for judging the art by eye; it
//! is not part of the library and is git-ignored.

use std::f64::consts::{PI, TAU};
use std::fmt::Write as _;
use std::path::Path;

use kurbo::simplify::{simplify_bezpath, SimplifyOptLevel, SimplifyOptions};
use kurbo::{Affine, BezPath, Circle, PathEl, Point, Shape, Vec2};
use resvg::{tiny_skia, usvg};

/// Spacing of centre-line samples, in px.
const STEP: f64 = 1.0;
/// Exemplar canvas size (SPEC: each library stroke lies within 512×512).
const SIZE: f64 = 512.0;
/// Largest extent of an exemplar's ink; the rest is margin.
const MAX_EXTENT: f64 = 492.0;
/// Outline fitting tolerance, in px.
const FIT_ACCURACY: f64 = 0.08;

// ---------------------------------------------------------------------------
// Randomness and small maths helpers
// ---------------------------------------------------------------------------

/// A tiny deterministic linear congruential generator.
struct Lcg(u64);

impl Lcg {
    fn new(seed: u64) -> Self {
        let mut g = Lcg(seed ^ 0x9e37_79b9_7f4a_7c15);
        g.next_f64();
        g
    }

    /// Uniform in [0, 1).
    fn next_f64(&mut self) -> f64 {
        self.0 = self
            .0
            .wrapping_mul(6_364_136_223_846_793_005)
            .wrapping_add(1_442_695_040_888_963_407);
        (self.0 >> 11) as f64 / (1u64 << 53) as f64
    }

    /// Uniform in [a, b).
    fn range(&mut self, a: f64, b: f64) -> f64 {
        a + (b - a) * self.next_f64()
    }
}

fn lerp(a: f64, b: f64, t: f64) -> f64 {
    a + (b - a) * t
}

/// Hermite smoothstep of `x` between `e0` and `e1`, clamped to [0, 1].
fn smoothstep(e0: f64, e1: f64, x: f64) -> f64 {
    let t = ((x - e0) / (e1 - e0)).clamp(0.0, 1.0);
    t * t * (3.0 - 2.0 * t)
}

fn dir(angle: f64) -> Vec2 {
    Vec2::new(angle.cos(), angle.sin())
}

/// Left-hand normal of a direction in SVG (y-down) coordinates.
fn left_of(t: Vec2) -> Vec2 {
    Vec2::new(t.y, -t.x)
}

// ---------------------------------------------------------------------------
// Centre lines
// ---------------------------------------------------------------------------

/// A centre line sampled at (nearly) uniform arc length `h`.
#[derive(Clone, Debug)]
struct Centerline {
    pts: Vec<Point>,
    h: f64,
}

impl Centerline {
    /// Resamples a dense polyline at uniform arc length close to [`STEP`].
    fn from_points(dense: &[Point]) -> Self {
        let mut cum = vec![0.0];
        for w in dense.windows(2) {
            cum.push(cum.last().unwrap() + (w[1] - w[0]).hypot());
        }
        let total = *cum.last().unwrap();
        let n = ((total / STEP).ceil() as usize).max(2);
        let h = total / n as f64;
        let mut pts = Vec::with_capacity(n + 1);
        let mut j = 0;
        for i in 0..=n {
            let s = (i as f64 * h).min(total);
            while j + 2 < cum.len() && cum[j + 1] < s {
                j += 1;
            }
            let seg = (cum[j + 1] - cum[j]).max(1e-12);
            let t = ((s - cum[j]) / seg).clamp(0.0, 1.0);
            pts.push(dense[j].lerp(dense[j + 1], t));
        }
        Centerline { pts, h }
    }

    /// Samples a Bézier path (first subpath only is expected).
    fn from_path(path: &BezPath) -> Self {
        let mut dense = Vec::new();
        kurbo::flatten(path, 0.002, |el| match el {
            PathEl::MoveTo(p) | PathEl::LineTo(p) => dense.push(p),
            _ => {}
        });
        Self::from_points(&dense)
    }

    /// A "turtle" curve: starts at `start` heading `angle` (radians, SVG
    /// y-down, so positive curvature turns clockwise on screen) and bends
    /// with curvature `k(u)`, `u` = fraction of `len` travelled.
    fn turtle(start: Point, angle: f64, len: f64, k: impl Fn(f64) -> f64) -> Self {
        let sub = 8;
        let n = (len / STEP).ceil().max(2.0) as usize * sub;
        let ds = len / n as f64;
        let mut p = start;
        let mut a = angle;
        let mut dense = vec![p];
        for i in 0..n {
            let u = (i as f64 + 0.5) / n as f64;
            let am = a + 0.5 * k(u) * ds;
            p += dir(am) * ds;
            a += k(u) * ds;
            dense.push(p);
        }
        Self::from_points(&dense)
    }

    fn len(&self) -> f64 {
        (self.pts.len() - 1) as f64 * self.h
    }

    fn n(&self) -> usize {
        self.pts.len()
    }

    /// Unit tangent at sample `i`.
    fn tangent(&self, i: usize) -> Vec2 {
        let last = self.n() - 1;
        let (a, b) = match i {
            0 => (0, 1),
            _ if i == last => (last - 1, last),
            _ => (i - 1, i + 1),
        };
        (self.pts[b] - self.pts[a]).normalize()
    }

    /// Signed curvature at sample `i`; positive turns toward the left normal.
    fn curvature(&self, i: usize) -> f64 {
        let last = self.n() - 1;
        let i = i.clamp(1, last - 1);
        let t0 = (self.pts[i] - self.pts[i - 1]).normalize();
        let t1 = (self.pts[i + 1] - self.pts[i]).normalize();
        -t0.cross(t1) / self.h
    }

    /// Index of the sample nearest arc length `s`.
    fn index_at(&self, s: f64) -> usize {
        ((s / self.h).round().max(0.0) as usize).min(self.n() - 1)
    }

    /// Point and unit tangent at arc length `s`, interpolated between
    /// samples (for offsetting other curves smoothly along this one).
    fn frame_at(&self, s: f64) -> (Point, Vec2) {
        let x = (s / self.h).clamp(0.0, (self.n() - 1) as f64);
        let i = (x.floor() as usize).min(self.n() - 2);
        let f = x - i as f64;
        let p = self.pts[i].lerp(self.pts[i + 1], f);
        let t = self.tangent(i).lerp(self.tangent(i + 1), f).normalize();
        (p, t)
    }

    fn point_at(&self, s: f64) -> Point {
        self.pts[self.index_at(s)]
    }

    fn tangent_at(&self, s: f64) -> Vec2 {
        self.tangent(self.index_at(s))
    }

    fn angle_at(&self, s: f64) -> f64 {
        self.tangent_at(s).atan2()
    }

    fn start_angle(&self) -> f64 {
        self.tangent(0).atan2()
    }

    fn end_angle(&self) -> f64 {
        self.tangent(self.n() - 1).atan2()
    }

    fn start(&self) -> Point {
        self.pts[0]
    }

    fn end(&self) -> Point {
        *self.pts.last().unwrap()
    }

    fn reversed(&self) -> Self {
        let mut pts = self.pts.clone();
        pts.reverse();
        Centerline { pts, h: self.h }
    }

    /// The two lines joined end to start (the join is resampled).
    fn concat(&self, other: &Centerline) -> Self {
        let mut dense = self.pts.clone();
        dense.extend_from_slice(&other.pts[1..]);
        Self::from_points(&dense)
    }

    /// The part between arc lengths `s0` and `s1`.
    fn slice(&self, s0: f64, s1: f64) -> Self {
        let (a, b) = (self.index_at(s0), self.index_at(s1));
        Centerline::from_points(&self.pts[a..=b])
    }

    fn transform(&self, t: Affine) -> Self {
        let pts = self.pts.iter().map(|&p| t * p).collect();
        let scale = t.as_coeffs()[0].hypot(t.as_coeffs()[1]);
        Centerline {
            pts,
            h: self.h * scale,
        }
    }

    /// The centre line as a smooth open Bézier path.
    fn to_bez(&self) -> BezPath {
        smooth_polyline(&self.pts, false)
    }
}

// ---------------------------------------------------------------------------
// Outlines
// ---------------------------------------------------------------------------

/// Fits a smooth Bézier path through a polyline (Catmull-Rom, then
/// simplified). Vertices where the polyline turns sharply are kept as
/// corners (the tips of tapered strokes and leaves).
fn smooth_polyline(raw: &[Point], closed: bool) -> BezPath {
    let mut pts: Vec<Point> = Vec::with_capacity(raw.len());
    for &p in raw {
        if pts.last().is_none_or(|q: &Point| (p - *q).hypot() > 0.02) {
            pts.push(p);
        }
    }
    if closed && pts.len() > 2 && (pts[0] - *pts.last().unwrap()).hypot() < 0.02 {
        pts.pop();
    }
    let n = pts.len();
    let get = |i: isize| -> Point {
        if closed {
            pts[i.rem_euclid(n as isize) as usize]
        } else {
            pts[i.clamp(0, n as isize - 1) as usize]
        }
    };
    // Incoming and outgoing tangent (scaled to the neighbouring chords).
    let mut tin = vec![Vec2::ZERO; n];
    let mut tout = vec![Vec2::ZERO; n];
    for i in 0..n {
        let ii = i as isize;
        let (prev, cur, next) = (get(ii - 1), get(ii), get(ii + 1));
        let din = cur - prev;
        let dout = next - cur;
        let open_end = !closed && (i == 0 || i == n - 1);
        let corner = open_end
            || din.hypot() < 1e-9
            || dout.hypot() < 1e-9
            || din.normalize().dot(dout.normalize()) < (40f64).to_radians().cos();
        if corner {
            tin[i] = din;
            tout[i] = dout;
        } else {
            let t = (next - prev) * 0.5;
            tin[i] = t;
            tout[i] = t;
        }
    }
    let mut path = BezPath::new();
    path.move_to(pts[0]);
    let segs = if closed { n } else { n - 1 };
    for i in 0..segs {
        let j = (i + 1) % n;
        let (p0, p1) = (pts[i], pts[j]);
        let chord = (p1 - p0).hypot();
        let scale = |v: Vec2| {
            let l = v.hypot();
            if l > 1e-12 {
                v * (chord / l)
            } else {
                v
            }
        };
        path.curve_to(p0 + scale(tout[i]) / 3.0, p1 - scale(tin[j]) / 3.0, p1);
    }
    if closed {
        path.close_path();
    }
    // (SimplifyOptLevel::Optimize gives ~20% fewer segments but can panic
    // inside kurbo 0.13 on looping outlines, so plain subdivision it is.)
    let opts = SimplifyOptions::default()
        .opt_level(SimplifyOptLevel::Subdivide)
        .angle_thresh(1e-2);
    simplify_bezpath(path, FIT_ACCURACY, &opts)
}

/// Outline of a variable-width stroke along `line`.
///
/// `half_width(u, tangent)` gives the half width at fraction `u` of the
/// length. Ends with non-zero width get round caps; ends tapering to zero
/// become points. The inner side of every bend is clamped to 90% of the
/// radius of curvature, so the offset never folds over itself.
fn stroke(line: &Centerline, half_width: impl Fn(f64, Vec2) -> f64) -> BezPath {
    let n = line.n();
    let mut left = Vec::with_capacity(n);
    let mut right = Vec::with_capacity(n);
    let mut widths = Vec::with_capacity(n);
    for i in 0..n {
        let u = i as f64 / (n - 1) as f64;
        let t = line.tangent(i);
        let nrm = left_of(t);
        let w = half_width(u, t).max(0.0);
        // Curvature averaged over a few samples, for a calmer clamp.
        let k = (i.saturating_sub(2)..(i + 3).min(n))
            .map(|j| line.curvature(j))
            .sum::<f64>()
            / (i.saturating_sub(2)..(i + 3).min(n)).len() as f64;
        let limit = if k.abs() > 1e-9 {
            0.9 / k.abs()
        } else {
            f64::MAX
        };
        let (wl, wr) = if k > 0.0 {
            (w.min(limit), w)
        } else {
            (w, w.min(limit))
        };
        let p = line.pts[i];
        left.push(p + nrm * wl);
        right.push(p - nrm * wr);
        widths.push(w);
    }
    let mut ring = left.clone();
    let cap_steps = 16;
    let (we, te) = (widths[n - 1], line.tangent(n - 1));
    if we > 0.05 {
        let c = line.pts[n - 1];
        for k in 1..cap_steps {
            let a = PI * k as f64 / cap_steps as f64;
            ring.push(c + (left_of(te) * a.cos() + te * a.sin()) * we);
        }
    }
    ring.extend(right.iter().rev());
    let (ws, ts) = (widths[0], line.tangent(0));
    if ws > 0.05 {
        let c = line.pts[0];
        for k in 1..cap_steps {
            let a = PI * k as f64 / cap_steps as f64;
            ring.push(c - (left_of(ts) * a.cos() + ts * a.sin()) * ws);
        }
    }
    smooth_polyline(&ring, true)
}

fn circle(c: Point, r: f64) -> BezPath {
    Circle::new(c, r).to_path(0.01)
}

/// A pointed leaf (or bud) as a closed Bézier outline, optionally with a
/// tapered midrib cut out of it (use the even-odd fill rule).
///
/// `base` is the stalk end, `angle` the leaf axis, `bend` curls the tip
/// sideways (fraction of the length, signed), `widest` is where the blade
/// is widest (fraction of the length).
struct LeafShape {
    len: f64,
    half_width: f64,
    bend: f64,
    widest: f64,
    midrib: bool,
}

fn leaf(base: Point, angle: f64, shape: &LeafShape) -> BezPath {
    let LeafShape {
        len: l,
        half_width: w,
        bend,
        widest: m,
        midrib,
    } = *shape;
    let xf = Affine::translate(base.to_vec2()) * Affine::rotate(angle);
    // Bend: shift sideways by bend·l·x², in leaf coordinates.
    let bent = |x: f64, y: f64| -> Point {
        let xn = x / l;
        xf * Point::new(x, y + bend * l * xn * xn)
    };
    let mut p = BezPath::new();
    p.move_to(bent(0.0, 0.0));
    for side in [1.0, -1.0] {
        let pts = [
            (0.10 * l, 0.55 * w),
            ((m - 0.18) * l, w),
            (m * l, w),
            ((m + 0.22) * l, w),
            (0.80 * l, 0.30 * w),
            (l, 0.0),
        ];
        let pts: Vec<(f64, f64)> = if side > 0.0 {
            pts.to_vec()
        } else {
            // Walk back from the tip along the other edge.
            let mut v: Vec<(f64, f64)> = pts[..5].iter().rev().cloned().collect();
            v.push((0.0, 0.0));
            v.iter().map(|&(x, y)| (x, -y)).collect()
        };
        for c in pts.chunks(3) {
            p.curve_to(
                bent(c[0].0, c[0].1),
                bent(c[1].0, c[1].1),
                bent(c[2].0, c[2].1),
            );
        }
    }
    p.close_path();
    if midrib {
        let r = 0.11 * w;
        let (x0, x1) = (0.07 * l, 0.84 * l);
        p.move_to(bent(x0, r));
        p.curve_to(
            bent(x0 + 0.25 * l, r),
            bent(x1 - 0.3 * l, 0.25 * r),
            bent(x1, 0.0),
        );
        p.curve_to(
            bent(x1 - 0.3 * l, -0.25 * r),
            bent(x0 + 0.25 * l, -r),
            bent(x0, -r),
        );
        p.curve_to(bent(x0 - 0.6 * r, -r), bent(x0 - 0.6 * r, r), bent(x0, r));
        p.close_path();
    }
    p
}

/// A spiral that continues a stroke: curvature ramps from `k0` to `k1`
/// (signed; positive turns clockwise on screen) with exponent `pow`.
fn spiral(start: Point, angle: f64, len: f64, k0: f64, k1: f64, pow: f64) -> Centerline {
    Centerline::turtle(start, angle, len, |u| k0 + (k1 - k0) * u.powf(pow))
}

// ---------------------------------------------------------------------------
// Exemplars and output
// ---------------------------------------------------------------------------

/// One filled shape of an exemplar.
struct Ink {
    layer: usize,
    path: BezPath,
    evenodd: bool,
}

/// One exemplar: layered ink plus its main branch.
struct Exemplar {
    inks: Vec<Ink>,
    spine: Centerline,
}

impl Exemplar {
    fn new(spine: Centerline) -> Self {
        Exemplar {
            inks: Vec::new(),
            spine,
        }
    }

    fn add(&mut self, layer: usize, path: BezPath) {
        self.inks.push(Ink {
            layer,
            path,
            evenodd: false,
        });
    }

    fn add_evenodd(&mut self, layer: usize, path: BezPath) {
        self.inks.push(Ink {
            layer,
            path,
            evenodd: true,
        });
    }

    /// Centres the ink on the canvas, shrinking it if it would not fit.
    fn fit_to_canvas(&mut self, name: &str) {
        let mut bb = self.inks[0].path.bounding_box();
        for ink in &self.inks[1..] {
            bb = bb.union(ink.path.bounding_box());
        }
        let extent = bb.width().max(bb.height());
        let scale = if extent > MAX_EXTENT {
            eprintln!(
                "  {name}: ink is {:.0}x{:.0}, scaled by {:.3}",
                bb.width(),
                bb.height(),
                MAX_EXTENT / extent
            );
            MAX_EXTENT / extent
        } else {
            1.0
        };
        let xf = Affine::translate((SIZE / 2.0, SIZE / 2.0))
            * Affine::scale(scale)
            * Affine::translate(-bb.center().to_vec2());
        for ink in &mut self.inks {
            ink.path.apply_affine(xf);
        }
        self.spine = self.spine.transform(xf);
        self.inks.sort_by_key(|i| i.layer);
    }

    /// The exemplar as SVG; with `spine_debug`, only a visible overlay of
    /// the spine and its end points instead.
    fn svg(&self, colors: &[&str], spine_debug: bool) -> String {
        let mut s = String::new();
        let _ = writeln!(
            s,
            r#"<svg xmlns="http://www.w3.org/2000/svg" width="512" height="512" viewBox="0 0 512 512">"#
        );
        if !spine_debug {
            let _ = writeln!(
                s,
                r#"<path id="spine" d="{}" fill="none" stroke="none"/>"#,
                path_d(&self.spine.to_bez())
            );
        }
        for ink in self.inks.iter().filter(|_| !spine_debug) {
            let rule = if ink.evenodd {
                r#" fill-rule="evenodd""#
            } else {
                ""
            };
            let _ = writeln!(
                s,
                r#"<path fill="{}"{} d="{}"/>"#,
                colors[ink.layer],
                rule,
                path_d(&ink.path)
            );
        }
        if spine_debug {
            let _ = writeln!(
                s,
                r##"<path d="{}" fill="none" stroke="#e0303a" stroke-width="2.5" stroke-opacity="0.8"/>"##,
                path_d(&self.spine.to_bez())
            );
            for p in [self.spine.start(), self.spine.end()] {
                let _ = writeln!(
                    s,
                    r##"<circle cx="{}" cy="{}" r="5" fill="#e0303a"/>"##,
                    num(p.x),
                    num(p.y)
                );
            }
        }
        s.push_str("</svg>\n");
        s
    }
}

/// A number with at most two decimals, without trailing zeros.
fn num(v: f64) -> String {
    let r = (v * 100.0).round() / 100.0;
    let mut s = format!("{:.2}", if r == 0.0 { 0.0 } else { r });
    while s.ends_with('0') {
        s.pop();
    }
    if s.ends_with('.') {
        s.pop();
    }
    s
}

fn path_d(p: &BezPath) -> String {
    let mut d = String::new();
    let pt = |d: &mut String, p: Point| {
        let _ = write!(d, "{} {}", num(p.x), num(p.y));
    };
    for el in p.elements() {
        if !d.is_empty() {
            d.push(' ');
        }
        match *el {
            PathEl::MoveTo(a) => {
                d.push('M');
                pt(&mut d, a);
            }
            PathEl::LineTo(a) => {
                d.push('L');
                pt(&mut d, a);
            }
            PathEl::QuadTo(a, b) => {
                d.push('Q');
                pt(&mut d, a);
                d.push(' ');
                pt(&mut d, b);
            }
            PathEl::CurveTo(a, b, c) => {
                d.push('C');
                pt(&mut d, a);
                d.push(' ');
                pt(&mut d, b);
                d.push(' ');
                pt(&mut d, c);
            }
            PathEl::ClosePath => d.push('Z'),
        }
    }
    d
}

fn render(svg: &str, pixmap: &mut tiny_skia::Pixmap, xf: tiny_skia::Transform) {
    let tree = usvg::Tree::from_str(svg, &usvg::Options::default()).expect("valid SVG");
    resvg::render(&tree, xf, &mut pixmap.as_mut());
}

/// Checks that the spine's ends lie on the ink, and with `whole` that
/// all of it does.
fn check_spine(name: &str, ex: &Exemplar, svg: &str, whole: bool) -> bool {
    let mut pm = tiny_skia::Pixmap::new(512, 512).unwrap();
    render(svg, &mut pm, tiny_skia::Transform::identity());
    let alpha = |p: Point| -> u8 {
        let (x, y) = (p.x.floor() as i64, p.y.floor() as i64);
        if !(0..512).contains(&x) || !(0..512).contains(&y) {
            return 0;
        }
        pm.pixel(x as u32, y as u32).unwrap().alpha()
    };
    let sp = &ex.spine;
    let mut ok = true;
    for (what, p) in [("start", sp.start()), ("end", sp.end())] {
        if alpha(p) < 250 {
            eprintln!("  {name}: spine {what} {p:?} is not on the ink");
            ok = false;
        }
    }
    let off = sp.pts.iter().filter(|&&p| alpha(p) < 128).count();
    if off > 0 && whole {
        eprintln!(
            "  {name}: {off} of {} spine samples off the ink",
            sp.pts.len()
        );
    }
    ok
}

struct Style {
    name: &'static str,
    colors: &'static [&'static str],
    exemplars: Vec<Exemplar>,
    /// Whether the whole spine runs on the ink (not so for the doodle,
    /// whose line loops around its spine).
    spine_on_ink: bool,
}

fn write_style(root: &Path, style: Style) -> std::io::Result<()> {
    let dir = root.join(style.name);
    std::fs::create_dir_all(&dir)?;
    let mut toml = String::from("kind = \"brush\"\nresolution = 512\nsdf = true\n");
    let cols = 4;
    let cell = 320u32;
    let rows = style.exemplars.len().div_ceil(cols) as u32;
    let mut sheet = tiny_skia::Pixmap::new(cell * cols as u32, cell * rows).unwrap();
    sheet.fill(tiny_skia::Color::WHITE);
    for (i, ex) in style.exemplars.iter().enumerate() {
        let name = format!("{}-{:02}", style.name, i + 1);
        let file = format!("{name}.svg");
        let svg = ex.svg(style.colors, false);
        std::fs::write(dir.join(&file), &svg)?;
        check_spine(&name, ex, &svg, style.spine_on_ink);
        let (s, e) = (ex.spine.start(), ex.spine.end());
        let _ = write!(
            toml,
            "\n[[exemplar]]\nfile = \"{file}\"\nstart = [{:.1}, {:.1}]\nend = [{:.1}, {:.1}]\n",
            s.x, s.y, e.x, e.y
        );
        let (cx, cy) = ((i % cols) as u32 * cell, (i / cols) as u32 * cell);
        let k = cell as f32 / 512.0;
        let frame = tiny_skia::Rect::from_xywh(
            cx as f32 + 1.0,
            cy as f32 + 1.0,
            cell as f32 - 2.0,
            cell as f32 - 2.0,
        )
        .unwrap();
        let mut paint = tiny_skia::Paint::default();
        paint.set_color_rgba8(236, 236, 236, 255);
        let path = tiny_skia::PathBuilder::from_rect(frame);
        sheet.stroke_path(
            &path,
            &paint,
            &tiny_skia::Stroke::default(),
            tiny_skia::Transform::identity(),
            None,
        );
        let xf = tiny_skia::Transform::from_row(k, 0.0, 0.0, k, cx as f32, cy as f32);
        render(&svg, &mut sheet, xf);
        render(&ex.svg(style.colors, true), &mut sheet, xf);
        if let Some(dbg) = std::env::var_os("BRUSH_ART_DEBUG") {
            // Full-size render of one exemplar, for close inspection.
            let mut pm = tiny_skia::Pixmap::new(512, 512).unwrap();
            pm.fill(tiny_skia::Color::WHITE);
            let id = tiny_skia::Transform::identity();
            render(&svg, &mut pm, id);
            render(&ex.svg(style.colors, true), &mut pm, id);
            let img = image::RgbaImage::from_raw(512, 512, pm.data().to_vec()).unwrap();
            img.save(Path::new(&dbg).join(format!("{name}.png")))
                .unwrap();
        }
    }
    std::fs::write(dir.join("style.toml"), toml)?;
    let img = image::RgbaImage::from_raw(sheet.width(), sheet.height(), sheet.data().to_vec())
        .expect("sheet buffer");
    img.save(dir.join("sheet.png")).expect("write sheet.png");
    println!(
        "wrote {} ({} exemplars)",
        dir.display(),
        style.exemplars.len()
    );
    Ok(())
}

fn main() -> std::io::Result<()> {
    let root = std::env::args().nth(1).unwrap_or_else(|| "styles".into());
    let root = Path::new(&root);
    let only = std::env::args().nth(2);
    for style in [vine::style(), scroll::style(), doodle::style()] {
        if style.exemplars.is_empty() || only.as_deref().is_some_and(|o| o != style.name) {
            continue;
        }
        write_style(root, style)?;
    }
    Ok(())
}

/// A main spine from control points given in a local frame (x along the
/// stroke), as one or more cubic segments.
fn spine_path(pts: &[(f64, f64)]) -> BezPath {
    let mut p = BezPath::new();
    p.move_to(pts[0]);
    for c in pts[1..].chunks(3) {
        p.curve_to(c[0], c[1], c[2]);
    }
    p
}

// ---------------------------------------------------------------------------
// Vine
// ---------------------------------------------------------------------------

mod vine {
    use super::*;

    const STEM: usize = 0;
    const LEAF: usize = 1;

    #[derive(Clone, Copy, PartialEq)]
    pub enum Start {
        Curl,
        Bud,
    }

    #[derive(Clone, Copy, PartialEq)]
    pub enum End {
        Leaf,
        Curl,
    }

    pub struct Spec {
        pub seed: u64,
        pub spine: &'static [(f64, f64)],
        /// Largest stem half width, px.
        pub width: f64,
        pub start: Start,
        pub end: End,
        /// Mean distance between leaves along the stem.
        pub spacing: f64,
        pub leaf_scale: f64,
        /// Place a tendril every n-th gap between leaves (0: none).
        pub tendril_every: usize,
        /// Place a berry cluster every n-th gap between leaves (0: none).
        pub berry_every: usize,
        /// Which side the first leaf grows on (+1 left, -1 right).
        pub first_side: f64,
    }

    pub fn style() -> Style {
        let specs = [
            Spec {
                seed: 1,
                spine: &[(0.0, 0.0), (130.0, -30.0), (260.0, 30.0), (370.0, 0.0)],
                width: 7.0,
                start: Start::Curl,
                end: End::Leaf,
                spacing: 62.0,
                leaf_scale: 1.0,
                tendril_every: 2,
                berry_every: 3,
                first_side: 1.0,
            },
            Spec {
                seed: 2,
                spine: &[(0.0, 0.0), (70.0, 0.0), (140.0, -6.0), (210.0, -4.0)],
                width: 6.3,
                start: Start::Bud,
                end: End::Curl,
                spacing: 52.0,
                leaf_scale: 0.85,
                tendril_every: 0,
                berry_every: 0,
                first_side: -1.0,
            },
            Spec {
                seed: 3,
                spine: &[(0.0, 40.0), (110.0, -60.0), (260.0, -60.0), (350.0, 40.0)],
                width: 7.7,
                start: Start::Curl,
                end: End::Curl,
                spacing: 66.0,
                leaf_scale: 1.05,
                tendril_every: 3,
                berry_every: 2,
                first_side: -1.0,
            },
            Spec {
                seed: 4,
                spine: &[(0.0, 0.0), (90.0, 10.0), (210.0, 10.0), (300.0, 0.0)],
                width: 6.3,
                start: Start::Bud,
                end: End::Leaf,
                spacing: 58.0,
                leaf_scale: 0.95,
                tendril_every: 2,
                berry_every: 0,
                first_side: 1.0,
            },
            Spec {
                seed: 5,
                spine: &[(0.0, 0.0), (150.0, 0.0), (260.0, -10.0), (330.0, -140.0)],
                width: 8.4,
                start: Start::Curl,
                end: End::Leaf,
                spacing: 64.0,
                leaf_scale: 1.1,
                tendril_every: 3,
                berry_every: 4,
                first_side: -1.0,
            },
            Spec {
                seed: 6,
                spine: &[(0.0, 0.0), (80.0, -50.0), (170.0, -50.0), (250.0, 0.0)],
                width: 5.6,
                start: Start::Curl,
                end: End::Leaf,
                spacing: 54.0,
                leaf_scale: 0.85,
                tendril_every: 0,
                berry_every: 2,
                first_side: 1.0,
            },
            Spec {
                seed: 7,
                spine: &[(0.0, 0.0), (120.0, 60.0), (220.0, -60.0), (350.0, 0.0)],
                width: 7.0,
                start: Start::Bud,
                end: End::Curl,
                spacing: 60.0,
                leaf_scale: 1.0,
                tendril_every: 2,
                berry_every: 3,
                first_side: -1.0,
            },
            Spec {
                seed: 8,
                spine: &[(0.0, 0.0), (120.0, 2.0), (220.0, -2.0), (330.0, 0.0)],
                width: 7.7,
                start: Start::Curl,
                end: End::Leaf,
                spacing: 60.0,
                leaf_scale: 1.0,
                tendril_every: 2,
                berry_every: 5,
                first_side: 1.0,
            },
            Spec {
                seed: 9,
                spine: &[(0.0, -20.0), (60.0, 40.0), (180.0, 60.0), (230.0, 10.0)],
                width: 6.3,
                start: Start::Bud,
                end: End::Leaf,
                spacing: 55.0,
                leaf_scale: 0.9,
                tendril_every: 3,
                berry_every: 2,
                first_side: 1.0,
            },
            Spec {
                seed: 10,
                spine: &[
                    (0.0, 0.0),
                    (80.0, -40.0),
                    (150.0, -40.0),
                    (210.0, 0.0),
                    (270.0, 35.0),
                    (320.0, 30.0),
                    (370.0, -10.0),
                ],
                width: 8.4,
                start: Start::Curl,
                end: End::Curl,
                spacing: 64.0,
                leaf_scale: 1.1,
                tendril_every: 2,
                berry_every: 3,
                first_side: -1.0,
            },
        ];
        Style {
            name: "vine",
            colors: &["#2f5d3a", "#6b9a45"],
            exemplars: specs.iter().map(build).collect(),
            spine_on_ink: true,
        }
    }

    /// Half width of the stem at fraction `u` of the main part: thickest
    /// near the start, thinning toward the growing tip.
    fn stem_width(spec: &Spec, u: f64) -> f64 {
        spec.width * lerp(1.0, 0.55, u.powf(0.8)) * (1.0 + 0.05 * (u * 9.0).sin())
    }

    pub fn build(spec: &Spec) -> Exemplar {
        let mut rng = Lcg::new(spec.seed);
        let main = Centerline::from_path(&spine_path(spec.spine));
        let l = main.len();
        let w0 = stem_width(spec, 0.0);
        let w1 = stem_width(spec, 1.0);

        // Start and end treatments extend the stem line.
        let curl_len = |w: f64| 110.0 + 10.0 * w;
        let start_curl = (spec.start == Start::Curl).then(|| {
            let side = -spec.first_side;
            let len = curl_len(w0);
            spiral(
                main.start(),
                main.start_angle() + PI,
                len,
                side * 0.004,
                side * 0.12,
                2.2,
            )
        });
        let end_curl = (spec.end == End::Curl).then(|| {
            let side = spec.first_side;
            let len = curl_len(w1) * 0.9;
            spiral(
                main.end(),
                main.end_angle(),
                len,
                side * 0.004,
                side * 0.13,
                2.0,
            )
        });
        let pre = start_curl.as_ref().map_or(0.0, |c| c.len());
        let post = end_curl.as_ref().map_or(0.0, |c| c.len());
        let mut full = main.clone();
        if let Some(c) = &start_curl {
            full = c.reversed().concat(&full);
        }
        if let Some(c) = &end_curl {
            full = full.concat(c);
        }
        let total = full.len();
        let width = |u: f64, _t: Vec2| -> f64 {
            let s = u * total;
            if s < pre {
                w0 * (s / pre).powf(0.75)
            } else if s > pre + l {
                w1 * ((total - s) / post).powf(0.75)
            } else {
                stem_width(spec, (s - pre) / l)
            }
        };

        // The spine: the main stem, trimmed a little at bare ends.
        let trim0 = if spec.start == Start::Curl { 4.0 } else { 3.0 };
        let spine = main.slice(trim0, l - 3.0);
        let mut ex = Exemplar::new(spine);
        ex.add(STEM, stroke(&full, width));

        // Leaves, tendrils and berries along the main stem.
        let mut s = 34.0 + rng.range(0.0, 12.0);
        let mut side = spec.first_side;
        let mut gap = 0;
        let stop = l - if spec.end == End::Leaf { 55.0 } else { 30.0 };
        while s < stop {
            let u = s / l;
            let p = main.point_at(s);
            let a = main.angle_at(s);
            let size = spec.leaf_scale * lerp(1.0, 0.72, u) * rng.range(0.9, 1.1);
            add_leaf(&mut ex, &mut rng, p, a, side, size, stem_width(spec, u));
            // Something on the opposite side, half way to the next leaf.
            let next = s + spec.spacing * rng.range(0.85, 1.15);
            let mid = 0.5 * (s + next);
            gap += 1;
            if mid < stop - 10.0 {
                let q = main.point_at(mid);
                let b = main.angle_at(mid);
                if spec.tendril_every > 0 && gap % spec.tendril_every == 0 {
                    add_tendril(&mut ex, &mut rng, q, b, -side, size);
                } else if spec.berry_every > 0 && gap % spec.berry_every == 0 {
                    add_berries(&mut ex, &mut rng, q, b, -side, size);
                }
            }
            side = -side;
            s = next;
        }
        match spec.end {
            End::Leaf => {
                let shape = LeafShape {
                    len: 88.0 * spec.leaf_scale,
                    half_width: 23.0 * spec.leaf_scale,
                    bend: -0.06 * spec.first_side,
                    widest: 0.40,
                    midrib: true,
                };
                let a = main.end_angle();
                let base = main.end() - dir(a) * 3.0;
                ex.add_evenodd(LEAF, leaf(base, a, &shape));
            }
            End::Curl => {}
        }
        if spec.start == Start::Bud {
            add_bud(&mut ex, main.start(), main.start_angle() + PI, w0);
        }
        ex.fit_to_canvas(&format!("vine seed {}", spec.seed));
        ex
    }

    /// A leaf on a short curved stalk, leaning toward the growing tip.
    fn add_leaf(
        ex: &mut Exemplar,
        rng: &mut Lcg,
        p: Point,
        stem_angle: f64,
        side: f64,
        size: f64,
        stem_w: f64,
    ) {
        // Left of the direction is a negative angle in y-down coordinates.
        let out = stem_angle - side * rng.range(0.85, 1.0);
        let stalk_len = 13.0 * size;
        let stalk = Centerline::turtle(p, out, stalk_len, |_| side * 0.02);
        // At least 2 px wide at the coarsest analysis level (8 units) at its tip.
        let sw = (0.45 * stem_w).max(6.0);
        ex.add(STEM, stroke(&stalk, |u, _| lerp(sw * 1.2, sw * 0.7, u)));
        let len = 78.0 * size;
        let shape = LeafShape {
            len,
            half_width: len * rng.range(0.25, 0.29),
            bend: side * rng.range(0.05, 0.10),
            widest: 0.40,
            midrib: len > 55.0,
        };
        let a = stalk.end_angle() + side * 0.22;
        ex.add_evenodd(LEAF, leaf(stalk.end() - dir(a) * 1.5, a, &shape));
    }

    /// A thin tendril that leaves the stem and rolls up into a spiral.
    fn add_tendril(
        ex: &mut Exemplar,
        rng: &mut Lcg,
        p: Point,
        stem_angle: f64,
        side: f64,
        size: f64,
    ) {
        let out = stem_angle - side * rng.range(0.55, 0.75);
        let len = rng.range(150.0, 180.0) * size;
        // Curl back toward the stem's start, away from the leaves ahead.
        let line = spiral(p, out, len, side * 0.008, -side * 0.17, 1.9);
        // Full width (≥ 2 px at the coarsest analysis level) until the last
        // fifth, which tapers to the spiral's point.
        ex.add(
            STEM,
            stroke(&line, |u, _| 4.4 * ((1.0 - u) / 0.2).min(1.0).powf(0.6)),
        );
    }

    /// Three berries on a forked stalk.
    fn add_berries(
        ex: &mut Exemplar,
        rng: &mut Lcg,
        p: Point,
        stem_angle: f64,
        side: f64,
        size: f64,
    ) {
        let out = stem_angle - side * rng.range(0.7, 0.9);
        let stalk = Centerline::turtle(p, out, 24.0 * size, |_| 0.0);
        ex.add(STEM, stroke(&stalk, |u, _| lerp(4.4, 4.2, u)));
        let fork = stalk.end();
        let base = stalk.end_angle();
        for (da, l, r) in [(-0.6, 18.0, 7.5), (0.05, 25.0, 8.5), (0.7, 17.0, 7.0)] {
            let a = base + da * side;
            let twig = Centerline::turtle(fork, a, l * size, |_| side * 0.01);
            ex.add(STEM, stroke(&twig, |u, _| lerp(4.2, 4.1, u)));
            let c = twig.end() + dir(twig.end_angle()) * (r * size * 0.8);
            ex.add(STEM, circle(c, r * size.sqrt()));
        }
    }

    /// A closed bud at the start of the stem, held by two sepals.
    fn add_bud(ex: &mut Exemplar, p: Point, angle: f64, stem_w: f64) {
        let bud = LeafShape {
            len: 42.0,
            half_width: 14.5,
            bend: 0.0,
            widest: 0.45,
            midrib: false,
        };
        ex.add(LEAF, leaf(p, angle, &bud));
        for side in [1.0, -1.0] {
            let sepal = LeafShape {
                len: 24.0,
                half_width: 5.0,
                bend: side * 0.25,
                widest: 0.35,
                midrib: false,
            };
            ex.add(
                STEM,
                leaf(p + dir(angle) * 1.0, angle + side * 0.55, &sepal),
            );
        }
        ex.add(STEM, circle(p, stem_w * 1.15));
    }
}

// ---------------------------------------------------------------------------
// Scroll
// ---------------------------------------------------------------------------

mod scroll {
    use super::*;

    const INK: usize = 0;
    /// Direction of the broad nib's edge (up-right, y-down radians): strokes
    /// moving this way are hairlines, strokes across it are full width.
    const NIB: f64 = -0.62;
    /// Hairline half width, px.
    const THIN: f64 = 3.0;

    /// Half width of a broad-nib stroke moving along `t`.
    fn nib(t: Vec2, thick: f64) -> f64 {
        lerp(THIN, thick, (t.atan2() - NIB).sin().abs())
    }

    #[derive(Clone, Copy)]
    pub enum Tip {
        /// A hairline entry or exit.
        Point,
        /// A volute curling to the given side (+1 clockwise on screen),
        /// ending in a ball; `len` is its length in px.
        Volute { side: f64, len: f64 },
    }

    /// Feather strokes branching off one side of the main stroke.
    pub struct Wing {
        /// +1: left of the drawing direction (up for a left-to-right stroke).
        pub side: f64,
        /// Range of the main stroke they grow from, as fractions.
        pub from: f64,
        pub to: f64,
        pub count: usize,
        /// Feather lengths at the first and the last feather.
        pub len0: f64,
        pub len1: f64,
    }

    /// A secondary scroll: leaves the main stroke and rolls into a volute.
    pub struct Branch {
        pub at: f64,
        pub side: f64,
        pub len: f64,
    }

    pub struct Spec {
        pub seed: u64,
        pub spine: &'static [(f64, f64)],
        pub thick: f64,
        pub start: Tip,
        pub end: Tip,
        pub wing: Option<Wing>,
        pub branches: &'static [Branch],
    }

    pub fn style() -> Style {
        use Tip::*;
        let specs = [
            Spec {
                seed: 11,
                spine: &[(0.0, 40.0), (120.0, -40.0), (260.0, -40.0), (360.0, 20.0)],
                thick: 9.0,
                start: Point,
                end: Volute {
                    side: 1.0,
                    len: 200.0,
                },
                wing: Some(Wing {
                    side: 1.0,
                    from: 0.22,
                    to: 0.7,
                    count: 6,
                    len0: 150.0,
                    len1: 80.0,
                }),
                branches: &[],
            },
            Spec {
                seed: 12,
                spine: &[(0.0, 0.0), (70.0, -50.0), (140.0, 50.0), (210.0, 0.0)],
                thick: 8.0,
                start: Volute {
                    side: 1.0,
                    len: 170.0,
                },
                end: Volute {
                    side: 1.0,
                    len: 170.0,
                },
                wing: None,
                branches: &[],
            },
            Spec {
                seed: 13,
                spine: &[(0.0, 0.0), (110.0, 8.0), (230.0, 8.0), (340.0, -6.0)],
                thick: 8.5,
                start: Volute {
                    side: -1.0,
                    len: 190.0,
                },
                end: Point,
                wing: Some(Wing {
                    side: -1.0,
                    from: 0.3,
                    to: 0.75,
                    count: 4,
                    len0: 90.0,
                    len1: 55.0,
                }),
                branches: &[],
            },
            Spec {
                seed: 14,
                spine: &[(0.0, 60.0), (160.0, 70.0), (300.0, 40.0), (360.0, -100.0)],
                thick: 10.0,
                start: Point,
                end: Volute {
                    side: -1.0,
                    len: 190.0,
                },
                wing: Some(Wing {
                    side: -1.0,
                    from: 0.25,
                    to: 0.8,
                    count: 6,
                    len0: 70.0,
                    len1: 130.0,
                }),
                branches: &[],
            },
            Spec {
                seed: 15,
                spine: &[(0.0, 0.0), (100.0, -60.0), (170.0, 60.0), (270.0, 0.0)],
                thick: 9.5,
                start: Volute {
                    side: 1.0,
                    len: 190.0,
                },
                end: Volute {
                    side: 1.0,
                    len: 190.0,
                },
                wing: None,
                branches: &[Branch {
                    at: 0.5,
                    side: -1.0,
                    len: 150.0,
                }],
            },
            Spec {
                seed: 16,
                spine: &[(0.0, 20.0), (70.0, -20.0), (150.0, -20.0), (220.0, 20.0)],
                thick: 7.5,
                start: Point,
                end: Volute {
                    side: 1.0,
                    len: 160.0,
                },
                wing: Some(Wing {
                    side: 1.0,
                    from: 0.25,
                    to: 0.6,
                    count: 3,
                    len0: 85.0,
                    len1: 60.0,
                }),
                branches: &[],
            },
            Spec {
                seed: 17,
                spine: &[(0.0, 0.0), (140.0, -40.0), (260.0, 40.0), (400.0, 0.0)],
                thick: 9.0,
                start: Point,
                end: Point,
                wing: None,
                branches: &[
                    Branch {
                        at: 0.3,
                        side: 1.0,
                        len: 140.0,
                    },
                    Branch {
                        at: 0.65,
                        side: -1.0,
                        len: 150.0,
                    },
                ],
            },
            Spec {
                seed: 18,
                spine: &[(0.0, 0.0), (90.0, -4.0), (180.0, 4.0), (270.0, 0.0)],
                thick: 8.0,
                start: Volute {
                    side: 1.0,
                    len: 180.0,
                },
                end: Volute {
                    side: -1.0,
                    len: 180.0,
                },
                wing: None,
                branches: &[],
            },
            Spec {
                seed: 19,
                spine: &[(0.0, -60.0), (60.0, 60.0), (200.0, 70.0), (300.0, 20.0)],
                thick: 10.0,
                start: Point,
                end: Volute {
                    side: -1.0,
                    len: 170.0,
                },
                wing: Some(Wing {
                    side: -1.0,
                    from: 0.35,
                    to: 0.8,
                    count: 5,
                    len0: 110.0,
                    len1: 70.0,
                }),
                branches: &[],
            },
            Spec {
                seed: 20,
                spine: &[(0.0, 0.0), (130.0, -45.0), (260.0, -45.0), (390.0, 0.0)],
                thick: 9.0,
                start: Volute {
                    side: -1.0,
                    len: 180.0,
                },
                end: Point,
                wing: Some(Wing {
                    side: -1.0,
                    from: 0.3,
                    to: 0.85,
                    count: 5,
                    len0: 60.0,
                    len1: 110.0,
                }),
                branches: &[Branch {
                    at: 0.2,
                    side: 1.0,
                    len: 120.0,
                }],
            },
        ];
        Style {
            name: "scroll",
            colors: &["#000"],
            exemplars: specs.iter().map(build).collect(),
            spine_on_ink: true,
        }
    }

    /// A volute continuing a stroke from `p` along `angle`.
    fn volute(p: Point, angle: f64, side: f64, len: f64) -> Centerline {
        spiral(p, angle, len * 1.3, side * 0.003, side * 0.08, 2.1)
    }

    /// Radius of a volute's ball terminal.
    fn ball_radius(thick: f64) -> f64 {
        0.42 * thick + 2.5
    }

    pub fn build(spec: &Spec) -> Exemplar {
        let mut rng = Lcg::new(spec.seed);
        let main = Centerline::from_path(&spine_path(spec.spine));
        let l = main.len();
        let thick = spec.thick * 1.2;
        let mut full = main.clone();
        let (mut pre, mut post) = (0.0, 0.0);
        let mut balls = Vec::new();
        if let Tip::Volute { side, len } = spec.start {
            let v = volute(main.start(), main.start_angle() + PI, side, len);
            balls.push(v.end());
            pre = v.len();
            full = v.reversed().concat(&full);
        }
        if let Tip::Volute { side, len } = spec.end {
            let v = volute(main.end(), main.end_angle(), side, len);
            balls.push(v.end());
            post = v.len();
            full = full.concat(&v);
        }
        let total = full.len();
        // Envelope: hairline entries/exits taper over the outer 30%;
        // volutes thin toward their ball.
        let envelope = |s: f64| -> f64 {
            if s < pre {
                lerp(0.45, 1.0, (s / pre).powf(0.8))
            } else if s > pre + l {
                lerp(0.45, 1.0, ((total - s) / post).powf(0.8))
            } else {
                let m = s - pre;
                let a = if pre > 0.0 {
                    1.0
                } else {
                    smoothstep(0.0, 0.3 * l, m)
                };
                let b = if post > 0.0 {
                    1.0
                } else {
                    smoothstep(0.0, 0.3 * l, l - m)
                };
                a.min(b)
            }
        };
        let width = |u: f64, t: Vec2| -> f64 {
            let e = envelope(u * total);
            // The hairline part fades in over the first few px only.
            let hair = smoothstep(0.0, 0.02, u.min(1.0 - u)).sqrt();
            THIN * hair + (nib(t, thick) - THIN) * e
        };
        // The spine: where the main stroke is at least 2.5 px wide (half).
        let ok = |s: f64| width((s + pre) / total, main.tangent_at(s)) >= 2.5;
        let mut s0 = 0.0;
        while !ok(s0) && s0 < 0.3 * l {
            s0 += 1.0;
        }
        let mut s1 = l;
        while !ok(s1) && s1 > 0.7 * l {
            s1 -= 1.0;
        }
        let mut ex = Exemplar::new(main.slice(s0 + 2.0, s1 - 2.0));
        ex.add(INK, stroke(&full, width));
        for b in balls {
            ex.add(INK, circle(b, ball_radius(thick)));
        }
        if let Some(w) = &spec.wing {
            add_wing(&mut ex, &mut rng, &main, w, thick);
        }
        for b in spec.branches {
            add_branch(&mut ex, &main, b, thick);
        }
        ex.fit_to_canvas(&format!("scroll seed {}", spec.seed));
        ex
    }

    /// Comma-shaped feathers: they swell just off the main stroke and
    /// taper to a point that hooks slightly forward.
    fn add_wing(ex: &mut Exemplar, rng: &mut Lcg, main: &Centerline, w: &Wing, thick: f64) {
        let l = main.len();
        for i in 0..w.count {
            let f = if w.count > 1 {
                i as f64 / (w.count - 1) as f64
            } else {
                0.5
            };
            let s = lerp(w.from, w.to, f) * l;
            let len = lerp(w.len0, w.len1, f) * rng.range(0.95, 1.05);
            // Out of the main stroke, leaning toward its end.
            let lean = lerp(1.2, 1.0, f) + rng.range(-0.04, 0.04);
            let a = main.angle_at(s) - w.side * lean;
            // Sweep toward the drawing direction, ever tighter to the tip.
            let turn = w.side * 0.85 / len;
            let line = Centerline::turtle(main.point_at(s), a, len, |u| turn * 2.0 * u);
            let fw = 0.75 * thick;
            ex.add(
                INK,
                stroke(&line, |u, t| {
                    let swell = lerp(0.55, 1.0, smoothstep(0.0, 0.15, u));
                    let taper = ((1.0 - u) / 0.55).min(1.0).powf(1.15);
                    // Never a hairline before the tip (2 px at the coarsest level).
                    (nib(t, fw) * swell).max(4.0) * taper
                }),
            );
        }
    }

    /// A smaller scroll leaving the main stroke and rolling into a volute.
    fn add_branch(ex: &mut Exemplar, main: &Centerline, b: &Branch, thick: f64) {
        let s = b.at * main.len();
        let a = main.angle_at(s) - b.side * 0.45;
        // Leave gently, then roll up against the direction of the main stroke.
        let k1 = b.side * 0.12;
        let line = Centerline::turtle(main.point_at(s), a, b.len, |u| {
            -b.side * 0.012 * (1.0 - u) + k1 * u.powf(1.8)
        });
        let bt = 0.7 * thick;
        ex.add(
            INK,
            stroke(&line, |u, t| {
                let e = lerp(1.0, 0.45, u.powf(0.8)) * smoothstep(0.0, 0.12, u).sqrt();
                THIN + (nib(t, bt) - THIN) * e
            }),
        );
        ex.add(INK, circle(line.end(), ball_radius(bt)));
    }
}

mod doodle {
    use super::*;

    const INK: usize = 0;

    #[derive(Clone, Copy)]
    pub enum Cap {
        /// A round blob of ink.
        Ball,
        /// A small curl turning to the given side, tapering to a point.
        Hook(f64),
    }

    pub struct Spec {
        pub seed: u64,
        pub spine: &'static [(f64, f64)],
        pub loops: usize,
        /// Loop height (centred cords swing ±height), px.
        pub height: f64,
        /// Backward reach per loop relative to the forward advance (> 1
        /// makes loops; larger is tighter, more overlapping loops).
        pub reach: f64,
        /// Loops on one side of the spine (cursive e-loops) instead of
        /// centred on it (telephone cord).
        pub garland: bool,
        /// Pen half width, px.
        pub pen: f64,
        pub start: Cap,
        pub end: Cap,
    }

    pub fn style() -> Style {
        use Cap::*;
        let specs = [
            Spec {
                seed: 21,
                spine: &[(0.0, 0.0), (130.0, -6.0), (270.0, 6.0), (400.0, 0.0)],
                loops: 7,
                height: 56.0,
                reach: 2.2,
                garland: false,
                pen: 4.5,
                start: Ball,
                end: Ball,
            },
            Spec {
                seed: 22,
                spine: &[(0.0, 0.0), (70.0, 0.0), (130.0, 0.0), (200.0, 0.0)],
                loops: 4,
                height: 60.0,
                reach: 2.2,
                garland: true,
                pen: 4.2,
                start: Ball,
                end: Hook(1.0),
            },
            Spec {
                seed: 23,
                spine: &[(0.0, 40.0), (120.0, -50.0), (260.0, -50.0), (380.0, 40.0)],
                loops: 6,
                height: 64.0,
                reach: 2.1,
                garland: true,
                pen: 4.8,
                start: Hook(-1.0),
                end: Ball,
            },
            Spec {
                seed: 24,
                spine: &[(0.0, 0.0), (150.0, -80.0), (290.0, 80.0), (440.0, 0.0)],
                loops: 10,
                height: 42.0,
                reach: 2.8,
                garland: false,
                pen: 4.2,
                start: Ball,
                end: Ball,
            },
            Spec {
                seed: 25,
                spine: &[(0.0, 0.0), (180.0, 0.0), (260.0, -20.0), (300.0, -160.0)],
                loops: 6,
                height: 52.0,
                reach: 2.0,
                garland: false,
                pen: 4.8,
                start: Hook(1.0),
                end: Hook(-1.0),
            },
            Spec {
                seed: 26,
                spine: &[(0.0, 0.0), (100.0, 10.0), (200.0, 10.0), (300.0, 0.0)],
                loops: 4,
                height: 80.0,
                reach: 2.2,
                garland: true,
                pen: 5.0,
                start: Ball,
                end: Hook(1.0),
            },
            Spec {
                seed: 27,
                spine: &[(0.0, 0.0), (160.0, 0.0), (310.0, 0.0), (470.0, 0.0)],
                loops: 12,
                height: 36.0,
                reach: 3.2,
                garland: false,
                pen: 4.1,
                start: Ball,
                end: Ball,
            },
            Spec {
                seed: 28,
                spine: &[(0.0, -30.0), (80.0, 40.0), (180.0, 40.0), (260.0, -30.0)],
                loops: 4,
                height: 60.0,
                reach: 1.7,
                garland: false,
                pen: 4.6,
                start: Hook(-1.0),
                end: Ball,
            },
            Spec {
                seed: 29,
                spine: &[(0.0, 0.0), (130.0, 50.0), (270.0, -50.0), (400.0, 0.0)],
                loops: 6,
                height: 62.0,
                reach: 2.3,
                garland: true,
                pen: 4.5,
                start: Ball,
                end: Ball,
            },
            Spec {
                seed: 30,
                spine: &[(0.0, 60.0), (120.0, 70.0), (260.0, 40.0), (330.0, -60.0)],
                loops: 5,
                height: 66.0,
                reach: 2.4,
                garland: false,
                pen: 4.8,
                start: Ball,
                end: Hook(1.0),
            },
        ];
        Style {
            name: "doodle",
            colors: &["#1b2a4a"],
            exemplars: specs.iter().map(build).collect(),
            spine_on_ink: false,
        }
    }

    /// The pen's path: a trochoid (prolate cycloid) laid along the spine,
    /// with loops easing in and out at the ends so the line starts and ends
    /// on the spine.
    fn pen_path(spec: &Spec, base: &Centerline, rng: &mut Lcg) -> Centerline {
        let l = base.len();
        let n = spec.loops as f64;
        let t_end = TAU * n;
        let a = l / t_end;
        let b = spec.reach * a;
        // Per-loop size jitter, smoothly interpolated: hand-drawn unevenness.
        let amps: Vec<f64> = (0..=spec.loops + 1)
            .map(|_| rng.range(0.85, 1.12))
            .collect();
        let amp = |t: f64| {
            let x = t / TAU;
            let i = (x.floor() as usize).min(spec.loops);
            let f = 0.5 - 0.5 * (PI * x.fract()).cos();
            lerp(amps[i], amps[i + 1], f)
        };
        let ease = 0.75 * TAU;
        let samples = (t_end / 0.004) as usize;
        let mut dense = Vec::with_capacity(samples + 1);
        for i in 0..=samples {
            let t = t_end * i as f64 / samples as f64;
            // Loops reach full width sooner than full height, so the first
            // and last loops are open rather than tiny ink blots.
            let e = smoothstep(0.0, ease, t) * smoothstep(0.0, ease, t_end - t) * amp(t);
            let ex = smoothstep(0.0, 0.45 * ease, t) * smoothstep(0.0, 0.45 * ease, t_end - t);
            let x = (a * t + ex * amp(t) * b * t.sin()).clamp(0.0, l);
            // Loops form where the pen runs backward, at t = π (mod 2π).
            let y = if spec.garland {
                e * spec.height * 0.5 * (1.0 - t.cos())
            } else {
                -e * spec.height * 0.5 * t.cos()
            };
            let (p, tangent) = base.frame_at(x);
            dense.push(p + left_of(tangent) * y);
        }
        Centerline::from_points(&dense)
    }

    /// A small hook continuing the line from `p` along `angle`.
    fn hook(p: Point, angle: f64, side: f64) -> Centerline {
        spiral(p, angle, 46.0, side * 0.02, side * 0.16, 1.4)
    }

    pub fn build(spec: &Spec) -> Exemplar {
        let mut rng = Lcg::new(spec.seed);
        let base = Centerline::from_path(&spine_path(spec.spine));
        let mut line = pen_path(spec, &base, &mut rng);
        let mut ex = Exemplar::new(base.slice(0.5, base.len() - 0.5));
        let (mut pre, mut post) = (0.0, 0.0);
        if let Cap::Hook(side) = spec.start {
            let h = hook(line.start(), line.start_angle() + PI, side);
            pre = h.len();
            line = h.reversed().concat(&line);
        }
        if let Cap::Hook(side) = spec.end {
            let h = hook(line.end(), line.end_angle(), side);
            post = h.len();
            line = line.concat(&h);
        }
        let total = line.len();
        let pen = spec.pen;
        let phase = rng.range(0.0, TAU);
        let width = |u: f64, _t: Vec2| -> f64 {
            let s = u * total;
            // A little pen pressure variation; hooks flick off to a point.
            let w = pen * (1.05 + 0.05 * (s / 37.0 + phase).sin());
            let a = if pre > 0.0 {
                (s / pre).min(1.0).powf(0.6)
            } else {
                1.0
            };
            let b = if post > 0.0 {
                ((total - s) / post).min(1.0).powf(0.6)
            } else {
                1.0
            };
            w * a.min(b)
        };
        ex.add(INK, stroke(&line, width));
        for (cap, p) in [(spec.start, base.start()), (spec.end, base.end())] {
            if let Cap::Ball = cap {
                ex.add(INK, circle(p, 2.0 * pen));
            }
        }
        ex.fit_to_canvas(&format!("doodle seed {}", spec.seed));
        ex
    }
}
