//! Rotations and rigid poses of the KUKA post, on plain `[[f64; 3]; 3]` matrices: KUKA's
//! A, B, C angles, rotation vectors (log/exp, for slerp) and the tool frame carried along a
//! path (parallel transport).

use std::f64::consts::PI;

use toolpath::vec3::{add, cross, dot, norm, scale, sub, V3};

pub(super) use crate::tolerance::GIMBAL_EPS;
use crate::tolerance::{FRAME_HINT_MIN, PARALLEL_AXES, ROTATION_ZERO, SMALL_ROTATION};

/// A rotation matrix, rows: `r[i][j]` is row i, column j; column j is the rotated frame's
/// j-th axis.
pub type Mat3 = [[f64; 3]; 3];

pub(super) const IDENTITY: Mat3 = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];

pub(super) fn mul(a: &Mat3, b: &Mat3) -> Mat3 {
    std::array::from_fn(|i| std::array::from_fn(|j| (0..3).map(|k| a[i][k] * b[k][j]).sum()))
}

pub(super) fn transpose(a: &Mat3) -> Mat3 {
    std::array::from_fn(|i| std::array::from_fn(|j| a[j][i]))
}

pub(super) fn apply(a: &Mat3, v: V3) -> V3 {
    std::array::from_fn(|i| a[i][0] * v[0] + a[i][1] * v[1] + a[i][2] * v[2])
}

pub(super) fn col(a: &Mat3, j: usize) -> V3 {
    [a[0][j], a[1][j], a[2][j]]
}

pub(super) fn from_cols(x: V3, y: V3, z: V3) -> Mat3 {
    [[x[0], y[0], z[0]], [x[1], y[1], z[1]], [x[2], y[2], z[2]]]
}

pub(super) fn rot_x(t: f64) -> Mat3 {
    let (s, c) = t.sin_cos();
    [[1.0, 0.0, 0.0], [0.0, c, -s], [0.0, s, c]]
}

pub(super) fn rot_y(t: f64) -> Mat3 {
    let (s, c) = t.sin_cos();
    [[c, 0.0, s], [0.0, 1.0, 0.0], [-s, 0.0, c]]
}

pub(super) fn rot_z(t: f64) -> Mat3 {
    let (s, c) = t.sin_cos();
    [[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]]
}

/// `x` wrapped to (−180, 180].
pub(super) fn wrap180(x: f64) -> f64 {
    let w = x - 360.0 * (x / 360.0).round();
    if w <= -180.0 {
        w + 360.0
    } else {
        w
    }
}

/// `x` plus the multiple of 360 that brings it nearest `target`.
pub(super) fn unwrap_near(x: f64, target: f64) -> f64 {
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
pub(super) fn angle_of(r: &Mat3) -> (f64, V3) {
    let w = [r[2][1] - r[1][2], r[0][2] - r[2][0], r[1][0] - r[0][1]];
    let cos = (r[0][0] + r[1][1] + r[2][2] - 1.0) / 2.0;
    ((norm(w) / 2.0).atan2(cos), w)
}

/// Rotation vector (axis · angle, radians) of a rotation matrix.
pub(super) fn log_rot(r: &Mat3) -> V3 {
    let (angle, w) = angle_of(r);
    if angle < SMALL_ROTATION {
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
pub(super) fn exp_rot(v: V3) -> Mat3 {
    let angle = norm(v);
    if angle < ROTATION_ZERO {
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
pub(super) fn frame_from_zx(z: V3, x_hint: V3, min_len: f64) -> Option<Mat3> {
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
pub(super) fn transport(r: &Mat3, z: V3) -> Mat3 {
    let (z0, x0) = (col(r, 2), col(r, 0));
    let c = cross(z0, z);
    let s = norm(c);
    let d = dot(z0, z);
    let turn = if s < PARALLEL_AXES {
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
    frame_from_zx(z, x, FRAME_HINT_MIN).unwrap_or(*r)
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
