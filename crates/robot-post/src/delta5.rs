//! The 5-axis printer post: a delta (or Cartesian) printer whose nozzle stays pointing down
//! (−Z) while the bed tilts (B) and rotates (C) so that each point's tool axis becomes machine
//! +Z (Isa & Lazoglu 2019, §4, Eq. 9–12, the singularity cone with C-axis patching, and the
//! kinematic error of their Fig. 16).
//!
//! # Conventions
//!
//! - The B axis is parallel to machine Y, at height `b_axis_z`, and crosses the C axis, which
//!   stands vertical at `c_axis_xy` when B = 0. The table surface is `table_above_b_axis` above
//!   the B axis along the C axis. The part is placed in the table frame (origin where the C axis
//!   meets the table surface) with its XY bounding-box centre on the C axis and its lowest bead
//!   bottom on the table surface: table = part + offset, the offset written in the header.
//! - B and C are the paper's φ and θ: the tool axis in the part is
//!   `n_b = R_z(C)·R_y(B)·(0,0,1) = (cos C sin B, sin C sin B, cos B)`. As ISO 841 has it for axes
//!   that move the workpiece, positive B and C turn the tool relative to the part, so the bed
//!   itself turns by −C about its axis and tilts by −B: a table-frame point `t` is at machine
//!   `Q + R_y(−B)·R_z(−C)·(t + h·ẑ)` with `Q` the crossing of the axes and `h` =
//!   `table_above_b_axis` ([`forward`] is the inverse of that).
//! - The paper prints Eq. 9 with minus signs on the first two components; its Eqs. 10–11 and
//!   its text (θ₁ = atan2(n_y, n_x) is the solution with φ > 0) hold for the signs above, which
//!   are those of the standard rotation matrices, so we use those.
//!
//! # Moves
//!
//! Print moves are `G1 X Y Z B C E F`, travels `G0`. XYZ have 3 decimals, B and C 4 (degrees),
//! E 5 (relative extrusion, `M83`), F 3 (mm/min: a move that hardly moves X, Y and Z while the
//! bed turns gets a small F). C is unwrapped (it never jumps by 360°) unless
//! the profile limits it, in which case every path is shifted by whole turns to fit the limits.
//! Each planned print segment may be split into equal sub-moves (positions on the planned
//! segment, B and C linear along it, as the controller would move them) so that no move turns C
//! by more than `max_c_step_deg` and the kinematic error stays within its goal.
//!
//! Travels: after printing the filament is retracted and the nozzle lifted by `z_hop` along the
//! current tool axis (machine +Z). A travel that turns B or C by more than `reorient_lift_deg`
//! first goes up to the safe height (above the sphere the part sweeps about the B/C crossing,
//! plus `z_hop` and `reorient_clearance`), turns the bed there, moves over the next point and
//! comes down; a smaller one goes straight to the next point at hop height. Then the nozzle
//! lowers by the hop (along the new tool axis) and un-retracts.
//!
//! # Feed
//!
//! The controller (Marlin with rotary axes) takes F as the speed along the machine XYZ path of a
//! move, or along the rotary axes (degrees) when XYZ do not move. F is scaled by that distance
//! over the move's length along the part, so the nozzle moves over the part at the planned
//! deposition speed (`first_layer_speed` for beads on the table, `print_speed` otherwise).

use std::collections::BTreeMap;

use toolpath::fixed;
use toolpath::vec3::{norm, sub, unit};

use crate::{MachineProfile, MoveKind, PathPoint, PostError, ToolPath};

/// Most sub-moves one planned segment is split into.
pub const MAX_SUBDIVISION: usize = 1024;

/// Below this |(n_x, n_y)| the tool axis is the singular point itself: θ is undefined.
const POLE: f64 = 1e-9;

/// Slack (mm) allowed when checking the work envelope.
const FIT_TOLERANCE: f64 = 1e-6;

/// Slack (degrees) allowed when checking the B and C limits.
const ANGLE_TOLERANCE: f64 = 1e-9;

/// The bed's geometry and the controller's resolutions: the `[delta5]` table of a `delta5`
/// machine profile. `profiles/delta5.toml` documents every key; lengths in mm, angles in
/// degrees.
#[derive(Debug, Clone, PartialEq, serde::Deserialize, serde::Serialize)]
#[serde(deny_unknown_fields)]
pub struct Delta5Geometry {
    /// Machine Z of the B (tilt) axis, which is parallel to machine Y.
    pub b_axis_z: f64,
    /// Machine X and Y of the C (rotary) axis when B = 0; the B axis crosses it.
    pub c_axis_xy: [f64; 2],
    /// Distance along the C axis from the B axis up to the table surface (negative: the surface
    /// is below the B axis).
    pub table_above_b_axis: f64,
    /// Lowest machine Z the nozzle reaches (the highest is the profile's `bed_size` Z).
    pub z_min: f64,
    /// Lowest and highest B (degrees); 0 (the level bed) must lie between them.
    pub b_limits_deg: [f64; 2],
    /// true: C turns without end (the program keeps C unwrapped); false: C stays within
    /// `c_limits_deg`.
    pub c_continuous: bool,
    /// Lowest and highest C (degrees) when `c_continuous` is false; at least 360° apart.
    pub c_limits_deg: [f64; 2],
    /// Half-angle (degrees) of the singularity cone around the C axis: for tool axes inside it
    /// C is patched, not taken from Eq. 10.
    pub singularity_cone_deg: f64,
    /// Largest C change (degrees) of one move; longer turns are split into sub-moves.
    pub max_c_step_deg: f64,
    /// The controller's interpolation step along X, Y and Z (mm).
    pub resolution_xyz: f64,
    /// The controller's interpolation step of B (degrees).
    pub resolution_b_deg: f64,
    /// The controller's interpolation step of C (degrees).
    pub resolution_c_deg: f64,
    /// Largest kinematic error (mm) a print move may carry; longer moves are split.
    pub kinematic_error_goal: f64,
    /// A travel turning B or C by more than this (degrees) goes up to the safe height first.
    pub reorient_lift_deg: f64,
    /// Clearance (mm) of the safe height above the part's swing sphere and the hop.
    pub reorient_clearance: f64,
}

