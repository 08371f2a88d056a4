//! The flags of a move from its joints alone: a joint near its limit, the arm's wrist near its
//! singularity. Collisions are the caller's (a head check), not computed here.

use super::{SimArm, SimFlags, SimMachine};

/// A joint this close to a limit (degrees) is marked, unless the margins say otherwise.
pub const NEAR_LIMIT_DEG: f64 = 5.0;

/// A wrist bent less than this (degrees, θ5 from 0° or 180°) is marked as near the wrist
/// singularity, unless the margins say otherwise (the KUKA cell's `wrist_singularity_deg`).
pub const NEAR_SINGULARITY_DEG: f64 = 5.0;

/// How close to a limit or the singularity a move is marked (degrees).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SimMargins {
    /// A joint within this of a limit (or beyond it) is near the limit.
    pub limit_deg: f64,
    /// A wrist bend (θ5 from 0° or 180°) below this is near the singularity.
    pub singularity_deg: f64,
}

impl Default for SimMargins {
    /// [`NEAR_LIMIT_DEG`] and [`NEAR_SINGULARITY_DEG`].
    fn default() -> SimMargins {
        SimMargins {
            limit_deg: NEAR_LIMIT_DEG,
            singularity_deg: NEAR_SINGULARITY_DEG,
        }
    }
}

/// `x` wrapped to (−180, 180] degrees.
fn wrap180(x: f64) -> f64 {
    let w = x - 360.0 * (x / 360.0).round();
    if w <= -180.0 {
        w + 360.0
    } else {
        w
    }
}

impl SimArm {
    /// The wrist's bend (degrees, 0..180) at joints A1..A6: |θ5| with θ5 = A5·sign5 −
    /// offset5 wrapped to ±180°; 0 and 180 are the wrist singularity (A4 and A6 turn about one
    /// line), as `robot_post::kuka::ArmModel::wrist_bend`.
    pub fn wrist_bend(&self, joints: &[f64]) -> Option<f64> {
        let a5 = *joints.get(4)?;
        let theta5 = a5 * f64::from(self.joint_signs[4]) - self.joint_offsets[4];
        Some(wrap180(theta5).abs())
    }
}

