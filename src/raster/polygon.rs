//! Steps 2–3 of [`crate::raster::binary`]: the straight runs of a closed
//! path and the optimal polygon over them (Selinger 2003, §2.2).
//!
//! **Straight runs** (§2.2.1). potrace calls a path straight when a line
//! passes within an L∞ box of half-side ½ round every vertex and the path
//! does not step in all four directions. Its implementation anchors the
//! line at the run's first vertex and narrows a cone of admissible
//! directions by the box round each later vertex; so does [`Runs`], with
//! boxes of half-side [`STRAIGHT_TOLERANCE`] round the vertices of
//! flourish's paths (through pixel-edge midpoints, so they step
//! diagonally too). The direction rule becomes: a run's steps keep to two
//! neighbouring directions of the eight (a staircase), so a run never
//! turns round the end of a line.
//!
//! **Possible segments.** Reaches are made monotone as potrace's `calc_lon`
//! cleans them up: `i → j` is a possible edge when every vertex from `i`
//! up to `j` has a run reaching `j`, so every sub-segment of a possible
//! segment is possible (the shortest-path search needs this).
//!
//! **Optimal polygon** (§2.2.2). The fewest possible segments round the
//! loop, and of those the one with the least sum of penalties: potrace's
//! `P(i, j) = |p_j − p_i| · √(mean squared distance of p_i … p_j to the
//! chord)`, read off prefix sums in constant time. As potrace does, the
//! cycle is cut at a fixed start vertex, which every candidate contains;
//! potrace takes the path's first vertex, here the start whose greedy
//! cover is shortest among [`START_TRIES`] spread round the loop (a greedy
//! cover is optimal from a fixed start on monotone reaches), so the count
//! is never worse than the greedy polygon flourish used before. From that
//! start, `seg0`/`seg1` bound where the `j`-th vertex can be and a dynamic
//! programme over them finds the least total penalty (potrace's
//! `bestpolygon`; linear in practice).

use super::binary::STRAIGHT_TOLERANCE;
use kurbo::{Point, Vec2};
use rayon::prelude::*;

/// Longest straight run considered, in path vertices (about 50–70 px of
/// outline). The penalty search's work grows with the runs' lengths: per
/// trace of the 2 Mpx ornament (callgrind) it costs 174 M instructions at
/// 400 and 114 M at 100. Longer runs buy nothing downstream (a straight
/// edge cut in two gets a smooth vertex on its line, and the curve fitter
/// spans it): at 100 the 2 Mpx ornament traces byte for byte as at 400
/// and the binary samples need the same segments. At 64 a 1.5-px
/// diagonal loses a tenth of its weight
/// (`binary_hairlines_keep_their_weight`).
const MAX_RUN: usize = 100;

/// How many starts (spread evenly round the loop) the fewest-segment
/// search tries before the penalty search runs from the best of them.
pub(super) const START_TRIES: usize = 32;

/// Step 2: `lon[i]` = how many vertices ahead of `i` a straight run from `i`
/// reaches (at least 1).
///
/// The path's steps come in few directions, and long stretches repeat one
/// (a pixel edge, a 45° staircase of edge midpoints). Along such a stretch
/// every test below is settled by its two ends: a vertex's L∞ distance
/// from a line through the anchor is affine along a straight stretch, the
/// cone of admissible directions is an angular interval, and a stretch
/// steps in one direction. So the walk jumps from stretch
/// end to stretch end and only steps vertex by vertex through the stretch
/// where the run ends. The result is the same as [`run_from`] applied at
/// every vertex (tested).
pub(super) fn straight_runs(path: &[Point]) -> Vec<usize> {
    let runs = Runs::new(path);
    if path.len() >= PARALLEL_RUNS {
        // A long loop (an ornament's outline holds most of its vertices)
        // is split across threads; the runs are collected in order.
        (0..path.len())
            .into_par_iter()
            .with_min_len(PARALLEL_RUNS / 2)
            .map(|i| runs.from(i))
            .collect()
    } else {
        (0..path.len()).map(|i| runs.from(i)).collect()
    }
}

/// Loops with at least this many vertices compute their runs in parallel.
const PARALLEL_RUNS: usize = 4096;

