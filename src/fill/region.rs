//! Target regions: a sketch's filled shape rasterized on the synthesis grid,
//! its exact boundary distance, and the target direction field.

use crate::error::{Error, Result};
use crate::field::diffusion::{self, StrokeSample};
use crate::field::DirectionGrid;
use crate::io;
use crate::raster::vector::flatten_segments;
use crate::raster::{Grid, Sdf};
use crate::svg_out::FillRule;
use kurbo::{Affine, BezPath, Line, Point, Shape as _};

/// Largest synthesis grid for one region, pixels per side.
pub const MAX_FILL_SIDE: u64 = 4096;

/// Largest synthesis grid for one region, pixels in all (8 Mpx).
pub const MAX_FILL_PIXELS: u64 = 8 << 20;

/// A region on its synthesis grid.
#[derive(Clone, Debug)]
pub struct Region {
    /// Pixel centres inside the shape (holes excluded).
    pub mask: Grid<bool>,
    /// Exact signed distance to the outline, pixels, negative inside;
    /// `to_user` maps grid pixels to sketch units.
    pub sdf: Sdf,
    /// Target direction per pixel (unit, pixel axes).
    pub direction: DirectionGrid,
    /// Number of inside pixels.
    pub area: usize,
}

impl Region {
    /// The region with its grids let go (0×0) and its area kept: what
    /// remains once it is filled and traced.
    pub fn without_grids(self) -> Region {
        Region {
            mask: Grid::new(0, 0, false),
            sdf: Sdf {
                dist: Grid::new(0, 0, 0.0),
                to_user: self.sdf.to_user,
            },
            direction: Grid::new(0, 0, [0.0; 2]),
            area: self.area,
        }
    }

    /// Rasterizes `outline` (sketch units) at `px_per_unit`, with `margin`
    /// pixels around its bounding box. Fails (naming `file` and `id`) when
    /// the grid is over the size limit or no pixel centre is inside.
    pub fn rasterize(
        id: &str,
        outline: &BezPath,
        fill_rule: FillRule,
        px_per_unit: f64,
        margin: usize,
    ) -> Result<Region> {
        let bb = outline.bounding_box();
        if !(bb.width().is_finite() && bb.height().is_finite()) {
            return Err(Error::invalid(format!("{id}: outline is not finite")));
        }
        let (w, h) = (
            (bb.width() * px_per_unit).ceil() + 2.0 * margin as f64,
            (bb.height() * px_per_unit).ceil() + 2.0 * margin as f64,
        );
        let (w, h) = (w.max(1.0) as u64, h.max(1.0) as u64);
        io::check_canvas(w, h)?;
        if w > MAX_FILL_SIDE || h > MAX_FILL_SIDE || w * h > MAX_FILL_PIXELS {
            return Err(Error::TooLarge { width: w, height: h, limit: format!(
                    "region {id}: {MAX_FILL_SIDE} px per side, {} Mpx in all for a fill; lower the style's resolution or raise its scale",
                    MAX_FILL_PIXELS >> 20
                ) });
        }
        let (w, h) = (w as usize, h as usize);
        // Grid pixel (0, 0) is at the box corner minus the margin.
        let origin = Point::new(
            bb.x0 - margin as f64 / px_per_unit,
            bb.y0 - margin as f64 / px_per_unit,
        );
        let to_px = Affine::scale(px_per_unit) * Affine::translate(-origin.to_vec2());
        let mut segments = Vec::new();
        flatten_segments(&(to_px * outline.clone()), 0.05, &mut segments);
        let mask = scan_inside(w, h, &segments, fill_rule);
        let area = mask.data().iter().filter(|&&b| b).count();
        if area == 0 {
            return Err(Error::degenerate(
                id,
                "region is smaller than one tile pixel; draw it larger or raise the style's resolution",
            ));
        }
        let sdf = Sdf::from_segments(&mask, &segments, to_px.inverse());
        // Boundary flow, diffused over a quarter of the region's smaller side.
        let boundary: Vec<StrokeSample> = segments
            .iter()
            .flat_map(|l| diffusion::sample_polyline(&[l.p0, l.p1], 1.0))
            .collect();
        let sigma = (w.min(h) as f64 / 4.0).max(2.0);
        let direction = diffusion::boundary_field(w, h, &boundary, sigma);
        Ok(Region {
            mask,
            sdf,
            direction,
            area,
        })
    }

