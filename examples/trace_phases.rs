//! Times the stages of tracing one binary bitmap (default: the 2 Mpx
//! ornament), median of RUNS runs each (and the fastest fit), in
//! milliseconds:
//!
//! ```text
//! cargo run --release --example trace_phases [-- FILE.png [RUNS]]
//! ```

use flourish::outline::{corridor::Corridor, paths, smooth as binary};
use flourish::raster::Grid;
use flourish::read::ink as input;
use flourish::trace::{self, TraceOptions};
use std::time::Instant;

fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(|a, b| a.total_cmp(b));
    v[v.len() / 2]
}

fn time<T>(runs: usize, mut f: impl FnMut() -> T) -> (f64, T) {
    let mut ts = Vec::new();
    let mut out = None;
    for _ in 0..runs {
        let t = Instant::now();
        out = Some(f());
        ts.push(t.elapsed().as_secs_f64() * 1e3);
    }
    (median(ts), out.expect("runs > 0"))
}

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let path = std::path::PathBuf::from(
        args.first()
            .map(String::as_str)
            .unwrap_or("samples/trace/ornament-2mp.png"),
    );
    let runs: usize = args
        .get(1)
        .and_then(|s| s.parse().ok())
        .unwrap_or(11)
        .max(1);
    let bytes = std::fs::read(&path).expect("read");
    let (t_decode, img) = time(runs, || {
        input::decode_raster(&path, &bytes).expect("decode")
    });
    let grey = img.to_luma8();
    let (w, h) = (grey.width() as usize, grey.height() as usize);
    let cov = Grid::from_vec(
        w,
        h,
        grey.as_raw()
            .iter()
            .map(|&v| if v < 128 { 1.0 } else { 0.0 })
            .collect(),
    )
    .expect("sizes");
    let bits = paths::Bitmap::from_coverage(&cov);
    let (t_extract, _) = time(runs, || paths::paths(&bits));
    let (t_loops, loops) = time(runs, || binary::smooth_loops(&cov));
    let (t_corr, corr) = time(runs, || Corridor::new(&cov));
    let opts = TraceOptions::default();
    let (t_fit, _) = time(runs, || trace::trace_outline(&loops, Some(&corr), &opts));
    // The fastest fit too: on a shared machine the median moves with the
    // load, the fastest run much less.
    let fit_min = (0..runs)
        .map(|_| {
            let t = Instant::now();
            let _ = trace::trace_outline(&loops, Some(&corr), &opts);
            t.elapsed().as_secs_f64() * 1e3
        })
        .fold(f64::INFINITY, f64::min);
    let (t_all, _) = time(runs, || {
        trace::trace_file(&path, &input::InputOptions::default(), &opts).expect("trace")
    });
    let all_min = (0..runs)
        .map(|_| {
            let t = Instant::now();
            let _ = trace::trace_file(&path, &input::InputOptions::default(), &opts);
            t.elapsed().as_secs_f64() * 1e3
        })
        .fold(f64::INFINITY, f64::min);
    if std::env::var_os("TRACE_PHASES_LOOPS").is_some() {
        let mut sizes: Vec<(f64, usize, usize)> = loops
            .iter()
            .map(|l| {
                let t = Instant::now();
                let _ = trace::trace_outline(std::slice::from_ref(l), Some(&corr), &opts);
                (
                    t.elapsed().as_secs_f64() * 1e3,
                    l.points.len(),
                    l.corners.len(),
                )
            })
            .collect();
        sizes.sort_by(|a, b| b.0.total_cmp(&a.0));
        for (ms, n, c) in sizes.iter().take(8) {
            println!("loop: {ms:.2} ms, {n} points, {c} corners");
        }
    }
    println!(
        "decode {t_decode:.1} ms, paths {t_extract:.1} ms, smooth_loops {t_loops:.1} ms, corridor {t_corr:.1} ms, fit {t_fit:.1} ms (fastest {fit_min:.1}), trace_file {t_all:.1} ms (fastest {all_min:.1}; {} loops)",
        loops.len()
    );
}
