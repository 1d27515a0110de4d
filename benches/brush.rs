//! Criterion benchmarks of the brush stages (decobrush.txt §5.1–5.3):
//! piecewise matching of a 200-sample query against 10 exemplars of 100
//! samples, ARAP factorization and solve on a 60-rib mesh, and the
//! graph-cut seam on 256×64 and 300×100 overlaps. Setup is kept out of the timings.
//! Run with `make bench` or
//! `cargo bench --bench brush -- --warm-up-time 1 --measurement-time 3`.

use criterion::{criterion_group, criterion_main, Criterion};
use flourish::brush::arap::{Arap, RibMesh};
use flourish::brush::graphcut::{seam, Cover, SeamParams};
use flourish::brush::matching::{match_query, MatchOptions, SampleFeature, SpineFeatures};
use flourish::raster::Grid;
use kurbo::{Point, Vec2};
use std::hint::black_box;

/// A spine of `n` samples (spacing 0.2, width 1) whose turning angle is
/// `amp · sin(freq · i + phase)`, with a one-number appearance descriptor.
fn spine(n: usize, amp: f64, freq: f64, phase: f64) -> SpineFeatures {
    let len = (n - 1) as f64 * 0.2;
    SpineFeatures {
        samples: (0..n)
            .map(|i| SampleFeature {
                turning: amp * (freq * i as f64 + phase).sin(),
                width: 1.0 + 0.1 * (0.05 * i as f64 + phase).cos(),
                dist_start: i as f64 * 0.2,
                dist_end: len - i as f64 * 0.2,
            })
            .collect(),
        appearance: (0..n)
            .map(|i| vec![0.5 + 0.3 * (0.1 * i as f64 + phase).sin()])
            .collect(),
    }
}

fn bench_matching(c: &mut Criterion) {
    let query = SpineFeatures {
        appearance: Vec::new(),
        ..spine(200, 0.05, 0.03, 0.0)
    };
    let exemplars: Vec<_> = (0..10)
        .map(|k| spine(100, 0.04 + 0.005 * k as f64, 0.05, k as f64))
        .collect();
    let opts = MatchOptions::default();
    let mut g = c.benchmark_group("brush");
    g.sample_size(10);
    g.bench_function("matching/200x(10x100)", |b| {
        b.iter(|| black_box(match_query(&query, &exemplars, &opts).expect("matches")))
    });
    g.finish();
}

fn bench_arap(c: &mut Criterion) {
    let spine: Vec<Point> = (0..60).map(|i| Point::new(i as f64, 0.0)).collect();
    let left: Vec<Point> = spine.iter().map(|p| *p + Vec2::new(0.0, -4.0)).collect();
    let right: Vec<Point> = spine.iter().map(|p| *p + Vec2::new(0.0, 4.0)).collect();
    let radius = 59.0 / std::f64::consts::FRAC_PI_2;
    let pins: Vec<Point> = (0..60)
        .map(|i| {
            let a = i as f64 / radius;
            Point::new(radius * a.sin(), radius * (1.0 - a.cos()))
        })
        .collect();
    let mut g = c.benchmark_group("brush");
    g.sample_size(10);
    for divisions in [1, 2] {
        let mesh = RibMesh::from_ribs(&spine, &left, &right, divisions).expect("mesh");
        g.bench_function(format!("arap/60 ribs d{divisions}/factor"), |b| {
            b.iter(|| black_box(Arap::new(&mesh, &mesh.spine).expect("factors")))
        });
        let arap = Arap::new(&mesh, &mesh.spine).expect("factors");
        g.bench_function(format!("arap/60 ribs d{divisions}/solve"), |b| {
            b.iter(|| black_box(arap.solve(&pins).expect("solves")))
        });
    }
    g.finish();
}

fn bench_graphcut(c: &mut Criterion) {
    // Two ornaments of curved ink lines, slightly out of phase.
    let ink = |x: usize, y: usize, phase: f64| {
        let v = ((x as f64 * 0.21 + phase).sin() * 6.0 + y as f64 * 0.9).sin();
        if v.abs() < 0.25 {
            0.0f32
        } else {
            1.0
        }
    };
    let params = SeamParams::default();
    let mut g = c.benchmark_group("brush");
    g.sample_size(10);
    for (w, h) in [(256, 64), (300, 100)] {
        let a = Grid::from_fn(w, h, |x, y| ink(x, y, 0.0));
        let b = Grid::from_fn(w, h, |x, y| ink(x, y, 0.4));
        let cover = Grid::from_fn(w, h, |x, _| match x {
            x if x < 16 => Cover::A,
            x if x >= w - 16 => Cover::B,
            _ => Cover::Both,
        });
        g.bench_function(format!("graphcut/{w}x{h}"), |bch| {
            bch.iter(|| black_box(seam(&a, &b, &cover, &params).expect("cuts")))
        });
    }
    g.finish();
}

criterion_group!(benches, bench_matching, bench_arap, bench_graphcut);
criterion_main!(benches);
