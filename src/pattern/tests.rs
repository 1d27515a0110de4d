//! The pattern pipeline on the shipped samples and styles: the
//! properties Barla et al. §2–3 promise (clustering, Lloyd spacing,
//! density, exact rigid copies, alternation, smooth turning), bad input
//! and determinism.

use super::element::load_example;
use super::seeds::{self, Region};
use super::{cluster, synthesize_sketch, PatternOptions, PatternOutput, PatternStyle};
use crate::error::Result;
use crate::library::{Library, StyleOptions};
use crate::read::sketch::{self, QueryKind, Sketch};
use crate::read::style::{FitPoints, StyleKind};
use crate::svg_out::{Document, FillRule};
use kurbo::{Affine, BezPath, PathEl, Point, Shape as _};
use resvg::usvg;
use std::path::{Path, PathBuf};

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

/// A run of the pattern mode: the style by name or folder, and the options.
#[derive(Clone, Default)]
struct Job {
    style: String,
    seed: u64,
    variation: f64,
    max_elements: Option<usize>,
}

fn opts(style: &str) -> Job {
    Job {
        style: style.into(),
        ..Default::default()
    }
}

/// The pattern of `sk` as the command line makes it: the job's style, and
/// each shape's `data-style`, from the shipped styles.
fn synth(job: &Job, sk: &Sketch) -> Result<PatternOutput> {
    let lib = Library::shipped();
    let load = StyleOptions {
        kind: Some(StyleKind::Pattern),
        ..StyleOptions::default()
    };
    let style = lib.load(&job.style, &load)?;
    let named = lib.load_named(sk, StyleKind::Pattern, &load)?;
    let styles = crate::Styles::new(&style, &named);
    let opts = PatternOptions {
        seed: job.seed,
        variation: job.variation,
        max_elements: job.max_elements.unwrap_or(super::DEFAULT_MAX_ELEMENTS),
        ..PatternOptions::default()
    };
    synthesize_sketch(sk, |q| Ok(styles.of(q)?.pattern()?.clone()), &opts)
}

/// [`synth`] on a sketch file, its errors naming the file.
fn run(job: &Job, path: &Path) -> Result<Document> {
    let sk = sketch::load(path)?;
    synth(job, &sk)
        .map(|o| o.to_document())
        .map_err(|e| e.in_file(path))
}

fn sample(name: &str) -> PathBuf {
    root().join("samples/pattern").join(format!("{name}.svg"))
}

/// Writes a style folder with `example` and `toml_extra` into a temp dir.
fn temp_style(example: &str, toml: &str) -> tempfile::TempDir {
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(dir.path().join("example.svg"), example).unwrap();
    std::fs::write(
        dir.path().join("style.toml"),
        format!("kind = \"pattern\"\n{toml}\n[[exemplar]]\nfile = \"example.svg\"\n"),
    )
    .unwrap();
    dir
}

fn temp_sketch(dir: &Path, body: &str) -> PathBuf {
    let p = dir.join("sketch.svg");
    std::fs::write(
        &p,
        format!(
            "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"400\" height=\"300\">{body}</svg>"
        ),
    )
    .unwrap();
    p
}

#[test]
fn clustering_groups_a_flower_and_keeps_distant_hatches_apart() {
    // Five petal strokes radiating from (50, 50), tips 10 px out, plus two
    // parallel hatches 40 px apart, far from the flower.
    let mut body = String::new();
    for k in 0..5 {
        let a = k as f64 * std::f64::consts::TAU / 5.0;
        let (x0, y0) = (50.0 + 2.0 * a.cos(), 50.0 + 2.0 * a.sin());
        let (x1, y1) = (50.0 + 10.0 * a.cos(), 50.0 + 10.0 * a.sin());
        body += &format!("<path d=\"M{x0} {y0}L{x1} {y1}\" stroke=\"#000\" stroke-width=\"2\"/>");
    }
    body += "<path d=\"M150 20L150 60\" stroke=\"#000\" stroke-width=\"1\"/>";
    body += "<path d=\"M190 20L190 60\" stroke=\"#000\" stroke-width=\"1\"/>";
    let svg = format!(
        "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"240\" height=\"100\">{body}</svg>"
    );
    let strokes = load_example(
        Path::new("flower.svg"),
        svg.as_bytes(),
        FitPoints::Skeleton,
        12.0,
    )
    .unwrap();
    assert_eq!(strokes.len(), 7);
    let elements = cluster::cluster(&strokes, 12.0);
    assert_eq!(elements.len(), 3, "{elements:#?}");
    let mut sizes: Vec<usize> = elements.iter().map(|e| e.strokes.len()).collect();
    sizes.sort_unstable();
    assert_eq!(sizes, vec![1, 1, 5]);
    // At a scale below the petal tips' spread the flower falls apart.
    assert!(cluster::cluster(&strokes, 3.0).len() > 3);
}

