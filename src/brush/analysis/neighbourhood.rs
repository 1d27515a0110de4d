//! Oriented 5×5 neighbourhoods, their PCA reduction and a k-d tree over
//! them (DecoBrush §4.3, §5.4.2).
//!
//! A neighbourhood is 25 samples of a field (an exemplar's SDF or
//! coverage) on a 5×5 lattice of 1 px spacing centred on a pixel and
//! rotated so that its up axis runs along the stroking orientation `ω`:
//! sample `(r, c)` (row `r` top to bottom, column `c` left to right, both
//! 0..5) sits at `p + (c − 2) ρ + (2 − r) ω`, with `ρ = (−ω_y, ω_x)` the
//! neighbourhood's right (pixel axes, y down). Rotating the image and the
//! orientation together leaves the neighbourhood unchanged, which is what
//! lets the synthesis compare a bent query with a straight exemplar.
//!
//! SDF values are clamped to ±[`NeighbourhoodSampler::clamp`] px and
//! divided by it, so distant ink does not dominate the L² distance.
//!
//! For search, neighbourhoods are projected on their first [`PCA_DIMS`]
//! principal components (covariance from a deterministic subsample,
//! eigenvectors by nalgebra) and indexed by a kiddo k-d tree; the tree is
//! built on first use, from the stored projections.

use crate::raster::Grid;
use kiddo::{ImmutableKdTree, SquaredEuclidean};
use serde::{Deserialize, Serialize};
use std::sync::OnceLock;

/// Side of a neighbourhood, in samples.
pub const SIDE: usize = 5;
/// Samples per neighbourhood.
pub const SIZE: usize = SIDE * SIDE;
/// Dimensions kept by the PCA.
pub const PCA_DIMS: usize = 8;
/// Largest number of neighbourhoods the covariance is estimated from.
pub const PCA_SUBSAMPLE: usize = 20_000;

/// One neighbourhood's samples, row-major (see the module docs).
pub type Neighbourhood = [f32; SIZE];

/// How neighbourhoods are read from a field.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct NeighbourhoodSampler {
    /// Fields are signed distances (px). `true`: they are read clamped to
    /// ±`clamp` and divided by it; `false`: they are read as coverage,
    /// `clamp(0.5 − d, 0, 1)` (styles with `sdf = false`).
    pub sdf: bool,
    /// Clamp of signed distances, px. Default 4.
    pub clamp: f32,
}

impl Default for NeighbourhoodSampler {
    fn default() -> Self {
        NeighbourhoodSampler {
            sdf: true,
            clamp: 4.0,
        }
    }
}

impl NeighbourhoodSampler {
    /// The value stored for a field sample `v`.
    #[inline]
    pub fn value(&self, v: f32) -> f32 {
        if self.sdf {
            v.clamp(-self.clamp, self.clamp) / self.clamp
        } else {
            (0.5 - v).clamp(0.0, 1.0)
        }
    }

    /// The neighbourhood of `field` (bilinear, borders clamped) centred at
    /// the pixel-space point `p` with up axis `up` (a unit vector, pixel
    /// axes; `[0, 0]` is read as screen up, `[0, −1]`).
    pub fn sample(&self, field: &Grid<f32>, p: [f64; 2], up: [f32; 2]) -> Neighbourhood {
        let (ux, uy) = if up == [0.0, 0.0] {
            (0.0, -1.0)
        } else {
            (up[0] as f64, up[1] as f64)
        };
        let (rx, ry) = (-uy, ux);
        let mut out = [0.0; SIZE];
        for r in 0..SIDE {
            let a = 2.0 - r as f64;
            for c in 0..SIDE {
                let b = c as f64 - 2.0;
                let x = p[0] + b * rx + a * ux;
                let y = p[1] + b * ry + a * uy;
                out[r * SIDE + c] = self.value(field.sample(x, y));
            }
        }
        out
    }
}

/// Where an indexed neighbourhood comes from: exemplar index and pixel.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub struct NeighbourhoodRef {
    /// Index of the exemplar in its style.
    pub exemplar: u32,
    /// Pixel column at the index's level.
    pub x: u32,
    /// Pixel row at the index's level.
    pub y: u32,
}

