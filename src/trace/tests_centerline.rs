//! Centerline tracing against drawings made from known paths: pencil-like
//! lines (2–5 px, soft edges, grain, uneven light) with X crossings, T
//! junctions, loops and gaps, read through the raster reader as a photo
//! would be.

use super::centerline::{trace_lines, Stroke};
use crate::read::ink::read_lines;
use crate::read::ImageOptions;
use kurbo::{BezPath, Point};

/// A drawn line: its centre (dense polyline, px) and width (px).
struct Drawn {
    pts: Vec<Point>,
    width: f64,
}

fn segment(a: Point, b: Point) -> Vec<Point> {
    let n = (a.distance(b) / 0.25).ceil().max(1.0) as usize;
    (0..=n).map(|i| a.lerp(b, i as f64 / n as f64)).collect()
}

fn arc(c: Point, r: f64, from: f64, to: f64) -> Vec<Point> {
    let n = ((to - from).abs() * r / 0.25).ceil().max(2.0) as usize;
    (0..=n)
        .map(|i| {
            let t = from + (to - from) * i as f64 / n as f64;
            Point::new(c.x + r * t.cos(), c.y + r * t.sin())
        })
        .collect()
}

fn dist_to(p: Point, pts: &[Point]) -> f64 {
    let mut best = f64::MAX;
    for s in pts.windows(2) {
        let (a, b) = (s[0], s[1]);
        let ab = b - a;
        let l2 = ab.hypot2();
        let t = if l2 > 0.0 {
            ((p - a).dot(ab) / l2).clamp(0.0, 1.0)
        } else {
            0.0
        };
        best = best.min(p.distance(a + ab * t));
    }
    if pts.len() == 1 {
        best = p.distance(pts[0]);
    }
    best
}

/// A small deterministic hash noise in [0, 1).
fn noise(x: usize, y: usize, seed: u64) -> f64 {
    let mut h = (x as u64).wrapping_mul(0x9E37_79B9_7F4A_7C15)
        ^ (y as u64).wrapping_mul(0xC2B2_AE3D_27D4_EB4F)
        ^ seed.wrapping_mul(0x1656_67B1_9E37_79F9);
    h ^= h >> 31;
    h = h.wrapping_mul(0xBF58_476D_1CE4_E5B9);
    h ^= h >> 29;
    (h >> 11) as f64 / (1u64 << 53) as f64
}

/// A grey PNG of `lines` on `w`×`h` paper: soft edges (a 1.5 px ramp),
/// pencil grain (each pixel's darkness 65–100 %), and light falling off
/// by a fifth towards one corner.
fn pencil_png(lines: &[Drawn], w: usize, h: usize, seed: u64) -> Vec<u8> {
    let mut img = image::GrayImage::new(w as u32, h as u32);
    for y in 0..h {
        for x in 0..w {
            let p = Point::new(x as f64 + 0.5, y as f64 + 0.5);
            let cov = lines
                .iter()
                .map(|l| ((0.5 * l.width - dist_to(p, &l.pts)) / 1.5 + 0.5).clamp(0.0, 1.0))
                .fold(0.0, f64::max);
            let dark = cov * (0.65 + 0.35 * noise(x, y, seed));
            let paper = 245.0 - 50.0 * (x as f64 / w as f64) * (y as f64 / h as f64);
            let v = paper * (1.0 - 0.85 * dark);
            img.put_pixel(x as u32, y as u32, image::Luma([v.round() as u8]));
        }
    }
    let mut bytes = Vec::new();
    img.write_to(
        &mut std::io::Cursor::new(&mut bytes),
        image::ImageFormat::Png,
    )
    .expect("PNG encodes");
    bytes
}

fn flatten(path: &BezPath) -> Vec<Point> {
    let mut pts = Vec::new();
    kurbo::flatten(path, 0.02, |el| match el {
        kurbo::PathEl::MoveTo(p) | kurbo::PathEl::LineTo(p) => pts.push(p),
        kurbo::PathEl::ClosePath => {
            if let Some(&f) = pts.first() {
                pts.push(f);
            }
        }
        _ => {}
    });
    pts
}

/// The larger of the two one-sided Hausdorff distances (px).
fn hausdorff(a: &[Point], b: &[Point]) -> f64 {
    let ab = a.iter().map(|&p| dist_to(p, b)).fold(0.0, f64::max);
    let ba = b.iter().map(|&p| dist_to(p, a)).fold(0.0, f64::max);
    ab.max(ba)
}

