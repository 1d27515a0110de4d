//! Signed distance fields and exact outlines to compact Bézier outlines —
//! the last stage of every raster mode, and the `flourish trace` command
//! on its own.
//!
//! Two roads, one rule: every curve stays within `tolerance` of what it is
//! fitted to.
//!
//! * **SDFs** (an SVG's layers, and the synthesized layers of brush and
//!   fill, [`trace_sdf`]): [`contour::extract`] (marching squares on the
//!   SDF, sub-pixel vertices, consistent saddles, closed oriented loops) →
//!   [`nest`] (outer boundaries and their holes; islands and holes under
//!   `min_area` dropped) → [`fit::fit_contour`] (corners found, cubic
//!   Béziers fitted by kurbo, each checked against the SDF's zero level) →
//!   transformed to the input's units.
//! * **Outlines** (every ink layer of a raster, [`trace_outline`] and
//!   [`trace_bitmap`]): no SDF in between. An anti-aliased layer's
//!   sub-pixel outline, or a binary layer's smoothed outline
//!   ([`crate::outline::smooth`]), is covered run by run between corners
//!   by the longest spans one cubic fits ([`cover`]), each cubic matched
//!   to the outline's area and moment (`direct`) and checked against the
//!   outline itself, or for a binary layer against the corridor where its
//!   edge may lie ([`crate::outline::corridor`]).
//!
//! DecoBrush (§7, "Vectorization from SDF") left this step to Illustrator;
//! flourish measures it against potrace (`make bench`).

pub mod centerline;
pub mod cover;
pub mod cutout;
mod direct;
pub mod fit;
mod nearest;
mod piece;
mod span;
#[cfg(test)]
mod tests_centerline;

use crate::error::{Error, Result};
use crate::outline::corridor::Corridor;
use crate::outline::paths::{self, Bitmap};
use crate::outline::smooth::{self, SmoothLoop};
use crate::raster::contour::{self, contains, Contour};
use crate::raster::Sdf;
use crate::read::ink::{Ink, LayerOutline, Traceable};
use crate::svg_out::{decimals_for, Color, Document, FillRule, Group, Output, Shape};
use kurbo::{BezPath, Point, Rect};
use rayon::prelude::*;

/// Tracing parameters, in pixels of the SDF.
#[derive(Clone, Debug)]
pub struct TraceOptions {
    /// Largest distance (px) between the fitted curves and the level set
    /// (default 0.25).
    pub tolerance: f64,
    /// Islands and holes with a smaller area (px²) are dropped (default 4).
    pub min_area: f64,
}

impl Default for TraceOptions {
    fn default() -> Self {
        TraceOptions {
            tolerance: 0.25,
            min_area: 4.0,
        }
    }
}

impl TraceOptions {
    /// Checks that every field is usable.
    pub fn validate(&self) -> Result<()> {
        if !(self.tolerance.is_finite() && self.tolerance >= 0.01 && self.tolerance <= 100.0) {
            return Err(Error::Option {
                name: "tolerance",
                reason: format!("{} px is not in 0.01..=100", self.tolerance),
            });
        }
        if !(self.min_area.is_finite() && self.min_area >= 0.0) {
            return Err(Error::Option {
                name: "min_area",
                reason: format!("{} px² is not a non-negative number", self.min_area),
            });
        }
        Ok(())
    }
}

/// An outer boundary and the holes inside it, as contours in pixel space.
#[derive(Clone, Debug)]
pub struct Island {
    /// The outer boundary (positive area).
    pub outer: Contour,
    /// Holes directly inside it (negative area).
    pub holes: Vec<Contour>,
}

/// Groups contours into islands: each hole goes to the smallest outer
/// boundary containing it. Contours with |area| below `min_area` px² are
/// dropped (an island's holes go with it). Order follows the input.
pub fn nest(contours: Vec<Contour>, min_area: f64) -> Vec<Island> {
    let polys: Vec<&[Point]> = contours.iter().map(|c| c.points.as_slice()).collect();
    let areas: Vec<f64> = contours.iter().map(Contour::signed_area).collect();
    let groups = nest_polygons(&polys, &areas, min_area);
    let mut slots: Vec<Option<Contour>> = contours.into_iter().map(Some).collect();
    groups
        .into_iter()
        .filter_map(|(o, hs)| {
            let outer = slots[o].take()?;
            let holes = hs.into_iter().filter_map(|h| slots[h].take()).collect();
            Some(Island { outer, holes })
        })
        .collect()
}

