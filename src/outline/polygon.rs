//! Steps 2–3 of [`crate::outline::smooth`]: the straight runs of a closed
//! path and the optimal polygon over them (Selinger 2003, §2.2).
//!
//! **Straight runs** (§2.2.1, the submodule `runs`). potrace calls a path
//! straight when a line passes within an L∞ box of half-side ½ round every
//! vertex and the path does not step in all four directions. Its
//! implementation anchors the line at the run's first vertex and narrows a
//! cone of admissible directions by the box round each later vertex; so
//! does flourish, with boxes of half-side [`STRAIGHT_TOLERANCE`] round the
//! vertices of its paths (through pixel-edge midpoints, so they step
//! diagonally too), walking from stretch to stretch of repeated steps. The
//! direction rule becomes: a run's steps keep to two neighbouring
//! directions of the eight (a staircase), so a run never turns round the
//! end of a line.
//!
//! **Possible segments.** Reaches are made monotone as potrace's `calc_lon`
//! cleans them up: `i → j` is a possible edge when every vertex from `i`
//! up to `j` has a run reaching `j`, so every sub-segment of a possible
//! segment is possible (the shortest-path search needs this).
//!
//! **Optimal polygon** (§2.2.2). The fewest possible segments round the
//! loop, and of those the one with the least sum of penalties: potrace's
//! `P(i, j) = |p_j − p_i| · √(mean squared distance of p_i … p_j to the
//! chord)`. As potrace does, the cycle is cut at a fixed start vertex,
//! which every candidate contains; potrace takes the path's first vertex,
//! here the start whose greedy cover is shortest among [`START_TRIES`]
//! spread round the loop (a greedy cover is optimal from a fixed start on
//! monotone reaches), so the count is never worse than a greedy
//! polygon's. From that start, `seg0`/`seg1` bound where the
//! `j`-th vertex can be and a dynamic programme over them finds the least
//! total penalty (potrace's `bestpolygon`; linear in practice).
//!
//! **Arithmetic.** Path vertices are pixel-edge midpoints, so in doubled
//! pixel coordinates ([`Lattice`]) they are integers, and everything up to
//! the penalty's final square root is exact integer arithmetic. The sum in
//! the penalty is `Σ (e × (v − m))²` with `e` the chord and `m` its
//! midpoint; since `e × (r − m) = 0` for the chord's end `r`, it equals
//! `Σ (u_k × u_t)²` with `u = v − r`, which needs only the three second
//! moments of the `u` about `r`. For a fixed end `r` the search walks the
//! candidate starts `k` backwards, so the moments grow by one vertex per
//! candidate (the first read off prefix sums), and a candidate whose own
//! total already reaches the best so far is skipped (penalties are ≥ 0).
//! The value is the one floating-point prefix sums give, bit for bit,
//! wherever those are exact: their terms are multiples of ¼ px², exact
//! while the sums stay below 2⁵³ quarter units, which holds for the paths
//! of rasters a few thousand pixels a side (tested on random loops
//! against the floating-point reference). Beyond that the integer sums
//! stay exact where the floating-point ones would round.

mod runs;

#[cfg(test)]
mod reference;

pub(super) use runs::straight_runs;

use kurbo::Point;
use std::ops::{Add, Mul, Sub};

/// How far (px) a straight run may pass from the path vertices it replaces.
/// Half a pixel: the whole uncertainty of a binary edge.
pub const STRAIGHT_TOLERANCE: f64 = 0.5;

/// Longest straight run considered, in path vertices (about 50–70 px of
/// outline). The penalty search's work grows with the runs' lengths.
/// Longer runs buy nothing downstream (a straight edge cut in two gets a
/// smooth vertex on its line, and the curve fitter spans it): the binary
/// samples trace the same with longer runs. Much shorter runs thin a
/// 1.5-px diagonal (`binary_hairlines_keep_their_weight`).
const MAX_RUN: usize = 100;

