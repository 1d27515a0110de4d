//! The query side of the brush: sketch paths → resampled spines.
//!
//! Every open query path of a [`Sketch`] (SPEC.md "Sketch SVG": a stroked
//! shape without fill; usvg has already resolved transforms) becomes one
//! [`QuerySpine`] per subpath: the subpath is flattened with kurbo, then
//! resampled at equal arc-length steps, and every sample carries the feature
//! vector of the piecewise matching (decobrush.txt §5.1, after Lu et al.
//! 2013): the signed turning angle, the stroke width and the arc-length
//! distances to both ends.
//!
//! Everything is in the sketch's user units. Resampling is one linear walk
//! over the flattened polyline, so a 100k-point path costs time and memory
//! linear in its size; the sample count is capped ([`QueryOptions::max_samples`])
//! by widening the spacing, so a huge path cannot blow up either.

use crate::error::{Error, Result};
use crate::read::sketch::{profile_at, QueryKind, Sketch};
use kurbo::{BezPath, PathEl, Point, Rect, Vec2};

/// How query paths are resampled.
#[derive(Clone, Debug, PartialEq)]
pub struct QueryOptions {
    /// Sample spacing along the spine, in multiples of the path's stroke
    /// width (default 0.2: five samples per width).
    pub spacing_in_widths: f64,
    /// Flattening tolerance, as a fraction of the spacing (default 0.002:
    /// a chord of a circle of radius R then spans about √(0.016 R/h)
    /// spacings h, so turning angles stay per-sample down to R ≈ 2 widths).
    pub tolerance_in_spacings: f64,
    /// Most samples one spine may have; a longer spine is resampled at a
    /// wider spacing, with a warning (default 100 000).
    pub max_samples: usize,
}

impl Default for QueryOptions {
    fn default() -> Self {
        QueryOptions {
            spacing_in_widths: 0.2,
            tolerance_in_spacings: 0.002,
            max_samples: 100_000,
        }
    }
}

/// One sample of a resampled spine.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct QuerySample {
    /// Position, in sketch user units.
    pub pos: Point,
    /// Unit tangent (direction of travel).
    pub tangent: Vec2,
    /// Signed turning angle at this sample, in radians: the angle from the
    /// incoming to the outgoing step, i.e. signed curvature × spacing
    /// (positive turns from +x towards +y; 0 at both ends).
    pub turning: f64,
    /// Intended ornament width here, in user units: the spine's
    /// synthesis width (the matching's feature).
    pub width: f64,
    /// The stroke's own width here over [`Self::width`] (its
    /// `data-widths`; 1 where it has none): the ornament is synthesized at
    /// `width` and its offsets across the spine are then scaled by this
    /// ([`super::swell`]).
    pub swell: f64,
    /// Arc length from the spine's start to this sample, in user units.
    pub dist_start: f64,
    /// Arc length from this sample to the spine's end, in user units.
    pub dist_end: f64,
}

/// One subpath of an open query path, resampled by arc length.
#[derive(Clone, Debug, PartialEq)]
pub struct QuerySpine {
    /// The query's id (`q-N` or the element's own id).
    pub query_id: String,
    /// Index of the subpath within the query's path.
    pub subpath: usize,
    /// The query's `data-style`, if any.
    pub style: Option<String>,
    /// The query's `data-seed`, in place of the run's seed, if any.
    pub seed: Option<u64>,
    /// The stroke width, in user units.
    pub width: f64,
    /// The actual arc length between samples, in user units (at most the
    /// requested spacing: the length is divided into equal steps).
    pub spacing: f64,
    /// Total arc length of the flattened subpath, in user units.
    pub length: f64,
    /// The samples, from start to end (at least two).
    pub samples: Vec<QuerySample>,
}

/// What [`spines`] found: the spines and the warnings about skipped or
/// altered paths (one line each, for `--verbose` or stderr).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct QuerySet {
    /// The spines in document order.
    pub spines: Vec<QuerySpine>,
    /// One line per skipped or altered path.
    pub warnings: Vec<String>,
    /// One line per query left to other modes (filled regions).
    pub notes: Vec<String>,
}

