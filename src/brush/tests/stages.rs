//! The brush stages chained on a real sketch (decobrush.txt §5.1–5.3):
//! query spine → piecewise matching → ARAP per segment → coordinate fields
//! → graph-cut seams in the overlaps, with synthetic ornament exemplars.
//! Checks path fidelity (the ornament covers the query, nothing far from
//! it), that every seam is no worse than the paper's naive mid-rib cut, and
//! that the whole chain is deterministic. Writes the composed ornament to
//! `$TMPDIR/flourish-brush-stages.png` for a look.

use crate::brush::arap::{mean_distortion, rasterize_coords, Arap, RibMesh};
use crate::brush::graphcut::{overlap_cover, seam, Cover, Label, SeamParams};
use crate::brush::matching::{match_query, MatchOptions, SpineFeatures};
use crate::brush::query::{self, QueryOptions, QuerySpine};
use crate::raster::Grid;
use kurbo::{Affine, Point, Vec2};

const SPACING: f64 = 2.0;
const HALF: f64 = 5.0;
/// Canvas pixels per sketch unit.
const ZOOM: f64 = 3.0;

/// A synthetic exemplar: an arc of curvature `kappa` (0: straight) with
/// `n` ribs at `SPACING`, half-width `HALF`, and an ink pattern of phase
/// `phase`, all in exemplar units.
struct Exemplar {
    kappa: f64,
    phase: f64,
    spine: Vec<Point>,
    left: Vec<Point>,
    right: Vec<Point>,
}

impl Exemplar {
    fn new(n: usize, kappa: f64, phase: f64) -> Self {
        let at = |s: f64| {
            if kappa == 0.0 {
                (Point::new(s, 0.0), Vec2::new(1.0, 0.0))
            } else {
                let a = kappa * s;
                (
                    Point::new(a.sin() / kappa, (1.0 - a.cos()) / kappa),
                    Vec2::new(a.cos(), a.sin()),
                )
            }
        };
        let (mut spine, mut left, mut right) = (vec![], vec![], vec![]);
        for i in 0..n {
            let (p, t) = at(i as f64 * SPACING);
            let nrm = Vec2::new(-t.y, t.x);
            spine.push(p);
            left.push(p + nrm * HALF);
            right.push(p - nrm * HALF);
        }
        Exemplar {
            kappa,
            phase,
            spine,
            left,
            right,
        }
    }

    /// (arc length, offset along the left normal) of an exemplar point.
    fn uv(&self, p: Point) -> (f64, f64) {
        let k = self.kappa;
        if k == 0.0 {
            return (p.x, p.y);
        }
        let r = 1.0 / k;
        let d = p - Point::new(0.0, r);
        let a = (d.x / r).atan2(-d.y / r);
        (a * r, r.signum() * (r.abs() - d.hypot()))
    }

    /// Ink (0) or paper (1) at an exemplar point: a central stem, curls
    /// alternating on both sides, and a ring at each end.
    fn ink(&self, p: Point) -> f32 {
        let (s, t) = self.uv(p);
        let len = (self.spine.len() - 1) as f64 * SPACING;
        let stem = t.abs() < 0.8;
        let j = ((s - self.phase) / 12.0).round();
        let side = if (j as i64).rem_euclid(2) == 0 {
            1.0
        } else {
            -1.0
        };
        let c = Point::new(self.phase + 12.0 * j, side * 2.6);
        let curl = (Point::new(s, t).distance(c) - 2.0).abs() < 0.6;
        let ring = |e: f64| (Point::new(s, t).distance(Point::new(e, 0.0)) - 3.5).abs() < 0.7;
        if stem || curl || ring(3.5) || ring(len - 3.5) {
            0.0
        } else {
            1.0
        }
    }

    fn features(&self) -> SpineFeatures {
        // Appearance: mean ink across each rib.
        let appearance = (0..self.spine.len())
            .map(|i| {
                let ink: f32 = (0..=10)
                    .map(|k| self.ink(self.right[i].lerp(self.left[i], k as f64 / 10.0)))
                    .sum();
                vec![ink as f64 / 11.0]
            })
            .collect();
        SpineFeatures::from_ribs(&self.spine, &self.left, &self.right, appearance).expect("ribs")
    }
}

