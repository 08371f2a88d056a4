//! The KUKA cell an integrator trusts (issue 36): every PTP's Status and Turn, the
//! controller's base and tool numbers, the safe point, the extruder's handshake, resets and
//! stop interrupt, and joints.csv checked by forward kinematics.

mod krl_common;
use krl_common::*;

use robot_post::krl::{self, KrlMove, Motion, Target};
use robot_post::kuka::{KrlFrame, KrlMotion, Pose};
use robot_post::{kuka, MachineProfile, MoveKind, PathPoint, ToolPath};

#[test]
fn every_ptp_carries_the_status_and_turn_of_a_solution() {
    let m = profile();
    let cell = m.kuka.as_ref().expect("kuka");
    let program = kuka(&all_shapes(), &m, "shapes", "shapes.step").expect("program");
    let read = krl::read(&program.files).expect("reads");
    let ptps: Vec<&KrlMove> = read
        .moves
        .iter()
        .filter(|mv| mv.motion == Motion::Ptp && matches!(mv.target, Target::Frame(_)))
        .collect();
    assert!(!ptps.is_empty());
    let home_status = cell.arm.configuration(&cell.home);
    for mv in ptps {
        let (s, t) = mv
            .status_turn
            .unwrap_or_else(|| panic!("{}:{} has no S and T", mv.file, mv.line));
        // S and T pick a solution of the pose within the joint limits: one whose
        // configuration is S and whose joints' signs are T.
        let flange = flange_of(&read, frame_of(mv));
        let picked: Vec<[f64; 6]> = cell
            .arm
            .inverse(&flange)
            .into_iter()
            .flat_map(|j| {
                // Each joint also taken ±360° where its limits allow.
                let mut all = vec![j];
                for i in 0..6 {
                    let more: Vec<[f64; 6]> = all
                        .iter()
                        .flat_map(|a| {
                            [-360.0, 360.0].map(|d| {
                                let mut b = *a;
                                b[i] += d;
                                b
                            })
                        })
                        .collect();
                    all.extend(more);
                }
                all
            })
            .filter(|j| cell.arm.within_limits(j))
            .filter(|j| cell.arm.configuration(j) == s)
            // The frame is written rounded: a joint within 0.01° of 0 may read either side.
            .filter(|j| (0..6).all(|n| j[n].abs() < 0.01 || (t >> n & 1 == 1) == (j[n] < 0.0)))
            .collect();
        assert!(
            !picked.is_empty(),
            "{}:{}: no solution with S {s:03b} T {t:06b}",
            mv.file,
            mv.line
        );
        // The arm stays in the configuration it starts in at home.
        assert_eq!(s, home_status, "{}:{}", mv.file, mv.line);
    }
    // The text is KRL's binary form.
    let src = &program.files[0].1;
    let ptp = src
        .lines()
        .find(|l| l.starts_with("PTP {X"))
        .expect("a Cartesian PTP");
    assert!(
        ptp.contains(", S 'B") && ptp.contains(", T 'B") && ptp.ends_with("'}"),
        "{ptp}"
    );
    assert!(program
        .warnings
        .iter()
        .all(|w| !w.contains("changes configuration")));
}

