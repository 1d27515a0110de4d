//! Level set to closed contours: marching squares on a sampled field.
//!
//! Samples sit at pixel centres; a sample is inside when its value is
//! negative. The grid is padded with outside samples so every contour
//! closes. A contour vertex lies on a *link* (the segment between two
//! 4-adjacent samples of opposite sign) at the linear interpolation of the
//! two values, which is exact for a signed distance field near a straight
//! boundary. Saddle cells are resolved by the value at the cell centre (the
//! mean of its four corners; a tie joins the ink, so binary diagonal lines
//! stay connected), the same way in every cell, so the topology is
//! consistent. Each crossed link is entered once and left once, so the
//! segments chain into disjoint closed loops with ink on a fixed side:
//! outer boundaries have positive signed area, holes negative.

use crate::raster::Grid;
use kurbo::Point;

/// A link between two 4-adjacent samples, in padded coordinates.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub struct Link {
    /// True for a horizontal link `(x, y)`–`(x + 1, y)`, false for a vertical
    /// link `(x, y)`–`(x, y + 1)`.
    pub horizontal: bool,
    /// Sample column of the first end (may be −1 in the padding).
    pub x: i32,
    /// Sample row of the first end (may be −1 in the padding).
    pub y: i32,
}

impl Link {
    /// The four links around the cell whose top-left sample is `(x, y)`,
    /// clockwise (y down) from its top: top, right, bottom, left.
    pub fn around(x: i32, y: i32) -> [Link; 4] {
        [
            Link {
                horizontal: true,
                x,
                y,
            },
            Link {
                horizontal: false,
                x: x + 1,
                y,
            },
            Link {
                horizontal: true,
                x,
                y: y + 1,
            },
            Link {
                horizontal: false,
                x,
                y,
            },
        ]
    }

    /// The two samples the link joins (first, second), unpadded coordinates.
    pub fn ends(self) -> ((i32, i32), (i32, i32)) {
        if self.horizontal {
            ((self.x, self.y), (self.x + 1, self.y))
        } else {
            ((self.x, self.y), (self.x, self.y + 1))
        }
    }

    /// The point at fraction `t` from the first end to the second, in pixel
    /// coordinates (pixel centres at half-integers).
    pub fn point(self, t: f64) -> Point {
        let (x, y) = (self.x as f64 + 0.5, self.y as f64 + 0.5);
        if self.horizontal {
            Point::new(x + t, y)
        } else {
            Point::new(x, y + t)
        }
    }

    /// The unit direction from the first end to the second.
    pub fn direction(self) -> kurbo::Vec2 {
        if self.horizontal {
            kurbo::Vec2::new(1.0, 0.0)
        } else {
            kurbo::Vec2::new(0.0, 1.0)
        }
    }
}

/// One closed contour: the links it crosses, in order, with the crossing
/// points in pixel coordinates.
#[derive(Clone, Debug, PartialEq)]
pub struct Contour {
    /// The crossed links, in traversal order.
    pub links: Vec<Link>,
    /// The crossing point on each link, in pixel coordinates.
    pub points: Vec<Point>,
}

impl Contour {
    /// Signed area (shoelace) in px²: positive for outer boundaries,
    /// negative for holes.
    pub fn signed_area(&self) -> f64 {
        signed_area(&self.points)
    }
}

/// Cumulative arc lengths (px) round a closed polygon: `cum[i]` to vertex
/// `i`, `cum[n]` the whole loop (the closing edge included).
pub fn closed_arc_lengths(points: &[Point]) -> Vec<f64> {
    let mut cum = Vec::with_capacity(points.len() + 1);
    let mut s = 0.0;
    cum.push(0.0);
    for (p, q) in points.iter().zip(points.iter().cycle().skip(1)) {
        s += (*q - *p).hypot();
        cum.push(s);
    }
    cum
}

/// Cumulative arc lengths (px, or the points' units) along an open
/// polyline: `cum[i]` to vertex `i`, `cum[0] = 0`.
pub fn open_arc_lengths(points: &[Point]) -> Vec<f64> {
    let mut cum = Vec::with_capacity(points.len());
    let mut s = 0.0;
    for (i, p) in points.iter().enumerate() {
        if i > 0 {
            s += (*p - points[i - 1]).hypot();
        }
        cum.push(s);
    }
    cum
}

/// `x` brought into `0..period` by adding or subtracting one period: the
/// same number as `x.rem_euclid(period)` for `x` in `−period..2·period`
/// (both add exactly `period` below zero, and from `period` up to twice
/// it the difference is exact), without the division.
pub fn wrap_once(x: f64, period: f64) -> f64 {
    if x < 0.0 {
        if x == -period {
            // What `rem_euclid` gives: the remainder's sign, zero.
            return -0.0;
        }
        x + period
    } else if x >= period {
        x - period
    } else {
        x
    }
}