impl Delta5Geometry {
    /// Checks every figure of the table; `name` is the profile's name for the message: all
    /// finite, lengths within ±1e6 mm; `b_limits_deg` within ±180° around 0; `c_limits_deg`
    /// ascending and at least 360° apart; the cone within 0–45°; the C step within (0, 180]°;
    /// resolutions positive and at most 10; the goal within 0.001–10 mm; `reorient_lift_deg`
    /// within 0–360°; the clearance zero or positive.
    pub fn validate(&self, name: &str) -> Result<(), PostError> {
        let bad = |field: &'static str, reason: String| PostError::ProfileValue {
            name: name.to_string(),
            field,
            reason,
        };
        for (field, v) in [
            ("delta5.b_axis_z", self.b_axis_z),
            ("delta5.c_axis_xy", self.c_axis_xy[0]),
            ("delta5.c_axis_xy", self.c_axis_xy[1]),
            ("delta5.table_above_b_axis", self.table_above_b_axis),
            ("delta5.z_min", self.z_min),
            ("delta5.c_limits_deg", self.c_limits_deg[0]),
            ("delta5.c_limits_deg", self.c_limits_deg[1]),
        ] {
            if !(v.is_finite() && v.abs() <= 1e6) {
                return Err(bad(field, format!("must be a number within ±1e6, got {v}")));
            }
        }
        let [b_lo, b_hi] = self.b_limits_deg;
        // `contains` is false for NaN.
        let b_ok = (-180.0..=0.0).contains(&b_lo) && (0.0..=180.0).contains(&b_hi) && b_lo < b_hi;
        if !b_ok {
            return Err(bad(
                "delta5.b_limits_deg",
                format!("must be [low, high] with -180 <= low <= 0 <= high <= 180, got [{b_lo}, {b_hi}]"),
            ));
        }
        let [c_lo, c_hi] = self.c_limits_deg;
        if c_hi - c_lo < 360.0 {
            return Err(bad(
                "delta5.c_limits_deg",
                format!("must be [low, high] at least 360 degrees apart, got [{c_lo}, {c_hi}]"),
            ));
        }
        for (field, v, lo, hi, lo_open) in [
            (
                "delta5.singularity_cone_deg",
                self.singularity_cone_deg,
                0.0,
                45.0,
                false,
            ),
            (
                "delta5.max_c_step_deg",
                self.max_c_step_deg,
                0.0,
                180.0,
                true,
            ),
            (
                "delta5.resolution_xyz",
                self.resolution_xyz,
                0.0,
                10.0,
                true,
            ),
            (
                "delta5.resolution_b_deg",
                self.resolution_b_deg,
                0.0,
                10.0,
                true,
            ),
            (
                "delta5.resolution_c_deg",
                self.resolution_c_deg,
                0.0,
                10.0,
                true,
            ),
            (
                "delta5.kinematic_error_goal",
                self.kinematic_error_goal,
                0.001,
                10.0,
                false,
            ),
            (
                "delta5.reorient_lift_deg",
                self.reorient_lift_deg,
                0.0,
                360.0,
                false,
            ),
            (
                "delta5.reorient_clearance",
                self.reorient_clearance,
                0.0,
                1e4,
                false,
            ),
        ] {
            let above = if lo_open { v > lo } else { v >= lo };
            if !(v.is_finite() && above && v <= hi) {
                let low = if lo_open { "above" } else { "at least" };
                return Err(bad(
                    field,
                    format!("must be {low} {lo} and at most {hi}, got {v}"),
                ));
            }
        }
        Ok(())
    }

    /// The crossing `Q` of the B and C axes, in machine coordinates.
    fn pivot(&self) -> [f64; 3] {
        [self.c_axis_xy[0], self.c_axis_xy[1], self.b_axis_z]
    }

    /// Whether `axis` (unit) lies in the singularity cone around the C axis (or is the
    /// singular point itself), where θ is patched instead of taken from Eq. 10.
    pub fn in_singularity_cone(&self, axis: [f64; 3]) -> bool {
        let r = axis[0].hypot(axis[1]);
        r < POLE || r <= self.singularity_cone_deg.to_radians().sin()
    }

    fn b_fits(&self, b: f64) -> bool {
        b >= self.b_limits_deg[0] - ANGLE_TOLERANCE && b <= self.b_limits_deg[1] + ANGLE_TOLERANCE
    }
}

/// Kinematic figures of one feature's print moves (paper Fig. 16).
#[derive(Debug, Clone, Default, PartialEq, serde::Serialize)]
pub struct KinematicFigures {
    /// Largest distance (mm) from the planned path of the controller's interpolated positions,
    /// transformed back to the part.
    pub max_mm: f64,
    /// Mean of those distances (mm) over every interpolation step.
    pub mean_mm: f64,
    /// Planned print segments split into more than one move (for the C step or the error goal).
    pub subdivided_segments: usize,
    /// `G1` print moves written.
    pub print_moves: usize,
    /// Interpolation steps the figures are taken over.
    pub samples: usize,
    /// Planned points in the singularity cone, whose C was patched.
    pub singular_points: usize,
    /// Largest angle (degrees) between a planned tool axis and the one the bed gives at that
    /// point: 0 but for rounding outside the cone, at most the cone's half-angle inside it.
    pub max_axis_deviation_deg: f64,
    /// Largest C change (degrees) of one print move.
    pub max_c_step_deg: f64,
}

/// A 5-axis program and what the post measured of it.
#[derive(Debug, Clone, PartialEq)]
pub struct Delta5Program {
    /// The G-code.
    pub gcode: String,
    /// Kinematic figures per feature id (features with print moves only).
    pub figures: BTreeMap<usize, KinematicFigures>,
    /// The kinematic error along the printed path as a stand-alone SVG: one colour per
    /// feature, axes labelled, the goal as a dashed line.
    pub error_plot_svg: String,
    /// table = part + offset (mm), as in the header.
    pub offset: [f64; 3],
    /// Machine Z of the safe height used for large reorientations.
    pub safe_z: f64,
}

/// Bed angles `(B, C)` in degrees for the unit tool axis `axis` (part coordinates), the
/// inverse kinematics of Isa & Lazoglu 2019, Eq. 9–12: `n_b = R_z(θ)·R_y(φ)·(0,0,1)` (Eq. 9)
/// with B = φ, C = θ.
///
/// θ has two solutions (Eq. 10), θ₁ = atan2(n_y, n_x) with σ = 1 and θ₂ = atan2(−n_y, −n_x)
/// with σ = −1, and φ = atan2(σ·√(n_x² + n_y²), n_z) (Eq. 11, written with atan2 so an axis
/// pointing below the horizon gets |φ| > 90°, which the B limits then accept or refuse). σ is
/// chosen by Eq. 12: the solution whose change from `previous_c_deg` is at most 90° (the
/// shortest), C unwrapped to lie nearest the previous C; with no previous C, σ = 1 and C in
/// (−180°, 180°]. If that solution's B is outside the B limits the other is taken.
///
/// At the singular point (n_x = n_y = 0) C keeps `previous_c_deg` (0 without one) and B is 0
/// (or 180). `None`: the axis is not a direction, or no solution's B is within the limits.
/// This is the pure Eq. 9–12; the post patches C inside the singularity cone on top of it.
pub fn inverse(
    axis: [f64; 3],
    previous_c_deg: Option<f64>,
    g: &Delta5Geometry,
) -> Option<(f64, f64)> {
    let a = unit(axis)?;
    let r = a[0].hypot(a[1]);
    if r < POLE {
        let b = if a[2] > 0.0 { 0.0 } else { 180.0 };
        let c = previous_c_deg.unwrap_or(0.0);
        return [b, -b].into_iter().find(|&b| g.b_fits(b)).map(|b| (b, c));
    }
    // Eq. 10, σ = 1 and σ = −1.
    let theta1 = a[1].atan2(a[0]).to_degrees();
    let theta2 = (-a[1]).atan2(-a[0]).to_degrees();
    // Eq. 11.
    let phi = |sigma: f64| (sigma * r).atan2(a[2]).to_degrees();
    let (c1, c2) = match previous_c_deg {
        Some(p) => (unwrap_near(theta1, p), unwrap_near(theta2, p)),
        None => (theta1, theta2),
    };
    // Eq. 12: σ = 1 when θ₁ is within 90° of the previous θ, else −1.
    let first = match previous_c_deg {
        Some(p) if (c1 - p).abs() > 90.0 => -1.0,
        _ => 1.0,
    };
    [first, -first]
        .into_iter()
        .map(|s| (phi(s), if s > 0.0 { c1 } else { c2 }))
        .find(|&(b, _)| g.b_fits(b))
}

