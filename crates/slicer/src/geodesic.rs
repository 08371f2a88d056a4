//! Geodesic distances on a curved layer, and the iso-lines of those distances.
//!
//! The feature-based AM paper asks that on a curved layer "the distance between the parallel
//! toolpaths should be geodesic distance, namely geodesic offset on the surface". A layer's
//! region, given in a 2-D chart of its surface, is triangulated ([`LayerMesh::build`]); each
//! vertex is then placed on the layer surface in 3-D, and distances are marched over the
//! triangles in 3-D ([`LayerMesh::march`], the fast marching method of Kimmel & Sethian 1998
//! with the planar-wavefront triangle update). That update is only right on acute triangles,
//! so the lattice is laid equilateral on the surface, not in the chart
//! ([`LayerMesh::build_with_metric`]), and refined around convex corners of the boundary;
//! near the boundary the distances are exact seeds ([`LayerMesh::boundary_seeds`]) that the
//! front never lowers. Paths are the iso-lines of such distance fields
//! ([`LayerMesh::iso_lines`]): contour rings are iso-lines of the distance to the region's
//! boundary; raster and zig-zag lines are iso-lines of the signed distance to a seed curve, so
//! neighbouring lines are one spacing apart measured on the surface, not in the chart.

use crate::fill::{bead_end_reach, MAX_END_REACH};
use crate::geom2d::{dist2, Point2, Region};

use crate::fast_hash::{FastMap, FastSet};
pub use crate::geom2d::region_contains;
use crate::geom2d::RegionIndex;
use brep::math::{P3, V3};
use spade::{ConstrainedDelaunayTriangulation, Point2 as SPoint, Triangulation};
use std::cmp::Ordering;
use std::collections::BinaryHeap;

/// A triangulated layer region: chart coordinates, 3-D points on the layer surface, triangles.
#[derive(Debug, Clone, Default)]
pub struct LayerMesh {
    /// Chart coordinates of each vertex.
    pub q: Vec<Point2>,
    /// The vertex on the layer surface, mm (filled by the caller after [`LayerMesh::build`]).
    pub p: Vec<P3>,
    /// Triangles (vertex indices), all inside the region.
    pub tris: Vec<[u32; 3]>,
    /// Whether each vertex lies on the region's boundary.
    pub boundary: Vec<bool>,
    /// The region's rings as closed vertex chains (first vertex not repeated).
    pub rings: Vec<Vec<u32>>,
    /// Triangles around each vertex.
    around: Vec<Vec<u32>>,
    /// The upper-triangular map `(m00, m01, m11)` from chart to the surface-isotropic frame
    /// of [`LayerMesh::build_with_metric`]; `None`: the chart itself.
    frame: Option<[f64; 3]>,
}

/// One iso-line: chart points, and the value of a second field at each.
#[derive(Debug, Clone, Default)]
pub struct IsoLine {
    /// Chart coordinates along the line.
    pub q: Vec<Point2>,
    /// The second field interpolated at each point.
    pub other: Vec<f64>,
    /// The line is a closed ring (the first point is repeated at the end).
    pub closed: bool,
}

/// Distance from `p` to the segment `a`–`b` in 3-D.
pub(crate) fn segment_distance(p: &P3, a: &P3, b: &P3) -> f64 {
    let d = b - a;
    let l2 = d.norm_squared();
    let t = if l2 > 0.0 {
        ((p - a).dot(&d) / l2).clamp(0.0, 1.0)
    } else {
        0.0
    };
    (p - (a + d * t)).norm()
}

/// A boundary segment of a layer mesh on the layer surface: start, direction (end − start) and
/// squared length.
type Segment = (P3, V3, f64);