/// [`nest`] on bare closed polygons with their signed `areas` (px²,
/// outer boundaries positive; what the speck threshold `min_area` reads,
/// which need not be the polygon's own): `(outer, holes)` as indices into
/// `polys`, outers in input order.
pub fn nest_polygons(polys: &[&[Point]], areas: &[f64], min_area: f64) -> Vec<(usize, Vec<usize>)> {
    let mut outers = Vec::new();
    let mut holes = Vec::new();
    for (i, (pts, &a)) in polys.iter().zip(areas).enumerate() {
        if pts.is_empty() {
            continue;
        }
        if a.abs() < min_area {
            continue;
        }
        let bbox = bounds(pts);
        if a > 0.0 {
            outers.push((i, bbox, a));
        } else {
            holes.push((i, bbox, -a));
        }
    }
    let mut islands: Vec<(usize, Vec<usize>)> =
        outers.iter().map(|&(i, _, _)| (i, Vec::new())).collect();
    // A hole goes to the smallest outer containing it (the first in input
    // order among equals): outers are tried by ascending area, from the
    // first at least as large as the hole, and the first that contains
    // it wins, so the large outlines (most of the vertices) are only
    // tested for holes that no smaller island holds.
    let mut by_area: Vec<usize> = (0..outers.len()).collect();
    by_area.sort_by(|&a, &b| outers[a].2.total_cmp(&outers[b].2));
    for (h, hb, ha) in holes {
        let probe = polys[h][0];
        let from = by_area.partition_point(|&k| outers[k].2 < ha);
        let owner = by_area
            .get(from..)
            .unwrap_or(&[])
            .iter()
            .copied()
            .find(|&k| {
                let (o, ob, _) = outers[k];
                ob.contains(probe) && ob.union(hb) == ob && contains(polys[o], probe)
            });
        if let Some(k) = owner {
            islands[k].1.push(h);
        }
    }
    islands
}

fn bounds(pts: &[Point]) -> Rect {
    let mut r = Rect::new(f64::MAX, f64::MAX, f64::MIN, f64::MIN);
    for p in pts {
        r.x0 = r.x0.min(p.x);
        r.y0 = r.y0.min(p.y);
        r.x1 = r.x1.max(p.x);
        r.y1 = r.y1.max(p.y);
    }
    r
}

/// Traces one SDF: one closed Bézier path per island (outer boundary then
/// its holes), in the SDF's user units.
pub fn trace_sdf(sdf: &Sdf, opts: &TraceOptions) -> Vec<BezPath> {
    let islands = nest(contour::extract(&sdf.dist), opts.min_area);
    islands
        .par_iter()
        .map(|island| {
            let mut path = BezPath::new();
            fit::fit_contour(&island.outer.points, sdf, opts.tolerance, &mut path);
            for h in &island.holes {
                fit::fit_contour(&h.points, sdf, opts.tolerance, &mut path);
            }
            sdf.to_user * path
        })
        .collect()
}

/// Traces a bitmap's outline (see [`crate::outline::smooth`]) directly: one
/// closed Bézier path per island, in pixel units, with no SDF and no second
/// contour extraction in between. The curves stay within `opts.tolerance`
/// of the outline itself, or, given a binary bitmap's `corridor`, within
/// `opts.tolerance` of the corridor and [`Corridor::HALF_WIDTH`] +
/// `opts.tolerance` of the outline ([`cover`]).
pub fn trace_outline(
    loops: &[SmoothLoop],
    corridor: Option<&Corridor>,
    opts: &TraceOptions,
) -> Vec<BezPath> {
    let polys: Vec<&[Point]> = loops.iter().map(|l| l.points.as_slice()).collect();
    let areas: Vec<f64> = loops.iter().map(|l| l.area).collect();
    // Every loop is fitted on its own (in parallel: one island can hold
    // most of the work) while the loops are nested, then the islands are
    // assembled in order, so the output does not depend on the thread
    // count. Loops too small to keep are skipped by their area (nesting
    // drops them by the same measure); the rare hole nesting finds no
    // outer for is fitted for nothing.
    let (islands, mut fitted) = rayon::join(
        || nest_polygons(&polys, &areas, opts.min_area),
        || {
            loops
                .par_iter()
                .map(|l| {
                    let mut path = BezPath::new();
                    let big = !l.points.is_empty() && l.area.abs() >= opts.min_area;
                    if big {
                        cover::fit_outline(
                            &l.points,
                            &l.tangents,
                            &l.corners,
                            opts.tolerance,
                            corridor,
                            &mut path,
                        );
                    }
                    path
                })
                .collect::<Vec<BezPath>>()
        },
    );
    assemble(&islands, &mut fitted)
}

