//! `flourish style check`: what a designer needs to know about a brush
//! library before using it — a report per exemplar with warnings, and a
//! diagnostics sheet (each exemplar with its stroke region, ribs,
//! orientation field and spine coloured from start, red, to end, green).

use super::style::{BrushStyle, Exemplar, SpineSource};
use crate::error::{Error, Result};
use crate::raster::Grid;
use crate::svg_out::Color;
use resvg::tiny_skia;
use std::fmt::Write as _;

/// Warning thresholds.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CheckOptions {
    /// Warn when the spine runs off the ink for more than this fraction of
    /// its length (default 0.75). DecoBrush §4.2 lets the main branch run
    /// where "a number of lines collectively hint where the center branch
    /// is" — between the loops of a doodle, typically half off the ink —
    /// so only a spine that hardly touches its stroke is suspect; ribs that
    /// cross no ink at all are warned about separately.
    pub off_ink: f64,
    /// Lines thinner than this at the coarsest level, px (default 2).
    pub thin_px: f64,
    /// Warn when more than this fraction of the ink's area lies in lines
    /// thinner than `thin_px` at the coarsest level (default 0.1; tapered
    /// tips are thin by design but small).
    pub thin_fraction: f64,
}

impl Default for CheckOptions {
    fn default() -> Self {
        CheckOptions {
            off_ink: 0.75,
            thin_px: 2.0,
            thin_fraction: 0.1,
        }
    }
}

/// What `style check` found for one exemplar.
#[derive(Clone, Debug, PartialEq)]
pub struct ExemplarReport {
    /// The exemplar file, relative to the style folder.
    pub file: String,
    /// Size in user units.
    pub size: [f64; 2],
    /// Size of the finest level, px.
    pub pixels: [usize; 2],
    /// Layer colours, bottom first.
    pub layers: Vec<Color>,
    /// How the spine was found.
    pub spine_source: SpineSource,
    /// Spine length, finest px.
    pub spine_length: f64,
    /// Smallest and largest rib width, finest px.
    pub width_range: [f64; 2],
    /// Number of rib samples.
    pub samples: usize,
    /// Fraction of the spine's length off the ink.
    pub off_ink: f64,
    /// Fraction of the ink's area in lines thinner than the threshold at
    /// the coarsest level ([`thin_ink`]).
    pub thin: f64,
    /// Stroke-region pixels at the finest level.
    pub region: usize,
    /// Warnings, one line each.
    pub warnings: Vec<String>,
}

/// What `style check` found for a library.
#[derive(Clone, Debug, PartialEq)]
pub struct StyleReport {
    /// The style's name.
    pub(crate) name: String,
    /// Level sizes (longest side, px), coarse to fine.
    pub(crate) levels: Vec<u32>,
    /// Indexed neighbourhoods per level, coarse to fine.
    pub(crate) neighbourhoods: Vec<usize>,
    /// One report per exemplar.
    pub(crate) exemplars: Vec<ExemplarReport>,
    /// For a fill or pattern style: its kind and one line per exemplar
    /// (empty for a brush style, whose exemplars are reported above).
    pub(crate) summary: Option<(&'static str, Vec<String>)>,
}

impl StyleReport {
    /// The style's name.
    pub fn name(&self) -> &str {
        &self.name
    }

    /// Every warning: the exemplar file (relative to the style folder)
    /// and what is wrong with it.
    pub fn warnings(&self) -> impl Iterator<Item = (&str, &str)> {
        self.exemplars
            .iter()
            .flat_map(|e| e.warnings.iter().map(|w| (e.file.as_str(), w.as_str())))
    }

    /// Number of warnings over all exemplars.
    pub fn warning_count(&self) -> usize {
        self.exemplars.iter().map(|e| e.warnings.len()).sum()
    }

