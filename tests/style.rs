//! `flourish style check` end to end: bad input (one clear line, exit 1),
//! thread-count determinism, the shipped libraries passing the check
//! without warnings, and the sheet never overwriting the style.
//!
//! Small styles are copied from `tests/fixtures/wavy` into temporary
//! folders.

use std::path::{Path, PathBuf};
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

const TOML: &str = include_str!("fixtures/wavy/style.toml");

/// The two wavy exemplars of `tests/fixtures/wavy` in `dir`, with `toml`.
fn small_style(dir: &Path, toml: &str) {
    let fixture = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("tests/fixtures/wavy");
    std::fs::create_dir_all(dir).unwrap();
    std::fs::write(dir.join("style.toml"), toml).unwrap();
    for name in ["a.svg", "b.svg"] {
        std::fs::copy(fixture.join(name), dir.join(name)).unwrap();
    }
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
}

/// `style check` reports every kind of style: a fill style's swatches
/// (size, repeat, colour layers and their coverage) and a pattern style's
/// elements and spacing; the diagnostics sheet stays a brush sheet.
#[test]
fn style_check_reports_fill_and_pattern_styles() {
    let out = flourish(&["style", "check", "knot"]);
    assert!(out.status.success());
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(text.starts_with("style knot: fill"), "{text}");
    assert!(
        text.contains("tile.svg: 96×96 px, seamless tile, 2 layers bottom first (#22324f"),
        "{text}"
    );
    let out = flourish(&["style", "check", "hatching"]);
    assert!(out.status.success());
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(text.starts_with("style hatching: pattern"), "{text}");
    assert!(text.contains("elements in a row"), "{text}");
    let tmp = tempfile::tempdir().unwrap();
    let sheet = tmp.path().join("sheet.png");
    let out = flourish(&["style", "check", "stipple", "--sheet", s(&sheet)]);
    assert_eq!(out.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&out.stderr).contains("pattern style"));
    assert!(!sheet.exists());
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

/// `style init` makes a folder of drawings a library: start and end found
/// for each (at the tips of the fixture's drawings), a
/// dot warned about with a usable fallback, the result passing `style
/// check`; an existing style.toml is kept unless `--force`.
#[test]
fn style_init_writes_a_library_with_found_ends() {
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path().join("lib");
    small_style(&dir, TOML);
    std::fs::remove_file(dir.join("style.toml")).unwrap();
    std::fs::write(
        dir.join("dot.svg"),
        r#"<svg xmlns="http://www.w3.org/2000/svg" width="100" height="100"><circle cx="50" cy="50" r="30"/></svg>"#,
    )
    .unwrap();
    std::fs::write(dir.join("notes.txt"), "not a drawing").unwrap();
    let out = flourish(&["style", "init", s(&dir)]);
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(0), "{err}");
    assert!(
        err.contains("dot.svg") && err.contains("no clear main branch"),
        "{err}"
    );
    let toml = std::fs::read_to_string(dir.join("style.toml")).unwrap();
    assert_eq!(toml.matches("[[exemplar]]").count(), 3, "{toml}");
    assert_eq!(toml.matches("start = [").count(), 3, "{toml}");
    // The fixture's drawings run from the butt end of a wavy line at
    // (20, 50) to the far side of a disc of radius 10 at (176, 50): the
    // found ends of a.svg lie within 2 units (about 1 % of the spine) of
    // those tips.
    let found: toml::Table = toml::from_str(&toml).unwrap();
    let ends = |file: &str| -> Option<[[f64; 2]; 2]> {
        let e = found["exemplar"]
            .as_array()?
            .iter()
            .find(|e| e["file"].as_str() == Some(file))?;
        let p = |key: &str| -> Option<[f64; 2]> {
            let v = e.get(key)?.as_array()?;
            Some([v[0].as_float()?, v[1].as_float()?])
        };
        Some([p("start")?, p("end")?])
    };
    // b.svg's line meets the disc from below and starts steeply: its end
    // is on the disc's rim where the line's direction leaves it, its
    // start on the slanted butt end (4.5 units either side of (20, 50)).
    let d = |p: [f64; 2], q: [f64; 2]| (p[0] - q[0]).hypot(p[1] - q[1]);
    let [a, b] = ends("a.svg").unwrap_or_else(|| panic!("a.svg: no ends in {toml}"));
    assert!(
        d(a, [20.0, 50.0]) <= 2.0 && d(b, [186.0, 50.0]) <= 2.0,
        "a.svg: found {a:?} {b:?}"
    );
    let [a, b] = ends("b.svg").unwrap_or_else(|| panic!("b.svg: no ends in {toml}"));
    assert!(
        d(a, [20.0, 50.0]) <= 4.6 && (d(b, [176.0, 50.0]) - 10.0).abs() <= 1.0 && b[0] > 176.0,
        "b.svg: found {a:?} {b:?}"
    );
    let cache = tmp.path().join("cache");
    let check = flourish(&["style", "check", s(&dir), "--cache", s(&cache)]);
    assert_eq!(
        check.status.code(),
        Some(0),
        "{}",
        String::from_utf8_lossy(&check.stderr)
    );
    let again = flourish(&["style", "init", s(&dir)]);
    assert_eq!(again.status.code(), Some(2));
    let force = flourish(&["style", "init", s(&dir), "--force"]);
    assert_eq!(force.status.code(), Some(0));
}