/// Shoelace signed area of a closed polygon.
pub fn signed_area(points: &[Point]) -> f64 {
    let n = points.len();
    let mut a = 0.0;
    for i in 0..n {
        let p = points[i];
        let q = points[(i + 1) % n];
        a += p.x * q.y - q.x * p.y;
    }
    0.5 * a
}

/// Dense index of links in the padded grid.
struct LinkIndex {
    w: i32,
    h: i32,
}

impl LinkIndex {
    // Padded samples run over x in -1..=w, y in -1..=h.
    fn id(&self, l: Link) -> usize {
        let (w, h) = (self.w as usize, self.h as usize);
        let (x, y) = ((l.x + 1) as usize, (l.y + 1) as usize);
        if l.horizontal {
            y * (w + 1) + x
        } else {
            (w + 1) * (h + 2) + y * (w + 2) + x
        }
    }

    fn link(&self, id: usize) -> Link {
        let (w, h) = (self.w as usize, self.h as usize);
        let hcount = (w + 1) * (h + 2);
        if id < hcount {
            Link {
                horizontal: true,
                x: (id % (w + 1)) as i32 - 1,
                y: (id / (w + 1)) as i32 - 1,
            }
        } else {
            let id = id - hcount;
            Link {
                horizontal: false,
                x: (id % (w + 2)) as i32 - 1,
                y: (id / (w + 2)) as i32 - 1,
            }
        }
    }
}

/// Extracts the closed contours of `{v < 0}`. Samples beyond the grid count
/// as outside, and a crossing into the padding is placed on the canvas
/// border. Vertices are kept strictly inside their links (at least 0.001 px
/// from either sample) so no two vertices coincide and no edge has zero
/// length.
pub fn extract(values: &Grid<f32>) -> Vec<Contour> {
    let (w, h) = (values.width() as i32, values.height() as i32);
    if w == 0 || h == 0 {
        return Vec::new();
    }
    let index = LinkIndex { w, h };
    // Inside flags with a one-sample border of outside, so each cell's four
    // corners are plain lookups (x, y from -1).
    let pw = w as usize + 2;
    let mut padded = vec![0u8; pw * (h as usize + 2)];
    for (y, row) in values.data().chunks(w as usize).enumerate() {
        let start = (y + 1) * pw + 1;
        for (flag, &v) in padded[start..start + row.len()].iter_mut().zip(row) {
            *flag = u8::from(v < 0.0);
        }
    }
    // Each crossed link with its successor's id: only the outline's links,
    // a few bytes each, not a table over every link of the grid.
    let mut next: Vec<(usize, usize)> = Vec::new();
    // Cells are indexed by their top-left sample (x, y), x in -1..w, y in -1..h.
    let rows = padded.chunks(pw).zip(padded.chunks(pw).skip(1));
    for (yi, (top, bottom)) in rows.enumerate() {
        let y = yi as i32 - 1;
        let mut xi = 0usize;
        while xi + 1 < pw {
            // Eight cells at once where their nine samples in both rows
            // are all inside or all outside (most of a drawing).
            if let (Some(t), Some(b)) = (top.get(xi..xi + 9), bottom.get(xi..xi + 9)) {
                let word = |s: &[u8]| {
                    let mut a = [0u8; 8];
                    a.copy_from_slice(&s[..8]);
                    u64::from_le_bytes(a)
                };
                let (t0, t1, b0, b1) = (word(t), word(&t[1..]), word(b), word(&b[1..]));
                if t0 == t1 && t0 == b0 && t0 == b1 && (t0 == 0 || t0 == 0x0101_0101_0101_0101) {
                    xi += 8;
                    continue;
                }
            }
            let x = xi as i32 - 1;
            let a = top[xi] != 0;
            let b = top[xi + 1] != 0;
            let c = bottom[xi + 1] != 0;
            let d = bottom[xi] != 0;
            xi += 1;
            let case = (a as u8) | (b as u8) << 1 | (c as u8) << 2 | (d as u8) << 3;
            if case == 0 || case == 15 {
                continue;
            }
            // Cell edges in clockwise order (y down): top a→b, right b→c,
            // bottom c→d, left d→a.
            let edges = Link::around(x, y);
            let corner = [a, b, c, d];
            let saddle = case == 5 || case == 10;
            let centre_inside = saddle && {
                let v = |x: i32, y: i32| values.get_or(x as isize, y as isize, 1.0);
                // A tie joins the ink: one-pixel diagonal runs in binary
                // art are lines, not beads (potrace's "minority" policy
                // for dark-on-light art).
                (v(x, y) + v(x + 1, y) + v(x + 1, y + 1) + v(x, y + 1)) <= 0.0
            };
            // A segment runs from an edge crossed inside→outside (clockwise)
            // to the out→in edge that bounds the same region of the cell.
            for e in 0..4 {
                let (from, to) = (corner[e], corner[(e + 1) % 4]);
                if !from || to {
                    continue;
                }
                let partner = if saddle {
                    if centre_inside {
                        (e + 1) % 4
                    } else {
                        (e + 3) % 4
                    }
                } else {
                    // The single out→in edge of the cell.
                    (0..4)
                        .find(|&k| !corner[k] && corner[(k + 1) % 4])
                        .unwrap_or(e)
                };
                next.push((index.id(edges[e]), index.id(edges[partner])));
            }
        }
    }
    // Walked in id order, as a sweep over all links would; a link is
    // crossed by one segment at most, so each id appears once.
    next.sort_unstable();
    let mut seen = vec![false; next.len()];
    let find = |id: usize| next.binary_search_by_key(&id, |&(l, _)| l).ok();
    let mut contours = Vec::new();
    for first in 0..next.len() {
        if seen[first] {
            continue;
        }
        let mut links = Vec::new();
        let mut at = Some(first);
        while let Some(i) = at.filter(|&i| !seen[i]) {
            seen[i] = true;
            let (id, succ) = next[i];
            links.push(index.link(id));
            at = find(succ);
        }
        let points = links.iter().map(|&l| crossing(values, l)).collect();
        contours.push(Contour { links, points });
    }
    contours
}