    /// The report as text, one exemplar per block.
    pub fn to_text(&self) -> String {
        let mut s = String::new();
        if let Some((kind, lines)) = &self.summary {
            let _ = writeln!(s, "style {}: {kind}", self.name);
            for l in lines {
                let _ = writeln!(s, "  {l}");
            }
            let _ = writeln!(s, "0 warnings");
            return s;
        }
        let lv: Vec<String> = self.levels.iter().map(|l| l.to_string()).collect();
        let nb: Vec<String> = self.neighbourhoods.iter().map(|l| l.to_string()).collect();
        let _ = writeln!(
            s,
            "style {}: {} exemplars, levels {} px, neighbourhoods {}",
            self.name,
            self.exemplars.len(),
            lv.join("/"),
            nb.join("/")
        );
        for e in &self.exemplars {
            let cols: Vec<String> = e.layers.iter().map(|c| c.to_hex()).collect();
            let _ = writeln!(
                s,
                "  {}: {}×{} units ({}×{} px), {} layer{} ({}), spine {} {:.0} px, width {:.1}–{:.1} px, {} samples, off ink {:.0}%, thin ink {:.0}%",
                e.file,
                e.size[0],
                e.size[1],
                e.pixels[0],
                e.pixels[1],
                e.layers.len(),
                if e.layers.len() == 1 { "" } else { "s" },
                cols.join(" "),
                e.spine_source.word(),
                e.spine_length,
                e.width_range[0],
                e.width_range[1],
                e.samples,
                e.off_ink * 100.0,
                e.thin * 100.0,
            );
            for w in &e.warnings {
                let _ = writeln!(s, "    warning: {w}");
            }
        }
        let n = self.warning_count();
        let _ = writeln!(s, "{} warning{}", n, if n == 1 { "" } else { "s" });
        s
    }
}

impl StyleReport {
    /// The report of a fill or pattern style named `name`: its kind and a
    /// line per exemplar.
    pub(crate) fn summary(name: &str, kind: &'static str, lines: Vec<String>) -> StyleReport {
        StyleReport {
            name: name.to_string(),
            levels: Vec::new(),
            neighbourhoods: Vec::new(),
            exemplars: Vec::new(),
            summary: Some((kind, lines)),
        }
    }
}

/// What is said of an exemplar whose ends could not be found.
pub const FALLBACK_WARNING: &str = "no clear main branch (a dot or a ring?): its spine runs across its longer side; give start and end in style.toml";

/// Checks every exemplar of `style`.
pub fn check(style: &BrushStyle, opts: &CheckOptions) -> StyleReport {
    let levels = style
        .exemplars
        .first()
        .map(|e| {
            e.levels
                .iter()
                .map(|l| l.width().max(l.height()) as u32)
                .collect()
        })
        .unwrap_or_default();
    StyleReport {
        name: style.name.clone(),
        levels,
        neighbourhoods: style.indexes.iter().map(|i| i.len()).collect(),
        exemplars: style
            .exemplars
            .iter()
            .map(|e| check_exemplar(e, opts))
            .collect(),
        summary: None,
    }
}

fn check_exemplar(e: &Exemplar, opts: &CheckOptions) -> ExemplarReport {
    let fine = e.finest();
    let coarse = e.levels.first().map(|l| l.scale).unwrap_or(1.0);
    let widths = e.ribs.widths();
    let wmin = widths.iter().cloned().fold(f64::INFINITY, f64::min);
    let wmax = widths.iter().cloned().fold(0.0, f64::max);
    let (off_ink, thin, region, pixels, layers) = match fine {
        Some(f) => (
            off_ink_fraction(&e.spine, &f.ink.ink),
            thin_ink(&f.ink.ink, coarse, opts.thin_px),
            f.orientation.mask.data().iter().filter(|&&m| m).count(),
            [f.width(), f.height()],
            f.ink.layers.iter().map(|l| l.color).collect(),
        ),
        None => (0.0, 0.0, 0, [0, 0], Vec::new()),
    };
    let mut warnings = Vec::new();
    if off_ink > opts.off_ink {
        warnings.push(format!(
            "spine leaves the ink for {:.0}% of its length",
            off_ink * 100.0
        ));
    }
    if thin > opts.thin_fraction {
        warnings.push(format!(
            "lines thinner than {} px at the coarsest level: {:.0}% of the ink",
            opts.thin_px,
            thin * 100.0,
        ));
    }
    if e.spine_source == SpineSource::Fallback {
        warnings.push(FALLBACK_WARNING.into());
    }
    if e.features.iter().filter(|f| f.ink == 0.0).count() * 4 > e.features.len() {
        warnings.push("more than a quarter of the ribs cross no ink".into());
    }
    ExemplarReport {
        file: e.file.display().to_string(),
        size: e.size,
        pixels,
        layers,
        spine_source: e.spine_source,
        spine_length: e.spine_length(),
        width_range: [if wmin.is_finite() { wmin } else { 0.0 }, wmax],
        samples: e.ribs.len(),
        off_ink,
        thin,
        region,
        warnings,
    }
}

/// Fraction of the polyline's length (finest px) where `ink > 0`, sampled
/// every half pixel.
pub fn off_ink_fraction(spine: &[[f64; 2]], ink: &Grid<f32>) -> f64 {
    let (mut total, mut off) = (0.0, 0.0);
    for w in spine.windows(2) {
        let (a, b) = (w[0], w[1]);
        let len = (b[0] - a[0]).hypot(b[1] - a[1]);
        let n = (len * 2.0).ceil().max(1.0) as usize;
        for k in 0..n {
            let t = (k as f64 + 0.5) / n as f64;
            let (x, y) = (a[0] + (b[0] - a[0]) * t, a[1] + (b[1] - a[1]) * t);
            if ink.sample(x, y) > 0.0 {
                off += len / n as f64;
            }
        }
        total += len;
    }
    if total > 0.0 {
        off / total
    } else {
        0.0
    }
}

/// The fraction of the ink's area in lines thinner than `thin_px` at the
/// coarsest level (`coarse` = coarsest px per finest px), measured on the
/// finest `ink` (signed distances, px) by a morphological opening: ink is
/// thick where a disc of diameter `thin_px` coarse pixels fits inside the
/// ink and covers it (centres: depth `−sdf ≥ r − ½`, as pixel centres sit
/// up to half a pixel off a line's middle; covered: within `r + ½` of a
/// centre, by the exact EDT). Tapered tips, being small, weigh little; long
/// hairlines weigh a lot. Returns the fraction (0–1) of ink pixels not
/// covered.
pub fn thin_ink(ink: &Grid<f32>, coarse: f64, thin_px: f64) -> f64 {
    let r = (thin_px / 2.0 / coarse.max(1e-9)) as f32;
    // Pixel centres sit up to half a pixel off a line's middle.
    let centres = ink.map(|d| -d >= r - 0.5);
    let d2 = crate::raster::edt::squared_edt(&centres);
    let reach = (r + 0.5) * (r + 0.5);
    let (mut inked, mut thin) = (0usize, 0usize);
    for (d, c2) in ink.data().iter().zip(d2.data()) {
        if *d < 0.0 {
            inked += 1;
            if *c2 > reach {
                thin += 1;
            }
        }
    }
    if inked == 0 {
        0.0
    } else {
        thin as f64 / inked as f64
    }
}

/// Width of one exemplar's panel on the sheet, px.
pub const PANEL_W: u32 = 300;
/// Height of one exemplar's panel on the sheet, px.
pub const PANEL_H: u32 = 150;
/// Panels per row on the sheet.
pub const COLUMNS: u32 = 3;

/// The diagnostics sheet as PNG bytes: one panel per exemplar (row-major in
/// `style.toml` order) showing the ink in its layer colours over the stroke
/// region (pale blue), ribs (grey), the orientation field (short dark blue
/// ticks pointing along `ω`) and the spine from red (start) to green (end).
pub fn sheet_png(style: &BrushStyle) -> Result<Vec<u8>> {
    let n = style.exemplars.len().max(1) as u32;
    let cols = n.min(COLUMNS);
    let rows = n.div_ceil(COLUMNS);
    let mut pm = tiny_skia::Pixmap::new(cols * PANEL_W, rows * PANEL_H)
        .ok_or_else(|| Error::invalid("cannot allocate the sheet"))?;
    pm.fill(tiny_skia::Color::WHITE);
    for (i, e) in style.exemplars.iter().enumerate() {
        let (cx, cy) = (
            (i as u32 % COLUMNS) * PANEL_W,
            (i as u32 / COLUMNS) * PANEL_H,
        );
        draw_panel(&mut pm, e, cx as f32, cy as f32);
    }
    // Opaque pixels: premultiplied RGBA is plain RGBA. Encoded with the
    // best compression, the sheets stay small enough for a README.
    let mut png = Vec::new();
    let enc = image::codecs::png::PngEncoder::new_with_quality(
        &mut png,
        image::codecs::png::CompressionType::Best,
        image::codecs::png::FilterType::Adaptive,
    );
    image::ImageEncoder::write_image(
        enc,
        pm.data(),
        pm.width(),
        pm.height(),
        image::ExtendedColorType::Rgba8,
    )
    .map_err(|e| Error::invalid(format!("PNG encoding failed: {e}")))?;
    Ok(png)
}

fn draw_panel(pm: &mut tiny_skia::Pixmap, e: &Exemplar, ox: f32, oy: f32) {
    let Some(f) = e.finest() else { return };
    // The panel shows the bounding box of ink and stroke region, padded.
    let (mut x0, mut y0, mut x1, mut y1) = (f.width(), f.height(), 0, 0);
    for y in 0..f.height() {
        for x in 0..f.width() {
            if f.orientation.mask.get(x, y) || f.ink.ink.get(x, y) < 0.0 {
                (x0, y0, x1, y1) = (x0.min(x), y0.min(y), x1.max(x + 1), y1.max(y + 1));
            }
        }
    }
    if x1 <= x0 || y1 <= y0 {
        (x0, y0, x1, y1) = (0, 0, f.width(), f.height());
    }
    let pad = 0.03 * (x1 - x0).max(y1 - y0) as f32;
    let (bx, by) = (x0 as f32 - pad, y0 as f32 - pad);
    let (bw, bh) = ((x1 - x0) as f32 + 2.0 * pad, (y1 - y0) as f32 + 2.0 * pad);
    // Panel px per finest px, and the offset that centres the box.
    let k = ((PANEL_W as f32 - 8.0) / bw).min((PANEL_H as f32 - 8.0) / bh);
    let tx = (PANEL_W as f32 - bw * k) / 2.0;
    let ty = (PANEL_H as f32 - bh * k) / 2.0;
    let to_fine = |x: f32, y: f32| ((x - tx) / k + bx, (y - ty) / k + by);
    // Ink and stroke region, per panel pixel.
    let (w, h) = (pm.width(), pm.height());
    for y in 0..PANEL_H {
        for x in 0..PANEL_W {
            let (gx, gy) = (ox as u32 + x, oy as u32 + y);
            if gx >= w || gy >= h {
                continue;
            }
            let (fx, fy) = to_fine(x as f32 + 0.5, y as f32 + 0.5);
            if fx < 0.0 || fy < 0.0 || fx >= f.width() as f32 || fy >= f.height() as f32 {
                continue;
            }
            let mut c = [255.0f32; 3];
            if f.orientation.mask.get(fx as usize, fy as usize) {
                c = [226.0, 236.0, 250.0];
            }
            for layer in &f.ink.layers {
                let d = layer.sdf.sample(fx as f64, fy as f64) * k;
                let a = (0.5 - d).clamp(0.0, 1.0) * 0.55;
                let lc = [
                    layer.color.r as f32,
                    layer.color.g as f32,
                    layer.color.b as f32,
                ];
                for j in 0..3 {
                    c[j] = c[j] * (1.0 - a) + lc[j] * a;
                }
            }
            let idx = (gy * w + gx) as usize;
            if let (Some(px), Some(v)) = (
                pm.pixels_mut().get_mut(idx),
                tiny_skia::PremultipliedColorU8::from_rgba(c[0] as u8, c[1] as u8, c[2] as u8, 255),
            ) {
                *px = v;
            }
        }
    }
    let map = |p: [f64; 2]| {
        (
            ox + tx + (p[0] as f32 - bx) * k,
            oy + ty + (p[1] as f32 - by) * k,
        )
    };
    let line = |pm: &mut tiny_skia::Pixmap, pts: &[(f32, f32)], rgba: [u8; 4], width: f32| {
        let mut pb = tiny_skia::PathBuilder::new();
        for (j, &(x, y)) in pts.iter().enumerate() {
            if j == 0 {
                pb.move_to(x, y);
            } else {
                pb.line_to(x, y);
            }
        }
        if let Some(path) = pb.finish() {
            let mut paint = tiny_skia::Paint::default();
            paint.set_color_rgba8(rgba[0], rgba[1], rgba[2], rgba[3]);
            paint.anti_alias = true;
            let stroke = tiny_skia::Stroke {
                width,
                line_cap: tiny_skia::LineCap::Round,
                ..Default::default()
            };
            pm.stroke_path(
                &path,
                &paint,
                &stroke,
                tiny_skia::Transform::identity(),
                None,
            );
        }
    };
    let dot = |pm: &mut tiny_skia::Pixmap, (x, y): (f32, f32), rgba: [u8; 4], r: f32| {
        if let Some(path) = tiny_skia::PathBuilder::from_circle(x, y, r) {
            let mut paint = tiny_skia::Paint::default();
            paint.set_color_rgba8(rgba[0], rgba[1], rgba[2], rgba[3]);
            paint.anti_alias = true;
            pm.fill_path(
                &path,
                &paint,
                tiny_skia::FillRule::Winding,
                tiny_skia::Transform::identity(),
                None,
            );
        }
    };
    // Ribs and outlines.
    for j in 0..e.ribs.len() {
        line(
            pm,
            &[map(e.ribs.left[j]), map(e.ribs.right[j])],
            [120, 120, 120, 150],
            0.7,
        );
    }
    let left: Vec<_> = e.ribs.left.iter().map(|&p| map(p)).collect();
    let right: Vec<_> = e.ribs.right.iter().map(|&p| map(p)).collect();
    line(pm, &left, [90, 90, 90, 200], 0.9);
    line(pm, &right, [90, 90, 90, 200], 0.9);
    // Orientation field: ticks on a 12 px panel grid inside the region.
    let step = 12.0;
    let mut y = step / 2.0;
    while y < PANEL_H as f32 {
        let mut x = step / 2.0;
        while x < PANEL_W as f32 {
            let (fx, fy) = to_fine(x, y);
            if fx >= 0.0 && fy >= 0.0 && (fx as usize) < f.width() && (fy as usize) < f.height() {
                let (ix, iy) = (fx as usize, fy as usize);
                if f.orientation.mask.get(ix, iy) {
                    let d = f.orientation.dir.get(ix, iy);
                    let (bx, by) = (ox + x, oy + y);
                    line(
                        pm,
                        &[
                            (bx - d[0] * 2.5, by - d[1] * 2.5),
                            (bx + d[0] * 3.5, by + d[1] * 3.5),
                        ],
                        [30, 50, 140, 230],
                        1.0,
                    );
                    dot(
                        pm,
                        (bx + d[0] * 3.5, by + d[1] * 3.5),
                        [30, 50, 140, 230],
                        1.1,
                    );
                }
            }
            x += step;
        }
        y += step;
    }
    // Spine, red to green.
    let m = e.spine.len();
    for j in 0..m.saturating_sub(1) {
        let t = j as f32 / (m - 1).max(1) as f32;
        let r = (220.0 * (1.0 - t) + 20.0 * t) as u8;
        let g = (30.0 * (1.0 - t) + 170.0 * t) as u8;
        line(
            pm,
            &[map(e.spine[j]), map(e.spine[j + 1])],
            [r, g, 40, 255],
            2.4,
        );
    }
    if let (Some(&a), Some(&b)) = (e.spine.first(), e.spine.last()) {
        dot(pm, map(a), [220, 30, 40, 255], 3.5);
        dot(pm, map(b), [20, 170, 40, 255], 3.5);
        // Ends found by the analysis are ringed (blue), fallback ones in
        // orange: the designer checks them.
        let ring = match e.spine_source {
            SpineSource::Found => Some([40, 90, 220, 255]),
            SpineSource::Fallback => Some([240, 140, 0, 255]),
            _ => None,
        };
        if let Some(c) = ring {
            for p in [a, b] {
                let (cx, cy) = map(p);
                let circle: Vec<(f32, f32)> = (0..=24)
                    .map(|k| {
                        let t = k as f32 / 24.0 * std::f32::consts::TAU;
                        (cx + 8.0 * t.cos(), cy + 8.0 * t.sin())
                    })
                    .collect();
                line(pm, &circle, c, 2.0);
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Two horizontal bands of widths `a` and `b` px (signed distances).
    fn bands(a: f32, b: f32) -> Grid<f32> {
        Grid::from_fn(120, 80, |x, y| {
            let (px, py) = (x as f32 + 0.5, y as f32 + 0.5);
            let ends = (10.0 - px).max(px - 110.0);
            let d1 = ((py - 20.3).abs() - a / 2.0).max(ends);
            let d2 = ((py - 55.7).abs() - b / 2.0).max(ends);
            d1.min(d2)
        })
    }

    #[test]
    fn thin_ink_is_the_area_of_lines_below_the_threshold() {
        // Threshold 2 coarse px at coarse = 1/4: 8 finest px.
        let g = bands(5.0, 12.0);
        let f = thin_ink(&g, 0.25, 2.0);
        // The 5 px band is about 5/17 of the ink.
        assert!((f - 5.0 / 17.0).abs() < 0.05, "{f}");
        assert!(thin_ink(&bands(10.0, 12.0), 0.25, 2.0) < 0.02);
        assert!(thin_ink(&bands(6.0, 7.0), 0.25, 2.0) > 0.98);
        assert_eq!(thin_ink(&Grid::new(4, 4, 1.0), 0.25, 2.0), 0.0);
    }

    #[test]
    fn off_ink_fraction_measures_length_off_the_ink() {
        let g = bands(8.0, 8.0);
        // Along the first band, then straight down across the gap to the
        // second: 100 px on, 35.4 px of which ~8 px on ink.
        let spine = [[10.0, 20.3], [110.0, 20.3], [110.0, 55.7]];
        let f = off_ink_fraction(&spine, &g);
        let expect = (35.4 - 8.0) / 135.4;
        assert!((f - expect).abs() < 0.03, "{f} vs {expect}");
        assert_eq!(off_ink_fraction(&spine[..2], &g), 0.0);
    }
}
