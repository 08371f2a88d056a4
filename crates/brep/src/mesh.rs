//! Watertight triangulation of faces.
//!
//! Every B-rep edge is discretised once, in 3-D, and both faces that use it take the same points,
//! so the mesh has no cracks. Each face's loops are taken into the surface's `(u, v)` domain by
//! projection, unwrapped across periods, bridged along singular lines (sphere poles, cone apexes),
//! closed through a pole or paired with each other where they wrap around the surface (the cut
//! this draws across the face, on both sides of the seam, is sampled like an edge, both sides
//! sharing its points), and triangulated there (constrained Delaunay, spade) with interior points
//! spaced by the surface's curvature. The `(u, v)` triangles are kept: mass properties integrate
//! the exact surface over them.

use crate::curve::Curve;
use crate::math::{Aabb, P3};
use crate::surface::Surface;
use crate::topology::{Brep, EdgeId, FaceId, LoopId};
use spade::{ConstrainedDelaunayTriangulation, Point2, Triangulation};
use std::collections::HashMap;

/// How finely to mesh.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct MeshOptions {
    /// Largest distance between a chord and the surface it stands for, mm.
    pub chord_tol: f64,
    /// Largest turn of the tangent or normal between neighbouring points, radians.
    pub angle_tol: f64,
    /// A finer chord tolerance for edges only (mass properties integrate the exact surface
    /// inside faces, so only the boundaries need to be fine); `None` uses `chord_tol`.
    pub edge_chord_tol: Option<f64>,
}

impl MeshOptions {
    /// A chord tolerance with a 15° angular limit.
    pub fn with_tolerance(chord_tol: f64) -> Self {
        MeshOptions {
            chord_tol,
            angle_tol: 15f64.to_radians(),
            edge_chord_tol: None,
        }
    }
}

impl Default for MeshOptions {
    fn default() -> Self {
        MeshOptions::with_tolerance(0.05)
    }
}

/// Why a face could not be meshed.
#[derive(Debug, thiserror::Error)]
pub enum MeshError {
    /// A face whose boundary makes no region on its surface.
    #[error("face #{id}: {msg}")]
    Face {
        /// STEP `#id` of the face.
        id: u64,
        /// What went wrong.
        msg: String,
    },
}

/// The triangulation of one face in its parameter domain.
#[derive(Debug, Clone)]
pub struct FaceTriangulation {
    /// The face.
    pub face: FaceId,
    /// `(u, v)` of each local vertex (unwrapped: periodic parameters may run past one period).
    pub uv: Vec<[f64; 2]>,
    /// Index into [`Mesh::positions`] of each local vertex.
    pub vertex: Vec<u32>,
    /// Triangles over local vertices, counter-clockwise about the face's outward normal. Some
    /// may collapse to a point or line in 3-D at a pole; [`Mesh::triangles`] drops those.
    pub triangles: Vec<[u32; 3]>,
}

/// How a mesh edge is used: by triangles running it low-to-high and high-to-low vertex
/// index, and which face triangulations (indices into [`Mesh::faces`]) those are.
#[derive(Debug, Default)]
struct EdgeUse {
    up: i32,
    down: i32,
    faces: Vec<usize>,
}

impl EdgeUse {
    /// Used once each way: a closed, consistently oriented edge.
    fn closed(&self) -> bool {
        self.up == 1 && self.down == 1
    }
}

/// A triangle mesh of a set of faces, sharing vertices along edges.
#[derive(Debug, Clone, Default)]
pub struct Mesh {
    /// Vertex positions, mm.
    pub positions: Vec<P3>,
    /// Per-face triangulations.
    pub faces: Vec<FaceTriangulation>,
    /// The vertex indices along each B-rep edge, from its start vertex to its end vertex.
    pub edge_points: HashMap<EdgeId, Vec<u32>>,
    /// The curve parameter of each point of [`Mesh::edge_points`], where the mesher sampled
    /// the edge's curve.
    pub edge_params: HashMap<EdgeId, Vec<f64>>,
}

impl Mesh {
    /// All triangles as global vertex indices, without those that collapse in 3-D.
    pub fn triangles(&self) -> Vec<[u32; 3]> {
        self.face_triangles().map(|(_, g)| g).collect()
    }

    /// Each triangle that does not collapse in 3-D, as global vertex indices, with the index
    /// of its face triangulation in [`Mesh::faces`].
    fn face_triangles(&self) -> impl Iterator<Item = (usize, [u32; 3])> + '_ {
        self.faces.iter().enumerate().flat_map(|(k, f)| {
            f.triangles
                .iter()
                .map(move |t| (k, t.map(|i| f.vertex[i as usize])))
                .filter(|(_, g)| g[0] != g[1] && g[1] != g[2] && g[0] != g[2])
        })
    }

    /// How each undirected mesh edge (its vertex indices, low first) is used.
    fn edge_uses(&self) -> HashMap<(u32, u32), EdgeUse> {
        let mut uses: HashMap<(u32, u32), EdgeUse> = HashMap::new();
        for (k, t) in self.face_triangles() {
            for j in 0..3 {
                let (a, b) = (t[j], t[(j + 1) % 3]);
                let e = uses.entry((a.min(b), a.max(b))).or_default();
                if a < b {
                    e.up += 1
                } else {
                    e.down += 1
                }
                e.faces.push(k);
            }
        }
        uses
    }

    /// Edges of the 3-D mesh not shared by exactly two triangles in opposite directions:
    /// `(boundary, non_manifold_or_misoriented)` counts. Both zero means watertight.
    pub fn open_edges(&self) -> (usize, usize) {
        let mut open = 0;
        let mut bad = 0;
        for e in self.edge_uses().values() {
            if e.up + e.down == 1 {
                open += 1;
            } else if !e.closed() {
                bad += 1;
            }
        }
        (open, bad)
    }

    /// The faces with a triangle edge not shared by exactly two triangles in opposite
    /// directions: where the mesh opens (or folds), face by face, in mesh order.
    pub fn faces_at_open_edges(&self) -> Vec<FaceId> {
        let mut bad: Vec<usize> = self
            .edge_uses()
            .into_values()
            .filter(|e| !e.closed())
            .flat_map(|e| e.faces)
            .collect();
        bad.sort_unstable();
        bad.dedup();
        bad.into_iter().map(|k| self.faces[k].face).collect()
    }

    /// The generalised winding number of the closed mesh around `p`: about 1 inside, 0 outside
    /// (the sum of the solid angles the triangles subtend, after Van Oosterom & Strackee), robust
    /// where a ray cast would graze an edge.
    pub fn winding_number(&self, p: &P3) -> f64 {
        let mut total = 0.0;
        for t in self.triangles() {
            let a = self.positions[t[0] as usize] - p;
            let b = self.positions[t[1] as usize] - p;
            let c = self.positions[t[2] as usize] - p;
            let (la, lb, lc) = (a.norm(), b.norm(), c.norm());
            let num = a.dot(&b.cross(&c));
            let den = la * lb * lc + a.dot(&b) * lc + b.dot(&c) * la + c.dot(&a) * lb;
            total += 2.0 * num.atan2(den);
        }
        total / (4.0 * std::f64::consts::PI)
    }

    /// The bounding box of the vertices.
    pub fn bbox(&self) -> Aabb {
        let mut b = Aabb::empty();
        for p in &self.positions {
            b.add(p);
        }
        b
    }
}

/// A boundary point of a face in its parameter domain.
#[derive(Debug, Clone, Copy)]
struct Pt {
    uv: [f64; 2],
    idx: u32,
    /// 0: regular; 1: `u` is free here (`S_u = 0`); 2: `v` is free (`S_v = 0`).
    sing: u8,
}

/// Meshes the given faces. Faces sharing an edge share its vertices.
pub fn mesh_faces(brep: &Brep, faces: &[FaceId], opts: &MeshOptions) -> Result<Mesh, MeshError> {
    let (positions, vert_idx, edge_pts, edge_params) = face_edge_points(brep, faces, opts);
    let mut m = Mesh {
        positions,
        ..Default::default()
    };
    for &f in faces {
        let ft = mesh_face(brep, f, &edge_pts, &vert_idx, &mut m.positions, opts)?;
        m.faces.push(ft);
    }
    m.edge_points = edge_pts;
    m.edge_params = edge_params;
    Ok(m)
}

