//! The fill pipeline on the shipped samples and styles: ink fraction and
//! containment per region, thread-count determinism, combing, EM energy,
//! continuity of the bands, the Shape Hint, and shared tile preparation.
//!
//! The shipped styles run at a 64 px tile (the `resolution` override) so
//! the tests stay fast.

use super::tile::{Palette, SourceDirection, Swatch, Tile};
use super::{em, fill_sketch, FillOptions, FillOutput, FillStyle};
use crate::error::Result;
use crate::field::diffusion::constant_field;
use crate::read::sketch::{self, Sketch};
use crate::svg_out::FillRule;
use kurbo::{BezPath, Line, ParamCurve, PathSeg, Point, Shape as _};
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

fn sample(name: &str) -> PathBuf {
    root().join("samples/fill").join(format!("{name}.svg"))
}

/// Fills `sk` with `style` (a shipped style's name or a folder), and each
/// region naming one with `data-style` with that shipped style, tiles at
/// `resolution` px (`None`: the style's own).
fn fill_with(
    sk: &Sketch,
    style: &str,
    resolution: Option<u32>,
    opts: &FillOptions,
) -> Result<FillOutput> {
    let dir = |name: &str| {
        let p = Path::new(name);
        if p.join("style.toml").is_file() {
            p.to_path_buf()
        } else {
            root().join("styles").join(name)
        }
    };
    let mut styles: BTreeMap<String, FillStyle> = BTreeMap::new();
    let names =
        std::iter::once(style.to_string()).chain(sk.queries.iter().filter_map(|q| q.style.clone()));
    for name in names {
        if let std::collections::btree_map::Entry::Vacant(slot) = styles.entry(name) {
            let st = FillStyle::load(&dir(slot.key()), resolution)?;
            slot.insert(st);
        }
    }
    fill_sketch(
        sk,
        |q| {
            let name = q.style.as_deref().unwrap_or(style);
            let (k, v) = styles.get_key_value(name).expect("loaded");
            Ok((k.as_str(), v))
        },
        opts,
    )
}

/// A sample filled with a shipped style at 64 px tiles.
fn run(style: &str, name: &str) -> FillOutput {
    let sk = sketch::load(&sample(name)).unwrap();
    fill_with(&sk, style, Some(64), &FillOptions::default()).unwrap()
}

/// At the style's own resolution (96 px tiles).
fn run_full(style: &str, name: &str) -> FillOutput {
    let sk = sketch::load(&sample(name)).unwrap();
    fill_with(&sk, style, None, &FillOptions::default()).unwrap()
}

/// The swatch at `path` alone as a tile at `res` px.
fn tile_of(path: &Path, res: u32, dir: SourceDirection) -> Tile {
    let sw = Swatch::read(path, res).unwrap();
    let palette = Palette::of(std::slice::from_ref(&sw)).unwrap();
    Tile::from_swatch(&sw, &palette, dir)
}

/// An empty 200 × 200 px sketch (px per unit 1), for a style's scale.
fn blank_sketch() -> Sketch {
    Sketch::from_svg(b"<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"200\" height=\"200\"/>")
        .unwrap()
}

/// `body` in a 200 × 200 sketch file in `dir`.
fn write_sketch(dir: &Path, name: &str, body: &str) -> String {
    let p = dir.join(name);
    std::fs::write(
        &p,
        format!(
            "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"200\" height=\"200\">{body}</svg>"
        ),
    )
    .unwrap();
    p.to_string_lossy().into_owned()
}

/// Distance from `p` to the outline's flattened segments.
fn outline_distance(outline: &BezPath, p: Point) -> f64 {
    let mut segs: Vec<Line> = Vec::new();
    crate::raster::vector::flatten_segments(outline, 0.01, &mut segs);
    segs.iter()
        .map(|l| crate::raster::sdf::point_segment_distance(p, *l))
        .fold(f64::INFINITY, f64::min)
}

fn inside(outline: &BezPath, rule: FillRule, p: Point) -> bool {
    let w = outline.winding(p);
    match rule {
        FillRule::NonZero => w != 0,
        FillRule::EvenOdd => w % 2 != 0,
    }
}

/// The sketch's first region query: its outline (user units) and fill rule.
fn first_region(sk: &sketch::Sketch) -> (BezPath, FillRule) {
    let (outline, rule) = sk.queries.iter().find_map(|q| q.region()).unwrap();
    (outline.clone(), rule)
}

