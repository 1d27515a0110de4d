//! Criterion benchmarks of the trace pipeline, stage by stage, on the
//! project's own samples (a 512² glyph and the 2-megapixel ornament).
//! Run with `make bench`; the potrace comparison is
//! `cargo run --release --example compare_potrace`.

use criterion::{criterion_group, criterion_main, Criterion};
use flourish::raster::contour;
use flourish::read::ink::{load, InputOptions};
use flourish::trace::{trace_file, trace_sdf, TraceOptions};
use std::hint::black_box;
use std::path::PathBuf;

fn sample(name: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("samples/trace")
        .join(name)
}

fn bench_trace(c: &mut Criterion) {
    let mut g = c.benchmark_group("trace");
    g.sample_size(10);
    for name in [
        "glyph-a.png",
        "ornament-scroll.png",
        "ornament-2mp.png",
        "ornament-2mp-aa.png",
        "ornament-scroll.svg",
    ] {
        let path = sample(name);
        let input = InputOptions::default();
        let opts = TraceOptions::default();
        g.bench_function(format!("{name}/load+sdf"), |b| {
            b.iter(|| black_box(load(&path, &input).expect("loads")))
        });
        let ink = load(&path, &input).expect("loads");
        let sdf = &ink.layers[0].sdf;
        g.bench_function(format!("{name}/contours"), |b| {
            b.iter(|| black_box(contour::extract(&sdf.dist)))
        });
        g.bench_function(format!("{name}/fit"), |b| {
            b.iter(|| black_box(trace_sdf(sdf, &opts)))
        });
        g.bench_function(format!("{name}/total"), |b| {
            b.iter(|| black_box(trace_file(&path, &input, &opts).expect("traces").to_svg()))
        });
    }
    g.finish();
}

criterion_group!(benches, bench_trace);
criterion_main!(benches);
