//! Criterion benchmarks of `flourish pattern` on the pattern samples, per
//! shipped style: a stroked wave (elements along a path) and a blob with a
//! hole (elements in a region, Lloyd seeds included), from the parsed
//! sketch to SVG text. Style analysis is kept out of the timing.
//!
//! Run: `cargo bench --bench pattern`.

use criterion::{criterion_group, criterion_main, BenchmarkId, Criterion};
use flourish::{Library, PatternOptions, Sketch, StyleOptions};
use std::hint::black_box;
use std::path::PathBuf;

fn sketch(name: &str) -> Sketch {
    let path = PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("samples/pattern")
        .join(format!("{name}.svg"));
    let bytes = std::fs::read(&path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    Sketch::from_svg(&bytes).unwrap_or_else(|e| panic!("{name}: {e}"))
}

fn bench(c: &mut Criterion) {
    let opts = PatternOptions::default();
    for sample in ["wave", "blob"] {
        let sk = sketch(sample);
        let mut g = c.benchmark_group(format!("pattern-{sample}"));
        g.sample_size(10);
        for name in ["hatching", "stipple", "flowers", "brushmarks"] {
            let style = Library::shipped()
                .load(name, &StyleOptions::default())
                .unwrap_or_else(|e| panic!("{name}: {e}"));
            g.bench_with_input(BenchmarkId::from_parameter(name), &style, |b, st| {
                b.iter(|| {
                    flourish::pattern(black_box(&sk), st, &opts)
                        .expect("synthesizes")
                        .to_svg()
                })
            });
        }
        g.finish();
    }
}

criterion_group!(benches, bench);
criterion_main!(benches);