#[test]
fn ink_fraction_and_containment_per_region() {
    for style in ["knot", "scales"] {
        for name in ["circle", "star", "letter", "frame"] {
            let out = run_full(style, name);
            let sk = sketch::load(&sample(name)).unwrap();
            let (outline, rule) = first_region(&sk);
            assert_eq!(out.regions.len(), 1);
            let r = &out.regions[0];
            let (f, t) = (r.ink_fraction(), r.tile_ink);
            println!("{style}/{name}: ink {f:.3}, tile {t:.3}");
            assert!(
                (f - t).abs() <= 0.15 * t,
                "{style}/{name}: ink {f:.3}, tile {t:.3}"
            );
            // No ink outside: every point of every traced curve is inside
            // the region or within the tracing tolerance of its outline.
            // Tolerance: 0.25 px tracing plus the linear interpolation of the
            // contour at acute corners of the clip (star tips), 0.5 px in all.
            let tol = 0.5 / r.region.sdf.px_per_unit();
            let mut n = 0;
            for layer in &r.paths {
                for p in layer {
                    for seg in p.segments() {
                        for k in 0..8 {
                            let q = seg.eval(k as f64 / 8.0);
                            n += 1;
                            if !inside(&outline, rule, q) {
                                let d = outline_distance(&outline, q);
                                assert!(d <= tol, "{style}/{name}: ink at {q:?}, {d} outside");
                            }
                        }
                    }
                }
            }
            assert!(n > 100, "{style}/{name}: only {n} curve samples");
            let _ = PathSeg::Line(Line::new((0.0, 0.0), (1.0, 1.0)));
        }
    }
}

#[test]
fn one_and_two_threads_give_identical_bytes() {
    let svg = |threads: usize| {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap();
        pool.install(|| run("scales", "combed").to_document().to_svg())
    };
    assert_eq!(svg(1), svg(2));
}

#[test]
fn combing_turns_the_direction_under_the_stroke() {
    let out = run("knot", "combed");
    let r = &out.regions[0];
    // The stroke rises to the right at its end (direction ≈ +x there) and
    // runs up-right in its middle: near (100, 100) the field points up.
    let to_px = r.region.sdf.to_user.inverse();
    let p = to_px * Point::new(100.0, 100.0);
    let d = r.region.direction.get(p.x as usize, p.y as usize);
    assert!(d[1] < -0.4, "{d:?}");
}

#[test]
fn energy_decreases_over_the_em_iterations_at_each_level() {
    let tile = tile_of(
        &root().join("styles/scales/tile.svg"),
        64,
        SourceDirection::Constant([1.0, 0.0]),
    );
    let dir = constant_field(96, 96, [1.0, 0.0]);
    let params = em::EmParams {
        levels: 2,
        iterations: 6,
        ..Default::default()
    };
    let s = em::synthesize(&tile, &dir, &params);
    assert_eq!(s.energy.len(), 2);
    // Each level records its start and one energy per M-step: the
    // coarsest, at half resolution, runs half of the six iterations per
    // neighbourhood size (two sizes there), the finest a quarter.
    assert_eq!(s.energy[0].len(), 1 + 2 * 3, "{:?}", s.energy);
    assert_eq!(s.energy[1].len(), 1 + 2, "{:?}", s.energy);
    // Three levels: the coarsest and the middle one run all six.
    for (level, want) in [(0, 2), (1, 6), (2, 6)] {
        assert_eq!(em::iterations_at(level, 3, 6), want, "level {level}");
    }
    assert_eq!(em::iterations_at(0, 1, 6), 6);
    assert_eq!(em::iterations_at(0, 2, 1), 1);
    // Levels after the coarsest start from the upsampled image and must
    // improve on it. The coarsest starts from the quilted copy, whose
    // interior energy is already 0 (every neighbourhood a tile
    // neighbourhood); it can only pick up the seams' and the grid edge's
    // disagreement, so it must stay small.
    for (level, e) in s.energy.iter().enumerate().skip(1) {
        let (first, last) = (e[0], e[e.len() - 1]);
        assert!(last < first, "level {level}: {e:?}");
    }
    let coarse = &s.energy[0];
    assert!(coarse[0] < 1e-3, "{coarse:?}");
    let finest = &s.energy[1];
    assert!(
        coarse.iter().all(|&e| e < finest[0]),
        "{coarse:?} vs {finest:?}"
    );
}

