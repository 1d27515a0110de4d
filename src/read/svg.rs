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

/// Most bytes the general entity references of a document may expand to
/// (16 MiB): SVG editors declare a few namespace URIs as entities, while a
/// few kilobytes of entities referenced many times over would fill memory
/// before the parser's own guard (nesting depth, references per entity)
/// notices.
pub const MAX_ENTITY_EXPANSION: u64 = 16 << 20;

/// Most XML nodes a document may hold (4 M): memory in proportion to the
/// input, whatever its entities and nesting make of it.
const MAX_NODES: u32 = 4 << 20;

/// How many bytes the general entity references of XML `text` expand to:
/// each entity declared in the internal DTD subset (`<!ENTITY name
/// "value">`) is measured with the entities it refers to expanded, and
/// every reference to it after the DTD counts that length. `None` when an
/// entity refers to itself, directly or not.
fn entity_expansion(text: &str) -> Option<u64> {
    let Some(dtd) = text.find("<!DOCTYPE") else {
        return Some(0);
    };
    let end = text[dtd..].find("]>").map_or(text.len(), |e| dtd + e + 2);
    let subset = &text[dtd..end];
    let mut values: Vec<(&str, &str)> = Vec::new();
    let mut rest = subset;
    while let Some(at) = rest.find("<!ENTITY") {
        rest = rest[at + 8..].trim_start();
        if rest.starts_with('%') {
            continue; // A parameter entity: used in the DTD only.
        }
        let name_end = rest.find(|c: char| c.is_whitespace()).unwrap_or(rest.len());
        let name = &rest[..name_end];
        let after = rest[name_end..].trim_start();
        let Some(q) = after.chars().next().filter(|&c| c == '"' || c == '\'') else {
            continue; // An external entity: it has no value here.
        };
        let Some(close) = after[1..].find(q) else {
            break;
        };
        values.push((name, &after[1..1 + close]));
        rest = &after[1 + close..];
    }
    if values.is_empty() {
        return Some(0);
    }
    let refs = |s: &str, name: &str| s.matches(&format!("&{name};")).count() as u64;
    // Expanded lengths in an order where every entity comes after those it
    // refers to (depth first); an entity met again while its own
    // references are being measured is a cycle.
    let n = values.len();
    let mut len: Vec<Option<u64>> = vec![None; n];
    let mut on_path = vec![false; n];
    fn measure(
        i: usize,
        values: &[(&str, &str)],
        refs: &dyn Fn(&str, &str) -> u64,
        len: &mut [Option<u64>],
        on_path: &mut [bool],
    ) -> Option<u64> {
        if let Some(l) = len[i] {
            return Some(l);
        }
        if on_path[i] {
            return None;
        }
        on_path[i] = true;
        let v = values[i].1;
        let mut total = v.len() as u64;
        for (j, (name, _)) in values.iter().enumerate() {
            let k = refs(v, name);
            if k > 0 {
                // Each `&name;` is replaced by its expansion.
                let l = measure(j, values, refs, len, on_path)?;
                total = total
                    .saturating_sub(k * (name.len() as u64 + 2))
                    .saturating_add(k.saturating_mul(l));
            }
        }
        on_path[i] = false;
        len[i] = Some(total);
        Some(total)
    }
    for i in 0..n {
        measure(i, &values, &refs, &mut len, &mut on_path)?;
    }
    let len: Vec<u64> = len.into_iter().map(|l| l.unwrap_or(0)).collect();
    let body = &text[end..];
    Some(values.iter().zip(&len).fold(0u64, |acc, ((n, _), &l)| {
        acc.saturating_add(refs(body, n).saturating_mul(l))
    }))
}

/// Parses XML text as every SVG of flourish is parsed: a DTD allowed (SVG
/// editors write one), its entities measured first and refused past
/// [`MAX_ENTITY_EXPANSION`], and at most 4 M nodes.
pub fn parse_xml(text: &str) -> Result<usvg::roxmltree::Document<'_>> {
    match entity_expansion(text) {
        Some(n) if n <= MAX_ENTITY_EXPANSION => {}
        Some(n) => {
            return Err(Error::Svg(format!(
                "its entities expand to {n} bytes, more than the limit of {MAX_ENTITY_EXPANSION}"
            )))
        }
        None => return Err(Error::Svg("an entity refers to itself".into())),
    }
    let opts = usvg::roxmltree::ParsingOptions {
        allow_dtd: true,
        nodes_limit: MAX_NODES,
        ..Default::default()
    };
    usvg::roxmltree::Document::parse_with_options(text, opts).map_err(|e| Error::Svg(e.to_string()))
}

/// Parses SVG bytes (plain or SVGZ, see [`inflate_svgz`]) with
/// [`svg_options`], the XML read by [`parse_xml`].
pub fn parse_svg(data: &[u8]) -> Result<usvg::Tree> {
    let data = inflate_svgz(data)?;
    let text = std::str::from_utf8(&data).map_err(|_| Error::Svg("not UTF-8 text".into()))?;
    let doc = parse_xml(text)?;
    let tree =
        usvg::Tree::from_xmltree(&doc, &svg_options()).map_err(|e| Error::Svg(e.to_string()))?;
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
    const SVG: &str = "http://www.w3.org/2000/svg";
    let drawn = parse_xml(text).is_ok_and(|doc| {
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

    /// Entities are measured before parsing: a namespace URI passes, a
    /// large entity referenced many times and a cycle are refused, and
    /// nested ones multiply.
    #[test]
    fn entities_are_measured_before_parsing() {
        let ns = r#"<?xml version="1.0"?><!DOCTYPE svg [<!ENTITY ns_svg "http://www.w3.org/2000/svg">]><svg xmlns="&ns_svg;" width="4" height="4"/>"#;
        assert_eq!(entity_expansion(ns), Some(26));
        assert!(parse_svg(ns.as_bytes()).is_ok());
        let big = format!(
            r#"<!DOCTYPE svg [<!ENTITY a "{}">]><svg xmlns="http://www.w3.org/2000/svg"><text>{}</text></svg>"#,
            "x".repeat(100_000),
            "&a;".repeat(20_000)
        );
        assert_eq!(entity_expansion(&big), Some(2_000_000_000));
        let e = parse_svg(big.as_bytes()).expect_err("refused").to_string();
        assert!(e.contains("entities expand to 2000000000 bytes"), "{e}");
        let nested = r#"<!DOCTYPE svg [<!ENTITY a "xy"><!ENTITY b '&a;&a;&a;'>]><svg>&b;&b;</svg>"#;
        assert_eq!(entity_expansion(nested), Some(12));
        let cycle = r#"<!DOCTYPE svg [<!ENTITY a "&b;"><!ENTITY b "&a;">]><svg>&a;</svg>"#;
        assert_eq!(entity_expansion(cycle), None);
        assert!(parse_svg(cycle.as_bytes()).is_err());
    }
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
