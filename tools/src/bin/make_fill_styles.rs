//! Draws the tiles of the two shipped fill styles (`knot`, `scales`) and
//! the fill sample sketches, deterministically.
//!
//! Run: `cargo run -p flourish-tools --bin make_fill_styles` (writes
//! `styles/knot`, `styles/scales` and `samples/fill/` under the crate
//! root).
//!
//! Both tiles are seamless: everything is drawn for the neighbouring
//! copies too, and the canvas cuts it at the tile's edge.

use std::f64::consts::PI;
use std::fmt::Write as _;
use std::path::Path;

fn svg(w: f64, h: f64, body: &str) -> String {
    format!(
        "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"{w}\" height=\"{h}\" viewBox=\"0 0 {w} {h}\">\n{body}</svg>\n"
    )
}

fn write(path: &Path, text: &str) -> std::io::Result<()> {
    if let Some(dir) = path.parent() {
        std::fs::create_dir_all(dir)?;
    }
    std::fs::write(path, text)
}

const T: f64 = 64.0;

/// Interlace: two families of diagonal bands woven over and under, each
/// band a navy edge around a gold core. Where a band passes under, its core
/// is interrupted for the width of the band above, so the crossing reads as
/// over/under even though each colour is one layer.
fn knot() -> String {
    let s = T / 2.0; // band spacing along u = x + y and v = x − y
    let (edge, core, gap) = (10.0, 5.0, 12.0);
    let mut dark = String::new();
    let mut light = String::new();
    // Lines u = i·s (running "\") and v = j·s (running "/").
    for fam in 0..2 {
        for i in -4i32..=8 {
            let c = i as f64 * s;
            // Parametrize by the other coordinate w in a wide range.
            let point = |w: f64| -> (f64, f64) {
                if fam == 0 {
                    ((c + w) / 2.0, (c - w) / 2.0)
                } else {
                    ((w + c) / 2.0, (w - c) / 2.0)
                }
            };
            let (a, b) = (point(-4.0 * T), point(4.0 * T));
            let _ = writeln!(
                dark,
                "  <path d=\"M{:.2} {:.2}L{:.2} {:.2}\" fill=\"none\" stroke=\"#22324f\" stroke-width=\"{edge}\"/>",
                a.0, a.1, b.0, b.1
            );
            // Crossings at w = j·s; this band is under where (i + j) is odd
            // for the first family, even for the second.
            let mut w0 = -4.0 * T;
            for j in -16i32..=16 {
                let w = j as f64 * s;
                let under = ((i + j).rem_euclid(2) == 1) == (fam == 0);
                if !under || w < w0 {
                    continue;
                }
                // The gap is measured along the band: `gap` units of length
                // are √2·gap/2 … in (u, v) the parameter w runs √2 faster.
                let half = gap / 2.0 * std::f64::consts::SQRT_2;
                let (p, q) = (point(w0), point(w - half));
                let _ = writeln!(
                    light,
                    "  <path d=\"M{:.2} {:.2}L{:.2} {:.2}\" fill=\"none\" stroke=\"#e9c46a\" stroke-width=\"{core}\"/>",
                    p.0, p.1, q.0, q.1
                );
                w0 = w + half;
            }
            let (p, q) = (point(w0), point(4.0 * T));
            let _ = writeln!(
                light,
                "  <path d=\"M{:.2} {:.2}L{:.2} {:.2}\" fill=\"none\" stroke=\"#e9c46a\" stroke-width=\"{core}\"/>",
                p.0, p.1, q.0, q.1
            );
        }
    }
    svg(T, T, &(dark + &light))
}

/// Fish scales: rows of lower half-circle arches (teal), each with a
/// concentric inner arch (ochre) and a bead (coral); rows offset by half a
/// scale.
fn scales() -> String {
    let r = T / 4.0;
    let (mut a, mut b, mut c) = (String::new(), String::new(), String::new());
    for j in -2i32..=9 {
        for i in -2i32..=5 {
            let cx = i as f64 * 2.0 * r + if j.rem_euclid(2) == 1 { r } else { 0.0 };
            let cy = j as f64 * r;
            let _ = writeln!(
                a,
                "  <path d=\"M{:.2} {cy:.2}A{r} {r} 0 0 1 {:.2} {cy:.2}\" fill=\"none\" stroke=\"#1d4e5f\" stroke-width=\"3.2\" stroke-linecap=\"round\"/>",
                cx + r,
                cx - r
            );
            let ri = 0.58 * r;
            let _ = writeln!(
                b,
                "  <path d=\"M{:.2} {:.2}A{ri} {ri} 0 0 1 {:.2} {:.2}\" fill=\"none\" stroke=\"#d08c2e\" stroke-width=\"2.4\" stroke-linecap=\"round\"/>",
                cx + ri * (PI / 8.0).cos(),
                cy + ri * (PI / 8.0).sin(),
                cx - ri * (PI / 8.0).cos(),
                cy + ri * (PI / 8.0).sin()
            );
            let _ = writeln!(
                c,
                "  <circle cx=\"{cx:.2}\" cy=\"{:.2}\" r=\"2.6\" fill=\"#c2553f\"/>",
                cy + 0.12 * r
            );
        }
    }
    svg(T, T, &(a + &b + &c))
}

