//! Element clustering by perceptual grouping (Barla et al. §2.2).
//!
//! Two elements are one when they meet the **proximity** test, the smaller
//! of the two directed Hausdorff distances between their boxes below ε
//! (nested or touching figures, §2.2.1), or the **continuation** test: for
//! one of the four axes (A₁, B₁ against E₂; A₂, B₂ against E₁) the other
//! box lies within ε/2 of the axis line and the gap between the two boxes
//! projected on that axis is below ε (broken or overlapping hatches,
//! §2.2.2). Both are computed on the boxes' corners.
//!
//! The grouping is the paper's greedy queue: pop E*, merge into it every
//! queued element that passes against the grown E*, refit; if anything
//! merged push E* back, else emit it.

use super::element::{directed_hausdorff, Element, ExampleStroke};
use kurbo::{Point, Vec2};
use std::collections::VecDeque;

/// prox(E₁, E₂) = min(d_H(E₁, E₂), d_H(E₂, E₁)) (§2.2.1).
pub fn proximity(e1: &Element, e2: &Element) -> f64 {
    directed_hausdorff(e1, e2, Vec2::ZERO).min(directed_hausdorff(e2, e1, Vec2::ZERO))
}

/// The continuation error of `other` along the line through `centre` with
/// direction `axis`, or `None` when `other` is not near-collinear (some
/// corner farther than ε/2 from the line) (§2.2.2).
fn continuation_along(
    own: &[Point; 4],
    centre: Point,
    axis: Vec2,
    other: &[Point; 4],
    eps: f64,
) -> Option<f64> {
    let normal = Vec2::new(-axis.y, axis.x);
    if other
        .iter()
        .any(|&p| (p - centre).dot(normal).abs() >= eps / 2.0)
    {
        return None;
    }
    let proj = |pts: &[Point; 4]| {
        pts.iter().fold((f64::MAX, f64::MIN), |(lo, hi), &p| {
            let t = (p - centre).dot(axis);
            (lo.min(t), hi.max(t))
        })
    };
    let (a0, a1) = proj(own);
    let (b0, b1) = proj(other);
    // The gap between the projected intervals (0 when they overlap).
    Some((b0 - a1).max(a0 - b1).max(0.0))
}

/// cont(E₁, E₂): the smallest continuation error over the four axis
/// configurations, `None` when no configuration is near-collinear.
pub fn continuation(e1: &Element, e2: &Element, eps: f64) -> Option<f64> {
    let (c1, c2) = (e1.corners(), e2.corners());
    [
        continuation_along(&c1, e1.centre, e1.axis, &c2, eps),
        continuation_along(&c1, e1.centre, e1.axis_b(), &c2, eps),
        continuation_along(&c2, e2.centre, e2.axis, &c1, eps),
        continuation_along(&c2, e2.centre, e2.axis_b(), &c1, eps),
    ]
    .into_iter()
    .flatten()
    .reduce(f64::min)
}

/// True when the two elements are perceived as one at scale ε.
pub fn groups(e1: &Element, e2: &Element, eps: f64) -> bool {
    proximity(e1, e2) < eps || continuation(e1, e2, eps).is_some_and(|c| c < eps)
}

/// Clusters the strokes into elements at scale `eps` with the greedy queue
/// of §2.2, processing strokes in drawing order.
pub fn cluster(strokes: &[ExampleStroke], eps: f64) -> Vec<Element> {
    let mut queue: VecDeque<Element> = (0..strokes.len())
        .map(|i| Element::fit(strokes, vec![i]))
        .collect();
    let mut out = Vec::new();
    while let Some(mut e) = queue.pop_front() {
        let mut merged = false;
        let mut i = 0;
        while i < queue.len() {
            if groups(&e, &queue[i], eps) {
                if let Some(other) = queue.remove(i) {
                    let mut ids = std::mem::take(&mut e.strokes);
                    ids.extend(other.strokes);
                    ids.sort_unstable();
                    e = Element::fit(strokes, ids);
                    merged = true;
                }
            } else {
                i += 1;
            }
        }
        if merged {
            queue.push_back(e);
        } else {
            out.push(e);
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    fn seg(a: (f64, f64), b: (f64, f64)) -> ExampleStroke {
        let points = (0..=20)
            .map(|i| {
                let t = i as f64 / 20.0;
                Point::new(a.0 + (b.0 - a.0) * t, a.1 + (b.1 - a.1) * t)
            })
            .collect();
        ExampleStroke {
            shapes: vec![],
            points,
            color: [0.0; 3],
            weight: 1.0,
        }
    }

    #[test]
    fn broken_hatch_continues() {
        // Two collinear pieces with a gap of 4 are one hatch at ε = 6, two at ε = 3.
        let s = [seg((0.0, 0.0), (0.0, 20.0)), seg((0.0, 24.0), (0.0, 40.0))];
        assert_eq!(cluster(&s, 6.0).len(), 1);
        assert_eq!(cluster(&s, 3.0).len(), 2);
    }
}
