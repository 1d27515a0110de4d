//! SVG in, through usvg: the one adaptor every mode reads SVG with.
//!
//! Parsing never touches the file system or the network ([`svg_options`]);
//! SVGZ is inflated with a size cap ([`inflate_svgz`]); usvg's paths become
//! kurbo paths ([`to_bezpath`]) and its paints flat colours by one rule
//! ([`paint_color`]: a gradient is the mean of its stops), so a drawing
//! read as a sketch, an exemplar, a tile or a picture to trace gets the
//! same colours.

use crate::error::{Error, Result};
use crate::io::MAX_FILE_BYTES;
use crate::svg_out::Color;
use kurbo::{Affine, BezPath};
use resvg::usvg;
use std::borrow::Cow;

/// usvg options that never touch the file system or the network: external
/// and embedded images are ignored, no fonts are loaded.
pub fn svg_options() -> usvg::Options<'static> {
    usvg::Options {
        resources_dir: None,
        image_href_resolver: usvg::ImageHrefResolver {
            resolve_data: Box::new(|_, _, _| None),
            resolve_string: Box::new(|_, _| None),
        },
        ..usvg::Options::default()
    }
}

/// SVG bytes as plain text bytes: SVGZ (gzip) inflated, refusing more
/// than [`MAX_FILE_BYTES`] once inflated (a small file can inflate a
/// thousandfold); plain SVG as it is.
pub fn inflate_svgz(data: &[u8]) -> Result<Cow<'_, [u8]>> {
    inflate_capped(data, MAX_FILE_BYTES)
}

fn inflate_capped(data: &[u8], cap: u64) -> Result<Cow<'_, [u8]>> {
    use std::io::Read as _;
    if !data.starts_with(&[0x1f, 0x8b]) {
        return Ok(Cow::Borrowed(data));
    }
    let mut out = Vec::new();
    flate2::read::GzDecoder::new(data)
        .take(cap + 1)
        .read_to_end(&mut out)
        .map_err(|e| Error::Svg(format!("SVGZ does not inflate: {e}")))?;
    if out.len() as u64 > cap {
        return Err(Error::invalid(format!(
            "SVGZ inflates to more than the limit of {cap} bytes"
        )));
    }
    Ok(Cow::Owned(out))
}

/// Parses SVG bytes (plain or SVGZ, see [`inflate_svgz`]) with
/// [`svg_options`].
pub fn parse_svg(data: &[u8]) -> Result<usvg::Tree> {
    let data = inflate_svgz(data)?;
    let tree =
        usvg::Tree::from_data(&data, &svg_options()).map_err(|e| Error::Svg(e.to_string()))?;
    let size = tree.size();
    if !(size.width().is_finite() && size.height().is_finite()) {
        return Err(Error::invalid("SVG size is not finite"));
    }
    Ok(tree)
}

/// The warning for plain SVG data (already inflated, see
/// [`inflate_svgz`]) that draws `<text>`: usvg drops text, as no fonts are
/// read, so callers say it is missing. Text inside `<defs>` (drawn only
/// where used) is not counted.
pub fn text_left_out(data: &[u8]) -> Option<&'static str> {
    let text = std::str::from_utf8(data).ok()?;
    if !text.contains("text") {
        return None;
    }
    let opts = usvg::roxmltree::ParsingOptions {
        allow_dtd: true,
        ..Default::default()
    };
    const SVG: &str = "http://www.w3.org/2000/svg";
    let drawn = usvg::roxmltree::Document::parse_with_options(text, opts).is_ok_and(|doc| {
        doc.descendants().any(|n| {
            n.has_tag_name((SVG, "text")) && !n.ancestors().any(|a| a.has_tag_name((SVG, "defs")))
        })
    });
    drawn.then_some("its text is left out (no fonts are read): convert text to paths first")
}

/// Reads and parses an SVG file.
#[cfg(test)]
pub fn load_svg(path: &std::path::Path) -> Result<usvg::Tree> {
    let data = crate::io::read_file(path)?;
    parse_svg(&data).map_err(|e| e.in_file(path))
}

/// Converts a tiny-skia path under transform `ts` into a kurbo path.
pub fn to_bezpath(path: &usvg::tiny_skia_path::Path, ts: usvg::Transform) -> BezPath {
    use usvg::tiny_skia_path::PathSegment;
    let affine = affine_of(ts);
    let p = |q: usvg::tiny_skia_path::Point| affine * kurbo::Point::new(q.x as f64, q.y as f64);
    let mut out = BezPath::new();
    for seg in path.segments() {
        match seg {
            PathSegment::MoveTo(a) => out.move_to(p(a)),
            PathSegment::LineTo(a) => out.line_to(p(a)),
            PathSegment::QuadTo(a, b) => out.quad_to(p(a), p(b)),
            PathSegment::CubicTo(a, b, c) => out.curve_to(p(a), p(b), p(c)),
            PathSegment::Close => out.close_path(),
        }
    }
    out
}

/// The affine of a usvg transform.
pub fn affine_of(ts: usvg::Transform) -> Affine {
    Affine::new([
        ts.sx as f64,
        ts.ky as f64,
        ts.kx as f64,
        ts.sy as f64,
        ts.tx as f64,
        ts.ty as f64,
    ])
}

/// Colour of a usvg paint: a flat colour as is, a gradient as the mean of
/// its stops, a pattern as black.
pub fn paint_color(paint: &usvg::Paint) -> Color {
    match paint {
        usvg::Paint::Color(c) => Color::rgb(c.red, c.green, c.blue),
        usvg::Paint::LinearGradient(g) => mean_stop(g.stops()),
        usvg::Paint::RadialGradient(g) => mean_stop(g.stops()),
        usvg::Paint::Pattern(_) => Color::BLACK,
    }
}

fn mean_stop(stops: &[usvg::Stop]) -> Color {
    if stops.is_empty() {
        return Color::BLACK;
    }
    let n = stops.len() as f64;
    let avg = |f: &dyn Fn(&usvg::Stop) -> u8| {
        (stops.iter().map(|s| f(s) as f64).sum::<f64>() / n).round() as u8
    };
    Color::rgb(
        avg(&|s| s.color().red),
        avg(&|s| s.color().green),
        avg(&|s| s.color().blue),
    )
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::io::Write as _;

    fn gzip(data: &[u8]) -> Vec<u8> {
        let mut enc = flate2::write::GzEncoder::new(Vec::new(), flate2::Compression::default());
        enc.write_all(data).expect("compresses");
        enc.finish().expect("compresses")
    }

    /// SVGZ inflates to the SVG it holds, plain SVG passes as it is, and
    /// what inflates past the cap (a small file of zeros) or is not gzip
    /// after its magic is refused.
    #[test]
    fn svgz_inflates_within_its_cap() {
        let svg = br#"<svg xmlns="http://www.w3.org/2000/svg" width="10" height="10"/>"#;
        assert_eq!(&*inflate_capped(&gzip(svg), 1000).expect("inflates"), svg);
        assert!(matches!(
            inflate_capped(svg, 1).expect("plain"),
            Cow::Borrowed(_)
        ));
        let bomb = gzip(&vec![0u8; 100_000]);
        assert!(bomb.len() < 1000);
        let e = inflate_capped(&bomb, 10_000).expect_err("over the cap");
        assert!(e.to_string().contains("limit"), "{e}");
        let e = inflate_capped(&[0x1f, 0x8b, 1, 2, 3], 1000).expect_err("not gzip");
        assert!(e.to_string().contains("SVGZ"), "{e}");
        assert!(parse_svg(&gzip(svg)).is_ok());
    }
}
