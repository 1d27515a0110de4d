//! Benchmark of `fill` synthesis: a 512×512 region from a 128×128 tile
//! (the `knot` and `scales` tiles rasterized at 128 px), the whole
//! multiresolution EM (quilting, PatchMatch, level sets, voting) with the
//! default parameters; tile loading is kept out of the timing; and the
//! knot in a 512 px disc (ring-shaped boundary flow, mask, Shape Hint). Goal ≤ 1 s;
//! texture-synthesis 0.8 on the same tile and size is the reference
//! (`examples/fill_timing.rs`, README "Fill").
//!
//! Run: `cargo bench --bench fill -- --warm-up-time 1 --measurement-time 3`.

use criterion::{criterion_group, criterion_main, BenchmarkId, Criterion};
use flourish::field::diffusion::constant_field;
use flourish::fill::em::{synthesize, synthesize_in, EmParams};
use flourish::fill::region::Region;
use flourish::fill::tile::{SourceDirection, Tile};
use flourish::svg_out::FillRule;
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
    // The same size as a region: a disc under its ring-shaped boundary
    // flow, searched only near the mask, with the Shape Hint at its rim.
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("styles/knot/tile.svg");
    let tile = match Tile::load(&path, 128, SourceDirection::Constant([1.0, -1.0])) {
        Ok(t) => t,
        Err(e) => panic!("{e}"),
    };
    let outline = kurbo::Shape::to_path(&kurbo::Circle::new((256.0, 256.0), 250.0), 0.1);
    let region = match Region::rasterize(
        Path::new("bench.svg"),
        "disc",
        &outline,
        FillRule::NonZero,
        1.0,
        0,
    ) {
        Ok(r) => r,
        Err(e) => panic!("{e}"),
    };
    let params = EmParams::default();
    g.bench_function("knot-disc", |b| {
        b.iter(|| {
            synthesize_in(
                black_box(&tile),
                &region.direction,
                Some(&region.mask),
                &params,
            )
        })
    });
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
