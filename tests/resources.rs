//! Bounded time and memory: `--timeout` ends a run cleanly (exit 1, one
//! line, no output file and no temporary file left, an existing output
//! untouched), a run that lasts shows what it is doing on stderr, and
//! `--max-memory` caps what a run holds: a mode refuses a canvas over it
//! before allocating, and any allocation past it ends the run with one
//! line instead of an abort.

use std::path::PathBuf;
use std::process::Command;

/// The program, with progress lines held back (a loaded machine can make
/// any run last past the 2 s delay); a test of progress sets its own.
fn flourish() -> Command {
    let mut c = Command::new(env!("CARGO_BIN_EXE_flourish"));
    c.env("FLOURISH_PROGRESS_AFTER", "100000");
    c
}

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

fn folder(name: &str) -> PathBuf {
    let dir = PathBuf::from(env!("CARGO_TARGET_TMPDIR"))
        .join("resources")
        .join(name);
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).expect("a temporary folder");
    dir
}

/// A run far longer than its timeout: the letter filled at the largest
/// tile resolution.
fn slow_fill(out: &std::path::Path) -> Command {
    let mut c = flourish();
    c.args([
        "--timeout",
        "0.2",
        "fill",
        "--style",
        "knot",
        "--resolution",
        "1024",
    ])
    .arg(root().join("samples/fill/letter.svg"))
    .arg("-o")
    .arg(out);
    c
}

#[test]
fn timeout_ends_the_run_cleanly() {
    let dir = folder("timeout");
    let out = dir.join("letter.svg");
    let run = slow_fill(&out).output().expect("runs");
    assert_eq!(run.status.code(), Some(1));
    let err = String::from_utf8_lossy(&run.stderr);
    assert_eq!(err.lines().count(), 1, "{err}");
    assert!(err.contains("timed out after 0.2 s"), "{err}");
    let left: Vec<_> = std::fs::read_dir(&dir).expect("the folder").collect();
    assert!(left.is_empty(), "nothing written: {left:?}");

    // An output that was there stays as it was.
    std::fs::write(&out, "before").expect("an old output");
    let run = slow_fill(&out).output().expect("runs");
    assert_eq!(run.status.code(), Some(1));
    assert_eq!(std::fs::read_to_string(&out).expect("kept"), "before");
    assert_eq!(std::fs::read_dir(&dir).expect("the folder").count(), 1);
}

#[test]
fn timeout_must_be_a_number_of_seconds() {
    for bad in ["0", "-1", "nan", "soon"] {
        let run = flourish()
            .args(["--timeout", bad, "style", "list"])
            .output()
            .expect("runs");
        assert_eq!(run.status.code(), Some(2), "--timeout {bad}");
    }
}

/// Past the progress delay (2 s; 0 here) the stage shows on stderr, a line
/// each time it changes when stderr is not a terminal; `--quiet` shows
/// nothing.
#[test]
fn a_run_that_lasts_shows_its_stage() {
    let dir = folder("progress");
    let run = |quiet: bool| {
        let mut c = flourish();
        if quiet {
            c.arg("--quiet");
        }
        c.env("FLOURISH_PROGRESS_AFTER", "0")
            .args(["fill", "--style", "knot"])
            .arg(root().join("samples/fill/letter.svg"))
            .arg("-o")
            .arg(dir.join("letter.svg"))
            .output()
            .expect("runs")
    };
    let loud = run(false);
    assert!(loud.status.success());
    let err = String::from_utf8_lossy(&loud.stderr);
    assert!(err.contains("letter.svg: fill: "), "{err}");
    let quiet = run(true);
    assert!(quiet.status.success());
    assert!(
        quiet.stderr.is_empty(),
        "{}",
        String::from_utf8_lossy(&quiet.stderr)
    );
}

/// Runs `args` and asserts a clean refusal: exit 1, one stderr line that
/// names `input` and contains `cause`, and nothing left in `dir`.
#[track_caller]
fn refused(dir: &std::path::Path, args: &[&str], input: &str, cause: &str) {
    let run = flourish().args(args).output().expect("runs");
    let err = String::from_utf8_lossy(&run.stderr);
    assert_eq!(run.status.code(), Some(1), "{args:?}: {err}");
    assert_eq!(err.lines().count(), 1, "{args:?}: {err}");
    assert!(
        err.contains(input) && err.contains(cause),
        "{args:?}: {err}"
    );
    let left: Vec<_> = std::fs::read_dir(dir).expect("the folder").collect();
    assert!(left.is_empty(), "{args:?}: nothing written: {left:?}");
}