fn sketch_spine() -> QuerySpine {
    let svg = r##"<svg xmlns="http://www.w3.org/2000/svg" width="320" height="160" viewBox="0 0 320 160">
        <path id="vine" d="M20 110 C 80 20, 140 20, 170 80 S 260 150, 300 60" fill="none" stroke="#000" stroke-width="10"/>
    </svg>"##;
    let sk = crate::read::sketch::parse(svg.as_bytes()).expect("parses");
    let set = query::spines(&sk, &QueryOptions::default()).expect("spines");
    assert!(set.warnings.is_empty(), "{:?}", set.warnings);
    set.spines.into_iter().next().expect("one spine")
}

/// Per segment: exemplar index and coordinate field on the canvas.
type Fields = Vec<(usize, Grid<Option<Point>>)>;

fn run(seed: u64) -> (QuerySpine, Vec<Exemplar>, Fields, Grid<f32>) {
    let q = sketch_spine();
    let exemplars = vec![
        Exemplar::new(45, 0.0, 0.0),
        Exemplar::new(50, 1.0 / 45.0, 4.0),
        Exemplar::new(50, -1.0 / 45.0, 8.0),
        Exemplar::new(40, 1.0 / 25.0, 2.0),
        Exemplar::new(40, -1.0 / 25.0, 6.0),
    ];
    let feats: Vec<SpineFeatures> = exemplars.iter().map(Exemplar::features).collect();
    let opts = MatchOptions {
        seed,
        ..MatchOptions::default()
    };
    let m = match_query(&SpineFeatures::from_query(&q), &feats, &opts).expect("matches");
    assert!(m.segments.len() >= 2, "{:?}", m.segments);
    assert_eq!(
        m.segments[0].exemplar_samples.start, 0,
        "the query starts on an exemplar start"
    );
    let last = m.segments.last().expect("segments");
    assert_eq!(
        last.exemplar_samples.end,
        exemplars[last.exemplar].spine.len()
    );

    let (w, h) = (320 * ZOOM as usize, 160 * ZOOM as usize);
    let mut fields: Fields = Vec::new();
    for seg in &m.segments {
        let ex = &exemplars[seg.exemplar];
        let r = seg.exemplar_samples.clone();
        let mesh = RibMesh::from_ribs(&ex.spine[r.clone()], &ex.left[r.clone()], &ex.right[r], 2)
            .expect("mesh");
        let arap = Arap::new(&mesh, &mesh.spine).expect("factors");
        let pins: Vec<Point> = q.samples[seg.query.clone()].iter().map(|s| s.pos).collect();
        let out = arap.solve(&pins).expect("solves");
        let d = mean_distortion(&mesh, &out);
        assert!(d < 0.25, "segment {seg:?} distortion {d}");
        let grid = rasterize_coords(&mesh, &out, w, h, Affine::scale(ZOOM)).expect("rasterizes");
        fields.push((seg.exemplar, grid));
    }

    // Seams between consecutive segments; the composed ink follows them.
    let params = SeamParams::default();
    let ink_of = |k: usize, x: usize, y: usize| {
        let (e, g) = &fields[k];
        g.get(x, y).map(|c| exemplars[*e].ink(c))
    };
    // owner[p]: which segment the composed image takes pixel p from.
    let mut owner: Grid<Option<usize>> = Grid::new(w, h, None);
    for y in 0..h {
        for x in 0..w {
            let first = (0..fields.len()).find(|&k| fields[k].1.get(x, y).is_some());
            owner.set(x, y, first);
        }
    }
    for k in 0..fields.len() - 1 {
        let covers = |k: usize| fields[k].1.map(|c| c.is_some());
        let (x0, y0, cover) =
            overlap_cover(&covers(k), &covers(k + 1), 2).expect("consecutive segments overlap");
        let (cw, ch) = (cover.width(), cover.height());
        let a = Grid::from_fn(cw, ch, |x, y| ink_of(k, x + x0, y + y0).unwrap_or(1.0));
        let b = Grid::from_fn(cw, ch, |x, y| ink_of(k + 1, x + x0, y + y0).unwrap_or(1.0));
        let s = seam(&a, &b, &cover, &params).expect("cuts");
        // The paper's naive alternative (Fig. 6b): a straight cut across
        // the middle of the overlap.
        let naive = naive_cut_cost(&a, &b, &cover, &params);
        assert!(s.cost <= naive + 1e-9, "seam {} vs naive {naive}", s.cost);
        for y in 0..ch {
            for x in 0..cw {
                let (gx, gy) = (x + x0, y + y0);
                match s.labels.get(x, y) {
                    Label::A if owner.get(gx, gy) == Some(k + 1) => owner.set(gx, gy, Some(k)),
                    Label::B if cover.get(x, y) == Cover::Both => owner.set(gx, gy, Some(k + 1)),
                    _ => {}
                }
            }
        }
    }
    let image = Grid::from_fn(w, h, |x, y| {
        owner.get(x, y).and_then(|k| ink_of(k, x, y)).unwrap_or(1.0)
    });
    (q, exemplars, fields, image)
}

