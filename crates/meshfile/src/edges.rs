//! The edges of a triangle mesh counted by how many triangles use them: a closed, manifold
//! surface uses every edge twice, once each way.

use std::collections::HashMap;

/// A mesh's edges by use.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct EdgeCounts {
    /// Edges (pairs of vertices) in all.
    pub edges: usize,
    /// Edges of one triangle only: the border of a hole or gap.
    pub open: usize,
    /// Edges of more than two triangles.
    pub non_manifold: usize,
}

impl EdgeCounts {
    /// Every edge shared by exactly two triangles.
    pub fn closed_manifold(&self) -> bool {
        self.open == 0 && self.non_manifold == 0
    }
}

/// Each undirected edge of `triangles` with the triangles using it.
pub fn edge_uses(triangles: &[[u32; 3]]) -> HashMap<(u32, u32), Vec<u32>> {
    let mut uses: HashMap<(u32, u32), Vec<u32>> = HashMap::with_capacity(triangles.len() * 3 / 2);
    for (k, t) in triangles.iter().enumerate() {
        for e in 0..3 {
            let (a, b) = (t[e], t[(e + 1) % 3]);
            uses.entry((a.min(b), a.max(b))).or_default().push(k as u32);
        }
    }
    uses
}

/// The edges of `triangles` counted by use.
pub fn count(triangles: &[[u32; 3]]) -> EdgeCounts {
    let uses = edge_uses(triangles);
    EdgeCounts {
        edges: uses.len(),
        open: uses.values().filter(|u| u.len() == 1).count(),
        non_manifold: uses.values().filter(|u| u.len() > 2).count(),
    }
}

#[cfg(test)]
mod tests {
    #[test]
    fn a_tetrahedron_is_closed_and_one_face_less_opens_three_edges() {
        let tet = [[0, 2, 1], [0, 1, 3], [1, 2, 3], [2, 0, 3]];
        let c = super::count(&tet);
        assert_eq!((c.edges, c.open, c.non_manifold), (6, 0, 0));
        let c = super::count(&tet[1..]);
        assert_eq!((c.open, c.non_manifold), (3, 0));
    }
}
