//! The KUKA robot post: KRL `.src`/`.dat` programs for a 6-axis arm carrying the extruder over
//! a fixed work table.
//!
//! Conventions, used by [`kuka`] and read back by [`crate::krl`]:
//!
//! - **Frames.** `$BASE` is the work table's frame in the robot's base frame (`$WORLD`, with a
//!   null `$ROBROOT`): the profile's `[kuka.base]`, Z up from the table top. The part is placed
//!   on the table by the rule of [`crate::placement::bed_offset`] (XY bounding-box centre on the
//!   table centre, lowest bead bottom on the table top); LIN targets are tool poses in `$BASE`,
//!   part point + offset, and the offset is written in a header comment
//!   `; part offset X.. Y.. Z.. (base = part + offset)`. `$TOOL` is the nozzle tip in the
//!   flange frame (`[kuka.tool]`), with its Z axis along the nozzle, out of the extruder into
//!   the deposit: the tool path's axis (deposit → nozzle) is the tool's −Z.
//! - **Orientation.** KUKA's A, B, C: R = R_z(A)·R_y(B)·R_x(C) (degrees), B within ±90°
//!   ([`abc_from_matrix`]). A and C are unwrapped: each is the value nearest the previous LIN's
//!   (they may leave ±180°), and at gimbal lock (B = ±90°, the tool's X axis along `$BASE` Z)
//!   A keeps its previous value and C takes the rest.
//! - **Rotation about the tool axis.** The axis fixes two angles. At the start of every path
//!   (a travel point, or the first point) the tool's X axis is the horizontal direction from
//!   the nozzle back to the robot's A1 axis, projected onto the plane normal to the tool axis
//!   (so A6 starts near its middle); along the path the frame is carried forward by the
//!   minimal rotation that turns one tool axis into the next (parallel transport), so the
//!   tool never spins about its own axis while printing.
//! - **Travel.** A travel point is visited where a path starts (a print point follows it); the
//!   planner's other travel points (lifts, waypoints) are superseded by this safe travel: from
//!   the end of a path, extruder off, retreat `travel_clearance` along the tool axis, rise
//!   straight up to the travel height (the highest point visited so far within about
//!   [`HEIGHT_CELL`] of the route, plus the clearance; no rise over planar layers), move
//!   across at that height while the orientation turns to the next path's (slerp, at most
//!   [`TRAVEL_ROTATION_STEP_DEG`] per LIN), go down to the approach point (`travel_clearance`
//!   out along the next tool axis) and approach along the axis to the path's first point. The
//!   first approach is a `PTP` from home; the program ends with the same retreat and a rise to
//!   the clearance over the part's top, then `PTP` home. Rising straight up assumes no
//!   material above the retreat point (no printing under an overhang).
//! - **Extruder.** One digital output, on for the LINs that print. With `extruder_switch =
//!   "trigger"` a `TRIGGER WHEN DISTANCE=0 DELAY=0 DO $OUT[n]=...` before the first print LIN
//!   (on) and before the retreat (off) switches it where those motions start, without
//!   stopping the advance run; with `"out"` a plain `$OUT[n]=...` between the motions stops
//!   the robot there (exact stop) and switches. Temperatures and the filament feed are the
//!   extruder controller's; the header states them.
//! - **Files.** `<name>.src` holds header comments (source, machine, part offset, tool and
//!   extruder conventions), the `INI` fold with `BAS (#INITMOV,0 )`, `$BASE`, `$TOOL`,
//!   `$ADVANCE`, `$APO.CDIS`, extruder off and `PTP` home (`DECL AXIS XHOME_PRINT` in
//!   `<name>.dat`), the motions (`$VEL.CP` in m/s where the speed changes, `LIN {X, Y, Z, A,
//!   B, C} C_DIS` per pose), then extruder off and `PTP` home. A program of more than
//!   `max_moves_per_file` motions keeps only the calls in the main program: the motions go to
//!   parts `<name>_p001.src` ... (each with its `.dat`), called in order.
//! - **Reach.** Every pose is checked against the arm model of `[kuka.arm]` (OPW kinematics,
//!   Brandstötter et al. 2014): the flange pose `$BASE · target · $TOOL⁻¹` must have an
//!   inverse-kinematics solution within the joint limits; the solution followed is the one
//!   nearest the previous pose's, in the same configuration when there is one. Unreachable
//!   poses and poses within `wrist_singularity_deg` of a stretched wrist (|A5| small) are
//!   reported ([`KukaFigures`], warnings, and a comment on the LIN), not refused.

use std::collections::BTreeMap;
use std::f64::consts::PI;

use crate::gcode::comment_text;
use crate::placement::bed_offset;
use crate::{MachineProfile, MoveKind, PostError, ToolPath};
use toolpath::fixed;
use toolpath::vec3::{add, cross, dot, norm, scale, sub, V3};

/// Largest orientation change of one LIN of a travel (degrees): a travel that turns the tool
/// further is split into several LINs.
pub const TRAVEL_ROTATION_STEP_DEG: f64 = 5.0;

/// Cell size (mm) of the height map that sets travel heights.
pub const HEIGHT_CELL: f64 = 2.0;

/// Largest deviation of a tool axis's length from 1 accepted (the axis is then normalised).
pub const AXIS_LENGTH_TOLERANCE: f64 = 1e-3;

/// `cos B` below which a rotation is treated as gimbal-locked (B = ±90°).
const GIMBAL_EPS: f64 = 1e-9;

/// Longest KRL name (identifiers and module names).
pub const KRL_NAME_MAX: usize = 24;

/// Name of the home position declared in the main program's `.dat`.
pub const HOME_NAME: &str = "XHOME_PRINT";

// --- profile ------------------------------------------------------------------------------------

/// A KRL frame `{X, Y, Z, A, B, C}`: mm and degrees, orientation R_z(A)·R_y(B)·R_x(C).
#[derive(Debug, Clone, Copy, PartialEq, serde::Deserialize, serde::Serialize)]
#[serde(deny_unknown_fields)]
pub struct KrlFrame {
    /// X (mm).
    #[serde(rename = "X")]
    pub x: f64,
    /// Y (mm).
    #[serde(rename = "Y")]
    pub y: f64,
    /// Z (mm).
    #[serde(rename = "Z")]
    pub z: f64,
    /// Rotation about Z (degrees), applied first.
    #[serde(rename = "A")]
    pub a: f64,
    /// Rotation about the new Y (degrees).
    #[serde(rename = "B")]
    pub b: f64,
    /// Rotation about the new X (degrees).
    #[serde(rename = "C")]
    pub c: f64,
}

impl KrlFrame {
    /// `[X, Y, Z, A, B, C]`.
    pub fn to_array(&self) -> [f64; 6] {
        [self.x, self.y, self.z, self.a, self.b, self.c]
    }

    /// The frame as a pose.
    pub fn pose(&self) -> Pose {
        Pose::from_frame(self.to_array())
    }
}

/// How the extruder's output is switched.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Deserialize, serde::Serialize)]
#[serde(rename_all = "snake_case")]
pub enum ExtruderSwitch {
    /// `$OUT[n] = TRUE/FALSE` between motions (stops the advance run: exact stop there).
    Out,
    /// `TRIGGER WHEN DISTANCE=0 DELAY=0 DO $OUT[n]=...` on the next motion (no stop).
    Trigger,
}

/// A 6-axis arm with an ortho-parallel base and a spherical wrist, in the parameters of
/// Brandstötter, Angerer & Hofbaur 2014 ("An analytical solution of the inverse kinematics
/// problem of industrial serial manipulators with an ortho-parallel basis and a spherical
/// wrist"): lengths in mm, the zero pose with the arm straight up. The controller's joint
/// angle Ai (degrees) and the model's θi are related by θi = Ai·sign_i − offset_i.
#[derive(Debug, Clone, PartialEq, serde::Deserialize, serde::Serialize)]
#[serde(deny_unknown_fields)]
pub struct ArmModel {
    /// Shoulder offset from the A1 axis (mm).
    pub a1: f64,
    /// Elbow offset, perpendicular to the forearm (mm).
    pub a2: f64,
    /// Lateral offset of the arm plane (mm).
    pub b: f64,
    /// Height of the A2 axis above the base (mm).
    pub c1: f64,
    /// Upper arm, A2 to A3 (mm).
    pub c2: f64,
    /// Forearm, A3 to the wrist centre (mm).
    pub c3: f64,
    /// Wrist centre to flange (mm).
    pub c4: f64,
    /// offset_i (degrees).
    pub joint_offsets: [f64; 6],
    /// sign_i, 1 or -1.
    pub joint_signs: [i32; 6],
    /// Lower software limits of A1..A6 (degrees).
    pub joint_min: [f64; 6],
    /// Upper software limits of A1..A6 (degrees).
    pub joint_max: [f64; 6],
}

