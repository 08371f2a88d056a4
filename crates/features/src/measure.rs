//! A solid as read, measured once: its shells' faces, the analysis mesh of them all, each
//! face's share of the enclosed volume and area, the volume and the outer shell's genus. What
//! feature extraction ([`crate::extract()`]) and the whole-part feature ([`crate::whole`]) both
//! start from.

use brep::mesh::{mesh_faces, MeshError};
use brep::solid::analysis_options;
use brep::topology::{Brep, FaceId, SolidId};
use std::collections::HashMap;

/// Why a solid could not be measured.
#[derive(Debug, thiserror::Error)]
pub enum MeasureError {
    /// A face could not be meshed.
    #[error(transparent)]
    Mesh(#[from] MeshError),
    /// The solid (its STEP `#id`) has no shell.
    #[error("solid #{0} has no shell")]
    NoShell(u64),
}

/// A solid's shells and faces as read, meshed once ([`measure`]).
pub(crate) struct Measured {
    /// Its outer shell.
    pub outer_shell: brep::topology::ShellId,
    /// The outer shell's faces.
    pub outer: Vec<FaceId>,
    /// Each void shell's faces.
    pub voids: Vec<Vec<FaceId>>,
    /// The outer faces, then the voids'.
    pub all_faces: Vec<FaceId>,
    /// The diagonal of its rough bounding box, mm (at least a micrometre).
    pub diag: f64,
    /// The analysis mesh's options for that size.
    pub mopts: brep::mesh::MeshOptions,
    /// All its faces meshed with `mopts`.
    pub mesh: brep::mesh::Mesh,
    /// The point the volume shares are taken about: the rough bounding box's centre.
    pub origin: brep::math::P3,
    /// Each face's share of the enclosed volume and its area, mm³ and mm².
    pub shares: HashMap<FaceId, (f64, f64)>,
    /// The enclosed volume, voids subtracted, mm³.
    pub part_volume: f64,
    /// The area of all its faces, mm².
    pub part_area: f64,
    /// The outer shell's genus, where it is a closed surface.
    pub genus: Option<i64>,
}

/// Solid `solid` of `b` measured: its shells' faces, the analysis mesh of them all, each face's
/// share of the volume and area (about the rough bounding box's centre), the enclosed volume
/// and the outer shell's genus. What [`crate::extract::extract`] and the whole-part feature
/// ([`crate::whole::whole_part_tree`]) both start from.
pub(crate) fn measure(b: &Brep, solid: SolidId) -> Result<Measured, MeasureError> {
    let shells = &b.solids[solid.idx()].shells;
    let Some(&outer_shell) = shells.first() else {
        return Err(MeasureError::NoShell(b.solids[solid.idx()].step_id));
    };
    let outer: Vec<FaceId> = b.shells[outer_shell.idx()].faces.clone();
    let voids: Vec<Vec<FaceId>> = shells[1..]
        .iter()
        .map(|s| b.shells[s.idx()].faces.clone())
        .collect();
    let mut all_faces = outer.clone();
    for v in &voids {
        all_faces.extend(v.iter().copied());
    }
    let rough = brep::solid::rough_bbox(b, solid);
    let diag = rough.diagonal().max(1e-3);
    let mopts = analysis_options(diag);
    let mesh = mesh_faces(b, &all_faces, &mopts)?;
    let origin = if rough.is_empty() {
        brep::math::P3::origin()
    } else {
        nalgebra::center(&rough.min, &rough.max)
    };
    let shares: HashMap<FaceId, (f64, f64)> = brep::mass::face_shares(b, &mesh, &origin)
        .into_iter()
        .map(|(f, v, a)| (f, (v, a)))
        .collect();
    let part_volume =
        vol_of(&shares, &outer).abs() - voids.iter().map(|v| vol_of(&shares, v).abs()).sum::<f64>();
    let part_area: f64 = all_faces
        .iter()
        .map(|f| shares.get(f).map_or(0.0, |s| s.1))
        .sum();
    let genus = brep::validate::check_shell(b, outer_shell).genus;
    Ok(Measured {
        outer_shell,
        outer,
        voids,
        all_faces,
        diag,
        mopts,
        mesh,
        origin,
        shares,
        part_volume,
        part_area,
        genus,
    })
}

/// The volume (mm³) the faces' shares enclose, signed by their orientation.
pub(crate) fn vol_of(shares: &HashMap<FaceId, (f64, f64)>, fs: &[FaceId]) -> f64 {
    fs.iter()
        .map(|f| shares.get(f).map_or(0.0, |s| s.0))
        .sum::<f64>()
}