/// B (degrees) for `axis` (unit) when C is fixed at `c_deg` (a patched C): Eq. 11 with the
/// component of the axis along the bed's tilt direction `(cos C, sin C, 0)` in place of
/// `σ·√(n_x² + n_y²)`, the tilt that brings the bed's axis closest to `axis`. Where C is
/// Eq. 10's, this is Eq. 11 itself.
pub fn tilt_for(axis: [f64; 3], c_deg: f64) -> f64 {
    let (s, c) = c_deg.to_radians().sin_cos();
    (axis[0] * c + axis[1] * s).atan2(axis[2]).to_degrees()
}

/// Machine nozzle position for the part point `p` when the bed is at `b_deg`, `c_deg` and the
/// part is placed with `offset` (table = part + offset): `Q + R_y(−B)·R_z(−C)·(p + offset +
/// h·ẑ)`.
pub fn to_machine(
    p: [f64; 3],
    b_deg: f64,
    c_deg: f64,
    g: &Delta5Geometry,
    offset: [f64; 3],
) -> [f64; 3] {
    let t = [
        p[0] + offset[0],
        p[1] + offset[1],
        p[2] + offset[2] + g.table_above_b_axis,
    ];
    let v = bed_to_machine(t, b_deg.to_radians(), c_deg.to_radians());
    let q = g.pivot();
    [q[0] + v[0], q[1] + v[1], q[2] + v[2]]
}

/// Forward kinematics: the part point under the nozzle and the part's tool axis when the
/// machine is at `machine` = `[X, Y, Z, B, C]` (mm, degrees) and the part is placed with
/// `offset` (table = part + offset, as the program's header states). The axis is
/// `R_z(C)·R_y(B)·(0,0,1)` (Eq. 9).
pub fn forward(machine: [f64; 5], g: &Delta5Geometry, offset: [f64; 3]) -> ([f64; 3], [f64; 3]) {
    let [x, y, z, b, c] = machine;
    let (b, c) = (b.to_radians(), c.to_radians());
    let q = g.pivot();
    let t = machine_to_bed([x - q[0], y - q[1], z - q[2]], b, c);
    let p = [
        t[0] - offset[0],
        t[1] - offset[1],
        t[2] - g.table_above_b_axis - offset[2],
    ];
    (p, machine_to_bed([0.0, 0.0, 1.0], b, c))
}

/// `R_y(−B)·R_z(−C)·v`: a table-frame vector in machine axes (angles in radians).
fn bed_to_machine(v: [f64; 3], b: f64, c: f64) -> [f64; 3] {
    let (sc, cc) = c.sin_cos();
    let (sb, cb) = b.sin_cos();
    let x = v[0] * cc + v[1] * sc;
    let y = -v[0] * sc + v[1] * cc;
    [x * cb - v[2] * sb, y, x * sb + v[2] * cb]
}

/// `R_z(C)·R_y(B)·v`: a machine vector in table-frame axes (angles in radians).
fn machine_to_bed(v: [f64; 3], b: f64, c: f64) -> [f64; 3] {
    let (sc, cc) = c.sin_cos();
    let (sb, cb) = b.sin_cos();
    let x = v[0] * cb + v[2] * sb;
    let z = -v[0] * sb + v[2] * cb;
    [x * cc - v[1] * sc, x * sc + v[1] * cc, z]
}

/// `theta` plus the whole turns that bring it nearest `previous` (degrees).
fn unwrap_near(theta: f64, previous: f64) -> f64 {
    theta + 360.0 * ((previous - theta) / 360.0).round()
}

fn lerp(a: [f64; 3], b: [f64; 3], f: f64) -> [f64; 3] {
    [
        a[0] + (b[0] - a[0]) * f,
        a[1] + (b[1] - a[1]) * f,
        a[2] + (b[2] - a[2]) * f,
    ]
}

/// Angle (degrees) between two unit vectors.
fn angle_deg(a: [f64; 3], b: [f64; 3]) -> f64 {
    let cross = [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ];
    let dot = a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
    norm(cross).atan2(dot).to_degrees()
}

/// Distance from `x` to the segment `a`–`b`.
fn distance_to_segment(x: [f64; 3], a: [f64; 3], b: [f64; 3]) -> f64 {
    let d = sub(b, a);
    let dd = d[0] * d[0] + d[1] * d[1] + d[2] * d[2];
    let w = sub(x, a);
    let f = if dd > 0.0 {
        ((w[0] * d[0] + w[1] * d[1] + w[2] * d[2]) / dd).clamp(0.0, 1.0)
    } else {
        0.0
    };
    norm(sub(x, lerp(a, b, f)))
}

/// The bed angles planned for one path point.
#[derive(Debug, Clone, Copy)]
struct Pose {
    b: f64,
    c: f64,
    /// C was patched (the axis is in the singularity cone).
    patched: bool,
}

/// Bed angles for every point: Eq. 10–12 outside the singularity cone, and inside it C
/// interpolated linearly, by length along the path, between the last point before and the
/// first point after the cone (the paper's singularity cone with C-axis patching), B then by
/// [`tilt_for`]. A path (a point that is not a print move and the print moves after it) is
/// patched on its own; a path that starts (ends) in the cone takes the C of its first (last)
/// point outside it, one wholly inside keeps the C the machine is at.
fn plan_poses(
    points: &[PathPoint],
    g: &Delta5Geometry,
    name: &str,
) -> Result<Vec<Pose>, PostError> {
    let mut poses = Vec::with_capacity(points.len());
    let mut start = 0;
    while start < points.len() {
        let mut end = start + 1;
        while end < points.len() && points[end].kind == MoveKind::Print {
            end += 1;
        }
        let entry = poses.last().map(|p: &Pose| p.c);
        plan_run(&points[start..end], entry, g, name, &mut poses)?;
        start = end;
    }
    Ok(poses)
}

fn axis_error(q: &PathPoint, name: &str, reason: String) -> PostError {
    PostError::Delta5Axis {
        feature: q.feature,
        i: q.axis[0],
        j: q.axis[1],
        k: q.axis[2],
        name: name.to_string(),
        reason,
    }
}

