//! Whether any placement can fit: the most a part may measure across and still fit the bed
//! (`marlin`) or the work envelope (`delta5`) in some placement, whatever its turn.
//!
//! A placement moves the part rigidly: on `marlin` the post only shifts it, so two points
//! farther apart than the bed's diagonal never both lie on the bed. On `delta5` each point is
//! printed with its own bed angles, but the bed turns about the crossing of its B and C axes,
//! so every point keeps its distance from that crossing: one of two points farther apart than
//! twice the largest distance from the crossing to the envelope is always outside it. `kuka`
//! has no such bound: the post warns of points off the table, and the part is moved into
//! the arm's reach ([`crate::fit::reach`]).

use crate::machine::{MachineKind, MachineProfile};
use crate::PostError;

/// The most (mm) two points of a part may lie apart and the part still fit `m` in some
/// placement (module docs); `None` when `m` sets no such bound (`kuka`).
///
/// Errors: `m` is not a valid `delta5` profile.
pub fn largest_across(m: &MachineProfile) -> Result<Option<f64>, PostError> {
    match m.kind {
        MachineKind::Marlin => {
            let [x, y, z] = m.bed_size;
            Ok(Some((x * x + y * y + z * z).sqrt()))
        }
        MachineKind::Delta5 => {
            let g = m.delta5_table()?;
            let (lo, hi) = crate::delta5::work_envelope(m, g);
            let q = g.pivot();
            let far = |k: usize| (lo[k] - q[k]).abs().max((hi[k] - q[k]).abs());
            Ok(Some(
                2.0 * (far(0).powi(2) + far(1).powi(2) + far(2).powi(2)).sqrt(),
            ))
        }
        MachineKind::Kuka => Ok(None),
    }
}

/// The directions [`across`] measures along (not normalised): the axes, the face diagonals
/// and the body diagonals.
const DIRECTIONS: [[f64; 3]; 13] = [
    [1.0, 0.0, 0.0],
    [0.0, 1.0, 0.0],
    [0.0, 0.0, 1.0],
    [1.0, 1.0, 0.0],
    [1.0, -1.0, 0.0],
    [1.0, 0.0, 1.0],
    [1.0, 0.0, -1.0],
    [0.0, 1.0, 1.0],
    [0.0, 1.0, -1.0],
    [1.0, 1.0, 1.0],
    [1.0, 1.0, -1.0],
    [1.0, -1.0, 1.0],
    [-1.0, 1.0, 1.0],
];

/// A lower bound (mm) of how far apart two of `points` lie: their largest extent along 13
/// directions, the axes, the face diagonals and the body diagonals (0 for no point). Any turn
/// of the points keeps it a lower bound.
pub fn across(points: impl Iterator<Item = [f64; 3]>) -> f64 {
    let mut lo = [f64::INFINITY; 13];
    let mut hi = [f64::NEG_INFINITY; 13];
    for p in points {
        for (k, d) in DIRECTIONS.iter().enumerate() {
            let s = p[0] * d[0] + p[1] * d[1] + p[2] * d[2];
            lo[k] = lo[k].min(s);
            hi[k] = hi[k].max(s);
        }
    }
    DIRECTIONS
        .iter()
        .enumerate()
        .map(|(k, d)| (hi[k] - lo[k]) / (d[0] * d[0] + d[1] * d[1] + d[2] * d[2]).sqrt())
        .filter(|w| w.is_finite())
        .fold(0.0, f64::max)
}