/// The crossing point of the zero level on link `l` by linear interpolation,
/// clamped into the link's interior; crossings into the padding lie on the
/// canvas border.
pub fn crossing(values: &Grid<f32>, l: Link) -> Point {
    let ((x0, y0), (x1, y1)) = l.ends();
    let w = values.width() as i32;
    let h = values.height() as i32;
    let outside = |x: i32, y: i32| x < 0 || y < 0 || x >= w || y >= h;
    let t = if outside(x0, y0) || outside(x1, y1) {
        0.5
    } else {
        let v0 = values.get(x0 as usize, y0 as usize) as f64;
        let v1 = values.get(x1 as usize, y1 as usize) as f64;
        clamp_t(v0 / (v0 - v1))
    };
    l.point(t)
}

/// Keeps a link parameter strictly inside the link.
pub fn clamp_t(t: f64) -> f64 {
    if t.is_finite() {
        t.clamp(0.001, 0.999)
    } else {
        0.5
    }
}

/// Point-in-polygon by the even-odd ray rule.
pub fn contains(poly: &[Point], p: Point) -> bool {
    let n = poly.len();
    let mut inside = false;
    let mut j = n.wrapping_sub(1);
    for i in 0..n {
        let (a, b) = (poly[i], poly[j]);
        if (a.y > p.y) != (b.y > p.y) && p.x < (b.x - a.x) * (p.y - a.y) / (b.y - a.y) + a.x {
            inside = !inside;
        }
        j = i;
    }
    inside
}

#[cfg(test)]
mod tests {
    use super::*;

    /// `wrap_once` is `rem_euclid` to the bit over one period either side,
    /// the ends and signed zeros included.
    #[test]
    fn wrap_once_is_rem_euclid_within_a_period() {
        let mut state = 0x2545_f491_4f6c_dd1du64;
        let mut rnd = || {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            (state >> 11) as f64 / (1u64 << 53) as f64
        };
        for _ in 0..20000 {
            let period =
                [360.0, std::f64::consts::TAU, 1e-3 + 5e3 * rnd()][(rnd() * 3.0) as usize % 3];
            let x = (3.0 * rnd() - 1.0) * period;
            assert_eq!(
                wrap_once(x, period).to_bits(),
                x.rem_euclid(period).to_bits(),
                "{x} mod {period}"
            );
        }
        for (x, p) in [
            (0.0, 5.0),
            (-0.0, 5.0),
            (5.0, 5.0),
            (-5.0, 5.0),
            (-1e-300, 5.0),
            (9.999999999, 5.0),
        ] {
            assert_eq!(
                wrap_once(x, p).to_bits(),
                f64::rem_euclid(x, p).to_bits(),
                "{x} mod {p}"
            );
        }
    }

    fn field(w: usize, h: usize, f: impl Fn(f64, f64) -> f64) -> Grid<f32> {
        Grid::from_fn(w, h, |x, y| f(x as f64 + 0.5, y as f64 + 0.5) as f32)
    }

