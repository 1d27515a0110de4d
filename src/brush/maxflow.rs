//! s–t maximum flow and minimum cut on sparse integer networks, for the
//! graph-cut seams of decobrush.txt §5.3.
//!
//! [`FlowGraph::max_flow`] is Boykov & Kolmogorov's algorithm ("An
//! Experimental Comparison of Min-Cut/Max-Flow Algorithms for Energy
//! Minimization in Vision", PAMI 2004): two search trees grow from the
//! source and the sink, an augmenting path is found where they touch, and
//! the nodes cut off by saturated edges are re-adopted instead of rebuilding
//! the trees, which makes it fast on 4-connected grids.
//! `FlowGraph::max_flow_dinic` (built for tests only) is Dinic's
//! algorithm, kept as the independent reference the tests compare against (with brute force on
//! tiny graphs). Capacities are integers, so both are exact.

use std::collections::VecDeque;

/// A directed flow network with integer capacities; edges are stored in
/// pairs (`e`, `e ^ 1`) so each one's residual reverse is at hand.
pub struct FlowGraph {
    head: Vec<usize>,
    next: Vec<usize>,
    to: Vec<usize>,
    cap: Vec<i64>,
}

const NIL: usize = usize::MAX;

impl FlowGraph {
    /// An empty network of `n` nodes.
    pub fn new(n: usize) -> Self {
        FlowGraph {
            head: vec![NIL; n],
            next: Vec::new(),
            to: Vec::new(),
            cap: Vec::new(),
        }
    }

    /// Adds the link `u → v` with capacity `uv` and `v → u` with `vu`
    /// (negative capacities count as 0; out-of-range nodes are ignored).
    pub fn add_edge(&mut self, u: usize, v: usize, uv: i64, vu: i64) {
        if u >= self.head.len() || v >= self.head.len() {
            return;
        }
        for (from, to, c) in [(u, v, uv), (v, u, vu)] {
            self.to.push(to);
            self.cap.push(c.max(0));
            self.next.push(self.head[from]);
            self.head[from] = self.to.len() - 1;
        }
    }

    /// Breadth-first levels from `s` over edges with residual capacity.
    fn levels(&self, s: usize) -> Vec<u32> {
        let mut level = vec![u32::MAX; self.head.len()];
        let mut queue = VecDeque::new();
        level[s] = 0;
        queue.push_back(s);
        while let Some(u) = queue.pop_front() {
            let mut e = self.head[u];
            while e != NIL {
                let v = self.to[e];
                if self.cap[e] > 0 && level[v] == u32::MAX {
                    level[v] = level[u] + 1;
                    queue.push_back(v);
                }
                e = self.next[e];
            }
        }
        level
    }

    /// The maximum flow from `s` to `t` by Dinic's algorithm (BFS level
    /// graph, then blocking flows by iterative depth-first search with
    /// current-arc pointers): the reference for [`FlowGraph::max_flow`].
    /// Leaves the residual network for [`FlowGraph::source_side`].
    #[cfg(test)]
    pub fn max_flow_dinic(&mut self, s: usize, t: usize) -> i64 {
        let n = self.head.len();
        if s >= n || t >= n || s == t {
            return 0;
        }
        let mut total: i64 = 0;
        loop {
            let mut level = self.levels(s);
            if level[t] == u32::MAX {
                return total;
            }
            let mut arc = self.head.clone();
            let mut path: Vec<usize> = Vec::new();
            let mut u = s;
            loop {
                if u == t {
                    // Augment along the path by its bottleneck.
                    let push = path.iter().map(|&e| self.cap[e]).min().unwrap_or(0);
                    for &e in &path {
                        self.cap[e] -= push;
                        self.cap[e ^ 1] += push;
                    }
                    total = total.saturating_add(push);
                    // Restart from the tail of the first saturated edge.
                    let cut = path.iter().position(|&e| self.cap[e] == 0).unwrap_or(0);
                    path.truncate(cut);
                    u = path.last().map_or(s, |&e| self.to[e]);
                    continue;
                }
                // Advance along an admissible arc, or retreat.
                let mut e = arc[u];
                while e != NIL {
                    let v = self.to[e];
                    if self.cap[e] > 0 && level[v] == level[u] + 1 {
                        break;
                    }
                    e = self.next[e];
                }
                arc[u] = e;
                if e != NIL {
                    path.push(e);
                    u = self.to[e];
                    continue;
                }
                level[u] = u32::MAX; // dead end for this phase
                match path.pop() {
                    None => break,
                    Some(back) => {
                        u = self.to[back ^ 1];
                        arc[u] = self.next[arc[u]];
                    }
                }
            }
        }
    }

