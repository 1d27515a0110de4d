//! Contours to cubic Béziers with kurbo's curve fitter.
//!
//! A contour (the marching-squares polygon of an SDF's zero level set) is
//! cut at its corners and each piece is presented to kurbo as a
//! `kurbo::ParamCurveFit` source: positions along the polygon by arc length, and
//! tangents perpendicular to the SDF gradient, which is smooth where the
//! outline is, so pieces join with G1 continuity. `fit_to_bezpath_opt`
//! then finds the fewest cubics within the tolerance. An outline known
//! exactly (a bitmap's smoothed or sub-pixel outline) is a `Piece` too,
//! covered by [`super::cover`] with its own tangents and corners, exact
//! moment integrals, and fitted by `super::direct` (no kurbo), each curve
//! checked against the outline itself (and a binary bitmap's corridor)
//! instead of an SDF. The span search both share is `super::span`; how a
//! piece is sampled and integrated is `super::piece`. Corners are the
//! vertices where the outline turns sharply within a pixel-scale window;
//! the curves meet there at an angle, so sharp corners stay sharp.

use super::piece::{corner_runs, Guide, Piece};
use super::span::{append_loop, line_cubic, longest_span};
use crate::outline::corner::corners;
use crate::raster::Sdf;
use kurbo::{BezPath, CubicBez, Point};

/// Fits a closed contour (pixel coordinates) of `sdf`'s zero level set with
/// cubic Béziers within `accuracy` px, appending a closed subpath to `out`.
/// Corners are found by [`corners`].
pub fn fit_contour(pts: &[Point], sdf: &Sdf, accuracy: f64, out: &mut BezPath) {
    if pts.len() < 3 {
        return;
    }
    fit_loop(pts, &corners(pts), sdf, accuracy, out);
}

/// The closed contour `pts` of `sdf` cut at `cs` into pieces, each fitted.
fn fit_loop(pts: &[Point], cs: &[usize], sdf: &Sdf, accuracy: f64, out: &mut BezPath) {
    let n = pts.len();
    let guide = Guide::Field(sdf);
    let mut pieces: Vec<Piece> = Vec::new();
    if cs.is_empty() {
        // A smooth loop is fitted as two open halves (a span's fit needs
        // distinct end points); the tangents at the joins come from the
        // guide, so the halves meet with G1 continuity.
        let h = n / 2;
        let first: Vec<usize> = (0..=h).collect();
        let second: Vec<usize> = (h..n).chain([0]).collect();
        for idx in [first, second] {
            let p = idx.iter().map(|&i| pts[i]).collect();
            pieces.push(Piece::new(p, Vec::new(), guide, false, false));
        }
    } else {
        for idx in corner_runs(cs, n) {
            let p = idx.iter().map(|&i| pts[i]).collect();
            pieces.push(Piece::new(p, Vec::new(), guide, true, true));
        }
    }
    let mut cubics = Vec::new();
    for piece in pieces.iter().flat_map(split_by_turning) {
        if piece.length() > 1e-9 {
            fit_piece(&piece, accuracy, &mut cubics);
        }
    }
    append_loop(&cubics, out);
}

/// Largest turning (radians) of one piece handed to the fitter: a quarter
/// turn, which one cubic can follow closely. Longer turns make kurbo's
/// optimizer fall back to slow arc-length error measures.
const MAX_PIECE_TURN: f64 = std::f64::consts::FRAC_PI_2;

/// Splits a piece where its accumulated turning exceeds [`MAX_PIECE_TURN`];
/// the cuts keep SDF tangents on both sides, so they are G1 joins.
fn split_by_turning<'a>(piece: &Piece<'a>) -> Vec<Piece<'a>> {
    let n = piece.pts.len();
    if n < 4 {
        return vec![piece.sub(0, n - 1, piece.corner_start, piece.corner_end)];
    }
    // Turning is accumulated between chords of about 3 px, which follow the
    // outline's shape and not the sub-pixel wobble of its vertices.
    const STEP: f64 = 3.0;
    let mut acc = vec![0.0; n];
    let mut anchor = 0usize;
    let mut prev_dir: Option<f64> = None;
    let mut total = 0.0;
    #[allow(clippy::needless_range_loop)] // i indexes cum, pts and acc alike
    for i in 1..n {
        if piece.cum[i] - piece.cum[anchor] >= STEP || i == n - 1 {
            let d = (piece.pts[i] - piece.pts[anchor]).atan2();
            if let Some(p) = prev_dir {
                let mut t = d - p;
                while t > std::f64::consts::PI {
                    t -= std::f64::consts::TAU;
                }
                while t < -std::f64::consts::PI {
                    t += std::f64::consts::TAU;
                }
                total += t.abs();
            }
            prev_dir = Some(d);
            anchor = i;
        }
        acc[i] = total;
    }
    // Equal shares of turning, each at most a quarter turn.
    let parts = (acc[n - 1] / MAX_PIECE_TURN).ceil().max(1.0) as usize;
    let mut cuts = vec![0usize];
    for k in 1..parts {
        let target = acc[n - 1] * k as f64 / parts as f64;
        let i = acc.partition_point(|&a| a < target).clamp(1, n - 2);
        if i > cuts[cuts.len() - 1] + 1 && i + 1 < n - 1 {
            cuts.push(i);
        }
    }
    cuts.push(n - 1);
    cuts.windows(2)
        .map(|w| {
            piece.sub(
                w[0],
                w[1],
                w[0] == 0 && piece.corner_start,
                w[1] == n - 1 && piece.corner_end,
            )
        })
        .collect()
}