fn unit_square(s: f64) -> BezPath {
    kurbo::Rect::new(0.0, 0.0, s, s).to_path(0.1)
}

#[test]
fn lloyd_energy_decreases_and_spacing_is_even_on_a_square() {
    let region = Region::new(&unit_square(200.0), FillRule::NonZero, 0.1).unwrap();
    let l = seeds::lloyd(&region, 100, 7, 400);
    assert_eq!(l.points.len(), 100);
    assert!(l.energy.len() > 5);
    for w in l.energy.windows(2) {
        assert!(
            w[1] <= w[0] * (1.0 + 1e-12),
            "energy rose: {} -> {}",
            w[0],
            w[1]
        );
    }
    assert!(l.energy[l.energy.len() - 1] < 0.8 * l.energy[0]);
    let nn: Vec<f64> = l
        .points
        .iter()
        .enumerate()
        .map(|(i, p)| {
            l.points
                .iter()
                .enumerate()
                .filter(|(j, _)| *j != i)
                .map(|(_, q)| (*q - *p).hypot())
                .fold(f64::MAX, f64::min)
        })
        .collect();
    let mean = nn.iter().sum::<f64>() / nn.len() as f64;
    let var = nn.iter().map(|d| (d - mean).powi(2)).sum::<f64>() / nn.len() as f64;
    let cv = var.sqrt() / mean;
    assert!(cv < 0.1, "spacing CV {cv}");
}

fn region_of(path: &Path, k: usize) -> (BezPath, FillRule) {
    let sk = sketch::load(path).unwrap();
    match &sk.queries[k].kind {
        QueryKind::Region { outline, fill_rule } => (outline.clone(), *fill_rule),
        other => panic!("not a region: {other:?}"),
    }
}

#[test]
fn element_count_follows_the_reference_density() {
    for style in ["stipple", "flowers", "hatching"] {
        let o = opts(style);
        let sk = sketch::load(&sample("blob")).unwrap();
        let out = synth(&o, &sk).unwrap();
        let (outline, rule) = region_of(&sample("blob"), 0);
        let area = Region::new(&outline, rule, 0.05).unwrap().area;
        // The hole: 390-ish × 270-ish blob minus a disc of radius 40.
        assert!(area > 50_000.0 && area < 90_000.0, "{area}");
        let st = &out.queries[0].style;
        let expected = st.elements().len() as f64 * area / st.reference.dist.area;
        let got = out.queries[0].elements.len() as f64;
        // At least the density's count, raised only as far as the
        // example's nearest-neighbour spacing asks.
        assert!(got >= 0.9 * expected, "{style}: {got} vs {expected}");
        // A field's spacing is the example's; rows (hatching) keep the
        // density's count.
        let ratio = spacing_ratio(&out.queries[0]);
        if st.reference.dist.spacing == st.reference.dist.pitch {
            assert!((0.8..=1.2).contains(&ratio), "{style}: spacing {ratio}");
        } else {
            assert!(got <= 1.1 * expected, "{style}: {got} vs {expected}");
        }
    }
}

/// Mean nearest-neighbour distance of a query's placed centres over the
/// example's (brute force).
fn spacing_ratio(q: &crate::pattern::QueryPattern) -> f64 {
    let centres: Vec<kurbo::Point> = q.elements.iter().map(|e| e.centre).collect();
    let own = crate::pattern::distribution::nearest_spacing(&q.style.reference.dist.centres);
    crate::pattern::distribution::nearest_spacing(&centres).unwrap_or(0.0) / own.unwrap_or(1.0)
}