/// A face's trimmed domain: closed polygons in the surface's `(u, v)` parameters (periodic
/// parameters unwrapped so the polygons do not jump), edges sampled within `opts`.
#[derive(Debug, Clone)]
pub struct FaceDomain {
    /// Boundary polygons; the region is what an even number of them does not enclose.
    pub loops: Vec<Vec<[f64; 2]>>,
    /// Periods of `u` and `v`, where the surface closes on itself.
    pub periods: [Option<f64>; 2],
}

impl FaceDomain {
    /// Whether `(u, v)` (in any period) lies in the face.
    pub fn contains(&self, uv: [f64; 2]) -> bool {
        let ks = |p: Option<f64>| {
            if p.is_some() {
                vec![0.0, -1.0, 1.0, -2.0, 2.0]
            } else {
                vec![0.0]
            }
        };
        for a in ks(self.periods[0]) {
            for b in ks(self.periods[1]) {
                let q = [
                    uv[0] + a * self.periods[0].unwrap_or(0.0),
                    uv[1] + b * self.periods[1].unwrap_or(0.0),
                ];
                let mut inside = false;
                for l in &self.loops {
                    let n = l.len();
                    for k in 0..n {
                        let (p0, p1) = (l[k], l[(k + 1) % n]);
                        if (p0[1] > q[1]) != (p1[1] > q[1]) {
                            let x = p0[0] + (q[1] - p0[1]) * (p1[0] - p0[0]) / (p1[1] - p0[1]);
                            if x > q[0] {
                                inside = !inside;
                            }
                        }
                    }
                }
                if inside {
                    return true;
                }
            }
        }
        false
    }
}

/// Vertex positions, vertex indices and edge point indices for one face's boundary.
#[allow(clippy::type_complexity)]
fn face_edge_points(
    brep: &Brep,
    faces: &[FaceId],
    opts: &MeshOptions,
) -> (
    Vec<P3>,
    Vec<Option<u32>>,
    HashMap<EdgeId, Vec<u32>>,
    HashMap<EdgeId, Vec<f64>>,
) {
    let mut positions: Vec<P3> = vec![];
    let mut params_of: HashMap<EdgeId, Vec<f64>> = HashMap::new();
    let mut vert_idx: Vec<Option<u32>> = vec![None; brep.vertices.len()];
    let mut edge_pts: HashMap<EdgeId, Vec<u32>> = HashMap::new();
    for e in brep.edges_of(faces) {
        let edge = brep.edge(e);
        for v in [edge.start, edge.end] {
            if vert_idx[v.idx()].is_none() {
                vert_idx[v.idx()] = Some(positions.len() as u32);
                positions.push(brep.vertices[v.idx()].point);
            }
        }
        let (Some(s), Some(t)) = (vert_idx[edge.start.idx()], vert_idx[edge.end.idx()]) else {
            continue;
        };
        let c = brep.edge_curve(e);
        let mut ts = edge_params(c, edge.t_start, edge.t_end, opts);
        // The surfaces the edge bounds (curved ones: a plane's parameters are linear).
        let surfs: Vec<&Surface> = edge
            .coedges
            .iter()
            .map(|&ce| brep.coedge_face(ce))
            .filter(|f| faces.contains(f))
            .map(|f| brep.face_surface(f))
            .filter(|s| !matches!(s, Surface::Plane { .. }))
            .collect();
        if !surfs.is_empty() && ts.len() >= 2 {
            ts = refine_on_surfaces(c, &ts, &surfs, opts);
        }
        let mut ids = vec![s];
        for &t in &ts[1..ts.len().saturating_sub(1)] {
            ids.push(positions.len() as u32);
            positions.push(c.eval(t));
        }
        ids.push(t);
        edge_pts.insert(e, ids);
        params_of.insert(e, ts);
    }
    for v in brep.vertices_of(faces) {
        if vert_idx[v.idx()].is_none() {
            vert_idx[v.idx()] = Some(positions.len() as u32);
            positions.push(brep.vertices[v.idx()].point);
        }
    }
    (positions, vert_idx, edge_pts, params_of)
}

/// What a loop is to its face.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum LoopRole {
    /// The boundary enclosing the face.
    Outer,
    /// A hole inside the face.
    Inner,
    /// A loop winding around a periodic surface (one rim of a band on a cylinder).
    Wrapping,
    /// A single vertex (a pole or apex).
    Vertex,
}

/// The role of each of a face's loops, found in its parameter domain: loops winding around the
/// surface are `Wrapping`; of the others, the one enclosing the largest area is `Outer` unless
/// a wrapping loop or a pole bounds the face, and the rest are `Inner`.
pub fn loop_roles(
    brep: &Brep,
    f: FaceId,
    opts: &MeshOptions,
) -> Result<Vec<(LoopId, LoopRole)>, MeshError> {
    let (positions, vert_idx, edge_pts, _) = face_edge_points(brep, &[f], opts);
    let (chains, _) = loop_chains(brep, f, &edge_pts, &vert_idx, &positions)?;
    let face = brep.face(f);
    let mut out: Vec<(LoopId, LoopRole)> = face
        .loops
        .iter()
        .filter(|l| brep.loops[l.idx()].coedges.is_empty())
        .map(|&l| (l, LoopRole::Vertex))
        .collect();
    let wraps = chains.iter().any(|(_, _, w)| *w != [0, 0]);
    // A loop with a pole bridge closes through the pole: it is the face's outer boundary.
    let bridged = |pts: &[Pt]| {
        let n = pts.len();
        (0..n).any(|k| pts[k].sing != 0 && pts[k].sing == pts[(k + 1) % n].sing)
    };
    let has_vertex_loop = out.iter().any(|(_, r)| *r == LoopRole::Vertex);
    let mut outer = None;
    if !wraps && !has_vertex_loop {
        outer = chains
            .iter()
            .filter(|(_, _, w)| *w == [0, 0])
            .max_by(|a, b| signed_area(&a.1).abs().total_cmp(&signed_area(&b.1).abs()))
            .map(|(l, _, _)| *l);
    }
    for (l, pts, w) in &chains {
        let role = if *w != [0, 0] {
            LoopRole::Wrapping
        } else if Some(*l) == outer || bridged(pts) {
            LoopRole::Outer
        } else {
            LoopRole::Inner
        };
        out.push((*l, role));
    }
    Ok(out)
}

/// The trimmed parameter domain of one face.
pub fn face_domain(brep: &Brep, f: FaceId, opts: &MeshOptions) -> Result<FaceDomain, MeshError> {
    let (mut positions, vert_idx, edge_pts, _) = face_edge_points(brep, &[f], opts);
    let (polys, _) = face_polygons(brep, f, &edge_pts, &vert_idx, &mut positions, opts)?;
    let s = brep.face_surface(f);
    Ok(FaceDomain {
        loops: polys
            .into_iter()
            .map(|p| p.into_iter().map(|q| q.uv).collect())
            .collect(),
        periods: [s.u_period(), s.v_period()],
    })
}

/// Points strictly inside an edge (its vertices excluded), spaced by the tolerances.
pub fn discretize_edge(c: &Curve, t0: f64, t1: f64, opts: &MeshOptions) -> Vec<P3> {
    let ts = edge_params(c, t0, t1, opts);
    if ts.len() <= 2 {
        return vec![];
    }
    ts[1..ts.len() - 1].iter().map(|&t| c.eval(t)).collect()
}

