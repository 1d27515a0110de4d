//! The E-step for signed distance channels: level-set evolution of the
//! synthesized SDF `Φᵒ` towards the matched tile neighbourhoods
//! (art-pattern-level-sets §2, Eq. 4–5).
//!
//! The level-set equation `Φ_t + F |∇Φ| = 0` moves every level of `Φ` along
//! its normal with speed `F = λ F_s − μ κ`:
//! * data speed (Eq. 4) `F_s = 2 (Φᵒ − Φ̄)`, where `Φ̄` is the mean of the
//!   overlapping neighbourhoods' SDF values at the pixel (Eq. 2 summed over
//!   `s_x`, divided by `|s_x|` so the time step does not depend on the
//!   patch overlap); positive where `Φᵒ` is too large, so the front moves
//!   outward there. `|∇Φ|` is taken by the upwind scheme of Osher & Sethian
//!   (one-sided differences chosen by the sign of `F`).
//! * curvature regularization (Eq. 5) `κ = div(∇Φ/|∇Φ|)` by central
//!   differences; `−μκ` shrinks convex fronts (mean curvature flow: a
//!   circle of radius r shrinks at `dr/dt = −μ/r`).
//!
//! Only the narrow band `|Φ| < band` is updated (Adalsteinsson & Sethian);
//! after the steps `Φ` is reinitialized to the exact signed distance of its
//! zero level (sub-pixel contours, exact distances), which restores
//! `|∇Φ| = 1` for the next E-step and the next band.

use crate::raster::contour;
use crate::raster::{Grid, Sdf};
use kurbo::{Affine, Line};
use rayon::prelude::*;

/// Parameters of one E-step of the level set.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Evolution {
    /// Weight `λ` of the data velocity (Eq. 5).
    pub lambda: f32,
    /// Weight `μ` of the curvature velocity (Eq. 5).
    pub mu: f32,
    /// Time step (≤ 0.25 for the curvature term's stability).
    pub dt: f32,
    /// Number of time steps.
    pub steps: usize,
    /// Narrow band half-width, pixels.
    pub band: f32,
}

/// The part of a grid the synthesis reads: pixels whose squared distance
/// (px²) to the region is at most `reach2`, the squared distances given
/// per pixel. Outside it the level set is neither moved nor kept an exact
/// distance (its sign stays), which bounds the cost of an E-step by the
/// region's neighbourhood instead of its bounding box (the narrow band of
/// Adalsteinsson & Sethian, applied to the region as well as the front).
#[derive(Clone, Copy, Debug)]
pub struct Live<'a> {
    /// Squared distance to the region per pixel, px².
    pub near: &'a Grid<f32>,
    /// Squared reach, px²: pixels at most this far are moved.
    pub reach2: f32,
}

impl Live<'_> {
    /// Whether pixel `(x, y)` is moved.
    fn moves(&self, x: usize, y: usize) -> bool {
        self.near.get(x, y) <= self.reach2
    }

    /// Whether pixel `(x, y)` keeps an exact distance: within the reach
    /// plus the one-pixel stencil of a step, plus the exact band of the
    /// reinitialization.
    fn exact(&self, x: usize, y: usize) -> bool {
        let d = self.reach2.sqrt() + 2.0 + crate::raster::sdf::BAND;
        self.near.get(x, y) <= d * d
    }
}

/// Evolves `phi` for `ev.steps` steps towards `target` (the mean matched
/// SDF; ignored where `weight` is 0), then reinitializes it. With `live`,
/// only the pixels it [`Live::moves`] are stepped and only its exact zone
/// is reinitialized exactly (see [`reinitialize_in`]).
pub fn evolve(
    phi: &mut Grid<f32>,
    target: &Grid<f32>,
    weight: &Grid<f32>,
    ev: &Evolution,
    live: Option<Live>,
) {
    for _ in 0..ev.steps {
        step(phi, target, weight, ev, live);
    }
    reinitialize_in(phi, live);
}

