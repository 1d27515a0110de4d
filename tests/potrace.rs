//! flourish against potrace on the binary samples: flourish must be at
//! least as accurate (symmetric Hausdorff distance to the vector ground
//! truth) and at least as compact (segments), and its output must
//! reproduce the input bitmap (IoU ≥ 0.99 after rendering and 50 %
//! thresholding). The anti-aliased samples, which flourish reads with
//! their coverage, are held against potrace on their thresholded bitmaps.
//!
//! Needs the `potrace` binary (Debian package `potrace`): when it is
//! missing the test fails under `CI`, else it is skipped loudly.
//! Figures go to stderr: `cargo test --release --test potrace -- --nocapture`.

mod support;

use support::compare;

const BINARY_SAMPLES: [&str; 4] = [
    "glyph-a-binary.png",
    "ornament-scroll-binary.png",
    "thin-lines-binary.png",
    "ornament-2mp.png",
];

/// The target: at least as accurate and as compact as potrace on
/// every binary sample, at the same speck size, and IoU ≥ 0.99 with the
/// input bitmap. Segments are met on every binary sample (0.75× to 0.96×
/// potrace's) and the symmetric deviation too (2 Mpx 15.0 vs 16.3 px,
/// glyph 1.02 vs 1.15); not met: IoU ≥ 0.99 on the thin shapes (thin
/// lines 0.925, scroll 0.977, 2 Mpx 0.974; all above potrace's, 0.856,
/// 0.964 and 0.959); run with `--ignored`.
#[test]
#[ignore = "target not yet met on every sample: IoU 0.99 on thin lines and ornaments; see README benchmark table"]
fn flourish_beats_potrace_on_binary_samples() {
    if !potrace_here("flourish_beats_potrace_on_binary_samples") {
        return;
    }
    let mut failures = Vec::new();
    for name in BINARY_SAMPLES {
        let c = compare(name, 1);
        eprintln!(
            "{name} ({}x{}): segments flourish {} / potrace {} | max deviation flourish {:.3} px (out→truth {:.3}, truth→out {:.3}) / potrace {:.3} px (out→truth {:.3}, truth→out {:.3}) | IoU flourish {:.5} / potrace {:.5}",
            c.width,
            c.height,
            c.flourish_segments,
            c.potrace_segments,
            c.flourish_dev,
            c.flourish_dev_dir.0,
            c.flourish_dev_dir.1,
            c.potrace_dev,
            c.potrace_dev_dir.0,
            c.potrace_dev_dir.1,
            c.flourish_iou,
            c.potrace_iou,
        );
        if c.flourish_dev > c.potrace_dev {
            failures.push(format!(
                "{name}: flourish max deviation {:.3} px > potrace {:.3} px",
                c.flourish_dev, c.potrace_dev
            ));
        }
        if c.flourish_segments > c.potrace_segments {
            failures.push(format!(
                "{name}: flourish {} segments > potrace {}",
                c.flourish_segments, c.potrace_segments
            ));
        }
        if c.flourish_iou < 0.99 {
            failures.push(format!(
                "{name}: flourish IoU with the input bitmap {:.5} < 0.99",
                c.flourish_iou
            ));
        }
    }
    assert!(
        failures.is_empty(),
        "flourish loses to potrace:\n  {}",
        failures.join("\n  ")
    );
}

/// How much farther than potrace's flourish's curves may stray from the
/// true outline, px. A binary bitmap fixes an edge only to ±0.5 px; where
/// the drawing has a cusp or a 3-px line end, the smooth reading of the
/// staircase (see `outline::smooth`) and potrace's differ by up to this much
/// in either direction (flourish is closer on three of the four samples).
const DEVIATION_ALLOWANCE: f64 = 0.2;