    /// After [`FlowGraph::max_flow`]: which nodes the source still reaches
    /// in the residual network (the source side of a minimum cut).
    pub fn source_side(&self, s: usize) -> Vec<bool> {
        self.levels(s).iter().map(|&l| l != u32::MAX).collect()
    }
}

/// Which search tree a node belongs to (Boykov–Kolmogorov).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Tree {
    Free,
    Source,
    Sink,
}

/// A node's parent link: the node is a tree root, an orphan, or hangs off
/// the parent by an edge (`parent → node` in the source tree, `node →
/// parent` in the sink tree).
const ROOT: usize = usize::MAX - 1;

impl FlowGraph {
    /// The maximum flow from `s` to `t` (Boykov–Kolmogorov 2004: growth,
    /// augmentation and adoption stages, with the distance/timestamp
    /// heuristic for choosing new parents). Leaves the residual network for
    /// [`FlowGraph::source_side`].
    pub fn max_flow(&mut self, s: usize, t: usize) -> i64 {
        let n = self.head.len();
        if s >= n || t >= n || s == t {
            return 0;
        }
        let mut bk = Bk {
            tree: vec![Tree::Free; n],
            parent: vec![NIL; n],
            active: vec![false; n],
            queue: VecDeque::new(),
            orphans: VecDeque::new(),
            stamp: vec![0; n],
            dist: vec![0; n],
            time: 1,
        };
        for (root, tree) in [(s, Tree::Source), (t, Tree::Sink)] {
            bk.tree[root] = tree;
            bk.parent[root] = ROOT;
            bk.stamp[root] = 1;
            bk.activate(root);
        }
        let mut total: i64 = 0;
        while let Some(link) = self.grow(&mut bk) {
            total = total.saturating_add(self.augment(&mut bk, link));
            bk.time += 1;
            while let Some(o) = bk.orphans.pop_front() {
                self.adopt(&mut bk, o);
            }
        }
        total
    }

    /// The node an edge leaves from.
    fn from(&self, e: usize) -> usize {
        self.to[e ^ 1]
    }

    /// Growth stage: expands the trees from the active nodes until they
    /// touch; returns the edge from a source-tree node to a sink-tree node.
    fn grow(&self, bk: &mut Bk) -> Option<usize> {
        while let Some(&p) = bk.queue.front() {
            if !bk.active[p] || bk.tree[p] == Tree::Free {
                bk.queue.pop_front();
                bk.active[p] = false;
                continue;
            }
            let mut e = self.head[p];
            while e != NIL {
                let q = self.to[e];
                // Residual capacity in the direction of growth.
                let (out, toward) = match bk.tree[p] {
                    Tree::Source => (self.cap[e], e),
                    _ => (self.cap[e ^ 1], e ^ 1),
                };
                if out > 0 {
                    match bk.tree[q] {
                        Tree::Free => {
                            bk.tree[q] = bk.tree[p];
                            bk.parent[q] = toward;
                            bk.stamp[q] = bk.stamp[p];
                            bk.dist[q] = bk.dist[p] + 1;
                            bk.activate(q);
                        }
                        tq if tq != bk.tree[p] => {
                            // The trees touch: the source-side end first.
                            return Some(toward);
                        }
                        _ => {}
                    }
                }
                e = self.next[e];
            }
            bk.queue.pop_front();
            bk.active[p] = false;
        }
        None
    }

    /// Augmentation stage: pushes the bottleneck along source root → link
    /// → sink root; nodes whose parent edge saturates become orphans.
    fn augment(&mut self, bk: &mut Bk, link: usize) -> i64 {
        // The link runs from a source-tree node to a sink-tree node (or the
        // reverse when found from the sink side: then `link` is q → p).
        let (a, b) = (self.from(link), self.to[link]);
        let (a, b, link) = if bk.tree[a] == Tree::Source {
            (a, b, link)
        } else {
            (b, a, link ^ 1)
        };
        debug_assert!(bk.tree[a] == Tree::Source && bk.tree[b] == Tree::Sink);
        let mut push = self.cap[link];
        let mut x = a;
        while bk.parent[x] != ROOT {
            push = push.min(self.cap[bk.parent[x]]);
            x = self.from(bk.parent[x]);
        }
        let mut x = b;
        while bk.parent[x] != ROOT {
            push = push.min(self.cap[bk.parent[x]]);
            x = self.to[bk.parent[x]];
        }
        self.cap[link] -= push;
        self.cap[link ^ 1] += push;
        let mut x = a;
        while bk.parent[x] != ROOT {
            let e = bk.parent[x];
            self.cap[e] -= push;
            self.cap[e ^ 1] += push;
            let up = self.from(e);
            if self.cap[e] == 0 {
                bk.parent[x] = NIL;
                bk.orphans.push_front(x);
            }
            x = up;
        }
        let mut x = b;
        while bk.parent[x] != ROOT {
            let e = bk.parent[x];
            self.cap[e] -= push;
            self.cap[e ^ 1] += push;
            let down = self.to[e];
            if self.cap[e] == 0 {
                bk.parent[x] = NIL;
                bk.orphans.push_front(x);
            }
            x = down;
        }
        push
    }

