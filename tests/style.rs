//! `flourish style check` and brush style analysis end to end: bad input
//! (one clear line, exit 1), the analysis cache (hit, miss, corrupt file
//! rebuilt), thread-count determinism, and the shipped libraries passing
//! the check without warnings.
//!
//! Small styles are written by the tests into temporary folders.

use flourish::brush::analysis::cache::CacheStatus;
use flourish::brush::analysis::{AnalysisOptions, BrushStyle};
use std::path::Path;
use std::process::{Command, Output, Stdio};

const BIN: &str = env!("CARGO_BIN_EXE_flourish");

fn flourish(args: &[&str]) -> Output {
    Command::new(BIN)
        .args(args)
        .stdin(Stdio::null())
        .output()
        .expect("run flourish")
}

fn s(p: &Path) -> &str {
    p.to_str().expect("utf-8 temp path")
}

/// A small brush exemplar: a wavy band ending in a ball, 200×100 units.
fn exemplar_svg(phase: f64) -> String {
    let mut d = String::from("M20 50");
    for i in 1..=16 {
        let x = 20.0 + 150.0 * i as f64 / 16.0;
        let y = 50.0 + 10.0 * (i as f64 * 0.4 + phase).sin();
        d.push_str(&format!(" L{x:.2} {y:.2}"));
    }
    format!(
        r##"<svg xmlns="http://www.w3.org/2000/svg" width="200" height="100">
  <path d="{d}" fill="none" stroke="#222" stroke-width="9"/>
  <circle cx="176" cy="50" r="10" fill="#a33"/>
</svg>"##
    )
}

const TOML: &str = "kind = \"brush\"\nresolution = 64\n\n[[exemplar]]\nfile = \"a.svg\"\nstart = [24.0, 50.0]\nend = [170.0, 50.0]\n\n[[exemplar]]\nfile = \"b.svg\"\nstart = [24.0, 50.0]\nend = [170.0, 50.0]\n";

fn small_style(dir: &Path, toml: &str) {
    std::fs::create_dir_all(dir).unwrap();
    std::fs::write(dir.join("style.toml"), toml).unwrap();
    std::fs::write(dir.join("a.svg"), exemplar_svg(0.0)).unwrap();
    std::fs::write(dir.join("b.svg"), exemplar_svg(1.3)).unwrap();
}

/// Runs `style check` on a style folder made from `toml` (and the two
/// exemplars, unless `blank` replaces a.svg by an empty drawing); returns
/// exit code and stderr.
fn check_with(toml: &str, blank: bool) -> (Option<i32>, String) {
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path().join("st");
    small_style(&dir, toml);
    if blank {
        std::fs::write(
            dir.join("a.svg"),
            r#"<svg xmlns="http://www.w3.org/2000/svg" width="200" height="100"/>"#,
        )
        .unwrap();
    }
    let cache = tmp.path().join("cache");
    let out = flourish(&["style", "check", s(&dir), "--cache", s(&cache)]);
    (
        out.status.code(),
        String::from_utf8_lossy(&out.stderr).into_owned(),
    )
}

fn assert_one_line_error(toml: &str, blank: bool, needles: &[&str]) {
    let (code, err) = check_with(toml, blank);
    assert_eq!(code, Some(1), "{toml}\n{err}");
    assert_eq!(err.lines().count(), 1, "{err}");
    assert!(err.starts_with("flourish: "), "{err}");
    for n in needles {
        assert!(err.contains(n), "missing {n:?} in {err}");
    }
}