/// What holds today, guarded against regressions: flourish's curves stay
/// as close to the true outline as potrace's (within
/// [`DEVIATION_ALLOWANCE`]), its render matches the input bitmap at least
/// as well as potrace's, it uses no more segments than potrace over the
/// binary samples, and at most 0.8× potrace's on the 2 Mpx ornament (the
/// issue's target).
#[test]
fn flourish_stays_level_with_potrace() {
    if !potrace_here("flourish_stays_level_with_potrace") {
        return;
    }
    let (mut ours, mut theirs) = (0usize, 0usize);
    for name in BINARY_SAMPLES {
        let c = compare(name, 1);
        print_comparison(name, &c);
        ours += c.flourish_segments;
        theirs += c.potrace_segments;
        // Per sample, no more segments than potrace (the polygon's
        // potrace-like straight runs and mitres: thin-lines-binary 242 vs
        // 246, the tightest).
        assert!(
            c.flourish_segments <= c.potrace_segments,
            "{name}: {} segments, potrace {}",
            c.flourish_segments,
            c.potrace_segments
        );
        // The deviation goal, both ways (symmetric Hausdorff to the
        // vector truth), at the same speck size: the binary glyph 0.97 vs
        // 1.15 px, the 2 Mpx ornament 15.0 vs 16.3 (a tendril the bitmap
        // holds only as dust that both drop), the binary scroll level
        // (12.08 both, its far point the same dust); within the measure's
        // accuracy (support: about ±0.06 px).
        assert!(
            c.flourish_dev <= c.potrace_dev + 0.05,
            "{name}: symmetric deviation {:.3} px > potrace {:.3}",
            c.flourish_dev,
            c.potrace_dev
        );
        if name == "ornament-2mp.png" {
            assert!(
                c.flourish_segments * 5 <= c.potrace_segments * 4,
                "{name}: {} segments, potrace {}: more than 0.8×",
                c.flourish_segments,
                c.potrace_segments
            );
        }
        assert!(
            c.flourish_dev_dir.0 <= c.potrace_dev_dir.0 + DEVIATION_ALLOWANCE,
            "{name}: flourish strays {:.3} px from the outline, potrace {:.3}",
            c.flourish_dev_dir.0,
            c.potrace_dev_dir.0
        );
        assert!(
            c.flourish_iou >= c.potrace_iou,
            "{name}: IoU {:.4} < potrace {:.4}",
            c.flourish_iou,
            c.potrace_iou
        );
    }
    assert!(
        ours <= theirs,
        "{ours} segments, potrace {theirs}: more than potrace"
    );
}

/// The anti-aliased samples, traced from their coverage, against potrace
/// on the same pictures thresholded at one half: no more segments on any
/// (thin lines 243 vs 246, the tightest, since the cut-off apexes of its
/// zigzags get their points back), curves closer to the drawing than
/// potrace's (output→truth; the far side, truth→output, is the dust of
/// hairline tips both lose), and a render at least as close to the
/// thresholded picture.
#[test]
fn anti_aliased_samples_stay_level_with_potrace() {
    if !potrace_here("anti_aliased_samples_stay_level_with_potrace") {
        return;
    }
    let samples = [
        "glyph-a.png",
        "glyph-g.png",
        "glyph-s.png",
        "holes.png",
        "ornament-rosette.png",
        "ornament-scroll.png",
        "thin-lines.png",
        // Not two-colour.png: flourish traces every ink of a picture in
        // several (the light gold disc too), potrace's threshold only the
        // dark ones, so the two trace different shapes.
    ];
    for name in samples {
        let c = compare(name, 1);
        print_comparison(name, &c);
        assert!(
            c.flourish_segments <= c.potrace_segments,
            "{name}: {} segments, potrace {}",
            c.flourish_segments,
            c.potrace_segments
        );
        assert!(
            c.flourish_dev_dir.0 <= c.potrace_dev_dir.0,
            "{name}: flourish strays {:.3} px from the drawing, potrace {:.3}",
            c.flourish_dev_dir.0,
            c.potrace_dev_dir.0
        );
        assert!(
            c.flourish_iou >= c.potrace_iou,
            "{name}: IoU {:.4} < potrace {:.4}",
            c.flourish_iou,
            c.potrace_iou
        );
    }
}

