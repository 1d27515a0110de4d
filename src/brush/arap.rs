//! As-rigid-as-possible deformation of an exemplar segment onto the query
//! spine (decobrush.txt §5.2), by the two-step method of Igarashi, Moscovich
//! and Hughes 2005, "As-Rigid-As-Possible Shape Manipulation".
//!
//! The segment is a triangle mesh built from its ribs ([`RibMesh`]): spine
//! samples plus left and right outline samples. Spine vertices are pinned to
//! the query's samples, all others are free:
//! 1. **Similarity step.** Each vertex of a triangle is written in the frame
//!    of the opposite edge, `v_i = v_j + x (v_k − v_j) + y R90 (v_k − v_j)`;
//!    the energy Σ |v_i' − (v_j' + x (v_k' − v_j') + y R90 (v_k' − v_j'))|²
//!    is zero exactly for similarity transforms. Its minimum with the pins
//!    fixed solves `G00 u = −G01 q` (Igarashi §4.1).
//! 2. **Scale adjustment.** Each triangle is fitted, as a similarity of its
//!    rest shape, to its step-1 image (a 4×4 least-squares problem per
//!    triangle) and scaled back to rest size (§4.2.1); then the vertices
//!    minimise Σ |(v_i'' − v_j'') − (v_i^f − v_j^f)|² over the triangle edges,
//!    x and y separately, `H00 u = b − H01 q` (§4.2.2).
//!
//! `G00`, `H00` and the per-triangle fits depend only on the rest mesh and
//! which vertices are pinned, so [`Arap::new`] factorizes them once (dense
//! Cholesky, nalgebra) and every [`Arap::solve`] with new pin positions is
//! back-substitution only.
//!
//! [`rasterize_coords`] maps the deformed mesh back to exemplar coordinates
//! per canvas pixel (barycentric interpolation of rest positions): the
//! coordinate field μ of §5.3–5.4 at the coarsest level.

use crate::error::{Error, Result};
use crate::raster::Grid;
use kurbo::{Affine, Point, Vec2};
use nalgebra::{Cholesky, DMatrix, DVector, Dyn, Matrix2, Matrix4, Matrix4x6, Matrix6x4};

/// Smallest triangle area, relative to its longest edge squared, that a
/// rib mesh accepts (smaller is treated as degenerate).
const MIN_SHAPE: f64 = 1e-6;

/// A triangle mesh over an exemplar segment's ribs, in rest (exemplar)
/// coordinates.
#[derive(Clone, Debug, PartialEq)]
pub struct RibMesh {
    /// Rest positions of the vertices, exemplar units.
    pub rest: Vec<Point>,
    /// Triangles as vertex index triples.
    pub triangles: Vec<[usize; 3]>,
    /// The vertex of each rib's spine sample, in rib order.
    pub spine: Vec<usize>,
    /// Vertices per rib (2 × divisions + 1), left outline first.
    pub per_rib: usize,
}

impl RibMesh {
    /// The mesh of ribs `spine[i]`, `left[i]`, `right[i]` (exemplar units):
    /// each half-rib is split into `divisions` equal pieces, and consecutive
    /// ribs are joined by a strip of two triangles per piece. Errors on
    /// fewer than two ribs, unequal lengths, non-finite points or a
    /// degenerate (zero-area) triangle, as from zero width or ribs collinear
    /// with the spine.
    pub fn from_ribs(
        spine: &[Point],
        left: &[Point],
        right: &[Point],
        divisions: usize,
    ) -> Result<Self> {
        let bad = |r: String| Err(Error::degenerate("ARAP rib mesh", r));
        let n = spine.len();
        if n < 2 || left.len() != n || right.len() != n {
            return bad(format!(
                "needs at least two ribs of spine, left and right points (got {}, {}, {})",
                n,
                left.len(),
                right.len()
            ));
        }
        if divisions == 0 {
            return bad("divisions must be at least 1".into());
        }
        let all = spine.iter().chain(left).chain(right);
        if !all.clone().all(|p| p.x.is_finite() && p.y.is_finite()) {
            return bad("a rib point is not finite".into());
        }
        let per_rib = 2 * divisions + 1;
        let mut rest = Vec::with_capacity(n * per_rib);
        for i in 0..n {
            for k in (1..=divisions).rev() {
                rest.push(spine[i].lerp(left[i], k as f64 / divisions as f64));
            }
            rest.push(spine[i]);
            for k in 1..=divisions {
                rest.push(spine[i].lerp(right[i], k as f64 / divisions as f64));
            }
        }
        let mut triangles = Vec::with_capacity((n - 1) * 2 * (per_rib - 1));
        for i in 0..n - 1 {
            for j in 0..per_rib - 1 {
                let a = i * per_rib + j;
                let b = a + 1;
                let c = b + per_rib;
                let d = a + per_rib;
                triangles.push([a, b, c]);
                triangles.push([a, c, d]);
            }
        }
        for (t, tri) in triangles.iter().enumerate() {
            let [p0, p1, p2] = tri.map(|v| rest[v]);
            let area2 = (p1 - p0).cross(p2 - p0).abs();
            let longest = (p1 - p0)
                .hypot2()
                .max((p2 - p1).hypot2())
                .max((p0 - p2).hypot2());
            if area2.is_nan() || area2 <= MIN_SHAPE * longest {
                return bad(format!(
                    "triangle {t} between ribs {} and {} has no area (zero width or collinear ribs)",
                    t / (2 * (per_rib - 1)),
                    t / (2 * (per_rib - 1)) + 1
                ));
            }
        }
        let spine = (0..n).map(|i| i * per_rib + divisions).collect();
        Ok(RibMesh {
            rest,
            triangles,
            spine,
            per_rib,
        })
    }
}

