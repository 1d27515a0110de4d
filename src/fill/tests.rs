//! The fill pipeline on the shipped samples and styles: ink fraction and
//! containment per region, thread-count determinism, combing, EM energy,
//! continuity of the bands, the Shape Hint, and shared tile preparation.
//!
//! The shipped styles run at a 64 px tile (the `resolution` override) so
//! the tests stay fast.

use super::tile::{SourceDirection, Tile};
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
    let tile = Tile::load(
        &root().join("styles/scales/tile.svg"),
        64,
        SourceDirection::Constant([1.0, 0.0]),
    )
    .unwrap();
    let dir = constant_field(96, 96, [1.0, 0.0]);
    let params = em::EmParams {
        levels: 2,
        iterations: 6,
        ..Default::default()
    };
    let s = em::synthesize(&tile, &dir, &params);
    assert_eq!(s.energy.len(), 2);
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
    // boundary flow there is not.
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
    // Straight stripes bent into rings by the boundary flow: without the
    // histogram weight of the votes this lost a fifth of its ink.
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
    let tile = &style.tile;
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
    // The circle sample under its ring-shaped boundary flow: the rings stay
    // whole; spokes must start as the rings grow, but gaps stay regular.
    let out = run_full("knot", "circle");
    let r = &out.regions[0];
    let (regular, forks) = continuity_of(&r.layers, &r.region.sdf.dist, tile);
    println!("circle: regular gaps {regular:.3}, forks {forks:.2} per 10⁴ px");
    // (With the tile's x axis as its direction the weave tears into
    // spirals.)
    assert!(regular >= 0.93, "circle: {regular}");
    assert!(forks <= 1.2, "circle: {forks}");
}

/// The knot's circle sample: its style, region and synthesis parameters.
fn knot_circle() -> (crate::fill::FillStyle, crate::fill::region::Region) {
    let style = crate::fill::FillStyle::load(&root().join("styles/knot"), None).unwrap();
    let sk = sketch::load(&sample("circle")).unwrap();
    let (outline, rule) = first_region(&sk);
    let region = crate::fill::region::Region::rasterize(
        "circle",
        &outline,
        rule,
        style.px_per_unit(),
        style.params.radius + 2,
    )
    .unwrap();
    (style, region)
}

#[test]
fn the_shape_hint_puts_the_tiles_edge_band_on_the_outline() {
    let (style, region) = knot_circle();
    // The tile's edge line runs along the rising bands, through ink.
    let edge = style.tile.edge.expect("edge line");
    assert!((edge.dir[0] - edge.dir[1].abs()).abs() < 1e-9 && edge.dir[1] < 0.0);
    // Ink on the rim (1–4 px inside the outline) with and without the term.
    let rim_ink = |shape: f32| {
        let params = em::EmParams {
            shape,
            ..style.params
        };
        let s = em::synthesize_in(&style.tile, &region.direction, Some(&region.mask), &params);
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
        &style.tile,
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
    let tile = &style.tile;
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
        let tile = Tile::load(
            &root().join(format!("styles/{name}/tile.svg")),
            res,
            SourceDirection::Constant([1.0, 0.0]),
        )
        .unwrap();
        let quarter = tile.half().half();
        assert_eq!(em::represents_every_layer(&quarter), want == 3, "{name}");
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
        style.px_per_unit(),
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
        let prepared = em::Prepared::new(&style.tile, &style.params);
        assert_eq!(prepared.tile_ink(0), style.tile.ink_fraction(0));
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
            let alone = em::synthesize_in(&style.tile, &r.direction, Some(&r.mask), &params);
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
            &style.tile,
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
        assert_eq!(r.tile_ink, style.tile.ink_fraction(0));
        assert_eq!(r.energy, s.energy, "region {qi}");
    }
}
