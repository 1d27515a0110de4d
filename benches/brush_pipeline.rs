//! Criterion benchmarks of the whole `flourish brush` pipeline, by stage:
//! one S-curve stroke about 8 stroke widths long in the vine style at
//! exemplar resolution 256 and 512 (copies of the shipped style with
//! their `resolution` set). Stages: initialization (query → matching → ARAP →
//! coordinate fields → seams), synthesis (correction and upsampling over
//! the levels), output (per-layer SDFs, debris removal, tracing), and the
//! whole sketch. Style analysis is cached and kept out of the timings.
//! `cargo bench --bench brush_pipeline -- --warm-up-time 1 --measurement-time 3`.

use criterion::{criterion_group, criterion_main, Criterion};
use flourish::brush::analysis::{AnalysisOptions, BrushStyle};
use flourish::brush::output::{brush_sketch, prepared_spines, trace_query};
use flourish::brush::pipeline::{coarse_init, BrushOptions};
use flourish::brush::synth::{self, SynthOptions};
use flourish::trace::TraceOptions;
use std::hint::black_box;
use std::path::{Path, PathBuf};

/// The shipped vine style with its `resolution` replaced.
fn vine_at(resolution: u32, tmp: &Path) -> PathBuf {
    let src = Path::new(env!("CARGO_MANIFEST_DIR")).join("styles/vine");
    let dst = tmp.join(format!("vine-{resolution}"));
    std::fs::create_dir_all(&dst).expect("temp style folder");
    for entry in std::fs::read_dir(&src).expect("vine style").flatten() {
        let p = entry.path();
        let name = p.file_name().expect("a file name");
        if name == "style.toml" {
            let text = std::fs::read_to_string(&p).expect("style.toml");
            let text: String = text
                .lines()
                .map(|l| {
                    if l.trim_start().starts_with("resolution") {
                        format!("resolution = {resolution}\n")
                    } else {
                        format!("{l}\n")
                    }
                })
                .collect();
            std::fs::write(dst.join(name), text).expect("writes style.toml");
        } else {
            std::fs::copy(&p, dst.join(name)).expect("copies an exemplar");
        }
    }
    dst
}

fn bench_pipeline(c: &mut Criterion) {
    let tmp = std::env::temp_dir().join("flourish-bench-styles");
    let analysis = AnalysisOptions {
        cache_dir: Some(std::env::temp_dir().join("flourish-bench-cache")),
        ..AnalysisOptions::default()
    };
    let sketch_path = Path::new(env!("CARGO_MANIFEST_DIR")).join("samples/brush/s-curve.svg");
    let sketch = flourish::read::sketch::load(&sketch_path).expect("sample");
    let opts = BrushOptions::default();
    let mut g = c.benchmark_group("brush-pipeline");
    g.sample_size(10);
    for res in [256u32, 512] {
        let style = BrushStyle::load(&vine_at(res, &tmp), &analysis).expect("style");
        let spines = prepared_spines(&sketch, &opts).expect("spines").0;
        let q = &spines[0];
        let init = coarse_init(&style, q, &opts).expect("init");
        g.bench_function(format!("s-curve-{res}/init"), |b| {
            b.iter(|| black_box(coarse_init(&style, q, &opts).expect("init")))
        });
        g.bench_function(format!("s-curve-{res}/synthesis"), |b| {
            b.iter(|| {
                black_box(synth::synthesize(
                    &style,
                    init.clone(),
                    &SynthOptions::default(),
                ))
            })
        });
        let r = flourish::brush::pipeline::brush_query(&style, q, &opts).expect("query");
        g.bench_function(format!("s-curve-{res}/output"), |b| {
            b.iter(|| {
                black_box(trace_query(
                    &style,
                    &r,
                    "q".into(),
                    &TraceOptions::default(),
                ))
            })
        });
        g.bench_function(format!("s-curve-{res}/total"), |b| {
            b.iter(|| black_box(brush_sketch(&style, &sketch, &opts).expect("brushes")))
        });
    }
    g.finish();
}

criterion_group!(benches, bench_pipeline);
criterion_main!(benches);
