//! Step 1 of [`crate::outline::smooth`]: the closed paths around a binary
//! bitmap's ink, walked on the bits directly (potrace's path decomposition,
//! Selinger 2003, §2.1, with flourish's vertices and orientation).
//!
//! A path runs through the midpoints of the pixel edges between ink and
//! paper: exactly the loops of [`crate::raster::contour::extract`] on the
//! ±½ field of the bitmap (pixel centres as samples, a crossing halfway
//! along every link, saddles joining the ink), in the same order, from the
//! same first vertex and in the same direction, so the smoothing
//! downstream sees the same input (tested against `extract` on random
//! bitmaps). Instead of marching every cell of the grid into a successor
//! table and sorting it, each loop is followed from its first link through
//! the four ink flags of each cell it enters, and the scan for first links
//! skips runs of eight samples without a change of colour.

pub use crate::raster::bitmap::Bitmap;
use kurbo::Point;

/// The signed area (px²) of the pixels a closed path bounds: the shoelace
/// area of the path with each diagonal step's pixel corner put back (the
/// step cuts that corner's triangle, ⅛ px², off or on). For an island
/// that is its pixel count, holes included (potrace's path area, which its
/// speck threshold `turdsize` reads, Selinger 2003 §2.1); a hole's is
/// minus its paper pixels. Outer paths are positive, as
/// [`crate::raster::contour::signed_area`] has them.
pub fn pixel_area(path: &[Point]) -> f64 {
    let n = path.len();
    let Some(&o) = path.first() else {
        return 0.0;
    };
    // Relative to the first vertex, so the products stay small (and exact:
    // every coordinate is a multiple of ½).
    let cross = |p: Point, q: Point| (p.x - o.x) * (q.y - o.y) - (q.x - o.x) * (p.y - o.y);
    let mut twice = 0.0;
    for k in 0..n {
        let p = path[k];
        let q = path[(k + 1) % n];
        let d = q - p;
        if d.x.abs() == 0.5 && d.y.abs() == 0.5 {
            // One end is on a vertical pixel edge (whole x), the other on a
            // horizontal one (whole y): the corner takes the whole x and y.
            let c = if p.x.fract() == 0.0 {
                Point::new(p.x, q.y)
            } else {
                Point::new(q.x, p.y)
            };
            twice += cross(p, c) + cross(c, q);
        } else {
            twice += cross(p, q);
        }
    }
    0.5 * twice
}

/// A link between two 4-adjacent pixel centres (x, y) and (x + 1, y)
/// (horizontal) or (x, y + 1) (vertical), as in [`crate::raster::contour`].
#[derive(Clone, Copy, PartialEq, Eq)]
struct Link {
    horizontal: bool,
    x: i32,
    y: i32,
}

impl Link {
    /// The path vertex on the link: its midpoint, in pixel coordinates
    /// (pixel centres at half-integers).
    fn point(self) -> Point {
        let (x, y) = (self.x as f64 + 0.5, self.y as f64 + 0.5);
        if self.horizontal {
            Point::new(x + 0.5, y)
        } else {
            Point::new(x, y + 0.5)
        }
    }
}

/// `PARTNER[case][e]`: in a cell whose corners (top-left, top-right,
/// bottom-right, bottom-left) are ink as the bits of `case`, the edge where
/// a path that leaves the ink across edge `e` (clockwise) continues. A
/// saddle joins the ink (the next edge clockwise); any other cell has one
/// edge crossed from paper into ink. Entries for edges not crossed from ink
/// to paper are unused.
const PARTNER: [[u8; 4]; 16] = partner_table();

const fn partner_table() -> [[u8; 4]; 16] {
    let mut t = [[0u8; 4]; 16];
    let mut case = 0;
    while case < 16 {
        let mut e = 0;
        while e < 4 {
            t[case][e] = if case == 5 || case == 10 {
                ((e + 1) % 4) as u8
            } else {
                let mut p = e;
                let mut k = 0;
                while k < 4 {
                    let from_ink = (case >> k) & 1 == 1;
                    let to_ink = (case >> ((k + 1) % 4)) & 1 == 1;
                    if !from_ink && to_ink {
                        p = k;
                    }
                    k += 1;
                }
                p as u8
            };
            e += 1;
        }
        case += 1;
    }
    t
}

