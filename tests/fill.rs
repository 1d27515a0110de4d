//! `flourish fill` on the command line: bad input (sketches and swatches)
//! gives one clear line, exit 1 and no output file; a gradient swatch is
//! quantized with a note.

use std::path::{Path, PathBuf};
use std::process::Command;

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

fn sample(name: &str) -> PathBuf {
    root().join("samples/fill").join(format!("{name}.svg"))
}

/// Runs the binary; returns (status, stderr).
fn cli(args: &[&str]) -> (i32, String) {
    let out = Command::new(env!("CARGO_BIN_EXE_flourish"))
        .args(args)
        .output()
        .unwrap();
    (
        out.status.code().unwrap_or(-1),
        String::from_utf8_lossy(&out.stderr).into_owned(),
    )
}

fn write_sketch(dir: &Path, name: &str, body: &str) -> String {
    let p = dir.join(name);
    std::fs::write(
        &p,
        format!(
            "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"200\" height=\"200\">{body}</svg>"
        ),
    )
    .unwrap();
    p.to_string_lossy().into_owned()
}

#[test]
fn bad_inputs_fail_with_one_clear_line() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("out.svg");
    let out = out.to_str().unwrap();
    let styles = root().join("styles");
    let styles = styles.to_str().unwrap();
    let open = sample("open-only");
    let speck = write_sketch(
        dir.path(),
        "speck.svg",
        "<circle cx=\"50\" cy=\"50\" r=\"0.05\" fill=\"#000\"/>",
    );
    let huge = write_sketch(
        dir.path(),
        "huge.svg",
        "<rect x=\"0\" y=\"0\" width=\"9000\" height=\"9000\" fill=\"#000\"/>",
    );
    // A style whose tile has no ink.
    let empty = dir.path().join("empty");
    std::fs::create_dir(&empty).unwrap();
    std::fs::write(
        empty.join("tile.svg"),
        "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"32\" height=\"32\"></svg>",
    )
    .unwrap();
    std::fs::write(
        empty.join("style.toml"),
        "kind = \"fill\"\n[[exemplar]]\nfile = \"tile.svg\"\n",
    )
    .unwrap();
    let circle = sample("circle");
    for (args, needle) in [
        (
            vec![
                "fill",
                "--styles",
                styles,
                open.to_str().unwrap(),
                "-o",
                out,
            ],
            "only open paths",
        ),
        (
            vec!["fill", "--styles", styles, &speck, "-o", out],
            "smaller than one tile pixel",
        ),
        (
            vec!["fill", "--styles", styles, &huge, "-o", out],
            "size limit",
        ),
        (
            vec![
                "fill",
                "--style",
                empty.to_str().unwrap(),
                circle.to_str().unwrap(),
                "-o",
                out,
            ],
            "no ink",
        ),
    ] {
        let (code, err) = cli(&args);
        assert_eq!(code, 1, "{args:?}: {err}");
        assert_eq!(err.trim_end().lines().count(), 1, "{err}");
        assert!(err.contains(needle), "{err}");
        assert!(!Path::new(out).exists());
    }
}

/// A fill style in `dir/name` whose exemplars are `files` (name, bytes),
/// listed `repeat` times each in style.toml.
fn write_style(dir: &Path, name: &str, files: &[(&str, &[u8])], repeat: usize) -> String {
    let d = dir.join(name);
    std::fs::create_dir(&d).unwrap();
    let mut toml = String::from("kind = \"fill\"\n");
    for (file, bytes) in files {
        std::fs::write(d.join(file), bytes).unwrap();
        for _ in 0..repeat {
            toml.push_str(&format!("[[exemplar]]\nfile = \"{file}\"\n"));
        }
    }
    std::fs::write(d.join("style.toml"), toml).unwrap();
    d.to_string_lossy().into_owned()
}

/// An 8-bit RGB PNG of `w`×`h` pixels, all of colour `rgb`.
fn png(w: u32, h: u32, rgb: [u8; 3]) -> Vec<u8> {
    let img = image::RgbImage::from_pixel(w, h, image::Rgb(rgb));
    let mut bytes = std::io::Cursor::new(Vec::new());
    img.write_to(&mut bytes, image::ImageFormat::Png).unwrap();
    bytes.into_inner()
}

#[test]
fn swatches_that_cannot_be_synthesized_fail_with_one_clear_line() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("out.svg");
    let out = out.to_str().unwrap();
    let knot = std::fs::read(root().join("styles/knot/tile.svg")).unwrap();
    let flat = br##"<svg xmlns="http://www.w3.org/2000/svg" width="32" height="32"><rect width="32" height="32" fill="#c03030"/></svg>"##;
    let flat = write_style(dir.path(), "flat", &[("tile.svg", flat)], 1);
    let speck = png(1, 1, [0, 0, 0]);
    let speck = write_style(dir.path(), "speck", &[("tile.png", &speck)], 1);
    let many = write_style(dir.path(), "many", &[("tile.svg", &knot)], 200);
    let circle = sample("circle");
    let circle = circle.to_str().unwrap();
    for (style, needle) in [
        (&flat, "one flat colour"),
        (&speck, "tile.png"),
        (&many, "200 exemplars"),
    ] {
        let args = ["fill", "--style", style, circle, "-o", out];
        let (code, err) = cli(&args);
        assert_eq!(code, 1, "{args:?}: {err}");
        assert_eq!(err.trim_end().lines().count(), 1, "{err}");
        assert!(err.contains(needle), "{err}");
        assert!(!Path::new(out).exists());
    }
}

#[test]
fn a_gradient_swatch_is_quantized_with_a_note_under_verbose() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("out.svg");
    let svg = br##"<svg xmlns="http://www.w3.org/2000/svg" width="64" height="64"><defs><linearGradient id="g" x1="0" x2="1"><stop offset="0" stop-color="#203060"/><stop offset="1" stop-color="#e0c060"/></linearGradient></defs><rect width="64" height="64" fill="#fff"/><circle cx="32" cy="32" r="20" fill="url(#g)"/><rect x="0" y="28" width="64" height="8" fill="#a02020"/></svg>"##;
    let style = write_style(dir.path(), "gradient", &[("tile.svg", svg)], 1);
    let circle = sample("circle");
    let (code, err) = cli(&[
        "fill",
        "-v",
        "--style",
        &style,
        circle.to_str().unwrap(),
        "-o",
        out.to_str().unwrap(),
    ]);
    assert_eq!(code, 0, "{err}");
    assert!(err.contains("gradient"), "{err}");
    let svg = std::fs::read_to_string(&out).unwrap();
    assert!(svg.contains("<path"), "{svg}");
}
