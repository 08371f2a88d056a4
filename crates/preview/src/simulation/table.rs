//! delta5's B and C from the tool axes alone, so that a delta5 preview simulates without the
//! post: Eq. 9–12 of Isa & Lazoglu 2019 as `robot_post::delta5::inverse` (in
//! `crates/robot-post/src/delta5/kinematics.rs`) has them, copied here (the preview does not
//! depend on the posts).

use super::{SimMachine, SimMargins, SimMove, SimTable, Simulation};
use crate::tolerance::{ANGLE_TOLERANCE, POLE};
use crate::HeadSize;
use toolpath::vec3::unit;
use toolpath::{MoveKind, PathPoint};

/// Bed angles `(B, C)` (degrees) for the unit tool axis `a` (part coordinates), a copy of
/// `robot_post::delta5::inverse` (Isa & Lazoglu 2019, Eq. 9–12): `a = R_z(C)·R_y(B)·(0,0,1)`;
/// θ₁ = atan2(a_y, a_x) with σ = 1 or θ₂ = atan2(−a_y, −a_x) with σ = −1 (Eq. 10), B =
/// atan2(σ·√(a_x² + a_y²), a_z) (Eq. 11), σ = 1 unless θ₁ turns more than 90° from
/// `previous_c` (Eq. 12), C unwrapped nearest `previous_c`; the other σ when B leaves
/// `b_limits`. At the pole (a_x = a_y = 0) C keeps `previous_c` (0 without one). `None`: no
/// B within the limits.
fn inverse(a: [f64; 3], previous_c: Option<f64>, b_limits: [f64; 2]) -> Option<(f64, f64)> {
    let fits = |b: f64| b >= b_limits[0] - ANGLE_TOLERANCE && b <= b_limits[1] + ANGLE_TOLERANCE;
    let r = a[0].hypot(a[1]);
    if r < POLE {
        let b = if a[2] > 0.0 { 0.0 } else { 180.0 };
        let c = previous_c.unwrap_or(0.0);
        return [b, -b].into_iter().find(|&b| fits(b)).map(|b| (b, c));
    }
    let theta1 = a[1].atan2(a[0]).to_degrees();
    let theta2 = (-a[1]).atan2(-a[0]).to_degrees();
    let phi = |sigma: f64| (sigma * r).atan2(a[2]).to_degrees();
    let near = |theta: f64, p: f64| theta + 360.0 * ((p - theta) / 360.0).round();
    let (c1, c2) = match previous_c {
        Some(p) => (near(theta1, p), near(theta2, p)),
        None => (theta1, theta2),
    };
    let first = match previous_c {
        Some(p) if (c1 - p).abs() > 90.0 => -1.0,
        _ => 1.0,
    };
    [first, -first]
        .into_iter()
        .map(|s| (phi(s), if s > 0.0 { c1 } else { c2 }))
        .find(|&(b, _)| fits(b))
}

/// Shifts one path's C by whole turns into `limits`, as near `entry` (the C before it; the
/// limits' middle without one) as they allow, as the post's `fit_c_limits`; left as it is when
/// no shift fits (the flags then mark it).
fn fit_c_limits(c: &mut [f64], entry: Option<f64>, limits: [f64; 2]) {
    let lo = c.iter().copied().fold(f64::INFINITY, f64::min);
    let hi = c.iter().copied().fold(f64::NEG_INFINITY, f64::max);
    let k_min = ((limits[0] - lo - ANGLE_TOLERANCE) / 360.0).ceil();
    let k_max = ((limits[1] - hi + ANGLE_TOLERANCE) / 360.0).floor();
    let Some(&first) = c.first() else { return };
    if k_min > k_max {
        return;
    }
    let target = entry.unwrap_or(0.5 * (limits[0] + limits[1]));
    let k = ((target - first) / 360.0).round().clamp(k_min, k_max);
    for v in c.iter_mut() {
        *v += 360.0 * k;
    }
}