/// The closed paths around the ink of `bits` (see the module docs): outer
/// boundaries with positive signed area
/// ([`crate::raster::contour::signed_area`]), holes negative; vertices at
/// the midpoints of pixel edges, in pixel coordinates.
pub fn paths(bits: &Bitmap) -> Vec<Vec<Point>> {
    let mut out = Vec::new();
    for_each_path(bits, |p| out.push(p));
    out
}

/// [`paths`], each handed to `found` as soon as it is walked (in the same
/// order), so its processing can start while the walk goes on.
pub fn for_each_path(bits: &Bitmap, mut found: impl FnMut(Vec<Point>)) {
    let (w, h) = (bits.width(), bits.height());
    if w == 0 || h == 0 {
        return;
    }
    let pw = w + 2;
    // Horizontal links already on a path: (w + 1) per padded row. Every
    // loop crosses one, and the first of a loop in row-major order is where
    // `extract` starts it.
    let mut seen = vec![false; (w + 1) * (h + 2)];
    // A loop cannot be longer than there are links.
    let cap = 2 * (w + 1) * (h + 2) + 2 * w + 2;
    for (yi, row) in bits.padded_rows().enumerate() {
        let mut xi = 0usize;
        while xi + 1 < pw {
            // Eight links at once where nine samples in a row agree.
            if let Some(s) = row.get(xi..xi + 9) {
                let word = |s: &[u8]| {
                    let mut a = [0u8; 8];
                    a.copy_from_slice(&s[..8]);
                    u64::from_le_bytes(a)
                };
                if word(s) == word(&s[1..]) {
                    xi += 8;
                    continue;
                }
            }
            let crossed = row.get(xi) != row.get(xi + 1);
            let id = yi * (w + 1) + xi;
            if crossed && !seen.get(id).copied().unwrap_or(true) {
                let start = Link {
                    horizontal: true,
                    x: xi as i32 - 1,
                    y: yi as i32 - 1,
                };
                found(walk(bits, start, &mut seen, cap));
            }
            xi += 1;
        }
    }
}

