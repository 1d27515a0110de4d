//! Synthesis by neighbourhood matching (Barla et al. §3.1–3.3).
//!
//! Seeds are visited growing outward from the one nearest the centre (§3.2,
//! Algorithm 1). For each, the already synthesized elements of its k-ring
//! are compared with the k-ring of every reference element:
//! 1. relevant pairs are the mutually closest (reference, target) elements
//!    by offset from their centres (§3.1, Fig. 3); pairs farther apart than
//!    half a spacing are not "relevant" and left out;
//! 2. per pair, the perceptual measures shape (symmetric Hausdorff between
//!    centre-aligned boxes), par (angle between principal axes), ov (ratio
//!    of principal lengths), sup (difference of thicknesses) and col (RGB
//!    distance) are averaged over the pairs — unknown neighbours are left
//!    out and the average is over known pairs only (§3.2);
//! 3. a reference neighbourhood is similar when
//!    col ∧ (shape ∨ (par ∧ ov ∧ sup)) with each measure below its σ; one of
//!    the similar ones is drawn at random from (seed, seed index) and its
//!    centre element is copied. When none passes (rare with Lloyd seeds,
//!    §5.2), the one with the smallest σ-normalized error is taken.
//!
//! Because target elements are copies of reference elements, every pair
//! measure is a lookup in a table of reference × reference measures (for
//! an example of more than [`MAX_TABLED_ELEMENTS`] elements, computed when
//! needed instead: the same values without the n² memory).
//!
//! The variation post-process (§3.3), scaled by t ∈ [0, 1]: with
//! probability t an element's length/width/colour are exchanged with a
//! similar reference element's (by copying that element instead, turned to
//! the same orientation, so every output stays an exact rigid copy); with
//! probability t its orientation is exchanged with one of the close
//! reference orientations; and each element with at least k neighbours
//! (k = 2 in 1-D, 4 in 2-D) moves by t of the way to the barycentre of its
//! neighbours plus S_ref·A_tar/(n·A_ref).

use super::distribution::{surrounded, Dim, Distribution, Graph};
use super::element::{directed_hausdorff, Element};
use crate::rng;
use kurbo::{Point, Vec2};
use std::f64::consts::PI;

/// Perceptual similarity thresholds (§3.1).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Thresholds {
    /// σ_shape, reference units (paper: 0.1·L, L the mean element length).
    pub shape: f64,
    /// σ_par, radians (paper: π/20).
    pub par: f64,
    /// σ_ov, a length ratio ≥ 1 (paper: 1.5).
    pub ov: f64,
    /// σ_sup, reference units (paper: 0.1·L).
    pub sup: f64,
    /// σ_col, RGB distance with channels in 0..1 (paper: 0.15).
    pub col: f64,
}

impl Thresholds {
    /// The paper's values for mean element length `l`.
    pub fn paper(l: f64) -> Thresholds {
        Thresholds {
            shape: 0.1 * l,
            par: PI / 20.0,
            ov: 1.5,
            sup: 0.1 * l,
            col: 0.15,
        }
    }
}

/// The five measures between two elements: shape, par, ov, sup, col.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Measures {
    /// Symmetric Hausdorff distance of the centre-aligned boxes.
    pub shape: f64,
    /// |angle between principal axes|, in [0, π/2].
    pub par: f64,
    /// max(|A₁|/|A₂|, |A₂|/|A₁|).
    pub ov: f64,
    /// ||B₁| − |B₂||.
    pub sup: f64,
    /// RGB distance.
    pub col: f64,
}

impl Measures {
    /// The measures of §3.1 between `a` and `b`, `floor` guarding the
    /// length ratio of point-like elements.
    pub fn between(a: &Element, b: &Element, floor: f64) -> Measures {
        let align = b.centre - a.centre;
        let shape = directed_hausdorff(a, b, align).max(directed_hausdorff(b, a, -align));
        let d = (a.angle() - b.angle()).rem_euclid(PI);
        let par = d.min(PI - d);
        let (la, lb) = (a.length().max(floor), b.length().max(floor));
        let ov = (la / lb).max(lb / la);
        let sup = (a.thickness() - b.thickness()).abs();
        let col = a
            .color
            .iter()
            .zip(b.color)
            .map(|(x, y)| (x - y) * (x - y))
            .sum::<f64>()
            .sqrt();
        Measures {
            shape,
            par,
            ov,
            sup,
            col,
        }
    }

    /// col ∧ (shape ∨ (par ∧ ov ∧ sup)).
    pub fn similar(&self, t: &Thresholds) -> bool {
        self.col < t.col
            && (self.shape < t.shape || (self.par < t.par && self.ov < t.ov && self.sup < t.sup))
    }