    /// Combs the direction field with a stroke given as a polyline in
    /// sketch units of width `width` (sketch units): Brushables Eq. 1–3.
    pub fn comb(&mut self, polyline: &[Point], width: f64) {
        let to_px = self.sdf.to_user.inverse();
        let pts: Vec<Point> = polyline.iter().map(|&p| to_px * p).collect();
        let sigma = 0.5 * width * self.sdf.px_per_unit();
        diffusion::comb(
            &mut self.direction,
            &diffusion::sample_polyline(&pts, 0.5),
            sigma,
        );
    }

    /// Sets the direction field from combing strokes (polylines in sketch
    /// units, each with its width in sketch units): the strokes' tangents
    /// diffused over the whole region by normalized convolution (std a
    /// quarter of the grid's shorter side, as the boundary flow), then each
    /// stroke combs its own width on top ([`Region::comb`], Brushables
    /// §3.1). A combed region thus follows its strokes everywhere instead of
    /// keeping the outline's flow away from them, whose singularities (the
    /// vortex of a closed outline) a pattern with one "up", such as scales,
    /// cannot follow. Without strokes the field is left as it is.
    pub fn comb_all(&mut self, strokes: &[(&[Point], f64)]) {
        if strokes.iter().all(|(p, _)| p.len() < 2) {
            return;
        }
        let to_px = self.sdf.to_user.inverse();
        let samples: Vec<diffusion::StrokeSample> = strokes
            .iter()
            .flat_map(|(pts, _)| {
                let px: Vec<Point> = pts.iter().map(|&p| to_px * p).collect();
                diffusion::sample_polyline(&px, 1.0)
            })
            .collect();
        let (w, h) = (self.width(), self.height());
        let sigma = (w.min(h) as f64 / 4.0).max(2.0);
        self.direction = diffusion::boundary_field(w, h, &samples, sigma);
        for (pts, width) in strokes {
            self.comb(pts, *width);
        }
    }

    /// Width of the grid, pixels.
    pub fn width(&self) -> usize {
        self.mask.width()
    }

    /// Height of the grid, pixels.
    pub fn height(&self) -> usize {
        self.mask.height()
    }
}

/// Inside test at pixel centres by scanlines: crossings of each row's
/// centre line with the segments, with their winding, under `rule`.
pub fn scan_inside(w: usize, h: usize, segments: &[Line], rule: FillRule) -> Grid<bool> {
    let mut g = Grid::new(w, h, false);
    let mut xs: Vec<(f64, i32)> = Vec::new();
    for y in 0..h {
        let yc = y as f64 + 0.5;
        xs.clear();
        for l in segments {
            let (a, b) = (l.p0, l.p1);
            // Half-open in y so shared vertices count once.
            let (lo, hi, dir) = if a.y <= b.y { (a, b, 1) } else { (b, a, -1) };
            if !(lo.y <= yc && yc < hi.y) {
                continue;
            }
            let t = (yc - lo.y) / (hi.y - lo.y);
            xs.push((lo.x + t * (hi.x - lo.x), dir));
        }
        xs.sort_by(|p, q| p.0.total_cmp(&q.0));
        let mut wind = 0;
        let mut k = 0;
        for x in 0..w {
            let xc = x as f64 + 0.5;
            while k < xs.len() && xs[k].0 < xc {
                wind += xs[k].1;
                k += 1;
            }
            let inside = match rule {
                FillRule::NonZero => wind != 0,
                FillRule::EvenOdd => wind % 2 != 0,
            };
            if inside {
                g.set(x, y, true);
            }
        }
    }
    g
}

#[cfg(test)]
mod tests {
    use super::*;
    use kurbo::{Circle, Rect};

