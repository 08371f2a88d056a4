//! The smooth stage: tool axes smoothed inside their tolerance cone (Chalvin et al. 2022,
//! [`slicer::orient::smooth`]), and on a B/C bed tipped back within its B limit; the planned
//! axes kept for the head check's tilts.

use crate::warning::{Warning, WarningKind};
use crate::Process;
use collide::TiltLimits;
use robot_post::machine::MachineProfile;
use slicer::orient::{limit_tilt, smooth as smooth_axes, OrientationFigures};
use slicer::toolpath::ToolPath;
use slicer::vec3::V3;
use std::collections::BTreeMap;

/// What the smooth stage returns.
#[derive(Debug)]
pub struct Smoothed {
    /// The tool path with its axes smoothed.
    pub toolpath: ToolPath,
    /// The axes as planned, one per point, where the head may tilt (empty on a 3-axis
    /// printer): the axes of the cones a tilt stays in.
    pub planned_axes: Vec<V3>,
    /// How far the head may tilt to clear a collision; `None`: not at all.
    pub limits: Option<TiltLimits>,
    /// Per feature id, the axes' steps and rates before and after smoothing.
    pub orientation: BTreeMap<usize, OrientationFigures>,
    /// Features whose axes were tipped back within the B limit.
    pub warnings: Vec<Warning>,
}

/// Smooths `toolpath`'s tool axes by the process's orientation settings; on a B/C bed, axes
/// that curved layers tip past the B limit are tilted back to it, inside the orientation's
/// tolerance cone (half its opening); farther, the post refuses them.
pub fn smooth(mut toolpath: ToolPath, process: &Process, machine: &MachineProfile) -> Smoothed {
    let limits = crate::collisions::tilt_limits(machine, &process.orientation);
    // (Only where the head may tilt: a 3-axis printer's axes stay +Z.)
    let planned_axes: Vec<V3> = match limits {
        Some(_) => toolpath.points.iter().map(|q| q.axis).collect(),
        None => vec![],
    };
    let orientation = smooth_axes(&mut toolpath, &process.orientation);
    let mut warnings = vec![];
    if let Ok(g) = machine.delta5_table() {
        let limit = g.b_limits_deg[0].abs().max(g.b_limits_deg[1].abs());
        let slack = 0.5 * process.orientation.cone_angle_deg;
        for (id, (n, worst)) in limit_tilt(&mut toolpath, limit, slack) {
            warnings.push(Warning::feature(
                id,
                WarningKind::TiltLimited {
                    axes: n,
                    worst_deg: worst,
                    limit_deg: limit,
                },
            ));
        }
    }
    Smoothed {
        toolpath,
        planned_axes,
        limits,
        orientation,
        warnings,
    }
}