/// How many starts (spread evenly round the loop) the fewest-segment
/// search tries before the penalty search runs from the best of them.
pub(super) const START_TRIES: usize = 32;

/// A path vertex (or a difference of two) on the half-pixel lattice, in
/// doubled pixel coordinates: `(2x, 2y)`.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub(super) struct Lattice {
    /// Twice the x coordinate (px).
    pub(super) x: i64,
    /// Twice the y coordinate (px).
    pub(super) y: i64,
}

impl Lattice {
    /// The lattice point of `p`, a pixel-edge midpoint (twice its
    /// coordinates are integers, so the conversion is exact; anything
    /// else is truncated towards zero).
    pub(super) fn of(p: Point) -> Self {
        Lattice {
            x: (2.0 * p.x) as i64,
            y: (2.0 * p.y) as i64,
        }
    }

    /// The z component of the cross product `self × o`.
    pub(super) fn cross(self, o: Lattice) -> i64 {
        self.x * o.y - self.y * o.x
    }

    /// Which of eight directions, 45° apart (0 along +x, counting towards
    /// +y), a step points in: from the signs of its components.
    pub(super) fn direction(self) -> u8 {
        octant(self.x.signum() as i32, self.y.signum() as i32)
    }
}

/// The direction (of eight, 45° apart: 0 along +x, counting towards +y)
/// of a step whose components have the signs `sx`, `sy` (−1, 0 or 1).
pub(super) fn octant(sx: i32, sy: i32) -> u8 {
    match (sx, sy) {
        (1, 0) => 0,
        (1, 1) => 1,
        (0, 1) => 2,
        (-1, 1) => 3,
        (-1, 0) => 4,
        (-1, -1) => 5,
        (0, -1) => 6,
        _ => 7,
    }
}

impl Add for Lattice {
    type Output = Lattice;
    fn add(self, o: Lattice) -> Lattice {
        Lattice {
            x: self.x + o.x,
            y: self.y + o.y,
        }
    }
}

impl Sub for Lattice {
    type Output = Lattice;
    fn sub(self, o: Lattice) -> Lattice {
        Lattice {
            x: self.x - o.x,
            y: self.y - o.y,
        }
    }
}

impl Mul<i64> for Lattice {
    type Output = Lattice;
    fn mul(self, t: i64) -> Lattice {
        Lattice {
            x: self.x * t,
            y: self.y * t,
        }
    }
}

/// Possible segments: `ahead[i]` = how many vertices ahead of `i` the
/// longest possible segment from `i` ends, `lon` cleaned up as potrace's
/// `calc_lon` does (`ahead[i] = min(lon[i], ahead[i + 1] + 1)` round the
/// loop), so that `i → j` possible implies every `i' → j'` inside it is.
/// At most `(n − 1) / 2` when the loop would otherwise close in two
/// segments (a polygon needs three).
#[inline(never)] // (once per path; kept whole in profiles)
pub(super) fn possible_segments(lon: &[usize]) -> Vec<usize> {
    let n = lon.len();
    let mut ahead: Vec<usize> = lon.iter().map(|&l| l.clamp(1, n.max(2) - 1)).collect();
    if n < 2 {
        return ahead;
    }
    // Backwards round the loop, then on across the wrap until nothing
    // changes: a reach is shorter than the loop, so a constraint travels
    // less than once round.
    let mut next = ahead[0];
    for a in ahead.iter_mut().rev() {
        *a = (*a).min(next + 1);
        next = *a;
    }
    let mut next = ahead[0];
    for a in ahead.iter_mut().rev() {
        if next + 1 >= *a {
            break;
        }
        *a = next + 1;
        next = *a;
    }
    if n >= 4 && closes_in_two(&ahead) {
        let cap = (n - 1) / 2;
        for a in ahead.iter_mut() {
            *a = (*a).min(cap);
        }
    }
    ahead
}