#[test]
fn a_direction_file_combs_every_region() {
    let dir = tempfile::tempdir().unwrap();
    let strokes = write_sketch(
        dir.path(),
        "d.svg",
        "<path d=\"M10 100H190\" fill=\"none\" stroke=\"#000\" stroke-width=\"60\"/>",
    );
    let sk = sketch::load(&sample("star")).unwrap();
    let plain = fill_with(&sk, "knot", Some(64), &FillOptions::default()).unwrap();
    let combed = fill_with(
        &sk,
        "knot",
        Some(64),
        &FillOptions {
            direction: Some(sketch::load(Path::new(&strokes)).unwrap()),
            ..FillOptions::default()
        },
    )
    .unwrap();
    // Under the stroke the field is the stroke's direction (+x); the
    // style's own flow (the rising bands) there is not.
    let r = &combed.regions[0].region;
    let p = r.sdf.to_user.inverse() * Point::new(100.0, 100.0);
    let d = r.direction.get(p.x as usize, p.y as usize);
    assert!(d[0] > 0.95, "{d:?}");
    assert_ne!(plain.to_document().to_svg(), combed.to_document().to_svg());
    // A direction file without open paths is refused.
    let bad = write_sketch(
        dir.path(),
        "bad.svg",
        "<circle cx=\"9\" cy=\"9\" r=\"5\" fill=\"#000\"/>",
    );
    let e = fill_with(
        &sk,
        "knot",
        Some(64),
        &FillOptions {
            direction: Some(sketch::load(Path::new(&bad)).unwrap()),
            ..FillOptions::default()
        },
    )
    .unwrap_err()
    .to_string();
    assert!(e.contains("no open stroked path"), "{e}");
}

#[test]
fn a_png_tile_fills_a_region() {
    // Diagonal dark stripes 12 px wide every 32 px on white, seamless at 64².
    let dir = tempfile::tempdir().unwrap();
    let img = image::RgbImage::from_fn(64, 64, |x, y| {
        if (x + y) % 32 < 12 {
            image::Rgb([30, 40, 90])
        } else {
            image::Rgb([255, 255, 255])
        }
    });
    img.save(dir.path().join("tile.png")).unwrap();
    std::fs::write(
        dir.path().join("style.toml"),
        "kind = \"fill\"\ndirection = [1.0, 0.0]\nlevels = 2\n[[exemplar]]\nfile = \"tile.png\"\n",
    )
    .unwrap();
    let sketch = write_sketch(
        dir.path(),
        "s.svg",
        "<circle cx=\"50\" cy=\"50\" r=\"40\" fill=\"#ccc\"/>",
    );
    let sk = sketch::load(Path::new(&sketch)).unwrap();
    let tile_style = dir.path().to_string_lossy().into_owned();
    let out = fill_with(&sk, &tile_style, Some(64), &FillOptions::default()).unwrap();
    let r = &out.regions[0];
    assert_eq!(r.colors.len(), 1);
    let (f, t) = (r.ink_fraction(), r.tile_ink);
    println!("png stripes: ink {f:.3}, tile {t:.3}");
    assert!((t - 12.0 / 32.0).abs() < 0.05, "{t}");
    // Straight stripes across the circle.
    assert!((f - t).abs() <= 0.15 * t, "ink {f:.3}, tile {t:.3}");
}

/// Continuity figures of a synthesized knot on `mask`: (fraction of
/// regular gaps, band junctions of the top layer per 10⁴ px), counted over
/// the pixels more than 6 px inside (bands legitimately stop at the
/// outline).
fn continuity_of(
    layers: &[crate::raster::Grid<f32>],
    inside: &crate::raster::Grid<f32>,
    tile: &Tile,
) -> (f64, f64) {
    use crate::fill::continuity::{junctions, regular_gaps, tile_gap_area};
    use crate::raster::Grid;
    let (w, h) = (inside.width(), inside.height());
    let counted = inside.map(|d| d < -6.0);
    let area = counted.data().iter().filter(|&&c| c).count().max(1) as f64;
    let paper = Grid::from_fn(w, h, |x, y| {
        layers[0].get(x, y) >= 0.0 && inside.get(x, y) < 0.0
    });
    let top = layers.len() - 1;
    let band = Grid::from_fn(w, h, |x, y| {
        layers[top].get(x, y) < 0.0 && inside.get(x, y) < 0.0
    });
    let tile_paper = tile.layers[0].sdf.map(|d| d >= 0.0);
    let gap = tile_gap_area(&tile_paper);
    assert!(gap > 0.0);
    let regular = regular_gaps(&paper, &counted, gap, 1.6);
    let forks = junctions(&band, &counted, 4) as f64 * 1e4 / area;
    (regular, forks)
}