#[test]
fn no_element_centre_leaves_its_region() {
    let (outline, _) = region_of(&sample("blob"), 0);
    for style in ["stipple", "flowers", "brushmarks"] {
        for variation in [0.0, 1.0] {
            let o = Job {
                variation,
                seed: 3,
                ..opts(style)
            };
            let sk = sketch::load(&sample("blob")).unwrap();
            let out = synth(&o, &sk).unwrap();
            for e in &out.queries[0].elements {
                // Even-odd on the exact curves, independent of the flattening.
                let inside = outline.winding(e.centre) % 2 != 0;
                assert!(
                    inside,
                    "{style} v={variation}: centre {:?} outside",
                    e.centre
                );
            }
        }
    }
}

/// `n` points spread evenly by arc length over a usvg path (canvas
/// units): the same curve gives the same points however it is written
/// (quads as cubics, straight cubics as lines).
fn points_of(p: &usvg::Path, n: usize) -> Vec<Point> {
    let bp = crate::read::svg::to_bezpath(p.data(), p.abs_transform());
    let mut pts: Vec<Vec<Point>> = Vec::new();
    kurbo::flatten(&bp, 1e-5, |el| match el {
        PathEl::MoveTo(a) => pts.push(vec![a]),
        PathEl::LineTo(a) => {
            if let Some(v) = pts.last_mut() {
                v.push(a)
            }
        }
        PathEl::ClosePath => {
            if let Some(v) = pts.last_mut() {
                let f = v[0];
                v.push(f)
            }
        }
        _ => {}
    });
    let segs: Vec<(Point, Point)> = pts
        .iter()
        .flat_map(|v| v.windows(2).map(|w| (w[0], w[1])))
        .collect();
    let total: f64 = segs.iter().map(|s| (s.1 - s.0).hypot()).sum();
    let mut out = Vec::new();
    let mut acc = 0.0;
    let mut k = 0;
    for (a, b) in &segs {
        let l = (*b - *a).hypot();
        while k < n && (k as f64 + 0.5) / n as f64 * total <= acc + l {
            let t = ((k as f64 + 0.5) / n as f64 * total - acc) / l.max(1e-300);
            out.push(a.lerp(*b, t.clamp(0.0, 1.0)));
            k += 1;
        }
        acc += l;
    }
    out
}

fn paths(g: &usvg::Group, out: &mut Vec<usvg::Path>) {
    for n in g.children() {
        match n {
            usvg::Node::Group(g) => paths(g, out),
            usvg::Node::Path(p) => out.push((**p).clone()),
            _ => {}
        }
    }
}

/// The rigid transform (rotation + translation, no mirror) that best maps
/// `a` onto `b` (2-D Kabsch) and the largest residual.
fn kabsch(a: &[Point], b: &[Point]) -> (f64, f64) {
    let n = a.len() as f64;
    let ca = a.iter().fold(kurbo::Vec2::ZERO, |s, p| s + p.to_vec2()) / n;
    let cb = b.iter().fold(kurbo::Vec2::ZERO, |s, p| s + p.to_vec2()) / n;
    let (mut sxx, mut sxy) = (0.0, 0.0);
    for (p, q) in a.iter().zip(b) {
        let (u, v) = (p.to_vec2() - ca, q.to_vec2() - cb);
        sxx += u.dot(v);
        sxy += u.cross(v);
    }
    let theta = sxy.atan2(sxx);
    let t = Affine::translate(cb) * Affine::rotate(theta) * Affine::translate(-ca);
    let resid = a
        .iter()
        .zip(b)
        .map(|(p, q)| (t * *p - *q).hypot())
        .fold(0.0, f64::max);
    (theta, resid)
}