    /// σ-normalized error, for the fallback when nothing is similar.
    pub fn error(&self, t: &Thresholds) -> f64 {
        let geo = (self.shape / t.shape.max(1e-12)).min(
            self.par / t.par
                + (self.ov - 1.0) / (t.ov - 1.0).max(1e-12)
                + self.sup / t.sup.max(1e-12),
        );
        // A colour mismatch outweighs any geometric one.
        geo + 100.0 * (self.col / t.col).max(1.0) * (self.col >= t.col) as u8 as f64
    }

    fn add(&mut self, o: &Measures) {
        self.shape += o.shape;
        self.par += o.par;
        self.ov += o.ov;
        self.sup += o.sup;
        self.col += o.col;
    }

    fn scale(&mut self, k: f64) {
        self.shape *= k;
        self.par *= k;
        self.ov *= k;
        self.sup *= k;
        self.col *= k;
    }
}

/// The analysed reference: elements, distribution, k-ring neighbourhoods
/// and the pair measure table.
#[derive(Clone, Debug)]
pub struct Reference {
    /// The reference elements.
    pub elements: Vec<Element>,
    /// Their distribution.
    pub dist: Distribution,
    /// For each element, its k-ring as (element, offset from its centre).
    pub hoods: Vec<Vec<(usize, Vec2)>>,
    /// measures[a·n + b] between elements a and b, when there are at most
    /// [`MAX_TABLED_ELEMENTS`] elements; empty otherwise, and the measures
    /// are computed when asked for (the same values).
    pub table: Vec<Measures>,
    /// The thresholds in use.
    pub thresholds: Thresholds,
    /// Rings per neighbourhood.
    pub rings: usize,
    /// The floor guarding the length ratio of point-like elements.
    pub floor: f64,
}

/// Largest number of reference elements whose pair measures are
/// precomputed: the table holds n² entries of 40 bytes (42 MB at this
/// limit; an example of 10 000 separate strokes would need 4 GB).
pub const MAX_TABLED_ELEMENTS: usize = 1024;

impl Reference {
    /// Precomputes neighbourhoods and, for at most
    /// [`MAX_TABLED_ELEMENTS`] elements, the measure table.
    pub fn new(elements: Vec<Element>, dist: Distribution, rings: usize) -> Reference {
        Reference::with_table_limit(elements, dist, rings, MAX_TABLED_ELEMENTS)
    }

    /// [`Reference::new`] with the measure table built only for at most
    /// `table_limit` elements.
    fn with_table_limit(
        elements: Vec<Element>,
        dist: Distribution,
        rings: usize,
        table_limit: usize,
    ) -> Reference {
        let n = elements.len();
        let mean_len = elements.iter().map(|e| e.length()).sum::<f64>() / n.max(1) as f64;
        let thresholds = Thresholds::paper(mean_len);
        let floor = (mean_len * 1e-3).max(1e-9);
        let mut table = Vec::new();
        if n <= table_limit {
            table.reserve_exact(n * n);
            for a in &elements {
                for b in &elements {
                    table.push(Measures::between(a, b, floor));
                }
            }
        }
        let hoods = (0..n)
            .map(|i| {
                dist.graph
                    .ring(i, rings)
                    .into_iter()
                    .map(|j| (j, dist.centres[j] - dist.centres[i]))
                    .collect()
            })
            .collect();
        Reference {
            elements,
            dist,
            hoods,
            table,
            thresholds,
            rings,
            floor,
        }
    }

    /// The measures between reference elements a and b (from the table
    /// when there is one).
    pub fn m(&self, a: usize, b: usize) -> Measures {
        match self.table.get(a * self.elements.len() + b) {
            Some(m) => *m,
            None => Measures::between(&self.elements[a], &self.elements[b], self.floor),
        }
    }