#[test]
fn the_knot_stays_continuous_under_constant_turning_and_ring_fields() {
    use crate::fill::continuity::junctions;
    use crate::raster::Grid;
    let style = crate::fill::FillStyle::load(&root().join("styles/knot"), None).unwrap();
    let tile = &style.tiles[0];
    // The tile itself: no band forks (every crossing passes over/under).
    let (tw, th) = (tile.width(), tile.height());
    let top = tile.layers.len() - 1;
    let rep = Grid::from_fn(3 * tw, 3 * th, |x, y| {
        tile.layers[top].sdf.get(x % tw, y % th) < 0.0
    });
    let centre = Grid::from_fn(3 * tw, 3 * th, |x, y| {
        (tw..2 * tw).contains(&x) && (th..2 * th).contains(&y)
    });
    assert_eq!(junctions(&rep, &centre, 4), 0);
    // A 200×200 px disc under a constant field at 30° and under a field
    // turning gently (45° across the disc).
    let n = 200usize;
    let disc = Grid::from_fn(n, n, |x, y| {
        (x as f32 + 0.5 - 100.0).hypot(y as f32 + 0.5 - 100.0) - 94.0
    });
    let mask = disc.map(|d| d < 0.0);
    let turning = Grid::from_fn(n, n, |x, _| {
        let a = (30.0 + 45.0 * x as f32 / n as f32).to_radians();
        [a.cos(), a.sin()]
    });
    let constant = constant_field(n, n, [30f64.to_radians().cos(), 30f64.to_radians().sin()]);
    // The turning field forces ∫|∇θ| dA / period ≈ 6 dislocations of the
    // ±45° bands (17 px apart); the constant one none.
    for (name, dir, most) in [("constant", constant, 0.4), ("turning", turning, 1.5)] {
        let s = em::synthesize_in(tile, &dir, Some(&mask), &style.params);
        let (regular, forks) = continuity_of(&s.layers, &disc, tile);
        println!("{name}: regular gaps {regular:.3}, forks {forks:.2} per 10⁴ px");
        assert!(regular >= 0.95, "{name}: {regular}");
        assert!(forks <= most, "{name}: {forks}");
    }
    // The circle sample, the weave upright as drawn (the style's flow).
    let out = run_full("knot", "circle");
    let r = &out.regions[0];
    let (regular, forks) = continuity_of(&r.layers, &r.region.sdf.dist, tile);
    println!("circle: regular gaps {regular:.3}, forks {forks:.2} per 10⁴ px");
    assert!(regular >= 0.95, "circle: {regular}");
    assert!(forks <= 0.4, "circle: {forks}");
    // Under the outline's ring-shaped flow the rings stay whole; spokes
    // must start as the rings grow, but gaps stay regular. (With the
    // tile's x axis as its direction the weave tears into spirals.)
    let (style, region) = knot_circle();
    let s = em::synthesize_in(tile, &region.direction, Some(&region.mask), &style.params);
    let (regular, forks) = continuity_of(&s.layers, &region.sdf.dist, tile);
    println!("circle, outline flow: regular gaps {regular:.3}, forks {forks:.2} per 10⁴ px");
    assert!(regular >= 0.9, "circle: {regular}");
    assert!(forks <= 1.5, "circle: {forks}");
}

/// The knot's circle sample under the outline's flow (`flow =
/// "outline"`, with the tile's edge line as its Shape Hint): the style
/// and the region.
fn knot_circle() -> (crate::fill::FillStyle, crate::fill::region::Region) {
    let mut style = crate::fill::FillStyle::load(&root().join("styles/knot"), None).unwrap();
    style.flow = crate::fill::Flow::Outline;
    style.params.shape = em::EmParams::default().shape;
    let sk = sketch::load(&sample("circle")).unwrap();
    let (outline, rule) = first_region(&sk);
    let region = crate::fill::region::Region::rasterize(
        "circle",
        &outline,
        rule,
        style.px_per_unit(&sk),
        style.params.radius + 2,
    )
    .unwrap();
    (style, region)
}

#[test]
fn the_shape_hint_puts_the_tiles_edge_band_on_the_outline() {
    let (style, region) = knot_circle();
    // The tile's edge line runs along the rising bands, through ink.
    let tile = &style.tiles[0];
    let edge = tile.edge.expect("edge line");
    assert!((edge.dir[0] - edge.dir[1].abs()).abs() < 1e-9 && edge.dir[1] < 0.0);
    // Ink on the rim (1–4 px inside the outline) with and without the term.
    let rim_ink = |shape: f32| {
        let params = em::EmParams {
            shape,
            ..style.params
        };
        let s = em::synthesize_in(tile, &region.direction, Some(&region.mask), &params);
        let rim: Vec<bool> = region
            .sdf
            .dist
            .data()
            .iter()
            .zip(s.layers[0].data())
            .filter(|(d, _)| (-4.0..-1.0).contains(*d))
            .map(|(_, &v)| v < 0.0)
            .collect();
        rim.iter().filter(|&&b| b).count() as f64 / rim.len() as f64
    };
    let (without, with) = (rim_ink(0.0), rim_ink(style.params.shape));
    println!("rim ink: {without:.3} without the Shape Hint, {with:.3} with");
    assert!(style.params.shape > 0.0);
    assert!(with >= 0.97, "{with}");
    assert!(with >= without + 0.1, "{without} → {with}");
}

