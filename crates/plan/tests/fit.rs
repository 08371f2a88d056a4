//! The machine-side placement search on a planned part: the impeller's tool path, out of the
//! default KUKA arm's reach where the post places it, is brought into reach by the least move
//! of the part on the table (`robot_post::fit::reach_shift`), which the post then honours.

use plan::{plan, Options, Process};
use robot_post::fit::{reach_shift, unreachable_points};
use robot_post::{MachineKind, MachineProfile};
use std::path::Path;

#[test]
fn the_impeller_moved_on_the_kuka_table_has_every_point_in_reach() {
    let name = "impeller.step";
    let p = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../../fixtures")
        .join(name);
    let part = brep::read_step(&p).unwrap_or_else(|e| panic!("{}: {e}", p.display()));
    let m = MachineProfile::builtin(MachineKind::Kuka);
    // The blades' edges on the hub's steep flank are refused by the support check (issue 31):
    // kept going past it; the reach the plan would mend itself is left as placed here.
    let options = Options {
        source: name.into(),
        stem: "part".into(),
        allow_collisions: true,
        keep_going: true,
        allow_unreachable: true,
        ..Default::default()
    };
    let planned = plan(&part, &Process::default(), &m, &options).expect("plans");
    let path = &planned.toolpath;
    let before = unreachable_points(path, &m).expect("post");
    assert!(
        before > 0,
        "the impeller is in reach as placed: nothing to test"
    );
    let fit = reach_shift(path, &m).expect("a place in reach");
    assert_eq!(fit.unreachable_before, before);
    let moved = fit.apply(&m);
    assert_eq!(unreachable_points(path, &moved).expect("post"), 0);
    // The program states the moved placement: its part offset is the centred one plus the
    // move.
    let centred = robot_post::kuka(path, &m, "part", name).expect("post");
    let shifted = robot_post::kuka(path, &moved, "part", name).expect("post");
    let offset = |files: &[(String, String)]| -> Vec<f64> {
        let src = &files[0].1;
        let line = src
            .lines()
            .find(|l| l.contains("part offset"))
            .expect("offset line");
        line.split_whitespace()
            .filter_map(|w| w.get(1..).and_then(|v| v.parse::<f64>().ok()))
            .take(3)
            .collect()
    };
    let (a, b) = (offset(&centred.files), offset(&shifted.files));
    assert_eq!(a.len(), 3, "{a:?}");
    assert!(
        (b[0] - a[0] - fit.shift[0]).abs() < 2e-3,
        "{a:?} {b:?} {fit:?}"
    );
    assert!(
        (b[1] - a[1] - fit.shift[1]).abs() < 2e-3,
        "{a:?} {b:?} {fit:?}"
    );
    assert!((b[2] - a[2]).abs() < 1e-9, "{a:?} {b:?}");
    eprintln!(
        "impeller on kuka: {before} unreachable; part_position {:?} (move {:.1} mm)",
        fit.part_position,
        fit.shift[0].hypot(fit.shift[1])
    );
}

#[test]
fn a_plan_moves_the_impeller_into_reach_itself_and_says_so() {
    let name = "impeller.step";
    let p = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../../fixtures")
        .join(name);
    let part = brep::read_step(&p).unwrap_or_else(|e| panic!("{}: {e}", p.display()));
    let m = MachineProfile::builtin(MachineKind::Kuka);
    let options = Options {
        source: name.into(),
        stem: "part".into(),
        allow_collisions: true,
        keep_going: true,
        ..Default::default()
    };
    // Without --allow-unreachable the plan moves the part on the table before the post.
    let planned = plan(&part, &Process::default(), &m, &options).expect("plans, moved");
    let moved = planned
        .report
        .moved_on_table
        .as_ref()
        .expect("moved on the table");
    assert!(moved.unreachable_before > 0);
    assert!(moved.distance_mm > 0.0);
    assert_eq!(planned.report.unreachable_points(), 0);
    // The program is written for the moved part: the settings record its part_position.
    let pos = &planned.report.settings.machine["kuka"]["part_position"];
    for k in 0..2 {
        let set = pos[k].as_f64().expect("part_position");
        assert!(
            (set - moved.part_position[k]).abs() <= 1e-3,
            "{pos} {moved:?}"
        );
    }
}