    /// Adoption stage for orphan `p`: a new parent in its own tree whose
    /// chain reaches the root (closest to the root by the heuristic), or,
    /// failing that, `p` leaves the tree and its children become orphans.
    fn adopt(&self, bk: &mut Bk, p: usize) {
        let tree = bk.tree[p];
        let mut best: Option<(usize, u32)> = None;
        let mut e = self.head[p];
        while e != NIL {
            let q = self.to[e];
            // The link q → p (source tree) or p → q (sink tree).
            let link = if tree == Tree::Source { e ^ 1 } else { e };
            if bk.tree[q] == tree && self.cap[link] > 0 {
                if let Some(d) = self.origin(bk, q) {
                    if best.is_none_or(|(_, bd)| d < bd) {
                        best = Some((link, d));
                    }
                }
            }
            e = self.next[e];
        }
        if let Some((link, d)) = best {
            bk.parent[p] = link;
            bk.stamp[p] = bk.time;
            bk.dist[p] = d + 1;
            return;
        }
        // No parent: free p; neighbours that could re-grow into it become
        // active, its children become orphans.
        let mut e = self.head[p];
        while e != NIL {
            let q = self.to[e];
            if bk.tree[q] == tree {
                let link = if tree == Tree::Source { e ^ 1 } else { e };
                if self.cap[link] > 0 {
                    bk.activate(q);
                }
                let pe = bk.parent[q];
                if pe != NIL && pe != ROOT {
                    let up = if tree == Tree::Source {
                        self.from(pe)
                    } else {
                        self.to[pe]
                    };
                    if up == p {
                        bk.parent[q] = NIL;
                        bk.orphans.push_back(q);
                    }
                }
            }
            e = self.next[e];
        }
        bk.tree[p] = Tree::Free;
        bk.active[p] = false;
    }

    /// The distance from `q` to its tree's root along parent links, or
    /// `None` when the chain ends at an orphan. Marks the chain with the
    /// current time and exact distances so later walks stop early.
    fn origin(&self, bk: &mut Bk, q: usize) -> Option<u32> {
        let tree = bk.tree[q];
        let up = |x: usize| {
            let e = bk.parent[x];
            if tree == Tree::Source {
                self.from(e)
            } else {
                self.to[e]
            }
        };
        let mut d: u32 = 0;
        let mut x = q;
        loop {
            if bk.stamp[x] == bk.time {
                d += bk.dist[x];
                break;
            }
            match bk.parent[x] {
                ROOT => {
                    bk.stamp[x] = bk.time;
                    bk.dist[x] = 0;
                    break;
                }
                NIL => return None,
                _ => {
                    x = up(x);
                    d += 1;
                }
            }
        }
        // Mark the chain q … x with its distances.
        let mut x = q;
        let mut dx = d;
        while bk.stamp[x] != bk.time {
            bk.stamp[x] = bk.time;
            bk.dist[x] = dx;
            x = up(x);
            dx = dx.saturating_sub(1);
        }
        Some(d)
    }
}

/// Boykov–Kolmogorov search state.
struct Bk {
    tree: Vec<Tree>,
    /// Parent edge, `ROOT` for the terminals, `NIL` for orphans and free
    /// nodes.
    parent: Vec<usize>,
    active: Vec<bool>,
    queue: VecDeque<usize>,
    /// Orphans to adopt: those cut off by an augmentation at the front,
    /// those freed during adoption at the back (as Kolmogorov's code does).
    orphans: VecDeque<usize>,
    /// Time of the last validated walk through each node, and its distance
    /// to the root then.
    stamp: Vec<u64>,
    dist: Vec<u32>,
    time: u64,
}

