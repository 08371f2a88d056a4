//! The machine programs of `features plan` (issue 21, "Machine programs"), end to end through
//! the binary: the profile's start and end G-code with their placeholders, the fan by layer,
//! no zero-length or zero-extrusion moves, feeds within the profile's limit (Marlin and
//! delta5), and KRL extrusion following the planned flow.

#[path = "common/cli.rs"]
mod cli;
#[path = "common/readback.rs"]
mod readback;

use cli::{fixture, plan, stderr, Scratch, BIN};
use std::path::Path;
use std::process::Command;

fn read(p: &Path) -> String {
    std::fs::read_to_string(p).unwrap_or_else(|e| panic!("{}: {e}", p.display()))
}

/// The lines of the profile's start G-code in a program, and the program's own lines after it
/// up to the end G-code, and the end G-code.
fn sections(program: &str) -> (&str, &str, &str) {
    let start = program.find("; start_gcode\n").expect("start_gcode mark");
    let own = program
        .find("; end of start_gcode\n")
        .expect("end of start_gcode mark");
    let end = program.find("; end_gcode\n").expect("end_gcode mark");
    (&program[start..own], &program[own..end], &program[end..])
}

/// One `G0`/`G1` of a program: the letters given with their values.
fn words(line: &str) -> Option<(&str, Vec<(char, f64)>)> {
    let code = line.split(';').next().unwrap_or("").trim();
    let mut w = code.split_whitespace();
    let cmd = w.next()?;
    if cmd != "G0" && cmd != "G1" {
        return None;
    }
    let args = w
        .map(|a| {
            let (k, v) = a.split_at(1);
            (
                k.chars().next().unwrap_or(' '),
                v.parse().expect("a number"),
            )
        })
        .collect();
    Some((cmd, args))
}

#[test]
fn marlin_start_end_gcode_and_fan_follow_the_profile() {
    let s = Scratch::new("marlin");
    let out = s.path("o");
    let o = plan(
        "plate_boss_boss.step",
        &[
            "--set",
            "machine.nozzle_temperature=215",
            "--set",
            "machine.fan_first_layer=20",
            "-o",
            out.to_str().unwrap(),
        ],
    );
    assert!(o.status.success(), "{}", stderr(&o));
    let program = read(&out.join("program.gcode"));
    let (start, own, end) = sections(&program);
    // Placeholders filled in: the temperatures (215 from --set), the bed's front left corner.
    for want in [
        "M104 S215 ; nozzle",
        "M109 S215 ; wait for the nozzle",
        "M190 S60 ; wait for the bed",
        "G28 ; home all axes",
        "; G29 ; bed levelling",
        // The purge line on the first layer's height (0.2 mm), its filament for that.
        "G0 X0.000 Y0.000 Z0.200 F7200 ; purge line",
        "G1 X100 E3.74177 F1200",
    ] {
        assert!(start.contains(want), "`{want}` not in:\n{start}");
    }
    for want in ["M107", "M104 S0", "M140 S0", "M84"] {
        assert!(end.contains(want), "`{want}` not in:\n{end}");
    }
    assert!(!program
        .lines()
        .any(|l| l.split(';').next().unwrap_or("").contains('{')));
    // The fan: 20 % (S51) on every bead resting on the plate (;HEIGHT: of its layer), 100 %
    // (S255) on every other, set before the print move.
    let (mut fan, mut height) = (None, 0.0);
    let (mut first, mut above) = (0, 0);
    for line in own.lines() {
        if let Some(s) = line.strip_prefix("M106 S") {
            fan = Some(s.split_whitespace().next().unwrap().parse::<u32>().unwrap());
        } else if line.starts_with("M107") {
            fan = Some(0);
        } else if let Some(h) = line.strip_prefix(";HEIGHT:") {
            height = h.parse::<f64>().unwrap();
        } else if let Some(("G1", w)) = words(line) {
            let Some(&(_, z)) = w.iter().find(|(k, _)| *k == 'Z') else {
                continue;
            };
            if z - height <= 0.01 {
                assert_eq!(fan, Some(51), "first layer: {line}");
                first += 1;
            } else {
                assert_eq!(fan, Some(255), "above the first layer: {line}");
                above += 1;
            }
        }
    }
    assert!(first > 100 && above > 100, "{first} {above}");
    // No move that goes nowhere, none extruding nothing.
    let (zero, e0) = empty_moves(own);
    assert_eq!((zero, e0), (0, 0));
    assert!(program.contains("; F: mm/min along the XYZ path"));

    // A misspelt placeholder is a profile error naming the key and the placeholder.
    let o = plan(
        "plate_boss_boss.step",
        &[
            "--set",
            "machine.end_gcode=M104 S{nozle_temperature}",
            "-o",
            s.path("never").to_str().unwrap(),
        ],
    );
    let err = stderr(&o);
    assert_eq!(o.status.code(), Some(2), "{err}");
    assert!(
        err.contains("end_gcode") && err.contains("{nozle_temperature}"),
        "{err}"
    );
    assert!(!s.path("never").exists());
}