#[test]
fn a_change_of_configuration_is_warned_naming_the_motion() {
    let m = profile();
    let cell = m.kuka.as_ref().expect("kuka");
    // Two tool axes either side of the forearm's line: with A4 held within ±30° the wrist
    // can only reach the second by flipping A5's sign.
    let mut m2 = m.clone();
    let k = m2.kuka.as_mut().expect("kuka");
    k.arm.joint_min[3] = -30.0;
    k.arm.joint_max[3] = 30.0;
    k.home[3] = 0.0;
    let tcp = |j: [f64; 6]| cell.arm.forward(j).compose(&cell.tool.pose());
    let (p1, p2) = (
        tcp([0.0, -80.0, 100.0, 0.0, 25.0, 0.0]),
        tcp([0.0, -80.0, 100.0, 0.0, -25.0, 0.0]),
    );
    // The table's origin under the path's XY middle and its lowest point, so that the post
    // places the part's points back on those poses.
    let b = [
        (p1.t[0] + p2.t[0]) / 2.0,
        (p1.t[1] + p2.t[1]) / 2.0,
        p1.t[2].min(p2.t[2]) - T,
    ];
    k.base = KrlFrame {
        x: b[0],
        y: b[1],
        z: b[2],
        a: 0.0,
        b: 0.0,
        c: 0.0,
    };
    let mut path = ToolPath::default();
    let mut pts = Vec::new();
    for k in 0..=20 {
        let s = f64::from(k) / 20.0;
        let p: [f64; 3] = std::array::from_fn(|i| p1.t[i] + s * (p2.t[i] - p1.t[i]) - b[i]);
        let a1 = p1.z_axis().map(|v| -v);
        let a2 = p2.z_axis().map(|v| -v);
        let axis: [f64; 3] = std::array::from_fn(|i| (1.0 - s) * a1[i] + s * a2[i]);
        pts.push((p, axis));
    }
    // The travel to the start, then print points from it (the first goes nowhere).
    pts.insert(0, pts[0]);
    push_path(&mut path, 9, 0, &pts);
    let program = kuka(&path, &m2, "flip", "flip.step").expect("program");
    let f = &program.figures[&9];
    assert!(f.configuration_changes >= 1, "{f:?}");
    let w = program
        .warnings
        .iter()
        .find(|w| w.contains("changes configuration"))
        .expect("a warning");
    // It names the motion by its file and line, and that line is a motion.
    let at = w.split("(flip.src:").nth(1).expect("file named");
    let line: usize = at
        .split(',')
        .next()
        .and_then(|n| n.parse().ok())
        .expect("line");
    let src = &program.files[0].1;
    let text = src.lines().nth(line - 1).expect("line in the file");
    assert!(
        text.starts_with("LIN ") || text.starts_with("PTP "),
        "{w}: {text}"
    );
}

#[test]
fn base_and_tool_numbers_select_the_controllers_frames() {
    let m = profile();
    let path = tilted_planes(1);
    let raw = kuka(&path, &m, "planes", "planes.step").expect("program");
    let mut numbered = m.clone();
    let k = numbered.kuka.as_mut().expect("kuka");
    k.base_index = Some(3);
    k.tool_index = Some(7);
    let program = kuka(&path, &numbered, "planes", "planes.step").expect("program");
    let src = &program.files[0].1;
    // The frames are selected, not assigned, and the frames assumed are stated.
    assert!(src.lines().any(|l| l == "BAS (#BASE, 3)"), "{src}");
    assert!(src.lines().any(|l| l == "BAS (#TOOL, 7)"), "{src}");
    assert!(!src
        .lines()
        .any(|l| l.starts_with("$BASE") || l.starts_with("$TOOL")));
    let cell = m.kuka.as_ref().expect("kuka");
    let read = round_trip(&path, &program.files);
    assert_eq!((read.base_index, read.tool_index), (Some(3), Some(7)));
    for k in 0..6 {
        assert!((read.base.expect("base")[k] - cell.base.to_array()[k]).abs() < 1e-3);
        assert!((read.tool.expect("tool")[k] - cell.tool.to_array()[k]).abs() < 1e-3);
    }
    // The motions are the raw program's: only the frames' lines differ.
    let raw_read = krl::read(&raw.files).expect("reads");
    assert_eq!(raw_read.base_index, None);
    assert_eq!(raw_read.moves.len(), read.moves.len());
    for (a, b) in raw_read.moves.iter().zip(&read.moves) {
        assert_eq!(a.target, b.target);
    }
    // A BAS call the program does not state its frame for is refused.
    let bare: Vec<(String, String)> = program
        .files
        .iter()
        .map(|(n, t)| {
            let t = t
                .lines()
                .filter(|l| !l.starts_with("; assumed BASE_DATA"))
                .collect::<Vec<_>>()
                .join("\n");
            (n.clone(), t)
        })
        .collect();
    let e = krl::read(&bare).expect_err("refused").to_string();
    assert!(e.contains("BAS (#BASE, 3) without"), "{e}");
    // Numbers outside 1..32 are refused in the profile.
    for (from, to, needle) in [
        (
            "part_position = [0.0, 0.0]",
            "part_position = [0.0, 0.0]\nbase_index = 0",
            "kuka.base_index",
        ),
        (
            "part_position = [0.0, 0.0]",
            "part_position = [0.0, 0.0]\ntool_index = 33",
            "kuka.tool_index",
        ),
    ] {
        let text = robot_post::machine::KUKA_TOML.replacen(from, to, 1);
        let e = MachineProfile::from_toml(&text).unwrap_err().to_string();
        assert!(e.contains(needle), "{e}");
    }
}

