//! The `[delta5]` table of a machine profile: where the bed's B and C axes are, their limits,
//! the singularity cone and the controller's resolutions.

use crate::PostError;

pub(super) use crate::tolerance::{ANGLE_TOLERANCE, POLE};

/// Slack (mm) allowed when checking the work envelope.
pub(super) const FIT_TOLERANCE: f64 = 1e-6;

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
    /// A travel turning the bed by more than this in all (degrees of B and C summed over its
    /// steps) goes up to the safe height first.
    pub reorient_lift_deg: f64,
    /// Clearance (mm) of the safe height above the part's swing sphere and the hop.
    pub reorient_clearance: f64,
    /// Radius (mm) of the table disc, which tilts and turns with B and C (the head must stay
    /// clear of it); 100 when the key is left out.
    #[serde(default = "default_table_radius")]
    pub table_radius: f64,
}

/// The table radius of a `[delta5]` table without the key, mm.
fn default_table_radius() -> f64 {
    100.0
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
            ("delta5.table_radius", self.table_radius, 0.0, 1e6, true),
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
    pub(crate) fn pivot(&self) -> [f64; 3] {
        [self.c_axis_xy[0], self.c_axis_xy[1], self.b_axis_z]
    }

    /// Whether `axis` (unit) lies in the singularity cone around the C axis (or is the
    /// singular point itself), where θ is patched instead of taken from Eq. 10.
    pub fn in_singularity_cone(&self, axis: [f64; 3]) -> bool {
        let r = axis[0].hypot(axis[1]);
        r < POLE || r <= self.singularity_cone_deg.to_radians().sin()
    }

    pub(super) fn b_fits(&self, b: f64) -> bool {
        b >= self.b_limits_deg[0] - ANGLE_TOLERANCE && b <= self.b_limits_deg[1] + ANGLE_TOLERANCE
    }
}