/// Refines an edge's sample parameters `ts` until, on each curved surface the edge bounds,
/// the surface over the straight segment between two samples' `(u, v)` (which is what a face
/// mesher draws) stays within the chord tolerance of the curve between them. Where the
/// surface's parameters bend round the edge, as near a sphere's pole, 3-D chords alone left
/// segments whose `(u, v)` image swung a millimetre and more off the edge: the face was
/// meshed and integrated over the wrong region (a rib on a dome's pole read 3.6 % too much
/// sphere, its feature 4 % too little volume).
fn refine_on_surfaces(c: &Curve, ts: &[f64], surfs: &[&Surface], opts: &MeshOptions) -> Vec<f64> {
    let tol = opts.edge_chord_tol.unwrap_or(opts.chord_tol);
    // Each sample with its `(u, v)` on every surface, projected once, each from its
    // neighbour's parameters.
    let uv_of = |p: &P3, hints: &[[f64; 2]]| -> Vec<[f64; 2]> {
        surfs
            .iter()
            .enumerate()
            .map(|(k, s)| {
                let hint = hints.get(k).map(|h| (h[0], h[1]));
                let (mut u, mut v) = s.project(p, hint);
                if let Some(h) = hints.get(k) {
                    if let Some(per) = s.u_period() {
                        u = crate::math::nearest_periodic(u, h[0], per);
                    }
                    if let Some(per) = s.v_period() {
                        v = crate::math::nearest_periodic(v, h[1], per);
                    }
                }
                [u, v]
            })
            .collect()
    };
    let mut prev: Vec<[f64; 2]> = vec![];
    let mut samples: Vec<(f64, P3, Vec<[f64; 2]>)> = Vec::with_capacity(ts.len());
    for &t in ts {
        let p = c.eval(t);
        let uv = uv_of(&p, &prev);
        prev = uv.clone();
        samples.push((t, p, uv));
    }
    let mut out = vec![ts[0]];
    for w in samples.windows(2) {
        // Depth-first halving, at most 2^6 pieces a segment.
        let mut stack = vec![(w[0].clone(), w[1].clone(), 0u32)];
        while let Some((a, b, d)) = stack.pop() {
            if d >= 6 || (b.1 - a.1).norm() <= tol {
                out.push(b.0);
                continue;
            }
            let m = 0.5 * (a.0 + b.0);
            let pm = c.eval(m);
            let mid: Vec<[f64; 2]> =
                a.2.iter()
                    .zip(&b.2)
                    .map(|(x, y)| [0.5 * (x[0] + y[0]), 0.5 * (x[1] + y[1])])
                    .collect();
            let uv = uv_of(&pm, &mid);
            // Against the curve's own point projected onto the surface: a file's edge may lie
            // off its face by more than the tolerance, which no refinement closes.
            let off = surfs.iter().enumerate().any(|(k, s)| {
                if singular_kind(s, a.2[k]) != 0 || singular_kind(s, b.2[k]) != 0 {
                    return false;
                }
                (s.eval(mid[k][0], mid[k][1]) - s.eval(uv[k][0], uv[k][1])).norm() > tol
            });
            if off {
                let mid = (m, pm, uv);
                stack.push((mid.clone(), b, d + 1));
                stack.push((a, mid, d + 1));
            } else {
                out.push(b.0);
            }
        }
    }
    out
}

/// The curve parameters an edge is sampled at, both ends included.
fn edge_params(c: &Curve, t0: f64, t1: f64, opts: &MeshOptions) -> Vec<f64> {
    let opts = &MeshOptions {
        chord_tol: opts.edge_chord_tol.unwrap_or(opts.chord_tol),
        ..*opts
    };
    let n0 = match c {
        // A line is its chord.
        Curve::Line { .. } => return vec![t0, t1],
        Curve::Polyline(p) => p.len().saturating_sub(1).max(1),
        Curve::Circle { radius, .. } => arc_segments((t1 - t0).abs(), *radius, opts),
        Curve::Ellipse { a, b, .. } => arc_segments((t1 - t0).abs(), a.max(*b), opts) * 2,
        Curve::Nurbs(n) => (n.spans * 2).clamp(4, 2000),
        Curve::Trimmed { .. } | Curve::Hyperbola { .. } | Curve::Parabola { .. } => 8,
    };
    let mut ts: Vec<f64> = (0..=n0)
        .map(|i| t0 + (t1 - t0) * i as f64 / n0 as f64)
        .collect();
    if !matches!(c, Curve::Circle { .. } | Curve::Polyline(_)) {
        // Adaptive refinement by chord deviation and tangent turn.
        let mut out = vec![ts[0]];
        for w in ts.windows(2) {
            refine(c, w[0], w[1], opts, 0, &mut out);
        }
        ts = out;
    }
    ts
}

fn arc_segments(angle: f64, radius: f64, opts: &MeshOptions) -> usize {
    let by_chord = if opts.chord_tol < radius {
        2.0 * (1.0 - opts.chord_tol / radius).acos()
    } else {
        std::f64::consts::PI
    };
    let step = by_chord.min(opts.angle_tol).max(1e-3);
    ((angle / step).ceil() as usize).clamp(1, 100_000)
}

fn refine(c: &Curve, a: f64, b: f64, opts: &MeshOptions, depth: u32, out: &mut Vec<f64>) {
    let m = 0.5 * (a + b);
    if depth < 14 {
        let pa = c.eval(a);
        let pb = c.eval(b);
        let pm = c.eval(m);
        let dev = chord_deviation(&pa, &pm, &pb);
        let ta = c.deriv(a);
        let tb = c.deriv(b);
        let turn = if ta.norm() > 1e-300 && tb.norm() > 1e-300 {
            ta.angle(&tb)
        } else {
            0.0
        };
        if dev > opts.chord_tol || turn > opts.angle_tol {
            refine(c, a, m, opts, depth + 1, out);
            refine(c, m, b, opts, depth + 1, out);
            return;
        }
    }
    out.push(b);
}

/// Distance from `pm` (a curve's point between `pa` and `pb`) to the chord `pa`–`pb`; to `pa`
/// when the chord has no length.
fn chord_deviation(pa: &P3, pm: &P3, pb: &P3) -> f64 {
    let chord = pb - pa;
    let l = chord.norm();
    if l > 1e-300 {
        (pm - pa).cross(&chord).norm() / l
    } else {
        (pm - pa).norm()
    }
}

fn face_err(brep: &Brep, f: FaceId, msg: impl Into<String>) -> MeshError {
    MeshError::Face {
        id: brep.face(f).step_id,
        msg: msg.into(),
    }
}

fn singular_kind(s: &Surface, uv: [f64; 2]) -> u8 {
    let (su, sv) = s.derivs(uv[0], uv[1]);
    let (a, b) = (su.norm(), sv.norm());
    if a < 1e-7 * b {
        1
    } else if b < 1e-7 * a {
        2
    } else {
        0
    }
}

fn mesh_face(
    brep: &Brep,
    f: FaceId,
    edge_pts: &HashMap<EdgeId, Vec<u32>>,
    vert_idx: &[Option<u32>],
    positions: &mut Vec<P3>,
    opts: &MeshOptions,
) -> Result<FaceTriangulation, MeshError> {
    let (polys, edge_of) = face_polygons(brep, f, edge_pts, vert_idx, positions, opts)?;
    let sense = if brep.face(f).same_sense { 1.0 } else { -1.0 };
    triangulate(
        brep,
        f,
        brep.face_surface(f),
        polys,
        &edge_of,
        positions,
        opts,
        sense,
    )
}

/// Each edge loop of a face taken into the parameter domain and unwrapped, with how many
/// periods it winds; and the mesh vertices of the face's vertex loops (poles).
#[allow(clippy::type_complexity)]
fn loop_chains(
    brep: &Brep,
    f: FaceId,
    edge_pts: &HashMap<EdgeId, Vec<u32>>,
    vert_idx: &[Option<u32>],
    positions: &[P3],
) -> Result<(Vec<(LoopId, Vec<Pt>, [i64; 2])>, Vec<u32>), MeshError> {
    let face = brep.face(f);
    let s = brep.face_surface(f);
    let periods = [s.u_period(), s.v_period()];
    let mut loops: Vec<(LoopId, Vec<Pt>, [i64; 2])> = vec![];
    let mut pole_vertices: Vec<u32> = vec![];
    let mut hint: Option<(f64, f64)> = None;
    for &l in &face.loops {
        let lp = &brep.loops[l.idx()];
        if let Some(v) = lp.vertex {
            if let Some(i) = vert_idx[v.idx()] {
                pole_vertices.push(i);
            }
            continue;
        }
        // (points of each coedge) with raw uv.
        let mut coedges: Vec<Vec<Pt>> = vec![];
        for &c in &lp.coedges {
            let ce = &brep.coedges[c.idx()];
            let Some(ids) = edge_pts.get(&ce.edge) else {
                continue;
            };
            let ids: Vec<u32> = if ce.forward {
                ids.clone()
            } else {
                ids.iter().rev().copied().collect()
            };
            let mut pts = Vec::with_capacity(ids.len());
            for i in ids {
                let p = positions[i as usize];
                let (u, v) = s.project(&p, hint);
                if !(u.is_finite() && v.is_finite()) {
                    return Err(face_err(
                        brep,
                        f,
                        "a boundary point does not project onto the surface",
                    ));
                }
                hint = Some((u, v));
                pts.push(Pt {
                    uv: [u, v],
                    idx: i,
                    sing: singular_kind(s, [u, v]),
                });
            }
            // Free coordinates of singular points come from their neighbour on the same edge.
            let n = pts.len();
            for k in 0..n {
                let sk = pts[k].sing;
                if sk == 0 {
                    continue;
                }
                let axis = (sk - 1) as usize;
                let nb = if k + 1 < n && pts[k + 1].sing == 0 {
                    Some(k + 1)
                } else if k > 0 && pts[k - 1].sing == 0 {
                    Some(k - 1)
                } else {
                    None
                };
                if let Some(j) = nb {
                    let mut val = pts[j].uv[axis];
                    if let Some(p) = periods[axis] {
                        val = crate::math::nearest_periodic(val, pts[j].uv[axis], p);
                    }
                    pts[k].uv[axis] = val;
                }
            }
            coedges.push(pts);
        }
        // Chain coedges: drop each coedge's last point unless it sits on a singular line (then
        // both sides of the pole keep their own free coordinate).
        let mut chain: Vec<Pt> = vec![];
        for pts in &coedges {
            let n = pts.len();
            for (k, p) in pts.iter().enumerate() {
                if k + 1 == n && p.sing == 0 {
                    continue;
                }
                chain.push(*p);
            }
        }
        if chain.len() < 2 {
            continue;
        }
        let (pts, w) = unwrap_loop(chain, periods);
        loops.push((l, pts, w));
    }

    Ok((loops, pole_vertices))
}