fn plan_run(
    run: &[PathPoint],
    entry: Option<f64>,
    g: &Delta5Geometry,
    name: &str,
    poses: &mut Vec<Pose>,
) -> Result<(), PostError> {
    let n = run.len();
    let mut axes = Vec::with_capacity(n);
    for q in run {
        let a = unit(q.axis)
            .ok_or_else(|| axis_error(q, name, "is not a direction (zero length)".into()))?;
        axes.push(a);
    }
    // Length along the path, for the patch's interpolation.
    let mut s = vec![0.0; n];
    for i in 1..n {
        s[i] = s[i - 1] + norm(sub(run[i].p, run[i - 1].p));
    }
    let singular: Vec<bool> = axes.iter().map(|&a| g.in_singularity_cone(a)).collect();
    let mut b = vec![0.0; n];
    let mut c = vec![0.0; n];
    let mut previous = entry;
    for i in (0..n).filter(|&i| !singular[i]) {
        let (bi, ci) = inverse(axes[i], previous, g).ok_or_else(|| {
            let need = axes[i][0].hypot(axes[i][1]).atan2(axes[i][2]).to_degrees();
            axis_error(
                &run[i],
                name,
                format!(
                    "needs B {} or {} degrees, outside the B limits [{}, {}]",
                    fixed(need, 3),
                    fixed(-need, 3),
                    g.b_limits_deg[0],
                    g.b_limits_deg[1]
                ),
            )
        })?;
        (b[i], c[i]) = (bi, ci);
        previous = Some(ci);
    }
    // The last point before and the first point after each point, outside the cone.
    let mut before = vec![None; n];
    let mut last = None;
    for i in 0..n {
        before[i] = last;
        if !singular[i] {
            last = Some(i);
        }
    }
    let mut after = vec![None; n];
    let mut next = None;
    for i in (0..n).rev() {
        after[i] = next;
        if !singular[i] {
            next = Some(i);
        }
    }
    for i in (0..n).filter(|&i| singular[i]) {
        c[i] = match (before[i], after[i]) {
            (Some(j), Some(k)) => {
                let f = if s[k] - s[j] > 1e-12 {
                    (s[i] - s[j]) / (s[k] - s[j])
                } else {
                    (i - j) as f64 / (k - j) as f64
                };
                c[j] + (c[k] - c[j]) * f
            }
            (Some(j), None) => c[j],
            (None, Some(k)) => c[k],
            (None, None) => entry.unwrap_or(0.0),
        };
        b[i] = tilt_for(axes[i], c[i]);
        if !g.b_fits(b[i]) {
            return Err(axis_error(
                &run[i],
                name,
                format!(
                    "needs B {} degrees, outside the B limits [{}, {}]",
                    fixed(b[i], 3),
                    g.b_limits_deg[0],
                    g.b_limits_deg[1]
                ),
            ));
        }
    }
    if !g.c_continuous {
        fit_c_limits(run, &mut c, entry, g, name)?;
    }
    poses.extend((0..n).map(|i| Pose {
        b: b[i],
        c: c[i],
        patched: singular[i],
    }));
    Ok(())
}

/// Shifts a path's C by whole turns so that it lies within the C limits, as near the machine's
/// C as the limits allow.
fn fit_c_limits(
    run: &[PathPoint],
    c: &mut [f64],
    entry: Option<f64>,
    g: &Delta5Geometry,
    name: &str,
) -> Result<(), PostError> {
    let lo = c.iter().copied().fold(f64::INFINITY, f64::min);
    let hi = c.iter().copied().fold(f64::NEG_INFINITY, f64::max);
    let [c_lo, c_hi] = g.c_limits_deg;
    let k_min = ((c_lo - lo - ANGLE_TOLERANCE) / 360.0).ceil();
    let k_max = ((c_hi - hi + ANGLE_TOLERANCE) / 360.0).floor();
    if k_min > k_max || c.is_empty() {
        return Err(PostError::Delta5CLimits {
            feature: run.first().map_or(0, |q| q.feature),
            span: hi - lo,
            c_min: c_lo,
            c_max: c_hi,
            name: name.to_string(),
        });
    }
    let target = entry.unwrap_or((c_lo + c_hi) / 2.0);
    let k = ((target - c[0]) / 360.0).round().clamp(k_min, k_max);
    for v in c.iter_mut() {
        *v += 360.0 * k;
    }
    Ok(())
}

/// The offset (mm, rounded to 0.001) from part to table coordinates: the XY bounding-box
/// centre of the print points on the C axis, the lowest bead bottom (`p − thickness·axis` over
/// print points) on the table surface. A path without print points is placed by its travel
/// points; an empty path gets no offset.
fn placement(path: &ToolPath) -> [f64; 3] {
    let placed = crate::marlin::placed_points(path);
    if placed.is_empty() {
        return [0.0; 3];
    }
    let mut lo = [f64::INFINITY; 3];
    let mut hi = [f64::NEG_INFINITY; 2];
    for q in &placed {
        let bottom = match (q.kind, unit(q.axis)) {
            (MoveKind::Print, Some(a)) => q.p[2] - q.thickness.max(0.0) * a[2],
            _ => q.p[2],
        };
        for k in 0..2 {
            lo[k] = lo[k].min(q.p[k]);
            hi[k] = hi[k].max(q.p[k]);
        }
        lo[2] = lo[2].min(bottom);
    }
    let round3 = |v: f64| (v * 1000.0).round() / 1000.0;
    [
        round3(-(lo[0] / 2.0 + hi[0] / 2.0)),
        round3(-(lo[1] / 2.0 + hi[1] / 2.0)),
        // Up, never down: the lowest bead must not end below the table.
        ((-lo[2] - 1e-9) * 1000.0).ceil() / 1000.0,
    ]
}

/// Machine joints `[X, Y, Z, B, C]` rounded as written: XYZ to 0.001 mm, B and C to 0.0001°.
type Joints = [f64; 5];

fn rounded(xyz: [f64; 3], b: f64, c: f64) -> Joints {
    let r3 = |v: f64| (v * 1e3).round() / 1e3;
    let r4 = |v: f64| (v * 1e4).round() / 1e4;
    [r3(xyz[0]), r3(xyz[1]), r3(xyz[2]), r4(b), r4(c)]
}

/// A 5-axis program for the path on a `delta5` machine, with its kinematic figures and error
/// plot.
///
/// Every point goes through the same bed kinematics in the path's (build) order: `two5d`
/// features, whose axis is their reference plane's normal, print with the bed held at that
/// plane's angles (B = 0, C unchanged for +Z). `source` (the STEP file's name) is written in
/// the first comment line.
///
/// The kinematic error (paper Fig. 16) of a print move is measured as the controller would
/// run it: X, Y, Z, B and C interpolated linearly in as many steps as the coarsest of the
/// resolutions needs, each step transformed back to the part ([`forward`]) and its distance to
/// the planned segment taken. A planned segment is split into equal sub-moves (on the planned
/// segment, B and C linear along it) until no move turns C by more than `max_c_step_deg` and
/// the error stays within `kinematic_error_goal` (or [`MAX_SUBDIVISION`] moves are reached;
/// the figures then show it).
///
/// Errors: the profile is not a valid `delta5` profile; a point holds a NaN or infinite number;
/// a tool axis is not a direction or needs a B outside the B limits (naming the feature); a
/// path cannot fit the C limits; a move leaves the work envelope (X and Y within `bed_size`
/// around the bed centre, Z within `z_min`..`bed_size` Z) or a point lies below the table
/// surface (naming the feature and by how much).
pub fn delta5(
    path: &ToolPath,
    m: &MachineProfile,
    source: &str,
) -> Result<Delta5Program, PostError> {
    let g = m.delta5_table()?;
    if g.z_min >= m.bed_size[2] {
        return Err(PostError::ProfileValue {
            name: m.name.clone(),
            field: "delta5.z_min",
            reason: format!(
                "must be below the bed_size Z {}, got {}",
                m.bed_size[2], g.z_min
            ),
        });
    }
    path.check_finite()?;
    let offset = placement(path);
    for q in &path.points {
        let below = -(q.p[2] + offset[2]);
        if below > FIT_TOLERANCE {
            return Err(PostError::Delta5Envelope {
                feature: q.feature,
                name: m.name.clone(),
                excess: format!(
                    "a point lies {} mm below the table surface",
                    fixed(below, 3)
                ),
            });
        }
    }
    let poses = plan_poses(&path.points, g, &m.name)?;

    // The sphere the part sweeps about the axes' crossing, for the safe height.
    let swing = path
        .points
        .iter()
        .map(|q| {
            let t = [
                q.p[0] + offset[0],
                q.p[1] + offset[1],
                q.p[2] + offset[2] + g.table_above_b_axis,
            ];
            norm(t) + q.width.max(0.0) / 2.0
        })
        .fold(0.0, f64::max);
    let wanted_safe = g.b_axis_z + swing + m.z_hop + g.reorient_clearance;
    let safe_z = wanted_safe.min(m.bed_size[2]);

    let mut w = Writer::new(m, g, offset, safe_z);
    let mut previous: Option<usize> = None;
    for (i, q) in path.points.iter().enumerate() {
        w.comments(q);
        match q.kind {
            MoveKind::Travel => w.travel(q, &poses[i])?,
            MoveKind::Print => {
                let from = match previous {
                    Some(j) if w.at.is_some() => j,
                    _ => {
                        w.travel(q, &poses[i])?;
                        i
                    }
                };
                w.print(&path.points[from], &poses[from], q, &poses[i])?;
            }
        }
        previous = Some(i);
    }
    w.footer()?;

    let figures: BTreeMap<usize, KinematicFigures> = w
        .figures
        .iter()
        .map(|(&f, a)| {
            let mut k = a.figures.clone();
            k.mean_mm = if k.samples > 0 {
                a.sum / k.samples as f64
            } else {
                0.0
            };
            (f, k)
        })
        .collect();
    let mut gcode = header(m, g, source, offset, safe_z, wanted_safe, &figures);
    gcode.push_str(&w.out);
    let error_plot_svg = error_plot(&w.plot, g.kinematic_error_goal, source);
    Ok(Delta5Program {
        gcode,
        figures,
        error_plot_svg,
        offset,
        safe_z,
    })
}

