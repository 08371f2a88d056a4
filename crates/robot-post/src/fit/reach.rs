//! On `kuka`: the least move of the part on the work table (the cell's `part_position`) that
//! brings every point into the arm's reach and joint limits.
//!
//! The arm reaches a point with a tool axis when its flange pose (`$BASE · target ·
//! $TOOL⁻¹`) has an inverse-kinematics solution within the joint limits (the post's check,
//! `kuka::checks`). The search tests the path's points with the orientation the post starts
//! a path with (tool X towards the A1 axis) and the approach and retreat points
//! `travel_clearance` out along the axis at each path's ends, on a subsample first, then on
//! every point for a candidate that passes, and confirms its choice with the post.
//!
//! The part moves in the table plane only: the table top is fixed, so lifting the part would
//! need something under it (a pedestal).

use super::{Discard, FitError};
use crate::kuka::{part_offset, start_frame, KukaCell, Pose};
use crate::machine::MachineProfile;
use crate::placement::bed_gaps_xy;
use crate::tolerance::MIN_AXIS;
use crate::PostError;
use toolpath::vec3::{add, dot, norm, scale};
use toolpath::{MoveKind, ToolPath};

/// Ring spacing (mm) of the coarse search: candidate moves lie on circles this far apart
/// about the profile's `part_position`, at most this far apart along each circle.
pub const COARSE_SHIFT_MM: f64 = 5.0;

/// Ring spacing (mm) of the fine search, inside the first coarse ring that holds a move that
/// reaches.
pub const FINE_SHIFT_MM: f64 = 1.0;

/// Points of the subsample a candidate is first tested on.
const SAMPLE_POINTS: usize = 2000;

/// Most of the poses missed where the profile places the part that are tested first at
/// every place ([`first_tested`]).
const FIRST_MISSES: usize = 64;

/// Most candidates confirmed with the post before the search gives up on the cheap test's
/// choices.
const MAX_CONFIRMED: usize = 2;

/// Slack (mm) of the table-edge test.
const EDGE_SLACK: f64 = 1e-6;

/// A place on the table where every point is in reach.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ReachShift {
    /// The cell's new `part_position` (`$BASE` X and Y, mm): `[kuka] part_position` of the
    /// profile to print with ([`ReachShift::apply`]).
    pub part_position: [f64; 2],
    /// The move (mm) from the profile's `part_position`; `[0, 0]` when every point is in
    /// reach already.
    pub shift: [f64; 2],
    /// Points the post found out of reach at the profile's `part_position`.
    pub unreachable_before: usize,
}

impl ReachShift {
    /// `m` with the cell's `part_position` set to this one.
    pub fn apply(&self, m: &MachineProfile) -> MachineProfile {
        let mut out = m.clone();
        if let Some(cell) = out.kuka.as_mut() {
            cell.part_position = self.part_position;
        }
        out
    }
}

/// Points (of the path's) the `kuka` post finds out of the arm's reach or joint limits, as it
/// places the part on the table: the sum of [`crate::KukaFigures::unreachable_points`].
///
/// Errors as [`crate::kuka()`]'s (not a valid `kuka` profile, a non-finite point, a tool axis
/// that is not a unit vector).
pub fn unreachable_points(path: &ToolPath, m: &MachineProfile) -> Result<usize, PostError> {
    let program = crate::kuka::kuka_to(
        path,
        m,
        "fit",
        "",
        &[],
        &mut Discard,
        crate::kuka::JointsCsv::Never,
    )?;
    Ok(program.figures.values().map(|f| f.unreachable_points).sum())
}

/// The tool poses the cheap reach test checks, part coordinates: each point the post visits
/// with its unit tool axis (print points, and travel points where a path starts: the post
/// passes over the others), and out along the axis by `travel_clearance` where a path starts
/// and ends (the approach and the retreat); and the safe point, `safe_height` over the top
/// of the print points over the first path's start, the tool upright.
fn test_poses(path: &ToolPath, clearance: f64, safe_height: f64) -> Vec<([f64; 3], [f64; 3])> {
    let n = path.points.len();
    let mut out = Vec::with_capacity(n + n / 8);
    let top = crate::placement::placed_points(path)
        .map(|q| q.p[2])
        .fold(f64::NEG_INFINITY, f64::max);
    if let Some(start) = path.points.first().filter(|_| top.is_finite()) {
        out.push(([start.p[0], start.p[1], top + safe_height], [0.0, 0.0, 1.0]));
    }
    for (i, q) in path.points.iter().enumerate() {
        let len = norm(q.axis);
        if len.is_nan() || len <= MIN_AXIS {
            continue;
        }
        let next_print = path
            .points
            .get(i + 1)
            .is_some_and(|n| n.kind == MoveKind::Print);
        let starts = q.kind == MoveKind::Travel || i == 0;
        if q.kind == MoveKind::Travel && !next_print {
            continue;
        }
        let a = scale(q.axis, 1.0 / len);
        out.push((q.p, a));
        if starts || !next_print {
            out.push((add(q.p, scale(a, clearance)), a));
        }
    }
    out
}

