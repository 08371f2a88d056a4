//! The placement time limit (`plan::Options::placement_time_limit`): a part refused as
//! modelled for something another placement may avoid (here the box, on a bed too low for
//! it, but wide enough that the box's size alone does not rule out every placement) has its
//! other placements tried without a limit, and none with a limit of 0 s: the refusal then
//! says the search stopped at the limit, lists what it left untried and names the remedy.

use plan::{Options, Placement, PlanError, Process};
use robot_post::{InMemory, MachineKind, MachineProfile};
use std::path::Path;
use std::time::Duration;

/// The box fixture's file.
fn the_box() -> brep::StepFile {
    let p = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../fixtures/box.step");
    brep::StepFile::read(&p).unwrap_or_else(|e| panic!("{}: {e}", p.display()))
}

/// A Marlin printer whose bed is a metre wide and 1 mm high: no face of the box fits under
/// it, yet its diagonal is longer than the box.
fn low_bed() -> MachineProfile {
    let mut m = MachineProfile::builtin(MachineKind::Marlin);
    m.bed_size = [1000.0, 1000.0, 1.0];
    m
}

/// The placements tried after the part as modelled and the stop, from the refusal.
fn refused(limit: Option<Duration>) -> (usize, Option<plan::retry::Stopped>) {
    let options = Options {
        source: "box.step".into(),
        stem: "box".into(),
        placement: Placement::Find,
        placement_time_limit: limit,
        ..Default::default()
    };
    let mut out = InMemory::default();
    match plan::plan_file_to(
        &the_box(),
        &Process::default(),
        &low_bed(),
        &options,
        &mut out,
    ) {
        Err(PlanError::NoPlacement { tried, stopped, .. }) => (tried.len(), stopped),
        Err(e) => panic!("refused, but not after trying placements: {e}"),
        Ok(_) => panic!("the box was planned on a 1 mm high bed"),
    }
}

#[test]
fn without_a_limit_the_other_placements_are_tried() {
    let (tried, stopped) = refused(None);
    assert!(tried > 0, "no other placement tried");
    assert_eq!(stopped, None);
}

#[test]
fn a_limit_of_zero_stops_after_the_part_as_modelled_naming_the_remedy() {
    let (tried, stopped) = refused(Some(Duration::ZERO));
    assert_eq!(tried, 0, "placements tried past the limit");
    let stopped = stopped.expect("the refusal says the search stopped at the limit");
    assert_eq!(stopped.limit_s, 0.0);
    // What was left untried is named: the planar faces, never listed.
    assert!(
        stopped.untried.iter().any(|u| u.contains("planar faces")),
        "{:?}",
        stopped.untried
    );
    let line = stopped.to_string();
    assert!(line.contains("time limit of 0 s"), "{line}");
    assert!(line.contains("--placement-time-limit"), "{line}");
    assert!(line.contains("--base-face"), "{line}");
}

/// No placement fits a bed smaller than the part across (`robot_post::fit::largest_across`):
/// none is planned, and the refusal says why.
#[test]
fn no_placement_is_planned_when_the_part_is_larger_than_any_placement_holds() {
    let mut m = MachineProfile::builtin(MachineKind::Marlin);
    m.bed_size = [5.0, 5.0, 5.0];
    let holds = robot_post::fit::largest_across(&m)
        .expect("a marlin profile")
        .expect("a bound");
    let options = Options {
        placement: Placement::Find,
        ..Default::default()
    };
    let mut out = InMemory::default();
    match plan::plan_file_to(&the_box(), &Process::default(), &m, &options, &mut out) {
        Err(PlanError::NoPlacement { tried, stopped, .. }) => {
            assert_eq!(stopped, None);
            assert_eq!(tried.len(), 1, "{tried:?}");
            assert!(tried[0].failure.contains("none fits"), "{tried:?}");
            assert!(
                tried[0].failure.contains(&format!("{holds:.1} mm")),
                "{tried:?}"
            );
        }
        Err(e) => panic!("refused, but not after looking for placements: {e}"),
        Ok(_) => panic!("the box was planned on a 5 mm bed"),
    }
}

/// The bound allows another placement's path 2 % and 2 mm less across than the part as
/// modelled's (its layers reach the part's extremes to within about half a bead and half a
/// layer): on a bed that holds just less than that, none is planned; on one that holds just
/// more, the placements are tried.
#[test]
fn the_bound_allows_two_percent_and_two_millimetres() {
    let options = Options {
        placement: Placement::Find,
        ..Default::default()
    };
    let m = MachineProfile::builtin(MachineKind::Marlin);
    let mut out = InMemory::default();
    let plan = plan::plan_file_to(&the_box(), &Process::default(), &m, &options, &mut out)
        .expect("the box plans on the built-in bed");
    let across = robot_post::fit::across(
        plan.toolpath
            .points
            .iter()
            .filter(|q| q.kind == slicer::toolpath::MoveKind::Print && q.role.is_part())
            .map(|q| q.p),
    );
    assert!(across > 10.0, "the box measures {across} mm across");
    let allowed = across * 0.98 - 2.0;
    for (holds, none) in [(allowed - 0.3, true), (allowed + 0.3, false)] {
        let mut small = MachineProfile::builtin(MachineKind::Marlin);
        // A cube bed whose diagonal is `holds`.
        small.bed_size = [holds / 3f64.sqrt(); 3];
        let mut out = InMemory::default();
        let refused =
            plan::plan_file_to(&the_box(), &Process::default(), &small, &options, &mut out);
        let Err(PlanError::NoPlacement { tried, .. }) = refused else {
            panic!("the box planned or was refused otherwise on a bed holding {holds:.2} mm");
        };
        let said = tried.iter().any(|t| t.failure.contains("none fits"));
        assert_eq!(said, none, "holds {holds:.2} mm of {across:.2}: {tried:?}");
    }
}
