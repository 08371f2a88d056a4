//! Freeform features: offset reference-surface layers, spatial slicing, paths on curved layers
//! (feature-based AM paper, "Feature-based five-axis path planning methodology": offset the
//! reference surface, spatially slice the freeform layers, generate the toolpaths of each
//! layer).
//!
//! - **Chart.** Every computation runs in a 2-D chart `q = (s, t)` of the reference surface S
//!   and the signed distance `d` from it along its unit normal N (pointing into the feature):
//!   the point `(q, d)` is `S(q) + d·N(q)`. The chart is the surface's own `(u, v)` scaled to
//!   millimetres at the feature's centre ([`ChartKind::Native`]), or, where `(u, v)` collapses
//!   under the feature (a boss on a sphere's pole), the orthogonal projection onto the tangent
//!   plane at the feature's centre ([`ChartKind::Ortho`]).
//! - **Offset surfaces.** Layer k lies on `S_k(q) = S(q) + z_k·N(q)`, `z_k` the sum of the
//!   first k layer thicknesses (`k·h` for uniform layers): exact for every surface, since it is
//!   evaluated from the exact S and N point by point. Deterioration (paper, Fig. 9: where the
//!   reference is concave with a radius of curvature under `z_k` the offset folds over itself)
//!   is detected from the principal curvatures of S under the feature: the plan stops with
//!   [`PlanError::OffsetFolds`], naming the feature and the first layer that would fold.
//! - **Spatial slicing.** The feature's exact-surface mesh is mapped into `(s, t, d)`; its
//!   section by the plane `d = z_k − h_k/2` (the middle of layer k) gives the layer's region
//!   in the chart, boundaries sampled within the mesh tolerance.
//! - **Paths.** [`crate::geodesic`] triangulates each region with a lattice equilateral on
//!   `S_k` (the chart's metric there), lifts it onto `S_k`, and fills it by the feature's
//!   `path_mode` with iso-lines of geodesic distances (spacing measured on the surface):
//!   rings are iso-lines of the distance to the boundary (exact three spacings deep), lines
//!   iso-lines of the signed distance to a seed curve. Strips too narrow for a bead (between
//!   the rings, or a whole sliver of a layer) get a variable-width gap fill, and sharp convex
//!   corners a spur into the tip (`corner_spurs`). Each path is lifted onto `S_k` with points
//!   inserted until every chord is within the feature's `tolerance` of the surface; the tool
//!   axis is N (or `fixed_tool_axis`); extrusion follows Isa & Lazoglu 2019, Eq. 1 with the
//!   layer's thickness and each point's bead width.

use crate::fill::{regions_from_loops, Point2, Region};
use crate::geodesic::{clip_reaching, LayerMesh, Piece, RunOn};
use crate::params::{LayerParams, PathMode};
use crate::planar::{feature_mesh, slicing_tolerance, Bead, FeatureFigures, PlanError};
use crate::toolpath::{MoveKind, PathPoint};
use brep::math::{any_perpendicular, P3, V3};
use brep::mesh::Mesh;
use brep::section::{section, Plane};
use brep::surface::Surface;
use features::{Feature, FeatureKind, FeatureTree};
use rayon::prelude::*;

/// Longest edge of the feature mesh mapped into `(s, t, d)`, mm: over 1 mm the distance to a
/// reference of curvature 1/R strays from linear by at most 1/(8R) mm (3 µm for R = 40 mm).
const MAX_MAPPED_EDGE: f64 = 1.0;

/// How chart coordinates map to the reference surface.
#[derive(Debug, Clone, Copy)]
pub enum ChartKind {
    /// `q = ((u − u0)·su, (v − v0)·sv)`: the surface's parameters scaled by `|S_u|`, `|S_v|` at
    /// the feature's centre (`su` negated where needed so the chart turns as N does).
    Native {
        /// Centre parameters.
        u0: f64,
        /// Centre parameters.
        v0: f64,
        /// Scale of u, mm per unit (signed).
        su: f64,
        /// Scale of v, mm per unit.
        sv: f64,
    },
    /// `q = ((F − c)·e1, (F − c)·e2)` for the surface point F: projection onto the tangent
    /// plane at the centre c.
    Ortho {
        /// Centre point.
        c: P3,
        /// First in-plane axis.
        e1: V3,
        /// Second in-plane axis (`e1 × e2` is the normal into the feature).
        e2: V3,
    },
}

/// A chart of a feature's reference surface with the normal into the feature.
#[derive(Debug, Clone, Copy)]
pub struct Chart<'a> {
    surf: &'a Surface,
    /// +1 when N is the surface's natural normal, −1 when reversed.
    sign: f64,
    /// The chart's form.
    pub kind: ChartKind,
}

