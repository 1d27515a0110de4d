//! Tests of the piecewise matching: the DP against exhaustive enumeration.

use super::*;
use kurbo::Point;
use proptest::prelude::*;

fn straight(n: usize, width: f64, turning: f64) -> SpineFeatures {
    let len = (n - 1) as f64 * 0.2 * width;
    SpineFeatures {
        samples: (0..n)
            .map(|i| {
                let d = i as f64 * 0.2 * width;
                SampleFeature {
                    turning,
                    width,
                    dist_start: d,
                    dist_end: len - d,
                }
            })
            .collect(),
        appearance: Vec::new(),
    }
}

/// The minimum cost over every segmentation of the query, by brute force.
fn exhaustive(p: &Problem, q0: usize, last: Option<(usize, usize)>) -> f64 {
    let n = p.query_len();
    if q0 == n {
        return 0.0;
    }
    let lens = p.exemplar_lens();
    let mut best = f64::INFINITY;
    let longest = p.max_segment().unwrap_or(n).min(n - q0);
    for len in p.min_segment()..=longest {
        for (e, &le) in lens.iter().enumerate() {
            for s0 in 0..le {
                if s0 + len > le {
                    break;
                }
                let mut c = last.map_or(0.0, |l| p.jump(l, (e, s0)));
                for k in 0..len {
                    c += p.unary(q0 + k, e, s0 + k);
                }
                c += exhaustive(p, q0 + len, Some((e, s0 + len - 1)));
                best = best.min(c);
            }
        }
    }
    best
}

fn features(max_len: usize) -> impl Strategy<Value = SpineFeatures> {
    (1..=max_len).prop_flat_map(|n| {
        (
            proptest::collection::vec((-0.3f64..0.3, 0.5f64..1.5), n),
            proptest::collection::vec(0.0f64..1.0, n),
        )
            .prop_map(move |(tw, app)| {
                let len = (n - 1) as f64 * 0.25;
                SpineFeatures {
                    samples: tw
                        .iter()
                        .enumerate()
                        .map(|(i, &(t, w))| SampleFeature {
                            turning: t,
                            width: w,
                            dist_start: i as f64 * 0.25,
                            dist_end: len - i as f64 * 0.25,
                        })
                        .collect(),
                    appearance: app.iter().map(|&a| vec![a]).collect(),
                }
            })
    })
}

/// The bounds of the overlap extension (see `segments_of`): at most the
/// option, at most half the neighbour's core, and only over query samples
/// whose zone is that of the exemplar sample they take.
fn extensions_are_bounded(p: &Problem, m: &Matching) -> Result<(), TestCaseError> {
    let segs = &m.segments;
    for (k, s) in segs.iter().enumerate() {
        let before = s.core.start - s.query.start;
        let after = s.query.end - s.core.end;
        prop_assert!(before <= p.opts.overlap && after <= p.opts.overlap);
        let prev = k.checked_sub(1).map_or(0, |j| segs[j].core.len() / 2);
        let next = segs.get(k + 1).map_or(0, |n| n.core.len() / 2);
        prop_assert!(
            before <= prev,
            "{before} samples into a core of {}",
            2 * prev
        );
        prop_assert!(after <= next, "{after} samples into a core of {}", 2 * next);
        for (i, q) in s.query.clone().enumerate() {
            if s.core.contains(&q) {
                continue;
            }
            let e = s.exemplar_samples.start + i;
            let zq = p.zone_of(&p.query.samples[q]);
            let ze = p.zone_of(&p.exemplars[s.exemplar].samples[e]);
            prop_assert_eq!(zq, ze, "sample {} extended over exemplar sample {}", q, e);
        }
    }
    Ok(())
}

