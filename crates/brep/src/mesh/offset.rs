//! A closed face mesh offset face by face along the exact surfaces' normals: the solid grown
//! by a machining allowance (issue 37, item 2; feature-based AM paper, the layer parameter
//! `tolerance` read as "the machining allowance for the following post-process").
//!
//! Each face `F` is given a distance `d_F` (0 leaves it where it is; negative moves it into
//! the solid). A vertex inside one face moves to `p + d_F·N_F(u, v)`, `N_F` the exact outward
//! normal of `F`'s surface at the vertex's `(u, v)`: it lies on the exact offset surface (a
//! plane shifted, a cylinder, cone, sphere or torus grown, a B-spline's offset). A vertex on
//! an edge or a corner, shared by faces `F_1 … F_k`, moves to the least-norm `q` with
//! `N_i · (q − p) = d_i` for each of them: the point where the faces' offset tangent planes
//! meet, so the neighbouring offset faces are extended (at a convex edge) or trimmed (at a
//! concave one) to meet there, as a sharp offset (OpenCASCADE's `GeomAbs_Intersection` join)
//! does; exact along straight edges between planes, and within `d²·κ` (κ the faces' curvature
//! across the edge) elsewhere. Faces tangent along an edge share the point `p + d·N`.
//!
//! Where a face is extended at a convex edge, its inner points slide along with the edge's
//! (fading with the distance), so no thin triangle between them turns over. Where it is
//! trimmed at a concave edge, the inner points the trim passes stay on the face's offset,
//! inside the neighbour's: the triangles from the edge to them fold back flat along the face
//! (the sections' union reads the solid they bound; where the face curves, the fold is a
//! sliver a few hundredths of a millimetre thick, measured on the impeller's blade roots). A triangle of inner points that the offset
//! turns over is a true fold, a concave radius below the distance: it is named among
//! [`OffsetMesh::folds`].

use super::model::Mesh;
use crate::math::{P3, V3};
use crate::tolerance::{NONZERO, OFFSET_RANK_CUTOFF, OFFSET_TANGENT, SLIDE_ZERO};
use crate::topology::{Brep, FaceId};
use nalgebra::Matrix3;

/// A corner's move is at most this many times the largest distance asked for: the mitre of two
/// faces meeting at a knife edge (nearly opposite normals) runs off far, and is cut back to
/// this (its vertex named in [`OffsetMesh::capped`]).
pub const MAX_MITRE: f64 = 4.0;

/// The offset of a mesh and where it went wrong.
#[derive(Debug, Clone)]
pub struct OffsetMesh {
    /// The same faces and triangles with the vertices moved.
    pub mesh: Mesh,
    /// Nominal centroids of the triangles the offset turned over (the offset self-intersects
    /// there).
    pub folds: Vec<P3>,
    /// Nominal positions of the vertices whose mitre was cut back to [`MAX_MITRE`] times the
    /// distance.
    pub capped: Vec<P3>,
}