impl SimMachine {
    /// The near-limit and near-singularity flags of `joints` (A1..A6 or B, C; degrees) by
    /// `margins`; `collision` is false. A joint is near its limit when it is within
    /// `limit_deg` of either limit or beyond one (C without limits never is); the arm is near
    /// its wrist singularity when [`SimArm::wrist_bend`] is below `singularity_deg` or above
    /// 180° less it. A table has no such singularity flagged: at B = 0 the post holds C (its
    /// singularity cone), which is no hazard. Missing and non-finite joints are not flagged.
    pub fn flags(&self, joints: &[f64], margins: &SimMargins) -> SimFlags {
        let near_limit = self
            .limits()
            .iter()
            .zip(joints)
            .enumerate()
            .filter_map(|(i, (lim, &v))| {
                let [lo, hi] = (*lim)?;
                (v.is_finite() && (v - lo < margins.limit_deg || hi - v < margins.limit_deg))
                    .then_some(i)
            })
            .collect();
        let near_singularity = match self {
            SimMachine::Arm(a) => a.wrist_bend(joints).is_some_and(|bend| {
                bend < margins.singularity_deg || 180.0 - bend < margins.singularity_deg
            }),
            SimMachine::Table(_) => false,
        };
        SimFlags {
            collision: false,
            near_limit,
            near_singularity,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::simulation::SimTable;

    /// The bundled KUKA profile's arm (`profiles/kuka.toml`).
    fn kuka_arm() -> SimArm {
        SimArm {
            a1: 25.0,
            a2: -35.0,
            b: 0.0,
            c1: 400.0,
            c2: 455.0,
            c3: 420.0,
            c4: 80.0,
            joint_offsets: [0.0, -90.0, 0.0, 0.0, 0.0, 0.0],
            joint_signs: [-1, 1, 1, -1, 1, -1],
            joint_min: [-170.0, -190.0, -120.0, -185.0, -120.0, -350.0],
            joint_max: [170.0, 45.0, 156.0, 185.0, 120.0, 350.0],
            base: [450.0, 0.0, 400.0, 0.0, 0.0, 0.0],
            part_offset: [0.0; 3],
            tool: [0.0, 0.0, 150.0, 0.0, 0.0, 0.0],
        }
    }

    #[test]
    fn an_arm_is_near_a_limit_within_the_margin_and_beyond_it() {
        let m = SimMachine::Arm(kuka_arm());
        let d = SimMargins::default();
        let home = [0.0, -90.0, 90.0, 0.0, 90.0, 0.0];
        assert_eq!(m.flags(&home, &d), SimFlags::default());
        // A1 at 166 of 170, A3 at -117 of -120, A6 past 350.
        let f = m.flags(&[166.0, -90.0, -117.0, 0.0, 90.0, 351.0], &d);
        assert_eq!(f.near_limit, vec![0, 2, 5]);
        assert!(!f.near_singularity && !f.collision);
        // 164 is 6 degrees off: not near by 5, near by 10.
        assert!(m
            .flags(&[164.0, -90.0, 90.0, 0.0, 90.0, 0.0], &d)
            .near_limit
            .is_empty());
        let wide = SimMargins {
            limit_deg: 10.0,
            ..d
        };
        assert_eq!(
            m.flags(&[164.0, -90.0, 90.0, 0.0, 90.0, 0.0], &wide)
                .near_limit,
            vec![0]
        );
    }

    #[test]
    fn an_arm_is_near_its_wrist_singularity_when_a5_is_small() {
        let m = SimMachine::Arm(kuka_arm());
        let d = SimMargins::default();
        for (a5, near) in [
            (4.9, true),
            (-4.9, true),
            (0.0, true),
            (5.1, false),
            (-60.0, false),
        ] {
            let f = m.flags(&[0.0, -90.0, 90.0, 0.0, a5, 0.0], &d);
            assert_eq!(f.near_singularity, near, "A5 {a5}");
        }
        // An offset wrist: θ5 = A5 − 90, singular at A5 = 90 and, wrapped, at A5 = -90.
        let mut arm = kuka_arm();
        arm.joint_offsets[4] = 90.0;
        assert_eq!(arm.wrist_bend(&[0.0, 0.0, 0.0, 0.0, 92.0, 0.0]), Some(2.0));
        assert_eq!(
            arm.wrist_bend(&[0.0, 0.0, 0.0, 0.0, -88.0, 0.0]),
            Some(178.0)
        );
        let m = SimMachine::Arm(arm);
        assert!(
            m.flags(&[0.0, 0.0, 0.0, 0.0, -88.0, 0.0], &d)
                .near_singularity
        );
        // Too few joints: nothing to say about the wrist.
        assert!(!m.flags(&[0.0, 0.0], &d).near_singularity);
    }

    #[test]
    fn a_table_is_near_its_b_limits_and_c_only_when_limited() {
        let mut t = SimTable {
            centre: [0.0, 0.0],
            z: 0.0,
            radius: 100.0,
            table_above_b_axis: 20.0,
            b_limits_deg: [-90.0, 90.0],
            c_limits_deg: None,
        };
        let d = SimMargins::default();
        let m = SimMachine::Table(t.clone());
        assert_eq!(m.flags(&[0.0, 5000.0], &d), SimFlags::default());
        assert_eq!(m.flags(&[87.0, 0.0], &d).near_limit, vec![0]);
        t.c_limits_deg = Some([-360.0, 360.0]);
        let m = SimMachine::Table(t);
        assert_eq!(m.flags(&[-86.0, 358.0], &d).near_limit, vec![0, 1]);
        assert_eq!(m.flags(&[f64::NAN, 0.0], &d), SimFlags::default());
    }
}
