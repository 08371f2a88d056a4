//! The mesh a feature is sliced from, and its chord tolerance.

use crate::error::PlanError;
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
) -> Result<brep::mesh::Mesh, PlanError> {
    let mut faces = f.faces.clone();
    for v in &f.voids {
        faces.extend(v.iter().copied());
    }
    mesh_faces(&tree.brep, &faces, &MeshOptions::with_tolerance(tol)).map_err(|e| PlanError::Mesh {
        id: f.id,
        msg: e.to_string(),
    })
}