/// Counts the `G1` moves of `own` that give an axis but go nowhere (X, Y, Z, B and C as
/// written, modal), and those written with `E0.00000`.
fn empty_moves(own: &str) -> (usize, usize) {
    let mut at = [f64::NAN; 5];
    let (mut zero, mut e0) = (0, 0);
    for line in own.lines() {
        let Some((cmd, w)) = words(line) else {
            continue;
        };
        let before = at;
        let mut axis = false;
        for &(k, v) in &w {
            if let Some(i) = "XYZBC".find(k) {
                at[i] = v;
                axis = true;
            }
        }
        if cmd == "G1" && axis {
            if before
                .iter()
                .zip(&at)
                .all(|(a, b)| a == b || (a.is_nan() && b.is_nan()))
            {
                zero += 1;
            }
            if line.contains("E0.00000") {
                e0 += 1;
            }
        }
    }
    (zero, e0)
}

#[test]
fn delta5_impeller_program_has_no_empty_moves_and_feeds_within_the_limit() {
    let s = Scratch::new("delta5");
    let out = s.path("imp");
    let o = plan(
        "impeller.step",
        &[
            "--machine",
            "delta5",
            "--allow-collisions",
            // The blades' edges on the hub's flank are refused by the support check.
            "--keep-going",
            "-o",
            out.to_str().unwrap(),
        ],
    );
    let err = stderr(&o);
    assert!(o.status.success(), "{err}");
    let program = read(&out.join("program.gcode"));
    let (start, own, _) = sections(&program);
    assert!(start.contains("M104 S210") && start.contains("G1 X50 E5.61265 F1200"));
    // Before: 2,888 zero-length G1 moves and 866 with E0.00000 (issue 21).
    assert_eq!(empty_moves(own), (0, 0));
    // E is conserved: the E of every move but retractions adds up to the tool path's (the
    // program's cumulative rounding keeps it to 0.00001 mm of the planned total).
    let csv = read(&out.join("toolpath.csv"));
    let planned: f64 = csv
        .lines()
        .skip(1)
        .map(|l| l.split(',').nth(9).unwrap().parse::<f64>().unwrap())
        .sum();
    let retraction = |w: &[(char, f64)]| w.len() == 2 && w[0].0 == 'E' && w[1] == ('F', 2100.0);
    let written: f64 = own
        .lines()
        .filter_map(words)
        .filter(|(_, w)| !retraction(w))
        .flat_map(|(_, w)| w.into_iter().filter(|(k, _)| *k == 'E').map(|(_, v)| v))
        .sum();
    // (toolpath.csv rounds each point's e to 0.000001 mm: 117,391 points.)
    assert!(
        (written - planned).abs() < 5e-3,
        "{written} written, {planned} planned"
    );
    // F never above max_feed_mm_min (12000 built in; before: up to F495235.684), and the
    // moves slowed to it are the count the warning gives.
    let feeds: Vec<f64> = own
        .lines()
        .filter_map(words)
        .flat_map(|(_, w)| w.into_iter().filter(|(k, _)| *k == 'F').map(|(_, v)| v))
        .collect();
    let max = feeds.iter().cloned().fold(0.0, f64::max);
    assert!(max <= 12000.0, "F{max}");
    let at_limit = own
        .lines()
        .filter(|l| l.starts_with("G1 X") && l.ends_with(" F12000.000"))
        .count();
    assert!(at_limit > 0);
    // The count is plan.json's figure; a warning only where more than 1 % of the print moves
    // are slowed (issue 31: a warning the user can do nothing about is a figure).
    let report: serde_json::Value =
        serde_json::from_str(&read(&out.join("plan.json"))).expect("plan.json");
    assert_eq!(report["feed_clamped_moves"].as_u64(), Some(at_limit as u64));
    let prints = own
        .lines()
        .filter(|l| l.starts_with("G1 X") && l.contains(" E"))
        .count();
    let warning = err.lines().find(|l| l.contains("max_feed_mm_min"));
    assert_eq!(
        warning.is_some(),
        at_limit * 100 > prints,
        "{at_limit} of {prints}: {err}"
    );
    if let Some(w) = warning {
        assert!(
            w.contains(&format!(
                ": warning: {at_limit} print move(s) asked for a feed above"
            )),
            "{w}"
        );
    }
    assert!(program.contains(
        "; F: machine-axis feed (mm/min along the XYZ path, degrees/min for a move of B and C alone) scaled so the nozzle moves over the part at print_speed"
    ));
}

