//! Volume, area and centroid by integrating the exact surfaces over each face's parameter-domain
//! triangulation (divergence theorem, 7-point Gauss rule per triangle), so curved faces are not
//! flattened into chords.

use crate::math::{Aabb, P3, V3};
use crate::mesh::Mesh;
use crate::topology::Brep;

/// Integrals over a set of faces.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct MassProperties {
    /// Signed enclosed volume, mm³ (positive for an outward-oriented closed shell).
    pub volume: f64,
    /// Surface area, mm².
    pub area: f64,
    /// Centroid of the enclosed volume.
    pub centroid: P3,
    /// Bounding box of the mesh.
    pub bbox: Aabb,
}

/// Dunavant's degree-5 rule: barycentric points and weights (weights sum to 1).
const GAUSS7: [([f64; 3], f64); 7] = [
    ([1.0 / 3.0, 1.0 / 3.0, 1.0 / 3.0], 0.225),
    (
        [
            0.059_715_871_789_770,
            0.470_142_064_105_115,
            0.470_142_064_105_115,
        ],
        0.132_394_152_788_506,
    ),
    (
        [
            0.470_142_064_105_115,
            0.059_715_871_789_770,
            0.470_142_064_105_115,
        ],
        0.132_394_152_788_506,
    ),
    (
        [
            0.470_142_064_105_115,
            0.470_142_064_105_115,
            0.059_715_871_789_770,
        ],
        0.132_394_152_788_506,
    ),
    (
        [
            0.797_426_985_353_087,
            0.101_286_507_323_456,
            0.101_286_507_323_456,
        ],
        0.125_939_180_544_827,
    ),
    (
        [
            0.101_286_507_323_456,
            0.797_426_985_353_087,
            0.101_286_507_323_456,
        ],
        0.125_939_180_544_827,
    ),
    (
        [
            0.101_286_507_323_456,
            0.101_286_507_323_456,
            0.797_426_985_353_087,
        ],
        0.125_939_180_544_827,
    ),
];

/// Integrates the faces of `mesh` (all of them) over their exact surfaces.
pub fn mass_properties(brep: &Brep, mesh: &Mesh) -> MassProperties {
    let bbox = mesh.bbox();
    let c = if bbox.is_empty() {
        P3::origin()
    } else {
        nalgebra::center(&bbox.min, &bbox.max)
    };
    let mut vol = 0.0;
    let mut area = 0.0;
    let mut first = V3::zeros();
    for ft in &mesh.faces {
        let s = brep.face_surface(ft.face);
        for t in &ft.triangles {
            let a = ft.uv[t[0] as usize];
            let b = ft.uv[t[1] as usize];
            let d = ft.uv[t[2] as usize];
            // Signed parameter-space area: negative where the face runs against the surface.
            let det = 0.5 * ((b[0] - a[0]) * (d[1] - a[1]) - (d[0] - a[0]) * (b[1] - a[1]));
            if det == 0.0 {
                continue;
            }
            for (w, wt) in GAUSS7.iter() {
                let u = w[0] * a[0] + w[1] * b[0] + w[2] * d[0];
                let v = w[0] * a[1] + w[1] * b[1] + w[2] * d[1];
                let p = s.eval(u, v) - c;
                let (su, sv) = s.derivs(u, v);
                let n = su.cross(&sv);
                vol += wt * det * p.dot(&n) / 3.0;
                area += wt * det.abs() * n.norm();
                first +=
                    wt * det * V3::new(p.x * p.x * n.x, p.y * p.y * n.y, p.z * p.z * n.z) * 0.5;
            }
        }
    }
    let centroid = if vol.abs() > 0.0 { c + first / vol } else { c };
    MassProperties {
        volume: vol,
        area,
        centroid,
        bbox,
    }
}