#[test]
fn the_energy_with_the_shape_hint_decreases_in_a_region() {
    let (style, region) = knot_circle();
    let s = em::synthesize_in(
        &style.tiles[0],
        &region.direction,
        Some(&region.mask),
        &style.params,
    );
    assert_eq!(s.energy.len(), style.params.levels);
    // Every level (the coarsest starts from quilting, which knows nothing
    // of the outline; the others from the upsampled image).
    for (level, e) in s.energy.iter().enumerate() {
        let (first, last) = (e[0], e[e.len() - 1]);
        assert!(last < first, "level {level}: {e:?}");
    }
}

/// Whole-arc figures of a scales result: the share of the orange inner
/// arcs (layer 1 less the dot above it) lying wholly inside `counted` whose area is within
/// 0.6–1.6× the tile's arc, and the share of the scales' paper gaps (layer
/// 0) within 1.6× of the tile's gap.
fn scales_figures(
    layers: &[crate::raster::Grid<f32>],
    counted: &crate::raster::Grid<bool>,
    tile: &Tile,
) -> (f64, f64) {
    use crate::fill::continuity::{pieces, regular_gaps, tile_gap_area};
    use crate::raster::Grid;
    let (tw, th) = (tile.width(), tile.height());
    // The tile's arcs, whole: pieces of a 3×3 repeat not touching its rim.
    let rep = Grid::from_fn(3 * tw, 3 * th, |x, y| {
        tile.layers[1].sdf.get(x % tw, y % th) < 0.0
            && tile.layers[2].sdf.get(x % tw, y % th) >= 0.0
    });
    let inner = Grid::from_fn(3 * tw, 3 * th, |x, y| {
        x > 0 && y > 0 && x + 1 < 3 * tw && y + 1 < 3 * th
    });
    let arcs = pieces(&rep, &inner);
    let mut areas: Vec<usize> = arcs.iter().filter(|p| p.within).map(|p| p.area).collect();
    areas.sort_unstable();
    let arc = areas[areas.len() / 2] as f64;
    // Orange ink: layer 1 extends under the dot (layer 2).
    let (w, h) = (layers[1].width(), layers[1].height());
    let orange = Grid::from_fn(w, h, |x, y| {
        layers[1].get(x, y) < 0.0 && layers[2].get(x, y) >= 0.0
    });
    let got = pieces(&orange, counted);
    // Slivers of a few pixels where the dot's outline and the orange
    // layer's extension under it differ are no arcs (the tracer drops them).
    let inside: Vec<_> = got
        .iter()
        .filter(|p| p.within && p.area as f64 >= 0.1 * arc)
        .collect();
    let whole = inside
        .iter()
        .filter(|p| (0.6 * arc..=1.6 * arc).contains(&(p.area as f64)))
        .count() as f64
        / inside.len().max(1) as f64;
    let gap = tile_gap_area(&tile.layers[0].sdf.map(|d| d >= 0.0));
    let regular = regular_gaps(&layers[0].map(|d| d >= 0.0), counted, gap, 1.6);
    (whole, regular)
}

#[test]
fn the_scales_keep_whole_arcs_in_rows_under_a_constant_field_and_combed() {
    let style = crate::fill::FillStyle::load(&root().join("styles/scales"), None).unwrap();
    let tile = &style.tiles[0];
    // A 200×200 px disc under a constant field at 20°.
    let n = 200usize;
    let disc = crate::raster::Grid::from_fn(n, n, |x, y| {
        (x as f32 + 0.5 - 100.0).hypot(y as f32 + 0.5 - 100.0) - 94.0
    });
    let mask = disc.map(|d| d < 0.0);
    let dir = constant_field(n, n, [20f64.to_radians().cos(), 20f64.to_radians().sin()]);
    let s = em::synthesize_in(tile, &dir, Some(&mask), &style.params);
    let (whole, regular) = scales_figures(&s.layers, &disc.map(|d| d < -4.0), tile);
    println!("constant: whole arcs {whole:.3}, regular gaps {regular:.3}");
    assert!(whole >= 0.85, "constant: {whole}");
    assert!(regular >= 0.95, "constant: {regular}");
    // The combed sample: the wide stroke sets the field over the whole
    // rounded rectangle (its outline's own flow would turn a full circle
    // around a vortex, which rows of scales cannot follow). Uncombed
    // shapes, the frame with its hole among them: the style's fixed flow
    // lays the rows straight across (under the outline's flow the rows
    // tear around the vortex).
    for (name, min_whole, min_regular) in [
        ("combed", 0.7, 0.9),
        ("circle", 0.85, 0.95),
        ("frame", 0.85, 0.95),
    ] {
        let out = run_full("scales", name);
        let r = &out.regions[0];
        let counted = r.region.sdf.dist.map(|d| d < -4.0);
        let (whole, regular) = scales_figures(&r.layers, &counted, tile);
        println!("{name}: whole arcs {whole:.3}, regular gaps {regular:.3}");
        assert!(whole >= min_whole, "{name}: {whole}");
        assert!(regular >= min_regular, "{name}: {regular}");
    }
}