/// 90° rotation used by the triangle-local frames.
fn rot(v: Vec2) -> Vec2 {
    Vec2::new(v.y, -v.x)
}

/// The local coordinates (x, y) of `p` in the frame of edge `a → b`:
/// `p = a + x (b − a) + y R90 (b − a)`.
fn local(p: Point, a: Point, b: Point) -> (f64, f64) {
    let d = b - a;
    let l2 = d.hypot2();
    let v = p - a;
    (v.dot(d) / l2, v.dot(rot(d)) / l2)
}

/// A prepared ARAP deformation: the factorizations of both steps for one
/// mesh and one set of pinned vertices.
pub struct Arap {
    rest: Vec<Point>,
    triangles: Vec<[usize; 3]>,
    /// Per vertex: `Ok(free index)` or `Err(pin index)`.
    slot: Vec<std::result::Result<usize, usize>>,
    n_free: usize,
    n_pins: usize,
    g_chol: Cholesky<f64, Dyn>,
    g01: DMatrix<f64>,
    h_chol: Cholesky<f64, Dyn>,
    h01: DMatrix<f64>,
    /// Per triangle: the least-squares fit `(MᵀM)⁻¹Mᵀ` (4×6) and the local
    /// coordinates of vertex 2 in the frame of edge 0 → 1.
    fits: Vec<(Matrix4x6<f64>, (f64, f64))>,
}