impl Bk {
    fn activate(&mut self, p: usize) {
        if !self.active[p] {
            self.active[p] = true;
            self.queue.push_back(p);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    /// Random networks: `n` nodes, random directed capacities on random
    /// pairs, source 0 and sink n − 1.
    fn network() -> impl Strategy<Value = (usize, Vec<(usize, usize, i64, i64)>)> {
        (2usize..40).prop_flat_map(|n| {
            let edge = (0..n, 0..n, 0i64..20, 0i64..20);
            (Just(n), proptest::collection::vec(edge, 0..4 * n))
        })
    }

    fn build(n: usize, edges: &[(usize, usize, i64, i64)]) -> FlowGraph {
        let mut g = FlowGraph::new(n);
        for &(u, v, a, b) in edges {
            if u != v {
                g.add_edge(u, v, a, b);
            }
        }
        g
    }

    /// The capacity of the cut (side, not side) in the original network.
    fn cut_value(n: usize, edges: &[(usize, usize, i64, i64)], side: &[bool]) -> i64 {
        let _ = n;
        edges
            .iter()
            .filter(|e| e.0 != e.1)
            .map(|&(u, v, a, b)| match (side[u], side[v]) {
                (true, false) => a,
                (false, true) => b,
                _ => 0,
            })
            .sum()
    }

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(300))]

        #[test]
        fn boykov_kolmogorov_equals_dinic((n, edges) in network()) {
            let mut bk = build(n, &edges);
            let mut dinic = build(n, &edges);
            let f = bk.max_flow(0, n - 1);
            prop_assert_eq!(f, dinic.max_flow_dinic(0, n - 1));
            // Max-flow = min-cut: the residual source side is a cut of
            // exactly that capacity, with the source in and the sink out.
            let side = bk.source_side(0);
            prop_assert!(side[0] && !side[n - 1]);
            prop_assert_eq!(cut_value(n, &edges, &side), f);
        }
    }

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(100))]

        /// Grids like the seam problems: 4-connected links and terminal
        /// links on random pixels.
        #[test]
        fn grid_max_flows_agree(
            w in 2usize..14,
            h in 2usize..14,
            seed in any::<u64>(),
        ) {
            let n = w * h + 2;
            let r = |i: usize, k: u64| crate::rng::hash(&[seed, i as u64, k]);
            let mut edges = Vec::new();
            for p in 0..w * h {
                let (x, y) = (p % w, p / w);
                if x + 1 < w {
                    edges.push((p, p + 1, (r(p, 0) % 30) as i64, (r(p, 1) % 30) as i64));
                }
                if y + 1 < h {
                    edges.push((p, p + w, (r(p, 2) % 30) as i64, (r(p, 3) % 30) as i64));
                }
                match r(p, 4) % 6 {
                    0 => edges.push((w * h, p, 1000, 0)),
                    1 => edges.push((p, w * h + 1, 1000, 0)),
                    _ => {}
                }
            }
            let mut a = build(n, &edges);
            let mut b = build(n, &edges);
            let f = a.max_flow(w * h, w * h + 1);
            prop_assert_eq!(f, b.max_flow_dinic(w * h, w * h + 1));
            prop_assert_eq!(cut_value(n, &edges, &a.source_side(w * h)), f);
        }
    }

    #[test]
    fn grid_flows_agree() {
        // A 60×40 grid with pseudo-random capacities, terminals at the
        // left and right columns.
        let (w, h) = (60, 40);
        let n = w * h + 2;
        let cap = |i: usize, k: u64| (crate::rng::hash(&[i as u64, k]) % 50) as i64;
        let mut edges = Vec::new();
        for y in 0..h {
            for x in 0..w {
                let p = y * w + x;
                if x + 1 < w {
                    edges.push((p, p + 1, cap(p, 0), cap(p, 1)));
                }
                if y + 1 < h {
                    edges.push((p, p + w, cap(p, 2), cap(p, 3)));
                }
            }
            edges.push((w * h, y * w, 1000, 0));
            edges.push((y * w + w - 1, w * h + 1, 1000, 0));
        }
        let mut a = build(n, &edges);
        let mut b = build(n, &edges);
        let f = a.max_flow(w * h, w * h + 1);
        assert_eq!(f, b.max_flow_dinic(w * h, w * h + 1));
        assert_eq!(cut_value(n, &edges, &a.source_side(w * h)), f);
    }
}