fn sketch(body: &str) -> String {
    svg(200.0, 200.0, body)
}

fn star() -> String {
    let mut d = String::new();
    for k in 0..10 {
        let a = -PI / 2.0 + k as f64 * PI / 5.0;
        let rr = if k % 2 == 0 { 92.0 } else { 40.0 };
        let _ = write!(
            d,
            "{}{:.2} {:.2}",
            if k == 0 { "M" } else { "L" },
            100.0 + rr * a.cos(),
            104.0 + rr * a.sin()
        );
    }
    d.push('Z');
    format!("  <path d=\"{d}\" fill=\"#ccc\"/>\n")
}

fn main() -> std::io::Result<()> {
    let root = Path::new(concat!(env!("CARGO_MANIFEST_DIR"), "/.."));
    // The source direction is that of the tile's own bands (Brushables
    // §3.1), so a curving field bends the bands along it. The knot's bands
    // run at ±45°: with the x axis as source, a circle's ring-shaped field
    // turned both families into spirals whose spacing must change with the
    // radius, and the weave tore everywhere; along one family, that family
    // becomes unbroken rings and only the other (the spokes) must end.
    // The flow is what that direction follows in a shape no stroke combs.
    // The knot keeps its over-under weave upright as drawn (under the
    // outline's flow a round shape turns it into rings and spokes, which
    // must break somewhere); the scales have one "up" and cannot follow
    // the vortex that the flow of a closed outline turns around: both run
    // straight across unless strokes comb them.
    for (name, tile, dir, says, flow) in [
        (
            "knot",
            knot(),
            "[1.0, -1.0]",
            "The bands rising to the right follow the region's direction field.",
            "# Where no stroke combs the shape, the weave stays upright as drawn.\nflow = [1.0, -1.0]",
        ),
        (
            "scales",
            scales(),
            "[1.0, 0.0]",
            "The rows of scales (the tile's x axis) follow the region's direction field.",
            "# Where no stroke combs the shape, the rows run along the sketch's x axis:\n# scales have one \"up\" and cannot follow an outline's flow around a vortex.\nflow = [1.0, 0.0]",
        ),
    ] {
        write(&root.join(format!("styles/{name}/tile.svg")), &tile)?;
        write(
            &root.join(format!("styles/{name}/style.toml")),
            &format!(
                "# Fill style drawn by examples/make_fill_styles.rs: a seamless {T}×{T} tile.\nkind = \"fill\"\n# Tile pixels on its longest side (1 px per tile unit).\nresolution = 96\n# Sketch units per tile unit.\nscale = 1.0\n# {says}\ndirection = {dir}\n{flow}\npatch = 9\nlevels = 2\niterations = 4\n\n[[exemplar]]\nfile = \"tile.svg\"\n"
            ),
        )?;
    }
    let f = root.join("samples/fill");
    write(
        &f.join("circle.svg"),
        &sketch("  <circle cx=\"100\" cy=\"100\" r=\"90\" fill=\"#ccc\"/>\n"),
    )?;
    write(&f.join("star.svg"), &sketch(&star()))?;
    // A letter S as one filled outline.
    write(
        &f.join("letter.svg"),
        &sketch("  <path d=\"M150 40C130 14 58 10 46 50C34 92 120 88 136 118C150 146 112 176 78 168C60 164 48 154 40 144L26 166C48 192 120 204 156 170C190 136 166 94 122 82C88 72 72 66 78 50C86 28 124 36 136 58Z\" fill=\"#ccc\"/>\n"),
    )?;
    write(
        &f.join("frame.svg"),
        &sketch("  <path d=\"M36 20H164A16 16 0 0 1 180 36V164A16 16 0 0 1 164 180H36A16 16 0 0 1 20 164V36A16 16 0 0 1 36 20ZM70 66V134H130V66Z\" fill=\"#ccc\" fill-rule=\"evenodd\"/>\n"),
    )?;
    write(
        &f.join("combed.svg"),
        &sketch("  <rect x=\"10\" y=\"30\" width=\"180\" height=\"140\" rx=\"20\" fill=\"#ccc\"/>\n  <path d=\"M20 150C70 150 90 50 180 50\" fill=\"none\" stroke=\"#f00\" stroke-opacity=\"0.3\" stroke-width=\"80\"/>\n"),
    )?;
    write(
        &f.join("open-only.svg"),
        &sketch(
            "  <path d=\"M20 20L180 180\" fill=\"none\" stroke=\"#000\" stroke-width=\"4\"/>\n",
        ),
    )?;
    Ok(())
}