/// What the straight-run walk needs of a path, computed once: its steps'
/// directions and how far each step repeats. [`Runs::from`] is then one
/// vertex's run.
pub(super) struct Runs<'a> {
    path: &'a [Point],
    /// The direction (of eight, [`direction`]) of the step into each vertex.
    dirs: Vec<u8>,
    /// `stretch[k]`: how many vertices ahead of `k` the step into `k + 1`
    /// keeps repeating (at least 1).
    stretch: Vec<usize>,
}

impl<'a> Runs<'a> {
    /// The steps and stretches of `path`.
    pub(super) fn new(path: &'a [Point]) -> Self {
        let n = path.len();
        let steps = path_steps(path);
        let mut stretch = vec![1usize; n];
        if n >= 3 {
            let same = |k: usize| steps[(k + 1) % n].0 == steps[k].0;
            // Walk backwards twice around the loop so the wrap is settled.
            let mut len_after = vec![0usize; n]; // repeats of step k+1 after it
            for pass in 0..2 {
                for k in (0..n).rev() {
                    let next = (k + 1) % n;
                    let v = if same(next) {
                        (len_after[next] + 1).min(n - 1)
                    } else {
                        0
                    };
                    if pass == 1 || v > len_after[k] {
                        len_after[k] = v;
                    }
                }
            }
            for k in 0..n {
                stretch[k] = len_after[k] + 1;
            }
        }
        Runs {
            path,
            dirs: steps.iter().map(|s| direction(s.0) as u8).collect(),
            stretch,
        }
    }

    /// `lon[i]`: how many vertices ahead of `i` the straight run from `i`
    /// reaches (at least 1).
    pub(super) fn from(&self, i: usize) -> usize {
        let (path, dirs, stretch) = (self.path, &self.dirs, &self.stretch);
        let n = path.len();
        let limit = n.min(MAX_RUN);
        let wrap = |k: usize| if k >= n { k - n } else { k };
        let mut run = Run::new(path[i]);
        let mut j = i;
        let mut m = 0usize;
        loop {
            let ahead = stretch[j];
            // As far along the stretch as the run may go: its end, or the
            // cap (a long straight edge reaches it from every vertex).
            let reach = ahead.min(limit - 1 - m);
            if reach >= 2 {
                // The stretch's first step must advance, and the vertex
                // reached must pass; then every vertex between passes too.
                let e = wrap(j + reach);
                if !run.advances(dirs[wrap(j + 1)]) {
                    break;
                }
                if run.admits(path[e]) {
                    m += reach;
                    j = e;
                    if !run.take(path[e]) || m + 1 >= limit {
                        break;
                    }
                    continue;
                }
            }
            // Vertex by vertex to the end of the stretch (or the cap).
            let mut ended = false;
            for _ in 0..ahead {
                if m + 1 >= limit {
                    ended = true;
                    break;
                }
                let k = wrap(j + 1);
                if !(run.advances(dirs[k]) && run.admits(path[k])) {
                    ended = true;
                    break;
                }
                m += 1;
                j = k;
                if !run.take(path[k]) {
                    ended = true;
                    break;
                }
            }
            if ended {
                break;
            }
        }
        m.max(1)
    }
}

/// Each step of a closed path (from vertex k − 1 to vertex k) and its
/// length.
fn path_steps(path: &[Point]) -> Vec<(Vec2, f64)> {
    let n = path.len();
    (0..n)
        .map(|k| {
            let d = path[k] - path[(k + n - 1) % n];
            (d, d.hypot())
        })
        .collect()
}