impl<'a> Chart<'a> {
    /// The chart of `surf` in its own (u, v), unscaled: exact on a plane.
    fn unit(surf: &'a Surface) -> Chart<'a> {
        Chart {
            surf,
            sign: 1.0,
            kind: ChartKind::Native {
                u0: 0.0,
                v0: 0.0,
                su: 1.0,
                sv: 1.0,
            },
        }
    }

    fn normal_at(&self, u: f64, v: f64) -> Option<V3> {
        self.surf.normal(u, v).map(|n| n * self.sign)
    }

    /// Surface parameters of chart point `q`.
    fn uv(&self, q: Point2) -> Option<(f64, f64)> {
        match self.kind {
            ChartKind::Native { u0, v0, su, sv } => Some((u0 + q[0] / su, v0 + q[1] / sv)),
            ChartKind::Ortho { c, e1, e2 } => {
                // Iterated projection: move the target by the chart residual and project again.
                let mut x = c + e1 * q[0] + e2 * q[1];
                let mut uv = self.surf.project(&x, None);
                for _ in 0..40 {
                    let f = self.surf.eval(uv.0, uv.1);
                    let r = [q[0] - (f - c).dot(&e1), q[1] - (f - c).dot(&e2)];
                    if r[0].abs() + r[1].abs() < 1e-10 {
                        return Some(uv);
                    }
                    x = f + e1 * r[0] + e2 * r[1];
                    uv = self.surf.project(&x, Some(uv));
                }
                let f = self.surf.eval(uv.0, uv.1);
                let r = [q[0] - (f - c).dot(&e1), q[1] - (f - c).dot(&e2)];
                (r[0].abs() + r[1].abs() < 1e-6).then_some(uv)
            }
        }
    }

    /// The reference surface at `(u, v)` and its unit normal into the feature, continued past
    /// a bounded parameter range (a revolved profile's or a B-spline's end) by its tangent
    /// plane along the boundary, so that a feature overhanging its reference face's edge still
    /// has a foot under every point. Poles are not continued.
    fn eval_ext(&self, u: f64, v: f64) -> Option<(P3, V3)> {
        let (bu, bv) = if matches!(self.surf, Surface::Sphere { .. }) {
            (None, None)
        } else {
            self.surf.bounds()
        };
        let clamp = |x: f64, r: Option<(f64, f64)>| {
            r.map(|(a, b)| x.clamp(a.min(b), a.max(b))).unwrap_or(x)
        };
        let (uc, vc) = (clamp(u, bu), clamp(v, bv));
        let n = self.normal_at(uc, vc)?;
        if uc == u && vc == v {
            return Some((self.surf.eval(u, v), n));
        }
        let (p, su, sv) = self.surf.eval_d1(uc, vc);
        Some((p + su * (u - uc) + sv * (v - vc), n))
    }

    /// Whether chart point `q` lies on the reference surface proper, not on its continuation
    /// past a bounded parameter range.
    fn on_face(&self, q: Point2) -> bool {
        let Some((u, v)) = self.uv(q) else {
            return false;
        };
        if matches!(self.kind, ChartKind::Ortho { .. }) {
            return true;
        }
        let (bu, bv) = self.surf.bounds();
        let inside = |x: f64, r: Option<(f64, f64)>| {
            r.is_none_or(|(a, b)| x >= a.min(b) - 1e-9 && x <= a.max(b) + 1e-9)
        };
        inside(u, bu) && inside(v, bv)
    }

    /// The most millimetres one chart unit spans at `q` on the offset at `d` (the chart's
    /// largest stretch there), to turn 3-D lengths into chart lengths conservatively.
    fn stretch(&self, q: Point2, d: f64) -> f64 {
        let e = 1e-4;
        let at = |dq: [f64; 2]| self.at([q[0] + dq[0], q[1] + dq[1]], d).map(|x| x.0);
        match (at([0.0, 0.0]), at([e, 0.0]), at([0.0, e])) {
            (Some(p), Some(a), Some(b)) => ((a - p).norm().max((b - p).norm()) / e).max(1e-6),
            _ => 1.0,
        }
    }

    /// The first fundamental form of the offset surface at `d` in the chart, at the centre of
    /// `region`'s box: `[[p_s·p_s, p_s·p_t], [p_s·p_t, p_t·p_t]]` by central differences.
    /// The identity where the chart cannot be evaluated there.
    fn metric(&self, region: &Region, d: f64) -> [[f64; 2]; 2] {
        let (mut lo, mut hi) = ([f64::INFINITY; 2], [f64::NEG_INFINITY; 2]);
        for q in &region.outer {
            for k in 0..2 {
                lo[k] = lo[k].min(q[k]);
                hi[k] = hi[k].max(q[k]);
            }
        }
        let c = [0.5 * (lo[0] + hi[0]), 0.5 * (lo[1] + hi[1])];
        let e = 1e-3;
        let diff = |k: usize| -> Option<V3> {
            let (mut a, mut b) = (c, c);
            a[k] -= e;
            b[k] += e;
            Some((self.at(b, d)?.0 - self.at(a, d)?.0) / (2.0 * e))
        };
        match (diff(0), diff(1)) {
            (Some(ps), Some(pt)) if c[0].is_finite() && c[1].is_finite() => {
                [[ps.dot(&ps), ps.dot(&pt)], [ps.dot(&pt), pt.dot(&pt)]]
            }
            _ => [[1.0, 0.0], [0.0, 1.0]],
        }
    }

    /// The point at chart `q` and distance `d` from the reference, and the unit normal there
    /// (the offset surface's normal is the reference's).
    pub fn at(&self, q: Point2, d: f64) -> Option<(P3, V3)> {
        let (u, v) = self.uv(q)?;
        let (f, n) = match self.kind {
            ChartKind::Native { .. } => self.eval_ext(u, v)?,
            ChartKind::Ortho { .. } => (self.surf.eval(u, v), self.normal_at(u, v)?),
        };
        let p = f + n * d;
        (p.coords.iter().all(|x| x.is_finite()) && n.iter().all(|x| x.is_finite()))
            .then_some((p, n))
    }

    /// Chart coordinates and distance `d` of `p` (its nearest point on the reference).
    pub fn inverse(&self, p: &P3) -> Option<(Point2, f64)> {
        let (mut u, mut v) = self.surf.project(p, None);
        let (mut f, mut n) = (self.surf.eval(u, v), self.normal_at(u, v)?);
        if let ChartKind::Native { u0, v0, .. } = self.kind {
            // A foot on the boundary with `p` off its normal: continue onto the extension
            // (Gauss–Newton on the continued surface).
            let off = |f: P3, n: V3| (p - f - n * (p - f).dot(&n)).norm();
            if off(f, n) > 1e-7 * (1.0 + (p - f).norm()) {
                let uv = self.surf.unwrap_near((u, v), (u0, v0));
                u = uv.0;
                v = uv.1;
                for _ in 0..30 {
                    let (e, _) = self.eval_ext(u, v)?;
                    let h = 1e-6;
                    let (eu, _) = self.eval_ext(u + h, v)?;
                    let (ev, _) = self.eval_ext(u, v + h)?;
                    let (a, b) = ((eu - e) / h, (ev - e) / h);
                    let r = p - e;
                    let g = [[a.dot(&a), a.dot(&b)], [a.dot(&b), b.dot(&b)]];
                    let det = g[0][0] * g[1][1] - g[0][1] * g[1][0];
                    if det.abs() < 1e-18 {
                        break;
                    }
                    let (ra, rb) = (a.dot(&r), b.dot(&r));
                    let du = (g[1][1] * ra - g[0][1] * rb) / det;
                    let dv = (g[0][0] * rb - g[0][1] * ra) / det;
                    u += du;
                    v += dv;
                    if du.abs() + dv.abs() < 1e-12 {
                        break;
                    }
                }
                let (e, m) = self.eval_ext(u, v)?;
                f = e;
                n = m;
            }
        }
        let d = (p - f).dot(&n);
        let q = match self.kind {
            ChartKind::Native { u0, v0, su, sv } => {
                let (u, v) = self.surf.unwrap_near((u, v), (u0, v0));
                [(u - u0) * su, (v - v0) * sv]
            }
            ChartKind::Ortho { c, e1, e2 } => [(f - c).dot(&e1), (f - c).dot(&e2)],
        };
        (q[0].is_finite() && q[1].is_finite() && d.is_finite()).then_some((q, d))
    }

    /// The smallest principal curvature `λ` of the reference at `q`, with `dN = λ·dS` along
    /// principal directions (N into the feature): negative where the surface curves towards
    /// the feature, whose offset at distance `d` then folds where `1 + d·λ ≤ 0`.
    fn min_curvature(&self, q: Point2, step: f64) -> Option<f64> {
        let e = |dq: [f64; 2]| self.at([q[0] + dq[0], q[1] + dq[1]], 0.0);
        let (ps, ns) = e([step, 0.0])?;
        let (pm, nm) = e([-step, 0.0])?;
        let (pt, nt) = e([0.0, step])?;
        let (pn, nn) = e([0.0, -step])?;
        let (js, jt) = (ps - pm, pt - pn);
        let (ks, kt) = (ns - nm, nt - nn);
        // Least squares W with [ks kt] = [js jt]·W, then its eigenvalues.
        let g = [[js.dot(&js), js.dot(&jt)], [js.dot(&jt), jt.dot(&jt)]];
        let det = g[0][0] * g[1][1] - g[0][1] * g[1][0];
        if det.abs() < 1e-18 {
            return None;
        }
        let gi = [
            [g[1][1] / det, -g[0][1] / det],
            [-g[1][0] / det, g[0][0] / det],
        ];
        let b = [[js.dot(&ks), js.dot(&kt)], [jt.dot(&ks), jt.dot(&kt)]];
        let w = [
            [
                gi[0][0] * b[0][0] + gi[0][1] * b[1][0],
                gi[0][0] * b[0][1] + gi[0][1] * b[1][1],
            ],
            [
                gi[1][0] * b[0][0] + gi[1][1] * b[1][0],
                gi[1][0] * b[0][1] + gi[1][1] * b[1][1],
            ],
        ];
        let tr = w[0][0] + w[1][1];
        let dt = w[0][0] * w[1][1] - w[0][1] * w[1][0];
        let disc = (0.25 * tr * tr - dt).max(0.0).sqrt();
        let l = 0.5 * tr - disc;
        l.is_finite().then_some(l)
    }
}

/// The feature's chart: the surface's own parameters unless they collapse under the feature.
fn choose_chart<'a>(
    surf: &'a Surface,
    sign: f64,
    id: usize,
    mesh: &Mesh,
) -> Result<Chart<'a>, PlanError> {
    let err = |msg: String| PlanError::Freeform { id, msg };
    let n = mesh.positions.len().max(1) as f64;
    let centroid = mesh.positions.iter().fold(V3::zeros(), |a, p| a + p.coords) / n;
    let centroid = P3::from(centroid);
    let (u0, v0) = surf.project(&centroid, None);
    let (su, sv) = surf.derivs(u0, v0);
    let area = |u: f64, v: f64| {
        let (a, b) = surf.derivs(u, v);
        a.cross(&b).norm()
    };
    let a0 = area(u0, v0);
    // Native when the parameters stay regular under the whole feature.
    let stride = (mesh.positions.len() / 400).max(1);
    let mut native = a0 > 1e-12 && su.norm() > 1e-9 && sv.norm() > 1e-9;
    if native {
        let (mut ulo, mut uhi) = (f64::INFINITY, f64::NEG_INFINITY);
        for p in mesh.positions.iter().step_by(stride) {
            let (u, v) = surf.unwrap_near(surf.project(p, None), (u0, v0));
            ulo = ulo.min(u);
            uhi = uhi.max(u);
            if area(u, v) < 0.2 * a0 {
                native = false;
                break;
            }
        }
        if let Some(per) = surf.u_period() {
            if uhi - ulo > 0.9 * per {
                native = false;
            }
        }
    }
    let n0 = surf
        .normal(u0, v0)
        .map(|n| n * sign)
        .ok_or_else(|| err("its reference surface has no normal under its centre".into()))?;
    if native {
        let flip = if su.cross(&sv).dot(&n0) < 0.0 {
            -1.0
        } else {
            1.0
        };
        return Ok(Chart {
            surf,
            sign,
            kind: ChartKind::Native {
                u0,
                v0,
                su: su.norm() * flip,
                sv: sv.norm(),
            },
        });
    }
    let c = surf.eval(u0, v0);
    let e1 = any_perpendicular(&n0).normalize();
    let e2 = n0.cross(&e1);
    let chart = Chart {
        surf,
        sign,
        kind: ChartKind::Ortho { c, e1, e2 },
    };
    // The projection chart needs the reference to be a height field over the tangent plane.
    for p in mesh.positions.iter().step_by(stride) {
        let (u, v) = surf.project(p, None);
        let ok = chart.normal_at(u, v).is_some_and(|n| n.dot(&n0) > 0.17);
        if !ok {
            return Err(err(
                "its reference surface turns more than 80° under it and its parameters collapse there: no chart for curved layers"
                    .into(),
            ));
        }
    }
    Ok(chart)
}

/// The mesh with every edge longer than `max_edge` split (conforming: a triangle is cut by
/// the midpoints of its long edges, shared with its neighbours), as one triangle list. The
/// distance field is linear over each triangle of the mapped mesh, so a planar face's few large
/// triangles would cut a curved layer along chords far from the true section curve.
fn refined(mesh: &Mesh, max_edge: f64) -> Mesh {
    let mut pos = mesh.positions.clone();
    let mut tris = mesh.triangles();
    for _ in 0..12 {
        let long =
            |a: u32, b: u32, pos: &[P3]| (pos[a as usize] - pos[b as usize]).norm() > max_edge;
        let mut mid: std::collections::HashMap<(u32, u32), u32> = std::collections::HashMap::new();
        for t in &tris {
            for k in 0..3 {
                let (a, b) = (t[k], t[(k + 1) % 3]);
                if long(a, b, &pos) {
                    let key = (a.min(b), a.max(b));
                    mid.entry(key).or_insert_with(|| {
                        let m = P3::from(0.5 * (pos[a as usize].coords + pos[b as usize].coords));
                        pos.push(m);
                        (pos.len() - 1) as u32
                    });
                }
            }
        }
        if mid.is_empty() {
            break;
        }
        let mut next = Vec::with_capacity(tris.len() * 2);
        for t in &tris {
            let m = [0, 1, 2].map(|k| {
                let (a, b) = (t[k], t[(k + 1) % 3]);
                mid.get(&(a.min(b), a.max(b))).copied()
            });
            match m {
                [None, None, None] => next.push(*t),
                [Some(x), Some(y), Some(z)] => {
                    next.extend([[t[0], x, z], [x, t[1], y], [z, y, t[2]], [x, y, z]]);
                }
                _ => {
                    // One or two split edges: fan from the first split edge's midpoint.
                    let k = (0..3).find(|&k| m[k].is_some()).unwrap_or(0);
                    let x = m[k].unwrap_or(t[k]);
                    let (a, b, c) = (t[k], t[(k + 1) % 3], t[(k + 2) % 3]);
                    let (mb, mc) = (m[(k + 1) % 3], m[(k + 2) % 3]);
                    // Polygon a, x, b, [mb], c, [mc]; fan around x.
                    let mut poly = vec![b];
                    if let Some(y) = mb {
                        poly.push(y);
                    }
                    poly.push(c);
                    if let Some(z) = mc {
                        poly.push(z);
                    }
                    poly.push(a);
                    for w in poly.windows(2) {
                        next.push([x, w[0], w[1]]);
                    }
                }
            }
        }
        tris = next;
    }
    let n = pos.len();
    Mesh {
        positions: pos,
        faces: vec![brep::mesh::FaceTriangulation {
            face: mesh
                .faces
                .first()
                .map(|f| f.face)
                .unwrap_or(brep::topology::FaceId(0)),
            uv: vec![[0.0, 0.0]; n],
            vertex: (0..n as u32).collect(),
            triangles: tris,
        }],
        edge_points: Default::default(),
        edge_params: Default::default(),
    }
}

/// Offset deterioration (paper, Fig. 9) judged from the feature's root: the smallest principal
/// curvature of the reference where the feature stands on it, against the feature's height
/// along the normal there. `Err(OffsetFolds)` names the first layer whose offset reaches the
/// radius of a concave valley.
fn fold_check(
    surf: &Surface,
    sign: f64,
    mesh: &Mesh,
    tol: f64,
    params: &LayerParams,
    id: usize,
) -> Result<(), PlanError> {
    // The root: mesh vertices on the reference surface.
    let roots: Vec<(f64, f64, P3)> = mesh
        .positions
        .iter()
        .filter_map(|p| {
            let (u, v) = surf.project(p, None);
            let f = surf.eval(u, v);
            ((p - f).norm() < 1e-3f64.max(2.0 * tol)).then_some((u, v, f))
        })
        .collect();
    if roots.is_empty() {
        return Ok(());
    }
    let c = roots.iter().fold(V3::zeros(), |a, r| a + r.2.coords) / roots.len() as f64;
    let (u0, v0) = surf.project(&P3::from(c), None);
    let (su, sv) = surf.derivs(u0, v0);
    let Some(n0) = surf.normal(u0, v0).map(|n| n * sign) else {
        return Ok(());
    };
    if su.norm() < 1e-9 || sv.norm() < 1e-9 {
        return Ok(());
    }
    let flip = if su.cross(&sv).dot(&n0) < 0.0 {
        -1.0
    } else {
        1.0
    };
    let (su, sv) = (su.norm() * flip, sv.norm());
    let chart = Chart {
        surf,
        sign,
        kind: ChartKind::Native { u0, v0, su, sv },
    };
    let f0 = surf.eval(u0, v0);
    let height = mesh
        .positions
        .iter()
        .map(|p| (p - f0).dot(&n0))
        .fold(0.0f64, f64::max);
    let step = (0.5 * params.uniform_layer_height).max(1e-3);
    let mut lambda = 0.0f64;
    for r in roots.iter().step_by((roots.len() / 300).max(1)) {
        let (u, v) = surf.unwrap_near((r.0, r.1), (u0, v0));
        if let Some(l) = chart.min_curvature([(u - u0) * su, (v - v0) * sv], step) {
            lambda = lambda.min(l);
        }
    }
    if lambda < -1e-9 {
        check_folds(id, &params.layer_heights(height), -1.0 / lambda)?;
    }
    Ok(())
}

