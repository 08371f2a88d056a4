//! The attributed adjacency graph: the convexity of each edge two faces share, and how each face
//! rises off the other along it (kept as maps keyed by edge; nothing walks the graph itself).
//!
//! Convexity is sampled along each edge. At each sample the exact outward normals of both faces
//! are taken, and the direction pointing into the first face across the edge is read from the
//! face's own triangle on that edge segment (so it does not depend on how a writer oriented the
//! loops). The edge is concave where the second face's normal leans towards the first face
//! (the external angle is under 180°), smooth where the normals agree within a tolerance.

use brep::math::V3;
use brep::mesh::Mesh;
use brep::topology::{Brep, EdgeId, FaceId};
use std::collections::{HashMap, HashSet};

/// How two faces meet along an edge.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Convexity {
    /// The material angle exceeds 180°: a root where something grows out of a face.
    Concave,
    /// The material angle is under 180°: an outside corner.
    Convex,
    /// Tangent within the tolerance everywhere sampled.
    Smooth,
    /// Concave in places and convex in others.
    Mixed,
}

/// How the face on each side of an edge leaves the other face's tangent plane.
#[derive(Debug, Clone, Copy)]
pub struct Rise {
    /// The two faces.
    pub faces: [FaceId; 2],
    /// `rise[k]`: mean height, along face `k`'s outward normal, of the other face's mesh points
    /// next to the edge (positive: the other face climbs off face `k`, as a fillet at the root of
    /// something growing out of face `k` does).
    pub rise: [f64; 2],
}

/// Faces and their adjacency.
#[derive(Debug, Clone)]
pub struct Aag {
    /// Convexity of each edge between two different faces (seams are absent).
    pub convexity: HashMap<EdgeId, Convexity>,
    /// Rise of each face off the other along each edge between two different faces.
    pub rise: HashMap<EdgeId, Rise>,
}

impl Aag {
    /// How far the face across `e` from `host` climbs off `host`'s tangent plane (mean, mm).
    pub fn rise_from(&self, e: EdgeId, host: FaceId) -> Option<f64> {
        let r = self.rise.get(&e)?;
        if r.faces[0] == host {
            Some(r.rise[0])
        } else if r.faces[1] == host {
            Some(r.rise[1])
        } else {
            None
        }
    }
}

/// Builds the graph of `faces` from a mesh of exactly those faces. `smooth_deg` is the angle
/// under which two faces count as tangent.
pub fn build(brep: &Brep, faces: &[FaceId], mesh: &Mesh, smooth_deg: f64) -> Aag {
    let member: HashSet<FaceId> = faces.iter().copied().collect();
    // For every mesh edge, the faces whose triangles use it and each triangle's third vertex.
    let mut third: HashMap<(u32, u32), Vec<(FaceId, u32)>> = HashMap::new();
    for ft in &mesh.faces {
        for t in &ft.triangles {
            let g = t.map(|i| ft.vertex[i as usize]);
            for k in 0..3 {
                let (a, b, c) = (g[k], g[(k + 1) % 3], g[(k + 2) % 3]);
                third
                    .entry((a.min(b), a.max(b)))
                    .or_default()
                    .push((ft.face, c));
            }
        }
    }
    let mut convexity = HashMap::new();
    let mut rises = HashMap::new();
    for e in brep.edges_of(faces) {
        let mut adj: Vec<FaceId> = vec![];
        for &c in &brep.edge(e).coedges {
            let f = brep.coedge_face(c);
            if member.contains(&f)
                && !adj.contains(&f)
                && brep.face(f).loops.contains(&brep.coedges[c.idx()].lp)
            {
                adj.push(f);
            }
        }
        if adj.len() != 2 {
            continue;
        }
        let (f1, f2) = (adj[0], adj[1]);
        let Some(pts) = mesh.edge_points.get(&e) else {
            continue;
        };
        let segs = pts.len().saturating_sub(1);
        let step = (segs / 12).max(1);
        let (mut concave, mut convex) = (0, 0);
        let (mut r12, mut r21, mut nr) = (0.0, 0.0, 0usize);
        for k in (0..segs).step_by(step) {
            let (a, b) = (pts[k], pts[k + 1]);
            let (pa, pb) = (mesh.positions[a as usize], mesh.positions[b as usize]);
            let Some(users) = third.get(&(a.min(b), a.max(b))) else {
                continue;
            };
            let c1 = users.iter().find(|(f, _)| *f == f1).map(|x| x.1);
            let c2 = users.iter().find(|(f, _)| *f == f2).map(|x| x.1);
            let (Some(c1), Some(c2)) = (c1, c2) else {
                continue;
            };
            let m = nalgebra::center(&pa, &pb);
            let normal = |f: FaceId| {
                let (u, v) = brep.face_project(f, &m);
                brep.face_normal(f, u, v)
            };
            let (Some(n1), Some(n2)) = (normal(f1), normal(f2)) else {
                continue;
            };
            let along = pb - pa;
            let into = |c: u32| -> Option<V3> {
                let w = mesh.positions[c as usize] - pa;
                let l2 = along.norm_squared();
                let d = if l2 > 0.0 {
                    w - along * (w.dot(&along) / l2)
                } else {
                    w
                };
                d.try_normalize(crate::tolerance::NORMALISABLE)
            };
            let (Some(d1), Some(d2)) = (into(c1), into(c2)) else {
                continue;
            };
            r12 += (mesh.positions[c2 as usize] - pa).dot(&n1);
            r21 += (mesh.positions[c1 as usize] - pa).dot(&n2);
            nr += 1;
            let angle = n1.dot(&n2).clamp(-1.0, 1.0).acos().to_degrees();
            if angle < smooth_deg {
                // Tangent here: neither concave nor convex.
            } else if n2.dot(&d1) + n1.dot(&d2) > 0.0 {
                concave += 1;
            } else {
                convex += 1;
            }
        }
        let c = match (concave > 0, convex > 0) {
            (true, false) => Convexity::Concave,
            (false, true) => Convexity::Convex,
            (true, true) => Convexity::Mixed,
            (false, false) => Convexity::Smooth,
        };
        convexity.insert(e, c);
        if nr > 0 {
            rises.insert(
                e,
                Rise {
                    faces: [f1, f2],
                    rise: [r12 / nr as f64, r21 / nr as f64],
                },
            );
        }
    }
    Aag {
        convexity,
        rise: rises,
    }
}
