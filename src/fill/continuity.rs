//! How continuous a synthesized pattern is: the ends of its bands.
//!
//! A band pattern such as an interlace knot has no band ends in its tile;
//! every place where a synthesized band stops is a tear (art-pattern-level-
//! sets §1: patch synthesis "breaks" curvilinear features, level sets keep
//! them). The ink is thinned to a one-pixel skeleton (Zhang & Suen 1984)
//! and the skeleton's end points are counted, leaving out the short spurs
//! that thinning grows from bumps of an edge (a branch that meets a
//! junction within `min_branch` pixels).

use crate::raster::Grid;

pub use crate::raster::skeleton::skeleton;
use crate::raster::skeleton::RING;

/// The 8 neighbours of `(x, y)` (P2…P9), outside the grid false.
fn ring(g: &Grid<bool>, x: usize, y: usize) -> [bool; 8] {
    RING.map(|(dx, dy)| g.get_or(x as isize + dx, y as isize + dy, false))
}

/// The branches leaving a skeleton pixel: the number of runs of skeleton
/// pixels around it (0→1 transitions of its ring), 0 when it is alone.
/// An end point has one, a line pixel two, a junction three or more.
fn degree(s: &Grid<bool>, x: usize, y: usize) -> usize {
    let p = ring(s, x, y);
    let runs = (0..8).filter(|&i| !p[i] && p[(i + 1) % 8]).count();
    if runs == 0 && p.iter().any(|&v| v) {
        // Surrounded: inside a clump, not an end.
        8
    } else {
        runs
    }
}

/// The skeleton of `ink` pruned `min_branch` times (each time every end
/// point is removed), which deletes the spurs thinning grows from bumps of
/// an edge and the forks it leaves at square band ends, and shortens every
/// real branch by as much. Also returns the ends of the short pieces that
/// pruning took whole (two per piece) at pixels where `counted` is true.
fn pruned(ink: &Grid<bool>, counted: &Grid<bool>, min_branch: usize) -> (Grid<bool>, usize) {
    let mut s = skeleton(ink);
    let (w, h) = (s.width(), s.height());
    let at = |x: usize, y: usize| counted.get_or(x as isize, y as isize, false);
    let mut ends = 0;
    for _ in 0..min_branch {
        let mut del = Vec::new();
        for y in 0..h {
            for x in 0..w {
                if !s.get(x, y) {
                    continue;
                }
                match degree(&s, x, y) {
                    0 => {
                        ends += 2 * usize::from(at(x, y));
                        del.push((x, y));
                    }
                    1 => {
                        // The last two pixels of a short piece go together.
                        let lone = RING.iter().any(|&(dx, dy)| {
                            let (nx, ny) = (x as isize + dx, y as isize + dy);
                            s.get_or(nx, ny, false) && degree(&s, nx as usize, ny as usize) == 1
                        });
                        ends += usize::from(lone && at(x, y));
                        del.push((x, y));
                    }
                    _ => {}
                }
            }
        }
        for (x, y) in del {
            s.set(x, y, false);
        }
    }
    (s, ends)
}

/// Band ends of `ink` at pixels where `counted` is true: the end points of
/// the skeleton pruned `min_branch` times (see `pruned`), an isolated
/// pixel counting as two, plus the short pieces pruning took whole.
pub fn band_ends(ink: &Grid<bool>, counted: &Grid<bool>, min_branch: usize) -> usize {
    let (s, mut ends) = pruned(ink, counted, min_branch);
    for y in 0..s.height() {
        for x in 0..s.width() {
            if s.get(x, y) && counted.get(x, y) {
                ends += match degree(&s, x, y) {
                    0 => 2,
                    1 => 1,
                    _ => 0,
                };
            }
        }
    }
    ends
}

/// Branchings of `ink` at pixels where `counted` is true: 8-connected
/// clusters of junction pixels (three or more branches) of the skeleton
/// pruned `min_branch` times. A band that forks, or two bands fused where
/// one should pass under the other, makes one.
pub fn junctions(ink: &Grid<bool>, counted: &Grid<bool>, min_branch: usize) -> usize {
    let (s, _) = pruned(ink, counted, min_branch);
    let j = Grid::from_fn(s.width(), s.height(), |x, y| {
        s.get(x, y) && degree(&s, x, y) >= 3 && degree(&s, x, y) < 8
    });
    components(&j, counted)
}

/// One 8-connected component of a binary image.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Piece {
    /// Area, pixels.
    pub area: usize,
    /// Whether some pixel of it is counted.
    pub touches: bool,
    /// Whether every pixel of it is counted.
    pub within: bool,
}