/// `Err(OffsetFolds)` at the first of the layers (thicknesses `heights`) whose top reaches
/// `radius`, the radius of a concave valley of the reference (infinite: none).
fn check_folds(id: usize, heights: &[f64], radius: f64) -> Result<(), PlanError> {
    let mut z = 0.0;
    for (layer, dl) in heights.iter().enumerate() {
        z += dl;
        if z >= radius {
            return Err(PlanError::OffsetFolds {
                id,
                layer: layer + 1,
                offset: z,
                radius,
            });
        }
    }
    Ok(())
}

/// Chart coordinates and distance of every mesh vertex, as a mesh in `(s, t, d)` space.
fn mapped_mesh(chart: &Chart, mesh: &Mesh, id: usize) -> Result<Mesh, PlanError> {
    let mut m = mesh.clone();
    for (i, p) in mesh.positions.iter().enumerate() {
        let (q, d) = chart.inverse(p).ok_or_else(|| PlanError::Freeform {
            id,
            msg: format!(
                "a point ({:.3}, {:.3}, {:.3}) of it has no foot on its reference surface",
                p.x, p.y, p.z
            ),
        })?;
        m.positions[i] = P3::new(q[0], q[1], d);
    }
    Ok(m)
}

/// One path of a curved layer in chart coordinates (or of a planar layer in its plane's),
/// with the bead width at each point.
#[derive(Debug, Clone, Default)]
pub struct FillPath {
    /// Bead centre line.
    pub points: Vec<Point2>,
    /// Bead width at each point, mm.
    pub widths: Vec<f64>,
}

impl FillPath {
    /// A path of one bead width throughout.
    pub fn uniform(points: Vec<Point2>, width: f64) -> Self {
        let widths = vec![width; points.len()];
        FillPath { points, widths }
    }

    /// The same path run the other way.
    pub fn reverse(&mut self) {
        self.points.reverse();
        self.widths.reverse();
    }
}

/// Paths of a region of a planar layer (in its plane's 2-D coordinates) filled as the regions
/// of curved layers are: rings and raster lines as iso-lines of the exact distance to the
/// boundary, where rings leave a strip narrower than a bead a gap fill as wide as the strip
/// at each point, and spurs into sharp corners. The planar planner fills its thin regions so
/// (a blade's or a rib's section), where offsetting rings of one width would overlap their
/// own beads or drop what is narrower than a bead.
///
/// `boundary` says what the region's boundary is: the part's surface, which a bead's middle
/// stays a tenth of a bead inside in a region too thin for a ring, or the edge of beads laid
/// around it (a strip rings leave), which the beads may reach within a fiftieth.
pub fn fill_flat_region(
    region: &Region,
    params: &LayerParams,
    layer: usize,
    width: f64,
    spacing: f64,
    boundary: Boundary,
) -> Vec<FillPath> {
    let plane = Surface::Plane {
        frame: brep::math::Frame::world(P3::origin()),
    };
    // The plane's own (u, v) at scale 1 is the identity on the layer's 2-D coordinates.
    let chart = Chart::unit(&plane);
    let sliver_inset = match boundary {
        Boundary::Part => SLIVER_INSET,
        Boundary::Beads => GAP_INSET,
    } * width;
    let mut paths = fill_region(
        &chart,
        region,
        0.0,
        params,
        layer,
        width,
        spacing,
        sliver_inset,
    );
    paths.extend(corner_spurs(&chart, region, 0.0, width));
    paths.retain(|p| p.points.len() >= 2);
    paths
}

/// What bounds a region filled by [`fill_flat_region`].
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Boundary {
    /// The part's surface (a layer's section).
    Part,
    /// The edges of beads laid around it (a strip the rings of `fill::fill_layer` leave).
    Beads,
}

/// How far inside a region too thin for a ring its gap fill's bead middles stay, in bead
/// widths, where the boundary is the part's: clear of the region's sampling error.
const SLIVER_INSET: f64 = 0.1;
/// The same where the boundary is a bead's edge (or the strip the last ring leaves).
const GAP_INSET: f64 = 0.02;