fn core_cost(p: &Problem, m: &Matching) -> f64 {
    p.cost_of_segments(&m.segments)
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(200))]

    #[test]
    fn dp_equals_exhaustive_search(
        query in features(6),
        exemplars in proptest::collection::vec(features(5), 1..=3),
        min_segment in 1usize..=3,
        max_segment in proptest::option::of(1usize..=4),
        seed in 0u64..4,
    ) {
        let opts = MatchOptions {
            candidates: usize::MAX,
            min_segment,
            max_segment,
            end_zone: 0.3,
            end_horizon: 1.0,
            seed,
            slack: 0.0,
            ..MatchOptions::default()
        };
        let p = Problem::new(&query, &exemplars, &opts).unwrap();
        let brute = exhaustive(&p, 0, None);
        // Every seed's varied matching is feasible when the optimum is,
        // really costs what it reports, and stays within the slack.
        let varied = MatchOptions { slack: 0.05, ..opts.clone() };
        match match_query(&query, &exemplars, &varied) {
            Ok(m) => {
                prop_assert!(brute.is_finite());
                prop_assert!((core_cost(&p, &m) - m.cost).abs() <= 1e-7 * (1.0 + brute));
                prop_assert!(m.cost >= brute - 1e-7 * (1.0 + brute));
                prop_assert!(m.cost <= brute * 1.05 + 1e-7 * (1.0 + brute), "{} vs {}", m.cost, brute);
            }
            Err(_) => prop_assert!(brute.is_infinite()),
        }
        match match_query(&query, &exemplars, &opts) {
            Ok(m) => {
                prop_assert!((m.cost - brute).abs() <= 1e-7 * (1.0 + brute), "{} vs {}", m.cost, brute);
                // The returned segmentation really costs that much.
                prop_assert!((core_cost(&p, &m) - m.cost).abs() <= 1e-7 * (1.0 + brute));
                // Cores tile the query; each is long enough and fits its exemplar.
                let mut q = 0;
                for s in &m.segments {
                    prop_assert_eq!(s.core.start, q);
                    prop_assert!(s.core.len() >= p.min_segment());
                    prop_assert!(s.core.len() <= p.max_segment().unwrap_or(usize::MAX));
                    prop_assert_eq!(s.query.len(), s.exemplar_samples.len());
                    prop_assert!(s.exemplar_samples.end <= exemplars[s.exemplar].samples.len());
                    q = s.core.end;
                }
                prop_assert_eq!(q, query.samples.len());
                extensions_are_bounded(&p, &m)?;
            }
            Err(_) => prop_assert!(brute.is_infinite()),
        }
    }

    #[test]
    fn pruned_dp_is_feasible_and_never_below_the_optimum(
        query in features(8),
        exemplars in proptest::collection::vec(features(6), 1..=3),
    ) {
        let exact = MatchOptions { candidates: usize::MAX, min_segment: 2, slack: 0.0, ..MatchOptions::default() };
        let pruned = MatchOptions { candidates: 3, beam: 2, ..exact.clone() };
        let p = Problem::new(&query, &exemplars, &pruned).unwrap();
        let (a, b) = (match_query(&query, &exemplars, &exact), match_query(&query, &exemplars, &pruned));
        // Feasible whenever the exact search is (the exact retry).
        prop_assert_eq!(a.is_ok(), b.is_ok());
        if let (Ok(a), Ok(b)) = (a, b) {
            prop_assert!(b.cost >= a.cost - 1e-9 * (1.0 + a.cost));
            prop_assert!((core_cost(&p, &b) - b.cost).abs() <= 1e-7 * (1.0 + b.cost));
        }
    }
}

#[test]
fn query_ends_take_exemplar_ends() {
    // A 30-sample query and a 40-sample exemplar: one segment would cut an
    // end short, so the matching takes the exemplar's start and its end.
    let q = straight(30, 1.0, 0.0);
    let ex = [straight(40, 1.0, 0.0)];
    let m = match_query(&q, &ex, &MatchOptions::default()).unwrap();
    assert!(m.segments.len() >= 2, "{:?}", m.segments);
    let first = &m.segments[0];
    let last = &m.segments[m.segments.len() - 1];
    assert_eq!(first.exemplar_samples.start, 0);
    assert_eq!(last.exemplar_samples.end, 40);
    let o = MatchOptions::default();
    assert!(
        m.cost <= o.jump_penalty * (1.0 + o.slack) + 1e-9,
        "one jump and no end penalty paid: {}",
        m.cost
    );
    let p = Problem::new(&q, &ex, &o).unwrap();
    extensions_are_bounded(&p, &m).unwrap();
    // Neighbours overlap by the extension.
    for w in m.segments.windows(2) {
        assert!(w[0].query.end > w[1].query.start);
        assert_eq!(w[0].core.end, w[1].core.start);
    }
}

