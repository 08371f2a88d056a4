//! A face's trimmed parameter domain: its closed boundary polygons, wrapping loops paired or
//! closed through a pole, inner loops aligned with the outer one, and the whole domain of a face
//! without edge loops.

use super::cuts::{cut_points, join_wrapping};
use super::edges::face_edge_points;
use super::grid::{grid_steps, step_count};
use super::loops::loop_chains;
use super::options::{face_err, MeshError, MeshOptions};
use super::uv::{signed_area, Pt};
use crate::math::P3;
use crate::surface::Surface;
use crate::tolerance::{LENGTH_FLOOR, PARAMETER_AREA, POINT_COINCIDENCE, SURFACE_COINCIDENCE};
use crate::topology::{Brep, EdgeId, FaceId};
use std::collections::HashMap;

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

/// The closed polygons bounding a face in its parameter domain, with, for each boundary
/// point, the B-rep edges it lies on.
#[allow(clippy::type_complexity)]
pub(super) fn face_polygons(
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
    let edge_of = edges_of_points(brep, f, edge_pts);

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
    let had_wrapping = !wrapping.is_empty();
    let (sing_v, sing_u) = s.singular_lines();
    while let Some((a, wa)) = wrapping.pop() {
        let axis = if wa[0] != 0 { 0 } else { 1 };
        let per = periods[axis].unwrap_or(0.0);
        if let Some(j) = wrapping.iter().position(|(_, wb)| wb[axis] == -wa[axis]) {
            let (b, _) = wrapping.swap_remove(j);
            polys.push(join_wrapping(a, b, axis, per, s, positions, opts));
        } else {
            // Close through the singular line on the side the face lies.
            let closed = (&sing_v, &sing_u, &pole_vertices[..]);
            let poly = close_through_pole(brep, f, a, wa, closed, positions, opts)?;
            polys.push(poly);
        }
    }
    // Poles (vertex loops) and only holes (no loop wraps, none closes through a pole): the face
    // is the whole closed surface less the holes (Onshape writes a sphere of revolution with
    // three holes so). Its seam is put where no hole reaches.
    let holes_only = !had_wrapping
        && !pole_vertices.is_empty()
        && !polys.is_empty()
        && polys.iter().all(|p| !has_bridge(p));
    if holes_only {
        if let Some(u0) = periods[0].and_then(|per| free_u(&polys, per)) {
            if let Some(poly) = full_domain(s, u0, &pole_vertices, positions, opts) {
                polys.insert(0, poly);
            }
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
        match full_domain(s, 0.0, &pole_vertices, positions, opts) {
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

/// Which B-rep edges each boundary point of a face lies on (vertices: all their edges in this
/// face).
fn edges_of_points(
    brep: &Brep,
    f: FaceId,
    edge_pts: &HashMap<EdgeId, Vec<u32>>,
) -> HashMap<u32, Vec<u32>> {
    let face = brep.face(f);
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
    edge_of
}

/// A loop `a` wrapping once around periodic direction `wa` with no partner, closed through the
/// singular line (of `sing_v` for `u`, `sing_u` for `v`) on the side the face lies: the cut to
/// the pole sampled like an edge, the same vertices on both sides.
fn close_through_pole(
    brep: &Brep,
    f: FaceId,
    a: Vec<Pt>,
    wa: [i64; 2],
    (sing_v, sing_u, pole_vertices): (&Vec<f64>, &Vec<f64>, &[u32]),
    positions: &mut Vec<P3>,
    opts: &MeshOptions,
) -> Result<Vec<Pt>, MeshError> {
    let s = brep.face_surface(f);
    let sense = if brep.face(f).same_sense { 1.0 } else { -1.0 };
    let axis = if wa[0] != 0 { 0 } else { 1 };
    let per = [s.u_period(), s.v_period()][axis].unwrap_or(0.0);
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
        .find(|&i| {
            (positions[i as usize] - p3).norm() < POINT_COINCIDENCE * (1.0 + p3.coords.norm())
        })
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
    Ok(poly)
}

/// Whether a boundary polygon closes through a pole (two consecutive points on one singular
/// line).
fn has_bridge(poly: &[Pt]) -> bool {
    let n = poly.len();
    (0..n).any(|k| poly[k].sing != 0 && poly[k].sing == poly[(k + 1) % n].sing)
}

/// A `u` (period `per`) that no polygon reaches: the middle of the widest gap between their `u`
/// extents taken modulo the period; `None` when they cover every `u`.
fn free_u(polys: &[Vec<Pt>], per: f64) -> Option<f64> {
    let mut spans: Vec<(f64, f64)> = vec![];
    for p in polys {
        let lo = p.iter().map(|q| q.uv[0]).fold(f64::INFINITY, f64::min);
        let hi = p.iter().map(|q| q.uv[0]).fold(f64::NEG_INFINITY, f64::max);
        if !(lo.is_finite() && hi.is_finite()) || hi - lo >= per {
            return None;
        }
        let a = lo.rem_euclid(per);
        spans.push((a, a + (hi - lo)));
    }
    spans.sort_by(|x, y| x.0.total_cmp(&y.0));
    // Sweep once round the circle from the first span's start.
    let start = spans.first()?.0;
    let mut reach = start;
    let mut best: Option<(f64, f64)> = None;
    for &(a, b) in spans
        .iter()
        .chain(std::iter::once(&(start + per, start + per)))
    {
        if a > reach && best.is_none_or(|(w, _)| a - reach > w) {
            best = Some((a - reach, 0.5 * (a + reach)));
        }
        reach = reach.max(b);
    }
    best.map(|(_, u)| u.rem_euclid(per))
}

fn fix_bridge_orientation(poly: &mut [Pt], periods: [Option<f64>; 2], sense: f64) {
    let n = poly.len();
    let is_break = |a: &Pt, b: &Pt| a.sing != 0 && a.sing == b.sing;
    let starts: Vec<usize> = (1..n)
        .filter(|&k| is_break(&poly[k - 1], &poly[k]))
        .collect();
    if starts.is_empty() || signed_area(poly) * sense > PARAMETER_AREA {
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

/// The boundary of a surface's whole parameter domain, for faces without edge loops: a closed
/// surface (both directions periodic, or periodic one way and collapsing to poles the other).
/// Seam sides share their vertices with the opposite side and pole sides collapse to one
/// vertex, so the result is watertight. A periodic `u` runs from `u0` round one period.
fn full_domain(
    s: &Surface,
    u0: f64,
    pole_vertices: &[u32],
    positions: &mut Vec<P3>,
    opts: &MeshOptions,
) -> Option<Vec<Pt>> {
    let (bu, bv) = s.bounds();
    let (pu, pv) = (s.u_period(), s.v_period());
    let ur = pu.map(|p| (u0, u0 + p)).or(bu)?;
    let vr = pv.map(|p| (0.0, p)).or(bv)?;
    let (du, dv) = grid_steps(s, ur, vr, opts);
    let (nu, nv) = (step_count(ur, du, 4), step_count(vr, dv, 4));
    let size = s.size_hint();
    let new_vertex = |p: P3, positions: &mut Vec<P3>| -> u32 {
        if let Some(&i) = pole_vertices.iter().find(|&&i| {
            (positions[i as usize] - p).norm() <= SURFACE_COINCIDENCE * size.max(LENGTH_FLOOR)
        }) {
            return i;
        }
        positions.push(p);
        (positions.len() - 1) as u32
    };
    // A side collapses when all its points coincide.
    let collapsed = |pts: &[P3]| {
        pts.iter()
            .all(|p| (p - pts[0]).norm() <= SURFACE_COINCIDENCE * size.max(LENGTH_FLOOR))
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
