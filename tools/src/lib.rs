//! What the tools share: the repository's root, SVG documents nested as
//! panels, and rendering to PNG.

use std::path::{Path, PathBuf};

/// The repository's root folder.
pub fn root() -> PathBuf {
    Path::new(concat!(env!("CARGO_MANIFEST_DIR"), "/..")).to_path_buf()
}

/// The content of an SVG document, without its outer `<svg>` element.
pub fn inner(svg: &str) -> &str {
    let start = svg
        .find("<svg")
        .and_then(|i| svg[i..].find('>').map(|j| i + j + 1));
    let end = svg.rfind("</svg>");
    match (start, end) {
        (Some(s), Some(e)) if s <= e => &svg[s..e],
        _ => "",
    }
}

/// Renders SVG text `svg` `width` px wide (its own size when `None`),
/// over `background` (RGBA; `None` keeps transparency), as PNG bytes.
pub fn render_png(
    svg: &str,
    width: Option<u32>,
    background: Option<[u8; 4]>,
) -> Result<Vec<u8>, Box<dyn std::error::Error>> {
    use resvg::{tiny_skia, usvg};
    let tree = usvg::Tree::from_data(svg.as_bytes(), &usvg::Options::default())?;
    let size = tree.size();
    let scale = width.map_or(1.0, |w| w as f32 / size.width());
    let (w, h) = (
        (size.width() * scale).ceil() as u32,
        (size.height() * scale).ceil() as u32,
    );
    let mut pixmap = tiny_skia::Pixmap::new(w.max(1), h.max(1)).ok_or("empty picture")?;
    if let Some([r, g, b, a]) = background {
        pixmap.fill(tiny_skia::Color::from_rgba8(r, g, b, a));
    }
    resvg::render(
        &tree,
        tiny_skia::Transform::from_scale(scale, scale),
        &mut pixmap.as_mut(),
    );
    Ok(pixmap.encode_png()?)
}

/// Writes `svg`'s `--preview` rendering (on white, at least 512 px) to
/// `out`.
pub fn write_preview(svg: &str, out: &Path) -> Result<(), Box<dyn std::error::Error>> {
    std::fs::write(out, flourish::preview_png(svg)?)?;
    Ok(())
}

/// A uniform number in [0, 1) from the key words: the library's seeded
/// streams (SplitMix64's finalizer over the words), so that the generators
/// make the same assets every time.
pub fn unit(words: &[u64]) -> f64 {
    fn mix(mut z: u64) -> u64 {
        z = z.wrapping_add(0x9E37_79B9_7F4A_7C15);
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^ (z >> 31)
    }
    let h = words
        .iter()
        .fold(0x6A09_E667_F3BC_C909, |h, &w| mix(h ^ mix(w)));
    (h >> 11) as f64 / (1u64 << 53) as f64
}
