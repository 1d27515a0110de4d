//! Rotated-patch PatchMatch: for each target neighbourhood, the most similar
//! neighbourhood of any of the style's exemplars (laid out on one
//! [`Atlas`]: wrapping within a seamless tile, inside the shape of any
//! other swatch).
//!
//! * **Distance** — the sum of squared differences over all channels of a
//!   `(2r+1)²` patch (art-pattern-level-sets Eq. 6 when the channels are
//!   pre-weighted by √α and √(1−α)), with the target patch rotated by the
//!   direction difference `β = θ_s(p) − θ_t(q)` (Brushables Eq. 5): target
//!   offset `o` is compared with source offset `R(β) o`. Angles are
//!   quantized to [`ANGLE_BINS`] and the rotated offsets rounded to whole
//!   pixels (tables built once), so a comparison is a plain gather.
//! * **Search** (CaTS §4.1.2) — random search in windows halving from the
//!   exemplar's size around the current match plus one jump to any allowed
//!   centre of any exemplar, then propagation by jump flooding
//!   with steps {4, 2, 1} (neighbour `n`'s match `p_n` proposes
//!   `p_n + R(β_n)(q − n)`, the rigid map of Brushables Fig. 8).
//!
//! Every pass reads the previous field and writes a new one (Jacobi
//! order), and random numbers are hashes of (seed, pass, position), so the
//! result does not depend on the number of threads.

use super::atlas::Atlas;
use super::shape::{self, Histogram};
use crate::raster::Grid;
use crate::rng;
use rayon::prelude::*;
use std::borrow::Cow;

/// Number of quantized rotation angles.
pub const ANGLE_BINS: usize = 32;

/// A multi-channel image, channels interleaved per pixel.
#[derive(Clone, Debug, PartialEq)]
pub struct Channels {
    /// Width, pixels.
    pub width: usize,
    /// Height, pixels.
    pub height: usize,
    /// Channels per pixel.
    pub depth: usize,
    /// `width · height · depth` values, row-major.
    pub data: Vec<f32>,
}

impl Channels {
    /// The channel values of pixel `(x, y)`.
    #[inline]
    pub fn px(&self, x: usize, y: usize) -> &[f32] {
        let i = (y * self.width + x) * self.depth;
        &self.data[i..i + self.depth]
    }
}

/// One match: a tile pixel and the patch distance.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Match {
    /// Tile x, pixels.
    pub x: u32,
    /// Tile y, pixels.
    pub y: u32,
    /// Patch distance (weighted SSD).
    pub cost: f32,
}

/// The nearest-neighbour field over the patch centres `S_X`: target pixels
/// `(i·spacing, j·spacing)` (art-pattern-level-sets §2 evaluates the energy
/// on neighbourhoods `w/4` apart).
#[derive(Clone, Debug, PartialEq)]
pub struct Nnf {
    /// Centres per row.
    pub cols: usize,
    /// Rows of centres.
    pub rows: usize,
    /// Distance between centres, pixels.
    pub spacing: usize,
    /// Matches, row-major.
    pub matches: Vec<Match>,
}

impl Nnf {
    /// The target pixel of centre `k`.
    #[inline]
    pub fn centre(&self, k: usize) -> (usize, usize) {
        (
            (k % self.cols) * self.spacing,
            (k / self.cols) * self.spacing,
        )
    }

    /// Centres covering a `width`×`height` target at `spacing`.
    pub fn shape(width: usize, height: usize, spacing: usize) -> (usize, usize) {
        ((width - 1) / spacing + 1, (height - 1) / spacing + 1)
    }
}

/// Patch geometry: radius and the rotated offset tables.
#[derive(Clone, Debug)]
pub struct Patch {
    /// Radius `r`; patches are `(2r+1)²`.
    pub radius: usize,
    /// Per angle bin, per offset: `(dx, dy, rx, ry)`, the target offset and
    /// its rotation rounded to pixels.
    tables: Vec<Vec<(i32, i32, i32, i32)>>,
    /// Sine and cosine of each bin's angle.
    sin_cos: Vec<(f32, f32)>,
}

