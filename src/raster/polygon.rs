//! Steps 2–3 of [`crate::raster::binary`]: the straight runs of a closed
//! path and the polygon with the fewest of them (Selinger 2003, §2.2: a
//! path segment is straight when a line passes within
//! [`STRAIGHT_TOLERANCE`] of its vertices; the optimal polygon, §2.2.2,
//! here by greedy covers from several starts).

use super::binary::STRAIGHT_TOLERANCE;
use kurbo::{Point, Vec2};
#[cfg(test)]
use rayon::prelude::*;

/// Longest straight run considered, in path vertices.
const MAX_RUN: usize = 400;

/// Step 2: `lon[i]` = how many vertices ahead of `i` a straight run from `i`
/// reaches (at least 1).
///
/// The path's steps come in few directions, and long stretches repeat one
/// (a pixel edge, a 45° staircase of edge midpoints). Along such a stretch
/// every test below is settled by its two ends: a point's distance to a
/// line is affine along a straight stretch, the cone of admissible
/// directions is an angular interval, and a stretch that advances keeps
/// advancing. So the walk jumps from stretch end to stretch end and only
/// steps vertex by vertex through the stretch where the run ends. The
/// result is the same as [`run_from`] applied at every vertex (tested).
#[cfg(test)]
fn straight_runs(path: &[Point]) -> Vec<usize> {
    let runs = Runs::new(path);
    (0..path.len())
        .into_par_iter()
        .map(|i| runs.from(i))
        .collect()
}

