//! Distance fields on a layer mesh: exact seeds near the boundary, fast marching, and the
//! local maximum of a field (a strip's ridge).

use super::mesh::LayerMesh;
use crate::geom2d::Point2;
use crate::tolerance::{BOX_SLACK, CELL_FLOOR, SHORT_VECTOR};
use brep::math::{P3, V3};
use std::cmp::Ordering;
use std::collections::BinaryHeap;

/// Distance from `p` to the segment `a`–`b` in 3-D.
pub(crate) fn segment_distance(p: &P3, a: &P3, b: &P3) -> f64 {
    Segment::new(*a, *b).distance2(p).sqrt()
}

/// A segment in 3-D as its start, direction (end − start) and squared length.
#[derive(Debug, Clone, Copy)]
struct Segment {
    a: P3,
    d: V3,
    l2: f64,
}

impl Segment {
    fn new(a: P3, b: P3) -> Segment {
        let d = b - a;
        Segment {
            a,
            d,
            l2: d.norm_squared(),
        }
    }

    /// The squared distance from `p` to the segment.
    fn distance2(&self, p: &P3) -> f64 {
        let t = if self.l2 > 0.0 {
            ((p - self.a).dot(&self.d) / self.l2).clamp(0.0, 1.0)
        } else {
            0.0
        };
        (p - (self.a + self.d * t)).norm_squared()
    }
}

/// An occupied cell of [`LayerMesh::boundary_seeds`]' grid: its key (row, column), its run of
/// segments and their 3-D box.
struct Cell {
    key: (i64, i64),
    start: usize,
    end: usize,
    lo: P3,
    hi: P3,
}

/// The largest `x` with `x.sqrt() <= r` (`r` ≥ 0), so that `x.sqrt() <= r` is `x <= limit` for
/// every `x`: the square root is monotone and correctly rounded, so the answer is exactly that of
/// the root, without taking it.
pub(super) fn sqrt_at_most(r: f64) -> f64 {
    if !(r.is_finite() && r >= 0.0) {
        return if r == f64::INFINITY {
            f64::INFINITY
        } else {
            -1.0
        };
    }
    let step = |x: f64, up: bool| {
        let b = x.to_bits();
        f64::from_bits(if up { b + 1 } else { b - 1 })
    };
    let mut x = r * r;
    while x > 0.0 && x.sqrt() > r {
        x = step(x, false);
    }
    while x < f64::MAX && step(x, true).sqrt() <= r {
        x = step(x, true);
    }
    x
}

/// Min-heap entry for marching.
#[derive(PartialEq)]
struct Entry(f64, u32);
impl Eq for Entry {}
impl PartialOrd for Entry {
    fn partial_cmp(&self, o: &Self) -> Option<Ordering> {
        Some(self.cmp(o))
    }
}
impl Ord for Entry {
    fn cmp(&self, o: &Self) -> Ordering {
        o.0.total_cmp(&self.0).then(o.1.cmp(&self.1))
    }
}

/// The planar-wavefront update of vertex `c` from the known vertices `a`, `b` of a triangle
/// (Kimmel & Sethian 1998): unfold the triangle into the plane, take the distance as linear
/// over it with a unit gradient matching `da`, `db` along `ab`, and use it when the
/// characteristic through `c` comes from within `ab` (upwind); otherwise the shorter path along
/// an edge.
fn triangle_update(pa: &P3, pb: &P3, pc: &P3, da: f64, db: f64) -> f64 {
    let along_edges = (da + (pc - pa).norm()).min(db + (pc - pb).norm());
    let ab = pb - pa;
    let c = ab.norm();
    if c < SHORT_VECTOR {
        return along_edges;
    }
    let ex = ab / c;
    let ac = pc - pa;
    let cx = ac.dot(&ex);
    let cy = (ac - ex * cx).norm();
    let gx = (db - da) / c;
    if cy < SHORT_VECTOR || gx.abs() >= 1.0 {
        return along_edges;
    }
    let gy = (1.0 - gx * gx).sqrt();
    // Where the characteristic through c crosses the line through a and b.
    let x = cx - gx * cy / gy;
    let through = da + gx * cx + gy * cy;
    if (0.0..=c).contains(&x) && through >= da.max(db) {
        through.min(along_edges)
    } else {
        along_edges
    }
}