/// The cell's frames, the arm model and the KRL settings: the `[kuka]` table of a `kuka`
/// machine profile. Every key is documented in `profiles/kuka.toml`.
#[derive(Debug, Clone, PartialEq, serde::Deserialize, serde::Serialize)]
#[serde(deny_unknown_fields)]
pub struct KukaCell {
    /// `$BASE`: the work table's frame in the robot's base frame.
    pub base: KrlFrame,
    /// `$TOOL`: the nozzle tip in the flange frame, Z along the nozzle.
    pub tool: KrlFrame,
    /// Home position A1..A6 (degrees), where the program starts and ends (`PTP`).
    pub home: [f64; 6],
    /// `$VEL.CP` of print moves (m/s); 0 derives it from `print_speed` and
    /// `first_layer_speed`.
    pub print_vel_cp: f64,
    /// `$VEL.CP` of travel moves (m/s); 0 derives it from `travel_speed`.
    pub travel_vel_cp: f64,
    /// `$APO.CDIS`: approximation distance of `C_DIS` (mm).
    pub apo_cdis: f64,
    /// Retreat and approach distance along the tool axis, and the clearance of the travel
    /// height over everything visited so far (mm).
    pub travel_clearance: f64,
    /// Number n of the digital output `$OUT[n]` that runs the extruder.
    pub extruder_output: u32,
    /// How the output is switched.
    pub extruder_switch: ExtruderSwitch,
    /// Most motions per `.src` file; a longer program is split into parts called from the
    /// main program.
    pub max_moves_per_file: usize,
    /// A pose whose wrist bend |A5| is below this (degrees) is reported as near the wrist
    /// singularity.
    pub wrist_singularity_deg: f64,
    /// The arm.
    pub arm: ArmModel,
}

impl KukaCell {
    /// Checks every figure of the table; `name` is the profile's name for the message.
    pub fn validate(&self, name: &str) -> Result<(), PostError> {
        let bad = |field: &'static str, reason: String| PostError::ProfileValue {
            name: name.to_string(),
            field,
            reason,
        };
        for (field, f) in [("kuka.base", &self.base), ("kuka.tool", &self.tool)] {
            let v = f.to_array();
            if let Some(x) = v.iter().find(|x| !x.is_finite()) {
                return Err(bad(field, format!("must hold finite numbers, got {x}")));
            }
            if let Some(x) = v[..3].iter().find(|x| x.abs() > 1e5) {
                return Err(bad(
                    field,
                    format!("X, Y, Z must be within ±100000 mm, got {x}"),
                ));
            }
            if let Some(x) = v[3..].iter().find(|x| x.abs() > 360.0) {
                return Err(bad(field, format!("A, B, C must be within ±360°, got {x}")));
            }
        }
        for (field, v, max) in [
            ("kuka.print_vel_cp", self.print_vel_cp, 3.0),
            ("kuka.travel_vel_cp", self.travel_vel_cp, 3.0),
            ("kuka.apo_cdis", self.apo_cdis, 100.0),
            ("kuka.travel_clearance", self.travel_clearance, 1000.0),
        ] {
            if !(v.is_finite() && (0.0..=max).contains(&v)) {
                return Err(bad(field, format!("must be between 0 and {max}, got {v}")));
            }
        }
        if !(1..=4096).contains(&self.extruder_output) {
            return Err(bad(
                "kuka.extruder_output",
                format!(
                    "must be an output number 1..4096, got {}",
                    self.extruder_output
                ),
            ));
        }
        if !(1..=1_000_000).contains(&self.max_moves_per_file) {
            return Err(bad(
                "kuka.max_moves_per_file",
                format!("must be 1..1000000, got {}", self.max_moves_per_file),
            ));
        }
        let w = self.wrist_singularity_deg;
        if !(w.is_finite() && (0.0..90.0).contains(&w)) {
            return Err(bad(
                "kuka.wrist_singularity_deg",
                format!("must be at least 0 and below 90, got {w}"),
            ));
        }
        self.arm.validate(name)?;
        for (i, &h) in self.home.iter().enumerate() {
            let (lo, hi) = (self.arm.joint_min[i], self.arm.joint_max[i]);
            if !(h.is_finite() && h >= lo && h <= hi) {
                return Err(bad(
                    "kuka.home",
                    format!("A{} = {h} is outside the joint limits {lo}..{hi}", i + 1),
                ));
            }
        }
        Ok(())
    }
}

