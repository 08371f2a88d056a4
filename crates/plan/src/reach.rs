//! Before the post of a KUKA cell: a part with points out of the arm's reach is moved on the
//! table, the least move that brings every point into reach and joint limits
//! ([`robot_post::fit::reach_shift`]), instead of refused (issue 31: placement found, not
//! assumed). The move is the cell's `part_position`, which the post honours.

use crate::Options;
use robot_post::fit::reach_shift;
use robot_post::machine::MachineProfile;
use robot_post::MachineKind;
use slicer::toolpath::ToolPath;

/// Where the part was moved on the table, and why.
#[derive(Debug, Clone)]
pub struct Moved {
    /// The machine profile with the cell's new `part_position`.
    pub machine: MachineProfile,
    /// That `part_position` (`$BASE` X, Y, mm).
    pub part_position: [f64; 2],
    /// How far the part moved, mm.
    pub distance_mm: f64,
    /// The points out of reach where the profile placed it.
    pub unreachable_before: usize,
}

/// The part moved into reach when some of `path`'s points are out of it on a KUKA cell (and
/// [`Options::allow_unreachable`] is off); `None` when every point is in reach, on other
/// machines, or when no place on the table reaches them all (the reach gate then refuses).
pub fn into_reach(path: &ToolPath, machine: &MachineProfile, options: &Options) -> Option<Moved> {
    if machine.kind != MachineKind::Kuka || options.allow_unreachable {
        return None;
    }
    // The search counts the points out of reach where the profile places the part first
    // (one run of the post's reach check), and moves nothing when there are none.
    let s = reach_shift(path, machine).ok()?;
    (s.unreachable_before > 0).then(|| Moved {
        machine: s.apply(machine),
        part_position: s.part_position,
        distance_mm: s.shift[0].hypot(s.shift[1]),
        unreachable_before: s.unreachable_before,
    })
}
