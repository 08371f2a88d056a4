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

mod cuts;
mod domain;
mod edges;
mod grid;
mod loops;
mod model;
pub mod offset;
mod options;
mod triangulate;
mod uv;

pub use domain::{face_domain, FaceDomain};
pub use edges::discretize_edge;
pub use loops::{loop_roles, LoopRole};
pub use model::{FaceTriangulation, Mesh};
pub use offset::{enclosed_volume, offset_mesh, OffsetMesh};
pub use options::{MeshError, MeshOptions};

use crate::math::P3;
use crate::topology::{Brep, EdgeId, FaceId};
use domain::face_polygons;
use edges::face_edge_points;
use std::collections::HashMap;
use triangulate::triangulate;

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
