//! Benchmark of `fill` synthesis: a 512×512 region from a 128×128 tile
//! (the `knot` and `scales` tiles rasterized at 128 px), the whole
//! multiresolution EM (quilting, PatchMatch, level sets, voting) with the
//! shipped parameters; tile loading is kept out of the timing. Goal ≤ 1 s;
//! texture-synthesis 0.8 on the same tile and size is the reference
//! (`examples/fill_timing.rs`, README "Fill").
//!
//! Run: `cargo bench --bench fill -- --warm-up-time 1 --measurement-time 3`.

use criterion::{criterion_group, criterion_main, BenchmarkId, Criterion};
use flourish::field::diffusion::constant_field;
use flourish::fill::em::{synthesize, EmParams};
use flourish::fill::tile::{SourceDirection, Tile};
use std::hint::black_box;
use std::path::Path;

fn bench(c: &mut Criterion) {
    let mut g = c.benchmark_group("fill-512-from-128");
    g.sample_size(10);
    let dir = constant_field(512, 512, [1.0, 0.0]);
    for name in ["knot", "scales"] {
        let path = Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("styles")
            .join(name)
            .join("tile.svg");
        let tile = match Tile::load(&path, 128, SourceDirection::Constant([1.0, 0.0])) {
            Ok(t) => t,
            Err(e) => panic!("{e}"),
        };
        let params = EmParams::default();
        g.bench_with_input(BenchmarkId::from_parameter(name), &tile, |b, t| {
            b.iter(|| synthesize(black_box(t), &dir, &params))
        });
    }
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