#[test]
fn krl_feed_follows_the_planned_flow_per_lin() {
    use robot_post::krl::Target;
    let s = Scratch::new("krl");
    let out = s.path("imp");
    let o = plan(
        "impeller.step",
        &[
            "--machine",
            "kuka",
            "--allow-collisions",
            // The blades' edges on the hub's flank are refused by the support check.
            "--keep-going",
            "--allow-unreachable",
            "-o",
            out.to_str().unwrap(),
        ],
    );
    assert!(o.status.success(), "{}", stderr(&o));
    let mut files = vec![];
    for entry in std::fs::read_dir(&out).expect("output folder").flatten() {
        let name = entry.file_name().to_string_lossy().into_owned();
        if name.ends_with(".src") || name.ends_with(".dat") {
            files.push((name, read(&entry.path())));
        }
    }
    let main = files
        .iter()
        .find(|(n, _)| n == "impeller.src")
        .map(|(_, t)| t.clone())
        .expect("impeller.src");
    assert!(main.contains("; filament feed per print motion: $ANOUT[1] = feed ratio / 0.10000"));
    assert!(
        !main.contains("mm per mm of bead"),
        "no single ratio for the program"
    );
    let krl = robot_post::krl::read(&files).expect("the KRL reads back");
    let full_scale = 0.1;
    let offset = krl.offset.expect("part offset");
    // The planned print points, in order, with their segment's start.
    let csv = read(&out.join("toolpath.csv"));
    let rows: Vec<(usize, bool, [f64; 3], f64)> = csv
        .lines()
        .skip(1)
        .map(|l| {
            let f: Vec<&str> = l.split(',').collect();
            let n = |i: usize| f[i].parse::<f64>().unwrap();
            (
                f[0].parse().unwrap(),
                f[2] == "print",
                [n(3), n(4), n(5)],
                n(9),
            )
        })
        .collect();
    // Walk the extruding LINs along the planned points: each LIN reaches the next planned
    // point it ends on (3 decimals); the planned ratio is the filament of the points since the
    // previous LIN's over the distance between them.
    let part = |t: &[f64; 6]| [t[0] - offset[0], t[1] - offset[1], t[2] - offset[2]];
    let d = |a: [f64; 3], b: [f64; 3]| {
        ((a[0] - b[0]).powi(2) + (a[1] - b[1]).powi(2) + (a[2] - b[2]).powi(2)).sqrt()
    };
    let (mut j, mut checked) = (0usize, 0usize);
    let mut from: Option<(usize, [f64; 3])> = None;
    // Per feature: filament and length read back, as the planned ratio's average.
    // Per feature: filament read back, length, filament planned.
    let mut by_feature = std::collections::BTreeMap::<usize, (f64, f64, f64)>::new();
    let mut worst = 0.0f64;
    for mv in &krl.moves {
        let Target::Frame(t) = mv.target else {
            from = None;
            continue;
        };
        let p = part(&t);
        if !mv.extruder {
            // Where a path starts: the planned travel point the approach ends on.
            from = rows[j..]
                .iter()
                .position(|r| d(r.2, p) < 2e-3)
                .map(|k| (j + k, p));
            if let Some((k, _)) = from {
                j = k;
            }
            continue;
        }
        let (start, a) = from.expect("a print LIN follows a path start");
        let k = start
            + 1
            + rows[start + 1..]
                .iter()
                .position(|r| d(r.2, p) < 2e-3)
                .expect("every print LIN ends on a planned point");
        let e: f64 = rows[start + 1..=k]
            .iter()
            .filter(|r| r.1)
            .map(|r| r.3)
            .sum();
        let length = d(rows[k].2, rows[start].2);
        let ratio = mv.feed.expect("a feed before printing") * full_scale;
        if length >= 0.05 && e > 0.0 {
            let planned = e / length;
            let off = (ratio - planned).abs() / planned;
            worst = worst.max(off);
            assert!(
                off <= 0.01,
                "LIN at {p:?}: ratio {ratio} read back, {planned} planned"
            );
            checked += 1;
        }
        let f = by_feature.entry(rows[k].0).or_default();
        f.0 += ratio * d(p, a);
        f.1 += d(p, a);
        f.2 += e;
        (j, from) = (k, Some((k, p)));
    }
    assert!(checked > 10_000, "{checked} LINs checked");
    eprintln!(
        "{checked} print LINs within {:.4} % of the planned ratio",
        worst * 100.0
    );
    // Per feature, the ratio read back is the plan's: the base about 0.0374 mm of filament per
    // mm, the blades less (0.0286 as planned, 0.0322 with their narrow beads widened to
    // min_bead_width); one ratio for the program would give every feature the same.
    let mean = |f: usize| by_feature[&f].0 / by_feature[&f].1;
    let planned = |f: usize| by_feature[&f].2 / by_feature[&f].1;
    eprintln!(
        "feed ratios read back (and planned): {:?}",
        (0..7).map(|f| (mean(f), planned(f))).collect::<Vec<_>>()
    );
    assert!((mean(0) - 0.0374).abs() < 0.001, "base {}", mean(0));
    for f in 0..=6 {
        assert!(
            (mean(f) / planned(f) - 1.0).abs() < 0.01,
            "feature {f}: {} read back, {} planned",
            mean(f),
            planned(f)
        );
    }
    for blade in 1..=6 {
        assert!(
            mean(blade) < 0.9 * mean(0),
            "blade {blade}: {}",
            mean(blade)
        );
    }
}