    /// Averaged measures between the reference neighbourhood of `cand` and
    /// the known target neighbours `known` (assigned element, offset), or
    /// `None` when no pair is relevant.
    pub fn compare(&self, cand: usize, known: &[(usize, Vec2)]) -> Option<Measures> {
        let hood = &self.hoods[cand];
        if hood.is_empty() || known.is_empty() {
            return None;
        }
        let gate2 = (0.5 * self.dist.spacing).powi(2);
        let nearest = |o: Vec2, set: &mut dyn Iterator<Item = (usize, Vec2)>| {
            set.map(|(k, p)| (k, (p - o).hypot2()))
                .fold((usize::MAX, f64::MAX), |b, x| if x.1 < b.1 { x } else { b })
        };
        let mut sum = Measures::default();
        let mut pairs = 0usize;
        for (ri, &(r_el, r_off)) in hood.iter().enumerate() {
            let (ti, d2) = nearest(r_off, &mut known.iter().map(|k| k.1).enumerate());
            if ti == usize::MAX || d2 > gate2 {
                continue;
            }
            let (back, _) = nearest(known[ti].1, &mut hood.iter().map(|h| h.1).enumerate());
            if back != ri {
                continue;
            }
            sum.add(&self.m(r_el, known[ti].0));
            pairs += 1;
        }
        (pairs > 0).then(|| {
            sum.scale(1.0 / pairs as f64);
            sum
        })
    }
}

/// The seeds to fill: positions in the pattern frame and their graph.
#[derive(Clone, Debug)]
pub struct Target {
    /// Seed positions (1-D: (arc length, 0); 2-D: canvas units).
    pub pos: Vec<Point>,
    /// Neighbour graph of the seeds.
    pub graph: Graph,
    /// For a closed 1-D path, its length: x offsets wrap modulo it.
    pub period: Option<f64>,
    /// Row (along a path) or field (in a region).
    pub dim: Dim,
}

impl Target {
    fn offset(&self, from: usize, to: usize) -> Vec2 {
        let mut d = self.pos[to] - self.pos[from];
        if let Some(p) = self.period {
            d.x -= p * (d.x / p).round();
        }
        d
    }

    /// The order of synthesis: breadth first from the seed nearest the
    /// centroid, then from the nearest unvisited seed, and so on.
    pub fn growth_order(&self) -> Vec<usize> {
        let n = self.pos.len();
        if n == 0 {
            return Vec::new();
        }
        let c = self.pos.iter().fold(Vec2::ZERO, |s, p| s + p.to_vec2()) / n as f64;
        let mut roots: Vec<usize> = (0..n).collect();
        roots.sort_by(|&a, &b| {
            (self.pos[a].to_vec2() - c)
                .hypot2()
                .total_cmp(&(self.pos[b].to_vec2() - c).hypot2())
                .then(a.cmp(&b))
        });
        let mut seen = vec![false; n];
        let mut order = Vec::with_capacity(n);
        for r in roots {
            if seen[r] {
                continue;
            }
            seen[r] = true;
            let mut q = std::collections::VecDeque::from([r]);
            while let Some(v) = q.pop_front() {
                order.push(v);
                for &w in &self.graph.adj[v] {
                    if !seen[w] {
                        seen[w] = true;
                        q.push_back(w);
                    }
                }
            }
        }
        order
    }
}

/// Assigns a reference element to every target seed (Algorithm 1).
/// `key` seeds the random choices (e.g. [seed, query index]).
pub fn synthesize(reference: &Reference, target: &Target, key: &[u64]) -> Vec<usize> {
    let n = target.pos.len();
    let nref = reference.elements.len();
    let mut assigned: Vec<Option<usize>> = vec![None; n];
    let mut similar = Vec::with_capacity(nref);
    let mut known = Vec::new();
    for v in target.growth_order() {
        known.clear();
        for j in target.graph.ring(v, reference.rings) {
            if let Some(a) = assigned[j] {
                known.push((a, target.offset(v, j)));
            }
        }
        let words = [key, &[v as u64]].concat();
        similar.clear();
        let mut best = (f64::MAX, usize::MAX);
        for cand in 0..nref {
            let Some(m) = reference.compare(cand, &known) else {
                continue;
            };
            if m.similar(&reference.thresholds) {
                similar.push(cand);
            }
            let e = m.error(&reference.thresholds);
            if e < best.0 {
                best = (e, cand);
            }
        }
        let pick = if !similar.is_empty() {
            similar[rng::index(&words, similar.len())]
        } else if best.1 != usize::MAX {
            best.1
        } else {
            // Nothing known yet (the centre seed): any reference element.
            rng::index(&words, nref)
        };
        assigned[v] = Some(pick);
    }
    assigned.into_iter().map(|a| a.unwrap_or(0)).collect()
}

/// One synthesized element in the pattern frame.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Placed {
    /// The reference element copied.
    pub element: usize,
    /// Where its centre goes (pattern frame).
    pub pos: Point,
    /// Extra rotation about its centre, radians.
    pub rotation: f64,
}