/// Paths of one region of a curved layer at offset `z`, in chart coordinates. Where the region
/// is too thin for a ring, the gap fill's bead middles stay `sliver_inset` inside it.
#[allow(clippy::too_many_arguments)]
fn fill_region(
    chart: &Chart,
    region: &Region,
    z: f64,
    params: &LayerParams,
    layer: usize,
    width: f64,
    spacing: f64,
    sliver_inset: f64,
) -> Vec<FillPath> {
    let mut out = vec![];
    let mut lm = LayerMesh::build_with_metric(region, spacing / 3.0, chart.metric(region, z));
    if lm.tris.is_empty() {
        return out;
    }
    let mut pts = Vec::with_capacity(lm.q.len());
    for q in &lm.q {
        match chart.at(*q, z) {
            Some((p, _)) => pts.push(p),
            None => return out,
        }
    }
    lm.p = pts;
    // Exact distances (to the lifted boundary) three spacings deep: the rings of the default
    // contour-zig-zag, the infill's edge and a thin blade's ridge all lie there, so they do
    // not depend on how well the front is marched over the lattice.
    let db = lm.march(&lm.boundary_seeds(SEED_DEPTH * spacing));
    let (deep, dmax) = db.iter().enumerate().filter(|(_, d)| d.is_finite()).fold(
        (0usize, 0.0f64),
        |a, (i, &d)| if d > a.1 { (i, d) } else { a },
    );
    // Rings: iso-lines of the distance to the boundary, half a bead in, then a spacing apart.
    // Where the region is too narrow for a ring's bead and its mirror image from the other
    // side (the ridge of the distance, the region's half width R there, is less than the
    // ring's inner bead edge), the ring narrows to what is left between its outer bead edge
    // and the ridge, `R − (c − w/2)`, extruded for that width by Eq. 1: the two sides then
    // put down the strip's volume instead of overlapping (a blade section 0.8 mm wide took
    // two full 0.45 mm beads). Where what is left is wider than a bead by less than the gap
    // fill's narrowest bead, the ring widens to take it. A ring less than a tenth of a bead
    // below the deepest point is left out.
    let rings = match params.path_mode {
        PathMode::Raster | PathMode::Zigzag => 0,
        PathMode::Contour => usize::MAX,
        PathMode::ContourZigzag => params.perimeters,
    };
    let levels: Vec<f64> = (0..rings)
        .map(|j| 0.5 * width + j as f64 * spacing)
        .take_while(|c| *c <= dmax - 0.1 * width)
        .collect();
    let gap_inset = 0.02 * width;
    // The ridge is needed only where the rings' iso-lines and the gap fills between them run:
    // at both ends of each lattice edge those levels cross.
    let ridge = if levels.is_empty() {
        vec![]
    } else {
        let wanted: Vec<f64> = levels
            .iter()
            .copied()
            .chain(levels.iter().skip(1).map(|c| c - 0.5 * width + gap_inset))
            .collect();
        let mask = crossing_vertices(&lm, &db, &wanted);
        lm.local_max(&db, 1.5 * spacing, &mask)
    };
    let mut last_ring = None;
    for (j, &c) in levels.iter().enumerate() {
        let edge = c - 0.5 * width;
        if j > 0 {
            // Where this ring does not reach (the region's half width is under `c` there),
            // the strip the ring before leaves along the ridge gets its gap fill.
            let gap = Gap {
                edge,
                inset: gap_inset,
                min_width: GAP_MIN_WIDTH_SHARE * width,
                below: c,
            };
            out.extend(gap_fill(&lm, &db, &ridge, gap, width));
        }
        for line in lm.iso_lines(&db, c, &ridge) {
            let widths = line
                .other
                .iter()
                .map(|r| {
                    let room = r - edge;
                    if room <= GAP_MIN_WIDTH_SHARE.mul_add(width, width) {
                        room.max(0.2 * width)
                    } else {
                        width
                    }
                })
                .collect();
            out.push(FillPath {
                points: line.q,
                widths,
            });
        }
        last_ring = Some(c);
    }
    // Infill where the rings stop: lines end a spacing past the last ring, joined along that
    // boundary (as on planar layers), or half a bead inside the boundary without rings. Where
    // the rings leave only a strip narrower than that (a thin blade), the lines cross the strip
    // from the edge of the last ring's bead instead, filling the gap.
    // The gap fill of all that is left farther in than `gap.edge` (no ring or line beyond
    // it), within what that core holds.
    let core_fill = |gap: Gap| {
        let ridge = ridge_for(&lm, &db, gap, spacing);
        conserved(
            gap_fill(&lm, &db, &ridge, gap, width),
            &lm,
            &db,
            gap.edge,
            |a, b| surface_length(chart, z, a, b),
        )
    };
    let inner = match last_ring {
        Some(c) if dmax > c + 1.5 * spacing => c + spacing,
        Some(c) => {
            // The strip along the ridge that the last ring's bead leaves.
            let edge = c + 0.5 * width;
            let gap = Gap {
                edge,
                inset: GAP_INSET * width,
                min_width: GAP_MIN_WIDTH_SHARE * width,
                below: f64::INFINITY,
            };
            out.extend(core_fill(gap));
            return out;
        }
        // A region too thin for a ring (the sliver a curved layer cuts off a blade's tip or
        // edge): the same gap fill from its boundary, the beads' middles a tenth of a bead
        // inside it, down to a fifth of a bead wide.
        None if rings > 0 || dmax <= 0.5 * width => {
            let gap = Gap {
                edge: 0.0,
                inset: sliver_inset,
                min_width: 0.2 * width,
                below: f64::INFINITY,
            };
            out.extend(core_fill(gap));
            return out;
        }
        None => 0.5 * width,
    };
    let zig = params.path_mode != PathMode::Raster;
    let angle = if zig && layer % 2 == 1 {
        params.raster_angle_deg + 90.0
    } else {
        params.raster_angle_deg
    }
    .to_radians();
    let dir = [angle.cos(), angle.sin()];
    let nrm = [-dir[1], dir[0]];
    // The seed curve: the chart line along `dir` through the deepest point; the field is the
    // signed geodesic distance to it, so its iso-lines are geodesic parallels.
    let q0 = lm.q[deep];
    let l: Vec<f64> =
        lm.q.iter()
            .map(|q| (q[0] - q0[0]) * nrm[0] + (q[1] - q0[1]) * nrm[1])
            .collect();
    // Vertices within a spacing of the seed line start at their distance across it: the
    // chart offset times the surface's stretch across the line there, i.e. the part of the
    // surface step along the chart normal that is square to the line's own surface direction
    // (a sheared chart does not map the chart normal to the surface normal of the line).
    let stretch = {
        let e = 1e-3;
        let step = |d: [f64; 2]| -> Option<V3> {
            let a = chart.at([q0[0] + e * d[0], q0[1] + e * d[1]], z)?.0;
            let b = chart.at([q0[0] - e * d[0], q0[1] - e * d[1]], z)?.0;
            Some((a - b) / (2.0 * e))
        };
        match (step(dir), step(nrm)) {
            (Some(t), Some(n)) if t.norm() > 1e-12 => {
                let t = t / t.norm();
                (n - t * n.dot(&t)).norm()
            }
            _ => 1.0,
        }
    };
    let seeds: Vec<(u32, f64)> = l
        .iter()
        .enumerate()
        .filter(|(_, x)| x.abs() * stretch <= spacing)
        .map(|(i, x)| (i as u32, x.abs() * stretch))
        .collect();
    let dist = lm.march(&seeds);
    let phi: Vec<f64> = dist
        .iter()
        .zip(&l)
        .map(|(d, l)| if *l < 0.0 { -d } else { *d })
        .collect();
    // The infill's area: inside the inner edge of the last ring's bead (half a spacing short
    // of the infill boundary), or the whole region without rings.
    let edge = if last_ring.is_some() {
        inner - 0.5 * spacing
    } else {
        0.0
    };
    let Some((lo, hi)) = level_span(&lm, &phi, &db, edge) else {
        return out;
    };
    if (hi - lo) / spacing > 1e5 {
        return out;
    }
    // Lines a whole number of spacings across the infill area, centred on it: the spacing
    // and the bead width with it (Eq. 1 extrudes for that width) stretch or shrink so that
    // the beads' strips fill the area's extent across the lines exactly, as a planar
    // slicer's solid infill does. At the nominal spacing a region a few beads across kept a
    // strip up to a spacing wide unfilled beside its outer lines (7–10 % of a small boss's
    // layer).
    let n = ((hi - lo) / spacing).round().max(1.0);
    let step = (hi - lo) / n;
    let width = width * step / spacing;
    if width < 0.2 * spacing {
        return out;
    }
    let spacing = step;
    let (j0, j1) = (0i64, n as i64 - 1);
    // A line end with no connector to meet runs on to the boundary, or inside rings to the
    // inner edge of the last ring's bead, so the line's strip of the region is filled up to
    // it (`fill::bead_end_reach`, as on planar layers): every raster end, and the two free
    // ends of each zig-zag chain.
    let reach = RunOn { width, edge };
    let mut pieces: Vec<(i64, Piece)> = vec![];
    for j in j0..=j1 {
        let level = lo + (j as f64 + 0.5) * spacing;
        for line in lm.iso_lines(&phi, level, &db) {
            let len = |a, b| surface_length(chart, z, a, b);
            let mut cut = clip_reaching(&line, inner, reach, len);
            if cut.is_empty() {
                // A line beside the infill boundary's reach (in a small area, or one
                // narrowing to a corner) crosses only the band between the last ring's bead
                // and the boundary where connectors run: it fills its strip of that band
                // from edge to edge, on its own.
                cut = clip_reaching(&line, edge + crate::fill::END_MARGIN * width, reach, len);
            }
            for piece in cut {
                let (a, b) = (piece.body[0], piece.body[piece.body.len() - 1]);
                let piece = if (b[0] - a[0]) * dir[0] + (b[1] - a[1]) * dir[1] < 0.0 {
                    piece.reversed()
                } else {
                    piece
                };
                pieces.push((j, piece));
            }
        }
    }
    if !zig {
        out.extend(
            pieces
                .into_iter()
                .map(|(_, p)| FillPath::uniform(p.reaching(), width)),
        );
        return out;
    }
    // Zig-zag: join each line's end to the nearest end of a line on the next level, along the
    // infill boundary (the iso-line where the lines were cut), when that way is short.
    let border = lm.iso_lines(&db, inner, &db);
    let along = Border::new(&border);
    let mut used = vec![false; pieces.len()];
    for s in 0..pieces.len() {
        if used[s] {
            continue;
        }
        used[s] = true;
        let first = &pieces[s].1;
        let (mut level, mut pts) = (pieces[s].0, first.body.clone());
        pts.splice(0..0, first.head.iter().copied());
        let mut tail = first.tail.clone();
        loop {
            let end = pts[pts.len() - 1];
            let mut best: Option<(f64, usize, bool, Vec<Point2>)> = None;
            for (i, (lv, p)) in pieces.iter().enumerate() {
                if used[i] || *lv != level + 1 {
                    continue;
                }
                let p = &p.body;
                for (rev, q) in [(false, p[0]), (true, p[p.len() - 1])] {
                    if let Some((len, way)) = along.connect(end, q, 2.5 * spacing) {
                        if best.as_ref().is_none_or(|b| len < b.0) {
                            best = Some((len, i, rev, way));
                        }
                    }
                }
            }
            match best {
                Some((_, i, rev, way)) => {
                    used[i] = true;
                    let next = if rev {
                        pieces[i].1.clone().reversed()
                    } else {
                        pieces[i].1.clone()
                    };
                    pts.extend(way);
                    pts.extend(next.body);
                    tail = next.tail;
                    level += 1;
                }
                None => break,
            }
        }
        pts.extend(tail);
        out.push(FillPath::uniform(pts, width));
    }
    out
}

/// The range of `phi` over the part of the lattice where `db` is at least `edge`, with the
/// crossings of that level on the lattice's edges interpolated.
fn level_span(lm: &LayerMesh, phi: &[f64], db: &[f64], edge: f64) -> Option<(f64, f64)> {
    let (mut lo, mut hi) = (f64::INFINITY, f64::NEG_INFINITY);
    let mut take = |x: f64| {
        if x.is_finite() {
            lo = lo.min(x);
            hi = hi.max(x);
        }
    };
    for t in &lm.tris {
        for k in 0..3 {
            let (a, b) = (t[k] as usize, t[(k + 1) % 3] as usize);
            let (da, db_) = (db[a], db[b]);
            if da >= edge {
                take(phi[a]);
            }
            if (da - edge) * (db_ - edge) < 0.0 {
                let s = (edge - da) / (db_ - da);
                take(phi[a] + (phi[b] - phi[a]) * s);
            }
        }
    }
    (lo < hi).then_some((lo, hi))
}

/// Gap fill of the whole core a region's rings leave (or of a region too thin for a ring),
/// its widths scaled down where they would put down more than the core holds. The ridge
/// height a gap fill takes as its width is right along a strip, whose two flanks meet at the
/// ridge, but not where the core is compact (a small boss's square core, whose flanks are
/// all four sides): there each side took the whole half width and the loop laid the core
/// twice over (+5 % on a 3 mm pin). The core's area on the layer surface is exact (the
/// lattice's triangles clipped at the core's edge), and so is each bead's strip by Eq. 1.
fn conserved(
    mut paths: Vec<FillPath>,
    lm: &LayerMesh,
    db: &[f64],
    edge: f64,
    len: impl Fn(Point2, Point2) -> f64,
) -> Vec<FillPath> {
    let covered: f64 = paths
        .iter()
        .map(|p| {
            (1..p.points.len())
                .map(|i| {
                    let l = len(p.points[i - 1], p.points[i]);
                    if l.is_finite() {
                        0.5 * (p.widths[i - 1] + p.widths[i]) * l
                    } else {
                        0.0
                    }
                })
                .sum::<f64>()
        })
        .sum();
    let held = lm.area_above(db, edge);
    if covered > held && covered > 0.0 {
        let k = held / covered;
        for p in &mut paths {
            for w in &mut p.widths {
                *w *= k;
            }
        }
    }
    paths
}

/// The length on the layer surface at `d` of the chart segment `a`–`b` (its chord there).
fn surface_length(chart: &Chart, d: f64, a: Point2, b: Point2) -> f64 {
    match (chart.at(a, d), chart.at(b, d)) {
        (Some((p, _)), Some((q, _))) => (q - p).norm(),
        _ => f64::NAN,
    }
}

/// Where a gap fill runs: from `edge` (the distance to the region's boundary where the beads
/// outside it stop), its beads' middles `inset` further in, no narrower than `min_width`, and
/// only where the ridge of the distance is below `below` (deeper, the next ring takes over).
#[derive(Debug, Clone, Copy)]
struct Gap {
    edge: f64,
    inset: f64,
    min_width: f64,
    below: f64,
}

/// Marks both ends of every lattice edge that one of `levels` of `db` crosses: the vertices
/// an iso-line at those levels interpolates between.
fn crossing_vertices(lm: &LayerMesh, db: &[f64], levels: &[f64]) -> Vec<bool> {
    let mut mask = vec![false; db.len()];
    for t in &lm.tris {
        for k in 0..3 {
            let (a, b) = (t[k] as usize, t[(k + 1) % 3] as usize);
            if levels.iter().any(|l| (db[a] - l) * (db[b] - l) <= 0.0) {
                mask[a] = true;
                mask[b] = true;
            }
        }
    }
    mask
}

/// The local ridge height of `db` (within one and a half spacings) seen from the flanks of
/// the strip beyond `gap.edge`, where the gap fill's iso-line needs it: at the vertices it
/// interpolates between.
fn ridge_for(lm: &LayerMesh, db: &[f64], gap: Gap, spacing: f64) -> Vec<f64> {
    let mask = crossing_vertices(lm, db, &[gap.edge + gap.inset]);
    lm.local_max(db, 1.5 * spacing, &mask)
}

/// Gap fill: the strip of a region farther than `gap.edge` from its boundary (`db`, the
/// distance to the boundary) but too narrow for a bead: its local half width β is the ridge
/// height (`ridge`, [`ridge_for`]) of `db` above the edge. The fill is one loop round the
/// ridge, `gap.inset` inside the strip's edge (an iso-line of `db`), each point β wide and
/// extruded for that width by Eq. 1: the two flanks together put down the strip's volume.
/// Stretches narrower than `gap.min_width`, or where the ridge reaches `gap.below`, are left
/// out.
fn gap_fill(lm: &LayerMesh, db: &[f64], ridge: &[f64], gap: Gap, width: f64) -> Vec<FillPath> {
    let mut out = vec![];
    let dmax = db
        .iter()
        .copied()
        .filter(|d| d.is_finite())
        .fold(0.0f64, f64::max);
    if dmax <= gap.edge + gap.inset.max(0.05 * width) {
        return out;
    }
    for line in lm.iso_lines(db, gap.edge + gap.inset, ridge) {
        let mut cur = FillPath::default();
        for (q, r) in line.q.iter().zip(&line.other) {
            let w = if *r < gap.below {
                (r - gap.edge).clamp(0.0, width)
            } else {
                0.0
            };
            if w >= gap.min_width {
                cur.points.push(*q);
                cur.widths.push(w);
            } else if cur.points.len() >= 2 {
                out.push(std::mem::take(&mut cur));
            } else {
                cur = FillPath::default();
            }
        }
        if cur.points.len() >= 2 {
            out.push(cur);
        }
    }
    out
}

