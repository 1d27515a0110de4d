//! Comparing two SVGs by rendering: the library side of `flourish diff`,
//! used by build pipelines and the golden tests.

use crate::error::{Error, Result};
use crate::{io, render};
use resvg::tiny_skia::Pixmap;
use std::path::Path;

/// A channel difference (0–255) above this marks a pixel as changed; it
/// absorbs anti-aliasing noise of the renderer.
pub const CHANNEL_THRESHOLD: u8 = 8;

/// Longest side, in pixels, at which documents are rendered for comparison.
pub const DIFF_SIDE: u32 = 1024;

/// The outcome of a comparison.
#[derive(Clone, Debug)]
pub struct DiffReport {
    /// Pixels that differ.
    pub changed: u64,
    /// Pixels compared.
    pub total: u64,
    /// Three panels side by side, expected | mask | actual, as RGBA rows.
    pub(crate) panels: image::RgbaImage,
}

impl DiffReport {
    /// Fraction of pixels that differ, 0..=1.
    pub fn fraction(&self) -> f64 {
        if self.total == 0 {
            0.0
        } else {
            self.changed as f64 / self.total as f64
        }
    }
}

/// Renders both SVG texts at the same pixel size (the first one's, scaled to
/// [`DIFF_SIDE`]) over white and compares them pixel by pixel.
pub fn diff_svg_texts(a_name: &Path, a: &[u8], b_name: &Path, b: &[u8]) -> Result<DiffReport> {
    for (name, bytes) in [(a_name, a), (b_name, b)] {
        if !crate::read::ink::looks_like_svg(bytes) {
            return Err(Error::invalid(
                "not an SVG document (diff compares two SVG files; trace a picture first)",
            )
            .in_file(name));
        }
    }
    let ta = crate::read::svg::parse_svg(a).map_err(|e| e.in_file(a_name))?;
    let tb = crate::read::svg::parse_svg(b).map_err(|e| e.in_file(b_name))?;
    let (sa, sb) = (ta.size(), tb.size());
    if (sa.width() - sb.width()).abs() > 1e-3 || (sa.height() - sb.height()).abs() > 1e-3 {
        return Err(Error::invalid(format!(
            "size {}×{} differs from {} ({}×{})",
            sb.width(),
            sb.height(),
            a_name.display(),
            sa.width(),
            sa.height()
        ))
        .in_file(b_name));
    }
    let white = Some([255, 255, 255, 255]);
    let pa = render::render_tree(&ta, Some(DIFF_SIDE), white).map_err(|e| e.in_file(a_name))?;
    let pb = render::render_tree(&tb, Some(DIFF_SIDE), white).map_err(|e| e.in_file(b_name))?;
    Ok(compare(&pa, &pb))
}

/// Reads and compares two SVG files.
pub fn diff_files(a: &Path, b: &Path) -> Result<DiffReport> {
    let da = io::read_file(a)?;
    let db = io::read_file(b)?;
    diff_svg_texts(a, &da, b, &db)
}

fn compare(a: &Pixmap, b: &Pixmap) -> DiffReport {
    let (w, h) = (a.width(), a.height());
    let mut panels = image::RgbaImage::from_pixel(w * 3, h, image::Rgba([255, 255, 255, 255]));
    let mut changed = 0u64;
    let (da, db) = (a.data(), b.data());
    for y in 0..h {
        for x in 0..w {
            let i = ((y * w + x) * 4) as usize;
            let pa = [da[i], da[i + 1], da[i + 2], da[i + 3]];
            let pb = [db[i], db[i + 1], db[i + 2], db[i + 3]];
            let differs = pa
                .iter()
                .zip(&pb)
                .any(|(p, q)| p.abs_diff(*q) > CHANNEL_THRESHOLD);
            changed += differs as u64;
            panels.put_pixel(x, y, image::Rgba(pa));
            panels.put_pixel(x + 2 * w, y, image::Rgba(pb));
            let grey = 255 - (255 - pa[0].min(pa[1]).min(pa[2])) / 4;
            let m = if differs {
                [220, 0, 0, 255]
            } else {
                [grey, grey, grey, 255]
            };
            panels.put_pixel(x + w, y, image::Rgba(m));
        }
    }
    DiffReport {
        changed,
        total: w as u64 * h as u64,
        panels,
    }
}

impl DiffReport {
    /// Three panels side by side, expected | mask (changed pixels red) |
    /// actual, as PNG bytes.
    pub fn panels_png(&self) -> Result<Vec<u8>> {
        let mut png = Vec::new();
        self.panels
            .write_to(&mut std::io::Cursor::new(&mut png), image::ImageFormat::Png)
            .map_err(|e| Error::invalid(format!("PNG encoding failed: {e}")))?;
        Ok(png)
    }
}