/// The cheap reach test of one placement (`offset`: `$BASE` = part + offset).
struct Tester<'a> {
    cell: &'a KukaCell,
    base: Pose,
    tool_inv: Pose,
    poses: Vec<([f64; 3], [f64; 3])>,
}

impl Tester<'_> {
    /// Whether the arm reaches pose `k` with the part placed at `offset`.
    fn reaches(&self, k: usize, offset: [f64; 3]) -> bool {
        let (p, a) = self.poses[k];
        let t = add(p, offset);
        let z = scale(a, -1.0);
        let pose = Pose {
            r: start_frame(z, t, &self.base),
            t,
        };
        let flange = self.base.compose(&pose).compose(&self.tool_inv);
        self.cell
            .arm
            .nearest(&flange, &self.cell.home, None)
            .is_some()
    }

    /// The first of `order` the arm does not reach at `offset`, as its place in `order`.
    fn first_miss(&self, order: &[usize], offset: [f64; 3]) -> Option<usize> {
        order.iter().position(|&k| !self.reaches(k, offset))
    }

    /// How many of the poses `of` the arm does not reach at `offset`.
    fn misses(&self, of: &[usize], offset: [f64; 3]) -> usize {
        of.iter().filter(|&&k| !self.reaches(k, offset)).count()
    }
}

/// Poses tested first at every place, the ones most likely to fail: those the arm misses
/// where the profile places the part (at most [`FIRST_MISSES`], spread over them) and those
/// farthest out in each direction along X, Y, Z and the table's diagonals. Without them, a
/// part with a few hundred points out of reach among half a million (the capsule on `kuka`)
/// passed the whole subsample at nearly every place tried and was found to miss only in the
/// full test.
fn first_tested(tester: &Tester, offset: [f64; 3]) -> Vec<usize> {
    let n = tester.poses.len();
    let missing: Vec<usize> = (0..n).filter(|&k| !tester.reaches(k, offset)).collect();
    let step = missing.len().div_ceil(FIRST_MISSES).max(1);
    let mut out: Vec<usize> = missing.iter().copied().step_by(step).collect();
    let dirs: [[f64; 3]; 10] = [
        [1.0, 0.0, 0.0],
        [-1.0, 0.0, 0.0],
        [0.0, 1.0, 0.0],
        [0.0, -1.0, 0.0],
        [0.0, 0.0, 1.0],
        [0.0, 0.0, -1.0],
        [1.0, 1.0, 0.0],
        [1.0, -1.0, 0.0],
        [-1.0, 1.0, 0.0],
        [-1.0, -1.0, 0.0],
    ];
    for d in dirs {
        let far = (0..n).max_by(|&a, &b| {
            let along = |k: usize| dot(tester.poses[k].0, d);
            along(a).total_cmp(&along(b))
        });
        out.extend(far.filter(|k| !out.contains(k)));
    }
    out
}

/// The moves tried on the ring of radius `r` (mm) about the origin, about `step` apart
/// along it (one, the origin, for `r` = 0).
fn ring(r: f64, step: f64) -> Vec<[f64; 2]> {
    if r <= 0.0 {
        return vec![[0.0, 0.0]];
    }
    let n = ((std::f64::consts::TAU * r / step).ceil() as usize).max(8);
    (0..n)
        .map(|k| {
            let t = std::f64::consts::TAU * k as f64 / n as f64;
            [r * t.cos(), r * t.sin()]
        })
        .collect()
}

