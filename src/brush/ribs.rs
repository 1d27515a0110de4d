//! Exemplar ribs prepared for the piecewise matching (decobrush.txt §5.1):
//! the style's exemplar width (the canvas scale), ribs resampled at the
//! query's pace, and their matching features: turning, stroke width (the
//! rib envelope), distances to the ends, and the ink cross-section that
//! jumps between segments compare.

use super::matching::{SampleFeature, SpineFeatures};
use super::query;
use crate::brush::analysis::BrushStyle;
use crate::error::{Error, Result};
use crate::raster::Grid;
use kurbo::Point;

/// The style's exemplar width, finest px ([`crate::brush::analysis::facts::StyleFacts::width`]):
/// the finest-px width a query's stroke width is mapped to.
pub fn exemplar_width(style: &BrushStyle) -> Result<f64> {
    let w = style.facts.width;
    if w.is_finite() && w > 0.0 {
        Ok(w)
    } else {
        Err(Error::degenerate(
            format!("style {}", style.name),
            "its exemplars have no rib widths",
        ))
    }
}

/// An exemplar's ribs resampled at a given spacing, finest px.
#[derive(Clone, Debug)]
pub struct Resampled {
    /// Spine points.
    pub spine: Vec<Point>,
    /// Left outline points.
    pub left: Vec<Point>,
    /// Right outline points.
    pub right: Vec<Point>,
    /// Ink fraction across each rib.
    pub ink: Vec<f64>,
    /// Ink cross-section of each rib (the appearance descriptor of the
    /// matching's jumps, [`cross_section`]).
    pub profile: Vec<Vec<f64>>,
}

/// Points at which a rib's ink cross-section is read, evenly from its left
/// to its right end.
pub const PROFILE_SAMPLES: usize = 9;

/// Finest px over which the cross-section's ink ramps from 1 (inside) to 0
/// (outside): a line read a pixel or two off its place still matches.
pub const PROFILE_RAMP: f64 = 3.0;

/// The ink cross-section of the rib from `left` to `right` (finest px) in
/// the all-ink SDF `sdf` (finest px, pixel centres at half-integers): [`PROFILE_SAMPLES`] soft ink values
/// `clamp(½ − d / PROFILE_RAMP, 0, 1)` at the centres of equal steps
/// across the rib, scaled by `1 / √PROFILE_SAMPLES` so the squared distance
/// of two profiles is their mean squared difference. Where the ornament
/// lines cross a rib (the lines of a loop, a leaf's edges, a spike's base)
/// is what a seam must join up: the matching's jumps compare these
/// profiles (decobrush.txt §5.1, "jumps between library segments that have
/// very different appearance").
pub fn cross_section(sdf: &Grid<f32>, left: Point, right: Point) -> Vec<f64> {
    let n = PROFILE_SAMPLES as f64;
    (0..PROFILE_SAMPLES)
        .map(|i| {
            let p = left.lerp(right, (i as f64 + 0.5) / n);
            let d = sdf.sample(p.x, p.y) as f64;
            (0.5 - d / PROFILE_RAMP).clamp(0.0, 1.0) / n.sqrt()
        })
        .collect()
}

/// Resamples exemplar `e`'s ribs at arc-length spacing `h` (finest px),
/// linearly interpolating spine, outline points and rib ink.
pub fn resample_ribs(style: &BrushStyle, e: usize, h: f64) -> Option<Resampled> {
    let ex = style.exemplars.get(e)?;
    let r = &ex.ribs;
    let n = r.len();
    if n < 2 || ex.features.len() != n || h.is_nan() || h <= 0.0 {
        return None;
    }
    let p = |v: [f64; 2]| Point::new(v[0], v[1]);
    let mut arc = vec![0.0; n];
    for i in 1..n {
        arc[i] = arc[i - 1] + p(r.spine[i]).distance(p(r.spine[i - 1]));
    }
    let len = arc[n - 1];
    let m = ((len / h).round() as usize).clamp(1, 100_000) + 1;
    let mut out = Resampled {
        spine: Vec::with_capacity(m),
        left: Vec::with_capacity(m),
        right: Vec::with_capacity(m),
        ink: Vec::with_capacity(m),
        profile: Vec::with_capacity(m),
    };
    let sdf = &ex.finest()?.ink.ink;
    for k in 0..m {
        let s = len * k as f64 / (m - 1) as f64;
        let i = arc.partition_point(|&a| a <= s).clamp(1, n - 1);
        let (a, b) = (arc[i - 1], arc[i]);
        let t = if b > a {
            ((s - a) / (b - a)).clamp(0.0, 1.0)
        } else {
            0.0
        };
        out.spine.push(p(r.spine[i - 1]).lerp(p(r.spine[i]), t));
        out.left.push(p(r.left[i - 1]).lerp(p(r.left[i]), t));
        out.right.push(p(r.right[i - 1]).lerp(p(r.right[i]), t));
        let ink = ex.features[i - 1].ink as f64 * (1.0 - t) + ex.features[i].ink as f64 * t;
        out.ink.push(ink);
        if let (Some(&l), Some(&r)) = (out.left.last(), out.right.last()) {
            out.profile.push(cross_section(sdf, l, r));
        }
    }
    Some(out)
}