impl ArmModel {
    /// Checks the lengths, offsets, signs and limits; `name` is the profile's name.
    pub fn validate(&self, name: &str) -> Result<(), PostError> {
        let bad = |field: &'static str, reason: String| PostError::ProfileValue {
            name: name.to_string(),
            field,
            reason,
        };
        for (field, v) in [
            ("kuka.arm.a1", self.a1),
            ("kuka.arm.a2", self.a2),
            ("kuka.arm.b", self.b),
            ("kuka.arm.c1", self.c1),
            ("kuka.arm.c4", self.c4),
        ] {
            if !(v.is_finite() && v.abs() <= 1e5) {
                return Err(bad(
                    field,
                    format!("must be a length within ±100000 mm, got {v}"),
                ));
            }
        }
        for (field, v) in [("kuka.arm.c2", self.c2), ("kuka.arm.c3", self.c3)] {
            if !(v.is_finite() && v > 0.0 && v <= 1e5) {
                return Err(bad(field, format!("must be a positive length, got {v}")));
            }
        }
        if let Some(v) = self
            .joint_offsets
            .iter()
            .find(|v| !(v.is_finite() && v.abs() <= 360.0))
        {
            return Err(bad(
                "kuka.arm.joint_offsets",
                format!("must be within ±360°, got {v}"),
            ));
        }
        if let Some(v) = self.joint_signs.iter().find(|&&v| v != 1 && v != -1) {
            return Err(bad(
                "kuka.arm.joint_signs",
                format!("must be 1 or -1, got {v}"),
            ));
        }
        for i in 0..6 {
            let (lo, hi) = (self.joint_min[i], self.joint_max[i]);
            if !(lo.is_finite() && hi.is_finite() && lo < hi && lo >= -720.0 && hi <= 720.0) {
                return Err(bad(
                    "kuka.arm.joint_min",
                    format!(
                        "A{}: limits must satisfy -720 <= min < max <= 720, got {lo}..{hi}",
                        i + 1
                    ),
                ));
            }
        }
        Ok(())
    }

    fn psi3_k(&self) -> (f64, f64) {
        (self.a2.atan2(self.c3), self.a2.hypot(self.c3))
    }

    /// The model's θ (radians) of controller joint angles `a` (degrees).
    fn theta(&self, a: [f64; 6]) -> [f64; 6] {
        std::array::from_fn(|i| {
            (a[i] * f64::from(self.joint_signs[i]) - self.joint_offsets[i]).to_radians()
        })
    }

    /// Controller joint angles (degrees, within ±180°) of the model's θ (radians).
    fn joints(&self, q: [f64; 6]) -> [f64; 6] {
        std::array::from_fn(|i| {
            wrap180((q[i].to_degrees() + self.joint_offsets[i]) * f64::from(self.joint_signs[i]))
        })
    }

    /// The flange pose in the robot's base frame for joint angles A1..A6 (degrees): the
    /// forward kinematics of Brandstötter et al. 2014 (wrist centre from the arm plane, then
    /// R = R_z(θ1)·R_y(θ2+θ3)·R_z(θ4)·R_y(θ5)·R_z(θ6), flange c4 along its Z).
    pub fn forward(&self, joints: [f64; 6]) -> Pose {
        let q = self.theta(joints);
        let (psi3, k) = self.psi3_k();
        let cx1 = self.c2 * q[1].sin() + k * (q[1] + q[2] + psi3).sin() + self.a1;
        let cz1 = self.c2 * q[1].cos() + k * (q[1] + q[2] + psi3).cos() + self.c1;
        let (s1, c1) = q[0].sin_cos();
        let wrist = [cx1 * c1 - self.b * s1, cx1 * s1 + self.b * c1, cz1];
        let r0c = mul(&rot_z(q[0]), &rot_y(q[1] + q[2]));
        let rce = mul(&mul(&rot_z(q[3]), &rot_y(q[4])), &rot_z(q[5]));
        let r = mul(&r0c, &rce);
        Pose {
            r,
            t: add(wrist, scale(col(&r, 2), self.c4)),
        }
    }

    /// Configuration bits of θ: shoulder (wrist centre in front of A1), elbow (up/down),
    /// wrist (θ5 sign).
    fn config(&self, q: &[f64; 6]) -> u8 {
        let (psi3, k) = self.psi3_k();
        let cx1 = self.c2 * q[1].sin() + k * (q[1] + q[2] + psi3).sin() + self.a1;
        u8::from(cx1 >= 0.0)
            | (u8::from((q[2] + psi3).sin() >= 0.0) << 1)
            | (u8::from(q[4].sin() >= 0.0) << 2)
    }

    /// Every inverse-kinematics solution (up to 8) of a flange pose, as θ (radians) with its
    /// configuration bits, limits not applied.
    fn solutions(&self, flange: &Pose) -> Vec<([f64; 6], u8)> {
        let r = &flange.r;
        let c = sub(flange.t, scale(col(r, 2), self.c4));
        let rho2 = c[0] * c[0] + c[1] * c[1] - self.b * self.b;
        let mut out = Vec::with_capacity(8);
        if rho2.is_nan() || rho2 < 0.0 {
            return out;
        }
        let n = rho2.sqrt();
        let (psi3, k) = self.psi3_k();
        for side in [1.0, -1.0] {
            let cx1 = side * n;
            let q1 = c[1].atan2(c[0]) - self.b.atan2(cx1);
            let (u, v) = (cx1 - self.a1, c[2] - self.c1);
            let cos_phi = (u * u + v * v - self.c2 * self.c2 - k * k) / (2.0 * self.c2 * k);
            if cos_phi.is_nan() || cos_phi.abs() > 1.0 + 1e-12 {
                continue;
            }
            let acos = cos_phi.clamp(-1.0, 1.0).acos();
            for phi in [acos, -acos] {
                let q2 = u.atan2(v) - (k * phi.sin()).atan2(self.c2 + k * phi.cos());
                let q3 = phi - psi3;
                let r0c = mul(&rot_z(q1), &rot_y(q2 + q3));
                let rce = mul(&transpose(&r0c), r);
                // Spherical wrist: rce = R_z(θ4)·R_y(θ5)·R_z(θ6).
                let s5 = rce[0][2].hypot(rce[1][2]);
                let q5 = s5.atan2(rce[2][2]);
                let mut push = |q: [f64; 6]| out.push((q, self.config(&q)));
                if s5 > 1e-12 {
                    let q4 = rce[1][2].atan2(rce[0][2]);
                    let q6 = rce[2][1].atan2(-rce[2][0]);
                    push([q1, q2, q3, q4, q5, q6]);
                    push([q1, q2, q3, q4 + PI, -q5, q6 - PI]);
                } else if rce[2][2] > 0.0 {
                    push([q1, q2, q3, 0.0, q5, rce[1][0].atan2(rce[0][0])]);
                } else {
                    push([q1, q2, q3, 0.0, q5, rce[1][0].atan2(-rce[0][0])]);
                }
                if acos == 0.0 {
                    break;
                }
            }
        }
        out
    }

    /// Every inverse-kinematics solution of a flange pose (robot base frame) as joint angles
    /// A1..A6 in degrees, each within ±180° (joint limits not applied): up to 8, from the
    /// shoulder, elbow and wrist choices.
    pub fn inverse(&self, flange: &Pose) -> Vec<[f64; 6]> {
        self.solutions(flange)
            .into_iter()
            .map(|(q, _)| self.joints(q))
            .collect()
    }

    /// Whether every joint is within its limits.
    pub fn within_limits(&self, joints: &[f64; 6]) -> bool {
        (0..6).all(|i| joints[i] >= self.joint_min[i] && joints[i] <= self.joint_max[i])
    }

    /// The solution within the joint limits nearest `near` (sum of absolute joint
    /// differences, each joint taken ±360° where its range allows), preferring configuration
    /// `keep` when given; `None` when the pose is out of reach or every solution breaks a
    /// limit. Returns the joints and the configuration bits.
    pub fn nearest(
        &self,
        flange: &Pose,
        near: &[f64; 6],
        keep: Option<u8>,
    ) -> Option<([f64; 6], u8)> {
        let mut best: Option<(f64, [f64; 6], u8)> = None;
        for (q, config) in self.solutions(flange) {
            let base = self.joints(q);
            let mut joints = [0.0; 6];
            let mut cost = 0.0;
            let mut ok = true;
            for i in 0..6 {
                let pick = (-2..=2)
                    .map(|m| base[i] + 360.0 * f64::from(m))
                    .filter(|v| *v >= self.joint_min[i] && *v <= self.joint_max[i])
                    .min_by(|a, b| (a - near[i]).abs().total_cmp(&(b - near[i]).abs()));
                match pick {
                    Some(v) => {
                        joints[i] = v;
                        cost += (v - near[i]).abs();
                    }
                    None => ok = false,
                }
            }
            if !ok {
                continue;
            }
            if keep.is_some_and(|k| k != config) {
                cost += 1e6;
            }
            if best.as_ref().is_none_or(|b| cost < b.0) {
                best = Some((cost, joints, config));
            }
        }
        best.map(|(_, j, c)| (j, c))
    }

    /// The wrist bend (degrees, 0..180) of joint angles: 0 (or 180) is the wrist singularity,
    /// A4 and A6 turning about one line.
    pub fn wrist_bend(&self, joints: &[f64; 6]) -> f64 {
        wrap180(self.theta(*joints)[4].to_degrees()).abs()
    }

    /// Configuration bits of joint angles (shoulder, elbow, wrist).
    pub fn configuration(&self, joints: &[f64; 6]) -> u8 {
        self.config(&self.theta(*joints))
    }
}

// --- rotations and poses ------------------------------------------------------------------------

/// A rotation matrix, rows: `r[i][j]` is row i, column j; column j is the rotated frame's
/// j-th axis.
pub type Mat3 = [[f64; 3]; 3];

const IDENTITY: Mat3 = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];

fn mul(a: &Mat3, b: &Mat3) -> Mat3 {
    std::array::from_fn(|i| std::array::from_fn(|j| (0..3).map(|k| a[i][k] * b[k][j]).sum()))
}

fn transpose(a: &Mat3) -> Mat3 {
    std::array::from_fn(|i| std::array::from_fn(|j| a[j][i]))
}

fn apply(a: &Mat3, v: V3) -> V3 {
    std::array::from_fn(|i| a[i][0] * v[0] + a[i][1] * v[1] + a[i][2] * v[2])
}

fn col(a: &Mat3, j: usize) -> V3 {
    [a[0][j], a[1][j], a[2][j]]
}

fn from_cols(x: V3, y: V3, z: V3) -> Mat3 {
    [[x[0], y[0], z[0]], [x[1], y[1], z[1]], [x[2], y[2], z[2]]]
}

fn rot_x(t: f64) -> Mat3 {
    let (s, c) = t.sin_cos();
    [[1.0, 0.0, 0.0], [0.0, c, -s], [0.0, s, c]]
}

fn rot_y(t: f64) -> Mat3 {
    let (s, c) = t.sin_cos();
    [[c, 0.0, s], [0.0, 1.0, 0.0], [-s, 0.0, c]]
}

