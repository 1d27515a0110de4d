//! Step 2 of [`crate::outline::smooth`]: the straight runs of a closed path
//! (Selinger 2003, §2.2.1), on the half-pixel lattice.
//!
//! A run is anchored at its first vertex; a cone of admissible directions
//! (from the anchor) is narrowed by the box of half-side
//! [`STRAIGHT_TOLERANCE`] round each later vertex, as potrace's `calc_lon`
//! does. The path's steps come in few directions and long stretches repeat
//! one step (a pixel edge, a 45° staircase of edge midpoints). Along such a
//! stretch every test is settled in closed form: the vertices are
//! `q₀ + t·s`, so the cone's two edge tests are affine in `t` and the
//! largest admitted `t` is one division each; a direction that reaches a
//! vertex of the stretch passes through the box of every vertex before it
//! (the L∞ distance of a point from a line is affine along the stretch, and
//! within the tolerance at both ends), so the boxes in between narrow
//! nothing a later vertex needs. The walk therefore goes from stretch to
//! stretch, as `calc_lon` goes from corner to corner, and the result is
//! the vertex-by-vertex walk's exactly (tested against it).
//!
//! All of it is exact integer arithmetic in doubled pixel coordinates
//! ([`Lattice`]): the box corners are lattice points and the cone tests
//! are signs of small cross products.

use super::{Lattice, MAX_RUN};
use kurbo::Point;
use rayon::prelude::*;

use super::STRAIGHT_TOLERANCE;

/// [`STRAIGHT_TOLERANCE`] in doubled pixel coordinates: the boxes' corners
/// are lattice points only while it is a multiple of ½ px (checked when
/// compiling).
const TOL: i64 = (2.0 * STRAIGHT_TOLERANCE) as i64;
const _: () = assert!(TOL as f64 == 2.0 * STRAIGHT_TOLERANCE && TOL > 0);