#[test]
fn safe_points_open_and_close_the_program() {
    let m = profile();
    for path in [all_shapes(), long_path(1, 3), to_gimbal_lock(1)] {
        let program = kuka(&path, &m, "safe", "safe.step").expect("program");
        let read = round_trip(&path, &program.files);
        assert_safe_points(&path, &read, 50.0);
        let mut higher = m.clone();
        higher.kuka.as_mut().expect("kuka").safe_height = 120.0;
        let program = kuka(&path, &higher, "safe", "safe.step").expect("program");
        let read = round_trip(&path, &program.files);
        assert_safe_points(&path, &read, 120.0);
    }
    let text =
        robot_post::machine::KUKA_TOML.replacen("safe_height = 50.0", "safe_height = -1.0", 1);
    let e = MachineProfile::from_toml(&text).unwrap_err().to_string();
    assert!(e.contains("kuka.safe_height"), "{e}");
}

#[test]
fn handshake_resets_and_stop_interrupt() {
    let m = profile();
    let mut ready = m.clone();
    ready.kuka.as_mut().expect("kuka").ready_input = Some(5);
    let mut split = ready.clone();
    split.kuka.as_mut().expect("kuka").max_moves_per_file = 40;
    for path in [all_shapes(), long_path(1, 3)] {
        for (profile, input) in [(&m, None), (&ready, Some(5)), (&split, Some(5))] {
            let program = kuka(&path, profile, "sig", "sig.step").expect("program");
            let read = round_trip(&path, &program.files);
            assert_signals(profile, &read, input);
            let src = &program.files[0].1;
            assert!(src.contains("INTERRUPT DECL 10 WHEN $STOPMESS==TRUE DO EXTRUDER_STOP( )"));
            assert!(src.contains("\nDEF EXTRUDER_STOP( )\n"));
        }
    }
    // A wait that is not closed, or a routine that is missing, is refused.
    let program = kuka(&long_path(1, 1), &ready, "sig", "sig.step").expect("program");
    let without = |needle: &str| -> Vec<(String, String)> {
        program
            .files
            .iter()
            .map(|(n, t)| {
                let t: Vec<&str> = t.lines().filter(|l| l.trim() != needle).collect();
                (n.clone(), t.join("\n"))
            })
            .collect()
    };
    let e = krl::read(&without("ENDIF"))
        .expect_err("refused")
        .to_string();
    assert!(e.contains("IF without ENDIF"), "{e}");
    let e = krl::read(&without("DEF EXTRUDER_STOP( )"))
        .expect_err("refused")
        .to_string();
    assert!(e.contains("after END"), "{e}");
    for (from, to, needle) in [
        (
            "safe_height = 50.0",
            "safe_height = 50.0\nready_input = 0",
            "kuka.ready_input",
        ),
        (
            "safe_height = 50.0",
            "safe_height = 50.0\nready_timeout = 0.0",
            "kuka.ready_timeout",
        ),
    ] {
        let text = robot_post::machine::KUKA_TOML.replacen(from, to, 1);
        let e = MachineProfile::from_toml(&text).unwrap_err().to_string();
        assert!(e.contains(needle), "{e}");
    }
}