/// `s` with line breaks and other control characters replaced by spaces, for comments.
fn comment_text(s: &str) -> String {
    s.chars()
        .map(|c| if c.is_control() { ' ' } else { c })
        .collect()
}

fn header(
    m: &MachineProfile,
    g: &Delta5Geometry,
    source: &str,
    offset: [f64; 3],
    safe_z: f64,
    wanted_safe: f64,
    figures: &BTreeMap<usize, KinematicFigures>,
) -> String {
    let t = |v: f64| fixed(v, 0);
    let mut lines = vec![
        format!("; generated by features from {}", comment_text(source)),
        format!("; machine: {} (delta5)", comment_text(&m.name)),
        format!(
            "; offset X{} Y{} Z{} (table = part + offset: the part's XY bounding-box centre on the C axis, its lowest bead bottom on the table surface)",
            fixed(offset[0], 3),
            fixed(offset[1], 3),
            fixed(offset[2], 3)
        ),
        format!(
            "; bed: B axis along Y at X{} Z{}, C axis at X{} Y{}, table surface {} mm above the B axis",
            fixed(g.c_axis_xy[0], 3),
            fixed(g.b_axis_z, 3),
            fixed(g.c_axis_xy[0], 3),
            fixed(g.c_axis_xy[1], 3),
            fixed(g.table_above_b_axis, 3)
        ),
        "; angles: B = phi, C = theta of Isa & Lazoglu 2019 Eq. 9-12; tool axis in the part = (cos C sin B, sin C sin B, cos B); the bed turns by -C and tilts by -B (ISO 841)".into(),
        format!(
            "; singularity cone {} deg around the C axis (C patched inside), at most {} deg of C per move, C {}",
            fixed(g.singularity_cone_deg, 3),
            fixed(g.max_c_step_deg, 3),
            if g.c_continuous {
                "continuous (unwrapped)".to_string()
            } else {
                format!("within [{}, {}] deg", fixed(g.c_limits_deg[0], 3), fixed(g.c_limits_deg[1], 3))
            }
        ),
    ];
    if wanted_safe > safe_z + FIT_TOLERANCE {
        lines.push(format!(
            "; safe height Z{} for reorientations: the top of the envelope, below the part's swing sphere (Z{}): large reorientations are not guaranteed clear",
            fixed(safe_z, 3),
            fixed(wanted_safe, 3)
        ));
    } else {
        lines.push(format!(
            "; safe height Z{} for reorientations (above the part's swing sphere about the B/C axes)",
            fixed(safe_z, 3)
        ));
    }
    lines.push(format!(
        "; kinematic error (goal {} mm; interpolation XYZ {} mm, B {} deg, C {} deg):",
        fixed(g.kinematic_error_goal, 3),
        fixed(g.resolution_xyz, 3),
        fixed(g.resolution_b_deg, 3),
        fixed(g.resolution_c_deg, 3)
    ));
    for (f, k) in figures {
        lines.push(format!(
            ";   feature {f}: max {} mm, mean {} mm, {} segments subdivided, {} singular points patched",
            fixed(k.max_mm, 4),
            fixed(k.mean_mm, 4),
            k.subdivided_segments,
            k.singular_points
        ));
    }
    lines.push(format!(
        "; nozzle {} mm, filament {} mm, bead {} mm",
        fixed(m.nozzle_diameter, 2),
        fixed(m.filament_diameter, 2),
        fixed(m.bead_width, 2)
    ));
    lines.push(";FLAVOR:Marlin".into());
    lines.push("G21 ; millimetres".into());
    lines.push("G90 ; absolute XYZ, B and C".into());
    lines.push("M83 ; relative extrusion: E is each segment's filament length".into());
    lines.push(format!("M140 S{} ; bed", t(m.bed_temperature)));
    lines.push(format!("M104 S{} ; nozzle", t(m.nozzle_temperature)));
    lines.push("G28 ; home all axes, B and C included".into());
    if m.bed_temperature > 0.0 {
        lines.push(format!("M190 S{} ; wait for the bed", t(m.bed_temperature)));
    }
    lines.push(format!(
        "M109 S{} ; wait for the nozzle",
        t(m.nozzle_temperature)
    ));
    lines.push("G92 E0".into());
    let mut out = lines.join("\n");
    out.push('\n');
    out
}

/// Running kinematic figures of one feature.
#[derive(Default)]
struct Accumulator {
    figures: KinematicFigures,
    sum: f64,
}

/// The program being written and the machine state it leaves.
struct Writer<'a> {
    out: String,
    m: &'a MachineProfile,
    g: &'a Delta5Geometry,
    offset: [f64; 3],
    /// Joints the last move ended at, the hop excluded.
    at: Option<Joints>,
    retracted: bool,
    printing: bool,
    hopped: bool,
    marks: crate::marlin::LayerMarks,
    /// The feature being written, for envelope errors.
    current: usize,
    safe_z: f64,
    lo: [f64; 3],
    hi: [f64; 3],
    travel_f: String,
    retraction_f: String,
    /// Filament written so far on print moves, in 0.00001 mm.
    e_written: i64,
    /// Filament planned so far on print moves (mm).
    e_planned: f64,
    figures: BTreeMap<usize, Accumulator>,
    /// (feature, length along the printed path, largest error of the move) per print move.
    plot: Vec<(usize, f64, f64)>,
    printed_length: f64,
}