/// Runs `features plan PART ARGS` with stderr on a pseudo-terminal; returns what the terminal
/// got and the exit status.
fn plan_on_a_terminal(part: &str, args: &[&str]) -> (String, std::process::ExitStatus) {
    use std::io::Read;
    use std::os::fd::FromRawFd;
    let (mut master, mut slave) = (0, 0);
    // SAFETY: openpty writes two new descriptors into the integers given; the null pointers
    // ask for no name, no termios and no window size.
    let r = unsafe {
        libc::openpty(
            &mut master,
            &mut slave,
            std::ptr::null_mut(),
            std::ptr::null(),
            std::ptr::null(),
        )
    };
    assert_eq!(r, 0, "openpty");
    // SAFETY: both descriptors are new and owned here, each by one File.
    let (mut master, slave) = unsafe {
        (
            std::fs::File::from_raw_fd(master),
            std::fs::File::from_raw_fd(slave),
        )
    };
    let mut child = Command::new(BIN)
        .arg("plan")
        .arg(fixture(part))
        .args(args)
        .stdout(std::process::Stdio::null())
        .stderr(std::process::Stdio::from(slave))
        .spawn()
        .expect("runs");
    let reader = std::thread::spawn(move || {
        let mut got = Vec::new();
        let mut buf = [0u8; 4096];
        // Ends with EIO once the child, the terminal's last writer, has closed it.
        while let Ok(n) = master.read(&mut buf) {
            if n == 0 {
                break;
            }
            got.extend_from_slice(&buf[..n]);
        }
        got
    });
    let status = child.wait().expect("waits");
    let got = reader.join().expect("reader");
    (String::from_utf8_lossy(&got).into_owned(), status)
}

#[test]
fn the_progress_bar_covers_the_whole_run_on_a_terminal_only() {
    let s = Scratch::new("progress");
    // Not a terminal: stderr holds our lines only, no bar.
    let out = s.path("a");
    let o = plan(
        "impeller.step",
        &[
            "--machine",
            "delta5",
            "--allow-collisions",
            // The blades' edges on the hub's flank are refused by the support check.
            "--keep-going",
            "-o",
            out.to_str().unwrap(),
        ],
    );
    let err = stderr(&o);
    assert!(o.status.success(), "{err}");
    assert!(!err.contains('\r') && !err.contains('\u{1b}'), "{err}");
    assert!(err.lines().all(|l| l.starts_with("features: ")), "{err}");
    // A terminal: the bar goes from reading the part through planning to writing the outputs,
    // with the time elapsed, and is cleared at the end.
    let out = s.path("b");
    let (tty, status) = plan_on_a_terminal(
        "impeller.step",
        &[
            "--machine",
            "delta5",
            "--allow-collisions",
            // The blades' edges on the hub's flank are refused by the support check.
            "--keep-going",
            "-o",
            out.to_str().unwrap(),
        ],
    );
    assert!(status.success(), "{tty}");
    for stage in ["reading", "planning", "feature ", "writing"] {
        assert!(tty.contains(stage), "`{stage}` never shown: {tty:?}");
    }
    // `[0s]` ... `[6s]`: the time elapsed since the run began.
    let elapsed = tty
        .split('[')
        .filter_map(|t| t.split_once("s]"))
        .filter_map(|(n, _)| n.parse::<u32>().ok())
        .max();
    assert!(elapsed.is_some_and(|s| s >= 1), "no elapsed time: {tty:?}");
    // The print-head check, a second or so on the impeller, shows (a quicker stage may be
    // drawn over before the terminal is redrawn).
    assert!(tty.contains(plan::Stage::HeadCheck.name()), "{tty:?}");
    // The warnings are whole lines among the bar's redraws.
    assert!(tty.contains("features: "), "{tty:?}");
    assert!(out.join("program.gcode").exists());
}

/// What PrusaSlicer's G-code viewer calls the kinds of extrusion (its `;TYPE:` names).
const VIEWER_TYPES: [&str; 15] = [
    "Perimeter",
    "External perimeter",
    "Overhang perimeter",
    "Internal infill",
    "Solid infill",
    "Top solid infill",
    "Ironing",
    "Bridge infill",
    "Gap fill",
    "Skirt/Brim",
    "Support material",
    "Support material interface",
    "Wipe tower",
    "Custom",
    "Mixed",
];

