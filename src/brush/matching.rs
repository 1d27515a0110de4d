//! Piecewise matching (decobrush.txt §5.1, adapting Lu et al. 2013): cover
//! the query spine with a sequence of exemplar segments.
//!
//! Every query sample `q` is assigned an exemplar sample `(e, s)`; inside a
//! segment consecutive query samples take consecutive exemplar samples
//! (exemplars keep their direction: the paper's strokes have a start and an
//! end, Fig. 5). The cost of an assignment is
//! - a **data term** per sample: the weighted squared difference of the
//!   feature vectors (turning angle, width, distances to both ends clamped at
//!   a horizon, so only samples near an end are told apart by them);
//! - a heavy **end penalty** when a query sample near an end of the query is
//!   matched to an exemplar sample that is not near the same end (the curls
//!   at the ends must not be cut short), and a **middle penalty** when a
//!   middle query sample takes an exemplar end;
//! - a **jump penalty** at every segment boundary, plus the mean squared
//!   difference of the appearance descriptors the two segments lay on the
//!   same query samples over the overlap (the next segment's samples
//!   against the continuation of the one it leaves) and the squared
//!   difference of the boundary thicknesses (rib lengths), so jumps
//!   happen only where the two look alike all across the seam region;
//! - a **repeat penalty** at a boundary that jumps back within the same
//!   exemplar (the next segment starts on a sample at or before the one
//!   the segment it leaves ends on, so it draws that stretch again), when
//!   the library offers other exemplars: a run of one piece repeated as a
//!   chain pays it at every link, so alternatives that look alike win;
//! - a minimum and an optional maximum segment length (in samples).
//!
//! The minimum is found by dynamic programming over (query sample,
//! candidate, run length — exact up to the maximum segment length, or
//! capped at the minimum when there is no maximum). Candidates
//! per query sample are the `candidates` best exemplar samples by data term
//! plus the continuations of the `beam` best states of the previous sample
//! and of the best state of every run length (so a segment just begun
//! survives until it is long enough to end and a complete segmentation
//! reaches the last sample),
//! so the cost is O(query × candidates²); with unlimited candidates the DP is
//! exact (tested against exhaustive enumeration of segmentations). Near-equal
//! choices are broken by a hash of (seed, position, choice).
//!
//! Seed 0 (the default) draws the optimum. Any other seed draws one of the
//! near-optimal matchings, as DecoBrush's randomized candidates make each
//! run draw other pieces (decobrush.txt §5): the DP runs again with a seeded cost added to every data term, drawn per
//! exemplar, per alignment of the exemplar to the query (a segment keeps
//! one) and per stretch of the query, so each seed prefers other pieces in
//! other places. The varied matching is kept when it differs from the
//! optimum and its true energy is within [`MatchOptions::slack`] of the
//! optimum's, else the variation is drawn again at half the size, and
//! after [`VARIATION_TRIES`] the optimum is drawn: every
//! varied ornament costs at most that much more than the best one.

use crate::brush::query::QuerySpine;
use crate::error::{Error, Result};
use crate::rng;
#[cfg(test)]
use kurbo::Point;
use std::collections::HashMap;
use std::ops::Range;

/// The matching features of one spine sample (decobrush.txt §5.1).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SampleFeature {
    /// Signed turning angle, radians (curvature × spacing).
    pub turning: f64,
    /// Ornament width (rib length), in the common length unit.
    pub width: f64,
    /// Arc length from the spine's start, in the common length unit.
    pub dist_start: f64,
    /// Arc length to the spine's end, in the common length unit.
    pub dist_end: f64,
}

/// The features along one spine, query or exemplar. Query and exemplars
/// must share a length unit and a sample spacing (the caller resamples the
/// exemplar spines at the query's spacing, scaled by the width ratio).
#[derive(Clone, Debug, PartialEq)]
pub struct SpineFeatures {
    /// One feature per sample, from start to end.
    pub samples: Vec<SampleFeature>,
    /// Appearance descriptor per sample (e.g. mean ink and ink width over
    /// the rib), compared across segment boundaries; all of one length, or
    /// empty when the spine has none (the query).
    pub appearance: Vec<Vec<f64>>,
}

