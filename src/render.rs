//! Rendering SVG to pixels with resvg: previews, render tests and `diff`.

use crate::error::{Error, Result};
use crate::io;
use resvg::tiny_skia;
use resvg::usvg;

/// Renders `tree` so that its longest side is `max_side` px (its own size
/// when `max_side` is `None`), over `background` (RGBA, `None` keeps
/// transparency).
pub fn render_tree(
    tree: &usvg::Tree,
    max_side: Option<u32>,
    background: Option<[u8; 4]>,
) -> Result<tiny_skia::Pixmap> {
    let size = tree.size();
    let scale = match max_side {
        Some(m) => m as f32 / size.width().max(size.height()),
        None => 1.0,
    };
    let w = (size.width() * scale).ceil().max(1.0);
    let h = (size.height() * scale).ceil().max(1.0);
    io::check_canvas(w as u64, h as u64)?;
    let mut pixmap = tiny_skia::Pixmap::new(w as u32, h as u32)
        .ok_or_else(|| Error::invalid("cannot allocate the render canvas"))?;
    if let Some([r, g, b, a]) = background {
        pixmap.fill(tiny_skia::Color::from_rgba8(r, g, b, a));
    }
    resvg::render(
        tree,
        tiny_skia::Transform::from_scale(scale, scale),
        &mut pixmap.as_mut(),
    );
    Ok(pixmap)
}

/// Renders SVG text on white as PNG bytes (documents smaller than 512 px
/// are enlarged to 512 px).
pub fn preview_png(svg: &str) -> Result<Vec<u8>> {
    let tree = crate::read::svg::parse_svg(svg.as_bytes())?;
    let longest = tree.size().width().max(tree.size().height());
    // Previews of tiny documents are enlarged to a readable size.
    let max_side = if longest < 512.0 { Some(512) } else { None };
    let pixmap = render_tree(&tree, max_side, Some([255, 255, 255, 255]))?;
    pixmap
        .encode_png()
        .map_err(|e| Error::invalid(format!("PNG encoding failed: {e}")))
}
