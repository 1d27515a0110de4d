//! Shared measurement code for comparing `flourish trace` with potrace
//! (`tests/potrace.rs`, `tools/src/bin/compare_potrace.rs`).
//!
//! * [`ground_truth`]: the exact outline of a sample's vector art in pixel
//!   coordinates of its PNG. The samples' PNGs are resvg renders of the SVG
//!   at its own size with the identity transform (user unit = pixel, see
//!   `tools/src/bin/make_trace_samples.rs`), so the SVG's shapes are flattened
//!   (0.01 px) with their absolute transforms, and the boundary of their
//!   union is kept: the outlines are cut into pieces of at most 0.5 px, each
//!   piece is kept when the points just left and right of it (±0.01 px) are
//!   on different sides of the union, and pieces whose ends and middle
//!   disagree are bisected down to 1/128 px. Only *ink* shapes count: fills
//!   whose colour is dark (luma < 50 %, the threshold the binary PNGs and
//!   potrace's bitmap use); in every sample but `two-colour` all fills are
//!   black.
//! * [`max_deviation`]: symmetric Hausdorff distance in px between traced
//!   paths (flattened at 0.01 px) and the truth, both sampled every 0.1 px
//!   of arc length, nearest distances from a uniform grid of segments.
//!   Accuracy about ±0.06 px (flattening plus half the sample spacing).
//! * [`run_potrace`], [`run_flourish`]: the two tracers, timed, with the
//!   same speck size: potrace's `-t` ([`potrace_turdsize`]) is set so both
//!   drop the same islands (flourish's `--min-area` counts a binary
//!   bitmap's pixels, as potrace's speck size does).

#![allow(dead_code)]

use flourish::{Document, Image, ImageOptions, TraceOptions};
use kurbo::{BezPath, Line, PathEl, Point, Rect, Vec2};
use resvg::tiny_skia;
use resvg::usvg;
use std::path::{Path, PathBuf};
use std::process::Command;
use std::time::{Duration, Instant};

/// The crate root (the folder holding `samples/`: the manifest's own for
/// the tests, its parent for the `tools/` programs that include this file).
pub fn root() -> PathBuf {
    let dir = PathBuf::from(env!("CARGO_MANIFEST_DIR"));
    match dir.parent() {
        Some(up) if !dir.join("samples").is_dir() && up.join("samples").is_dir() => {
            up.to_path_buf()
        }
        _ => dir,
    }
}

/// `samples/trace/NAME`.
pub fn sample(name: &str) -> PathBuf {
    root().join("samples/trace").join(name)
}

/// The ground-truth SVG of a sample PNG: `NAME.svg` for `NAME.png`,
/// `NAME-binary.png` and `NAME-aa.png`.
pub fn truth_svg_for(png: &Path) -> PathBuf {
    let stem = png.file_stem().unwrap().to_string_lossy().to_string();
    let stem = stem
        .strip_suffix("-binary")
        .or_else(|| stem.strip_suffix("-aa"))
        .unwrap_or(&stem)
        .to_string();
    png.with_file_name(format!("{stem}.svg"))
}

// ---------------------------------------------------------------------------
// Ground truth.
// ---------------------------------------------------------------------------

/// One flattened filled shape with a row index for winding numbers.
struct FlatShape {
    segs: Vec<Line>,
    even_odd: bool,
    bbox: Rect,
    /// Row `r` holds the segments whose y-range meets `[y0 + r, y0 + r + 1)`.
    rows: Vec<Vec<u32>>,
    y0: f64,
}

impl FlatShape {
    fn new(segs: Vec<Line>, even_odd: bool) -> Self {
        let mut bbox = Rect::new(f64::MAX, f64::MAX, f64::MIN, f64::MIN);
        for l in &segs {
            bbox = bbox.union_pt(l.p0).union_pt(l.p1);
        }
        let y0 = bbox.y0.floor();
        let nrows = ((bbox.y1 - y0).floor() as usize + 1).max(1);
        let mut rows = vec![Vec::new(); nrows];
        for (i, l) in segs.iter().enumerate() {
            let a = ((l.p0.y.min(l.p1.y) - y0).floor() as usize).min(nrows - 1);
            let b = ((l.p0.y.max(l.p1.y) - y0).floor() as usize).min(nrows - 1);
            for r in rows.iter_mut().take(b + 1).skip(a) {
                r.push(i as u32);
            }
        }
        FlatShape {
            segs,
            even_odd,
            bbox,
            rows,
            y0,
        }
    }