impl SpineFeatures {
    /// The features of an exemplar given by its ribs (spine, left and right
    /// outline points per sample, equally spaced along the spine, in the
    /// common length unit): turning angles and end distances from the
    /// spine, width from the rib length `|left − right|`, and the given
    /// appearance descriptors (one per rib, or none).
    #[cfg(test)]
    pub fn from_ribs(
        spine: &[Point],
        left: &[Point],
        right: &[Point],
        appearance: Vec<Vec<f64>>,
    ) -> Result<Self> {
        let n = spine.len();
        if n < 2 || left.len() != n || right.len() != n {
            return Err(Error::degenerate(
                "exemplar features",
                "needs at least two ribs with spine, left and right points",
            ));
        }
        if !appearance.is_empty() && appearance.len() != n {
            return Err(Error::degenerate(
                "exemplar features",
                format!("{} appearance descriptors for {n} ribs", appearance.len()),
            ));
        }
        let length = crate::brush::query::polyline_length(spine);
        let samples = crate::brush::query::features(spine, 0.0, length)
            .iter()
            .zip(left.iter().zip(right))
            .map(|(q, (l, r))| SampleFeature {
                turning: q.turning,
                width: l.distance(*r),
                dist_start: q.dist_start,
                dist_end: q.dist_end,
            })
            .collect();
        Ok(SpineFeatures {
            samples,
            appearance,
        })
    }

    /// The features of a query spine (no appearance descriptors).
    pub fn from_query(q: &QuerySpine) -> Self {
        SpineFeatures {
            samples: q
                .samples
                .iter()
                .map(|s| SampleFeature {
                    turning: s.turning,
                    width: s.width,
                    dist_start: s.dist_start,
                    dist_end: s.dist_end,
                })
                .collect(),
            appearance: Vec::new(),
        }
    }
}

/// Weights and limits of the matching; lengths are in multiples of the
/// query's mean width, costs are unitless.
#[derive(Clone, Debug, PartialEq)]
pub struct MatchOptions {
    /// Exemplar samples kept per query sample by data term (default 16;
    /// `usize::MAX` makes the search exact).
    pub candidates: usize,
    /// Best previous states whose continuations are also candidates
    /// (default 16).
    pub beam: usize,
    /// Weight of the squared turning-angle difference, per rad² (default 400).
    pub w_turning: f64,
    /// Weight of the squared width difference over the mean width (default 1).
    pub w_width: f64,
    /// Weight of the squared difference of each clamped end distance over
    /// the horizon (default 1).
    pub w_ends: f64,
    /// Distance beyond which end distances are all alike, widths (default 2).
    pub end_horizon: f64,
    /// Distance from an end within which a sample belongs to that end,
    /// widths (default 0.5).
    pub end_zone: f64,
    /// Penalty for a query end sample matched off that exemplar end (100).
    pub end_penalty: f64,
    /// Penalty for a middle query sample matched to an exemplar end (10).
    pub middle_penalty: f64,
    /// Cost of every segment boundary (default 10). Measured on a
    /// 60-width meander, a sample's data term is 0.5–0.75, five samples
    /// per stroke width: a jump must save about three widths of data cost,
    /// so long coherent pieces win over many short ones (a small penalty
    /// cuts a query into many short segments that repeat loops at every
    /// backward jump).
    pub jump_penalty: f64,
    /// Weight of the squared appearance difference at a boundary (10).
    pub w_appearance: f64,
    /// Weight of the squared thickness difference over the mean width at a
    /// boundary (10).
    pub w_thickness: f64,
    /// Cost added to a boundary that jumps back within the same exemplar
    /// when there are other exemplars (default 10, a second jump penalty).
    pub repeat_penalty: f64,
    /// Shortest segment, in samples (default 5; shorter queries are one
    /// segment).
    pub min_segment: usize,
    /// Longest segment, in samples (default `None`: as long as the
    /// exemplar allows; costs one DP slot per sample of length).
    pub max_segment: Option<usize>,
    /// Samples by which each segment is extended into its neighbours
    /// (default 4).
    pub overlap: usize,
    /// Seed of the tie-breaking hash and of the variation.
    pub seed: u64,
    /// Largest seeded cost added to a query sample's data term in the
    /// varied search (default 0.5, about a sample's data term on a
    /// well-matched stroke; 0 leaves the seed to break ties only).
    pub variation: f64,
    /// Energy a varied matching may cost above the optimum, relative to the
    /// optimum's (default 0.03; 0 keeps the optimum).
    pub slack: f64,
    /// Costs closer than this (relative) count as ties (default 1e-9).
    pub tie_tolerance: f64,
}