/// The least move of the part on the table (in `$BASE` X and Y, from the profile's
/// `part_position`, to about [`FINE_SHIFT_MM`]) that brings every point of `path` into the
/// arm's reach and joint limits, keeping the part on the table (`bed_size`) when it was on
/// it.
///
/// Moves are tried on rings [`COARSE_SHIFT_MM`] apart, then on [`FINE_SHIFT_MM`] rings inside
/// the first coarse ring that holds one that reaches; each is tested on a subsample of the
/// path's points (and every point that failed a test before), then on every point, and the
/// choice is confirmed by the post ([`unreachable_points`] is 0).
///
/// Errors: [`FitError::NoShift`] with the best place tried and its unreachable points when
/// no place on the table reaches every point; [`FitError::Post`] when the profile is not a
/// valid `kuka` profile or the post refuses the path.
pub fn reach_shift(path: &ToolPath, m: &MachineProfile) -> Result<ReachShift, FitError> {
    let cell = m.kuka_table()?;
    let before = unreachable_points(path, m)?;
    let here = cell.part_position;
    if before == 0 {
        return Ok(ReachShift {
            part_position: here,
            shift: [0.0, 0.0],
            unreachable_before: 0,
        });
    }
    let offset = part_offset(path, m)?;
    let tester = Tester {
        cell,
        base: cell.base.pose(),
        tool_inv: cell.tool.pose().inverse(),
        poses: test_poses(path, cell.travel_clearance, cell.safe_height),
    };
    let n = tester.poses.len();
    let mut sample = first_tested(&tester, offset);
    let every = (n / SAMPLE_POINTS).max(1);
    sample.extend((0..n).step_by(every));
    let all: Vec<usize> = (0..n).collect();
    let gaps = bed_gaps_xy(path, m);
    let on_table = gaps.map_or(0.0, |g| g.overhang(here));
    let allowed = |s: [f64; 2]| {
        gaps.map_or(0.0, |g| g.overhang([here[0] + s[0], here[1] + s[1]])) <= on_table + EDGE_SLACK
    };
    let at = |s: [f64; 2]| [offset[0] + s[0], offset[1] + s[1], offset[2]];
    // No farther than the table's half size, nor than the arm's whole span: a move past
    // that cannot bring a point nearer to the arm than the part's own size.
    let arm = &cell.arm;
    let tool = cell.tool.to_array();
    let span = arm.a1.abs()
        + arm.b.abs()
        + arm.c2
        + arm.a2.hypot(arm.c3)
        + arm.c4.abs()
        + tool[0].hypot(tool[1]).hypot(tool[2]);
    let r_max = (m.bed_size[0].max(m.bed_size[1]) / 2.0).min(span);
    let passes = |s: [f64; 2], sample: &mut Vec<usize>| -> bool {
        if !allowed(s) {
            return false;
        }
        if let Some(i) = tester.first_miss(sample, at(s)) {
            // The point that failed is tested first from now on.
            sample[..=i].rotate_right(1);
            return false;
        }
        match tester.first_miss(&all, at(s)) {
            Some(i) => {
                sample.insert(0, i);
                false
            }
            None => true,
        }
    };
    let mut confirmed = 0;
    let mut coarse = 0.0;
    // Past MAX_CONFIRMED places the cheap test passed and the post did not, the search gives
    // up on the cheap test.
    while coarse <= r_max && confirmed < MAX_CONFIRMED {
        let hit = ring(coarse, COARSE_SHIFT_MM)
            .into_iter()
            .any(|s| passes(s, &mut sample));
        if hit {
            let mut r = (coarse - COARSE_SHIFT_MM + FINE_SHIFT_MM).max(FINE_SHIFT_MM);
            while r <= coarse + FINE_SHIFT_MM / 2.0 && confirmed < MAX_CONFIRMED {
                for s in ring(r, FINE_SHIFT_MM) {
                    if confirmed >= MAX_CONFIRMED || !passes(s, &mut sample) {
                        continue;
                    }
                    confirmed += 1;
                    let position = [here[0] + s[0], here[1] + s[1]];
                    let fit = ReachShift {
                        part_position: position,
                        shift: s,
                        unreachable_before: before,
                    };
                    if unreachable_points(path, &fit.apply(m))? == 0 {
                        return Ok(fit);
                    }
                }
                r += FINE_SHIFT_MM;
            }
        }
        coarse += COARSE_SHIFT_MM;
    }
    Err(best_miss(path, m, &tester, &sample, r_max, at, allowed))
}

/// The [`FitError::NoShift`] of a search that found no place: the place, on coarse rings
/// four times further apart, where the fewest poses of `sample` miss, with the post's count
/// there. Only the subsample is counted at each place: every pose at every place is what made
/// a refusal slow (the capsule as modelled on `kuka`, 464,211 points: 3 minutes).
fn best_miss(
    path: &ToolPath,
    m: &MachineProfile,
    tester: &Tester,
    sample: &[usize],
    r_max: f64,
    at: impl Fn([f64; 2]) -> [f64; 3],
    allowed: impl Fn([f64; 2]) -> bool,
) -> FitError {
    let here = tester.cell.part_position;
    let step = 4.0 * COARSE_SHIFT_MM;
    let mut best = ([0.0, 0.0], usize::MAX);
    let mut r = 0.0;
    while r <= r_max {
        for s in ring(r, step) {
            if !allowed(s) {
                continue;
            }
            let misses = tester.misses(sample, at(s));
            if misses < best.1 {
                best = (s, misses);
            }
        }
        r += step;
    }
    let position = [here[0] + best.0[0], here[1] + best.0[1]];
    let fit = ReachShift {
        part_position: position,
        shift: best.0,
        unreachable_before: 0,
    };
    let unreachable = unreachable_points(path, &fit.apply(m)).unwrap_or(best.1);
    FitError::NoShift {
        name: m.name.clone(),
        x: position[0],
        y: position[1],
        unreachable,
    }
}