#[test]
fn bad_styles_fail_with_one_clear_line() {
    let ok = TOML;
    assert_one_line_error(
        &ok.replace("\"brush\"", "\"sparkle\""),
        false,
        &["style.toml", "sparkle"],
    );
    assert_one_line_error(
        &ok.replace("\"a.svg\"", "\"missing.svg\""),
        false,
        &["missing.svg"],
    );
    assert_one_line_error(ok, true, &["a.svg", "blank exemplar"]);
    assert_one_line_error(
        &ok.replacen("start = [24.0, 50.0]", "start = [240.0, 50.0]", 1),
        false,
        &["style.toml", "exemplar[0].start", "outside"],
    );
    assert_one_line_error(
        &ok.replacen("end = [170.0, 50.0]", "end = [24.0, 50.0]", 1),
        false,
        &["style.toml", "exemplar[0].end", "equals start"],
    );
    assert_one_line_error(
        "kind = \"brush\"\nresolution = 64\n",
        false,
        &["style.toml", "exemplar", "at least one"],
    );
    assert_one_line_error(
        &ok.replace("resolution = 64", "resolution = \"big\""),
        false,
        &["style.toml", "line 2"],
    );
    assert_one_line_error(
        &ok.replacen("start = [24.0, 50.0]", "start = [nan, 50.0]", 1),
        false,
        &["style.toml", "exemplar[0].start", "finite"],
    );
    assert_one_line_error(
        &ok.replacen("end = [170.0, 50.0]\n", "\n", 1),
        false,
        &["style.toml", "exemplar[0].end", "missing"],
    );
    assert_one_line_error(
        &ok.replace("resolution = 64", "resolution = 5000"),
        false,
        &["style.toml", "resolution"],
    );
    assert_one_line_error(
        "kind = \"pattern\"\nscale = 2.0\n[[exemplar]]\nfile = \"a.svg\"\n",
        false,
        &["kind", "brush"],
    );
}

#[test]
fn missing_style_toml_fails_with_one_line() {
    let tmp = tempfile::tempdir().unwrap();
    let out = flourish(&["style", "check", s(tmp.path()), "--styles", s(tmp.path())]);
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(1), "{err}");
    assert_eq!(err.lines().count(), 1, "{err}");
    assert!(err.contains("style.toml"), "{err}");
}

#[test]
fn cache_hits_misses_and_rebuilds_corrupt_files() {
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path().join("wavy");
    small_style(&dir, TOML);
    let opts = AnalysisOptions {
        cache_dir: Some(tmp.path().join("cache")),
        ..AnalysisOptions::default()
    };
    let (first, st) = BrushStyle::load_with_status(&dir, &opts).unwrap();
    assert_eq!(st, CacheStatus::Miss);
    let bytes = postcard::to_stdvec(&first).unwrap();
    let (second, st) = BrushStyle::load_with_status(&dir, &opts).unwrap();
    assert_eq!(st, CacheStatus::Hit);
    assert_eq!(postcard::to_stdvec(&second).unwrap(), bytes);
    // The cached index answers like the fresh one.
    let q = first.neighbourhood(2, first.indexes[2].refs[7]).unwrap();
    assert_eq!(second.indexes[2].nearest(&q), first.indexes[2].nearest(&q));

    let files: Vec<_> = std::fs::read_dir(tmp.path().join("cache"))
        .unwrap()
        .map(|e| e.unwrap().path())
        .collect();
    assert_eq!(files.len(), 1, "{files:?}");
    let file = &files[0];
    let good = std::fs::read(file).unwrap();
    // Truncated, garbage, a flipped size byte deep inside, and empty: each is
    // rebuilt, never trusted, never a panic; the rebuilt file is then a hit.
    let mut flipped = good.clone();
    let mid = flipped.len() / 2;
    for b in &mut flipped[mid..mid + 64] {
        *b ^= 0x5a;
    }
    let variants: Vec<Vec<u8>> = vec![
        good[..good.len() / 3].to_vec(),
        b"not a cache at all".to_vec(),
        flipped,
        Vec::new(),
    ];
    for bad in variants {
        std::fs::write(file, &bad).unwrap();
        let (style, st) = BrushStyle::load_with_status(&dir, &opts).unwrap();
        // A flip inside sample data can decode; it must then still be
        // consistent. Every other variant must be rebuilt.
        if st == CacheStatus::Hit {
            assert!(style.validate());
        } else {
            assert_eq!(st, CacheStatus::Rebuilt);
            assert_eq!(postcard::to_stdvec(&style).unwrap(), bytes);
            let (_, st) = BrushStyle::load_with_status(&dir, &opts).unwrap();
            assert_eq!(st, CacheStatus::Hit);
        }
    }
    // Editing an exemplar changes the key: a miss, not the old analysis,
    // and the stale file is replaced, not kept beside the new one.
    std::fs::write(dir.join("b.svg"), exemplar_svg(2.0)).unwrap();
    let (_, st) = BrushStyle::load_with_status(&dir, &opts).unwrap();
    assert_eq!(st, CacheStatus::Miss);
    let after: Vec<_> = std::fs::read_dir(tmp.path().join("cache"))
        .unwrap()
        .map(|e| e.unwrap().path())
        .collect();
    assert_eq!(after.len(), 1, "{after:?}");
    assert_ne!(&after[0], file);
    // Caching off.
    let off = AnalysisOptions {
        use_cache: false,
        ..opts
    };
    assert_eq!(
        BrushStyle::load_with_status(&dir, &off).unwrap().1,
        CacheStatus::Disabled
    );
}

