//! Graph-cut seams between overlapping warped segments (decobrush.txt §5.3,
//! Eq. 1–2).
//!
//! On the overlap grid every pixel is a node with 4-connected links. Pixel
//! `p` shows intensity `L_p` in segment A and `R_p` in segment B (1 paper,
//! 0 ink). When the seam passes between neighbours `p` (kept from A) and `q`
//! (from B) it pays Eq. 2, `(L_p − R_q)²`, the mismatch of what meets across
//! the seam, plus Eq. 1 averaged over both pixels,
//! `E_c = w_c (2 − L − R) + C`, which makes seams short (`C`) and keeps them
//! off black feature lines (`w_c`); the paper's constants are `C = 0.02`,
//! `w_c = 0.01`. Pixels covered by one segment only are tied to it by
//! infinite terminal links.
//!
//! The least-cost labeling is an s–t minimum cut (A = source side), found
//! exactly with Boykov–Kolmogorov max-flow ([`crate::brush::maxflow`]) on
//! integer capacities (costs quantized to 10⁻⁶, so the cut value and the
//! brute-force minimum agree exactly; tested on every labeling of tiny
//! grids). The paper uses Schmidt et al.'s planar cut; any exact minimum
//! cut gives the same cost.

use crate::brush::maxflow::FlowGraph;
use crate::error::{Error, Result};
use crate::raster::Grid;

/// Which segments cover an overlap-grid pixel.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Cover {
    /// Neither: the pixel is not part of the seam problem.
    None,
    /// Only segment A: the pixel must come from A.
    A,
    /// Only segment B: the pixel must come from B.
    B,
    /// Both: the cut decides.
    Both,
}

/// The segment a pixel is taken from after the cut.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Label {
    /// Not covered by either segment.
    Outside,
    /// From segment A (the source side of the cut).
    A,
    /// From segment B (the sink side).
    B,
}

/// The constants of Eq. 1.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SeamParams {
    /// `C`, the cost per unit of seam length (paper: 0.02).
    pub c: f64,
    /// `w_c`, the weight of ink under the seam (paper: 0.01).
    pub w_c: f64,
}

impl Default for SeamParams {
    fn default() -> Self {
        SeamParams { c: 0.02, w_c: 0.01 }
    }
}

/// A seam: the per-pixel labels and the cost of the cut.
#[derive(Clone, Debug, PartialEq)]
pub struct Seam {
    /// Per overlap-grid pixel, the segment it is taken from.
    pub labels: Grid<Label>,
    /// The cut's cost in Eq. 1–2 units (after quantization to 10⁻⁶).
    pub cost: f64,
}

/// Quantization of the costs: capacities are integers in units of 10⁻⁶.
const SCALE: f64 = 1e6;

/// The cost, quantized, of cutting between `p` (from A) and `q` (from B):
/// Eq. 2 plus Eq. 1 averaged over both ends.
fn link(params: &SeamParams, lp: f64, rp: f64, lq: f64, rq: f64) -> i64 {
    let ec = |l: f64, r: f64| params.w_c * (2.0 - l - r) + params.c;
    let d = lp - rq;
    let w = d * d + 0.5 * (ec(lp, rp) + ec(lq, rq));
    (w * SCALE).round().max(0.0) as i64
}

/// The seam problem of two segments drawn on one canvas: `a` and `b` say
/// which canvas pixels each covers. Returns the crop origin `(x0, y0)` and
/// the [`Cover`] grid over the bounding box of the pixels both cover,
/// widened by `margin` pixels (so the single-covered pixels bordering the
/// overlap tie the cut to its segments), or `None` when they do not
/// overlap or the masks differ in size.
#[cfg(test)]
pub fn overlap_cover(
    a: &Grid<bool>,
    b: &Grid<bool>,
    margin: usize,
) -> Option<(usize, usize, Grid<Cover>)> {
    let (w, h) = (a.width(), a.height());
    if b.width() != w || b.height() != h {
        return None;
    }
    let (mut x0, mut y0, mut x1, mut y1) = (usize::MAX, usize::MAX, 0, 0);
    for y in 0..h {
        for x in 0..w {
            if a.get(x, y) && b.get(x, y) {
                (x0, y0, x1, y1) = (x0.min(x), y0.min(y), x1.max(x), y1.max(y));
            }
        }
    }
    if x0 > x1 {
        return None;
    }
    let (x0, y0) = (x0.saturating_sub(margin), y0.saturating_sub(margin));
    let (x1, y1) = (
        x1.saturating_add(margin).min(w - 1),
        y1.saturating_add(margin).min(h - 1),
    );
    let cover = Grid::from_fn(x1 - x0 + 1, y1 - y0 + 1, |x, y| {
        match (a.get(x + x0, y + y0), b.get(x + x0, y + y0)) {
            (true, true) => Cover::Both,
            (true, false) => Cover::A,
            (false, true) => Cover::B,
            (false, false) => Cover::None,
        }
    });
    Some((x0, y0, cover))
}