    fn contains(&self, p: Point) -> bool {
        if !(p.x >= self.bbox.x0
            && p.x <= self.bbox.x1
            && p.y >= self.bbox.y0
            && p.y <= self.bbox.y1)
        {
            return false;
        }
        let r = ((p.y - self.y0).floor() as usize).min(self.rows.len() - 1);
        let mut w = 0i32;
        for &i in &self.rows[r] {
            let l = self.segs[i as usize];
            let (a, b) = (l.p0, l.p1);
            if (a.y <= p.y) != (b.y <= p.y) {
                let x = a.x + (p.y - a.y) / (b.y - a.y) * (b.x - a.x);
                if x > p.x {
                    w += if b.y > a.y { 1 } else { -1 };
                }
            }
        }
        if self.even_odd {
            w % 2 != 0
        } else {
            w != 0
        }
    }
}

fn is_ink(paint: &usvg::Paint) -> bool {
    match paint {
        usvg::Paint::Color(c) => {
            (0.2126 * c.red as f64 + 0.7152 * c.green as f64 + 0.0722 * c.blue as f64) < 128.0
        }
        _ => true,
    }
}

fn collect(group: &usvg::Group, out: &mut Vec<FlatShape>) {
    for node in group.children() {
        match node {
            usvg::Node::Group(g) => collect(g, out),
            usvg::Node::Path(p) if p.is_visible() => {
                let t = p.abs_transform();
                if let Some(fill) = p.fill() {
                    if fill.opacity().get() > 0.0 && is_ink(fill.paint()) {
                        let mut segs = Vec::new();
                        flatten_segments(&to_kurbo(p.data(), t), 0.01, &mut segs);
                        out.push(FlatShape::new(segs, fill.rule() == usvg::FillRule::EvenOdd));
                    }
                }
                if let Some(stroke) = p.stroke() {
                    if stroke.opacity().get() > 0.0 && is_ink(stroke.paint()) {
                        let res = t.get_scale().0.max(t.get_scale().1).max(1e-3);
                        if let Some(outline) = p.data().stroke(&stroke.to_tiny_skia(), res) {
                            let mut segs = Vec::new();
                            flatten_segments(&to_kurbo(&outline, t), 0.01, &mut segs);
                            out.push(FlatShape::new(segs, false));
                        }
                    }
                }
            }
            _ => {}
        }
    }
}

/// The size of an SVG in user units (= px of its sample PNG).
pub fn svg_size(svg_path: &Path) -> (f64, f64) {
    let tree = load_svg(svg_path);
    (tree.size().width() as f64, tree.size().height() as f64)
}

/// The boundary of the union of the ink shapes of `svg_path`, in pixel
/// coordinates of its rendered PNG; see the module docs.
pub fn ground_truth(svg_path: &Path) -> Vec<Line> {
    use rayon::prelude::*;
    let tree = load_svg(svg_path);
    let mut shapes = Vec::new();
    collect(tree.root(), &mut shapes);
    let inside = |p: Point| shapes.iter().any(|s| s.contains(p));
    // Boundary test at a point of a segment with unit normal `n`.
    let on_boundary = |p: Point, n: Vec2| inside(p + n * 0.01) != inside(p - n * 0.01);
    let all: Vec<Line> = shapes.iter().flat_map(|s| s.segs.iter().copied()).collect();
    all.par_iter()
        .flat_map_iter(|l| {
            let mut out = Vec::new();
            let d = l.p1 - l.p0;
            let len = d.hypot();
            if len <= 1e-12 {
                return out;
            }
            let n = Vec2::new(-d.y, d.x) / len;
            let k = (len / 0.5).ceil().max(1.0) as usize;
            for i in 0..k {
                let a = l.p0.lerp(l.p1, i as f64 / k as f64);
                let b = l.p0.lerp(l.p1, (i + 1) as f64 / k as f64);
                keep_pieces(a, b, n, &on_boundary, 0, &mut out);
            }
            out
        })
        .collect()
}

/// Keeps the parts of `a`–`b` on the union's boundary, bisecting where its
/// classification changes.
fn keep_pieces(
    a: Point,
    b: Point,
    n: Vec2,
    on: &impl Fn(Point, Vec2) -> bool,
    depth: u32,
    out: &mut Vec<Line>,
) {
    let m = a.midpoint(b);
    let (ka, km, kb) = (on(a.lerp(b, 0.02), n), on(m, n), on(a.lerp(b, 0.98), n));
    if ka == km && km == kb {
        if km {
            out.push(Line::new(a, b));
        }
        return;
    }
    if depth >= 6 {
        // Below 1/128 px: keep the half-piece that is on the boundary.
        if km {
            out.push(Line::new(a, b));
        }
        return;
    }
    keep_pieces(a, m, n, on, depth + 1, out);
    keep_pieces(m, b, n, on, depth + 1, out);
}

// ---------------------------------------------------------------------------
// Distances.
// ---------------------------------------------------------------------------

