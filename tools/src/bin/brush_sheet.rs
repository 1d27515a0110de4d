//! Builds the README's brush comparison sheets: for each shipped brush
//! style, sketch | art-brush baseline (one exemplar stretched along the
//! whole path) | flourish, on the S-curve and meander samples, written to
//! `docs/brush-STYLE.png`. Run with
//! `cargo run --release -p flourish-tools --bin brush_sheet`.

use flourish::{BrushOptions, Library, Sketch, StyleOptions};
use flourish_tools::{inner, render_png, root};

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let root = root();
    for st in ["vine", "scroll", "doodle"] {
        let style = Library::shipped().load(st, &StyleOptions::default())?;
        let mut rows = String::new();
        let mut y = 0.0;
        let mut width: f64 = 0.0;
        for s in ["s-curve", "meander"] {
            let path = root.join("samples/brush").join(format!("{s}.svg"));
            let text = std::fs::read_to_string(&path)?;
            let sketch = Sketch::from_svg(text.as_bytes())?;
            let art = flourish::brush(
                &sketch,
                &style,
                &BrushOptions {
                    art_brush: true,
                    ..BrushOptions::default()
                },
            )?;
            let fl = flourish::brush(&sketch, &style, &BrushOptions::default())?;
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
        std::fs::write(
            &out,
            render_png(&svg, Some(1200), Some([255, 255, 255, 255]))?,
        )?;
        println!("{}", out.display());
    }
    Ok(())
}
