//! Runs `pattern` for every shipped pattern style on the pattern samples
//! and writes the outputs and their previews: the golden files and the
//! README pictures (example | along a path | inside a shape).
//!
//! Run: `cargo run --release -p flourish-tools --bin pattern_demo [OUT_DIR]`
//! (default `golden/pattern`). Prints a line per output with its shapes
//! and time.

use flourish::{Library, PatternOptions, Sketch, StyleKind, StyleOptions, Styles};
use flourish_tools::{root, write_preview};
use std::path::{Path, PathBuf};
use std::time::Instant;

type Result<T> = std::result::Result<T, Box<dyn std::error::Error>>;

/// The pattern of shipped `style` (and the shapes' own `data-style`s) in
/// the sketch `path`.
fn pattern(style: &str, path: &Path, opts: &PatternOptions) -> Result<flourish::Document> {
    let lib = Library::shipped();
    let load = StyleOptions::default();
    let style = lib.load(style, &load)?;
    let sketch = Sketch::from_svg(&std::fs::read(path)?)?;
    let named = lib.load_named(&sketch, StyleKind::Pattern, &load)?;
    Ok(flourish::pattern(&sketch, Styles::new(&style, &named), opts)?.document)
}

/// The styles shipped for `pattern`.
const STYLES: [&str; 4] = ["hatching", "stipple", "flowers", "brushmarks"];
/// Samples run with every style (the `mixed` one names its own styles).
const SAMPLES: [&str; 2] = ["wave", "blob"];

/// The viewBox and the inner markup of an SVG document.
fn parts(svg: &str) -> (String, String) {
    let open_end = svg.find('>').map_or(0, |i| i + 1);
    let head = &svg[..open_end];
    let vb = head
        .split("viewBox=\"")
        .nth(1)
        .and_then(|r| r.split('"').next())
        .unwrap_or("0 0 100 100")
        .to_string();
    let body = svg[open_end..]
        .trim_end()
        .trim_end_matches("</svg>")
        .to_string();
    (vb, body)
}

/// Three documents side by side in framed 400 × 260 panels.
fn strip(panels: &[String]) -> String {
    let (w, h, pad) = (400.0, 260.0, 10.0);
    let mut s = format!(
        "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"{}\" height=\"{}\">",
        w * panels.len() as f64,
        h
    );
    for (i, p) in panels.iter().enumerate() {
        let (vb, body) = parts(p);
        let x = i as f64 * w;
        s += &format!(
            "<rect x=\"{}\" y=\"{pad}\" width=\"{}\" height=\"{}\" fill=\"none\" stroke=\"#ccc\"/>",
            x + pad / 2.0,
            w - pad,
            h - 2.0 * pad
        );
        s += &format!(
            "<svg x=\"{}\" y=\"{}\" width=\"{}\" height=\"{}\" viewBox=\"{vb}\">{body}</svg>",
            x + 2.0 * pad,
            2.0 * pad,
            w - 4.0 * pad,
            h - 4.0 * pad
        );
    }
    s + "</svg>"
}

fn main() -> Result<()> {
    let root = root();
    let out: PathBuf = std::env::args()
        .nth(1)
        .map(PathBuf::from)
        .unwrap_or_else(|| root.join("golden/pattern"));
    std::fs::create_dir_all(&out)?;
    let samples = root.join("samples/pattern");
    for style in STYLES {
        let dir = root.join("styles").join(style);
        let ex = std::fs::read_to_string(dir.join("example.svg"))?;
        write_preview(&ex, &out.join(format!("{style}-example.png")))?;
        for sample in SAMPLES {
            let t = Instant::now();
            let doc = pattern(
                style,
                &samples.join(format!("{sample}.svg")),
                &PatternOptions::default(),
            )?;
            let ms = t.elapsed().as_secs_f64() * 1e3;
            let text = doc.to_svg();
            let name = format!("{sample}-{style}");
            std::fs::write(out.join(format!("{name}.svg")), &text)?;
            write_preview(&text, &out.join(format!("{name}.png")))?;
            let n: usize = doc.groups.iter().map(|g| g.shapes.len()).sum();
            println!("  {name}: {n} shapes in {ms:.1} ms");
        }
        // The README strip: example | along a path | inside a shape.
        let panels = [
            ex.clone(),
            std::fs::read_to_string(out.join(format!("wave-{style}.svg")))?,
            std::fs::read_to_string(out.join(format!("blob-{style}.svg")))?,
        ];
        write_preview(&strip(&panels), &out.join(format!("{style}-strip.png")))?;
        // The region again with variation 0.5, to show §3.3.
        let opts = PatternOptions {
            variation: 0.5,
            ..Default::default()
        };
        let doc = pattern(style, &samples.join("blob.svg"), &opts)?;
        let text = doc.to_svg();
        write_preview(&text, &out.join(format!("blob-{style}-variation.png")))?;
    }
    let text = pattern(
        "hatching",
        &samples.join("mixed.svg"),
        &PatternOptions::default(),
    )?
    .to_svg();
    std::fs::write(out.join("mixed.svg"), &text)?;
    write_preview(&text, &out.join("mixed.png"))?;
    Ok(())
}
