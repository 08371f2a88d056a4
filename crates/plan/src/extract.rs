//! The extract stage: the placed part's features recognised (one tree per solid), put in build
//! order with their file-wide ids, and checked against the process (feature ids that exist) and
//! against what one plan can hold, before any layer is made.
//!
//! **Slicing** (the process key `slicing`, issue 33): `features` plans the recognised features;
//! `planar` plans each solid whole as one two5d feature along +Z from its lowest point
//! ([`planar_assembly`]); `auto` is `features` on a machine that can tilt, and on one that
//! prints only along +Z, `planar` when some feature grows along another direction
//! ([`tilted_features`]), with a warning for each such feature.

use crate::tolerance::{PLUS_Z_SLACK, SAME_POINT_MM};
use crate::warning::{Warning, WarningKind};
use crate::{PlanError, Process, MAX_BEAD_KM};
use brep::math::V3;
use brep::section::Plane;
use brep::topology::{Brep, FaceId};
use features::{extract_all, Assembly, ExtractOptions, Feature, FeatureKind, FeatureTree};
use robot_post::machine::{MachineKind, MachineProfile};
use slicer::params::Slicing;

/// A feature's place: its tree, its index there, and the offset of its tree's file-wide ids.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Slot {
    /// Its tree (solid) in the assembly.
    pub tree: usize,
    /// Its index in that tree's features.
    pub index: usize,
    /// The file-wide id of that tree's feature 0 (the features of earlier solids).
    pub offset: usize,
}

/// What the extract stage returns: the features in build order.
#[derive(Debug)]
pub struct Extracted {
    /// The features, one tree per solid.
    pub assembly: Assembly,
    /// Every feature in build order.
    pub order: Vec<Slot>,
    /// Each tree's build plate: its base feature's reference plane.
    pub plates: Vec<Option<Plane>>,
    /// How the part was sliced: [`Slicing::Features`] or [`Slicing::Planar`] (never `Auto`).
    pub slicing: Slicing,
    /// The features `auto` planned with the part in planar layers, one warning each.
    pub warnings: Vec<Warning>,
}

impl Extracted {
    /// The feature at `slot`.
    pub fn feature(&self, slot: Slot) -> &Feature {
        &self.assembly.trees[slot.tree].features[slot.index]
    }

    /// The file-wide id of the feature at `slot`.
    pub fn id(&self, slot: Slot) -> usize {
        slot.offset + self.feature(slot).id
    }
}

/// Recognises the features of `part` and orders them for building; refuses a part whose
/// features need more bead than one plan holds ([`PlanError::TooBig`]).
pub fn extract(
    part: &brep::StepPart,
    process: &Process,
    machine: &MachineProfile,
) -> Result<Extracted, PlanError> {
    process.validate_for_nozzle(machine.nozzle_diameter)?;
    let assembly = match process.base().slicing {
        Slicing::Planar => planar_assembly(&part.brep)?,
        Slicing::Auto | Slicing::Features => extract_all(&part.brep, &ExtractOptions::default())?,
    };
    arrange(assembly, &part.brep, process, machine)
}

/// Each solid of `brep` (the part as it stands on the plate) as ONE two5d feature: all its
/// faces with its voids, on the plane normal to +Z through its lowest point, its volume the
/// solid's ([`features::whole_part_features`]). What `slicing = "planar"` plans; another
/// stage may try it as one more candidate.
pub fn planar_assembly(brep: &Brep) -> Result<Assembly, PlanError> {
    Ok(features::whole_part_features(brep)?)
}

/// The features of `assembly` (extracted by [`extract`] or by the place stage from `brep`,
/// the part as it stands) sliced as the process's `slicing` says ([`choose_slicing`]), in
/// build order, checked against the process and the size one plan holds.
pub fn arrange(
    assembly: Assembly,
    brep: &Brep,
    process: &Process,
    machine: &MachineProfile,
) -> Result<Extracted, PlanError> {
    let (assembly, slicing, chosen) = choose_slicing(assembly, brep, process, machine.kind)?;
    // The reader's warnings first: what it skipped or mended in the file.
    let mut warnings: Vec<Warning> = brep
        .warnings
        .iter()
        .map(|w| Warning::part(WarningKind::Reader(w.clone())))
        .collect();
    warnings.extend(chosen);
    let trees = &assembly.trees;
    process.validate_feature_ids(trees.iter().map(|t| t.features.len()).sum())?;
    let plates = trees
        .iter()
        .map(|t| {
            t.features
                .first()
                .and_then(|b| slicer::planar::reference_plane(t, b))
        })
        .collect();
    let mut order = vec![];
    let mut offset = 0usize;
    for (tree, t) in trees.iter().enumerate() {
        for &index in &t.build_order {
            order.push(Slot {
                tree,
                index,
                offset,
            });
        }
        offset += t.features.len();
    }
    let extracted = Extracted {
        assembly,
        order,
        plates,
        slicing,
        warnings,
    };
    check_size(&extracted, process, machine)?;
    Ok(extracted)
}

