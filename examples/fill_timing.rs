//! Times the fill synthesis core on the benchmark case: a 512×512 region
//! from a 128×128 tile (the `knot` tile at 128 px), constant direction.
//!
//! Run: `cargo run --release --example fill_timing [TILE.svg] [SIDE]`;
//! writes `/tmp/fill-tile-128.png` (the tile's colour, the input for the
//! texture-synthesis comparison) and `/tmp/fill-timing.png` (the bottom
//! layer's ink), and prints the median of five runs and the energies.

use flourish::field::diffusion::constant_field;
use flourish::fill::em::{synthesize, EmParams};
use flourish::fill::tile::{SourceDirection, Tile};
use std::path::PathBuf;
use std::time::Instant;

/// CPU time of the whole process (all threads), seconds, from
/// `/proc/self/stat` (utime + stime in clock ticks of 10 ms); 0 elsewhere.
fn cpu_seconds() -> f64 {
    let stat = std::fs::read_to_string("/proc/self/stat").unwrap_or_default();
    // Fields after the parenthesized command name; utime and stime are
    // the 14th and 15th fields of the line.
    let rest = stat.rsplit_once(')').map_or("", |(_, r)| r);
    let f: Vec<f64> = rest
        .split_whitespace()
        .map(|v| v.parse().unwrap_or(0.0))
        .collect();
    (f.get(11).copied().unwrap_or(0.0) + f.get(12).copied().unwrap_or(0.0)) / 100.0
}

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let tile = args.get(1).map(PathBuf::from).unwrap_or_else(|| {
        PathBuf::from(concat!(env!("CARGO_MANIFEST_DIR"), "/styles/knot/tile.svg"))
    });
    let side: usize = args.get(2).and_then(|s| s.parse().ok()).unwrap_or(512);
    let t = Tile::load(&tile, 128, SourceDirection::Constant([1.0, 0.0])).expect("tile");
    // The tile as the comparison's input PNG (composite colour, 128×128).
    let tile_png = image::RgbImage::from_fn(t.width() as u32, t.height() as u32, |x, y| {
        let c = t.colour.get(x as usize, y as usize);
        image::Rgb(c.map(|v| (v * 255.0).round().clamp(0.0, 255.0) as u8))
    });
    let _ = tile_png.save("/tmp/fill-tile-128.png");
    let dir = constant_field(side, side, [1.0, 0.0]);
    let params = EmParams::default();
    let mut times = Vec::new();
    let mut cpu = Vec::new();
    let mut last = None;
    for _ in 0..5 {
        let (t0, c0) = (Instant::now(), cpu_seconds());
        let s = synthesize(&t, &dir, &params);
        times.push(t0.elapsed().as_secs_f64());
        cpu.push(cpu_seconds() - c0);
        last = Some(s);
    }
    times.sort_by(f64::total_cmp);
    cpu.sort_by(f64::total_cmp);
    println!("CPU time: median {:.2} s (runs {cpu:.2?})", cpu[2]);
    println!(
        "{side}×{side} from {}×{} tile: median {:.3} s (runs {times:.3?})",
        t.width(),
        t.height(),
        times[2]
    );
    if let Some(s) = last {
        println!("energy per level: {:?}", s.energy);
        let g = &s.layers[0];
        let img = image::GrayImage::from_fn(g.width() as u32, g.height() as u32, |x, y| {
            image::Luma([if g.get(x as usize, y as usize) < 0.0 {
                0
            } else {
                255
            }])
        });
        let _ = img.save("/tmp/fill-timing.png");
    }
}