/// The narrowest gap fill between rings, in bead widths: a ring with less than this left
/// beyond its bead widens to take it.
const GAP_MIN_WIDTH_SHARE: f64 = 0.1;

/// Distances to a layer region's boundary are exact (not marched) this many spacings deep.
const SEED_DEPTH: f64 = 3.0;

/// A corner spur is laid only at a convex corner of the layer region sharper than this
/// (radians, measured on the layer surface).
const SPUR_MAX_ANGLE: f64 = 1.75;
/// Shortest corner spur, mm.
const SPUR_MIN_LENGTH: f64 = 0.1;

/// Corner spurs: the outermost paths (rings, or lines without rings) run half a bead inside
/// the boundary, so at a convex corner of angle θ their beads stop `(w/2)(1/sin(θ/2) − 1)`
/// short of it along the bisector, and the tip of the wedge stays empty: at the sharp corners
/// where curved layers cut a blade's end obliquely, a millimetre and more. Each such corner
/// gets a short path along its bisector (on the layer surface) from where the outer beads stop
/// towards the tip, each point as wide as the wedge there (`2ρ·sin(θ/2)` at distance ρ from the
/// corner, capped by twice the distance to the boundary), down to 0.3 of a bead; the
/// extrusion follows that width by Eq. 1, so the wedge is filled rather than over-filled.
fn corner_spurs(chart: &Chart, region: &Region, z: f64, width: f64) -> Vec<FillPath> {
    let mut out = vec![];
    let rings: Vec<&Vec<Point2>> = std::iter::once(&region.outer)
        .chain(region.holes.iter())
        .filter(|r| r.len() >= 3)
        .collect();
    let lifted: Option<Vec<Vec<P3>>> = rings
        .iter()
        .map(|r| r.iter().map(|q| chart.at(*q, z).map(|x| x.0)).collect())
        .collect();
    let Some(lifted) = lifted else { return out };
    let to_boundary = |p: &P3| -> f64 {
        let mut best = f64::INFINITY;
        for ring in &lifted {
            for i in 0..ring.len() {
                let (a, b) = (ring[i], ring[(i + 1) % ring.len()]);
                best = best.min(crate::geodesic::segment_distance(p, &a, &b));
            }
        }
        best
    };
    for (ring, lp) in rings.iter().zip(&lifted) {
        let n = ring.len();
        // The point `reach` away on the surface along the ring from vertex i, walking `dir`.
        let side = |i: usize, dir: isize, reach: f64| -> Option<(Point2, P3)> {
            let pc = lp[i];
            let mut prev = (ring[i], pc);
            for k in 1..n {
                let j = (i as isize + dir * k as isize).rem_euclid(n as isize) as usize;
                let (q, p) = (ring[j], lp[j]);
                let d = (p - pc).norm();
                if d >= reach {
                    let dp = (prev.1 - pc).norm();
                    let t = if d > dp {
                        ((reach - dp) / (d - dp)).clamp(0.0, 1.0)
                    } else {
                        1.0
                    };
                    let qq = [
                        prev.0[0] + (q[0] - prev.0[0]) * t,
                        prev.0[1] + (q[1] - prev.0[1]) * t,
                    ];
                    return Some((qq, prev.1 + (p - prev.1) * t));
                }
                prev = (q, p);
            }
            None
        };
        // The angle at each vertex between the ring's points half a bead either side, on the
        // surface; NaN where the ring turns away from the region there.
        let angle: Vec<f64> = (0..n)
            .map(|i| {
                let (Some((qa, pa)), Some((qb, pb))) =
                    (side(i, -1, 0.5 * width), side(i, 1, 0.5 * width))
                else {
                    return f64::NAN;
                };
                let (u, v) = (
                    [ring[i][0] - qa[0], ring[i][1] - qa[1]],
                    [qb[0] - ring[i][0], qb[1] - ring[i][1]],
                );
                if u[0] * v[1] - u[1] * v[0] <= 0.0 {
                    return f64::NAN;
                }
                let (a, b) = ((pa - lp[i]).normalize(), (pb - lp[i]).normalize());
                a.dot(&b).clamp(-1.0, 1.0).acos()
            })
            .collect();
        for i in 0..n {
            let theta = angle[i];
            if !(theta > 1e-3 && theta < SPUR_MAX_ANGLE) {
                continue;
            }
            // One spur a corner: the sharpest vertex within half a bead along the ring.
            let sharpest = [-1isize, 1].iter().all(|&dir| {
                (1..n)
                    .map_while(|k| {
                        let j = (i as isize + dir * k as isize).rem_euclid(n as isize) as usize;
                        ((lp[j] - lp[i]).norm() < 0.5 * width).then_some(j)
                    })
                    .all(|j| !(angle[j] < theta || (angle[j] == theta && j < i)))
            });
            if !sharpest {
                continue;
            }
            let (Some((q1, p1)), Some((q2, p2))) = (side(i, -1, width), side(i, 1, width)) else {
                continue;
            };
            let (qc, pc) = (ring[i], lp[i]);
            let (l1, l2) = ((p1 - pc).norm(), (p2 - pc).norm());
            if l1 < 1e-9 || l2 < 1e-9 {
                continue;
            }
            // The bisector in the chart: the chart is linear over the corner's neighbourhood,
            // so the chart steps to the unit surface steps along both sides add up to a step
            // of length 2·cos(θ/2) along the bisector on the surface.
            let b = [
                (q1[0] - qc[0]) / l1 + (q2[0] - qc[0]) / l2,
                (q1[1] - qc[1]) / l1 + (q2[1] - qc[1]) / l2,
            ];
            let (sn, cs) = ((0.5 * theta).sin(), (0.5 * theta).cos());
            let rho_s = 0.5 * width * (1.0 / sn - 1.0);
            // The tip ends where the wedge is 0.3 bead wide: its middle stays 0.15 bead off
            // the sides, clear of the region's sampling error.
            let rho_e = 0.15 * width / sn;
            if rho_s - rho_e < SPUR_MIN_LENGTH {
                continue;
            }
            let steps = ((rho_s - rho_e) / (0.25 * width)).ceil().clamp(1.0, 1e3) as usize;
            let mut spur = FillPath::default();
            for k in 0..=steps {
                let rho = rho_e + (rho_s - rho_e) * k as f64 / steps as f64;
                let f = rho / (2.0 * cs);
                let q = [qc[0] + b[0] * f, qc[1] + b[1] * f];
                if !crate::geodesic::region_contains(region, q) {
                    break;
                }
                let Some((p, _)) = chart.at(q, z) else { break };
                let db = to_boundary(&p);
                // Another side of the region comes nearer than the wedge's: stop.
                if db < 0.8 * rho * sn {
                    break;
                }
                spur.points.push(q);
                spur.widths.push((2.0 * db.min(rho * sn)).min(width));
            }
            if spur.points.len() >= 2 {
                spur.reverse();
                out.push(spur);
            }
        }
    }
    out
}

/// The infill boundary's rings, to run zig-zag connectors along.
struct Border<'a> {
    rings: &'a [crate::geodesic::IsoLine],
    /// Arc length at each point of each ring.
    arc: Vec<Vec<f64>>,
}

impl<'a> Border<'a> {
    fn new(rings: &'a [crate::geodesic::IsoLine]) -> Self {
        let arc = rings
            .iter()
            .map(|r| {
                let mut a = vec![0.0];
                for w in r.q.windows(2) {
                    let l = ((w[1][0] - w[0][0]).powi(2) + (w[1][1] - w[0][1]).powi(2)).sqrt();
                    a.push(a[a.len() - 1] + l);
                }
                a
            })
            .collect();
        Border { rings, arc }
    }

    /// Ring, segment and arc length of the ring point nearest `q`, with its distance.
    fn locate(&self, q: Point2) -> Option<(usize, usize, f64, f64)> {
        let mut best: Option<(usize, usize, f64, f64)> = None;
        for (r, ring) in self.rings.iter().enumerate() {
            for (i, w) in ring.q.windows(2).enumerate() {
                let (a, b) = (w[0], w[1]);
                let ab = [b[0] - a[0], b[1] - a[1]];
                let l2 = ab[0] * ab[0] + ab[1] * ab[1];
                let t = if l2 > 0.0 {
                    (((q[0] - a[0]) * ab[0] + (q[1] - a[1]) * ab[1]) / l2).clamp(0.0, 1.0)
                } else {
                    0.0
                };
                let x = [a[0] + ab[0] * t, a[1] + ab[1] * t];
                let d = ((q[0] - x[0]).powi(2) + (q[1] - x[1]).powi(2)).sqrt();
                if best.is_none_or(|b| d < b.3) {
                    best = Some((r, i, self.arc[r][i] + t * l2.sqrt(), d));
                }
            }
        }
        best
    }

    /// The way from `a` to `b` along one ring (interior ring points only), if both lie on the
    /// same ring (within a few micrometres... of a spacing) and the shorter way is at most `max`.
    fn connect(&self, a: Point2, b: Point2, max: f64) -> Option<(f64, Vec<Point2>)> {
        let (ra, ia, sa, da) = self.locate(a)?;
        let (rb, ib, sb, db) = self.locate(b)?;
        if ra != rb || da > 0.05 * max || db > 0.05 * max {
            return None;
        }
        let ring = &self.rings[ra];
        let total = self.arc[ra][self.arc[ra].len() - 1];
        let fwd = sb - sa;
        let (len, forward) = if ring.closed {
            let f = fwd.rem_euclid(total);
            if f <= total - f {
                (f, true)
            } else {
                (total - f, false)
            }
        } else {
            (fwd.abs(), fwd >= 0.0)
        };
        if len > max {
            return None;
        }
        let n = ring.q.len() - usize::from(ring.closed);
        let mut way = vec![];
        if n > 0 {
            // Ring points strictly between the two segments, walking the chosen way.
            let mut i = ia;
            let mut guard = 0;
            while i != ib && guard <= n {
                if forward {
                    i = (i + 1) % n.max(1);
                    way.push(ring.q[i]);
                } else {
                    way.push(ring.q[i]);
                    i = (i + n - 1) % n.max(1);
                }
                guard += 1;
            }
        }
        Some((len, way))
    }
}