impl Patch {
    /// Tables for radius `r`.
    pub fn new(radius: usize) -> Patch {
        let r = radius as i32;
        let tables = (0..ANGLE_BINS)
            .map(|b| {
                let a = b as f64 * std::f64::consts::TAU / ANGLE_BINS as f64;
                let (s, c) = a.sin_cos();
                let mut t = Vec::new();
                for dy in -r..=r {
                    for dx in -r..=r {
                        let (fx, fy) = (dx as f64, dy as f64);
                        t.push((
                            dx,
                            dy,
                            (c * fx - s * fy).round() as i32,
                            (s * fx + c * fy).round() as i32,
                        ));
                    }
                }
                t
            })
            .collect();
        let sin_cos = (0..ANGLE_BINS)
            .map(|b| (b as f32 * std::f32::consts::TAU / ANGLE_BINS as f32).sin_cos())
            .collect();
        Patch {
            radius,
            tables,
            sin_cos,
        }
    }

    /// The offset table of angle bin `b`.
    #[inline]
    pub fn table(&self, b: usize) -> &[(i32, i32, i32, i32)] {
        &self.tables[b % ANGLE_BINS]
    }
}

/// Nearest integer, halves away from zero (a cast instead of `libm`'s
/// `round`, which would dominate the propagation step).
#[inline]
fn round(v: f32) -> i64 {
    (v + 0.5f32.copysign(v)) as i64
}

/// The angle bin of `beta` radians.
#[inline]
pub fn angle_bin(beta: f32) -> usize {
    let t = beta / std::f32::consts::TAU * ANGLE_BINS as f32;
    round(t).rem_euclid(ANGLE_BINS as i64) as usize
}

/// A level's exemplars ready to be searched: their channels and direction
/// angles laid out on the padded [`Atlas`] (see there), with the layout.
#[derive(Clone, Debug)]
pub struct Source {
    /// Where each exemplar lies.
    pub atlas: Atlas,
    /// The weighted channels over the whole atlas (margins included).
    pub channels: Channels,
    /// Direction angles (radians, pixel axes) over the whole atlas.
    pub angle: Grid<f32>,
}

impl Source {
    /// One seamless tile as a source, padded by `margin` (for tests).
    #[cfg(test)]
    pub fn tile(channels: &Channels, angle: &Grid<f32>, margin: usize) -> Source {
        let (w, h, d) = (channels.width, channels.height, channels.depth);
        let atlas = Atlas::new(vec![(w, h, true, None)], margin);
        let px = Grid::from_fn(w, h, |x, y| (x as u32, y as u32));
        let at = atlas.pad(&[&px], (0, 0));
        let mut data = Vec::with_capacity(atlas.width * atlas.height * d);
        for &(x, y) in at.data() {
            data.extend_from_slice(channels.px(x as usize, y as usize));
        }
        Source {
            channels: Channels {
                width: atlas.width,
                height: atlas.height,
                depth: d,
                data,
            },
            angle: atlas.pad(&[angle], 0.0),
            atlas,
        }
    }
}

/// The margin an atlas needs for patches of radius `r` turned by any
/// angle: `⌈r√2⌉ + 1` pixels.
pub fn patch_reach(r: usize) -> usize {
    (r as f64 * std::f64::consts::SQRT_2).ceil() as usize + 1
}

/// `sum` plus the squared differences between the gathered target patch
/// `tp` (`D` channels per pixel) and the source pixels at `base + offsets`
/// of `data`, pixel by pixel in patch order, stopping once over `bound`:
/// [`Problem::distance`]'s loop with the depth known at compile time, so
/// each pixel's channels are one unrolled run without bounds checks.
#[inline]
fn ssd<const D: usize>(
    tp: &[f32],
    data: &[f32],
    base: isize,
    offsets: &[isize],
    mut sum: f32,
    bound: f32,
) -> f32 {
    for (t, &off) in tp.chunks_exact(D).zip(offsets) {
        let i = (base + off) as usize;
        let (Some(sp), Ok(t)) = (
            data.get(i..i + D)
                .and_then(|s| <&[f32; D]>::try_from(s).ok()),
            <&[f32; D]>::try_from(t),
        ) else {
            return f32::INFINITY;
        };
        for c in 0..D {
            let e = sp[c] - t[c];
            sum += e * e;
        }
        if sum > bound {
            return sum;
        }
    }
    sum
}

