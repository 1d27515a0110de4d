//! Traces a bitmap (PNG, JPEG, …) or an SVG into compact filled Bézier
//! outlines, one layer per ink colour.
//!
//! ```text
//! cargo run --release --example trace -- samples/trace/glyph-a.png glyph.svg
//! ```

use flourish::{Image, ImageOptions, TraceOptions};

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let [input, out] = args.as_slice() else {
        eprintln!("usage: trace IN.png OUT.svg");
        std::process::exit(2);
    };
    let read = ImageOptions {
        layers: true,
        ..ImageOptions::default()
    };
    let image = Image::from_bytes(&std::fs::read(input)?, &read)?;
    let result = flourish::trace(&image, &TraceOptions::default())?;
    for note in &result.notes {
        eprintln!("{input}: {note}");
    }
    std::fs::write(out, result.to_svg())?;
    Ok(())
}
