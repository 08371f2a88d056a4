//! Placements found by search (`robot_post::fit`): the least turn about +Z that fits a bed or
//! work envelope, and the least move on the KUKA table that brings every point into reach.

use robot_post::fit::{
    bounding_path, envelope_excess, reach_shift, turn_to_fit, turned, unreachable_points, FitError,
};
use robot_post::fit::{reach::FINE_SHIFT_MM, turn::FINE_STEP_DEG};
use robot_post::placement::bed_offset;
use robot_post::toolpath::Role;
use robot_post::{delta5, MachineKind, MachineProfile, MoveKind, PathPoint, ToolPath};

const T: f64 = 0.2;
const W: f64 = 0.45;
const UP: [f64; 3] = [0.0, 0.0, 1.0];

fn pt(kind: MoveKind, p: [f64; 3], axis: [f64; 3]) -> PathPoint {
    PathPoint {
        feature: 1,
        layer: 0,
        kind,
        p,
        axis,
        e: if kind == MoveKind::Print { 0.03 } else { 0.0 },
        thickness: T as f32,
        width: W as f32,
        role: Role::Perimeter,
    }
}

/// The outline of an `lx` × `ly` mm rectangle with a corner at the origin, one layer on the
/// plate, beads every `step` mm along it, tool axis `axis`.
fn rectangle(lx: f64, ly: f64, step: f64, axis: [f64; 3]) -> ToolPath {
    let corners = [[0.0, 0.0], [lx, 0.0], [lx, ly], [0.0, ly], [0.0, 0.0]];
    let mut points = vec![pt(MoveKind::Travel, [0.0, 0.0, T], axis)];
    for w in corners.windows(2) {
        let n = ((w[1][0] - w[0][0]).hypot(w[1][1] - w[0][1]) / step).ceil() as usize;
        for k in 1..=n {
            let f = k as f64 / n as f64;
            let x = w[0][0] + f * (w[1][0] - w[0][0]);
            let y = w[0][1] + f * (w[1][1] - w[0][1]);
            points.push(pt(MoveKind::Print, [x, y, T], axis));
        }
    }
    ToolPath { points }
}

fn marlin_bed(x: f64, y: f64) -> MachineProfile {
    let mut m = MachineProfile::builtin(MachineKind::Marlin);
    m.bed_size = [x, y, 100.0];
    m
}

#[test]
fn a_bar_longer_than_the_bed_fits_turned_towards_its_diagonal() {
    // 200 × 20 mm on a 160 × 160 bed: too long along X, (200 + 20)/√2 = 155.6 mm across at
    // 45°, so some turn of at most 45° fits.
    let bar = rectangle(200.0, 20.0, 5.0, UP);
    let m = marlin_bed(160.0, 160.0);
    assert!(bed_offset(&bar, &m).is_err());
    let fit = turn_to_fit(&bar, &m).expect("a turn fits");
    // Placed centred, it overhangs each end by half of 200 + W − 160 mm.
    assert!(
        (fit.excess_at_zero_mm - (200.0 + W - 160.0) / 2.0).abs() < 1e-6,
        "{fit:?}"
    );
    assert!(
        fit.angle_deg.abs() > 0.0 && fit.angle_deg.abs() <= 45.0,
        "{fit:?}"
    );
    // The post places the turned bar on the bed, and one fine step less does not fit: the
    // least turn.
    assert!(bed_offset(&turned(&bar, fit.angle_deg), &m).is_ok());
    let less = fit.angle_deg - fit.angle_deg.signum() * FINE_STEP_DEG;
    assert!(bed_offset(&turned(&bar, less), &m).is_err(), "{fit:?}");
    // A bar that fits as modelled is not turned.
    let fit = turn_to_fit(&bar, &marlin_bed(220.0, 220.0)).expect("fits");
    assert_eq!(fit.angle_deg, 0.0);
    assert_eq!(fit.excess_at_zero_mm, 0.0);
}

#[test]
fn a_bar_longer_than_the_bed_diagonal_gets_the_turn_that_misses_least() {
    let bar = rectangle(300.0, 20.0, 5.0, UP);
    let m = marlin_bed(160.0, 160.0);
    match turn_to_fit(&bar, &m) {
        Err(FitError::NoTurn {
            angle_deg,
            excess_mm,
            ..
        }) => {
            // At 45° the bar spans (300 + 20)/√2 + W ≈ 226.7 mm of the 160 mm bed.
            assert!((angle_deg.abs() - 45.0).abs() <= 1.0, "{angle_deg}");
            let at_45 = (320.0 / 2f64.sqrt() + W - 160.0) / 2.0;
            assert!((excess_mm - at_45).abs() < 1.0, "{excess_mm} vs {at_45}");
            let at_0 = envelope_excess(&bar, &m).expect("excess");
            assert!(excess_mm < at_0);
        }
        other => panic!("{other:?}"),
    }
}

