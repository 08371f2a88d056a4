//! The planner as a library: a part planned by `plan::plan` without the binary. Every tool
//! path point belongs to a reported feature, each feature's reported point count is its own
//! points in the file-wide numbering (several solids included), and the material is conserved.

use plan::{plan, Options, Process};
use robot_post::{MachineKind, MachineProfile, MoveKind};
use std::path::Path;

fn fixture(name: &str) -> brep::StepPart {
    let p = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../../fixtures")
        .join(name);
    brep::read_step(&p).unwrap_or_else(|e| panic!("{}: {e}", p.display()))
}

fn planned(name: &str, machine: MachineKind) -> plan::Plan {
    let options = Options {
        source: name.into(),
        stem: "part".into(),
        // stacked_solids's cylinder is sunk into the base: its head meets the base (planned
        // whole, as warned); the collision tests check those moves.
        allow_collisions: true,
        ..Default::default()
    };
    plan(
        &fixture(name),
        &Process::default(),
        &MachineProfile::builtin(machine),
        &options,
    )
    .unwrap_or_else(|e| panic!("{name}: {e}"))
}

#[test]
fn every_solid_of_a_file_is_planned_with_its_own_ids_and_counts() {
    for name in ["two_solids.step", "stacked_solids.step"] {
        let p = planned(name, MachineKind::Marlin);
        let ids: Vec<usize> = p.features().iter().map(|f| f.feature.id).collect();
        assert!(ids.len() >= 2, "{name}: {ids:?}");
        let mut sorted = ids.clone();
        sorted.sort_unstable();
        sorted.dedup();
        assert_eq!(sorted.len(), ids.len(), "{name}: ids repeat: {ids:?}");
        for f in p.features() {
            let own = p
                .toolpath
                .points
                .iter()
                .filter(|q| q.feature == f.feature.id)
                .count();
            assert_eq!(own, f.points, "{name}: feature {}", f.feature.id);
            assert!(
                f.layers > 0 && f.points > 0,
                "{name}: feature {}",
                f.feature.id
            );
            // The self-check passed: extruded within 3 % of volume × fill (solid fill).
            let rel = (f.extruded_volume_mm3 - f.feature.volume_mm3) / f.feature.volume_mm3;
            assert!(
                rel.abs() <= 0.03,
                "{name}: feature {} off by {rel}",
                f.feature.id
            );
        }
        let total: usize = p.features().iter().map(|f| f.points).sum();
        assert_eq!(total, p.toolpath.points.len(), "{name}");
        assert!(p.report.complete);
        assert!(p
            .program
            .iter()
            .any(|f| f.name == "program.gcode" && !f.bytes.is_empty()));
    }
}

#[test]
fn the_report_reads_back_as_the_plan_schema_with_post_figures() {
    let p = planned("sphere_boss.step", MachineKind::Delta5);
    let json: serde_json::Value =
        serde_json::from_str(&p.report.to_json().expect("json")).expect("reads back");
    assert_eq!(json["schema"], "features.plan/1");
    let features = json["features"].as_array().expect("features");
    assert_eq!(features.len(), p.features().len());
    for f in features {
        // Delta5's figures and the smoothing figures sit beside the planner's.
        for key in [
            "layers",
            "extruded_volume_mm3",
            "kinematic_error_max_mm",
            "orientation_step_max_deg_after",
        ] {
            assert!(f.get(key).is_some(), "{key} missing in {f}");
        }
    }
    let prints = p
        .toolpath
        .points
        .iter()
        .filter(|q| q.kind == MoveKind::Print)
        .count();
    assert!(prints > 0);
    assert!(json["features"].as_array().is_some_and(|a| a
        .iter()
        .any(|f| f["kind"] == "freeform" && f["chart"].is_string())));
}

/// `plan_into` writes into its sink the files `plan` holds, byte for byte, and holds none
/// itself, and into its CSV writer (beside the post, on another thread) exactly the held tool
/// path's `toolpath.csv`; a sink or a CSV writer that cannot write fails the plan with the
/// file's name.
#[test]
fn a_plan_written_into_a_sink_is_the_plan_held() {
    struct Refusing;
    impl robot_post::ProgramSink for Refusing {
        fn file(&mut self, name: &str) -> std::io::Result<Box<dyn std::io::Write + '_>> {
            Err(std::io::Error::other(format!("no room for {name}")))
        }
    }
    for (name, machine) in [
        ("plate_boss_boss.step", MachineKind::Marlin),
        ("sphere_boss.step", MachineKind::Delta5),
    ] {
        let held = planned(name, machine);
        let options = Options {
            source: name.into(),
            stem: "part".into(),
            allow_collisions: true,
            ..Default::default()
        };
        let part = fixture(name);
        let m = MachineProfile::builtin(machine);
        let mut sink = robot_post::InMemory::default();
        let mut csv: Vec<u8> = vec![];
        let streamed = plan::plan_into(
            &part,
            &Process::default(),
            &m,
            &options,
            &mut sink,
            Some(&mut csv),
        )
        .unwrap_or_else(|e| panic!("{name}: {e}"));
        assert!(streamed.program.is_empty(), "{name}");
        assert!(!sink.files.is_empty(), "{name}");
        assert_eq!(sink.files, held.program, "{name}");
        assert_eq!(streamed.toolpath, held.toolpath, "{name}");
        assert!(
            csv == held.toolpath.to_csv().as_bytes(),
            "{name}: toolpath.csv written beside the post differs from the held path's"
        );
        struct Full;
        impl std::io::Write for Full {
            fn write(&mut self, _: &[u8]) -> std::io::Result<usize> {
                Err(std::io::Error::other("disk full"))
            }
            fn flush(&mut self) -> std::io::Result<()> {
                Ok(())
            }
        }
        let mut full = Full;
        let mut sink = robot_post::InMemory::default();
        match plan::plan_into(
            &part,
            &Process::default(),
            &m,
            &options,
            &mut sink,
            Some(&mut full),
        ) {
            Err(e) => assert!(
                e.to_string()
                    .contains("cannot write toolpath.csv: disk full"),
                "{name}: {e}"
            ),
            Ok(_) => panic!("{name}: planned with a toolpath.csv that cannot be written"),
        }
        match plan::plan_into(
            &part,
            &Process::default(),
            &m,
            &options,
            &mut Refusing,
            None,
        ) {
            Err(e) => assert!(
                e.to_string().contains("cannot write program.gcode"),
                "{name}: {e}"
            ),
            Ok(_) => panic!("{name}: planned into a sink that cannot write"),
        }
    }
}