/// One comparison's figures on stderr.
fn print_comparison(name: &str, c: &support::Comparison) {
    eprintln!(
        "{name}: segments {} vs potrace {}; out→truth {:.3} vs {:.3} px; IoU {:.4} vs {:.4}",
        c.flourish_segments,
        c.potrace_segments,
        c.flourish_dev_dir.0,
        c.potrace_dev_dir.0,
        c.flourish_iou,
        c.potrace_iou
    );
}

/// Whether potrace is installed; without it a comparison fails under `CI`
/// and is skipped loudly elsewhere.
fn potrace_here(test: &str) -> bool {
    if support::potrace_available() {
        return true;
    }
    let msg = "potrace not found: install it (apt-get install potrace) to compare flourish with it";
    if std::env::var_os("CI").is_some() {
        panic!("{msg}");
    }
    eprintln!("\n!!!!!!!! SKIPPED {test}: {msg} !!!!!!!!\n");
    false
}

/// The measuring stick itself: a disc traced by an exact circle has
/// (nearly) zero deviation, and a shifted one deviates by the shift.
#[test]
fn hausdorff_of_known_shapes() {
    use kurbo::{Circle, Shape};
    let truth_path = Circle::new((50.0, 50.0), 20.0).to_path(1e-4);
    let mut truth = Vec::new();
    support::flatten_segments(&truth_path, 0.001, &mut truth);
    let same = Circle::new((50.0, 50.0), 20.0).to_path(1e-4);
    let d = support::max_deviation(&[same], &truth);
    assert!(d < 0.02, "{d}");
    let shifted = Circle::new((50.3, 50.0), 20.0).to_path(1e-4);
    let d = support::max_deviation(&[shifted], &truth);
    assert!((d - 0.3).abs() < 0.02, "{d}");
    let bigger = Circle::new((50.0, 50.0), 21.0).to_path(1e-4);
    let d = support::max_deviation(&[bigger], &truth);
    assert!((d - 1.0).abs() < 0.02, "{d}");
}

/// The ground truth of an even-odd target is all its rings, and potrace's
/// paths land in pixel coordinates (bounding box of the bitmap's ink).
#[test]
fn ground_truth_and_potrace_coordinates() {
    let svg = support::sample("glyph-a.svg");
    let truth = support::ground_truth(&svg);
    assert!(!truth.is_empty());
    // Every truth point is within the 512 px canvas.
    for l in &truth {
        for p in [l.p0, l.p1] {
            assert!(
                p.x >= 0.0 && p.x <= 512.0 && p.y >= 0.0 && p.y <= 512.0,
                "{p:?}"
            );
        }
    }
    if !support::potrace_available() {
        eprintln!("!!!!!!!! potrace not found: coordinate check skipped !!!!!!!!");
        return;
    }
    let bitmap = image::open(support::sample("glyph-a-binary.png"))
        .unwrap()
        .to_luma8();
    let (paths, segs, _) = support::run_potrace(&bitmap, 1);
    assert!(segs > 0);
    let mut bb = kurbo::Rect::new(f64::MAX, f64::MAX, f64::MIN, f64::MIN);
    for p in &paths {
        bb = bb.union(kurbo::Shape::bounding_box(p));
    }
    let (mut x0, mut y0, mut x1, mut y1) = (u32::MAX, u32::MAX, 0, 0);
    for (x, y, p) in bitmap.enumerate_pixels() {
        if p[0] < 128 {
            x0 = x0.min(x);
            y0 = y0.min(y);
            x1 = x1.max(x + 1);
            y1 = y1.max(y + 1);
        }
    }
    let ink = kurbo::Rect::new(x0 as f64, y0 as f64, x1 as f64, y1 as f64);
    for (a, b) in [
        (bb.x0, ink.x0),
        (bb.y0, ink.y0),
        (bb.x1, ink.x1),
        (bb.y1, ink.y1),
    ] {
        assert!(
            (a - b).abs() < 1.0,
            "potrace bbox {bb:?} vs ink bbox {ink:?}"
        );
    }
}