/// The greedy cover of the loop from `start` over the reaches `ahead`: how
/// many segments it has, counting up to `limit` at most.
fn cover(ahead: &[usize], start: usize, limit: usize) -> usize {
    let n = ahead.len();
    let mut count = 1;
    let mut at = 0usize; // steps from start
    let mut i = start; // (start + at) mod n
    while count < limit {
        let step = ahead.get(i).map_or(1, |&a| a.max(1));
        at += step;
        if at >= n {
            break;
        }
        // i, step < n: one wrap at most.
        i += step;
        if i >= n {
            i -= n;
        }
        count += 1;
    }
    count
}

/// Whether the greedy cover from one of the [`fewest_start`] candidates
/// closes the loop in fewer than three segments.
fn closes_in_two(ahead: &[usize]) -> bool {
    let n = ahead.len();
    let tries = n.min(START_TRIES);
    (0..tries).any(|k| cover(ahead, k * n / tries, 3) < 3)
}

/// The start (of [`START_TRIES`] spread round the loop) whose greedy
/// cover has the fewest segments, and that count: the first such start.
#[inline(never)] // (once per path; kept whole in profiles)
pub(super) fn fewest_start(ahead: &[usize]) -> (usize, usize) {
    let n = ahead.len();
    // A cover stops counting as soon as it cannot beat the best so far.
    let tries = n.min(START_TRIES);
    let mut best = (0, usize::MAX);
    for k in 0..tries {
        let start = k * n / tries;
        let count = cover(ahead, start, best.1);
        if count < best.1 {
            best = (start, count);
        }
    }
    best
}

/// The path's vertices from a start vertex round the loop and back to it,
/// relative to it ([`Lattice`]), with prefix sums of their coordinates'
/// products, for potrace's penalty.
struct Chords {
    /// The vertices relative to the start, `n + 1` of them (the start
    /// again last).
    v: Vec<Lattice>,
    /// `s[t]`: sums of x, y, x², xy, y² over the first `t` vertices
    /// (wrapping: only differences of nearby entries are read).
    s: Vec<[i64; 5]>,
}

impl Chords {
    fn new(path: &[Point], start: usize) -> Self {
        let origin = path
            .get(start)
            .map_or(Lattice::default(), |&p| Lattice::of(p));
        let (before, after) = path.split_at(start.min(path.len()));
        let mut v = Vec::with_capacity(path.len() + 1);
        let relative = |&p: &Point| Lattice::of(p) - origin;
        v.extend(after.iter().map(relative));
        v.extend(before.iter().map(relative));
        v.extend(after.first().map(relative));
        let mut s = Vec::with_capacity(v.len() + 1);
        let mut acc = [0i64; 5];
        s.push(acc);
        s.extend(v.iter().map(|q| {
            let terms = [q.x, q.y, q.x * q.x, q.x * q.y, q.y * q.y];
            for (a, t) in acc.iter_mut().zip(terms) {
                *a = a.wrapping_add(t);
            }
            acc
        }));
        Chords { v, s }
    }

    /// potrace's penalty of the segment from relative vertex `k` to `i`
    /// (`k < i ≤ n`): the chord's length times the root mean square
    /// distance of the vertices `k ..= i` from the chord's line (Selinger
    /// 2003, §2.2.2), px².
    #[cfg(test)]
    fn penalty(&self, k: usize, i: usize) -> f64 {
        match (
            self.v.get(k),
            self.v.get(i),
            self.s.get(k),
            self.s.get(i + 1),
        ) {
            (Some(&p), Some(&r), Some(a), Some(b)) => {
                let c = (i + 1 - k) as i64;
                penalty(p - r, moments(a, b, r, c), c as f64)
            }
            _ => f64::INFINITY,
        }
    }
}

