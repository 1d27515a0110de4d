//! Test oracles: the straight runs and the optimal polygon computed the
//! plain way, without the lattice arithmetic (floating point, the runs
//! walked vertex by vertex, the penalty from prefix sums about the start
//! vertex). The fast code must agree with them exactly.

use super::STRAIGHT_TOLERANCE;
use super::{fewest_start, MAX_RUN};
use kurbo::{Point, Vec2};

/// Which of eight directions, 45° apart (0 along +x, counting towards
/// +y), a step of a path points in.
pub(super) fn direction(step: Vec2) -> u8 {
    let sx = (step.x > 1e-9) as i32 - (step.x < -1e-9) as i32;
    let sy = (step.y > 1e-9) as i32 - (step.y < -1e-9) as i32;
    super::octant(sx, sy)
}

/// One straight run from an anchor, in floating point.
struct Run {
    anchor: Point,
    cone: Option<(Vec2, Vec2)>,
    dirs: u8,
}

impl Run {
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

    fn admits(&self, q: Point) -> bool {
        let d = q - self.anchor;
        match self.cone {
            Some((r, l)) => r.cross(d) >= 0.0 && d.cross(l) >= 0.0,
            None => true,
        }
    }

    fn take(&mut self, q: Point) -> bool {
        let tol = STRAIGHT_TOLERANCE;
        let d = q - self.anchor;
        if d.x.abs() <= tol && d.y.abs() <= tol {
            return true;
        }
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

/// The straight run from vertex `i`, vertex by vertex in floating point.
pub(super) fn run_from(path: &[Point], i: usize) -> usize {
    let n = path.len();
    let mut run = Run {
        anchor: path[i],
        cone: None,
        dirs: 0,
    };
    let mut best = 1;
    for m in 1..n.min(MAX_RUN) {
        let k = (i + m) % n;
        let step = path[k] - path[(k + n - 1) % n];
        if !(run.advances(direction(step)) && run.admits(path[k])) {
            break;
        }
        best = m;
        if !run.take(path[k]) {
            break;
        }
    }
    best
}

/// Prefix sums of the path's coordinates relative to the start vertex, in
/// floating point.
pub(super) struct Sums {
    s: Vec<[f64; 5]>,
    q: Vec<Vec2>,
}

impl Sums {
    pub(super) fn new(path: &[Point], start: usize) -> Self {
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

    /// potrace's penalty of the segment from relative vertex `i` to `j`.
    pub(super) fn penalty(&self, i: usize, j: usize) -> f64 {
        let (a, b) = (self.s[i], self.s[j + 1]);
        let (p, r) = (self.q[i], self.q[j]);
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
        let cxx = sxx - 2.0 * m.x * sx + cnt * m.x * m.x;
        let cxy = sxy - m.x * sy - m.y * sx + cnt * m.x * m.y;
        let cyy = syy - 2.0 * m.y * sy + cnt * m.y * m.y;
        let s = e.x * e.x * cyy - 2.0 * e.x * e.y * cxy + e.y * e.y * cxx;
        (s.max(0.0) / cnt).sqrt()
    }
}

/// The optimal polygon by potrace's dynamic programme, every candidate's
/// penalty from [`Sums`].
pub(super) fn optimal_polygon(path: &[Point], ahead: &[usize]) -> Vec<usize> {
    let n = path.len();
    if n < 3 || ahead.len() != n {
        return (0..n).collect();
    }
    let (start, _) = fewest_start(ahead);
    let sums = Sums::new(path, start);
    let super::Bounds { clip1, seg0, seg1 } = super::Bounds::new(ahead, start);
    let m = seg0.len() - 1;
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