/// The Eq. 1–2 cost of splitting the overlap by distance to the two
/// single-covered sides (a straight cut across the middle).
fn naive_cut_cost(a: &Grid<f32>, b: &Grid<f32>, cover: &Grid<Cover>, p: &SeamParams) -> f64 {
    let (w, h) = (cover.width(), cover.height());
    let pts = |c: Cover| -> Vec<Point> {
        (0..w * h)
            .filter(|i| cover.data()[*i] == c)
            .map(|i| Point::new((i % w) as f64, (i / w) as f64))
            .collect()
    };
    let (pa, pb) = (pts(Cover::A), pts(Cover::B));
    let near = |set: &[Point], q: Point| set.iter().map(|s| s.distance(q)).fold(f64::MAX, f64::min);
    let lab = Grid::from_fn(w, h, |x, y| match cover.get(x, y) {
        Cover::A => true,
        Cover::B | Cover::None => false,
        Cover::Both => {
            let q = Point::new(x as f64, y as f64);
            near(&pa, q) <= near(&pb, q)
        }
    });
    let mut cost = 0.0;
    for y in 0..h {
        for x in 0..w {
            for (dx, dy) in [(1isize, 0isize), (0, 1), (-1, 0), (0, -1)] {
                let (qx, qy) = (x as isize + dx, y as isize + dy);
                if qx < 0 || qy < 0 || qx >= w as isize || qy >= h as isize {
                    continue;
                }
                let (qx, qy) = (qx as usize, qy as usize);
                if cover.get(x, y) == Cover::None || cover.get(qx, qy) == Cover::None {
                    continue;
                }
                if lab.get(x, y) && !lab.get(qx, qy) {
                    let ec = |x, y| p.w_c * (2.0 - a.get(x, y) as f64 - b.get(x, y) as f64) + p.c;
                    let d = a.get(x, y) as f64 - b.get(qx, qy) as f64;
                    cost += d * d + 0.5 * (ec(x, y) + ec(qx, qy));
                }
            }
        }
    }
    cost
}

#[test]
fn stages_chain_into_an_ornament_along_the_path() {
    let (q, _, fields, image) = run(0);
    let (w, h) = (image.width(), image.height());
    let covered = |x: usize, y: usize| fields.iter().any(|(_, g)| g.get(x, y).is_some());
    // Path fidelity: pixels near the spine are covered; nothing covered is
    // far from it.
    for y in 0..h {
        for x in 0..w {
            let c = Point::new((x as f64 + 0.5) / ZOOM, (y as f64 + 0.5) / ZOOM);
            let (near, d) = q
                .samples
                .iter()
                .enumerate()
                .map(|(i, s)| (i, s.pos.distance(c)))
                .fold((0, f64::MAX), |a, b| if b.1 < a.1 { b } else { a });
            // Beside the spine (not beyond its ends, where ribs stop).
            let beside = near > 0 && near + 1 < q.samples.len();
            if beside && d < 0.6 * HALF {
                assert!(covered(x, y), "({x},{y}) at {d} from the spine is bare");
            }
            if covered(x, y) {
                assert!(d < 2.0 * HALF, "({x},{y}) covered {d} from the spine");
            }
        }
    }
    let mut png = image::GrayImage::new(w as u32, h as u32);
    for (i, v) in image.data().iter().enumerate() {
        png.put_pixel(
            (i % w) as u32,
            (i / w) as u32,
            image::Luma([(v * 255.0) as u8]),
        );
    }
    let out = std::env::temp_dir().join("flourish-brush-stages.png");
    png.save(&out).expect("writes the preview");
    let ink = image.data().iter().filter(|v| **v < 0.5).count();
    assert!(ink as f64 > 1000.0 * ZOOM * ZOOM, "ornament has ink: {ink}");
}

#[test]
fn chain_is_deterministic_and_seeded() {
    let a = run(7).3;
    let b = run(7).3;
    assert_eq!(a, b);
}