/// The closed polygons bounding a face in its parameter domain, with, for each boundary
/// point, the B-rep edges it lies on.
#[allow(clippy::type_complexity)]
fn face_polygons(
    brep: &Brep,
    f: FaceId,
    edge_pts: &HashMap<EdgeId, Vec<u32>>,
    vert_idx: &[Option<u32>],
    positions: &mut Vec<P3>,
    opts: &MeshOptions,
) -> Result<(Vec<Vec<Pt>>, HashMap<u32, Vec<u32>>), MeshError> {
    let face = brep.face(f);
    let s = brep.face_surface(f);
    let periods = [s.u_period(), s.v_period()];
    let sense = if face.same_sense { 1.0 } else { -1.0 };
    // Which B-rep edges each boundary point lies on (vertices: all their edges in this face).
    let mut edge_of: HashMap<u32, Vec<u32>> = HashMap::new();
    for &l in &face.loops {
        for &c in &brep.loops[l.idx()].coedges {
            let e = brep.coedges[c.idx()].edge;
            for &i in edge_pts.get(&e).into_iter().flatten() {
                let v = edge_of.entry(i).or_default();
                if !v.contains(&e.0) {
                    v.push(e.0);
                }
            }
        }
    }

    // 1. Each loop into the parameter domain.
    let (chains, pole_vertices) = loop_chains(brep, f, edge_pts, vert_idx, positions)?;
    let loops: Vec<(Vec<Pt>, [i64; 2])> = chains.into_iter().map(|(_, p, w)| (p, w)).collect();

    // 2. Pair or close loops that wrap around a periodic direction.
    let mut polys: Vec<Vec<Pt>> = vec![];
    let mut wrapping: Vec<(Vec<Pt>, [i64; 2])> = vec![];
    for (pts, w) in loops {
        if w == [0, 0] {
            polys.push(pts);
        } else {
            wrapping.push((pts, w));
        }
    }
    let (sing_v, sing_u) = s.singular_lines();
    while let Some((a, wa)) = wrapping.pop() {
        let axis = if wa[0] != 0 { 0 } else { 1 };
        let per = periods[axis].unwrap_or(0.0);
        if let Some(j) = wrapping.iter().position(|(_, wb)| wb[axis] == -wa[axis]) {
            let (b, _) = wrapping.swap_remove(j);
            polys.push(join_wrapping(a, b, axis, per, s, positions, opts));
        } else {
            // Close through the singular line on the side the face lies.
            let lines = if axis == 0 { &sing_v } else { &sing_u };
            let other = 1 - axis;
            let level = a.iter().map(|p| p.uv[other]).sum::<f64>() / a.len() as f64;
            // Travelling +axis with the face on the left means the face is on the +other side
            // for axis u; for axis v the left is the -u side.
            let dir = wa[axis].signum() as f64 * sense * if axis == 0 { 1.0 } else { -1.0 };
            let pick = lines
                .iter()
                .copied()
                .filter(|x| (x - level) * dir > 0.0)
                .min_by(|x, y| (x - level).abs().total_cmp(&(y - level).abs()))
                .or_else(|| {
                    lines
                        .iter()
                        .copied()
                        .min_by(|x, y| (x - level).abs().total_cmp(&(y - level).abs()))
                });
            let Some(line) = pick else {
                return Err(face_err(
                    brep,
                    f,
                    "a boundary loop wraps around the surface and nothing closes it",
                ));
            };
            let first = a[0].uv;
            let mut uv_end = first;
            uv_end[axis] += wa[axis] as f64 * per;
            let mut c1 = uv_end;
            c1[other] = line;
            let mut c2 = first;
            c2[other] = line;
            let p3 = s.eval(c1[0], c1[1]);
            let pole = pole_vertices
                .iter()
                .copied()
                .find(|&i| (positions[i as usize] - p3).norm() < 1e-6 * (1.0 + p3.coords.norm()))
                .unwrap_or_else(|| {
                    positions.push(p3);
                    (positions.len() - 1) as u32
                });
            let sk = if axis == 0 { 1 } else { 2 };
            let mut poly = a;
            let start = poly[0];
            let end = Pt {
                uv: uv_end,
                idx: start.idx,
                sing: start.sing,
            };
            // The two sides of the cut from the loop to the pole are one curve on the surface
            // (a meridian of a sphere): sample it like an edge, the same vertices on both sides.
            let mut shift = [0.0; 2];
            shift[axis] = wa[axis] as f64 * per;
            let cut = cut_points(s, uv_end, c1, positions, opts);
            poly.push(end);
            poly.extend(cut.iter().copied());
            poly.push(Pt {
                uv: c1,
                idx: pole,
                sing: sk,
            });
            poly.push(Pt {
                uv: c2,
                idx: pole,
                sing: sk,
            });
            poly.extend(cut.iter().rev().map(|p| Pt {
                uv: [p.uv[0] - shift[0], p.uv[1] - shift[1]],
                ..*p
            }));
            polys.push(poly);
        }
    }
    // Inner loops were unwrapped near their own first point: shift each by whole periods into
    // the outer loop (the one enclosing the largest area).
    if polys.len() > 1 && (periods[0].is_some() || periods[1].is_some()) {
        align_loops(&mut polys, periods);
    }
    // A face bounded by one loop with pole bridges: the bridges' period shifts must give the
    // region on the face's side.
    if polys.len() == 1 {
        fix_bridge_orientation(&mut polys[0], periods, sense);
    }
    if polys.is_empty() {
        // No edge loop at all (a whole sphere or torus bounded by a vertex loop, or nothing):
        // the face is the surface's whole closed domain.
        match full_domain(s, &pole_vertices, positions, opts) {
            Some(poly) => polys.push(poly),
            None => {
                return Err(face_err(
                    brep,
                    f,
                    "no boundary loop makes a region on the surface",
                ));
            }
        }
    }

    Ok((polys, edge_of))
}

/// Unwraps a closed chain of points: periodic coordinates are made continuous, runs between
/// pole bridges are shifted to lie next to each other. Returns the points and how many periods
/// the loop winds in `u` and `v`.
fn unwrap_loop(mut chain: Vec<Pt>, periods: [Option<f64>; 2]) -> (Vec<Pt>, [i64; 2]) {
    let n = chain.len();
    let is_break = |a: &Pt, b: &Pt| a.sing != 0 && a.sing == b.sing;
    // Rotate so the chain starts right after a bridge, if there is one.
    if let Some(k) = (0..n).find(|&k| is_break(&chain[k], &chain[(k + 1) % n])) {
        chain.rotate_left((k + 1) % n);
    }
    let has_break = (0..n).any(|k| is_break(&chain[k], &chain[(k + 1) % n]));
    let mut out: Vec<Pt> = Vec::with_capacity(n);
    for k in 0..n {
        let mut p = chain[k];
        if let Some(prev) = out.last() {
            // Periodic coordinates follow the previous point; across a pole bridge this starts
            // the next run next to where the previous one ended.
            for axis in 0..2 {
                if let Some(per) = periods[axis] {
                    p.uv[axis] = crate::math::nearest_periodic(p.uv[axis], prev.uv[axis], per);
                }
            }
        }
        out.push(p);
    }
    let mut wrap = [0i64; 2];
    if !has_break {
        for axis in 0..2 {
            if let Some(per) = periods[axis] {
                let last = out[n - 1].uv[axis];
                let back = crate::math::nearest_periodic(out[0].uv[axis], last, per);
                wrap[axis] = ((back - out[0].uv[axis]) / per).round() as i64;
            }
        }
    }
    (out, wrap)
}