#[test]
fn a_bar_off_the_delta5_envelope_fits_turned() {
    // A planar bar along X, 205 mm long: its ends leave the 200 × 200 mm envelope (X within
    // ±100 mm of the C axis) as modelled.
    let bar = rectangle(205.0, 10.0, 2.0, UP);
    let m = MachineProfile::builtin(MachineKind::Delta5);
    assert!(envelope_excess(&bar, &m).expect("excess") > 2.0);
    assert!(delta5(&bar, &m, "bar").is_err());
    let fit = turn_to_fit(&bar, &m).expect("a turn fits");
    assert!(
        fit.angle_deg != 0.0 && fit.angle_deg.abs() <= 45.0,
        "{fit:?}"
    );
    assert!(delta5(&turned(&bar, fit.angle_deg), &m, "bar").is_ok());
}

/// The default cell with its table centre `x` mm in front of the A1 axis.
fn kuka_with_table_at(x: f64) -> MachineProfile {
    let mut m = MachineProfile::builtin(MachineKind::Kuka);
    if let Some(cell) = m.kuka.as_mut() {
        cell.base.x = x;
    }
    m
}

#[test]
fn a_part_just_out_of_reach_comes_in_with_the_least_move() {
    // A 10 × 10 mm square printed with the nozzle pointing down, on a table moved out until
    // the far edge leaves the arm's reach.
    let part = rectangle(10.0, 10.0, 1.0, UP);
    let unreachable = |x: f64| unreachable_points(&part, &kuka_with_table_at(x)).expect("post");
    let (mut near, mut far) = (450.0, 2000.0);
    assert_eq!(unreachable(near), 0);
    assert!(unreachable(far) > 0);
    while far - near > 0.01 {
        let mid = (near + far) / 2.0;
        if unreachable(mid) > 0 {
            far = mid;
        } else {
            near = mid;
        }
    }
    // 3 mm past the last table position that reaches everything.
    let out = near + 3.0;
    let m = kuka_with_table_at(out);
    let fit = reach_shift(&part, &m).expect("a move reaches");
    assert!(fit.unreachable_before > 0);
    assert_eq!(unreachable_points(&part, &fit.apply(&m)).expect("post"), 0);
    let length = fit.shift[0].hypot(fit.shift[1]);
    assert!(length >= 3.0 - 0.01, "{fit:?}");
    assert!(length <= 3.0 + 2.0 * FINE_SHIFT_MM, "{fit:?}");
    // Towards the robot.
    assert!(fit.shift[0] < 0.0, "{fit:?}");
    // The profile's key reads back.
    let text = fit.apply(&m).to_toml();
    let back = MachineProfile::from_toml(&text).expect("profile");
    assert_eq!(back, fit.apply(&m));
}

#[test]
fn a_part_in_reach_is_not_moved_and_one_far_out_is_refused() {
    let part = rectangle(10.0, 10.0, 1.0, UP);
    let fit = reach_shift(&part, &kuka_with_table_at(450.0)).expect("in reach");
    assert_eq!(fit.shift, [0.0, 0.0]);
    assert_eq!(fit.unreachable_before, 0);
    match reach_shift(&part, &kuka_with_table_at(3000.0)) {
        Err(FitError::NoShift { unreachable, .. }) => assert!(unreachable > 0),
        other => panic!("{other:?}"),
    }
}

