//! Benchmarks of `pattern` synthesis, style analysis kept out of the timing:
//! - 1-D: along a 1000 px path (goal ≤ 20 ms);
//! - 2-D: a square sized for 1000 elements (goal ≤ 200 ms), Lloyd included.
//!
//! Run: `cargo bench --bench pattern`.

use criterion::{criterion_group, criterion_main, BenchmarkId, Criterion};
use flourish::pattern::seeds::Region;
use flourish::pattern::{along_path, in_region, PatternOptions, PatternStyle};
use flourish::svg_out::FillRule;
use kurbo::BezPath;
use std::hint::black_box;
use std::path::Path;

fn style(name: &str) -> PatternStyle {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("styles")
        .join(name);
    match PatternStyle::load(&dir) {
        Ok(s) => s,
        Err(e) => panic!("{e}"),
    }
}

fn bench(c: &mut Criterion) {
    let opts = PatternOptions::default();
    let mut g = c.benchmark_group("pattern-1d-1000px");
    // A gentle S curve 1000 px long (two cubics of 500 px).
    let mut spine = BezPath::new();
    spine.move_to((0.0, 0.0));
    spine.curve_to((160.0, -120.0), (340.0, 120.0), (490.0, 0.0));
    spine.curve_to((640.0, -120.0), (820.0, 120.0), (980.0, 0.0));
    let len = kurbo::Shape::perimeter(&spine, 0.01);
    assert!((len - 1000.0).abs() < 60.0, "{len}");
    for name in ["hatching", "brushmarks", "flowers", "stipple"] {
        let st = style(name);
        g.bench_with_input(BenchmarkId::from_parameter(name), &st, |b, st| {
            b.iter(|| along_path(black_box(st), &spine, 20.0, &opts, &[0, 0]))
        });
    }
    g.finish();

    let mut g = c.benchmark_group("pattern-2d-1000-elements");
    g.sample_size(10);
    for name in ["stipple", "flowers", "brushmarks"] {
        let st = style(name);
        // A square whose area asks for 1000 elements.
        let side = (1000.0 * st.reference.dist.area / st.elements().len() as f64).sqrt();
        let sq = BezPath::from_vec(vec![
            kurbo::PathEl::MoveTo((0.0, 0.0).into()),
            kurbo::PathEl::LineTo((side, 0.0).into()),
            kurbo::PathEl::LineTo((side, side).into()),
            kurbo::PathEl::LineTo((0.0, side).into()),
            kurbo::PathEl::ClosePath,
        ]);
        let region = match Region::new(&sq, FillRule::NonZero, 0.05) {
            Ok(r) => r,
            Err(e) => panic!("{e}"),
        };
        g.bench_with_input(BenchmarkId::from_parameter(name), &st, |b, st| {
            b.iter(|| {
                let out = in_region(black_box(st), &region, &sq, &opts, &[0, 0]);
                assert!(out.as_ref().map(|v| v.len()).unwrap_or(0) >= 990);
                out
            })
        });
    }
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