/// The assembly to plan for the process's `slicing` on a machine of `kind`, how it is sliced,
/// and a warning for each feature `auto` put into planar layers. `features` keeps `assembly`;
/// `planar` makes [`planar_assembly`] of `brep` (unless `assembly` already is one); `auto`
/// does so when the part's solids overlap (feature by feature their shared material would be
/// laid twice), and on a machine that prints only along +Z when [`tilted_features`] finds
/// any.
pub fn choose_slicing(
    assembly: Assembly,
    brep: &Brep,
    process: &Process,
    kind: MachineKind,
) -> Result<(Assembly, Slicing, Vec<Warning>), PlanError> {
    let whole = features::is_whole_part(&assembly);
    match process.base().slicing {
        Slicing::Planar if !whole => Ok((planar_assembly(brep)?, Slicing::Planar, vec![])),
        Slicing::Auto if !whole && assembly.overlapping => Ok((
            planar_assembly(brep)?,
            Slicing::Planar,
            vec![Warning::part(WarningKind::OverlappingSolids)],
        )),
        Slicing::Auto if !whole && kind.plus_z_only() => {
            let tilted = tilted_features(&assembly, process);
            if tilted.is_empty() {
                return Ok((assembly, Slicing::Features, vec![]));
            }
            let warnings = tilted
                .into_iter()
                .map(|(feature, kind, along)| {
                    Warning::part(WarningKind::PlanarInstead {
                        feature,
                        kind,
                        along,
                    })
                })
                .collect();
            Ok((planar_assembly(brep)?, Slicing::Planar, warnings))
        }
        _ if whole => Ok((assembly, Slicing::Planar, vec![])),
        _ => Ok((assembly, Slicing::Features, vec![])),
    }
}

/// The features of `assembly` whose build direction is not +Z: every freeform feature, and
/// every two5d feature whose reference normal's z falls short of 1 by more than 0.001 (about
/// 2.6° off +Z, the crate's `PLUS_Z_SLACK`). A freeform feature whose process fixes its tool
/// axis to +Z (`fixed_tool_axis`) is not one: its curved layers are laid along +Z. Each with
/// its file-wide id, its kind's name and the direction it grows along (where one is known).
pub fn tilted_features(
    assembly: &Assembly,
    process: &Process,
) -> Vec<(usize, &'static str, Option<[f64; 3]>)> {
    let base = process.base();
    let plus_z = |a: V3| 1.0 - a.z <= PLUS_Z_SLACK;
    let fixed_plus_z = |id: usize| {
        let fixed = process
            .params_for(&base, id)
            .ok()
            .and_then(|p| p.fixed_tool_axis);
        fixed
            .and_then(|a| V3::new(a[0], a[1], a[2]).try_normalize(SAME_POINT_MM))
            .is_some_and(plus_z)
    };
    let mut out = vec![];
    let mut offset = 0usize;
    for t in &assembly.trees {
        for f in &t.features {
            let tilted = match f.kind {
                FeatureKind::Freeform => !fixed_plus_z(offset + f.id),
                FeatureKind::Two5d => !f
                    .reference
                    .normal
                    .is_some_and(|n| plus_z(V3::new(n[0], n[1], n[2]))),
            };
            if tilted {
                let along = growth(t, f).map(|d| [d.x, d.y, d.z]);
                out.push((offset + f.id, f.kind.as_str(), along));
            }
        }
        offset += t.features.len();
    }
    out
}

/// The direction feature `f` grows along: its reference normal; for a feature on a curved
/// surface, from the middle of its healing faces' vertices to the middle of its own.
fn growth(tree: &FeatureTree, f: &Feature) -> Option<V3> {
    if let Some(n) = f.reference.normal {
        return Some(V3::new(n[0], n[1], n[2]));
    }
    let b = &tree.brep;
    let middle = |faces: &[FaceId]| {
        let vs = b.vertices_of(faces);
        (!vs.is_empty()).then(|| {
            vs.iter()
                .map(|v| b.vertices[v.idx()].point.coords)
                .sum::<V3>()
                / vs.len() as f64
        })
    };
    let d = middle(&f.faces)? - middle(&f.heal_faces)?;
    d.try_normalize(SAME_POINT_MM)
}

/// The bead the features need at the least (volume over the thickest layer and the widest
/// spacing their parameters allow), before any of it is made: past [`MAX_BEAD_KM`] the part
/// is refused.
fn check_size(
    extracted: &Extracted,
    process: &Process,
    machine: &MachineProfile,
) -> Result<(), PlanError> {
    let base = process.base();
    let bead = machine.bead();
    let (mut volume, mut bead_mm) = (0.0, 0.0);
    for &slot in &extracted.order {
        let f = extracted.feature(slot);
        let params = process.params_for(&base, slot.offset + f.id)?;
        let thickest = params
            .adaptive_layer_height
            .iter()
            .copied()
            .chain([params.uniform_layer_height, params.max_layer_height])
            .filter(|h| h.is_finite() && *h > 0.0)
            .fold(0.0f64, f64::max);
        let widest = params
            .adaptive_offset
            .iter()
            .copied()
            .chain([params.spacing(bead.width)])
            .filter(|s| s.is_finite() && *s > 0.0)
            .fold(0.0f64, f64::max);
        if f.volume.is_finite() && thickest > 0.0 && widest > 0.0 {
            volume += f.volume;
            bead_mm += f.volume / (thickest * widest);
        }
    }
    if bead_mm > MAX_BEAD_KM * 1e6 {
        return Err(PlanError::TooBig {
            volume_m3: volume / MM3_PER_M3,
            bead_km: bead_mm / MM_PER_KM,
        });
    }
    Ok(())
}

/// mm³ in a m³.
const MM3_PER_M3: f64 = 1e9;
/// mm in a km.
const MM_PER_KM: f64 = 1e6;
