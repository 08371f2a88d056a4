//! The whole part as features: each solid one two5d feature of all its faces, built on the
//! plate from its lowest point along +Z, as a planar slicer slices it (issue 33, the process
//! key `slicing = "planar"`). No loop is split off and no face healed.

use crate::assembly::{assemble, Assembly};
use crate::extract::{ExtractError, Feature, FeatureKind, FeatureTree, Reference};
use brep::mesh::mesh_faces;
use brep::solid::analysis_options;
use brep::topology::{Brep, FaceId, SolidId};
use std::collections::HashMap;

/// The `subtype` of a solid planned whole.
pub const WHOLE_PART: &str = "whole_part";

/// The build direction of a solid planned whole: +Z.
pub const PLUS_Z: [f64; 3] = [0.0, 0.0, 1.0];

/// Every solid of `brep` as one feature ([`whole_part_tree`]), ordered and checked together
/// like [`crate::extract_all`]'s trees (lowest first, overlaps and floating solids reported).
pub fn whole_part_features(brep: &Brep) -> Result<Assembly, ExtractError> {
    assemble(brep, whole_part_tree)
}

/// Whether every tree of `assembly` is a solid planned whole ([`whole_part_features`]).
pub fn is_whole_part(assembly: &Assembly) -> bool {
    assembly
        .trees
        .iter()
        .all(|t| t.features.len() == 1 && t.features[0].subtype == WHOLE_PART)
}

/// Solid `solid` of `part` as a tree of one two5d feature: its outer shell's faces with its
/// void shells, reference the build plate along +Z with no face (the plane through its lowest
/// point), volume the solid's enclosed volume (voids subtracted), `closed` when it is a valid
/// solid.
pub fn whole_part_tree(part: &Brep, solid: SolidId) -> Result<FeatureTree, ExtractError> {
    let b = part.solid_alone(solid);
    let solid = SolidId(0);
    let mut warnings = vec![];
    let shells = b.solids[solid.idx()].shells.clone();
    let Some(&outer_shell) = shells.first() else {
        return Err(ExtractError::Empty(format!(
            "solid #{} has no shell",
            b.solids[solid.idx()].step_id
        )));
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
    let rough = brep::solid::rough_bbox(&b, solid);
    let diag = rough.diagonal().max(1e-3);
    let mesh = mesh_faces(&b, &all_faces, &analysis_options(diag))?;
    let origin = if rough.is_empty() {
        brep::math::P3::origin()
    } else {
        nalgebra::center(&rough.min, &rough.max)
    };
    let shares: HashMap<FaceId, (f64, f64)> = brep::mass::face_shares(&b, &mesh, &origin)
        .into_iter()
        .map(|(f, v, a)| (f, (v, a)))
        .collect();
    let vol_of = |fs: &[FaceId]| {
        fs.iter()
            .map(|f| shares.get(f).map_or(0.0, |s| s.0))
            .sum::<f64>()
            .abs()
    };
    let part_volume = vol_of(&outer) - voids.iter().map(|v| vol_of(v)).sum::<f64>();
    let part_area: f64 = all_faces
        .iter()
        .map(|f| shares.get(f).map_or(0.0, |s| s.1))
        .sum();
    let genus = brep::validate::check_shell(&b, outer_shell).genus;
    // The same check the recognised features get, at the same (coarser) mesh.
    let problems =
        crate::check::check_solid(&b, &outer, &voids, &analysis_options(diag * 4.0)).problems;
    let closed = problems.is_empty();
    if !closed {
        let list: Vec<String> = problems.iter().take(4).map(|p| p.to_string()).collect();
        warnings.push(format!(
            "the solid is not a valid solid: {}{}",
            list.join("; "),
            if problems.len() > 4 { "; ..." } else { "" }
        ));
    }
    if !voids.is_empty() {
        warnings.push(format!(
            "{} void shell(s) kept with the part, sliced with it",
            voids.len()
        ));
    }
    let feature = Feature {
        id: 0,
        kind: FeatureKind::Two5d,
        subtype: WHOLE_PART.to_string(),
        reference: Reference {
            surface: "build_plate".into(),
            face: None,
            step_face: None,
            normal: Some(PLUS_Z),
        },
        parents: vec![],
        faces: outer,
        voids,
        heal_faces: vec![],
        shell: outer_shell,
        volume: part_volume,
        root_loops: 0,
        depth: 0,
        closed,
        problems,
    };
    Ok(FeatureTree {
        brep: b,
        solid,
        features: vec![feature],
        build_order: vec![0],
        depth: 0,
        part_volume,
        part_area,
        part_faces: all_faces.len(),
        genus,
        mesh,
        roots: vec![],
        warnings,
    })
}
