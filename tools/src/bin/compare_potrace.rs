//! Prints a markdown table comparing `flourish trace` (default options) with
//! potrace (`potrace -s`, default options but for the speck size, set to
//! drop what flourish drops: `-t 3` against `--min-area 4`; on the 50
//! %-thresholded bitmap) on every sample in `samples/trace` and every
//! bitmap of the third-party art's `trace/` folder (`$FLOURISH_ART`, else
//! `../shared/art`) when it is there: segments, max deviation from the
//! vector ground truth (symmetric Hausdorff, px; samples only unless
//! `--art-deviation`), IoU with the thresholded bitmap, and the time of the
//! whole commands, pairwise (see `time_commands` in the support module):
//! the median of RUNS pairs' ratios (default 7), with the median and the
//! worst ratio over all bitmaps at the end.
//!
//! ```text
//! cargo build --release
//! cargo run --release -p flourish-tools --bin compare_potrace [-- RUNS [--art-deviation]]
//! ```
//!
//! The measurement code is shared with `tests/potrace.rs`
//! (`tests/support/mod.rs`, where the ground truth and the distance are
//! documented). flourish is timed as the process `target/release/flourish`
//! (`$FLOURISH_BIN`) reading the PNG; potrace as a process reading the PBM,
//! written beforehand.

#[path = "../../../tests/support/mod.rs"]
mod support;

use std::path::PathBuf;

fn main() {
    if !support::potrace_available() {
        eprintln!("potrace not found: apt-get install potrace");
        std::process::exit(1);
    }
    let args: Vec<String> = std::env::args().skip(1).collect();
    if args.first().map(String::as_str) == Some("--explain") {
        let name = args.get(1).expect("--explain NAME.png OUTDIR");
        let dir = std::path::PathBuf::from(args.get(2).map(String::as_str).unwrap_or("."));
        let at = match (args.get(3), args.get(4)) {
            (Some(x), Some(y)) => Some(kurbo::Point::new(
                x.parse().expect("X"),
                y.parse().expect("Y"),
            )),
            _ => None,
        };
        let half: f64 = args.get(5).and_then(|h| h.parse().ok()).unwrap_or(24.0);
        explain(name, &dir, at, half);
        return;
    }
    if !support::flourish_bin().exists() {
        eprintln!(
            "{} not found: cargo build --release first",
            support::flourish_bin().display()
        );
        std::process::exit(1);
    }
    let runs: usize = args.first().and_then(|s| s.parse().ok()).unwrap_or(7);
    let art_deviation = args.iter().any(|a| a == "--art-deviation");
    let pngs = |dir: PathBuf| -> Vec<PathBuf> {
        let mut v: Vec<PathBuf> = std::fs::read_dir(&dir)
            .map(|d| d.filter_map(|e| e.ok()).map(|e| e.path()).collect())
            .unwrap_or_default();
        v.retain(|p| p.extension().is_some_and(|e| e == "png"));
        v.sort();
        v
    };
    let mut files: Vec<(PathBuf, bool)> = pngs(support::root().join("samples/trace"))
        .into_iter()
        // flourish traces every ink of a picture in several (the light gold
        // disc too), potrace's threshold only the dark ones.
        .filter(|p| !p.to_string_lossy().contains("two-colour"))
        .map(|p| (p, true))
        .collect();
    let art = std::env::var_os("FLOURISH_ART")
        .map(PathBuf::from)
        .unwrap_or_else(|| support::root().join("../shared/art"));
    files.extend(
        pngs(art.join("trace"))
            .into_iter()
            .map(|p| (p, art_deviation)),
    );
    println!("Whole commands, {runs} pairs each (flourish and potrace back to back, alternating which goes first), after one untimed run of each; time ratio: median of the pairs' flourish/potrace; ms: medians. potrace -t {}; deviations are symmetric Hausdorff distances (px) to the SVG ground truth (— where not measured); IoU: rendered output vs 50 %-thresholded input.\n", support::potrace_turdsize());
    println!("| file | size | flourish segments | potrace segments | segment ratio | flourish max dev | potrace max dev | flourish ms | potrace ms | time ratio | flourish IoU | potrace IoU |");
    println!("|---|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|");
    let (mut fs, mut ps) = (0usize, 0usize);
    let mut ratios = Vec::new();
    let dev = |d: Option<f64>| d.map_or("—".to_string(), |d| format!("{d:.3}"));
    for (png, deviation) in &files {
        let c = support::compare_file(png, runs, *deviation);
        fs += c.flourish_segments;
        ps += c.potrace_segments;
        ratios.push((c.times.ratio, c.name.clone()));
        println!(
            "| {} | {}x{} | {} | {} | {:.3} | {} | {} | {:.1} | {:.1} | {:.2} | {:.4} | {:.4} |",
            c.name,
            c.width,
            c.height,
            c.flourish_segments,
            c.potrace_segments,
            c.flourish_segments as f64 / c.potrace_segments as f64,
            dev(c.flourish_dev),
            dev(c.potrace_dev),
            c.times.flourish.as_secs_f64() * 1e3,
            c.times.potrace.as_secs_f64() * 1e3,
            c.times.ratio,
            c.flourish_iou,
            c.potrace_iou,
        );
    }
    ratios.sort_by(|a, b| a.0.total_cmp(&b.0));
    if let (Some(mid), Some(worst)) = (ratios.get(ratios.len() / 2), ratios.last()) {
        println!(
            "\nAll {} bitmaps: flourish {fs} segments, potrace {ps} (ratio {:.3}); time ratio median {:.2}, worst {:.2} ({}). Ratios are flourish / potrace.",
            ratios.len(),
            fs as f64 / ps as f64,
            mid.0,
            worst.0,
            worst.1,
        );
    }
}