/// Fits one piece with as few cubics as a greedy cover finds: from the
/// start of what is left, the longest span that one cubic fits (the
/// direct fit of [`super::direct`], which matches area and moment to the
/// source, checked against the SDF itself) is found by halving until a span
/// passes and then bisecting between that success and the failure above
/// it, on the cheap test of [`super::span::longest_span`]. Extending each
/// span as far as it goes is what an optimal cover does when fitting is
/// monotone in the span, and it needs no merging pass afterwards. Spans
/// shorter than [`MIN_SPAN_PX`](super::span::MIN_SPAN_PX) that still do not fit fall back to the
/// polygon, which lies on the level set.
fn fit_piece(piece: &Piece, accuracy: f64, out: &mut Vec<CubicBez>) {
    let n = piece.pts.len();
    let a = piece.pts[0];
    let b = piece.pts[n - 1];
    let chord = kurbo::Line::new(a, b);
    if a != b
        && piece
            .pts
            .iter()
            .all(|&p| crate::raster::sdf::point_segment_distance(p, chord) <= accuracy)
    {
        out.push(line_cubic(a, b));
        return;
    }
    let mut start = 0.0;
    while start < 1.0 {
        // Down to an eighth of the span found (or half a pixel): a longer
        // search buys little length and costs a fit per step.
        start = longest_span(piece, start, 1.0, 0.125, accuracy, out);
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::raster::contour;
    use crate::raster::Grid;
    use crate::trace::piece::{clipped_value, CHECK_SLACK};
    use kurbo::Vec2;
    use kurbo::{Affine, ParamCurve};

    pub(crate) fn disc_sdf(size: usize, cx: f64, cy: f64, r: f64) -> Sdf {
        Sdf {
            dist: Grid::from_fn(size, size, |x, y| {
                ((x as f64 + 0.5 - cx).hypot(y as f64 + 0.5 - cy) - r) as f32
            }),
            to_user: Affine::IDENTITY,
        }
    }

    proptest::proptest! {
        /// Stepping on from an earlier arc length's segment finds what a
        /// search from scratch does (zero-length segments included).
        #[test]
        fn locate_after_agrees_with_locate(
            gaps in proptest::collection::vec(proptest::sample::select(vec![0.0, 0.3, 1.0, 2.5]), 1..30),
            a in 0.0f64..1.1,
            b in 0.0f64..1.1,
        ) {
            let mut pts = vec![Point::new(3.0, 4.0)];
            for (k, g) in gaps.iter().enumerate() {
                let last = pts[pts.len() - 1];
                pts.push(last + Vec2::new(*g, 0.1 * (k % 3) as f64 * g));
            }
            let piece = Piece::new(pts, Vec::new(), Guide::Outline(None), false, false);
            let len = piece.length();
            let (s1, s2) = (a.min(b) * len, a.max(b) * len);
            let (j, _) = piece.locate(s1);
            proptest::prop_assert_eq!(piece.locate_after(j, s2), piece.locate(s2));
        }
    }

    #[test]
    fn large_disc_needs_few_cubics() {
        let sdf = disc_sdf(660, 330.0, 330.0, 307.0);
        let cs = contour::extract(&sdf.dist);
        assert_eq!(cs.len(), 1);
        let mut path = BezPath::new();
        fit_contour(&cs[0].points, &sdf, 0.25, &mut path);
        let n = crate::svg_out::count_segments(&path);
        assert!(n <= 8, "{n} segments");
    }

    #[test]
    fn ink_running_off_the_canvas_is_closed_by_a_few_lines_on_the_border() {
        // A disc centred on the canvas's top-left corner and one covering
        // the whole canvas: the contour runs along the border, where the
        // SDF is far from zero, and each border stretch must still be one
        // segment, not one per marching-squares edge.
        for (cx, cy, r, most) in [(0.0, 0.0, 60.0, 8), (50.0, 50.0, 500.0, 12)] {
            let sdf = disc_sdf(100, cx, cy, r);
            let cs = contour::extract(&sdf.dist);
            assert_eq!(cs.len(), 1);
            let mut path = BezPath::new();
            fit_contour(&cs[0].points, &sdf, 0.25, &mut path);
            let n = crate::svg_out::count_segments(&path);
            assert!(n <= most, "disc at ({cx}, {cy}) r {r}: {n} segments");
            // And the curves follow the clipped level set.
            for seg in path.segments() {
                for k in 0..=20 {
                    let p = seg.eval(k as f64 / 20.0);
                    let v = clipped_value(&sdf, p);
                    assert!(v.abs() <= 0.25 + CHECK_SLACK + 0.05, "{p:?}: {v}");
                }
            }
        }
    }
}