/// What the straight-run walk needs of a path, computed once: its steps and
/// how far each step repeats. [`Runs::from`] is then one vertex's run, so
/// the polygon search (step 3) computes runs only at the vertices it visits.
pub(super) struct Runs<'a> {
    path: &'a [Point],
    steps: Vec<(Vec2, f64)>,
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
            steps,
            stretch,
        }
    }

    /// `lon[i]`: how many vertices ahead of `i` the straight run from `i`
    /// reaches (at least 1).
    pub(super) fn from(&self, i: usize) -> usize {
        let (path, steps, stretch) = (self.path, &self.steps, &self.stretch);
        let n = path.len();
        let limit = n.min(MAX_RUN);
        let mut run = Run::new(path[i]);
        let mut j = i;
        let mut m = 0usize;
        loop {
            let ahead = stretch[j];
            let e = (j + ahead) % n;
            if ahead >= 2 && m + ahead < limit {
                // The stretch's first step must advance, and its end must
                // pass; then every vertex between passes too.
                let first = (j + 1) % n;
                if !run.advances(path[first], steps[first]) {
                    break;
                }
                if run.admits(path[e]) {
                    m += ahead;
                    j = e;
                    if !run.take(path[e]) {
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
                let k = (j + 1) % n;
                if !(run.advances(path[k], steps[k]) && run.admits(path[k])) {
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

/// The state of one straight run from an anchor vertex.
struct Run {
    anchor: Point,
    /// The cone of admissible directions, as its right and left edge
    /// vectors (counter-clockwise from right to left); None = any.
    cone: Option<(Vec2, Vec2)>,
    /// The farthest distance from the anchor of a vertex taken so far.
    farthest: f64,
}

impl Run {
    fn new(anchor: Point) -> Self {
        Run {
            anchor,
            cone: None,
            farthest: 0.0,
        }
    }

    /// Every step must advance along the run: a step across it (the end
    /// cap of a line, a notch) ends the run, or runs would cut such corners
    /// while staying within tolerance of every vertex.
    fn advances(&self, q: Point, (step, step_len): (Vec2, f64)) -> bool {
        let d = q - self.anchor;
        let len = d.hypot();
        len == 0.0 || step.dot(d) > 0.1 * len * step_len
    }

    /// Whether the segment from the anchor to `q` is a straight run over
    /// the vertices taken so far: it reaches (nearly) as far as every one
    /// of them, and passes within the tolerance of each (its direction is
    /// in the cone).
    fn admits(&self, q: Point) -> bool {
        let d = q - self.anchor;
        // len + tol < farthest, without the square root.
        let reach = self.farthest - STRAIGHT_TOLERANCE;
        if reach > 0.0 && d.hypot2() < reach * reach {
            return false;
        }
        match self.cone {
            Some((r, l)) => r.cross(d) >= 0.0 && d.cross(l) >= 0.0,
            None => true,
        }
    }

    /// Takes `q` into the run, narrowing the cone to the directions that
    /// pass within the tolerance of it; false when nothing is left beyond.
    fn take(&mut self, q: Point) -> bool {
        let tol = STRAIGHT_TOLERANCE;
        let d = q - self.anchor;
        let len = d.hypot();
        self.farthest = self.farthest.max(len);
        if len <= tol {
            return true;
        }
        // The half-angle a of the cone: sin a = tol / len. The edges are
        // d turned by ±a, scaled by len (only their directions matter):
        // len·cos a = √(len² − tol²), len·sin a = tol.
        let c = (len * len - tol * tol).sqrt() / len;
        let s = tol / len;
        let right = Vec2::new(d.x * c + d.y * s, -d.x * s + d.y * c);
        let left = Vec2::new(d.x * c - d.y * s, d.x * s + d.y * c);
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
        if !(run.advances(path[k], steps[k]) && run.admits(path[k])) {
            break;
        }
        best = m;
        if !run.take(path[k]) {
            break;
        }
    }
    best
}

/// Step 3: the polygon with fewest straight edges, as path indices in order.
pub(super) fn optimal_polygon(mut lon: impl FnMut(usize) -> usize, n: usize) -> Vec<usize> {
    // The greedy cover from `start`: how many vertices it has, counting up
    // to `limit` at most, and them in order into `out` when given.
    let mut cover = |start: usize, limit: usize, mut out: Option<&mut Vec<usize>>| -> usize {
        if let Some(o) = out.as_deref_mut() {
            o.push(start);
        }
        let mut count = 1;
        let mut at = 0usize; // steps from start
        let mut i = start; // (start + at) mod n
        while count < limit {
            let step = lon(i).max(1);
            at += step;
            if at >= n {
                break;
            }
            // i, step < n: one wrap at most.
            i += step;
            if i >= n {
                i -= n;
            }
            if let Some(o) = out.as_deref_mut() {
                o.push(i);
            }
            count += 1;
        }
        count
    };
    // The first start with the fewest vertices; a cover stops counting as
    // soon as it cannot beat the best so far.
    let tries = n.min(32);
    let mut best: Option<(usize, usize)> = None;
    for k in 0..tries {
        let start = k * n / tries;
        let limit = best.map_or(usize::MAX, |b| b.1);
        let count = cover(start, limit, None);
        if count < limit {
            best = Some((start, count));
        }
    }
    let mut out = Vec::new();
    if let Some((start, count)) = best {
        out.reserve(count);
        cover(start, usize::MAX, Some(&mut out));
    }
    out
}

/// [`optimal_polygon`] as first written: every cover built in full, the
/// first of fewest vertices kept. The reference the counting search must
/// agree with.
#[cfg(test)]
fn optimal_polygon_reference(mut lon: impl FnMut(usize) -> usize, n: usize) -> Vec<usize> {
    let mut cover = |start: usize| -> Vec<usize> {
        let mut out = vec![start];
        let mut at = 0usize;
        while at < n {
            let step = lon((start + at) % n).max(1);
            at += step;
            if at >= n {
                break;
            }
            out.push((start + at) % n);
        }
        out
    };
    let tries = n.min(32);
    let mut best: Option<Vec<usize>> = None;
    for k in 0..tries {
        let poly = cover(k * n / tries);
        if best.as_ref().is_none_or(|b| poly.len() < b.len()) {
            best = Some(poly);
        }
    }
    best.unwrap_or_default()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::raster::binary::smooth_outline;
    use crate::raster::Grid;
    use crate::trace::contour;

    proptest::proptest! {
        /// The counting search picks the same polygon as building every
        /// cover in full, for any run lengths (ties between starts, runs
        /// reaching past the start, runs of one).
        #[test]
        fn counted_covers_pick_the_reference_polygon(
            lon in proptest::collection::vec(1usize..12, 1..200),
            long in proptest::collection::vec(1usize..400, 0..4),
        ) {
            let mut lon = lon;
            let n = lon.len();
            for (k, &m) in long.iter().enumerate() {
                let at = k * 37 % n;
                lon[at] = m.min(n.saturating_sub(1)).max(1);
            }
            for l in lon.iter_mut() {
                *l = (*l).min(n.saturating_sub(1)).max(1);
            }
            proptest::prop_assert_eq!(
                optimal_polygon(|i| lon[i], n),
                optimal_polygon_reference(|i| lon[i], n)
            );
        }
    }

    /// The stretch-jumping walk gives the vertex-by-vertex runs exactly,
    /// on the loops of random blobs (every kind of staircase and corner),
    /// and the polygon search the reference's polygon.
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
                assert_eq!(
                    optimal_polygon(|i| fast[i], path.len()),
                    optimal_polygon_reference(|i| fast[i], path.len())
                );
            }
        }
        assert!(checked > 5000, "only {checked} vertices");
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
        let values = cov.map(|c| if c >= 0.5 { -0.5 } else { 0.5 });
        let cs = contour::extract(&values);
        assert_eq!(cs.len(), 1);
        let path = &cs[0].points;
        let n = path.len();
        let lon = straight_runs(path);
        for (i, &m) in lon.iter().enumerate() {
            assert_eq!(m, run_from(path, i));
        }
        let longest = lon.iter().copied().max().unwrap_or(0);
        assert!(longest >= 8, "longest run {longest} of {n}");
        // Straight means: every vertex within the tolerance of the chord.
        for (i, &m) in lon.iter().enumerate() {
            let chord = kurbo::Line::new(path[i], path[(i + m) % n]);
            for k in 0..=m {
                let d = crate::raster::sdf::point_segment_distance(path[(i + k) % n], chord);
                assert!(d <= STRAIGHT_TOLERANCE + 1e-9, "run {i}+{m}: {d}");
            }
        }
        // The polygon needs far fewer vertices than the path.
        let poly = optimal_polygon(|i| lon[i], n);
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
