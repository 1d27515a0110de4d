//! Criterion benchmarks of `flourish fill`: each shipped style at its own
//! resolution in the fill samples (a disc, a star, a letter), from the
//! parsed sketch to SVG text: region rasterization, the multiresolution EM
//! (quilting, PatchMatch, level sets, voting), clipping and tracing. Style
//! loading is kept out of the timing.
//!
//! Run: `cargo bench --bench fill -- --warm-up-time 1 --measurement-time 3`.

use criterion::{criterion_group, criterion_main, BenchmarkId, Criterion};
use flourish::{FillOptions, Library, Sketch, StyleOptions};
use std::hint::black_box;
use std::path::PathBuf;

fn sketch(name: &str) -> Sketch {
    let path = PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("samples/fill")
        .join(format!("{name}.svg"));
    let bytes = std::fs::read(&path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    Sketch::from_svg(&bytes).unwrap_or_else(|e| panic!("{name}: {e}"))
}

fn bench(c: &mut Criterion) {
    let opts = FillOptions::default();
    for name in ["knot", "scales"] {
        let style = Library::shipped()
            .load(name, &StyleOptions::default())
            .unwrap_or_else(|e| panic!("{name}: {e}"));
        let mut g = c.benchmark_group(format!("fill-{name}"));
        g.sample_size(10);
        for sample in ["circle", "star", "letter"] {
            let sk = sketch(sample);
            g.bench_with_input(BenchmarkId::from_parameter(sample), &sk, |b, sk| {
                b.iter(|| {
                    flourish::fill(black_box(sk), &style, &opts)
                        .expect("fills")
                        .to_svg()
                })
            });
        }
        g.finish();
    }
}

criterion_group!(benches, bench);
criterion_main!(benches);
