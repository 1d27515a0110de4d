//! Exact Euclidean distance transform (Felzenszwalb & Huttenlocher 2012,
//! "Distance Transforms of Sampled Functions").
//!
//! The squared distance to the nearest seed is the lower envelope of
//! parabolas `(q - p)² + f(p)` rooted at the seeds; one pass per column and
//! one per row computes it exactly in linear time.

use super::Grid;
use rayon::prelude::*;

/// Stand-in for "no seed": larger than any squared distance on a legal grid.
pub const FAR: f32 = 1e20;

/// 1-D squared distance transform of `f` (values ≥ [`FAR`] are "no seed")
/// into `out`; `v` and `z` are scratch buffers of length `n` and `n + 1`.
fn dt_1d(f: &[f32], out: &mut [f32], v: &mut [usize], z: &mut [f32]) {
    let n = f.len();
    let mut k: isize = -1;
    for q in 0..n {
        if f[q] >= FAR {
            continue;
        }
        let fq = f[q] + (q * q) as f32;
        loop {
            if k < 0 {
                k = 0;
                v[0] = q;
                z[0] = f32::NEG_INFINITY;
                z[1] = f32::INFINITY;
                break;
            }
            let p = v[k as usize];
            // Intersection of the parabolas rooted at p and q.
            let s = (fq - (f[p] + (p * p) as f32)) / (2.0 * (q as f32 - p as f32));
            if s <= z[k as usize] {
                k -= 1;
                continue;
            }
            k += 1;
            v[k as usize] = q;
            z[k as usize] = s;
            z[k as usize + 1] = f32::INFINITY;
            break;
        }
    }
    if k < 0 {
        out.iter_mut().for_each(|o| *o = FAR);
        return;
    }
    let mut j = 0usize;
    for (q, o) in out.iter_mut().enumerate() {
        while z[j + 1] < q as f32 {
            j += 1;
        }
        let p = v[j];
        let d = q as f32 - p as f32;
        *o = d * d + f[p];
    }
}

/// Squared Euclidean distance (in pixels²) from every sample to the nearest
/// sample where `seed` is true; [`FAR`] everywhere when there is no seed.
pub fn squared_edt(seed: &Grid<bool>) -> Grid<f32> {
    let (w, h) = (seed.width(), seed.height());
    // Columns (transposed into rows for cache-friendly parallel passes):
    // on a binary image the lower envelope of parabolas is the squared
    // distance to the nearest seed above or below, found by one sweep
    // each way (the same whole numbers `dt_1d` gives, exact in f32 below
    // 2²⁴).
    let mut cols = vec![FAR; w * h];
    cols.par_chunks_mut(h.max(1))
        .enumerate()
        .for_each(|(x, col)| {
            let mut last: Option<usize> = None;
            for (y, c) in col.iter_mut().enumerate() {
                if seed.get(x, y) {
                    last = Some(y);
                }
                if let Some(p) = last {
                    let d = y as f32 - p as f32;
                    *c = d * d;
                }
            }
            last = None;
            for (y, c) in col.iter_mut().enumerate().rev() {
                if seed.get(x, y) {
                    last = Some(y);
                }
                if let Some(p) = last {
                    let d = p as f32 - y as f32;
                    *c = c.min(d * d);
                }
            }
        });
    let mut out = vec![FAR; w * h];
    out.par_chunks_mut(w).enumerate().for_each_init(
        || (vec![0.0f32; w], vec![0usize; w], vec![0.0f32; w + 1]),
        |(f, v, z), (y, row)| {
            for x in 0..w {
                f[x] = cols[x * h + y];
            }
            dt_1d(f, row, v, z);
        },
    );
    Grid::from_vec(w, h, out).expect("sizes match by construction")
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    fn brute(seed: &Grid<bool>) -> Grid<f32> {
        Grid::from_fn(seed.width(), seed.height(), |x, y| {
            let mut best = FAR;
            for sy in 0..seed.height() {
                for sx in 0..seed.width() {
                    if seed.get(sx, sy) {
                        let dx = sx as f32 - x as f32;
                        let dy = sy as f32 - y as f32;
                        best = best.min(dx * dx + dy * dy);
                    }
                }
            }
            best
        })
    }

    #[test]
    fn single_seed_is_exact() {
        let mut g = Grid::new(7, 5, false);
        g.set(2, 3, true);
        let d = squared_edt(&g);
        assert_eq!(d.get(6, 0), 16.0 + 9.0);
        assert_eq!(d.get(2, 3), 0.0);
    }

    #[test]
    fn no_seed_is_far() {
        let d = squared_edt(&Grid::new(4, 3, false));
        assert!(d.data().iter().all(|&v| v >= FAR));
    }

    proptest! {
        #[test]
        fn matches_brute_force(w in 1usize..14, h in 1usize..14, bits in proptest::collection::vec(0u8..10, 196)) {
            let g = Grid::from_fn(w, h, |x, y| bits[(y * 14 + x) % bits.len()] == 0);
            let fast = squared_edt(&g);
            let slow = brute(&g);
            for (a, b) in fast.data().iter().zip(slow.data()) {
                if *b >= FAR { prop_assert!(*a >= FAR); } else { prop_assert_eq!(a, b); }
            }
        }
    }
}
