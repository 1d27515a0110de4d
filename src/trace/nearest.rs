//! The outline check's search for a polyline segment near a point
//! ([`super::fit`]'s `Piece::holds`): each curve sample must lie within a
//! distance of the outline, and most samples of a long span are far from
//! most of its segments, so segments that cannot be close are skipped by
//! their arc length; and the direct fit's search for a chord of a
//! flattened cubic near an outline sample ([`first_within`]).

use kurbo::Point;

/// Searches segments `from..=to` of the polyline `pts` (pixel
/// coordinates; clamped to it; `cum` its cumulative arc lengths, px) for
/// one within `near` px of `p`, stopping at the first: returns it, or
/// `None` and the distance (px) of a segment within `far` (≥ `near`),
/// infinity if none is. Segments that cannot come within `far` (once one
/// is found: within `near`) are skipped by arc length: every point of
/// segment `k ≥ j` is at most `cum[k + 1] − cum[j]` from vertex `j` along
/// the polyline, so it is at least `|p − pts[j]| − (cum[k + 1] − cum[j])`
/// from `p`.
pub(super) fn nearest_segment(
    pts: &[Point],
    cum: &[f64],
    p: Point,
    from: usize,
    to: usize,
    near: f64,
    far: f64,
) -> (Option<usize>, f64) {
    // Margin (px) for the rounding of the bound, far below any distance
    // that matters.
    const MARGIN: f64 = 1e-6;
    let last = pts.len().saturating_sub(2);
    let to = to.min(last);
    let mut best = f64::INFINITY;
    // Once a segment within `far` is known only `near` matters.
    let mut bound = far;
    let mut j = from;
    // The first segment is measured outright: the search mostly starts
    // where the point lies (`Piece::holds`' cursor), and there the bound
    // below only costs a root and a galloping search.
    if j <= to && j + 1 < pts.len() {
        let d = crate::raster::sdf::point_segment_distance(p, kurbo::Line::new(pts[j], pts[j + 1]));
        if d <= near {
            return (Some(j), d);
        }
        if d <= far {
            best = d;
            bound = near;
        }
        j += 1;
    }
    while j <= to && j < pts.len().saturating_sub(1) {
        // Squared first: most points are within the bound of the vertex.
        let v2 = (p - pts[j]).hypot2();
        let r = bound + MARGIN;
        if v2 > r * r {
            let reach = v2.sqrt() - r;
            // Skip the segments ending less than `reach` further on
            // (`cum` ascends); none when segment j itself reaches that far.
            let target = cum[j] + reach;
            if cum.get(j + 1).is_some_and(|&c| c < target) {
                let skip = cum.get(j + 1..to + 2).map_or(0, |c| gallop(c, target));
                if skip > 0 {
                    j += skip;
                    continue;
                }
            }
        }
        let d = crate::raster::sdf::point_segment_distance(p, kurbo::Line::new(pts[j], pts[j + 1]));
        if d <= near {
            return (Some(j), d);
        }
        if d <= far {
            best = best.min(d);
            bound = near;
        }
        j += 1;
    }
    (None, best)
}

/// The first segment of the short polyline `pts` (a flattened cubic,
/// `cum` its cumulative chord lengths, px) within `limit` px of `p`, with
/// its distance: segments `cursor..=hi` first (a point is usually near the
/// segment the last one was, or just ahead), then `lo..cursor`; `None` if
/// none is. This is what [`nearest_segment`] answers with `near` = `far` =
/// `limit`, by the same bound (a segment whose end lies less than
/// `|p − pts[j]| − limit` along the polyline from vertex `j` cannot come
/// within `limit`), stepped over one segment at a time: the polyline's
/// dozens of segments leave a galloping search little to save.
pub(super) fn first_within(
    pts: &[Point],
    cum: &[f64],
    p: Point,
    lo: usize,
    cursor: usize,
    hi: usize,
    limit: f64,
) -> Option<(usize, f64)> {
    // Margin (px) for the rounding of the bound, far below any distance
    // that matters.
    const MARGIN: f64 = 1e-6;
    let last = pts.len().min(cum.len()).saturating_sub(2);
    let r = limit + MARGIN;
    let scan = |from: usize, to: usize| {
        let to = to.min(last);
        let mut j = from;
        while j <= to {
            let a = pts[j];
            let v2 = (p - a).hypot2();
            let len = cum[j + 1] - cum[j];
            if v2 > (r + len) * (r + len) {
                // Out of reach, and so is every segment ending less than
                // `|p − a| − r` further on.
                let target = cum[j] + v2.sqrt() - r;
                j += 1;
                while j <= to && cum[j + 1] < target {
                    j += 1;
                }
                continue;
            }
            let d = crate::raster::sdf::point_segment_distance(p, kurbo::Line::new(a, pts[j + 1]));
            if d <= limit {
                return Some((j, d));
            }
            j += 1;
        }
        None
    };
    scan(cursor, hi).or_else(|| {
        if cursor > lo {
            scan(lo, cursor - 1)
        } else {
            None
        }
    })
}

/// The number of leading values of ascending `c` below `target`, found by
/// doubling steps and then bisecting: the skips in [`nearest_segment`]
/// are mostly a few segments, now and then thousands.
fn gallop(c: &[f64], target: f64) -> usize {
    gallop_while(c, |x| x < target)
}