#[test]
fn every_output_element_is_an_exact_rigid_copy() {
    for (style, sk) in [
        ("flowers", "blob"),
        ("hatching", "wave"),
        ("brushmarks", "blob"),
        ("stipple", "wave"),
    ] {
        let o = Job {
            variation: 1.0,
            ..opts(style)
        };
        let sketch = sketch::load(&sample(sk)).unwrap();
        let out = synth(&o, &sketch).unwrap();
        let text = out.to_document().to_svg();
        // The example and the output, both read back independently.
        let ex_path = root().join("styles").join(style).join("example.svg");
        let ex_tree = crate::read::svg::load_svg(&ex_path).unwrap();
        let mut ex_paths = Vec::new();
        paths(ex_tree.root(), &mut ex_paths);
        let out_tree = crate::read::svg::parse_svg(text.as_bytes()).unwrap();
        let mut out_paths = Vec::new();
        paths(out_tree.root(), &mut out_paths);
        let q = &out.queries[0];
        let st = &q.style;
        let mut k = 0;
        for e in &q.elements {
            let mut a = Vec::new();
            let mut b = Vec::new();
            for &s in &st.elements()[e.element].strokes {
                // One usvg path per example stroke (fill and stroke together).
                let ex = &ex_paths[s];
                let shapes = st.strokes[s].shapes.len();
                let mut first = true;
                for _ in 0..shapes {
                    let op = &out_paths[k];
                    k += 1;
                    if let (Some(so), Some(se)) = (op.stroke(), ex.stroke()) {
                        assert!((so.width().get() - se.width().get()).abs() < 1e-3);
                    }
                    if first {
                        a.extend(points_of(ex, 64));
                        b.extend(points_of(op, 64));
                        first = false;
                    }
                }
            }
            assert_eq!(
                a.len(),
                b.len(),
                "{style}: element {} changed its point count",
                e.element
            );
            let (_, resid) = kabsch(&a, &b);
            assert!(
                resid < 5e-3,
                "{style}: element {} is not a rigid copy (residual {resid})",
                e.element
            );
            let m = e.transform.as_coeffs();
            let det = m[0] * m[3] - m[1] * m[2];
            assert!(
                (det - 1.0).abs() < 1e-9,
                "transform is not a rotation: {det}"
            );
        }
        assert_eq!(k, out_paths.len(), "{style}: stray output paths");
    }
}

fn alternation_along(out: &crate::pattern::PatternOutput) -> (usize, usize) {
    let q = &out.queries[0];
    let colours: Vec<[u8; 3]> = q
        .elements
        .iter()
        .map(|e| {
            let c = q.style.elements()[e.element].color;
            [c[0], c[1], c[2]].map(|v| (v * 255.0).round() as u8)
        })
        .collect();
    let changes = colours.windows(2).filter(|w| w[0] != w[1]).count();
    (changes, colours.len().saturating_sub(1))
}

#[test]
fn alternating_colours_keep_alternating() {
    // A hand-built row: red and blue dots, alternating.
    let mut body = String::new();
    for i in 0..14 {
        let c = if i % 2 == 0 { "#d22" } else { "#22d" };
        body += &format!(
            "<circle cx=\"{}\" cy=\"20\" r=\"4\" fill=\"{c}\"/>",
            10 + i * 16
        );
    }
    let example = format!(
        "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"240\" height=\"40\">{body}</svg>"
    );
    let dir = temp_style(&example, "scale = 3.0\nrings = 2\n");
    let sk = temp_sketch(dir.path(), "<path d=\"M20 150C120 20 280 280 380 150\" stroke=\"#000\" stroke-width=\"10\" fill=\"none\"/>");
    for seed in 0..4 {
        let o = Job {
            style: dir.path().to_string_lossy().into(),
            seed,
            ..Default::default()
        };
        let out = synth(&o, &sketch::load(&sk).unwrap()).unwrap();
        let (changes, pairs) = alternation_along(&out);
        assert!(pairs > 20);
        assert_eq!(changes, pairs, "seed {seed}: colours stopped alternating");
    }
    // The shipped flowers alternate along their rows; so along a path.
    let out = synth(&opts("flowers"), &sketch::load(&sample("wave")).unwrap()).unwrap();
    let (changes, pairs) = alternation_along(&out);
    assert_eq!(changes, pairs, "flowers stopped alternating");
}

#[test]
fn output_is_identical_at_one_and_two_threads() {
    let in_pool = |threads: usize, variation: f64| {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap();
        pool.install(|| {
            let o = Job {
                variation,
                seed: 11,
                ..opts("stipple")
            };
            run(&o, &sample("mixed")).unwrap().to_svg()
        })
    };
    for v in [0.0, 0.7] {
        let (a, b) = (in_pool(1, v), in_pool(2, v));
        assert!(a.len() > 1000);
        assert!(
            a == b,
            "output differs between 1 and 2 threads (variation {v})"
        );
    }
    // The seed matters.
    let o = Job {
        seed: 12,
        ..opts("stipple")
    };
    assert_ne!(run(&o, &sample("blob")).unwrap().to_svg(), {
        let o = Job {
            seed: 11,
            ..opts("stipple")
        };
        run(&o, &sample("blob")).unwrap().to_svg()
    });
}