/// Offsets `mesh` (a mesh of faces of `brep`, as [`super::mesh_faces`] makes it): every face
/// by `distance(face)` along its outward normal, edges and corners mitred (module docs).
pub fn offset_mesh(brep: &Brep, mesh: &Mesh, distance: &dyn Fn(FaceId) -> f64) -> OffsetMesh {
    // Each vertex's constraints: (outward normal, distance), one per face that uses it.
    let mut cons: Vec<Vec<(V3, f64)>> = vec![Vec::new(); mesh.positions.len()];
    let mut largest = 0.0f64;
    let mut normals: Vec<Vec<Option<V3>>> = Vec::with_capacity(mesh.faces.len());
    for t in &mesh.faces {
        let d = distance(t.face);
        if !d.is_finite() {
            normals.push(vec![]);
            continue;
        }
        largest = largest.max(d.abs());
        let surf = brep.face_surface(t.face);
        let sense = if brep.face(t.face).same_sense {
            1.0
        } else {
            -1.0
        };
        let fallback = triangle_normals(mesh, t);
        let mut local = Vec::with_capacity(t.vertex.len());
        for (i, (&g, uv)) in t.vertex.iter().zip(&t.uv).enumerate() {
            let n = surf
                .normal(uv[0], uv[1])
                .map(|n| n * sense)
                .or(fallback[i])
                .and_then(|n| n.try_normalize(NONZERO));
            if let (Some(n), Some(c)) = (n, cons.get_mut(g as usize)) {
                c.push((n, d));
            }
            local.push(n);
        }
        normals.push(local);
    }
    let mut capped = vec![];
    let moves: Vec<V3> = mesh
        .positions
        .iter()
        .zip(&cons)
        .map(|(p, c)| {
            let (mv, cut) = mitre(c, MAX_MITRE * largest);
            if cut {
                capped.push(*p);
            }
            mv
        })
        .collect();
    let mut positions: Vec<P3> = mesh
        .positions
        .iter()
        .zip(&moves)
        .map(|(p, mv)| p + mv)
        .collect();
    // Folds are read off the offset before the slides: the slides are the mesh's, not the
    // surface's.
    let offset = positions.clone();
    for (t, n) in mesh.faces.iter().zip(&normals) {
        carry_inside(mesh, (t, n), &cons, &moves, &mut positions);
    }
    let on_edge = |g: u32| cons.get(g as usize).is_some_and(|c| c.len() > 1);
    let folds = mesh
        .triangles()
        .into_iter()
        .filter(|t| !t.iter().any(|&g| on_edge(g)))
        .filter_map(|t| {
            let [a, b, c] = t.map(|i| mesh.positions[i as usize]);
            let [x, y, z] = t.map(|i| offset[i as usize]);
            let before = (b - a).cross(&(c - a));
            let after = (y - x).cross(&(z - x));
            (before.dot(&after) < 0.0).then(|| P3::from((a.coords + b.coords + c.coords) / 3.0))
        })
        .collect();
    OffsetMesh {
        mesh: Mesh {
            positions,
            ..mesh.clone()
        },
        folds,
        capped,
    }
}

/// How far into a face the slide of its boundary is carried, in lengths of that slide.
const CARRY: f64 = 8.0;

/// The points inside face `t` slid along with its boundary: where the offset extends or trims a
/// face at an edge, the edge's points move along the face (the mitre's part across the face's
/// normal) while the face's inner points would stay, and a thin triangle between them turns over.
/// Each inner point takes the slide of its nearest boundary point, fading to nothing
/// [`CARRY`] slides away: a move that changes by less than a third of the distance between
/// two points, so no triangle turns over for it.
fn carry_inside(
    mesh: &Mesh,
    (t, normals): (&super::model::FaceTriangulation, &[Option<V3>]),
    cons: &[Vec<(V3, f64)>],
    moves: &[V3],
    positions: &mut [P3],
) {
    let edge = |g: u32| cons.get(g as usize).is_some_and(|c| c.len() > 1);
    let mut slides: Vec<(P3, V3)> = vec![];
    for (&g, n) in t.vertex.iter().zip(normals) {
        let (true, Some(n)) = (edge(g), n) else {
            continue;
        };
        let gi = g as usize;
        // The slide: the move less its part along this face's normal there.
        let slide = moves[gi] - n * moves[gi].dot(n);
        if slide.norm() > SLIDE_ZERO {
            slides.push((mesh.positions[gi], slide));
        }
    }
    if slides.is_empty() {
        return;
    }
    for (&g, n) in t.vertex.iter().zip(normals) {
        if edge(g) {
            continue;
        }
        let p = mesh.positions[g as usize];
        let nearest = slides.iter().min_by(|a, b| {
            (a.0 - p)
                .norm_squared()
                .total_cmp(&(b.0 - p).norm_squared())
        });
        let Some((b, slide)) = nearest else {
            continue;
        };
        // A trim (the edge slides into the face) is not carried: the points it passes lie
        // inside the neighbour's offset (pushing them onto the trimmed edge, from the nearest
        // edge point alone, turned more triangles over than it flattened: measured on the
        // impeller's blade roots).
        if slide.dot(&(p - b)) > 0.0 {
            continue;
        }
        let w = 1.0 - (b - p).norm() / (CARRY * slide.norm());
        // Along the face where the point is (a curved face turns away from the edge's
        // tangent plane): the point stays on the offset surface.
        let along = match n {
            Some(n) => slide - n * slide.dot(n),
            None => *slide,
        };
        if w > 0.0 {
            positions[g as usize] += along * w;
        }
    }
}