/// Builds the query spines of every open query path of `sketch`.
///
/// Zero-length and single-point subpaths, and subpaths lying wholly outside
/// the viewBox, are skipped with a warning; filled regions are left to
/// `fill`/`pattern` with a note. A non-finite coordinate is an error naming
/// the sketch file.
pub fn spines(sketch: &Sketch, opts: &QueryOptions) -> Result<QuerySet> {
    check_options(opts)?;
    let mut out = QuerySet::default();
    for q in &sketch.queries {
        let (spine, width) = match &q.kind {
            QueryKind::Path { spine, width } => (spine, *width),
            QueryKind::Region { .. } => {
                out.notes.push(format!(
                    "query {} is a filled region, left to fill and pattern",
                    q.id
                ));
                continue;
            }
        };
        if !width.is_finite() || width <= 0.0 || !path_is_finite(spine) {
            return Err(Error::invalid(format!(
                "query {} has a non-finite coordinate or width",
                q.id
            )));
        }
        let spacing = width * opts.spacing_in_widths;
        let polys = flatten_subpaths(spine, spacing, opts);
        // Where each subpath starts along the whole path, and its length,
        // for the width profile's positions.
        let lengths: Vec<f64> = polys.iter().map(|p| polyline_length(p)).collect();
        let total: f64 = lengths.iter().sum();
        let mut before = 0.0;
        for (k, poly) in polys.into_iter().enumerate() {
            let offset = before;
            before += lengths[k];
            let what = format!("query {} subpath {k}", q.id);
            if !touches(&poly, sketch.view_box.inflate(width, width)) {
                out.warnings
                    .push(format!("{what} lies outside the viewBox and is skipped"));
                continue;
            }
            match resample(&poly, spacing, opts.max_samples) {
                Resampled::Degenerate(reason) => {
                    out.warnings.push(format!("{what} {reason} and is skipped"))
                }
                Resampled::Ok { points, widened } => {
                    if widened {
                        out.warnings.push(format!(
                            "{what} is longer than {} samples; resampled more coarsely",
                            opts.max_samples
                        ));
                    }
                    let length = lengths[k];
                    let mut samples = features(&points, width, length);
                    if let Some(w) = &q.widths {
                        for s in &mut samples {
                            let share = if total > 0.0 {
                                (offset + s.dist_start) / total
                            } else {
                                0.0
                            };
                            s.swell = profile_at(w, share) / width;
                        }
                    }
                    out.spines.push(QuerySpine {
                        query_id: q.id.clone(),
                        subpath: k,
                        style: q.style.clone(),
                        seed: q.seed,
                        width,
                        spacing: length / (points.len() - 1) as f64,
                        length,
                        samples,
                    });
                }
            }
        }
    }
    Ok(out)
}

fn check_options(opts: &QueryOptions) -> Result<()> {
    if !(opts.spacing_in_widths.is_finite() && opts.spacing_in_widths > 0.0) {
        return Err(Error::Option {
            name: "spacing",
            reason: format!("{} is not a positive number", opts.spacing_in_widths),
        });
    }
    if !(opts.tolerance_in_spacings.is_finite() && opts.tolerance_in_spacings > 0.0) {
        return Err(Error::Option {
            name: "tolerance",
            reason: format!("{} is not a positive number", opts.tolerance_in_spacings),
        });
    }
    if opts.max_samples < 2 {
        return Err(Error::Option {
            name: "max_samples",
            reason: "a spine needs at least 2 samples".into(),
        });
    }
    Ok(())
}

fn path_is_finite(path: &BezPath) -> bool {
    let ok = |p: &Point| p.x.is_finite() && p.y.is_finite();
    path.elements().iter().all(|el| match el {
        PathEl::MoveTo(a) | PathEl::LineTo(a) => ok(a),
        PathEl::QuadTo(a, b) => ok(a) && ok(b),
        PathEl::CurveTo(a, b, c) => ok(a) && ok(b) && ok(c),
        PathEl::ClosePath => true,
    })
}

/// Whether the polyline's bounding box meets `view` (edges included).
fn touches(poly: &[Point], view: Rect) -> bool {
    let Some(first) = poly.first() else {
        return true; // empty subpaths are reported as degenerate instead
    };
    let r = poly
        .iter()
        .fold(Rect::from_points(*first, *first), |r, p| r.union_pt(*p));
    // Closed intervals, so lines along an edge of the view still count.
    r.x1 >= view.x0 && r.x0 <= view.x1 && r.y1 >= view.y0 && r.y0 <= view.y1
}