#[test]
fn count_along_a_path_follows_the_example_spacing() {
    let o = opts("brushmarks");
    let sk = sketch::load(&sample("wave")).unwrap();
    let out = synth(&o, &sk).unwrap();
    let QueryKind::Path { spine, .. } = &sk.queries[0].kind else {
        panic!("wave is a path")
    };
    let len = spine.perimeter(0.01);
    let spacing = out.queries[0].style.reference.dist.chain_spacing();
    assert_eq!(
        out.queries[0].elements.len(),
        (len / spacing).round() as usize
    );
    // Neighbours sit one spacing apart along the path.
    let c: Vec<Point> = out.queries[0].elements.iter().map(|e| e.centre).collect();
    for w in c.windows(2) {
        let d = (w[1] - w[0]).hypot();
        assert!(d > 0.8 * spacing && d < 1.1 * spacing, "{d} vs {spacing}");
    }
}

fn one_line_error(e: crate::Error, needle: &str, file: &str) {
    let s = e.to_string();
    assert!(!s.contains('\n'), "{s}");
    assert!(s.contains(needle), "{s:?} lacks {needle:?}");
    assert!(s.contains(file), "{s:?} does not name {file}");
}

#[test]
fn bad_input_gives_one_clear_line() {
    let dots = "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"60\" height=\"20\"><circle cx=\"10\" cy=\"10\" r=\"2\"/><circle cx=\"30\" cy=\"10\" r=\"2\"/><circle cx=\"50\" cy=\"10\" r=\"2\"/></svg>";
    // An example with no strokes.
    let d = temp_style("<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"10\" height=\"10\"><text>hi</text></svg>", "scale = 2.0");
    one_line_error(
        PatternStyle::load(d.path()).unwrap_err(),
        "no visible strokes",
        "example.svg",
    );
    // scale <= 0 and NaN.
    for bad in ["scale = 0.0", "scale = -3.0", "scale = nan"] {
        let d = temp_style(dots, bad);
        one_line_error(
            PatternStyle::load(d.path()).unwrap_err(),
            "scale",
            "style.toml",
        );
    }
    let d = temp_style(dots, "scale = 2.0");
    let style = d.path().to_string_lossy().to_string();
    let o = Job {
        style: style.clone(),
        ..Default::default()
    };
    // A region of zero area.
    let sk = temp_sketch(
        d.path(),
        "<path d=\"M10 10L100 10L200 10Z\" fill=\"#000\"/>",
    );
    one_line_error(run(&o, &sk).unwrap_err(), "zero area", "sketch.svg");
    // A self-intersecting region is filled by its fill rule.
    let sk = temp_sketch(
        d.path(),
        "<path d=\"M10 10L200 200L200 10L10 200Z\" fill=\"#000\"/>",
    );
    assert!(run(&o, &sk).is_ok());
    // More elements than the limit.
    let sk = temp_sketch(
        d.path(),
        "<rect x=\"0\" y=\"0\" width=\"400\" height=\"300\" fill=\"#000\"/>",
    );
    let small = Job {
        max_elements: Some(50),
        ..o.clone()
    };
    one_line_error(run(&small, &sk).unwrap_err(), "limit of 50", "sketch.svg");
    // A sketch with nothing to decorate, a missing style, a bad variation.
    let sk = temp_sketch(d.path(), "");
    one_line_error(run(&o, &sk).unwrap_err(), "no stroked path", "sketch.svg");
    let missing = Job {
        style: "no-such-style".into(),
        ..opts("x")
    };
    let sk = sample("wave");
    one_line_error(
        run(&missing, &sk).unwrap_err(),
        "style not found",
        "no-such-style",
    );
    let bad_var = Job {
        variation: 1.5,
        ..o.clone()
    };
    one_line_error(run(&bad_var, &sk).unwrap_err(), "variation", "variation");
    // A style of another kind.
    let b = tempfile::tempdir().unwrap();
    std::fs::write(b.path().join("style.toml"), "kind = \"brush\"\n").unwrap();
    let brush = Job {
        style: b.path().to_string_lossy().into(),
        ..Default::default()
    };
    one_line_error(
        run(&brush, &sk).unwrap_err(),
        "needs \"pattern\"",
        "style.toml",
    );
}

