//! Fixtures, geometry and read-back checks shared by the KUKA post's tests: tool paths to post,
//! the KRL read back and compared with the plan (LIN and spline programs), and the checks of
//! the program's cell conventions (safe point, signals, Status and Turn, joints.csv).
#![allow(dead_code)]

use robot_post::krl::{self, KrlMove, KrlRead, Motion, Target};
use robot_post::kuka::{Pose, SPLINE_MIN_SEGMENT};
use robot_post::{MachineKind, MachineProfile, MoveKind, PathPoint, ToolPath};

pub const W: f64 = 0.45;

pub const T: f64 = 0.2;

pub fn profile() -> MachineProfile {
    MachineProfile::builtin(MachineKind::Kuka)
}

pub fn pt(feature: usize, layer: usize, kind: MoveKind, p: [f64; 3], axis: [f64; 3]) -> PathPoint {
    let n = (axis[0] * axis[0] + axis[1] * axis[1] + axis[2] * axis[2]).sqrt();
    PathPoint {
        feature: feature as u32,
        layer: layer as u32,
        kind,
        p,
        axis: [axis[0] / n, axis[1] / n, axis[2] / n],
        e: if kind == MoveKind::Print { 0.03 } else { 0.0 },
        thickness: T as f32,
        width: W as f32,
        role: robot_post::toolpath::Role::Perimeter,
    }
}

/// Appends one path: a travel to the first point, print moves to the others.
pub fn push_path(path: &mut ToolPath, feature: usize, layer: usize, pts: &[([f64; 3], [f64; 3])]) {
    for (k, (p, a)) in pts.iter().enumerate() {
        let kind = if k == 0 {
            MoveKind::Travel
        } else {
            MoveKind::Print
        };
        path.points.push(pt(feature, layer, kind, *p, *a));
    }
}

/// Layers on a hemisphere of radius 40 mm (centre at part Z 0): latitude circles from 60° to
/// 10° from the pole, each a closed path of 72 segments, the tool axis the sphere's normal.
pub fn hemisphere(feature: usize) -> ToolPath {
    let mut path = ToolPath::default();
    let r = 40.0;
    for (layer, polar_deg) in (10..=60).rev().step_by(5).enumerate() {
        let phi = f64::from(polar_deg).to_radians();
        let pts: Vec<_> = (0..=72)
            .map(|k| {
                let az = f64::from(k) * 5.0_f64.to_radians() + layer as f64 * 0.3;
                let n = [phi.sin() * az.cos(), phi.sin() * az.sin(), phi.cos()];
                ([r * n[0], r * n[1], r * n[2]], n)
            })
            .collect();
        push_path(&mut path, feature, layer, &pts);
    }
    path
}

/// A path over the pole of the hemisphere along a meridian: the tool axis tilts from 60° one
/// way through vertical to 60° the other way (in the XZ plane, then in a skew plane).
pub fn through_pole(feature: usize) -> ToolPath {
    let mut path = ToolPath::default();
    let r = 40.0;
    for (layer, plane_deg) in [0.0f64, 90.0, 35.0].iter().enumerate() {
        let az = plane_deg.to_radians();
        let pts: Vec<_> = (-60..=60)
            .step_by(2)
            .map(|d| {
                let t = f64::from(d).to_radians();
                let n = [t.sin() * az.cos(), t.sin() * az.sin(), t.cos()];
                ([r * n[0], r * n[1], r * n[2]], n)
            })
            .collect();
        push_path(&mut path, feature, layer, &pts);
    }
    path
}