fn trace(lines: &[Drawn], w: usize, h: usize, seed: u64) -> Vec<Stroke> {
    let png = pencil_png(lines, w, h, seed);
    if let Ok(dir) = std::env::var("CENTERLINE_DUMP") {
        let _ = std::fs::write(format!("{dir}/{w}x{h}-{seed}.png"), &png);
    }
    let ink = read_lines(&png, &ImageOptions::default(), None).expect("drawing reads");
    trace_lines(&ink.coverage, None, 0.25, 4.0)
}

/// Every drawn line is one stroke within 1.5 px (Hausdorff, both ways) of
/// width within 1 px of the drawn one, and every other stroke is at most
/// two line widths long.
fn check(name: &str, lines: &[Drawn], w: usize, h: usize) {
    for seed in 1..=3 {
        let strokes = trace(lines, w, h, seed);
        let flat: Vec<Vec<Point>> = strokes.iter().map(|s| flatten(&s.path)).collect();
        let mut used = vec![false; strokes.len()];
        for (i, l) in lines.iter().enumerate() {
            let best = flat
                .iter()
                .enumerate()
                .map(|(k, f)| (hausdorff(&l.pts, f), k))
                .min_by(|a, b| a.0.total_cmp(&b.0));
            let Some((d, k)) = best else {
                panic!("{name} seed {seed}: no strokes");
            };
            let summary: Vec<String> = flat
                .iter()
                .map(|f| {
                    let (a, b) = (f[0], f[f.len() - 1]);
                    format!("({:.0},{:.0})-({:.0},{:.0})", a.x, a.y, b.x, b.y)
                })
                .collect();
            assert!(
                d <= 1.5,
                "{name} seed {seed}: line {i} is {d:.2} px from its nearest stroke \
                 (strokes {summary:?})"
            );
            assert!(
                (strokes[k].width - l.width).abs() <= 1.0,
                "{name} seed {seed}: line {i} {} px wide traced as {}",
                l.width,
                strokes[k].width
            );
            used[k] = true;
        }
        for (k, f) in flat.iter().enumerate() {
            let len: f64 = f.windows(2).map(|p| p[0].distance(p[1])).sum();
            let limit = 2.0 * lines.iter().map(|l| l.width).fold(0.0, f64::max);
            assert!(
                used[k] || len <= limit,
                "{name} seed {seed}: extra stroke {k} {len:.1} px long"
            );
        }
    }
}

#[test]
fn x_crossing_gives_two_straight_strokes() {
    for width in [2.5, 3.5, 5.0] {
        let lines = [
            Drawn {
                pts: segment(Point::new(20.0, 25.0), Point::new(140.0, 115.0)),
                width,
            },
            Drawn {
                pts: segment(Point::new(25.0, 120.0), Point::new(135.0, 20.0)),
                width,
            },
        ];
        check(&format!("X {width}"), &lines, 160, 140);
    }
}

#[test]
fn t_junction_ends_the_stem_on_the_bar() {
    for width in [2.0, 3.0, 4.5] {
        let lines = [
            Drawn {
                pts: segment(Point::new(20.0, 30.0), Point::new(150.0, 36.0)),
                width,
            },
            Drawn {
                pts: segment(Point::new(85.0, 33.0), Point::new(80.0, 130.0)),
                width,
            },
        ];
        check(&format!("T {width}"), &lines, 170, 150);
    }
}

#[test]
fn loops_and_curves_cross_through() {
    let width = 3.0;
    let tau = std::f64::consts::TAU;
    let wave: Vec<Point> = (0..=600)
        .map(|i| {
            let x = 15.0 + 170.0 * i as f64 / 600.0;
            Point::new(x, 100.0 + 30.0 * (x / 25.0).sin())
        })
        .collect();
    let lines = [
        Drawn {
            pts: arc(Point::new(70.0, 90.0), 40.0, 0.0, tau),
            width,
        },
        Drawn { pts: wave, width },
        Drawn {
            pts: arc(Point::new(150.0, 42.0), 25.0, 0.3, 4.5),
            width,
        },
    ];
    check("loops", &lines, 200, 170);
}

