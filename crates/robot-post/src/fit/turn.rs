//! The least turn of the part about the build direction (+Z) that fits the machine's bed or
//! work envelope, as the post places the part.
//!
//! Each post places the part by the XY bounding-box centre of its print points (on the bed
//! centre, or the `delta5` C axis) and its lowest bead bottom (on the plate or table), so a
//! turn about +Z changes the bounding box and with it what fits: a bar lying diagonally fits
//! a bed its length does not. On `delta5` the nozzle positions also depend on the bed angles,
//! which turn with the part.

use super::{Discard, FitError};
use crate::machine::{MachineKind, MachineProfile};
use crate::placement::{bed_offset, bed_overhang_xy};
use crate::PostError;
use toolpath::{MoveKind, PathPoint, Role, ToolPath};

/// Step (degrees) of the coarse search over turns.
pub const COARSE_STEP_DEG: f64 = 1.0;

/// Step (degrees) of the fine search between the last coarse turn that misses and the first
/// that fits.
pub const FINE_STEP_DEG: f64 = 0.1;

/// Slack (mm) of the cheap fit test, the posts' own tolerance.
const FIT_SLACK: f64 = 1e-6;

/// Most turns confirmed with the post before the search gives up on the cheap test's
/// choices.
const MAX_CONFIRMED: usize = 8;

/// A turn about +Z that fits.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TurnFit {
    /// The turn (degrees, counter-clockwise seen from above, within (−180, 180]): the part's
    /// points and tool axes turned by it about the Z axis ([`turned`]); the post places the
    /// turned part by its own rule. 0 when the part fits as modelled.
    pub angle_deg: f64,
    /// By how much (mm) the part as modelled (turned by 0) leaves the bed or envelope, by
    /// the cheap test of [`envelope_excess`]; 0 when it fits.
    pub excess_at_zero_mm: f64,
}

/// A travel-only path through `points` (part coordinates, Z up from the plate), tool axis +Z:
/// the part's bounding points (its hull or box corners) given to [`turn_to_fit`] before any
/// tool path is planned. The posts place a travel-only path by all its points, so the turn
/// found fits the points themselves (no bead width); on `delta5` it is the turn for a part
/// printed with the bed level throughout.
pub fn bounding_path(points: &[[f64; 3]]) -> ToolPath {
    let points = points
        .iter()
        .map(|&p| PathPoint {
            feature: 0,
            layer: 0,
            kind: MoveKind::Travel,
            p,
            axis: [0.0, 0.0, 1.0],
            e: 0.0,
            thickness: 0.0,
            width: 0.0,
            role: Role::Perimeter,
        })
        .collect();
    ToolPath { points }
}

/// `path` with every point and tool axis turned by `angle_deg` (counter-clockwise seen from
/// above) about the Z axis of the part's coordinates.
pub fn turned(path: &ToolPath, angle_deg: f64) -> ToolPath {
    let mut out = path.clone();
    turn_into(path, angle_deg, &mut out);
    out
}

/// Writes `path` turned by `angle_deg` into `out`, a clone of `path`.
fn turn_into(path: &ToolPath, angle_deg: f64, out: &mut ToolPath) {
    let (s, c) = angle_deg.to_radians().sin_cos();
    let turn = |v: [f64; 3]| [c * v[0] - s * v[1], s * v[0] + c * v[1], v[2]];
    for (q, o) in path.points.iter().zip(out.points.iter_mut()) {
        o.p = turn(q.p);
        o.axis = turn(q.axis);
    }
}

/// How far (mm) the path leaves the machine as its post places it: on `marlin` and `kuka`
/// the bed (`bed_size`; on `kuka` the work table, which the post warns of), the largest
/// overhang in X, Y or Z ([`bed_offset`]'s placement); on `delta5` the work envelope of the
/// nozzle positions at the points ([`crate::delta5::envelope_excess`]). 0 when it fits.
///
/// The cheap test of [`turn_to_fit`]: the post checks the moves between points too.
pub fn envelope_excess(path: &ToolPath, m: &MachineProfile) -> Result<f64, PostError> {
    match m.kind {
        MachineKind::Delta5 => crate::delta5::envelope_excess(path, m),
        MachineKind::Marlin | MachineKind::Kuka => {
            path.check_finite()?;
            let mut bottom = f64::INFINITY;
            let mut top = f64::NEG_INFINITY;
            let any_print = path.points.iter().any(|q| q.kind == MoveKind::Print);
            for q in &path.points {
                top = top.max(q.p[2]);
                if q.kind == MoveKind::Print {
                    bottom = bottom.min(q.p[2] - f64::from(q.thickness.max(0.0)));
                } else if !any_print {
                    bottom = bottom.min(q.p[2]);
                }
            }
            let z = if bottom.is_finite() {
                (top - bottom - m.bed_size[2]).max(0.0)
            } else {
                0.0
            };
            Ok(bed_overhang_xy(path, m, [0.0, 0.0]).max(z))
        }
    }
}