/// Squares on planes tilted by 20°, 40° and 60° towards four directions, tool axis the plane
/// normal.
pub fn tilted_planes(feature: usize) -> ToolPath {
    let mut path = ToolPath::default();
    let mut layer = 0;
    for tilt in [20.0f64, 40.0, 60.0] {
        for dir in [0.0f64, 90.0, 180.0, 270.0] {
            let (t, d) = (tilt.to_radians(), dir.to_radians());
            let n = [t.sin() * d.cos(), t.sin() * d.sin(), t.cos()];
            // Two unit vectors in the plane.
            let u = [-d.sin(), d.cos(), 0.0];
            let v = [
                n[1] * u[2] - n[2] * u[1],
                n[2] * u[0] - n[0] * u[2],
                n[0] * u[1] - n[1] * u[0],
            ];
            let c = [30.0 * d.cos(), 30.0 * d.sin(), 15.0];
            let corners = [
                (-1.0, -1.0),
                (1.0, -1.0),
                (1.0, 1.0),
                (-1.0, 1.0),
                (-1.0, -1.0),
            ];
            let pts: Vec<_> = corners
                .iter()
                .map(|(a, b)| {
                    let p: [f64; 3] =
                        std::array::from_fn(|k| c[k] + 8.0 * a * u[k] + 8.0 * b * v[k]);
                    (p, n)
                })
                .collect();
            push_path(&mut path, feature, layer, &pts);
            layer += 1;
        }
    }
    path
}

/// The tool axis tilts towards the robot (−X of the table) to horizontal, prints along a
/// vertical wall with the axis horizontal, and tilts back: the carried tool frame reaches
/// gimbal lock (its X axis along $BASE Z) and stays there for a while. The path is symmetric
/// about Y 0 and starts there, in line with the robot's A1 axis, so the start frame's X axis
/// points straight back at the robot and the lock is exact.
pub fn to_gimbal_lock(feature: usize) -> ToolPath {
    let mut path = ToolPath::default();
    let r = 30.0;
    let mut pts = Vec::new();
    for d in (0..=90).step_by(3) {
        let t = f64::from(d).to_radians();
        let n = [-t.sin(), 0.0, t.cos()];
        pts.push(([r * n[0], 0.0, 10.0 + r * n[2]], n));
    }
    for y in (1..=5).chain((-5..=4).rev()) {
        pts.push(([-r, f64::from(y) * 2.0, 10.0], [-1.0, 0.0, 0.0]));
    }
    for d in (0..=87).rev().step_by(3) {
        let t = f64::from(d).to_radians();
        let n = [-t.sin(), 0.0, t.cos()];
        pts.push(([r * n[0], -10.0, 10.0 + r * n[2]], n));
    }
    push_path(&mut path, feature, 0, &pts);
    path
}

/// Flat layers of a 30 mm square spiral-ish zig-zag: many short print moves, to force a split.
pub fn long_path(feature: usize, layers: usize) -> ToolPath {
    let mut path = ToolPath::default();
    for layer in 0..layers {
        let z = T * (layer as f64 + 1.0);
        let pts: Vec<_> = (0..=60)
            .map(|k| {
                let x = -15.0 + f64::from(k) * 0.5;
                let y = if k % 2 == 0 { -15.0 } else { 15.0 };
                ([x, y, z], [0.0, 0.0, 1.0])
            })
            .collect();
        push_path(&mut path, feature, layer, &pts);
    }
    path
}

pub fn all_shapes() -> ToolPath {
    let mut path = hemisphere(1);
    path.points.extend(through_pole(2).points);
    path.points.extend(tilted_planes(3).points);
    path
}

// --- geometry, written out here so the test does not trust the post's own helpers ---------------

pub type M3 = [[f64; 3]; 3];

pub fn mat_mul(a: &M3, b: &M3) -> M3 {
    std::array::from_fn(|i| std::array::from_fn(|j| (0..3).map(|k| a[i][k] * b[k][j]).sum()))
}

/// R_z(A)·R_y(B)·R_x(C), degrees.
pub fn rebuild(a: f64, b: f64, c: f64) -> M3 {
    let (sa, ca) = a.to_radians().sin_cos();
    let (sb, cb) = b.to_radians().sin_cos();
    let (sc, cc) = c.to_radians().sin_cos();
    let rz = [[ca, -sa, 0.0], [sa, ca, 0.0], [0.0, 0.0, 1.0]];
    let ry = [[cb, 0.0, sb], [0.0, 1.0, 0.0], [-sb, 0.0, cb]];
    let rx = [[1.0, 0.0, 0.0], [0.0, cc, -sc], [0.0, sc, cc]];
    mat_mul(&mat_mul(&rz, &ry), &rx)
}

