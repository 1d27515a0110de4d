//! Exact scanline fill: which pixel centres lie inside closed outlines.

use super::Grid;
use kurbo::Point;

/// Marks in `grid` the pixel centres `(x + 0.5, y + 0.5)` inside the closed
/// outlines made of `edges` (each edge `(from, to)`, any order of edges),
/// by exact crossing counts along each row of centres: nonzero winding, or
/// even–odd when `even_odd`. Marks are added to what `grid` holds (a union).
pub fn fill(
    grid: &mut Grid<bool>,
    edges: impl IntoIterator<Item = (Point, Point)>,
    even_odd: bool,
) {
    let (w, h) = (grid.width(), grid.height());
    let mut rows: Vec<Vec<(f64, i32)>> = vec![Vec::new(); h];
    for (a, b) in edges {
        if a.y == b.y {
            continue;
        }
        let (lo, hi) = (a.y.min(b.y), a.y.max(b.y));
        // Rows whose centre y + 0.5 lies in [lo, hi).
        let r0 = (lo - 0.5).ceil().max(0.0) as usize;
        let r1 = ((hi - 0.5).ceil().max(0.0) as usize).min(h);
        let dir = if b.y > a.y { 1 } else { -1 };
        for (r, row) in rows.iter_mut().enumerate().take(r1).skip(r0) {
            let y = r as f64 + 0.5;
            let x = a.x + (y - a.y) / (b.y - a.y) * (b.x - a.x);
            row.push((x, dir));
        }
    }
    for (r, row) in rows.iter_mut().enumerate() {
        if row.is_empty() {
            continue;
        }
        row.sort_by(|p, q| p.0.total_cmp(&q.0));
        let mut wind = 0;
        for k in 0..row.len() - 1 {
            wind += row[k].1;
            let inside = if even_odd { wind % 2 != 0 } else { wind != 0 };
            if !inside {
                continue;
            }
            // Pixel centres x + 0.5 in [row[k].0, row[k + 1].0).
            let x0 = (row[k].0 - 0.5).ceil().max(0.0) as usize;
            let x1 = ((row[k + 1].0 - 0.5).ceil().max(0.0) as usize).min(w);
            for x in x0..x1 {
                grid.set(x, r, true);
            }
        }
    }
}
