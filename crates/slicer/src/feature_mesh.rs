//! The mesh a feature is sliced from, and its chord tolerance.

use crate::error::FeatureError;
use crate::params::LayerParams;
use crate::tolerance::MICROMETRE;
use brep::mesh::{mesh_faces, MeshOptions};
use features::{Feature, FeatureTree};

/// Chord tolerance of the mesh a feature is sliced from: much finer than a layer, since its
/// chords are what the sections see.
pub(crate) fn slicing_tolerance(params: &LayerParams) -> f64 {
    (params.tolerance * 0.25)
        .min(0.25 * params.uniform_layer_height)
        .max(MICROMETRE)
}

/// The mesh of a feature's shell and its voids, at chord tolerance `tol`.
pub(crate) fn feature_mesh(
    tree: &FeatureTree,
    f: &Feature,
    tol: f64,
) -> Result<brep::mesh::Mesh, FeatureError> {
    let mut faces = f.faces.clone();
    for v in &f.voids {
        faces.extend(v.iter().copied());
    }
    let mesh_at = |tol: f64| {
        mesh_faces(&tree.brep, &faces, &MeshOptions::with_tolerance(tol)).map_err(|e| {
            FeatureError::Mesh {
                id: f.id,
                msg: e.to_string(),
            }
        })
    };
    let mut mesh = mesh_at(tol)?;
    // A small feature's sections lose to their chords what its volume keeps (issue 31, item
    // 4): meshed again finer for its thickness.
    let fine = THICKNESS_CHORD_SHARE * thickness(f.volume, &mesh);
    if fine.is_finite() && fine < tol {
        mesh = mesh_at(fine.max(MICROMETRE))?;
    }
    orient_voids(&mut mesh, &f.voids);
    Ok(mesh)
}

/// Each void shell of `voids` turned to face into the void where a file wrote it facing out
/// (enclosing a positive volume, like a solid's outer shell): its sections then run clockwise
/// around the void, as a hole's do, which the winding reading of crossing loops
/// (`fill::regions_by_winding`) relies on.
fn orient_voids(mesh: &mut brep::mesh::Mesh, voids: &[Vec<brep::topology::FaceId>]) {
    for v in voids {
        let of_void = |t: &brep::mesh::FaceTriangulation| v.contains(&t.face);
        let volume: f64 = mesh
            .faces
            .iter()
            .filter(|t| of_void(t))
            .flat_map(|t| {
                t.triangles.iter().map(|tri| {
                    let [a, b, c] = tri.map(|i| mesh.positions[t.vertex[i as usize] as usize]);
                    a.coords.dot(&b.coords.cross(&c.coords)) / 6.0
                })
            })
            .sum();
        if volume > 0.0 {
            for t in mesh.faces.iter_mut().filter(|t| of_void(t)) {
                for tri in &mut t.triangles {
                    tri.swap(1, 2);
                }
            }
        }
    }
}

/// The chord tolerance of a feature's mesh as a share of its thickness ([`thickness`]): a
/// round section of radius r meshed at chord tolerance s keeps, as an inscribed polygon, about
/// `1 − (4/3)·s/r` of its area (each chord of length c cuts off a segment of area
/// `(2/3)·c·s`, and the chords add up to `2πr`). A pin's thickness `2V/A` is about its radius
/// (`r·h/(r + h)` with its ends), so this share keeps a pin's sections within 0.3 % of their
/// area: a 1.39 mm pin was 2.4 % short at the slicing tolerance of 0.0125 mm.
const THICKNESS_CHORD_SHARE: f64 = 0.002;

/// A feature's thickness, mm: twice its volume over its surface area (a wall's thickness, a
/// long pin's radius); infinite where the mesh has no area.
fn thickness(volume: f64, mesh: &brep::mesh::Mesh) -> f64 {
    let area: f64 = mesh
        .triangles()
        .iter()
        .map(|t| {
            let [a, b, c] = t.map(|i| mesh.positions[i as usize]);
            0.5 * (b - a).cross(&(c - a)).norm()
        })
        .sum();
    if area > 0.0 && volume.is_finite() && volume > 0.0 {
        2.0 * volume / area
    } else {
        f64::INFINITY
    }
}