#[test]
fn joints_csv_gives_every_motion_by_forward_kinematics() {
    let m = profile();
    let cell = m.kuka.as_ref().expect("kuka");
    let mut spline = m.clone();
    spline.kuka.as_mut().expect("kuka").motion = KrlMotion::Spline;
    let home_status = cell.arm.configuration(&cell.home);
    for profile in [&m, &spline] {
        for path in [all_shapes(), long_path(1, 2), lines_and_arcs(1)] {
            let program = kuka(&path, profile, "j", "j.step").expect("program");
            let read = krl::read(&program.files).expect("reads");
            let offset = read.offset.expect("offset");
            let rows = joint_rows(&program.files);
            let cart: Vec<&KrlMove> = read
                .moves
                .iter()
                .filter(|mv| matches!(mv.target, Target::Frame(_)))
                .collect();
            assert_eq!(rows.len(), cart.len(), "one row per Cartesian motion");
            let (base, tool) = (
                Pose::from_frame(read.base.expect("base")),
                Pose::from_frame(read.tool.expect("tool")),
            );
            let base_inv = base.inverse();
            let mut last_point = 0;
            for (k, ((n, point, joints), mv)) in rows.iter().zip(&cart).enumerate() {
                assert_eq!(*n, k + 1);
                // The points the motions go to, in the path's order.
                assert!(
                    *point >= last_point && *point < path.points.len(),
                    "row {n}"
                );
                last_point = *point;
                let j = joints.unwrap_or_else(|| panic!("row {n} out of reach"));
                assert!(cell.arm.within_limits(&j), "row {n}: {j:?}");
                // The tool pose by forward kinematics, in $BASE: the motion's frame.
                let tcp = base_inv.compose(&cell.arm.forward(j).compose(&tool));
                let f = frame_of(mv);
                let d = len3(sub3(tcp.t, [f[0], f[1], f[2]]));
                assert!(d <= 0.05, "row {n}: {d} mm from {}:{}", mv.file, mv.line);
                let turned = rotation_between(&tcp.r, &rebuild(f[3], f[4], f[5]));
                assert!(
                    turned <= 0.1,
                    "row {n}: {turned}° from {}:{}",
                    mv.file,
                    mv.line
                );
                // A print motion's pose is its planned point's, with its tool axis.
                if mv.extruder {
                    let p = sub3(tcp.t, offset);
                    let axis = tcp.z_axis().map(|v| -v);
                    let q: &PathPoint = &path.points[*point];
                    assert_eq!(q.kind, MoveKind::Print, "row {n}");
                    assert!(
                        len3(sub3(p, q.p)) <= 0.05 && angle_deg(axis, q.axis) <= 0.1,
                        "row {n}: {p:?} is not point {point}'s {:?}",
                        q.p
                    );
                }
                // The reach check's solution: the configuration kept, and a PTP's S and T.
                assert_eq!(cell.arm.configuration(&j), home_status, "row {n}");
                if let Some((s, t)) = mv.status_turn {
                    assert_eq!(
                        (s, t),
                        (cell.arm.configuration(&j), robot_post::kuka::turn(&j)),
                        "row {n}"
                    );
                }
            }
        }
    }
    // A motion out of reach has its row, without joints: the same motions the program marks.
    let mut path = long_path(1, 1);
    let high: Vec<_> = (0..5)
        .map(|k| ([f64::from(k), 0.0, 2000.0], [0.0, 0.0, 1.0]))
        .collect();
    push_path(&mut path, 2, 0, &high);
    let program = kuka(&path, &m, "far", "far.step").expect("written anyway");
    let read = krl::read(&program.files).expect("reads");
    let rows = joint_rows(&program.files);
    let cart = read
        .moves
        .iter()
        .filter(|mv| matches!(mv.target, Target::Frame(_)));
    let mut empty = 0;
    for ((n, _, joints), mv) in rows.iter().zip(cart) {
        let marked = mv.note.as_deref() == Some("UNREACHABLE");
        assert_eq!(joints.is_none(), marked, "row {n}");
        empty += usize::from(marked);
    }
    assert!(empty >= 5);
}