#[test]
fn a_canvas_over_the_memory_budget_is_refused_before_it_is_allocated() {
    let dir = folder("budget-estimate");
    let letter = root().join("samples/fill/letter.svg");
    let out = dir.join("letter.svg");
    let args = [
        "--max-memory",
        "300M",
        "fill",
        "--style",
        "knot",
        "--resolution",
        "1024",
        letter.to_str().expect("utf-8"),
        "-o",
        out.to_str().expect("utf-8"),
    ];
    refused(&dir, &args, "letter.svg", "memory budget");
    // At the style's own resolution the letter fits the same budget.
    let mut fits = args.to_vec();
    fits.drain(5..7);
    let run = flourish().args(&fits).output().expect("runs");
    assert!(
        run.status.success(),
        "{}",
        String::from_utf8_lossy(&run.stderr)
    );
}

#[test]
fn an_allocation_past_the_budget_ends_the_run_with_one_line() {
    // A 4000×4000 px drawing traced under 16 MB: decoding it alone takes
    // more, and no estimate stands in the way, so the last resort answers.
    let dir = folder("budget-guard");
    let src = folder("budget-guard-input");
    let png = src.join("big.png");
    let img = image::GrayImage::from_fn(4000, 4000, |x, y| {
        let (dx, dy) = (x as f64 - 2000.0, y as f64 - 2000.0);
        image::Luma([if dx * dx + dy * dy < 1.5e6 { 0 } else { 255 }])
    });
    img.save(&png).expect("a PNG");
    let out = dir.join("big.svg");
    refused(
        &dir,
        &[
            "--max-memory",
            "16M",
            "trace",
            png.to_str().expect("utf-8"),
            "-o",
            out.to_str().expect("utf-8"),
        ],
        "big.png",
        "memory budget of 16 MB",
    );
}

#[test]
fn max_memory_takes_a_size_and_verbose_reports_the_peak() {
    let dir = folder("budget-sizes");
    let letter = root().join("samples/fill/letter.svg");
    for good in ["512", "512M", "1G", "1.5GB", "2GiB"] {
        let run = flourish()
            .args(["-v", "--max-memory", good, "fill", "--style", "knot"])
            .arg(&letter)
            .arg("-o")
            .arg(dir.join("letter.svg"))
            .output()
            .expect("runs");
        let err = String::from_utf8_lossy(&run.stderr);
        assert!(run.status.success(), "--max-memory {good}: {err}");
        assert!(err.contains("flourish: peak memory "), "{err}");
    }
    for bad in ["0", "-5", "lots", "1X", "1", "nan", "1e30G"] {
        let run = flourish()
            .args(["--max-memory", bad, "style", "list"])
            .output()
            .expect("runs");
        let err = String::from_utf8_lossy(&run.stderr);
        assert_eq!(run.status.code(), Some(2), "--max-memory {bad}: {err}");
        assert_eq!(err.lines().count(), 1, "{err}");
    }
}