impl<'a> Writer<'a> {
    fn new(
        m: &'a MachineProfile,
        g: &'a Delta5Geometry,
        offset: [f64; 3],
        safe_z: f64,
    ) -> Writer<'a> {
        let (x0, y0) = if m.bed_origin_centre {
            (-m.bed_size[0] / 2.0, -m.bed_size[1] / 2.0)
        } else {
            (0.0, 0.0)
        };
        Writer {
            out: String::new(),
            m,
            g,
            offset,
            at: None,
            retracted: false,
            printing: false,
            hopped: false,
            marks: crate::marlin::LayerMarks::default(),
            current: 0,
            safe_z,
            lo: [x0, y0, g.z_min],
            hi: [x0 + m.bed_size[0], y0 + m.bed_size[1], m.bed_size[2]],
            travel_f: fixed(m.travel_speed * 60.0, 0),
            retraction_f: fixed(m.retraction_speed * 60.0, 0),
            e_written: 0,
            e_planned: 0.0,
            figures: BTreeMap::new(),
            plot: Vec::new(),
            printed_length: 0.0,
        }
    }

    fn line(&mut self, s: &str) {
        self.out.push_str(s);
        self.out.push('\n');
    }

    /// `;LAYER:` and `;FEATURE:` comments where the point's layer or feature changes.
    fn comments(&mut self, q: &PathPoint) {
        self.current = q.feature;
        self.marks.write(q, &mut self.out);
    }

    /// Refuses a nozzle position outside the work envelope.
    fn check(&self, xyz: [f64; 3]) -> Result<(), PostError> {
        let mut excess = Vec::new();
        for (k, letter) in ["X", "Y", "Z"].iter().enumerate() {
            if xyz[k] < self.lo[k] - FIT_TOLERANCE {
                excess.push(format!(
                    "{letter} {} is {} mm below {}",
                    fixed(xyz[k], 3),
                    fixed(self.lo[k] - xyz[k], 3),
                    fixed(self.lo[k], 3)
                ));
            } else if xyz[k] > self.hi[k] + FIT_TOLERANCE || xyz[k].is_nan() {
                excess.push(format!(
                    "{letter} {} is {} mm above {}",
                    fixed(xyz[k], 3),
                    fixed(xyz[k] - self.hi[k], 3),
                    fixed(self.hi[k], 3)
                ));
            }
        }
        if excess.is_empty() {
            Ok(())
        } else {
            Err(PostError::Delta5Envelope {
                feature: self.current,
                name: self.m.name.clone(),
                excess: excess.join(", "),
            })
        }
    }

    fn joints(&self, p: [f64; 3], b: f64, c: f64) -> Joints {
        rounded(to_machine(p, b, c, self.g, self.offset), b, c)
    }

    fn hop_z(&self, z: f64) -> f64 {
        (z + self.m.z_hop).min(self.hi[2]).max(z)
    }

    fn retract(&mut self) {
        if self.m.retraction_length > 0.0 && !self.retracted {
            let line = format!(
                "G1 E-{} F{}",
                fixed(self.m.retraction_length, 5),
                self.retraction_f
            );
            self.line(&line);
            self.retracted = true;
        }
    }

    fn g0_z(&mut self, at: Joints, z: f64) -> Result<(), PostError> {
        self.check([at[0], at[1], z])?;
        let line = format!("G0 Z{} F{}", fixed(z, 3), self.travel_f);
        self.line(&line);
        Ok(())
    }

    /// To the point `q` (bed at `pose`) at hop height; see the module documentation.
    fn travel(&mut self, q: &PathPoint, pose: &Pose) -> Result<(), PostError> {
        if self.printing {
            self.retract();
        }
        self.printing = false;
        let target = self.joints(q.p, pose.b, pose.c);
        self.check([target[0], target[1], target[2]])?;
        let hop = self.hop_z(target[2]);
        let reorient = match self.at {
            Some(at) => {
                (target[3] - at[3]).abs() > self.g.reorient_lift_deg
                    || (target[4] - at[4]).abs() > self.g.reorient_lift_deg
            }
            None => true,
        };
        if let Some(at) = self.at {
            if !self.hopped {
                if self.m.z_hop > 0.0 {
                    self.g0_z(at, self.hop_z(at[2]))?;
                }
                self.hopped = true;
            }
        }
        if reorient {
            let (x, y) = self.at.map_or((target[0], target[1]), |at| (at[0], at[1]));
            self.check([x, y, self.safe_z])?;
            let lines = [
                format!("G0 Z{} F{}", fixed(self.safe_z, 3), self.travel_f),
                format!(
                    "G0 B{} C{} F{} ; reorient at the safe height",
                    fixed(target[3], 4),
                    fixed(target[4], 4),
                    self.travel_f
                ),
                format!(
                    "G0 X{} Y{} F{}",
                    fixed(target[0], 3),
                    fixed(target[1], 3),
                    self.travel_f
                ),
                format!("G0 Z{} F{}", fixed(hop, 3), self.travel_f),
            ];
            self.check([target[0], target[1], self.safe_z])?;
            for l in &lines {
                self.line(l);
            }
        } else {
            self.check([target[0], target[1], hop])?;
            let line = format!(
                "G0 X{} Y{} Z{} B{} C{} F{}",
                fixed(target[0], 3),
                fixed(target[1], 3),
                fixed(hop, 3),
                fixed(target[3], 4),
                fixed(target[4], 4),
                self.travel_f
            );
            self.line(&line);
        }
        self.hopped = true;
        self.at = Some(target);
        Ok(())
    }

    /// The planned segment from `a` (bed at `pa`, where the machine is) to `q` (bed at `pq`),
    /// as one or more `G1` moves.
    fn print(
        &mut self,
        a: &PathPoint,
        pa: &Pose,
        q: &PathPoint,
        pq: &Pose,
    ) -> Result<(), PostError> {
        let Some(start) = self.at else {
            return Ok(());
        };
        if self.hopped {
            self.g0_z(start, start[2])?;
            self.hopped = false;
        }
        if self.retracted {
            let line = format!(
                "G1 E{} F{}",
                fixed(self.m.retraction_length, 5),
                self.retraction_f
            );
            self.line(&line);
            self.retracted = false;
        }
        let g = self.g;
        let dc = (pq.c - pa.c).abs();
        let mut n = ((dc / g.max_c_step_deg - 1e-9).ceil().max(1.0) as usize).min(MAX_SUBDIVISION);
        let length = norm(sub(q.p, a.p));
        let (moves, errors) = loop {
            let moves: Vec<Joints> = (1..=n)
                .map(|k| {
                    if k == n {
                        self.joints(q.p, pq.b, pq.c)
                    } else {
                        let f = k as f64 / n as f64;
                        let b = pa.b + (pq.b - pa.b) * f;
                        let c = pa.c + (pq.c - pa.c) * f;
                        self.joints(lerp(a.p, q.p, f), b, c)
                    }
                })
                .collect();
            let mut from = start;
            let mut errors = Vec::with_capacity(n);
            for &to in &moves {
                errors.push(self.move_error(from, to, a.p, q.p));
                from = to;
            }
            let worst = errors.iter().map(|e| e.0).fold(0.0, f64::max);
            if worst <= g.kinematic_error_goal || n >= MAX_SUBDIVISION || length / (n as f64) < 1e-3
            {
                break (moves, errors);
            }
            // The error of a turning move shrinks with the square of its length.
            let grow = (n as f64 * (worst / g.kinematic_error_goal).sqrt() * 1.1).ceil() as usize;
            n = grow.max(n + 1).min(MAX_SUBDIVISION);
        };

        // Planned deposition speed along the part.
        let bottom = match unit(q.axis) {
            Some(ax) => q.p[2] - q.thickness.max(0.0) * ax[2],
            None => q.p[2],
        };
        let on_table = bottom + self.offset[2] <= 0.01;
        let v = if on_table {
            self.m.first_layer_speed
        } else {
            self.m.print_speed
        };
        let part_step = length / n as f64;
        let mut from = start;
        let acc = self.figures.entry(q.feature).or_default();
        acc.figures.print_moves += n;
        if n > 1 {
            acc.figures.subdivided_segments += 1;
        }
        if pq.patched {
            acc.figures.singular_points += 1;
        }
        let realised = machine_to_bed([0.0, 0.0, 1.0], pq.b.to_radians(), pq.c.to_radians());
        if let Some(planned) = unit(q.axis) {
            let dev = angle_deg(planned, realised);
            acc.figures.max_axis_deviation_deg = acc.figures.max_axis_deviation_deg.max(dev);
        }
        let mut lines = Vec::with_capacity(n);
        for (&to, &(worst, sum, count)) in moves.iter().zip(&errors) {
            let xyz = norm(sub([to[0], to[1], to[2]], [from[0], from[1], from[2]]));
            let rotary = (to[3] - from[3]).hypot(to[4] - from[4]);
            let distance = if xyz > 1e-9 { xyz } else { rotary };
            let f = if part_step > 1e-9 && distance > 0.0 {
                60.0 * v * distance / part_step
            } else {
                60.0 * v
            };
            let f = f.max(0.001);
            self.e_planned += q.e / n as f64;
            // Cumulative rounding: the E written adds up to the planned total.
            let target = (self.e_planned * 1e5).round() as i64;
            let de = target - self.e_written;
            self.e_written = target;
            acc.figures.max_c_step_deg = acc.figures.max_c_step_deg.max((to[4] - from[4]).abs());
            acc.figures.max_mm = acc.figures.max_mm.max(worst);
            acc.sum += sum;
            acc.figures.samples += count;
            self.printed_length += part_step;
            self.plot.push((q.feature, self.printed_length, worst));
            lines.push(format!(
                "G1 X{} Y{} Z{} B{} C{} E{} F{}",
                fixed(to[0], 3),
                fixed(to[1], 3),
                fixed(to[2], 3),
                fixed(to[3], 4),
                fixed(to[4], 4),
                e_text(de),
                fixed(f, 3)
            ));
            from = to;
        }
        for (to, l) in moves.iter().zip(&lines) {
            self.check([to[0], to[1], to[2]])?;
            self.line(l);
        }
        self.printing = true;
        self.at = moves.last().copied();
        Ok(())
    }

    /// Kinematic error of the move `from` → `to` against the planned segment `p0`–`p1`: the
    /// controller's linear interpolation of the joints in steps of the resolutions, each step
    /// transformed back to the part (Isa & Lazoglu 2019, Fig. 16, after Makhanov). Returns the
    /// largest distance, the sum of the distances and the number of steps.
    fn move_error(
        &self,
        from: Joints,
        to: Joints,
        p0: [f64; 3],
        p1: [f64; 3],
    ) -> (f64, f64, usize) {
        let g = self.g;
        let steps = [
            (to[0] - from[0]).abs() / g.resolution_xyz,
            (to[1] - from[1]).abs() / g.resolution_xyz,
            (to[2] - from[2]).abs() / g.resolution_xyz,
            (to[3] - from[3]).abs() / g.resolution_b_deg,
            (to[4] - from[4]).abs() / g.resolution_c_deg,
        ]
        .into_iter()
        .fold(1.0, f64::max)
        .ceil()
        .min(1e6) as usize;
        let (mut worst, mut sum) = (0.0f64, 0.0);
        for k in 1..=steps {
            let f = k as f64 / steps as f64;
            let j: Joints = std::array::from_fn(|i| from[i] + (to[i] - from[i]) * f);
            let (p, _) = forward(j, g, self.offset);
            let d = distance_to_segment(p, p0, p1);
            worst = worst.max(d);
            sum += d;
        }
        (worst, sum, steps)
    }

    fn footer(&mut self) -> Result<(), PostError> {
        self.line("; end");
        self.retract();
        self.line("M104 S0 ; nozzle off");
        self.line("M140 S0 ; bed off");
        if let Some(at) = self.at {
            self.g0_z(at, self.safe_z.max(at[2]).min(self.hi[2]))?;
            let line = format!("G0 B0.0000 F{} ; level the bed", self.travel_f);
            self.line(&line);
        }
        self.line("G28 ; home");
        self.line("M84 ; motors off");
        Ok(())
    }
}