/// The Marlin program as PrusaSlicer's G-code viewer reads it (issue 33, item 5): every
/// extruding move under a `;TYPE:` the viewer knows (none "Unknown"), the purge line among
/// them; the layers the viewer counts (a new one wherever an extrusion's Z changes) are the
/// program's `;LAYER_CHANGE`s and the plan's layers, the purge line adding none; the bed in
/// the header and the config block at the end; no comment naming a slicer (the viewer would
/// take the program for that slicer's). The skirt lies its distance around the first layer.
#[test]
fn the_marlin_program_reads_as_a_gcode_viewer_reads_it() {
    let s = Scratch::new("viewer");
    let out = s.path("o");
    let o = plan("plate_boss_boss.step", &["-o", out.to_str().unwrap()]);
    assert!(o.status.success(), "{}", stderr(&o));
    let program = read(&out.join("program.gcode"));
    let report: serde_json::Value =
        serde_json::from_str(&read(&out.join("plan.json"))).expect("plan.json");
    let moves = readback::extrusions(&program, 0.1);
    let unknown: Vec<usize> = moves
        .iter()
        .filter(|x| !x.role.as_deref().is_some_and(|r| VIEWER_TYPES.contains(&r)))
        .map(|x| x.line)
        .collect();
    assert!(
        unknown.is_empty(),
        "extrusions of no known type at lines {unknown:?}"
    );
    let (start, _, _) = sections(&program);
    let purge = moves.first().expect("extrusions");
    assert_eq!(purge.role.as_deref(), Some("Skirt/Brim"));
    assert!(start.lines().any(|l| l.starts_with("G1 X100 E")));
    let layers: u64 = report["features"]
        .as_array()
        .expect("features")
        .iter()
        .map(|f| f["layers"].as_u64().expect("layers"))
        .sum();
    let zs = readback::viewer_layers(&moves);
    let changes = program.lines().filter(|l| *l == ";LAYER_CHANGE").count();
    assert_eq!(
        (zs.len() as u64, changes as u64),
        (layers, layers),
        "{zs:?}"
    );
    assert!((zs[0] - 0.2).abs() < 1e-9, "the first layer at {}", zs[0]);
    // The bed and the settings.
    assert!(program.contains("\n; bed_shape = 0x0,220x0,220x220,0x220\n"));
    let block = program
        .split("; prusaslicer_config = begin\n")
        .nth(1)
        .expect("config block");
    assert!(block.ends_with("; prusaslicer_config = end\n"));
    for want in [
        "; bed_shape = 0x0,220x0,220x220,0x220",
        "; printer_technology = FFF",
        "; layer_height = 0.2",
        "; first_layer_height = 0.2",
        "; nozzle_diameter = 0.4",
        "; filament_diameter = 1.75",
        "; extrusion_width = 0.45",
        "; skirts = 1",
        "; arc_fitting = disabled",
    ] {
        assert!(
            block.lines().any(|l| l == want),
            "`{want}` not in:\n{block}"
        );
    }
    for l in program.lines().filter(|l| l.starts_with(';')) {
        for name in robot_post::marlin::config::VIEWER_PRODUCERS {
            assert!(!l.contains(name), "{l}");
        }
    }
    // The skirt: one loop of the first layer's beads, 6 mm (and half a bead) out from the
    // part's first-layer beads, in plan.json and toolpath.csv, under Skirt/Brim.
    assert_eq!(report["skirt_brim"]["skirt_loops"], 1);
    assert_eq!(report["skirt_brim"]["brim_loops"], 0);
    let rows = readback::rows(&read(&out.join("toolpath.csv")));
    let skirt: Vec<&readback::Row> = rows.iter().filter(|r| r.adhesion).collect();
    assert_eq!(
        skirt.len() as u64,
        report["skirt_brim"]["points"].as_u64().unwrap()
    );
    let first: Vec<&readback::Row> = rows
        .iter()
        .filter(|r| r.print && !r.adhesion && (r.p[2] - 0.2).abs() < 1e-6)
        .collect();
    assert!(first.len() > 100);
    for q in skirt.iter().step_by(3) {
        assert!((q.p[2] - 0.2).abs() < 1e-6 && (q.thickness - 0.2).abs() < 1e-6);
        let d = first
            .iter()
            .map(|r| (r.p[0] - q.p[0]).hypot(r.p[1] - q.p[1]))
            .fold(f64::INFINITY, f64::min);
        // 6 mm from the beads' edge: 6.45 from the outer beads' centre lines, chords of
        // 0.05 mm cutting the round corners.
        assert!((6.35..6.5).contains(&d), "skirt point {:?} {d} mm off", q.p);
    }
    let skirt_moves = moves
        .iter()
        .filter(|x| x.role.as_deref() == Some("Skirt/Brim"))
        .count();
    assert!(skirt_moves > 4);
}

