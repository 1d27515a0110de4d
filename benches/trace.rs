//! Criterion benchmarks of `flourish trace` on the project's own samples
//! (a 512² glyph, a scroll, the 2-megapixel ornament, binary and
//! anti-aliased, and an SVG): the picture read from bytes and traced to
//! SVG text, as the command does it after reading the file.
//! Run with `make bench`; the side-by-side with potrace is
//! `cargo run --release -p flourish-tools --bin compare_potrace`.

use criterion::{criterion_group, criterion_main, Criterion};
use flourish::{Image, ImageOptions, TraceOptions};
use std::hint::black_box;
use std::path::PathBuf;

fn sample(name: &str) -> Vec<u8> {
    let path = PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("samples/trace")
        .join(name);
    std::fs::read(&path).unwrap_or_else(|e| panic!("{}: {e}", path.display()))
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
        let bytes = sample(name);
        let (input, opts) = (ImageOptions::default(), TraceOptions::default());
        g.bench_function(name, |b| {
            b.iter(|| {
                let image = Image::from_bytes(black_box(&bytes), &input).expect("reads");
                flourish::trace(&image, &opts).expect("traces").to_svg()
            })
        });
    }
    g.finish();
}

criterion_group!(benches, bench_trace);
criterion_main!(benches);
