//! Criterion benchmarks of `flourish brush`: each shipped style along
//! three samples (an S-curve, a spiral, a zig-zag), from the parsed sketch
//! to SVG text: matching, ARAP, graph cuts, hierarchical synthesis and
//! tracing. The style analysis is cached and kept out of the timing.
//!
//! Run with `make bench` or
//! `cargo bench --bench brush -- --warm-up-time 1 --measurement-time 3`.

use criterion::{criterion_group, criterion_main, BenchmarkId, Criterion};
use flourish::{BrushOptions, Library, Sketch, StyleOptions};
use std::hint::black_box;
use std::path::PathBuf;

fn sketch(name: &str) -> Sketch {
    let path = PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("samples/brush")
        .join(format!("{name}.svg"));
    let bytes = std::fs::read(&path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    Sketch::from_svg(&bytes).unwrap_or_else(|e| panic!("{name}: {e}"))
}

fn bench(c: &mut Criterion) {
    let load = StyleOptions {
        cache_dir: Some(std::env::temp_dir().join("flourish-bench-cache")),
        ..StyleOptions::default()
    };
    let opts = BrushOptions::default();
    for name in ["vine", "scroll", "doodle"] {
        let style = Library::shipped()
            .load(name, &load)
            .unwrap_or_else(|e| panic!("{name}: {e}"));
        let mut g = c.benchmark_group(format!("brush-{name}"));
        g.sample_size(10);
        for sample in ["s-curve", "spiral", "zigzag"] {
            let sk = sketch(sample);
            g.bench_with_input(BenchmarkId::from_parameter(sample), &sk, |b, sk| {
                b.iter(|| {
                    flourish::brush(black_box(sk), &style, &opts)
                        .expect("brushes")
                        .to_svg()
                })
            });
        }
        g.finish();
    }
}

criterion_group!(benches, bench);
criterion_main!(benches);
