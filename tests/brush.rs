//! `flourish brush` on the command line: variations written side by side,
//! a sketch with nothing to brush refused in one line with no output, and
//! exemplars with no clear main branch warned about and still used.

use std::path::PathBuf;

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

fn temp_sketch(body: &str) -> (tempfile::TempDir, PathBuf) {
    let dir = tempfile::tempdir().unwrap();
    let p = dir.path().join("s.svg");
    std::fs::write(
        &p,
        format!(r#"<svg xmlns="http://www.w3.org/2000/svg" width="400" height="200" viewBox="0 0 400 200">{body}</svg>"#),
    )
    .unwrap();
    (dir, p)
}

#[test]
fn cli_writes_variations_and_fails_cleanly() {
    let bin = env!("CARGO_BIN_EXE_flourish");
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("o.svg");
    let cache = std::env::temp_dir().join("flourish-test-cache");
    let run = |args: &[&str]| std::process::Command::new(bin).args(args).output().unwrap();
    let sample = root().join("samples/brush/short.svg");
    let r = run(&[
        "brush",
        "--style",
        "doodle",
        "--styles",
        root().join("styles").to_str().unwrap(),
        "--cache",
        cache.to_str().unwrap(),
        sample.to_str().unwrap(),
        "-o",
        out.to_str().unwrap(),
        "--variations",
        "2",
    ]);
    assert!(r.status.success(), "{}", String::from_utf8_lossy(&r.stderr));
    let a = std::fs::read_to_string(dir.path().join("o-1.svg")).unwrap();
    let b = std::fs::read_to_string(dir.path().join("o-2.svg")).unwrap();
    assert!(a.contains("<g id=\"short\""), "{a}");
    assert_ne!(a, b, "two variations differ");
    let (_d, empty) = temp_sketch(r##"<rect x="10" y="10" width="50" height="50" fill="#000"/>"##);
    let r = run(&[
        "brush",
        "--style",
        "doodle",
        "--cache",
        cache.to_str().unwrap(),
        empty.to_str().unwrap(),
        "-o",
        out.to_str().unwrap(),
    ]);
    assert_eq!(r.status.code(), Some(1));
    let err = String::from_utf8_lossy(&r.stderr);
    assert_eq!(err.lines().count(), 1, "{err}");
    assert!(
        err.contains("s.svg") && err.contains("no open paths"),
        "{err}"
    );
    assert!(!out.exists(), "no output on failure");
}

/// A library of a ring and a dot with no `start`/`end`: each is named in
/// one warning line saying it has no clear main branch, and the fallback
/// spine (across the drawing's longer side) still brushes the stroke:
/// exit 0 and ink along it.
#[test]
fn exemplars_without_a_main_branch_warn_and_fall_back() {
    let bin = env!("CARGO_BIN_EXE_flourish");
    let dir = tempfile::tempdir().unwrap();
    let lib = dir.path().join("rings");
    std::fs::create_dir(&lib).unwrap();
    std::fs::write(
        lib.join("ring.svg"),
        r##"<svg xmlns="http://www.w3.org/2000/svg" width="100" height="100"><circle cx="50" cy="50" r="30" fill="none" stroke="#000" stroke-width="8"/></svg>"##,
    )
    .unwrap();
    std::fs::write(
        lib.join("dot.svg"),
        r#"<svg xmlns="http://www.w3.org/2000/svg" width="100" height="100"><circle cx="50" cy="50" r="30"/></svg>"#,
    )
    .unwrap();
    std::fs::write(
        lib.join("style.toml"),
        "kind = \"brush\"\nresolution = 128\n\n[[exemplar]]\nfile = \"ring.svg\"\n\n[[exemplar]]\nfile = \"dot.svg\"\n",
    )
    .unwrap();
    let out = dir.path().join("o.svg");
    let r = std::process::Command::new(bin)
        .args([
            "brush",
            "--style",
            lib.to_str().unwrap(),
            "--cache",
            dir.path().join("cache").to_str().unwrap(),
            root().join("samples/brush/s-curve.svg").to_str().unwrap(),
            "-o",
            out.to_str().unwrap(),
        ])
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&r.stderr);
    assert!(r.status.success(), "{err}");
    for file in ["ring.svg", "dot.svg"] {
        let lines: Vec<&str> = err.lines().filter(|l| l.contains(file)).collect();
        assert_eq!(lines.len(), 1, "{file}: {err}");
        assert!(
            lines[0].contains("warning") && lines[0].contains("no clear main branch"),
            "{err}"
        );
    }
    let svg = std::fs::read_to_string(&out).unwrap();
    assert!(
        svg.contains("<g id=\"s-curve\"") && svg.contains("<path"),
        "{svg}"
    );
}