impl Arap {
    /// Factorizes both ARAP steps for `mesh` with the vertices `pinned`
    /// fixed (Igarashi et al. 2005 §4). Needs at least two distinct pinned
    /// vertices, and every free vertex connected to them.
    pub fn new(mesh: &RibMesh, pinned: &[usize]) -> Result<Self> {
        let bad = |r: String| Err(Error::degenerate("ARAP deformation", r));
        let nv = mesh.rest.len();
        let mut slot = vec![Ok(usize::MAX); nv];
        for (k, &v) in pinned.iter().enumerate() {
            match slot.get_mut(v) {
                Some(s @ Ok(_)) => *s = Err(k),
                Some(Err(_)) => return bad(format!("vertex {v} is pinned twice")),
                None => return bad(format!("pinned vertex {v} is not in the mesh")),
            }
        }
        if pinned.len() < 2 {
            return bad("needs at least two pinned vertices".into());
        }
        let mut n_free = 0;
        for i in slot.iter_mut().flatten() {
            *i = n_free;
            n_free += 1;
        }
        let n_pins = pinned.len();
        if mesh.triangles.iter().flatten().any(|&v| v >= nv) {
            return bad("a triangle names a missing vertex".into());
        }
        // Step 1: G over interleaved (x, y) coordinates, split free/pinned.
        let mut g00 = DMatrix::zeros(2 * n_free, 2 * n_free);
        let mut g01 = DMatrix::zeros(2 * n_free, 2 * n_pins);
        let r90 = Matrix2::new(0.0, 1.0, -1.0, 0.0);
        let id = Matrix2::identity();
        for tri in &mesh.triangles {
            for c in 0..3 {
                let (i, j, k) = (tri[c], tri[(c + 1) % 3], tri[(c + 2) % 3]);
                let (x, y) = local(mesh.rest[i], mesh.rest[j], mesh.rest[k]);
                // Residual v_i − (1 − x) v_j − x v_k − y R (v_k − v_j).
                let blocks = [
                    (i, id),
                    (j, -(1.0 - x) * id + y * r90),
                    (k, -x * id - y * r90),
                ];
                for (va, ba) in &blocks {
                    for (vb, bb) in &blocks {
                        let m = ba.transpose() * bb;
                        let Ok(a) = slot[*va] else { continue };
                        match slot[*vb] {
                            Ok(b) => add_block(&mut g00, 2 * a, 2 * b, &m),
                            Err(b) => add_block(&mut g01, 2 * a, 2 * b, &m),
                        }
                    }
                }
            }
        }
        // Step 2b: edge Laplacian H (x and y alike), split free/pinned.
        let mut h00 = DMatrix::zeros(n_free, n_free);
        let mut h01 = DMatrix::zeros(n_free, n_pins);
        for tri in &mesh.triangles {
            for c in 0..3 {
                let (i, j) = (tri[c], tri[(c + 1) % 3]);
                for (a, b, s) in [(i, i, 1.0), (j, j, 1.0), (i, j, -1.0), (j, i, -1.0)] {
                    let Ok(fa) = slot[a] else { continue };
                    match slot[b] {
                        Ok(fb) => h00[(fa, fb)] += s,
                        Err(pb) => h01[(fa, pb)] += s,
                    }
                }
            }
        }
        // Step 2a: per-triangle similarity fits.
        let mut fits = Vec::with_capacity(mesh.triangles.len());
        for tri in &mesh.triangles {
            let [p0, p1, p2] = tri.map(|v| mesh.rest[v]);
            let (x, y) = local(p2, p0, p1);
            let m = fit_matrix(x, y);
            let mtm: Matrix4<f64> = m.transpose() * m;
            let Some(inv) = mtm.try_inverse() else {
                return bad("a triangle cannot be fitted".into());
            };
            fits.push((inv * m.transpose(), (x, y)));
        }
        let unconnected = || {
            Error::degenerate(
                "ARAP deformation",
                "the system is singular: some free vertices are not connected to the pins",
            )
        };
        let g_chol = Cholesky::new(g00).ok_or_else(unconnected)?;
        let h_chol = Cholesky::new(h00).ok_or_else(unconnected)?;
        Ok(Arap {
            rest: mesh.rest.clone(),
            triangles: mesh.triangles.clone(),
            slot,
            n_free,
            n_pins,
            g_chol,
            g01,
            h_chol,
            h01,
            fits,
        })
    }

    /// Step 1 only: the similarity-step positions of every vertex for the
    /// pins at `pins` (one per pinned vertex, in the order given to
    /// [`Arap::new`]).
    pub fn solve_similarity(&self, pins: &[Point]) -> Result<Vec<Point>> {
        self.check_pins(pins)?;
        let mut q = DVector::zeros(2 * self.n_pins);
        for (k, p) in pins.iter().enumerate() {
            q[2 * k] = p.x;
            q[2 * k + 1] = p.y;
        }
        let rhs = -(&self.g01 * q);
        let u = self.g_chol.solve(&rhs);
        Ok(self.assemble(pins, |f| Point::new(u[2 * f], u[2 * f + 1])))
    }