#[test]
fn analysis_and_sheet_do_not_depend_on_the_thread_count() {
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path().join("wavy");
    small_style(&dir, TOML);
    let mut outs = Vec::new();
    for threads in ["1", "2"] {
        let sheet = tmp.path().join(format!("sheet{threads}.png"));
        let out = flourish(&[
            "--threads",
            threads,
            "style",
            "check",
            s(&dir),
            "--no-cache",
            "--sheet",
            s(&sheet),
        ]);
        assert_eq!(
            out.status.code(),
            Some(0),
            "{}",
            String::from_utf8_lossy(&out.stderr)
        );
        outs.push((out.stdout, std::fs::read(&sheet).unwrap()));
    }
    assert_eq!(outs[0], outs[1]);
    let report = String::from_utf8_lossy(&outs[0].0);
    assert!(
        report.contains("a.svg") && report.contains("b.svg"),
        "{report}"
    );
    assert!(report.contains("traced"), "{report}");
    assert!(outs[0].1.starts_with(b"\x89PNG"));
}

#[test]
fn shipped_brush_styles_pass_the_check_without_warnings() {
    let tmp = tempfile::tempdir().unwrap();
    for name in ["vine", "scroll", "doodle"] {
        let out = flourish(&["style", "check", name, "--strict", "--cache", s(tmp.path())]);
        let report = String::from_utf8_lossy(&out.stdout);
        assert_eq!(out.status.code(), Some(0), "{name}: {report}");
        assert!(report.ends_with("0 warnings\n"), "{report}");
        // 8–12 exemplars, each with 30–100 samples.
        let n = report.matches(".svg:").count();
        assert!((8..=12).contains(&n), "{report}");
    }
}

/// The exemplar of `exemplar_svg` on a 200×200 canvas, optionally turned a
/// quarter turn about the centre.
fn square_exemplar(rotated: bool) -> String {
    let body = exemplar_svg(0.4)
        .lines()
        .filter(|l| !l.starts_with("<svg") && !l.starts_with("</svg"))
        .collect::<Vec<_>>()
        .join("\n");
    let g = if rotated {
        "<g transform=\"rotate(90 100 100)\">"
    } else {
        "<g transform=\"translate(0 50)\">"
    };
    let inner = if rotated {
        format!("<g transform=\"translate(0 50)\">{body}</g>")
    } else {
        body
    };
    format!(
        "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"200\" height=\"200\">{g}{inner}</g></svg>"
    )
}

