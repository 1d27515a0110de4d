//! The brush style analysis on small styles: the cache (hit, miss,
//! corrupt files rebuilt), rotation invariance of the orientation field
//! and the neighbourhoods, and PNG exemplars.

use super::cache::CacheStatus;
use super::{AnalysisOptions, BrushStyle};
use std::path::{Path, PathBuf};

fn fixture(name: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("tests/fixtures/wavy")
        .join(name)
}

/// The wavy two-exemplar style of `tests/fixtures/wavy` in `dir`.
fn small_style(dir: &Path) {
    std::fs::create_dir_all(dir).unwrap();
    for name in ["style.toml", "a.svg", "b.svg"] {
        std::fs::copy(fixture(name), dir.join(name)).unwrap();
    }
}

#[test]
fn cache_hits_misses_and_rebuilds_corrupt_files() {
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path().join("wavy");
    small_style(&dir);
    let opts = AnalysisOptions {
        cache_dir: Some(tmp.path().join("cache")),
        ..AnalysisOptions::default()
    };
    let (first, st) = BrushStyle::load_with_status(&dir, &opts).unwrap();
    assert_eq!(st, CacheStatus::Miss);
    let bytes = postcard::to_stdvec(&first).unwrap();
    let (second, st) = BrushStyle::load_with_status(&dir, &opts).unwrap();
    assert_eq!(st, CacheStatus::Hit);
    assert_eq!(postcard::to_stdvec(&second).unwrap(), bytes);
    // The cached index answers like the fresh one.
    let q = first.neighbourhood(2, first.indexes[2].refs[7]).unwrap();
    assert_eq!(second.indexes[2].nearest(&q), first.indexes[2].nearest(&q));

    let files: Vec<_> = std::fs::read_dir(tmp.path().join("cache"))
        .unwrap()
        .map(|e| e.unwrap().path())
        .collect();
    assert_eq!(files.len(), 1, "{files:?}");
    let file = &files[0];
    let good = std::fs::read(file).unwrap();
    // Truncated, garbage, a run of flipped bytes deep inside, 16 single
    // bytes flipped at spread positions of the body, and empty: the
    // checksum or the header refuses each; it is rebuilt, never trusted,
    // never a panic, and the rebuilt file is then a hit.
    let mut flipped = good.clone();
    let mid = flipped.len() / 2;
    for b in &mut flipped[mid..mid + 64] {
        *b ^= 0x5a;
    }
    let mut spread = good.clone();
    let body = 76..spread.len();
    for k in 0..16 {
        let at = body.start + (k * 7919 + 13) % body.len();
        spread[at] ^= 1 << (k % 8);
    }
    let variants: Vec<Vec<u8>> = vec![
        good[..good.len() / 3].to_vec(),
        b"not a cache at all".to_vec(),
        flipped,
        spread,
        Vec::new(),
    ];
    for bad in variants {
        std::fs::write(file, &bad).unwrap();
        let (style, st) = BrushStyle::load_with_status(&dir, &opts).unwrap();
        assert_eq!(st, CacheStatus::Rebuilt);
        assert_eq!(postcard::to_stdvec(&style).unwrap(), bytes);
        let (_, st) = BrushStyle::load_with_status(&dir, &opts).unwrap();
        assert_eq!(st, CacheStatus::Hit);
    }
    // A FIFO in the cache file's place is never opened (opening it would
    // block): it is replaced by a rebuilt file.
    #[cfg(unix)]
    {
        std::fs::remove_file(file).unwrap();
        let made = std::process::Command::new("mkfifo").arg(file).status();
        if made.map(|s| s.success()).unwrap_or(false) {
            let (_, st) = BrushStyle::load_with_status(&dir, &opts).unwrap();
            assert_eq!(st, CacheStatus::Rebuilt);
            assert!(std::fs::metadata(file).unwrap().is_file());
        } else {
            std::fs::write(file, &good).unwrap();
        }
    }
    // Editing an exemplar changes the key: a miss, not the old analysis,
    // and the stale file is replaced, not kept beside the new one.
    let edited = std::fs::read_to_string(dir.join("b.svg"))
        .unwrap()
        .replace("#a33", "#a34");
    std::fs::write(dir.join("b.svg"), edited).unwrap();
    let (_, st) = BrushStyle::load_with_status(&dir, &opts).unwrap();
    assert_eq!(st, CacheStatus::Miss);
    let after: Vec<_> = std::fs::read_dir(tmp.path().join("cache"))
        .unwrap()
        .map(|e| e.unwrap().path())
        .collect();
    assert_eq!(after.len(), 1, "{after:?}");
    assert_ne!(&after[0], file);
    // Caching off.
    let off = AnalysisOptions {
        use_cache: false,
        ..opts
    };
    assert_eq!(
        BrushStyle::load_with_status(&dir, &off).unwrap().1,
        CacheStatus::Disabled
    );
}

