//! Sizes follow the drawing, not its unit system: the same sketch drawn
//! in px, mm and pt gives the same result, scaled (element counts within
//! 2 %, rendered ink IoU ≥ 0.98 at the same pixel size).

use flourish::{BrushOptions, FillOptions, Library, Output, PatternOptions, Sketch, StyleOptions};
use resvg::{tiny_skia, usvg};
use std::path::PathBuf;

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

/// A px sample redrawn in `unit` (`mm` or `pt`, `per_px` of them to a
/// CSS px): the same size on the page, its user units that unit.
fn in_units(svg: &str, unit: &str, per_px: f64) -> String {
    let open = svg.find("<svg").expect("an svg element");
    let close = open + svg[open..].find('>').expect("its end");
    let head = &svg[open..close];
    let attr = |name: &str| -> f64 {
        head.split(&format!(" {name}=\""))
            .nth(1)
            .and_then(|r| r.split('"').next())
            .and_then(|v| v.parse().ok())
            .expect("a numeric size")
    };
    let (w, h) = (attr("width"), attr("height"));
    let end = svg.rfind("</svg>").expect("its close");
    format!(
        r#"<svg xmlns="http://www.w3.org/2000/svg" width="{}{unit}" height="{}{unit}" viewBox="0 0 {} {}"><g transform="scale({})">{}</g></svg>"#,
        w * per_px,
        h * per_px,
        w * per_px,
        h * per_px,
        per_px,
        &svg[close + 1..end]
    )
}

/// Ink pixels of an output rendered `side` px wide.
fn ink(out: &Output, side: u32) -> Vec<bool> {
    let tree = usvg::Tree::from_str(&out.to_svg(), &usvg::Options::default()).expect("parses");
    let s = side as f32 / tree.size().width();
    let h = (tree.size().height() * s).ceil() as u32;
    let mut pm = tiny_skia::Pixmap::new(side, h).expect("a canvas");
    resvg::render(
        &tree,
        tiny_skia::Transform::from_scale(s, s),
        &mut pm.as_mut(),
    );
    pm.pixels().iter().map(|p| p.alpha() > 127).collect()
}

fn shapes(out: &Output) -> usize {
    out.document.groups.iter().map(|g| g.shapes.len()).sum()
}

fn check(name: &str, run: impl Fn(&Sketch) -> Output, sample: &str) {
    let svg = std::fs::read_to_string(root().join("samples").join(sample)).expect("sample");
    let px = run(&Sketch::from_svg(svg.as_bytes()).expect("px parses"));
    // 96 px to the inch: 25.4 mm, 72 pt.
    for (unit, per_px) in [("mm", 25.4 / 96.0), ("pt", 72.0 / 96.0)] {
        let other = in_units(&svg, unit, per_px);
        let sk = Sketch::from_svg(other.as_bytes()).expect("parses");
        assert!((sk.px_per_unit() - 1.0 / per_px).abs() < 1e-6, "{unit}");
        let out = run(&sk);
        let (a, b) = (shapes(&px), shapes(&out));
        assert!(
            (a as f64 - b as f64).abs() <= 0.02 * a as f64 + 1.0,
            "{name} in {unit}: {b} shapes against {a} in px"
        );
        let (x, y) = (ink(&px, 800), ink(&out, 800));
        let both = x.iter().zip(&y).filter(|(p, q)| **p && **q).count() as f64;
        let either = x.iter().zip(&y).filter(|(p, q)| **p || **q).count().max(1) as f64;
        assert!(
            both / either >= 0.98,
            "{name} in {unit}: IoU {:.4} with the px drawing",
            both / either
        );
    }
}

#[test]
fn a_sketch_in_mm_or_pt_gives_the_px_result_scaled() {
    let lib = Library::shipped();
    let load = StyleOptions {
        cache_dir: Some(std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("target/test-cache")),
        ..StyleOptions::default()
    };
    let stipple = lib.load("stipple", &load).expect("stipple");
    check(
        "pattern",
        |sk| flourish::pattern(sk, &stipple, &PatternOptions::default()).expect("pattern"),
        "pattern/wave.svg",
    );
    let scales = lib.load("scales", &load).expect("scales");
    check(
        "fill",
        |sk| flourish::fill(sk, &scales, &FillOptions::default()).expect("fill"),
        "fill/circle.svg",
    );
    let doodle = lib.load("doodle", &load).expect("doodle");
    check(
        "brush",
        |sk| flourish::brush(sk, &doodle, &BrushOptions::default()).expect("brush"),
        "brush/short.svg",
    );
}

/// `scale` (`--scale F`) draws a pattern style's elements F times larger:
/// each element is a rigid copy, so the largest is exactly twice as wide;
/// a fill style's pattern comes out coarser, with fewer shapes.
#[test]
fn scale_draws_the_style_larger() {
    let lib = Library::shipped();
    let load = StyleOptions::default();
    let sketch = Sketch::from_svg(
        &std::fs::read(root().join("samples/pattern/blob.svg")).expect("the blob sample"),
    )
    .expect("parses");
    let flowers = lib.load("flowers", &load).expect("flowers");
    let largest = |scale: f64| -> f64 {
        let opts = PatternOptions {
            scale,
            ..PatternOptions::default()
        };
        let out = flourish::pattern(&sketch, &flowers, &opts).expect("pattern");
        out.document
            .groups
            .iter()
            .flat_map(|g| &g.shapes)
            .map(|s| kurbo::Shape::bounding_box(&s.path).width())
            .fold(0.0, f64::max)
    };
    let (one, two) = (largest(1.0), largest(2.0));
    assert!((two / one - 2.0).abs() < 0.02, "{one} → {two}");

    let circle = Sketch::from_svg(
        &std::fs::read(root().join("samples/fill/circle.svg")).expect("the circle sample"),
    )
    .expect("parses");
    let scales = lib.load("scales", &load).expect("scales");
    let fill = |scale: f64| {
        let opts = FillOptions {
            scale,
            ..FillOptions::default()
        };
        shapes(&flourish::fill(&circle, &scales, &opts).expect("fill"))
    };
    let (one, two) = (fill(1.0), fill(2.0));
    assert!(two * 2 < one, "{one} shapes at 1, {two} at 2");
    let bad = FillOptions {
        scale: 0.0,
        ..FillOptions::default()
    };
    assert!(flourish::fill(&circle, &scales, &bad).is_err());
}