/// The least-norm move `x` with `n · x = d` for every constraint, tangent normals merged
/// (the larger distance kept), its length cut to `cap` (and `true` then).
fn mitre(cons: &[(V3, f64)], cap: f64) -> (V3, bool) {
    let mut merged: Vec<(V3, f64)> = Vec::with_capacity(cons.len());
    for &(n, d) in cons {
        match merged
            .iter_mut()
            .find(|(m, _)| 1.0 - m.dot(&n) < OFFSET_TANGENT)
        {
            Some(m) => m.1 = m.1.max(d),
            None => merged.push((n, d)),
        }
    }
    let x = match merged.as_slice() {
        [] => V3::zeros(),
        [(n, d)] => n * *d,
        many => {
            // x = (NᵀN)⁺ Nᵀ d, the pseudo-inverse through NᵀN's eigen-decomposition.
            let mut ntn = Matrix3::zeros();
            let mut ntd = V3::zeros();
            for (n, d) in many {
                ntn += n * n.transpose();
                ntd += n * *d;
            }
            let eig = ntn.symmetric_eigen();
            let top = eig.eigenvalues.max();
            let mut x = V3::zeros();
            for k in 0..3 {
                let l = eig.eigenvalues[k];
                if l > OFFSET_RANK_CUTOFF * top {
                    let v: V3 = eig.eigenvectors.column(k).into();
                    x += v * (v.dot(&ntd) / l);
                }
            }
            x
        }
    };
    let len = x.norm();
    if cap > 0.0 && len > cap {
        (x * (cap / len), true)
    } else {
        (x, false)
    }
}

/// Each local vertex's normal from the face's triangles around it (area-weighted), for the
/// points where the surface has none (a sphere's pole, a cone's apex).
fn triangle_normals(mesh: &Mesh, t: &super::model::FaceTriangulation) -> Vec<Option<V3>> {
    let mut acc = vec![V3::zeros(); t.vertex.len()];
    for tri in &t.triangles {
        let [a, b, c] = tri.map(|i| mesh.positions[t.vertex[i as usize] as usize]);
        let n = (b - a).cross(&(c - a));
        for &i in tri {
            acc[i as usize] += n;
        }
    }
    acc.into_iter().map(|n| n.try_normalize(NONZERO)).collect()
}

/// The volume a closed, outward mesh encloses (divergence theorem over its triangles), mm³.
pub fn enclosed_volume(mesh: &Mesh) -> f64 {
    mesh.triangles()
        .iter()
        .map(|t| {
            let [a, b, c] = t.map(|i| mesh.positions[i as usize]);
            a.coords.dot(&b.coords.cross(&c.coords)) / 6.0
        })
        .sum()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_corner_of_three_planes_moves_along_each_normal() {
        let cons = [(V3::x(), 1.0), (V3::y(), 1.0), (V3::z(), 0.0)];
        let (x, cut) = mitre(&cons, 10.0);
        assert!(!cut);
        assert!((x - V3::new(1.0, 1.0, 0.0)).norm() < 1e-12, "{x:?}");
    }

    #[test]
    fn an_edge_of_two_planes_meets_both_offset_planes_at_the_least_move() {
        let a = V3::new(1.0, 0.0, 1.0).normalize();
        let b = V3::new(-1.0, 0.0, 1.0).normalize();
        let (x, _) = mitre(&[(a, 2.0), (b, 2.0)], 100.0);
        assert!((a.dot(&x) - 2.0).abs() < 1e-12 && (b.dot(&x) - 2.0).abs() < 1e-12);
        assert!(x.y.abs() < 1e-12, "no move along the edge: {x:?}");
    }

    #[test]
    fn tangent_faces_move_together_by_the_larger_distance() {
        let n = V3::z();
        let (x, _) = mitre(&[(n, 1.0), (n, 0.5)], 10.0);
        assert!((x - V3::new(0.0, 0.0, 1.0)).norm() < 1e-12);
    }

    #[test]
    fn a_knife_edge_is_cut_back() {
        let a = V3::new(1.0, 0.0, 0.01).normalize();
        let b = V3::new(-1.0, 0.0, 0.01).normalize();
        let (x, cut) = mitre(&[(a, 1.0), (b, 1.0)], 4.0);
        assert!(cut && (x.norm() - 4.0).abs() < 1e-9);
    }
}