/// Traces a binary bitmap's ink: what [`trace_outline`] makes of its
/// smoothed loops ([`crate::outline::smooth::bitmap_loops`]) and its
/// [`Corridor`], path by path. Each path is smoothed and fitted in one
/// task, started as soon as the path is found (the walk round the pixel
/// edges is sequential; the other threads fit what it has found so far),
/// with no loop kept once fitted. Islands are nested on the pixel paths
/// themselves, whose containment is the smoothed loops' (the loops stay
/// within half a pixel of their paths, which lie a pixel apart or more).
/// Each result goes back to its path's place, so the output does not
/// depend on the thread count.
pub fn trace_bitmap(bits: &Bitmap, opts: &TraceOptions) -> Vec<BezPath> {
    let corridor = Corridor::from_bitmap(bits);
    let fit = |p: &[Point]| {
        let mut path = BezPath::new();
        let l = smooth::smooth_loop(p);
        if l.points.len() >= 3 {
            cover::fit_outline(
                &l.points,
                &l.tangents,
                &l.corners,
                opts.tolerance,
                Some(&corridor),
                &mut path,
            );
        }
        path
    };
    let done: std::sync::Mutex<Vec<(usize, BezPath)>> = std::sync::Mutex::new(Vec::new());
    let mut paths: Vec<std::sync::Arc<Vec<Point>>> = Vec::new();
    let mut areas: Vec<f64> = Vec::new();
    let mut islands = Vec::new();
    rayon::scope(|s| {
        paths::for_each_path(bits, |p| {
            let i = paths.len();
            let area = paths::pixel_area(&p);
            let p = std::sync::Arc::new(p);
            if area.abs() >= opts.min_area {
                let (p, fit, done) = (p.clone(), &fit, &done);
                s.spawn(move |_| {
                    let path = fit(&p);
                    // A poisoned lock only means another task panicked,
                    // which the scope reports anyway.
                    let mut done = done.lock().unwrap_or_else(|e| e.into_inner());
                    done.push((i, path));
                });
            }
            paths.push(p);
            areas.push(area);
        });
        let polys: Vec<&[Point]> = paths.iter().map(|p| p.as_slice()).collect();
        islands = nest_polygons(&polys, &areas, opts.min_area);
    });
    let mut fitted = vec![BezPath::new(); paths.len()];
    for (i, path) in done.into_inner().unwrap_or_else(|e| e.into_inner()) {
        if let Some(slot) = fitted.get_mut(i) {
            *slot = path;
        }
    }
    assemble(&islands, &mut fitted)
}

/// Each island's fitted loops (`fitted`, by loop index; taken) as one
/// path, outer boundary first, in the islands' order; an island whose
/// outer loop was too small to fit is left out.
fn assemble(islands: &[(usize, Vec<usize>)], fitted: &mut [BezPath]) -> Vec<BezPath> {
    islands
        .iter()
        .filter_map(|(outer, holes)| {
            let mut path = std::mem::take(fitted.get_mut(*outer)?);
            if path.elements().is_empty() {
                return None;
            }
            for &i in holes {
                if let Some(p) = fitted.get_mut(i) {
                    path.extend(std::mem::take(p));
                }
            }
            Some(path)
        })
        .collect()
}