/// [`crate::fill::order_paths`] for paths that carry their bead widths.
fn order_fill_paths(paths: Vec<FillPath>, start: Point2) -> Vec<FillPath> {
    let paths = paths.into_iter().filter(|p| p.points.len() >= 2).collect();
    crate::fill::order_greedy(paths, start, |p| &p.points, FillPath::reverse)
}

/// A lifted path point: chart coordinates, position and unit normal.
#[derive(Debug, Clone, Copy)]
struct Lifted {
    q: Point2,
    p: P3,
    n: V3,
    /// Bead width here.
    w: f64,
}

/// Lifts a chart polyline onto the offset surface at `z`, inserting points until every chord
/// is within `tol` of the surface, then dropping points whose removal keeps the polyline
/// within `tol / 2` of the dense one (Douglas–Peucker in 3-D).
fn lift(chart: &Chart, path: &FillPath, z: f64, tol: f64) -> Vec<Lifted> {
    fn refine(
        chart: &Chart,
        a: Lifted,
        b: Lifted,
        z: f64,
        tol: f64,
        depth: u32,
        out: &mut Vec<Lifted>,
    ) {
        if depth < 10 {
            let qm = [0.5 * (a.q[0] + b.q[0]), 0.5 * (a.q[1] + b.q[1])];
            if let Some((p, n)) = chart.at(qm, z) {
                let mid = Lifted {
                    q: qm,
                    p,
                    n,
                    w: 0.5 * (a.w + b.w),
                };
                if (p - P3::from(0.5 * (a.p.coords + b.p.coords))).norm() > tol {
                    refine(chart, a, mid, z, tol, depth + 1, out);
                    refine(chart, mid, b, z, tol, depth + 1, out);
                    return;
                }
            }
        }
        out.push(b);
    }
    let mut dense: Vec<Lifted> = vec![];
    for (q, w) in path.points.iter().zip(&path.widths) {
        let Some((p, n)) = chart.at(*q, z) else {
            continue;
        };
        let cur = Lifted { q: *q, p, n, w: *w };
        match dense.last().copied() {
            Some(prev) => refine(chart, prev, cur, z, tol, 0, &mut dense),
            None => dense.push(cur),
        }
    }
    if dense.len() <= 2 {
        return dense;
    }
    let mut keep = vec![false; dense.len()];
    keep[0] = true;
    keep[dense.len() - 1] = true;
    let mut stack = vec![(0usize, dense.len() - 1)];
    while let Some((i, j)) = stack.pop() {
        if j <= i + 1 {
            continue;
        }
        let (a, b) = (dense[i].p, dense[j].p);
        let ab = b - a;
        let l2 = ab.norm_squared();
        let (mut worst, mut at) = (0.0f64, i);
        for (k, x) in dense.iter().enumerate().take(j).skip(i + 1) {
            let t = if l2 > 0.0 {
                ((x.p - a).dot(&ab) / l2).clamp(0.0, 1.0)
            } else {
                0.0
            };
            let d = (x.p - (a + ab * t)).norm();
            if d > worst {
                worst = d;
                at = k;
            }
        }
        if worst > 0.5 * tol {
            keep[at] = true;
            stack.push((i, at));
            stack.push((at, j));
        }
    }
    dense
        .into_iter()
        .zip(keep)
        .filter_map(|(x, k)| k.then_some(x))
        .collect()
}

/// Figures of a freeform feature's layers, beyond [`FeatureFigures`].
#[derive(Debug, Clone, Copy, Default)]
pub struct FreeformFigures {
    /// `native` (the surface's parameters) or `projection` (tangent-plane chart).
    pub chart: &'static str,
    /// Smallest radius of a concave valley of the reference under the feature, mm (infinite
    /// when it curves away from the feature everywhere).
    pub concave_radius: f64,
    /// Print points with nothing under them: on layer k ≥ 2 more than half a bead outside
    /// layer k−1's region, or on layer 1 over the reference surface's continuation past its
    /// face (overhangs the reference surface's offsets cannot avoid, e.g. a wall leaning
    /// over the reference).
    pub overhang_points: usize,
    /// First and last layer (1-based) with such points.
    pub overhang_layers: Option<(usize, usize)>,
}

/// Whether chart point `q` lies in one of `regions` or within `reach` (chart units) of one.
fn near_regions(regions: &[Region], q: Point2, reach: f64) -> bool {
    if regions
        .iter()
        .any(|r| crate::geodesic::region_contains(r, q))
    {
        return true;
    }
    let r2 = reach * reach;
    regions.iter().any(|r| {
        std::iter::once(&r.outer).chain(r.holes.iter()).any(|ring| {
            let n = ring.len();
            (0..n).any(|i| {
                let (a, b) = (ring[i], ring[(i + 1) % n]);
                let ab = [b[0] - a[0], b[1] - a[1]];
                let l2 = ab[0] * ab[0] + ab[1] * ab[1];
                let t = if l2 > 0.0 {
                    (((q[0] - a[0]) * ab[0] + (q[1] - a[1]) * ab[1]) / l2).clamp(0.0, 1.0)
                } else {
                    0.0
                };
                let x = [a[0] + ab[0] * t - q[0], a[1] + ab[1] * t - q[1]];
                x[0] * x[0] + x[1] * x[1] <= r2
            })
        })
    })
}

/// Plans one freeform feature on offsets of its reference surface, appending its points to
/// `out` (travel from `cursor`, which is left at the last point).
pub fn plan_freeform(
    tree: &FeatureTree,
    f: &Feature,
    params: &LayerParams,
    bead: Bead,
    out: &mut Vec<PathPoint>,
    cursor: &mut Option<P3>,
) -> Result<(FeatureFigures, FreeformFigures), PlanError> {
    let id = f.id;
    let err = |msg: String| PlanError::Freeform { id, msg };
    if f.kind != FeatureKind::Freeform {
        return Err(err("it is not freeform".into()));
    }
    params
        .validate()
        .map_err(|msg| PlanError::Params { id, msg })?;
    let b = &tree.brep;
    let rf = f
        .reference
        .face
        .ok_or_else(|| err("it has no reference face".into()))?;
    let surf = b.face_surface(rf);
    // N into the feature: the host face's outward normal (the parent's outside).
    let mut sign = if b.face(rf).same_sense { 1.0 } else { -1.0 };
    let tol = slicing_tolerance(params);
    let mesh = feature_mesh(tree, f, tol)?;
    if mesh.positions.is_empty() {
        return Err(err("its mesh is empty".into()));
    }
    let mesh = refined(&mesh, MAX_MAPPED_EDGE);
    // Offset deterioration first: a concave reference under the feature folds its offsets
    // before they reach the feature's top, and the feature may not even have a chart then
    // (a rib standing across a trough maps onto both of its flanks).
    fold_check(surf, sign, &mesh, tol, params, id)?;
    let mut chart = choose_chart(surf, sign, id, &mesh)?;
    let mut mapped = mapped_mesh(&chart, &mesh, id)?;
    // The feature lies on the side N points to: check, and turn N round if the face said
    // otherwise.
    let mean_d = mapped.positions.iter().map(|p| p.z).sum::<f64>() / mapped.positions.len() as f64;
    if mean_d < 0.0 {
        sign = -sign;
        chart = choose_chart(surf, sign, id, &mesh)?;
        mapped = mapped_mesh(&chart, &mesh, id)?;
    }
    let top = mapped.positions.iter().map(|p| p.z).fold(0.0f64, f64::max);
    let heights = params.layer_heights(top);
    // Offset deterioration (paper, Fig. 9): the smallest concave radius under the feature.
    let stride = (mapped.positions.len() / 300).max(1);
    let step = (0.5 * params.uniform_layer_height).max(1e-3);
    let mut lambda = 0.0f64;
    for p in mapped.positions.iter().step_by(stride) {
        if let Some(l) = chart.min_curvature([p.x, p.y], step) {
            lambda = lambda.min(l);
        }
    }
    let concave_radius = if lambda < -1e-9 {
        -1.0 / lambda
    } else {
        f64::INFINITY
    };
    let spacing = params.spacing(bead.width);
    let mut fig = FeatureFigures::default();
    let mut ff = FreeformFigures {
        chart: match chart.kind {
            ChartKind::Native { .. } => "native",
            ChartKind::Ortho { .. } => "projection",
        },
        concave_radius,
        overhang_points: 0,
        overhang_layers: None,
    };
    let mut prev_regions: Vec<Region> = vec![];
    let mut printed_layers = vec![];
    let mut z = 0.0;
    let up = Plane::new(P3::origin(), V3::z());
    // Checked before any layer is planned: nothing is laid down for a feature that folds.
    check_folds(id, &heights, concave_radius)?;
    let fixed = params
        .fixed_tool_axis
        .map(|a| V3::new(a[0], a[1], a[2]).normalize());
    // Each layer's regions and fill depend on that layer alone: computed in parallel, then
    // ordered, lifted and joined by travel one layer after the other.
    let mut tops = Vec::with_capacity(heights.len());
    for &dl in &heights {
        tops.push((z + 0.5 * dl, z + dl));
        z += dl;
    }
    let filled: Vec<(Vec<Region>, Vec<FillPath>)> = tops
        .par_iter()
        .enumerate()
        .map(|(layer, &(mid, z))| {
            let loops: Vec<Vec<Point2>> = section(&mapped, &up.offset(mid))
                .iter()
                .map(|l| l.iter().map(|p| [p.x, p.y]).collect())
                .collect();
            let regions = regions_from_loops(&loops);
            let spacing = params
                .spacing_for_layer(bead.width, layer)
                .max(1e-3)
                .min(spacing.max(1e-3) * 1e3);
            let mut paths = vec![];
            for r in &regions {
                paths.extend(fill_region(
                    &chart,
                    r,
                    z,
                    params,
                    layer,
                    bead.width,
                    spacing,
                    SLIVER_INSET * bead.width,
                ));
                paths.extend(corner_spurs(&chart, r, z, bead.width));
            }
            (regions, paths)
        })
        .collect();
    for (layer, ((&dl, &(_, z)), (regions, paths))) in
        heights.iter().zip(&tops).zip(filled).enumerate()
    {
        let below = std::mem::replace(&mut prev_regions, regions);
        let start = cursor
            .and_then(|c| chart.inverse(&c).map(|(q, _)| q))
            .unwrap_or([0.0, 0.0]);
        let paths = if params.path_mode == PathMode::Raster {
            paths
        } else {
            order_fill_paths(paths, start)
        };
        let mut printed = false;
        for path in paths {
            let pts = lift(&chart, &path, z, params.tolerance);
            if pts.len() < 2 {
                continue;
            }
            // Support: the layer below (or, under the first layer, the reference face).
            for x in &pts {
                let held = if layer == 0 {
                    chart.on_face(x.q)
                } else {
                    near_regions(&below, x.q, 0.5 * bead.width / chart.stretch(x.q, z))
                };
                if !held {
                    ff.overhang_points += 1;
                    let l = layer + 1;
                    ff.overhang_layers = Some(match ff.overhang_layers {
                        Some((a, b)) => (a.min(l), b.max(l)),
                        None => (l, l),
                    });
                }
            }
            printed = true;
            let axis = |n: V3| {
                let a = fixed.unwrap_or(n);
                [a.x, a.y, a.z]
            };
            // Travel: up one layer over the start of the path, along the layer above
            // (clear of this layer's beads on a curved surface), then down.
            let first = pts[0];
            let lift_to = z + dl;
            let mut travel: Vec<(P3, V3)> = vec![];
            if let Some(c) = *cursor {
                if let Some((qc, dc)) = chart.inverse(&c) {
                    let hz = lift_to.max(dc + dl);
                    let span = ((first.q[0] - qc[0]).powi(2) + (first.q[1] - qc[1]).powi(2)).sqrt();
                    let n = (span / 2.0).ceil().clamp(1.0, 1000.0) as usize;
                    for i in 0..=n {
                        let t = i as f64 / n as f64;
                        let q = [
                            qc[0] + (first.q[0] - qc[0]) * t,
                            qc[1] + (first.q[1] - qc[1]) * t,
                        ];
                        if let Some(x) = chart.at(q, hz) {
                            travel.push(x);
                        }
                    }
                }
            }
            travel.push((first.p, first.n));
            for (p, n) in travel {
                if let Some(c) = *cursor {
                    fig.travel_length += (p - c).norm();
                }
                out.push(PathPoint {
                    feature: id,
                    layer,
                    kind: MoveKind::Travel,
                    p: [p.x, p.y, p.z],
                    axis: axis(n),
                    e: 0.0,
                    thickness: dl,
                    width: bead.width,
                });
                *cursor = Some(p);
            }
            for w in pts.windows(2) {
                let l = (w[1].p - w[0].p).norm();
                let width = 0.5 * (w[0].w + w[1].w);
                let e = bead.filament_length(width, dl, l);
                fig.print_length += l;
                fig.filament += e;
                out.push(PathPoint {
                    feature: id,
                    layer,
                    kind: MoveKind::Print,
                    p: [w[1].p.x, w[1].p.y, w[1].p.z],
                    axis: axis(w[1].n),
                    e,
                    thickness: dl,
                    width,
                });
            }
            *cursor = pts.last().map(|x| x.p);
        }
        if printed {
            printed_layers.push(dl);
        }
    }
    fig.finish(id, out, &printed_layers);
    if let Some((a, b)) = ff.overhang_layers {
        fig.warnings.push(format!(
            "feature {id}: {} print point(s) in layers {a}..{b} overhang the layer below (nothing under them on the offsets of its reference surface)",
            ff.overhang_points
        ));
    }
    Ok((fig, ff))
}