/// The variation post-process (§3.3) with amount `t` in 0..=1.
/// `keep(pos)` says whether a moved centre is acceptable (inside the
/// region, within the band); a rejected move keeps the seed position.
pub fn vary(
    reference: &Reference,
    target: &Target,
    assigned: &[usize],
    t: f64,
    key: &[u64],
    keep: &dyn Fn(Point) -> bool,
) -> Vec<Placed> {
    let th = &reference.thresholds;
    let k = match target.dim {
        Dim::One => 2,
        Dim::Two => 4,
    };
    (0..assigned.len())
        .map(|i| {
            let a = assigned[i];
            let w = |s: u64| [key, &[i as u64, s]].concat();
            let mut placed = Placed {
                element: a,
                pos: target.pos[i],
                rotation: 0.0,
            };
            if t <= 0.0 {
                return placed;
            }
            let angle_of = |e: usize| reference.elements[e].angle();
            // Length, width and colour exchange: copy a similar element
            // instead, turned to this one's orientation.
            if rng::unit(&w(1)) < t {
                let sim: Vec<usize> = (0..reference.elements.len())
                    .filter(|&j| {
                        let m = reference.m(a, j);
                        j != a && m.ov < th.ov && m.sup < th.sup && m.col < th.col
                    })
                    .collect();
                if !sim.is_empty() {
                    let j = sim[rng::index(&w(2), sim.len())];
                    placed.element = j;
                    placed.rotation = wrap_half_turn(angle_of(a) - angle_of(j));
                }
            }
            // Orientation exchange among the close reference orientations.
            if rng::unit(&w(3)) < t {
                let cur = angle_of(placed.element) + placed.rotation;
                let mut close: Vec<(f64, f64)> = reference
                    .elements
                    .iter()
                    .map(|e| {
                        let d = wrap_half_turn(e.angle() - cur);
                        (d.abs(), d)
                    })
                    .filter(|(ad, _)| *ad < 2.0 * th.par)
                    .collect();
                close.sort_by(|x, y| x.0.total_cmp(&y.0));
                close.truncate(4);
                if !close.is_empty() {
                    placed.rotation += close[rng::index(&w(4), close.len())].1;
                }
            }
            // Position: barycentre of the neighbours plus the reference shift.
            let nb = &target.graph.adj[i];
            // The barycentre of a one-sided neighbourhood (at the region's
            // border, a path's ends) lies inward: such elements stay put.
            let around = surrounded(nb.iter().map(|&j| target.offset(i, j)), target.dim);
            if nb.len() >= k && around {
                if let Some(s_ref) = reference.dist.shift[placed.element] {
                    let bary = nb.iter().fold(Vec2::ZERO, |s, &j| s + target.offset(i, j))
                        / nb.len() as f64;
                    let a_ref = reference.dist.graph.hood_area[placed.element];
                    let a_tar = target.graph.hood_area[i];
                    let n_ref = reference.dist.graph.adj[placed.element].len() as f64;
                    // Areas compare only between like dimensions; across
                    // them the plain reference displacement S_ref/n_ref is used.
                    let ratio = if reference.dist.dim == target.dim {
                        a_tar / (nb.len() as f64 * a_ref)
                    } else {
                        1.0 / n_ref
                    };
                    if a_ref > 0.0 && a_tar > 0.0 && ratio.is_finite() {
                        let s_tar = s_ref * ratio;
                        let p = target.pos[i] + (bary + s_tar) * t;
                        if keep(p) {
                            placed.pos = p;
                        }
                    }
                }
            }
            placed
        })
        .collect()
}

