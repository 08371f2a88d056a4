//! The KUKA post's spline mode (issue 36): print paths as SPLINE blocks through fewer points,
//! read back within the tolerance, split across part files.

mod krl_common;
use krl_common::*;

use robot_post::krl::{self, KrlRead, Motion};
use robot_post::kuka::{ExtruderSwitch, KrlMotion};
use robot_post::{kuka, ToolPath};

#[test]
fn spline_mode_drops_points_and_reads_back_within_the_tolerance() {
    let lin = profile();
    let mut spline = lin.clone();
    spline.kuka.as_mut().expect("kuka").motion = KrlMotion::Spline;
    // The finely divided lines and gentle arcs lose most of their points, and keep SPL
    // segments on the arcs.
    let path = lines_and_arcs(1);
    let pa = kuka(&path, &lin, "l", "f.step").expect("lin");
    let pb = kuka(&path, &spline, "l", "f.step").expect("spline");
    let a = round_trip(&path, &pa.files);
    let b = spline_round_trip(&path, &spline, &pb.files);
    assert_status_turn(&b);
    let prints = |r: &KrlRead| r.moves.iter().filter(|m| m.extruder).count();
    assert!(
        prints(&b) * 4 < prints(&a),
        "{} vs {}",
        prints(&b),
        prints(&a)
    );
    assert!(b.moves.iter().any(|m| m.motion == Motion::Spl));
    let size =
        |p: &robot_post::kuka::KrlProgram| -> usize { p.files.iter().map(|f| f.1.len()).sum() };
    assert!(size(&pb) * 2 < size(&pa), "{} vs {}", size(&pb), size(&pa));
    // Lin mode writes no spline.
    assert!(pa.files.iter().all(|f| !f.1.contains("SPLINE")));
    // Switched by $OUT (exact stops), the extruder goes on before the block and off after it,
    // and the program reads back the same.
    let mut out = spline.clone();
    out.kuka.as_mut().expect("kuka").extruder_switch = ExtruderSwitch::Out;
    let po = kuka(&path, &out, "l", "f.step").expect("spline, $OUT");
    let o = spline_round_trip(&path, &out, &po.files);
    assert_eq!(o.moves.len(), b.moves.len());
    let src = &po.files[0].1;
    assert!(
        src.contains("$OUT[1] = TRUE\nSPLINE\n"),
        "on before the block"
    );
    assert!(
        src.contains("ENDSPLINE\n$VEL.CP"),
        "the block ends before the travel"
    );
    assert!(!src.contains("PATH=0 ONSTART DELAY=0 DO $OUT"));
}

#[test]
fn spline_blocks_split_across_parts_and_refused_when_broken() {
    let mut m = profile();
    let k = m.kuka.as_mut().expect("kuka");
    k.motion = KrlMotion::Spline;
    k.max_moves_per_file = 30;
    let path = all_shapes();
    let program = kuka(&path, &m, "parts", "f.step").expect("program");
    assert!(program.files.len() > 4);
    let read = spline_round_trip(&path, &m, &program.files);
    assert_signals(&m, &read, None);
    // Every part's blocks are closed in that part.
    for (name, text) in &program.files {
        let opened = text.lines().filter(|l| *l == "SPLINE").count();
        let closed = text.lines().filter(|l| *l == "ENDSPLINE").count();
        assert_eq!(opened, closed, "{name}");
    }
    // The reader refuses a block left open, an empty block, a LIN inside a block.
    let (name, text) = program
        .files
        .iter()
        .find(|(_, t)| t.contains("ENDSPLINE"))
        .expect("a block")
        .clone();
    let with = |t: String| -> Vec<(String, String)> {
        program
            .files
            .iter()
            .map(|(n, old)| (n.clone(), if *n == name { t.clone() } else { old.clone() }))
            .collect()
    };
    for (broken, needle) in [
        (text.replacen("ENDSPLINE\n", "", 1), "SPLINE"),
        (
            text.replacen("SPLINE\n", "SPLINE\nENDSPLINE\nSPLINE\n", 1),
            "empty SPLINE",
        ),
        (
            text.replacen("\nSLIN ", "\nLIN ", 1),
            "inside a SPLINE block",
        ),
    ] {
        let e = krl::read(&with(broken)).expect_err("refused").to_string();
        assert!(e.contains(needle), "{needle}: {e}");
    }
}

/// The checks of `every_fixture_in_lin_and_spline_mode` (kuka_krl.rs) on a planned part's
/// tool path: the `toolpath.csv` named by `KRL_TOOLPATH` (`features plan PART --machine kuka`
/// writes it), in lin and spline mode; prints the programs' sizes and motions. Ignored: run it
/// with
/// `KRL_TOOLPATH=... cargo test --release -p robot-post --test kuka_spline -- --ignored`.
#[test]
#[ignore]
fn a_planned_toolpath_in_lin_and_spline_mode() {
    let Ok(file) = std::env::var("KRL_TOOLPATH") else {
        return;
    };
    let text = std::fs::read_to_string(&file).expect("toolpath.csv");
    let path = ToolPath::from_csv(&text).expect("csv");
    let mut lin = profile();
    lin.kuka.as_mut().expect("kuka").ready_input = Some(3);
    let mut spline = lin.clone();
    spline.kuka.as_mut().expect("kuka").motion = KrlMotion::Spline;
    for (mode, m) in [("lin", &lin), ("spline", &spline)] {
        let program = kuka(&path, m, "part", "part.step").expect("program");
        let read = if mode == "lin" {
            round_trip(&path, &program.files)
        } else {
            spline_round_trip(&path, m, &program.files)
        };
        assert_status_turn(&read);
        assert_safe_points(&path, &read, 50.0);
        assert_signals(m, &read, Some(3));
        let krl = program.files.iter().filter(|f| !f.0.ends_with(".csv"));
        let bytes: usize = krl.clone().map(|f| f.1.len()).sum();
        let prints = read.moves.iter().filter(|mv| mv.extruder).count();
        println!(
            "{file} {mode}: {bytes} bytes in {} KRL files, {} motions ({prints} printing)",
            krl.count(),
            read.moves.len()
        );
    }
}