pub fn angle_deg(u: [f64; 3], v: [f64; 3]) -> f64 {
    let d = u[0] * v[0] + u[1] * v[1] + u[2] * v[2];
    let c = [
        u[1] * v[2] - u[2] * v[1],
        u[2] * v[0] - u[0] * v[2],
        u[0] * v[1] - u[1] * v[0],
    ];
    let s = (c[0] * c[0] + c[1] * c[1] + c[2] * c[2]).sqrt();
    s.atan2(d).to_degrees()
}

/// The angle of the rotation between two matrices (degrees).
pub fn rotation_between(a: &M3, b: &M3) -> f64 {
    let at: M3 = std::array::from_fn(|i| std::array::from_fn(|j| a[j][i]));
    let m = mat_mul(&at, b);
    let w = [m[2][1] - m[1][2], m[0][2] - m[2][0], m[1][0] - m[0][1]];
    let s = (w[0] * w[0] + w[1] * w[1] + w[2] * w[2]).sqrt() / 2.0;
    s.atan2((m[0][0] + m[1][1] + m[2][2] - 1.0) / 2.0)
        .to_degrees()
}

pub fn frame_of(m: &KrlMove) -> [f64; 6] {
    match m.target {
        Target::Frame(f) => f,
        Target::Axis(_) => panic!("{}:{} is not a Cartesian motion", m.file, m.line),
    }
}

/// Reads the program back and checks every planned point against it: print points are the
/// LINs with the extruder on, in order (position within 0.01 mm, tool axis = −Z of the rebuilt
/// rotation within 0.1°); every travel point is the last LIN before its path prints.
pub fn round_trip(path: &ToolPath, files: &[(String, String)]) -> KrlRead {
    let read = krl::read(files).unwrap_or_else(|e| panic!("reader refused the program: {e}"));
    let offset = read.offset.expect("part offset comment");
    assert!(read.base.is_some() && read.tool.is_some());
    let moves = &read.moves;
    // The run of moves with the extruder on after each off -> on switch.
    let mut runs: Vec<(usize, usize)> = Vec::new();
    for (i, m) in moves.iter().enumerate() {
        if m.extruder && (i == 0 || !moves[i - 1].extruder) {
            runs.push((i, i));
        }
        if m.extruder {
            runs.last_mut().expect("run").1 = i;
            assert_eq!(m.motion, Motion::Lin, "{}:{}", m.file, m.line);
        }
    }
    // The print runs of the path: a travel point, then print points. A print point where the
    // nozzle already is (same position and axis as the point before) has no motion.
    let same = |a: &PathPoint, b: &PathPoint| a.p == b.p && a.axis == b.axis;
    let mut points: Vec<&PathPoint> = Vec::new();
    for (i, q) in path.points.iter().enumerate() {
        if !(i > 0 && q.kind == MoveKind::Print && same(q, &path.points[i - 1])) {
            points.push(q);
        }
    }
    let mut paths: Vec<(usize, usize, usize)> = Vec::new();
    for (i, q) in points.iter().enumerate() {
        if q.kind == MoveKind::Print && i > 0 && points[i - 1].kind == MoveKind::Travel {
            paths.push((i - 1, i, i));
        }
        if q.kind == MoveKind::Print {
            if let Some(last) = paths.last_mut() {
                last.2 = i;
            }
        }
    }
    assert_eq!(
        runs.len(),
        paths.len(),
        "extruder switched on once per path"
    );
    let check = |m: &KrlMove, q: &PathPoint, what: &str| {
        let f = frame_of(m);
        for k in 0..3 {
            assert!(
                (f[k] - offset[k] - q.p[k]).abs() <= 0.01,
                "{what} at {}:{}: {f:?} vs {:?}",
                m.file,
                m.line,
                q.p
            );
        }
        let r = rebuild(f[3], f[4], f[5]);
        let nozzle = [-r[0][2], -r[1][2], -r[2][2]];
        let err = angle_deg(nozzle, q.axis);
        assert!(
            err <= 0.1,
            "{what} at {}:{}: axis off by {err}°",
            m.file,
            m.line
        );
    };
    for ((start, end), (travel, first, last)) in runs.iter().zip(&paths) {
        assert_eq!(end - start, last - first, "one LIN per print point");
        for k in 0..=(end - start) {
            check(&moves[start + k], points[first + k], "print");
        }
        assert!(*start > 0 && !moves[start - 1].extruder);
        check(&moves[start - 1], points[*travel], "travel");
        // Off before the travel that follows.
        if let Some(next) = moves.get(end + 1) {
            assert!(!next.extruder);
        }
    }
    read
}

