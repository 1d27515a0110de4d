//! End-to-end tests of the `flourish` command line: exit statuses (0
//! success, 1 failure, 2 usage error), one-line error messages that name the
//! file, and outputs that are either complete or absent (an existing output
//! is left untouched when a run fails).
//!
//! Every input is generated inside the test (PNGs through `image`, SVGs by
//! hand) in a temporary folder.

use std::path::{Path, PathBuf};
use std::process::{Command, Output, Stdio};
use std::time::{Duration, Instant};

const BIN: &str = env!("CARGO_BIN_EXE_flourish");

/// Content written to pre-existing outputs: must survive failed runs.
const SENTINEL: &[u8] = b"do not touch\n";

// ---------------------------------------------------------------------------
// Helpers

fn flourish(args: &[&str]) -> Output {
    Command::new(BIN)
        .args(args)
        .env("FLOURISH_PROGRESS_AFTER", "100000")
        .stdin(Stdio::null())
        .output()
        .expect("run flourish")
}

/// Runs flourish in `dir`, killing it (and failing) after `limit`: a
/// guard against a hang, set far above what the run takes on a slow
/// machine (the tests assert no timings).
fn flourish_guarded(dir: &Path, args: &[&str], limit: Duration) -> Output {
    let start = Instant::now();
    let mut child = Command::new(BIN)
        .env("FLOURISH_PROGRESS_AFTER", "100000")
        .args(args)
        .current_dir(dir)
        .stdin(Stdio::null())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .expect("run flourish");
    loop {
        if child.try_wait().expect("wait").is_some() {
            break;
        }
        if start.elapsed() > limit {
            let _ = child.kill();
            let out = child.wait_with_output().expect("collect output");
            panic!(
                "flourish {args:?} still running after {limit:?}; stderr: {}",
                String::from_utf8_lossy(&out.stderr)
            );
        }
        std::thread::sleep(Duration::from_millis(20));
    }
    child.wait_with_output().expect("collect output")
}

/// Traces `svg` into `dir`/out.svg under the hang guard (120 s, far above
/// the second or so the run takes) and asserts it wrote paths.
fn traces_to_paths(dir: &Path, svg: &Path) {
    let out = dir.join("out.svg");
    let o = flourish_guarded(
        dir,
        &["trace", s(svg), "-o", s(&out)],
        Duration::from_secs(120),
    );
    assert!(o.status.success(), "stderr: {}", stderr(&o));
    assert!(std::fs::read_to_string(&out).unwrap().contains("<path"));
}

/// Runs flourish with its address space capped at `mib` MiB (`ulimit -v`),
/// so a run that allocates a huge image dies instead of answering.
fn flourish_capped(dir: &Path, args: &[&str], mib: u64) -> Output {
    let script = format!("ulimit -v {} && exec \"$0\" \"$@\"", mib * 1024);
    Command::new("sh")
        .arg("-c")
        .arg(script)
        .arg(BIN)
        .args(args)
        .env("FLOURISH_PROGRESS_AFTER", "100000")
        .current_dir(dir)
        .stdin(Stdio::null())
        .output()
        .expect("run flourish under sh")
}

fn s(p: &Path) -> &str {
    p.to_str().expect("utf-8 temp path")
}

fn stderr(o: &Output) -> String {
    String::from_utf8_lossy(&o.stderr).into_owned()
}

fn stdout(o: &Output) -> String {
    String::from_utf8_lossy(&o.stdout).into_owned()
}

fn code(o: &Output) -> Option<i32> {
    o.status.code()
}

/// A run failure: exit 1, exactly one stderr line containing the file name
/// of `file` and every string of `causes` (case-insensitive).
#[track_caller]
fn assert_failure(o: &Output, file: &Path, causes: &[&str]) {
    let err = stderr(o);
    assert_eq!(code(o), Some(1), "expected exit 1; stderr: {err}");
    let lines: Vec<&str> = err.lines().filter(|l| !l.trim().is_empty()).collect();
    assert_eq!(
        lines.len(),
        1,
        "expected exactly one line on stderr, got: {err:?}"
    );
    let name = file.file_name().unwrap().to_str().unwrap();
    assert!(
        lines[0].contains(name),
        "stderr line does not name {name}: {err:?}"
    );
    for c in causes {
        assert!(
            lines[0].to_lowercase().contains(&c.to_lowercase()),
            "stderr line does not mention {c:?}: {err:?}"
        );
    }
}

/// `diff` could not compare: exit 2 and one line naming the file.
#[track_caller]
fn assert_trouble(o: &Output, file: &Path, causes: &[&str]) {
    let err = stderr(o);
    assert_eq!(code(o), Some(2), "expected exit 2; stderr: {err}");
    let lines: Vec<&str> = err.lines().filter(|l| !l.trim().is_empty()).collect();
    assert_eq!(lines.len(), 1, "expected one line on stderr, got: {err:?}");
    let name = file.file_name().unwrap().to_str().unwrap();
    assert!(
        lines[0].contains(name),
        "stderr does not name {name}: {err:?}"
    );
    for c in causes {
        assert!(
            lines[0].contains(c),
            "stderr does not mention {c:?}: {err:?}"
        );
    }
}

/// A usage error: exit 2 and something on stderr, nothing on stdout.
#[track_caller]
fn assert_usage(o: &Output, mention: &str) {
    let err = stderr(o);
    assert_eq!(code(o), Some(2), "expected exit 2 (usage); stderr: {err}");
    assert!(!err.trim().is_empty(), "usage error with an empty stderr");
    assert!(
        err.to_lowercase().contains(&mention.to_lowercase()),
        "usage message does not mention {mention:?}: {err:?}"
    );
    assert!(
        o.stdout.is_empty(),
        "usage error wrote to stdout: {:?}",
        stdout(o)
    );
}

/// No `.flourish-*.tmp` files left behind in `dir`.
#[track_caller]
fn assert_no_temp_files(dir: &Path) {
    for e in std::fs::read_dir(dir).unwrap() {
        let name = e.unwrap().file_name().to_string_lossy().into_owned();
        assert!(
            !(name.starts_with(".flourish-") && name.ends_with(".tmp")),
            "temporary file {name} left in {}",
            dir.display()
        );
    }
}

/// Parses SVG output with usvg, as a renderer would.
#[track_caller]
fn parse_output(svg: &[u8]) -> Result<resvg::usvg::Tree, resvg::usvg::Error> {
    resvg::usvg::Tree::from_data(svg, &resvg::usvg::Options::default())
}

fn tempdir() -> tempfile::TempDir {
    tempfile::tempdir().expect("temp dir")
}

// ---------------------------------------------------------------------------
// Generated inputs

/// Coverage of a disc / ring scene at (x, y), supersampled `ss`×`ss`.
fn render_gray(w: u32, h: u32, ss: u32, inside: impl Fn(f64, f64) -> bool) -> image::GrayImage {
    image::GrayImage::from_fn(w, h, |x, y| {
        let mut n = 0;
        for j in 0..ss {
            for i in 0..ss {
                let px = x as f64 + (i as f64 + 0.5) / ss as f64;
                let py = y as f64 + (j as f64 + 0.5) / ss as f64;
                n += inside(px, py) as u32;
            }
        }
        let cov = n as f64 / (ss * ss) as f64;
        image::Luma([(255.0 * (1.0 - cov)).round() as u8])
    })
}

fn disc(cx: f64, cy: f64, r: f64) -> impl Fn(f64, f64) -> bool {
    move |x, y| (x - cx).powi(2) + (y - cy).powi(2) <= r * r
}

/// A small black disc on white, `size`×`size`.
fn write_disc_png(path: &Path, size: u32) {
    let c = size as f64 / 2.0;
    render_gray(size, size, 4, disc(c, c, size as f64 * 0.3))
        .save(path)
        .expect("write PNG");
}

/// Several discs and a ring, 200×200, anti-aliased (4×4 supersampling).
fn write_complex_png(path: &Path) {
    let discs = [
        (40.0, 40.0, 25.0),
        (150.0, 50.0, 30.0),
        (60.0, 150.0, 18.5),
        (120.0, 120.0, 12.3),
    ];
    let img = render_gray(200, 200, 4, |x, y| {
        let ring = {
            let d = ((x - 130.0).powi(2) + (y - 150.0).powi(2)).sqrt();
            (28.0..=40.0).contains(&d)
        };
        ring || discs.iter().any(|&(cx, cy, r)| disc(cx, cy, r)(x, y))
    });
    img.save(path).expect("write PNG");
}

/// A PNG full of noise (so it compresses badly) as bytes.
fn noisy_png_bytes(w: u32, h: u32) -> Vec<u8> {
    let mut state = 0x2545_f491_4f6c_dd1du64;
    let img = image::RgbImage::from_fn(w, h, |_, _| {
        state ^= state << 13;
        state ^= state >> 7;
        state ^= state << 17;
        let b = state.to_le_bytes();
        image::Rgb([b[0], b[1], b[2]])
    });
    let mut out = Vec::new();
    img.write_to(&mut std::io::Cursor::new(&mut out), image::ImageFormat::Png)
        .expect("encode PNG");
    out
}

fn crc32(bytes: &[u8]) -> u32 {
    let mut crc = 0xffff_ffffu32;
    for &b in bytes {
        crc ^= b as u32;
        for _ in 0..8 {
            crc = if crc & 1 != 0 {
                (crc >> 1) ^ 0xedb8_8320
            } else {
                crc >> 1
            };
        }
    }
    !crc
}

fn png_chunk(out: &mut Vec<u8>, kind: &[u8; 4], data: &[u8]) {
    out.extend_from_slice(&(data.len() as u32).to_be_bytes());
    let mut body = kind.to_vec();
    body.extend_from_slice(data);
    out.extend_from_slice(&body);
    out.extend_from_slice(&crc32(&body).to_be_bytes());
}

/// A PNG whose header declares `w`×`h` 8-bit greyscale pixels, with a tiny
/// (valid zlib, far too short) IDAT and an IEND.
fn png_header_only(w: u32, h: u32) -> Vec<u8> {
    let mut out = b"\x89PNG\r\n\x1a\n".to_vec();
    let mut ihdr = Vec::new();
    ihdr.extend_from_slice(&w.to_be_bytes());
    ihdr.extend_from_slice(&h.to_be_bytes());
    ihdr.extend_from_slice(&[8, 0, 0, 0, 0]); // depth 8, grey, deflate, adaptive, no interlace
    png_chunk(&mut out, b"IHDR", &ihdr);
    // zlib: header 78 01, one final stored block of 2 bytes (filter 0, pixel 0), Adler-32.
    let idat = [
        0x78, 0x01, 0x01, 0x02, 0x00, 0xfd, 0xff, 0x00, 0x00, 0x00, 0x02, 0x00, 0x01,
    ];
    png_chunk(&mut out, b"IDAT", &idat);
    png_chunk(&mut out, b"IEND", &[]);
    out
}