impl Default for MatchOptions {
    fn default() -> Self {
        MatchOptions {
            candidates: 16,
            beam: 16,
            w_turning: 400.0,
            w_width: 1.0,
            w_ends: 1.0,
            end_horizon: 2.0,
            end_zone: 0.5,
            end_penalty: 100.0,
            middle_penalty: 10.0,
            jump_penalty: 10.0,
            w_appearance: 10.0,
            w_thickness: 10.0,
            repeat_penalty: 20.0,
            min_segment: 5,
            max_segment: None,
            overlap: 4,
            seed: 0,
            variation: 0.5,
            slack: 0.03,
            tie_tolerance: 1e-9,
        }
    }
}

/// One matched exemplar segment.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct MatchedSegment {
    /// Index of the exemplar.
    pub exemplar: usize,
    /// Query samples this segment owns (the segments' cores tile the query).
    pub core: Range<usize>,
    /// Query samples it covers once extended into its neighbours.
    pub query: Range<usize>,
    /// Exemplar samples matched to `query`, same length, same direction.
    pub exemplar_samples: Range<usize>,
}

/// The result of [`match_query`].
#[derive(Clone, Debug, PartialEq)]
pub struct Matching {
    /// Segments from the query's start to its end.
    pub segments: Vec<MatchedSegment>,
    /// Total cost of the cores' assignment (data + penalties + jumps).
    pub cost: f64,
}

/// The longest run of consecutive segments that draw the same stretch of
/// one exemplar (same exemplar, exemplar samples overlapping by more than
/// half the shorter one's): 1 when no piece follows itself.
#[cfg(test)]
pub fn longest_repeat(segments: &[MatchedSegment]) -> usize {
    let same = |a: &MatchedSegment, b: &MatchedSegment| {
        let (ra, rb) = (&a.exemplar_samples, &b.exemplar_samples);
        let common = ra.end.min(rb.end).saturating_sub(ra.start.max(rb.start));
        a.exemplar == b.exemplar && 2 * common > ra.len().min(rb.len())
    };
    let (mut best, mut run) = (usize::from(!segments.is_empty()), 1);
    for w in segments.windows(2) {
        run = if same(&w[0], &w[1]) { run + 1 } else { 1 };
        best = best.max(run);
    }
    best
}

/// Length of a stretch of the query with one draw of the variation, in
/// shortest segments.
pub const VARIATION_STRETCH: usize = 4;

/// Varied searches tried, each with a new draw of half the previous
/// variation, before the optimum is drawn.
pub const VARIATION_TRIES: usize = 3;

/// Where along its spine a sample lies, for the end penalties.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Zone {
    Start,
    Middle,
    End,
}

/// A prepared matching problem: normalized features and the cost terms.
pub struct Problem<'a> {
    query: &'a SpineFeatures,
    exemplars: &'a [SpineFeatures],
    opts: &'a MatchOptions,
    mean_width: f64,
    horizon: f64,
    zone: f64,
    /// Whether more than one exemplar has samples (a repeat has an
    /// alternative).
    alternatives: bool,
    /// Largest seeded cost added to each data term (0: the true energy).
    vary: f64,
    /// Which draw of the seeded cost (one per varied search).
    draw: u64,
}