    #[test]
    fn a_ring_has_a_hole_and_exact_distances() {
        let mut p = Circle::new((50.0, 50.0), 40.0).to_path(0.01);
        // Inner circle drawn the other way round: a hole under nonzero.
        let inner = Circle::new((50.0, 50.0), 15.0).to_path(0.01);
        p.extend(inner.reverse_subpaths());
        let r = Region::rasterize("q-1", &p, FillRule::NonZero, 1.0, 4).unwrap();
        // Grid origin is (6, 6) in sketch units.
        let at = |x: f64, y: f64| r.mask.get((x - 6.0) as usize, (y - 6.0) as usize);
        assert!(at(50.0, 20.0));
        assert!(!at(50.0, 50.0));
        let d = r.sdf.value(Point::new(50.0 - 6.0 + 0.5, 20.0 - 6.0 + 0.5));
        // (50.5, 20.5) is 29.5 from the centre: 10.5 inside the outer circle.
        assert!((d - -10.5).abs() < 0.05, "{d}");
        let ring = std::f64::consts::PI * (40.0f64.powi(2) - 15.0f64.powi(2));
        assert!((r.area as f64 - ring).abs() / ring < 0.01);
    }

    #[test]
    fn even_odd_matches_kurbo_winding() {
        let mut p = Rect::new(0.0, 0.0, 30.0, 20.0).to_path(0.1);
        p.extend(Rect::new(5.0, 5.0, 12.0, 15.0).to_path(0.1));
        let mut segs = Vec::new();
        flatten_segments(&p, 0.05, &mut segs);
        let g = scan_inside(32, 22, &segs, FillRule::EvenOdd);
        for y in 0..22 {
            for x in 0..32 {
                let c = Point::new(x as f64 + 0.5, y as f64 + 0.5);
                assert_eq!(g.get(x, y), p.winding(c) % 2 != 0, "{x} {y}");
            }
        }
    }

    #[test]
    fn combing_strokes_set_the_whole_field_without_the_outlines_vortex() {
        // A 100×60 rectangle: its boundary flow circles the centre, so the
        // bottom-left corner runs roughly opposite to the top-right one.
        let p = Rect::new(0.0, 0.0, 100.0, 60.0).to_path(0.1);
        let r = Region::rasterize("q", &p, FillRule::NonZero, 1.0, 2).unwrap();
        let (a, b) = (r.direction.get(5, 55), r.direction.get(95, 5));
        assert!(a[0] * b[0] + a[1] * b[1] < 0.0, "{a:?} {b:?}");
        // A thin stroke rising at 30° across the middle (grid px = units
        // + 2).
        let (c, s) = (30f64.to_radians().cos(), -(30f64.to_radians().sin()));
        let stroke = [
            Point::new(50.0 - 30.0 * c, 30.0 - 30.0 * s),
            Point::new(50.0 + 30.0 * c, 30.0 + 30.0 * s),
        ];
        // Combing alone leaves the far edge to the boundary flow.
        let mut only = r.clone();
        only.comb(&stroke, 4.0);
        let o = only.direction.get(50, 57);
        assert!(o[0] as f64 * c + o[1] as f64 * s < 0.9, "{o:?}");
        // comb_all turns every pixel to the stroke's direction.
        let mut all = r.clone();
        all.comb_all(&[(&stroke, 4.0)]);
        for (x, y) in [(5, 55), (95, 5), (5, 5), (95, 55), (50, 30), (50, 57)] {
            let d = all.direction.get(x, y);
            let cos = d[0] as f64 * c + d[1] as f64 * s;
            assert!(cos > 0.999, "({x}, {y}): {d:?}");
        }
        // No strokes: nothing changes.
        let mut none = r.clone();
        none.comb_all(&[]);
        assert_eq!(none.direction.data(), r.direction.data());
    }

    #[test]
    fn a_speck_is_refused() {
        let p = Circle::new((5.0, 5.0), 0.2).to_path(0.01);
        let e = Region::rasterize("dot", &p, FillRule::NonZero, 1.0, 0)
            .unwrap_err()
            .to_string();
        assert!(e.contains("smaller than one tile pixel"), "{e}");
    }
}
