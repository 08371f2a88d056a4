//! A face's loops taken into its parameter domain: projected, unwrapped across periods, and
//! their roles (outer, inner, wrapping, vertex).

use super::edges::face_edge_points;
use super::options::{face_err, MeshError, MeshOptions};
use super::uv::{signed_area, singular_kind, Pt};
use crate::math::P3;
use crate::topology::{Brep, EdgeId, FaceId, LoopId};
use std::collections::HashMap;

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

/// Each edge loop of a face taken into the parameter domain and unwrapped, with how many
/// periods it winds; and the mesh vertices of the face's vertex loops (poles).
#[allow(clippy::type_complexity)]
pub(super) fn loop_chains(
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