/// A sketch of `n` short strokes scattered over 800×600 units.
fn strokes(n: usize) -> String {
    let mut svg =
        String::from(r#"<svg xmlns="http://www.w3.org/2000/svg" width="800" height="600">"#);
    for i in 0..n {
        let (x, y) = ((i * 37) % 780 + 10, (i * 91) % 580 + 10);
        svg.push_str(&format!(
            r##"<path d="M{x} {y} l12 5" fill="none" stroke="#000" stroke-width="3"/>"##
        ));
    }
    svg.push_str("</svg>");
    svg
}

#[test]
fn a_hundred_thousand_paths_are_patterned_and_more_are_refused() {
    let dir = folder("many-paths");
    let src = folder("many-paths-input");
    let many = src.join("many.svg");
    std::fs::write(&many, strokes(100_000)).expect("a sketch");
    let out = dir.join("many.svg");
    let run = flourish()
        .args(["-q", "pattern", "--style", "stipple"])
        .arg(&many)
        .arg("-o")
        .arg(&out)
        .output()
        .expect("runs");
    assert!(
        run.status.success(),
        "{}",
        String::from_utf8_lossy(&run.stderr)
    );
    let svg = std::fs::read(&out).expect("an output");
    resvg::usvg::Tree::from_data(&svg, &resvg::usvg::Options::default()).expect("valid SVG");
    std::fs::remove_file(&out).expect("removed");

    let too_many = src.join("too-many.svg");
    std::fs::write(&too_many, strokes(100_001)).expect("a sketch");
    refused(
        &dir,
        &[
            "pattern",
            "--style",
            "stipple",
            too_many.to_str().expect("utf-8"),
            "-o",
            out.to_str().expect("utf-8"),
        ],
        "too-many.svg",
        "more than the limit of 100000",
    );
}

/// A brush run over many strokes counts them on stderr as it goes.
#[test]
fn a_long_brush_run_counts_its_strokes() {
    let dir = folder("tally");
    let sketch = dir.join("strokes.svg");
    std::fs::write(&sketch, strokes(40)).expect("a sketch");
    let cache = folder("tally-cache");
    let run = flourish()
        .env("FLOURISH_PROGRESS_AFTER", "0")
        .args(["brush", "--style", "vine", "--cache"])
        .arg(&cache)
        .arg(&sketch)
        .arg("-o")
        .arg(dir.join("out.svg"))
        .output()
        .expect("runs");
    let err = String::from_utf8_lossy(&run.stderr);
    assert!(run.status.success(), "{err}");
    assert!(err.contains("brush: strokes synthesized: "), "{err}");
    assert!(err.contains(" of 40"), "{err}");
}

/// Real drawings have specks: a filled shape with nothing inside at the
/// working resolution is left out with a warning, not the whole run.
#[test]
fn specks_are_left_out_of_fill_and_pattern_with_a_warning() {
    let dir = folder("specks");
    let sketch = dir.join("specks.svg");
    std::fs::write(
        &sketch,
        r##"<svg xmlns="http://www.w3.org/2000/svg" width="300" height="300">
<circle id="big" cx="150" cy="150" r="100" fill="#000"/>
<circle id="speck" cx="20" cy="20" r="0.01" fill="#000"/>
<path id="flat" d="M10 280 L200 280 L290 280 Z" fill="#000"/>
</svg>"##,
    )
    .expect("a sketch");
    for (mode, style, left_out) in [
        ("fill", "knot", vec!["speck"]),
        ("pattern", "stipple", vec!["speck", "flat"]),
    ] {
        let out = dir.join(format!("{mode}.svg"));
        let run = flourish()
            .args([mode, "--style", style])
            .arg(&sketch)
            .arg("-o")
            .arg(&out)
            .output()
            .expect("runs");
        let err = String::from_utf8_lossy(&run.stderr);
        assert!(run.status.success(), "{mode}: {err}");
        for id in left_out {
            assert!(
                err.lines()
                    .any(|l| l.contains("warning") && l.contains(id) && l.contains("left out")),
                "{mode}: {id}: {err}"
            );
        }
        let svg = std::fs::read_to_string(&out).expect("an output");
        assert!(svg.contains(r#"id="big""#), "{mode}: {svg}");
    }
}

/// Runs flourish under `ulimit -v` (address space, `mib` MiB) with a hang
/// guard of `guard_s` seconds; returns exit code, stderr.
fn capped(args: &[&str], mib: u64, guard_s: u64) -> (Option<i32>, String) {
    use std::time::{Duration, Instant};
    let script = format!("ulimit -v {} && exec \"$0\" \"$@\"", mib * 1024);
    let mut child = Command::new("sh")
        .arg("-c")
        .arg(script)
        .arg(env!("CARGO_BIN_EXE_flourish"))
        .args(args)
        .env("FLOURISH_CACHE_DIR", folder("hostile-cache"))
        .env("FLOURISH_PROGRESS_AFTER", "100000")
        .stdin(std::process::Stdio::null())
        .stdout(std::process::Stdio::null())
        .stderr(std::process::Stdio::piped())
        .spawn()
        .expect("sh runs");
    let start = Instant::now();
    while child.try_wait().expect("wait").is_none() {
        if start.elapsed() > Duration::from_secs(guard_s) {
            let _ = child.kill();
            panic!("{args:?}: still running after {guard_s} s");
        }
        std::thread::sleep(Duration::from_millis(20));
    }
    let out = child.wait_with_output().expect("output");
    (
        out.status.code(),
        String::from_utf8_lossy(&out.stderr).into_owned(),
    )
}

/// Each hostile or merely awkward input of the issue tracker's list, under
/// a 2 GiB address-space cap and a hang guard: a valid output, or exit 1
/// with one line naming the file. Never an abort, a signal or a hang.
#[test]
fn hostile_inputs_end_in_a_valid_output_or_one_line() {
    let dir = folder("hostile");
    let w = |name: &str, text: String| {
        let p = dir.join(name);
        std::fs::write(&p, text).expect("an input");
        p
    };
    let svg = |body: &str| {
        format!(r#"<svg xmlns="http://www.w3.org/2000/svg" width="800" height="600">{body}</svg>"#)
    };
    // 300,000 points in one path, stroked and as a region.
    let mut d = String::from("M400 300");
    for i in 1..300_000 {
        let t = i as f64 * 1e-3;
        let r = 250.0 * (0.5 + 0.5 * (t * 0.3).sin());
        d.push_str(&format!(
            " L{:.2} {:.2}",
            400.0 + r * t.cos(),
            300.0 + r * t.sin()
        ));
    }
    let points = w(
        "points.svg",
        svg(&format!(
            r##"<path d="{d}" fill="none" stroke="#000" stroke-width="12"/>"##
        )),
    );
    let points_region = w(
        "points-region.svg",
        svg(&format!(r##"<path d="{d} Z" fill="#000"/>"##)),
    );
    // Arcs with 1e308 radii and coordinates, beside a shape that is fine.
    let arcs = w(
        "arcs.svg",
        svg(
            r##"<path d="M10 10 A1e308 1e308 0 0 1 1e308 1e308" fill="none" stroke="#000" stroke-width="5"/><path d="M100 100 C200 0 300 200 400 100" fill="none" stroke="#000" stroke-width="20"/><circle cx="600" cy="300" r="80" fill="#000"/>"##,
        ),
    );
    // One coordinate of 3.4e38.
    let far = w(
        "far.svg",
        svg(
            r##"<path d="M10 10 L3.4e38 20" fill="none" stroke="#000" stroke-width="5"/><path d="M100 100 L400 120" fill="none" stroke="#000" stroke-width="20"/>"##,
        ),
    );
    // A sketch 0.0001 units high.
    let flat = w(
        "flat.svg",
        r##"<svg xmlns="http://www.w3.org/2000/svg" width="0.0001" height="0.0001" viewBox="0 0 0.0001 0.0001"><rect width="0.0001" height="0.0001" fill="#000"/></svg>"##.to_string(),
    );
    // 2,000 regions, each patterned with many elements.
    let mut many = String::new();
    for i in 0..2000 {
        let (x, y) = ((i % 50) * 16 + 8, (i / 50) * 15 + 8);
        many.push_str(&format!(
            r##"<rect x="{x}" y="{y}" width="14" height="13" fill="#000"/>"##
        ));
    }
    let regions = w("regions.svg", svg(&many));
    // Ten hairlines across the page: their pieces come to more canvas
    // than a sketch may take.
    let mut lines = String::new();
    for k in 0..10 {
        lines.push_str(&format!(
            r##"<path d="M0 {} L800 {}" fill="none" stroke="#000" stroke-width="0.1"/>"##,
            k * 10,
            500 + k * 10
        ));
    }
    let hairlines = w("hairlines.svg", svg(&lines));
    // A style of 20,000 exemplars, and one whose exemplar is a FIFO.
    let crowd = dir.join("crowd");
    std::fs::create_dir_all(&crowd).expect("a style folder");
    let mut toml = String::from("kind = \"fill\"\n");
    for i in 0..20_000 {
        toml.push_str(&format!("[[exemplar]]\nfile = \"e{i}.svg\"\n"));
    }
    std::fs::write(crowd.join("style.toml"), toml).expect("style.toml");
    let fifo_style = dir.join("fifo");
    std::fs::create_dir_all(&fifo_style).expect("a style folder");
    std::fs::write(
        fifo_style.join("style.toml"),
        "kind = \"fill\"\n[[exemplar]]\nfile = \"tile.svg\"\n",
    )
    .expect("style.toml");
    let fifo = Command::new("mkfifo")
        .arg(fifo_style.join("tile.svg"))
        .status()
        .is_ok_and(|s| s.success());

    let out = dir.join("out.svg");
    let o = out.to_str().expect("utf-8");
    let p = |x: &std::path::Path| x.to_str().expect("utf-8").to_string();
    let mut cases: Vec<(Vec<String>, String)> = vec![
        (
            vec![
                "pattern".into(),
                "--style".into(),
                "stipple".into(),
                p(&points),
            ],
            p(&points),
        ),
        (
            vec![
                "fill".into(),
                "--style".into(),
                "knot".into(),
                p(&points_region),
            ],
            p(&points_region),
        ),
        (
            vec!["brush".into(), "--style".into(), "vine".into(), p(&arcs)],
            p(&arcs),
        ),
        (
            vec![
                "pattern".into(),
                "--style".into(),
                "stipple".into(),
                p(&arcs),
            ],
            p(&arcs),
        ),
        (
            vec!["fill".into(), "--style".into(), "knot".into(), p(&arcs)],
            p(&arcs),
        ),
        (
            vec![
                "pattern".into(),
                "--style".into(),
                "stipple".into(),
                p(&far),
            ],
            p(&far),
        ),
        (
            vec!["brush".into(), "--style".into(), "vine".into(), p(&far)],
            p(&far),
        ),
        (
            vec![
                "brush".into(),
                "--style".into(),
                "vine".into(),
                p(&hairlines),
            ],
            p(&hairlines),
        ),
        (vec!["trace".into(), p(&flat)], p(&flat)),
        (
            vec!["fill".into(), "--style".into(), "knot".into(), p(&flat)],
            p(&flat),
        ),
        (
            vec![
                "pattern".into(),
                "--style".into(),
                "stipple".into(),
                p(&regions),
            ],
            p(&regions),
        ),
        (
            vec!["fill".into(), "--style".into(), p(&crowd), p(&arcs)],
            "style.toml".into(),
        ),
    ];
    if fifo {
        cases.push((
            vec!["fill".into(), "--style".into(), p(&fifo_style), p(&arcs)],
            "tile.svg".into(),
        ));
    }
    for (args, named) in cases {
        let _ = std::fs::remove_file(&out);
        let mut all: Vec<&str> = args.iter().map(String::as_str).collect();
        all.extend(["-o", o]);
        let (code, err) = capped(&all, 2048, 300);
        match code {
            Some(0) => {
                let bytes = std::fs::read(&out).expect("an output");
                let tree = resvg::usvg::Tree::from_data(&bytes, &resvg::usvg::Options::default())
                    .unwrap_or_else(|e| panic!("{args:?}: invalid output: {e}"));
                assert!(
                    tree.size().width() > 0.0 && tree.size().height() > 0.0,
                    "{args:?}: zero size"
                );
                let paths = String::from_utf8_lossy(&bytes).matches("<path").count();
                assert!(paths <= 200_000, "{args:?}: {paths} paths");
            }
            Some(1) => {
                let lines: Vec<&str> = err.lines().filter(|l| !l.contains("warning")).collect();
                assert_eq!(lines.len(), 1, "{args:?}: {err}");
                let name = std::path::Path::new(&named)
                    .file_name()
                    .and_then(|n| n.to_str())
                    .expect("a name");
                assert!(lines[0].contains(name), "{args:?}: {err}");
                assert!(!out.exists(), "{args:?}: output left");
            }
            other => panic!("{args:?}: exit {other:?}: {err}"),
        }
    }
}

/// A stroke 1 unit wide across the page needs a 6400×4800 px canvas at
/// 8 px across, past the 16 Mpx one canvas may have: it is brushed in
/// pieces, under the 2 GiB cap.
#[test]
fn a_long_thin_stroke_is_brushed_in_pieces_within_the_budget() {
    let dir = folder("long-stroke");
    let sketch = dir.join("long.svg");
    std::fs::write(
        &sketch,
        r##"<svg xmlns="http://www.w3.org/2000/svg" width="800" height="600"><path id="long" d="M10 10 C300 50 500 550 790 590" fill="none" stroke="#000" stroke-width="1"/></svg>"##,
    )
    .expect("a sketch");
    let out = dir.join("out.svg");
    let (code, err) = capped(
        &[
            "brush",
            "--style",
            "vine",
            sketch.to_str().expect("utf-8"),
            "-o",
            out.to_str().expect("utf-8"),
        ],
        2048,
        300,
    );
    assert_eq!(code, Some(0), "{err}");
    let bytes = std::fs::read(&out).expect("an output");
    let tree = resvg::usvg::Tree::from_data(&bytes, &resvg::usvg::Options::default())
        .expect("a valid output");
    // The ornament reaches both ends of the stroke.
    let b = tree.root().abs_bounding_box();
    assert!(b.left() < 20.0 && b.right() > 780.0, "{b:?}");
    assert!(b.top() < 20.0 && b.bottom() > 580.0, "{b:?}");
}

/// Runs flourish with `args` and returns its exit code, stderr and peak
/// resident memory in MiB (the kernel's high-water mark, read while it
/// runs: the last reading before it ends, at most the true peak).
fn peak_resident(args: &[&str]) -> (Option<i32>, String, u64) {
    let mut child = flourish()
        .args(args)
        .stdin(std::process::Stdio::null())
        .stdout(std::process::Stdio::null())
        .stderr(std::process::Stdio::piped())
        .spawn()
        .expect("flourish runs");
    let status = format!("/proc/{}/status", child.id());
    let mut kib = 0u64;
    while child.try_wait().expect("wait").is_none() {
        if let Ok(s) = std::fs::read_to_string(&status) {
            if let Some(v) = s
                .lines()
                .find_map(|l| l.strip_prefix("VmHWM:"))
                .and_then(|v| v.trim().trim_end_matches("kB").trim().parse::<u64>().ok())
            {
                kib = kib.max(v);
            }
        }
        std::thread::sleep(std::time::Duration::from_millis(10));
    }
    let out = child.wait_with_output().expect("output");
    (
        out.status.code(),
        String::from_utf8_lossy(&out.stderr).into_owned(),
        kib / 1024,
    )
}

/// Issue 23: a stroke 500 widths long (10 000 units at 20 wide, in 13 rows
/// across an 800-unit page) is brushed within the 400 MB memory goal, as
/// the program counts its heap and as the kernel counts its pages.
#[test]
fn a_stroke_five_hundred_widths_long_stays_within_the_memory_goal() {
    let dir = folder("five-hundred-widths");
    let mut d = String::new();
    let (mut y, mut len, mut last) = (40.0f64, 0.0f64, None::<(f64, f64)>);
    for row in 0.. {
        for i in 0..=76 {
            let x = if row % 2 == 0 {
                20 + 10 * i
            } else {
                780 - 10 * i
            } as f64;
            let p = (x, y + 12.0 * (x / 40.0).sin());
            if let Some(q) = last {
                len += ((p.0 - q.0).powi(2) + (p.1 - q.1).powi(2)).sqrt();
            }
            d += &format!(
                "{}{:.1} {:.1} ",
                if last.is_none() { "M" } else { "L" },
                p.0,
                p.1
            );
            last = Some(p);
        }
        y += 100.0;
        if len >= 10_000.0 {
            break;
        }
    }
    let sketch = dir.join("long.svg");
    std::fs::write(
        &sketch,
        format!(r##"<svg xmlns="http://www.w3.org/2000/svg" width="800" height="{h}" viewBox="0 0 800 {h}"><path d="{d}" fill="none" stroke="#000" stroke-width="20"/></svg>"##, h = y + 40.0),
    )
    .expect("a sketch");
    let out = dir.join("out.svg");
    let (code, err, mib) = peak_resident(&[
        "-v",
        "brush",
        "--style",
        "vine",
        sketch.to_str().expect("utf-8"),
        "-o",
        out.to_str().expect("utf-8"),
    ]);
    assert_eq!(code, Some(0), "{err}");
    assert!(mib <= 400, "peak resident {mib} MiB");
    let counted = err
        .lines()
        .find_map(|l| l.strip_prefix("flourish: peak memory "))
        .and_then(|l| {
            let mut w = l.split(' ');
            let n = w.next()?.parse::<f64>().ok()?;
            match w.next()? {
                "KB" => Some(n / 1024.0),
                "MB" => Some(n),
                "GB" => Some(n * 1024.0),
                _ => None,
            }
        })
        .expect("-v reports the peak");
    assert!(counted <= 400.0, "{err}");
}