impl<'a> Problem<'a> {
    /// Validates the inputs and prepares the normalizations.
    pub fn new(
        query: &'a SpineFeatures,
        exemplars: &'a [SpineFeatures],
        opts: &'a MatchOptions,
    ) -> Result<Self> {
        let bad = |r: String| Err(Error::degenerate("piecewise matching", r));
        if query.samples.is_empty() {
            return bad("the query has no samples".into());
        }
        if exemplars.iter().all(|e| e.samples.is_empty()) {
            return bad("no exemplar has samples".into());
        }
        let finite = |f: &SampleFeature| {
            f.turning.is_finite()
                && f.width.is_finite()
                && f.dist_start.is_finite()
                && f.dist_end.is_finite()
        };
        let dim = exemplars
            .iter()
            .flat_map(|e| e.appearance.first())
            .map(Vec::len)
            .next()
            .unwrap_or(0);
        for (i, e) in exemplars.iter().enumerate() {
            if !e.samples.iter().all(finite) {
                return bad(format!("exemplar {i} has a non-finite feature"));
            }
            let ok_app = e.appearance.is_empty()
                || e.appearance.len() == e.samples.len()
                    && e.appearance
                        .iter()
                        .all(|a| a.len() == dim && a.iter().all(|v| v.is_finite()));
            if !ok_app {
                return bad(format!(
                    "exemplar {i}: appearance descriptors missing, of unequal length or not finite"
                ));
            }
        }
        if !query.samples.iter().all(finite) {
            return bad("the query has a non-finite feature".into());
        }
        let n = query.samples.len() as f64;
        let mean_width = query.samples.iter().map(|s| s.width).sum::<f64>() / n;
        if mean_width <= 0.0 {
            return bad("the query has no width".into());
        }
        Ok(Problem {
            query,
            exemplars,
            opts,
            mean_width,
            horizon: opts.end_horizon.max(1e-9) * mean_width,
            zone: opts.end_zone * mean_width,
            alternatives: exemplars.iter().filter(|e| !e.samples.is_empty()).count() > 1,
            vary: 0.0,
            draw: 0,
        })
    }

    /// The same problem with draw `draw` of a seeded cost of up to `vary`
    /// added to every data term (see the module docs).
    fn varied(self, vary: f64, draw: u64) -> Self {
        Problem { vary, draw, ..self }
    }

    fn zone_of(&self, f: &SampleFeature) -> Zone {
        if f.dist_start < self.zone && f.dist_start <= f.dist_end {
            Zone::Start
        } else if f.dist_end < self.zone {
            Zone::End
        } else {
            Zone::Middle
        }
    }

    /// The data term and end penalties of matching query sample `q` to
    /// sample `s` of exemplar `e` (indices must be in range).
    pub fn unary(&self, q: usize, e: usize, s: usize) -> f64 {
        let (Some(a), Some(b)) = (
            self.query.samples.get(q),
            self.exemplars.get(e).and_then(|x| x.samples.get(s)),
        ) else {
            return f64::INFINITY;
        };
        let o = self.opts;
        let h = self.horizon;
        let clamp = |d: f64| d.clamp(0.0, h) / h;
        let dt = a.turning - b.turning;
        let dw = (a.width - b.width) / self.mean_width;
        let ds = clamp(a.dist_start) - clamp(b.dist_start);
        let de = clamp(a.dist_end) - clamp(b.dist_end);
        let mut c = o.w_turning * dt * dt + o.w_width * dw * dw + o.w_ends * (ds * ds + de * de);
        if self.vary > 0.0 {
            let stretch = (VARIATION_STRETCH * o.min_segment.max(1)) as u64;
            let align = (s as i64 - q as i64) as u64;
            let key = [
                o.seed,
                0x7A21,
                self.draw,
                e as u64,
                align,
                q as u64 / stretch,
            ];
            c += self.vary * rng::unit(&key);
        }
        let (zq, ze) = (self.zone_of(a), self.zone_of(b));
        if zq != ze {
            c += if zq == Zone::Middle {
                o.middle_penalty
            } else {
                o.end_penalty
            };
        }
        c
    }