fn rot_z(t: f64) -> Mat3 {
    let (s, c) = t.sin_cos();
    [[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]]
}

/// `x` wrapped to (−180, 180].
fn wrap180(x: f64) -> f64 {
    let w = x - 360.0 * (x / 360.0).round();
    if w <= -180.0 {
        w + 360.0
    } else {
        w
    }
}

/// `x` plus the multiple of 360 that brings it nearest `target`.
fn unwrap_near(x: f64, target: f64) -> f64 {
    x + 360.0 * ((target - x) / 360.0).round()
}

/// KUKA's orientation: R = R_z(A)·R_y(B)·R_x(C), angles in degrees.
pub fn matrix_from_abc(abc: [f64; 3]) -> Mat3 {
    let [a, b, c] = abc.map(f64::to_radians);
    mul(&mul(&rot_z(a), &rot_y(b)), &rot_x(c))
}

/// KUKA's A, B, C (degrees) of a rotation matrix, the inverse of [`matrix_from_abc`]: B within
/// ±90°; A and C unwrapped to the values nearest `previous`'s A and C (so they never jump by
/// ±360°). At gimbal lock (B = ±90°: only C − A or C + A is defined) A keeps `previous`'s
/// value (0 without one) and C takes the rest.
pub fn abc_from_matrix(r: &Mat3, previous: Option<[f64; 3]>) -> [f64; 3] {
    let cb = r[0][0].hypot(r[1][0]);
    let b = (-r[2][0]).atan2(cb).to_degrees();
    let (a, c) = if cb < GIMBAL_EPS {
        let a = previous.map_or(0.0, |p| p[0]);
        let ar = a.to_radians();
        let c = if r[2][0] < 0.0 {
            // B = +90°: r01 = sin(C − A), r11 = cos(C − A).
            ar + r[0][1].atan2(r[1][1])
        } else {
            // B = −90°: r01 = −sin(A + C), r11 = cos(A + C).
            (-r[0][1]).atan2(r[1][1]) - ar
        };
        (a, c.to_degrees())
    } else {
        (
            r[1][0].atan2(r[0][0]).to_degrees(),
            r[2][1].atan2(r[2][2]).to_degrees(),
        )
    };
    match previous {
        Some(p) => [unwrap_near(a, p[0]), b, unwrap_near(c, p[2])],
        None => [a, b, c],
    }
}

/// The angle (degrees) of the rotation that turns `a` into `b`.
pub fn rotation_angle_deg(a: &Mat3, b: &Mat3) -> f64 {
    angle_of(&mul(&transpose(a), b)).0.to_degrees()
}

/// The rotation angle (radians, from atan2, so exact near 0 and π) of a rotation matrix, and
/// its skew part `w` = 2·sin(angle)·axis.
fn angle_of(r: &Mat3) -> (f64, V3) {
    let w = [r[2][1] - r[1][2], r[0][2] - r[2][0], r[1][0] - r[0][1]];
    let cos = (r[0][0] + r[1][1] + r[2][2] - 1.0) / 2.0;
    ((norm(w) / 2.0).atan2(cos), w)
}

/// Rotation vector (axis · angle, radians) of a rotation matrix.
fn log_rot(r: &Mat3) -> V3 {
    let (angle, w) = angle_of(r);
    if angle < 1e-9 {
        return scale(w, 0.5);
    }
    if angle > PI - 1e-6 {
        // Near a half turn: the axis from the symmetric part, its sign from `w`.
        let i = (0..3)
            .max_by(|&i, &j| r[i][i].total_cmp(&r[j][j]))
            .unwrap_or(0);
        let ai = ((r[i][i] + 1.0) / 2.0).max(0.0).sqrt();
        let mut axis = [0.0; 3];
        for (j, v) in axis.iter_mut().enumerate() {
            *v = if j == i {
                ai
            } else {
                (r[i][j] + r[j][i]) / (4.0 * ai)
            };
        }
        let n = norm(axis);
        let mut axis = scale(axis, 1.0 / n);
        if dot(axis, w) < 0.0 {
            axis = scale(axis, -1.0);
        }
        return scale(axis, angle);
    }
    scale(w, angle / (2.0 * angle.sin()))
}

/// Rotation matrix of a rotation vector (Rodrigues).
fn exp_rot(v: V3) -> Mat3 {
    let angle = norm(v);
    if angle < 1e-15 {
        return IDENTITY;
    }
    let k = scale(v, 1.0 / angle);
    let (s, c) = angle.sin_cos();
    let t = 1.0 - c;
    [
        [
            c + k[0] * k[0] * t,
            k[0] * k[1] * t - k[2] * s,
            k[0] * k[2] * t + k[1] * s,
        ],
        [
            k[1] * k[0] * t + k[2] * s,
            c + k[1] * k[1] * t,
            k[1] * k[2] * t - k[0] * s,
        ],
        [
            k[2] * k[0] * t - k[1] * s,
            k[2] * k[1] * t + k[0] * s,
            c + k[2] * k[2] * t,
        ],
    ]
}

/// The frame with Z axis `z` (unit) whose X axis is `x_hint` made normal to it; `None` when
/// `x_hint` is (nearly) along `z`.
fn frame_from_zx(z: V3, x_hint: V3, min_len: f64) -> Option<Mat3> {
    let x = sub(x_hint, scale(z, dot(x_hint, z)));
    let n = norm(x);
    if n.is_nan() || n < min_len {
        return None;
    }
    let x = scale(x, 1.0 / n);
    Some(from_cols(x, cross(z, x), z))
}

/// The frame `r` carried to the new Z axis `z` by the minimal rotation that turns its Z into
/// `z` (parallel transport): the rotation about the new axis stays continuous.
fn transport(r: &Mat3, z: V3) -> Mat3 {
    let (z0, x0) = (col(r, 2), col(r, 0));
    let c = cross(z0, z);
    let s = norm(c);
    let d = dot(z0, z);
    let turn = if s < 1e-12 {
        if d > 0.0 {
            IDENTITY
        } else {
            // Reversed axis: the half turn about the frame's own X.
            exp_rot(scale(x0, PI))
        }
    } else {
        exp_rot(scale(c, s.atan2(d) / s))
    };
    let x = apply(&turn, x0);
    frame_from_zx(z, x, 1e-9).unwrap_or(*r)
}

/// A rigid transform: rotation `r` then translation `t` (mm).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Pose {
    /// Orientation.
    pub r: Mat3,
    /// Position (mm).
    pub t: [f64; 3],
}

impl Pose {
    /// The identity.
    pub const IDENTITY: Pose = Pose {
        r: IDENTITY,
        t: [0.0; 3],
    };

    /// The pose of a KRL frame `[X, Y, Z, A, B, C]`.
    pub fn from_frame(f: [f64; 6]) -> Pose {
        Pose {
            r: matrix_from_abc([f[3], f[4], f[5]]),
            t: [f[0], f[1], f[2]],
        }
    }

    /// The KRL frame of the pose, A and C unwrapped against `previous` ([`abc_from_matrix`]).
    pub fn to_frame(&self, previous: Option<[f64; 3]>) -> [f64; 6] {
        let [a, b, c] = abc_from_matrix(&self.r, previous);
        [self.t[0], self.t[1], self.t[2], a, b, c]
    }

    /// `self · other`: `other` expressed in `self`'s frame, as KRL's `:` operator.
    pub fn compose(&self, other: &Pose) -> Pose {
        Pose {
            r: mul(&self.r, &other.r),
            t: add(apply(&self.r, other.t), self.t),
        }
    }

    /// The inverse transform.
    pub fn inverse(&self) -> Pose {
        let rt = transpose(&self.r);
        Pose {
            t: scale(apply(&rt, self.t), -1.0),
            r: rt,
        }
    }

    /// A point of this frame in the parent frame.
    pub fn apply(&self, p: [f64; 3]) -> [f64; 3] {
        add(apply(&self.r, p), self.t)
    }

    /// The frame's Z axis in the parent frame.
    pub fn z_axis(&self) -> [f64; 3] {
        col(&self.r, 2)
    }
}

// --- the program --------------------------------------------------------------------------------