/// Points strictly inside a cut the mesher adds across a face (not a B-rep edge: the seam side
/// of a band or of a loop closed through a pole), from `p` to `q` in `(u, v)`, spaced like an
/// edge by the chord and angle tolerances of the surface curve between them. A cut is drawn
/// twice, a period apart, so both sides must take these same vertices: a cut left as one
/// segment becomes a chord through the solid (a meridian from the rim to a sphere's pole).
fn cut_points(
    s: &Surface,
    p: [f64; 2],
    q: [f64; 2],
    positions: &mut Vec<P3>,
    opts: &MeshOptions,
) -> Vec<Pt> {
    let at = |t: f64| [p[0] + t * (q[0] - p[0]), p[1] + t * (q[1] - p[1])];
    let eval = |t: f64| {
        let uv = at(t);
        s.eval(uv[0], uv[1])
    };
    // Uniform steps first (a chord test between the ends alone can miss a curve that comes
    // back), unless the curve is straight (a cylinder's generator); then bisection by chord
    // deviation and the turn of the chord direction.
    const START: usize = 8;
    let (pp, pq) = (eval(0.0), eval(1.0));
    let chord = pq - pp;
    let straight = (1..START).all(|i| {
        let x = eval(i as f64 / START as f64) - pp;
        let dev = if chord.norm() > 1e-300 {
            x.cross(&chord).norm() / chord.norm()
        } else {
            x.norm()
        };
        dev <= 0.1 * opts.chord_tol
    });
    if straight {
        return vec![];
    }
    let mut ts = vec![0.0];
    for i in 0..START {
        let (a, b) = (i as f64 / START as f64, (i + 1) as f64 / START as f64);
        cut_refine(&eval, a, b, opts, 0, &mut ts);
    }
    let mut out = vec![];
    for &t in &ts[1..ts.len() - 1] {
        let uv = at(t);
        let sing = singular_kind(s, uv);
        if sing != 0 {
            continue;
        }
        positions.push(s.eval(uv[0], uv[1]));
        out.push(Pt {
            uv,
            idx: (positions.len() - 1) as u32,
            sing,
        });
    }
    out
}

/// Bisects `[a, b]` of a cut until its chords are within tolerance, pushing the right ends.
fn cut_refine(
    eval: &dyn Fn(f64) -> P3,
    a: f64,
    b: f64,
    opts: &MeshOptions,
    depth: u32,
    out: &mut Vec<f64>,
) {
    let m = 0.5 * (a + b);
    if depth < 12 {
        let (pa, pm, pb) = (eval(a), eval(m), eval(b));
        let dev = chord_deviation(&pa, &pm, &pb);
        let (d0, d1) = (pm - pa, pb - pm);
        let turn = if d0.norm() > 1e-300 && d1.norm() > 1e-300 {
            2.0 * d0.angle(&d1)
        } else {
            0.0
        };
        if dev > opts.chord_tol || turn > opts.angle_tol {
            cut_refine(eval, a, m, opts, depth + 1, out);
            cut_refine(eval, m, b, opts, depth + 1, out);
            return;
        }
    }
    out.push(b);
}

/// Joins a loop winding `+1` with one winding `-1` (a band around a cylinder) into one polygon
/// through a cut at the first loop's start; the cut's two sides share their vertices.
fn join_wrapping(
    a: Vec<Pt>,
    b: Vec<Pt>,
    axis: usize,
    per: f64,
    s: &Surface,
    positions: &mut Vec<P3>,
    opts: &MeshOptions,
) -> Vec<Pt> {
    let wa = a.clone();
    let first = wa[0];
    let mut end = first;
    // The loop that winds forward ends one period on.
    let forward = {
        let n = wa.len();
        let last = wa[n - 1].uv[axis];
        crate::math::nearest_periodic(first.uv[axis], last, per) > first.uv[axis]
    };
    end.uv[axis] += if forward { per } else { -per };
    // Start `b` at its point nearest the cut, shifted next to `end`.
    let target = end.uv[axis];
    let (j, _) = b
        .iter()
        .enumerate()
        .map(|(i, p)| {
            (
                i,
                (crate::math::nearest_periodic(p.uv[axis], target, per) - target).abs(),
            )
        })
        .min_by(|x, y| x.1.total_cmp(&y.1))
        .unwrap_or((0, 0.0));
    let m = b.len();
    let mut out = a;
    out.push(end);
    let mut prev = target;
    let mut run = Vec::with_capacity(m + 1);
    for k in 0..=m {
        let mut p = b[(j + k) % m];
        p.uv[axis] = crate::math::nearest_periodic(p.uv[axis], prev, per);
        prev = p.uv[axis];
        run.push(p);
    }
    // The cut from `end` to `b`'s first point, and its twin a period away from `b`'s last
    // point back to the start of `a`.
    let (b0, bn) = (run[0].uv, run[m].uv);
    let shift = [b0[0] - bn[0], b0[1] - bn[1]];
    let cut = cut_points(s, end.uv, b0, positions, opts);
    out.extend(cut.iter().copied());
    out.extend(run);
    out.extend(cut.iter().rev().map(|p| Pt {
        uv: [p.uv[0] - shift[0], p.uv[1] - shift[1]],
        ..*p
    }));
    out
}

fn signed_area(poly: &[Pt]) -> f64 {
    let n = poly.len();
    let mut a = 0.0;
    for k in 0..n {
        let p = poly[k].uv;
        let q = poly[(k + 1) % n].uv;
        a += p[0] * q[1] - q[0] * p[1];
    }
    0.5 * a
}

fn fix_bridge_orientation(poly: &mut [Pt], periods: [Option<f64>; 2], sense: f64) {
    let n = poly.len();
    let is_break = |a: &Pt, b: &Pt| a.sing != 0 && a.sing == b.sing;
    let starts: Vec<usize> = (1..n)
        .filter(|&k| is_break(&poly[k - 1], &poly[k]))
        .collect();
    if starts.is_empty() || signed_area(poly) * sense > 1e-12 {
        return;
    }
    let mut best = (signed_area(poly) * sense, None);
    for &k in &starts {
        let axis = (poly[k].sing - 1) as usize;
        let Some(per) = periods[axis] else { continue };
        for shift in [per, -per] {
            let mut trial = poly.to_vec();
            for p in &mut trial[k..] {
                p.uv[axis] += shift;
            }
            let a = signed_area(&trial) * sense;
            if a > best.0 {
                best = (a, Some((k, axis, shift)));
            }
        }
    }
    if let (_, Some((k, axis, shift))) = best {
        for p in &mut poly[k..] {
            p.uv[axis] += shift;
        }
    }
}

/// Segments of the boundary, bucketed in horizontal bands, for inside tests and distances.
struct Boundary {
    segs: Vec<([f64; 2], [f64; 2])>,
    y0: f64,
    band: f64,
    bands: Vec<Vec<u32>>,
}

impl Boundary {
    fn new(polys: &[Vec<[f64; 2]>], bb: (f64, f64)) -> Self {
        let mut segs = vec![];
        for p in polys {
            let n = p.len();
            for k in 0..n {
                let a = p[k];
                let b = p[(k + 1) % n];
                if a != b {
                    segs.push((a, b));
                }
            }
        }
        let nb = ((segs.len() as f64).sqrt() as usize).clamp(1, 512);
        let band = ((bb.1 - bb.0) / nb as f64).max(1e-300);
        let mut bands = vec![vec![]; nb];
        for (i, (a, b)) in segs.iter().enumerate() {
            let lo = (((a[1].min(b[1]) - bb.0) / band).floor().max(0.0) as usize).min(nb - 1);
            let hi = (((a[1].max(b[1]) - bb.0) / band).floor().max(0.0) as usize).min(nb - 1);
            for bandv in bands.iter_mut().take(hi + 1).skip(lo) {
                bandv.push(i as u32);
            }
        }
        Boundary {
            segs,
            y0: bb.0,
            band,
            bands,
        }
    }

