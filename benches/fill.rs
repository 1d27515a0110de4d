//! Criterion benchmarks of `flourish fill`: each shipped style at its own
//! resolution in the fill samples (a disc, a star, a letter), from the
//! parsed sketch to SVG text: region rasterization, the multiresolution EM
//! (quilting, PatchMatch, level sets, voting), clipping and tracing. Style
//! loading is kept out of the timing.
//!
//! `fill-art` is the whole command's work on third-party swatches of
//! `../shared/art` (skipped when it is absent): three styles (interlace
//! line art, a coloured panel without paper, thin jigsaw lines) loaded and
//! filled into the drop-cap letter B, a letter-sized region (567×732 px
//! grid, 0.17 Mpx inside), from reading the style and the sketch to SVG
//! text.
//!
//! Run: `cargo bench --bench fill -- --warm-up-time 1 --measurement-time 3`.

use criterion::{criterion_group, criterion_main, BenchmarkId, Criterion};
use flourish::{FillOptions, Library, Sketch, Style, StyleOptions};
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

/// The whole command on three third-party swatches in the art's letter B.
fn bench_art(c: &mut Criterion) {
    let art = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../shared/art");
    if !art.is_dir() {
        return;
    }
    let sketch_file = art.join("sketches/region-03-letter-b.svg");
    let opts = FillOptions::default();
    let mut g = c.benchmark_group("fill-art");
    g.sample_size(10);
    for name in ["celtic-roundels", "crosses-color", "jigsaw-lines"] {
        let dir = art.join("styles").join(name);
        g.bench_with_input(BenchmarkId::from_parameter(name), &dir, |b, dir| {
            b.iter(|| {
                let bytes = std::fs::read(&sketch_file).expect("sketch");
                let sk = Sketch::from_svg(&bytes).expect("parses");
                let style = Style::load(dir, &StyleOptions::default()).expect("loads");
                flourish::fill(black_box(&sk), &style, &opts)
                    .expect("fills")
                    .to_svg()
            })
        });
    }
    g.finish();
}

criterion_group!(benches, bench, bench_art);
criterion_main!(benches);