/// What the post found for one feature's points.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct KukaFigures {
    /// Path points of the feature.
    pub points: usize,
    /// Motions (LIN, and the first PTP) written for them, travel moves included.
    pub moves: usize,
    /// Points with a pose out of the arm's reach or joint limits.
    pub unreachable_points: usize,
    /// Points with a pose within `wrist_singularity_deg` of the wrist singularity.
    pub wrist_singular_points: usize,
    /// Index (in the tool path) of the first unreachable point.
    pub first_unreachable: Option<usize>,
    /// Index of the first point near the wrist singularity.
    pub first_wrist_singular: Option<usize>,
    /// Smallest wrist bend |A5| over the reachable poses (degrees).
    pub min_wrist_bend_deg: Option<f64>,
    /// Motions on which the arm would have to change configuration (shoulder, elbow or wrist
    /// flip), which a LIN cannot do.
    pub configuration_changes: usize,
    /// Motions on which A or C turns by more than 90°: the tool's X axis passes through (or
    /// close by) `$BASE` Z, the gimbal lock, where A and C turn by about 180° because B stays
    /// within ±90°.
    pub gimbal_crossings: usize,
}

/// A KRL program: the files, what the reach check found per feature, and warnings.
#[derive(Debug, Clone, PartialEq)]
pub struct KrlProgram {
    /// `(file name, text)`: the main `<name>.src` and `<name>.dat` first, then the parts
    /// `<name>_p001.src`, `<name>_p001.dat`, ... when the program is split.
    pub files: Vec<(String, String)>,
    /// Per feature id.
    pub figures: BTreeMap<usize, KukaFigures>,
    /// One line each: the part overhanging the table, unreachable points, wrist
    /// singularities, configuration changes, gimbal crossings.
    pub warnings: Vec<String>,
}

/// One step of the program, in order.
#[derive(Debug, Clone)]
enum Step {
    Comment(String),
    /// `$VEL.CP` (m/s).
    Vel(f64),
    Extruder(bool),
    /// A motion to a tool pose in `$BASE`, for path point `point`.
    Move {
        ptp: bool,
        pose: Pose,
        point: usize,
    },
}

/// A KRL program for the path, with every pose checked against the arm model.
///
/// `program_name` becomes the module name, made a KRL identifier by [`krl_name`]; `source`
/// (the STEP file's name) is written in the header. See the module documentation for the
/// frames, orientation, travel and extruder conventions.
///
/// Errors: the profile is not a `kuka` profile or is invalid, a point holds a NaN or infinite
/// number, or a tool axis is not a unit vector (within [`AXIS_LENGTH_TOLERANCE`]). Points the
/// arm cannot reach, and poses near the wrist singularity, are reported in
/// [`KrlProgram::figures`] and [`KrlProgram::warnings`] and marked on their LIN; so is a part
/// larger than the table (`bed_size`).
pub fn kuka(
    path: &ToolPath,
    m: &MachineProfile,
    program_name: &str,
    source: &str,
) -> Result<KrlProgram, PostError> {
    let cell = m.kuka_table()?;
    path.check_finite()?;
    let mut axes = Vec::with_capacity(path.points.len());
    for (index, q) in path.points.iter().enumerate() {
        let n = norm(q.axis);
        if n.is_nan() || (n - 1.0).abs() > AXIS_LENGTH_TOLERANCE {
            return Err(PostError::KukaAxisNotUnit {
                index,
                feature: q.feature,
                i: q.axis[0],
                j: q.axis[1],
                k: q.axis[2],
            });
        }
        axes.push(scale(q.axis, 1.0 / n));
    }
    let mut warnings = Vec::new();
    let offset = placement(path, m, &mut warnings)?;
    let base = cell.base.pose();
    let steps = plan_motion(path, &axes, offset, m, cell, &base);
    let checked = check(path, &steps, cell, &base, &mut warnings);
    let files = write_files(
        path,
        m,
        cell,
        &steps,
        &checked,
        offset,
        program_name,
        source,
    );
    Ok(KrlProgram {
        files,
        figures: checked.figures,
        warnings,
    })
}

/// The part offset (part + offset = `$BASE` coordinates): [`bed_offset`]'s placement; a part
/// larger than the table is placed the same way, with a warning.
fn placement(
    path: &ToolPath,
    m: &MachineProfile,
    warnings: &mut Vec<String>,
) -> Result<[f64; 3], PostError> {
    match bed_offset(path, m) {
        Ok(o) => Ok(o),
        Err(e @ PostError::DoesNotFit { .. }) => {
            warnings.push(format!("{e} (written anyway: the arm's reach decides)"));
            let mut open = m.clone();
            open.bed_origin_centre = true;
            open.bed_size = [f64::INFINITY; 3];
            let o = bed_offset(path, &open)?;
            let shift = if m.bed_origin_centre {
                [0.0, 0.0]
            } else {
                [m.bed_size[0] / 2.0, m.bed_size[1] / 2.0]
            };
            Ok([o[0] + shift[0], o[1] + shift[1], o[2]])
        }
        Err(e) => Err(e),
    }
}

/// The motions of the program: travels, print moves, speeds and extruder switching.
fn plan_motion(
    path: &ToolPath,
    axes: &[V3],
    offset: [f64; 3],
    m: &MachineProfile,
    cell: &KukaCell,
    base: &Pose,
) -> Vec<Step> {
    let (print_v, first_v) = if cell.print_vel_cp > 0.0 {
        (
            cell.print_vel_cp,
            cell.print_vel_cp * m.first_layer_speed / m.print_speed,
        )
    } else {
        (m.print_speed / 1000.0, m.first_layer_speed / 1000.0)
    };
    let travel_v = if cell.travel_vel_cp > 0.0 {
        cell.travel_vel_cp
    } else {
        m.travel_speed / 1000.0
    };
    let mut w = Motion {
        steps: Vec::new(),
        vel: None,
        on: false,
        clearance: cell.travel_clearance,
        z_top: f64::NEG_INFINITY,
        height: HeightMap {
            cell: HEIGHT_CELL,
            z: Default::default(),
        },
    };
    let (mut layer, mut feature) = (None, None);
    let mut cur: Option<(Pose, usize)> = None;
    for (i, q) in path.points.iter().enumerate() {
        let p = add(q.p, offset);
        let z = scale(axes[i], -1.0);
        w.z_top = w.z_top.max(p[2]);
        // A travel point goes only where a path starts (a print point follows): the
        // planner's other travel points (lifts, waypoints) are superseded by the safe travel.
        let starts_path = path
            .points
            .get(i + 1)
            .is_some_and(|n| n.kind == MoveKind::Print);
        if q.kind == MoveKind::Travel && !starts_path {
            continue;
        }
        if layer != Some(q.layer) || feature != Some(q.feature) {
            layer = Some(q.layer);
            feature = Some(q.feature);
            w.steps.push(Step::Comment(format!(
                "FEATURE {} LAYER {}",
                q.feature, q.layer
            )));
        }
        let next = match (q.kind, cur) {
            (MoveKind::Print, Some((prev, _))) => {
                let pose = Pose {
                    r: transport(&prev.r, z),
                    t: p,
                };
                // A print move that goes nowhere (the nozzle is already there) is dropped,
                // with its switching. Speed first: a TRIGGER goes right before its motion.
                if w.goes_nowhere(&pose) {
                    cur = Some((pose, i));
                    continue;
                }
                let on_plate = p[2] - q.thickness.max(0.0) <= 0.01;
                w.vel(if on_plate { first_v } else { print_v });
                if !w.on {
                    w.extruder(true);
                }
                w.motion(false, pose, i);
                pose
            }
            _ => {
                let pose = Pose {
                    r: start_frame(z, p, base),
                    t: p,
                };
                w.travel(cur.map(|c| c.0), pose, i, travel_v);
                pose
            }
        };
        // The bead just laid (or the path's start) is material the travels must clear.
        match (q.kind, cur) {
            (MoveKind::Print, Some((prev, _))) => w.height.add_segment(prev.t, p),
            _ => w.height.add(p),
        }
        cur = Some((next, i));
    }
    if let Some((end, i)) = cur {
        w.leave(&end, i, travel_v);
    }
    w.steps
}