#[test]
fn rotating_an_exemplar_rotates_its_orientation_and_neighbourhoods() {
    let tmp = tempfile::tempdir().unwrap();
    // Start and end of the band (y + 50 in the square canvas), and their
    // quarter turn about (100, 100): (x, y) -> (200 - y, x).
    let (s, e) = ([24.0, 100.0], [170.0, 100.0]);
    let rot = |p: [f64; 2]| [200.0 - p[1], p[0]];
    let mut styles = Vec::new();
    for (name, rotated, s, e) in [("a", false, s, e), ("b", true, rot(s), rot(e))] {
        let dir = tmp.path().join(name);
        std::fs::create_dir_all(&dir).unwrap();
        let square = if rotated {
            "square-rotated.svg"
        } else {
            "square.svg"
        };
        std::fs::copy(fixture(square), dir.join("x.svg")).unwrap();
        std::fs::write(
            dir.join("style.toml"),
            format!(
                "kind = \"brush\"\nresolution = 128\n[[exemplar]]\nfile = \"x.svg\"\nstart = [{}, {}]\nend = [{}, {}]\n",
                s[0], s[1], e[0], e[1]
            ),
        )
        .unwrap();
        let opts = AnalysisOptions {
            use_cache: false,
            ..AnalysisOptions::default()
        };
        styles.push(BrushStyle::load(&dir, &opts).unwrap());
    }
    let (a, b) = (&styles[0], &styles[1]);
    let (la, lb) = (
        a.exemplars[0].finest().unwrap(),
        b.exemplars[0].finest().unwrap(),
    );
    assert_eq!((la.width(), la.height()), (128, 128));
    // Pixel (i, j) turns into (127 − j, i); orientation ω into (−ω_y, ω_x).
    let (mut both, mut only, mut aligned, mut close) = (0, 0, 0, 0);
    for j in 0..128 {
        for i in 0..128 {
            if !la.orientation.mask.get(i, j) {
                continue;
            }
            let (ri, rj) = (127 - j, i);
            if !lb.orientation.mask.get(ri, rj) {
                only += 1;
                continue;
            }
            both += 1;
            let wa = la.orientation.dir.get(i, j);
            let wb = lb.orientation.dir.get(ri, rj);
            if -wa[1] * wb[0] + wa[0] * wb[1] > 10f32.to_radians().cos() {
                aligned += 1;
            }
            let na = a
                .sampler
                .sample(&la.ink.ink, [i as f64 + 0.5, j as f64 + 0.5], wa);
            let nb = b
                .sampler
                .sample(&lb.ink.ink, [ri as f64 + 0.5, rj as f64 + 0.5], wb);
            let worst = na
                .iter()
                .zip(&nb)
                .map(|(x, y)| (x - y).abs())
                .fold(0.0, f32::max);
            if worst < 0.15 {
                close += 1;
            }
        }
    }
    assert!(both > 500, "{both}");
    assert!(only * 20 < both, "regions differ: {only} of {both}");
    assert!(
        aligned * 100 > both * 95,
        "orientation: {aligned} of {both}"
    );
    assert!(close * 100 > both * 95, "neighbourhoods: {close} of {both}");
}

#[test]
fn png_exemplars_are_analysed_too() {
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path().join("png");
    std::fs::create_dir_all(&dir).unwrap();
    // A dark band with a round end on white, 160×80 px.
    let img = image::RgbImage::from_fn(160, 80, |x, y| {
        let (px, py) = (x as f64 + 0.5, y as f64 + 0.5);
        let band = (20.0..130.0).contains(&px) && (py - 40.0).abs() < 6.0;
        let ball = (px - 134.0).hypot(py - 40.0) < 10.0;
        if band || ball {
            image::Rgb([30, 40, 60])
        } else {
            image::Rgb([255, 255, 255])
        }
    });
    img.save(dir.join("band.png")).unwrap();
    std::fs::write(
        dir.join("style.toml"),
        "kind = \"brush\"\nresolution = 128\n[[exemplar]]\nfile = \"band.png\"\nstart = [30.0, 40.0]\nend = [125.0, 40.0]\n",
    )
    .unwrap();
    let opts = AnalysisOptions {
        use_cache: false,
        ..AnalysisOptions::default()
    };
    let st = BrushStyle::load(&dir, &opts).unwrap();
    let ex = &st.exemplars[0];
    assert_eq!(ex.size, [160.0, 80.0]);
    let fine = ex.finest().unwrap();
    assert_eq!((fine.width(), fine.height()), (128, 64));
    // Widths along the band: 12 px × 0.8 = 9.6 finest px, within a pixel,
    // away from the ball; the spine is extended over the ball.
    let w = ex.ribs.widths();
    let mid = &w[w.len() / 4..w.len() / 2];
    assert!(mid.iter().all(|&x| (x - 9.6).abs() < 1.0), "{mid:?}");
    assert!(ex.extension[1] > 10.0, "{:?}", ex.extension);
    assert!(st.indexes.iter().all(|i| !i.is_empty()));
}