/// The second moments `Σ u_x², Σ u_x u_y, Σ u_y²` of `u = v_t − r` over
/// the `c` vertices whose sums of x, y, x², xy, y² are `end − start`.
fn moments(start: &[i64; 5], end: &[i64; 5], r: Lattice, c: i64) -> [i64; 3] {
    let d: [i64; 5] = std::array::from_fn(|t| end[t].wrapping_sub(start[t]));
    [
        d[2] - 2 * r.x * d[0] + c * r.x * r.x,
        d[3] - r.x * d[1] - r.y * d[0] + c * r.x * r.y,
        d[4] - 2 * r.y * d[1] + c * r.y * r.y,
    ]
}

/// potrace's penalty from the chord `u` (start minus end, doubled
/// coordinates), the second moments of the `cnt` vertices about the end
/// ([`Chords::moments`]): `√(Σ (u × u_t)² / cnt)`, the doubled
/// coordinates' factor 16 taken out exactly.
#[cfg(test)]
fn penalty(u: Lattice, [mxx, mxy, myy]: [i64; 3], cnt: f64) -> f64 {
    root_mean(u.x * u.x * myy - 2 * u.x * u.y * mxy + u.y * u.y * mxx, cnt)
}

/// `√(s / 16 / cnt)`: the penalty from its exact sum `s` in doubled
/// coordinates (the factor 16 is a power of two, so this is the value the
/// sum in pixel units gives).
fn root_mean(s: i64, cnt: f64) -> f64 {
    (s as f64 * (1.0 / 16.0) / cnt).sqrt()
}

/// Step 3: the optimal polygon over the possible segments `ahead` (see
/// [`possible_segments`]) of the closed `path`, as path indices in order
/// from the start vertex: the fewest segments from the start, and of those
/// the least total penalty (module docs; potrace's `bestpolygon`).
#[inline(never)] // (once per path; kept whole in profiles)
pub(super) fn optimal_polygon(path: &[Point], ahead: &[usize]) -> Vec<usize> {
    let n = path.len();
    if n < 3 || ahead.len() != n {
        return (0..n).collect();
    }
    let (start, _) = fewest_start(ahead);
    let chords = Chords::new(path, start);
    let Bounds { clip1, seg0, seg1 } = Bounds::new(ahead, start);
    let m = seg0.len() - 1;
    // pen[i]: the least total penalty of j segments from 0 to i, for i in
    // seg1[j] ..= seg0[j] (these ranges are disjoint for different j, as
    // in potrace); prev[i]: the vertex before i on that polygon.
    let mut pen = vec![f64::INFINITY; n + 1];
    let mut prev = vec![0usize; n + 1];
    pen[0] = 0.0;
    // least[k]: the least total of layer j − 1 from seg1[j − 1] up to k,
    // so the search into a vertex stops where no start below can win.
    let mut least = vec![f64::INFINITY; n + 1];
    for j in 1..=m {
        let range = seg1[j - 1]..=seg0[j - 1].min(n);
        if let (Some(totals), Some(lows)) = (pen.get(range.clone()), least.get_mut(range)) {
            let mut low = f64::INFINITY;
            for (l, &t) in lows.iter_mut().zip(totals) {
                low = low.min(t);
                *l = low;
            }
        }
        let first = seg1[j];
        let layer = clip1.get(first..=seg0[j].min(n)).unwrap_or_default();
        for (i, &clip) in (first..).zip(layer) {
            let hi = seg0[j - 1].min(i.saturating_sub(1));
            let lo = clip.max(seg1[j - 1]);
            // (Empty for i = 0, where potrace's loop only compares
            // pen[0] with itself.)
            let (before, rest) = pen.split_at_mut(i);
            if let (Some(pens), Some(least), Some(best), Some(p)) = (
                before.get(lo..=hi),
                least.get(lo..=hi),
                rest.first_mut(),
                prev.get_mut(i),
            ) {
                (*best, *p) = best_start(&chords, (pens, least), lo, i, (*best, *p));
            }
        }
    }
    let mut out = Vec::with_capacity(m);
    let mut i = n;
    for _ in 0..m {
        i = prev[i];
        out.push((start + i) % n);
    }
    out.reverse();
    out
}

