//! The head-check stage (issue 18): the machine's print head swept along every move against
//! what was built before it and the table, colliding moves tilted and travels lifted
//! ([`crate::collisions::avoid`]), and what is left counted per feature.

use crate::collisions::{self, Avoided};
use crate::lay::LaidFeature;
use crate::report::CollisionEntry;
use crate::smooth::Smoothed;
use robot_post::machine::MachineProfile;
use slicer::orient::OrientationFigures;
use slicer::toolpath::ToolPath;
use std::collections::BTreeMap;

/// What the head-check stage returns.
#[derive(Debug)]
pub struct Checked {
    /// The tool path after avoidance (tilted axes, lifted travels, siblings interleaved).
    pub toolpath: ToolPath,
    /// The colliding moves left and the moves tilt cleared.
    pub avoided: Avoided,
    /// Per feature id, its colliding moves as reported.
    pub collisions: BTreeMap<usize, CollisionEntry>,
    /// Per feature id, its points in the tool path (lifted travels add some).
    pub points: BTreeMap<usize, usize>,
    /// Smoothing's figures, carried on.
    pub orientation: BTreeMap<usize, OrientationFigures>,
    /// Smoothing's warnings, carried on.
    pub warnings: Vec<crate::Warning>,
}

/// Checks the head along `smoothed`'s tool path on `machine`, avoiding what it can; sibling
/// features (the same parents, from `features`) may be interleaved layer by layer.
pub fn head_check(
    smoothed: Smoothed,
    machine: &MachineProfile,
    features: &[LaidFeature],
) -> Checked {
    let Smoothed {
        mut toolpath,
        planned_axes,
        limits,
        orientation,
        warnings,
    } = smoothed;
    let entries: Vec<_> = features.iter().map(|f| f.entry.clone()).collect();
    let avoided = collisions::avoid(&mut toolpath, &planned_axes, machine, &entries, limits);
    Checked {
        collisions: collisions::entries(&avoided),
        points: collisions::points(&toolpath),
        toolpath,
        avoided,
        orientation,
        warnings,
    }
}
