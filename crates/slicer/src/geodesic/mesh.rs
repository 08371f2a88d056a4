//! The layer mesh: a region of a layer, in its chart, triangulated on a lattice equilateral on
//! the layer surface.

use crate::geom2d::{dist2, Point2, Region, RegionIndex};
use crate::tolerance::METRIC_DEGENERATE;
use brep::math::P3;
use spade::{ConstrainedDelaunayTriangulation, Point2 as SPoint, Triangulation};

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
    pub(super) around: Vec<Vec<u32>>,
    /// The vertices joined to each vertex by an edge (offsets into one list, and the list),
    /// made by the first search that needs them.
    pub(super) adjacency: std::sync::OnceLock<(Vec<u32>, Vec<u32>)>,
    /// The triangle across each edge of each triangle, made by the first ray that needs it
    /// (`LayerMesh::ray_max`).
    pub(super) tri_adjacency: std::sync::OnceLock<Vec<[u32; 3]>>,
    /// The upper-triangular map `(m00, m01, m11)` from chart to the surface-isotropic frame
    /// of [`LayerMesh::build_with_metric`]; `None`: the chart itself.
    pub(super) frame: Option<[f64; 3]>,
}

/// One iso-line: chart points, and the value of a second field at each.
#[derive(Debug, Clone, Default)]
pub struct IsoLine {
    /// Chart coordinates along the line.
    pub q: Vec<Point2>,
    /// The second field interpolated at each point.
    pub other: Vec<f64>,
    /// At each point, the end of the lattice edge it lies on where the field is below the
    /// level (the end farther down; [`LayerMesh::ascent`] there tells which way is up).
    pub low: Vec<u32>,
    /// The line is a closed ring (the first point is repeated at the end).
    pub closed: bool,
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

/// Points in the cells of a grid, cell by cell in rows (one list, a run of it per cell), for
/// the points of a few neighbouring cells at a time.
struct PointGrid {
    /// The lowest cell (column, row) with a point.
    lo: (i64, i64),
    /// Columns from `lo.0` to the highest with a point.
    width: usize,
    /// Rows from `lo.1`.
    height: usize,
    /// Where each cell's run starts in `points` (one more at the end).
    first: Vec<usize>,
    points: Vec<Point2>,
}

impl PointGrid {
    /// The grid of `points`, each with its cell (column, row).
    fn new(points: impl Iterator<Item = ((i64, i64), Point2)>) -> PointGrid {
        let points: Vec<((i64, i64), Point2)> = points.collect();
        let (mut lo, mut hi) = ((i64::MAX, i64::MAX), (i64::MIN, i64::MIN));
        for ((i, j), _) in &points {
            lo = (lo.0.min(*i), lo.1.min(*j));
            hi = (hi.0.max(*i), hi.1.max(*j));
        }
        if points.is_empty() {
            return PointGrid {
                lo: (0, 0),
                width: 0,
                height: 0,
                first: vec![0],
                points: vec![],
            };
        }
        let (width, height) = ((hi.0 - lo.0 + 1) as usize, (hi.1 - lo.1 + 1) as usize);
        let at = |(i, j): (i64, i64)| (j - lo.1) as usize * width + (i - lo.0) as usize;
        let mut first = vec![0usize; width * height + 1];
        for (c, _) in &points {
            first[at(*c) + 1] += 1;
        }
        for k in 0..width * height {
            first[k + 1] += first[k];
        }
        let mut fill = first.clone();
        let mut sorted = vec![[0.0; 2]; points.len()];
        for (c, q) in points {
            sorted[fill[at(c)]] = q;
            fill[at(c)] += 1;
        }
        PointGrid {
            lo,
            width,
            height,
            first,
            points: sorted,
        }
    }