/// What a search compares: the level's [`Source`] and the target with its
/// direction angles (radians, pixel axes).
#[derive(Clone, Debug)]
pub struct Problem<'a> {
    /// The exemplars.
    pub source: &'a Source,
    /// Target channels (clamped at the border).
    pub target: &'a Channels,
    /// Target direction angles.
    pub target_angle: &'a Grid<f32>,
    /// Patch geometry.
    pub patch: &'a Patch,
    gather: Cow<'a, Gather>,
    /// Every allowed patch centre of the source (for the search's jumps
    /// between exemplars).
    centres: Cow<'a, [(u32, u32)]>,
    active: Option<&'a [bool]>,
    shape: Option<ShapeTerm<'a>>,
}

/// The linear offsets of a rotated patch into an atlas's channels, per
/// angle bin: what a [`Problem`] gathers with. It depends only on the
/// atlas's width and depth and the patch radius, so it is built once and
/// shared by every search against that source ([`Problem::with_gather`]).
#[derive(Clone, Debug)]
pub struct Gather {
    /// Atlas width and depth it was built for, pixels and channels.
    dims: (usize, usize),
    /// Patch radius it was built for, pixels.
    radius: usize,
    linear: Vec<Vec<isize>>,
}

impl Gather {
    /// The offsets of `patch`'s rotation tables into `source`.
    pub fn new(source: &Source, patch: &Patch) -> Gather {
        let (pw, d) = (source.channels.width, source.channels.depth);
        let linear = (0..ANGLE_BINS)
            .map(|b| {
                patch
                    .table(b)
                    .iter()
                    .map(|&(_, _, rx, ry)| (ry as isize * pw as isize + rx as isize) * d as isize)
                    .collect()
            })
            .collect();
        Gather {
            dims: (pw, d),
            radius: patch.radius,
            linear,
        }
    }

    /// Whether this gather was built for a source of `source`'s width and
    /// depth and a patch of `patch`'s radius.
    pub fn fits(&self, source: &Source, patch: &Patch) -> bool {
        self.dims == (source.channels.width, source.channels.depth) && self.radius == patch.radius
    }
}

/// The Shape Hint term of a search (Brushables Eq. 6): `weight · χ²`
/// between the source pixel's and the target centre's descriptors, each
/// in its own direction frame (so the pair is compared rotated by Eq. 5's
/// angle).
#[derive(Clone, Copy, Debug)]
pub struct ShapeTerm<'a> {
    /// Descriptor of every source (atlas) pixel.
    pub source: &'a Grid<Histogram>,
    /// Descriptor of every target pixel.
    pub target: &'a Grid<Histogram>,
    /// Weight of χ² against the patch SSD.
    pub weight: f32,
    /// Whether the term holds where the target sees no outline too (a
    /// swatch's own edge: the interior is kept from copying it), or only
    /// near the outline (a tile's edge line, which repeats across the
    /// tile).
    pub everywhere: bool,
}