    /// The cost of a boundary from exemplar sample `from` (the last of a
    /// segment) to `to` (the first of the next): the jump penalty, the
    /// appearance difference over the overlap, the thickness difference
    /// and the repeat penalty (see the module docs); infinite for samples
    /// out of range.
    pub fn jump(&self, from: (usize, usize), to: (usize, usize)) -> f64 {
        let o = self.opts;
        let get = |(e, s): (usize, usize)| {
            let x = self.exemplars.get(e)?;
            Some((x.samples.get(s)?, x.appearance.get(s)))
        };
        let (Some((fa, aa)), Some((fb, ab))) = (get(from), get(to)) else {
            return f64::INFINITY;
        };
        let dw = (fa.width - fb.width) / self.mean_width;
        let d2 = |x: &Vec<f64>, y: &Vec<f64>| -> f64 {
            x.iter().zip(y).map(|(u, v)| (u - v) * (u - v)).sum()
        };
        // Over the overlap the two segments are laid on the same query
        // samples: `to + k` of the next against `from + 1 + k` of the one
        // it leaves (its continuation), for |k| ≤ overlap; the mean of
        // their appearance differences, or the boundary pair's alone where
        // neither exemplar reaches further.
        let (Some(xa), Some(xb)) = (self.exemplars.get(from.0), self.exemplars.get(to.0)) else {
            return f64::INFINITY;
        };
        let w = o.overlap as isize;
        let (mut sum, mut n) = (0.0, 0usize);
        for k in -w..=w {
            let (sa, sb) = (from.1 as isize + 1 + k, to.1 as isize + k);
            if sa < 0 || sb < 0 {
                continue;
            }
            if let (Some(x), Some(y)) = (
                xa.appearance.get(sa as usize),
                xb.appearance.get(sb as usize),
            ) {
                sum += d2(x, y);
                n += 1;
            }
        }
        let app = if n > 0 {
            sum / n as f64
        } else {
            match (aa, ab) {
                (Some(x), Some(y)) => d2(x, y),
                _ => 0.0,
            }
        };
        let repeat = if self.alternatives && from.0 == to.0 && to.1 <= from.1 {
            o.repeat_penalty
        } else {
            0.0
        };
        o.jump_penalty + o.w_appearance * app + o.w_thickness * dw * dw + repeat
    }

    /// Number of query samples.
    pub fn query_len(&self) -> usize {
        self.query.samples.len()
    }

    /// Sample counts of the exemplars.
    pub fn exemplar_lens(&self) -> Vec<usize> {
        self.exemplars.iter().map(|e| e.samples.len()).collect()
    }

    /// The effective shortest segment: the option, at least 1, at most the
    /// query's length.
    pub fn min_segment(&self) -> usize {
        self.opts.min_segment.clamp(1, self.query_len())
    }

    /// The effective longest segment, if limited: the option, at least the
    /// effective shortest.
    #[cfg(test)]
    pub fn max_segment(&self) -> Option<usize> {
        self.opts.max_segment.map(|m| m.max(self.min_segment()))
    }

    /// The cost of matched segments whose cores tile the query, as the DP
    /// counts it (data terms over the cores, a boundary cost between
    /// consecutive cores).
    pub fn cost_of_segments(&self, segs: &[MatchedSegment]) -> f64 {
        let triples: Vec<(usize, usize, Range<usize>)> = segs
            .iter()
            .map(|m| {
                let s0 = m.exemplar_samples.start + (m.core.start - m.query.start);
                (m.exemplar, s0, m.core.clone())
            })
            .collect();
        self.cost_of(&triples)
    }

    /// The cost of a segmentation given as (exemplar, first exemplar sample,
    /// query range) triples tiling the query, as the DP counts it.
    pub fn cost_of(&self, segs: &[(usize, usize, Range<usize>)]) -> f64 {
        let mut c = 0.0;
        let mut last: Option<(usize, usize)> = None;
        for (e, s0, r) in segs {
            if let Some(l) = last {
                c += self.jump(l, (*e, *s0));
            }
            for (k, q) in r.clone().enumerate() {
                c += self.unary(q, *e, s0 + k);
            }
            last = Some((*e, s0 + r.len().saturating_sub(1)));
        }
        c
    }
}

#[derive(Clone, Copy, Debug)]
enum Back {
    Start,
    Continue(usize, usize),
    Jump(usize, usize),
}

/// One DP layer: candidates and, per candidate, cost and back pointer per
/// run length 1..=slots (index r − 1; the last slot holds all longer runs
/// when there is no maximum).
struct Layer {
    cands: Vec<(usize, usize)>,
    cost: Vec<f64>,
    back: Vec<Back>,
}

/// Matches `query` against `exemplars` (decobrush.txt §5.1) and returns the
/// segments, extended by `opts.overlap` samples into their neighbours: the
/// seed's near-optimal matching (see the module docs), with its true cost.
pub fn match_query(
    query: &SpineFeatures,
    exemplars: &[SpineFeatures],
    opts: &MatchOptions,
) -> Result<Matching> {
    let best = match_search(query, exemplars, opts, 0.0, 0)?;
    if opts.seed == 0 || !(opts.slack > 0.0 && opts.variation > 0.0) {
        return Ok(best);
    }
    let p = Problem::new(query, exemplars, opts)?;
    let bound = best.cost + opts.slack * best.cost.abs();
    let mut vary = opts.variation;
    for draw in 0..VARIATION_TRIES as u64 {
        if let Ok(m) = match_search(query, exemplars, opts, vary, draw) {
            let cost = p.cost_of_segments(&m.segments);
            if cost <= bound && m.segments != best.segments {
                return Ok(Matching {
                    segments: m.segments,
                    cost,
                });
            }
        }
        vary /= 2.0;
    }
    Ok(best)
}

