//! Target direction fields for fills: the region's own flow, and combing
//! strokes blended into it (Brushables, Lukáč et al. 2015, §3.2).
//!
//! **Kernel diffusion (Eq. 1–2).** A stroke `K` with unit tangents `d⁰(k)`
//! spreads its direction to a pixel `p` as the Gaussian-weighted mean
//! `d_K(p) = Σ_k G(|p−k|, σ) d⁰(k) / w_K(p)`, `w_K(p) = Σ_k G(|p−k|, σ)`,
//! with `σ` half the stroke width. **Combing (Eq. 3)** mixes it into the
//! previous field convexly, `dⁿ = w_s d_K + (1 − w_s) dⁿ⁻¹`, where `w_s` is
//! the stroke's kernel weight normalized to 1 on a long straight stroke and
//! clamped to `[0, 1]`, so a stroke acts only within its footprint.
//!
//! The region's default field is the same diffusion applied to its
//! boundary: the outline is a "stroke" whose tangents run along the edge,
//! and its kernel is wide (a fraction of the region) so the flow reaches the
//! interior. That wide kernel is evaluated as a normalized convolution of
//! the splatted boundary tangents with three box passes (a Gaussian to
//! within a few per cent, in time independent of σ).

use crate::field::DirectionGrid;
use crate::raster::Grid;
use kurbo::{Point, Vec2};
use rayon::prelude::*;

/// A piece of a direction stroke: a point (pixels) and the unit tangent
/// there, with the length of polyline it stands for (pixels).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct StrokeSample {
    /// Position in pixel coordinates.
    pub at: Point,
    /// Unit tangent, pixel axes (y down).
    pub dir: Vec2,
    /// Arc length represented, pixels.
    pub len: f64,
}

/// Samples a polyline (pixel coordinates) every `step` pixels, with its
/// unit tangents; zero-length pieces are skipped.
pub fn sample_polyline(points: &[Point], step: f64) -> Vec<StrokeSample> {
    let mut out = Vec::new();
    for w in points.windows(2) {
        let (a, b) = (w[0], w[1]);
        let d = b - a;
        let l = d.hypot();
        if l.is_nan() || l <= 1e-9 {
            continue;
        }
        let n = (l / step).ceil().max(1.0) as usize;
        let dir = d / l;
        for i in 0..n {
            let t = (i as f64 + 0.5) / n as f64;
            out.push(StrokeSample {
                at: a.lerp(b, t),
                dir,
                len: l / n as f64,
            });
        }
    }
    out
}

/// The region's default direction: boundary tangents diffused inward by a
/// normalized box-filtered (≈ Gaussian, std `sigma` px) convolution.
/// Pixels the kernel does not reach, or where opposite sides cancel, get
/// the mean direction of the whole boundary, else `+x`.
pub fn boundary_field(
    width: usize,
    height: usize,
    boundary: &[StrokeSample],
    sigma: f64,
) -> DirectionGrid {
    let mut vx = Grid::new(width, height, 0.0f32);
    let mut vy = Grid::new(width, height, 0.0f32);
    let mut wt = Grid::new(width, height, 0.0f32);
    let mut mean = Vec2::ZERO;
    for s in boundary {
        // A sample on the grid's far edge (x = width) belongs to the last
        // pixel, not outside: an outline drawn along the canvas edge keeps
        // its direction there.
        let (x, y) = (s.at.x.floor(), s.at.y.floor());
        if width == 0 || height == 0 || !(x >= 0.0 && y >= 0.0) {
            continue;
        }
        if x > width as f64 || y > height as f64 {
            continue;
        }
        let (x, y) = ((x as usize).min(width - 1), (y as usize).min(height - 1));
        vx.set(x, y, vx.get(x, y) + (s.dir.x * s.len) as f32);
        vy.set(x, y, vy.get(x, y) + (s.dir.y * s.len) as f32);
        wt.set(x, y, wt.get(x, y) + s.len as f32);
        mean += s.dir * s.len;
    }
    // Three box passes of width b have variance 3(b² − 1)/12 = σ².
    let b = ((4.0 * sigma * sigma + 1.0).sqrt().round() as usize).max(1) | 1;
    for _ in 0..3 {
        for g in [&mut vx, &mut vy, &mut wt] {
            *g = box_blur(g, b / 2);
        }
    }
    let fallback = if mean.hypot() > 1e-9 {
        mean.normalize()
    } else {
        Vec2::new(1.0, 0.0)
    };
    let peak = wt.data().iter().copied().fold(0.0f32, f32::max);
    Grid::from_fn(width, height, |x, y| {
        let (a, c, w) = (vx.get(x, y), vy.get(x, y), wt.get(x, y));
        let m = a.hypot(c);
        if w > peak * 1e-6 && m > 0.05 * w {
            [a / m, c / m]
        } else {
            [fallback.x as f32, fallback.y as f32]
        }
    })
}

