//! The `[kuka]` table of a machine profile: the cell's frames, the arm model, its joint limits
//! and the KRL output settings.

use super::rotation::Pose;
use crate::PostError;

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

/// How the print paths are written.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, serde::Deserialize, serde::Serialize)]
#[serde(rename_all = "snake_case")]
pub enum KrlMotion {
    /// One `LIN ... C_DIS` per path point.
    #[default]
    Lin,
    /// `SPLINE` blocks of `SPL` and `SLIN` segments through the points left after dropping
    /// those within `spline_tolerance` of the line through their neighbours.
    Spline,
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
    /// Where on the table the part goes: the table point (`$BASE` X and Y, mm) its XY
    /// bounding-box centre is placed on. Optional: `[0, 0]`, the table's origin, when left
    /// out. [`crate::fit::reach_shift`] finds the least move of it that brings every point
    /// into the arm's reach.
    #[serde(default, skip_serializing_if = "is_origin")]
    pub part_position: [f64; 2],
    /// `$TOOL`: the nozzle tip in the flange frame, Z along the nozzle.
    pub tool: KrlFrame,
    /// The controller's base number n (1..32) that holds `base`: when given, the program
    /// selects it with `BAS (#BASE, n)` instead of assigning `$BASE`, and states the frame it
    /// assumes `BASE_DATA[n]` holds in a comment, for the integrator to check. Optional: the
    /// frame is assigned to `$BASE` when left out.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub base_index: Option<u32>,
    /// The controller's tool number n (1..32) that holds `tool`, as `base_index`:
    /// `BAS (#TOOL, n)` and a comment stating the assumed `TOOL_DATA[n]`. Optional: `$TOOL` is
    /// assigned when left out.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub tool_index: Option<u32>,
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
    /// The safe point's height (mm) over the part's top (`$BASE` Z): the program goes there by
    /// `PTP`, over the first path's start, before its first motion near the part, and back there
    /// after the last. Optional: [`DEFAULT_SAFE_HEIGHT`] when left out.
    #[serde(default = "default_safe_height")]
    pub safe_height: f64,
    /// Number n of the digital output `$OUT[n]` that runs the extruder.
    pub extruder_output: u32,
    /// How the output is switched.
    pub extruder_switch: ExtruderSwitch,
    /// Number n of the digital input `$IN[n]` on which the extruder reports it is ready (at
    /// temperature): when given, the program waits for it before its first print move, at most
    /// `ready_timeout` seconds, then halts. Optional: no handshake when left out.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub ready_input: Option<u32>,
    /// The longest wait for `ready_input` (s) before the program halts. Optional:
    /// [`DEFAULT_READY_TIMEOUT`] when left out.
    #[serde(default = "default_ready_timeout")]
    pub ready_timeout: f64,
    /// Number n of the analog output `$ANOUT[n]` that carries each print LIN's feed ratio
    /// (filament mm per mm of path). Optional: 1 when left out.
    #[serde(default = "default_feed_output")]
    pub feed_output: u32,
    /// The feed ratio (filament mm per mm of path) at `$ANOUT[n] = 1.0`: the output written is
    /// the ratio over this. Optional: 0.1 when left out.
    #[serde(default = "default_feed_ratio_full_scale")]
    pub feed_ratio_full_scale: f64,
    /// How the print paths are written: `lin` (one `LIN` per point) or `spline` (`SPLINE`
    /// blocks through the points left after dropping those a straight run passes within
    /// `spline_tolerance` of). Optional: `lin` when left out.
    #[serde(default)]
    pub motion: KrlMotion,
    /// With `motion = "spline"`: how far (mm) the written path may pass from a planned point
    /// (half of it for the points dropped, half for a spline segment's bulge). Optional:
    /// [`DEFAULT_SPLINE_TOLERANCE`] when left out.
    #[serde(default = "default_spline_tolerance")]
    pub spline_tolerance: f64,
    /// Most motions per `.src` file; a longer program is split into parts called from the
    /// main program.
    pub max_moves_per_file: usize,
    /// A pose whose wrist bend |A5| is below this (degrees) is reported as near the wrist
    /// singularity.
    pub wrist_singularity_deg: f64,
    /// The arm.
    pub arm: ArmModel,
}

fn is_origin(p: &[f64; 2]) -> bool {
    *p == [0.0, 0.0]
}

/// The safe point's height over the part's top (mm) of a cell that does not say
/// (`safe_height`).
pub const DEFAULT_SAFE_HEIGHT: f64 = 50.0;

/// The spline tolerance (mm) of a cell that does not say (`spline_tolerance`): the process's
/// default chord tolerance.
pub const DEFAULT_SPLINE_TOLERANCE: f64 = 0.05;

fn default_spline_tolerance() -> f64 {
    DEFAULT_SPLINE_TOLERANCE
}

/// The longest wait for the extruder's ready input (s) of a cell that does not say
/// (`ready_timeout`).
pub const DEFAULT_READY_TIMEOUT: f64 = 60.0;

fn default_ready_timeout() -> f64 {
    DEFAULT_READY_TIMEOUT
}

fn default_safe_height() -> f64 {
    DEFAULT_SAFE_HEIGHT
}

fn default_feed_output() -> u32 {
    1
}

fn default_feed_ratio_full_scale() -> f64 {
    0.1
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
        for (field, n) in [
            ("kuka.base_index", self.base_index),
            ("kuka.tool_index", self.tool_index),
        ] {
            if let Some(n) = n.filter(|n| !(1..=32).contains(n)) {
                return Err(bad(field, format!("must be a number 1..32, got {n}")));
            }
        }
        if let Some(x) = self
            .part_position
            .iter()
            .find(|x| !(x.is_finite() && x.abs() <= 1e5))
        {
            return Err(bad(
                "kuka.part_position",
                format!("must be within ±100000 mm, got {x}"),
            ));
        }
        for (field, v, max) in [
            ("kuka.print_vel_cp", self.print_vel_cp, 3.0),
            ("kuka.travel_vel_cp", self.travel_vel_cp, 3.0),
            ("kuka.apo_cdis", self.apo_cdis, 100.0),
            ("kuka.travel_clearance", self.travel_clearance, 1000.0),
            ("kuka.safe_height", self.safe_height, 2000.0),
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
        if let Some(n) = self.ready_input.filter(|n| !(1..=4096).contains(n)) {
            return Err(bad(
                "kuka.ready_input",
                format!("must be an input number 1..4096, got {n}"),
            ));
        }
        let t = self.ready_timeout;
        if !(t.is_finite() && t > 0.0 && t <= 86400.0) {
            return Err(bad(
                "kuka.ready_timeout",
                format!("must be above 0 and at most 86400 s, got {t}"),
            ));
        }
        if !(1..=4096).contains(&self.feed_output) {
            return Err(bad(
                "kuka.feed_output",
                format!(
                    "must be an analog output number 1..4096, got {}",
                    self.feed_output
                ),
            ));
        }
        let t = self.spline_tolerance;
        if !(t.is_finite() && t > 0.0 && t <= 1.0) {
            return Err(bad(
                "kuka.spline_tolerance",
                format!("must be above 0 and at most 1 mm, got {t}"),
            ));
        }
        let f = self.feed_ratio_full_scale;
        if !(f.is_finite() && f > 0.0 && f <= 10.0) {
            return Err(bad(
                "kuka.feed_ratio_full_scale",
                format!("must be above 0 and at most 10 mm of filament per mm, got {f}"),
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
}