    fn band_of(&self, y: f64) -> usize {
        (((y - self.y0) / self.band).floor().max(0.0) as usize).min(self.bands.len() - 1)
    }

    /// Even-odd inside test by a ray towards +x.
    fn inside(&self, p: [f64; 2]) -> bool {
        let mut c = false;
        for &i in &self.bands[self.band_of(p[1])] {
            let (a, b) = self.segs[i as usize];
            if (a[1] > p[1]) != (b[1] > p[1]) {
                let x = a[0] + (p[1] - a[1]) * (b[0] - a[0]) / (b[1] - a[1]);
                if x > p[0] {
                    c = !c;
                }
            }
        }
        c
    }

    /// Whether a boundary segment passes within `r` of `p`.
    fn near(&self, p: [f64; 2], r: f64) -> bool {
        let lo = self.band_of(p[1] - r);
        let hi = self.band_of(p[1] + r);
        for band in &self.bands[lo..=hi] {
            for &i in band {
                let (a, b) = self.segs[i as usize];
                let d = [b[0] - a[0], b[1] - a[1]];
                let l2 = d[0] * d[0] + d[1] * d[1];
                let t = if l2 > 0.0 {
                    (((p[0] - a[0]) * d[0] + (p[1] - a[1]) * d[1]) / l2).clamp(0.0, 1.0)
                } else {
                    0.0
                };
                let q = [a[0] + t * d[0] - p[0], a[1] + t * d[1] - p[1]];
                if q[0] * q[0] + q[1] * q[1] < r * r {
                    return true;
                }
            }
        }
        false
    }
}

/// How many steps of `step` cover `range`: at least `min`, at most 400 (a grid's side).
fn step_count(range: (f64, f64), step: f64, min: usize) -> usize {
    if step.is_finite() {
        ((range.1 - range.0) / step).ceil().clamp(min as f64, 400.0) as usize
    } else {
        min
    }
}

/// Parameter steps `(du, dv)` that keep chords within tolerance, from sampled second differences.
fn grid_steps(s: &Surface, ub: (f64, f64), vb: (f64, f64), opts: &MeshOptions) -> (f64, f64) {
    if matches!(s, Surface::Plane { .. }) {
        return (f64::INFINITY, f64::INFINITY);
    }
    let n = 8;
    let (mut du, mut dv) = (f64::INFINITY, f64::INFINITY);
    let hu = (ub.1 - ub.0).max(1e-9) * 1e-3;
    let hv = (vb.1 - vb.0).max(1e-9) * 1e-3;
    for i in 0..=n {
        for j in 0..=n {
            // Sample cell centres: second differences at a clamped domain edge are meaningless.
            let u = ub.0 + (ub.1 - ub.0) * (i as f64 + 0.5) / (n + 1) as f64;
            let v = vb.0 + (vb.1 - vb.0) * (j as f64 + 0.5) / (n + 1) as f64;
            let p = s.eval(u, v);
            let (su, sv) = s.derivs(u, v);
            let suu =
                (s.eval(u + hu, v).coords - p.coords * 2.0 + s.eval(u - hu, v).coords) / (hu * hu);
            let svv =
                (s.eval(u, v + hv).coords - p.coords * 2.0 + s.eval(u, v - hv).coords) / (hv * hv);
            let (muu, mvv) = (suu.norm(), svv.norm());
            if muu > 1e-9 * (1.0 + su.norm()) {
                du = du.min((8.0 * opts.chord_tol / muu).sqrt());
                if su.norm() > 1e-12 {
                    du = du.min(opts.angle_tol * su.norm() / muu);
                }
            }
            if mvv > 1e-9 * (1.0 + sv.norm()) {
                dv = dv.min((8.0 * opts.chord_tol / mvv).sqrt());
                if sv.norm() > 1e-12 {
                    dv = dv.min(opts.angle_tol * sv.norm() / mvv);
                }
            }
        }
    }
    (du, dv)
}