/// A and C never jump: between consecutive Cartesian motions they change by no more than the
/// rotation allows (|ΔC| ≤ δ / cos B, |ΔA| ≤ δ·(1 + |tan B|), δ the rotation angle), B
/// stays within ±90°.
pub fn assert_continuous_angles(read: &KrlRead) {
    let frames: Vec<(&KrlMove, [f64; 6])> = read
        .moves
        .iter()
        .filter_map(|m| match m.target {
            Target::Frame(f) => Some((m, f)),
            Target::Axis(_) => None,
        })
        .collect();
    for w in frames.windows(2) {
        let ((m0, f0), (m1, f1)) = (w[0], w[1]);
        assert!(f1[4].abs() <= 90.0 + 1e-4, "B {}", f1[4]);
        let delta = rotation_between(&rebuild(f0[3], f0[4], f0[5]), &rebuild(f1[3], f1[4], f1[5]));
        let b = f0[4].abs().max(f1[4].abs()).to_radians();
        let (da, dc) = ((f1[3] - f0[3]).abs(), (f1[5] - f0[5]).abs());
        let slack = 0.01;
        if b.cos() > 1e-3 {
            assert!(
                dc <= 1.1 * delta / b.cos() + slack && da <= 1.1 * delta * (1.0 + b.tan()) + slack,
                "{}:{} -> {}:{}: A {} -> {}, C {} -> {}, rotation {delta}°",
                m0.file,
                m0.line,
                m1.file,
                m1.line,
                f0[3],
                f1[3],
                f0[5],
                f1[5]
            );
        } else {
            // At gimbal lock A is held and C takes the rotation.
            assert!(
                da <= slack,
                "A moved {da}° at gimbal lock, {}:{}",
                m1.file,
                m1.line
            );
            assert!(
                dc <= delta + slack,
                "C moved {dc}° at gimbal lock, {}:{}",
                m1.file,
                m1.line
            );
        }
        // Never a turn's worth.
        assert!(da < 180.0 && dc < 180.0);
    }
}

/// The flange pose of a Cartesian motion read back, in the robot's base frame.
pub fn flange_of(read: &KrlRead, f: [f64; 6]) -> Pose {
    let base = Pose::from_frame(read.base.expect("$BASE"));
    let tool_inv = Pose::from_frame(read.tool.expect("$TOOL")).inverse();
    base.compose(&Pose::from_frame(f)).compose(&tool_inv)
}

/// The safe point's checks: the program's first Cartesian motion is a PTP `height` over the
/// part's top (`$BASE` Z), over the first path's start, the tool upright; its last is a PTP
/// back to the same point.
pub fn assert_safe_points(path: &ToolPath, read: &KrlRead, height: f64) {
    let offset = read.offset.expect("offset");
    let top = path
        .points
        .iter()
        .filter(|q| q.kind == MoveKind::Print)
        .map(|q| q.p[2])
        .fold(f64::NEG_INFINITY, f64::max)
        + offset[2];
    let start = path.points[0].p;
    let cart: Vec<&KrlMove> = read
        .moves
        .iter()
        .filter(|mv| matches!(mv.target, Target::Frame(_)))
        .collect();
    let (first, last) = (cart[0], cart[cart.len() - 1]);
    for mv in [first, last] {
        assert_eq!(mv.motion, Motion::Ptp, "{}:{}", mv.file, mv.line);
        assert!(mv.status_turn.is_some(), "{}:{}", mv.file, mv.line);
        assert!(!mv.extruder);
        let f = frame_of(mv);
        assert!((f[2] - (top + height)).abs() < 2e-3, "{f:?}, top {top}");
        assert!((f[0] - offset[0] - start[0]).abs() < 2e-3, "{f:?}");
        assert!((f[1] - offset[1] - start[1]).abs() < 2e-3, "{f:?}");
        let r = rebuild(f[3], f[4], f[5]);
        assert!(angle_deg([-r[0][2], -r[1][2], -r[2][2]], [0.0, 0.0, 1.0]) < 1e-3);
    }
    // Home before and after.
    let n = read.moves.len();
    assert!(matches!(read.moves[0].target, Target::Axis(_)));
    assert!(matches!(read.moves[n - 1].target, Target::Axis(_)));
    // Nothing between home and the safe point, or after it.
    assert!(std::ptr::eq(first, &read.moves[1]) && std::ptr::eq(last, &read.moves[n - 2]));
}