/// The stroke width of an exemplar at rib `i`, finest px: the longest rib
/// within `half` ribs either way (half a stroke width). A rib reaches the
/// farthest ink across the spine, so along a chain of loops or leaves it
/// is long at each loop and short between them; the width a designer drew
/// such an ornament with, the one the query's stroke width is compared to
/// (§5.1), is the envelope over about one stroke width.
fn stroke_width(ribs: &[f64], i: usize, half: usize) -> f64 {
    let lo = i.saturating_sub(half);
    let hi = (i + half + 1).min(ribs.len());
    ribs.get(lo..hi)
        .unwrap_or(&[])
        .iter()
        .fold(0.0, |a: f64, &b| a.max(b))
}

/// The matching features of resampled exemplar ribs, in sketch units
/// (`scale` sketch units per finest px).
pub fn exemplar_features(r: &Resampled, scale: f64, mean_width: f64) -> SpineFeatures {
    let pts: Vec<Point> = r
        .spine
        .iter()
        .map(|q| (q.to_vec2() * scale).to_point())
        .collect();
    let len = query::polyline_length(&pts);
    let ribs: Vec<f64> = r
        .left
        .iter()
        .zip(&r.right)
        .map(|(l, q)| l.distance(*q))
        .collect();
    // Samples within half a stroke width either way (the spacing is the
    // same all along the resampled spine).
    let spacing = len / (pts.len().max(2) - 1) as f64;
    let half = if spacing > 0.0 {
        (0.5 * mean_width * scale / spacing).round() as usize
    } else {
        0
    };
    let samples = query::features(&pts, mean_width * scale, len)
        .into_iter()
        .enumerate()
        .map(|(i, s)| SampleFeature {
            turning: s.turning,
            width: stroke_width(&ribs, i, half) * scale,
            dist_start: s.dist_start,
            dist_end: s.dist_end,
        })
        .collect();
    SpineFeatures {
        samples,
        appearance: r.profile.clone(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn cross_section_finds_the_line_crossing_the_rib() {
        // A vertical line 3 px thick at x = 10 (SDF |x − 10| − 1.5).
        let sdf = Grid::from_fn(20, 10, |x, _| ((x as f32 + 0.5) - 10.0).abs() - 1.5);
        let p = cross_section(&sdf, Point::new(1.0, 5.0), Point::new(19.0, 5.0));
        assert_eq!(p.len(), PROFILE_SAMPLES);
        let norm = (PROFILE_SAMPLES as f64).sqrt();
        // Sample 4 (x = 10, SDF −1 between the pixel centres 9.5 and
        // 10.5) is inside, ½ + 1 / PROFILE_RAMP; the outer ones are paper.
        assert!(
            (p[4] * norm - (0.5 + 1.0 / PROFILE_RAMP)).abs() < 1e-6,
            "{p:?}"
        );
        assert!(p[4] > p[3] && p[4] > p[5]);
        assert_eq!(p[0], 0.0);
        assert_eq!(p[8], 0.0);
        // Squared distance of two profiles is their mean squared difference.
        let q = cross_section(&sdf, Point::new(19.0, 5.0), Point::new(1.0, 5.0));
        let d2: f64 = p.iter().zip(&q).map(|(a, b)| (a - b) * (a - b)).sum();
        assert!(d2 < 1e-12, "a symmetric line reads the same both ways");
    }

    #[test]
    fn stroke_width_is_the_envelope_of_the_ribs() {
        // Loops every 4 ribs: long ribs at the loops, short between.
        let ribs: Vec<f64> = (0..12)
            .map(|i| if i % 4 == 0 { 10.0 } else { 2.0 })
            .collect();
        assert_eq!(stroke_width(&ribs, 2, 2), 10.0);
        assert_eq!(stroke_width(&ribs, 2, 1), 2.0);
        assert_eq!(stroke_width(&ribs, 11, 2), 2.0);
        assert_eq!(stroke_width(&ribs, 0, 0), 10.0);
        assert_eq!(stroke_width(&[], 0, 3), 0.0);
    }
}
