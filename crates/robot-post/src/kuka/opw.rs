//! Forward and inverse kinematics of the arm model (OPW, Brandstötter et al. 2014): the
//! joint solutions of a flange pose, their configurations, limits and the wrist bend.

use super::cell::ArmModel;
use std::f64::consts::PI;

use super::rotation::{col, mul, rot_y, rot_z, transpose, wrap180, Pose};
use crate::tolerance::{COSINE_SLACK, WRIST_SINGULAR};
use toolpath::vec3::{add, scale, sub};

/// The arm's kinematics (OPW: Brandstötter, Angerer & Hofbaur 2014).
impl ArmModel {
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

    /// KUKA's Status (S) of θ, the arm's configuration in three bits (KUKA System Software,
    /// "Status" of a POS/E6POS): bit 0 set when the wrist centre lies behind the A1 axis (its X
    /// in the A1 coordinate system negative: the overhead area), bit 1 when A3 ≥ φ (φ the A3 of
    /// the stretched arm, wrist centre on the line through A2 and A3: the elbow up), bit 2 when
    /// A5 ≤ 0 (the wrist flipped).
    fn config(&self, q: &[f64; 6]) -> u8 {
        let (psi3, k) = self.psi3_k();
        let cx1 = self.c2 * q[1].sin() + k * (q[1] + q[2] + psi3).sin() + self.a1;
        let a = self.joints(*q);
        let phi = wrap180(
            ((-psi3).to_degrees() + self.joint_offsets[2]) * f64::from(self.joint_signs[2]),
        );
        u8::from(cx1 < 0.0) | (u8::from(a[2] >= phi) << 1) | (u8::from(a[4] <= 0.0) << 2)
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
            if cos_phi.is_nan() || cos_phi.abs() > 1.0 + COSINE_SLACK {
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
                if s5 > WRIST_SINGULAR {
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
    /// limit. Returns the joints and the configuration bits (KUKA's Status,
    /// [`ArmModel::configuration`]).
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

    /// The configuration of joint angles (degrees): KUKA's Status bits (overhead area, elbow
    /// up, wrist flipped; see [`ArmModel::nearest`]'s configurations).
    pub fn configuration(&self, joints: &[f64; 6]) -> u8 {
        let mut a = *joints;
        // The Status reads A3 and A5 within ±180°, as the model's angles are.
        a[2] = wrap180(a[2]);
        a[4] = wrap180(a[4]);
        self.config(&self.theta(a))
    }
}

/// KUKA's Turn (T) of joint angles (degrees): bit n set where A(n+1) < 0, so that with the
/// Status it picks one of the solutions of a pose whose joints may turn past ±180°. A joint
/// within [`TURN_ZERO`] below 0 (0 as `joints.csv` writes it) counts as 0.
pub fn turn(joints: &[f64; 6]) -> u8 {
    joints
        .iter()
        .enumerate()
        .fold(0, |t, (n, a)| t | (u8::from(*a < -TURN_ZERO) << n))
}

/// Half the step (degrees) joint angles are written in: a joint this close below 0 is 0 for
/// its Turn bit.
pub const TURN_ZERO: f64 = 5e-5;

/// A Status or Turn as KRL writes it, binary with `bits` digits: `'B010'`.
pub fn bits_text(v: u8, bits: usize) -> String {
    format!("'B{v:0bits$b}'")
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn turn_bits_and_their_text() {
        assert_eq!(turn(&[0.0, -90.0, 90.0, 0.0, 90.0, 0.0]), 0b10);
        assert_eq!(turn(&[-1.0, -90.0, 90.0, 0.0, 90.0, -5.0]), 0b100011);
        assert_eq!(turn(&[0.0, -90.0, 90.0, -1e-12, 90.0, -1e-6]), 0b10);
        assert_eq!(bits_text(2, 3), "'B010'");
        assert_eq!(bits_text(0b100010, 6), "'B100010'");
    }
}