/// A 4-px line from (20, 40) to (160, 60) broken by a gap of `gap` px
/// between its inks (round ends), drawn in pencil with `seed`, traced.
fn broken_line(gap: f64, seed: u64) -> (Vec<Point>, Vec<Stroke>) {
    let width = 4.0;
    let whole = segment(Point::new(20.0, 40.0), Point::new(160.0, 60.0));
    let along = (whole[250] - whole[240]) * ((width + gap) / whole[240].distance(whole[250]));
    let png = pencil_png(
        &[
            Drawn {
                pts: segment(Point::new(20.0, 40.0), whole[240]),
                width,
            },
            Drawn {
                pts: segment(whole[240] + along, Point::new(160.0, 60.0)),
                width,
            },
        ],
        180,
        100,
        seed,
    );
    let ink = read_lines(&png, &ImageOptions::default(), None).expect("drawing reads");
    (whole, trace_lines(&ink.coverage, None, 0.25, 4.0))
}

#[test]
fn gaps_shorter_than_the_width_are_bridged() {
    for seed in 1..=3 {
        let (whole, strokes) = broken_line(2.5, seed);
        assert_eq!(strokes.len(), 1, "seed {seed}: the 2.5-px gap is bridged");
        assert!(hausdorff(&whole, &flatten(&strokes[0].path)) <= 1.5);
    }
}

#[test]
fn gaps_of_two_widths_stay_open() {
    for seed in 1..=3 {
        let (_, strokes) = broken_line(8.0, seed);
        assert_eq!(strokes.len(), 2, "seed {seed}: the 8-px gap stays open");
    }
}

#[test]
fn given_width_overrides_and_blank_paper_gives_no_strokes() {
    let lines = [Drawn {
        pts: segment(Point::new(10.0, 10.0), Point::new(90.0, 50.0)),
        width: 3.0,
    }];
    let png = pencil_png(&lines, 100, 60, 1);
    let ink = read_lines(&png, &ImageOptions::default(), Some(7.5)).expect("reads");
    let strokes = trace_lines(&ink.coverage, ink.stroke_width, 0.25, 4.0);
    assert_eq!(strokes.len(), 1);
    assert_eq!(strokes[0].width, 7.5);
    let blank = pencil_png(&[], 100, 60, 1);
    let ink = read_lines(&blank, &ImageOptions::default(), None).expect("reads");
    assert!(trace_lines(&ink.coverage, None, 0.25, 4.0).is_empty());
}

/// Paper to ornament without `--width`: a pencil drawing's lines (3 and
/// 5 px) become queries widened together until the median is a 24th of
/// the page's shorter side, in proportion; with `--width`, exactly that.
#[test]
fn a_drawing_sketch_is_widened_for_ornament_unless_a_width_is_given() {
    let lines = [
        Drawn {
            pts: segment(Point::new(20.0, 30.0), Point::new(220.0, 40.0)),
            width: 3.0,
        },
        Drawn {
            pts: segment(Point::new(20.0, 120.0), Point::new(220.0, 150.0)),
            width: 5.0,
        },
    ];
    let (w, h) = (240, 192);
    let png = pencil_png(&lines, w, h, 2);
    let widths = |sk: &crate::Sketch| -> Vec<f64> {
        sk.queries
            .iter()
            .filter_map(|q| match q.kind {
                crate::read::sketch::QueryKind::Path { width, .. } => Some(width),
                _ => None,
            })
            .collect()
    };
    let measured = trace(&lines, w, h, 2);
    assert_eq!(measured.len(), 2);
    let sk = crate::sketch_from_drawing(&png, None).expect("drawing reads");
    let got = widths(&sk);
    assert_eq!(got.len(), 2);
    // The median of two is the wider line's (index len / 2).
    let target = h as f64 / 24.0;
    let k = target / measured[0].width.max(measured[1].width);
    for (g, m) in got.iter().zip(&measured) {
        assert!((g - k * m.width).abs() < 1e-9, "{g} vs {k} × {}", m.width);
    }
    assert!(got.iter().cloned().fold(0.0, f64::max) - target < 1e-9);
    assert!(
        sk.notes.iter().any(|n| n.contains("widened")),
        "{:?}",
        sk.notes
    );
    let sk = crate::sketch_from_drawing(&png, Some(6.0)).expect("drawing reads");
    assert_eq!(widths(&sk), vec![6.0, 6.0]);
    assert!(!sk.notes.iter().any(|n| n.contains("widened")));
}