const SQUARE_SVG: &str = r#"<svg xmlns="http://www.w3.org/2000/svg" width="100" height="50" viewBox="0 0 100 50">
<rect x="10" y="10" width="30" height="30" fill="black"/>
</svg>
"#;

const SQUARE_SVG_MOVED: &str = r#"<svg xmlns="http://www.w3.org/2000/svg" width="100" height="50" viewBox="0 0 100 50">
<rect x="50" y="10" width="30" height="30" fill="black"/>
</svg>
"#;

const SQUARE_SVG_TALL: &str = r#"<svg xmlns="http://www.w3.org/2000/svg" width="100" height="80" viewBox="0 0 100 80">
<rect x="10" y="10" width="30" height="30" fill="black"/>
</svg>
"#;

// ---------------------------------------------------------------------------
// trace: bad inputs, one at a time

/// Runs `trace IN -o OUT` twice: once with no output present (it must not
/// be created) and once with a pre-existing output (it must be untouched).
/// Returns the first run's output.
#[track_caller]
fn trace_must_fail(input: &Path, causes: &[&str]) -> Output {
    let dir = input.parent().unwrap();
    let out = dir.join("out.svg");
    let _ = std::fs::remove_file(&out);
    let o = flourish(&["trace", s(input), "-o", s(&out)]);
    assert_failure(&o, input, causes);
    assert!(!out.exists(), "failed run created {}", out.display());
    assert_no_temp_files(dir);

    std::fs::write(&out, SENTINEL).unwrap();
    let o2 = flourish(&["trace", s(input), "-o", s(&out)]);
    assert_failure(&o2, input, causes);
    assert_eq!(
        std::fs::read(&out).unwrap(),
        SENTINEL,
        "failed run changed the existing output"
    );
    assert_no_temp_files(dir);
    o
}

#[test]
fn random_bytes_are_not_an_image() {
    let t = tempdir();
    let p = t.path().join("noise.png");
    let bytes: Vec<u8> = (0..4096u32)
        .map(|i| (i.wrapping_mul(2_654_435_761) >> 13) as u8 | 1)
        .collect();
    std::fs::write(&p, bytes).unwrap();
    trace_must_fail(&p, &["image"]);
}

#[test]
fn text_file_named_png_is_not_an_image() {
    let t = tempdir();
    let p = t.path().join("notes.png");
    std::fs::write(&p, "This is a shopping list, not a picture.\nmilk\neggs\n").unwrap();
    trace_must_fail(&p, &["image"]);
}

#[test]
fn empty_file_fails_cleanly() {
    let t = tempdir();
    let p = t.path().join("empty.png");
    std::fs::write(&p, b"").unwrap();
    trace_must_fail(&p, &[]);
}

#[test]
fn truncated_png_fails_cleanly() {
    let t = tempdir();
    let p = t.path().join("truncated.png");
    let full = noisy_png_bytes(64, 64);
    std::fs::write(&p, &full[..full.len() / 2]).unwrap();
    trace_must_fail(&p, &[]);
}

#[test]
fn svg_that_does_not_parse_fails_cleanly() {
    let t = tempdir();
    let p = t.path().join("broken.svg");
    std::fs::write(
        &p,
        "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"10\" height=\"10\"><rect x=\"1\" </svg",
    )
    .unwrap();
    trace_must_fail(&p, &["svg"]);
}