/// The number of leading values of ascending `c` at or below `target`,
/// by doubling steps and then bisecting ([`crate::trace::fit`]'s `locate`
/// walks forwards from the segment it found last).
pub(super) fn gallop_le(c: &[f64], target: f64) -> usize {
    gallop_while(c, |x| x <= target)
}

/// The number of values of ascending `c` at or below `target`, by
/// doubling steps back from the end and then bisecting: `locate` steps
/// back a span's length now and then.
pub(super) fn gallop_back_le(c: &[f64], target: f64) -> usize {
    let n = c.len();
    // Find a window `n - hi .. n - lo` whose first value is at or below
    // `target` (or the start) and whose later values are above it.
    let (mut lo, mut hi) = (0usize, 1usize);
    while hi <= n && c[n - hi] > target {
        lo = hi;
        hi *= 2;
    }
    let start = n.saturating_sub(hi);
    start
        + c.get(start..n - lo)
            .map_or(0, |w| w.partition_point(|&x| x <= target))
}

/// The length of the leading run of `c` where `ahead` holds (`c` ascends,
/// so it holds on a prefix): doubling steps, then bisection.
fn gallop_while(c: &[f64], ahead: impl Fn(f64) -> bool) -> usize {
    let (mut lo, mut hi) = (0usize, 1usize);
    while hi <= c.len() && ahead(c[hi - 1]) {
        lo = hi;
        hi *= 2;
    }
    let hi = hi.min(c.len());
    lo + c
        .get(lo..hi)
        .map_or(0, |c| c.partition_point(|&x| ahead(x)))
}

#[cfg(test)]
mod tests {
    use super::*;
    use kurbo::Vec2;
    use proptest::prelude::*;

    /// A polyline from the origin by `steps`, with its cumulative arc
    /// lengths.
    fn polyline(steps: &[(f64, f64)]) -> (Vec<Point>, Vec<f64>) {
        let mut pts = vec![Point::ORIGIN];
        for &(dx, dy) in steps {
            let last = pts[pts.len() - 1];
            pts.push(last + Vec2::new(dx, dy));
        }
        let mut cum = vec![0.0];
        for w in pts.windows(2) {
            cum.push(cum[cum.len() - 1] + (w[1] - w[0]).hypot());
        }
        (pts, cum)
    }

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(200))]

        /// The galloping search agrees with a plain binary search.
        #[test]
        fn gallop_is_partition_point(mut c in prop::collection::vec(0.0f64..100.0, 0..60), t in -1.0f64..101.0) {
            c.sort_by(|a, b| a.total_cmp(b));
            prop_assert_eq!(gallop(&c, t), c.partition_point(|&x| x < t));
            prop_assert_eq!(gallop_le(&c, t), c.partition_point(|&x| x <= t));
            prop_assert_eq!(gallop_back_le(&c, t), c.partition_point(|&x| x <= t));
        }

        /// The segment search with skips by arc length answers as a scan
        /// of every segment does: one within `near`, else one within `far`.
        #[test]
        fn nearest_segment_matches_brute_force(
            steps in prop::collection::vec((-3.0f64..3.0, -3.0f64..3.0), 2..80),
            px in -20.0f64..20.0,
            py in -20.0f64..20.0,
            near in 0.05f64..1.0,
            extra in 0.0f64..1.0,
            from_share in 0.0f64..1.0,
        ) {
            let (pts, cum) = polyline(&steps);
            let n = pts.len();
            let far = near + extra;
            let p = Point::new(px, py);
            let from = ((n - 2) as f64 * from_share) as usize;
            let dists: Vec<f64> = (from..n - 1)
                .map(|j| crate::raster::sdf::point_segment_distance(p, kurbo::Line::new(pts[j], pts[j + 1])))
                .collect();
            let (found, best) = nearest_segment(&pts, &cum, p, from, n - 2, near, far);
            match found {
                Some(j) => {
                    prop_assert!(j >= from && dists[j - from] <= near);
                    prop_assert!(dists[..j - from].iter().all(|&d| d > near));
                }
                None => {
                    prop_assert!(dists.iter().all(|&d| d > near));
                    let any_far = dists.iter().any(|&d| d <= far);
                    prop_assert_eq!(best <= far, any_far);
                }
            }
        }

        /// The plain scan answers as the search with skips does when
        /// `near` = `far`: the same first segment, at the same distance.
        #[test]
        fn first_within_matches_nearest_segment(
            steps in prop::collection::vec((-1.0f64..1.0, -1.0f64..1.0), 2..70),
            px in -10.0f64..10.0,
            py in -10.0f64..10.0,
            limit in 0.05f64..1.5,
            cursor_share in 0.0f64..1.0,
            lo_share in 0.0f64..1.0,
        ) {
            let (pts, cum) = polyline(&steps);
            let n = pts.len();
            let p = Point::new(px, py);
            let cursor = ((n - 2) as f64 * cursor_share) as usize;
            let lo = (cursor as f64 * lo_share) as usize;
            let expected = match nearest_segment(&pts, &cum, p, cursor, n - 2, limit, limit) {
                (Some(j), d) => Some((j, d)),
                (None, _) if cursor > lo => {
                    match nearest_segment(&pts, &cum, p, lo, cursor - 1, limit, limit) {
                        (Some(j), d) => Some((j, d)),
                        (None, _) => None,
                    }
                }
                (None, _) => None,
            };
            prop_assert_eq!(first_within(&pts, &cum, p, lo, cursor, n - 2, limit), expected);
        }
    }
}