/// The highest point visited so far over each cell of a square grid of the table (`$BASE`
/// X, Y), for travel heights.
struct HeightMap {
    cell: f64,
    z: std::collections::HashMap<(i64, i64), f64>,
}

impl HeightMap {
    fn key(&self, x: f64, y: f64) -> (i64, i64) {
        (
            (x / self.cell).floor() as i64,
            (y / self.cell).floor() as i64,
        )
    }

    fn add(&mut self, p: V3) {
        let k = self.key(p[0], p[1]);
        let z = self.z.entry(k).or_insert(f64::NEG_INFINITY);
        *z = z.max(p[2]);
    }

    /// Every point of the segment from `a` to `b`, sampled at half a cell.
    fn add_segment(&mut self, a: V3, b: V3) {
        let len = (b[0] - a[0]).hypot(b[1] - a[1]);
        let n = ((2.0 * len / self.cell).ceil() as usize).clamp(1, 1_000_000);
        for k in 0..=n {
            let t = k as f64 / n as f64;
            self.add(add(scale(a, 1.0 - t), scale(b, t)));
        }
    }

    /// The highest point visited within about a cell of the XY segment from `a` to `b`
    /// (−∞ when none).
    fn max_along(&self, a: V3, b: V3) -> f64 {
        let len = (b[0] - a[0]).hypot(b[1] - a[1]);
        let n = ((2.0 * len / self.cell).ceil() as usize).clamp(1, 1_000_000);
        let mut top = f64::NEG_INFINITY;
        let mut last = None;
        for k in 0..=n {
            let t = k as f64 / n as f64;
            let (cx, cy) = self.key(a[0] + t * (b[0] - a[0]), a[1] + t * (b[1] - a[1]));
            if last == Some((cx, cy)) {
                continue;
            }
            last = Some((cx, cy));
            for dx in -1..=1 {
                for dy in -1..=1 {
                    if let Some(z) = self.z.get(&(cx + dx, cy + dy)) {
                        top = top.max(*z);
                    }
                }
            }
        }
        top
    }
}

/// The tool frame at the start of a path: Z along `z` (unit, `$BASE`), X the horizontal
/// direction from the nozzle at `p` back to the robot's A1 axis made normal to Z (or, when
/// the tool points along that direction, the horizontal normal to it).
fn start_frame(z: V3, p: V3, base: &Pose) -> Mat3 {
    let world = base.apply(p);
    let back = [-world[0], -world[1], 0.0];
    let back = if norm(back) < 1.0 {
        [-1.0, 0.0, 0.0]
    } else {
        scale(back, 1.0 / norm(back))
    };
    let to_base = transpose(&base.r);
    let d = apply(&to_base, back);
    let side = apply(&to_base, cross([0.0, 0.0, 1.0], back));
    frame_from_zx(z, d, 0.2)
        .or_else(|| frame_from_zx(z, side, 1e-6))
        .or_else(|| frame_from_zx(z, [1.0, 0.0, 0.0], 1e-6))
        .or_else(|| frame_from_zx(z, [0.0, 1.0, 0.0], 1e-6))
        .unwrap_or(IDENTITY)
}

/// The steps being planned and the state they leave.
struct Motion {
    steps: Vec<Step>,
    vel: Option<f64>,
    on: bool,
    clearance: f64,
    /// Highest point of the path so far ($BASE Z, mm).
    z_top: f64,
    /// The points visited so far.
    height: HeightMap,
}

impl Motion {
    fn vel(&mut self, v: f64) {
        if self.vel != Some(v) {
            self.vel = Some(v);
            self.steps.push(Step::Vel(v));
        }
    }

    fn extruder(&mut self, on: bool) {
        self.on = on;
        self.steps.push(Step::Extruder(on));
    }

    /// Whether `pose` is the previous motion's (within 1e-9 mm and 1e-9°).
    fn goes_nowhere(&self, pose: &Pose) -> bool {
        let last = self.steps.iter().rev().find_map(|s| match s {
            Step::Move { pose, .. } => Some(*pose),
            _ => None,
        });
        last.is_some_and(|last| {
            norm(sub(last.t, pose.t)) < 1e-9 && rotation_angle_deg(&last.r, &pose.r) < 1e-9
        })
    }

    /// A motion, unless it would go nowhere.
    fn motion(&mut self, ptp: bool, pose: Pose, point: usize) {
        if !self.goes_nowhere(&pose) {
            self.steps.push(Step::Move { ptp, pose, point });
        }
    }

    /// Travel speed, extruder off, and back off `from` along the tool axis by the clearance;
    /// returns where it backed off to.
    fn retreat(&mut self, from: &Pose, point: usize, travel_v: f64) -> [f64; 3] {
        self.vel(travel_v);
        if self.on {
            self.extruder(false);
        }
        let retreat = add(from.t, scale(col(&from.r, 2), -self.clearance));
        self.motion(
            false,
            Pose {
                r: from.r,
                t: retreat,
            },
            point,
        );
        retreat
    }

    /// Travel from `cur` (or from home) to the path start `to` (point `point`).
    fn travel(&mut self, cur: Option<Pose>, to: Pose, point: usize, travel_v: f64) {
        let c = self.clearance;
        let approach = add(to.t, scale(col(&to.r, 2), -c));
        let Some(from) = cur else {
            self.vel(travel_v);
            self.motion(
                true,
                Pose {
                    r: to.r,
                    t: approach,
                },
                point,
            );
            self.motion(false, to, point);
            return;
        };
        let retreat = self.retreat(&from, point, travel_v);
        let h = (self.height.max_along(retreat, approach) + c)
            .max(retreat[2])
            .max(approach[2]);
        let up = [retreat[0], retreat[1], h];
        self.motion(false, Pose { r: from.r, t: up }, point);
        let over = [approach[0], approach[1], h];
        let turn = log_rot(&mul(&transpose(&from.r), &to.r));
        let angle = norm(turn).to_degrees();
        let n = ((angle / TRAVEL_ROTATION_STEP_DEG).ceil() as usize).max(1);
        for k in 1..=n {
            let t = k as f64 / n as f64;
            let pose = if k == n {
                Pose { r: to.r, t: over }
            } else {
                Pose {
                    r: mul(&from.r, &exp_rot(scale(turn, t))),
                    t: add(scale(up, 1.0 - t), scale(over, t)),
                }
            };
            self.motion(false, pose, point);
        }
        self.motion(
            false,
            Pose {
                r: to.r,
                t: approach,
            },
            point,
        );
        self.motion(false, to, point);
    }

    /// The end: extruder off, retreat along the tool axis and rise to the safe height.
    fn leave(&mut self, from: &Pose, point: usize, travel_v: f64) {
        let c = self.clearance;
        let retreat = self.retreat(from, point, travel_v);
        let h = (self.z_top + c).max(retreat[2]);
        self.motion(
            false,
            Pose {
                r: from.r,
                t: [retreat[0], retreat[1], h],
            },
            point,
        );
    }
}

/// What the reach check found, per motion and per feature.
struct Checked {
    /// Per `Step::Move`, in order: the KRL frame written.
    frames: Vec<[f64; 6]>,
    /// Per `Step::Move`: a note for the LIN's comment, if any.
    notes: Vec<Option<&'static str>>,
    figures: BTreeMap<usize, KukaFigures>,
}

