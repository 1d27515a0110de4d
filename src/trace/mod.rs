//! Signed distance fields to compact Bézier outlines — the last stage of
//! every raster mode, and the `flourish trace` command on its own.
//!
//! Stages: [`contour::extract`] (marching squares on the SDF, sub-pixel
//! vertices, consistent saddles, closed oriented loops) → [`nest`] (outer
//! boundaries and their holes; islands and holes under `min_area` dropped)
//! → [`fit::fit_contour`] (corners found, cubic Béziers fitted by kurbo
//! within `tolerance`) → transformed to the input's units.
//!
//! DecoBrush (§7, "Vectorization from SDF") left this step to Illustrator;
//! flourish measures it against potrace (`make bench`).

pub mod contour;
pub mod fit;

use crate::error::{Error, Result};
use crate::raster::input::{self, Ink, InputOptions};
use crate::raster::Sdf;
use crate::svg_out::{decimals_for, Document, FillRule, Group, Shape};
use contour::{contains, Contour};
use kurbo::{BezPath, Rect};
use rayon::prelude::*;
use std::path::Path;

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
                name: "--tolerance",
                reason: format!("{} px is not in 0.01..=100", self.tolerance),
            });
        }
        if !(self.min_area.is_finite() && self.min_area >= 0.0) {
            return Err(Error::Option {
                name: "--min-area",
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
    let mut outers = Vec::new();
    let mut holes = Vec::new();
    for c in contours {
        let a = c.signed_area();
        if a.abs() < min_area {
            continue;
        }
        let bbox = bounds(&c);
        if a > 0.0 {
            outers.push((c, bbox, a));
        } else {
            holes.push((c, bbox));
        }
    }
    let mut islands: Vec<Island> = outers
        .iter()
        .map(|(c, _, _)| Island {
            outer: c.clone(),
            holes: Vec::new(),
        })
        .collect();
    for (h, hb) in holes {
        let probe = h.points[0];
        let owner = outers
            .iter()
            .enumerate()
            .filter(|(_, (_, ob, _))| ob.contains(probe) && ob.union(hb) == *ob)
            .filter(|(_, (o, _, _))| contains(&o.points, probe))
            .min_by(|a, b| a.1 .2.total_cmp(&b.1 .2))
            .map(|(i, _)| i);
        if let Some(i) = owner {
            islands[i].holes.push(h);
        }
    }
    islands
}

fn bounds(c: &Contour) -> Rect {
    let mut r = Rect::new(f64::MAX, f64::MAX, f64::MIN, f64::MIN);
    for p in &c.points {
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

/// Traces every layer of `ink` into a document the size of the input, one
/// `<g id="layer-N">` per layer, bottom first.
pub fn trace_ink(ink: &Ink, opts: &TraceOptions) -> Result<Document> {
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
        let paths = trace_sdf(&layer.sdf, opts);
        if paths.is_empty() {
            continue;
        }
        doc.groups.push(Group {
            id: format!("layer-{}", i + 1),
            shapes: paths
                .into_iter()
                .map(|p| Shape {
                    fill_rule: FillRule::NonZero,
                    ..Shape::filled(p, layer.color)
                })
                .collect(),
        });
    }
    Ok(doc)
}

/// Reads `path` (raster or SVG) and traces it: the library side of
/// `flourish trace`.
pub fn trace_file(path: &Path, input: &InputOptions, opts: &TraceOptions) -> Result<Document> {
    opts.validate()?;
    let ink = input::load(path, input)?;
    trace_ink(&ink, opts)
}