/// Where potrace's `bestpolygon` searches, in indices relative to the
/// start vertex (0, and `n` for it again).
pub(super) struct Bounds {
    /// `clip1[j]`: the nearest vertex a segment into `j` can start from
    /// (nondecreasing).
    pub(super) clip1: Vec<usize>,
    /// `seg0[j]`: the farthest vertex `j` segments reach from 0.
    pub(super) seg0: Vec<usize>,
    /// `seg1[j]`: the nearest vertex from which `n` is reached in `m − j`
    /// segments (`m = seg0.len() − 1`, the fewest segments).
    pub(super) seg1: Vec<usize>,
}

impl Bounds {
    /// The bounds of possible segments `ahead` (see [`possible_segments`])
    /// from vertex `start`.
    pub(super) fn new(ahead: &[usize], start: usize) -> Self {
        let n = ahead.len();
        // clip0[i]: the farthest vertex a segment from i reaches
        // (nondecreasing).
        let (before, after) = ahead.split_at(start.min(n));
        let mut clip0 = Vec::with_capacity(n);
        clip0.extend(after.iter().map(|&a| a.max(1)));
        clip0.extend(before.iter().map(|&a| a.max(1)));
        for (i, c) in clip0.iter_mut().enumerate() {
            *c = (*c + i).min(n);
        }
        let mut clip1 = vec![0usize; n + 1];
        let mut i = 0;
        for (j, c) in clip1.iter_mut().enumerate().skip(1) {
            while clip0.get(i).is_some_and(|&c0| c0 < j) {
                i += 1;
            }
            *c = i;
        }
        let mut seg0 = vec![0usize];
        let mut at = 0;
        while at < n {
            at = clip0.get(at).copied().unwrap_or(n);
            seg0.push(at);
        }
        let m = seg0.len() - 1;
        let mut seg1 = vec![0usize; m + 1];
        seg1[m] = n;
        for j in (1..=m).rev() {
            seg1[j - 1] = clip1.get(seg1[j]).copied().unwrap_or(0);
        }
        Bounds { clip1, seg0, seg1 }
    }
}

/// The best start `k` of the last segment into relative vertex `i`, of the
/// candidates `lo ..= lo + pens.len() − 1` (whose totals are `pens`),
/// tried from the far end down as in potrace: the least `pen[k] + P(k, i)`
/// and its `k`, the first found on ties; `best` if none beats it.
///
/// Walking down, the moments about `v_i` grow by one vertex per candidate
/// (the first read off the prefix sums). `P(k, i) ≥ 0`, so a candidate
/// whose own total is no better than the best so far cannot win and its
/// penalty is not evaluated; the walk stops where `least` (each
/// candidate's lower bound on the totals from it down) reaches the best.
#[inline(never)] // (once per path; kept whole in profiles)
fn best_start(
    chords: &Chords,
    (pens, least): (&[f64], &[f64]),
    lo: usize,
    i: usize,
    mut best: (f64, usize),
) -> (f64, usize) {
    let Some(hi) = (lo + pens.len()).checked_sub(1).filter(|&hi| hi >= lo) else {
        return best;
    };
    let (Some(vs), Some(&r), Some(a), Some(b)) = (
        chords.v.get(lo..=hi),
        chords.v.get(i),
        chords.s.get(hi),
        chords.s.get(i + 1),
    ) else {
        return best;
    };
    // The moments about r of the vertices hi ..= i; each candidate below
    // adds its own vertex.
    let c = i + 1 - hi;
    let [mut mxx, mut mxy, mut myy] = moments(a, b, r, c as i64);
    let mut cnt = c as f64;
    let mut k = hi;
    for ((&v, &pk), &low) in vs.iter().zip(pens).zip(least).rev() {
        if low >= best.0 {
            // No start from here down has a total below the best.
            break;
        }
        let u = v - r;
        let (xx, xy, yy) = (u.x * u.x, u.x * u.y, u.y * u.y);
        if k < hi {
            mxx += xx;
            mxy += xy;
            myy += yy;
            cnt += 1.0;
        }
        if pk < best.0 {
            // Σ (u × u_t)² (module docs).
            let p = pk + root_mean(xx * myy - 2 * xy * mxy + yy * mxx, cnt);
            if p < best.0 {
                best = (p, k);
            }
        }
        k = k.wrapping_sub(1);
    }
    best
}