    /// The points of cells `i0..=i1` of row `j`.
    fn row(&self, j: i64, i0: i64, i1: i64) -> &[Point2] {
        if j < self.lo.1 || j - self.lo.1 >= self.height as i64 {
            return &[];
        }
        let (i0, i1) = (i0.max(self.lo.0), i1.min(self.lo.0 + self.width as i64 - 1));
        if i0 > i1 {
            return &[];
        }
        let base = (j - self.lo.1) as usize * self.width;
        let (a, b) = (
            base + (i0 - self.lo.0) as usize,
            base + (i1 - self.lo.0) as usize,
        );
        &self.points[self.first[a]..self.first[b + 1]]
    }
}

/// The most lattice cells (of the region's box) a layer mesh is built with.
pub(super) const MAX_CELLS: f64 = 4e6;

/// The lattice step for a region whose outer ring is `outer`: `step`, or coarser where the
/// region's box would hold more than [`MAX_CELLS`] cells of it (a curved layer some 300 mm
/// across at 0.15 mm), so a large region is filled rather than left empty.
pub(super) fn lattice_step(outer: &[Point2], step: f64) -> f64 {
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
        let grid = PointGrid::new(rings.iter().flatten().map(|q| (cell(*q), *q)));
        let near_boundary = |q: Point2, s: f64| {
            let (i, j) = cell(q);
            (j - 1..=j + 1).any(|b| {
                grid.row(b, i - 1, i + 1)
                    .iter()
                    .any(|p| dist2(*p, q) < (0.6 * s) * (0.6 * s))
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
            let row = inside.row(y);
            for c in 0..=cols {
                let q = [lo[0] + shift + c as f64 * step, y];
                if row.contains(q[0]) && !near_boundary(q, step) {
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
                let row = inside.row(y);
                let c0 = ((c[0] - span - lo[0] - shift) / fine).floor().max(0.0) as usize;
                let c1 = ((c[0] + span - lo[0] - shift) / fine).ceil().max(0.0) as usize;
                for k in c0..=c1 {
                    let q = [lo[0] + shift + k as f64 * fine, y];
                    if dist2(*c, q) <= reach2 && row.contains(q[0]) && !near_boundary(q, fine) {
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

    /// `q` in the frame of the chart's metric at the region, where lengths are the surface's
    /// ([`LayerMesh::build_with_metric`]); the chart's own coordinates without one.
    pub fn metric_point(&self, q: Point2) -> Point2 {
        match self.frame {
            Some([m00, m01, m11]) => [m00 * q[0] + m01 * q[1], m11 * q[1]],
            None => q,
        }
    }

    /// The chart step at vertex `v` that raises the piecewise-linear field `f` by one, along
    /// its steepest ascent there: the direction of the triangles' gradients around `v`
    /// (summed, weighted by area), the length one over the steepest of them (a triangle that
    /// spans a ridge of `f` is flatter than its flanks, and would overshoot). `None` where
    /// the field is flat or not finite around `v`.
    pub fn ascent(&self, f: &[f64], v: u32) -> Option<Point2> {
        let mut sum = [0.0f64; 2];
        let mut steepest = 0.0f64;
        for &t in &self.around[v as usize] {
            let [a, b, c] = self.tris[t as usize].map(|i| i as usize);
            let (fa, fb, fc) = (f[a], f[b], f[c]);
            if !(fa.is_finite() && fb.is_finite() && fc.is_finite()) {
                continue;
            }
            let (qa, qb, qc) = (self.q[a], self.q[b], self.q[c]);
            let (u, w) = (
                [qb[0] - qa[0], qb[1] - qa[1]],
                [qc[0] - qa[0], qc[1] - qa[1]],
            );
            let det = u[0] * w[1] - u[1] * w[0];
            if det.abs() < f64::MIN_POSITIVE.sqrt() {
                continue;
            }
            // The gradient g with g·u = fb − fa and g·w = fc − fa.
            let (du, dw) = (fb - fa, fc - fa);
            let g = [(du * w[1] - dw * u[1]) / det, (dw * u[0] - du * w[0]) / det];
            let area = 0.5 * det.abs();
            sum = [sum[0] + area * g[0], sum[1] + area * g[1]];
            steepest = steepest.max(g[0].hypot(g[1]));
        }
        let n = sum[0].hypot(sum[1]);
        if n <= 0.0 || steepest <= 0.0 || !n.is_finite() {
            return None;
        }
        let k = 1.0 / (n * steepest);
        Some([sum[0] * k, sum[1] * k])
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
        let m = if a > METRIC_DEGENERATE {
            let (m00, m01) = (a.sqrt(), g[0][1] / a.sqrt());
            let c = g[1][1] - m01 * m01;
            (c > METRIC_DEGENERATE * g[1][1].max(METRIC_DEGENERATE)).then(|| [m00, m01, c.sqrt()])
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
}