/// The extruder's signals read back: the stop interrupt declared, on, and resetting the feed
/// and the extruder before braking; both reset when the program ends; with `ready`, the wait
/// for that input right after the safe point, before any print move.
pub fn assert_signals(m: &MachineProfile, read: &KrlRead, ready: Option<u32>) {
    let cell = m.kuka.as_ref().expect("kuka");
    let stops: Vec<_> = read
        .interrupts
        .iter()
        .filter(|i| i.condition == "$STOPMESS==TRUE")
        .collect();
    assert_eq!(stops.len(), 1, "{:?}", read.interrupts);
    let irq = stops[0];
    assert!(irq.on && irq.brakes, "{irq:?}");
    assert_eq!(irq.analog, vec![(cell.feed_output, 0.0)]);
    assert_eq!(irq.outputs, vec![(cell.extruder_output, false)]);
    assert_eq!(read.end_feed, Some(0.0));
    assert!(!read.end_extruder);
    match (ready, &read.ready) {
        (None, None) => {}
        (Some(n), Some(r)) => {
            assert_eq!(r.input, n);
            assert!((r.timeout_s - cell.ready_timeout).abs() < 1e-9);
            assert!(r.halts);
            // Right after the safe point's PTP, before the first print move.
            let safe = &read.moves[r.before_move - 1];
            assert_eq!(safe.motion, Motion::Ptp);
            assert!(matches!(safe.target, Target::Frame(_)));
            let first_print = read.moves.iter().position(|mv| mv.extruder);
            assert!(first_print.is_some_and(|i| i >= r.before_move));
        }
        (want, got) => panic!("ready input {want:?}, read {got:?}"),
    }
}

/// Layers of long straight lines finely divided and gentle arcs (radius 150 mm), the tool
/// axis upright, filament 0.02 mm per mm: what a spline program writes with few points.
pub fn lines_and_arcs(feature: usize) -> ToolPath {
    let mut path = ToolPath::default();
    for layer in 0..4 {
        let z = T * (layer as f64 + 1.0);
        let y0 = -20.0 + 10.0 * layer as f64;
        let mut pts: Vec<([f64; 3], [f64; 3])> = (0..=160)
            .map(|k| ([-30.0 + 0.25 * f64::from(k), y0, z], [0.0, 0.0, 1.0]))
            .collect();
        let r = 150.0;
        for k in 1..=120 {
            let t = f64::from(k) * 0.5 / r;
            pts.push((
                [10.0 + r * t.sin(), y0 + r * (1.0 - t.cos()), z],
                [0.0, 0.0, 1.0],
            ));
        }
        push_path(&mut path, feature, layer, &pts);
    }
    for i in 1..path.points.len() {
        if path.points[i].kind == MoveKind::Print {
            let (a, b) = (path.points[i - 1].p, path.points[i].p);
            let d = ((b[0] - a[0]).powi(2) + (b[1] - a[1]).powi(2) + (b[2] - a[2]).powi(2)).sqrt();
            path.points[i].e = 0.02 * d;
        }
    }
    path
}

pub fn sub3(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}

pub fn len3(a: [f64; 3]) -> f64 {
    (a[0] * a[0] + a[1] * a[1] + a[2] * a[2]).sqrt()
}

/// The distance from `p` to the segment `a`-`b`, and where along it (0..1) the nearest point is.
pub fn to_segment(p: [f64; 3], a: [f64; 3], b: [f64; 3]) -> (f64, f64) {
    let ab = sub3(b, a);
    let l2 = ab[0] * ab[0] + ab[1] * ab[1] + ab[2] * ab[2];
    let ap = sub3(p, a);
    let t = if l2 > 0.0 {
        ((ap[0] * ab[0] + ap[1] * ab[1] + ap[2] * ab[2]) / l2).clamp(0.0, 1.0)
    } else {
        0.0
    };
    (
        len3([ap[0] - t * ab[0], ap[1] - t * ab[1], ap[2] - t * ab[2]]),
        t,
    )
}