/// How far round each vertex [`LayerMesh::local_max`] looks.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Reach {
    /// This far (mm) round every vertex.
    Within(f64),
    /// `most` mm, but no more than `steps` lattice edges at the vertex ([`LayerMesh::edge_at`]:
    /// on a lattice far finer than `most`, a search of a few edges' ball).
    Steps {
        /// The farthest, mm.
        most: f64,
        /// Edges, at most.
        steps: f64,
    },
}

impl LayerMesh {
    /// Exact 3-D distances to the boundary (the lifted ring polylines) of every vertex within
    /// `reach` (chart units) of it, as seeds for [`LayerMesh::march`]: a front started from
    /// exact values a few triangles deep is far more accurate than one started at the ring.
    pub fn boundary_seeds(&self, reach: f64) -> Vec<(u32, f64)> {
        // A grid of half-reach cells in the surface-isotropic frame (about mm): the boundary
        // segments within `reach` of a vertex lie in the 5 × 5 cells around it.
        let cell = (0.5 * reach).max(CELL_FLOOR);
        let frame = self.frame.unwrap_or([1.0, 0.0, 1.0]);
        let key = |q: Point2| {
            let y = [frame[0] * q[0] + frame[1] * q[1], frame[2] * q[1]];
            ((y[0] / cell).floor() as i64, (y[1] / cell).floor() as i64)
        };
        // Each segment with its direction and length computed once, sorted by cell (row, then
        // column), so that the cells of one row a vertex looks at are one run of the list.
        let mut segments: Vec<((i64, i64), Segment)> = vec![];
        for ring in &self.rings {
            let n = ring.len();
            for i in 0..n {
                let (a, b) = (ring[i], ring[(i + 1) % n]);
                let qa = self.q[a as usize];
                let qb = self.q[b as usize];
                let mid = [0.5 * (qa[0] + qb[0]), 0.5 * (qa[1] + qb[1])];
                let (i, j) = key(mid);
                segments.push(((j, i), Segment::new(self.p[a as usize], self.p[b as usize])));
            }
        }
        segments.sort_by_key(|s| s.0);
        let grid: Vec<Segment> = segments.iter().map(|s| s.1).collect();
        // The occupied cells in that order: each with its run of `grid` and the 3-D box of its
        // segments, which bounds their distance from below.
        let mut cells: Vec<Cell> = vec![];
        for (k, (c, seg)) in segments.iter().enumerate() {
            let b = seg.a + seg.d;
            let (lo, hi) = (seg.a.inf(&b), seg.a.sup(&b));
            match cells.last_mut() {
                Some(last) if last.key == *c => {
                    last.end = k + 1;
                    last.lo = last.lo.inf(&lo);
                    last.hi = last.hi.sup(&hi);
                }
                _ => cells.push(Cell {
                    key: *c,
                    start: k,
                    end: k + 1,
                    lo,
                    hi,
                }),
            }
        }
        // Where each row's cells start, by row from the lowest one with a segment, when the
        // rows are few enough to list (else found by bisection).
        let rows = match (cells.first(), cells.last()) {
            (Some(a), Some(b)) if b.key.0 - a.key.0 < 1 << 20 => {
                let (j0, n) = (a.key.0, (b.key.0 - a.key.0 + 1) as usize);
                let mut first = vec![0usize; n + 1];
                for c in &cells {
                    first[(c.key.0 - j0) as usize + 1] += 1;
                }
                for r in 0..n {
                    first[r + 1] += first[r];
                }
                Some((j0, first))
            }
            _ => None,
        };
        // The occupied cells `(i0..=i1, j)`.
        let run = |j: i64, i0: i64, i1: i64| -> &[Cell] {
            let (a, b) = match &rows {
                Some((j0, first)) => {
                    if j < *j0 || j - j0 >= (first.len() - 1) as i64 {
                        return &[];
                    }
                    let r = (j - j0) as usize;
                    (first[r], first[r + 1])
                }
                None => (0, cells.len()),
            };
            let row = &cells[a..b];
            let lo = a + row.partition_point(|c| c.key < (j, i0));
            let hi = a + row.partition_point(|c| c.key <= (j, i1));
            &cells[lo..hi]
        };
        let reach2 = reach * reach;
        let mut out = vec![];
        for (v, q) in self.q.iter().enumerate() {
            let (i, j) = key(*q);
            let p = self.p[v];
            // `segment_distance` squared; the square root of the least square is the least
            // distance (the root is monotone and rounded correctly). The vertex's own row
            // first; a cell whose box lies farther than the least so far, or than `reach` (a
            // vertex farther than that is no seed), by more than any round-off, holds no
            // segment that matters and is passed over.
            let mut best2 = f64::INFINITY;
            for b in [j, j - 1, j + 1, j - 2, j + 2] {
                for c in run(b, i - 2, i + 2) {
                    let out = (c.lo - p).sup(&(p - c.hi)).sup(&V3::zeros());
                    if out.norm_squared() > best2.min(reach2) + BOX_SLACK {
                        continue;
                    }
                    for s in &grid[c.start..c.end] {
                        best2 = best2.min(s.distance2(&p));
                    }
                }
            }
            let mut best = best2.sqrt();
            if self.boundary[v] {
                best = 0.0;
            }
            if best.is_finite() && (best <= reach || self.boundary[v]) {
                out.push((v as u32, best));
            }
        }
        out
    }