/// A uniform field `dir` (normalized; `+x` when zero).
pub fn constant_field(width: usize, height: usize, dir: [f64; 2]) -> DirectionGrid {
    let l = dir[0].hypot(dir[1]);
    let d = if l > 1e-12 {
        [(dir[0] / l) as f32, (dir[1] / l) as f32]
    } else {
        [1.0, 0.0]
    };
    Grid::new(width, height, d)
}

/// Combs `field` with one stroke (Brushables Eq. 1–3): `sigma` is half the
/// stroke width in pixels. Only pixels within 3σ of the stroke change.
pub fn comb(field: &mut DirectionGrid, stroke: &[StrokeSample], sigma: f64) {
    if stroke.is_empty() || sigma.is_nan() || sigma <= 0.0 {
        return;
    }
    let (w, h) = (field.width(), field.height());
    let reach = 3.0 * sigma;
    let (mut x0, mut y0, mut x1, mut y1) = (f64::MAX, f64::MAX, f64::MIN, f64::MIN);
    for s in stroke {
        x0 = x0.min(s.at.x - reach);
        y0 = y0.min(s.at.y - reach);
        x1 = x1.max(s.at.x + reach);
        y1 = y1.max(s.at.y + reach);
    }
    let cx = |v: f64, n: usize| v.clamp(0.0, n as f64) as usize;
    let (x0, x1, y0, y1) = (cx(x0, w), cx(x1.ceil(), w), cx(y0, h), cx(y1.ceil(), h));
    if x0 >= x1 || y0 >= y1 {
        return;
    }
    let norm = 1.0 / ((2.0 * std::f64::consts::PI).sqrt() * sigma);
    let inv2s2 = 1.0 / (2.0 * sigma * sigma);
    let rows: Vec<(usize, Vec<[f32; 2]>)> = (y0..y1)
        .into_par_iter()
        .map(|y| {
            let row = (x0..x1)
                .map(|x| {
                    let p = Point::new(x as f64 + 0.5, y as f64 + 0.5);
                    let (mut sum, mut wk) = (Vec2::ZERO, 0.0);
                    for s in stroke {
                        let d2 = (p - s.at).hypot2();
                        if d2 > reach * reach {
                            continue;
                        }
                        let g = (-d2 * inv2s2).exp() * s.len;
                        sum += s.dir * g;
                        wk += g;
                    }
                    let prev = field.get(x, y);
                    if wk <= 0.0 {
                        return prev;
                    }
                    let dk = sum / wk;
                    let ws = (wk * norm).clamp(0.0, 1.0);
                    let prev = Vec2::new(prev[0] as f64, prev[1] as f64);
                    let mixed = dk * ws + prev * (1.0 - ws);
                    let m = mixed.hypot();
                    if m > 1e-9 {
                        [(mixed.x / m) as f32, (mixed.y / m) as f32]
                    } else {
                        [dk.x as f32, dk.y as f32]
                    }
                })
                .collect();
            (y, row)
        })
        .collect();
    for (y, row) in rows {
        for (i, v) in row.into_iter().enumerate() {
            field.set(x0 + i, y, v);
        }
    }
}