#[test]
fn a_pyramid_level_is_added_only_while_every_layer_survives_halving() {
    // The scales' orange arc (2.4 units) is 1.8 px wide at half of a 96 px
    // tile but 0.9 px at a quarter, where its SDF barely dips below zero:
    // three asked-for levels give two. The knot's bands (128 px) survive
    // to a quarter: three levels.
    let dir = constant_field(40, 40, [1.0, 0.0]);
    let params = em::EmParams {
        levels: 3,
        iterations: 1,
        ..Default::default()
    };
    for (name, res, want) in [("scales", 96, 2), ("knot", 128, 3)] {
        let tile = tile_of(
            &root().join(format!("styles/{name}/tile.svg")),
            res,
            SourceDirection::Constant([1.0, 0.0]),
        );
        let quarter = tile.half().half();
        assert_eq!(em::represents_every_layer(&[quarter]), want == 3, "{name}");
        let s = em::synthesize(&tile, &dir, &params);
        assert_eq!(s.energy.len(), want, "{name}");
    }
}

/// A region of `outline` on the grid of a style at `px_per_unit`.
fn region_of(style: &crate::fill::FillStyle, outline: &BezPath) -> crate::fill::region::Region {
    let mut r = crate::fill::region::Region::rasterize(
        "shape",
        outline,
        FillRule::NonZero,
        style.px_per_unit(&blank_sketch()),
        style.params.radius + 2,
    )
    .unwrap();
    if let crate::fill::Flow::Fixed(d) = style.flow {
        r.direction = constant_field(r.width(), r.height(), d);
    }
    r
}

#[test]
fn one_prepared_tile_serves_many_regions_as_each_alone() {
    // The tile side of a synthesis (pyramid, channels, patch tables, padded
    // gathers, quilting tables, Shape Hint descriptors) is made once per
    // style and shared: each region's synthesis must be the one it gets
    // from a preparation of its own, whatever was synthesized before it.
    let shapes: Vec<BezPath> = vec![
        kurbo::Circle::new((20.0, 20.0), 12.0).to_path(0.1),
        BezPath::from_svg("M10 10 L50 14 L40 40 L14 30 Z").unwrap(),
        kurbo::Rect::new(0.0, 0.0, 6.0, 5.0).to_path(0.1),
    ];
    for name in ["knot", "scales"] {
        let style =
            crate::fill::FillStyle::load(&root().join("styles").join(name), Some(64)).unwrap();
        let regions: Vec<_> = shapes.iter().map(|s| region_of(&style, s)).collect();
        let tile = &style.tiles[0];
        let prepared = em::Prepared::new(&style.tiles, &style.params);
        assert_eq!(prepared.tile_ink(0), tile.ink_fraction(0));
        // In order, then again in reverse on the same preparation.
        let order: Vec<usize> = (0..regions.len()).chain((0..regions.len()).rev()).collect();
        for (i, &k) in order.iter().enumerate() {
            let r = &regions[k];
            let seed = 7 + k as u64;
            let shared = prepared.synthesize(&r.direction, Some(&r.mask), seed);
            let params = em::EmParams {
                seed,
                ..style.params
            };
            let alone = em::synthesize_in(tile, &r.direction, Some(&r.mask), &params);
            assert_eq!(shared.energy, alone.energy, "{name} region {k} (run {i})");
            assert_eq!(shared.layers.len(), alone.layers.len());
            for (a, b) in shared.layers.iter().zip(&alone.layers) {
                assert_eq!(a.data(), b.data(), "{name} region {k} (run {i})");
            }
            assert_eq!(shared.colour.data(), alone.colour.data());
        }
    }
}