/// The points of `path` that decide [`envelope_excess`] on `m` at every turn, where that is
/// fewer than all: on `delta5` with every tool axis +Z (a planar plan: the bed level
/// throughout, every pose B = 0 and C = 0, so each nozzle position is its point moved by the
/// placement's offset), the vertices of the XY convex hulls of all points and of the print
/// points (which place the part), the lowest and the highest point, and the print point with
/// the lowest bead bottom, in path order: at any turn the extremes of X and Y lie on those
/// hulls, and the offset and Z are those of the whole path. `None` elsewhere (tilted axes
/// turn the bed point by point; on a bed the beads' widths count). NIST CTC-05's 3.1 million
/// points on `delta5`: a few hundred, where each turn tried took its bed angles afresh.
pub fn deciding_points(path: &ToolPath, m: &MachineProfile) -> Option<ToolPath> {
    const UP: [f64; 3] = [0.0, 0.0, 1.0];
    if m.kind != MachineKind::Delta5
        || path.points.is_empty()
        || path.points.iter().any(|q| q.axis != UP)
    {
        return None;
    }
    let all: Vec<usize> = (0..path.points.len()).collect();
    let prints: Vec<usize> = all
        .iter()
        .copied()
        .filter(|&i| path.points[i].kind == MoveKind::Print)
        .collect();
    let by = |key: &dyn Fn(&PathPoint) -> f64, set: &[usize], low: bool| -> Option<usize> {
        let cmp =
            |a: &&usize, b: &&usize| key(&path.points[**a]).total_cmp(&key(&path.points[**b]));
        if low {
            set.iter().min_by(cmp).copied()
        } else {
            set.iter().max_by(cmp).copied()
        }
    };
    let mut keep = hull_xy(path, &all);
    keep.extend(hull_xy(path, &prints));
    keep.extend(by(&|q| q.p[2], &all, true));
    keep.extend(by(&|q| q.p[2], &all, false));
    keep.extend(by(
        &|q| q.p[2] - f64::from(q.thickness.max(0.0)),
        &prints,
        true,
    ));
    keep.sort_unstable();
    keep.dedup();
    (keep.len() < path.points.len()).then(|| ToolPath {
        points: keep.iter().map(|&i| path.points[i]).collect(),
    })
}

/// The indices (of `path`'s points, among `set`) of the vertices of the XY convex hull of
/// those points (Andrew's monotone chain; points on an edge left out).
fn hull_xy(path: &ToolPath, set: &[usize]) -> Vec<usize> {
    let xy = |i: usize| [path.points[i].p[0], path.points[i].p[1]];
    let mut order = set.to_vec();
    order.sort_unstable_by(|&a, &b| {
        let (p, q) = (xy(a), xy(b));
        p[0].total_cmp(&q[0]).then(p[1].total_cmp(&q[1]))
    });
    if order.len() < 3 {
        return order;
    }
    // Whether o → a → b turns counter-clockwise.
    let left = |o: usize, a: usize, b: usize| {
        let (o, a, b) = (xy(o), xy(a), xy(b));
        (a[0] - o[0]) * (b[1] - o[1]) - (a[1] - o[1]) * (b[0] - o[0]) > 0.0
    };
    let mut hull: Vec<usize> = Vec::with_capacity(2 * order.len().min(1024));
    for pass in [order.clone(), order.into_iter().rev().collect()] {
        let start = hull.len();
        for i in pass {
            while hull.len() >= start + 2 && !left(hull[hull.len() - 2], hull[hull.len() - 1], i) {
                hull.pop();
            }
            hull.push(i);
        }
        // The chain's last point is the next chain's first.
        hull.pop();
    }
    hull
}

