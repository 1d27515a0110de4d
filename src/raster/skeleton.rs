//! One-pixel skeletons of binary ink (Zhang & Suen 1984, "A fast parallel
//! algorithm for thinning digital patterns"), shared by centre-line
//! tracing and fill's line-continuity measures.

use super::Grid;

/// The 8 neighbour offsets in the order P2…P9 of Zhang & Suen: clockwise
/// from north (N, NE, E, SE, S, SW, W, NW).
pub const RING: [(isize, isize); 8] = [
    (0, -1),
    (1, -1),
    (1, 0),
    (1, 1),
    (0, 1),
    (-1, 1),
    (-1, 0),
    (-1, -1),
];

/// The one-pixel, 8-connected skeleton of `ink` by Zhang–Suen thinning:
/// boundary pixels whose removal keeps the neighbourhood connected (one
/// 0→1 transition around them, 2–6 ink neighbours) are removed in
/// alternating south-east and north-west sub-passes, each deciding on the
/// grid as it was before it, until none is. Pixels outside the grid count
/// as paper. Only pixels still ink are visited again.
pub fn skeleton(ink: &Grid<bool>) -> Grid<bool> {
    let (w, h) = (ink.width(), ink.height());
    let mut s = ink.data().to_vec();
    let mut live: Vec<usize> = (0..w * h).filter(|&i| s[i]).collect();
    let at = |s: &[bool], x: isize, y: isize| {
        x >= 0 && y >= 0 && x < w as isize && y < h as isize && s[y as usize * w + x as usize]
    };
    let mut gone = Vec::new();
    loop {
        let mut changed = false;
        for pass in 0..2 {
            gone.clear();
            for &i in &live {
                let (x, y) = ((i % w) as isize, (i / w) as isize);
                let p: [bool; 8] = RING.map(|(dx, dy)| at(&s, x + dx, y + dy));
                let b = p.iter().filter(|&&v| v).count();
                if !(2..=6).contains(&b) {
                    continue;
                }
                let a = (0..8).filter(|&k| !p[k] && p[(k + 1) % 8]).count();
                if a != 1 {
                    continue;
                }
                // p[0] N, p[2] E, p[4] S, p[6] W.
                let keep = if pass == 0 {
                    p[2] && p[4] && (p[0] || p[6])
                } else {
                    p[0] && p[6] && (p[2] || p[4])
                };
                if !keep {
                    gone.push(i);
                }
            }
            for &i in &gone {
                s[i] = false;
            }
            changed |= !gone.is_empty();
            live.retain(|&i| s[i]);
        }
        if !changed {
            return Grid::from_vec(w, h, s).unwrap_or_else(|| Grid::new(w, h, false));
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The textbook form: every pixel of the grid visited in each
    /// sub-pass, with the two deletion conditions written out.
    fn reference(ink: &Grid<bool>) -> Grid<bool> {
        let (w, h) = (ink.width(), ink.height());
        let mut g = ink.clone();
        loop {
            let mut changed = false;
            for pass in 0..2 {
                let mut del = Vec::new();
                for y in 0..h {
                    for x in 0..w {
                        if !g.get(x, y) {
                            continue;
                        }
                        let p =
                            RING.map(|(dx, dy)| g.get_or(x as isize + dx, y as isize + dy, false));
                        let b = p.iter().filter(|&&v| v).count();
                        let a = (0..8).filter(|&i| !p[i] && p[(i + 1) % 8]).count();
                        let (c1, c2) = if pass == 0 {
                            (p[0] && p[2] && p[4], p[2] && p[4] && p[6])
                        } else {
                            (p[0] && p[2] && p[6], p[0] && p[4] && p[6])
                        };
                        if (2..=6).contains(&b) && a == 1 && !c1 && !c2 {
                            del.push((x, y));
                        }
                    }
                }
                changed |= !del.is_empty();
                for (x, y) in del {
                    g.set(x, y, false);
                }
            }
            if !changed {
                return g;
            }
        }
    }

    #[test]
    fn matches_the_textbook_form_on_random_ink() {
        let mut state = 0x9e37_79b9_7f4a_7c15u64;
        let mut next = || {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            state
        };
        for k in 0..200 {
            let (w, h) = (3 + k % 17, 3 + k % 13);
            let fill = next() % 90 + 5;
            let ink = Grid::from_fn(w, h, |_, _| next() % 100 < fill);
            assert_eq!(skeleton(&ink), reference(&ink), "case {k}");
        }
    }

    #[test]
    fn a_thick_bar_thins_to_a_line() {
        let ink = Grid::from_fn(20, 7, |x, y| (2..18).contains(&x) && (1..6).contains(&y));
        let s = skeleton(&ink);
        // Away from the ends, where the corners leave short diagonal tails.
        for x in 7..13 {
            let column = (0..7).filter(|&y| s.get(x, y)).count();
            assert_eq!(column, 1, "column {x}");
        }
    }
}