    /// Both steps: the deformed position of every vertex for the pins at
    /// `pins` (one per pinned vertex, in the order given to [`Arap::new`]).
    pub fn solve(&self, pins: &[Point]) -> Result<Vec<Point>> {
        let sim = self.solve_similarity(pins)?;
        // Step 2a: fit each triangle as a similarity of its rest shape,
        // then scale it back to rest size about its centroid.
        let mut bx = DVector::zeros(self.n_free);
        let mut by = DVector::zeros(self.n_free);
        for (tri, (fit, (x, y))) in self.triangles.iter().zip(&self.fits) {
            let v = tri.map(|i| sim[i]);
            let vin = nalgebra::Vector6::new(v[0].x, v[0].y, v[1].x, v[1].y, v[2].x, v[2].y);
            let w = fit * vin;
            let f0 = Point::new(w[0], w[1]);
            let f1 = Point::new(w[2], w[3]);
            let f2 = f0 + (f1 - f0) * *x + rot(f1 - f0) * *y;
            let rest_len = (self.rest[tri[1]] - self.rest[tri[0]]).hypot();
            let fit_len = (f1 - f0).hypot();
            let scale = if fit_len > 0.0 {
                rest_len / fit_len
            } else {
                1.0
            };
            let c = Point::new((f0.x + f1.x + f2.x) / 3.0, (f0.y + f1.y + f2.y) / 3.0);
            let fitted = [f0, f1, f2].map(|p| c + (p - c) * scale);
            // Step 2b right-hand side: edge vectors of the fitted triangle.
            for k in 0..3 {
                let (i, j) = (tri[k], tri[(k + 1) % 3]);
                let t = fitted[k] - fitted[(k + 1) % 3];
                if let Ok(fi) = self.slot[i] {
                    bx[fi] += t.x;
                    by[fi] += t.y;
                }
                if let Ok(fj) = self.slot[j] {
                    bx[fj] -= t.x;
                    by[fj] -= t.y;
                }
            }
        }
        let qx = DVector::from_iterator(self.n_pins, pins.iter().map(|p| p.x));
        let qy = DVector::from_iterator(self.n_pins, pins.iter().map(|p| p.y));
        let ux = self.h_chol.solve(&(bx - &self.h01 * qx));
        let uy = self.h_chol.solve(&(by - &self.h01 * qy));
        Ok(self.assemble(pins, |f| Point::new(ux[f], uy[f])))
    }

    fn check_pins(&self, pins: &[Point]) -> Result<()> {
        if pins.len() != self.n_pins {
            return Err(Error::degenerate(
                "ARAP deformation",
                format!("{} pin positions for {} pins", pins.len(), self.n_pins),
            ));
        }
        if !pins.iter().all(|p| p.x.is_finite() && p.y.is_finite()) {
            return Err(Error::degenerate(
                "ARAP deformation",
                "a pin position is not finite",
            ));
        }
        Ok(())
    }

    fn assemble(&self, pins: &[Point], free: impl Fn(usize) -> Point) -> Vec<Point> {
        self.slot
            .iter()
            .map(|s| match *s {
                Ok(f) => free(f),
                Err(k) => pins[k],
            })
            .collect()
    }
}

/// Adds the 2×2 block `m` at (`r`, `c`).
fn add_block(g: &mut DMatrix<f64>, r: usize, c: usize, m: &Matrix2<f64>) {
    for a in 0..2 {
        for b in 0..2 {
            g[(r + a, c + b)] += m[(a, b)];
        }
    }
}

/// The 6×4 matrix giving a triangle's three vertices from its first two,
/// with vertex 2 at local coordinates (x, y) of edge 0 → 1.
fn fit_matrix(x: f64, y: f64) -> Matrix6x4<f64> {
    // v2 = (1 − x) v0 + x v1 + y R (v1 − v0), R (a, b) = (b, −a).
    Matrix6x4::new(
        1.0,
        0.0,
        0.0,
        0.0,
        0.0,
        1.0,
        0.0,
        0.0,
        0.0,
        0.0,
        1.0,
        0.0,
        0.0,
        0.0,
        0.0,
        1.0,
        1.0 - x,
        -y,
        x,
        y,
        y,
        1.0 - x,
        -y,
        x,
    )
}

/// The singular values (σ1 ≥ σ2) of the deformation gradient of triangle
/// `tri` from `rest` to `deformed` positions (`(∞, 0)` for a degenerate
/// or out-of-range triangle).
#[cfg(test)]
pub fn triangle_stretches(rest: &[Point], deformed: &[Point], tri: [usize; 3]) -> (f64, f64) {
    let (Some(a), Some(b), Some(c), Some(p), Some(q), Some(r)) = (
        rest.get(tri[0]),
        rest.get(tri[1]),
        rest.get(tri[2]),
        deformed.get(tri[0]),
        deformed.get(tri[1]),
        deformed.get(tri[2]),
    ) else {
        return (f64::INFINITY, 0.0);
    };
    let d = Matrix2::new(b.x - a.x, c.x - a.x, b.y - a.y, c.y - a.y);
    let e = Matrix2::new(q.x - p.x, r.x - p.x, q.y - p.y, r.y - p.y);
    let Some(dinv) = d.try_inverse() else {
        return (f64::INFINITY, 0.0);
    };
    let f = e * dinv;
    // Closed-form 2×2 singular values.
    let (p1, q1) = ((f[(0, 0)] + f[(1, 1)]) / 2.0, (f[(1, 0)] - f[(0, 1)]) / 2.0);
    let (r1, t1) = ((f[(0, 0)] - f[(1, 1)]) / 2.0, (f[(1, 0)] + f[(0, 1)]) / 2.0);
    let (s, t) = (p1.hypot(q1), r1.hypot(t1));
    (s + t, (s - t).abs())
}