/// An angle difference wrapped to (−π/2, π/2] (axes are unoriented).
pub fn wrap_half_turn(d: f64) -> f64 {
    let r = d.rem_euclid(PI);
    if r > PI / 2.0 {
        r - PI
    } else {
        r
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn bar(x: f64, angle: f64, len: f64, color: [f64; 3]) -> Element {
        Element {
            strokes: vec![],
            centre: Point::new(x, 0.0),
            axis: Vec2::new(angle.cos(), angle.sin()),
            half_a: len / 2.0,
            half_b: 0.5,
            color,
        }
    }

    #[test]
    fn measures_follow_the_paper() {
        let a = bar(0.0, 0.0, 10.0, [0.0; 3]);
        let same = Measures::between(&a, &bar(50.0, PI, 10.0, [0.0; 3]), 1e-6);
        assert!(same.shape < 1e-9 && same.par < 1e-9 && (same.ov - 1.0).abs() < 1e-9);
        let turned = Measures::between(&a, &bar(0.0, PI / 2.0, 10.0, [0.0; 3]), 1e-6);
        assert!((turned.par - PI / 2.0).abs() < 1e-9);
        // Corner (5, 0.5) of one cross arm is 4.5 from the other arm.
        assert!((turned.shape - 4.5).abs() < 1e-9, "{}", turned.shape);
        let long = Measures::between(&a, &bar(0.0, 0.0, 20.0, [1.0, 0.0, 0.0]), 1e-6);
        assert!((long.ov - 2.0).abs() < 1e-9);
        assert!((long.col - 1.0).abs() < 1e-9);
        let t = Thresholds::paper(10.0);
        assert!(same.similar(&t));
        assert!(!turned.similar(&t));
        assert!(!long.similar(&t));
    }

    #[test]
    fn matching_pairs_closest_neighbours_only() {
        // A row of alternating colours: after a red, the candidates whose
        // left neighbour is red are the blue ones.
        let els: Vec<Element> = (0..8)
            .map(|i| bar(i as f64 * 10.0, PI / 2.0, 6.0, [(i % 2) as f64, 0.0, 0.0]))
            .collect();
        let heights = vec![6.0; 8];
        let dist = Distribution::analyse(
            els.iter().map(|e| e.centre).collect(),
            &heights,
            Dim::One,
            10.0,
        );
        let r = Reference::new(els, dist, 1);
        // Known: element 2 (colour 0) one spacing to the left.
        let known = [(2usize, Vec2::new(-10.0, 0.0))];
        for cand in 1..8 {
            let m = r.compare(cand, &known).unwrap();
            assert_eq!(m.similar(&r.thresholds), cand % 2 == 1, "candidate {cand}");
        }
        // Element 0 has no left neighbour: nothing relevant to compare.
        assert!(r.compare(0, &known).is_none());
        // A neighbour far off the reference positions is not paired.
        assert!(r.compare(3, &[(2, Vec2::new(-10.0, 30.0))]).is_none());
    }

    fn field(n: usize) -> Vec<Element> {
        // A jittered grid of bars of a few lengths, angles and colours.
        let side = (n as f64).sqrt().ceil() as usize;
        (0..n)
            .map(|i| {
                let (x, y) = ((i % side) as f64, (i / side) as f64);
                let h = rng::unit(&[7, i as u64]);
                let mut e = bar(
                    10.0 * x + 3.0 * h,
                    (i % 5) as f64 * 0.3,
                    4.0 + (i % 3) as f64,
                    [(i % 2) as f64 * 0.5, 0.0, 0.0],
                );
                e.centre.y = 10.0 * y + 2.0 * rng::unit(&[8, i as u64]);
                e
            })
            .collect()
    }

    fn reference(n: usize, table_limit: usize) -> Reference {
        let els = field(n);
        let heights = vec![5.0; n];
        let dist = Distribution::analyse(
            els.iter().map(|e| e.centre).collect(),
            &heights,
            Dim::Two,
            10.0,
        );
        Reference::with_table_limit(els, dist, 2, table_limit)
    }

    #[test]
    fn measures_computed_on_demand_equal_the_table() {
        let (tabled, untabled) = (reference(60, usize::MAX), reference(60, 0));
        assert_eq!(tabled.table.len(), 60 * 60);
        assert!(untabled.table.is_empty());
        for a in 0..60 {
            for b in 0..60 {
                assert_eq!(tabled.m(a, b), untabled.m(a, b));
            }
        }
        // The same synthesis and variation, bit for bit.
        let pos: Vec<Point> = (0..150)
            .map(|i| Point::new((i % 15) as f64 * 9.5, (i / 15) as f64 * 9.0))
            .collect();
        let target = Target {
            graph: Graph::delaunay(&pos),
            pos,
            period: None,
            dim: Dim::Two,
        };
        let a = synthesize(&tabled, &target, &[3]);
        assert_eq!(a, synthesize(&untabled, &target, &[3]));
        let keep = |_: Point| true;
        assert_eq!(
            vary(&tabled, &target, &a, 0.7, &[3], &keep),
            vary(&untabled, &target, &a, 0.7, &[3], &keep)
        );
    }

    #[test]
    fn a_large_example_keeps_no_quadratic_table() {
        let n = MAX_TABLED_ELEMENTS + 1;
        let r = reference(n, MAX_TABLED_ELEMENTS);
        assert_eq!(r.table.capacity(), 0);
        assert_eq!(
            r.m(0, n - 1),
            Measures::between(&r.elements[0], &r.elements[n - 1], r.floor)
        );
        // At the limit the table is exact-sized, n² entries.
        let r = reference(64, 64);
        assert_eq!(r.table.len(), 64 * 64);
    }
}