/// Flattens every subpath of `path` into a polyline (closed subpaths end on
/// their first point). The tolerance follows the spacing, widened first
/// when the control polygon is so long that the sample cap would apply.
fn flatten_subpaths(path: &BezPath, spacing: f64, opts: &QueryOptions) -> Vec<Vec<Point>> {
    // The control polygon bounds the arc length from above.
    let hull = control_polygon_length(path);
    let spacing = spacing.max(hull / opts.max_samples as f64);
    let tolerance = spacing * opts.tolerance_in_spacings;
    let mut subpaths: Vec<Vec<Point>> = Vec::new();
    kurbo::flatten(path.iter(), tolerance, |el| match el {
        PathEl::MoveTo(p) => subpaths.push(vec![p]),
        PathEl::LineTo(p) => match subpaths.last_mut() {
            Some(s) => s.push(p),
            None => subpaths.push(vec![p]),
        },
        PathEl::ClosePath => {
            if let Some(s) = subpaths.last_mut() {
                if let Some(&first) = s.first() {
                    s.push(first);
                }
            }
        }
        PathEl::QuadTo(..) | PathEl::CurveTo(..) => {}
    });
    subpaths
}

fn control_polygon_length(path: &BezPath) -> f64 {
    let mut last = Point::ZERO;
    let mut start = Point::ZERO;
    let mut len = 0.0;
    let mut to = |p: Point, last: &mut Point| {
        len += last.distance(p);
        *last = p;
    };
    for el in path.elements() {
        match *el {
            PathEl::MoveTo(p) => {
                last = p;
                start = p;
            }
            PathEl::LineTo(p) => to(p, &mut last),
            PathEl::QuadTo(a, b) => {
                to(a, &mut last);
                to(b, &mut last);
            }
            PathEl::CurveTo(a, b, c) => {
                to(a, &mut last);
                to(b, &mut last);
                to(c, &mut last);
            }
            PathEl::ClosePath => to(start, &mut last),
        }
    }
    len
}

/// Arc length of a polyline.
pub fn polyline_length(poly: &[Point]) -> f64 {
    poly.windows(2).map(|w| w[0].distance(w[1])).sum()
}

