//! The whole part as features: its solids one two5d feature of all their faces, built on the
//! plate from the lowest point along +Z, as a planar slicer slices it (issue 33, the process
//! key `slicing = "planar"`). No loop is split off and no face healed.
//!
//! The solids are sliced together, in the same layers, as ONE feature: a planar slicer lays
//! every body's section of a layer before the next layer, so no body waits for another to be
//! finished (the head would meet the finished one) and a body that starts in the air is held
//! up by support from the plate like any overhang. Solids that overlap (bodies pushed into
//! each other) are united layer by layer: their section loops cross, and the layer is where
//! they wind round (the slicer's `regions_by_winding`), so the material they share is laid
//! once; the feature's volume is the solids' sum less the overlaps measured
//! ([`crate::assembly`]), which the self-check holds the layers to.

use crate::assembly::{overlaps, relate, solid_name, solid_trees, Assembly};
use crate::extract::{ExtractError, Feature, FeatureKind, FeatureTree, Reference};
use crate::measure::{measure, Measured};
use brep::solid::analysis_options;
use brep::topology::{Brep, FaceId, Origin, ShellId, SolidId};

/// The `subtype` of a solid planned whole.
pub const WHOLE_PART: &str = "whole_part";

/// The `subtype` of a mesh's body planned whole (the seed paper's mesh two5D feature): a
/// solid whose B-rep is a triangle mesh's facets ([`brep::topology::Origin::Mesh`]).
pub const MESH_TWO5D: &str = "mesh_two5d";

/// The `subtype` of a solid of `brep` planned whole: [`MESH_TWO5D`] for a mesh's body,
/// [`WHOLE_PART`] otherwise.
fn whole_subtype(brep: &Brep) -> &'static str {
    match brep.origin {
        Origin::Mesh => MESH_TWO5D,
        Origin::Step => WHOLE_PART,
    }
}

/// The bodies of a mesh's B-rep (STL, 3MF, OBJ) as features: each body ONE `mesh_two5d`
/// feature ([`whole_part_tree`]), the bodies built lowest first like a STEP file's solids
/// ([`crate::extract_all`]); bodies that overlap are sliced together as ONE feature instead
/// ([`whole_part_features`]), so that the material they share is laid once.
pub fn mesh_features(brep: &Brep) -> Result<Assembly, ExtractError> {
    let assembly = crate::assembly::assemble(brep, whole_part_tree)?;
    if assembly.overlapping {
        return whole_part_features(brep);
    }
    Ok(assembly)
}

/// The build direction of a solid planned whole: +Z.
pub const PLUS_Z: [f64; 3] = [0.0, 0.0, 1.0];

/// The solids of `brep` as features: all of them one feature, sliced in the same layers, the
/// material two of them share counted once (overlaps reported); a single solid as one
/// feature ([`whole_part_tree`]) checked like [`crate::extract_all`]'s trees. Solids that
/// enclose no volume are skipped with a warning.
pub fn whole_part_features(brep: &Brep) -> Result<Assembly, ExtractError> {
    let (solids, mut warnings) = solid_trees(brep, whole_part_tree)?;
    let (ids, trees): (Vec<SolidId>, Vec<FeatureTree>) = solids.into_iter().unzip();
    if trees.len() > 1 {
        let shared = overlaps(&trees);
        let common: f64 = shared.iter().map(|o| o.volume).sum();
        if let Some(tree) = solids_together(brep, &ids, &trees, common)? {
            warnings.extend(shared.iter().map(|o| {
                format!(
                    "{} and {} overlap by about {:.3} mm^3: sliced together, each layer the \
                     union of their sections, so that material is laid once",
                    solid_name(&trees[o.first]),
                    solid_name(&trees[o.second]),
                    o.volume
                )
            }));
            return Ok(Assembly {
                trees: vec![tree],
                warnings,
                overlapping: false,
            });
        }
    }
    Ok(relate(trees, warnings))
}

