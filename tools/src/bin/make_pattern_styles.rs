//! Draws the example SVGs of the four shipped pattern styles and the
//! pattern sample sketches, deterministically (hashed jitter, no clock).
//!
//! Run: `cargo run -p flourish-tools --bin make_pattern_styles` (writes
//! `styles/` and `samples/pattern/` under the crate root).

use flourish_tools::unit;
use std::f64::consts::PI;
use std::fmt::Write as _;
use std::path::Path;

fn jitter(words: &[u64], amp: f64) -> f64 {
    (unit(words) * 2.0 - 1.0) * amp
}

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

/// A row of sketchy hatches whose length swells and shrinks (three waves);
/// every third hatch is drawn with two overlapping gestures.
fn hatching() -> String {
    let mut b = String::new();
    let n = 27;
    for i in 0..n {
        let k = i as u64;
        let x = 14.0 + i as f64 * 9.0 + jitter(&[1, k], 0.8);
        let len = 22.0 + 14.0 * (2.0 * PI * i as f64 / 9.0).sin();
        let lean = 0.28 + jitter(&[2, k], 0.05);
        let (dx, dy) = (lean.sin() * len / 2.0, lean.cos() * len / 2.0);
        let cy = 40.0 + jitter(&[3, k], 0.8);
        let bow = jitter(&[4, k], 1.6);
        let gestures = if i % 3 == 1 { 2 } else { 1 };
        for g in 0..gestures {
            let o = g as f64 * 1.1;
            let (x0, y0, x1, y1) = (x - dx + o, cy + dy, x + dx + o * 0.6, cy - dy);
            let (mx, my) = ((x0 + x1) / 2.0 + bow, (y0 + y1) / 2.0);
            let _ = writeln!(
                b,
                "  <path d=\"M{x0:.2} {y0:.2}Q{mx:.2} {my:.2} {x1:.2} {y1:.2}\" fill=\"none\" stroke=\"#26282c\" stroke-width=\"{:.2}\" stroke-linecap=\"round\"/>",
                1.5 - g as f64 * 0.5
            );
        }
    }
    svg(270.0, 80.0, &b)
}

/// Stipples: dots of varying size thrown with a minimum distance (dart
/// throwing), a few of them drawn as tiny flicks.
fn stipple() -> String {
    let mut pts: Vec<(f64, f64)> = Vec::new();
    let (w, h, r_min) = (180.0, 180.0, 11.0);
    let mut k = 0u64;
    while pts.len() < 400 && k < 20_000 {
        let p = (
            8.0 + unit(&[10, k]) * (w - 16.0),
            8.0 + unit(&[11, k]) * (h - 16.0),
        );
        k += 1;
        if pts.iter().all(|q| (q.0 - p.0).hypot(q.1 - p.1) >= r_min) {
            pts.push(p);
        }
    }
    let mut b = String::new();
    for (i, (x, y)) in pts.iter().enumerate() {
        let i = i as u64;
        let r = 1.3 + unit(&[12, i]) * 1.1;
        if i % 7 == 3 {
            let a = unit(&[13, i]) * PI;
            let (dx, dy) = (a.cos() * 1.6, a.sin() * 1.6);
            let _ = writeln!(
                b,
                "  <path d=\"M{:.2} {:.2}L{:.2} {:.2}\" fill=\"none\" stroke=\"#1f1d1a\" stroke-width=\"{:.2}\" stroke-linecap=\"round\"/>",
                x - dx,
                y - dy,
                x + dx,
                y + dy,
                r * 1.2
            );
        } else {
            let _ = writeln!(
                b,
                "  <circle cx=\"{x:.2}\" cy=\"{y:.2}\" r=\"{r:.2}\" fill=\"#1f1d1a\"/>"
            );
        }
    }
    svg(w, h, &b)
}

/// Five-petal flowers on a staggered grid, petal colours alternating along
/// each row, each with a golden heart; every petal is its own stroke.
fn flowers() -> String {
    let mut b = String::new();
    let colours = [("#d9487a", "#a3244f"), ("#3f7fc4", "#1f4f8a")];
    let (cols, rows, dx, dy) = (7, 6, 30.0, 26.0);
    for row in 0..rows {
        for col in 0..cols {
            let k = (row * 16 + col) as u64;
            let cx = 20.0
                + col as f64 * dx
                + if row % 2 == 1 { dx / 2.0 } else { 0.0 }
                + jitter(&[20, k], 1.2);
            let cy = 20.0 + row as f64 * dy + jitter(&[21, k], 1.2);
            let (fill, edge) = colours[col % 2];
            let turn = unit(&[22, k]) * 2.0 * PI / 5.0;
            for p in 0..5 {
                let a = turn + p as f64 * 2.0 * PI / 5.0;
                let (ux, uy) = (a.cos(), a.sin());
                let (vx, vy) = (-uy, ux);
                let (l, w) = (9.0, 3.6);
                let (bx, by) = (cx + ux * 1.5, cy + uy * 1.5);
                let (tx, ty) = (cx + ux * l, cy + uy * l);
                let _ = writeln!(
                    b,
                    "  <path d=\"M{bx:.2} {by:.2}C{:.2} {:.2} {:.2} {:.2} {tx:.2} {ty:.2}C{:.2} {:.2} {:.2} {:.2} {bx:.2} {by:.2}Z\" fill=\"{fill}\" stroke=\"{edge}\" stroke-width=\".7\"/>",
                    bx + vx * w + ux * 2.0,
                    by + vy * w + uy * 2.0,
                    tx + vx * w * 0.9 - ux * 1.5,
                    ty + vy * w * 0.9 - uy * 1.5,
                    tx - vx * w * 0.9 - ux * 1.5,
                    ty - vy * w * 0.9 - uy * 1.5,
                    bx - vx * w + ux * 2.0,
                    by - vy * w + uy * 2.0,
                );
            }
            let _ = writeln!(
                b,
                "  <circle cx=\"{cx:.2}\" cy=\"{cy:.2}\" r=\"2.2\" fill=\"#f2b632\"/>"
            );
        }
    }
    svg(240.0, 170.0, &b)
}