/// The 8-connected components of `ink`, in scan order of their first
/// pixel, with how they lie relative to `counted`.
pub fn pieces(ink: &Grid<bool>, counted: &Grid<bool>) -> Vec<Piece> {
    let (w, h) = (ink.width(), ink.height());
    let mut seen = Grid::new(w, h, false);
    let mut out = Vec::new();
    let mut stack = Vec::new();
    for y0 in 0..h {
        for x0 in 0..w {
            if !ink.get(x0, y0) || seen.get(x0, y0) {
                continue;
            }
            let mut p = Piece {
                area: 0,
                touches: false,
                within: true,
            };
            seen.set(x0, y0, true);
            stack.push((x0, y0));
            while let Some((x, y)) = stack.pop() {
                let c = counted.get_or(x as isize, y as isize, false);
                p.touches |= c;
                p.within &= c;
                p.area += 1;
                for (dx, dy) in RING {
                    let (nx, ny) = (x as isize + dx, y as isize + dy);
                    if ink.get_or(nx, ny, false) && !seen.get(nx as usize, ny as usize) {
                        seen.set(nx as usize, ny as usize, true);
                        stack.push((nx as usize, ny as usize));
                    }
                }
            }
            out.push(p);
        }
    }
    out
}

/// Number of 8-connected components of `ink` that reach a pixel where
/// `counted` is true.
pub fn components(ink: &Grid<bool>, counted: &Grid<bool>) -> usize {
    pieces(ink, counted).iter().filter(|p| p.touches).count()
}

/// Regularity of the gaps of a lattice pattern: the fraction of the
/// `paper` pieces lying wholly where `counted` is true whose area is
/// within a factor `k` of `reference` (the tile's median gap, pixels).
/// A torn weave merges gaps into large irregular ones and leaves slivers;
/// 0 when no gap lies wholly inside.
pub fn regular_gaps(paper: &Grid<bool>, counted: &Grid<bool>, reference: f64, k: f64) -> f64 {
    let inner: Vec<Piece> = pieces(paper, counted)
        .into_iter()
        .filter(|p| p.within)
        .collect();
    let ok = inner
        .iter()
        .filter(|p| (p.area as f64) >= reference / k && (p.area as f64) <= reference * k)
        .count();
    if inner.is_empty() {
        0.0
    } else {
        ok as f64 / inner.len() as f64
    }
}

/// The median area of the gaps of a periodic tile's `paper` (measured on
/// its 3×3 repetition, the pieces of the centre copy that do not reach
/// the repetition's edge), pixels; 0 when there is none.
pub fn tile_gap_area(paper: &Grid<bool>) -> f64 {
    let (w, h) = (paper.width(), paper.height());
    let rep = Grid::from_fn(3 * w, 3 * h, |x, y| paper.get(x % w, y % h));
    let inner = Grid::from_fn(3 * w, 3 * h, |x, y| {
        x > 0 && y > 0 && x + 1 < 3 * w && y + 1 < 3 * h
    });
    let centre = Grid::from_fn(3 * w, 3 * h, |x, y| {
        (w..2 * w).contains(&x) && (h..2 * h).contains(&y)
    });
    let mut areas: Vec<usize> = pieces(&rep, &inner)
        .into_iter()
        .zip(pieces(&rep, &centre))
        .filter(|(a, c)| a.within && c.touches)
        .map(|(a, _)| a.area)
        .collect();
    areas.sort_unstable();
    areas.get(areas.len() / 2).map_or(0.0, |&a| a as f64)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn all(w: usize, h: usize) -> Grid<bool> {
        Grid::new(w, h, true)
    }

    #[test]
    fn a_bar_has_two_ends_and_a_ring_none() {
        let bar = Grid::from_fn(40, 20, |x, y| (5..35).contains(&x) && (8..13).contains(&y));
        assert_eq!(band_ends(&bar, &all(40, 20), 3), 2);
        let ring = Grid::from_fn(40, 40, |x, y| {
            let r = (x as f32 - 19.5).hypot(y as f32 - 19.5);
            (10.0..15.0).contains(&r)
        });
        assert_eq!(band_ends(&ring, &all(40, 40), 3), 0);
        assert_eq!(components(&ring, &all(40, 40)), 1);
        assert_eq!(junctions(&ring, &all(40, 40), 3), 0);
    }

    #[test]
    fn a_plus_has_four_ends_and_a_broken_band_two_more() {
        let plus = Grid::from_fn(41, 41, |x, y| {
            ((4..37).contains(&x) && (18..23).contains(&y))
                || ((4..37).contains(&y) && (18..23).contains(&x))
        });
        assert_eq!(band_ends(&plus, &all(41, 41), 3), 4);
        assert_eq!(junctions(&plus, &all(41, 41), 3), 1);
        // A gap in one arm: two more ends, one more component.
        let broken = Grid::from_fn(41, 41, |x, y| plus.get(x, y) && !(28..31).contains(&x));
        assert_eq!(band_ends(&broken, &all(41, 41), 3), 6);
        assert_eq!(components(&broken, &all(41, 41)), 2);
        // Counting only the left half sees one end.
        let left = Grid::from_fn(41, 41, |x, _| x < 12);
        assert_eq!(band_ends(&plus, &left, 3), 1);
    }

    #[test]
    fn bumps_on_an_edge_are_not_ends() {
        // A band with one-pixel bumps every 6 px along its top edge.
        let g = Grid::from_fn(60, 20, |x, y| {
            (2..58).contains(&x) && ((8..14).contains(&y) || (y == 7 && x % 6 == 0))
        });
        assert_eq!(band_ends(&g, &all(60, 20), 4), 2);
    }
}
