//! Draws the README's fill pictures: tile (3×3 repeats) | region | result,
//! one PNG per shipped style, into `docs/fill-STYLE.png`; and a gallery of
//! every style in every uncombed sample shape, `docs/fill-gallery.png`.
//!
//! Run: `cargo run --release -p flourish-tools --bin fill_readme`.

use flourish::{FillOptions, Library, Sketch, StyleOptions};
use flourish_tools::{inner, render_png, root};
use std::path::Path;

/// The shipped `style` in the sample `sketch_path`, as SVG text.
fn fill(style: &str, sketch_path: &Path) -> Result<String, Box<dyn std::error::Error>> {
    let style = Library::shipped().load(style, &StyleOptions::default())?;
    let sketch = Sketch::from_svg(&std::fs::read(sketch_path)?)?;
    Ok(flourish::fill(&sketch, &style, &FillOptions::default())?.to_svg())
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let root = root();
    for (style, sample) in [("knot", "circle"), ("scales", "combed")] {
        let tile = std::fs::read_to_string(root.join(format!("styles/{style}/tile.svg")))?;
        let sketch_path = root.join(format!("samples/fill/{sample}.svg"));
        let sketch = std::fs::read_to_string(&sketch_path)?;
        let result = fill(style, &sketch_path)?;
        let mut tiles = String::new();
        for j in 0..3 {
            for i in 0..3 {
                tiles += &cell(i * 64, j * 64, 64, inner(&tile));
            }
        }
        let svg = format!(
            "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"640\" height=\"200\" viewBox=\"0 0 640 200\">\
             <rect width=\"640\" height=\"200\" fill=\"#fff\"/>\
             <svg x=\"4\" y=\"4\" width=\"192\" height=\"192\" viewBox=\"0 0 192 192\">{tiles}</svg>\
             <rect x=\"4\" y=\"4\" width=\"64\" height=\"64\" fill=\"none\" stroke=\"#e04040\" stroke-width=\"1.5\"/>\
             <svg x=\"220\" y=\"0\" width=\"200\" height=\"200\" viewBox=\"0 0 200 200\">{}</svg>\
             <svg x=\"440\" y=\"0\" width=\"200\" height=\"200\" viewBox=\"0 0 200 200\">{}</svg></svg>",
            inner(&sketch),
            inner(&result)
        );
        write_png(&root.join(format!("docs/fill-{style}.png")), &svg, 640)?;
    }
    // The gallery: a row per style, a column per shape.
    let shapes = ["circle", "star", "letter", "frame"];
    let styles = ["knot", "scales"];
    let (w, h) = (200 * shapes.len(), 200 * styles.len());
    let mut cells = String::new();
    for (j, style) in styles.iter().enumerate() {
        for (i, shape) in shapes.iter().enumerate() {
            let sketch_path = root.join(format!("samples/fill/{shape}.svg"));
            let result = fill(style, &sketch_path)?;
            cells += &cell(i * 200, j * 200, 200, inner(&result));
        }
    }
    let svg = format!(
        "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"{w}\" height=\"{h}\" viewBox=\"0 0 {w} {h}\">\
         <rect width=\"{w}\" height=\"{h}\" fill=\"#fff\"/>{cells}</svg>"
    );
    write_png(&root.join("docs/fill-gallery.png"), &svg, w as u32)?;
    Ok(())
}

/// A square nested viewport of `size` units at `(x, y)` showing `body`
/// drawn on a `size`-unit page.
fn cell(x: usize, y: usize, size: usize, body: &str) -> String {
    format!("<svg x=\"{x}\" y=\"{y}\" width=\"{size}\" height=\"{size}\" viewBox=\"0 0 {size} {size}\">{body}</svg>")
}

/// Renders SVG text `svg` at `width` px wide into the PNG file `out`.
fn write_png(out: &Path, svg: &str, width: u32) -> Result<(), Box<dyn std::error::Error>> {
    std::fs::write(out, render_png(svg, Some(width), None)?)?;
    println!("{}", out.display());
    Ok(())
}