/// `units` hundred-thousandths of a millimetre as fixed-point text with 5 decimals.
fn e_text(units: i64) -> String {
    let sign = if units < 0 { "-" } else { "" };
    let a = units.unsigned_abs();
    format!("{sign}{}.{:05}", a / 100_000, a % 100_000)
}

/// `s` escaped for XML text.
fn xml(s: &str) -> String {
    comment_text(s)
        .replace('&', "&amp;")
        .replace('<', "&lt;")
        .replace('>', "&gt;")
        .replace('"', "&quot;")
}

/// A round tick step (1, 2 or 5 times a power of ten) giving about `count` ticks over `span`.
fn tick_step(span: f64, count: f64) -> f64 {
    let raw = (span / count).max(1e-12);
    let p = 10f64.powf(raw.log10().floor());
    [1.0, 2.0, 5.0, 10.0]
        .into_iter()
        .map(|k| k * p)
        .find(|&s| s >= raw)
        .unwrap_or(10.0 * p)
}

/// Colours of the features' lines, in turn.
const PALETTE: [&str; 8] = [
    "#1f77b4", "#ff7f0e", "#2ca02c", "#9467bd", "#8c564b", "#e377c2", "#17becf", "#bcbd22",
];

/// Points kept in the plot at most; more are merged keeping each bin's largest error.
const PLOT_POINTS: usize = 4000;

