//! The machine programs of `features plan` (issue 21, "Machine programs"), end to end through
//! the binary: the profile's start and end G-code with their placeholders, the fan by layer,
//! no zero-length or zero-extrusion moves, feeds within the profile's limit (Marlin and
//! delta5), and KRL extrusion following the planned flow.

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

const BIN: &str = env!("CARGO_BIN_EXE_features");

fn fixture(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../../fixtures")
        .join(name)
}

/// A scratch folder of one test, removed when dropped.
struct Scratch(PathBuf);
impl Scratch {
    fn new(test: &str) -> Scratch {
        let d =
            std::env::temp_dir().join(format!("features-programs-{}-{test}", std::process::id()));
        let _ = std::fs::remove_dir_all(&d);
        std::fs::create_dir_all(&d).expect("scratch");
        Scratch(d)
    }
    fn path(&self, name: &str) -> PathBuf {
        self.0.join(name)
    }
}
impl Drop for Scratch {
    fn drop(&mut self) {
        let _ = std::fs::remove_dir_all(&self.0);
    }
}

fn plan(part: &str, args: &[&str]) -> Output {
    Command::new(BIN)
        .arg("plan")
        .arg(fixture(part))
        .args(args)
        .output()
        .expect("runs")
}

fn stderr(o: &Output) -> String {
    String::from_utf8_lossy(&o.stderr).into_owned()
}

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
        "G0 X0.000 Y0.000 Z0.3 F7200 ; purge line",
        "G1 X100 E5.61265 F1200",
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
    let warning = err
        .lines()
        .find(|l| l.contains("max_feed_mm_min"))
        .unwrap_or_else(|| panic!("no feed warning in {err}"));
    assert!(
        warning.contains(&format!(
            ": warning: {at_limit} print move(s) asked for a feed above"
        )),
        "{warning}"
    );
    assert!(program.contains(
        "; F: machine-axis feed (mm/min along the XYZ path, degrees/min for a move of B and C alone) scaled so the nozzle moves over the part at print_speed"
    ));
}