#[test]
fn a_wide_band_is_filled_in_path_coordinates() {
    use kurbo::ParamCurveNearest;
    // The wave is 36 wide: more than two stipple spacings, so stipples fill
    // the band at the example's density instead of making a single file.
    let sk = sketch::load(&sample("wave")).unwrap();
    let QueryKind::Path { spine, width } = &sk.queries[0].kind else {
        panic!("wave is a path")
    };
    let out = synth(&opts("stipple"), &sk).unwrap();
    let q = &out.queries[0];
    let expected = q.style.expected_in_area(spine.perimeter(0.01) * width);
    let got = q.elements.len() as f64;
    assert!(got >= 0.9 * expected, "{got} vs {expected}");
    let ratio = spacing_ratio(q);
    assert!((0.8..=1.2).contains(&ratio), "spacing {ratio}");
    let mut off_path = 0;
    for e in &q.elements {
        let d = spine
            .segments()
            .map(|s| s.nearest(e.centre, 1e-6).distance_sq.sqrt())
            .fold(f64::MAX, f64::min);
        assert!(
            d <= width / 2.0 + 1e-6,
            "centre {:?} is {d} off the spine",
            e.centre
        );
        if d > 0.25 * width {
            off_path += 1;
        }
    }
    assert!(
        off_path * 4 > q.elements.len(),
        "the band is not filled across: {off_path}"
    );
}

#[test]
fn a_single_stroke_example_repeats_at_its_own_size() {
    let d = temp_style(
        "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"40\" height=\"40\"><path d=\"M10 20L30 20\" stroke=\"#000\" stroke-width=\"2\"/></svg>",
        "scale = 4.0",
    );
    let sk = temp_sketch(d.path(), "<path d=\"M0 100L400 100\" fill=\"none\" stroke=\"#000\" stroke-width=\"4\"/><rect x=\"50\" y=\"150\" width=\"200\" height=\"100\" fill=\"#000\"/>");
    let o = Job {
        style: d.path().to_string_lossy().into(),
        ..Default::default()
    };
    let out = synth(&o, &sketch::load(&sk).unwrap()).unwrap();
    // 20 px long (butt caps) + ε 4 = 24 px apart: 400 / 24 ≈ 17.
    assert_eq!(out.queries[0].elements.len(), 17);
    // Rows of them, 24 px apart along a row and 2 + 24/2 = 14 px between rows.
    let n2 = out.queries[1].elements.len();
    assert_eq!(n2, (200.0_f64 * 100.0 / (24.0 * 14.0)).round() as usize);
}

#[test]
fn smoothly_turning_marks_keep_turning_smoothly_along_a_path() {
    // Fig. 5(c): each brush mark is turned π/16 from the last in the
    // example; along a path, successive copies must keep small, steady steps.
    let out = synth(&opts("brushmarks"), &sketch::load(&sample("wave")).unwrap()).unwrap();
    let q = &out.queries[0];
    let angles: Vec<f64> = q
        .elements
        .iter()
        .map(|e| q.style.elements()[e.element].angle())
        .collect();
    let steps: Vec<f64> = angles
        .windows(2)
        .map(|w| crate::pattern::synth::wrap_half_turn(w[1] - w[0]))
        .collect();
    let smooth = steps
        .iter()
        .filter(|d| d.abs() <= std::f64::consts::PI / 8.0)
        .count();
    assert!(steps.len() > 20);
    assert!(
        smooth * 10 >= steps.len() * 9,
        "{smooth} of {} steps are smooth: {steps:?}",
        steps.len()
    );
    // And it turns: the steps do not cancel out (one direction of turning).
    let same_sign = steps
        .iter()
        .filter(|d| d.signum() == steps[steps.len() / 2].signum())
        .count();
    assert!(same_sign * 10 >= steps.len() * 8, "{steps:?}");
}