/// The kinematic error along the printed path as SVG: x the length along the printed path
/// (mm), y the largest error of each print move (mm), one colour per feature, the goal dashed.
fn error_plot(samples: &[(usize, f64, f64)], goal: f64, source: &str) -> String {
    let (w, h) = (900.0, 420.0);
    let (left, right, top, bottom) = (80.0, 160.0, 40.0, 60.0);
    let (pw, ph) = (w - left - right, h - top - bottom);
    let x_max = samples.last().map_or(0.0, |s| s.1).max(1e-9);
    let y_top = samples.iter().map(|s| s.2).fold(goal, f64::max) * 1.15;
    let sx = |x: f64| left + pw * x / x_max;
    let sy = |y: f64| top + ph * (1.0 - y / y_top);
    let mut o = String::new();
    o.push_str(&format!(
        "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"{w}\" height=\"{h}\" viewBox=\"0 0 {w} {h}\" font-family=\"sans-serif\" font-size=\"12\">\n"
    ));
    o.push_str(&format!(
        "<rect width=\"{w}\" height=\"{h}\" fill=\"white\"/>\n"
    ));
    o.push_str(&format!(
        "<text x=\"{}\" y=\"22\" text-anchor=\"middle\" font-size=\"14\">Kinematic error along the path: {}</text>\n",
        left + pw / 2.0,
        xml(source)
    ));
    // Axes, ticks and grid.
    o.push_str(&format!(
        "<path d=\"M{left} {top} V{} H{}\" stroke=\"black\" fill=\"none\"/>\n",
        top + ph,
        left + pw
    ));
    let xs = tick_step(x_max, 8.0);
    let mut x = 0.0;
    while x <= x_max * (1.0 + 1e-9) {
        let px = sx(x);
        o.push_str(&format!(
            "<line x1=\"{px:.2}\" y1=\"{}\" x2=\"{px:.2}\" y2=\"{}\" stroke=\"black\"/><text x=\"{px:.2}\" y=\"{}\" text-anchor=\"middle\">{}</text>\n",
            top + ph,
            top + ph + 5.0,
            top + ph + 18.0,
            tick_label(x, xs)
        ));
        x += xs;
    }
    let ys = tick_step(y_top, 6.0);
    let mut y = 0.0;
    while y <= y_top * (1.0 + 1e-9) {
        let py = sy(y);
        o.push_str(&format!(
            "<line x1=\"{}\" y1=\"{py:.2}\" x2=\"{}\" y2=\"{py:.2}\" stroke=\"#dddddd\"/><text x=\"{}\" y=\"{:.2}\" text-anchor=\"end\">{}</text>\n",
            left,
            left + pw,
            left - 6.0,
            py + 4.0,
            tick_label(y, ys)
        ));
        y += ys;
    }
    o.push_str(&format!(
        "<text x=\"{}\" y=\"{}\" text-anchor=\"middle\">length along the printed path (mm)</text>\n",
        left + pw / 2.0,
        h - 15.0
    ));
    o.push_str(&format!(
        "<text x=\"20\" y=\"{}\" text-anchor=\"middle\" transform=\"rotate(-90 20 {})\">kinematic error (mm)</text>\n",
        top + ph / 2.0,
        top + ph / 2.0
    ));
    // One polyline per stretch of a feature, thinned to the plot's resolution.
    let bin = x_max / PLOT_POINTS as f64;
    let mut features: Vec<usize> = Vec::new();
    let mut i = 0;
    while i < samples.len() {
        let f = samples[i].0;
        let mut pts: Vec<(f64, f64)> = Vec::new();
        while i < samples.len() && samples[i].0 == f {
            let (_, x, y) = samples[i];
            match pts.last_mut() {
                Some(last)
                    if samples.len() > PLOT_POINTS
                        && (x / bin).floor() == (last.0 / bin).floor() =>
                {
                    if y > last.1 {
                        *last = (x, y);
                    }
                }
                _ => pts.push((x, y)),
            }
            i += 1;
        }
        let slot = features.iter().position(|&g| g == f).unwrap_or_else(|| {
            features.push(f);
            features.len() - 1
        });
        let colour = PALETTE[slot % PALETTE.len()];
        let d: Vec<String> = pts
            .iter()
            .map(|&(x, y)| format!("{:.2},{:.2}", sx(x), sy(y)))
            .collect();
        o.push_str(&format!(
            "<polyline class=\"feature-{f}\" fill=\"none\" stroke=\"{colour}\" stroke-width=\"1.2\" points=\"{}\"/>\n",
            d.join(" ")
        ));
    }
    // The goal.
    let gy = sy(goal);
    o.push_str(&format!(
        "<line class=\"goal\" x1=\"{left}\" y1=\"{gy:.2}\" x2=\"{}\" y2=\"{gy:.2}\" stroke=\"red\" stroke-dasharray=\"6 4\"/><text x=\"{}\" y=\"{:.2}\" fill=\"red\" text-anchor=\"end\">goal {} mm</text>\n",
        left + pw,
        left + pw - 4.0,
        gy - 4.0,
        fixed(goal, 3)
    ));
    // Legend.
    for (k, f) in features.iter().enumerate() {
        let ly = top + 30.0 + 18.0 * k as f64;
        o.push_str(&format!(
            "<line x1=\"{}\" y1=\"{ly:.2}\" x2=\"{}\" y2=\"{ly:.2}\" stroke=\"{}\" stroke-width=\"2\"/><text x=\"{}\" y=\"{:.2}\">feature {f}</text>\n",
            left + pw + 10.0,
            left + pw + 30.0,
            PALETTE[k % PALETTE.len()],
            left + pw + 36.0,
            ly + 4.0
        ));
    }
    o.push_str("</svg>\n");
    o
}

/// A tick value with as many decimals as its step needs.
fn tick_label(v: f64, step: f64) -> String {
    let decimals = (-step.log10().floor()).max(0.0) as usize;
    fixed(v, decimals)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::MachineKind;

    fn geometry() -> Delta5Geometry {
        MachineProfile::builtin(MachineKind::Delta5)
            .delta5
            .expect("the bundled delta5 profile has its table")
    }

    #[test]
    fn forward_inverts_to_machine() {
        let g = geometry();
        let offset = [1.5, -2.0, 3.25];
        for (p, b, c) in [
            ([0.0, 0.0, 0.0], 0.0, 0.0),
            ([10.0, -4.0, 7.0], 35.0, 120.0),
            ([-3.0, 8.0, 20.0], -60.0, -725.0),
        ] {
            let m = to_machine(p, b, c, &g, offset);
            let (back, axis) = forward([m[0], m[1], m[2], b, c], &g, offset);
            assert!(norm(sub(back, p)) < 1e-9, "{back:?} vs {p:?}");
            // The tool axis maps to machine +Z.
            let up = bed_to_machine(axis, b.to_radians(), c.to_radians());
            assert!(norm(sub(up, [0.0, 0.0, 1.0])) < 1e-12, "{up:?}");
        }
    }

    #[test]
    fn inverse_follows_eq_9_to_12() {
        let g = geometry();
        for k in 0..200 {
            let t = k as f64 * 0.7;
            let axis = unit([
                t.cos() * 0.8,
                (1.3 * t).sin() * 0.6,
                0.3 + (t * 0.37).cos().abs(),
            ])
            .unwrap_or([0.0, 0.0, 1.0]);
            let prev = (k % 3 != 0).then_some(t * 40.0 - 500.0);
            let (b, c) = inverse(axis, prev, &g).unwrap_or_else(|| panic!("{axis:?}"));
            let (_, back) = forward([0.0, 0.0, 0.0, b, c], &g, [0.0; 3]);
            assert!(angle_deg(axis, back) < 1e-9, "{axis:?} -> {b} {c}");
            if let Some(p) = prev {
                // Eq. 12: the change of θ is the shortest, at most 90°.
                assert!((c - p).abs() <= 90.0 + 1e-9, "{p} -> {c}");
            } else {
                assert!(b >= 0.0 && c > -180.0 - 1e-9 && c <= 180.0 + 1e-9);
            }
        }
        // The singular point keeps the previous C.
        assert_eq!(inverse([0.0, 0.0, 1.0], Some(33.0), &g), Some((0.0, 33.0)));
        // Beyond the B limits (±90°): refused.
        assert_eq!(inverse([1.0, 0.0, -0.2], None, &g), None);
        assert_eq!(inverse([0.0, 0.0, 0.0], None, &g), None);
    }

    #[test]
    fn e_text_is_fixed_point() {
        assert_eq!(e_text(0), "0.00000");
        assert_eq!(e_text(123_456), "1.23456");
        assert_eq!(e_text(-80_000), "-0.80000");
        assert_eq!(e_text(7), "0.00007");
    }
}