/// Mean over triangles of |σ1 − 1| + |σ2 − 1|, the distortion of `deformed`
/// relative to the rest mesh (0 for a rigid motion).
#[cfg(test)]
pub fn mean_distortion(mesh: &RibMesh, deformed: &[Point]) -> f64 {
    if mesh.triangles.is_empty() || deformed.len() != mesh.rest.len() {
        return f64::INFINITY;
    }
    let total: f64 = mesh
        .triangles
        .iter()
        .map(|&t| {
            let (s1, s2) = triangle_stretches(&mesh.rest, deformed, t);
            (s1 - 1.0).abs() + (s2 - 1.0).abs()
        })
        .sum();
    total / mesh.triangles.len() as f64
}

/// The exemplar coordinates of every pixel centre covered by the deformed
/// mesh: pixel `(x, y)` (centre `(x + 0.5, y + 0.5)`) inside deformed
/// triangle T gets the barycentric interpolation of T's rest positions, in
/// exemplar units; pixels outside the mesh are `None`. `to_pixel` maps
/// deformed (canvas) positions to pixel coordinates. Where triangles
/// overlap (a fold), the first in mesh order wins. Each triangle walks only
/// the pixels of its bounding box clipped to the grid.
pub fn rasterize_coords(
    mesh: &RibMesh,
    deformed: &[Point],
    width: usize,
    height: usize,
    to_pixel: Affine,
) -> Result<Grid<Option<Point>>> {
    if deformed.len() != mesh.rest.len() {
        return Err(Error::degenerate(
            "coordinate rasterization",
            format!(
                "{} deformed positions for {} vertices",
                deformed.len(),
                mesh.rest.len()
            ),
        ));
    }
    crate::io::check_canvas(width as u64, height as u64).map_err(|e| e.in_part("brush canvas"))?;
    let mut grid = Grid::new(width, height, None);
    for tri in &mesh.triangles {
        let [Some(p0), Some(p1), Some(p2)] = tri.map(|v| deformed.get(v).map(|p| to_pixel * *p))
        else {
            continue;
        };
        let [Some(r0), Some(r1), Some(r2)] = tri.map(|v| mesh.rest.get(v).copied()) else {
            continue;
        };
        let area = (p1 - p0).cross(p2 - p0);
        if area.is_nan() || area.abs() <= 1e-12 {
            continue;
        }
        let lo_x = p0.x.min(p1.x).min(p2.x) - 0.5;
        let hi_x = p0.x.max(p1.x).max(p2.x) - 0.5;
        let lo_y = p0.y.min(p1.y).min(p2.y) - 0.5;
        let hi_y = p0.y.max(p1.y).max(p2.y) - 0.5;
        if !(hi_x >= 0.0 && hi_y >= 0.0 && lo_x < width as f64 && lo_y < height as f64) {
            continue;
        }
        let x0 = lo_x.ceil().max(0.0) as usize;
        let y0 = lo_y.ceil().max(0.0) as usize;
        let x1 = (hi_x.floor() as usize).min(width.saturating_sub(1));
        let y1 = (hi_y.floor() as usize).min(height.saturating_sub(1));
        for y in y0..=y1 {
            for x in x0..=x1 {
                if grid.get(x, y).is_some() {
                    continue;
                }
                let c = Point::new(x as f64 + 0.5, y as f64 + 0.5);
                let l0 = (p1 - c).cross(p2 - c) / area;
                let l1 = (p2 - c).cross(p0 - c) / area;
                let l2 = 1.0 - l0 - l1;
                let eps = -1e-9;
                if l0 >= eps && l1 >= eps && l2 >= eps {
                    let v = r0.to_vec2() * l0 + r1.to_vec2() * l1 + r2.to_vec2() * l2;
                    grid.set(x, y, Some(v.to_point()));
                }
            }
        }
    }
    Ok(grid)
}

#[cfg(test)]
#[path = "arap_tests.rs"]
mod tests;