#[test]
fn svg_with_nonsense_size_fails_cleanly() {
    let t = tempdir();
    let p = t.path().join("zero.svg");
    std::fs::write(&p, r#"<svg xmlns="http://www.w3.org/2000/svg" width="0" height="0"><rect width="1" height="1"/></svg>"#)
        .unwrap();
    trace_must_fail(&p, &[]);
}

#[test]
fn huge_declared_png_fails_fast_with_size_limit() {
    let t = tempdir();
    let p = t.path().join("huge.png");
    std::fs::write(&p, png_header_only(50_000, 50_000)).unwrap();
    let out = t.path().join("out.svg");
    // Nothing allocated: the 2.5 GB grey image would not fit in 1 GiB of
    // address space, and the refusal must come before it.
    let o = flourish_capped(t.path(), &["trace", s(&p), "-o", s(&out)], 1024);
    assert_failure(&o, &p, &["size limit"]);
    assert!(!out.exists());
    // And the same through the helper (pre-existing output untouched).
    trace_must_fail(&p, &["size limit"]);
}

/// A 100-megapixel picture (10,000 px square, issue 24's size case) is
/// refused before it is decoded: one line naming the file and the size
/// limit, exit 1, no output.
#[test]
fn hundred_megapixel_png_is_refused_with_the_size_limit() {
    let t = tempdir();
    let p = t.path().join("photo-100mpx.png");
    std::fs::write(&p, png_header_only(10_000, 10_000)).unwrap();
    trace_must_fail(&p, &["size limit", "10000×10000"]);
}

#[test]
fn huge_declared_svg_canvas_is_capped_by_resolution() {
    // A huge SVG is rasterized at --resolution, so it is not a size error;
    // an absurd --resolution is.
    let t = tempdir();
    let p = t.path().join("wide.svg");
    std::fs::write(
        &p,
        r#"<svg xmlns="http://www.w3.org/2000/svg" width="1000000" height="10"><rect width="500000" height="5"/></svg>"#,
    )
    .unwrap();
    let out = t.path().join("out.svg");
    let o = flourish_capped(
        t.path(),
        &["trace", s(&p), "-o", s(&out), "--resolution", "100000"],
        1024,
    );
    assert_failure(&o, &p, &["size limit"]);
    assert!(!out.exists());
}

/// Shapes with coordinates of 10¹² or more (far off the canvas, or
/// crossing it with an edge of nearly zero curvature) trace in moments:
/// only the parts near the canvas are flattened and measured. (Flattening
/// a circle of radius 10¹² px to 0.01 px in full would take minutes and
/// gigabytes.)
#[test]
fn svg_shapes_with_huge_coordinates_trace_quickly() {
    let t = tempdir();
    let p = write(
        t.path(),
        "huge.svg",
        r#"<svg xmlns="http://www.w3.org/2000/svg" width="100" height="100">
<circle cx="1e20" cy="5" r="1e19"/>
<circle cx="50" cy="1e12" r="999999999950"/>
<path d="M10 10 L 1e30 1e30 L 10 20Z"/>
<rect x="20" y="20" width="10" height="10"/></svg>"#,
    );
    traces_to_paths(t.path(), &p);
}

#[test]
fn svg_long_stroked_path_traces_quickly() {
    // A spiral polyline of 100 000 points: if its stroke outline's every
    // segment read every other segment for its winding number, it would
    // take minutes; read band by band, it takes a second or two.
    let t = tempdir();
    let n = 100_000;
    let pts: Vec<String> = (0..n)
        .map(|i| {
            let f = i as f64 / n as f64;
            let (a, r) = (f * 60.0 * std::f64::consts::PI, 5.0 + 90.0 * f);
            format!("{:.2} {:.2}", 100.0 + r * a.cos(), 100.0 + r * a.sin())
        })
        .collect();
    let p = write(
        t.path(),
        "spiral.svg",
        &format!(
            r#"<svg xmlns="http://www.w3.org/2000/svg" width="200" height="200">
<polyline points="{}" fill="none" stroke="black" stroke-width="0.8"/></svg>"#,
            pts.join(" ")
        ),
    );
    traces_to_paths(t.path(), &p);
}

#[test]
fn missing_input_fails_cleanly() {
    let t = tempdir();
    let p = t.path().join("does-not-exist.png");
    trace_must_fail(&p, &[]);
}

#[test]
fn directory_as_input_fails_cleanly() {
    let t = tempdir();
    let p = t.path().join("folder.png");
    std::fs::create_dir(&p).unwrap();
    trace_must_fail(&p, &["directory"]);
}

// ---------------------------------------------------------------------------
// trace: degenerate but valid inputs

#[test]
fn endless_device_as_input_fails_at_the_size_limit() {
    // /dev/zero has no length to check beforehand: read to its end, it
    // would fill memory. Reading stops at the file size limit instead.
    let dev = Path::new("/dev/zero");
    if !dev.exists() {
        return;
    }
    let t = tempdir();
    let out = t.path().join("out.svg");
    for cmd in ["trace", "fill"] {
        let o = flourish_guarded(
            t.path(),
            &[cmd, s(dev), "-o", s(&out)],
            Duration::from_secs(30),
        );
        assert_failure(&o, dev, &["limit"]);
        assert!(!out.exists());
    }
}

/// A picture with nothing to trace is bad input (issue 24): blank paper,
/// a photo of blank paper (uneven light and grain, no ink), nothing but
/// transparency, a solid black image and a 1 × 10,000-px strip of ink each
/// give one line naming the file and the cause, exit 1, and no output.
#[test]
fn pictures_with_nothing_to_trace_are_refused() {
    let t = tempdir();
    let blank = t.path().join("white.png");
    image::GrayImage::from_pixel(40, 30, image::Luma([255]))
        .save(&blank)
        .unwrap();
    trace_must_fail(&blank, &["nothing to trace", "no ink"]);
    // Paper photographed under a lamp: light falling off across the
    // sheet, and grain.
    let photo = t.path().join("blank-paper-photo.png");
    image::GrayImage::from_fn(320, 240, |x, y| {
        let fall = 60.0 * (f64::from(x) / 320.0) + 25.0 * (f64::from(y) / 240.0);
        let grain = f64::from((x.wrapping_mul(7919) ^ y.wrapping_mul(104_729)) % 13) - 6.0;
        image::Luma([(235.0 - fall + grain).clamp(0.0, 255.0) as u8])
    })
    .save(&photo)
    .unwrap();
    trace_must_fail(&photo, &["nothing to trace", "no ink"]);
    let clear = t.path().join("clear.png");
    image::RgbaImage::from_pixel(16, 16, image::Rgba([0, 0, 0, 0]))
        .save(&clear)
        .unwrap();
    trace_must_fail(&clear, &["nothing to trace", "no ink"]);
    let black = t.path().join("black.png");
    image::GrayImage::from_pixel(200, 150, image::Luma([0]))
        .save(&black)
        .unwrap();
    trace_must_fail(&black, &["nothing to trace", "whole picture"]);
    let strip = t.path().join("strip-1x10000.png");
    image::GrayImage::from_pixel(1, 10_000, image::Luma([0]))
        .save(&strip)
        .unwrap();
    trace_must_fail(&strip, &["nothing to trace", "whole picture"]);
    // The same with --centerline: a blank page has no lines.
    let out = t.path().join("lines.svg");
    let o = flourish(&["trace", "--centerline", s(&photo), "-o", s(&out)]);
    assert_failure(&o, &photo, &["nothing to trace", "no lines"]);
    assert!(!out.exists());
}

/// A 1-px-wide line 10,000 px long on paper is a drawing, not bad input:
/// it traces to the one rectangle it is.
#[test]
fn one_pixel_line_ten_thousand_long_traces_to_its_rectangle() {
    let t = tempdir();
    let p = t.path().join("line.png");
    image::GrayImage::from_fn(10_000, 5, |_, y| {
        image::Luma([if y == 2 { 0 } else { 255 }])
    })
    .save(&p)
    .unwrap();
    let out = t.path().join("line.svg");
    let o = flourish(&["trace", s(&p), "-o", s(&out)]);
    assert_eq!(code(&o), Some(0), "stderr: {}", stderr(&o));
    let svg = std::fs::read(&out).unwrap();
    let tree = parse_output(&svg).expect("parses");
    let b = tree.root().abs_bounding_box();
    assert!(
        (b.width() - 10_000.0).abs() < 0.5 && (b.height() - 1.0).abs() < 0.25,
        "traced box {b:?}"
    );
}

/// A drawing in a light ink (yellow, light grey: darkness 0.2–0.4, under
/// the half that black ink's edges are read at) traces as a drawing, in
/// its ink's colour and at its drawn size, not as an empty page.
#[test]
fn light_ink_drawings_are_traced_in_their_colour() {
    use kurbo::Shape;
    let t = tempdir();
    let (size, r) = (120u32, 36.0);
    let c = size as f64 / 2.0;
    let grey = render_gray(size, size, 4, disc(c, c, r));
    let yellow = image::RgbImage::from_fn(size, size, |x, y| {
        let k = 1.0 - grey.get_pixel(x, y)[0] as f64 / 255.0;
        let mix = |ink: f64| (255.0 + k * (ink - 255.0)).round() as u8;
        image::Rgb([mix(240.0), mix(200.0), mix(40.0)])
    });
    let light_grey = image::GrayImage::from_fn(size, size, |x, y| {
        let k = 1.0 - grey.get_pixel(x, y)[0] as f64 / 255.0;
        image::Luma([(255.0 + k * (170.0 - 255.0)).round() as u8])
    });
    let yp = t.path().join("yellow.png");
    let gp = t.path().join("light-grey.png");
    yellow.save(&yp).unwrap();
    light_grey.save(&gp).unwrap();
    for (p, fill) in [(&yp, "#f0c828"), (&gp, "#aaa")] {
        let out = t.path().join("out.svg");
        let o = flourish(&["trace", s(p), "-o", s(&out)]);
        assert_eq!(code(&o), Some(0), "stderr: {}", stderr(&o));
        let text = std::fs::read_to_string(&out).unwrap();
        assert!(
            text.contains(&format!("fill=\"{fill}\"")),
            "{}: {text}",
            p.display()
        );
        let d = text
            .split(" d=\"")
            .nth(1)
            .and_then(|r| r.split('"').next())
            .expect("a path");
        let area = kurbo::BezPath::from_svg(d).expect("path data").area().abs();
        let drawn = std::f64::consts::PI * r * r;
        assert!(
            (area / drawn - 1.0).abs() < 0.01,
            "{}: area {area:.1} vs {drawn:.1}",
            p.display()
        );
    }
}

/// Text is not traced (no fonts are read): the shapes still are, and the
/// designer is told why the lettering is missing, unless `--quiet`; text
/// kept in `<defs>` is not drawn and draws no warning.
#[test]
fn svg_text_is_reported_as_left_out() {
    let t = tempdir();
    let drawn = t.path().join("label.svg");
    std::fs::write(
        &drawn,
        r#"<svg xmlns="http://www.w3.org/2000/svg" width="100" height="50"><rect x="5" y="5" width="20" height="20"/><text x="40" y="30">Label</text></svg>"#,
    )
    .unwrap();
    let kept = t.path().join("defs.svg");
    std::fs::write(
        &kept,
        r#"<svg xmlns="http://www.w3.org/2000/svg" width="100" height="50"><defs><text id="t">Label</text></defs><rect x="5" y="5" width="20" height="20"/></svg>"#,
    )
    .unwrap();
    let out = t.path().join("out.svg");
    let o = flourish(&["trace", s(&drawn), "-o", s(&out)]);
    assert_eq!(code(&o), Some(0), "stderr: {}", stderr(&o));
    let err = stderr(&o);
    assert!(
        err.contains("label.svg") && err.contains("text") && err.contains("paths"),
        "{err}"
    );
    assert_eq!(err.lines().count(), 1, "{err}");
    assert!(std::fs::read_to_string(&out).unwrap().contains("<path"));
    let o = flourish(&["trace", "-q", s(&drawn), "-o", s(&out)]);
    assert_eq!(code(&o), Some(0));
    assert!(stderr(&o).is_empty(), "{}", stderr(&o));
    let o = flourish(&["trace", s(&kept), "-o", s(&out)]);
    assert_eq!(code(&o), Some(0));
    assert!(!stderr(&o).contains("text"), "{}", stderr(&o));
}

/// Inkscape's compressed SVG (SVGZ) traces exactly as the SVG it holds.
#[test]
fn svgz_traces_as_its_svg() {
    use std::io::Write as _;
    let t = tempdir();
    let svg = r##"<svg xmlns="http://www.w3.org/2000/svg" width="60" height="40"><circle cx="20" cy="20" r="12" fill="#246"/><path d="M35 30 L55 10" stroke="#000" stroke-width="3"/></svg>"##;
    let plain = t.path().join("art.svg");
    std::fs::write(&plain, svg).unwrap();
    let zipped = t.path().join("art.svgz");
    let mut enc = flate2::write::GzEncoder::new(Vec::new(), flate2::Compression::default());
    enc.write_all(svg.as_bytes()).unwrap();
    std::fs::write(&zipped, enc.finish().unwrap()).unwrap();
    let (a, b) = (t.path().join("a.svg"), t.path().join("b.svg"));
    for (inp, out) in [(&plain, &a), (&zipped, &b)] {
        let o = flourish(&["trace", s(inp), "-o", s(out)]);
        assert_eq!(code(&o), Some(0), "stderr: {}", stderr(&o));
    }
    let (a, b) = (std::fs::read(&a).unwrap(), std::fs::read(&b).unwrap());
    assert!(String::from_utf8_lossy(&a).contains("<path"));
    assert_eq!(a, b);
}

/// A photo stored sideways with an Exif orientation (as phones store
/// them) is traced as it displays: a 40×20 PNG inked on its left half and
/// marked "turn 90° clockwise" traces to a 20×40 document inked on top.
#[test]
fn exif_orientation_is_applied() {
    use image::ImageEncoder as _;
    let t = tempdir();
    let p = t.path().join("sideways.png");
    let img = image::GrayImage::from_fn(40, 20, |x, _| image::Luma([if x < 20 { 0 } else { 255 }]));
    // Big-endian TIFF header, one IFD entry: Orientation (0x0112), SHORT,
    // count 1, value 6 (rotate 90° clockwise to display).
    let exif = vec![
        b'M', b'M', 0, 42, 0, 0, 0, 8, 0, 1, 0x01, 0x12, 0, 3, 0, 0, 0, 1, 0, 6, 0, 0, 0, 0, 0, 0,
    ];
    let mut png = Vec::new();
    let mut enc = image::codecs::png::PngEncoder::new(&mut png);
    enc.set_exif_metadata(exif).expect("PNG takes Exif");
    enc.write_image(img.as_raw(), 40, 20, image::ExtendedColorType::L8)
        .expect("encodes");
    std::fs::write(&p, &png).unwrap();
    let out = t.path().join("upright.svg");
    let o = flourish(&["trace", s(&p), "-o", s(&out)]);
    assert_eq!(code(&o), Some(0), "stderr: {}", stderr(&o));
    let tree = parse_output(&std::fs::read(&out).unwrap()).expect("parses");
    assert_eq!((tree.size().width(), tree.size().height()), (20.0, 40.0));
    let bb = tree.root().abs_bounding_box();
    assert!(
        bb.top() < 0.5 && bb.bottom() > 19.5 && bb.bottom() < 20.5,
        "{bb:?}"
    );
    assert!(bb.left() < 0.5 && bb.right() > 19.5, "{bb:?}");
}

/// A one-pixel picture is all paper or all ink: refused as having nothing
/// to trace, never a panic.
#[test]
fn one_pixel_images_have_nothing_to_trace() {
    let t = tempdir();
    for (name, v) in [("black1.png", 0u8), ("white1.png", 255), ("grey1.png", 128)] {
        let p = t.path().join(name);
        image::GrayImage::from_pixel(1, 1, image::Luma([v]))
            .save(&p)
            .unwrap();
        trace_must_fail(&p, &["nothing to trace"]);
    }
}

#[test]
fn empty_svg_gives_valid_empty_svg() {
    let t = tempdir();
    let p = t.path().join("blank.svg");
    std::fs::write(
        &p,
        r#"<svg xmlns="http://www.w3.org/2000/svg" width="20" height="10"/>"#,
    )
    .unwrap();
    let out = t.path().join("blank-out.svg");
    let o = flourish(&["trace", s(&p), "-o", s(&out)]);
    assert_eq!(code(&o), Some(0), "stderr: {}", stderr(&o));
    let svg = std::fs::read(&out).unwrap();
    assert!(!String::from_utf8_lossy(&svg).contains("<path"));
    let tree = parse_output(&svg).unwrap();
    assert_eq!((tree.size().width(), tree.size().height()), (20.0, 10.0));
}

// ---------------------------------------------------------------------------
// trace: output problems

#[test]
fn output_in_missing_folder_fails_cleanly() {
    let t = tempdir();
    let p = t.path().join("disc.png");
    write_disc_png(&p, 32);
    let out = t.path().join("no-such-folder").join("out.svg");
    let o = flourish(&["trace", s(&p), "-o", s(&out)]);
    assert_failure(&o, &out, &[]);
    assert!(!out.exists());
    assert!(!out.parent().unwrap().exists());
}

#[test]
fn output_in_read_only_folder_fails_cleanly() {
    use std::os::unix::fs::PermissionsExt;
    let t = tempdir();
    let p = t.path().join("disc.png");
    write_disc_png(&p, 32);
    let ro = t.path().join("ro");
    std::fs::create_dir(&ro).unwrap();
    std::fs::write(ro.join("out.svg"), SENTINEL).unwrap();
    std::fs::set_permissions(&ro, std::fs::Permissions::from_mode(0o555)).unwrap();
    // As root (or on odd file systems) permissions do not bite: skip.
    if std::fs::write(ro.join("probe"), b"x").is_ok() {
        let _ = std::fs::remove_file(ro.join("probe"));
        std::fs::set_permissions(&ro, std::fs::Permissions::from_mode(0o755)).unwrap();
        eprintln!("skipped output_in_read_only_folder_fails_cleanly: read-only folder is writable (root?)");
        return;
    }
    let out = ro.join("out.svg");
    let o = flourish(&["trace", s(&p), "-o", s(&out)]);
    let new_out = ro.join("new.svg");
    let o2 = flourish(&["trace", s(&p), "-o", s(&new_out)]);
    std::fs::set_permissions(&ro, std::fs::Permissions::from_mode(0o755)).unwrap();
    assert_failure(&o, &out, &[]);
    assert!(
        std::fs::read(&out).unwrap() == SENTINEL,
        "existing output changed"
    );
    assert_failure(&o2, &new_out, &[]);
    assert!(!new_out.exists());
}

#[test]
fn output_equal_to_input_is_refused() {
    let t = tempdir();
    let p = t.path().join("disc.png");
    write_disc_png(&p, 32);
    let before = std::fs::read(&p).unwrap();
    let o = flourish(&["trace", s(&p), "-o", s(&p)]);
    assert_ne!(code(&o), Some(0), "overwriting the input was accepted");
    assert!(
        matches!(code(&o), Some(1) | Some(2)),
        "stderr: {}",
        stderr(&o)
    );
    assert_eq!(stderr(&o).lines().count(), 1, "stderr: {}", stderr(&o));
    assert!(stderr(&o).contains("disc.png"), "stderr: {}", stderr(&o));
    assert!(std::fs::read(&p).unwrap() == before, "input was changed");

    // Same file under another spelling.
    let other = format!("{}/./disc.png", s(t.path()));
    let o = flourish(&["trace", s(&p), "-o", &other]);
    assert!(
        matches!(code(&o), Some(1) | Some(2)),
        "stderr: {}",
        stderr(&o)
    );
    assert!(std::fs::read(&p).unwrap() == before, "input was changed");

    // An SVG input written over itself.
    let svg = t.path().join("square.svg");
    std::fs::write(&svg, SQUARE_SVG).unwrap();
    let o = flourish(&["trace", s(&svg), "-o", s(&svg)]);
    assert!(
        matches!(code(&o), Some(1) | Some(2)),
        "stderr: {}",
        stderr(&o)
    );
    assert_eq!(
        std::fs::read_to_string(&svg).unwrap(),
        SQUARE_SVG,
        "input was changed"
    );
}

#[test]
fn preview_equal_to_input_is_refused() {
    let t = tempdir();
    let p = t.path().join("disc.png");
    write_disc_png(&p, 32);
    let before = std::fs::read(&p).unwrap();
    let out = t.path().join("disc.svg");
    let o = flourish(&["trace", s(&p), "-o", s(&out), "--preview", s(&p)]);
    assert!(
        matches!(code(&o), Some(1) | Some(2)),
        "stderr: {}",
        stderr(&o)
    );
    assert!(std::fs::read(&p).unwrap() == before, "input was changed");
    assert!(
        !out.exists(),
        "output written although the preview was refused"
    );
}

#[test]
fn out_dir_that_would_overwrite_an_input_is_refused() {
    let t = tempdir();
    let svg = t.path().join("square.svg");
    std::fs::write(&svg, SQUARE_SVG).unwrap();
    let o = flourish(&["trace", s(&svg), "--out-dir", s(t.path())]);
    assert!(
        matches!(code(&o), Some(1) | Some(2)),
        "stderr: {}",
        stderr(&o)
    );
    assert_eq!(
        std::fs::read_to_string(&svg).unwrap(),
        SQUARE_SVG,
        "input was changed"
    );
}

#[test]
fn preview_is_written() {
    let t = tempdir();
    let p = t.path().join("disc.png");
    write_disc_png(&p, 32);
    let out = t.path().join("disc.svg");
    let prev = t.path().join("disc-preview.png");
    let o = flourish(&["trace", s(&p), "-o", s(&out), "--preview", s(&prev)]);
    assert_eq!(code(&o), Some(0), "stderr: {}", stderr(&o));
    let img = image::open(&prev).expect("preview is a PNG");
    assert!(img.width() > 0 && img.height() > 0);
}

// ---------------------------------------------------------------------------
// trace: usage errors

#[test]
fn dash_o_with_two_inputs_is_a_usage_error() {
    let t = tempdir();
    let (a, b) = (t.path().join("a.png"), t.path().join("b.png"));
    write_disc_png(&a, 16);
    write_disc_png(&b, 16);
    let out = t.path().join("out.svg");
    let o = flourish(&["trace", s(&a), s(&b), "-o", s(&out)]);
    assert_usage(&o, "out-dir");
    assert!(!out.exists());
}

#[test]
fn neither_output_nor_out_dir_is_a_usage_error() {
    let t = tempdir();
    let a = t.path().join("a.png");
    write_disc_png(&a, 16);
    let o = flourish(&["trace", s(&a)]);
    assert_usage(&o, "-o");
}

#[test]
fn both_output_and_out_dir_is_a_usage_error() {
    let t = tempdir();
    let a = t.path().join("a.png");
    write_disc_png(&a, 16);
    let out = t.path().join("out.svg");
    let o = flourish(&["trace", s(&a), "-o", s(&out), "--out-dir", s(t.path())]);
    assert_usage(&o, "out-dir");
    assert!(!out.exists());
}

#[test]
fn no_inputs_is_a_usage_error() {
    let o = flourish(&["trace", "-o", "x.svg"]);
    assert_usage(&o, "IN");
}

#[test]
fn bad_tolerance_is_a_usage_error() {
    let t = tempdir();
    let a = t.path().join("a.png");
    write_disc_png(&a, 16);
    let out = t.path().join("out.svg");
    for bad in [
        "--tolerance=0",
        "--tolerance=-1",
        "--tolerance=NaN",
        "--tolerance=inf",
        "--tolerance=abc",
        "--tolerance=1e9",
    ] {
        let o = flourish(&["trace", s(&a), "-o", s(&out), bad]);
        assert_usage(&o, "tolerance");
        assert!(!out.exists(), "{bad}: output written");
    }
    // Space-separated forms too.
    for bad in ["0", "-1", "NaN"] {
        let o = flourish(&["trace", s(&a), "-o", s(&out), "--tolerance", bad]);
        assert_eq!(
            code(&o),
            Some(2),
            "--tolerance {bad}: stderr: {}",
            stderr(&o)
        );
        assert!(!out.exists(), "--tolerance {bad}: output written");
    }
}

#[test]
fn bad_min_area_resolution_threads_are_usage_errors() {
    let t = tempdir();
    let a = t.path().join("a.png");
    write_disc_png(&a, 16);
    let out = t.path().join("out.svg");
    for (args, mention) in [
        (vec!["--min-area=-1"], "min-area"),
        (vec!["--min-area=NaN"], "min-area"),
        (vec!["--resolution", "0"], "resolution"),
        (vec!["--resolution=-5"], "resolution"),
        (vec!["--threads", "0"], "threads"),
        // Each would be a thread: a million of them never got started.
        (vec!["--threads", "1000000"], "threads"),
    ] {
        let mut full = vec!["trace", s(&a), "-o", s(&out)];
        full.extend(args.iter().copied());
        let o = flourish(&full);
        assert_usage(&o, mention);
        assert!(!out.exists(), "{args:?}: output written");
    }
}

#[test]
fn unknown_flag_is_a_usage_error() {
    let t = tempdir();
    let a = t.path().join("a.png");
    write_disc_png(&a, 16);
    let out = t.path().join("out.svg");
    let o = flourish(&["trace", s(&a), "-o", s(&out), "--frobnicate"]);
    assert_usage(&o, "--frobnicate");
    assert!(!out.exists());
    let o = flourish(&["frobnicate"]);
    assert_usage(&o, "frobnicate");
    let o = flourish(&[]);
    assert_eq!(code(&o), Some(2), "no subcommand: stderr {}", stderr(&o));
}

/// Every usage error is one line on stderr, the argument parser's too.
#[test]
fn usage_errors_are_one_line() {
    let t = tempdir();
    let a = t.path().join("a.png");
    write_disc_png(&a, 16);
    for args in [
        vec!["trace", s(&a), "--frobnicate"],
        vec!["trace"],
        vec!["frobnicate"],
        vec!["trace", s(&a), "--tolerance", "lots"],
        vec![],
    ] {
        let o = flourish(&args);
        assert_eq!(code(&o), Some(2), "{args:?}: {}", stderr(&o));
        assert_eq!(stderr(&o).lines().count(), 1, "{args:?}: {}", stderr(&o));
        assert!(stderr(&o).starts_with("flourish: "), "{}", stderr(&o));
    }
}

/// A result for standard output with standard output closed, or read by
/// no one, is a failure, exit 1, not a silent success; `> /dev/null` is a
/// success.
#[cfg(target_os = "linux")]
#[test]
fn a_closed_standard_output_fails_the_run() {
    let t = tempdir();
    let a = t.path().join("a.png");
    write_disc_png(&a, 16);
    let run = |redirect: &str| {
        Command::new("bash")
            .args([
                "-c",
                &format!("set -o pipefail; \"$0\" trace \"$1\" -o - {redirect}"),
                BIN,
                s(&a),
            ])
            .stdin(Stdio::null())
            .output()
            .expect("run bash")
    };
    for redirect in [">&-", "| (exec 0<&-; sleep 1)"] {
        let o = run(redirect);
        assert_eq!(code(&o), Some(1), "{redirect}: stderr: {}", stderr(&o));
        assert_eq!(stderr(&o).lines().count(), 1, "{}", stderr(&o));
        assert!(stderr(&o).contains("<stdout>"), "{}", stderr(&o));
    }
    let o = run("> /dev/null");
    assert_eq!(code(&o), Some(0), "stderr: {}", stderr(&o));
}

/// An SVG whose entities would expand quadratically (a 100 kB entity
/// referenced 20 000 times: 2 GB from 160 kB) is refused at once, in one
/// line, without the memory it would take.
#[test]
fn entities_that_would_fill_memory_are_refused() {
    let t = tempdir();
    let svg = t.path().join("lol.svg");
    let text = format!(
        r#"<?xml version="1.0"?><!DOCTYPE svg [<!ENTITY a "{}">]><svg xmlns="http://www.w3.org/2000/svg" width="10" height="10"><text>{}</text></svg>"#,
        "x".repeat(100_000),
        "&a;".repeat(20_000)
    );
    std::fs::write(&svg, text).expect("write");
    let out = t.path().join("out.svg");
    for cmd in [
        vec!["trace", s(&svg), "-o", s(&out)],
        vec!["pattern", s(&svg), "-o", s(&out)],
    ] {
        let o = flourish_capped(t.path(), &cmd, 1024);
        assert_failure(&o, &svg, &["entities expand"]);
        assert!(!out.exists());
    }
}

#[test]
fn help_and_version_succeed() {
    let o = flourish(&["--help"]);
    assert_eq!(code(&o), Some(0));
    assert!(stdout(&o).contains("trace"));
    let o = flourish(&["--version"]);
    assert_eq!(code(&o), Some(0));
    assert!(stdout(&o).contains("flourish"));
}

// ---------------------------------------------------------------------------
// trace: batches

#[test]
fn out_dir_batch_writes_one_svg_per_input() {
    let t = tempdir();
    let outdir = t.path().join("out");
    std::fs::create_dir(&outdir).unwrap();
    let inputs: Vec<PathBuf> = (0..3)
        .map(|i| t.path().join(format!("in{i}.png")))
        .collect();
    for (i, p) in inputs.iter().enumerate() {
        write_disc_png(p, 20 + 8 * i as u32);
    }
    let mut args = vec!["trace"];
    args.extend(inputs.iter().map(|p| s(p)));
    args.extend(["--out-dir", s(&outdir)]);
    let o = flourish(&args);
    assert_eq!(code(&o), Some(0), "stderr: {}", stderr(&o));
    assert!(
        stderr(&o).trim().is_empty(),
        "noise on stderr: {:?}",
        stderr(&o)
    );
    for i in 0..3 {
        let svg = std::fs::read(outdir.join(format!("in{i}.svg"))).expect("output written");
        let text = String::from_utf8_lossy(&svg);
        assert!(text.contains("<path"), "in{i}.svg has no path");
        let tree = parse_output(&svg).unwrap();
        assert_eq!(tree.size().width(), (20 + 8 * i) as f32);
    }
    assert_eq!(
        std::fs::read_dir(&outdir).unwrap().count(),
        3,
        "unexpected extra files"
    );
}

#[test]
fn out_dir_batch_with_one_bad_input_writes_the_others() {
    let t = tempdir();
    let outdir = t.path().join("out");
    std::fs::create_dir(&outdir).unwrap();
    let good1 = t.path().join("good1.png");
    let bad = t.path().join("bad.png");
    let good2 = t.path().join("good2.png");
    write_disc_png(&good1, 24);
    std::fs::write(&bad, b"definitely not a PNG").unwrap();
    write_disc_png(&good2, 30);
    // An existing output for the bad input must survive.
    std::fs::write(outdir.join("bad.svg"), SENTINEL).unwrap();
    let o = flourish(&[
        "trace",
        s(&good1),
        s(&bad),
        s(&good2),
        "--out-dir",
        s(&outdir),
    ]);
    assert_failure(&o, &bad, &[]);
    assert!(
        !stderr(&o).contains("good1") && !stderr(&o).contains("good2"),
        "stderr: {}",
        stderr(&o)
    );
    for name in ["good1.svg", "good2.svg"] {
        let svg = std::fs::read(outdir.join(name)).unwrap_or_else(|_| panic!("{name} not written"));
        parse_output(&svg).unwrap();
    }
    assert!(
        std::fs::read(outdir.join("bad.svg")).unwrap() == SENTINEL,
        "existing output changed"
    );
    assert_no_temp_files(&outdir);
}

#[test]
fn out_dir_batch_with_missing_input_writes_the_others() {
    let t = tempdir();
    let outdir = t.path().join("out");
    std::fs::create_dir(&outdir).unwrap();
    let good = t.path().join("good.png");
    let missing = t.path().join("missing.png");
    write_disc_png(&good, 24);
    let o = flourish(&["trace", s(&missing), s(&good), "--out-dir", s(&outdir)]);
    assert_failure(&o, &missing, &[]);
    assert!(outdir.join("good.svg").exists());
    assert!(!outdir.join("missing.svg").exists());
}

/// A missing `--out-dir` (and `--preview` folder) is made, parents
/// included, like `mkdir -p`; a file in its place is an error that
/// leaves the file alone.
#[test]
fn out_dir_is_made_when_missing_and_a_file_there_is_an_error() {
    let t = tempdir();
    let a = t.path().join("a.png");
    write_disc_png(&a, 16);
    let (out, png) = (t.path().join("new/svg"), t.path().join("new/png"));
    let o = flourish(&["trace", s(&a), "--out-dir", s(&out), "--preview", s(&png)]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    assert!(out.join("a.svg").is_file());
    assert!(png.join("a.png").is_file());
    let file = t.path().join("taken");
    std::fs::write(&file, "keep").unwrap();
    let o = flourish(&["trace", s(&a), "--out-dir", s(&file)]);
    assert_failure(&o, &file, &[]);
    assert_eq!(std::fs::read_to_string(&file).unwrap(), "keep");
}

#[test]
fn out_dir_with_clashing_names_is_a_usage_error() {
    let t = tempdir();
    std::fs::create_dir(t.path().join("x")).unwrap();
    std::fs::create_dir(t.path().join("out")).unwrap();
    let a = t.path().join("a.png");
    let b = t.path().join("x").join("a.png");
    write_disc_png(&a, 16);
    write_disc_png(&b, 16);
    let o = flourish(&["trace", s(&a), s(&b), "--out-dir", s(&t.path().join("out"))]);
    assert_usage(&o, "a.svg");
    assert_eq!(std::fs::read_dir(t.path().join("out")).unwrap().count(), 0);
}

// ---------------------------------------------------------------------------
// trace: standard output and determinism

#[test]
fn dash_o_dash_writes_svg_to_stdout() {
    let t = tempdir();
    let p = t.path().join("disc.png");
    write_disc_png(&p, 32);
    let o = flourish(&["trace", s(&p), "-o", "-"]);
    assert_eq!(code(&o), Some(0), "stderr: {}", stderr(&o));
    let text = stdout(&o);
    assert!(
        text.trim_start().starts_with("<svg") || text.trim_start().starts_with("<?xml"),
        "stdout: {text}"
    );
    assert!(text.contains("<path"), "stdout: {text}");
    let tree = parse_output(&o.stdout).expect("stdout parses");
    assert_eq!(tree.size().width(), 32.0);
    // Nothing named "-" appears in the working folder.
    assert!(!Path::new("-").exists());

    // Same bytes as writing to a file.
    let out = t.path().join("disc.svg");
    let o2 = flourish(&["trace", s(&p), "-o", s(&out)]);
    assert_eq!(code(&o2), Some(0));
    assert!(
        std::fs::read(&out).unwrap() == o.stdout,
        "-o - and -o FILE differ"
    );
}

#[test]
fn output_does_not_depend_on_thread_count() {
    let t = tempdir();
    let p = t.path().join("scene.png");
    write_complex_png(&p);
    let mut outputs = Vec::new();
    for n in ["1", "2"] {
        let out = t.path().join(format!("scene-{n}.svg"));
        let o = flourish(&["trace", s(&p), "-o", s(&out), "--threads", n]);
        assert_eq!(code(&o), Some(0), "--threads {n}: stderr: {}", stderr(&o));
        outputs.push(std::fs::read(&out).unwrap());
    }
    // Global flag placed before the subcommand.
    let out = t.path().join("scene-g.svg");
    let o = flourish(&["--threads", "2", "trace", s(&p), "-o", s(&out)]);
    assert_eq!(code(&o), Some(0), "stderr: {}", stderr(&o));
    outputs.push(std::fs::read(&out).unwrap());
    let text = String::from_utf8_lossy(&outputs[0]);
    assert!(text.matches("<path").count() >= 1, "no paths: {text}");
    // Four islands (one disc merges with the ring) and the ring's hole.
    let subpaths = text.matches(['m', 'M']).count();
    assert!(subpaths >= 5, "too few subpaths ({subpaths}): {text}");
    assert!(
        outputs[0] == outputs[1],
        "--threads 1 and --threads 2 differ"
    );
    assert!(
        outputs[0] == outputs[2],
        "--threads placement changes the output"
    );
    // And runs are repeatable.
    let out = t.path().join("scene-again.svg");
    let o = flourish(&["trace", s(&p), "-o", s(&out), "--threads", "2"]);
    assert_eq!(code(&o), Some(0));
    assert!(
        std::fs::read(&out).unwrap() == outputs[1],
        "two runs with --threads 2 differ"
    );
}

// ---------------------------------------------------------------------------
// trace: SVG input must not reach outside itself

/// Makes `path` a FIFO when `mkfifo` is available (opening it for reading
/// would block, so a read shows up as a timeout), else a plain file.
fn make_trap(path: &Path) -> bool {
    let ok = Command::new("mkfifo")
        .arg(path)
        .status()
        .map(|s| s.success())
        .unwrap_or(false);
    if !ok {
        std::fs::write(path, SQUARE_SVG).unwrap();
    }
    ok
}

#[test]
fn svg_external_references_are_not_followed() {
    let t = tempdir();
    let dir = t.path();
    make_trap(&dir.join("pic.png"));
    make_trap(&dir.join("other.svg"));
    make_trap(&dir.join("style.css"));
    let cases = [
        (
            "abs-image.svg",
            r#"<svg xmlns="http://www.w3.org/2000/svg" xmlns:xlink="http://www.w3.org/1999/xlink" width="50" height="50">
<image href="/etc/passwd" width="50" height="50"/>
<image xlink:href="/etc/passwd" width="50" height="50"/>
<rect x="10" y="10" width="20" height="20"/>
</svg>"#,
        ),
        (
            "rel-image.svg",
            r#"<svg xmlns="http://www.w3.org/2000/svg" xmlns:xlink="http://www.w3.org/1999/xlink" width="50" height="50">
<image href="pic.png" width="50" height="50"/>
<image xlink:href="pic.png" width="50" height="50"/>
<image href="file:pic.png" width="50" height="50"/>
<rect x="10" y="10" width="20" height="20"/>
</svg>"#,
        ),
        (
            "use-ext.svg",
            r#"<svg xmlns="http://www.w3.org/2000/svg" xmlns:xlink="http://www.w3.org/1999/xlink" width="50" height="50">
<use href="other.svg#x"/>
<use xlink:href="other.svg#x"/>
<rect x="10" y="10" width="20" height="20"/>
</svg>"#,
        ),
        (
            "css-ext.svg",
            r#"<?xml-stylesheet href="style.css" type="text/css"?>
<svg xmlns="http://www.w3.org/2000/svg" width="50" height="50">
<style>@import url("style.css");</style>
<rect x="10" y="10" width="20" height="20" style="fill: url(other.svg#g)"/>
</svg>"#,
        ),
        (
            "entity.svg",
            r#"<?xml version="1.0"?>
<!DOCTYPE svg [<!ENTITY ext SYSTEM "other.svg">]>
<svg xmlns="http://www.w3.org/2000/svg" width="50" height="50">
<text>&ext;</text>
<rect x="10" y="10" width="20" height="20"/>
</svg>"#,
        ),
    ];
    for (name, body) in cases {
        let p = dir.join(name);
        std::fs::write(&p, body).unwrap();
        let out = dir.join(format!("{name}.out.svg"));
        let o = flourish_guarded(
            dir,
            &["trace", s(&p), "-o", s(&out)],
            Duration::from_secs(30),
        );
        let c = code(&o);
        assert!(
            matches!(c, Some(0) | Some(1)),
            "{name}: exit {c:?}, stderr: {}",
            stderr(&o)
        );
        if c == Some(1) {
            assert_failure(&o, &p, &[]);
            assert!(!out.exists());
        } else {
            let svg = std::fs::read(&out).unwrap();
            let text = String::from_utf8_lossy(&svg);
            assert!(
                !text.contains("root:"),
                "{name}: /etc/passwd leaked into the output"
            );
            assert!(
                !text.contains("<image"),
                "{name}: output references an image"
            );
            assert!(
                !text.contains("href"),
                "{name}: output references another file"
            );
            parse_output(&svg).unwrap();
        }
    }
}

// ---------------------------------------------------------------------------
// diff

fn write(dir: &Path, name: &str, text: &str) -> PathBuf {
    let p = dir.join(name);
    std::fs::write(&p, text).unwrap();
    p
}

/// `diff` given a picture says it compares SVG documents (exit 2); with
/// `--out -` only the three-panel PNG goes to standard output.
#[test]
fn diff_refuses_pictures_and_keeps_stdout_for_the_image() {
    let t = tempdir();
    let a = write(
        t.path(),
        "a.svg",
        r#"<svg xmlns="http://www.w3.org/2000/svg" width="100" height="50"><rect width="40" height="40"/></svg>"#,
    );
    let png = t.path().join("p.png");
    write_disc_png(&png, 16);
    let o = flourish(&["diff", s(&png), s(&a)]);
    assert_trouble(&o, &png, &["not an SVG document"]);
    let o = flourish(&["diff", s(&a), s(&a), "--out", "-"]);
    assert_eq!(code(&o), Some(0), "stderr: {}", stderr(&o));
    assert!(
        o.stdout.starts_with(b"\x89PNG"),
        "stdout is not the PNG alone"
    );
    assert!(stderr(&o).contains("changed: 0"), "{}", stderr(&o));
}

#[test]
fn diff_identical_files_exit_zero() {
    let t = tempdir();
    let a = write(t.path(), "a.svg", SQUARE_SVG);
    let b = write(t.path(), "b.svg", SQUARE_SVG);
    let o = flourish(&["diff", s(&a), s(&b)]);
    assert_eq!(code(&o), Some(0), "stderr: {}", stderr(&o));
    assert!(
        stdout(&o).starts_with("changed: 0"),
        "stdout: {}",
        stdout(&o)
    );
    assert!(stderr(&o).is_empty(), "stderr: {}", stderr(&o));
    // A file against itself.
    let o = flourish(&["diff", s(&a), s(&a)]);
    assert_eq!(code(&o), Some(0));
    // --quiet (-q, before or after the subcommand) prints nothing.
    for args in [
        ["--quiet", "diff", s(&a), s(&b)],
        ["diff", "-q", s(&a), s(&b)],
    ] {
        let o = flourish(&args);
        assert_eq!(code(&o), Some(0));
        assert!(o.stdout.is_empty(), "stdout: {}", stdout(&o));
    }
    // Quiet and verbose at once is a usage error.
    let o = flourish(&["-q", "-v", "diff", s(&a), s(&b)]);
    assert_eq!(code(&o), Some(2), "stderr: {}", stderr(&o));
}

#[test]
fn diff_different_files_exit_one() {
    let t = tempdir();
    let a = write(t.path(), "a.svg", SQUARE_SVG);
    let b = write(t.path(), "b.svg", SQUARE_SVG_MOVED);
    let o = flourish(&["diff", s(&a), s(&b)]);
    assert_eq!(code(&o), Some(1), "stderr: {}", stderr(&o));
    let out = stdout(&o);
    assert!(out.starts_with("changed: "), "stdout: {out}");
    assert!(!out.starts_with("changed: 0.000000"), "stdout: {out}");
    // Within a generous tolerance it passes.
    let o = flourish(&["diff", s(&a), s(&b), "--tolerance", "0.9"]);
    assert_eq!(
        code(&o),
        Some(0),
        "stdout: {} stderr: {}",
        stdout(&o),
        stderr(&o)
    );
}

#[test]
fn diff_out_writes_three_panels() {
    let t = tempdir();
    let a = write(t.path(), "a.svg", SQUARE_SVG);
    let b = write(t.path(), "b.svg", SQUARE_SVG_MOVED);
    let d = t.path().join("d.png");
    let o = flourish(&["diff", s(&a), s(&b), "--out", s(&d)]);
    assert_eq!(code(&o), Some(1), "stderr: {}", stderr(&o));
    let img = image::open(&d).expect("diff image is a PNG");
    // 100×50 rendered with its longest side at 1024 px.
    let side = 1024;
    assert_eq!(img.height(), side / 2);
    assert_eq!(img.width(), 3 * side);
    assert_eq!(img.width(), 3 * (img.height() * 2));
    // Identical files also get their panels.
    let d2 = t.path().join("d2.png");
    let o = flourish(&["diff", s(&a), s(&a), "--out", s(&d2)]);
    assert_eq!(code(&o), Some(0));
    let img = image::open(&d2).unwrap();
    assert_eq!(img.width(), 3 * side);
}

#[test]
fn diff_different_sizes_fail_with_clear_message() {
    let t = tempdir();
    let a = write(t.path(), "a.svg", SQUARE_SVG);
    let b = write(t.path(), "tall.svg", SQUARE_SVG_TALL);
    let d = t.path().join("d.png");
    let o = flourish(&["diff", s(&a), s(&b), "--out", s(&d)]);
    assert_trouble(&o, &b, &["size"]);
    assert!(!d.exists());
}

#[test]
fn diff_bad_tolerance_is_a_usage_error() {
    let t = tempdir();
    let a = write(t.path(), "a.svg", SQUARE_SVG);
    for bad in ["2", "NaN", "inf"] {
        let o = flourish(&["diff", s(&a), s(&a), "--tolerance", bad]);
        assert_usage(&o, "tolerance");
    }
    let o = flourish(&["diff", s(&a), s(&a), "--tolerance=-0.5"]);
    assert_usage(&o, "tolerance");
}

#[test]
fn diff_bad_inputs_fail_cleanly() {
    let t = tempdir();
    let a = write(t.path(), "a.svg", SQUARE_SVG);
    let broken = write(t.path(), "broken.svg", "<svg><g></svg>");
    let missing = t.path().join("missing.svg");
    let d = t.path().join("d.png");
    std::fs::write(&d, SENTINEL).unwrap();
    for (x, y, bad) in [
        (&a, &broken, &broken),
        (&broken, &a, &broken),
        (&a, &missing, &missing),
        (&missing, &a, &missing),
    ] {
        let o = flourish(&["diff", s(x), s(y), "--out", s(&d)]);
        assert_trouble(&o, bad, &[]);
        assert_eq!(
            std::fs::read(&d).unwrap(),
            SENTINEL,
            "existing diff image changed"
        );
    }
    // Missing arguments.
    let o = flourish(&["diff", s(&a)]);
    assert_eq!(code(&o), Some(2));
}

#[test]
fn diff_out_in_missing_folder_fails_cleanly() {
    let t = tempdir();
    let a = write(t.path(), "a.svg", SQUARE_SVG);
    let d = t.path().join("nope").join("d.png");
    let o = flourish(&["diff", s(&a), s(&a), "--out", s(&d)]);
    assert_trouble(&o, &d, &[]);
    assert!(!d.exists());
}

#[test]
fn diff_out_equal_to_an_input_is_refused() {
    // `diff a.svg b.svg --out b.svg` wrote the panels PNG over b.svg.
    let t = tempdir();
    let a = write(t.path(), "a.svg", SQUARE_SVG);
    let b = write(t.path(), "b.svg", SQUARE_SVG_MOVED);
    for (out, text) in [(&a, SQUARE_SVG), (&b, SQUARE_SVG_MOVED)] {
        let o = flourish(&["diff", s(&a), s(&b), "--out", s(out)]);
        assert_trouble(&o, out, &["overwrite"]);
        assert_eq!(std::fs::read_to_string(out).unwrap(), text, "input changed");
        assert!(o.stdout.is_empty(), "stdout: {}", stdout(&o));
    }
    // Through another spelling of the same path.
    let other = t.path().join(".").join("b.svg");
    let o = flourish(&["diff", s(&a), s(&b), "--out", s(&other)]);
    assert_trouble(&o, &b, &["overwrite"]);
    assert_eq!(std::fs::read_to_string(&b).unwrap(), SQUARE_SVG_MOVED);
    assert_no_temp_files(t.path());
}

// ---------------------------------------------------------------------------
// Previews and file modes

#[test]
fn batch_preview_folder_never_overwrites_an_input() {
    // `--out-dir out --preview .` with `./a.png` as input would write the
    // preview of a.png to ./a.png.
    let t = tempdir();
    let a = t.path().join("a.png");
    write_disc_png(&a, 20);
    let before = std::fs::read(&a).unwrap();
    let outdir = t.path().join("out");
    std::fs::create_dir(&outdir).unwrap();
    let o = flourish(&[
        "trace",
        s(&a),
        "--out-dir",
        s(&outdir),
        "--preview",
        s(t.path()),
    ]);
    assert!(
        std::fs::read(&a).unwrap() == before,
        "the preview overwrote the input (exit {:?})",
        code(&o)
    );
    assert!(
        matches!(code(&o), Some(1) | Some(2)),
        "stderr: {}",
        stderr(&o)
    );
}

#[test]
fn preview_equal_to_output_is_refused() {
    let t = tempdir();
    let a = t.path().join("a.png");
    write_disc_png(&a, 20);
    let out = t.path().join("a.svg");
    let o = flourish(&["trace", s(&a), "-o", s(&out), "--preview", s(&out)]);
    if code(&o) == Some(0) {
        let bytes = std::fs::read(&out).unwrap();
        panic!(
            "-o X --preview X accepted; X now starts with {:?}",
            String::from_utf8_lossy(&bytes[..8.min(bytes.len())])
        );
    }
    assert!(
        matches!(code(&o), Some(1) | Some(2)),
        "stderr: {}",
        stderr(&o)
    );
}

#[test]
fn preview_and_output_both_on_stdout_is_refused() {
    // `-o - --preview -` wrote the SVG and then the PNG to stdout, run
    // together into one corrupt stream.
    let t = tempdir();
    let a = t.path().join("a.png");
    write_disc_png(&a, 20);
    let o = flourish(&["trace", s(&a), "-o", "-", "--preview", "-"]);
    assert_usage(&o, "standard output");
}

#[test]
fn failed_preview_leaves_no_svg_behind() {
    let t = tempdir();
    let a = t.path().join("a.png");
    write_disc_png(&a, 20);
    let out = t.path().join("a.svg");
    let prev = t.path().join("no-such-folder").join("a.png");
    let o = flourish(&["trace", s(&a), "-o", s(&out), "--preview", s(&prev)]);
    assert_failure(&o, &prev, &[]);
    assert!(
        !out.exists(),
        "the run failed (exit 1) but wrote {}",
        out.display()
    );
}

#[test]
fn outputs_follow_the_umask() {
    use std::os::unix::fs::PermissionsExt;
    let t = tempdir();
    let a = t.path().join("a.png");
    write_disc_png(&a, 20);
    let out = t.path().join("a.svg");
    let o = Command::new("sh")
        .arg("-c")
        .arg(format!(
            "umask 022 && exec '{BIN}' trace '{}' -o '{}'",
            s(&a),
            s(&out)
        ))
        .output()
        .unwrap();
    assert_eq!(code(&o), Some(0), "stderr: {}", stderr(&o));
    let mode = std::fs::metadata(&out).unwrap().permissions().mode() & 0o777;
    assert_eq!(
        mode, 0o644,
        "output mode {mode:o}, expected 644 under umask 022 (temp file mode kept)"
    );
}

#[test]
fn io_errors_name_the_output_not_a_temp_file() {
    let t = tempdir();
    let a = t.path().join("a.png");
    write_disc_png(&a, 20);
    let out = t.path().join("missing").join("a.svg");
    let o = flourish(&["trace", s(&a), "-o", s(&out)]);
    assert_failure(&o, &out, &[]);
    assert!(
        !stderr(&o).contains(".flourish-"),
        "message names the temporary file: {}",
        stderr(&o)
    );
}

/// A stroked path with no length is skipped with a warning on stderr (not
/// only a `--verbose` note); the other paths are still drawn, exit 0.
#[test]
fn zero_length_path_is_skipped_with_a_warning() {
    let dir = tempdir();
    let sketch = dir.path().join("sketch.svg");
    std::fs::write(
        &sketch,
        r##"<svg xmlns="http://www.w3.org/2000/svg" width="200" height="100">
  <path d="M10 50 C60 10 140 90 190 50" stroke="#000" stroke-width="12" fill="none"/>
  <path id="dot" d="M100 80 L100 80" stroke="#000" stroke-width="12" fill="none"/>
</svg>"##,
    )
    .unwrap();
    let out = dir.path().join("out.svg");
    let o = flourish(&["pattern", "--style", "hatching", s(&sketch), "-o", s(&out)]);
    assert_eq!(code(&o), Some(0), "{}", stderr(&o));
    let err = stderr(&o);
    assert!(
        err.contains("warning") && err.contains("no length"),
        "{err}"
    );
    assert!(out.exists());
    // --quiet silences it.
    let o = flourish(&[
        "pattern",
        "--quiet",
        "--style",
        "hatching",
        s(&sketch),
        "-o",
        s(&out),
    ]);
    assert_eq!(code(&o), Some(0));
    assert!(stderr(&o).is_empty(), "{}", stderr(&o));
}

// ---------------------------------------------------------------------------
// brush

/// `--variations N --out-dir DIR` writes `NAME-v1.svg … NAME-vN.svg` (and
/// previews `NAME-vK.png`) for every input, each variation with its own
/// seed; `--variations` with neither `-o` nor `--out-dir` is a usage error.
#[test]
fn brush_variations_with_out_dir_name_each_variation() {
    let dir = tempdir();
    let (out, png) = (dir.path().join("out"), dir.path().join("png"));
    std::fs::create_dir_all(&out).unwrap();
    std::fs::create_dir_all(&png).unwrap();
    let sketch = |name: &str, d: &str| {
        let p = dir.path().join(format!("{name}.svg"));
        std::fs::write(
            &p,
            format!(
                r##"<svg xmlns="http://www.w3.org/2000/svg" width="200" height="100" viewBox="0 0 200 100"><path id="{name}" d="{d}" fill="none" stroke="#000" stroke-width="14"/></svg>"##
            ),
        )
        .unwrap();
        p
    };
    let a = sketch("wave", "M20 60 C 60 10, 120 100, 180 40");
    let b = sketch("line", "M20 50 L180 50");
    let cache = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("target/test-cache");
    let o = flourish(&[
        "brush",
        "--style",
        "doodle",
        "--cache",
        s(&cache),
        s(&a),
        s(&b),
        "--out-dir",
        s(&out),
        "--preview",
        s(&png),
        "--variations",
        "2",
        "--quiet",
    ]);
    assert_eq!(code(&o), Some(0), "{}", stderr(&o));
    for name in ["wave", "line"] {
        let v1 = std::fs::read_to_string(out.join(format!("{name}-v1.svg"))).unwrap();
        let v2 = std::fs::read_to_string(out.join(format!("{name}-v2.svg"))).unwrap();
        assert!(v1.contains(&format!("<g id=\"{name}\"")), "{v1}");
        assert_ne!(v1, v2, "{name}: the two variations differ");
        assert!(png.join(format!("{name}-v1.png")).is_file());
        assert!(png.join(format!("{name}-v2.png")).is_file());
        assert!(!out.join(format!("{name}.svg")).exists());
    }
    let o = flourish(&["brush", "--style", "doodle", s(&a), "--variations", "2"]);
    assert_usage(&o, "--variations");
}

#[test]
fn brush_iterations_out_of_range_is_a_usage_error() {
    // `--iterations 1000000000` ran a billion correction passes (a hang).
    let t = tempdir();
    let a = write(
        t.path(),
        "wave.svg",
        r##"<svg xmlns="http://www.w3.org/2000/svg" width="200" height="100">
<path d="M20 50 C 60 10, 140 90, 180 50" fill="none" stroke="#000" stroke-width="20"/>
</svg>"##,
    );
    let out = t.path().join("out.svg");
    let o = flourish_guarded(
        t.path(),
        &[
            "brush",
            "--style",
            "doodle",
            s(&a),
            "-o",
            s(&out),
            "--iterations",
            "1000000000",
        ],
        Duration::from_secs(60),
    );
    assert_usage(&o, "--iterations");
    assert!(!out.exists());
}

#[test]
fn brush_memory_does_not_grow_with_the_number_of_strokes() {
    // Every query's synthesized fields (~2 MB for a short stroke, ~18 MB
    // for a long one) go once it is traced: kept until the whole sketch
    // is done, they would grow with the number of strokes until thousands
    // of strokes run out of memory. Run under a 400 MB address space
    // limit (the run itself needs about 130 MB).
    let t = tempdir();
    let mut body = String::new();
    for i in 0..200 {
        let (x, y) = (10.0 + (i % 20) as f64 * 9.0, 10.0 + (i / 20) as f64 * 9.0);
        body.push_str(&format!(
            r##"<path d="M{x} {y} l0.3 0.2" fill="none" stroke="#000" stroke-width="0.5"/>"##
        ));
    }
    let a = write(
        t.path(),
        "many.svg",
        &format!(
            r##"<svg xmlns="http://www.w3.org/2000/svg" width="200" height="200">{body}</svg>"##
        ),
    );
    let out = t.path().join("out.svg");
    let cache = t.path().join("cache");
    let o = Command::new("sh")
        .arg("-c")
        .arg(r#"ulimit -v 400000 && exec "$0" "$@""#)
        .arg(BIN)
        .args([
            "--threads",
            "2",
            "brush",
            "--style",
            "doodle",
            "--cache",
            s(&cache),
            s(&a),
            "-o",
            s(&out),
        ])
        .stdin(Stdio::null())
        .output()
        .expect("run flourish");
    assert_eq!(code(&o), Some(0), "stderr: {}", stderr(&o));
    let svg = std::fs::read(&out).unwrap();
    let tree = parse_output(&svg).expect("output parses");
    assert_eq!(tree.root().children().len(), 200, "one group per stroke");
}

#[test]
fn data_style_reads_only_the_styles_folder() {
    // A shape's data-style="/abs/folder" (or "../x") is not read as a
    // folder path, so a sketch cannot make flourish read any folder's
    // style.toml and exemplars; a missing one is reported with the
    // sketch's name.
    let t = tempdir();
    let styles = t.path().join("styles");
    std::fs::create_dir(&styles).unwrap();
    let shipped = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("styles");
    for (cmd, style) in [("pattern", "stipple"), ("fill", "knot")] {
        let outside = shipped.join(style);
        for (name, cause) in [
            (s(&outside).to_string(), "not a style name"),
            (format!("../{style}"), "not a style name"),
            (String::new(), "not a style name"),
            ("missing".to_string(), "not found"),
        ] {
            let a = write(
                t.path(),
                "shape.svg",
                &format!(
                    r##"<svg xmlns="http://www.w3.org/2000/svg" width="200" height="200">
<circle cx="100" cy="100" r="80" fill="#ccc" data-style="{name}"/></svg>"##
                ),
            );
            let out = t.path().join("out.svg");
            let o = flourish(&[
                cmd,
                "--styles",
                s(&styles),
                "--style",
                s(&outside),
                s(&a),
                "-o",
                s(&out),
            ]);
            assert_failure(&o, &a, &["data-style", cause]);
            assert!(!out.exists(), "{cmd} {name:?}: output written");
        }
    }
}

#[test]
fn brush_thin_diagonal_stroke_is_brushed_in_pieces() {
    // One stroke 0.4 units wide across a 200-unit sketch: a 4000×4000 px
    // canvas at 8 px across (over what one stroke may take of the memory
    // budget), so it is synthesized in pieces along its spine.
    let t = tempdir();
    let a = write(
        t.path(),
        "diagonal.svg",
        r##"<svg xmlns="http://www.w3.org/2000/svg" width="200" height="200">
<path d="M2 2 L198 198" fill="none" stroke="#000" stroke-width="0.4"/></svg>"##,
    );
    let out = t.path().join("out.svg");
    let cache = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("target/test-cache");
    let o = flourish_guarded(
        t.path(),
        &[
            "brush",
            "--style",
            "vine",
            "--cache",
            s(&cache),
            s(&a),
            "-o",
            s(&out),
        ],
        Duration::from_secs(300),
    );
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let svg = std::fs::read_to_string(&out).expect("an output");
    assert!(svg.matches("<path").count() > 10, "{svg}");
}

#[test]
fn file_name_with_a_newline_is_named_on_one_line() {
    // "new\nline.svg" printed as is would make a two-line error.
    let t = tempdir();
    let p = write(t.path(), "new\nline.svg", "not an svg");
    let out = t.path().join("out.svg");
    for cmd in ["trace", "pattern"] {
        let o = flourish(&[cmd, s(&p), "-o", s(&out)]);
        assert_eq!(code(&o), Some(1), "stderr: {}", stderr(&o));
        let err = stderr(&o);
        assert_eq!(err.lines().count(), 1, "{err:?}");
        assert!(err.contains("new\\nline.svg"), "{err:?}");
        assert!(!out.exists());
    }
}

/// A photo's uneven light is evened out quietly; `-v` says so, on one
/// line naming the file, and an evenly lit picture says nothing.
#[test]
fn verbose_trace_says_when_a_photos_light_was_evened_out() {
    let t = tempdir();
    let photo = t.path().join("photo.png");
    // White paper lit from 1 at the left to 0.4 at the right, a black disc.
    image::GrayImage::from_fn(200, 160, |x, y| {
        let light = 1.0 - 0.6 * f64::from(x) / 200.0;
        let ink = (f64::from(x) - 100.0).hypot(f64::from(y) - 80.0) < 30.0;
        let r = if ink { 20.0 } else { 240.0 };
        image::Luma([(r * light).round() as u8])
    })
    .save(&photo)
    .unwrap();
    let out = t.path().join("out.svg");
    let o = flourish(&["-v", "trace", s(&photo), "-o", s(&out)]);
    assert!(o.status.success(), "{o:?}");
    let err = String::from_utf8_lossy(&o.stderr);
    // The note, then the run's peak memory.
    assert_eq!(err.lines().count(), 2, "{err}");
    assert!(err.contains("flourish: peak memory "), "{err}");
    assert!(
        err.contains("photo.png") && err.contains("uneven light evened out"),
        "{err}"
    );
    let o = flourish(&["trace", s(&photo), "-o", s(&out)]);
    assert!(o.status.success() && o.stderr.is_empty(), "{o:?}");
    let even = t.path().join("even.png");
    write_disc_png(&even, 120);
    let o = flourish(&["-v", "trace", s(&even), "-o", s(&out)]);
    assert!(o.status.success(), "{o:?}");
    assert!(
        !String::from_utf8_lossy(&o.stderr).contains("light"),
        "{o:?}"
    );
}

/// `-` reads standard input; `-o DIR/` writes DIR/NAME.svg (NAME `stdin`
/// for standard input); a `--preview` ending in .png is a file, also with
/// `--out-dir` and one input, and a usage error with several.
#[test]
fn dash_reads_stdin_and_output_paths_mean_what_they_say() {
    let t = tempdir();
    let a = t.path().join("a.png");
    write_disc_png(&a, 24);
    let o = Command::new(BIN)
        .args(["trace", "-", "-o", "-"])
        .stdin(std::fs::File::open(&a).expect("open"))
        .output()
        .expect("run");
    assert_eq!(code(&o), Some(0), "stderr: {}", stderr(&o));
    assert!(stdout(&o).contains("<path"), "{}", stdout(&o));
    let dir = t.path().join("outs");
    let o = flourish(&["trace", s(&a), "-o", &format!("{}/", s(&dir))]);
    assert_eq!(code(&o), Some(0), "stderr: {}", stderr(&o));
    assert!(dir.join("a.svg").is_file());
    let batch = t.path().join("batch");
    let p = batch.join("p.png");
    let o = flourish(&["trace", s(&a), "--out-dir", s(&batch), "--preview", s(&p)]);
    assert_eq!(code(&o), Some(0), "stderr: {}", stderr(&o));
    assert!(p.is_file(), "--preview D/p.png is a file");
    let b = t.path().join("b.png");
    write_disc_png(&b, 24);
    let o = flourish(&[
        "trace",
        s(&a),
        s(&b),
        "--out-dir",
        s(&batch),
        "--preview",
        s(&p),
    ]);
    assert_usage(&o, "names a file");
}

/// `style list` shows every shipped style with its kind; an unknown
/// style's error names the close ones.
#[test]
fn styles_are_listed_and_close_names_suggested() {
    let o = flourish(&["style", "list"]);
    assert_eq!(code(&o), Some(0), "stderr: {}", stderr(&o));
    let list = stdout(&o);
    for (name, kind) in [("vine", "brush"), ("knot", "fill"), ("stipple", "pattern")] {
        assert!(
            list.lines()
                .any(|l| l.starts_with(name) && l.contains(kind)),
            "{list}"
        );
    }
    let t = tempdir();
    let sketch = write(
        t.path(),
        "s.svg",
        r##"<svg xmlns="http://www.w3.org/2000/svg" width="100" height="100"><circle cx="50" cy="50" r="40" fill="#000"/></svg>"##,
    );
    let o = flourish(&[
        "fill",
        "--style",
        "knott",
        s(&sketch),
        "-o",
        s(&t.path().join("o.svg")),
    ]);
    assert_eq!(code(&o), Some(1), "stderr: {}", stderr(&o));
    assert!(stderr(&o).contains("did you mean knot"), "{}", stderr(&o));
}

/// `--invert` traces the paper as black ink (it used to take the paper's
/// own colour: white shapes on a white preview).
#[test]
fn invert_traces_the_paper_as_black_ink() {
    for sample in ["glyph-a-binary.png", "ornament-scroll.png", "glyph-s.svg"] {
        let out = Command::new(env!("CARGO_BIN_EXE_flourish"))
            .args(["trace", "--invert", "-o", "-"])
            .arg(
                PathBuf::from(env!("CARGO_MANIFEST_DIR"))
                    .join("samples/trace")
                    .join(sample),
            )
            .output()
            .expect("runs");
        assert!(out.status.success(), "{sample}");
        let svg = String::from_utf8_lossy(&out.stdout);
        assert!(svg.contains("fill=\"#000\""), "{sample}: {svg}");
        assert!(!svg.contains("fill=\"#fff"), "{sample}: white ink");
    }
}

/// `trace --centerline`: a drawn cross becomes two stroked open paths of
/// the drawn width (or `--width`); an SVG is refused with one line.
#[test]
fn trace_centerline_gives_stroked_paths() {
    let dir = tempdir();
    let png = dir.path().join("cross.png");
    // Two 4 px bars crossing at the centre of a 120×120 page.
    render_gray(120, 120, 4, |x, y| {
        ((y - 60.0).abs() <= 2.0 && (15.0..=105.0).contains(&x))
            || ((x - 60.0).abs() <= 2.0 && (15.0..=105.0).contains(&y))
    })
    .save(&png)
    .expect("write PNG");
    let out = dir.path().join("cross.svg");
    let o = flourish(&["trace", "--centerline", s(&png), "-o", s(&out)]);
    assert_eq!(code(&o), Some(0), "stderr: {}", stderr(&o));
    let svg = std::fs::read_to_string(&out).unwrap();
    assert_eq!(svg.matches("<path").count(), 2, "{svg}");
    assert_eq!(svg.matches("fill=\"none\"").count(), 2, "{svg}");
    assert!(svg.contains("stroke-width=\"4"), "{svg}");
    parse_output(svg.as_bytes()).expect("output parses");

    let o = flourish(&[
        "trace",
        "--centerline",
        "--width",
        "2.5",
        s(&png),
        "-o",
        s(&out),
    ]);
    assert_eq!(code(&o), Some(0), "stderr: {}", stderr(&o));
    let svg = std::fs::read_to_string(&out).unwrap();
    assert_eq!(svg.matches("stroke-width=\"2.5\"").count(), 2, "{svg}");

    let sketch = dir.path().join("lines.svg");
    std::fs::write(
        &sketch,
        r#"<svg xmlns="http://www.w3.org/2000/svg" width="10" height="10"><path d="M1 1L9 9" stroke="black"/></svg>"#,
    )
    .unwrap();
    let o = flourish(&["trace", "--centerline", s(&sketch), "-o", s(&out)]);
    assert_failure(&o, &sketch, &["raster"]);
}

/// `pattern` and `brush` take a PNG drawing: its lines, traced along their
/// centres, are the queries; blank paper fails with one line.
#[test]
fn pattern_and_brush_accept_a_png_drawing() {
    let dir = tempdir();
    let png = dir.path().join("drawn.png");
    render_gray(160, 120, 4, |x, y| {
        (y - 60.0 - 20.0 * (x / 25.0).sin()).abs() <= 2.0 && (15.0..=145.0).contains(&x)
    })
    .save(&png)
    .expect("write PNG");
    let out = dir.path().join("out.svg");
    let o = flourish(&["pattern", s(&png), "-o", s(&out)]);
    assert_eq!(code(&o), Some(0), "stderr: {}", stderr(&o));
    let svg = std::fs::read_to_string(&out).unwrap();
    assert!(svg.contains("<g id=\"q-1\""), "{svg}");
    let o = flourish(&["brush", "--width", "16", s(&png), "-o", s(&out)]);
    assert_eq!(code(&o), Some(0), "stderr: {}", stderr(&o));
    let svg = std::fs::read_to_string(&out).unwrap();
    assert!(svg.contains("<g id=\"q-1\""), "{svg}");

    let blank = dir.path().join("blank.png");
    render_gray(80, 60, 1, |_, _| false)
        .save(&blank)
        .expect("write PNG");
    let o = flourish(&["pattern", s(&blank), "-o", s(&out)]);
    assert_failure(&o, &blank, &["no lines"]);
}