#[cfg(test)]
mod tests {
    use super::reference::{self, Sums};
    use super::*;
    use crate::outline::smooth::smooth_outline;
    use crate::raster::contour;
    use crate::raster::Grid;

    /// Every polygon round `n` vertices containing `start` (exhaustively,
    /// over vertex subsets) whose segments are possible under `ahead`:
    /// the fewest segments and, of those, the least total penalty.
    fn brute_force(path: &[Point], ahead: &[usize], start: Option<usize>) -> (usize, f64) {
        let n = path.len();
        let mut best = (usize::MAX, f64::INFINITY);
        for mask in 1u32..(1 << n) {
            if start.is_some_and(|s| mask & (1 << s) == 0) {
                continue;
            }
            let vs: Vec<usize> = (0..n).filter(|&v| mask & (1 << v) != 0).collect();
            let sums = Sums::new(path, vs[0]);
            let mut pen = 0.0;
            let mut ok = true;
            for (e, &a) in vs.iter().enumerate() {
                let b = vs.get(e + 1).copied().unwrap_or(vs[0] + n);
                if b - a > ahead[a] {
                    ok = false;
                    break;
                }
                pen += sums.penalty(a - vs[0], b - vs[0]);
            }
            if ok && (vs.len() < best.0 || (vs.len() == best.0 && pen < best.1 - 1e-12)) {
                best = (vs.len(), pen);
            }
        }
        best
    }

    /// Points on the half-pixel lattice from doubled coordinates.
    fn lattice_path(pts: &[(i32, i32)]) -> Vec<Point> {
        pts.iter()
            .map(|&(x, y)| Point::new(f64::from(x) / 2.0, f64::from(y) / 2.0))
            .collect()
    }