#[test]
fn a_sketch_of_many_shapes_fills_each_as_its_own_synthesis_does() {
    // Shapes in two styles, interleaved: fill_sketch prepares each style
    // once; every region must equal the unshared synthesis with its seed,
    // clipped as fill_sketch clips.
    let dir = tempfile::tempdir().unwrap();
    let body = r##"<circle cx="30" cy="30" r="14" fill="#ccc"/>
<polygon points="60,10 90,20 80,50 55,45" fill="#ccc" data-style="scales"/>
<circle cx="40" cy="80" r="6" fill="#ccc"/>
<rect x="70" y="65" width="30" height="20" fill="#ccc" data-style="scales"/>
<circle cx="150" cy="150" r="9" fill="#ccc"/>"##;
    let path = write_sketch(dir.path(), "many.svg", body);
    let sk = sketch::load(Path::new(&path)).unwrap();
    let o = FillOptions::default();
    let out = fill_with(&sk, "knot", Some(64), &o).unwrap();
    assert_eq!(out.regions.len(), 5);
    for (qi, r) in out.regions.iter().enumerate() {
        let name = if qi % 2 == 1 { "scales" } else { "knot" };
        let style = FillStyle::load(&root().join("styles").join(name), Some(64)).unwrap();
        let params = em::EmParams {
            seed: crate::rng::hash(&[o.seed, qi as u64]),
            ..style.params
        };
        let s = em::synthesize_in(
            &style.tiles[0],
            &r.region.direction,
            Some(&r.region.mask),
            &params,
        );
        let mut layers = s.layers;
        for k in (1..layers.len()).rev() {
            let (lo, hi) = layers.split_at_mut(k);
            for (a, &b) in lo[k - 1].data_mut().iter_mut().zip(hi[0].data()) {
                *a = a.min(b);
            }
        }
        for l in &mut layers {
            for (a, &b) in l.data_mut().iter_mut().zip(r.region.sdf.dist.data()) {
                *a = a.max(b);
            }
        }
        assert_eq!(layers.len(), r.layers.len(), "region {qi}");
        for (a, b) in layers.iter().zip(&r.layers) {
            assert_eq!(a.data(), b.data(), "region {qi} ({name})");
        }
        assert_eq!(r.tile_ink, style.tiles[0].ink_fraction(0));
        assert_eq!(r.energy, s.energy, "region {qi}");
    }
}

/// A style of two swatches in `dir`: a seamless two-colour tile of
/// diagonal bands (blue bands 10 units wide, a yellow stripe 4 wide down
/// each) and a motif on paper (a red ring round a blue dot), each 48
/// units, read at 64 px.
fn two_swatch_style(dir: &Path) -> String {
    let mut bands = String::new();
    for k in -2..4 {
        let o = 24.0 * k as f64;
        bands += &format!(
            "<path d=\"M{} 0L{} 0L{} 48L{} 48Z\" fill=\"#1f3a80\"/>",
            o,
            o + 10.0,
            o + 10.0 + 48.0,
            o + 48.0
        );
        bands += &format!(
            "<path d=\"M{} 0L{} 0L{} 48L{} 48Z\" fill=\"#f0c020\"/>",
            o + 3.0,
            o + 7.0,
            o + 7.0 + 48.0,
            o + 3.0 + 48.0
        );
    }
    std::fs::write(
        dir.join("bands.svg"),
        format!(
            "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"48\" height=\"48\">{bands}</svg>"
        ),
    )
    .unwrap();
    std::fs::write(
        dir.join("ring.svg"),
        "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"48\" height=\"48\">\
         <circle cx=\"24\" cy=\"24\" r=\"18\" fill=\"none\" stroke=\"#c02020\" stroke-width=\"5\"/>\
         <circle cx=\"24\" cy=\"24\" r=\"6\" fill=\"#1f3a80\"/></svg>",
    )
    .unwrap();
    std::fs::write(
        dir.join("style.toml"),
        "kind = \"fill\"\nresolution = 64\nlevels = 2\n\
         [[exemplar]]\nfile = \"bands.svg\"\n[[exemplar]]\nfile = \"ring.svg\"\n",
    )
    .unwrap();
    dir.to_string_lossy().into_owned()
}

#[test]
fn a_style_of_several_swatches_reads_each_as_what_it_is() {
    let dir = tempfile::tempdir().unwrap();
    let style = two_swatch_style(dir.path());
    let st = FillStyle::load(Path::new(&style), None).unwrap();
    assert_eq!(st.tiles.len(), 2);
    // One palette over both: blue, yellow, red; no ground (paper shows).
    assert_eq!(st.ground, None);
    assert_eq!(st.tiles[0].layers.len(), 3);
    assert!(st.tiles.iter().all(|t| t.layers.len() == 3));
    // The bands run on across their seams; the ring is a motif on paper,
    // its shape the disc it bounds.
    assert!(st.tiles[0].periodic && st.tiles[0].shape.is_none());
    let ring = &st.tiles[1];
    assert!(!ring.periodic);
    let shape = ring.shape.as_ref().unwrap();
    let (w, h) = (shape.width(), shape.height());
    assert!(shape.get(w / 2, h / 2) && !shape.get(1, 1));
    let area = shape.data().iter().filter(|&&s| s).count() as f64;
    // Radius 20.5 units (the ring's outer edge) at 64 px per 48 units.
    let disc = std::f64::consts::PI * (20.5f64 * 64.0 / 48.0).powi(2);
    assert!((area / disc - 1.0).abs() < 0.1, "{area} vs {disc}");
    assert_eq!(st.exemplar("ring.svg"), Some(1));
    assert_eq!(st.exemplar("nope.svg"), None);
}

