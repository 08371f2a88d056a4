//! The extract stage: the placed part's features recognised (one tree per solid), put in build
//! order with their file-wide ids, and checked against the process (feature ids that exist) and
//! against what one plan can hold, before any layer is made.

use crate::{PlanError, Process, MAX_BEAD_KM};
use brep::section::Plane;
use features::{extract_all, Assembly, ExtractOptions, Feature};
use robot_post::machine::MachineProfile;

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
    arrange(
        extract_all(&part.brep, &ExtractOptions::default())?,
        process,
        machine,
    )
}

/// The features of `assembly` (extracted by [`extract`] or by the place stage) in build order,
/// checked against the process and the size one plan holds.
pub fn arrange(
    assembly: Assembly,
    process: &Process,
    machine: &MachineProfile,
) -> Result<Extracted, PlanError> {
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
    };
    check_size(&extracted, process, machine)?;
    Ok(extracted)
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