/// Box mean of radius `r` (window 2r+1), horizontally then vertically,
/// zero beyond the borders (the normalized convolution divides it out).
fn box_blur(g: &Grid<f32>, r: usize) -> Grid<f32> {
    let (w, h) = (g.width(), g.height());
    let pass = |src: &Grid<f32>, horizontal: bool| -> Grid<f32> {
        let (n, m) = if horizontal { (w, h) } else { (h, w) };
        let lines: Vec<Vec<f32>> = (0..m)
            .into_par_iter()
            .map(|j| {
                let at = |i: usize| {
                    if horizontal {
                        src.get(i, j)
                    } else {
                        src.get(j, i)
                    }
                };
                let mut prefix = vec![0.0f64; n + 1];
                for i in 0..n {
                    prefix[i + 1] = prefix[i] + at(i) as f64;
                }
                let k = (2 * r + 1) as f64;
                (0..n)
                    .map(|i| {
                        let lo = i.saturating_sub(r);
                        let hi = (i + r + 1).min(n);
                        ((prefix[hi] - prefix[lo]) / k) as f32
                    })
                    .collect()
            })
            .collect();
        let mut out = Grid::new(w, h, 0.0);
        for (j, line) in lines.into_iter().enumerate() {
            for (i, v) in line.into_iter().enumerate() {
                if horizontal {
                    out.set(i, j, v);
                } else {
                    out.set(j, i, v);
                }
            }
        }
        out
    };
    pass(&pass(g, true), false)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_circle_boundary_flows_around_the_centre() {
        let (c, r) = (Point::new(40.0, 40.0), 30.0);
        let pts: Vec<Point> = (0..=200)
            .map(|i| {
                let a = i as f64 / 200.0 * std::f64::consts::TAU;
                c + Vec2::new(a.cos(), a.sin()) * r
            })
            .collect();
        let f = boundary_field(80, 80, &sample_polyline(&pts, 0.5), 6.0);
        // Half way in, the flow is tangent to the circle, same turn sense.
        for k in 0..8 {
            let a = k as f64 / 8.0 * std::f64::consts::TAU;
            let p = c + Vec2::new(a.cos(), a.sin()) * 20.0;
            let d = f.get(p.x as usize, p.y as usize);
            let t = Vec2::new(-a.sin(), a.cos());
            assert!(d[0] as f64 * t.x + d[1] as f64 * t.y > 0.95, "{k}: {d:?}");
        }
    }

    /// A rectangle drawn exactly on the canvas edges: the right and bottom
    /// sides lie on x = width and y = height and still steer the field
    /// next to them.
    #[test]
    fn an_outline_on_the_far_canvas_edges_counts() {
        let (w, h) = (40usize, 30usize);
        let pts = [
            Point::new(0.0, 0.0),
            Point::new(w as f64, 0.0),
            Point::new(w as f64, h as f64),
            Point::new(0.0, h as f64),
            Point::new(0.0, 0.0),
        ];
        let f = boundary_field(w, h, &sample_polyline(&pts, 0.5), 3.0);
        // Next to the right side the flow runs down it (+y), next to the
        // bottom one along it (−x), as the outline does.
        let right = f.get(w - 1, h / 2);
        assert!(right[1] > 0.9, "right edge {right:?}");
        let bottom = f.get(w / 2, h - 1);
        assert!(bottom[0] < -0.9, "bottom edge {bottom:?}");
    }

    #[test]
    fn combing_is_local_and_follows_the_stroke() {
        let mut f = constant_field(60, 60, [1.0, 0.0]);
        let stroke = sample_polyline(&[Point::new(30.0, 5.0), Point::new(30.0, 55.0)], 0.5);
        comb(&mut f, &stroke, 4.0);
        // On the stroke: its direction (down); far away: unchanged.
        let on = f.get(30, 30);
        assert!(on[1] > 0.99, "{on:?}");
        assert_eq!(f.get(5, 30), [1.0, 0.0]);
        // Half-way through the footprint: a mix of both, still unit length.
        let mid = f.get(34, 30);
        assert!(mid[0] > 0.1 && mid[1] > 0.1, "{mid:?}");
        assert!((mid[0].hypot(mid[1]) - 1.0).abs() < 1e-4);
    }
}
