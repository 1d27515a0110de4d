//! Benchmarks of brush style analysis (`flourish style check`):
//! - analysis of a shipped 10-exemplar style at resolution 512, no cache
//!   (goal ≤ 2 s), with its drawn spines and (`vine-traced`) with every
//!   spine traced by Dijkstra;
//! - reloading the same style from its cache file (goal ≤ 50 ms; the k-d
//!   trees are built on first search, not on load).
//!
//! Run: `cargo bench --bench style`.

use criterion::{criterion_group, criterion_main, BenchmarkId, Criterion};
use flourish::{Style, StyleOptions};
use std::hint::black_box;
use std::path::PathBuf;

fn dir(name: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("styles")
        .join(name)
}

/// Copies a style folder, leaving out the `id="spine"` lines of its SVGs.
fn copy_without_spines(from: &std::path::Path, to: &std::path::Path) -> std::io::Result<()> {
    std::fs::create_dir_all(to)?;
    for entry in std::fs::read_dir(from)? {
        let p = entry?.path();
        let Some(name) = p.file_name() else { continue };
        if p.extension().is_none_or(|e| e != "svg") {
            std::fs::copy(&p, to.join(name))?;
            continue;
        }
        let text = std::fs::read_to_string(&p)?;
        let kept: Vec<&str> = text
            .lines()
            .filter(|l| !l.contains("id=\"spine\""))
            .collect();
        std::fs::write(to.join(name), kept.join("\n"))?;
    }
    Ok(())
}

fn bench(c: &mut Criterion) {
    let mut g = c.benchmark_group("style-analysis-512");
    g.sample_size(10);
    let fresh = StyleOptions {
        use_cache: false,
        ..StyleOptions::default()
    };
    for name in ["vine", "scroll", "doodle"] {
        let d = dir(name);
        g.bench_with_input(BenchmarkId::from_parameter(name), &d, |b, d| {
            b.iter(|| Style::load(black_box(d), &fresh).map(|s| s.files().len()))
        });
    }
    // The same vine with its drawn spines removed: every spine traced by
    // Dijkstra over the edge tangent flow from style.toml's start and end.
    let traced = match tempfile::tempdir() {
        Ok(t) => t,
        Err(e) => panic!("{e}"),
    };
    let tdir = traced.path().join("vine");
    if let Err(e) = copy_without_spines(&dir("vine"), &tdir) {
        panic!("{e}");
    }
    g.bench_with_input(BenchmarkId::from_parameter("vine-traced"), &tdir, |b, d| {
        b.iter(|| Style::load(black_box(d), &fresh).map(|s| s.files().len()))
    });
    g.finish();

    let mut g = c.benchmark_group("style-reload-512");
    g.sample_size(10);
    let cache = match tempfile::tempdir() {
        Ok(t) => t,
        Err(e) => panic!("{e}"),
    };
    let cached = StyleOptions {
        cache_dir: Some(cache.path().to_path_buf()),
        ..StyleOptions::default()
    };
    for name in ["vine", "scroll", "doodle"] {
        let d = dir(name);
        // Fill the cache outside the timing.
        if let Err(e) = Style::load(&d, &cached) {
            panic!("{e}");
        }
        g.bench_with_input(BenchmarkId::from_parameter(name), &d, |b, d| {
            b.iter(|| Style::load(black_box(d), &cached).map(|s| s.files().len()))
        });
    }
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