    proptest::proptest! {
        /// The dynamic programme finds the polygon the exhaustive search
        /// over vertex subsets finds: from its start vertex, the same
        /// fewest segments and least total penalty; and (all starts tried
        /// on loops this small) no polygon at all has fewer segments.
        #[test]
        fn penalty_polygon_equals_exhaustive_search(
            pts in proptest::collection::vec((0i32..20, 0i32..20), 4..13),
            lon in proptest::collection::vec(1usize..8, 13),
        ) {
            let path = lattice_path(&pts);
            let n = path.len();
            let ahead = possible_segments(&lon[..n]);
            // Monotone: a possible segment's sub-segments are possible.
            for i in 0..n {
                proptest::prop_assert!(ahead[i] <= ahead[(i + 1) % n] + 1);
                proptest::prop_assert!(ahead[i] >= 1 && ahead[i] <= lon[i].max(1));
            }
            let poly = optimal_polygon(&path, &ahead);
            proptest::prop_assert_eq!(&poly, &reference::optimal_polygon(&path, &ahead));
            let start = poly[0];
            let sums = Sums::new(&path, start);
            let mut pen = 0.0;
            for (e, &a) in poly.iter().enumerate() {
                let b = poly.get(e + 1).copied().unwrap_or(start);
                let (ra, rb) = ((a + n - start) % n, (b + n - start) % n);
                let rb = if rb == 0 { n } else { rb };
                proptest::prop_assert!(rb > ra && rb - ra <= ahead[a], "segment {a} -> {b}");
                pen += sums.penalty(ra, rb);
            }
            let (count, best) = brute_force(&path, &ahead, Some(start));
            proptest::prop_assert_eq!(poly.len(), count);
            proptest::prop_assert!((pen - best).abs() < 1e-6, "{} vs {}", pen, best);
            proptest::prop_assert_eq!(brute_force(&path, &ahead, None).0, count);
        }

        /// The lattice penalty is the chord length times the root mean
        /// square distance of the vertices from the chord, and bit for bit
        /// the floating-point prefix sums' value.
        #[test]
        fn lattice_penalty_is_direct_and_equals_the_float_sums(
            pts in proptest::collection::vec((-100i32..100, -100i32..100), 3..30),
            start in 0usize..30, i in 0usize..30, len in 1usize..30,
        ) {
            let path = lattice_path(&pts);
            let n = path.len();
            let (start, i) = (start % n, i % n);
            let j = (i + len).min(n);
            proptest::prop_assume!(j > i);
            let at = |t: usize| path[(start + t) % n];
            let e = at(j) - at(i);
            let m = at(i).midpoint(at(j));
            let direct = ((i..=j).map(|t| e.cross(at(t) - m).powi(2)).sum::<f64>()
                / (j + 1 - i) as f64)
                .sqrt();
            let p = Chords::new(&path, start).penalty(i, j);
            proptest::prop_assert!((p * p - direct * direct).abs() < 1e-9 * (1.0 + direct * direct));
            let float = Sums::new(&path, start).penalty(i, j);
            proptest::prop_assert_eq!(p.to_bits(), float.to_bits());
        }

        /// The possible segments are the fixpoint of potrace's clean-up,
        /// `ahead[i] = min(lon[i], ahead[i + 1] + 1)` round the loop (every
        /// reach clamped to the loop), less the cap for loops that would
        /// close in two segments: as two full backward passes give them.
        #[test]
        fn possible_segments_are_the_cleanup_fixpoint(
            lon in proptest::collection::vec(1usize..40, 1..60),
        ) {
            let n = lon.len();
            let mut want: Vec<usize> = lon.iter().map(|&l| l.clamp(1, n.max(2) - 1)).collect();
            for _ in 0..2 {
                for i in (0..n).rev() {
                    want[i] = want[i].min(want[(i + 1) % n] + 1);
                }
            }
            if n >= 4 && fewest_start(&want).1 < 3 {
                for a in want.iter_mut() {
                    *a = (*a).min((n - 1) / 2);
                }
            }
            proptest::prop_assert_eq!(possible_segments(&lon), want);
        }
    }

    /// A union of `count` random discs and slanted bars, rasterized on a
    /// `size`² grid.
    pub(super) fn random_blobs(
        size: usize,
        count: usize,
        rnd: &mut impl FnMut() -> f64,
    ) -> Grid<f32> {
        let scale = size as f64 / 64.0;
        let shapes: Vec<(f64, f64, f64, f64)> = (0..count)
            .map(|_| {
                let (cx, cy) = (rnd() * 60.0 * scale, rnd() * 60.0 * scale);
                (cx, cy, (3.0 + rnd() * 15.0) * scale, rnd())
            })
            .collect();
        Grid::from_fn(size, size, |x, y| {
            let (x, y) = (x as f64 + 0.5, y as f64 + 0.5);
            let hit = shapes.iter().any(|&(cx, cy, r, k)| {
                if k < 0.5 {
                    (x - cx).hypot(y - cy) <= r
                } else {
                    let slope = 4.0 * k - 3.0;
                    ((y - cy) - slope * (x - cx)).abs() < 0.3 * r && (x - cx).abs() < 2.0 * r
                }
            });
            if hit {
                1.0
            } else {
                0.0
            }
        })
    }