/// Traces every layer of `ink` into a document the size of the input, one
/// `<g id="layer-N">` per layer, bottom first.
pub fn trace_ink(ink: &Ink, opts: &TraceOptions) -> Result<Output> {
    opts.validate()?;
    let px_per_unit = ink
        .layers
        .first()
        .map(|l| l.sdf.px_per_unit())
        .unwrap_or(1.0);
    let mut doc = Document::new(
        ink.width,
        ink.height,
        decimals_for(opts.tolerance / px_per_unit),
    );
    for (i, layer) in ink.layers.iter().enumerate() {
        doc.groups
            .extend(layer_group(i, trace_sdf(&layer.sdf, opts), layer.color));
    }
    Ok(Output {
        document: doc,
        warnings: ink.warnings.clone(),
        notes: ink.notes.clone(),
    })
}

/// The `<g id="layer-N">` of layer `i`'s traced paths (non-zero fill, so
/// holes stay open), or nothing when it has none.
fn layer_group(i: usize, paths: Vec<BezPath>, color: Color) -> Option<Group> {
    (!paths.is_empty()).then(|| Group {
        id: format!("layer-{}", i + 1),
        shapes: paths
            .into_iter()
            .map(|p| Shape {
                fill_rule: FillRule::NonZero,
                ..Shape::filled(p, color)
            })
            .collect(),
    })
}

/// Reads `path` (raster or SVG) and traces it ([`trace`]); errors name
/// the file.
#[cfg(test)]
pub fn trace_file(
    path: &std::path::Path,
    input: &crate::read::ImageOptions,
    opts: &TraceOptions,
) -> Result<Output> {
    opts.validate()?;
    trace(&crate::read::ink::load_traceable(path, input)?, opts).map_err(|e| e.in_file(path))
}

/// Traces a picture read for tracing: the library side of `flourish
/// trace`. A raster's layers are traced from their outlines
/// ([`trace_outline`]); an SVG's from their SDFs.
pub fn trace(picture: &Traceable, opts: &TraceOptions) -> Result<Output> {
    opts.validate()?;
    match picture {
        Traceable::Field(ink) => trace_ink(ink, opts),
        Traceable::Regions(r) => {
            let px_per_unit = 1.0 / r.to_user.determinant().abs().sqrt().max(1e-12);
            let mut doc = Document::new(
                r.width,
                r.height,
                decimals_for(opts.tolerance / px_per_unit),
            );
            doc.groups =
                cutout::trace_partition(&r.partition, &r.colours, opts.tolerance, opts.min_area);
            for g in &mut doc.groups {
                for s in &mut g.shapes {
                    s.path = r.to_user * s.path.clone();
                }
            }
            Ok(Output {
                document: doc,
                warnings: Vec::new(),
                notes: r.notes.clone(),
            })
        }
        Traceable::Lines(l) => {
            let (w, h) = (l.coverage.width(), l.coverage.height());
            let mut doc = Document::new(w as f64, h as f64, decimals_for(opts.tolerance));
            let strokes =
                centerline::trace_lines(&l.coverage, l.stroke_width, opts.tolerance, opts.min_area);
            if strokes.is_empty() {
                return Err(Error::Invalid(
                    "nothing to trace: no lines on the page (blank paper?)".into(),
                ));
            }
            {
                doc.groups.push(Group {
                    id: "layer-1".into(),
                    shapes: strokes
                        .into_iter()
                        .map(|s| Shape {
                            path: s.path,
                            fill: None,
                            fill_rule: FillRule::NonZero,
                            stroke: Some(crate::svg_out::Stroke {
                                color: l.color,
                                width: s.width,
                                cap: crate::svg_out::LineCap::Round,
                                join: crate::svg_out::LineJoin::Round,
                            }),
                            opacity: 1.0,
                        })
                        .collect(),
                });
            }
            Ok(Output {
                document: doc,
                warnings: Vec::new(),
                notes: l.notes.clone(),
            })
        }
        Traceable::Outline(o) => {
            let mut doc = Document::new(o.width, o.height, decimals_for(opts.tolerance));
            for (i, layer) in o.layers.iter().enumerate() {
                let paths = match &layer.outline {
                    LayerOutline::Bitmap(bits) => trace_bitmap(bits, opts),
                    LayerOutline::Loops(loops) => trace_outline(loops, None, opts),
                };
                doc.groups.extend(layer_group(i, paths, layer.color));
            }
            Ok(Output {
                document: doc,
                warnings: Vec::new(),
                notes: o.notes.clone(),
            })
        }
    }
}

#[cfg(test)]
mod tests;