/// `skirt_loops`, `skirt_distance_mm` and `brim_width_mm` (issue 33): a brim of whole beads
/// touching the part, the skirt its distance beyond it, none of either at 0; misspelt or out
/// of range, an error naming the key.
#[test]
fn skirt_and_brim_follow_the_process_keys() {
    let s = Scratch::new("brim");
    let out = s.path("o");
    let o = plan(
        "plate_boss_boss.step",
        &[
            "--set",
            "brim_width_mm=2",
            "--set",
            "skirt_loops=2",
            "--set",
            "skirt_distance_mm=3",
            "-o",
            out.to_str().unwrap(),
        ],
    );
    assert!(o.status.success(), "{}", stderr(&o));
    let report: serde_json::Value =
        serde_json::from_str(&read(&out.join("plan.json"))).expect("plan.json");
    // 2 mm of 0.45 mm beads: 4 loops.
    assert_eq!(report["skirt_brim"]["skirt_loops"], 2);
    assert_eq!(report["skirt_brim"]["brim_loops"], 4);
    // The self-check compares the part's beads only: the plan is complete.
    assert_eq!(report["complete"], true);
    let rows = readback::rows(&read(&out.join("toolpath.csv")));
    let csv = read(&out.join("toolpath.csv"));
    let roles = |role: &str| csv.lines().filter(|l| l.ends_with(role)).count();
    assert!(roles(",brim") > 0 && roles(",skirt") > 0);
    let first: Vec<&readback::Row> = rows
        .iter()
        .filter(|r| r.print && !r.adhesion && (r.p[2] - 0.2).abs() < 1e-6)
        .collect();
    let nearest = |q: &readback::Row| {
        first
            .iter()
            .map(|r| (r.p[0] - q.p[0]).hypot(r.p[1] - q.p[1]))
            .fold(f64::INFINITY, f64::min)
    };
    // The brim's innermost loop touches the part's outer beads (a bead apart, centre to
    // centre); the skirt's innermost lies 3 mm beyond the brim's outer edge.
    let brim = csv
        .lines()
        .skip(1)
        .zip(&rows)
        .filter(|(l, _)| l.ends_with(",brim"));
    let d = brim.map(|(_, r)| nearest(r)).fold(f64::INFINITY, f64::min);
    assert!(
        (0.4..0.46).contains(&d),
        "brim {d} mm from the part's beads"
    );
    let skirt = csv
        .lines()
        .skip(1)
        .zip(&rows)
        .filter(|(l, _)| l.ends_with(",skirt"));
    let d = skirt.map(|(_, r)| nearest(r)).fold(f64::INFINITY, f64::min);
    assert!(
        (0.225 + 1.8 + 3.0 + 0.225 - 0.1..5.4).contains(&d),
        "skirt {d} mm off"
    );

    let none = s.path("none");
    let o = plan(
        "plate_boss_boss.step",
        &["--set", "skirt_loops=0", "-o", none.to_str().unwrap()],
    );
    assert!(o.status.success(), "{}", stderr(&o));
    let report: serde_json::Value =
        serde_json::from_str(&read(&none.join("plan.json"))).expect("plan.json");
    assert!(report.get("skirt_brim").is_none());
    assert!(!read(&none.join("toolpath.csv")).contains(",skirt"));

    for (set, key) in [
        ("skirt_lops=2", "skirt_loops"),
        ("brim_width_mm=-1", "brim_width_mm"),
        ("features.0.skirt_loops=2", "skirt_loops"),
    ] {
        let o = plan(
            "plate_boss_boss.step",
            &["--set", set, "-o", s.path("never").to_str().unwrap()],
        );
        let err = stderr(&o);
        assert_eq!(o.status.code(), Some(2), "{set}: {err}");
        assert!(err.contains(key), "{set}: {err}");
    }
}

/// Arc fitting (issue 33, item 6): with `arc_fitting = true` the perimeters of the bosses
/// become `G2`/`G3`; read back with the arcs interpolated, the program runs along the planned
/// path within the tolerance both ways (every planned print point near the program's path,
/// every point of the program's path near the planned one), feeds the same filament, and is
/// shorter.
#[test]
fn arcs_read_back_to_the_planned_path() {
    let s = Scratch::new("arcs");
    let (lines, arcs) = (s.path("lines"), s.path("arcs"));
    for (dir, set) in [(&lines, "arc_fitting=false"), (&arcs, "arc_fitting=true")] {
        let o = plan(
            "plate_boss_boss.step",
            &["--set", set, "-o", dir.to_str().unwrap()],
        );
        assert!(o.status.success(), "{}", stderr(&o));
    }
    let program = read(&arcs.join("program.gcode"));
    let plain = read(&lines.join("program.gcode"));
    assert!(program.contains("; arc_fitting = emit_center\n"));
    assert!(
        program.len() < plain.len(),
        "{} {}",
        program.len(),
        plain.len()
    );
    let off = readback::offset(&program);
    let rows = readback::rows(&read(&arcs.join("toolpath.csv")));
    let moves = readback::extrusions(&program, 0.02);
    let (g2, g3) = (
        program.lines().filter(|l| l.starts_with("G2 ")).count(),
        program.lines().filter(|l| l.starts_with("G3 ")).count(),
    );
    assert!(g2 + g3 > 100, "{g2} G2, {g3} G3");
    assert!(!plain
        .lines()
        .any(|l| l.starts_with("G2 ") || l.starts_with("G3 ")));
    // The planned print segments and the program's, by layer height (0.001 mm).
    type Segs = std::collections::HashMap<i64, Vec<[[f64; 2]; 2]>>;
    let key = |z: f64| (z * 1e3).round() as i64;
    let mut planned: Segs = Default::default();
    for w in rows.windows(2).filter(|w| w[1].print) {
        let m = |r: &readback::Row| [r.p[0] + off[0], r.p[1] + off[1]];
        planned
            .entry(key(w[1].p[2] + off[2]))
            .or_default()
            .push([m(&w[0]), m(&w[1])]);
    }
    let mut written: Segs = Default::default();
    // The part's and the skirt's moves, after the start G-code (its purge line).
    let own = program
        .lines()
        .position(|l| l == "; end of start_gcode")
        .expect("end of start_gcode");
    for x in moves.iter().filter(|x| x.line > own) {
        for w in x.points.windows(2) {
            written
                .entry(key(w[1][2]))
                .or_default()
                .push([[w[0][0], w[0][1]], [w[1][0], w[1][1]]]);
        }
    }
    let far = |p: [f64; 2], segs: &[[[f64; 2]; 2]]| {
        segs.iter()
            .map(|s| segment_distance(p, s[0], s[1]))
            .fold(f64::INFINITY, f64::min)
    };
    // `tolerance` (0.05 mm) and the text's rounding.
    let tol = 0.05 + 2e-3;
    let mut worst: (f64, f64) = (0.0, 0.0);
    for (z, segs) in &planned {
        let Some(ours) = written.get(z) else {
            panic!("no program moves at Z {z} um");
        };
        for s in segs.iter().step_by(5) {
            worst.0 = worst.0.max(far(s[1], ours));
        }
        for s in ours.iter().step_by(5) {
            worst.1 = worst.1.max(far(s[1], segs));
        }
    }
    assert!(worst.0 <= tol && worst.1 <= tol, "{worst:?}");
    let e = |p: &str| {
        readback::extrusions(p, 1.0)
            .iter()
            .map(|x| x.e)
            .sum::<f64>()
    };
    assert!(
        (e(&program) - e(&plain)).abs() < 1e-3,
        "{} {}",
        e(&program),
        e(&plain)
    );
}

