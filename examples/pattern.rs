//! Arranges the hand-drawn elements of a pattern style along the stroked
//! paths and inside the filled shapes of a sketch.
//!
//! ```text
//! cargo run --release --example pattern -- stipple samples/pattern/blob.svg stipple.svg
//! ```

use flourish::{Library, PatternOptions, Sketch, StyleKind, StyleOptions, Styles};

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let [style, sketch, out] = args.as_slice() else {
        eprintln!("usage: pattern STYLE SKETCH.svg OUT.svg");
        std::process::exit(2);
    };
    let library = Library::shipped();
    let load = StyleOptions::default();
    let style = library.load(style, &load)?;
    let sketch = Sketch::from_svg(&std::fs::read(sketch)?)?;
    // Shapes may name another style with data-style="NAME".
    let named = library.load_named(&sketch, StyleKind::Pattern, &load)?;
    let opts = PatternOptions {
        seed: 7,
        ..PatternOptions::default()
    };
    let result = flourish::pattern(&sketch, Styles::new(&style, &named), &opts)?;
    std::fs::write(out, result.to_svg())?;
    Ok(())
}