#[test]
fn rotating_an_exemplar_rotates_its_orientation_and_neighbourhoods() {
    let tmp = tempfile::tempdir().unwrap();
    // Start and end of the band (y + 50 in the square canvas), and their
    // quarter turn about (100, 100): (x, y) -> (200 - y, x).
    let (s, e) = ([24.0, 100.0], [170.0, 100.0]);
    let rot = |p: [f64; 2]| [200.0 - p[1], p[0]];
    let mut styles = Vec::new();
    for (name, rotated, s, e) in [("a", false, s, e), ("b", true, rot(s), rot(e))] {
        let dir = tmp.path().join(name);
        std::fs::create_dir_all(&dir).unwrap();
        std::fs::write(dir.join("x.svg"), square_exemplar(rotated)).unwrap();
        std::fs::write(
            dir.join("style.toml"),
            format!(
                "kind = \"brush\"\nresolution = 128\n[[exemplar]]\nfile = \"x.svg\"\nstart = [{}, {}]\nend = [{}, {}]\n",
                s[0], s[1], e[0], e[1]
            ),
        )
        .unwrap();
        let opts = AnalysisOptions {
            use_cache: false,
            ..AnalysisOptions::default()
        };
        styles.push(BrushStyle::load(&dir, &opts).unwrap());
    }
    let (a, b) = (&styles[0], &styles[1]);
    let (la, lb) = (
        a.exemplars[0].finest().unwrap(),
        b.exemplars[0].finest().unwrap(),
    );
    assert_eq!((la.width(), la.height()), (128, 128));
    // Pixel (i, j) turns into (127 − j, i); orientation ω into (−ω_y, ω_x).
    let (mut both, mut only, mut aligned, mut close) = (0, 0, 0, 0);
    for j in 0..128 {
        for i in 0..128 {
            if !la.orientation.mask.get(i, j) {
                continue;
            }
            let (ri, rj) = (127 - j, i);
            if !lb.orientation.mask.get(ri, rj) {
                only += 1;
                continue;
            }
            both += 1;
            let wa = la.orientation.dir.get(i, j);
            let wb = lb.orientation.dir.get(ri, rj);
            if -wa[1] * wb[0] + wa[0] * wb[1] > 10f32.to_radians().cos() {
                aligned += 1;
            }
            let na = a
                .sampler
                .sample(&la.ink.ink, [i as f64 + 0.5, j as f64 + 0.5], wa);
            let nb = b
                .sampler
                .sample(&lb.ink.ink, [ri as f64 + 0.5, rj as f64 + 0.5], wb);
            let worst = na
                .iter()
                .zip(&nb)
                .map(|(x, y)| (x - y).abs())
                .fold(0.0, f32::max);
            if worst < 0.15 {
                close += 1;
            }
        }
    }
    assert!(both > 500, "{both}");
    assert!(only * 20 < both, "regions differ: {only} of {both}");
    assert!(
        aligned * 100 > both * 95,
        "orientation: {aligned} of {both}"
    );
    assert!(close * 100 > both * 95, "neighbourhoods: {close} of {both}");
}

#[test]
fn png_exemplars_are_analysed_too() {
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path().join("png");
    std::fs::create_dir_all(&dir).unwrap();
    // A dark band with a round end on white, 160×80 px.
    let img = image::RgbImage::from_fn(160, 80, |x, y| {
        let (px, py) = (x as f64 + 0.5, y as f64 + 0.5);
        let band = (20.0..130.0).contains(&px) && (py - 40.0).abs() < 6.0;
        let ball = (px - 134.0).hypot(py - 40.0) < 10.0;
        if band || ball {
            image::Rgb([30, 40, 60])
        } else {
            image::Rgb([255, 255, 255])
        }
    });
    img.save(dir.join("band.png")).unwrap();
    std::fs::write(
        dir.join("style.toml"),
        "kind = \"brush\"\nresolution = 128\n[[exemplar]]\nfile = \"band.png\"\nstart = [30.0, 40.0]\nend = [125.0, 40.0]\n",
    )
    .unwrap();
    let opts = AnalysisOptions {
        use_cache: false,
        ..AnalysisOptions::default()
    };
    let st = BrushStyle::load(&dir, &opts).unwrap();
    let ex = &st.exemplars[0];
    assert_eq!(ex.size, [160.0, 80.0]);
    let fine = ex.finest().unwrap();
    assert_eq!((fine.width(), fine.height()), (128, 64));
    // Widths along the band: 12 px × 0.8 = 9.6 finest px, within a pixel,
    // away from the ball; the spine is extended over the ball.
    let w = ex.ribs.widths();
    let mid = &w[w.len() / 4..w.len() / 2];
    assert!(mid.iter().all(|&x| (x - 9.6).abs() < 1.0), "{mid:?}");
    assert!(ex.extension[1] > 10.0, "{:?}", ex.extension);
    assert!(st.indexes.iter().all(|i| !i.is_empty()));
}

#[test]
fn sheet_over_a_file_of_the_style_is_refused() {
    // `--sheet STYLE/style.toml` wrote the PNG over the style's own file.
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path().join("wavy");
    small_style(&dir, TOML);
    for name in ["style.toml", "a.svg"] {
        let target = dir.join(name);
        let before = std::fs::read(&target).unwrap();
        let out = flourish(&[
            "style",
            "check",
            s(&dir),
            "--no-cache",
            "--sheet",
            s(&target),
        ]);
        let err = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(1), "{err}");
        assert_eq!(err.lines().count(), 1, "{err}");
        assert!(err.contains(name) && err.contains("overwrite"), "{err}");
        assert_eq!(std::fs::read(&target).unwrap(), before, "{name} changed");
    }
}
