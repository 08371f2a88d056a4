//! The mesh: per-face triangulations sharing vertices along edges, and its queries (open
//! edges, winding number, bounding box).

use crate::math::{Aabb, P3};
use crate::topology::{EdgeId, FaceId};
use std::collections::HashMap;

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