/// Finds the least-cost seam between segments A and B on an overlap grid:
/// `a` and `b` are their intensities per pixel (0 ink … 1 paper; use 1
/// where a segment does not cover), `cover` which segments cover each pixel.
pub fn seam(
    a: &Grid<f32>,
    b: &Grid<f32>,
    cover: &Grid<Cover>,
    params: &SeamParams,
) -> Result<Seam> {
    let (w, h) = (cover.width(), cover.height());
    if a.width() != w || a.height() != h || b.width() != w || b.height() != h {
        return Err(Error::degenerate(
            "graph-cut seam",
            format!(
                "grids differ in size: A {}×{}, B {}×{}, cover {w}×{h}",
                a.width(),
                a.height(),
                b.width(),
                b.height()
            ),
        ));
    }
    if !(params.c.is_finite() && params.w_c.is_finite() && params.c >= 0.0 && params.w_c >= 0.0) {
        return Err(Error::degenerate(
            "graph-cut seam",
            "C and w_c must be finite and ≥ 0",
        ));
    }
    let val = |g: &Grid<f32>, i: usize| {
        let v = g.data()[i] as f64;
        if v.is_finite() {
            v.clamp(0.0, 1.0)
        } else {
            1.0
        }
    };
    let n = w * h;
    let (src, snk) = (n, n + 1);
    let mut g = FlowGraph::new(n + 2);
    let mut finite_total: i64 = 0;
    let cov = cover.data();
    for y in 0..h {
        for x in 0..w {
            let p = y * w + x;
            if cov[p] == Cover::None {
                continue;
            }
            for q in [(x + 1 < w).then(|| p + 1), (y + 1 < h).then(|| p + w)]
                .into_iter()
                .flatten()
            {
                if cov[q] == Cover::None {
                    continue;
                }
                let (lp, rp, lq, rq) = (val(a, p), val(b, p), val(a, q), val(b, q));
                let pq = link(params, lp, rp, lq, rq);
                let qp = link(params, lq, rq, lp, rp);
                finite_total = finite_total.saturating_add(pq).saturating_add(qp);
                g.add_edge(p, q, pq, qp);
            }
        }
    }
    let inf = finite_total.saturating_add(1);
    for (p, c) in cov.iter().enumerate() {
        match c {
            Cover::A => g.add_edge(src, p, inf, 0),
            Cover::B => g.add_edge(p, snk, inf, 0),
            Cover::None | Cover::Both => {}
        }
    }
    let flow = g.max_flow(src, snk);
    let side = g.source_side(src);
    let labels = Grid::from_fn(w, h, |x, y| {
        let p = y * w + x;
        match cov[p] {
            Cover::None => Label::Outside,
            _ if side[p] => Label::A,
            _ => Label::B,
        }
    });
    Ok(Seam {
        labels,
        cost: flow as f64 / SCALE,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    /// The energy of a labeling by Eq. 1–2, summed link by link.
    fn energy(a: &Grid<f32>, b: &Grid<f32>, cov: &Grid<Cover>, lab: &[bool]) -> i64 {
        let (w, h) = (cov.width(), cov.height());
        let p = SeamParams::default();
        let mut e = 0;
        for y in 0..h {
            for x in 0..w {
                for (dx, dy) in [(1, 0), (0, 1), (-1, 0), (0, -1)] {
                    let (qx, qy) = (x as isize + dx, y as isize + dy);
                    if qx < 0 || qy < 0 || qx >= w as isize || qy >= h as isize {
                        continue;
                    }
                    let (qx, qy) = (qx as usize, qy as usize);
                    let (i, j) = (y * w + x, qy * w + qx);
                    if cov.get(x, y) == Cover::None || cov.get(qx, qy) == Cover::None {
                        continue;
                    }
                    if lab[i] && !lab[j] {
                        let v = |g: &Grid<f32>, x, y| g.get(x, y) as f64;
                        e += link(&p, v(a, x, y), v(b, x, y), v(a, qx, qy), v(b, qx, qy));
                    }
                }
            }
        }
        e
    }

    fn brute(a: &Grid<f32>, b: &Grid<f32>, cov: &Grid<Cover>) -> i64 {
        let free: Vec<usize> = (0..cov.data().len())
            .filter(|&i| cov.data()[i] == Cover::Both)
            .collect();
        let mut best = i64::MAX;
        for mask in 0u32..(1 << free.len()) {
            let mut lab: Vec<bool> = cov.data().iter().map(|c| *c == Cover::A).collect();
            for (k, &i) in free.iter().enumerate() {
                lab[i] = mask >> k & 1 == 1;
            }
            best = best.min(energy(a, b, cov, &lab));
        }
        best
    }

    fn problem() -> impl Strategy<Value = (Grid<f32>, Grid<f32>, Grid<Cover>)> {
        (1usize..=4, 1usize..=3).prop_flat_map(|(w, h)| {
            let n = w * h;
            let cover = prop_oneof![
                Just(Cover::None),
                Just(Cover::A),
                Just(Cover::B),
                Just(Cover::Both),
                Just(Cover::Both),
            ];
            (
                proptest::collection::vec(0.0f32..=1.0, n),
                proptest::collection::vec(0.0f32..=1.0, n),
                proptest::collection::vec(cover, n),
            )
                .prop_map(move |(a, b, c)| {
                    (
                        Grid::from_vec(w, h, a).unwrap(),
                        Grid::from_vec(w, h, b).unwrap(),
                        Grid::from_vec(w, h, c).unwrap(),
                    )
                })
        })
    }

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(300))]

        #[test]
        fn min_cut_equals_brute_force((a, b, cov) in problem()) {
            let s = seam(&a, &b, &cov, &SeamParams::default()).unwrap();
            let want = brute(&a, &b, &cov);
            prop_assert_eq!((s.cost * SCALE).round() as i64, want);
            // The labeling itself is a minimum cut and respects the terminals.
            let lab: Vec<bool> = s.labels.data().iter().map(|l| *l == Label::A).collect();
            prop_assert_eq!(energy(&a, &b, &cov, &lab), want);
            for (l, c) in s.labels.data().iter().zip(cov.data()) {
                match c {
                    Cover::None => prop_assert_eq!(*l, Label::Outside),
                    Cover::A => prop_assert_eq!(*l, Label::A),
                    Cover::B => prop_assert_eq!(*l, Label::B),
                    Cover::Both => prop_assert!(*l != Label::Outside),
                }
            }
        }
    }

    #[test]
    fn seam_avoids_ink_and_follows_agreement() {
        // A left, B right, a free band in between; a black vertical line
        // sits at x = 10 in both segments, and the segments agree
        // everywhere except at x ≥ 14 where B's paper turns grey. The seam
        // must run through agreeing paper, never along the line.
        let (w, h) = (24, 8);
        let a = Grid::from_fn(w, h, |x, _| if x == 10 { 0.0 } else { 1.0 });
        let b = Grid::from_fn(w, h, |x, _| match x {
            10 => 0.0,
            x if x >= 14 => 0.5,
            _ => 1.0,
        });
        let cov = Grid::from_fn(w, h, |x, _| match x {
            0..=3 => Cover::A,
            20.. => Cover::B,
            _ => Cover::Both,
        });
        let s = seam(&a, &b, &cov, &SeamParams::default()).unwrap();
        for y in 0..h {
            let row: Vec<Label> = (0..w).map(|x| s.labels.get(x, y)).collect();
            let first_b = row.iter().position(|l| *l == Label::B).unwrap();
            assert!(row[first_b..].iter().all(|l| *l == Label::B), "{row:?}");
            assert!(
                (4..=14).contains(&first_b) && first_b != 10 && first_b != 11,
                "{first_b}"
            );
        }
        // A straight vertical seam of h links across agreeing paper costs
        // h × (0 + C) exactly.
        assert!((s.cost - h as f64 * 0.02).abs() < 1e-9, "{}", s.cost);
    }

    #[test]
    fn overlap_cover_crops_to_the_overlap() {
        let a = Grid::from_fn(20, 10, |x, _| x < 12);
        let b = Grid::from_fn(20, 10, |x, y| x >= 8 && y >= 3);
        let (x0, y0, c) = overlap_cover(&a, &b, 2).unwrap();
        assert_eq!((x0, y0, c.width(), c.height()), (6, 1, 8, 9));
        assert_eq!(c.get(0, 0), Cover::A);
        assert_eq!(c.get(3, 5), Cover::Both);
        assert_eq!(c.get(7, 8), Cover::B);
        assert_eq!(c.get(7, 0), Cover::None);
        let none = Grid::new(20, 10, false);
        assert!(overlap_cover(&a, &none, 2).is_none());
        assert!(overlap_cover(&a, &Grid::new(3, 3, true), 2).is_none());
    }

    #[test]
    fn mismatched_sizes_are_errors() {
        let a = Grid::new(3, 3, 1.0f32);
        let b = Grid::new(3, 2, 1.0f32);
        let c = Grid::new(3, 3, Cover::Both);
        assert!(seam(&a, &b, &c, &SeamParams::default()).is_err());
    }
}