/// Tapered brush dabs in a row whose orientation turns smoothly, 1.5 half
/// turns over the row, so the turning can continue past its end.
fn brushmarks() -> String {
    let mut b = String::new();
    let n = 26;
    for i in 0..n {
        let k = i as u64;
        let x = 16.0 + i as f64 * 20.0;
        let y = 30.0 + jitter(&[30, k], 0.6);
        let a = i as f64 * PI / 16.0 + jitter(&[31, k], 0.03);
        let (ux, uy) = (a.cos(), a.sin());
        let (vx, vy) = (-uy, ux);
        let (l, w) = (8.5, 3.2);
        let bend = 1.5;
        let (x0, y0, x1, y1) = (x - ux * l, y - uy * l, x + ux * l, y + uy * l);
        let _ = writeln!(
            b,
            "  <path d=\"M{x0:.2} {y0:.2}C{:.2} {:.2} {:.2} {:.2} {x1:.2} {y1:.2}C{:.2} {:.2} {:.2} {:.2} {x0:.2} {y0:.2}Z\" fill=\"#1d4e89\"/>",
            x - ux * l * 0.5 + vx * (w + bend),
            y - uy * l * 0.5 + vy * (w + bend),
            x + ux * l * 0.4 + vx * (w * 0.8 + bend),
            y + uy * l * 0.4 + vy * (w * 0.8 + bend),
            x + ux * l * 0.4 - vx * (w * 0.6 - bend),
            y + uy * l * 0.4 - vy * (w * 0.6 - bend),
            x - ux * l * 0.5 - vx * (w - bend),
            y - uy * l * 0.5 - vy * (w - bend),
        );
    }
    svg(532.0, 60.0, &b)
}

fn samples(dir: &Path) -> std::io::Result<()> {
    // An open wave: the spine for 1-D patterns; stroke width = band width.
    write(
        &dir.join("wave.svg"),
        &svg(
            640.0,
            220.0,
            "  <path d=\"M40 150C140 20 240 20 320 110S500 200 600 70\" fill=\"none\" stroke=\"#888\" stroke-width=\"36\"/>\n",
        ),
    )?;
    // A closed blob with a round hole: a region query with a hole.
    write(
        &dir.join("blob.svg"),
        &svg(
            420.0,
            320.0,
            "  <path d=\"M210 30C320 20 400 90 390 170S310 300 200 290 20 230 30 150 100 40 210 30Z\
M250 160a40 40 0 1 0 -80 0a40 40 0 1 0 80 0Z\" fill=\"#ddd\" fill-rule=\"evenodd\"/>\n",
        ),
    )?;
    // A frame: a spiral path with hatching and a square region of flowers.
    write(
        &dir.join("mixed.svg"),
        &svg(
            480.0,
            300.0,
            "  <rect id=\"meadow\" x=\"250\" y=\"40\" width=\"200\" height=\"220\" rx=\"24\" fill=\"#eee\" data-style=\"flowers\"/>\n\
  <path id=\"vine\" d=\"M40 260C40 120 120 40 200 60\" fill=\"none\" stroke=\"#999\" stroke-width=\"16\" data-style=\"brushmarks\"/>\n\
  <circle cx=\"110\" cy=\"190\" r=\"40\" fill=\"none\" stroke=\"#999\" stroke-width=\"10\"/>\n",
        ),
    )?;
    Ok(())
}

fn main() -> std::io::Result<()> {
    let root = Path::new(concat!(env!("CARGO_MANIFEST_DIR"), "/.."));
    let styles = root.join("styles");
    let defs: [(&str, String, &str); 4] = [
        (
            "hatching",
            hatching(),
            "scale = 5.0\nrings = 4\nfit = \"skeleton\"\n",
        ),
        ("stipple", stipple(), "scale = 4.0\nrings = 1\n"),
        ("flowers", flowers(), "scale = 7.0\nrings = 2\n"),
        ("brushmarks", brushmarks(), "scale = 2.5\nrings = 5\n"),
    ];
    for (name, example, params) in defs {
        let dir = styles.join(name);
        write(&dir.join("example.svg"), &example)?;
        write(
            &dir.join("style.toml"),
            &format!(
                "# Pattern style drawn by examples/make_pattern_styles.rs.\nkind = \"pattern\"\n{params}\n[[exemplar]]\nfile = \"example.svg\"\n"
            ),
        )?;
    }
    samples(&root.join("samples/pattern"))
}
