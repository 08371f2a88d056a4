//! The placement time limit (`plan::Options::placement_time_limit`): a part refused as
//! modelled for something another placement may avoid (here the box, on a bed smaller than
//! it) has its other placements tried without a limit, and none with a limit of 0 s: the
//! refusal then says the search stopped at the limit, lists what it left untried and names
//! the remedy.

use plan::{Options, Placement, PlanError, Process};
use robot_post::{InMemory, MachineKind, MachineProfile};
use std::path::Path;
use std::time::Duration;

/// The box fixture's file.
fn the_box() -> brep::StepFile {
    let p = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../fixtures/box.step");
    brep::StepFile::read(&p).unwrap_or_else(|e| panic!("{}: {e}", p.display()))
}

/// A Marlin printer whose bed, 5 mm each way, no face of the box fits.
fn small_bed() -> MachineProfile {
    let mut m = MachineProfile::builtin(MachineKind::Marlin);
    m.bed_size = [5.0, 5.0, 5.0];
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
        &small_bed(),
        &options,
        &mut out,
    ) {
        Err(PlanError::NoPlacement { tried, stopped, .. }) => (tried.len(), stopped),
        Err(e) => panic!("refused, but not after trying placements: {e}"),
        Ok(_) => panic!("the box was planned on a 5 mm bed"),
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
