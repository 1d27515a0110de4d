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

/// Evolves `phi` for `ev.steps` steps towards `target` (the mean matched
/// SDF; ignored where `weight` is 0), then reinitializes it.
pub fn evolve(phi: &mut Grid<f32>, target: &Grid<f32>, weight: &Grid<f32>, ev: &Evolution) {
    for _ in 0..ev.steps {
        step(phi, target, weight, ev);
    }
    reinitialize(phi);
}

/// One explicit time step over the narrow band.
pub fn step(phi: &mut Grid<f32>, target: &Grid<f32>, weight: &Grid<f32>, ev: &Evolution) {
    let (w, h) = (phi.width(), phi.height());
    let src: &Grid<f32> = phi;
    let mut next = vec![0.0f32; w * h];
    next.par_chunks_mut(w.max(1))
        .enumerate()
        .for_each(|(y, row)| {
            let value = |x: usize| -> f32 {
                let c = src.get(x, y);
                if c.abs() >= ev.band {
                    return c;
                }
                let at = |dx: isize, dy: isize| {
                    let xx = (x as isize + dx).clamp(0, w as isize - 1) as usize;
                    let yy = (y as isize + dy).clamp(0, h as isize - 1) as usize;
                    src.get(xx, yy)
                };
                let (l, r, u, d) = (at(-1, 0), at(1, 0), at(0, -1), at(0, 1));
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
                let pxy = 0.25 * (at(1, 1) - at(1, -1) - at(-1, 1) + at(-1, -1));
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

/// Replaces `phi` by the signed distance to its zero level (pixel units,
/// negative inside): sub-pixel contours of `Φ`, exact distances to them
/// within `sdf::BAND`, within half a pixel beyond, except where the
/// nearest zero level is its closure along the canvas border (no pixel
/// beyond the border marks the other side): there beyond the band it is
/// the distance to the nearest pixel of the other side, which can be
/// larger. A field without a zero level keeps its sign, clamped to the
/// grid's diagonal.
pub fn reinitialize(phi: &mut Grid<f32>) {
    let mut segments = Vec::new();
    for c in contour::extract(phi) {
        let n = c.points.len();
        for i in 0..n {
            segments.push(Line::new(c.points[i], c.points[(i + 1) % n]));
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
            evolve(&mut phi, &zero, &zero, &ev);
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
            evolve(&mut phi, &target, &one, &ev);
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