#[cfg(test)]
mod tests {
    use super::*;
    use brep::math::Frame;

    #[test]
    fn a_flat_disc_is_covered_in_every_mode() {
        // On a plane the chart is exact: the fills must cover the disc like planar fills do.
        let surf = world_plane();
        let chart = Chart::unit(&surf);
        let outer: Vec<Point2> = (0..64)
            .map(|i| {
                let a = i as f64 / 64.0 * std::f64::consts::TAU;
                [6.0 * a.cos(), 6.0 * a.sin()]
            })
            .collect();
        let area = brep::section::signed_area(&outer);
        let region = Region {
            outer,
            holes: vec![],
        };
        for (mode, lo) in [
            (PathMode::ContourZigzag, 0.97),
            (PathMode::Contour, 0.98),
            (PathMode::Zigzag, 0.98),
            (PathMode::Raster, 0.98),
        ] {
            let params = LayerParams {
                path_mode: mode,
                ..LayerParams::default()
            };
            let paths = fill_test_region(&chart, &region, 0.2, &params, 1);
            let covered = covered_area(&paths);
            let r = covered / area;
            assert!(r > lo && r < 1.02, "{mode:?}: {r}");
            // Bead middles half a bead inside the boundary, but where the free ends of raster
            // and zig-zag lines run on to it (stopping a hundredth of a bead short).
            let free_ends = matches!(mode, PathMode::Raster | PathMode::Zigzag);
            for p in &paths {
                for q in &p.points {
                    let r = q[0].hypot(q[1]);
                    if free_ends {
                        assert!(r < 6.0 - 0.004 * 0.45, "{mode:?}: {q:?} outside");
                    } else {
                        assert!(r < 6.0 - 0.2, "{mode:?}: {q:?} outside the bead inset");
                    }
                }
            }
        }
    }

    #[test]
    fn thin_strips_of_a_planar_layer_are_filled_to_their_width() {
        // Strips from under half a bead to a few beads wide, slanted to the lattice. Offsets
        // of one bead width overlapped their own beads in a strip 0.6 mm wide (148 % of its
        // area) and left the middle of one 1.35 mm wide (68 %); the rings now narrow to the
        // room the strip has and gap fill takes what is left along the ridge.
        let (c, s) = (0.3f64.cos(), 0.3f64.sin());
        let rot = |x: f64, y: f64| [x * c - y * s, x * s + y * c];
        for wd in [0.3, 0.45, 0.6, 0.8, 1.0, 1.24, 1.35, 1.6, 2.0, 2.4, 3.0] {
            let region = Region {
                outer: vec![rot(0.0, 0.0), rot(30.0, 0.0), rot(30.0, wd), rot(0.0, wd)],
                holes: vec![],
            };
            for mode in [PathMode::ContourZigzag, PathMode::Contour] {
                let params = LayerParams {
                    path_mode: mode,
                    ..LayerParams::default()
                };
                let paths = fill_flat_region(&region, &params, 0, 0.45, 0.45, Boundary::Part);
                let r = covered_area(&paths) / (30.0 * wd);
                assert!((0.95..1.06).contains(&r), "{wd} mm, {mode:?}: {r:.4}");
                for p in &paths {
                    assert_eq!(p.points.len(), p.widths.len());
                    for (q, w) in p.points.iter().zip(&p.widths) {
                        // Back in the strip's frame: the bead's middle inside the strip.
                        let y = -q[0] * s + q[1] * c;
                        assert!(y > 0.0 && y < wd, "{wd} mm: {q:?} outside");
                        assert!(*w > 0.0 && *w <= 0.45 * 1.1 + 1e-12, "{wd} mm: width {w}");
                    }
                }
            }
        }
    }

    #[test]
    fn rings_on_a_cylinder_layer_are_a_spacing_apart_on_the_surface_not_in_the_chart() {
        // A cylinder of radius 4 offset by 8: the layer has radius 12, three times the
        // reference, so one chart unit across the axis spans 3 mm there.
        let surf = radius_4_cylinder();
        let chart = stretched_chart(&surf);
        // 3 chart units (9 mm on the layer) around, 8 mm along the axis.
        let paths = fill_on_layer(
            &chart,
            vec![[-1.5, -4.0], [1.5, -4.0], [1.5, 4.0], [-1.5, 4.0]],
            PathMode::Contour,
        );
        let lift = |q: Point2| chart.at(q, 8.0).expect("on the layer").0;
        let rings: Vec<Vec<P3>> = paths
            .iter()
            .filter(|p| p.points.len() > 2 && p.points.first() == p.points.last())
            .map(|p| p.points.iter().map(|q| lift(*q)).collect())
            .collect();
        assert!(rings.len() >= 5, "{} rings", rings.len());
        // Along the middle of the long sides, where the rings run straight along the axis,
        // neighbouring rings are one spacing apart on the surface (arc ≈ chord at 0.45 mm on
        // a 12 mm radius).
        let side = |ring: &[P3]| -> f64 {
            ring.iter()
                .filter(|p| p.z.abs() < 1.0 && p.y > 0.0)
                .map(|p| p.y.atan2(p.x) * 12.0)
                .fold(f64::NEG_INFINITY, f64::max)
        };
        for w in rings.windows(2).take(4) {
            let gap = side(&w[0]) - side(&w[1]);
            assert!(
                (gap - 0.45).abs() < 0.02,
                "rings {gap} mm apart on the surface"
            );
        }
    }

    #[test]
    fn small_regions_are_filled_to_their_area_in_every_mode() {
        // Squares and oblongs a few beads across, slanted to the raster: the default
        // contour-zig-zag left a strip up to a spacing wide beside its outer infill lines, and
        // lines that only crossed the band beside the rings were dropped (−7 to −10 % of a
        // 3.4 mm boss's layer); a compact core's gap fill took its half width on every side
        // and laid it twice (+5 % on a 2.6 mm pin).
        let plane = world_plane();
        let chart = Chart::unit(&plane);
        for (a, b) in [
            (1.3, 1.3),
            (2.0, 2.0),
            (2.6, 2.6),
            (3.4, 3.4),
            (4.3, 4.3),
            (3.0, 6.0),
            (2.2, 9.0),
        ] {
            for turn in [0.0f64, 0.3, 0.785] {
                let (c, sn) = (turn.cos(), turn.sin());
                let outer: Vec<Point2> = [(0.0, 0.0), (a, 0.0), (a, b), (0.0, b)]
                    .iter()
                    .map(|&(x, y)| [x * c - y * sn, x * sn + y * c])
                    .collect();
                let region = Region {
                    outer,
                    holes: vec![],
                };
                for mode in [PathMode::ContourZigzag, PathMode::Contour, PathMode::Zigzag] {
                    let params = LayerParams {
                        path_mode: mode,
                        ..LayerParams::default()
                    };
                    let mut paths = fill_test_region(&chart, &region, 0.0, &params, 0);
                    paths.extend(corner_spurs(&chart, &region, 0.0, 0.45));
                    let r = covered_area(&paths) / (a * b);
                    // Contour-only fills end in a last ring narrowed to the room left, laid
                    // on its iso-line rather than the middle of that room: a compact core
                    // keeps up to 5 % of its area unfilled (known; not the default mode).
                    let lo = if mode == PathMode::Contour {
                        0.94
                    } else {
                        0.97
                    };
                    assert!(
                        (lo..=1.03).contains(&r),
                        "{a} x {b} mm turned {turn} rad, {mode:?}: beads cover {:.1} % of it",
                        100.0 * r
                    );
                }
            }
        }
    }

    /// The area the beads of `paths` cover in the chart: length × width, segment by segment.
    fn covered_area(paths: &[FillPath]) -> f64 {
        paths
            .iter()
            .map(|p| {
                p.points
                    .windows(2)
                    .zip(p.widths.windows(2))
                    .map(|(q, w)| {
                        (q[1][0] - q[0][0]).hypot(q[1][1] - q[0][1]) * 0.5 * (w[0] + w[1])
                    })
                    .sum::<f64>()
            })
            .sum()
    }

    /// The plane z = 0.
    fn world_plane() -> Surface {
        Surface::Plane {
            frame: Frame::world(P3::origin()),
        }
    }

    /// A cylinder of radius 4 about the z axis.
    fn radius_4_cylinder() -> Surface {
        Surface::Cylinder {
            frame: Frame::world(P3::origin()),
            radius: 4.0,
        }
    }