/// One explicit time step over the narrow band (and within `live`).
pub fn step(
    phi: &mut Grid<f32>,
    target: &Grid<f32>,
    weight: &Grid<f32>,
    ev: &Evolution,
    live: Option<Live>,
) {
    let (w, h) = (phi.width(), phi.height());
    let src: &Grid<f32> = phi;
    let mut next = vec![0.0f32; w * h];
    next.par_chunks_mut(w.max(1))
        .enumerate()
        .for_each(|(y, row)| {
            // The rows above and below, clamped at the grid's edge.
            let data = src.data();
            let line = |yy: usize| &data[yy * w..(yy + 1) * w];
            let (up, mid, down) = (line(y.saturating_sub(1)), line(y), line((y + 1).min(h - 1)));
            let value = |x: usize| -> f32 {
                let c = mid[x];
                if c.abs() >= ev.band || live.is_some_and(|l| !l.moves(x, y)) {
                    return c;
                }
                let (xl, xr) = (x.saturating_sub(1), (x + 1).min(w - 1));
                let (l, r, u, d) = (mid[xl], mid[xr], up[x], down[x]);
                // One-sided differences.
                let (dmx, dpx, dmy, dpy) = (c - l, r - c, c - u, d - c);
                let fs = if weight.get(x, y) > 0.0 {
                    2.0 * (c - target.get(x, y))
                } else {
                    0.0
                };
                let f = ev.lambda * fs;
                let grad_up = if f > 0.0 {
                    (dmx.max(0.0).powi(2)
                        + dpx.min(0.0).powi(2)
                        + dmy.max(0.0).powi(2)
                        + dpy.min(0.0).powi(2))
                    .sqrt()
                } else {
                    (dmx.min(0.0).powi(2)
                        + dpx.max(0.0).powi(2)
                        + dmy.min(0.0).powi(2)
                        + dpy.max(0.0).powi(2))
                    .sqrt()
                };
                // Curvature times |∇Φ| by central differences.
                let px = 0.5 * (r - l);
                let py = 0.5 * (d - u);
                let pxx = r - 2.0 * c + l;
                let pyy = d - 2.0 * c + u;
                let pxy = 0.25 * (down[xr] - up[xr] - down[xl] + up[xl]);
                let g2 = px * px + py * py;
                let kappa_grad = if g2 > 1e-12 {
                    (pxx * py * py - 2.0 * px * py * pxy + pyy * px * px) / g2
                } else {
                    0.0
                };
                c - ev.dt * f * grad_up + ev.dt * ev.mu * kappa_grad
            };
            for (x, out) in row.iter_mut().enumerate() {
                *out = value(x);
            }
        });
    if let Some(g) = Grid::from_vec(w, h, next) {
        *phi = g;
    }
}

/// [`reinitialize_in`] over the whole grid.
#[cfg(test)]
pub fn reinitialize(phi: &mut Grid<f32>) {
    reinitialize_in(phi, None);
}