/// Euler angles (unwrapped along the program) and the reach check of every motion.
fn check(
    path: &ToolPath,
    steps: &[Step],
    cell: &KukaCell,
    base: &Pose,
    warnings: &mut Vec<String>,
) -> Checked {
    let arm = &cell.arm;
    let tool_inv = cell.tool.pose().inverse();
    let n = path.points.len();
    let mut unreachable = vec![false; n];
    let mut singular = vec![false; n];
    let mut figures: BTreeMap<usize, KukaFigures> = BTreeMap::new();
    for q in &path.points {
        figures.entry(q.feature).or_default().points += 1;
    }
    let mut frames = Vec::new();
    let mut notes = Vec::new();
    let mut prev_abc: Option<[f64; 3]> = None;
    let mut joints = cell.home;
    let mut config = Some(arm.configuration(&cell.home));
    for step in steps {
        let Step::Move { pose, point, .. } = step else {
            continue;
        };
        let feature = path.points[*point].feature;
        let fig = figures.entry(feature).or_default();
        fig.moves += 1;
        let f = pose.to_frame(prev_abc);
        if let Some(p) = prev_abc {
            if (f[3] - p[0]).abs() > 90.0 || (f[5] - p[2]).abs() > 90.0 {
                fig.gimbal_crossings += 1;
            }
        }
        prev_abc = Some([f[3], f[4], f[5]]);
        frames.push(f);
        let flange = base.compose(pose).compose(&tool_inv);
        let note = match arm.nearest(&flange, &joints, config) {
            None => {
                unreachable[*point] = true;
                if fig.first_unreachable.is_none_or(|i| *point < i) {
                    fig.first_unreachable = Some(*point);
                }
                Some("UNREACHABLE")
            }
            Some((j, c)) => {
                if config.is_some_and(|k| k != c) {
                    fig.configuration_changes += 1;
                }
                joints = j;
                config = Some(c);
                let bend = arm.wrist_bend(&j);
                let bend = bend.min(180.0 - bend);
                fig.min_wrist_bend_deg = Some(fig.min_wrist_bend_deg.map_or(bend, |b| b.min(bend)));
                if bend < cell.wrist_singularity_deg {
                    singular[*point] = true;
                    if fig.first_wrist_singular.is_none_or(|i| *point < i) {
                        fig.first_wrist_singular = Some(*point);
                    }
                    Some("WRIST SINGULAR")
                } else {
                    None
                }
            }
        };
        notes.push(note);
    }
    for (i, q) in path.points.iter().enumerate() {
        if let Some(fig) = figures.get_mut(&q.feature) {
            fig.unreachable_points += usize::from(unreachable[i]);
            fig.wrist_singular_points += usize::from(singular[i]);
        }
    }
    let at = |i: usize| {
        let p = path.points[i].p;
        format!(
            "point {i} (part X{} Y{} Z{})",
            fixed(p[0], 3),
            fixed(p[1], 3),
            fixed(p[2], 3)
        )
    };
    for (id, fig) in &figures {
        if let Some(i) = fig.first_unreachable {
            warnings.push(format!(
                "feature {id}: {} of {} points out of the arm's reach or joint limits, first at {}",
                fig.unreachable_points,
                fig.points,
                at(i)
            ));
        }
        if let Some(i) = fig.first_wrist_singular {
            warnings.push(format!(
                "feature {id}: {} points within {}° of the wrist singularity (|A5| small), first at {}",
                fig.wrist_singular_points,
                fixed(cell.wrist_singularity_deg, 1),
                at(i)
            ));
        }
        if fig.configuration_changes > 0 {
            warnings.push(format!(
                "feature {id}: the arm changes configuration on {} motions (a LIN cannot)",
                fig.configuration_changes
            ));
        }
        if fig.gimbal_crossings > 0 {
            warnings.push(format!(
                "feature {id}: the tool's X axis passes through or near $BASE Z on {} motions: A or C turns by more than 90° there (B stays within ±90°)",
                fig.gimbal_crossings
            ));
        }
    }
    Checked {
        frames,
        notes,
        figures,
    }
}

/// `s` as a KRL identifier of at most `max` characters: ASCII letters, digits and `_`
/// (others become `_`), starting with a letter, lower case, not a KRL keyword; `features`
/// when nothing is left.
pub fn krl_name(s: &str, max: usize) -> String {
    let mut name: String = s
        .chars()
        .map(|c| {
            if c.is_ascii_alphanumeric() || c == '_' {
                c.to_ascii_lowercase()
            } else {
                '_'
            }
        })
        .collect();
    if name.trim_matches('_').is_empty() {
        name = "features".into();
    }
    if !name.starts_with(|c: char| c.is_ascii_alphabetic()) {
        name.insert_str(0, "p_");
    }
    const KEYWORDS: &[&str] = &[
        "and",
        "anin",
        "anout",
        "axis",
        "b_and",
        "b_exor",
        "b_not",
        "b_or",
        "bool",
        "brake",
        "c_dis",
        "c_ori",
        "c_ptp",
        "c_vel",
        "case",
        "char",
        "circ",
        "circ_rel",
        "const",
        "continue",
        "decl",
        "def",
        "default",
        "defdat",
        "deffct",
        "delay",
        "distance",
        "do",
        "e6axis",
        "e6pos",
        "else",
        "end",
        "enddat",
        "endfct",
        "endfor",
        "endif",
        "endloop",
        "endswitch",
        "endwhile",
        "enum",
        "exit",
        "exor",
        "ext",
        "extfct",
        "false",
        "for",
        "frame",
        "global",
        "goto",
        "halt",
        "if",
        "import",
        "int",
        "interrupt",
        "is",
        "lin",
        "lin_rel",
        "loop",
        "main",
        "not",
        "or",
        "pos",
        "prio",
        "ptp",
        "ptp_rel",
        "public",
        "pulse",
        "real",
        "repeat",
        "resume",
        "return",
        "sec",
        "signal",
        "struc",
        "switch",
        "then",
        "to",
        "trigger",
        "true",
        "until",
        "wait",
        "when",
        "while",
        "xhome_print",
    ];
    if KEYWORDS.contains(&name.as_str()) {
        name.push_str("_prg");
    }
    name.truncate(max.max(1));
    name
}

/// A KRL frame aggregate `{X .., Y .., Z .., A .., B .., C ..}`: mm with 3 decimals, degrees
/// with 4.
pub fn frame_text(f: &[f64; 6]) -> String {
    format!(
        "{{X {}, Y {}, Z {}, A {}, B {}, C {}}}",
        fixed(f[0], 3),
        fixed(f[1], 3),
        fixed(f[2], 3),
        fixed(f[3], 4),
        fixed(f[4], 4),
        fixed(f[5], 4)
    )
}

