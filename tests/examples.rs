//! The four examples of `examples/` run, and each writes what the command
//! line writes for the same inputs, byte for byte.

use std::path::{Path, PathBuf};
use std::process::Command;

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

/// An example's binary, built beside the tests (`cargo test` builds the
/// examples of the package).
fn example(name: &str) -> PathBuf {
    let exe = std::env::current_exe().expect("the test's own path");
    let profile = exe
        .parent()
        .and_then(Path::parent)
        .expect("target/PROFILE/deps/..");
    let bin = profile.join("examples").join(name);
    assert!(
        bin.exists(),
        "{} is not built: run `cargo build --examples` first (`make test` does)",
        bin.display()
    );
    bin
}

/// Runs `program` with `args` in a shared analysis cache; panics on
/// failure with its stderr.
fn run(program: &Path, args: &[&str], cache: &Path) {
    let out = Command::new(program)
        .args(args)
        .env("FLOURISH_CACHE_DIR", cache)
        .output()
        .unwrap_or_else(|e| panic!("{}: {e}", program.display()));
    assert!(
        out.status.success(),
        "{} {args:?}: {}",
        program.display(),
        String::from_utf8_lossy(&out.stderr)
    );
}

/// The example's output and the command's, for `example ARGS… OUT` and
/// `flourish CLI… -o OUT`.
fn both(name: &str, args: &[&str], cli: &[&str]) -> (Vec<u8>, Vec<u8>) {
    let dir = tempfile::tempdir().expect("temp dir");
    let cache = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("target/test-cache");
    let (ex, cmd) = (dir.path().join("example.svg"), dir.path().join("cli.svg"));
    let mut ex_args = args.to_vec();
    ex_args.push(ex.to_str().expect("utf-8 path"));
    run(&example(name), &ex_args, &cache);
    let mut cli_args = cli.to_vec();
    cli_args.extend(["-o", cmd.to_str().expect("utf-8 path")]);
    run(Path::new(env!("CARGO_BIN_EXE_flourish")), &cli_args, &cache);
    let read = |p: &Path| std::fs::read(p).unwrap_or_else(|e| panic!("{}: {e}", p.display()));
    (read(&ex), read(&cmd))
}

fn check(name: &str, (example, cli): (Vec<u8>, Vec<u8>)) {
    let text = String::from_utf8_lossy(&example);
    assert!(
        text.contains("<path"),
        "{name}: the example drew nothing: {text}"
    );
    assert!(
        example == cli,
        "{name}: the example's output is not the command's"
    );
}

fn sample(path: &str) -> String {
    root()
        .join("samples")
        .join(path)
        .to_string_lossy()
        .into_owned()
}

#[test]
fn brush() {
    let s = sample("brush/short.svg");
    check(
        "brush",
        both(
            "brush",
            &["doodle", &s],
            &["brush", "--style", "doodle", &s],
        ),
    );
}

#[test]
fn fill() {
    let s = sample("fill/circle.svg");
    check(
        "fill",
        both("fill", &["scales", &s], &["fill", "--style", "scales", &s]),
    );
}

#[test]
fn pattern() {
    let s = sample("pattern/mixed.svg");
    check(
        "pattern",
        both(
            "pattern",
            &["hatching", &s],
            &["pattern", "--style", "hatching", "--seed", "7", &s],
        ),
    );
}

#[test]
fn trace() {
    let s = sample("trace/two-colour.png");
    check("trace", both("trace", &[&s], &["trace", "--layers", &s]));
}
