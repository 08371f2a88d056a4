//! The bed's kinematics (Isa & Lazoglu 2019, Eq. 9–12): bed angles for a tool axis, the
//! machine position of a part point and back, and the bed angles along the path with C patched
//! inside the singularity cone.

use super::geometry::{Delta5Geometry, ANGLE_TOLERANCE, POLE};
use crate::tolerance::ARC_ZERO;
use crate::PostError;
use toolpath::vec3::{norm, sub, unit};
use toolpath::{fixed, MoveKind, PathPoint};

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
pub(super) fn bed_to_machine(v: [f64; 3], b: f64, c: f64) -> [f64; 3] {
    let (sc, cc) = c.sin_cos();
    let (sb, cb) = b.sin_cos();
    let x = v[0] * cc + v[1] * sc;
    let y = -v[0] * sc + v[1] * cc;
    [x * cb - v[2] * sb, y, x * sb + v[2] * cb]
}

/// `R_z(C)·R_y(B)·v`: a machine vector in table-frame axes (angles in radians).
pub(super) fn machine_to_bed(v: [f64; 3], b: f64, c: f64) -> [f64; 3] {
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

pub(super) fn lerp(a: [f64; 3], b: [f64; 3], f: f64) -> [f64; 3] {
    [
        a[0] + (b[0] - a[0]) * f,
        a[1] + (b[1] - a[1]) * f,
        a[2] + (b[2] - a[2]) * f,
    ]
}

/// Angle (degrees) between two unit vectors.
pub(super) fn angle_deg(a: [f64; 3], b: [f64; 3]) -> f64 {
    let cross = [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ];
    let dot = a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
    norm(cross).atan2(dot).to_degrees()
}

/// Distance from `x` to the segment `a`–`b`.
pub(super) fn distance_to_segment(x: [f64; 3], a: [f64; 3], b: [f64; 3]) -> f64 {
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
pub(super) struct Pose {
    pub(super) b: f64,
    pub(super) c: f64,
    /// C was patched (the axis is in the singularity cone).
    pub(super) patched: bool,
}

/// Bed angles for every point: Eq. 10–12 outside the singularity cone, and inside it C
/// interpolated linearly, by length along the path, between the last point before and the
/// first point after the cone (the paper's singularity cone with C-axis patching), B then by
/// [`tilt_for`]. A path (a point that is not a print move and the print moves after it) is
/// patched on its own; a path that starts (ends) in the cone takes the C of its first (last)
/// point outside it, one wholly inside keeps the C the machine is at.
pub(super) fn plan_poses(
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

fn axis_error(q: &PathPoint, name: &str, reason: String, remedy: String) -> PostError {
    PostError::Delta5Axis {
        feature: q.feature as usize,
        i: q.axis[0],
        j: q.axis[1],
        k: q.axis[2],
        name: name.to_string(),
        reason,
        remedy,
    }
}

/// B limits are named rounded up to a multiple of this (degrees) in a refusal's remedy.
const B_REMEDY_STEP_DEG: f64 = 5.0;

/// The remedy of a tool axis needing B `need` degrees: a machine whose B limits reach it
/// (rounded up to [`B_REMEDY_STEP_DEG`], at most 180).
fn b_remedy(need: f64) -> String {
    let up = ((need.abs() / B_REMEDY_STEP_DEG).ceil() * B_REMEDY_STEP_DEG).min(180.0);
    format!(": a machine with B up to {up} degrees (delta5.b_limits_deg) would take it")
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
        let a = unit(q.axis).ok_or_else(|| {
            axis_error(
                q,
                name,
                "is not a direction (zero length)".into(),
                String::new(),
            )
        })?;
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
                    g.b_limits_deg[1],
                ),
                b_remedy(need),
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
                let f = if s[k] - s[j] > ARC_ZERO {
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
                    g.b_limits_deg[1],
                ),
                b_remedy(b[i]),
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
            feature: run.first().map_or(0, |q| q.feature as usize),
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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::{MachineKind, MachineProfile};

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
}