impl<'a> Problem<'a> {
    /// Sets up a search (builds the gather offsets and the centre list).
    #[cfg(test)]
    pub fn new(
        source: &'a Source,
        target: &'a Channels,
        target_angle: &'a Grid<f32>,
        patch: &'a Patch,
    ) -> Problem<'a> {
        let gather = Cow::Owned(Gather::new(source, patch));
        let centres = Cow::Owned(source.atlas.centres(patch_reach(patch.radius)));
        Problem::with(source, target, target_angle, patch, gather, centres)
    }

    /// `Problem::new` (built for tests) with the gather offsets built
    /// beforehand by [`Gather::new`]`(source, patch)` and the source's
    /// allowed centres for this patch ([`Atlas::centres`] at
    /// [`patch_reach`]), both shared by every search against one source.
    /// A `gather` of another size or radius is not used: the problem
    /// builds its own.
    pub fn with_gather(
        source: &'a Source,
        target: &'a Channels,
        target_angle: &'a Grid<f32>,
        patch: &'a Patch,
        gather: &'a Gather,
        centres: &'a [(u32, u32)],
    ) -> Problem<'a> {
        let gather = if gather.fits(source, patch) {
            Cow::Borrowed(gather)
        } else {
            Cow::Owned(Gather::new(source, patch))
        };
        Problem::with(
            source,
            target,
            target_angle,
            patch,
            gather,
            Cow::Borrowed(centres),
        )
    }

    /// The problem with its gather decided, no active mask, no shape term.
    fn with(
        source: &'a Source,
        target: &'a Channels,
        target_angle: &'a Grid<f32>,
        patch: &'a Patch,
        gather: Cow<'a, Gather>,
        centres: Cow<'a, [(u32, u32)]>,
    ) -> Problem<'a> {
        Problem {
            source,
            target,
            target_angle,
            patch,
            gather,
            centres,
            active: None,
            shape: None,
        }
    }

    /// Adds the Shape Hint term to every distance.
    pub fn with_shape(mut self, shape: ShapeTerm<'a>) -> Problem<'a> {
        self.shape = Some(shape);
        self
    }

    /// The Shape Hint cost of matching target `(qx, qy)` with source pixel
    /// `(px, py)` (0 without the term, and away from the outline unless
    /// the term holds everywhere).
    #[inline]
    pub fn shape_cost(&self, qx: usize, qy: usize, px: usize, py: usize) -> f32 {
        match &self.shape {
            Some(s) => {
                let t = s.target.get(qx, qy);
                if !s.everywhere && shape::is_empty(&t) {
                    0.0
                } else {
                    s.weight * shape::chi2(&s.source.get(px, py), &t)
                }
            }
            None => 0.0,
        }
    }

    /// Restricts the search to the centres flagged in `active` (one flag
    /// per centre of the field); the others keep their match and cost.
    pub fn with_active(mut self, active: &'a [bool]) -> Problem<'a> {
        self.active = Some(active);
        self
    }

    /// Whether centre `k` is searched.
    #[inline]
    pub fn is_active(&self, k: usize) -> bool {
        match self.active {
            Some(a) => a.get(k).copied().unwrap_or(true),
            None => true,
        }
    }

    /// The rotation bin between source pixel `(px, py)` and target `(qx, qy)`.
    #[inline]
    pub fn bin(&self, px: usize, py: usize, qx: usize, qy: usize) -> usize {
        angle_bin(self.source.angle.get(px, py) - self.target_angle.get(qx, qy))
    }

    /// The source position (atlas pixels, not yet brought into its
    /// exemplar) that target pixel `(qx + dx, qy + dy)` maps to under the
    /// match `(px, py)` of centre `(qx, qy)`.
    #[inline]
    pub fn map(&self, qx: usize, qy: usize, px: usize, py: usize, dx: i32, dy: i32) -> (i64, i64) {
        let (s, c) = self.patch.sin_cos[self.bin(px, py, qx, qy)];
        let (fx, fy) = (dx as f32, dy as f32);
        let rx = round(c * fx - s * fy);
        let ry = round(s * fx + c * fy);
        (px as i64 + rx, py as i64 + ry)
    }

    /// Atlas position `(x, y)` proposed from the match `from` as a patch
    /// centre of `from`'s exemplar (wrapped in a tile, clamped inside a
    /// swatch), or `None` when the swatch's shape does not allow it.
    #[inline]
    fn bring(&self, from: (u32, u32), x: i64, y: i64) -> Option<(usize, usize)> {
        let atlas = &self.source.atlas;
        let b = atlas.block_of(from.1 as usize);
        let (px, py) = atlas.bring_in(b, x, y, patch_reach(self.patch.radius));
        atlas.allowed(px, py).then_some((px as usize, py as usize))
    }

    /// Gathers the target patch at `(qx, qy)` (clamped at the border).
    pub fn target_patch(&self, qx: usize, qy: usize, out: &mut Vec<f32>) {
        out.clear();
        let t = self.target;
        let d = t.depth;
        let r = self.patch.radius as i64;
        let (x0, x1) = (qx as i64 - r, qx as i64 + r);
        let inside_x = x0 >= 0 && x1 < t.width as i64;
        for dy in -r..=r {
            let y = (qy as i64 + dy).clamp(0, t.height as i64 - 1) as usize;
            if inside_x {
                // One contiguous run of the row.
                let a = (y * t.width + x0 as usize) * d;
                out.extend_from_slice(&t.data[a..a + (2 * r as usize + 1) * d]);
            } else {
                for x in x0..=x1 {
                    let x = x.clamp(0, t.width as i64 - 1) as usize;
                    out.extend_from_slice(t.px(x, y));
                }
            }
        }
    }

    /// Distance between the gathered target patch of `(qx, qy)` and source
    /// pixel `(px, py)` (an allowed centre), plus the Shape Hint cost;
    /// stops early once over `bound`.
    pub fn distance(
        &self,
        tp: &[f32],
        qx: usize,
        qy: usize,
        px: usize,
        py: usize,
        bound: f32,
    ) -> f32 {
        let src = &self.source.channels;
        let d = src.depth;
        let offsets = &self.gather.linear[self.bin(px, py, qx, qy)];
        let base = ((py * src.width + px) * d) as isize;
        let mut sum = self.shape_cost(qx, qy, px, py);
        if sum > bound {
            return sum;
        }
        match d {
            4 => ssd::<4>(tp, &src.data, base, offsets, sum, bound),
            5 => ssd::<5>(tp, &src.data, base, offsets, sum, bound),
            6 => ssd::<6>(tp, &src.data, base, offsets, sum, bound),
            7 => ssd::<7>(tp, &src.data, base, offsets, sum, bound),
            _ => {
                for (t, &off) in tp.chunks_exact(d).zip(offsets) {
                    let i = (base + off) as usize;
                    for (a, b) in src.data[i..i + d].iter().zip(t) {
                        let e = a - b;
                        sum += e * e;
                    }
                    if sum > bound {
                        return sum;
                    }
                }
                sum
            }
        }
    }

    /// Recomputes every match's cost against the current target.
    pub fn refresh(&self, nnf: &mut Nnf) {
        nnf.matches = self.each_active(nnf, &nnf.matches, |buf, _k, (qx, qy), m| {
            self.target_patch(qx, qy, buf);
            Match {
                cost: self.distance(buf, qx, qy, m.x as usize, m.y as usize, f32::INFINITY),
                ..m
            }
        });
    }

    /// Maps every active match through `step` in parallel, in index order
    /// (so the result does not depend on the thread count); inactive
    /// matches are kept. `step` gets a reusable patch buffer, the match's
    /// index, its centre on the target (px) and the match.
    fn each_active<F>(&self, shape: &Nnf, matches: &[Match], step: F) -> Vec<Match>
    where
        F: Fn(&mut Vec<f32>, usize, (usize, usize), Match) -> Match + Sync,
    {
        (0..matches.len())
            .into_par_iter()
            .map_init(Vec::new, |buf, k| {
                let m = matches[k];
                if self.is_active(k) {
                    step(buf, k, shape.centre(k), m)
                } else {
                    m
                }
            })
            .collect()
    }

    /// Replaces `best` by source pixel `(px, py)` when that patch is closer
    /// to the gathered target patch `tp` centred at `(qx, qy)`.
    fn try_candidate(
        &self,
        tp: &[f32],
        (qx, qy): (usize, usize),
        (px, py): (usize, usize),
        best: &mut Match,
    ) {
        let c = self.distance(tp, qx, qy, px, py, best.cost);
        if c < best.cost {
            *best = Match {
                x: px as u32,
                y: py as u32,
                cost: c,
            };
        }
    }

    /// One PatchMatch round: random search, then jump-flooding propagation.
    /// Costs must be current (see [`Problem::refresh`]).
    pub fn improve(&self, nnf: &mut Nnf, seed: u64, round: u64) {
        let atlas = &self.source.atlas;
        // Random search (CaTS Alg. 5, windows halving from the exemplar's
        // size), and one jump to any allowed centre of any exemplar, so
        // the energy can move a neighbourhood to another exemplar.
        nnf.matches = self.each_active(nnf, &nnf.matches, |buf, k, q, mut best| {
            self.target_patch(q.0, q.1, buf);
            let (cx, cy) = Atlas::pick(&self.centres, &[seed, round, k as u64, 0x7A3F]);
            self.try_candidate(buf, q, (cx as usize, cy as usize), &mut best);
            let bl = &atlas.blocks[atlas.block_of(best.y as usize)];
            let mut radius = bl.w.max(bl.h) as i64 / 2;
            let mut i = 0u64;
            while radius >= 1 {
                let span = 2 * radius as usize + 1;
                let draw =
                    |axis| rng::index(&[seed, round, k as u64, i, axis], span) as i64 - radius;
                let (ox, oy) = (draw(0), draw(1));
                let from = (best.x, best.y);
                if let Some(p) = self.bring(from, best.x as i64 + ox, best.y as i64 + oy) {
                    self.try_candidate(buf, q, p, &mut best);
                }
                radius /= 2;
                i += 1;
            }
            best
        });
        // Propagation by jump flooding (CaTS Alg. 6). A proposal that is
        // the centre's match from before this round, or one another
        // neighbour already proposed in this pass, was scored against a
        // best at least as high as the current one and lost (or is the
        // best): scoring it again cannot change the match.
        let before = nnf.matches.clone();
        for step in [4usize, 2, 1] {
            nnf.matches = self.each_active(nnf, &nnf.matches, |buf, k, q, mut best| {
                let (i, j) = (k % nnf.cols, k / nnf.cols);
                let mut gathered = false;
                let mut tried = [(before[k].x as usize, before[k].y as usize); 5];
                let mut n_tried = 1;
                let neighbours = [
                    (i.checked_sub(step), Some(j)),
                    (Some(i + step).filter(|&v| v < nnf.cols), Some(j)),
                    (Some(i), j.checked_sub(step)),
                    (Some(i), Some(j + step).filter(|&v| v < nnf.rows)),
                ];
                for (ni, nj) in neighbours {
                    let (Some(ni), Some(nj)) = (ni, nj) else {
                        continue;
                    };
                    let n = nnf.matches[nj * nnf.cols + ni];
                    let (nx, ny) = (ni * nnf.spacing, nj * nnf.spacing);
                    let dx = q.0 as i32 - nx as i32;
                    let dy = q.1 as i32 - ny as i32;
                    let (mx, my) = self.map(nx, ny, n.x as usize, n.y as usize, dx, dy);
                    let Some(p) = self.bring((n.x, n.y), mx, my) else {
                        continue;
                    };
                    if p == (best.x as usize, best.y as usize) || tried[..n_tried].contains(&p) {
                        continue;
                    }
                    tried[n_tried] = p;
                    n_tried += 1;
                    if !gathered {
                        self.target_patch(q.0, q.1, buf);
                        gathered = true;
                    }
                    self.try_candidate(buf, q, p, &mut best);
                }
                best
            });
        }
    }

    /// The exact nearest allowed source centre of `(qx, qy)` by exhaustive
    /// search (first minimum in centre order): the reference for tests.
    #[cfg(test)]
    pub fn brute_force(&self, qx: usize, qy: usize) -> Match {
        let mut buf = Vec::new();
        self.target_patch(qx, qy, &mut buf);
        let mut best = Match {
            x: 0,
            y: 0,
            cost: f32::INFINITY,
        };
        for &(px, py) in self.centres.iter() {
            self.try_candidate(&buf, (qx, qy), (px as usize, py as usize), &mut best);
        }
        best
    }
}

/// A field of matches seeded at random among the allowed centres of
/// `source` (hash of seed and centre).
#[cfg(test)]
pub fn random_nnf(width: usize, height: usize, spacing: usize, source: &Source, seed: u64) -> Nnf {
    let (cols, rows) = Nnf::shape(width, height, spacing);
    let centres = source.atlas.centres(source.atlas.margin);
    let matches = (0..cols * rows)
        .map(|k| {
            let (x, y) = Atlas::pick(&centres, &[seed, 0x5EED, k as u64]);
            Match {
                x,
                y,
                cost: f32::INFINITY,
            }
        })
        .collect();
    Nnf {
        cols,
        rows,
        spacing,
        matches,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn noise(w: usize, h: usize, d: usize, seed: u64) -> Channels {
        Channels {
            width: w,
            height: h,
            depth: d,
            data: (0..w * h * d)
                .map(|i| rng::unit(&[seed, i as u64]) as f32)
                .collect(),
        }
    }

    #[test]
    fn finds_the_exact_match_of_a_copy() {
        // Target: a 40×30 window of a 32×32 noise tile, starting at (5, 9),
        // wrapping. Every centre's exact match is its own source pixel.
        let src = noise(32, 32, 3, 1);
        let (w, h) = (40, 30);
        let mut data = Vec::new();
        for y in 0..h {
            for x in 0..w {
                data.extend_from_slice(src.px((x + 5) % 32, (y + 9) % 32));
            }
        }
        let tgt = Channels {
            width: w,
            height: h,
            depth: 3,
            data,
        };
        let zero_s = Grid::new(32, 32, 0.0);
        let zero_t = Grid::new(w, h, 0.0);
        let patch = Patch::new(3);
        let margin = patch_reach(3);
        let source = Source::tile(&src, &zero_s, margin);
        let pb = Problem::new(&source, &tgt, &zero_t, &patch);
        let mut nnf = random_nnf(w, h, 2, &source, 7);
        pb.refresh(&mut nnf);
        for round in 0..6 {
            pb.improve(&mut nnf, 7, round);
        }
        let mut exact = 0;
        for k in 0..nnf.matches.len() {
            let (qx, qy) = nnf.centre(k);
            // Border centres see clamped pixels: only interior ones count.
            if qx < 3 || qy < 3 || qx + 3 >= w || qy + 3 >= h {
                continue;
            }
            let m = nnf.matches[k];
            let bf = pb.brute_force(qx, qy);
            assert_eq!(
                (bf.x, bf.y),
                (
                    ((qx + 5) % 32 + margin) as u32,
                    ((qy + 9) % 32 + margin) as u32
                )
            );
            assert_eq!(bf.cost, 0.0);
            if (m.x, m.y) == (bf.x, bf.y) {
                exact += 1;
            }
        }
        let interior = (0..nnf.matches.len())
            .filter(|&k| {
                let (qx, qy) = nnf.centre(k);
                !(qx < 3 || qy < 3 || qx + 3 >= w || qy + 3 >= h)
            })
            .count();
        assert_eq!(exact, interior, "{exact} of {interior} exact");
    }

    #[test]
    fn rotation_tables_turn_offsets() {
        let p = Patch::new(2);
        // A quarter turn (bin 8 of 32) maps (1, 0) to (0, 1).
        let t = p.table(8);
        let e = t.iter().find(|e| (e.0, e.1) == (1, 0)).unwrap();
        assert_eq!((e.2, e.3), (0, 1));
        assert_eq!(angle_bin(std::f32::consts::FRAC_PI_2), 8);
        assert_eq!(angle_bin(-std::f32::consts::FRAC_PI_2), 24);
    }

    #[test]
    fn a_rotated_copy_is_found_with_its_rotation() {
        // Source angle 0, target angle −90°: β = +90°; target patch offsets
        // (dx, dy) read tile offsets (−dy, dx). Build the target that way.
        let src = noise(24, 24, 2, 3);
        let (w, h) = (20, 20);
        let (cx, cy) = (10i64, 10i64);
        let mut data = Vec::new();
        for y in 0..h as i64 {
            for x in 0..w as i64 {
                let (dx, dy) = (x - cx, y - cy);
                let sx = (7 - dy).rem_euclid(24) as usize;
                let sy = (4 + dx).rem_euclid(24) as usize;
                data.extend_from_slice(src.px(sx, sy));
            }
        }
        let tgt = Channels {
            width: w,
            height: h,
            depth: 2,
            data,
        };
        let sa = Grid::new(24, 24, 0.0);
        let ta = Grid::new(w, h, -std::f32::consts::FRAC_PI_2);
        let patch = Patch::new(2);
        let m = patch_reach(2) as u32;
        let source = Source::tile(&src, &sa, m as usize);
        let pb = Problem::new(&source, &tgt, &ta, &patch);
        let bf = pb.brute_force(10, 10);
        assert_eq!((bf.x, bf.y, bf.cost), (7 + m, 4 + m, 0.0));
    }
}