#[test]
fn long_query_is_covered_by_several_segments() {
    let q = straight(200, 1.0, 0.01);
    let ex: Vec<_> = (0..10)
        .map(|i| straight(100, 1.0, 0.002 * i as f64))
        .collect();
    let m = match_query(&q, &ex, &MatchOptions::default()).unwrap();
    assert!(m.segments.len() >= 3);
    assert_eq!(m.segments[0].exemplar_samples.start, 0);
    let last = &m.segments[m.segments.len() - 1];
    assert_eq!(last.exemplar_samples.end, 100);
    // The exemplar whose turning matches (0.01 = 0.002 × 5) and its
    // nearest neighbours (taken instead of repeating it) dominate.
    let owned: usize = m
        .segments
        .iter()
        .filter(|s| (4..=6).contains(&s.exemplar))
        .map(|s| s.core.len())
        .sum();
    assert!(owned > 150, "{:?}", m.segments);
}

#[test]
fn seed_breaks_ties_between_identical_exemplars() {
    let q = straight(20, 1.0, 0.0);
    let ex = [straight(20, 1.0, 0.0), straight(20, 1.0, 0.0)];
    let pick = |seed| {
        let opts = MatchOptions {
            seed,
            ..MatchOptions::default()
        };
        match_query(&q, &ex, &opts).unwrap()
    };
    let picks: Vec<usize> = (0..16).map(|s| pick(s).segments[0].exemplar).collect();
    assert!(picks.contains(&0) && picks.contains(&1), "{picks:?}");
    assert_eq!(pick(3), pick(3));
    assert_eq!(pick(3).segments.len(), 1);
}

#[test]
fn seeds_draw_other_near_optimal_matchings() {
    // Five look-alike exemplars along a 300-sample query: the optimum is
    // one segmentation, but many others cost barely more; each seed but 0
    // must draw one of them (within the slack), and draw it again when
    // asked; seed 0 draws the optimum.
    let q = straight(300, 1.0, 0.01);
    let ex: Vec<_> = (0..5)
        .map(|i| straight(60 + 7 * i, 1.0, 0.009 + 0.0005 * i as f64))
        .collect();
    let exact = MatchOptions {
        slack: 0.0,
        ..MatchOptions::default()
    };
    let best = match_query(&q, &ex, &exact).unwrap();
    assert_eq!(
        best,
        match_query(&q, &ex, &MatchOptions::default()).unwrap()
    );
    let p = Problem::new(&q, &ex, &exact).unwrap();
    let mut seen = Vec::new();
    for seed in 1..9 {
        let o = MatchOptions {
            seed,
            ..MatchOptions::default()
        };
        let m = match_query(&q, &ex, &o).unwrap();
        assert_eq!(m, match_query(&q, &ex, &o).unwrap(), "seed {seed} repeats");
        assert!((p.cost_of_segments(&m.segments) - m.cost).abs() <= 1e-7 * (1.0 + m.cost));
        assert!(
            m.cost <= best.cost * (1.0 + o.slack) + 1e-9,
            "{} vs {}",
            m.cost,
            best.cost
        );
        if !seen.contains(&m.segments) {
            seen.push(m.segments);
        }
    }
    assert!(seen.len() >= 6, "{} matchings in 8 seeds", seen.len());
}

#[test]
fn jumps_prefer_look_alike_boundaries() {
    // Two exemplar families: appearance 0 and appearance 1. A boundary
    // between families pays w_appearance, so the query stays in one family.
    let q = straight(60, 1.0, 0.0);
    let with_app = |a: f64| {
        let mut f = straight(35, 1.0, 0.0);
        f.appearance = vec![vec![a]; 35];
        f
    };
    let ex = [with_app(0.0), with_app(1.0), with_app(0.0)];
    let m = match_query(&q, &ex, &MatchOptions::default()).unwrap();
    let fam = |e: usize| ex[e].appearance[0][0];
    for w in m.segments.windows(2) {
        assert_eq!(fam(w[0].exemplar), fam(w[1].exemplar), "{:?}", m.segments);
    }
}

#[test]
fn a_piece_is_not_repeated_as_a_chain_when_there_are_alternatives() {
    // Two short exemplars, the second a little wider than the query: a
    // long query is covered by middles of the first over and over unless
    // repeating a piece costs more than taking the other one.
    let q = straight(80, 1.0, 0.0);
    let ex = [straight(15, 1.0, 0.0), straight(15, 1.05, 0.0)];
    let run = |repeat_penalty| {
        let o = MatchOptions {
            repeat_penalty,
            slack: 0.0,
            ..MatchOptions::default()
        };
        let m = match_query(&q, &ex, &o).unwrap();
        (longest_repeat(&m.segments), m.segments)
    };
    let (chain, segs) = run(0.0);
    assert!(
        chain > 2,
        "without the penalty the best piece repeats: {segs:?}"
    );
    let (chain, segs) = run(MatchOptions::default().repeat_penalty);
    assert!(chain <= 2, "{segs:?}");
    assert!(segs.iter().any(|s| s.exemplar == 1), "{segs:?}");
    // One exemplar alone has no alternative: it repeats as before.
    let alone = MatchOptions {
        slack: 0.0,
        ..MatchOptions::default()
    };
    let one = match_query(&q, &ex[..1], &alone).unwrap();
    let free = MatchOptions {
        repeat_penalty: 0.0,
        ..alone
    };
    assert_eq!(one, match_query(&q, &ex[..1], &free).unwrap());
}