/// Solids `ids` of `brep` (`trees` made of each by [`whole_part_tree`]) as a tree of ONE
/// two5d feature: every outer shell's faces with every void shell, on the build plate along
/// +Z, its volume and area the solids' sums, `closed` when each is a valid solid. `None` when
/// there is no solid.
fn solids_together(
    brep: &Brep,
    ids: &[SolidId],
    trees: &[FeatureTree],
    common: f64,
) -> Result<Option<FeatureTree>, ExtractError> {
    let (mut faces, mut voids) = (vec![], vec![]);
    for &s in ids {
        let shells = &brep.solids[s.idx()].shells;
        if let Some(outer) = shells.first() {
            faces.extend(brep.shells[outer.idx()].faces.iter().copied());
        }
        voids.extend(
            shells
                .iter()
                .skip(1)
                .map(|v| brep.shells[v.idx()].faces.clone()),
        );
    }
    let Some((&solid, first)) = ids.first().zip(trees.first()) else {
        return Ok(None);
    };
    let shell = brep.solids[solid.idx()].shells[0];
    let mut all_faces = faces.clone();
    all_faces.extend(voids.iter().flatten().copied());
    let mut bbox = first.mesh.bbox();
    for t in &trees[1..] {
        let b = t.mesh.bbox();
        bbox.min = bbox.min.inf(&b.min);
        bbox.max = bbox.max.sup(&b.max);
    }
    let mesh = brep::mesh::mesh_faces(
        brep,
        &all_faces,
        &analysis_options(bbox.diagonal().max(MIN_DIAG)),
    )
    .map_err(crate::measure::MeasureError::from)?;
    // The material two solids share is laid once (the layers' sections are their union).
    let part_volume: f64 = trees.iter().map(|t| t.part_volume).sum::<f64>() - common;
    let problems: Vec<_> = trees
        .iter()
        .flat_map(|t| t.features[0].problems.iter().cloned())
        .collect();
    let warnings = trees
        .iter()
        .flat_map(|t| {
            let name = solid_name(t);
            t.warnings.iter().map(move |w| format!("{name}: {w}"))
        })
        .collect();
    let feature = whole_feature(
        brep,
        whole_subtype(brep),
        faces,
        voids,
        shell,
        part_volume,
        trees.iter().all(|t| t.features[0].closed),
        problems,
    );
    Ok(Some(FeatureTree {
        brep: brep.clone(),
        solid,
        features: vec![feature],
        build_order: vec![0],
        depth: 0,
        part_volume,
        part_area: trees.iter().map(|t| t.part_area).sum(),
        part_faces: trees.iter().map(|t| t.part_faces).sum(),
        genus: None,
        mesh,
        roots: vec![],
        warnings,
    }))
}

/// The smallest box diagonal (mm) an analysis mesh is sized for.
const MIN_DIAG: f64 = 1e-3;

/// A whole-part feature (id 0, two5d, on the build plate) of shell faces `faces` with
/// `voids`, of `subtype` ([`WHOLE_PART`] or [`MESH_TWO5D`]).
#[allow(clippy::too_many_arguments)]
fn whole_feature(
    b: &Brep,
    subtype: &str,
    faces: Vec<FaceId>,
    voids: Vec<Vec<FaceId>>,
    shell: ShellId,
    volume: f64,
    closed: bool,
    problems: Vec<crate::check::SolidProblem>,
) -> Feature {
    Feature {
        id: 0,
        kind: FeatureKind::Two5d,
        subtype: subtype.to_string(),
        reference: plate_reference(b, &faces),
        parents: vec![],
        faces,
        voids,
        heal_faces: vec![],
        shell,
        volume,
        root_loops: 0,
        depth: 0,
        closed,
        problems,
    }
}

/// What a whole-part feature of `faces` is built on: the build plate, along +Z, with no face,
/// at the part's lowest point.
fn plate_reference(b: &Brep, faces: &[FaceId]) -> Reference {
    Reference {
        surface: "build_plate".into(),
        face: None,
        step_face: None,
        normal: Some(PLUS_Z),
        origin: crate::extract::lowest_point(b, faces, PLUS_Z),
    }
}

/// Whether every tree of `assembly` is a solid planned whole ([`whole_part_features`]).
pub fn is_whole_part(assembly: &Assembly) -> bool {
    assembly.trees.iter().all(|t| {
        t.features.len() == 1 && [WHOLE_PART, MESH_TWO5D].contains(&t.features[0].subtype.as_str())
    })
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
    let feature = whole_feature(
        &b,
        whole_subtype(&b),
        outer,
        voids,
        outer_shell,
        part_volume,
        closed,
        problems,
    );
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