impl crate::raster::plain::Plain for NeighbourhoodRef {
    const BYTES: usize = 12;
    fn put(self, out: &mut Vec<u8>) {
        [self.exemplar, self.x, self.y].put(out);
    }
    fn get(b: &[u8]) -> Self {
        let [exemplar, x, y] = <[u32; 3]>::get(b);
        NeighbourhoodRef { exemplar, x, y }
    }
}

/// A PCA basis: `y = B (v − μ)` keeps the first [`PCA_DIMS`] components.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Pca {
    /// The mean neighbourhood `μ`.
    #[serde(with = "crate::raster::plain::vec")]
    pub mean: Vec<f32>,
    /// The principal axes, strongest first, each [`SIZE`] long (unit).
    #[serde(with = "crate::raster::plain::vec")]
    pub axes: Vec<[f32; SIZE]>,
    /// Variance along each axis (eigenvalues), strongest first.
    pub variances: Vec<f32>,
}

impl Pca {
    /// The PCA of `data`, covariance from at most [`PCA_SUBSAMPLE`] of them
    /// taken at an even stride (deterministic). Signs of the axes are fixed
    /// so their largest component is positive.
    pub fn fit(data: &[Neighbourhood]) -> Pca {
        let stride = data.len().div_ceil(PCA_SUBSAMPLE).max(1);
        let sub: Vec<&Neighbourhood> = data.iter().step_by(stride).collect();
        let n = sub.len().max(1) as f64;
        let mut mean = [0.0f64; SIZE];
        for v in &sub {
            for k in 0..SIZE {
                mean[k] += v[k] as f64 / n;
            }
        }
        let mut cov = nalgebra::DMatrix::<f64>::zeros(SIZE, SIZE);
        for v in &sub {
            let d: Vec<f64> = (0..SIZE).map(|k| v[k] as f64 - mean[k]).collect();
            for i in 0..SIZE {
                for j in i..SIZE {
                    cov[(i, j)] += d[i] * d[j] / n;
                }
            }
        }
        for i in 0..SIZE {
            for j in 0..i {
                cov[(i, j)] = cov[(j, i)];
            }
        }
        let eig = nalgebra::SymmetricEigen::new(cov);
        let mut order: Vec<usize> = (0..SIZE).collect();
        order.sort_by(|&a, &b| {
            eig.eigenvalues[b]
                .total_cmp(&eig.eigenvalues[a])
                .then(a.cmp(&b))
        });
        let mut axes = Vec::with_capacity(PCA_DIMS);
        let mut variances = Vec::with_capacity(PCA_DIMS);
        for &k in order.iter().take(PCA_DIMS) {
            let col = eig.eigenvectors.column(k);
            let mut big = 0;
            for i in 0..SIZE {
                if col[i].abs() > col[big].abs() {
                    big = i;
                }
            }
            let sign = if col[big] < 0.0 { -1.0 } else { 1.0 };
            axes.push(std::array::from_fn(|i| (col[i] * sign) as f32));
            variances.push(eig.eigenvalues[k].max(0.0) as f32);
        }
        Pca {
            mean: mean.iter().map(|&m| m as f32).collect(),
            axes,
            variances,
        }
    }

    /// The projection of `v` on the axes.
    pub fn project(&self, v: &Neighbourhood) -> [f32; PCA_DIMS] {
        let mut out = [0.0; PCA_DIMS];
        for (o, axis) in out.iter_mut().zip(&self.axes) {
            let mut s = 0.0;
            for k in 0..SIZE {
                s += axis[k] * (v[k] - self.mean.get(k).copied().unwrap_or(0.0));
            }
            *o = s;
        }
        out
    }
}

/// The neighbourhoods of one pyramid level of a style, PCA-reduced and
/// searchable.
#[derive(Debug, Serialize, Deserialize)]
pub struct NeighbourhoodIndex {
    /// The reduction.
    pub pca: Pca,
    /// Projected neighbourhoods, parallel to `refs`.
    #[serde(with = "crate::raster::plain::vec")]
    pub points: Vec<[f32; PCA_DIMS]>,
    /// Where each neighbourhood comes from. Not cached: brush styles
    /// rebuild it from their stroke-region masks (row-major order).
    #[serde(skip)]
    pub refs: Vec<NeighbourhoodRef>,
    #[serde(skip)]
    tree: OnceLock<Option<ImmutableKdTree<f32, PCA_DIMS>>>,
}