/// Replaces `phi` by the signed distance to its zero level (pixel units,
/// negative inside): sub-pixel contours of `Φ`, exact distances to them
/// within `sdf::BAND`, within half a pixel beyond, except where the
/// nearest zero level is its closure along the canvas border (no pixel
/// beyond the border marks the other side): there beyond the band it is
/// the distance to the nearest pixel of the other side, which can be
/// larger. A field without a zero level keeps its sign, clamped to the
/// grid's diagonal.
///
/// Exact only where `live` asks ([`Live::exact`]; everywhere for `None`):
/// the zero level's segments outside that zone are left out, so the
/// pixels beyond it keep their sign and get the distance to the other
/// side.
pub fn reinitialize_in(phi: &mut Grid<f32>, live: Option<Live>) {
    let (w, h) = (phi.width(), phi.height());
    let mut segments = Vec::new();
    for c in contour::extract(phi) {
        let n = c.points.len();
        for i in 0..n {
            let l = Line::new(c.points[i], c.points[(i + 1) % n]);
            let m = l.midpoint();
            let (x, y) = (
                (m.x.max(0.0) as usize).min(w.saturating_sub(1)),
                (m.y.max(0.0) as usize).min(h.saturating_sub(1)),
            );
            if live.is_none_or(|lv| lv.exact(x, y)) {
                segments.push(l);
            }
        }
    }
    if segments.is_empty() {
        let far = (phi.width() + phi.height()) as f32;
        for v in phi.data_mut() {
            *v = if *v < 0.0 { -far } else { far };
        }
        return;
    }
    let inside = phi.map(|v| v < 0.0);
    *phi = Sdf::from_segments(&inside, &segments, Affine::IDENTITY).dist;
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::raster::sdf::{BAND, MIN_INSIDE};

    fn circle(n: usize, r: f32) -> Grid<f32> {
        let c = n as f32 / 2.0;
        Grid::from_fn(n, n, |x, y| {
            (x as f32 + 0.5 - c).hypot(y as f32 + 0.5 - c) - r
        })
    }

    /// Radius from the enclosed area, with sub-pixel coverage ½ − Φ.
    fn radius(phi: &Grid<f32>) -> f32 {
        let a: f32 = phi.data().iter().map(|v| (0.5 - v).clamp(0.0, 1.0)).sum();
        (a / std::f32::consts::PI).sqrt()
    }

    #[test]
    fn curvature_flow_shrinks_a_circle_at_one_over_r() {
        let (r0, dt) = (20.0f32, 0.2f32);
        let mut phi = circle(64, r0);
        let zero = Grid::new(64, 64, 0.0);
        let ev = Evolution {
            lambda: 0.0,
            mu: 1.0,
            dt,
            steps: 25,
            band: 6.0,
        };
        let mut t = 0.0;
        for _ in 0..20 {
            evolve(&mut phi, &zero, &zero, &ev, None);
            t += dt * ev.steps as f32;
            let expected = (r0 * r0 - 2.0 * t).sqrt();
            let got = radius(&phi);
            assert!(
                (got - expected).abs() < 0.35,
                "t = {t}: r = {got}, analytic {expected}"
            );
        }
        // t = 100: r = √200 ≈ 14.1 — a real shrink, not a standstill.
        assert!(radius(&phi) < 14.5);
    }

    #[test]
    fn the_data_term_moves_the_front_to_the_target() {
        let mut phi = circle(48, 8.0);
        let target = circle(48, 12.0);
        let one = Grid::new(48, 48, 1.0);
        let ev = Evolution {
            lambda: 1.0,
            mu: 0.0,
            dt: 0.2,
            steps: 10,
            band: 8.0,
        };
        for _ in 0..6 {
            evolve(&mut phi, &target, &one, &ev, None);
        }
        assert!((radius(&phi) - 12.0).abs() < 0.3, "{}", radius(&phi));
    }

    /// Reinitialization against brute force: the distance from every pixel
    /// centre to every contour segment of a random field's zero level
    /// (kept off the canvas border, where the contour is closed along the
    /// border and no pixel beyond it holds the other side).
    #[test]
    fn reinitialization_matches_brute_force_distances() {
        for seed in 0..4u64 {
            let (w, h) = (37, 29);
            // A smooth random field: a few random discs, at least 2 px
            // from the border.
            let bumps: Vec<[f32; 3]> = (0..6)
                .map(|i| {
                    let r = |k: u64| crate::rng::unit(&[seed, i, k]) as f32;
                    let at = |k: u64, n: usize| 8.0 + r(k) * (n as f32 - 16.0);
                    [at(0, w), at(1, h), 2.0 + 4.0 * r(2)]
                })
                .collect();
            let mut phi = Grid::from_fn(w, h, |x, y| {
                let (px, py) = (x as f32 + 0.5, y as f32 + 0.5);
                bumps
                    .iter()
                    .map(|b| (px - b[0]).hypot(py - b[1]) - b[2])
                    .fold(f32::INFINITY, f32::min)
            });
            let before = phi.clone();
            let segments: Vec<Line> = contour::extract(&phi)
                .iter()
                .flat_map(|c| {
                    let n = c.points.len();
                    (0..n).map(move |i| Line::new(c.points[i], c.points[(i + 1) % n]))
                })
                .collect();
            reinitialize(&mut phi);
            for y in 0..h {
                for x in 0..w {
                    let p = kurbo::Point::new(x as f64 + 0.5, y as f64 + 0.5);
                    let exact = segments
                        .iter()
                        .map(|l| crate::raster::sdf::point_segment_distance(p, *l))
                        .fold(f64::INFINITY, f64::min) as f32;
                    let got = phi.get(x, y);
                    assert_eq!(got < 0.0, before.get(x, y) < 0.0, "sign at ({x}, {y})");
                    // Ink stays ink: a centre on the contour keeps MIN_INSIDE.
                    let want = if got < 0.0 {
                        exact.max(MIN_INSIDE)
                    } else {
                        exact
                    };
                    let err = got.abs() - want;
                    // Exact within the SDF's band, within half a pixel beyond.
                    let tol = if exact <= BAND { 1e-4 } else { 0.5 };
                    assert!(err.abs() < tol, "({x}, {y}): {got} vs {exact}");
                }
            }
        }
    }

    /// A field of many small random discs over a 60×50 grid.
    fn speckle(seed: u64) -> Grid<f32> {
        let bumps: Vec<[f32; 3]> = (0..40)
            .map(|i| {
                let r = |k: u64| crate::rng::unit(&[seed, i, k]) as f32;
                [r(0) * 60.0, r(1) * 50.0, 1.0 + 3.0 * r(2)]
            })
            .collect();
        Grid::from_fn(60, 50, |x, y| {
            let (px, py) = (x as f32 + 0.5, y as f32 + 0.5);
            bumps
                .iter()
                .map(|b| (px - b[0]).hypot(py - b[1]) - b[2])
                .fold(f32::INFINITY, f32::min)
        })
    }

    /// Restricting the E-step to a live zone around a small region: one
    /// step and one reinitialization give bit for bit the whole grid's
    /// values in the zone (and a pixel beyond), keep every sign and move
    /// nothing outside it; over several E-steps, where the frozen
    /// surroundings differ from evolved ones, the region's ink agrees.
    #[test]
    fn a_live_zone_evolves_as_the_whole_grid_inside_it() {
        for seed in 0..4u64 {
            let start = speckle(seed);
            let region = Grid::from_fn(60, 50, |x, y| {
                (20..32).contains(&x) && (18..30).contains(&y)
            });
            let near = crate::raster::edt::squared_edt(&region);
            let live = Live {
                near: &near,
                reach2: 6.0f32.powi(2),
            };
            let target = speckle(seed + 100);
            let one = Grid::new(60, 50, 1.0);
            let ev = Evolution {
                lambda: 0.6,
                mu: 0.3,
                dt: 0.2,
                steps: 5,
                band: 6.0,
            };
            let (mut whole, mut part) = (start.clone(), start.clone());
            step(&mut whole, &target, &one, &ev, None);
            step(&mut part, &target, &one, &ev, Some(live));
            for y in 0..50 {
                for x in 0..60 {
                    let want = if near.get(x, y) <= 36.0 {
                        whole.get(x, y)
                    } else {
                        start.get(x, y)
                    };
                    assert_eq!(part.get(x, y), want, "step ({x}, {y}) seed {seed}");
                }
            }
            let stepped = part.clone();
            reinitialize(&mut whole);
            let mut whole = {
                let mut p = stepped.clone();
                reinitialize(&mut p);
                p
            };
            reinitialize_in(&mut part, Some(live));
            for y in 0..50 {
                for x in 0..60 {
                    if near.get(x, y) <= 49.0 {
                        assert_eq!(part.get(x, y), whole.get(x, y), "reinit ({x}, {y})");
                    }
                    assert_eq!(part.get(x, y) < 0.0, stepped.get(x, y) < 0.0, "sign");
                }
            }
            // Several E-steps, votes (weight) only where patches reach and
            // the curvature weight of a synthesis (μ over the patch
            // overlap): the region's ink agrees.
            let votes = near.map(|d| if d <= 25.0 { 1.0 } else { 0.0 });
            let ev = Evolution { mu: 0.04, ..ev };
            let one = votes;
            let mut part = whole.clone();
            for _ in 0..4 {
                evolve(&mut whole, &target, &one, &ev, None);
                evolve(&mut part, &target, &one, &ev, Some(live));
            }
            let inside: Vec<(usize, usize)> = (0..50)
                .flat_map(|y| (0..60).map(move |x| (x, y)))
                .filter(|&(x, y)| region.get(x, y))
                .collect();
            let agree = inside
                .iter()
                .filter(|&&(x, y)| (part.get(x, y) < 0.0) == (whole.get(x, y) < 0.0))
                .count();
            assert!(
                agree * 100 >= inside.len() * 98,
                "seed {seed}: {agree} of {} agree",
                inside.len()
            );
        }
    }

    #[test]
    fn reinitialization_restores_distances() {
        let mut phi = circle(40, 10.0).map(|v| 3.0 * v);
        reinitialize(&mut phi);
        let want = circle(40, 10.0);
        // Exact within the SDF's band, within half a pixel beyond.
        for (a, b) in phi.data().iter().zip(want.data()) {
            let tol = if b.abs() < 3.0 { 0.1 } else { 0.5 };
            assert!((a - b).abs() < tol, "{a} vs {b}");
        }
    }
}
