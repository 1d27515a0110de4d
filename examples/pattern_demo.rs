//! Runs `pattern` for every shipped pattern style on the pattern samples
//! and writes the outputs and their previews: the golden files and the
//! README pictures (example | along a path | inside a shape).
//!
//! Run: `cargo run --release --example pattern_demo [OUT_DIR]` (default
//! `golden/pattern`). Prints a line per style with the analysis figures.

use flourish::pattern::{self, PatternOptions, PatternStyle};
use flourish::render::write_preview;
use std::path::{Path, PathBuf};
use std::time::Instant;

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

fn main() -> flourish::Result<()> {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let out: PathBuf = std::env::args()
        .nth(1)
        .map(PathBuf::from)
        .unwrap_or_else(|| root.join("golden/pattern"));
    std::fs::create_dir_all(&out).map_err(|e| flourish::Error::io(&out, e))?;
    let samples = root.join("samples/pattern");
    for style in STYLES {
        let dir = root.join("styles").join(style);
        let ps = PatternStyle::load(&dir)?;
        let ex = std::fs::read_to_string(dir.join("example.svg"))
            .map_err(|e| flourish::Error::io(&dir, e))?;
        write_preview(&ex, &out.join(format!("{style}-example.png")))?;
        println!(
            "{style}: {} strokes -> {} elements, {:?}, spacing {:.2}, A_ref {:.0}",
            ps.strokes.len(),
            ps.elements().len(),
            ps.reference.dist.dim,
            ps.reference.dist.spacing,
            ps.reference.dist.area
        );
        for sample in SAMPLES {
            let opts = PatternOptions {
                style: style.into(),
                styles_dir: root.join("styles"),
                ..Default::default()
            };
            let t = Instant::now();
            let doc = pattern::run(&opts, &samples.join(format!("{sample}.svg")))?;
            let ms = t.elapsed().as_secs_f64() * 1e3;
            let text = doc.to_svg();
            let name = format!("{sample}-{style}");
            flourish::io::write_atomic(&out.join(format!("{name}.svg")), text.as_bytes())?;
            write_preview(&text, &out.join(format!("{name}.png")))?;
            let n: usize = doc.groups.iter().map(|g| g.shapes.len()).sum();
            println!("  {name}: {n} shapes in {ms:.1} ms");
        }
        // The README strip: example | along a path | inside a shape.
        let panels = [
            ex.clone(),
            std::fs::read_to_string(out.join(format!("wave-{style}.svg")))
                .map_err(|e| flourish::Error::io(&out, e))?,
            std::fs::read_to_string(out.join(format!("blob-{style}.svg")))
                .map_err(|e| flourish::Error::io(&out, e))?,
        ];
        write_preview(&strip(&panels), &out.join(format!("{style}-strip.png")))?;
        // The region again with variation 0.5, to show §3.3.
        let opts = PatternOptions {
            style: style.into(),
            styles_dir: root.join("styles"),
            variation: 0.5,
            ..Default::default()
        };
        let doc = pattern::run(&opts, &samples.join("blob.svg"))?;
        let text = doc.to_svg();
        write_preview(&text, &out.join(format!("blob-{style}-variation.png")))?;
    }
    let opts = PatternOptions {
        style: "hatching".into(),
        styles_dir: root.join("styles"),
        ..Default::default()
    };
    let text = pattern::run(&opts, &samples.join("mixed.svg"))?.to_svg();
    flourish::io::write_atomic(&out.join("mixed.svg"), text.as_bytes())?;
    write_preview(&text, &out.join("mixed.png"))?;
    Ok(())
}