/// The optimum of the problem with draw `draw` of a seeded variation of up
/// to `vary` on the data terms: the pruned search, or the exact one when
/// pruning lost every complete segmentation.
fn match_search(
    query: &SpineFeatures,
    exemplars: &[SpineFeatures],
    opts: &MatchOptions,
    vary: f64,
    draw: u64,
) -> Result<Matching> {
    match match_pruned(query, exemplars, opts, vary, draw) {
        // The pruned search lost every complete segmentation (its kept
        // runs all ran off their exemplars' ends near the query's end):
        // the exact search over every exemplar sample finds one if any
        // exists.
        Err(_) if opts.candidates < usize::MAX => match_pruned(
            query,
            exemplars,
            &MatchOptions {
                candidates: usize::MAX,
                ..opts.clone()
            },
            vary,
            draw,
        ),
        r => r,
    }
}

/// [`match_query`] with the options' candidate pruning, failing when no
/// complete segmentation survived it.
fn match_pruned(
    query: &SpineFeatures,
    exemplars: &[SpineFeatures],
    opts: &MatchOptions,
    vary: f64,
    draw: u64,
) -> Result<Matching> {
    let p = Problem::new(query, exemplars, opts)?.varied(vary, draw);
    let n = p.query_len();
    let lmin = p.min_segment();
    // Run-length slots per candidate: exact up to the maximum segment
    // length when there is one, else capped at the minimum (all longer runs
    // behave alike).
    let (slots, capped) = match opts.max_segment {
        Some(m) => (m.max(lmin), false),
        None => (lmin, true),
    };
    let lens = p.exemplar_lens();
    let tol = |c: f64| opts.tie_tolerance * (1.0 + c.abs());
    let near_better = |v: f64, key: u64, cur: f64, cur_key: u64| {
        !cur.is_finite() || v < cur - tol(cur) || (v <= cur + tol(cur) && key < cur_key)
    };
    let mut layers: Vec<Layer> = Vec::with_capacity(n);
    for q in 0..n {
        let cands = candidates(&p, q, layers.last(), slots, &lens);
        let m = cands.len();
        let mut cost = vec![f64::INFINITY; m * slots];
        let mut back = vec![Back::Start; m * slots];
        // Per previous candidate: its best complete run (length ≥ minimum).
        let complete: Vec<Option<(f64, usize)>> = layers.last().map_or(Vec::new(), |prev| {
            (0..prev.cands.len())
                .map(|pi| {
                    let mut best: Option<(f64, usize, u64)> = None;
                    for r in lmin - 1..slots {
                        let v = prev.cost[pi * slots + r];
                        let key = rng::hash(&[opts.seed, q as u64, pi as u64, r as u64, 0xC0]);
                        let take = v.is_finite()
                            && best.is_none_or(|(bv, _, bk)| near_better(v, key, bv, bk));
                        if take {
                            best = Some((v, r, key));
                        }
                    }
                    best.map(|(v, r, _)| (v, r))
                })
                .collect()
        });
        // Offers a value for slot (c, r); near-ties go to the lower hash.
        // The hashes are computed only for near-ties.
        let mut offer = |slot: usize, v: f64, b: Back| {
            let cur = cost[slot];
            let better = !cur.is_finite()
                || v < cur - tol(cur)
                || (v <= cur + tol(cur)
                    && back_key(opts.seed, q, slot, b) < back_key(opts.seed, q, slot, back[slot]));
            if v.is_finite() && better {
                cost[slot] = v;
                back[slot] = b;
            }
        };
        for (ci, &(e, s)) in cands.iter().enumerate() {
            let u = p.unary(q, e, s);
            if !u.is_finite() {
                continue;
            }
            let Some(prev) = layers.last() else {
                offer(ci * slots, u, Back::Start);
                continue;
            };
            // A new segment after a complete one.
            for (pi, &pc) in prev.cands.iter().enumerate() {
                if let Some(&Some((v, r))) = complete.get(pi) {
                    offer(ci * slots, v + p.jump(pc, (e, s)) + u, Back::Jump(pi, r));
                }
            }
            // Continuing the segment that matched (e, s − 1).
            if s > 0 {
                if let Some(pi) = prev.cands.iter().position(|&c| c == (e, s - 1)) {
                    for r in 0..slots {
                        let v = prev.cost[pi * slots + r];
                        let next = if r + 1 < slots {
                            r + 1
                        } else if capped {
                            slots - 1
                        } else {
                            continue; // the segment is as long as allowed
                        };
                        if v.is_finite() {
                            offer(ci * slots + next, v + u, Back::Continue(pi, r));
                        }
                    }
                }
            }
        }
        layers.push(Layer { cands, cost, back });
    }
    // The best complete state at the last sample.
    let last = layers
        .last()
        .ok_or_else(|| Error::degenerate("piecewise matching", "empty query"))?;
    let mut best: Option<(usize, f64, u64)> = None;
    for ci in 0..last.cands.len() {
        for r in lmin - 1..slots {
            let slot = ci * slots + r;
            let v = last.cost[slot];
            let key = rng::hash(&[opts.seed, n as u64, slot as u64, 0xE2D]);
            if v.is_finite() && best.is_none_or(|(_, bv, bk)| near_better(v, key, bv, bk)) {
                best = Some((slot, v, key));
            }
        }
    }
    let Some((mut slot, total, _)) = best else {
        return Err(Error::degenerate(
            "piecewise matching",
            format!("no exemplar segments of {lmin} to {slots} samples fit the query"),
        ));
    };
    // Backtrack: assignment per query sample and segment starts.
    let mut assign = vec![(0usize, 0usize); n];
    let mut starts = vec![false; n];
    for q in (0..n).rev() {
        let layer = &layers[q];
        assign[q] = layer.cands[slot / slots];
        match layer.back[slot] {
            Back::Start => starts[q] = true,
            Back::Jump(pi, r) => {
                starts[q] = true;
                slot = pi * slots + r;
            }
            Back::Continue(pi, r) => slot = pi * slots + r,
        }
    }
    Ok(Matching {
        segments: segments_of(&p, &assign, &starts),
        cost: total,
    })
}

