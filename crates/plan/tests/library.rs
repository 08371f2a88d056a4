//! The planner as a library: a part planned by `plan::plan` without the binary. Every tool
//! path point belongs to a reported feature, each feature's reported point count is its own
//! points in the file-wide numbering (several solids included), and the material is conserved.

use plan::{plan, Options, Process};
use robot_post::sink::CHUNK;
use robot_post::{InMemory, Job, MachineKind, MachineProfile, MoveKind, ProgramSink};
use std::path::Path;

fn fixture(name: &str) -> brep::StepPart {
    let p = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../../fixtures")
        .join(name);
    brep::read_step(&p).unwrap_or_else(|e| panic!("{}: {e}", p.display()))
}

fn planned(name: &str, machine: MachineKind) -> plan::Plan {
    planned_with(name, machine, &Process::default())
}

/// [`planned`] with `process`.
fn planned_with(name: &str, machine: MachineKind, process: &Process) -> plan::Plan {
    let options = Options {
        source: name.into(),
        stem: "part".into(),
        // stacked_solids's cylinder is sunk into the base: planned feature by feature its head
        // meets the base (as warned); the collision tests check those moves.
        allow_collisions: true,
        // The impeller's blade edges on the hub's flank are refused by the support check
        // (tests/plan_cli.rs checks that): kept going past it, as these tests are about ids,
        // counts and streaming.
        keep_going: true,
        ..Default::default()
    };
    plan(
        &fixture(name),
        process,
        &MachineProfile::builtin(machine),
        &options,
    )
    .unwrap_or_else(|e| panic!("{name}: {e}"))
}

#[test]
fn every_solid_of_a_file_is_planned_with_its_own_ids_and_counts() {
    // Feature by feature: `slicing = "auto"` plans stacked_solids's overlapping solids whole,
    // one feature, and this test is about several features' ids and counts.
    let process = Process::from_toml("[defaults]\nslicing = \"features\"\n").expect("process");
    for name in ["two_solids.step", "stacked_solids.step"] {
        let p = planned_with(name, MachineKind::Marlin, &process);
        let ids: Vec<usize> = p.features().iter().map(|f| f.feature.id).collect();
        assert!(ids.len() >= 2, "{name}: {ids:?}");
        let mut sorted = ids.clone();
        sorted.sort_unstable();
        sorted.dedup();
        assert_eq!(sorted.len(), ids.len(), "{name}: ids repeat: {ids:?}");
        // The skirt's points carry the first layer's feature id but are no feature's
        // (plan.json's skirt_brim counts them).
        let skirt = p.report.skirt_brim.as_ref().map_or(0, |s| s.points);
        let adhesion = |q: &&robot_post::PathPoint| {
            matches!(
                q.role,
                robot_post::toolpath::Role::Skirt | robot_post::toolpath::Role::Brim
            )
        };
        assert_eq!(p.toolpath.points.iter().filter(adhesion).count(), skirt);
        for f in p.features() {
            let own = p
                .toolpath
                .points
                .iter()
                .filter(|q| q.feature as usize == f.feature.id && !adhesion(q))
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
        assert_eq!(total + skirt, p.toolpath.points.len(), "{name}");
        // Complete exactly when every layer is held up (the self-check passed above).
        let held = p.features().iter().all(|f| f.unsupported_area_mm2 == 0.0);
        assert_eq!(p.report.complete, held, "{name}");
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
    for (name, machine, first) in [
        ("plate_boss_boss.step", MachineKind::Marlin, "program.gcode"),
        ("sphere_boss.step", MachineKind::Delta5, "program.gcode"),
        ("sphere_boss.step", MachineKind::Kuka, "part.src"),
    ] {
        let held = planned(name, machine);
        let options = Options {
            source: name.into(),
            stem: "part".into(),
            allow_collisions: true,
            keep_going: true,
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
                e.to_string().contains(&format!("cannot write {first}")),
                "{name}: {e}"
            ),
            Ok(_) => panic!("{name}: planned into a sink that cannot write"),
        }
    }
}

/// The program of a planned part posted into memory whole ([`Post::post`]) and streamed into
/// sinks that take the text 1 byte, 7 bytes and 4 kB or more at a time: the same files, byte
/// for byte (a post's look back at its text, and the KRL parts' boundaries, survive the cuts).
fn same_in_pieces_of_any_size(plan: &plan::Plan, m: &MachineProfile) {
    let notes = vec!["a note".to_string()];
    let job = Job {
        source: "part.step",
        stem: "part",
        notes: &notes,
        ..Job::default()
    };
    let whole = m.post().post(&plan.toolpath, &job).expect("posted");
    assert!(!whole.files.is_empty());
    for chunk in [1, 7, 4096] {
        let mut sink = InMemory::chunked(chunk);
        let streamed = m
            .post()
            .post_to(&plan.toolpath, &job, &mut sink)
            .expect("posted");
        assert!(streamed.files.is_empty(), "{chunk}");
        assert_eq!(sink.files, whole.files, "{chunk}");
        assert_eq!(streamed.figures, whole.figures, "{chunk}");
        assert_eq!(streamed.warnings, whole.warnings, "{chunk}");
    }
}

/// A sink that keeps nothing: per file, the bytes written, the largest single write and the
/// number of writes.
#[derive(Default)]
struct Counting {
    files: Vec<(String, Count)>,
}

#[derive(Default, Clone, Copy)]
struct Count {
    bytes: usize,
    largest: usize,
    writes: usize,
}

impl std::io::Write for &mut Count {
    fn write(&mut self, buf: &[u8]) -> std::io::Result<usize> {
        self.bytes += buf.len();
        self.largest = self.largest.max(buf.len());
        self.writes += 1;
        Ok(buf.len())
    }

    fn flush(&mut self) -> std::io::Result<()> {
        Ok(())
    }
}

impl ProgramSink for Counting {
    fn file(&mut self, name: &str) -> std::io::Result<Box<dyn std::io::Write + '_>> {
        self.files.push((name.to_string(), Count::default()));
        let last = self.files.len() - 1;
        Ok(Box::new(&mut self.files[last].1))
    }
}