/// The distance from `p` to a polyline.
pub fn to_polyline(p: [f64; 3], line: &[[f64; 3]]) -> f64 {
    line.windows(2)
        .map(|w| to_segment(p, w[0], w[1]).0)
        .fold(f64::INFINITY, f64::min)
}

/// Reads a spline program back and checks it against the plan, path by path: each print run
/// is a spline block's segments from the path's travel point; every point written is a
/// planned point; every planned point lies within half the spline tolerance of the written
/// polyline, its tool axis within 0.2° of the axis turned between the written ends; every
/// `SPL` segment, drawn as a cubic whose end tangents bisect the turns at its ends, stays
/// within the tolerance of the planned path; the filament fed over each run is the plan's.
pub fn spline_round_trip(
    path: &ToolPath,
    m: &MachineProfile,
    files: &[(String, String)],
) -> KrlRead {
    let cell = m.kuka.as_ref().expect("kuka");
    let tol = cell.spline_tolerance;
    let read = krl::read(files).unwrap_or_else(|e| panic!("reader refused the program: {e}"));
    let offset = read.offset.expect("part offset comment");
    let moves = &read.moves;
    let mut runs: Vec<(usize, usize)> = Vec::new();
    for (i, mv) in moves.iter().enumerate() {
        if mv.extruder && (i == 0 || !moves[i - 1].extruder) {
            runs.push((i, i));
        }
        if mv.extruder {
            runs.last_mut().expect("run").1 = i;
            assert!(
                matches!(mv.motion, Motion::Spl | Motion::Slin),
                "{}:{}",
                mv.file,
                mv.line
            );
        }
    }
    // The planned paths: a travel point and its print points.
    let mut paths: Vec<Vec<&PathPoint>> = Vec::new();
    for (i, q) in path.points.iter().enumerate() {
        let next_print = path
            .points
            .get(i + 1)
            .is_some_and(|n| n.kind == MoveKind::Print);
        if q.kind == MoveKind::Travel && next_print {
            paths.push(vec![q]);
        } else if q.kind == MoveKind::Print {
            paths.last_mut().expect("a path").push(q);
        }
    }
    assert_eq!(
        runs.len(),
        paths.len(),
        "extruder switched on once per path"
    );
    let part = |f: [f64; 6]| [f[0] - offset[0], f[1] - offset[1], f[2] - offset[2]];
    let axis = |f: [f64; 6]| {
        let r = rebuild(f[3], f[4], f[5]);
        [-r[0][2], -r[1][2], -r[2][2]]
    };
    for ((start, end), planned) in runs.iter().zip(&paths) {
        let written: Vec<[f64; 6]> = (start - 1..=*end).map(|i| frame_of(&moves[i])).collect();
        let line: Vec<[f64; 3]> = written.iter().map(|f| part(*f)).collect();
        let plan: Vec<[f64; 3]> = planned.iter().map(|q| q.p).collect();
        assert!(
            len3(sub3(line[0], plan[0])) <= 0.01,
            "starts at the travel point"
        );
        assert!(len3(sub3(line[line.len() - 1], plan[plan.len() - 1])) <= 0.01);
        for p in &line {
            assert!(
                plan.iter().any(|q| len3(sub3(*p, *q)) <= 0.01),
                "{p:?} is not a planned point"
            );
        }
        // The written points are planned points in order: each planned point lies on the
        // segment to the next written one, or is it.
        let mut j = 0;
        for q in planned.iter().skip(1) {
            let k = j.min(line.len() - 2);
            let (d, t) = to_segment(q.p, line[k], line[k + 1]);
            assert!(d <= tol / 2.0 + 2e-3, "planned {:?} is {d} mm off", q.p);
            let (a0, a1) = (axis(written[k]), axis(written[k + 1]));
            let mix: [f64; 3] = std::array::from_fn(|i| (1.0 - t) * a0[i] + t * a1[i]);
            let err = angle_deg(mix, q.axis);
            assert!(err <= 0.2, "axis at {:?} off by {err}°", q.p);
            if j + 1 < line.len() && len3(sub3(q.p, line[j + 1])) <= 0.01 {
                j += 1;
            }
        }
        assert_eq!(j, line.len() - 1, "every written point met in order");
        // SPL segments drawn as cubics stay within the tolerance of the planned path.
        for k in 1..line.len() {
            if moves[start + k - 1].motion != Motion::Spl {
                continue;
            }
            assert!(k >= 2 && k + 1 < line.len(), "an SPL at a block's end");
            // Its neighbours have a direction.
            for (a, b) in [(line[k - 2], line[k - 1]), (line[k], line[k + 1])] {
                assert!(len3(sub3(b, a)) >= SPLINE_MIN_SEGMENT - 2e-3);
            }
            let unit = |v: [f64; 3]| {
                let n = len3(v);
                [v[0] / n, v[1] / n, v[2] / n]
            };
            let (p0, p1) = (line[k - 1], line[k]);
            let l = len3(sub3(p1, p0));
            let d_prev = unit(sub3(p0, line[k - 2]));
            let d = unit(sub3(p1, p0));
            let d_next = unit(sub3(line[k + 1], p1));
            let m0 = unit(std::array::from_fn(|i| d_prev[i] + d[i]));
            let m1 = unit(std::array::from_fn(|i| d[i] + d_next[i]));
            for j in 1..16 {
                let s = f64::from(j) / 16.0;
                let (h00, h10, h01, h11) = (
                    2.0 * s.powi(3) - 3.0 * s * s + 1.0,
                    s.powi(3) - 2.0 * s * s + s,
                    -2.0 * s.powi(3) + 3.0 * s * s,
                    s.powi(3) - s * s,
                );
                let c: [f64; 3] = std::array::from_fn(|i| {
                    h00 * p0[i] + h10 * l * m0[i] + h01 * p1[i] + h11 * l * m1[i]
                });
                let d = to_polyline(c, &plan);
                assert!(
                    d <= tol + 2e-3,
                    "SPL {}:{} bulges {d} mm",
                    moves[start + k - 1].file,
                    moves[start + k - 1].line
                );
            }
        }
        // The filament: the feed in force over each segment's length.
        let fed: f64 = (1..line.len())
            .map(|k| {
                let f = moves[start + k - 1].feed.expect("a feed");
                f * cell.feed_ratio_full_scale * len3(sub3(line[k], line[k - 1]))
            })
            .sum();
        let e: f64 = planned.iter().skip(1).map(|q| q.e).sum();
        assert!(
            (fed - e).abs() <= 1e-3 * e + 1e-4,
            "fed {fed} mm of filament, planned {e}"
        );
    }
    read
}