#[test]
fn a_region_may_pin_one_swatch_and_the_option_pins_the_rest() {
    let dir = tempfile::tempdir().unwrap();
    let style = two_swatch_style(dir.path());
    let body = r##"<circle cx="50" cy="50" r="40" fill="#ccc"/>
<rect x="110" y="20" width="80" height="80" fill="#ccc" data-exemplar="ring.svg"/>"##;
    let sk = sketch::load(Path::new(&write_sketch(dir.path(), "s.svg", body))).unwrap();
    let out = fill_with(&sk, &style, None, &FillOptions::default()).unwrap();
    assert_eq!(out.regions[0].exemplars, vec![0, 1]);
    assert_eq!(out.regions[1].exemplars, vec![1]);
    // The pinned region's own synthesis is the ring's alone.
    let only = FillOptions {
        exemplar: Some("bands.svg".into()),
        ..FillOptions::default()
    };
    let out = fill_with(&sk, &style, None, &only).unwrap();
    assert_eq!(out.regions[0].exemplars, vec![0]);
    assert_eq!(out.regions[1].exemplars, vec![1]);
    let e = fill_with(
        &sk,
        &style,
        None,
        &FillOptions {
            exemplar: Some("nope.svg".into()),
            ..FillOptions::default()
        },
    )
    .unwrap_err()
    .to_string();
    assert!(
        e.contains("q-1") && e.contains("nope.svg") && e.contains("bands.svg, ring.svg"),
        "{e}"
    );
}

#[test]
fn several_swatches_in_several_colours_give_identical_bytes_on_one_and_two_threads() {
    let dir = tempfile::tempdir().unwrap();
    let style = two_swatch_style(dir.path());
    let body = r##"<circle cx="60" cy="60" r="50" fill="#ccc"/>
<path d="M120 30 L190 40 L170 180 L110 150 Z" fill="#ccc"/>
<rect x="10" y="120" width="90" height="70" fill="#ccc" data-exemplar="ring.svg"/>"##;
    let sk = sketch::load(Path::new(&write_sketch(dir.path(), "s.svg", body))).unwrap();
    let svg = |threads: usize| {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap();
        pool.install(|| {
            fill_with(&sk, &style, None, &FillOptions::default())
                .unwrap()
                .to_document()
                .to_svg()
        })
    };
    let one = svg(1);
    assert_eq!(one, svg(2));
    // All three colours are drawn.
    for c in ["#1f3a80", "#f0c020", "#c02020"] {
        assert!(one.contains(c), "{c} missing");
    }
}

/// Colour layers run side by side only while their working memory fits
/// the allowance: all three of a letter-sized grid under the default
/// budget, one at a time on the largest grid or with the budget spent,
/// never none and never more than there are.
#[test]
fn layers_run_side_by_side_only_within_the_memory_allowance() {
    use super::layers_within;
    let gib = 1u64 << 30;
    assert_eq!(layers_within(3, 567 * 732, gib, 0), 3);
    assert_eq!(layers_within(3, 8 << 20, gib, 0), 1);
    assert_eq!(layers_within(3, 567 * 732, gib, gib), 1);
    assert_eq!(layers_within(0, 10, gib, 0), 1);
    assert_eq!(layers_within(2, 0, u64::MAX, 0), 2);
    // The allowance divided by a layer's bytes, plus the first.
    let px = 1 << 20;
    let each = px as u64 * super::LAYER_BYTES_PER_PX;
    let want = (gib / super::PARALLEL_LAYERS_SHARE / each) as usize + 1;
    assert_eq!(layers_within(64, px, gib, 0), want);
}

/// `fill_document` gives `fill_sketch`'s document, bit for bit, with every
/// region's grids let go.
#[test]
fn the_document_alone_is_the_same_document_without_the_grids() {
    let sk = sketch::load(&sample("letter")).unwrap();
    let st = FillStyle::load(&root().join("styles").join("scales"), Some(64)).unwrap();
    let opts = FillOptions::default();
    let full = fill_sketch(&sk, |_| Ok(("scales", &st)), &opts).unwrap();
    let lean = super::fill_document(&sk, |_| Ok(("scales", &st)), &opts).unwrap();
    assert_eq!(full.to_document().to_svg(), lean.to_document().to_svg());
    assert!(!full.regions.is_empty());
    for (f, l) in full.regions.iter().zip(&lean.regions) {
        assert!(!f.layers.is_empty() && f.region.mask.width() > 0);
        assert!(l.layers.is_empty());
        assert_eq!(l.region.mask.data().len(), 0);
        assert_eq!(l.region.area, f.region.area);
    }
}
