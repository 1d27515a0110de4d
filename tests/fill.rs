//! `flourish fill` on the command line: bad input gives one clear line,
//! exit 1 and no output file.

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