#[test]
fn the_kuka_post_moves_the_part_by_part_position_and_warns_off_the_table() {
    let part = rectangle(10.0, 10.0, 1.0, UP);
    let m = MachineProfile::builtin(MachineKind::Kuka);
    let offset = |m: &MachineProfile| -> (Vec<f64>, Vec<String>) {
        let program = robot_post::kuka(&part, m, "part", "part.step").expect("post");
        let line = program.files[0]
            .1
            .lines()
            .find(|l| l.contains("part offset"))
            .expect("offset line")
            .to_string();
        let xyz = line
            .split_whitespace()
            .filter_map(|w| w.get(1..).and_then(|v| v.parse::<f64>().ok()))
            .take(3)
            .collect();
        (xyz, program.warnings)
    };
    let (centred, warnings) = offset(&m);
    assert!(!warnings.iter().any(|w| w.contains("part_position")));
    let mut moved = m.clone();
    let half_table = m.bed_size[0] / 2.0;
    // 20 mm in from the table's edge: on the table, no warning.
    let dx = half_table - 5.0 - W / 2.0 - 20.0;
    moved.kuka.as_mut().expect("kuka").part_position = [-dx, 7.5];
    let (xyz, warnings) = offset(&moved);
    assert!(
        (xyz[0] - centred[0] + dx).abs() < 1e-3,
        "{xyz:?} {centred:?}"
    );
    assert!(
        (xyz[1] - centred[1] - 7.5).abs() < 1e-3,
        "{xyz:?} {centred:?}"
    );
    assert_eq!(xyz[2], centred[2]);
    assert!(!warnings.iter().any(|w| w.contains("part_position")));
    // 20 mm past it: the part overhangs by 20 mm, written with a warning.
    moved.kuka.as_mut().expect("kuka").part_position = [dx + 40.0, 0.0];
    let (_, warnings) = offset(&moved);
    let w = warnings
        .iter()
        .find(|w| w.contains("part_position"))
        .expect("warned");
    assert!(w.contains("by up to 20.000 mm"), "{w}");
}

#[test]
fn the_corners_of_a_bar_fit_turned_as_its_beads_do() {
    // The bar's box corners, before any path is planned: no bead width, so (200 × cos a +
    // 20 × sin a) ≤ 160 at the least turn a, and a slightly smaller turn than its beads need.
    let corners = [
        [0.0, 0.0, 0.0],
        [200.0, 0.0, 0.0],
        [200.0, 20.0, 0.0],
        [0.0, 20.0, 0.0],
        [0.0, 0.0, 10.0],
        [200.0, 20.0, 10.0],
    ];
    let m = marlin_bed(160.0, 160.0);
    let fit = turn_to_fit(&bounding_path(&corners), &m).expect("a turn fits");
    let a = fit.angle_deg.abs().to_radians();
    assert!(200.0 * a.cos() + 20.0 * a.sin() <= 160.0 + 1e-3, "{fit:?}");
    let b = (fit.angle_deg.abs() - FINE_STEP_DEG).to_radians();
    assert!(200.0 * b.cos() + 20.0 * b.sin() > 160.0, "{fit:?}");
    let beads = turn_to_fit(&rectangle(200.0, 20.0, 5.0, UP), &m).expect("fits");
    assert!(
        fit.angle_deg.abs() <= beads.angle_deg.abs(),
        "{fit:?} {beads:?}"
    );
}

/// On delta5 a planar plan's turn is searched on the few points that decide it: their
/// envelope excess at every turn is the whole path's (a bar leaving the envelope, with a
/// second layer inside it and a travel out past it); a tilted axis, or a bed, keeps every
/// point.
#[test]
fn a_planar_path_on_delta5_is_turned_by_the_points_that_decide_it() {
    use robot_post::fit::turn::deciding_points;
    let mut path = rectangle(205.0, 30.0, 1.0, UP);
    for k in 0..200 {
        let x = 2.0 + k as f64;
        let y = 15.0 + 10.0 * (x / 7.0).sin();
        path.points.push(pt(MoveKind::Print, [x, y, 2.0 * T], UP));
    }
    path.points
        .push(pt(MoveKind::Travel, [-4.0, 31.0, 12.0], UP));
    path.points
        .push(pt(MoveKind::Print, [100.0, 10.0, 3.0 * T], UP));
    let m = MachineProfile::builtin(MachineKind::Delta5);
    let few = deciding_points(&path, &m).expect("a planar path");
    assert!(
        few.points.len() * 20 < path.points.len(),
        "{}",
        few.points.len()
    );
    let mut missed = 0;
    for k in 0..72 {
        let a = f64::from(k) * 5.0 - 180.0;
        let all = envelope_excess(&turned(&path, a), &m).expect("excess");
        let cheap = envelope_excess(&turned(&few, a), &m).expect("excess");
        assert!((all - cheap).abs() < 1e-9, "turn {a}: {all} vs {cheap}");
        missed += usize::from(all > 0.0);
    }
    // The bar leaves the envelope at some turns and fits at others.
    assert!(missed > 0 && missed < 72, "{missed}");
    assert!(deciding_points(&path, &marlin_bed(220.0, 220.0)).is_none());
    path.points[3].axis = [0.0, 0.6, 0.8];
    assert!(deciding_points(&path, &m).is_none());
}