impl Simulation {
    /// A delta5 simulation of `points` (a tool path's points, in its frame) on `table`: one
    /// move per point with a direction for an axis and a B within the limits (the others are
    /// left out), B and C from the axis by Eq. 9–12 (a copy of
    /// `robot_post::delta5::inverse`), each path (a point that is not a print move and the
    /// print moves after it) shifted by whole turns into C's limits when it has them, and the
    /// flags by `margins`.
    ///
    /// Not copied: the post's singularity cone, inside which it interpolates C between the
    /// points either side (here C comes from Eq. 10–12 up to the pole and holds there), nor
    /// its sub-moves. Where the axis is near vertical, C here may turn faster than the
    /// program's.
    pub fn table_from_axes(
        points: &[PathPoint],
        table: SimTable,
        head: HeadSize,
        margins: SimMargins,
    ) -> Simulation {
        let mut moves: Vec<SimMove> = Vec::with_capacity(points.len());
        let mut previous: Option<f64> = None;
        let mut start = 0;
        while start < points.len() {
            let mut end = start + 1;
            while end < points.len() && points[end].kind == MoveKind::Print {
                end += 1;
            }
            let entry = previous;
            let first = moves.len();
            for (i, q) in points.iter().enumerate().take(end).skip(start) {
                let Some(a) = unit(q.axis) else { continue };
                let Some((b, c)) = inverse(a, previous, table.b_limits_deg) else {
                    continue;
                };
                previous = Some(c);
                moves.push(SimMove {
                    point: i,
                    joints: vec![b, c],
                    ..SimMove::default()
                });
            }
            if let Some(limits) = table.c_limits_deg {
                let mut c: Vec<f64> = moves[first..].iter().map(|m| m.joints[1]).collect();
                fit_c_limits(&mut c, entry, limits);
                for (m, v) in moves[first..].iter_mut().zip(&c) {
                    m.joints[1] = *v;
                }
                previous = c.last().copied().or(previous);
            }
            start = end;
        }
        Simulation::new(SimMachine::Table(table), head, moves, margins)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use toolpath::Role;

    fn table() -> SimTable {
        SimTable {
            centre: [0.0, 0.0],
            z: 0.0,
            radius: 100.0,
            table_above_b_axis: 20.0,
            b_limits_deg: [-90.0, 90.0],
            c_limits_deg: None,
        }
    }

    /// `R_z(C)·R_y(B)·(0,0,1)`.
    fn axis_of(b: f64, c: f64) -> [f64; 3] {
        let (sb, cb) = b.to_radians().sin_cos();
        let (sc, cc) = c.to_radians().sin_cos();
        [cc * sb, sc * sb, cb]
    }

    fn point(axis: [f64; 3], kind: MoveKind) -> PathPoint {
        PathPoint {
            feature: 0,
            layer: 0,
            kind,
            p: [0.0; 3],
            axis,
            e: 0.0,
            thickness: 0.2,
            width: 0.45,
            role: Role::Perimeter,
        }
    }

    fn head() -> HeadSize {
        HeadSize {
            tip_radius: 0.5,
            half_angle_deg: 30.0,
            cone_length: 8.0,
            body_radius: 20.0,
            body_length: 60.0,
        }
    }

    #[test]
    fn b_and_c_turn_the_bed_axis_onto_each_tool_axis_and_c_never_jumps() {
        // An axis tilting to 60° and turning round twice.
        let points: Vec<PathPoint> = (0..=200)
            .map(|k| {
                let t = k as f64 / 200.0;
                let kind = if k == 0 {
                    MoveKind::Travel
                } else {
                    MoveKind::Print
                };
                point(axis_of(60.0 * t, 720.0 * t - 170.0), kind)
            })
            .collect();
        let s = Simulation::table_from_axes(&points, table(), head(), SimMargins::default());
        assert_eq!(s.moves.len(), points.len());
        for (m, q) in s.moves.iter().zip(&points) {
            let a = axis_of(m.joints[0], m.joints[1]);
            let d: f64 = (0..3)
                .map(|k| (a[k] - q.axis[k]).powi(2))
                .sum::<f64>()
                .sqrt();
            assert!(d < 1e-9, "move {}: {a:?} for {:?}", m.point, q.axis);
        }
        for w in s.moves.windows(2).skip(1) {
            assert!((w[1].joints[1] - w[0].joints[1]).abs() < 10.0);
        }
        // Unwrapped: C runs on past 180°.
        assert!(s.moves.last().is_some_and(|m| m.joints[1] > 500.0));
        assert!(s.moves.iter().all(|m| m.flags == Default::default()));
    }

    #[test]
    fn limited_c_is_shifted_into_its_limits_and_b_near_a_limit_is_flagged() {
        let mut t = table();
        t.c_limits_deg = Some([0.0, 360.0]);
        t.b_limits_deg = [-60.0, 60.0];
        let points = vec![
            point(axis_of(30.0, -90.0), MoveKind::Travel),
            point(axis_of(57.0, -80.0), MoveKind::Print),
            // Beyond B's limits either way: left out.
            point(axis_of(80.0, -80.0), MoveKind::Print),
            point([0.0; 3], MoveKind::Print),
        ];
        let s = Simulation::table_from_axes(&points, t, head(), SimMargins::default());
        assert_eq!(s.moves.iter().map(|m| m.point).collect::<Vec<_>>(), [0, 1]);
        assert!((s.moves[0].joints[1] - 270.0).abs() < 1e-9);
        assert_eq!(s.moves[1].flags.near_limit, vec![0]);
    }
}
