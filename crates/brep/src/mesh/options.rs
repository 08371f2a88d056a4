//! How finely to mesh, and why a face could not be meshed.

use crate::topology::{Brep, FaceId};

/// How finely to mesh.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct MeshOptions {
    /// Largest distance between a chord and the surface it stands for, mm.
    pub chord_tol: f64,
    /// Largest turn of the tangent or normal between neighbouring points, radians.
    pub angle_tol: f64,
    /// A finer chord tolerance for edges only (mass properties integrate the exact surface
    /// inside faces, so only the boundaries need to be fine); `None` uses `chord_tol`.
    pub edge_chord_tol: Option<f64>,
}

impl MeshOptions {
    /// A chord tolerance with a 15° angular limit.
    pub fn with_tolerance(chord_tol: f64) -> Self {
        MeshOptions {
            chord_tol,
            angle_tol: 15f64.to_radians(),
            edge_chord_tol: None,
        }
    }
}

impl Default for MeshOptions {
    fn default() -> Self {
        MeshOptions::with_tolerance(0.05)
    }
}

/// Why a face could not be meshed.
#[derive(Debug, thiserror::Error)]
pub enum MeshError {
    /// A face whose boundary makes no region on its surface.
    #[error("face #{id}: {msg}")]
    Face {
        /// STEP `#id` of the face.
        id: u64,
        /// What went wrong.
        msg: String,
    },
}

pub(super) fn face_err(brep: &Brep, f: FaceId, msg: impl Into<String>) -> MeshError {
    MeshError::Face {
        id: brep.face(f).step_id,
        msg: msg.into(),
    }
}
