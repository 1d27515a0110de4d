//! Grows ornament of a brush style along the stroked paths of a sketch.
//!
//! ```text
//! cargo run --release --example brush -- vine samples/brush/s-curve.svg vine.svg
//! ```

use flourish::{BrushOptions, Library, Sketch, StyleOptions};

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let [style, sketch, out] = args.as_slice() else {
        eprintln!("usage: brush STYLE SKETCH.svg OUT.svg");
        std::process::exit(2);
    };
    // A shipped style by name, or a folder holding style.toml.
    let style = Library::shipped().load(style, &StyleOptions::default())?;
    let sketch = Sketch::from_svg(&std::fs::read(sketch)?)?;
    let result = flourish::brush(&sketch, &style, &BrushOptions::default())?;
    for warning in &result.warnings {
        eprintln!("warning: {warning}");
    }
    std::fs::write(out, result.to_svg())?;
    Ok(())
}