/// Step 2: `lon[i]` = how many vertices ahead of `i` a straight run from `i`
/// reaches (at least 1, fewer than [`MAX_RUN`]).
#[inline(never)] // (once per path; kept whole in profiles)
pub(in crate::outline) fn straight_runs(path: &[Point]) -> Vec<usize> {
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

/// The step from a path vertex to the next and how far it repeats.
#[derive(Clone, Copy, Debug, Default)]
struct Step {
    /// The step, in doubled coordinates.
    x: i32,
    y: i32,
    /// Its direction (of eight, [`Lattice::direction`]) as a bit, and that
    /// direction's bit with its two neighbours'.
    bit: u8,
    near: u8,
    /// How many vertices ahead the step keeps repeating (at least 1), at
    /// most [`MAX_RUN`].
    len: u16,
}

/// What the straight-run walk needs of a path, computed once: its vertices
/// on the lattice and the steps after them. [`Runs::from`] is then one
/// vertex's run.
pub(super) struct Runs {
    path: Vec<Lattice>,
    /// `after[k]`: the step from vertex `k` to `k + 1` and its stretch.
    after: Vec<Step>,
}

impl Runs {
    /// The steps and stretches of the closed path `path`.
    pub(super) fn new(path: &[Point]) -> Self {
        let path: Vec<Lattice> = path.iter().map(|&p| Lattice::of(p)).collect();
        let n = path.len();
        let step = |a: Lattice, b: Lattice| {
            let s = b - a;
            let bit = 1u8 << s.direction();
            Step {
                x: s.x as i32,
                y: s.y as i32,
                bit,
                near: bit | bit.rotate_left(1) | bit.rotate_right(1),
                len: 1,
            }
        };
        let mut after: Vec<Step> = Vec::with_capacity(n);
        after.extend(path.windows(2).map(|w| step(w[0], w[1])));
        if let (Some(&last), Some(&first)) = (path.last(), path.first()) {
            after.push(step(last, first));
        }
        let same = |a: &Step, b: &Step| (a.x, a.y) == (b.x, b.y);
        // From a vertex whose step differs from the next one's (its
        // stretch is 1) backwards once round the loop: a stretch is one
        // longer than the next vertex's when their steps agree.
        let cap = MAX_RUN as u16;
        let next = |k: usize| if k + 1 == n { 0 } else { k + 1 };
        match (0..n).find(|&b| !same(&after[b], &after[next(b)])) {
            Some(b) => {
                let mut extend = |k: usize| {
                    let following = after[next(k)];
                    if same(&after[k], &following) {
                        after[k].len = (following.len + 1).min(cap);
                    }
                };
                (0..b).rev().for_each(&mut extend);
                (b + 1..n).rev().for_each(&mut extend);
            }
            None => after.iter_mut().for_each(|s| s.len = cap),
        }
        Runs { path, after }
    }

    /// `lon[i]`: how many vertices ahead of `i` the straight run from `i`
    /// reaches (at least 1).
    pub(super) fn from(&self, i: usize) -> usize {
        let (path, after) = (&self.path, &self.after);
        let n = path.len();
        let limit = n.min(MAX_RUN);
        let wrap = |k: usize| if k >= n { k - n } else { k };
        // The steps taken so far keep to two neighbouring directions of
        // the eight (potrace's rule that a straight path never steps in
        // all four directions, for paths that also step diagonally): a run
        // does not turn round the end of a line, whose two sides would
        // otherwise be one run within the tolerance of a 1-px line's
        // vertices. `allowed` holds the directions within one of every
        // step taken: a step in one of them keeps the run's steps to two
        // neighbouring directions. Such steps advance along the run, so
        // no vertex is nearer the anchor than one before it (in either
        // coordinate): a notch's back step ends the run.
        let mut allowed = u8::MAX;
        // The vertex reached (j), relative to the anchor, and how many
        // more vertices the run may take.
        let mut j = i;
        let mut d = Lattice::default();
        let Some(mut rem) = limit.checked_sub(1) else {
            return 1;
        };
        let run = |rem: usize| (limit - 1 - rem).max(1);
        // Until the run leaves the box round the anchor, every direction
        // passes through the boxes so far: whole stretches are taken.
        let (mut r, mut l) = loop {
            let Some(&s) = after.get(j) else {
                return 1;
            };
            if rem == 0 || allowed & s.bit == 0 {
                return run(rem);
            }
            allowed &= s.near;
            let t = usize::from(s.len).min(rem);
            rem -= t;
            j = wrap(j + t);
            d = d + Lattice::from(s) * t as i64;
            if d.x.abs() > TOL || d.y.abs() > TOL {
                break corners(d);
            }
        };
        // Then the cone of admissible directions, from its right edge r to
        // its left edge l (counter-clockwise), is narrowed stretch by
        // stretch.
        while rem > 0 {
            let Some(&s) = after.get(j) else {
                break;
            };
            if allowed & s.bit == 0 {
                break;
            }
            allowed &= s.near;
            let reach = usize::from(s.len).min(rem);
            let step = Lattice::from(s);
            let end = d + step * reach as i64;
            if !(r.cross(end) >= 0 && end.cross(l) >= 0) {
                // The run ends inside this stretch.
                rem -= admitted(d, step, (r, l), reach);
                break;
            }
            rem -= reach;
            j = wrap(j + reach);
            d = end;
            // The box round d narrows the cone; nothing is left beyond when
            // its edges cross.
            let (right, left) = corners(d);
            if r.cross(right) > 0 {
                r = right;
            }
            if left.cross(l) > 0 {
                l = left;
            }
            if r.cross(l) < 0 {
                break;
            }
        }
        run(rem)
    }
}

impl From<Step> for Lattice {
    fn from(s: Step) -> Lattice {
        Lattice {
            x: i64::from(s.x),
            y: i64::from(s.y),
        }
    }
}

/// The largest `t ≤ reach` for which the vertex `d0 + t·step` (relative to
/// the anchor) lies in the cone `(r, l)`, `d0` being in it: each edge's
/// test, `r × (d0 + t·step) ≥ 0` and `(d0 + t·step) × l ≥ 0`, is affine
/// in `t`.
fn admitted(d0: Lattice, step: Lattice, (r, l): (Lattice, Lattice), reach: usize) -> usize {
    let mut t = reach as i64;
    let (a, b) = (r.cross(d0), r.cross(step));
    if b < 0 {
        t = t.min(a / -b);
    }
    let (a, b) = (d0.cross(l), step.cross(l));
    if b < 0 {
        t = t.min(a / -b);
    }
    t.max(0) as usize
}

/// The right and left edges of the cone of directions from the anchor
/// through the box of half-side [`STRAIGHT_TOLERANCE`] round `d` (which
/// does not contain the anchor): the box's two corners outermost seen
/// from the anchor, picked by the signs of `d` as in potrace's `calc_lon`
/// (right: counter-clockwise of it is admissible).
fn corners(d: Lattice) -> (Lattice, Lattice) {
    let sx = usize::from(d.x > 0) + 2 * usize::from(d.x < 0);
    let sy = usize::from(d.y > 0) + 2 * usize::from(d.y < 0);
    let [rx, ry, lx, ly] = CORNERS.get(3 * sx + sy).copied().unwrap_or_default();
    (
        Lattice {
            x: d.x + i64::from(rx),
            y: d.y + i64::from(ry),
        },
        Lattice {
            x: d.x + i64::from(lx),
            y: d.y + i64::from(ly),
        },
    )
}

/// [`corners`]' offsets from `d` (right x, y, left x, y) by the signs of
/// `d`'s coordinates (0, +, − as 0, 1, 2; index `3 · x + y`).
const CORNERS: [[i8; 4]; 9] = corner_offsets();

const fn sign(c: bool) -> i8 {
    if c {
        TOL as i8
    } else {
        -(TOL as i8)
    }
}

const fn corner_offsets() -> [[i8; 4]; 9] {
    let mut t = [[0i8; 4]; 9];
    let mut k = 0;
    while k < 9 {
        let sx: i8 = [0, 1, -1][k / 3];
        let sy: i8 = [0, 1, -1][k % 3];
        t[k] = [
            sign(sy > 0 || (sy == 0 && sx < 0)),
            sign(sx < 0 || (sx == 0 && sy < 0)),
            sign(sy < 0 || (sy == 0 && sx < 0)),
            sign(sx > 0 || (sx == 0 && sy < 0)),
        ];
        k += 1;
    }
    t
}

#[cfg(test)]
mod tests {
    use super::super::reference::{direction, run_from};
    use super::*;
    use crate::raster::contour;
    use crate::raster::Grid;

    /// The closed paths round the ink of `cov` (coverage ≥ ½).
    fn paths_of(cov: &Grid<f32>) -> Vec<Vec<Point>> {
        let values = cov.map(|c| if c >= 0.5 { -0.5 } else { 0.5 });
        contour::extract(&values)
            .into_iter()
            .map(|c| c.points)
            .collect()
    }

    /// The stretch-by-stretch lattice walk gives the floating-point
    /// vertex-by-vertex runs exactly, on the loops of random blobs (every
    /// kind of staircase and corner), and every run is straight by the
    /// definition.
    #[test]
    fn lattice_runs_equal_the_vertex_by_vertex_reference() {
        let mut seed = 0x9e3779b97f4a7c15u64;
        let mut rnd = move || {
            seed ^= seed << 13;
            seed ^= seed >> 7;
            seed ^= seed << 17;
            (seed >> 11) as f64 / (1u64 << 53) as f64
        };
        let mut checked = 0;
        for round in 0..60 {
            // A union of random discs and slanted bars, rasterized; the
            // later rounds larger, so long shallow staircases occur.
            let size = if round < 40 { 64 } else { 200 };
            let cov = crate::outline::polygon::tests::random_blobs(size, 4, &mut rnd);
            for path in &paths_of(&cov) {
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
        assert!(checked > 30_000, "only {checked} vertices");
    }

    /// The one closed path round the ink of a bitmap with one island.
    fn only_path(cov: &Grid<f32>) -> Vec<Point> {
        let mut ps = paths_of(cov);
        assert_eq!(ps.len(), 1);
        ps.remove(0)
    }

    /// Along an edge longer than [`MAX_RUN`] vertices (a bar 300 px
    /// long), every run stops at the cap and agrees with the
    /// vertex-by-vertex reference.
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
        let mut capped = 0;
        for (i, lon) in straight_runs(path).into_iter().enumerate() {
            assert_eq!(lon, run_from(path, i), "vertex {i}");
            capped += usize::from(lon == MAX_RUN - 1);
        }
        assert!(capped > 300, "{capped} runs reach the cap");
    }

    /// A large disc: near its extremes the staircase has long treads
    /// and the runs end inside them (where the closed-form admission
    /// decides); they agree with the vertex-by-vertex walk.
    #[test]
    fn runs_ending_inside_long_treads_agree_with_the_reference() {
        let cov = Grid::from_fn(320, 320, |x, y| {
            let (x, y) = (x as f64 + 0.5, y as f64 + 0.5);
            if (x - 160.3).hypot(y - 159.8) <= 150.0 {
                1.0
            } else {
                0.0
            }
        });
        let path = &only_path(&cov);
        let n = path.len();
        let step = |k: usize| path[k % n] - path[(k + n - 1) % n];
        let mut inside = 0;
        for (i, m) in straight_runs(path).into_iter().enumerate() {
            assert_eq!(m, run_from(path, i), "vertex {i}");
            // The run's last vertex is inside a stretch of one step
            // repeated at least five times on.
            let e = i + m;
            inside += usize::from((e..e + 5).all(|k| step(k + 1) == step(k)));
        }
        assert!(inside > 50, "{inside} runs end inside a tread");
    }
}