#[test]
fn longest_repeat_counts_runs_of_one_stretch() {
    let seg = |exemplar, r: Range<usize>| MatchedSegment {
        exemplar,
        core: 0..1,
        query: 0..1,
        exemplar_samples: r,
    };
    assert_eq!(longest_repeat(&[]), 0);
    assert_eq!(longest_repeat(&[seg(0, 0..10)]), 1);
    let chain = [seg(0, 2..10), seg(0, 3..11), seg(0, 2..9), seg(1, 2..9)];
    assert_eq!(longest_repeat(&chain), 3);
    // Another stretch of the same exemplar, or another exemplar, breaks it.
    let apart = [
        seg(0, 0..10),
        seg(0, 10..20),
        seg(1, 10..20),
        seg(0, 10..20),
    ];
    assert_eq!(longest_repeat(&apart), 1);
}

#[test]
fn bad_inputs_are_errors() {
    let q = straight(5, 1.0, 0.0);
    let empty = SpineFeatures {
        samples: vec![],
        appearance: vec![],
    };
    let opts = MatchOptions::default();
    assert!(match_query(&empty, std::slice::from_ref(&q), &opts).is_err());
    assert!(match_query(&q, std::slice::from_ref(&empty), &opts).is_err());
    let mut nan = q.clone();
    nan.samples[2].turning = f64::NAN;
    assert!(match_query(&q, &[nan], &opts).is_err());
    // Exemplars shorter than the shortest segment cannot cover the query.
    let opts = MatchOptions {
        min_segment: 4,
        ..MatchOptions::default()
    };
    assert!(match_query(&q, &[straight(3, 1.0, 0.0)], &opts).is_err());
}

#[test]
fn rib_features_measure_turning_width_and_ends() {
    // A quarter circle of radius 20, 11 ribs, half-widths 3 (left) and 2.
    let r = 20.0;
    let pt = |a: f64, d: f64| Point::new((r - d) * a.sin(), r - (r - d) * a.cos());
    let angles: Vec<f64> = (0..11)
        .map(|i| i as f64 * std::f64::consts::FRAC_PI_2 / 10.0)
        .collect();
    let spine: Vec<Point> = angles.iter().map(|&a| pt(a, 0.0)).collect();
    let left: Vec<Point> = angles.iter().map(|&a| pt(a, 3.0)).collect();
    let right: Vec<Point> = angles.iter().map(|&a| pt(a, -2.0)).collect();
    let f = SpineFeatures::from_ribs(&spine, &left, &right, vec![]).unwrap();
    let step = std::f64::consts::FRAC_PI_2 / 10.0;
    for (i, s) in f.samples.iter().enumerate() {
        assert!((s.width - 5.0).abs() < 1e-9);
        if i > 0 && i < 10 {
            assert!((s.turning - step).abs() < 1e-9, "{}", s.turning);
        }
    }
    assert_eq!(f.samples[0].dist_start, 0.0);
    assert!((f.samples[10].dist_start - f.samples[0].dist_end).abs() < 1e-9);
    assert!(SpineFeatures::from_ribs(&spine, &left[1..], &right, vec![]).is_err());
    assert!(SpineFeatures::from_ribs(&spine, &left, &right, vec![vec![1.0]]).is_err());
}

#[test]
fn max_segment_splits_long_runs() {
    let q = straight(40, 1.0, 0.0);
    let ex = [straight(60, 1.0, 0.0)];
    let opts = MatchOptions {
        max_segment: Some(12),
        ..MatchOptions::default()
    };
    let m = match_query(&q, &ex, &opts).unwrap();
    assert!(m.segments.len() >= 4, "{:?}", m.segments);
    assert!(m.segments.iter().all(|s| s.core.len() <= 12));
}
