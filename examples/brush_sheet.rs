//! Builds the README's brush comparison sheets: for each shipped brush
//! style, sketch | art-brush baseline (one exemplar stretched along the
//! whole path) | flourish, on the S-curve and meander samples, written to
//! `docs/brush-STYLE.png`. Run with
//! `cargo run --release --example brush_sheet`.

use flourish::brush::analysis::{AnalysisOptions, BrushStyle};
use flourish::brush::output::brush_sketch;
use flourish::brush::pipeline::BrushOptions;
use std::path::Path;

/// The content of an SVG document, without its outer `<svg>` element.
fn inner(svg: &str) -> &str {
    let start = svg
        .find("<svg")
        .and_then(|i| svg[i..].find('>').map(|j| i + j + 1));
    let end = svg.rfind("</svg>");
    match (start, end) {
        (Some(s), Some(e)) if s <= e => &svg[s..e],
        _ => "",
    }
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let analysis = AnalysisOptions::default();
    for st in ["vine", "scroll", "doodle"] {
        let style = BrushStyle::load(&root.join("styles").join(st), &analysis)?;
        let mut rows = String::new();
        let mut y = 0.0;
        let mut width: f64 = 0.0;
        for s in ["s-curve", "meander"] {
            let path = root.join("samples/brush").join(format!("{s}.svg"));
            let sketch = flourish::read::sketch::load(&path)?;
            let text = std::fs::read_to_string(&path)?;
            let art = brush_sketch(
                &style,
                &sketch,
                &BrushOptions {
                    art_brush: true,
                    ..BrushOptions::default()
                },
            )?;
            let fl = brush_sketch(&style, &sketch, &BrushOptions::default())?;
            // Every row is scaled to panels 800 units wide.
            let k = 800.0 / sketch.width;
            let (w, h) = (800.0, sketch.height * k);
            let sketch_g = inner(&text).replace("stroke=\"#000\"", "stroke=\"#bbb\"");
            // Each panel is a nested viewport: it clips what reaches past
            // the sketch's own page, so panels never overlap.
            let (sw, sh) = (sketch.width, sketch.height);
            let panel = |x: f64, body: &str| {
                format!(
                    "<svg x=\"{x}\" y=\"{y}\" width=\"{w}\" height=\"{h}\" viewBox=\"0 0 {sw} {sh}\">{body}</svg>"
                )
            };
            rows.push_str(&panel(0.0, &sketch_g));
            rows.push_str(&panel(w, inner(&art.document.to_svg())));
            rows.push_str(&panel(2.0 * w, inner(&fl.document.to_svg())));
            y += h;
            width = width.max(3.0 * w);
        }
        let svg = format!(
            "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"{width}\" height=\"{y}\" viewBox=\"0 0 {width} {y}\">{rows}</svg>"
        );
        let out = root.join("docs").join(format!("brush-{st}.png"));
        let tree = flourish::read::svg::parse_svg(&out, svg.as_bytes())?;
        let pixmap =
            flourish::render::render_tree(&out, &tree, Some(1200), Some([255, 255, 255, 255]))?;
        let png = pixmap.encode_png()?;
        flourish::io::write_atomic(&out, &png)?;
        println!("{}", out.display());
    }
    Ok(())
}
