//! Edge sampling: every B-rep edge discretised once in 3-D, refined by chord, turn and, on
//! curved surfaces, by how its `(u, v)` image bends.

use super::options::MeshOptions;
use super::uv::singular_kind;
use crate::curve::Curve;
use crate::math::P3;
use crate::surface::Surface;
use crate::tolerance::NONZERO;
use crate::topology::{Brep, EdgeId, FaceId};
use std::collections::HashMap;

/// Faces meshed together that are searched rather than indexed.
const FEW_FACES: usize = 32;

/// Vertex positions, vertex indices and edge point indices for one face's boundary.
#[allow(clippy::type_complexity)]
pub(super) fn face_edge_points(
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
    // Whether a face is meshed: a search of `faces` for a few, by index for many (a mesh's
    // B-rep has a face per triangle, and a search for each edge's faces was quadratic in
    // them; an index of every face for each face meshed alone would be too).
    let index = (faces.len() > FEW_FACES).then(|| {
        let mut m = vec![false; brep.faces.len()];
        for f in faces {
            m[f.idx()] = true;
        }
        m
    });
    let meshed = |f: FaceId| {
        index
            .as_ref()
            .map_or_else(|| faces.contains(&f), |m| m[f.idx()])
    };
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
            .filter(|&f| meshed(f))
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
        let turn = if ta.norm() > NONZERO && tb.norm() > NONZERO {
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
pub(super) fn chord_deviation(pa: &P3, pm: &P3, pb: &P3) -> f64 {
    let chord = pb - pa;
    let l = chord.norm();
    if l > NONZERO {
        (pm - pa).cross(&chord).norm() / l
    } else {
        (pm - pa).norm()
    }
}