/// Every Cartesian PTP carries S and T.
pub fn assert_status_turn(read: &KrlRead) {
    for mv in &read.moves {
        if mv.motion == Motion::Ptp && matches!(mv.target, Target::Frame(_)) {
            assert!(mv.status_turn.is_some(), "{}:{}", mv.file, mv.line);
        }
    }
}

/// The rows of a program's `joints.csv`: the motion's number, the path point it goes to and
/// its joints (none when out of reach).
pub fn joint_rows(files: &[(String, String)]) -> Vec<(usize, usize, Option<[f64; 6]>)> {
    let (_, text) = files
        .iter()
        .find(|(n, _)| n == robot_post::kuka::JOINTS_CSV)
        .expect("joints.csv");
    let mut lines = text.lines();
    assert_eq!(lines.next(), Some(robot_post::kuka::JOINTS_HEADER));
    lines
        .map(|l| {
            let cells: Vec<&str> = l.split(',').collect();
            assert_eq!(cells.len(), 8, "{l}");
            let n: usize = cells[0].parse().expect("move number");
            let point: usize = cells[1].parse().expect("point");
            let joints = if cells[2..].iter().all(|c| c.is_empty()) {
                None
            } else {
                let v: Vec<f64> = cells[2..]
                    .iter()
                    .map(|c| c.parse().expect("a joint angle"))
                    .collect();
                Some([v[0], v[1], v[2], v[3], v[4], v[5]])
            };
            (n, point, joints)
        })
        .collect()
}
