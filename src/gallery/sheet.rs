//! Contact sheets: per style, a row per case of its swatch (or first
//! exemplar, or example) | the sketch | the result, each in its own
//! viewport; per bitmap, the drawing | the trace.

use super::checks::Case;
use std::collections::BTreeMap;
use std::path::Path;

/// Panel size, sheet units (px at the rendered width).
const PANEL: (f64, f64) = (320.0, 240.0);

/// `svg` in a `PANEL`-sized viewport at (`x`, `y`), its own viewBox (or
/// width and height) scaled to fit, with a grey frame.
fn panel(x: f64, y: f64, svg: &str) -> String {
    let open_end = svg
        .find("<svg")
        .and_then(|i| svg[i..].find('>').map(|j| i + j + 1));
    let close = svg.rfind("</svg>");
    let (Some(open_end), Some(close)) = (open_end, close) else {
        return String::new();
    };
    let head = &svg[..open_end];
    let attr = |name: &str| {
        head.split(&format!(" {name}=\""))
            .nth(1)
            .and_then(|r| r.split('"').next())
            .map(str::to_string)
    };
    let number = |v: Option<String>| {
        v.and_then(|s| {
            s.trim_end_matches(|c: char| c.is_ascii_alphabetic())
                .parse::<f64>()
                .ok()
        })
    };
    let view_box = attr("viewBox").unwrap_or_else(|| {
        format!(
            "0 0 {} {}",
            number(attr("width")).unwrap_or(100.0),
            number(attr("height")).unwrap_or(100.0)
        )
    });
    let (w, h) = PANEL;
    format!(
        "<rect x=\"{x}\" y=\"{y}\" width=\"{w}\" height=\"{h}\" fill=\"#fff\" stroke=\"#ccc\"/>\
         <svg x=\"{}\" y=\"{}\" width=\"{}\" height=\"{}\" viewBox=\"{view_box}\">{}</svg>",
        x + 6.0,
        y + 6.0,
        w - 12.0,
        h - 12.0,
        &svg[open_end..close]
    )
}

/// The first exemplar file of the style in `dir`, as text.
fn swatch(dir: &Path) -> Option<String> {
    let toml = crate::read::style::load(dir).ok()?;
    let file = dir.join(&toml.exemplar.first()?.file);
    std::fs::read_to_string(file).ok()
}

/// Renders sheet SVG text `width` px wide to PNG file `out`.
fn render(svg: &str, width: u32, out: &Path) {
    let Ok(tree) = crate::read::svg::parse_svg(svg.as_bytes()) else {
        return;
    };
    if let Ok(pm) = crate::render::render_tree(&tree, Some(width), Some([255, 255, 255, 255])) {
        if let Ok(png) = pm.encode_png() {
            let _ = std::fs::write(out, png);
        }
    }
}

/// Writes `out/MODE-STYLE.png` for each style of `cases` (for a trace,
/// `out/trace.png`).
pub(super) fn write(mode: &str, cases: &[Case], out: &Path) {
    let mut groups: BTreeMap<String, Vec<&Case>> = BTreeMap::new();
    for c in cases {
        let key = c
            .style
            .file_name()
            .map(|n| n.to_string_lossy().into_owned())
            .unwrap_or_default();
        groups.entry(key).or_default().push(c);
    }
    let (pw, ph) = PANEL;
    for (style, rows) in groups {
        let cols = if mode == "trace" { 2.0 } else { 3.0 };
        let mut body = String::new();
        for (i, c) in rows.iter().enumerate() {
            let y = i as f64 * ph;
            let result = c
                .output
                .as_ref()
                .and_then(|p| std::fs::read_to_string(p).ok())
                .unwrap_or_else(|| {
                    format!(
                        "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"320\" height=\"240\"><text x=\"10\" y=\"120\">{}</text></svg>",
                        c.error.as_deref().unwrap_or("no output").replace('<', "&lt;")
                    )
                });
            if mode == "trace" {
                let truth =
                    std::fs::read_to_string(c.input.with_extension("svg")).unwrap_or_default();
                body += &panel(0.0, y, &truth);
                body += &panel(pw, y, &result);
            } else {
                body += &panel(0.0, y, &swatch(&c.style).unwrap_or_default());
                body += &panel(
                    pw,
                    y,
                    &std::fs::read_to_string(&c.input).unwrap_or_default(),
                );
                body += &panel(2.0 * pw, y, &result);
            }
        }
        let (w, h) = (cols * pw, rows.len() as f64 * ph);
        let svg = format!(
            "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"{w}\" height=\"{h}\" viewBox=\"0 0 {w} {h}\">{body}</svg>"
        );
        let name = if mode == "trace" {
            "trace".to_string()
        } else {
            format!("{mode}-{style}")
        };
        render(&svg, w as u32, &out.join(format!("{name}.png")));
    }
}