/// Distance from `p` to segment `l`.
pub fn point_segment_distance(p: Point, l: &Line) -> f64 {
    let d = l.p1 - l.p0;
    let len2 = d.hypot2();
    let t = if len2 > 0.0 {
        ((p - l.p0).dot(d) / len2).clamp(0.0, 1.0)
    } else {
        0.0
    };
    (p - (l.p0 + d * t)).hypot()
}

/// The line segments of `path` flattened within `tolerance`, every subpath
/// closed.
pub fn flatten_segments(path: &BezPath, tolerance: f64, out: &mut Vec<Line>) {
    let mut subpath: Vec<Point> = Vec::new();
    let close = |pts: &mut Vec<Point>, out: &mut Vec<Line>| {
        if let (Some(&a), Some(&b)) = (pts.first(), pts.last()) {
            out.extend(pts.windows(2).map(|w| Line::new(w[0], w[1])));
            if a != b {
                out.push(Line::new(b, a));
            }
        }
        pts.clear();
    };
    kurbo::flatten(path, tolerance, |el| match el {
        PathEl::MoveTo(p) => {
            close(&mut subpath, out);
            subpath.push(p);
        }
        PathEl::LineTo(p) => subpath.push(p),
        PathEl::ClosePath => close(&mut subpath, out),
        _ => {}
    });
    close(&mut subpath, out);
}

/// A usvg path under `transform` as a kurbo path.
pub fn to_kurbo(path: &tiny_skia::Path, transform: tiny_skia::Transform) -> BezPath {
    let t = transform;
    let affine = kurbo::Affine::new([
        t.sx as f64,
        t.ky as f64,
        t.kx as f64,
        t.sy as f64,
        t.tx as f64,
        t.ty as f64,
    ]);
    let pt = |p: tiny_skia::Point| affine * Point::new(p.x as f64, p.y as f64);
    let mut out = BezPath::new();
    for seg in path.segments() {
        match seg {
            tiny_skia::PathSegment::MoveTo(p) => out.move_to(pt(p)),
            tiny_skia::PathSegment::LineTo(p) => out.line_to(pt(p)),
            tiny_skia::PathSegment::QuadTo(a, b) => out.quad_to(pt(a), pt(b)),
            tiny_skia::PathSegment::CubicTo(a, b, c) => out.curve_to(pt(a), pt(b), pt(c)),
            tiny_skia::PathSegment::Close => out.close_path(),
        }
    }
    out
}