/// Follows the loop through `start` (a crossed horizontal link) until it
/// closes, marking its horizontal links in `seen`.
///
/// The walk works on the padded flags directly: a link is kept as its
/// first pixel's (x, y) and that pixel's padded index `k`, so each of a
/// cell's four corners is one lookup at `c`, `c + 1`, `c + pw + 1` and
/// `c + pw` from its top-left corner's index `c`.
fn walk(bits: &Bitmap, start: Link, seen: &mut [bool], cap: usize) -> Vec<Point> {
    let pw = bits.width() + 2;
    let f = bits.flags();
    // Padded index of pixel (x, y), x and y from −1; out of range reads as
    // paper (a crossed link never reaches there).
    let index = |x: i32, y: i32| (y + 1) as usize * pw + (x + 1) as usize;
    let ink = |k: usize| f.get(k).is_some_and(|&v| v != 0);
    let mut pts = Vec::new();
    let (mut horizontal, mut x, mut y) = (start.horizontal, start.x, start.y);
    let mut k = index(x, y);
    loop {
        let cur = Link { horizontal, x, y };
        pts.push(cur.point());
        // The cell in which the path leaves the ink across the link
        // (clockwise), its top-left corner's index, and which of its edges
        // the link is.
        let (cx, cy, c, e) = if horizontal {
            // Horizontal links of padded row y + 1 start at (y + 1)(w + 1).
            if let Some(s) = seen.get_mut(k.wrapping_sub((y + 1) as usize)) {
                *s = true;
            }
            if ink(k) {
                (x, y, k, 0)
            } else {
                (x, y - 1, k.wrapping_sub(pw), 2)
            }
        } else if ink(k) {
            (x - 1, y, k.wrapping_sub(1), 1)
        } else {
            (x, y, k, 3)
        };
        let at = |d: usize| usize::from(ink(c.wrapping_add(d)));
        let case = at(0) | at(1) << 1 | at(pw + 1) << 2 | at(pw) << 3;
        // Edge `e` of cell (cx, cy), clockwise: top, right, bottom, left.
        (horizontal, x, y, k) = match PARTNER[case][e] {
            0 => (true, cx, cy, c),
            1 => (false, cx + 1, cy, c.wrapping_add(1)),
            2 => (true, cx, cy + 1, c.wrapping_add(pw)),
            _ => (false, cx, cy, c),
        };
        if (horizontal, x, y) == (start.horizontal, start.x, start.y) || pts.len() > cap {
            return pts;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::raster::contour;
    use crate::raster::Grid;
    use proptest::prelude::*;

    /// A random `w` × `h` bitmap, ink with probability `density` per pixel
    /// (per 5 × 3 block when `blocky`), hashed from `seed`.
    fn random_bits(w: usize, h: usize, density: f64, blocky: bool, seed: u64) -> Bitmap {
        Bitmap::from_fn(w, h, |x, y| {
            let (x, y) = if blocky { (x / 5, y / 3) } else { (x, y) };
            let mut z = seed
                ^ (x as u64).wrapping_mul(0x9e37_79b9_7f4a_7c15)
                ^ (y as u64).wrapping_mul(0xc2b2_ae3d_27d4_eb4f);
            z ^= z >> 31;
            z = z.wrapping_mul(0xbf58_476d_1ce4_e5b9);
            z ^= z >> 29;
            ((z >> 11) as f64 / (1u64 << 53) as f64) < density
        })
    }

    /// The reference: marching squares on the ±½ field.
    fn reference(bits: &Bitmap) -> Vec<Vec<Point>> {
        let values = Grid::from_fn(bits.width(), bits.height(), |x, y| {
            if bits.ink(x as isize, y as isize) {
                -0.5f32
            } else {
                0.5
            }
        });
        contour::extract(&values)
            .into_iter()
            .map(|c| c.points)
            .collect()
    }

    #[test]
    fn a_square_and_its_hole() {
        let bits = Bitmap::from_fn(7, 7, |x, y| {
            (1..6).contains(&x) && (1..6).contains(&y) && (x, y) != (3, 3)
        });
        let ps = paths(&bits);
        assert_eq!(ps, reference(&bits));
        assert_eq!(ps.len(), 2);
        assert!((contour::signed_area(&ps[0]) - (25.0 - 0.5)).abs() < 1e-12);
        assert!((contour::signed_area(&ps[1]) + 0.5).abs() < 1e-12);
        // The pixels themselves: 25 in the island, holes included, and the
        // one-pixel hole.
        assert_eq!(pixel_area(&ps[0]), 25.0);
        assert_eq!(pixel_area(&ps[1]), -1.0);
    }

    #[test]
    fn empty_and_full() {
        assert!(paths(&Bitmap::from_fn(0, 5, |_, _| true)).is_empty());
        assert!(paths(&Bitmap::from_fn(9, 4, |_, _| false)).is_empty());
        let full = Bitmap::from_fn(3, 2, |_, _| true);
        assert_eq!(paths(&full), reference(&full));
    }

    #[test]
    fn coverage_round_trip() {
        let cov = Grid::from_fn(5, 3, |x, y| ((x * 7 + y * 3) % 4) as f32 / 3.0);
        let bits = Bitmap::from_coverage(&cov);
        let back = bits.to_coverage();
        for y in 0..3 {
            for x in 0..5 {
                assert_eq!(back.get(x, y), if cov.get(x, y) >= 0.5 { 1.0 } else { 0.0 });
            }
        }
    }

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(400))]

        /// Same loops, same order, same first vertex, same direction as
        /// marching squares, on random bitmaps of every density (saddles,
        /// one-pixel lines, ink on the border, runs longer than a word).
        #[test]
        fn paths_equal_marching_squares(
            w in 1usize..40,
            h in 1usize..24,
            density in 0.05f64..0.95,
            blocky in any::<bool>(),
            seed in any::<u64>(),
        ) {
            let bits = random_bits(w, h, density, blocky, seed);
            prop_assert_eq!(paths(&bits), reference(&bits));
        }

        /// The pixel areas of all paths (holes negative) add up to the
        /// ink's pixel count, saddles and borders included; each island's
        /// is a whole number of pixels.
        #[test]
        fn pixel_areas_count_the_ink(
            w in 1usize..30,
            h in 1usize..20,
            density in 0.05f64..0.95,
            seed in any::<u64>(),
        ) {
            let bits = random_bits(w, h, density, false, seed);
            let ink = (0..w * h)
                .filter(|&i| bits.ink((i % w) as isize, (i / w) as isize))
                .count();
            let areas: Vec<f64> = paths(&bits).iter().map(|p| pixel_area(p)).collect();
            for a in &areas {
                prop_assert!(a.fract() == 0.0 && *a != 0.0, "{}", a);
            }
            prop_assert_eq!(areas.iter().sum::<f64>(), ink as f64);
        }
    }
}