/// A key for tie-breaking a slot's choice, from (seed, position, choice).
fn back_key(seed: u64, q: usize, slot: usize, b: Back) -> u64 {
    let (tag, i, r) = match b {
        Back::Start => (1, 0, 0),
        Back::Continue(i, r) => (2, i, r),
        Back::Jump(i, r) => (3, i, r),
    };
    rng::hash(&[seed, q as u64, slot as u64, tag, i as u64, r as u64])
}

/// The candidates of query sample `q`: the best exemplar samples by unary
/// cost, plus the continuations of the previous layer's best states.
fn candidates(
    p: &Problem,
    q: usize,
    prev: Option<&Layer>,
    slots: usize,
    lens: &[usize],
) -> Vec<(usize, usize)> {
    let o = p.opts;
    let total: usize = lens.iter().sum();
    let mut all: Vec<(usize, usize)> = Vec::new();
    if o.candidates >= total {
        for (e, &len) in lens.iter().enumerate() {
            all.extend((0..len).map(|s| (e, s)));
        }
        return all;
    }
    let mut scored: Vec<(f64, u64, usize, usize)> = Vec::with_capacity(total);
    for (e, &len) in lens.iter().enumerate() {
        for s in 0..len {
            let key = rng::hash(&[o.seed, q as u64, e as u64, s as u64]);
            scored.push((p.unary(q, e, s), key, e, s));
        }
    }
    let k = o.candidates.max(1);
    let by = |a: &(f64, u64, usize, usize), b: &(f64, u64, usize, usize)| {
        a.0.total_cmp(&b.0).then(a.1.cmp(&b.1))
    };
    if scored.len() > k {
        scored.select_nth_unstable_by(k - 1, by);
        scored.truncate(k);
    }
    scored.sort_by(by);
    all.extend(scored.iter().map(|t| (t.2, t.3)));
    if let Some(prev) = prev {
        let mut best: Vec<(f64, usize)> = (0..prev.cands.len())
            .map(|ci| {
                let m = prev.cost[ci * slots..(ci + 1) * slots]
                    .iter()
                    .fold(f64::INFINITY, |a, &b| a.min(b));
                (m, ci)
            })
            .filter(|t| t.0.is_finite())
            .collect();
        best.sort_by(|a, b| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1)));
        let mut keep: Vec<usize> = best.iter().take(o.beam).map(|t| t.1).collect();
        // Also the best state of every run length: a segment just begun
        // must survive until it is long enough to end, or the beam can
        // hold only incomplete runs at the last sample.
        // Only runs that can still grow to the shortest segment before
        // their exemplar ends.
        let lmin = p.min_segment();
        for r in 0..slots {
            let top = (0..prev.cands.len())
                .filter(|&ci| {
                    let (e, s) = prev.cands[ci];
                    prev.cost[ci * slots + r].is_finite()
                        && s + lmin.saturating_sub(r + 1) < lens[e]
                })
                .min_by(|&a, &b| {
                    prev.cost[a * slots + r]
                        .total_cmp(&prev.cost[b * slots + r])
                        .then(a.cmp(&b))
                });
            keep.extend(top);
        }
        for ci in keep {
            let (e, s) = prev.cands[ci];
            if s + 1 < lens[e] {
                all.push((e, s + 1));
            }
        }
    }
    let mut seen: HashMap<(usize, usize), ()> = HashMap::with_capacity(all.len());
    all.retain(|c| seen.insert(*c, ()).is_none());
    all
}

