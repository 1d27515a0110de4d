//! Golden files: every mode through the library's face on the shipped
//! samples and styles, compared with `golden/MODE/` byte for byte (the
//! pattern mode's numbers to ±0.002: libm may differ in the last bits
//! across machines). `UPDATE_GOLDEN=1 cargo test --test golden` rewrites
//! them (`make golden`); a mismatch leaves the actual output, and for a
//! trace the three-panel render comparison, in `golden/.failed/`.

use flourish::{
    BrushOptions, FillOptions, Image, ImageOptions, Library, PatternOptions, Sketch, StyleOptions,
    Styles, TraceOptions,
};
use std::path::{Path, PathBuf};

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

fn sketch(path: &Path) -> Sketch {
    Sketch::from_svg(&std::fs::read(path).expect("sample")).expect("sample parses")
}

/// Compares `actual` with `golden/DIR/NAME`: exactly, or with every
/// number within `numbers` of the golden one. With `UPDATE_GOLDEN` set,
/// writes it instead. Returns whether it matched (a mismatch is written
/// to `golden/.failed/NAME`).
fn matches(dir: &str, name: &str, actual: &str, numbers: Option<f64>) -> bool {
    let path = root().join("golden").join(dir).join(name);
    if std::env::var_os("UPDATE_GOLDEN").is_some() {
        std::fs::create_dir_all(path.parent().expect("a folder")).expect("golden folder");
        std::fs::write(&path, actual).expect("writes the golden file");
        return true;
    }
    let expected = std::fs::read_to_string(&path)
        .unwrap_or_else(|e| panic!("{}: {e}; run `make golden`", path.display()));
    let same = match numbers {
        None => expected == actual,
        Some(tol) => same_but_numbers(&expected, actual, tol),
    };
    if !same {
        let failed = root().join("golden/.failed");
        std::fs::create_dir_all(&failed).expect("failed folder");
        std::fs::write(failed.join(name), actual).expect("writes the actual output");
    }
    same
}

/// The two texts are the same but for numbers, which differ by at most
/// `tol`.
fn same_but_numbers(a: &str, b: &str, tol: f64) -> bool {
    let tokens = |s: &str| -> Vec<String> {
        let mut out = Vec::new();
        let mut cur = String::new();
        for ch in s.chars() {
            let numeric = ch.is_ascii_digit() || ch == '.' || (ch == '-' && cur.is_empty());
            if numeric {
                cur.push(ch);
            } else {
                if !cur.is_empty() {
                    out.push(std::mem::take(&mut cur));
                }
                out.push(ch.to_string());
            }
        }
        if !cur.is_empty() {
            out.push(cur);
        }
        out
    };
    let (x, y) = (tokens(a), tokens(b));
    x.len() == y.len()
        && x.iter()
            .zip(&y)
            .all(|(p, q)| match (p.parse::<f64>(), q.parse::<f64>()) {
                (Ok(p), Ok(q)) => (p - q).abs() <= tol,
                _ => p == q,
            })
}

fn assert_none_failed(mode: &str, failures: &[String]) {
    assert!(
        failures.is_empty(),
        "{mode}: differs from golden/{mode}/ (actual outputs in golden/.failed/): {failures:?}"
    );
}

#[test]
fn brush() {
    let lib = Library::shipped();
    let load = StyleOptions {
        cache_dir: Some(std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("target/test-cache")),
        ..StyleOptions::default()
    };
    let mut failures = Vec::new();
    for style in ["vine", "scroll", "doodle"] {
        let st = lib.load(style, &load).expect("style loads");
        for s in [
            "s-curve",
            "spiral",
            "closed-loop",
            "zigzag",
            "short",
            "meander",
            "self-crossing",
            "branching",
            "word",
        ] {
            let sk = sketch(&root().join("samples/brush").join(format!("{s}.svg")));
            let out = flourish::brush(&sk, &st, &BrushOptions::default()).expect("brushes");
            let name = format!("{s}-{style}.svg");
            if !matches("brush", &name, &out.to_svg(), None) {
                failures.push(name);
            }
        }
    }
    assert_none_failed("brush", &failures);
}

#[test]
fn fill() {
    let lib = Library::shipped();
    // 64 px tiles keep the test fast.
    let load = StyleOptions {
        resolution: Some(64),
        ..StyleOptions::default()
    };
    let mut failures = Vec::new();
    for (style, s) in [
        ("knot", "circle"),
        ("scales", "star"),
        ("knot", "letter"),
        ("scales", "frame"),
        ("knot", "combed"),
    ] {
        let st = lib.load(style, &load).expect("style loads");
        let sk = sketch(&root().join("samples/fill").join(format!("{s}.svg")));
        let out = flourish::fill(&sk, &st, &FillOptions::default()).expect("fills");
        let name = format!("{s}-{style}.svg");
        if !matches("fill", &name, &out.to_svg(), None) {
            failures.push(name);
        }
    }
    assert_none_failed("fill", &failures);
}

#[test]
fn pattern() {
    let lib = Library::shipped();
    let load = StyleOptions::default();
    let run = |style: &str, s: &str| {
        let st = lib.load(style, &load).expect("style loads");
        let sk = sketch(&root().join("samples/pattern").join(format!("{s}.svg")));
        let named = lib
            .load_named(&sk, flourish::StyleKind::Pattern, &load)
            .expect("named styles load");
        flourish::pattern(&sk, Styles::new(&st, &named), &PatternOptions::default())
            .expect("synthesizes")
            .to_svg()
    };
    let mut failures = Vec::new();
    for style in ["hatching", "stipple", "flowers", "brushmarks"] {
        for s in ["wave", "blob"] {
            let name = format!("{s}-{style}.svg");
            if !matches("pattern", &name, &run(style, s), Some(0.002)) {
                failures.push(name);
            }
        }
    }
    if !matches(
        "pattern",
        "mixed.svg",
        &run("hatching", "mixed"),
        Some(0.002),
    ) {
        failures.push("mixed.svg".into());
    }
    assert_none_failed("pattern", &failures);
}

#[test]
fn trace() {
    let mut samples: Vec<PathBuf> = std::fs::read_dir(root().join("samples/trace"))
        .expect("samples/trace")
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| matches!(p.extension().and_then(|e| e.to_str()), Some("png" | "svg")))
        .collect();
    samples.sort();
    let mut failures = Vec::new();
    for path in samples {
        let stem = path.file_stem().unwrap().to_string_lossy().to_string();
        let ext = path.extension().unwrap().to_string_lossy().to_string();
        let name = format!("{stem}-{ext}.svg");
        let image = Image::from_bytes(
            &std::fs::read(&path).expect("sample"),
            &ImageOptions::default(),
        )
        .expect("reads");
        let svg = flourish::trace(&image, &TraceOptions::default())
            .expect("traces")
            .to_svg();
        if !matches("trace", &name, &svg, None) {
            let failed = root().join("golden/.failed");
            let expected = root().join("golden/trace").join(&name);
            if let Ok(report) = flourish::diff(&expected, &failed.join(&name)) {
                if let Ok(png) = report.panels_png() {
                    let _ = std::fs::write(failed.join(format!("{stem}-{ext}.png")), png);
                }
            }
            failures.push(name);
        }
    }
    assert_none_failed("trace", &failures);
}