/// Whether the post accepts the placement of `path`: `Ok(false)` when it refuses it for
/// leaving the bed or envelope, the post's error for any other refusal.
fn post_accepts(path: &ToolPath, m: &MachineProfile) -> Result<bool, PostError> {
    let verdict = match m.kind {
        MachineKind::Delta5 => crate::delta5::delta5_to(path, m, "", &[], &mut Discard).map(|_| ()),
        MachineKind::Marlin | MachineKind::Kuka => bed_offset(path, m).map(|_| ()),
    };
    match verdict {
        Ok(()) => Ok(true),
        Err(PostError::DoesNotFit { .. } | PostError::Delta5Envelope { .. }) => Ok(false),
        Err(e) => Err(e),
    }
}

/// The turns tried, in the order tried: 0, then ±1°, ±2° ... (counter-clockwise first) up
/// to 180°.
fn coarse_turns() -> impl Iterator<Item = f64> {
    let steps = (180.0 / COARSE_STEP_DEG).round() as i32;
    std::iter::once(0.0).chain((1..=steps).flat_map(move |k| {
        let a = f64::from(k) * COARSE_STEP_DEG;
        // 180° and −180° are one turn.
        let both = if k < steps { vec![a, -a] } else { vec![a] };
        both.into_iter()
    }))
}

/// The least turn of the part about +Z (by its absolute angle, to [`FINE_STEP_DEG`]) that
/// makes the post place every point of `path` on the bed (`marlin`; on `kuka` the table) or
/// in the work envelope (`delta5`).
///
/// Turns are tried from 0 outwards in [`COARSE_STEP_DEG`] steps with [`envelope_excess`];
/// between the first that fits and the one before it, in [`FINE_STEP_DEG`] steps. The
/// choice is confirmed by the post itself (placement, and on `delta5` the whole program with
/// its sub-moves and travels), and the next candidate taken when it refuses.
///
/// Errors: [`FitError::NoTurn`] with the turn that missed least and by how much when none
/// fits; [`FitError::Post`] when the post refuses the path for another reason (a tool axis
/// beyond the B limits, a non-finite point, a profile of another kind).
pub fn turn_to_fit(path: &ToolPath, m: &MachineProfile) -> Result<TurnFit, FitError> {
    turn_to_fit_until(path, m, None)
}

/// [`turn_to_fit`], given up past `stop_at` ([`FitError::TimeLimit`], checked before each
/// turn; `None`: never): a long path on `delta5` takes its bed angles afresh at every turn.
pub fn turn_to_fit_until(
    path: &ToolPath,
    m: &MachineProfile,
    stop_at: Option<std::time::Instant>,
) -> Result<TurnFit, FitError> {
    let late = || stop_at.is_some_and(|t| std::time::Instant::now() >= t);
    // The cheap test on the points that decide it, where those are fewer.
    let deciding = deciding_points(path, m);
    let cheap = deciding.as_ref().unwrap_or(path);
    let mut work = cheap.clone();
    let mut excess_at = |a: f64| -> Result<f64, PostError> {
        turn_into(cheap, a, &mut work);
        envelope_excess(&work, m)
    };
    let excess_at_zero_mm = excess_at(0.0)?;
    let mut best = (0.0, excess_at_zero_mm);
    let mut confirmed = 0;
    for a in coarse_turns() {
        if late() {
            return Err(FitError::TimeLimit);
        }
        let e = if a == 0.0 {
            excess_at_zero_mm
        } else {
            excess_at(a)?
        };
        if e < best.1 {
            best = (a, e);
        }
        if e > FIT_SLACK {
            continue;
        }
        // The fine turns between the coarse turn before `a` on its side, which missed, and
        // `a`.
        let fine = if a == 0.0 {
            Vec::new()
        } else {
            fine_turns(a - a.signum() * COARSE_STEP_DEG, a)
        };
        for t in fine.into_iter().chain(std::iter::once(a)) {
            if t != a && excess_at(t)? > FIT_SLACK {
                continue;
            }
            if confirmed >= MAX_CONFIRMED {
                break;
            }
            confirmed += 1;
            if post_accepts(&turned(path, t), m)? {
                return Ok(TurnFit {
                    angle_deg: t,
                    excess_at_zero_mm,
                });
            }
        }
    }
    Err(FitError::NoTurn {
        name: m.name.clone(),
        angle_deg: best.0,
        excess_mm: best.1,
    })
}

/// The turns strictly between `from` and `to` (degrees, same side of 0) in
/// [`FINE_STEP_DEG`] steps, nearest `from` first.
fn fine_turns(from: f64, to: f64) -> Vec<f64> {
    let n = ((to - from).abs() / FINE_STEP_DEG).round() as i32;
    let dir = (to - from).signum();
    (1..n)
        .map(|k| from + dir * f64::from(k) * FINE_STEP_DEG)
        .collect()
}