/// Distance from `p` to the segment `a`–`b`.
fn segment_distance(p: [f64; 2], a: [f64; 2], b: [f64; 2]) -> f64 {
    let (dx, dy) = (b[0] - a[0], b[1] - a[1]);
    let len2 = dx * dx + dy * dy;
    let t = if len2 > 0.0 {
        (((p[0] - a[0]) * dx + (p[1] - a[1]) * dy) / len2).clamp(0.0, 1.0)
    } else {
        0.0
    };
    (p[0] - a[0] - t * dx).hypot(p[1] - a[1] - t * dy)
}

/// KRL as a robot programmer writes it (issue 36 item 1), end to end: bundled parts planned for
/// the KUKA cell with the controller's base and tool numbers and the extruder's ready input,
/// in `lin` and in `spline` mode, read back by `robot_post::krl`: `BAS` selects the numbers;
/// every Cartesian `PTP` has its Status and Turn; the first and last Cartesian motions are the
/// safe point `safe_height` (50 mm) over the part's top; the program waits for the input before
/// its first print motion; the stop interrupt resets the feed and the extruder and brakes; both
/// are off at the end; and every print motion's target is a planned print point, in the path's
/// order, the points a spline leaves out within its tolerance of the chord it draws; and
/// `joints.csv` has a row per Cartesian motion whose forward kinematics is that motion's frame
/// within 0.05 mm, and for a print motion the planned point the row names, with its axis
/// within 0.1°.
#[test]
fn krl_reads_back_with_the_cells_conventions_in_lin_and_spline_mode() {
    use robot_post::krl::{Motion, Target};
    use robot_post::kuka::Pose;
    const SAFE: f64 = 50.0;
    const SPLINE_TOLERANCE: f64 = 0.05;
    for part in ["plate_boss_boss", "sphere_boss", "domed_pad"] {
        for motion in ["lin", "spline"] {
            let s = Scratch::new(&format!("krl-cell-{part}-{motion}"));
            let out = s.path("out");
            let o = plan(
                &format!("{part}.step"),
                &[
                    "--machine",
                    "kuka",
                    "--set",
                    "machine.kuka.base_index=1",
                    "--set",
                    "machine.kuka.tool_index=2",
                    "--set",
                    "machine.kuka.ready_input=3",
                    "--set",
                    &format!("machine.kuka.motion={motion}"),
                    "-o",
                    out.to_str().unwrap(),
                ],
            );
            assert!(o.status.success(), "{part} {motion}: {}", stderr(&o));
            let mut files = vec![];
            for entry in std::fs::read_dir(&out).expect("output folder").flatten() {
                let name = entry.file_name().to_string_lossy().into_owned();
                if name.ends_with(".src") || name.ends_with(".dat") {
                    files.push((name, read(&entry.path())));
                }
            }
            let krl = robot_post::krl::read(&files).expect("the KRL reads back");
            let at = format!("{part} {motion}");
            assert_eq!((krl.base_index, krl.tool_index), (Some(1), Some(2)), "{at}");
            let offset = krl.offset.expect("part offset");
            // The planned print points, in order.
            let rows = readback::rows(&read(&out.join("toolpath.csv")));
            let prints: Vec<[f64; 3]> = rows.iter().filter(|r| r.print).map(|r| r.p).collect();
            let top = prints.iter().map(|p| p[2]).fold(f64::MIN, f64::max);
            let cart: Vec<_> = krl
                .moves
                .iter()
                .filter(|m| matches!(m.target, Target::Frame(_)))
                .collect();
            for m in &cart {
                if m.motion == Motion::Ptp {
                    assert!(
                        m.status_turn.is_some(),
                        "{at}: PTP without S and T at {}:{}",
                        m.file,
                        m.line
                    );
                }
            }
            for m in [cart.first(), cart.last()].into_iter().flatten() {
                let Target::Frame(t) = m.target else {
                    unreachable!()
                };
                assert_eq!(m.motion, Motion::Ptp, "{at}: {}:{}", m.file, m.line);
                assert!(
                    (t[2] - offset[2] - (top + SAFE)).abs() < 0.01,
                    "{at}: the safe point at Z {} for a top at {top}",
                    t[2] - offset[2]
                );
            }
            let first_print = krl.moves.iter().position(|m| m.extruder).expect("prints");
            let ready = krl.ready.as_ref().expect("the ready input's wait");
            assert_eq!(ready.input, 3, "{at}");
            assert!(
                ready.halts && ready.before_move <= first_print,
                "{at}: {ready:?}"
            );
            let (feed, extruder) = (
                krl.feed_output.expect("feed output"),
                krl.extruder_output.expect("extruder output"),
            );
            assert!(
                krl.interrupts
                    .iter()
                    .any(|i| i.condition == "$STOPMESS==TRUE"
                        && i.on
                        && i.analog.contains(&(feed, 0.0))
                        && i.outputs.contains(&(extruder, false))
                        && i.brakes),
                "{at}: {:?}",
                krl.interrupts
            );
            assert_eq!((krl.end_feed, krl.end_extruder), (Some(0.0), false), "{at}");
            // Every print motion ends on a planned print point, in order; the points between
            // two print motions' ends lie within the tolerance of the chord (lin: none between).
            let d = |a: [f64; 3], b: [f64; 3]| {
                ((a[0] - b[0]).powi(2) + (a[1] - b[1]).powi(2) + (a[2] - b[2]).powi(2)).sqrt()
            };
            let (mut j, mut last): (usize, Option<usize>) = (0, None);
            let mut skipped = 0;
            for m in &krl.moves {
                // A path ends where the extruder goes off: no chord across a travel.
                let Target::Frame(t) = m.target else {
                    last = None;
                    continue;
                };
                if !m.extruder {
                    last = None;
                    continue;
                }
                let p = [t[0] - offset[0], t[1] - offset[1], t[2] - offset[2]];
                let k = (j..prints.len())
                    .find(|&k| d(prints[k], p) <= 0.002)
                    .unwrap_or_else(|| {
                        panic!("{at}: {}:{} ends on no planned point ahead", m.file, m.line)
                    });
                if let Some(l) = last.filter(|&l| l < k) {
                    let (a, b) = (prints[l], prints[k]);
                    for q in &prints[l + 1..k] {
                        let ab = [b[0] - a[0], b[1] - a[1], b[2] - a[2]];
                        let aq = [q[0] - a[0], q[1] - a[1], q[2] - a[2]];
                        let len2 = ab.iter().map(|x| x * x).sum::<f64>();
                        let t = if len2 > 0.0 {
                            (0..3).map(|i| ab[i] * aq[i]).sum::<f64>() / len2
                        } else {
                            0.0
                        }
                        .clamp(0.0, 1.0);
                        let foot = [a[0] + t * ab[0], a[1] + t * ab[1], a[2] + t * ab[2]];
                        let tolerance = if motion == "spline" {
                            SPLINE_TOLERANCE
                        } else {
                            0.01
                        };
                        assert!(
                            d(*q, foot) <= tolerance,
                            "{at}: {q:?} left out, {} from the chord",
                            d(*q, foot)
                        );
                    }
                    skipped += k - l - 1;
                }
                last = Some(k);
                j = k;
            }
            // joints.csv: a row per Cartesian motion, whose forward kinematics (the profile's
            // arm, then $TOOL, in $BASE) is the planned point it names, with its tool axis.
            let cell = robot_post::MachineProfile::builtin(robot_post::MachineKind::Kuka)
                .kuka
                .expect("the KUKA cell");
            let base_inv = Pose::from_frame(krl.base.expect("base")).inverse();
            let tool = Pose::from_frame(krl.tool.expect("tool"));
            let joints = read(&out.join("joints.csv"));
            let mut lines = joints.lines();
            assert_eq!(lines.next(), Some(robot_post::kuka::JOINTS_HEADER));
            let mut checked = 0;
            for (n, l) in lines.enumerate() {
                let cells: Vec<f64> = l.split(',').map(|c| c.parse().expect(l)).collect();
                assert_eq!(cells.len(), 8, "{at}: {l}");
                assert_eq!(cells[0] as usize, n + 1, "{at}: {l}");
                let j = [cells[2], cells[3], cells[4], cells[5], cells[6], cells[7]];
                let tcp = base_inv.compose(&cell.arm.forward(j).compose(&tool));
                let m = cart[n];
                let Target::Frame(f) = m.target else {
                    unreachable!()
                };
                let moved = d(tcp.t, [f[0], f[1], f[2]]);
                assert!(
                    moved <= 0.05,
                    "{at}: row {}: {moved} mm from its motion",
                    n + 1
                );
                let row = &rows[cells[1] as usize];
                if m.extruder {
                    let p = [
                        tcp.t[0] - offset[0],
                        tcp.t[1] - offset[1],
                        tcp.t[2] - offset[2],
                    ];
                    let z = tcp.z_axis();
                    let cos = -(0..3).map(|k| z[k] * row.axis[k]).sum::<f64>();
                    assert!(
                        d(p, row.p) <= 0.05 && cos >= 0.1f64.to_radians().cos(),
                        "{at}: row {}: {p:?} is not its point {:?}",
                        n + 1,
                        row.p
                    );
                    checked += 1;
                }
            }
            assert!(checked > 1000, "{at}: {checked} print rows");
            eprintln!(
                "{at}: {} Cartesian motions, {skipped} planned points left out between print motions, {checked} print rows by forward kinematics",
                cart.len()
            );
        }
    }
}