impl Clone for NeighbourhoodIndex {
    fn clone(&self) -> Self {
        NeighbourhoodIndex::new(self.pca.clone(), self.points.clone(), self.refs.clone())
    }
}

impl NeighbourhoodIndex {
    /// An index over `points` (projections by `pca`) with their origins.
    pub fn new(pca: Pca, points: Vec<[f32; PCA_DIMS]>, refs: Vec<NeighbourhoodRef>) -> Self {
        NeighbourhoodIndex {
            pca,
            points,
            refs,
            tree: OnceLock::new(),
        }
    }

    /// Number of indexed neighbourhoods.
    pub fn len(&self) -> usize {
        self.points.len()
    }

    /// Whether nothing is indexed.
    #[cfg(test)]
    pub fn is_empty(&self) -> bool {
        self.points.is_empty()
    }

    fn tree(&self) -> Option<&ImmutableKdTree<f32, PCA_DIMS>> {
        self.tree
            .get_or_init(|| {
                if self.points.is_empty() || self.points.len() > u32::MAX as usize {
                    None
                } else {
                    ImmutableKdTree::new_from_slice(&self.points).ok()
                }
            })
            .as_ref()
    }

    /// The indexed neighbourhood nearest to `query` in PCA space, with its
    /// squared distance there; `None` when the index is empty.
    pub fn nearest(&self, query: &Neighbourhood) -> Option<(NeighbourhoodRef, f32)> {
        let q = self.pca.project(query);
        let tree = self.tree()?;
        let found = tree
            .query(&q)
            .nearest_one::<SquaredEuclidean<f32>>()
            .execute();
        let r = self.refs.get(found.item as usize)?;
        Some((*r, found.distance))
    }