/// The outcome of [`resample`].
#[derive(Clone, Debug, PartialEq)]
pub enum Resampled {
    /// The resampled points, both ends included (at least two), and whether
    /// the spacing had to be widened to respect the sample cap.
    Ok {
        /// Points at equal arc-length steps.
        points: Vec<Point>,
        /// True when `max_samples` forced a wider spacing.
        widened: bool,
    },
    /// The polyline cannot be resampled; the reason, in words.
    Degenerate(&'static str),
}

/// Resamples a polyline at equal arc-length steps of at most `spacing`
/// (user units), both ends included, with at most `max_samples` points.
/// One walk over the polyline: linear time and memory.
pub fn resample(poly: &[Point], spacing: f64, max_samples: usize) -> Resampled {
    if poly.len() < 2 {
        return Resampled::Degenerate("has a single point");
    }
    let length = polyline_length(poly);
    let extent = poly
        .iter()
        .fold(0.0f64, |m, p| m.max(p.x.abs()).max(p.y.abs()));
    if !length.is_finite() || length <= 1e-12 * extent.max(1.0) {
        return Resampled::Degenerate("has zero length");
    }
    let max_steps = max_samples.max(2) - 1;
    let wanted = (length / spacing).ceil();
    // `wanted` is finite and positive here (length > 0, spacing > 0).
    let widened = wanted > max_steps as f64;
    let steps = if widened {
        max_steps
    } else {
        (wanted as usize).max(1)
    };
    let step = length / steps as f64;
    let mut points = Vec::with_capacity(steps + 1);
    points.push(poly[0]);
    // Walk the edges once; `travelled` is the arc length at the current
    // edge's start.
    let mut travelled = 0.0;
    let mut k = 1;
    for w in poly.windows(2) {
        let seg = w[0].distance(w[1]);
        while k < steps && (k as f64) * step <= travelled + seg {
            let t = if seg > 0.0 {
                ((k as f64) * step - travelled) / seg
            } else {
                0.0
            };
            points.push(w[0].lerp(w[1], t.clamp(0.0, 1.0)));
            k += 1;
        }
        travelled += seg;
    }
    // Rounding may leave the last interior samples unplaced; they sit at
    // the end of the polyline.
    let last = poly[poly.len() - 1];
    while points.len() < steps {
        points.push(last);
    }
    points.push(last);
    Resampled::Ok { points, widened }
}

/// The matching features of equally spaced `points` spanning arc length
/// `length`, all with ornament width `width` (decobrush.txt §5.1).
pub fn features(points: &[Point], width: f64, length: f64) -> Vec<QuerySample> {
    let n = points.len();
    let step = if n > 1 { length / (n - 1) as f64 } else { 0.0 };
    (0..n)
        .map(|i| {
            let prev = if i > 0 {
                points[i] - points[i - 1]
            } else {
                Vec2::ZERO
            };
            let next = if i + 1 < n {
                points[i + 1] - points[i]
            } else {
                Vec2::ZERO
            };
            let turning = if i > 0 && i + 1 < n {
                prev.cross(next).atan2(prev.dot(next))
            } else {
                0.0
            };
            let s = step * i as f64;
            QuerySample {
                pos: points[i],
                tangent: unit_tangent(prev, next),
                turning,
                width,
                swell: 1.0,
                dist_start: s,
                dist_end: (length - s).max(0.0),
            }
        })
        .collect()
}

/// The unit tangent from the incoming and outgoing steps: their sum when
/// it does not vanish, else whichever is non-zero, else +x.
fn unit_tangent(prev: Vec2, next: Vec2) -> Vec2 {
    let u = |v: Vec2| {
        let l = v.hypot();
        (l > 0.0 && l.is_finite()).then(|| v / l)
    };
    let (a, b) = (u(prev), u(next));
    match (a, b) {
        (Some(a), Some(b)) => u(a + b).unwrap_or(b),
        (Some(a), None) => a,
        (None, Some(b)) => b,
        (None, None) => Vec2::new(1.0, 0.0),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn sketch(body: &str) -> Sketch {
        let svg = format!(
            r##"<svg xmlns="http://www.w3.org/2000/svg" width="200" height="200" viewBox="0 0 200 200">{body}</svg>"##
        );
        crate::read::sketch::parse(svg.as_bytes()).expect("parses")
    }

    #[test]
    fn straight_line_is_resampled_evenly() {
        let s = sketch(r##"<path d="M10 10 H110" stroke="#000" stroke-width="10" fill="none"/>"##);
        let set = spines(&s, &QueryOptions::default()).unwrap();
        assert_eq!(set.spines.len(), 1);
        let sp = &set.spines[0];
        assert!((sp.length - 100.0).abs() < 1e-3, "{}", sp.length);
        assert_eq!(sp.samples.len(), 51, "spacing 2 = 0.2 × width 10");
        for (i, q) in sp.samples.iter().enumerate() {
            assert!((q.pos.x - 10.0 - 2.0 * i as f64).abs() < 1e-3);
            assert!(q.turning.abs() < 1e-9);
            assert!((q.tangent.x - 1.0).abs() < 1e-9);
            assert!((q.dist_start + q.dist_end - sp.length).abs() < 1e-9);
            assert_eq!(q.width, 10.0);
        }
    }

    #[test]
    fn circle_arc_turning_is_curvature_times_spacing() {
        // Half circle of radius 50 drawn clockwise on screen (y down), which
        // turns from +x towards +y: positive turning.
        let s = sketch(
            r##"<path d="M50 100 A50 50 0 0 1 150 100" stroke="#000" stroke-width="5" fill="none"/>"##,
        );
        let set = spines(&s, &QueryOptions::default()).unwrap();
        let sp = &set.spines[0];
        assert!((sp.length - std::f64::consts::PI * 50.0).abs() < 0.05);
        let want = sp.spacing / 50.0;
        let inner = &sp.samples[1..sp.samples.len() - 1];
        let total: f64 = inner.iter().map(|q| q.turning).sum();
        // The n − 1 steps turn by π in all; the n − 2 inner samples see all
        // but one step's worth.
        assert!(
            (total + want - std::f64::consts::PI).abs() < 0.01,
            "{total}"
        );
        for q in inner {
            assert!(
                (q.turning - want).abs() < 0.2 * want,
                "{} vs {want}",
                q.turning
            );
        }
    }

    #[test]
    fn degenerate_and_outside_paths_are_skipped_with_warnings() {
        let s = sketch(
            r##"<path id="dot" d="M10 10 L10 10" stroke="#000" stroke-width="4" fill="none"/>
               <path id="far" d="M100000 100000 L100100 100000" stroke="#000" stroke-width="4" fill="none"/>
               <path id="ok" d="M10 20 L60 20" stroke="#000" stroke-width="4" fill="none"/>
               <rect x="0" y="0" width="10" height="10" fill="red"/>"##,
        );
        let set = spines(&s, &QueryOptions::default()).unwrap();
        assert_eq!(set.spines.len(), 1);
        assert_eq!(set.spines[0].query_id, "ok");
        assert!(set
            .warnings
            .iter()
            .any(|w| w.contains("far") && w.contains("outside")));
        assert_eq!(set.notes.len(), 1, "{:?}", set.notes);
        // `dot` has no length: sketch.rs already skips it with a warning.
        assert!(s.warnings.iter().any(|w| w.contains("dot")));
    }

    #[test]
    fn degenerate_subpaths_are_skipped_and_the_rest_kept() {
        let s = sketch(
            r##"<path id="multi" d="M10 20 L60 20 M90 90 L90 90 M100 100 Z M120 120 L150 150" stroke="#000" stroke-width="4" fill="none"/>"##,
        );
        let set = spines(&s, &QueryOptions::default()).unwrap();
        let ids: Vec<usize> = set.spines.iter().map(|s| s.subpath).collect();
        assert_eq!(set.spines.len(), 2, "{ids:?} {:?}", set.warnings);
        assert!(!set.warnings.is_empty());
        assert!(set
            .warnings
            .iter()
            .all(|w| w.starts_with("query multi subpath")));
    }

    #[test]
    fn zero_length_and_single_point_polylines_are_degenerate() {
        let p = Point::new(3.0, 4.0);
        assert_eq!(
            resample(&[p], 1.0, 10),
            Resampled::Degenerate("has a single point")
        );
        assert_eq!(
            resample(&[p, p, p], 1.0, 10),
            Resampled::Degenerate("has zero length")
        );
    }

    #[test]
    fn hundred_thousand_points_resample_linearly_and_are_capped() {
        let poly: Vec<Point> = (0..100_000)
            .map(|i| Point::new(i as f64 * 0.01, (i as f64 * 0.001).sin()))
            .collect();
        let t = std::time::Instant::now();
        let Resampled::Ok { points, widened } = resample(&poly, 0.5, 100_000) else {
            panic!("resamples")
        };
        assert!(!widened);
        assert!(
            points.len() > 1000 && points.len() < 4000,
            "{}",
            points.len()
        );
        let Resampled::Ok { points, widened } = resample(&poly, 1e-6, 5000) else {
            panic!("resamples")
        };
        assert!(widened);
        assert_eq!(points.len(), 5000);
        assert!(t.elapsed().as_secs_f64() < 1.0, "{:?}", t.elapsed());
    }

    #[test]
    fn hundred_thousand_point_sketch_path_through_spines() {
        let mut s = sketch("");
        let mut spine = BezPath::new();
        spine.move_to((0.0, 100.0));
        for i in 1..100_000 {
            let x = i as f64 * 0.002;
            spine.line_to((x, 100.0 + 20.0 * (x * 0.3).sin()));
        }
        s.queries.push(crate::read::sketch::Query {
            id: "long".into(),
            style: None,
            seed: None,
            widths: None,
            kind: QueryKind::Path { spine, width: 2.0 },
        });
        let t = std::time::Instant::now();
        let set = spines(&s, &QueryOptions::default()).unwrap();
        assert!(t.elapsed().as_secs_f64() < 1.0, "{:?}", t.elapsed());
        let sp = &set.spines[0];
        assert_eq!(sp.samples.len(), (sp.length / 0.4).ceil() as usize + 1);
        // A tiny spacing is capped at max_samples, with a warning.
        let opts = QueryOptions {
            spacing_in_widths: 1e-6,
            max_samples: 20_000,
            ..QueryOptions::default()
        };
        let set = spines(&s, &opts).unwrap();
        assert_eq!(set.spines[0].samples.len(), 20_000);
        assert!(set.warnings.iter().any(|w| w.contains("coarsely")));
    }

    #[test]
    fn equal_steps_survive_rounding() {
        let poly = [
            Point::new(0.0, 0.0),
            Point::new(1.0, 0.0),
            Point::new(1.0, 1.0),
        ];
        let Resampled::Ok { points, .. } = resample(&poly, 0.3, 100) else {
            panic!()
        };
        assert_eq!(points.len(), 8, "7 steps of 2/7");
        assert_eq!(points[7], Point::new(1.0, 1.0));
        for w in points.windows(2) {
            assert!(w[0].distance(w[1]) <= 2.0 / 7.0 + 1e-12);
        }
    }

    #[test]
    fn non_finite_coordinates_name_the_query() {
        let mut s =
            sketch(r##"<path d="M10 10 H110" stroke="#000" stroke-width="10" fill="none"/>"##);
        if let QueryKind::Path { spine, .. } = &mut s.queries[0].kind {
            spine.line_to((f64::NAN, 3.0));
        }
        let e = spines(&s, &QueryOptions::default())
            .unwrap_err()
            .to_string();
        assert!(e.starts_with("query q-1 has a non-finite"), "{e}");
    }
}
