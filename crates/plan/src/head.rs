//! The head-check stage (issue 18): the machine's print head swept along every move against
//! what was built before it and the table, colliding moves tilted and travels lifted
//! ([`crate::collisions::avoid`]), on the printed pedestal that keeps it off the table where
//! one is needed ([`crate::pedestal::stand`], issue 31), and what is left counted per feature.

use crate::collisions::{self, Avoided};
use crate::extract::Extracted;
use crate::lay::LaidFeature;
use crate::pedestal::{self, Stood};
use crate::report::CollisionEntry;
use crate::smooth::Smoothed;
use crate::warning::{Warning, WarningKind};
use crate::{Options, PlanError, Process};
use robot_post::machine::MachineProfile;
use slicer::orient::OrientationFigures;
use slicer::toolpath::ToolPath;
use std::collections::BTreeMap;

/// What the head-check stage returns.
#[derive(Debug)]
pub struct Checked {
    /// The tool path after avoidance (tilted axes, lifted travels, siblings interleaved), the
    /// pedestal's points first when there is one.
    pub toolpath: ToolPath,
    /// The colliding moves left and the moves tilt cleared.
    pub avoided: Avoided,
    /// Per feature id, its colliding moves as reported.
    pub collisions: BTreeMap<usize, CollisionEntry>,
    /// Per feature id, its points in the tool path (lifted travels add some).
    pub points: BTreeMap<usize, usize>,
    /// The pedestal the part stands on, if any.
    pub pedestal: Option<Stood>,
    /// What the self-check asks of the pedestal (its prism's volume × the base feature's
    /// fill).
    pub pedestal_planned: Option<slicer::verify::PlannedFeature>,
    /// Smoothing's figures, carried on.
    pub orientation: BTreeMap<usize, OrientationFigures>,
    /// Smoothing's warnings, carried on.
    pub warnings: Vec<Warning>,
    /// The pedestal's warnings of the part (none where one was wanted).
    pub part_warnings: Vec<Warning>,
}

/// The smoothed tool path as it is, the head not checked: for a plan that the support gate
/// refuses already ([`unsupported`]), which no avoidance or pedestal could save. Its refusal
/// lists no collisions (the head check's cost, several times the layers' on a part whose
/// head meets the table, is spared each placement that fails for its overhangs).
pub fn unchecked(smoothed: Smoothed) -> Checked {
    let Smoothed {
        toolpath,
        orientation,
        warnings,
        ..
    } = smoothed;
    let avoided = Avoided::default();
    Checked {
        pedestal_planned: None,
        collisions: collisions::entries(&avoided),
        points: collisions::points(&toolpath),
        toolpath,
        avoided,
        pedestal: None,
        orientation,
        warnings,
        part_warnings: vec![],
    }
}

/// Whether the support gate refuses these features whatever the head check finds: some
/// layer is unsupported and `--keep-going` does not let that pass.
pub fn unsupported(features: &[LaidFeature], options: &Options) -> bool {
    !options.keep_going
        && features
            .iter()
            .any(|f| f.held.as_ref().is_some_and(|h| h.support.worst.is_some()))
}

/// Checks the head along `smoothed`'s tool path on `machine`, avoiding what it can; sibling
/// features (the same parents, from `features`) may be interleaved layer by layer; the part
/// stands on the pedestal the process asks for (`auto`: the least that keeps the head off the
/// table, printed first as the next free feature id).
pub fn head_check(
    smoothed: Smoothed,
    extracted: &Extracted,
    process: &Process,
    machine: &MachineProfile,
    features: &[LaidFeature],
    options: &Options,
) -> Result<Checked, PlanError> {
    let Smoothed {
        toolpath,
        planned_axes,
        limits,
        orientation,
        warnings,
    } = smoothed;
    let entries: Vec<_> = features.iter().map(|f| f.entry.clone()).collect();
    let base = process.base();
    let params = process.params_for(&base, 0)?;
    let trees = &extracted.assembly.trees;
    let ctx = pedestal::Context {
        trees,
        params: &params,
        // A 3-axis printer's head stays above what it lays: no pedestal unless asked for.
        setting: match (machine.kind, base.pedestal) {
            (robot_post::MachineKind::Marlin, slicer::params::Pedestal::Auto) => {
                slicer::params::Pedestal::Off
            }
            (_, p) => p,
        },
        bead: machine.bead(),
        machine,
        id: trees.iter().map(|t| t.features.len()).sum(),
        allow_collisions: options.allow_collisions,
        stop_at: options.stop_at,
    };
    let avoid = |p: &mut ToolPath, axes: &[slicer::vec3::V3], stop: collide::Stop| {
        collisions::avoid(p, axes, machine, &entries, limits, stop)
    };
    let stood = pedestal::stand(&ctx, toolpath, planned_axes, avoid).map_err(|e| match e {
        pedestal::PedestalError::TimeLimit => PlanError::TimeLimit,
        e => PlanError::Pedestal(e),
    })?;
    let pedestal_planned = stood.pedestal.as_ref().map(|p| {
        let area = machine.bead().filament_area();
        p.planned(area)
    });
    Ok(Checked {
        pedestal_planned,
        collisions: collisions::entries(&stood.avoided),
        points: collisions::points(&stood.path),
        toolpath: stood.path,
        avoided: stood.avoided,
        pedestal: stood.pedestal,
        orientation,
        warnings,
        part_warnings: stood
            .warnings
            .into_iter()
            .map(|w| Warning::part(WarningKind::Planner(w)))
            .collect(),
    })
}