    /// Like [`NeighbourhoodIndex::nearest`] but the k-d tree's approximate
    /// (descent-only) search: faster, not always the exact nearest.
    pub fn approx_nearest(&self, query: &Neighbourhood) -> Option<(NeighbourhoodRef, f32)> {
        let q = self.pca.project(query);
        let tree = self.tree()?;
        let found = tree
            .query(&q)
            .nearest_one::<SquaredEuclidean<f32>>()
            .approx()
            .execute();
        let r = self.refs.get(found.item as usize)?;
        Some((*r, found.distance))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// An asymmetric analytic field: an L of two bars, rotated by `a`
    /// about `c`, as a signed distance (px).
    fn ell(n: usize, c: [f64; 2], a: f64) -> Grid<f32> {
        let (s, co) = a.sin_cos();
        Grid::from_fn(n, n, |x, y| {
            let (dx, dy) = (x as f64 + 0.5 - c[0], y as f64 + 0.5 - c[1]);
            // Back-rotate into the shape's frame.
            let (u, v) = (co * dx + s * dy, -s * dx + co * dy);
            let bar1 = (u.abs() - 9.0).max(v.abs() - 2.0);
            let bar2 = ((u - 7.0).abs() - 2.0).max((v + 5.0).abs() - 7.0);
            bar1.min(bar2) as f32
        })
    }

    #[test]
    fn rotating_the_image_rotates_its_neighbourhoods_consistently() {
        let s = NeighbourhoodSampler::default();
        let c = [32.0, 32.0];
        let base = ell(64, c, 0.0);
        for a in [0.4f64, 1.3, 2.9, -2.2] {
            let rot = ell(64, c, a);
            let (sn, cs) = a.sin_cos();
            for (p, up) in [
                ([32.0, 30.0], [0.0f64, -1.0]),
                ([38.0, 27.0], [0.6, -0.8]),
                ([27.0, 33.0], [1.0, 0.0]),
            ] {
                let (dx, dy) = (p[0] - c[0], p[1] - c[1]);
                let q = [c[0] + cs * dx - sn * dy, c[1] + sn * dx + cs * dy];
                let rup = [
                    (cs * up[0] - sn * up[1]) as f32,
                    (sn * up[0] + cs * up[1]) as f32,
                ];
                let n0 = s.sample(&base, p, [up[0] as f32, up[1] as f32]);
                let n1 = s.sample(&rot, q, rup);
                for k in 0..SIZE {
                    assert!(
                        (n0[k] - n1[k]).abs() < 0.1,
                        "a={a} k={k}: {} vs {}",
                        n0[k],
                        n1[k]
                    );
                }
                // And an unrotated sampling of the rotated image differs.
                let wrong = s.sample(&rot, q, [up[0] as f32, up[1] as f32]);
                let diff: f32 = (0..SIZE).map(|k| (wrong[k] - n0[k]).abs()).sum();
                assert!(diff > 0.5 || a.abs() < 0.5, "a={a}: {diff}");
            }
        }
    }

    #[test]
    fn neighbourhood_layout_is_up_along_the_orientation() {
        // A field increasing to the right (x): with up = +x, the top row
        // (r = 0) is the largest, the bottom row the smallest.
        let f = Grid::from_fn(20, 20, |x, _| x as f32 * 0.1);
        let s = NeighbourhoodSampler {
            sdf: true,
            clamp: 100.0,
        };
        let n = s.sample(&f, [10.0, 10.0], [1.0, 0.0]);
        assert!(n[0] > n[SIZE - 1]);
        assert!((n[2] - n[22] - 0.004).abs() < 1e-6, "{} {}", n[2], n[22]);
        // Columns run along ρ = (−ω_y, ω_x) = (0, 1): constant in x.
        assert!((n[0] - n[4]).abs() < 1e-6);
    }

    #[test]
    fn index_finds_what_brute_force_finds() {
        // Pseudo-random neighbourhoods; exact search in PCA space equals a
        // brute-force scan over the projections.
        let mut state = 12345u64;
        let mut rnd = || {
            state = state
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            ((state >> 33) as f32 / (1u64 << 31) as f32) - 0.5
        };
        let data: Vec<Neighbourhood> = (0..500)
            .map(|i| {
                let g = (i % 7) as f32 * 0.3;
                std::array::from_fn(|k| g * (k as f32 / 24.0) + 0.1 * rnd())
            })
            .collect();
        let pca = Pca::fit(&data);
        assert_eq!(pca.axes.len(), PCA_DIMS);
        assert!(pca.variances.windows(2).all(|w| w[0] >= w[1]));
        let points: Vec<_> = data.iter().map(|v| pca.project(v)).collect();
        let refs = (0..500)
            .map(|i| NeighbourhoodRef {
                exemplar: 0,
                x: i,
                y: 0,
            })
            .collect();
        let index = NeighbourhoodIndex::new(pca.clone(), points.clone(), refs);
        for i in [0usize, 17, 250, 499] {
            let mut q = data[i];
            q[3] += 0.01;
            let (r, d) = index.nearest(&q).unwrap();
            let pq = pca.project(&q);
            let brute = points
                .iter()
                .map(|p| (0..PCA_DIMS).map(|k| (p[k] - pq[k]).powi(2)).sum::<f32>())
                .fold(f32::INFINITY, f32::min);
            assert!((d - brute).abs() < 1e-5, "{d} vs {brute}");
            let pr = points[r.x as usize];
            let dr: f32 = (0..PCA_DIMS).map(|k| (pr[k] - pq[k]).powi(2)).sum();
            assert!((dr - brute).abs() < 1e-5);
        }
        // Round trip through the cache format keeps it searchable (the
        // refs are restored by the owner).
        let bytes = postcard::to_stdvec(&index).unwrap();
        let mut back: NeighbourhoodIndex = postcard::from_bytes(&bytes).unwrap();
        back.refs = index.refs.clone();
        assert_eq!(back.nearest(&data[17]), index.nearest(&data[17]));
        assert!(NeighbourhoodIndex::new(pca, vec![], vec![])
            .nearest(&data[0])
            .is_none());
    }
}