/// What a post holds of its text is bounded: streaming `file`, a program of many megabytes,
/// it hands on about a megabyte at a time ([`CHUNK`]), never more than that and what one path
/// point makes (a print segment split into up to 1,024 moves: under 64 kB).
fn held_text_is_bounded(plan: &plan::Plan, m: &MachineProfile, file: &str) {
    let job = Job {
        source: "part.step",
        stem: "part",
        notes: &[],
        ..Job::default()
    };
    let mut sink = Counting::default();
    m.post()
        .post_to(&plan.toolpath, &job, &mut sink)
        .expect("posted");
    let (_, count) = sink
        .files
        .iter()
        .find(|(name, _)| name == file)
        .unwrap_or_else(|| panic!("no {file}"));
    assert!(count.bytes > 4 * CHUNK, "{file}: {} bytes", count.bytes);
    assert!(
        count.largest >= CHUNK && count.largest < CHUNK + 64 * 1024,
        "{file}: a write of {} bytes",
        count.largest
    );
    assert!(count.writes > count.bytes / (CHUNK + 64 * 1024), "{file}");
}

/// The delta5 post streams the impeller's program (about 9 MB): the same in pieces of any
/// size, a megabyte held at a time.
#[test]
fn the_delta5_program_is_streamed() {
    let p = planned("impeller.step", MachineKind::Delta5);
    let m = MachineProfile::builtin(MachineKind::Delta5);
    same_in_pieces_of_any_size(&p, &m);
    held_text_is_bounded(&p, &m, "program.gcode");
}

/// The KUKA post streams sphere_boss's KRL files: the same in pieces of any size, split into
/// parts (41 of them) or not, and a megabyte held at a time of a main program of about 15 MB.
#[test]
fn the_krl_program_is_streamed() {
    let p = planned("sphere_boss.step", MachineKind::Kuka);
    let mut m = MachineProfile::builtin(MachineKind::Kuka);
    same_in_pieces_of_any_size(&p, &m);
    if let Some(cell) = m.kuka.as_mut() {
        cell.max_moves_per_file = 1_000_000;
    }
    same_in_pieces_of_any_size(&p, &m);
    held_text_is_bounded(&p, &m, "part.src");
}