/// The `.src` and `.dat` files.
#[allow(clippy::too_many_arguments)]
fn write_files(
    path: &ToolPath,
    m: &MachineProfile,
    cell: &KukaCell,
    steps: &[Step],
    checked: &Checked,
    offset: [f64; 3],
    program_name: &str,
    source: &str,
) -> Vec<(String, String)> {
    let out = cell.extruder_output;
    // Lines grouped by motion: each group ends with one motion; the lines before it (comments,
    // speeds, extruder switching) go with it, so a TRIGGER stays with its motion.
    let mut groups: Vec<Vec<String>> = Vec::new();
    let mut pending: Vec<String> = Vec::new();
    let mut vel_before: Vec<Option<f64>> = Vec::new();
    let mut vel = None;
    let mut k = 0;
    for step in steps {
        match step {
            Step::Comment(c) => pending.push(format!("; {}", comment_text(c))),
            Step::Vel(v) => {
                pending.push(format!("$VEL.CP = {}", fixed(*v, 4)));
            }
            Step::Extruder(on) => {
                let state = if *on { "TRUE" } else { "FALSE" };
                pending.push(match cell.extruder_switch {
                    ExtruderSwitch::Out => format!("$OUT[{out}] = {state}"),
                    ExtruderSwitch::Trigger => {
                        format!("TRIGGER WHEN DISTANCE=0 DELAY=0 DO $OUT[{out}]={state}")
                    }
                });
            }
            Step::Move { ptp, .. } => {
                let f = &checked.frames[k];
                let mut line = if *ptp {
                    format!("PTP {}", frame_text(f))
                } else {
                    format!("LIN {} C_DIS", frame_text(f))
                };
                if let Some(note) = checked.notes[k] {
                    line.push_str(" ; ");
                    line.push_str(note);
                }
                k += 1;
                pending.push(line);
                vel_before.push(vel);
                groups.push(std::mem::take(&mut pending));
            }
        }
        if let Step::Vel(v) = step {
            vel = Some(*v);
        }
    }
    let trailing = pending;

    let moves = groups.len();
    let per = cell.max_moves_per_file.max(1);
    let parts = if moves > per { moves.div_ceil(per) } else { 0 };
    let digits = parts.to_string().len().max(3);
    let name = if parts > 0 {
        krl_name(program_name, KRL_NAME_MAX - 2 - digits)
    } else {
        krl_name(program_name, KRL_NAME_MAX)
    };
    let part_name = |i: usize| format!("{name}_p{:0digits$}", i + 1);

    let src = comment_text(source);
    let print_len: f64 = path
        .points
        .windows(2)
        .filter(|w| w[1].kind == MoveKind::Print)
        .map(|w| norm(sub(w[1].p, w[0].p)))
        .sum();
    let filament: f64 = path
        .points
        .iter()
        .filter(|q| q.kind == MoveKind::Print)
        .map(|q| q.e)
        .sum();
    let feed = if print_len > 0.0 {
        filament / print_len
    } else {
        0.0
    };
    let switch = match cell.extruder_switch {
        ExtruderSwitch::Out => format!("$OUT[{out}] between motions (exact stop)"),
        ExtruderSwitch::Trigger => format!("$OUT[{out}] by TRIGGER at the motion's start"),
    };

    let mut main: Vec<String> = vec![
        "&ACCESS RVP".into(),
        "&REL 1".into(),
        format!("DEF {name}( )"),
        format!("; generated by features from {src}"),
        format!("; machine: {} (kuka)", comment_text(&m.name)),
        format!(
            "; part offset X{} Y{} Z{} (base = part + offset)",
            fixed(offset[0], 3),
            fixed(offset[1], 3),
            fixed(offset[2], 3)
        ),
        "; tool: Z along the nozzle into the deposit (the tool path axis is -Z of $TOOL)".into(),
        format!(
            "; extruder: {switch}; set on its controller: nozzle {} C, bed {} C, filament {} mm fed {} mm per mm of bead",
            fixed(m.nozzle_temperature, 0),
            fixed(m.bed_temperature, 0),
            fixed(m.filament_diameter, 2),
            fixed(feed, 5)
        ),
        format!(
            "; {moves} motions{}",
            if parts > 0 {
                format!(" in {parts} parts of at most {per}")
            } else {
                String::new()
            }
        ),
        ";FOLD INI".into(),
        "  ;FOLD BASISTECH INI".into(),
        "    GLOBAL INTERRUPT DECL 3 WHEN $STOPMESS==TRUE DO IR_STOPM ( )".into(),
        "    INTERRUPT ON 3".into(),
        "    BAS (#INITMOV,0 )".into(),
        "  ;ENDFOLD (BASISTECH INI)".into(),
        ";ENDFOLD (INI)".into(),
        ";FOLD FRAMES AND SPEEDS".into(),
        format!("$BASE = {}", frame_text(&cell.base.to_array())),
        format!("$TOOL = {}", frame_text(&cell.tool.to_array())),
        "$ADVANCE = 3".into(),
        format!("$APO.CDIS = {}", fixed(cell.apo_cdis, 3)),
        ";ENDFOLD (FRAMES AND SPEEDS)".into(),
        format!("$OUT[{out}] = FALSE"),
        format!("PTP {HOME_NAME}"),
    ];
    let mut files = Vec::new();
    let mut part_files = Vec::new();
    if parts == 0 {
        for g in &groups {
            main.extend(g.iter().cloned());
        }
        main.extend(trailing.iter().cloned());
    } else {
        for (i, chunk) in groups.chunks(per).enumerate() {
            let pname = part_name(i);
            main.push(format!("{pname}( )"));
            let mut lines: Vec<String> = vec![
                "&ACCESS RVP".into(),
                "&REL 1".into(),
                format!("DEF {pname}( )"),
                format!(
                    "; part {} of {parts} of {name}, generated by features from {src}",
                    i + 1
                ),
            ];
            // The speed in force, unless the part's first motion sets its own.
            let sets_vel = chunk
                .first()
                .is_some_and(|g| g.iter().any(|l| l.starts_with("$VEL.CP")));
            if let (Some(Some(v)), false) = (vel_before.get(i * per), sets_vel) {
                lines.push(format!("$VEL.CP = {}", fixed(*v, 4)));
            }
            for g in chunk {
                lines.extend(g.iter().cloned());
            }
            if i + 1 == parts {
                lines.extend(trailing.iter().cloned());
            }
            lines.push("END".into());
            let dat = vec![
                "&ACCESS RVP".into(),
                "&REL 1".into(),
                format!("DEFDAT {pname}"),
                format!("; part {} of {parts} of {name}", i + 1),
                "ENDDAT".into(),
            ];
            part_files.push((format!("{pname}.src"), join(&lines)));
            part_files.push((format!("{pname}.dat"), join(&dat)));
        }
    }
    main.push(format!("$OUT[{out}] = FALSE"));
    main.push(format!("PTP {HOME_NAME}"));
    main.push("END".into());
    let h = cell.home;
    let dat = vec![
        "&ACCESS RVP".into(),
        "&REL 1".into(),
        format!("DEFDAT {name}"),
        format!("; generated by features from {src}"),
        format!(
            "DECL AXIS {HOME_NAME} = {{A1 {}, A2 {}, A3 {}, A4 {}, A5 {}, A6 {}}}",
            fixed(h[0], 3),
            fixed(h[1], 3),
            fixed(h[2], 3),
            fixed(h[3], 3),
            fixed(h[4], 3),
            fixed(h[5], 3)
        ),
        "ENDDAT".into(),
    ];
    files.push((format!("{name}.src"), join(&main)));
    files.push((format!("{name}.dat"), join(&dat)));
    files.extend(part_files);
    files
}

/// Lines joined with `\n`, ending with one.
fn join(lines: &[String]) -> String {
    let mut s = lines.join("\n");
    s.push('\n');
    s
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn abc_round_trip_and_unwrapping() {
        for abc in [
            [10.0, 20.0, 30.0],
            [-170.0, 89.0, 179.0],
            [0.0, 0.0, 180.0],
            [45.0, -60.0, -120.0],
        ] {
            let r = matrix_from_abc(abc);
            let back = abc_from_matrix(&r, Some(abc));
            for k in 0..3 {
                assert!((back[k] - abc[k]).abs() < 1e-9, "{abc:?} -> {back:?}");
            }
        }
        // Unwrapped: A near 350 stays near 350, not -10.
        let r = matrix_from_abc([-10.0, 5.0, 0.0]);
        let back = abc_from_matrix(&r, Some([349.0, 5.0, 0.0]));
        assert!((back[0] - 350.0).abs() < 1e-9, "{back:?}");
        // Gimbal lock: A is kept, the matrix is reproduced.
        let r = matrix_from_abc([30.0, 90.0, 10.0]);
        let back = abc_from_matrix(&r, Some([25.0, 89.0, 0.0]));
        assert_eq!(back[0], 25.0);
        assert!(rotation_angle_deg(&r, &matrix_from_abc(back)) < 1e-6);
        let r = matrix_from_abc([30.0, -90.0, 10.0]);
        let back = abc_from_matrix(&r, Some([-40.0, -89.0, 0.0]));
        assert_eq!(back[0], -40.0);
        assert!(rotation_angle_deg(&r, &matrix_from_abc(back)) < 1e-6);
    }

    #[test]
    fn krl_names() {
        assert_eq!(krl_name("impeller", 24), "impeller");
        assert_eq!(krl_name("My Part-2.step", 24), "my_part_2_step");
        assert_eq!(krl_name("3d", 24), "p_3d");
        assert_eq!(krl_name("", 24), "features");
        assert_eq!(krl_name("LIN", 24), "lin_prg");
        assert_eq!(krl_name("a_very_long_name_for_a_program", 19).len(), 19);
    }

    #[test]
    fn slerp_pieces() {
        let a = matrix_from_abc([10.0, 20.0, 30.0]);
        let b = matrix_from_abc([100.0, -30.0, 170.0]);
        let d = log_rot(&mul(&transpose(&a), &b));
        let end = mul(&a, &exp_rot(d));
        assert!(rotation_angle_deg(&end, &b) < 1e-9);
        let half_turn = exp_rot([0.0, PI, 0.0]);
        let d = log_rot(&half_turn);
        assert!(rotation_angle_deg(&exp_rot(d), &half_turn) < 1e-6);
    }
}
