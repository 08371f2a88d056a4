//! The whole part as features: each solid one two5d feature of all its faces, built on the
//! plate from its lowest point along +Z, as a planar slicer slices it (issue 33, the process
//! key `slicing = "planar"`). No loop is split off and no face healed.

use crate::assembly::{assemble, Assembly};
use crate::extract::{ExtractError, Feature, FeatureKind, FeatureTree, Reference};
use crate::measure::{measure, Measured};
use brep::solid::analysis_options;
use brep::topology::{Brep, SolidId};

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
    let Measured {
        outer_shell,
        outer,
        voids,
        all_faces,
        diag,
        mesh,
        part_volume,
        part_area,
        genus,
        ..
    } = measure(&b, solid)?;
    // The same check the recognised features get, at the same (coarser) mesh.
    let problems =
        crate::check::check_solid(&b, &outer, &voids, &analysis_options(diag * 4.0)).problems;
    let closed = problems.is_empty();
    if !closed {
        warnings.push(format!(
            "the solid is not a valid solid: {}",
            crate::check::listed(&problems)
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
