//! `cargo install` gives a `flourish` that works from any folder: the
//! shipped styles travel inside the binary. The binary is installed into
//! a temporary root (built in its own target folder, from the lock file,
//! offline) and run from another folder with an empty cache.

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

fn run(bin: &Path, dir: &Path, cache: &Path, args: &[&str]) -> Output {
    let out = Command::new(bin)
        .args(args)
        .current_dir(dir)
        .env("XDG_CACHE_HOME", cache)
        .env_remove("FLOURISH_STYLES")
        .env_remove("FLOURISH_CACHE_DIR")
        .output()
        .expect("run the installed flourish");
    assert!(
        out.status.success(),
        "{args:?}: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    out
}

#[test]
fn an_installed_binary_finds_the_shipped_styles_from_any_folder() {
    let tmp = tempfile::tempdir().expect("temp dir");
    let prefix = tmp.path().join("prefix");
    let status = Command::new(env!("CARGO"))
        .args(["install", "--path"])
        .arg(root())
        .args(["--root"])
        .arg(&prefix)
        .args([
            "--locked",
            "--offline",
            "--profile",
            "test",
            "--bin",
            "flourish",
        ])
        .env("CARGO_TARGET_DIR", root().join("target/install-test"))
        .status()
        .expect("run cargo install");
    assert!(status.success(), "cargo install failed");
    let bin = prefix.join("bin/flourish");
    // Somewhere with no styles/ folder and an empty cache.
    let work = tmp.path().join("work");
    let cache = tmp.path().join("cache");
    std::fs::create_dir_all(&work).expect("work folder");
    for (from, to) in [
        ("samples/brush/short.svg", "stroke.svg"),
        ("samples/fill/circle.svg", "circle.svg"),
        ("samples/pattern/wave.svg", "wave.svg"),
    ] {
        std::fs::copy(root().join(from), work.join(to)).expect("copy a sample");
    }
    let list = run(&bin, &work, &cache, &["style", "list"]);
    let list = String::from_utf8_lossy(&list.stdout);
    for name in [
        "vine", "scroll", "doodle", "knot", "scales", "stipple", "hatching",
    ] {
        assert!(list.contains(name), "style list lacks {name}: {list}");
    }
    for args in [
        ["brush", "--style", "doodle", "stroke.svg", "-o", "b.svg"],
        ["fill", "--style", "scales", "circle.svg", "-o", "f.svg"],
        ["pattern", "--style", "stipple", "wave.svg", "-o", "p.svg"],
    ] {
        run(&bin, &work, &cache, &args);
        let out = std::fs::read_to_string(work.join(args[5])).expect("an output");
        assert!(out.contains("<path"), "{args:?} drew nothing");
    }
}
