//! Rough bounding boxes of solids and face sets, good enough to size tolerances.

use crate::math::Aabb;
use crate::topology::{Brep, FaceId, SolidId};

/// A bounding box good enough to size tolerances: vertices, a few points of every edge, and
/// samples of faces that have no edge at all (a whole sphere or torus).
pub fn rough_bbox(brep: &Brep, s: SolidId) -> Aabb {
    faces_rough_bbox(brep, &brep.solid_faces(s))
}

/// [`rough_bbox`] of a set of faces.
pub fn faces_rough_bbox(brep: &Brep, faces: &[FaceId]) -> Aabb {
    let mut b = Aabb::empty();
    let faces = faces.to_vec();
    for v in brep.vertices_of(&faces) {
        b.add(&brep.vertices[v.idx()].point);
    }
    for e in brep.edges_of(&faces) {
        let edge = brep.edge(e);
        let c = brep.edge_curve(e);
        for k in 1..8 {
            b.add(&c.eval(edge.t_start + (edge.t_end - edge.t_start) * k as f64 / 8.0));
        }
    }
    for f in faces {
        let face = brep.face(f);
        if face
            .loops
            .iter()
            .all(|l| brep.loops[l.idx()].coedges.is_empty())
        {
            let srf = brep.face_surface(f);
            let (bu, bv) = srf.bounds();
            let ur = srf
                .u_period()
                .map(|p| (0.0, p))
                .or(bu)
                .unwrap_or((0.0, 1.0));
            let vr = srf
                .v_period()
                .map(|p| (0.0, p))
                .or(bv)
                .unwrap_or((0.0, 1.0));
            for i in 0..=8 {
                for j in 0..=8 {
                    b.add(&srf.eval(
                        ur.0 + (ur.1 - ur.0) * i as f64 / 8.0,
                        vr.0 + (vr.1 - vr.0) * j as f64 / 8.0,
                    ));
                }
            }
        }
    }
    b
}