    fn check_clean(c: &Contour) {
        let n = c.points.len();
        assert!(n >= 3);
        for i in 0..n {
            let d = (c.points[i] - c.points[(i + 1) % n]).hypot();
            assert!(d > 1e-4, "zero-length edge at {i}");
        }
        let mut links = c.links.clone();
        links.sort();
        links.dedup();
        assert_eq!(links.len(), n, "duplicate vertex");
    }

    #[test]
    fn disc_is_one_outer_loop() {
        let g = field(20, 20, |x, y| ((x - 10.0).hypot(y - 10.0)) - 6.0);
        let cs = extract(&g);
        assert_eq!(cs.len(), 1);
        check_clean(&cs[0]);
        let a = cs[0].signed_area();
        assert!(a > 0.0);
        assert!((a - std::f64::consts::PI * 36.0).abs() < 2.0, "{a}");
        for p in &cs[0].points {
            assert!(((p.x - 10.0).hypot(p.y - 10.0) - 6.0).abs() < 0.05);
        }
    }

    #[test]
    fn ring_has_outer_and_hole() {
        let g = field(24, 24, |x, y| {
            let r = (x - 12.0).hypot(y - 12.0);
            (r - 9.0).max(4.0 - r)
        });
        let mut cs = extract(&g);
        assert_eq!(cs.len(), 2);
        cs.sort_by(|a, b| b.signed_area().total_cmp(&a.signed_area()));
        assert!(cs[0].signed_area() > 0.0);
        assert!(cs[1].signed_area() < 0.0);
        assert!(contains(&cs[0].points, cs[1].points[0]));
        cs.iter().for_each(check_clean);
    }

    #[test]
    fn two_touching_squares_by_a_corner() {
        // Two squares meeting diagonally at one sample corner: the saddle
        // rule must give the same answer wherever it is applied.
        let mut g = Grid::new(6, 6, 1.0f32);
        for (x, y) in [
            (1, 1),
            (2, 1),
            (1, 2),
            (2, 2),
            (3, 3),
            (4, 3),
            (3, 4),
            (4, 4),
        ] {
            g.set(x, y, -1.0);
        }
        let cs = extract(&g);
        // Cell centre between (2,2) and (3,3) averages to 0, a tie: joined.
        assert_eq!(cs.len(), 1);
        cs.iter().for_each(check_clean);
        // Make the centre outside: apart.
        g.set(2, 2, -0.5);
        let cs = extract(&g);
        assert_eq!(cs.len(), 2);
        assert!(cs.iter().all(|c| c.signed_area() > 0.0));
        cs.iter().for_each(check_clean);
    }

    #[test]
    fn checkerboard_of_saddles() {
        let g = Grid::from_fn(8, 8, |x, y| if (x + y) % 2 == 0 { -1.0f32 } else { 1.5 });
        let cs = extract(&g);
        // Centres average to 0.25 → outside: every inside sample is its own island.
        assert_eq!(cs.len(), 32);
        assert!(cs
            .iter()
            .all(|c| c.signed_area() > 0.0 && c.points.len() == 4));
        let g2 = g.map(|v| if v < 0.0 { -1.0 } else { 1.0 });
        let cs2 = extract(&g2);
        // Ties (centres average to exactly 0) join the ink → one region
        // with holes.
        let outers = cs2.iter().filter(|c| c.signed_area() > 0.0).count();
        assert_eq!(outers, 1);
        assert!(cs2.iter().filter(|c| c.signed_area() < 0.0).count() > 0);
    }

    #[test]
    fn one_pixel_line_survives() {
        let g = field(20, 9, |_, y| (y - 4.5).abs() - 0.5);
        let cs = extract(&g);
        assert_eq!(cs.len(), 1);
        let c = &cs[0];
        check_clean(c);
        let ys: Vec<f64> = c.points.iter().map(|p| p.y).collect();
        let (lo, hi) = ys
            .iter()
            .fold((f64::MAX, f64::MIN), |(a, b), &y| (a.min(y), b.max(y)));
        assert!((hi - lo - 1.0).abs() < 0.01, "{lo} {hi}");
    }

    #[test]
    fn ink_touching_the_border_closes_on_it() {
        let g = Grid::new(3, 2, -1.0f32);
        let cs = extract(&g);
        assert_eq!(cs.len(), 1);
        // The loop runs along the canvas border and cuts each canvas corner
        // by a half-pixel triangle: 6 − 4 · ⅛ px².
        assert!((cs[0].signed_area() - 5.5).abs() < 1e-9);
    }
}