#[allow(clippy::too_many_arguments)]
fn triangulate(
    brep: &Brep,
    f: FaceId,
    s: &Surface,
    polys: Vec<Vec<Pt>>,
    edge_of: &HashMap<u32, Vec<u32>>,
    positions: &mut Vec<P3>,
    opts: &MeshOptions,
    sense: f64,
) -> Result<FaceTriangulation, MeshError> {
    // Scale (u, v) so that a unit step is about a unit length on the surface.
    let (mut su, mut sv, mut n) = (0.0, 0.0, 0.0);
    let (mut ub, mut vb) = (
        (f64::INFINITY, f64::NEG_INFINITY),
        (f64::INFINITY, f64::NEG_INFINITY),
    );
    for p in polys.iter().flatten() {
        ub = (ub.0.min(p.uv[0]), ub.1.max(p.uv[0]));
        vb = (vb.0.min(p.uv[1]), vb.1.max(p.uv[1]));
        if p.sing == 0 {
            let (a, b) = s.derivs(p.uv[0], p.uv[1]);
            su += a.norm();
            sv += b.norm();
            n += 1.0;
        }
    }
    let (su, sv) = if n > 0.0 && su > 0.0 && sv > 0.0 {
        (su / n, sv / n)
    } else {
        (1.0, 1.0)
    };
    let scaled: Vec<Vec<[f64; 2]>> = polys
        .iter()
        .map(|p| p.iter().map(|q| [q.uv[0] * su, q.uv[1] * sv]).collect())
        .collect();
    let bnd = Boundary::new(&scaled, (vb.0 * sv, vb.1 * sv));

    let mut cdt: ConstrainedDelaunayTriangulation<Point2<f64>> =
        ConstrainedDelaunayTriangulation::new();
    let mut loc = Local::default();
    let insert = |cdt: &mut ConstrainedDelaunayTriangulation<Point2<f64>>,
                  loc: &mut Local,
                  xy: [f64; 2],
                  uv: [f64; 2],
                  idx: u32| { loc.insert(cdt, xy, uv, idx) };

    // Boundary points, with pole bridges subdivided so the fan at a pole is well shaped.
    let mut constraints_failed = 0usize;
    for poly in &polys {
        let mut handles = vec![];
        let m = poly.len();
        for k in 0..m {
            let p = poly[k];
            let q = poly[(k + 1) % m];
            let Some((h, _)) = insert(
                &mut cdt,
                &mut loc,
                [p.uv[0] * su, p.uv[1] * sv],
                p.uv,
                p.idx,
            ) else {
                return Err(face_err(
                    brep,
                    f,
                    "boundary point is not a finite parameter",
                ));
            };
            handles.push(h);
            if p.sing != 0 && p.sing == q.sing {
                let axis = (p.sing - 1) as usize;
                let span = (q.uv[axis] - p.uv[axis]).abs();
                let steps = ((span / 0.2).ceil() as usize).clamp(1, 64);
                for j in 1..steps {
                    let t = j as f64 / steps as f64;
                    let uv = [
                        p.uv[0] + t * (q.uv[0] - p.uv[0]),
                        p.uv[1] + t * (q.uv[1] - p.uv[1]),
                    ];
                    if let Some((h, _)) =
                        insert(&mut cdt, &mut loc, [uv[0] * su, uv[1] * sv], uv, p.idx)
                    {
                        handles.push(h);
                    }
                }
            }
        }
        let hn = handles.len();
        for k in 0..hn {
            let (a, b) = (handles[k], handles[(k + 1) % hn]);
            if a != b && cdt.try_add_constraint(a, b).is_empty() {
                constraints_failed += 1;
            }
        }
    }

    // Interior grid points.
    let (mut du, mut dv) = grid_steps(s, ub, vb, opts);
    // A straight direction (cylinder and cone generators) still gets rows, at most `ASPECT`
    // times the curved direction's spacing on the surface, so holes do not fan out into
    // triangles spanning a wide arc.
    const ASPECT: f64 = 6.0;
    if du.is_finite() && !dv.is_finite() {
        dv = du * su / sv * ASPECT;
    } else if dv.is_finite() && !du.is_finite() {
        du = dv * sv / su * ASPECT;
    }
    let (nu, nv) = (step_count(ub, du, 1), step_count(vb, dv, 1));
    if nu > 1 || nv > 1 {
        let (gu, gv) = ((ub.1 - ub.0) / nu as f64, (vb.1 - vb.0) / nv as f64);
        let margin = 0.35
            * (if nu > 1 { gu * su } else { f64::INFINITY }).min(if nv > 1 {
                gv * sv
            } else {
                f64::INFINITY
            });
        // A direction that needs no subdivision still gets points where the other one does, at
        // a spacing that keeps triangles from being needles.
        let (nu, nv) = (nu.max(1), nv.max(1));
        for i in 0..=nu {
            for j in 0..=nv {
                let uv = [ub.0 + gu * i as f64, vb.0 + gv * j as f64];
                let xy = [uv[0] * su, uv[1] * sv];
                if (nu > 1 && (i == 0 || i == nu)) || (nv > 1 && (j == 0 || j == nv)) {
                    continue;
                }
                if !bnd.inside(xy) || bnd.near(xy, margin) {
                    continue;
                }
                let p = s.eval(uv[0], uv[1]);
                let idx = positions.len() as u32;
                positions.push(p);
                insert(&mut cdt, &mut loc, xy, uv, idx);
            }
        }
    }

    // Which triangles are inside: count constraint crossings from the hull (odd = inside). This
    // is exact where the boundary's points are collinear to rounding; the centroid test is the
    // fallback when a boundary segment could not be inserted (crossing loops in bad files).
    // A chord between two points of the same B-rep edge could be drawn by the face on the other
    // side of that edge too, giving four triangles on one segment: split such chords with a
    // point of this face's own until none is left.
    const MAX_ROUNDS: usize = 10;
    const MAX_ADDED: usize = 200_000;
    let planar = matches!(s, Surface::Plane { .. });
    let mut rounds = 0;
    let mut added = 0usize;
    loop {
        let depth = (constraints_failed == 0).then(|| constraint_depth(&cdt));
        let mut triangles = vec![];
        let mut splits: Vec<[f64; 2]> = vec![];
        let mut seen = std::collections::HashSet::new();
        // Every drawn edge: (local handles, mesh vertices, constraint, middle).
        #[allow(clippy::type_complexity)]
        let mut drawn: Vec<((usize, usize), (u32, u32), bool, [f64; 2])> = vec![];
        for face in cdt.inner_faces() {
            let vs = face.vertices();
            let inside = match &depth {
                Some(d) => d[face.fix().index()] % 2 == 1,
                None => bnd.inside([
                    (vs[0].position().x + vs[1].position().x + vs[2].position().x) / 3.0,
                    (vs[0].position().y + vs[1].position().y + vs[2].position().y) / 3.0,
                ]),
            };
            if !inside {
                continue;
            }
            let mut t = [0u32; 3];
            let mut known = true;
            for k in 0..3 {
                match loc.handle_local.get(&vs[k].fix().index()) {
                    Some(&l) => t[k] = l as u32,
                    None => known = false,
                }
            }
            if !known {
                continue;
            }
            if rounds < MAX_ROUNDS {
                // Chord error: the flat triangle's centroid against the surface's. Stops two
                // rounds before chord splitting does, so that has the last word.
                if !planar && rounds + 2 < MAX_ROUNDS {
                    let c = [
                        (loc.uv[t[0] as usize][0]
                            + loc.uv[t[1] as usize][0]
                            + loc.uv[t[2] as usize][0])
                            / 3.0,
                        (loc.uv[t[0] as usize][1]
                            + loc.uv[t[1] as usize][1]
                            + loc.uv[t[2] as usize][1])
                            / 3.0,
                    ];
                    let flat = (positions[loc.vertex[t[0] as usize] as usize].coords
                        + positions[loc.vertex[t[1] as usize] as usize].coords
                        + positions[loc.vertex[t[2] as usize] as usize].coords)
                        / 3.0;
                    let xy = [c[0] * su, c[1] * sv];
                    if (s.eval(c[0], c[1]).coords - flat).norm() > opts.chord_tol
                        && added < MAX_ADDED
                        && !bnd.near(xy, 0.25 * min_edge(&loc, t, su, sv))
                    {
                        splits.push(xy);
                    }
                }
                for e in face.adjacent_edges() {
                    let (ha, hb) = (e.from().fix().index(), e.to().fix().index());
                    if let (Some(&la), Some(&lb)) =
                        (loc.handle_local.get(&ha), loc.handle_local.get(&hb))
                    {
                        let (pa, pb) = (e.from().position(), e.to().position());
                        drawn.push((
                            (ha.min(hb), ha.max(hb)),
                            (loc.vertex[la], loc.vertex[lb]),
                            e.is_constraint_edge(),
                            [(pa.x + pb.x) * 0.5, (pa.y + pb.y) * 0.5],
                        ));
                    }
                    if e.is_constraint_edge() {
                        continue;
                    }
                    let (Some(&la), Some(&lb)) =
                        (loc.handle_local.get(&ha), loc.handle_local.get(&hb))
                    else {
                        continue;
                    };
                    let (ga, gb) = (loc.vertex[la], loc.vertex[lb]);
                    let shared = match (edge_of.get(&ga), edge_of.get(&gb)) {
                        (Some(ea), Some(eb)) => ea.iter().any(|x| eb.contains(x)),
                        _ => false,
                    };
                    if shared && seen.insert((ha.min(hb), ha.max(hb))) {
                        let (pa, pb) = (e.from().position(), e.to().position());
                        splits.push([(pa.x + pb.x) * 0.5, (pa.y + pb.y) * 0.5]);
                    }
                }
            }
            if sense < 0.0 {
                t.swap(1, 2);
            }
            triangles.push(t);
        }
        // A pair of mesh vertices joined by more than one triangle on the same side: points
        // that are one vertex in 3-D (a pole's points along its singular line, the two sides
        // of the cut to a pole) joined to the same neighbour twice over. Split the free edges
        // drawn between them.
        let mut uses: HashMap<(u32, u32), (u32, u32)> = HashMap::new();
        for t in &triangles {
            let g = [
                loc.vertex[t[0] as usize],
                loc.vertex[t[1] as usize],
                loc.vertex[t[2] as usize],
            ];
            if g[0] == g[1] || g[1] == g[2] || g[0] == g[2] {
                continue;
            }
            for k in 0..3 {
                let (a, c) = (g[k], g[(k + 1) % 3]);
                let u = uses.entry((a.min(c), a.max(c))).or_default();
                if a < c {
                    u.0 += 1;
                } else {
                    u.1 += 1;
                }
            }
        }
        for (h, (ga, gb), constraint, mid) in &drawn {
            if !constraint
                && ga != gb
                && uses
                    .get(&(*ga.min(gb), *ga.max(gb)))
                    .is_some_and(|u| u.0 > 1 || u.1 > 1)
                && seen.insert(*h)
            {
                splits.push(*mid);
            }
        }
        if splits.is_empty() || rounds >= MAX_ROUNDS {
            return Ok(FaceTriangulation {
                face: f,
                uv: loc.uv,
                vertex: loc.vertex,
                triangles,
            });
        }
        added += splits.len();
        for xy in splits {
            let uv = [xy[0] / su, xy[1] / sv];
            let idx = positions.len() as u32;
            positions.push(s.eval(uv[0], uv[1]));
            insert(&mut cdt, &mut loc, xy, uv, idx);
        }
        rounds += 1;
    }
}

/// The shortest edge of a local triangle, in scaled parameters.
fn min_edge(loc: &Local, t: [u32; 3], su: f64, sv: f64) -> f64 {
    (0..3)
        .map(|k| {
            let a = loc.uv[t[k] as usize];
            let b = loc.uv[t[(k + 1) % 3] as usize];
            ((a[0] - b[0]) * su).hypot((a[1] - b[1]) * sv)
        })
        .fold(f64::INFINITY, f64::min)
}

/// Local vertices of one face's triangulation, keyed by spade's vertex handles.
#[derive(Default)]
struct Local {
    uv: Vec<[f64; 2]>,
    vertex: Vec<u32>,
    handle_local: HashMap<usize, usize>,
}

impl Local {
    fn insert(
        &mut self,
        cdt: &mut ConstrainedDelaunayTriangulation<Point2<f64>>,
        xy: [f64; 2],
        uv: [f64; 2],
        idx: u32,
    ) -> Option<(spade::handles::FixedVertexHandle, usize)> {
        // spade refuses magnitudes below 2^-142; such values are zero for us.
        let snap = |x: f64| if x.abs() < 1e-30 { 0.0 } else { x };
        let h = cdt.insert(Point2::new(snap(xy[0]), snap(xy[1]))).ok()?;
        let (uvs, verts) = (&mut self.uv, &mut self.vertex);
        let e = *self.handle_local.entry(h.index()).or_insert_with(|| {
            uvs.push(uv);
            verts.push(idx);
            uvs.len() - 1
        });
        Some((h, e))
    }
}