/// The largest `x` with `x.sqrt() <= r` (`r` ≥ 0), so that `x.sqrt() <= r` is `x <= limit` for
/// every `x`: the square root is monotone and correctly rounded, so the answer is exactly that of
/// the root, without taking it.
fn sqrt_at_most(r: f64) -> f64 {
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

/// Resamples a closed ring so no segment is longer than `step`, or `fine` where `near` holds
/// at either end of the segment.
fn resample(ring: &[Point2], step: f64, fine: f64, near: &dyn Fn(Point2) -> bool) -> Vec<Point2> {
    let n = ring.len();
    let mut out = Vec::with_capacity(n);
    for i in 0..n {
        let (a, b) = (ring[i], ring[(i + 1) % n]);
        let s = if near(a) || near(b) { fine } else { step };
        let k = (dist2(a, b).sqrt() / s).ceil().clamp(1.0, 1e4) as usize;
        for j in 0..k {
            let t = j as f64 / k as f64;
            out.push([a[0] + (b[0] - a[0]) * t, a[1] + (b[1] - a[1]) * t]);
        }
    }
    out
}

/// The points where a ring turns towards the region (left: outer rings run counter-clockwise,
/// holes clockwise) by more than `min_turn` radians: the convex corners, around which the
/// iso-lines of the distance to the boundary are circular arcs.
fn convex_corners(ring: &[Point2], min_turn: f64) -> Vec<Point2> {
    let n = ring.len();
    let mut out = vec![];
    if n < 3 {
        return out;
    }
    for i in 0..n {
        let (a, b, c) = (ring[(i + n - 1) % n], ring[i], ring[(i + 1) % n]);
        let u = [b[0] - a[0], b[1] - a[1]];
        let v = [c[0] - b[0], c[1] - b[1]];
        let cross = u[0] * v[1] - u[1] * v[0];
        let dot = u[0] * v[0] + u[1] * v[1];
        if cross > 0.0 && cross.atan2(dot) > min_turn {
            out.push(b);
        }
    }
    out
}

/// The most lattice cells (of the region's box) a layer mesh is built with.
const MAX_CELLS: f64 = 4e6;

/// The lattice step for a region whose outer ring is `outer`: `step`, or coarser where the
/// region's box would hold more than [`MAX_CELLS`] cells of it (a curved layer some 300 mm
/// across at 0.15 mm), so a large region is filled rather than left empty.
fn lattice_step(outer: &[Point2], step: f64) -> f64 {
    let (mut lo, mut hi) = ([f64::INFINITY; 2], [f64::NEG_INFINITY; 2]);
    for q in outer {
        for k in 0..2 {
            lo[k] = lo[k].min(q[k]);
            hi[k] = hi[k].max(q[k]);
        }
    }
    let cells = ((hi[0] - lo[0]) / step) * ((hi[1] - lo[1]) / step);
    if cells.is_finite() && cells > MAX_CELLS {
        step * (cells / MAX_CELLS).sqrt()
    } else {
        step
    }
}

/// A ring vertex turning by more than this (radians) towards the region is a convex corner.
const CORNER_TURN: f64 = 0.4;
/// Around a convex corner the lattice is refined within this many lattice steps.
const CORNER_REACH: f64 = 4.0;

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
    if c < 1e-12 {
        return along_edges;
    }
    let ex = ab / c;
    let ac = pc - pa;
    let cx = ac.dot(&ex);
    let cy = (ac - ex * cx).norm();
    let gx = (db - da) / c;
    if cy < 1e-12 || gx.abs() >= 1.0 {
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

impl LayerMesh {
    /// Triangulates `region` (chart coordinates): its rings resampled to `step`, a triangular
    /// lattice of spacing `step` inside, constrained Delaunay, triangles kept whose centroid is
    /// inside the region. [`LayerMesh::p`] is left empty for the caller to fill.
    pub fn build(region: &Region, step: f64) -> LayerMesh {
        let mut m = LayerMesh::default();
        if !(step.is_finite() && step > 0.0) {
            return m;
        }
        let step = lattice_step(&region.outer, step);
        // Convex corners get a lattice a third as fine within `CORNER_REACH` steps, so the
        // iso-lines' arcs round them (linear interpolation over a coarse triangle spanning a
        // corner would cut it off by a chord).
        let corners: Vec<Point2> = std::iter::once(&region.outer)
            .chain(region.holes.iter())
            .flat_map(|r| convex_corners(r, CORNER_TURN))
            .collect();
        let reach2 = (CORNER_REACH * step).powi(2);
        let near_corner = |q: Point2| corners.iter().any(|c| dist2(*c, q) <= reach2);
        let fine = step / 3.0;
        let rings: Vec<Vec<Point2>> = std::iter::once(&region.outer)
            .chain(region.holes.iter())
            .filter(|r| r.len() >= 3)
            .map(|r| resample(r, step, fine, &near_corner))
            .collect();
        let (mut lo, mut hi) = ([f64::INFINITY; 2], [f64::NEG_INFINITY; 2]);
        for q in rings.iter().flatten() {
            for k in 0..2 {
                lo[k] = lo[k].min(q[k]);
                hi[k] = hi[k].max(q[k]);
            }
        }
        if !(lo[0].is_finite() && hi[0].is_finite() && lo[1].is_finite() && hi[1].is_finite()) {
            return m;
        }
        // Boundary points in a bucket grid, to keep lattice points off the boundary.
        let cell = |q: Point2| {
            (
                ((q[0] - lo[0]) / step).floor() as i64,
                ((q[1] - lo[1]) / step).floor() as i64,
            )
        };
        let mut grid: FastMap<(i64, i64), Vec<Point2>> = FastMap::default();
        for q in rings.iter().flatten() {
            grid.entry(cell(*q)).or_default().push(*q);
        }
        let near_boundary = |q: Point2, s: f64| {
            let (i, j) = cell(q);
            (i - 1..=i + 1).any(|a| {
                (j - 1..=j + 1).any(|b| {
                    grid.get(&(a, b))
                        .is_some_and(|v| v.iter().any(|p| dist2(*p, q) < (0.6 * s) * (0.6 * s)))
                })
            })
        };
        let mut cdt: ConstrainedDelaunayTriangulation<SPoint<f64>> =
            ConstrainedDelaunayTriangulation::new();
        // Our vertex of each triangulation vertex, by the triangulation's (dense) index.
        let mut index: Vec<u32> = vec![];
        let mut add = |cdt: &mut ConstrainedDelaunayTriangulation<SPoint<f64>>,
                       m: &mut LayerMesh,
                       q: Point2,
                       on_boundary: bool| {
            let h = cdt.insert(SPoint::new(q[0], q[1])).ok()?;
            if index.len() <= h.index() {
                index.resize(h.index() + 1, u32::MAX);
            }
            if index[h.index()] == u32::MAX {
                m.q.push(q);
                m.boundary.push(on_boundary);
                index[h.index()] = (m.q.len() - 1) as u32;
            }
            Some(h)
        };
        let ours = |index: &[u32], i: usize| index.get(i).copied().filter(|&v| v != u32::MAX);
        // `region_contains` by horizontal bands of the region's edges.
        let inside = RegionIndex::new(region);
        let mut ring_handles = vec![];
        for ring in &rings {
            let hs: Vec<_> = ring
                .iter()
                .filter_map(|q| add(&mut cdt, &mut m, *q, true))
                .collect();
            ring_handles.push(hs.clone());
            for i in 0..hs.len() {
                let (a, b) = (hs[i], hs[(i + 1) % hs.len()]);
                if a != b && cdt.can_add_constraint(a, b) {
                    cdt.add_constraint(a, b);
                }
            }
        }
        let dy = step * 0.75f64.sqrt();
        let rows = ((hi[1] - lo[1]) / dy).ceil() as usize;
        let cols = ((hi[0] - lo[0]) / step).ceil() as usize;
        for r in 0..=rows {
            let y = lo[1] + r as f64 * dy;
            let shift = if r % 2 == 1 { 0.5 * step } else { 0.0 };
            for c in 0..=cols {
                let q = [lo[0] + shift + c as f64 * step, y];
                if inside.contains(q) && !near_boundary(q, step) {
                    add(&mut cdt, &mut m, q, false);
                }
            }
        }
        // The fine lattice around each convex corner: the coarse one's rows and columns split
        // in three (so the coarse points are among its points), within reach of the corner.
        let fdy = dy / 3.0;
        let span = CORNER_REACH * step;
        for c in &corners {
            let r0 = ((c[1] - span - lo[1]) / fdy).floor().max(0.0) as usize;
            let r1 = ((c[1] + span - lo[1]) / fdy).ceil().max(0.0) as usize;
            for r in r0..=r1 {
                let y = lo[1] + r as f64 * fdy;
                let shift = if r % 2 == 1 { 0.5 * fine } else { 0.0 };
                let c0 = ((c[0] - span - lo[0] - shift) / fine).floor().max(0.0) as usize;
                let c1 = ((c[0] + span - lo[0] - shift) / fine).ceil().max(0.0) as usize;
                for k in c0..=c1 {
                    let q = [lo[0] + shift + k as f64 * fine, y];
                    if dist2(*c, q) <= reach2 && inside.contains(q) && !near_boundary(q, fine) {
                        add(&mut cdt, &mut m, q, false);
                    }
                }
            }
        }
        m.rings = ring_handles
            .iter()
            .map(|hs| hs.iter().filter_map(|h| ours(&index, h.index())).collect())
            .collect();
        for f in cdt.inner_faces() {
            let vs = f.vertices();
            let ids: Option<Vec<u32>> = vs.iter().map(|v| ours(&index, v.fix().index())).collect();
            let Some(ids) = ids else { continue };
            let c = [
                (m.q[ids[0] as usize][0] + m.q[ids[1] as usize][0] + m.q[ids[2] as usize][0]) / 3.0,
                (m.q[ids[0] as usize][1] + m.q[ids[1] as usize][1] + m.q[ids[2] as usize][1]) / 3.0,
            ];
            if inside.contains(c) {
                m.tris.push([ids[0], ids[1], ids[2]]);
            }
        }
        m.around = vec![vec![]; m.q.len()];
        for (t, tri) in m.tris.iter().enumerate() {
            for &v in tri {
                m.around[v as usize].push(t as u32);
            }
        }
        m
    }

    /// The area on the layer surface (the lifted vertices `p`) of the part of the region
    /// where the piecewise-linear field `f` is at least `level`.
    pub fn area_above(&self, f: &[f64], level: f64) -> f64 {
        let tri = |a: P3, b: P3, c: P3| 0.5 * (b - a).cross(&(c - a)).norm();
        let mut sum = 0.0;
        for t in &self.tris {
            let v = t.map(|i| i as usize);
            let (p, h) = (v.map(|i| self.p[i]), v.map(|i| f[i] - level));
            if h.iter().any(|x| !x.is_finite()) {
                continue;
            }
            let above = h.iter().filter(|x| **x >= 0.0).count();
            let whole = tri(p[0], p[1], p[2]);
            let cut = |i: usize, j: usize| p[i] + (p[j] - p[i]) * (h[i] / (h[i] - h[j]));
            sum += match above {
                3 => whole,
                0 => 0.0,
                1 => {
                    let i = (0..3).find(|&i| h[i] >= 0.0).unwrap_or(0);
                    let (j, k) = ((i + 1) % 3, (i + 2) % 3);
                    tri(p[i], cut(i, j), cut(i, k))
                }
                _ => {
                    let i = (0..3).find(|&i| h[i] < 0.0).unwrap_or(0);
                    let (j, k) = ((i + 1) % 3, (i + 2) % 3);
                    whole - tri(p[i], cut(i, j), cut(i, k))
                }
            };
        }
        sum
    }

    /// [`LayerMesh::build`] in the frame `y = M·q` of the chart metric at the region: `M` is
    /// upper triangular with `|M·dq|² = dqᵀ·G·dq`, G the first fundamental form of the layer
    /// surface in the chart (`g[0][0] = |p_s|²`, `g[0][1] = p_s·p_t`, `g[1][1] = |p_t|²`). The
    /// lattice is then equilateral on the surface, not in the chart, so `step` is in mm and
    /// the triangles stay acute where the chart stretches the layer (an offset far from a
    /// cylinder's axis): fast marching's planar-wavefront update needs acute triangles, and
    /// over long obtuse ones it overestimates the distance. Chart coordinates come back in
    /// [`LayerMesh::q`]. A degenerate metric falls back to the chart's own frame.
    pub fn build_with_metric(region: &Region, step: f64, g: [[f64; 2]; 2]) -> LayerMesh {
        let a = g[0][0];
        let m = if a > 1e-12 {
            let (m00, m01) = (a.sqrt(), g[0][1] / a.sqrt());
            let c = g[1][1] - m01 * m01;
            (c > 1e-12 * g[1][1].max(1e-12)).then(|| [m00, m01, c.sqrt()])
        } else {
            None
        };
        let Some([m00, m01, m11]) = m else {
            return LayerMesh::build(region, step);
        };
        let fwd = |q: &Point2| [m00 * q[0] + m01 * q[1], m11 * q[1]];
        let ry = Region {
            outer: region.outer.iter().map(fwd).collect(),
            holes: region
                .holes
                .iter()
                .map(|h| h.iter().map(fwd).collect())
                .collect(),
        };
        let mut mesh = LayerMesh::build(&ry, step);
        for q in &mut mesh.q {
            let t = q[1] / m11;
            *q = [(q[0] - m01 * t) / m00, t];
        }
        mesh.frame = Some([m00, m01, m11]);
        mesh
    }

    /// Exact 3-D distances to the boundary (the lifted ring polylines) of every vertex within
    /// `reach` (chart units) of it, as seeds for [`LayerMesh::march`]: a front started from
    /// exact values a few triangles deep is far more accurate than one started at the ring.
    pub fn boundary_seeds(&self, reach: f64) -> Vec<(u32, f64)> {
        // A grid of half-reach cells in the surface-isotropic frame (about mm): the boundary
        // segments within `reach` of a vertex lie in the 5 × 5 cells around it.
        let cell = (0.5 * reach).max(1e-9);
        let frame = self.frame.unwrap_or([1.0, 0.0, 1.0]);
        let key = |q: Point2| {
            let y = [frame[0] * q[0] + frame[1] * q[1], frame[2] * q[1]];
            ((y[0] / cell).floor() as i64, (y[1] / cell).floor() as i64)
        };
        // Each segment as its start and direction (what `segment_distance` computes from its
        // ends), so a vertex's pass over its cells reads them in a row.
        let mut grid: FastMap<(i64, i64), Vec<Segment>> = FastMap::default();
        for ring in &self.rings {
            let n = ring.len();
            for i in 0..n {
                let (a, b) = (ring[i], ring[(i + 1) % n]);
                let qa = self.q[a as usize];
                let qb = self.q[b as usize];
                let mid = [0.5 * (qa[0] + qb[0]), 0.5 * (qa[1] + qb[1])];
                let (pa, pb) = (self.p[a as usize], self.p[b as usize]);
                let d = pb - pa;
                grid.entry(key(mid))
                    .or_default()
                    .push((pa, d, d.norm_squared()));
            }
        }
        let mut out = vec![];
        for (v, q) in self.q.iter().enumerate() {
            let (i, j) = key(*q);
            let p = self.p[v];
            // `segment_distance` squared; the square root of the least square is the least
            // distance (the root is monotone and rounded correctly).
            let mut best2 = f64::INFINITY;
            for a in i - 2..=i + 2 {
                for b in j - 2..=j + 2 {
                    for &(pa, d, l2) in grid.get(&(a, b)).map(|x| x.as_slice()).unwrap_or(&[]) {
                        let t = if l2 > 0.0 {
                            ((p - pa).dot(&d) / l2).clamp(0.0, 1.0)
                        } else {
                            0.0
                        };
                        best2 = best2.min((p - (pa + d * t)).norm_squared());
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

    /// For each vertex where `mask` holds, the largest `f` over the vertices joined to it
    /// through the mesh within 3-D distance `radius` (others get `f` itself): the local height
    /// of a ridge of `f` seen from its flanks.
    pub fn local_max(&self, f: &[f64], radius: f64, mask: &[bool]) -> Vec<f64> {
        let mut out = f.to_vec();
        if !mask.iter().any(|&m| m) {
            return out;
        }
        let (first, next) = self.neighbours();
        let within = sqrt_at_most(radius);
        // `seen[x] == v + 1`: x was looked at from v, inside the ball or not (no clearing
        // between vertices; each vertex's distance is taken once per flood).
        let mut seen = vec![0u32; self.q.len()];
        let mut stack = vec![];
        for v in 0..self.q.len() {
            if !mask[v] {
                continue;
            }
            let stamp = v as u32 + 1;
            stack.clear();
            stack.push(v as u32);
            seen[v] = stamp;
            let mut best = f[v];
            let pv = self.p[v];
            while let Some(u) = stack.pop() {
                let u = u as usize;
                if f[u].is_finite() {
                    best = best.max(f[u]);
                }
                for &x in &next[first[u] as usize..first[u + 1] as usize] {
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
    /// `first[v + 1]`) into one list.
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

    /// The iso-lines `f = level` over the mesh, chained into polylines, with `other`
    /// interpolated along them. Triangles where `f` is not finite at a vertex are skipped.
    pub fn iso_lines(&self, f: &[f64], level: f64, other: &[f64]) -> Vec<IsoLine> {
        type Key = (u32, u32);
        let key = |a: u32, b: u32| (a.min(b), a.max(b));
        let mut point: FastMap<Key, (Point2, f64)> = FastMap::default();
        let mut links: FastMap<Key, Vec<Key>> = FastMap::default();
        let at = |a: u32, b: u32| -> (Point2, f64) {
            let (fa, fb) = (f[a as usize], f[b as usize]);
            let t = if (fb - fa).abs() > 0.0 {
                ((level - fa) / (fb - fa)).clamp(0.0, 1.0)
            } else {
                0.5
            };
            let (qa, qb) = (self.q[a as usize], self.q[b as usize]);
            (
                [qa[0] + (qb[0] - qa[0]) * t, qa[1] + (qb[1] - qa[1]) * t],
                other[a as usize] + (other[b as usize] - other[a as usize]) * t,
            )
        };
        for tri in &self.tris {
            if tri.iter().any(|&v| !f[v as usize].is_finite()) {
                continue;
            }
            let up = [0, 1, 2].map(|k| f[tri[k] as usize] >= level);
            let Some(lone) = brep::section::lone_vertex(up) else {
                continue;
            };
            let (a, b, c) = (tri[lone], tri[(lone + 1) % 3], tri[(lone + 2) % 3]);
            let (e1, e2) = (key(a, b), key(a, c));
            point.entry(e1).or_insert_with(|| at(a, b));
            point.entry(e2).or_insert_with(|| at(a, c));
            links.entry(e1).or_default().push(e2);
            links.entry(e2).or_default().push(e1);
        }
        let mut used: FastSet<Key> = FastSet::default();
        let mut keys: Vec<Key> = links.keys().copied().collect();
        keys.sort_unstable();
        // Chain from the open ends first, then the rings.
        keys.sort_by_key(|k| links[k].len() != 1);
        let mut out = vec![];
        for s in keys {
            if used.contains(&s) {
                continue;
            }
            let mut chain = vec![s];
            used.insert(s);
            let mut cur = s;
            loop {
                let next = links[&cur].iter().copied().find(|k| !used.contains(k));
                match next {
                    Some(k) => {
                        used.insert(k);
                        chain.push(k);
                        cur = k;
                    }
                    None => break,
                }
            }
            let closed = chain.len() > 2 && links[&cur].contains(&s) && links[&s].len() == 2;
            let mut line = IsoLine {
                closed,
                ..IsoLine::default()
            };
            for k in &chain {
                let (q, o) = point[k];
                line.q.push(q);
                line.other.push(o);
            }
            if closed {
                line.q.push(line.q[0]);
                line.other.push(line.other[0]);
            }
            if line.q.len() >= 2 {
                out.push(line);
            }
        }
        out
    }
}

/// A piece of an iso-line where the distance to the region's boundary is at least the
/// infill area's, and the ways on from its cut ends towards the boundary.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Piece {
    /// The line from cut to cut (or to the line's end), cut exactly at the crossings.
    pub body: Vec<Point2>,
    /// The way on before the body's first point, in the line's order (empty at a line end).
    pub head: Vec<Point2>,
    /// The way on after the body's last point.
    pub tail: Vec<Point2>,
}

impl Piece {
    /// The same piece run the other way.
    pub fn reversed(self) -> Piece {
        let rev = |mut v: Vec<Point2>| {
            v.reverse();
            v
        };
        Piece {
            body: rev(self.body),
            head: rev(self.tail),
            tail: rev(self.head),
        }
    }

    /// The body with both ways on: a raster line run on to the boundary.
    pub fn reaching(self) -> Vec<Point2> {
        let mut pts = self.head;
        pts.extend(self.body);
        pts.extend(self.tail);
        pts
    }
}

/// Where the free ends of [`clip_reaching`]'s pieces run on to, for beads `width` wide: the
/// level `edge` of the line's `other` value (the distance to the region's boundary): 0 for
/// the boundary itself, the inner edge of the last ring's bead inside rings.
#[derive(Debug, Clone, Copy)]
pub struct RunOn {
    /// Bead width, mm.
    pub width: f64,
    /// The `other` value the ends run on to.
    pub edge: f64,
}

/// The pieces of `line` where its `other` value (the distance to the region's boundary) is
/// at least `min`, cut exactly at the crossings, each with the ways on from its cut ends
/// along the line by [`bead_end_reach`]: the edge lies where `other` falls to `run_on.edge`
/// (or the line ends), the room is half the way to where `other` climbs back to `min` (the
/// next piece). `len` is the length on the surface between two chart points.
pub fn clip_reaching(
    line: &IsoLine,
    min: f64,
    run_on: RunOn,
    len: impl Fn(Point2, Point2) -> f64,
) -> Vec<Piece> {
    let n = line.q.len();
    let lerp = |a: Point2, b: Point2, t: f64| [a[0] + (b[0] - a[0]) * t, a[1] + (b[1] - a[1]) * t];
    // The way on from a cut in segment `i` (between points i and i+1) at the cut point `x`,
    // forwards or backwards: the line's points beyond it up to the reach, not `x` itself.
    let run_on = |i: usize, x: Point2, forward: bool| -> Vec<Point2> {
        let RunOn { width, edge } = run_on;
        let mut pts = vec![];
        let (mut at, mut walked, mut prev_d) = (x, 0.0, min);
        let mut k = if forward { i + 1 } else { i };
        let (mut boundary, mut room) = (f64::INFINITY, f64::INFINITY);
        let mut steps: Vec<(Point2, f64)> = vec![];
        while k < n && walked < 2.0 * MAX_END_REACH * width {
            let (q, d) = (line.q[k], line.other[k]);
            let l = len(at, q);
            if !l.is_finite() {
                break;
            }
            if d <= edge {
                let t = if prev_d > d {
                    (prev_d - edge) / (prev_d - d)
                } else {
                    1.0
                };
                boundary = walked + t * l;
                break;
            }
            if d >= min {
                let t = if d > prev_d {
                    (min - prev_d) / (d - prev_d)
                } else {
                    0.0
                };
                room = 0.5 * (walked + t.clamp(0.0, 1.0) * l);
                break;
            }
            walked += l;
            steps.push((q, walked));
            at = q;
            prev_d = d;
            if forward {
                k += 1;
            } else if k == 0 {
                break;
            } else {
                k -= 1;
            }
        }
        if boundary.is_infinite() && room.is_infinite() && walked < 2.0 * MAX_END_REACH * width {
            // The line ends (on the mesh's edge) before either.
            boundary = walked;
        }
        let r = bead_end_reach(width, boundary, room);
        let (mut from, mut done) = (x, 0.0);
        for &(q, w) in &steps {
            if w >= r {
                let seg = w - done;
                let t = if seg > 0.0 { (r - done) / seg } else { 1.0 };
                pts.push(lerp(from, q, t.clamp(0.0, 1.0)));
                return pts;
            }
            pts.push(q);
            from = q;
            done = w;
        }
        if r > done {
            // The reach ends inside the step the walk stopped in (towards point `k`).
            if let Some(&q) = line.q.get(k) {
                let l = len(from, q);
                if l > 0.0 && l.is_finite() {
                    pts.push(lerp(from, q, ((r - done) / l).clamp(0.0, 1.0)));
                }
            }
        }
        pts
    };
    let mut out = vec![];
    let mut cur = Piece::default();
    for i in 0..n {
        let inside = line.other[i] >= min;
        if i > 0 {
            let (a, b) = (line.other[i - 1], line.other[i]);
            if (a >= min) != inside {
                let t = ((min - a) / (b - a)).clamp(0.0, 1.0);
                let x = lerp(line.q[i - 1], line.q[i], t);
                cur.body.push(x);
                if inside {
                    // Entering: the way back out, reversed, leads up to the cut.
                    let mut back = run_on(i - 1, x, false);
                    back.reverse();
                    cur.head = back;
                } else {
                    cur.tail = run_on(i - 1, x, true);
                    out.push(std::mem::take(&mut cur));
                }
            }
        }
        if inside {
            cur.body.push(line.q[i]);
        }
    }
    out.push(cur);
    out.retain(|p| p.body.len() >= 2);
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    fn square(a: f64) -> Region {
        Region {
            outer: vec![[0.0, 0.0], [a, 0.0], [a, a], [0.0, a]],
            holes: vec![],
        }
    }

    #[test]
    fn the_square_limit_answers_as_the_root_does() {
        for r in [0.0, 1e-300, 0.3, 0.675, 1.0, 2.0f64.sqrt(), 1e10] {
            let lim = sqrt_at_most(r);
            assert!(lim.sqrt() <= r, "{r}");
            assert!(f64::from_bits(lim.to_bits() + 1).sqrt() > r, "{r}");
            for k in -50i64..50 {
                let x = f64::from_bits((lim.to_bits() as i64 + k).max(0) as u64);
                assert_eq!(x.sqrt() <= r, x <= lim, "r {r}, x {x}");
            }
        }
    }

    #[test]
    fn marching_on_a_flat_square_gives_euclidean_distance() {
        let mut m = LayerMesh::build(&square(10.0), 0.25);
        m.p = m.q.iter().map(|q| P3::new(q[0], q[1], 0.0)).collect();
        let seeds: Vec<(u32, f64)> = (0..m.q.len() as u32)
            .filter(|&v| m.boundary[v as usize])
            .map(|v| (v, 0.0))
            .collect();
        let d = m.march(&m.boundary_seeds(0.5));
        let _ = seeds;
        let mut worst = 0.0f64;
        let mut bias = 0.0;
        for (q, d) in m.q.iter().zip(&d) {
            let exact = q[0].min(q[1]).min(10.0 - q[0]).min(10.0 - q[1]);
            worst = worst.max((d - exact).abs());
            bias += d - exact;
        }
        assert!(bias.abs() / (m.q.len() as f64) < 0.01, "bias {bias}");
        // Exact seeds at the boundary, planar fronts: exact up to the square's corners.
        assert!(worst < 0.05, "worst error {worst}");
        // Iso-line at 2 mm: a square ring 6 mm a side.
        let rings = m.iso_lines(&d, 2.0, &d);
        assert_eq!(rings.len(), 1);
        assert!(rings[0].closed);
        let len: f64 = rings[0]
            .q
            .windows(2)
            .map(|w| dist2(w[0], w[1]).sqrt())
            .sum();
        assert!((len - 24.0).abs() < 1.0, "ring length {len}");
    }

    #[test]
    fn marching_on_a_cylinder_measures_along_the_surface() {
        // Chart (s, t) = (R·angle, z) of a cylinder of radius 5: distances from the line s = 0
        // are arc lengths, which the chart keeps, not chords.
        let r = 5.0;
        let mut m = LayerMesh::build(&square(10.0), 0.2);
        m.p =
            m.q.iter()
                .map(|q| P3::new(r * (q[0] / r).cos(), r * (q[0] / r).sin(), q[1]))
                .collect();
        let seeds: Vec<(u32, f64)> = (0..m.q.len() as u32)
            .filter(|&v| m.q[v as usize][0] < 1e-9)
            .map(|v| (v, 0.0))
            .collect();
        let d = m.march(&seeds);
        for (q, d) in m.q.iter().zip(&d) {
            assert!((d - q[0]).abs() < 0.05 + 0.01 * q[0], "at {q:?}: {d}");
        }
    }

    #[test]
    fn clipping_cuts_at_the_crossings_and_runs_on_to_the_edge() {
        /// 0.45 mm beads run on to the region's boundary.
        const TO_BOUNDARY: RunOn = RunOn {
            width: 0.45,
            edge: 0.0,
        };
        let flat = |a: Point2, b: Point2| (a[0] - b[0]).hypot(a[1] - b[1]);
        // `other` falls to 0 (the boundary) at both ends of the line.
        let line = IsoLine {
            q: vec![[0.0, 0.0], [1.0, 0.0], [2.0, 0.0], [3.0, 0.0]],
            other: vec![0.0, 1.0, 1.0, 0.0],
            closed: false,
        };
        let pieces = clip_reaching(&line, 0.5, TO_BOUNDARY, flat);
        assert_eq!(pieces.len(), 1);
        let p = &pieces[0];
        assert_eq!(p.body, vec![[0.5, 0.0], [1.0, 0.0], [2.0, 0.0], [2.5, 0.0]]);
        // On to a hundredth of a bead before the boundary.
        let m = crate::fill::END_MARGIN * 0.45;
        assert_eq!(p.head.len(), 1);
        assert!((p.head[0][0] - m).abs() < 1e-12, "{:?}", p.head);
        assert!((p.tail[0][0] - (3.0 - m)).abs() < 1e-12, "{:?}", p.tail);
        let reversed = p.clone().reversed();
        assert_eq!(reversed.head, p.tail);
        assert_eq!(reversed.clone().reaching().len(), 6);
        // Inside rings, on only to the level of the last ring's bead edge.
        let ringed = clip_reaching(
            &line,
            0.5,
            RunOn {
                width: 0.45,
                edge: 0.25,
            },
            flat,
        );
        assert!(
            (ringed[0].head[0][0] - (0.25 + m)).abs() < 1e-12,
            "{:?}",
            ringed[0].head
        );
        assert!(
            (ringed[0].tail[0][0] - (2.75 - m)).abs() < 1e-12,
            "{:?}",
            ringed[0].tail
        );
        // A dip that does not reach the boundary: the two pieces run on to meet halfway.
        let line = IsoLine {
            q: (0..5).map(|i| [i as f64, 0.0]).collect(),
            other: vec![0.0, 1.0, 0.2, 1.0, 0.0],
            closed: false,
        };
        let pieces = clip_reaching(&line, 0.5, TO_BOUNDARY, flat);
        assert_eq!(pieces.len(), 2);
        let (a, b) = (&pieces[0], &pieces[1]);
        assert!((a.body[a.body.len() - 1][0] - 1.625).abs() < 1e-12);
        assert_eq!(a.tail.last(), Some(&[2.0, 0.0]));
        assert_eq!(b.head.first(), Some(&[2.0, 0.0]));
    }

    #[test]
    fn a_large_region_gets_a_coarser_lattice_not_none() {
        let big = square(400.0);
        let s = lattice_step(&big.outer, 0.15);
        let cells = (400.0 / s) * (400.0 / s);
        assert!(
            s > 0.15 && (cells - MAX_CELLS).abs() < 1.0,
            "step {s}, {cells} cells"
        );
        let small = square(5.0);
        assert_eq!(lattice_step(&small.outer, 0.15), 0.15);
    }
}
