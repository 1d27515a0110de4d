//! Fills the closed shapes of a sketch with an art pattern synthesized
//! from a fill style's tile.
//!
//! ```text
//! cargo run --release --example fill -- knot samples/fill/circle.svg knot.svg
//! ```

use flourish::{FillOptions, Library, Sketch, StyleKind, StyleOptions, Styles};

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let [style, sketch, out] = args.as_slice() else {
        eprintln!("usage: fill STYLE SKETCH.svg OUT.svg");
        std::process::exit(2);
    };
    let library = Library::shipped();
    let load = StyleOptions::default();
    let style = library.load(style, &load)?;
    let sketch = Sketch::from_svg(&std::fs::read(sketch)?)?;
    // Shapes may name another style with data-style="NAME".
    let named = library.load_named(&sketch, StyleKind::Fill, &load)?;
    let result = flourish::fill(
        &sketch,
        Styles::new(&style, &named),
        &FillOptions::default(),
    )?;
    std::fs::write(out, result.to_svg())?;
    Ok(())
}