/// Segments from a per-sample assignment and segment starts, each extended
/// into its neighbours (§5.1, "we extend each segment in both directions
/// to overlap the nearby matched segments") by up to `overlap` samples,
/// as far as query and exemplar allow, and bounded so that the seam
/// between two segments stays between their ornaments:
/// - by at most half the neighbour's core, so a short neighbour (an end
///   ornament matched alone) keeps a part that no other segment covers,
///   where the graph cut cannot replace it;
/// - only over samples whose query zone and exemplar zone agree: a middle
///   segment is not extended into the query's end zones (over the end
///   ornament) nor over its exemplar's end (bringing that exemplar's end
///   ornament into the middle of the query).
fn segments_of(p: &Problem, assign: &[(usize, usize)], starts: &[bool]) -> Vec<MatchedSegment> {
    let n = assign.len();
    let overlap = p.opts.overlap;
    let lens = p.exemplar_lens();
    let mut cores = Vec::new();
    let mut q0 = 0;
    for q in 1..=n {
        if starts.get(q).copied().unwrap_or(true) {
            cores.push(q0..q);
            q0 = q;
        }
    }
    // Whether query sample q may take sample s of exemplar e.
    let agree = |q: usize, e: usize, s: usize| {
        let qz = p.query.samples.get(q).map(|f| p.zone_of(f));
        let ez = p
            .exemplars
            .get(e)
            .and_then(|x| x.samples.get(s))
            .map(|f| p.zone_of(f));
        qz.is_some() && qz == ez
    };
    let mut out = Vec::with_capacity(cores.len());
    for (k, core) in cores.iter().enumerate() {
        let Some(&(e, s0)) = assign.get(core.start) else {
            continue;
        };
        let len_e = lens.get(e).copied().unwrap_or(0);
        let prev = k
            .checked_sub(1)
            .and_then(|j| cores.get(j))
            .map_or(0, |c| c.len() / 2);
        let next = cores.get(k + 1).map_or(0, |c| c.len() / 2);
        let mut before = 0;
        while before < overlap.min(prev).min(s0)
            && agree(core.start - before - 1, e, s0 - before - 1)
        {
            before += 1;
        }
        let s_end = s0 + core.len();
        let mut after = 0;
        while after < overlap.min(next).min(len_e.saturating_sub(s_end))
            && agree(core.end + after, e, s_end + after)
        {
            after += 1;
        }
        out.push(MatchedSegment {
            exemplar: e,
            core: core.clone(),
            query: core.start - before..core.end + after,
            exemplar_samples: s0 - before..s_end + after,
        });
    }
    out
}

#[cfg(test)]
#[path = "matching_tests.rs"]
mod tests;