/// `--explain NAME.png OUTDIR [X Y [HALF]]`: where each tracer deviates most.
/// Prints the worst points of both directions and the truth regions missed
/// by more than 1.5 px, and writes 8× magnified crops around them (or only
/// around (X, Y) when given, HALF px either side, default 24) (`OUTDIR/NAME-K.png`: input bitmap grey, truth
/// green, flourish red, potrace blue, each tracer's on-curve nodes as dots
/// of its colour).
fn explain(name: &str, dir: &std::path::Path, at: Option<kurbo::Point>, half: f64) {
    use kurbo::{Point, Rect};
    use resvg::tiny_skia;
    std::fs::create_dir_all(dir).unwrap();
    let png = support::sample(name);
    let bitmap = image::open(&png).unwrap().to_luma8();
    let truth = support::ground_truth(&support::truth_svg_for(&png));
    let (doc, _) = support::run_flourish(&png, 1);
    std::fs::write(dir.join(format!("{name}.flourish.svg")), doc.to_svg()).unwrap();
    let fpaths = support::doc_paths(&doc);
    let (ppaths, _, _) = support::run_potrace(&bitmap, 1);
    let mut spots: Vec<(String, Point)> = Vec::new();
    for (label, paths) in [("flourish", &fpaths), ("potrace", &ppaths)] {
        let ((a, pa), (b, pb)) = support::worst_points(paths, &truth);
        println!("{label}: output→truth {a:.3} px at ({:.1}, {:.1}); truth→output {b:.3} px at ({:.1}, {:.1})", pa.x, pa.y, pb.x, pb.y);
        spots.push((format!("{label} out→truth {a:.2}"), pa));
        spots.push((format!("{label} truth→out {b:.2}"), pb));
        let far = support::far_truth_points(paths, &truth, 1.5, 24.0);
        println!(
            "  {} truth regions (24 px cells) farther than 1.5 px from {label}; worst:",
            far.len()
        );
        for (d, p) in far.iter().take(8) {
            println!("    {d:.2} px at ({:.1}, {:.1})", p.x, p.y);
        }
        for (d, p) in far.iter().take(3) {
            spots.push((format!("{label} missed {d:.2}"), *p));
        }
    }
    if let Some(p) = at {
        spots = vec![("requested".to_string(), p)];
    }
    let nodes = |paths: &[kurbo::BezPath]| -> Vec<Point> {
        paths
            .iter()
            .flat_map(|p| p.segments().map(|s| kurbo::ParamCurve::start(&s)))
            .collect()
    };
    let (nodes_f, nodes_p) = (nodes(&fpaths), nodes(&ppaths));
    let flat_f = support::flatten_paths(&fpaths);
    let flat_p = support::flatten_paths(&ppaths);
    for (k, (label, c)) in spots.iter().enumerate() {
        let z = (192.0 / half) as f32;
        let view = Rect::new(c.x - half, c.y - half, c.x + half, c.y + half);
        let side = (2.0 * half as f32 * z) as u32;
        let mut pm = tiny_skia::Pixmap::new(side, side).unwrap();
        pm.fill(tiny_skia::Color::WHITE);
        let mut paint = tiny_skia::Paint::default();
        paint.set_color_rgba8(200, 200, 200, 255);
        for y in view.y0.floor().max(0.0) as u32..(view.y1.ceil() as u32).min(bitmap.height()) {
            for x in view.x0.floor().max(0.0) as u32..(view.x1.ceil() as u32).min(bitmap.width()) {
                if bitmap.get_pixel(x, y)[0] < 128 {
                    let r = tiny_skia::Rect::from_xywh(
                        (x as f64 - view.x0) as f32 * z,
                        (y as f64 - view.y0) as f32 * z,
                        z,
                        z,
                    );
                    if let Some(r) = r {
                        pm.fill_rect(r, &paint, tiny_skia::Transform::identity(), None);
                    }
                }
            }
        }
        for (lines, rgb, w) in [
            (&truth, (0, 160, 0), 3.0),
            (&flat_f, (220, 0, 0), 1.5),
            (&flat_p, (0, 0, 255), 1.5),
        ] {
            let mut pb = tiny_skia::PathBuilder::new();
            for l in lines.iter() {
                if !(view.contains(l.p0) || view.contains(l.p1)) {
                    continue;
                }
                pb.move_to(
                    ((l.p0.x - view.x0) as f32) * z,
                    ((l.p0.y - view.y0) as f32) * z,
                );
                pb.line_to(
                    ((l.p1.x - view.x0) as f32) * z,
                    ((l.p1.y - view.y0) as f32) * z,
                );
            }
            if let Some(path) = pb.finish() {
                let mut paint = tiny_skia::Paint::default();
                paint.set_color_rgba8(rgb.0, rgb.1, rgb.2, 255);
                paint.anti_alias = true;
                let stroke = tiny_skia::Stroke {
                    width: w,
                    ..Default::default()
                };
                pm.stroke_path(
                    &path,
                    &paint,
                    &stroke,
                    tiny_skia::Transform::identity(),
                    None,
                );
            }
        }
        for (pts, rgb) in [(&nodes_f, (220, 0, 0)), (&nodes_p, (0, 0, 255))] {
            let mut paint = tiny_skia::Paint::default();
            paint.set_color_rgba8(rgb.0, rgb.1, rgb.2, 255);
            for p in pts.iter().filter(|p| view.contains(**p)) {
                let r = tiny_skia::Rect::from_xywh(
                    ((p.x - view.x0) as f32) * z - 4.0,
                    ((p.y - view.y0) as f32) * z - 4.0,
                    8.0,
                    8.0,
                );
                if let Some(r) = r {
                    pm.fill_rect(r, &paint, tiny_skia::Transform::identity(), None);
                }
            }
        }
        let out = dir.join(format!("{name}-{k}.png"));
        pm.save_png(&out).unwrap();
        println!("{}: {label} around ({:.1}, {:.1})", out.display(), c.x, c.y);
    }
}