/// Lines and curves drawn in `path` (moves and closes are not segments),
/// as the SVG writer counts them.
fn count_segments(path: &BezPath) -> usize {
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

/// Parses an SVG file with usvg.
fn load_svg(path: &Path) -> usvg::Tree {
    let data = std::fs::read(path).expect("SVG file");
    usvg::Tree::from_data(&data, &usvg::Options::default()).expect("SVG parses")
}

/// A uniform grid of segments for nearest-distance queries.
pub struct SegmentGrid {
    segs: Vec<Line>,
    cells: Vec<Vec<u32>>,
    origin: Point,
    cell: f64,
    nx: usize,
    ny: usize,
}

impl SegmentGrid {
    /// Indexes `lines` (long ones split) over `bounds` grown to fit them.
    pub fn new(lines: &[Line], bounds: Rect, cell: f64) -> Self {
        let mut segs = Vec::with_capacity(lines.len());
        let mut bb = bounds;
        for l in lines {
            let len = l.length();
            if !len.is_finite() {
                continue;
            }
            let k = (len / cell).ceil().max(1.0) as usize;
            for i in 0..k {
                let s = Line::new(
                    l.p0.lerp(l.p1, i as f64 / k as f64),
                    l.p0.lerp(l.p1, (i + 1) as f64 / k as f64),
                );
                bb = bb.union_pt(s.p0).union_pt(s.p1);
                segs.push(s);
            }
        }
        let origin = Point::new(bb.x0 - cell, bb.y0 - cell);
        let nx = ((bb.width() + 2.0 * cell) / cell).ceil() as usize + 1;
        let ny = ((bb.height() + 2.0 * cell) / cell).ceil() as usize + 1;
        let mut cells = vec![Vec::new(); nx * ny];
        for (i, s) in segs.iter().enumerate() {
            let (cx0, cy0) = Self::cell_of(
                origin,
                cell,
                nx,
                ny,
                Point::new(s.p0.x.min(s.p1.x), s.p0.y.min(s.p1.y)),
            );
            let (cx1, cy1) = Self::cell_of(
                origin,
                cell,
                nx,
                ny,
                Point::new(s.p0.x.max(s.p1.x), s.p0.y.max(s.p1.y)),
            );
            for cy in cy0..=cy1 {
                for cx in cx0..=cx1 {
                    cells[cy * nx + cx].push(i as u32);
                }
            }
        }
        SegmentGrid {
            segs,
            cells,
            origin,
            cell,
            nx,
            ny,
        }
    }

    fn cell_of(origin: Point, cell: f64, nx: usize, ny: usize, p: Point) -> (usize, usize) {
        let cx = ((p.x - origin.x) / cell)
            .floor()
            .clamp(0.0, (nx - 1) as f64) as usize;
        let cy = ((p.y - origin.y) / cell)
            .floor()
            .clamp(0.0, (ny - 1) as f64) as usize;
        (cx, cy)
    }

    /// Distance from `p` to the nearest segment (∞ when there are none).
    pub fn nearest(&self, p: Point) -> f64 {
        if self.segs.is_empty() {
            return f64::INFINITY;
        }
        let (cx, cy) = Self::cell_of(self.origin, self.cell, self.nx, self.ny, p);
        let mut best = f64::INFINITY;
        let max_r = self.nx.max(self.ny);
        for r in 0..=max_r {
            // Every cell at ring r + 1 or beyond is at least r cells away.
            let (x0, x1) = (cx as isize - r as isize, cx as isize + r as isize);
            let (y0, y1) = (cy as isize - r as isize, cy as isize + r as isize);
            for y in y0..=y1 {
                if y < 0 || y >= self.ny as isize {
                    continue;
                }
                let on_edge_row = y == y0 || y == y1;
                let mut x = x0;
                while x <= x1 {
                    if x >= 0 && x < self.nx as isize {
                        for &i in &self.cells[y as usize * self.nx + x as usize] {
                            best = best.min(point_segment_distance(p, &self.segs[i as usize]));
                        }
                    }
                    x = if on_edge_row || x == x1 { x + 1 } else { x1 };
                }
            }
            if best <= r as f64 * self.cell {
                break;
            }
        }
        best
    }
}

/// Points every `step` px along `lines` (both ends included).
fn sample_lines(lines: &[Line], step: f64) -> Vec<Point> {
    let mut pts = Vec::new();
    for l in lines {
        let k = (l.length() / step).ceil().max(1.0) as usize;
        for i in 0..=k {
            pts.push(l.p0.lerp(l.p1, i as f64 / k as f64));
        }
    }
    pts
}

/// `paths` flattened to segments at 0.01 px.
pub fn flatten_paths(paths: &[BezPath]) -> Vec<Line> {
    let mut out = Vec::new();
    for p in paths {
        flatten_segments(p, 0.01, &mut out);
    }
    out
}

/// Both directed Hausdorff distances (output → truth, truth → output), px.
pub fn deviations(paths: &[BezPath], truth: &[Line]) -> (f64, f64) {
    use rayon::prelude::*;
    let out = flatten_paths(paths);
    let mut bounds = Rect::new(0.0, 0.0, 1.0, 1.0);
    for l in out.iter().chain(truth) {
        bounds = bounds.union_pt(l.p0).union_pt(l.p1);
    }
    let cell = 4.0;
    let truth_grid = SegmentGrid::new(truth, bounds, cell);
    let out_grid = SegmentGrid::new(&out, bounds, cell);
    let a = sample_lines(&out, 0.1)
        .par_iter()
        .map(|&p| truth_grid.nearest(p))
        .reduce(|| 0.0, f64::max);
    let b = sample_lines(truth, 0.1)
        .par_iter()
        .map(|&p| out_grid.nearest(p))
        .reduce(|| 0.0, f64::max);
    (a, b)
}

/// The worst points of both directions: (distance, point on the output),
/// (distance, point on the truth).
pub fn worst_points(paths: &[BezPath], truth: &[Line]) -> ((f64, Point), (f64, Point)) {
    use rayon::prelude::*;
    let out = flatten_paths(paths);
    let mut bounds = Rect::new(0.0, 0.0, 1.0, 1.0);
    for l in out.iter().chain(truth) {
        bounds = bounds.union_pt(l.p0).union_pt(l.p1);
    }
    let truth_grid = SegmentGrid::new(truth, bounds, 4.0);
    let out_grid = SegmentGrid::new(&out, bounds, 4.0);
    let worst = |pts: Vec<Point>, g: &SegmentGrid| {
        pts.par_iter()
            .map(|&p| (g.nearest(p), p))
            .reduce(|| (0.0, Point::ZERO), |a, b| if b.0 > a.0 { b } else { a })
    };
    (
        worst(sample_lines(&out, 0.1), &truth_grid),
        worst(sample_lines(truth, 0.1), &out_grid),
    )
}

/// Truth points farther than `d` px from the output, as (distance, point),
/// one per `cluster` px cell, worst first.
pub fn far_truth_points(
    paths: &[BezPath],
    truth: &[Line],
    d: f64,
    cluster: f64,
) -> Vec<(f64, Point)> {
    let out = flatten_paths(paths);
    let mut bounds = Rect::new(0.0, 0.0, 1.0, 1.0);
    for l in out.iter().chain(truth) {
        bounds = bounds.union_pt(l.p0).union_pt(l.p1);
    }
    let g = SegmentGrid::new(&out, bounds, 4.0);
    let mut best = std::collections::BTreeMap::<(i64, i64), (f64, Point)>::new();
    for p in sample_lines(truth, 0.1) {
        let e = g.nearest(p);
        if e > d {
            let k = (
                (p.x / cluster).floor() as i64,
                (p.y / cluster).floor() as i64,
            );
            let slot = best.entry(k).or_insert((0.0, p));
            if e > slot.0 {
                *slot = (e, p);
            }
        }
    }
    let mut v: Vec<_> = best.into_values().collect();
    v.sort_by(|a, b| b.0.total_cmp(&a.0));
    v
}

/// Symmetric Hausdorff distance (px) between `paths` and the truth.
pub fn max_deviation(paths: &[BezPath], truth: &[Line]) -> f64 {
    let (a, b) = deviations(paths, truth);
    a.max(b)
}

// ---------------------------------------------------------------------------
// Tracers.
// ---------------------------------------------------------------------------

/// True when a `potrace` binary runs.
pub fn potrace_available() -> bool {
    Command::new("potrace")
        .arg("--version")
        .output()
        .map(|o| o.status.success())
        .unwrap_or(false)
}

/// Runs `potrace -s` with the speck size of [`potrace_turdsize`] on `pbm`,
/// writing `svg`; the wall time of the whole process.
pub fn potrace_process(pbm: &Path, svg: &Path) -> Duration {
    let t = Instant::now();
    let st = Command::new("potrace")
        .arg("-s")
        .arg("-t")
        .arg(potrace_turdsize().to_string())
        .arg("-o")
        .arg(svg)
        .arg(pbm)
        .status()
        .expect("run potrace");
    let e = t.elapsed();
    assert!(st.success(), "potrace failed: {st}");
    e
}

/// Ink mask of a bitmap: luma < 128.
pub fn ink_mask(bitmap: &image::GrayImage) -> Vec<bool> {
    bitmap.pixels().map(|p| p[0] < 128).collect()
}

/// The bitmap as binary PBM (P4), ink black.
pub fn pbm_bytes(bitmap: &image::GrayImage) -> Vec<u8> {
    let (w, h) = (bitmap.width() as usize, bitmap.height() as usize);
    let mut out = format!("P4\n{w} {h}\n").into_bytes();
    let stride = w.div_ceil(8);
    for y in 0..h {
        let mut row = vec![0u8; stride];
        for x in 0..w {
            if bitmap.get_pixel(x as u32, y as u32)[0] < 128 {
                row[x / 8] |= 0x80 >> (x % 8);
            }
        }
        out.extend_from_slice(&row);
    }
    out
}

fn median(mut v: Vec<Duration>) -> Duration {
    v.sort();
    v[v.len() / 2]
}

/// The paths of an SVG file (absolute transforms applied, then `scale`).
fn svg_paths(tree: &usvg::Tree, scale: (f64, f64)) -> Vec<BezPath> {
    fn walk(g: &usvg::Group, scale: (f64, f64), out: &mut Vec<BezPath>) {
        for node in g.children() {
            match node {
                usvg::Node::Group(g) => walk(g, scale, out),
                usvg::Node::Path(p) => out.push(
                    kurbo::Affine::scale_non_uniform(scale.0, scale.1)
                        * to_kurbo(p.data(), p.abs_transform()),
                ),
                _ => {}
            }
        }
    }
    let mut out = Vec::new();
    walk(tree.root(), scale, &mut out);
    out
}

/// potrace's speck size (`-t N`: islands of up to N pixels are dropped)
/// that drops what flourish's [`flourish_options`] drop (islands of fewer
/// than `min_area` pixels): `⌈min_area⌉ − 1`, 3 at flourish's default
/// (potrace's own default is 2). `POTRACE_TURDSIZE` overrides it.
pub fn potrace_turdsize() -> u32 {
    std::env::var("POTRACE_TURDSIZE")
        .ok()
        .and_then(|v| v.parse().ok())
        .unwrap_or_else(|| (flourish_options().min_area.ceil() as u32).saturating_sub(1))
}

/// Traces `bitmap` (ink where luma < 128) with potrace's defaults
/// (`potrace -s`) but for the speck size ([`potrace_turdsize`]): its paths
/// in pixel coordinates, its segment count (lines and curves) and the
/// median wall-clock time of `runs` runs of the process.
pub fn run_potrace(bitmap: &image::GrayImage, runs: usize) -> (Vec<BezPath>, usize, Duration) {
    let dir = tempfile::tempdir().expect("temp dir");
    let pbm = dir.path().join("in.pbm");
    let svg = dir.path().join("out.svg");
    std::fs::write(&pbm, pbm_bytes(bitmap)).expect("write PBM");
    let mut times = Vec::new();
    for _ in 0..runs.max(1) {
        let _ = std::fs::remove_file(&svg);
        times.push(potrace_process(&pbm, &svg));
    }
    let tree = load_svg(&svg);
    // potrace writes width/height in pt; map the tree's size onto the bitmap.
    let scale = (
        bitmap.width() as f64 / tree.size().width() as f64,
        bitmap.height() as f64 / tree.size().height() as f64,
    );
    let paths = svg_paths(&tree, scale);
    let segments = paths.iter().map(count_segments).sum();
    let raw = raw_segment_count(&std::fs::read_to_string(&svg).expect("potrace SVG"));
    assert_eq!(
        segments, raw,
        "potrace segments through usvg vs in the raw path data"
    );
    (paths, segments, median(times))
}

/// Lines and curves in the `d` attributes of SVG text (commands M L C Z,
/// either case, with implicit repetition: what potrace writes).
pub fn raw_segment_count(svg: &str) -> usize {
    let mut n = 0;
    for part in svg.split(" d=\"").skip(1) {
        let d = &part[..part.find('"').unwrap_or(part.len())];
        let mut cmd = ' ';
        let mut nums = 0usize;
        let flush = |cmd: char, nums: usize| match cmd.to_ascii_lowercase() {
            'c' => nums / 6,
            'l' => nums / 2,
            'm' => (nums / 2).saturating_sub(1),
            _ => 0,
        };
        let mut tok = String::new();
        for ch in d.chars().chain(std::iter::once(' ')) {
            if ch.is_ascii_alphabetic()
                || ch.is_whitespace()
                || ch == ','
                || (ch == '-' && !tok.is_empty())
            {
                if !tok.is_empty() {
                    nums += 1;
                    tok.clear();
                }
                if ch.is_ascii_alphabetic() {
                    n += flush(cmd, nums);
                    cmd = ch;
                    nums = 0;
                } else if ch == '-' {
                    tok.push(ch);
                }
            } else {
                tok.push(ch);
            }
        }
        n += flush(cmd, nums);
    }
    n
}

/// The trace options the comparison uses: the defaults, with the tolerance
/// taken from `FLOURISH_TOLERANCE` (px) and the speck size from
/// `FLOURISH_MIN_AREA` (px²) when those are set, so the example can show
/// the trade-offs.
pub fn flourish_options() -> TraceOptions {
    let mut o = TraceOptions::default();
    if let Some(t) = std::env::var("FLOURISH_TOLERANCE")
        .ok()
        .and_then(|v| v.parse::<f64>().ok())
    {
        o.tolerance = t;
    }
    if let Some(a) = std::env::var("FLOURISH_MIN_AREA")
        .ok()
        .and_then(|v| v.parse::<f64>().ok())
    {
        o.min_area = a;
    }
    o
}

/// Traces `png` with `flourish::trace` and [`flourish_options`]:
/// the document and the median in-process time of `runs` runs.
pub fn run_flourish(png: &Path, runs: usize) -> (Document, Duration) {
    let mut times = Vec::new();
    let mut doc = None;
    let opts = flourish_options();
    for _ in 0..runs.max(1) {
        let t = Instant::now();
        let bytes = std::fs::read(png).expect("sample");
        let image = Image::from_bytes(&bytes, &ImageOptions::default()).expect("reads");
        let d = flourish::trace(&image, &opts)
            .expect("flourish trace")
            .document;
        times.push(t.elapsed());
        doc = Some(d);
    }
    (doc.unwrap(), median(times))
}

/// The paths of a traced document (pixel units for raster input).
pub fn doc_paths(doc: &Document) -> Vec<BezPath> {
    doc.groups
        .iter()
        .flat_map(|g| g.shapes.iter().map(|s| s.path.clone()))
        .collect()
}

/// Ink mask of `paths` filled (non-zero) on a `w`×`h` canvas: anti-aliased
/// render, thresholded at 50 % coverage, the same way the binary samples
/// were made from the vector art.
pub fn rasterize(paths: &[BezPath], w: u32, h: u32) -> Vec<bool> {
    let mut pm = tiny_skia::Pixmap::new(w, h).expect("canvas");
    let mut pb = tiny_skia::PathBuilder::new();
    for p in paths {
        for el in p.elements() {
            match *el {
                PathEl::MoveTo(a) => pb.move_to(a.x as f32, a.y as f32),
                PathEl::LineTo(a) => pb.line_to(a.x as f32, a.y as f32),
                PathEl::QuadTo(a, b) => pb.quad_to(a.x as f32, a.y as f32, b.x as f32, b.y as f32),
                PathEl::CurveTo(a, b, c) => pb.cubic_to(
                    a.x as f32, a.y as f32, b.x as f32, b.y as f32, c.x as f32, c.y as f32,
                ),
                PathEl::ClosePath => pb.close(),
            }
        }
    }
    if let Some(path) = pb.finish() {
        let mut paint = tiny_skia::Paint::default();
        paint.set_color_rgba8(0, 0, 0, 255);
        paint.anti_alias = true;
        pm.fill_path(
            &path,
            &paint,
            tiny_skia::FillRule::Winding,
            tiny_skia::Transform::identity(),
            None,
        );
    }
    pm.pixels().iter().map(|p| p.alpha() >= 128).collect()
}

/// Intersection over union of two masks.
pub fn iou(a: &[bool], b: &[bool]) -> f64 {
    let (mut i, mut u) = (0usize, 0usize);
    for (&x, &y) in a.iter().zip(b) {
        i += (x && y) as usize;
        u += (x || y) as usize;
    }
    if u == 0 {
        1.0
    } else {
        i as f64 / u as f64
    }
}

/// Everything measured for one sample.
#[derive(Clone, Debug)]
pub struct Comparison {
    pub name: String,
    pub width: u32,
    pub height: u32,
    pub flourish_segments: usize,
    pub potrace_segments: usize,
    /// Symmetric Hausdorff distances to the truth (px).
    pub flourish_dev: f64,
    pub potrace_dev: f64,
    /// Directed parts: (output → truth, truth → output).
    pub flourish_dev_dir: (f64, f64),
    pub potrace_dev_dir: (f64, f64),
    pub flourish_time: Duration,
    pub potrace_time: Duration,
    /// IoU of each tracer's output, rendered and thresholded, with the
    /// 50 %-thresholded input bitmap.
    pub flourish_iou: f64,
    pub potrace_iou: f64,
}

/// The `flourish` binary the whole-command timing runs:
/// `$FLOURISH_BIN`, else the release build in `target/release`.
pub fn flourish_bin() -> PathBuf {
    std::env::var_os("FLOURISH_BIN")
        .map(PathBuf::from)
        .unwrap_or_else(|| root().join("target/release/flourish"))
}

/// Whole commands timed against each other on one bitmap.
#[derive(Clone, Copy, Debug)]
pub struct CommandTimes {
    /// Median wall-clock time of `flourish trace PNG -o SVG` (decoding,
    /// tracing and writing, the process's start included).
    pub flourish: Duration,
    /// Median wall-clock time of `potrace -s -t N PBM -o SVG`.
    pub potrace: Duration,
    /// Median over the pairs of flourish's time over potrace's.
    pub ratio: f64,
}

/// Times the whole `flourish trace` command on `png` (the binary at
/// [`flourish_bin`], default options) against the whole `potrace -s`
/// command on the same bitmap thresholded at 50 % (written as PBM once,
/// outside the timing; speck size [`potrace_turdsize`]): after one untimed
/// run of each, `runs` pairs run back to back, flourish first in even
/// pairs and potrace first in odd ones, so a change of load on a shared
/// machine falls on both; the ratio is the median of the pairs' ratios.
pub fn time_commands(png: &Path, bitmap: &image::GrayImage, runs: usize) -> CommandTimes {
    let dir = tempfile::tempdir().expect("temp dir");
    let pbm = dir.path().join("in.pbm");
    let (fsvg, psvg) = (dir.path().join("f.svg"), dir.path().join("p.svg"));
    std::fs::write(&pbm, pbm_bytes(bitmap)).expect("write PBM");
    let bin = flourish_bin();
    let flourish = || {
        let t = Instant::now();
        let st = Command::new(&bin)
            .arg("trace")
            .arg(png)
            .arg("-o")
            .arg(&fsvg)
            .arg("-q")
            .status()
            .expect("run flourish");
        let e = t.elapsed();
        assert!(
            st.success(),
            "flourish trace {} failed: {st}",
            png.display()
        );
        e
    };
    let potrace = || potrace_process(&pbm, &psvg);
    flourish();
    potrace();
    let (mut ft, mut pt, mut ratios) = (Vec::new(), Vec::new(), Vec::new());
    for k in 0..runs.max(1) {
        let (f, p) = if k % 2 == 0 {
            let f = flourish();
            (f, potrace())
        } else {
            let p = potrace();
            (flourish(), p)
        };
        ratios.push(f.as_secs_f64() / p.as_secs_f64().max(1e-6));
        ft.push(f);
        pt.push(p);
    }
    ratios.sort_by(f64::total_cmp);
    CommandTimes {
        flourish: median(ft),
        potrace: median(pt),
        ratio: ratios[ratios.len() / 2],
    }
}

/// Everything measured for one bitmap by [`compare_file`].
#[derive(Clone, Debug)]
pub struct FileComparison {
    /// The bitmap's file name.
    pub name: String,
    pub width: u32,
    pub height: u32,
    pub flourish_segments: usize,
    pub potrace_segments: usize,
    /// Symmetric Hausdorff distances (px) to the ground truth, when the
    /// truth lines up with the bitmap (not on a scan turned by hand).
    pub flourish_dev: Option<f64>,
    pub potrace_dev: Option<f64>,
    /// The whole commands timed against each other.
    pub times: CommandTimes,
    /// IoU of each tracer's output, rendered and thresholded, with the
    /// 50 %-thresholded input bitmap.
    pub flourish_iou: f64,
    pub potrace_iou: f64,
}

/// Runs both tracers on the bitmap `png` (a sample, or third-party art
/// whose ground truth `NAME.svg` is drawn at a uniform scale of the
/// bitmap) and measures them; the ground-truth distances only where the
/// truth, scaled to the bitmap, lines up with it (not `*-scanned*`,
/// turned by hand) and `deviation` asks for them (the truth of large art
/// takes long to extract).
pub fn compare_file(png: &Path, runs: usize, deviation: bool) -> FileComparison {
    let bitmap = image::open(png).expect("bitmap").to_luma8();
    let (w, h) = bitmap.dimensions();
    let name = png
        .file_name()
        .map(|n| n.to_string_lossy().to_string())
        .unwrap_or_default();
    let (doc, _) = run_flourish(png, 1);
    let fpaths = doc_paths(&doc);
    let (ppaths, psegs, _) = run_potrace(&bitmap, 1);
    let svg = truth_svg_for(png);
    let aligned = deviation && svg.exists() && !name.contains("scanned");
    let (fdev, pdev) = if aligned {
        let (sw, sh) = svg_size(&svg);
        let s = w as f64 / sw;
        assert!(
            (sh * s - h as f64).abs() < 1.0,
            "{name}: the truth ({sw}×{sh}) is not the bitmap ({w}×{h}) scaled"
        );
        let truth: Vec<Line> = ground_truth(&svg)
            .into_iter()
            .map(|l| Line::new((l.p0.x * s, l.p0.y * s), (l.p1.x * s, l.p1.y * s)))
            .collect();
        let (f, p) = (deviations(&fpaths, &truth), deviations(&ppaths, &truth));
        (Some(f.0.max(f.1)), Some(p.0.max(p.1)))
    } else {
        (None, None)
    };
    let mask = ink_mask(&bitmap);
    FileComparison {
        name,
        width: w,
        height: h,
        flourish_segments: doc.segment_count(),
        potrace_segments: psegs,
        flourish_dev: fdev,
        potrace_dev: pdev,
        times: time_commands(png, &bitmap, runs),
        flourish_iou: iou(&rasterize(&fpaths, w, h), &mask),
        potrace_iou: iou(&rasterize(&ppaths, w, h), &mask),
    }
}

/// Runs both tracers on `samples/trace/NAME` and measures them.
pub fn compare(png_name: &str, runs: usize) -> Comparison {
    let png = sample(png_name);
    let bitmap = image::open(&png).expect("sample PNG").to_luma8();
    let (w, h) = bitmap.dimensions();
    let svg = truth_svg_for(&png);
    let (sw, sh) = svg_size(&svg);
    assert!(
        (sw - w as f64).abs() < 1e-6 && (sh - h as f64).abs() < 1e-6,
        "{png_name}: SVG is {sw}×{sh}, PNG {w}×{h}: user unit ≠ pixel"
    );
    let truth = ground_truth(&svg);
    let (doc, ft) = run_flourish(&png, runs);
    let fpaths = doc_paths(&doc);
    let (ppaths, psegs, pt) = run_potrace(&bitmap, runs);
    let fdir = deviations(&fpaths, &truth);
    let pdir = deviations(&ppaths, &truth);
    let mask = ink_mask(&bitmap);
    Comparison {
        name: png_name.to_string(),
        width: w,
        height: h,
        flourish_segments: doc.segment_count(),
        potrace_segments: psegs,
        flourish_dev: fdir.0.max(fdir.1),
        potrace_dev: pdir.0.max(pdir.1),
        flourish_dev_dir: fdir,
        potrace_dev_dir: pdir,
        flourish_time: ft,
        potrace_time: pt,
        flourish_iou: iou(&rasterize(&fpaths, w, h), &mask),
        potrace_iou: iou(&rasterize(&ppaths, w, h), &mask),
    }
}