    /// The edge (mm) of the equilateral triangle as large as the mean of the triangles at
    /// vertex `v` on the layer surface: how closely the lattice samples it there, also where the
    /// chart stretches its triangles long and thin; 0 for a vertex of no triangle.
    pub fn edge_at(&self, v: usize) -> f64 {
        let tris = &self.around[v];
        if tris.is_empty() {
            return 0.0;
        }
        let area: f64 = tris
            .iter()
            .map(|&t| {
                let [a, b, c] = self.tris[t as usize].map(|i| self.p[i as usize]);
                0.5 * (b - a).cross(&(c - a)).norm()
            })
            .sum::<f64>()
            / tris.len() as f64;
        // An equilateral triangle of edge e has area e²·√3/4.
        (4.0 * area / 3f64.sqrt()).sqrt()
    }

    /// For each vertex where `mask` holds, the largest `f` over the vertices joined to it
    /// through the mesh within 3-D distance `reach` of it (others get `f` itself): the local
    /// height of a ridge of `f` seen from its flanks. Exact up to the vertex's `cap`: its
    /// search stops at the first value above that, which it keeps (above `cap`, at most the
    /// largest); with `f64::INFINITY` the value is exact.
    pub fn local_max(&self, f: &[f64], reach: Reach, mask: &[bool], cap: &[f64]) -> Vec<f64> {
        let mut out = f.to_vec();
        if !mask.iter().any(|&m| m) {
            return out;
        }
        let (first, next) = self.adjacency.get_or_init(|| self.neighbours());
        let around = |u: usize| &next[first[u] as usize..first[u + 1] as usize];
        // The squared radius: once for a fixed reach, per vertex for one by steps.
        let fixed = match reach {
            Reach::Within(r) => sqrt_at_most(r),
            Reach::Steps { .. } => 0.0,
        };
        let within_at = |v: usize| match reach {
            Reach::Within(_) => fixed,
            Reach::Steps { most, steps } => sqrt_at_most(most.min(steps * self.edge_at(v))),
        };
        // `seen[x] == v + 1`: x was looked at from v, inside the ball or not (no clearing
        // between vertices; each vertex's distance is taken once per flood).
        let mut seen = vec![0u32; self.q.len()];
        let mut stack = vec![];
        for v in 0..self.q.len() {
            if !mask[v] {
                continue;
            }
            let pv = self.p[v];
            let cap = cap[v];
            let within = within_at(v);
            // A climb first, from each vertex to its highest neighbour inside the ball while
            // that is higher: every vertex on the way is joined to v inside the ball, and a
            // flank's climb passes the cap in a few steps where the search would look at the
            // whole ball.
            let mut climbed = f[v];
            let mut u = v;
            while climbed.partial_cmp(&cap) != Some(Ordering::Greater) {
                let mut hi = if f[u].is_finite() {
                    f[u]
                } else {
                    f64::NEG_INFINITY
                };
                let mut step = None;
                for &x in around(u) {
                    let fx = f[x as usize];
                    if fx.is_finite()
                        && fx > hi
                        && (self.p[x as usize] - pv).norm_squared() <= within
                    {
                        hi = fx;
                        step = Some(x as usize);
                    }
                }
                match step {
                    Some(x) => {
                        u = x;
                        climbed = climbed.max(hi);
                    }
                    None => break,
                }
            }
            if climbed > cap {
                out[v] = climbed;
                continue;
            }
            let stamp = v as u32 + 1;
            stack.clear();
            stack.push(v as u32);
            seen[v] = stamp;
            let mut best = f[v];
            while let Some(u) = stack.pop() {
                let u = u as usize;
                if f[u].is_finite() {
                    best = best.max(f[u]);
                }
                if best > cap {
                    break;
                }
                for &x in around(u) {
                    if seen[x as usize] != stamp {
                        seen[x as usize] = stamp;
                        if (self.p[x as usize] - pv).norm_squared() <= within {
                            stack.push(x);
                        }
                    }
                }
            }
            out[v] = best;
        }
        out
    }