/// Fewest constraint edges crossed from outside the hull to each face (0-1 breadth-first search).
fn constraint_depth(cdt: &ConstrainedDelaunayTriangulation<Point2<f64>>) -> Vec<u32> {
    let mut depth = vec![u32::MAX; cdt.num_all_faces()];
    let mut queue = std::collections::VecDeque::new();
    for e in cdt.convex_hull() {
        if let Some(f) = e.rev().face().as_inner() {
            let d = u32::from(e.is_constraint_edge());
            let i = f.fix().index();
            if d < depth[i] {
                depth[i] = d;
                queue.push_back((f.fix(), d));
            }
        }
    }
    while let Some((fh, d)) = queue.pop_front() {
        if d > depth[fh.index()] {
            continue;
        }
        for e in cdt.face(fh).adjacent_edges() {
            let Some(nf) = e.rev().face().as_inner() else {
                continue;
            };
            let c = u32::from(e.is_constraint_edge());
            let nd = d + c;
            let i = nf.fix().index();
            if nd < depth[i] {
                depth[i] = nd;
                if c == 0 {
                    queue.push_front((nf.fix(), nd));
                } else {
                    queue.push_back((nf.fix(), nd));
                }
            }
        }
    }
    depth
}

/// The boundary of a surface's whole parameter domain, for faces without edge loops: a closed
/// surface (both directions periodic, or periodic one way and collapsing to poles the other).
/// Seam sides share their vertices with the opposite side and pole sides collapse to one
/// vertex, so the result is watertight.
fn full_domain(
    s: &Surface,
    pole_vertices: &[u32],
    positions: &mut Vec<P3>,
    opts: &MeshOptions,
) -> Option<Vec<Pt>> {
    let (bu, bv) = s.bounds();
    let (pu, pv) = (s.u_period(), s.v_period());
    let ur = pu.map(|p| (0.0, p)).or(bu)?;
    let vr = pv.map(|p| (0.0, p)).or(bv)?;
    let (du, dv) = grid_steps(s, ur, vr, opts);
    let (nu, nv) = (step_count(ur, du, 4), step_count(vr, dv, 4));
    let size = s.size_hint();
    let new_vertex = |p: P3, positions: &mut Vec<P3>| -> u32 {
        if let Some(&i) = pole_vertices
            .iter()
            .find(|&&i| (positions[i as usize] - p).norm() <= 1e-7 * size.max(1e-9))
        {
            return i;
        }
        positions.push(p);
        (positions.len() - 1) as u32
    };
    // A side collapses when all its points coincide.
    let collapsed = |pts: &[P3]| {
        pts.iter()
            .all(|p| (p - pts[0]).norm() <= 1e-7 * size.max(1e-9))
    };
    let side_u = |v: f64| -> Vec<P3> {
        (0..=nu)
            .map(|i| s.eval(ur.0 + (ur.1 - ur.0) * i as f64 / nu as f64, v))
            .collect()
    };
    let side_v = |u: f64| -> Vec<P3> {
        (0..=nv)
            .map(|j| s.eval(u, vr.0 + (vr.1 - vr.0) * j as f64 / nv as f64))
            .collect()
    };
    let (bottom, top) = (side_u(vr.0), side_u(vr.1));
    let (left, _right) = (side_v(ur.0), side_v(ur.1));
    let bottom_pole = collapsed(&bottom);
    let top_pole = collapsed(&top);
    if pu.is_none() || !(pv.is_some() || (bottom_pole && top_pole)) {
        return None;
    }
    // Vertex indices: the left seam (shared with the right), the bottom and top sides.
    let mut left_idx = vec![0u32; nv + 1];
    let bottom_idx: Vec<u32> = if bottom_pole {
        vec![new_vertex(bottom[0], positions); nu + 1]
    } else {
        bottom.iter().map(|p| new_vertex(*p, positions)).collect()
    };
    let top_idx: Vec<u32> = if pv.is_some() {
        bottom_idx.clone()
    } else if top_pole {
        vec![new_vertex(top[0], positions); nu + 1]
    } else {
        top.iter().map(|p| new_vertex(*p, positions)).collect()
    };
    left_idx[0] = bottom_idx[0];
    left_idx[nv] = top_idx[0];
    for j in 1..nv {
        left_idx[j] = new_vertex(left[j], positions);
    }
    let right_idx = |j: usize| {
        if j == 0 {
            bottom_idx[nu]
        } else if j == nv {
            top_idx[nu]
        } else {
            left_idx[j]
        }
    };
    let u_at = |i: usize| ur.0 + (ur.1 - ur.0) * i as f64 / nu as f64;
    let v_at = |j: usize| vr.0 + (vr.1 - vr.0) * j as f64 / nv as f64;
    let mut poly = vec![];
    for i in 0..nu {
        poly.push(Pt {
            uv: [u_at(i), vr.0],
            idx: bottom_idx[i],
            sing: if bottom_pole { 1 } else { 0 },
        });
    }
    for j in 0..nv {
        poly.push(Pt {
            uv: [ur.1, v_at(j)],
            idx: right_idx(j),
            sing: 0,
        });
    }
    for i in (1..=nu).rev() {
        poly.push(Pt {
            uv: [u_at(i), vr.1],
            idx: top_idx[i],
            sing: if top_pole { 1 } else { 0 },
        });
    }
    for j in (1..=nv).rev() {
        poly.push(Pt {
            uv: [ur.0, v_at(j)],
            idx: left_idx[j],
            sing: 0,
        });
    }
    Some(poly)
}

/// Shifts every loop but the outer one (largest enclosed area) by whole periods so that it lies
/// inside the outer loop.
fn align_loops(polys: &mut [Vec<Pt>], periods: [Option<f64>; 2]) {
    let outer = (0..polys.len())
        .max_by(|&a, &b| {
            signed_area(&polys[a])
                .abs()
                .total_cmp(&signed_area(&polys[b]).abs())
        })
        .unwrap_or(0);
    let outer_pts: Vec<[f64; 2]> = polys[outer].iter().map(|p| p.uv).collect();
    let inside = |q: [f64; 2]| {
        let n = outer_pts.len();
        let mut c = false;
        for k in 0..n {
            let (a, b) = (outer_pts[k], outer_pts[(k + 1) % n]);
            if (a[1] > q[1]) != (b[1] > q[1]) {
                let x = a[0] + (q[1] - a[1]) * (b[0] - a[0]) / (b[1] - a[1]);
                if x > q[0] {
                    c = !c;
                }
            }
        }
        c
    };
    let centre = |pts: &[Pt]| {
        let n = pts.len().max(1) as f64;
        let s = pts
            .iter()
            .fold([0.0, 0.0], |acc, p| [acc[0] + p.uv[0], acc[1] + p.uv[1]]);
        [s[0] / n, s[1] / n]
    };
    let oc = centre(&polys[outer]);
    for (i, poly) in polys.iter_mut().enumerate() {
        if i == outer {
            continue;
        }
        let pu = periods[0].unwrap_or(0.0);
        let pv = periods[1].unwrap_or(0.0);
        let ku: &[f64] = if periods[0].is_some() {
            &[0.0, -1.0, 1.0, -2.0, 2.0]
        } else {
            &[0.0]
        };
        let kv: &[f64] = if periods[1].is_some() {
            &[0.0, -1.0, 1.0, -2.0, 2.0]
        } else {
            &[0.0]
        };
        let c = centre(poly);
        // Prefer a shift that puts the loop's points inside the outer loop; else the nearest.
        let mut best = (usize::MAX, f64::INFINITY, 0.0, 0.0);
        for &a in ku {
            for &b in kv {
                let (du, dv) = (a * pu, b * pv);
                let outside = poly
                    .iter()
                    .filter(|p| !inside([p.uv[0] + du, p.uv[1] + dv]))
                    .count();
                let dist = (c[0] + du - oc[0]).hypot(c[1] + dv - oc[1]);
                if (outside, dist) < (best.0, best.1) {
                    best = (outside, dist, du, dv);
                }
            }
        }
        for p in poly.iter_mut() {
            p.uv[0] += best.2;
            p.uv[1] += best.3;
        }
    }
}