    /// On the loops of random blobs (real pixel-edge paths, up to a few
    /// thousand vertices), the lattice search gives the floating-point
    /// search's polygon exactly, and every candidate's penalty is the
    /// float sums' bit for bit.
    #[test]
    fn lattice_polygon_equals_the_float_reference() {
        let mut seed = 0x2545f4914f6cdd1du64;
        let mut rnd = move || {
            seed ^= seed << 13;
            seed ^= seed >> 7;
            seed ^= seed << 17;
            (seed >> 11) as f64 / (1u64 << 53) as f64
        };
        let (mut loops, mut vertices) = (0, 0);
        for round in 0..24 {
            let cov = random_blobs(if round % 3 == 0 { 400 } else { 96 }, 5, &mut rnd);
            let values = cov.map(|c| if c >= 0.5 { -0.5 } else { 0.5 });
            for c in contour::extract(&values) {
                let path = &c.points;
                let n = path.len();
                if n < 4 {
                    continue;
                }
                let ahead = possible_segments(&straight_runs(path));
                let poly = optimal_polygon(path, &ahead);
                assert_eq!(
                    poly,
                    reference::optimal_polygon(path, &ahead),
                    "{n} vertices"
                );
                let start = fewest_start(&ahead).0;
                let (fast, float) = (Chords::new(path, start), Sums::new(path, start));
                for i in (1..=n).step_by(7) {
                    for k in i.saturating_sub(MAX_RUN)..i {
                        let (p, q) = (fast.penalty(k, i), float.penalty(k, i));
                        assert_eq!(p.to_bits(), q.to_bits(), "P({k}, {i}) of {n}");
                    }
                }
                loops += 1;
                vertices += n;
            }
        }
        assert!(
            loops > 40 && vertices > 20_000,
            "{loops} loops, {vertices} vertices"
        );
    }

    /// The one closed path round the ink of a bitmap with one island.
    fn only_path(cov: &Grid<f32>) -> Vec<Point> {
        let values = cov.map(|c| if c >= 0.5 { -0.5 } else { 0.5 });
        let mut cs = contour::extract(&values);
        assert_eq!(cs.len(), 1);
        cs.remove(0).points
    }

    #[test]
    fn straight_runs_follow_a_shallow_staircase() {
        // A band of slope 1/5 rasterized: its long edges are staircases of
        // five-pixel steps. Runs are anchored at a vertex that may itself be
        // half a pixel off the drawn edge, so they span a couple of steps,
        // not the whole edge (see the module docs).
        let cov = Grid::from_fn(90, 40, |x, y| {
            let (x, y) = (x as f64 + 0.5, y as f64 + 0.5);
            let c = 10.3 + x / 5.0;
            if (y - c).abs() < 4.0 && (5.0..85.0).contains(&x) {
                1.0
            } else {
                0.0
            }
        });
        let path = &only_path(&cov);
        let n = path.len();
        let lon = straight_runs(path);
        for (i, &m) in lon.iter().enumerate() {
            assert_eq!(m, reference::run_from(path, i));
        }
        let longest = lon.iter().copied().max().unwrap_or(0);
        assert!(longest >= 8, "longest run {longest} of {n}");
        // Straight means: the chord passes through the box round every
        // vertex (L∞ distance from its line within the tolerance).
        for (i, &m) in lon.iter().enumerate() {
            let d = path[(i + m) % n] - path[i];
            for k in 0..=m {
                let off = d.cross(path[(i + k) % n] - path[i]).abs() / (d.x.abs() + d.y.abs());
                assert!(off <= STRAIGHT_TOLERANCE + 1e-9, "run {i}+{m}: {off}");
            }
        }
        // The polygon needs far fewer vertices than the path.
        let poly = optimal_polygon(path, &possible_segments(&lon));
        assert!(poly.len() * 5 <= n, "{} vertices of {n}", poly.len());
        // And the smoothed outline stays within half a pixel (plus the
        // rounding of the band's four corners) of the drawn band's edges.
        let loops = smooth_outline(&cov);
        assert_eq!(loops.len(), 1);
        for p in &loops[0] {
            if (6.0..84.0).contains(&p.x) {
                let off = ((p.y - 10.3 - p.x / 5.0).abs() - 4.0).abs();
                assert!(off < 0.6, "{p:?} is {off} px off the band's edge");
            }
        }
    }
}