    /// The chart of `surf` (a radius-4 cylinder) with one chart unit a radian × 4 mm across
    /// the axis and 1 mm along it: on the layer 8 mm out (radius 12) a unit across is 3 mm.
    fn stretched_chart(surf: &Surface) -> Chart<'_> {
        Chart {
            surf,
            sign: 1.0,
            kind: ChartKind::Native {
                u0: 0.0,
                v0: 0.0,
                su: 4.0,
                sv: 1.0,
            },
        }
    }

    /// The fill of the region `outer` on the layer 8 mm off the reference, 0.45 mm beads.
    fn fill_on_layer(chart: &Chart, outer: Vec<Point2>, mode: PathMode) -> Vec<FillPath> {
        let region = Region {
            outer,
            holes: vec![],
        };
        let params = LayerParams {
            path_mode: mode,
            ..LayerParams::default()
        };
        fill_test_region(chart, &region, 8.0, &params, 0)
    }

    /// `fill_region` with 0.45 mm beads 0.45 mm apart, the part's boundary round the region.
    fn fill_test_region(
        chart: &Chart,
        region: &Region,
        z: f64,
        params: &LayerParams,
        layer: usize,
    ) -> Vec<FillPath> {
        fill_region(
            chart,
            region,
            z,
            params,
            layer,
            0.45,
            0.45,
            SLIVER_INSET * 0.45,
        )
    }

    /// The path points of `paths` lifted onto the layer at `z`.
    fn lifted(chart: &Chart, paths: &[FillPath], z: f64) -> Vec<P3> {
        paths
            .iter()
            .flat_map(|p| p.points.iter())
            .map(|q| chart.at(*q, z).expect("on the layer").0)
            .collect()
    }

    #[test]
    fn ring_corners_keep_their_offset_on_a_stretched_chart() {
        // The cylinder layer of the test above: one chart unit across the axis is 3 mm on
        // the layer, so the rectangle's right-angled corners look sharp in the chart and the
        // lattice triangles there are long. The outer ring's corner must still be the inward
        // offset's: (w/2)·√2 = 0.318 mm from each corner of the region, not cut off by a chord.
        let surf = radius_4_cylinder();
        let chart = stretched_chart(&surf);
        let outer = vec![[-0.5, -3.0], [0.5, -3.0], [0.5, 3.0], [-0.5, 3.0]];
        let region = Region {
            outer: outer.clone(),
            holes: vec![],
        };
        let params = LayerParams {
            path_mode: PathMode::ContourZigzag,
            ..LayerParams::default()
        };
        let paths = fill_test_region(&chart, &region, 8.0, &params, 0);
        let pts = lifted(&chart, &paths, 8.0);
        for c in &outer {
            let pc = chart.at(*c, 8.0).expect("corner").0;
            let nearest = pts
                .iter()
                .map(|p| (p - pc).norm())
                .fold(f64::INFINITY, f64::min);
            let ideal = 0.225 * std::f64::consts::SQRT_2;
            assert!(
                (nearest - ideal).abs() < 0.03,
                "corner {c:?}: nearest path point {nearest:.3} mm away, the offset's is {ideal:.3}"
            );
        }
    }

    #[test]
    fn a_sharp_wedge_gets_a_spur_into_its_tip() {
        // A 30° wedge on a plane: rings stop (w/2)/sin 15° = 0.87 mm short of the tip; the
        // spur runs on along the bisector, as wide as the wedge, to where it is 0.3 bead wide.
        let surf = world_plane();
        let chart = Chart::unit(&surf);
        let half = 15f64.to_radians();
        let (l, w) = (10.0, 0.45);
        let outer = vec![
            [0.0, 0.0],
            [l * half.cos(), -l * half.sin()],
            [l * half.cos(), l * half.sin()],
        ];
        let region = Region {
            outer: outer.clone(),
            holes: vec![],
        };
        let spurs = corner_spurs(&chart, &region, 0.2, w);
        // The tip; the two base corners are 75°, too blunt for a spur.
        assert_eq!(spurs.len(), 1, "{spurs:?}");
        let spur = &spurs[0];
        let to_side = |q: &Point2| q[1].abs().mul_add(-half.cos(), q[0] * half.sin()).abs();
        for (q, bw) in spur.points.iter().zip(&spur.widths) {
            assert!(q[1].abs() < 1e-9, "off the bisector: {q:?}");
            assert!(
                (bw - 2.0 * to_side(q)).abs() < 1e-6 && *bw <= w,
                "width {bw} at {q:?}, the wedge is {}",
                2.0 * to_side(q)
            );
        }
        let tip = spur.points.last().expect("spur")[0];
        let start = spur.points[0][0];
        assert!((tip - 0.15 * w / half.sin()).abs() < 0.02, "tip {tip}");
        let rho_s = 0.5 * w * (1.0 / half.sin() - 1.0);
        assert!((start - rho_s).abs() < 0.02, "start {start}");
        // With the rings, the nearest path point to the tip moves from 0.87 mm to the spur's.
        let params = LayerParams::default();
        let rings = fill_region(&chart, &region, 0.2, &params, 0, w, w, SLIVER_INSET * w);
        let nearest = |paths: &[FillPath]| {
            paths
                .iter()
                .flat_map(|p| p.points.iter())
                .map(|q| q[0].hypot(q[1]))
                .fold(f64::INFINITY, f64::min)
        };
        assert!(nearest(&rings) > 0.8, "rings reach {}", nearest(&rings));
        assert!(nearest(&spurs) < 0.3, "spur reaches {}", nearest(&spurs));
    }

    #[test]
    fn rings_on_a_pitched_strip_of_a_stretched_layer_are_a_spacing_apart() {
        // The cylinder layer of radius 12 again (3 mm on the layer per chart unit across the
        // axis), now with a strip pitched 35° to the axis, 6 mm wide on the layer. Over a
        // lattice laid in the chart the triangles would be long and obtuse on the layer, the
        // marched distance too large, and the inner rings too near the boundary.
        let surf = radius_4_cylinder();
        let chart = stretched_chart(&surf);
        // Unrolled layer coordinates (arc length across the axis, height) to the chart.
        let pitch = 35f64.to_radians();
        let (dir, nrm) = ([pitch.cos(), pitch.sin()], [-pitch.sin(), pitch.cos()]);
        let corner = |l: f64, w: f64| -> Point2 {
            let a = dir[0] * l + nrm[0] * w;
            let z = dir[1] * l + nrm[1] * w;
            [a / 3.0, z]
        };
        let region = Region {
            outer: vec![
                corner(-8.0, -3.0),
                corner(8.0, -3.0),
                corner(8.0, 3.0),
                corner(-8.0, 3.0),
            ],
            holes: vec![],
        };
        let params = LayerParams {
            path_mode: PathMode::Contour,
            ..LayerParams::default()
        };
        let paths = fill_test_region(&chart, &region, 8.0, &params, 0);
        // Each path point's distance (on the unrolled layer) to the strip's near long side,
        // away from the strip's ends.
        let mut by_ring: Vec<Vec<f64>> = vec![];
        for p in paths.iter().filter(|p| p.points.len() > 2) {
            let d: Vec<f64> = p
                .points
                .iter()
                .map(|q| chart.at(*q, 8.0).expect("on the layer").0)
                .map(|x| [x.y.atan2(x.x) * 12.0, x.z])
                .filter(|u| (u[0] * dir[0] + u[1] * dir[1]).abs() < 3.0)
                .map(|u| 3.0 - (u[0] * nrm[0] + u[1] * nrm[1]).abs())
                .collect();
            if !d.is_empty() {
                by_ring.push(d);
            }
        }
        by_ring.sort_by(|a, b| a[0].total_cmp(&b[0]));
        assert!(by_ring.len() >= 6, "{} rings", by_ring.len());
        // Rings 3 to 5 lie deeper than the exact seeds: their distance is marched.
        for (j, d) in by_ring.iter().take(6).enumerate() {
            let want = 0.225 + 0.45 * j as f64;
            for x in d {
                assert!(
                    (x - want).abs() < 0.02,
                    "ring {j}: {x:.3} mm from the side, want {want:.3}"
                );
            }
        }
    }

    #[test]
    fn raster_lines_on_a_stretched_layer_are_a_spacing_apart_on_the_surface() {
        // Raster lines at 45° in the chart of the radius-12 cylinder layer (3 mm per chart
        // unit across the axis): on the surface they run at about 18° to the axis, and
        // neighbouring lines are one spacing apart measured there, across the lines.
        let surf = radius_4_cylinder();
        let chart = stretched_chart(&surf);
        let paths = fill_on_layer(
            &chart,
            vec![[-2.0, -6.0], [2.0, -6.0], [2.0, 6.0], [-2.0, 6.0]],
            PathMode::Raster,
        );
        // Unrolled: a = 12·angle, z. A chart step (1, 1) is (3, 1) unrolled.
        let dir = V3::new(3.0, 1.0, 0.0).normalize();
        let across = V3::new(-dir.y, dir.x, 0.0);
        // Each line's offset across the lines, from its points near the middle.
        let mut offsets: Vec<f64> = paths
            .iter()
            .filter_map(|p| {
                let o: Vec<f64> = p
                    .points
                    .iter()
                    .map(|q| chart.at(*q, 8.0).expect("on the layer").0)
                    .map(|x| V3::new(x.y.atan2(x.x) * 12.0, x.z, 0.0))
                    .filter(|u| u.norm() < 3.0)
                    .map(|u| u.dot(&across))
                    .collect();
                (!o.is_empty()).then(|| o.iter().sum::<f64>() / o.len() as f64)
            })
            .collect();
        offsets.sort_by(f64::total_cmp);
        assert!(offsets.len() >= 8, "{} lines", offsets.len());
        for w in offsets.windows(2) {
            let gap = w[1] - w[0];
            assert!(
                (gap - 0.45).abs() < 0.03,
                "neighbouring lines {gap:.3} mm apart on the surface"
            );
        }
    }

    #[test]
    fn a_sliver_thinner_than_a_bead_is_filled_not_dropped() {
        // A strip 0.3 mm wide and 6 mm long on a plane: no ring of a 0.45 mm bead fits, so
        // the gap fill lays it down, as wide as the strip, with about the strip's area.
        let surf = world_plane();
        let chart = Chart::unit(&surf);
        let outer = vec![[0.0, 0.0], [6.0, 0.0], [6.0, 0.3], [0.0, 0.3]];
        for mode in [PathMode::ContourZigzag, PathMode::Contour, PathMode::Zigzag] {
            let paths = fill_on_layer(&chart, outer.clone(), mode);
            let covered = covered_area(&paths);
            let r = covered / (6.0 * 0.3);
            assert!(r > 0.8 && r < 1.05, "{mode:?}: {r} of the sliver's area");
            for p in &paths {
                for (q, w) in p.points.iter().zip(&p.widths) {
                    assert!(*w <= 0.3 + 1e-6, "{mode:?}: {w} mm wide in a 0.3 mm strip");
                    assert!(q[1] > 0.0 && q[1] < 0.3, "{mode:?}: {q:?} outside");
                }
            }
        }
    }
}
