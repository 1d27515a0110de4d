//! Bounded time: `--timeout` ends a run cleanly (exit 1, one line, no
//! output file and no temporary file left, an existing output untouched),
//! and a run that lasts shows what it is doing on stderr.

use std::path::PathBuf;
use std::process::Command;

fn flourish() -> Command {
    Command::new(env!("CARGO_BIN_EXE_flourish"))
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
    assert!(err.contains("letter.svg: fill: 1 region"), "{err}");
    let quiet = run(true);
    assert!(quiet.status.success());
    assert!(
        quiet.stderr.is_empty(),
        "{}",
        String::from_utf8_lossy(&quiet.stderr)
    );
}
