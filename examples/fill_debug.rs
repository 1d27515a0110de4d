//! Diagnostics of the fill synthesis on one sample's first region: runs the
//! EM with parameters from the command line, writes the layers as a PNG
//! (outside the region greyed) and the direction field as hues to
//! `/tmp/fd/direction.png`, and prints the continuity figures of
//! `fill::continuity` for the result and the tile (band ends, forks, gap
//! regularity, ink on the rim) and the forced dislocations
//! `Σ|∇θ| / 17 px`.
//!
//! Run: `cargo run --release --example fill_debug STYLE SAMPLE OUT.png
//! [radius levels iterations resolution direction° layer shape pipeline
//! seed]`; `-` keeps a default, `direction°` replaces the field by a
//! constant, `pipeline` (any word) also writes `/tmp/fd/sketch.png` from
//! the whole `fill_sketch`.

use flourish::fill::em::{synthesize_in, EmParams};
use flourish::fill::region::Region;
use flourish::fill::FillStyle;
use flourish::read::sketch::{self, QueryKind};
use std::path::Path;
use std::time::Instant;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let a: Vec<String> = std::env::args().collect();
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let style = a.get(1).map_or("knot", |s| s.as_str());
    let sample = a.get(2).map_or("circle", |s| s.as_str());
    let out = a.get(3).map_or("/tmp/fill-debug.png", |s| s.as_str());
    std::fs::create_dir_all("/tmp/fd")?;
    let num = |i: usize| a.get(i).and_then(|s| s.parse::<usize>().ok());
    let st = FillStyle::load(&root.join("styles").join(style), num(7).map(|v| v as u32))?;
    let params = EmParams {
        radius: num(4).unwrap_or(st.params.radius),
        levels: num(5).unwrap_or(st.params.levels),
        iterations: num(6).unwrap_or(st.params.iterations),
        seed: a.get(12).and_then(|s| s.parse().ok()).unwrap_or(0),
        shape: a
            .get(10)
            .and_then(|s| s.parse().ok())
            .unwrap_or(st.params.shape),
        ..st.params
    };
    let sk = sketch::load(&root.join("samples/fill").join(format!("{sample}.svg")))?;
    let (outline, rule) = sk
        .queries
        .iter()
        .find_map(|q| q.region())
        .ok_or("no region")?;
    let mut region = Region::rasterize(
        &sk.path,
        "r",
        outline,
        rule,
        st.px_per_unit(),
        params.radius + 2,
    )?;
    // The sample's open paths comb the field, as `fill_sketch` does.
    let strokes: Vec<(Vec<kurbo::Point>, f64)> = sk
        .queries
        .iter()
        .filter_map(|q| match &q.kind {
            QueryKind::Path { spine, width } => {
                let mut pts = Vec::new();
                kurbo::flatten(spine, 0.1, |el| match el {
                    kurbo::PathEl::MoveTo(p) | kurbo::PathEl::LineTo(p) => pts.push(p),
                    _ => {}
                });
                Some((pts, *width))
            }
            _ => None,
        })
        .collect();
    let combing: Vec<(&[kurbo::Point], f64)> =
        strokes.iter().map(|(p, w)| (p.as_slice(), *w)).collect();
    region.comb_all(&combing);
    if let Some(deg) = a.get(8).and_then(|s| s.parse::<f64>().ok()) {
        let t = deg.to_radians();
        region.direction = flourish::field::diffusion::constant_field(
            region.width(),
            region.height(),
            [t.cos(), t.sin()],
        );
    }
    if a.get(11).is_some() {
        let o = flourish::fill::FillOptions {
            style: style.into(),
            ..Default::default()
        };
        let out = flourish::fill::fill_sketch(&o, &sk)?;
        let r = &out.regions[0];
        let img = image::GrayImage::from_fn(
            r.layers[0].width() as u32,
            r.layers[0].height() as u32,
            |x, y| {
                let v = r
                    .layers
                    .iter()
                    .map(|l| l.get(x as usize, y as usize) < 0.0)
                    .filter(|&b| b)
                    .count();
                image::Luma([255 - 120 * v as u8])
            },
        );
        img.save("/tmp/fd/sketch.png")?;
        eprintln!("pipeline energy {:?}", r.energy);
    }
    let t0 = Instant::now();
    let s = synthesize_in(&st.tile, &region.direction, Some(&region.mask), &params);
    eprintln!(
        "{:?} {:.3} s; energy {:?}",
        params,
        t0.elapsed().as_secs_f64(),
        s.energy
    );
    let (w, h) = (region.width(), region.height());
    let rim: Vec<bool> = (0..w * h)
        .filter(|&i| (-4.0..-1.0).contains(&region.sdf.dist.data()[i]))
        .map(|i| s.layers[0].data()[i] < 0.0)
        .collect();
    println!(
        "rim ink {:.3} (edge {:?})",
        rim.iter().filter(|&&b| b).count() as f64 / rim.len() as f64,
        st.tile.edge
    );
    let layer = num(9).unwrap_or(s.layers.len() - 1);
    let ink = flourish::raster::Grid::from_fn(w, h, |x, y| {
        s.layers[layer].get(x, y) < 0.0 && region.mask.get(x, y)
    });
    let paper = flourish::raster::Grid::from_fn(w, h, |x, y| {
        s.layers[0].get(x, y) >= 0.0 && region.mask.get(x, y)
    });
    let (tw, th) = (st.tile.width(), st.tile.height());
    let tink = flourish::raster::Grid::from_fn(3 * tw, 3 * th, |x, y| {
        st.tile.layers[layer].sdf.get(x % tw, y % th) < 0.0
    });
    let tpaper = flourish::raster::Grid::from_fn(3 * tw, 3 * th, |x, y| {
        st.tile.layers[0].sdf.get(x % tw, y % th) >= 0.0
    });
    let centre = flourish::raster::Grid::from_fn(3 * tw, 3 * th, |x, y| {
        (tw..2 * tw).contains(&x) && (th..2 * th).contains(&y)
    });
    let te = flourish::fill::continuity::band_ends(&tink, &centre, 4);
    let tp = flourish::fill::continuity::components(&tpaper, &centre);
    println!(
        "tile: ends {te} ({:.2} per 10⁴ px), paper pieces {:.2} per 10⁴ px",
        te as f64 * 1e4 / (tw * th) as f64,
        tp as f64 * 1e4 / (tw * th) as f64
    );
    let inner = region.sdf.dist.map(|d| d < -6.0);
    let area = inner.data().iter().filter(|&&b| b).count();
    let ends = flourish::fill::continuity::band_ends(&ink, &inner, 4);
    let comps = flourish::fill::continuity::components(&ink, &inner);
    let pieces = flourish::fill::continuity::components(&paper, &inner);
    let jn = flourish::fill::continuity::junctions(&ink, &inner, 4);
    let tj = flourish::fill::continuity::junctions(&tink, &centre, 4);
    println!(
        "junctions {:.2} per 10⁴ px (tile {:.2})",
        jn as f64 * 1e4 / area as f64,
        tj as f64 * 1e4 / (tw * th) as f64
    );
    let tpp =
        flourish::raster::Grid::from_fn(tw, th, |x, y| st.tile.layers[0].sdf.get(x, y) >= 0.0);
    let gap = flourish::fill::continuity::tile_gap_area(&tpp);
    let reg = flourish::fill::continuity::regular_gaps(&paper, &inner, gap, 1.6);
    println!("tile gap {gap} px, regular gaps {reg:.3}");
    println!(
        "paper pieces {:.2} per 10⁴ px",
        pieces as f64 * 1e4 / area as f64
    );
    // Forced dislocations: Σ|∇θ| over the interior / band period (17 px).
    let mut rot = 0.0;
    for y in 1..h - 1 {
        for x in 1..w - 1 {
            if !inner.get(x, y) {
                continue;
            }
            let ang = |x: usize, y: usize| {
                let d = region.direction.get(x, y);
                d[1].atan2(d[0])
            };
            let wrap = |a: f32| {
                (a + std::f32::consts::PI).rem_euclid(std::f32::consts::TAU) - std::f32::consts::PI
            };
            let gx = wrap(ang(x + 1, y) - ang(x - 1, y)) / 2.0;
            let gy = wrap(ang(x, y + 1) - ang(x, y - 1)) / 2.0;
            rot += gx.hypot(gy) as f64;
        }
    }
    println!(
        "ends {ends} in {area} px ({:.2} per 10⁴ px), components {comps}, Σ|∇θ|/17 = {:.1}",
        ends as f64 * 1e4 / area as f64,
        rot / 17.0
    );
    let img = image::RgbImage::from_fn(w as u32, h as u32, |x, y| {
        let (x, y) = (x as usize, y as usize);
        let mut c = [255u8, 255, 255];
        for (l, layer) in s.layers.iter().enumerate() {
            if layer.get(x, y) < 0.0 {
                let col = st.tile.layers[l].color;
                c = [col.r, col.g, col.b];
            }
        }
        if !region.mask.get(x, y) {
            c = c.map(|v| v / 2 + 100);
        }
        image::Rgb(c)
    });
    img.save(out)?;
    let dimg = image::RgbImage::from_fn(w as u32, h as u32, |x, y| {
        let d = region.direction.get(x as usize, y as usize);
        let a = d[1].atan2(d[0]);
        let c = |o: f32| ((0.5 + 0.5 * (a + o).cos()) * 255.0) as u8;
        let mut px = [c(0.0), c(2.094), c(4.189)];
        if (x % 12 == 6) && (y % 12 == 6) {
            px = [0, 0, 0];
        }
        image::Rgb(px)
    });
    dimg.save("/tmp/fd/direction.png")?;
    Ok(())
}
