//! Helpers of the pole-seam mesh tests, shared by `crates/brep/tests/pole_seam.rs` (whole
//! parts) and `crates/features/tests/pole_seam.rs` (base features after extraction), which
//! includes this file by path.

use brep::mass::mass_properties;
use brep::math::P3;
use brep::mesh::{mesh_faces, Mesh};
use brep::solid::analysis_options;
use brep::topology::{FaceId, SolidId};
use brep::Brep;
use std::path::PathBuf;

/// A fixture's B-rep and its (first) solid.
pub fn read(name: &str) -> (Brep, SolidId) {
    let path = PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("../../fixtures")
        .join(format!("{name}.step"));
    let part = brep::read_step(&path).expect("fixture reads");
    let s = part.brep.solid_ids().next().expect("a solid");
    (part.brep, s)
}

/// The volume the triangles enclose (sum of signed tetrahedra).
pub fn mesh_volume(m: &Mesh) -> f64 {
    m.triangles()
        .iter()
        .map(|t| {
            let [a, b, c] = t.map(|i| m.positions[i as usize].coords);
            a.dot(&b.cross(&c)) / 6.0
        })
        .sum()
}

/// The exact volume of a closed set of faces: the exact surfaces integrated over their
/// parameter triangles, at analysis precision.
pub fn exact_volume(brep: &Brep, faces: &[FaceId], diag: f64) -> f64 {
    let m = mesh_faces(brep, faces, &analysis_options(diag)).expect("meshes");
    mass_properties(brep, &m).volume
}

/// The largest distance from a triangle's centroid to the face's surface, over the faces on
/// a sphere: a chord cutting across the face shows here.
pub fn sphere_sag(brep: &Brep, m: &Mesh) -> f64 {
    let mut worst: f64 = 0.0;
    for ft in &m.faces {
        let s = brep.face_surface(ft.face);
        if s.kind() != "sphere" {
            continue;
        }
        for t in &ft.triangles {
            let [a, b, c] = t.map(|i| ft.vertex[i as usize]);
            if a == b || b == c || a == c {
                continue;
            }
            let c = P3::from(
                (m.positions[a as usize].coords
                    + m.positions[b as usize].coords
                    + m.positions[c as usize].coords)
                    / 3.0,
            );
            let (u, v) = s.project(&c, None);
            worst = worst.max((s.eval(u, v) - c).norm());
        }
    }
    worst
}

/// Winding numbers 0.3 mm under and over a sphere `(centre z, radius)` at `y = 0` (the seam's
/// azimuth), `x` from 1 to 15 mm: `(x, under, over)`.
pub fn seam_windings(m: &Mesh, zc: f64, r: f64) -> Vec<(f64, f64, f64)> {
    [1.0, 2.0, 4.0, 6.0, 7.5, 9.0, 12.0, 15.0]
        .into_iter()
        .map(|x: f64| {
            let z = zc + (r * r - x * x).sqrt();
            (
                x,
                m.winding_number(&P3::new(x, 0.0, z - 0.3)),
                m.winding_number(&P3::new(x, 0.0, z + 0.3)),
            )
        })
        .collect()
}