    /// The vertices joined to each vertex by an edge of a triangle, as offsets (`first[v]` ..
    /// `first[v + 1]`) into one list (kept in `adjacency` once made).
    fn neighbours(&self) -> (Vec<u32>, Vec<u32>) {
        let n = self.q.len();
        let mut first = Vec::with_capacity(n + 1);
        let mut next = Vec::with_capacity(6 * n);
        first.push(0u32);
        for v in 0..n {
            let start = next.len();
            for &t in &self.around[v] {
                for &x in &self.tris[t as usize] {
                    if x as usize != v && !next[start..].contains(&x) {
                        next.push(x);
                    }
                }
            }
            first.push(next.len() as u32);
        }
        (first, next)
    }

    /// Distances over the mesh's 3-D points from `seeds` (vertex, starting distance), by fast
    /// marching. Vertices the front never reaches keep `f64::INFINITY`.
    pub fn march(&self, seeds: &[(u32, f64)]) -> Vec<f64> {
        let n = self.p.len();
        let mut d = vec![f64::INFINITY; n];
        let mut known = vec![false; n];
        let mut heap = BinaryHeap::new();
        // Seeds are exact: the front may not lower them. A triangle with a seed on each side
        // of a convex corner of the boundary would otherwise give the distance to the chord
        // across the corner, and the iso-lines would cut the corner off.
        let mut seeded = vec![false; n];
        for &(v, s) in seeds {
            if (v as usize) < n && s < d[v as usize] {
                d[v as usize] = s;
                seeded[v as usize] = true;
                heap.push(Entry(s, v));
            }
        }
        while let Some(Entry(dv, v)) = heap.pop() {
            let vi = v as usize;
            if known[vi] || dv > d[vi] {
                continue;
            }
            known[vi] = true;
            for &t in &self.around[vi] {
                let tri = self.tris[t as usize];
                for k in 0..3 {
                    let c = tri[k] as usize;
                    if known[c] || seeded[c] {
                        continue;
                    }
                    let (a, b) = (tri[(k + 1) % 3] as usize, tri[(k + 2) % 3] as usize);
                    let cand = match (known[a], known[b]) {
                        (true, true) => {
                            triangle_update(&self.p[a], &self.p[b], &self.p[c], d[a], d[b])
                        }
                        (true, false) => d[a] + (self.p[c] - self.p[a]).norm(),
                        (false, true) => d[b] + (self.p[c] - self.p[b]).norm(),
                        _ => continue,
                    };
                    if cand < d[c] {
                        d[c] = cand;
                        heap.push(Entry(cand, c as u32));
                    }
                }
            }
        }
        d
    }
}
