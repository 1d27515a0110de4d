//! Benchmarks of brush style analysis (`flourish style check`):
//! - analysis of a shipped 10-exemplar style at resolution 512, no cache
//!   (goal ≤ 2 s);
//! - reloading the same style from its cache file (goal ≤ 50 ms; the k-d
//!   trees are built on first search, not on load).
//!
//! Run: `cargo bench --bench style`.

use criterion::{criterion_group, criterion_main, BenchmarkId, Criterion};
use flourish::style::brush::{AnalysisOptions, BrushStyle};
use std::hint::black_box;
use std::path::PathBuf;

fn dir(name: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("styles")
        .join(name)
}

fn bench(c: &mut Criterion) {
    let mut g = c.benchmark_group("style-analysis-512");
    g.sample_size(10);
    let fresh = AnalysisOptions {
        use_cache: false,
        ..AnalysisOptions::default()
    };
    for name in ["vine", "scroll", "doodle"] {
        let d = dir(name);
        g.bench_with_input(BenchmarkId::from_parameter(name), &d, |b, d| {
            b.iter(|| BrushStyle::load(black_box(d), &fresh).map(|s| s.exemplars.len()))
        });
    }
    g.finish();

    let mut g = c.benchmark_group("style-reload-512");
    g.sample_size(10);
    let cache = match tempfile::tempdir() {
        Ok(t) => t,
        Err(e) => panic!("{e}"),
    };
    let cached = AnalysisOptions {
        cache_dir: Some(cache.path().to_path_buf()),
        ..AnalysisOptions::default()
    };
    for name in ["vine", "scroll", "doodle"] {
        let d = dir(name);
        // Fill the cache outside the timing.
        if let Err(e) = BrushStyle::load(&d, &cached) {
            panic!("{e}");
        }
        g.bench_with_input(BenchmarkId::from_parameter(name), &d, |b, d| {
            b.iter(|| BrushStyle::load(black_box(d), &cached).map(|s| s.exemplars.len()))
        });
    }
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