/// Which of eight directions, 45° apart (0 along +x, counting towards
/// +y), a step of a path points in; from the signs of its components
/// (a path's steps are along an axis or diagonal).
fn direction(step: Vec2) -> u32 {
    let sx = (step.x > 1e-9) as i32 - (step.x < -1e-9) as i32;
    let sy = (step.y > 1e-9) as i32 - (step.y < -1e-9) as i32;
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

/// The state of one straight run from an anchor vertex.
struct Run {
    anchor: Point,
    /// The cone of admissible directions, as its right and left edge
    /// vectors (counter-clockwise from right to left); None = any.
    cone: Option<(Vec2, Vec2)>,
    /// The directions (of eight) of the steps taken so far, as bits.
    dirs: u8,
}

impl Run {
    fn new(anchor: Point) -> Self {
        Run {
            anchor,
            cone: None,
            dirs: 0,
        }
    }

    /// Whether the step into `q` may join the run; records its direction.
    ///
    /// The steps of a run keep to two neighbouring directions of the eight
    /// (potrace's rule that a straight path never steps in all four
    /// directions, for paths that also step diagonally): a run does not
    /// turn round the end of a line, whose two sides would otherwise be
    /// one run within the tolerance of a 1-px line's vertices. Two such
    /// directions are 45° apart, so every step advances along the run and
    /// no vertex is nearer the anchor than one before it: a notch's back
    /// step ends the run, and no further test is needed for that.
    fn advances(&mut self, dir: u8) -> bool {
        let bit = 1u8 << dir;
        let near = bit | bit.rotate_left(1) | bit.rotate_right(1);
        let dirs = self.dirs | bit;
        if self.dirs & !near != 0 || dirs.count_ones() > 2 {
            return false;
        }
        self.dirs = dirs;
        true
    }

    /// Whether the segment from the anchor to `q` is a straight run over
    /// the vertices taken so far: it passes through the box of each (its
    /// direction is in the cone).
    fn admits(&self, q: Point) -> bool {
        let d = q - self.anchor;
        match self.cone {
            Some((r, l)) => r.cross(d) >= 0.0 && d.cross(l) >= 0.0,
            None => true,
        }
    }

    /// Takes `q` into the run, narrowing the cone to the directions that
    /// pass through the box of half-side [`STRAIGHT_TOLERANCE`] round it;
    /// false when nothing is left beyond.
    fn take(&mut self, q: Point) -> bool {
        let tol = STRAIGHT_TOLERANCE;
        let d = q - self.anchor;
        if d.x.abs() <= tol && d.y.abs() <= tol {
            return true;
        }
        // The cone's new edges: the box's two corners that are outermost
        // seen from the anchor (the box does not contain it, so they span
        // less than 180°), picked by the signs of d as in potrace's
        // calc_lon (right: counter-clockwise of it is admissible).
        let sign = |c: bool| if c { tol } else { -tol };
        let right = Vec2::new(
            d.x + sign(d.y >= 0.0 && (d.y > 0.0 || d.x < 0.0)),
            d.y + sign(d.x <= 0.0 && (d.x < 0.0 || d.y < 0.0)),
        );
        let left = Vec2::new(
            d.x + sign(d.y <= 0.0 && (d.y < 0.0 || d.x < 0.0)),
            d.y + sign(d.x >= 0.0 && (d.x > 0.0 || d.y < 0.0)),
        );
        self.cone = Some(match self.cone {
            None => (right, left),
            Some((r, l)) => {
                let r2 = if r.cross(right) > 0.0 { right } else { r };
                let l2 = if left.cross(l) > 0.0 { left } else { l };
                if r2.cross(l2) < 0.0 {
                    return false;
                }
                (r2, l2)
            }
        });
        true
    }
}

/// [`straight_runs`] at one vertex, vertex by vertex: the reference the
/// stretch-jumping walk must agree with.
#[cfg(test)]
fn run_from(path: &[Point], i: usize) -> usize {
    let n = path.len();
    let steps = path_steps(path);
    let mut run = Run::new(path[i]);
    let mut best = 1;
    for m in 1..n.min(MAX_RUN) {
        let k = (i + m) % n;
        if !(run.advances(direction(steps[k].0) as u8) && run.admits(path[k])) {
            break;
        }
        best = m;
        if !run.take(path[k]) {
            break;
        }
    }
    best
}

/// Possible segments: `ahead[i]` = how many vertices ahead of `i` the
/// longest possible segment from `i` ends, `lon` cleaned up as potrace's
/// `calc_lon` does (`ahead[i] = min(lon[i], ahead[i + 1] + 1)` round the
/// loop), so that `i → j` possible implies every `i' → j'` inside it is.
/// At most `(n − 1) / 2` when the loop would otherwise close in two
/// segments (a polygon needs three).
pub(super) fn possible_segments(lon: &[usize]) -> Vec<usize> {
    let n = lon.len();
    let mut ahead: Vec<usize> = lon.iter().map(|&l| l.clamp(1, n.max(2) - 1)).collect();
    if n < 2 {
        return ahead;
    }
    // Two passes backwards round the loop settle the wrap: a reach is
    // shorter than the loop, so a constraint travels less than once round.
    for _ in 0..2 {
        for i in (0..n).rev() {
            let next = ahead[(i + 1) % n] + 1;
            if next < ahead[i] {
                ahead[i] = next;
            }
        }
    }
    if n >= 4 && fewest_start(&ahead).1 < 3 {
        let cap = (n - 1) / 2;
        for a in ahead.iter_mut() {
            *a = (*a).min(cap);
        }
    }
    ahead
}

/// The start (of [`START_TRIES`] spread round the loop) whose greedy
/// cover has the fewest segments, and that count: the first such start.
pub(super) fn fewest_start(ahead: &[usize]) -> (usize, usize) {
    let n = ahead.len();
    // The greedy cover from `start`: how many segments it has, counting up
    // to `limit` at most.
    let cover = |start: usize, limit: usize| -> usize {
        let mut count = 1;
        let mut at = 0usize; // steps from start
        let mut i = start; // (start + at) mod n
        while count < limit {
            let step = ahead[i].max(1);
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
    };
    // A cover stops counting as soon as it cannot beat the best so far.
    let tries = n.min(START_TRIES);
    let mut best = (0, usize::MAX);
    for k in 0..tries {
        let start = k * n / tries;
        let count = cover(start, best.1);
        if count < best.1 {
            best = (start, count);
        }
    }
    best
}

/// Prefix sums of the path's coordinates (relative to the start vertex,
/// taken `start`-first round the loop and back to it), for potrace's
/// penalty in constant time.
struct Sums {
    /// `s[t]`: sums of x, y, x², xy, y² over the first `t` vertices.
    s: Vec<[f64; 5]>,
    /// The vertices, relative to the start, `n + 1` of them (the start
    /// again last).
    q: Vec<Vec2>,
}

impl Sums {
    fn new(path: &[Point], start: usize) -> Self {
        let n = path.len();
        let q: Vec<Vec2> = (0..=n)
            .map(|t| path[(start + t) % n] - path[start])
            .collect();
        let mut s = Vec::with_capacity(n + 2);
        let mut acc = [0.0; 5];
        s.push(acc);
        for v in &q {
            acc[0] += v.x;
            acc[1] += v.y;
            acc[2] += v.x * v.x;
            acc[3] += v.x * v.y;
            acc[4] += v.y * v.y;
            s.push(acc);
        }
        Sums { s, q }
    }

    /// potrace's penalty of the segment from relative vertex `i` to `j`
    /// (`i < j ≤ n`): the chord's length times the root mean square
    /// distance of the vertices `i ..= j` from the chord's line (Selinger
    /// 2003, §2.2.2), px².
    fn penalty(&self, i: usize, j: usize) -> f64 {
        let (Some(a), Some(b)) = (self.s.get(i), self.s.get(j + 1)) else {
            return f64::INFINITY;
        };
        let (Some(&p), Some(&r)) = (self.q.get(i), self.q.get(j)) else {
            return f64::INFINITY;
        };
        let cnt = (j + 1 - i) as f64;
        let [sx, sy, sxx, sxy, syy] = [
            b[0] - a[0],
            b[1] - a[1],
            b[2] - a[2],
            b[3] - a[3],
            b[4] - a[4],
        ];
        let m = (p + r) * 0.5;
        let e = r - p;
        // Σ (e × (v − m))² = e_x² Σ(y − m_y)² − 2 e_x e_y Σ(x − m_x)(y − m_y)
        // + e_y² Σ(x − m_x)².
        let cxx = sxx - 2.0 * m.x * sx + cnt * m.x * m.x;
        let cxy = sxy - m.x * sy - m.y * sx + cnt * m.x * m.y;
        let cyy = syy - 2.0 * m.y * sy + cnt * m.y * m.y;
        let s = e.x * e.x * cyy - 2.0 * e.x * e.y * cxy + e.y * e.y * cxx;
        (s.max(0.0) / cnt).sqrt()
    }
}

/// Step 3: the optimal polygon over the possible segments `ahead` (see
/// [`possible_segments`]) of the closed `path`, as path indices in order
/// from the start vertex: the fewest segments from the start, and of those
/// the least total penalty (module docs; potrace's `bestpolygon`).
pub(super) fn optimal_polygon(path: &[Point], ahead: &[usize]) -> Vec<usize> {
    let n = path.len();
    if n < 3 || ahead.len() != n {
        return (0..n).collect();
    }
    let (start, _) = fewest_start(ahead);
    let sums = Sums::new(path, start);
    // clip0[i]: the farthest vertex a segment from i reaches; clip1[j]: the
    // nearest vertex a segment into j can start from (relative indices,
    // the start at 0 and again at n). Both are nondecreasing.
    let clip0: Vec<usize> = (0..n)
        .map(|i| (i + ahead[(start + i) % n].max(1)).min(n))
        .collect();
    let mut clip1 = vec![0usize; n + 1];
    let mut i = 0;
    for (j, c) in clip1.iter_mut().enumerate().skip(1) {
        while clip0.get(i).is_some_and(|&c0| c0 < j) {
            i += 1;
        }
        *c = i;
    }
    // seg0[j]: the farthest vertex j segments reach from 0; seg1[j]: the
    // nearest vertex from which n is reached in m − j segments.
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
    // pen[i]: the least total penalty of j segments from 0 to i, for i in
    // seg1[j] ..= seg0[j] (these ranges are disjoint for different j, as
    // in potrace); prev[i]: the vertex before i on that polygon.
    let mut pen = vec![f64::INFINITY; n + 1];
    let mut prev = vec![0usize; n + 1];
    pen[0] = 0.0;
    for j in 1..=m {
        for i in seg1[j]..=seg0[j].min(n) {
            let lo = clip1[i].max(seg1[j - 1]);
            for k in (lo..=seg0[j - 1].min(i.saturating_sub(1))).rev() {
                let p = pen[k] + sums.penalty(k, i);
                if p < pen[i] {
                    pen[i] = p;
                    prev[i] = k;
                }
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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::raster::binary::smooth_outline;
    use crate::raster::Grid;
    use crate::trace::contour;

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

    proptest::proptest! {
        /// The dynamic programme finds the polygon the exhaustive search
        /// over vertex subsets finds: from its start vertex, the same
        /// fewest segments and least total penalty; and (all starts tried
        /// on loops this small) no polygon at all has fewer segments.
        #[test]
        fn penalty_polygon_equals_exhaustive_search(
            pts in proptest::collection::vec((0.0f64..10.0, 0.0f64..10.0), 4..13),
            lon in proptest::collection::vec(1usize..8, 13),
        ) {
            let path: Vec<Point> = pts.iter().map(|&(x, y)| Point::new(x, y)).collect();
            let n = path.len();
            let ahead = possible_segments(&lon[..n]);
            // Monotone: a possible segment's sub-segments are possible.
            for i in 0..n {
                proptest::prop_assert!(ahead[i] <= ahead[(i + 1) % n] + 1);
                proptest::prop_assert!(ahead[i] >= 1 && ahead[i] <= lon[i].max(1));
            }
            let poly = optimal_polygon(&path, &ahead);
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

        /// The penalty read off prefix sums is the chord length times the
        /// root mean square distance of the vertices from the chord.
        #[test]
        fn penalty_from_sums_is_direct(
            pts in proptest::collection::vec((-50.0f64..50.0, -50.0f64..50.0), 3..30),
            start in 0usize..30, i in 0usize..30, len in 1usize..30,
        ) {
            let path: Vec<Point> = pts.iter().map(|&(x, y)| Point::new(x, y)).collect();
            let n = path.len();
            let (start, i) = (start % n, i % n);
            let j = (i + len).min(n);
            proptest::prop_assume!(j > i);
            let sums = Sums::new(&path, start);
            let at = |t: usize| path[(start + t) % n];
            let e = at(j) - at(i);
            let m = at(i).midpoint(at(j));
            let direct = ((i..=j).map(|t| e.cross(at(t) - m).powi(2)).sum::<f64>()
                / (j + 1 - i) as f64)
                .sqrt();
            // Squares compared: the sums cancel to within rounding of
            // |e|² times the coordinates' squares (100² here).
            let p = sums.penalty(i, j);
            proptest::prop_assert!((p * p - direct * direct).abs() < 1e-8 * (1.0 + e.hypot2()) * 1e4);
        }
    }

    /// The stretch-jumping walk gives the vertex-by-vertex runs exactly,
    /// on the loops of random blobs (every kind of staircase and corner),
    /// and every run is straight by the definition.
    #[test]
    fn jumping_runs_equal_the_vertex_by_vertex_reference() {
        let mut seed = 0x9e3779b97f4a7c15u64;
        let mut rnd = move || {
            seed ^= seed << 13;
            seed ^= seed >> 7;
            seed ^= seed << 17;
            (seed >> 11) as f64 / (1u64 << 53) as f64
        };
        let mut checked = 0;
        for _ in 0..40 {
            // A union of random discs and slanted bars, rasterized.
            let shapes: Vec<(f64, f64, f64, f64)> = (0..4)
                .map(|_| (rnd() * 60.0, rnd() * 60.0, 3.0 + rnd() * 15.0, rnd()))
                .collect();
            let cov = Grid::from_fn(64, 64, |x, y| {
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
            });
            let values = cov.map(|c| if c >= 0.5 { -0.5 } else { 0.5 });
            for c in contour::extract(&values) {
                let path = &c.points;
                let fast = straight_runs(path);
                for (i, &lon) in fast.iter().enumerate() {
                    assert_eq!(lon, run_from(path, i), "vertex {i} of {}", path.len());
                    checked += 1;
                }
                // Every run is straight by the definition itself: the
                // chord passes through the box round every vertex, and the
                // steps keep to two neighbouring directions.
                let n = path.len();
                for (i, &m) in fast.iter().enumerate() {
                    let d = path[(i + m) % n] - path[i];
                    let l1 = d.x.abs() + d.y.abs();
                    let mut dirs = 0u8;
                    for k in 1..=m {
                        let q = path[(i + k) % n] - path[i];
                        assert!(d.cross(q).abs() <= STRAIGHT_TOLERANCE * l1 + 1e-9);
                        dirs |= 1 << direction(path[(i + k) % n] - path[(i + k + n - 1) % n]);
                    }
                    assert!(
                        dirs.count_ones() <= 2
                            && (dirs.count_ones() < 2 || {
                                let lo = dirs.trailing_zeros();
                                let hi = 7 - dirs.leading_zeros();
                                hi - lo == 1 || (lo == 0 && hi == 7)
                            }),
                        "run {i}+{m} steps in directions {dirs:08b}"
                    );
                }
            }
        }
        assert!(checked > 5000, "only {checked} vertices");
    }

    /// The one closed path round the ink of a bitmap with one island.
    fn only_path(cov: &Grid<f32>) -> Vec<Point> {
        let values = cov.map(|c| if c >= 0.5 { -0.5 } else { 0.5 });
        let mut cs = contour::extract(&values);
        assert_eq!(cs.len(), 1);
        cs.remove(0).points
    }

    /// Along an edge longer than [`MAX_RUN`] vertices (a bar 300 px
    /// long), every run stops at the cap, jumping there in one step, and
    /// agrees with the vertex-by-vertex reference.
    #[test]
    fn runs_along_a_long_edge_stop_at_the_cap() {
        let cov = Grid::from_fn(320, 12, |x, y| {
            if (10..310).contains(&x) && (4..8).contains(&y) {
                1.0
            } else {
                0.0
            }
        });
        let path = &only_path(&cov);
        let runs = Runs::new(path);
        let mut capped = 0;
        for i in 0..path.len() {
            let lon = runs.from(i);
            assert_eq!(lon, run_from(path, i), "vertex {i}");
            capped += usize::from(lon == MAX_RUN - 1);
        }
        assert!(capped > 300, "{capped} runs reach the cap");
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
            assert_eq!(m, run_from(path, i));
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
