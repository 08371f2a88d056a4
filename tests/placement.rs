//! Placement found, not assumed (issue 31, item 3), end to end through the binary: a part
//! refused as modelled is planned on another placement (turned about +Z to fit, or on another
//! planar face), said on stderr and in `plan.json`; when none plans, each candidate's failure
//! is listed. The parts are fixtures turned or stretched here, in their STEP text.

#[path = "common/cli.rs"]
mod cli;

use cli::{fixture, stderr, Scratch, BIN};
use serde_json::Value;
use std::path::Path;
use std::process::{Command, Output};

/// Writes `src` (a fixture's name) to `dst` with every 3D `CARTESIAN_POINT` mapped by `point`
/// and every 3D `DIRECTION` by `dir` (2D ones, of curves in a surface's parameters, kept).
fn transformed(
    src: &str,
    dst: &Path,
    point: impl Fn([f64; 3]) -> [f64; 3],
    dir: impl Fn([f64; 3]) -> [f64; 3],
) {
    let text = std::fs::read_to_string(fixture(src)).expect("fixture");
    let mut out = String::with_capacity(text.len());
    let mut rest = text.as_str();
    loop {
        let next = ["CARTESIAN_POINT(", "DIRECTION("]
            .iter()
            .filter_map(|k| rest.find(k).map(|i| (i, *k)))
            .min();
        let Some((at, key)) = next else {
            out.push_str(rest);
            break;
        };
        // The coordinates: the parenthesis after the entity's name.
        let open = at + rest[at..].find(",(").expect("coordinates") + 2;
        let close = open + rest[open..].find(')').expect("closed");
        out.push_str(&rest[..open]);
        let v: Vec<f64> = rest[open..close]
            .split(',')
            .map(|x| x.trim().parse().expect("a number"))
            .collect();
        if v.len() == 3 {
            let p = [v[0], v[1], v[2]];
            let q = if key == "DIRECTION(" {
                dir(p)
            } else {
                point(p)
            };
            out.push_str(&q.map(|x| format!("{x:?}")).join(","));
        } else {
            out.push_str(&rest[open..close]);
        }
        rest = &rest[close..];
    }
    std::fs::write(dst, out).expect("write");
}

fn plan_at(part: &Path, machine: &str, out: &Path, more: &[&str]) -> Output {
    Command::new(BIN)
        .arg("plan")
        .arg(part)
        .args(["--machine", machine, "-o"])
        .arg(out)
        .args(more)
        .output()
        .expect("runs")
}

fn report(dir: &Path) -> Value {
    serde_json::from_str(&std::fs::read_to_string(dir.join("plan.json")).expect("plan.json"))
        .expect("json")
}

/// Half a turn about X: the part upside down.
fn upside_down(p: [f64; 3]) -> [f64; 3] {
    [p[0], -p[1], -p[2]]
}

#[test]
fn a_part_modelled_upside_down_plans_on_its_plate_face() {
    let s = Scratch::new("upside_down");
    let part = s.path("plate_boss_boss_upside_down.step");
    transformed("plate_boss_boss.step", &part, upside_down, upside_down);
    let out = s.path("plan");
    // Without support material: with it, the plate is printed on columns as modelled (the
    // retry looks for another placement only when the part as modelled is refused).
    let o = plan_at(&part, "marlin", &out, &["--set", "support_material=off"]);
    let err = stderr(&o);
    assert!(o.status.success(), "{err}");
    assert!(out.join("program.gcode").exists());
    let r = report(&out);
    assert_eq!(r["complete"], true);
    // Standing on the plate's bottom face: its outward normal, +Z in the file turned over,
    // turned down; every feature held up.
    let p = &r["placement"];
    let down: Vec<f64> = p["down"]
        .as_array()
        .expect("down")
        .iter()
        .map(|x| x.as_f64().expect("number"))
        .collect();
    assert!(
        (down[2] - 1.0).abs() < 1e-9 && down[0].abs() < 1e-9,
        "{down:?}"
    );
    assert!(p["base_face"].as_u64().is_some(), "{p}");
    for f in r["features"].as_array().expect("features") {
        assert_eq!(f["unsupported_area_mm2"], 0.0);
    }
    // What failed as modelled: the plate laid in the air over the bosses.
    let tried = p["tried"].as_array().expect("tried");
    assert_eq!(tried[0]["candidate"], "the part as modelled");
    assert!(
        tried[0]["failure"]
            .as_str()
            .is_some_and(|f| f.contains("unsupported")),
        "{tried:?}"
    );
    let id = p["base_face"].as_u64().expect("face");
    assert!(
        err.lines()
            .any(|l| l.contains(&format!("placed on face #{id}"))
                && l.contains("after the part as modelled failed")),
        "{err}"
    );
    // Turned back onto its plate, it is the part as modelled in the fixture: the same moves.
    let orig = s.path("orig");
    let o = plan_at(
        &fixture("plate_boss_boss.step"),
        "marlin",
        &orig,
        &["--set", "support_material=off"],
    );
    assert!(o.status.success(), "{}", stderr(&o));
    let moves = |dir: &Path| -> Vec<String> {
        std::fs::read_to_string(dir.join("program.gcode"))
            .expect("program")
            .lines()
            .filter(|l| !l.starts_with(';'))
            .map(str::to_string)
            .collect()
    };
    assert!(moves(&out) == moves(&orig), "the programs' moves differ");
    // --orient modelled keeps it as modelled: refused, naming the remedy.
    let o = plan_at(
        &part,
        "marlin",
        &s.path("kept"),
        &["--orient", "modelled", "--set", "support_material=off"],
    );
    let err = stderr(&o);
    assert_eq!(o.status.code(), Some(2), "{err}");
    let last = err.lines().last().unwrap_or("");
    assert!(last.contains("leave out --orient modelled"), "{last}");
}

#[test]
fn a_bar_missing_the_delta5_envelope_plans_turned_about_z() {
    let s = Scratch::new("bar_turned");
    // The 20 × 30 × 10 box stretched to 20 × 202 × 4 mm: 2 mm longer than the 200 mm square
    // work envelope.
    let part = s.path("bar.step");
    let length = 202.0;
    transformed(
        "box.step",
        &part,
        |p| [p[0], p[1] * length / 30.0, p[2] * 0.4],
        |d| d,
    );
    let out = s.path("plan");
    let o = plan_at(&part, "delta5", &out, &[]);
    let err = stderr(&o);
    assert!(o.status.success(), "{err}");
    let r = report(&out);
    let p = &r["placement"];
    assert!(p["base_face"].is_null(), "{p}");
    let turn = p["turn_deg"].as_f64().expect("turned");
    // Turned, the extent along X and Y of the nozzle's path, half a bead (delta5's
    // bead_width 0.45 mm) inside the bar's outline, lies within the 200 mm square.
    let bead = 0.45;
    let (s_, c) = turn.to_radians().sin_cos();
    let reach_y = (length - bead) * c.abs() + (20.0 - bead) * s_.abs();
    let reach_x = (length - bead) * s_.abs() + (20.0 - bead) * c.abs();
    assert!(
        reach_x < 200.0 && reach_y < 200.0,
        "{turn}: {reach_x} {reach_y}"
    );
    let tried = p["tried"].as_array().expect("tried");
    assert_eq!(tried.len(), 1, "{tried:?}");
    assert!(
        tried[0]["failure"]
            .as_str()
            .is_some_and(|f| f.contains("work envelope")),
        "{tried:?}"
    );
    assert!(err.contains("turned"), "{err}");
}

#[test]
fn a_part_no_placement_saves_is_refused_listing_each_candidate() {
    let s = Scratch::new("bar_too_long");
    // 300 mm: longer than the envelope's diagonal and its height on end.
    let part = s.path("bar.step");
    transformed(
        "box.step",
        &part,
        |p| [p[0], p[1] * 10.0, p[2] * 0.4],
        |d| d,
    );
    let out = s.path("plan");
    let o = plan_at(&part, "delta5", &out, &[]);
    let err = stderr(&o);
    assert_eq!(o.status.code(), Some(2), "{err}");
    // The refusal of the part as modelled is the last line, and its plan.json shows why.
    let last = err.lines().last().unwrap_or("");
    assert!(
        last.contains("work envelope") && last.contains("no program written"),
        "{last}"
    );
    assert!(!out.join("program.gcode").exists());
    let r = report(&out);
    assert_eq!(r["complete"], false);
    let tried = r["placement"]["tried"].as_array().expect("tried");
    // As modelled, then the box's faces but the one it stands on, at most four (and, for
    // those leaving the envelope, that no turn about +Z fits): each listed on stderr.
    assert_eq!(tried[0]["candidate"], "the part as modelled");
    let faces = tried
        .iter()
        .filter(|t| {
            t["candidate"]
                .as_str()
                .is_some_and(|c| c.starts_with("face #") && !c.contains("turned"))
        })
        .count();
    assert_eq!(faces, 4, "{tried:?}");
    assert!(
        tried.iter().any(|t| t["failure"]
            .as_str()
            .is_some_and(|f| f.contains("no turn about the build direction fits"))),
        "{tried:?}"
    );
    let refused: Vec<&str> = err
        .lines()
        .filter(|l| l.contains(": placement ") && l.contains(" refused: "))
        .collect();
    for t in &tried[1..] {
        let c = t["candidate"].as_str().expect("candidate");
        let f = t["failure"].as_str().expect("failure");
        assert!(
            refused
                .iter()
                .any(|l| l.contains(&format!("{c} refused: {f}"))),
            "{c}: {err}"
        );
    }
}

#[test]
fn a_chosen_face_refused_names_the_remedy() {
    let s = Scratch::new("chosen_face");
    // On the small boss's top the plate is laid in the air: refused, with no retry, and the
    // line says another placement may plan.
    let out = s.path("top");
    let o = plan_at(
        &fixture("plate_boss_boss.step"),
        "marlin",
        &out,
        // Without support material, which would carry the plate on columns.
        &["--base-face", "521", "--set", "support_material=off"],
    );
    let err = stderr(&o);
    assert_eq!(o.status.code(), Some(2), "{err}");
    assert!(!err.contains("trying placement"), "{err}");
    let last = err.lines().last().unwrap_or("");
    assert!(last.contains("--orient auto"), "{last}");
}

/// The last candidate (`plan::retry::Candidate::Planar`): SolidWorks' leg fork, planned feature
/// by feature as modelled, loses its base feature's rounded end below the plate (the
/// self-check refuses it, tests/plan.rs); by default it is then sliced whole in planar layers
/// along +Z on delta5, with support material under its overhangs, and plans.
#[test]
fn a_part_whose_features_fail_their_self_check_plans_sliced_whole() {
    let part =
        Path::new(env!("CARGO_MANIFEST_DIR")).join("../../../shared/corpus/sw2017_leg_fork.step");
    if !part.exists() {
        eprintln!("skipped: {} is not there", part.display());
        return;
    }
    let s = Scratch::new("planar_fallback");
    let out = s.path("plan");
    let o = plan_at(&part, "delta5", &out, &[]);
    let err = stderr(&o);
    assert!(o.status.success(), "{err}");
    assert!(
        err.contains("placed as modelled, sliced whole in planar layers along +Z"),
        "{err}"
    );
    let r = report(&out);
    assert_eq!(r["complete"], true);
    assert_eq!(r["slicing"], "planar");
    let tried = r["placement"]["tried"].as_array().expect("tried");
    assert_eq!(tried.len(), 1, "only the planar slicing after a self-check");
    assert!(
        tried[0]["failure"]
            .as_str()
            .is_some_and(|f| f.contains("self-check")),
        "{tried:?}"
    );
    // One feature, the whole solid: laid within the self-check's 3 % of its volume, and
    // every tool axis +Z (no tilt).
    let features = r["features"].as_array().expect("features");
    assert_eq!(features.len(), 1);
    let f = &features[0];
    let (v, e) = (
        f["volume_mm3"].as_f64().expect("volume"),
        f["extruded_volume_mm3"].as_f64().expect("extruded"),
    );
    assert!(((e - v) / v).abs() <= 0.03, "{e} mm^3 laid for {v}");
    let csv = std::fs::read_to_string(out.join("toolpath.csv")).expect("toolpath.csv");
    for line in csv.lines().skip(1) {
        let c: Vec<&str> = line.split(',').collect();
        let k: f64 = c[8].parse().expect("k");
        assert!((k - 1.0).abs() < 1e-9, "{line}");
    }
}

#[test]
fn an_attempt_is_given_up_at_its_first_unsupported_curved_feature_and_the_refusal_is_whole() {
    // The impeller on delta5, its features kept (`slicing = "features"`): its blades' curved
    // layers overhang the hub as modelled and on its face, so every attempt stops at the
    // first blade; then the part as modelled is planned in full for the refusal reported.
    let s = Scratch::new("given_up");
    let out = s.path("plan");
    let o = plan_at(
        &fixture("impeller.step"),
        "delta5",
        &out,
        &["--set", "slicing=features"],
    );
    let err = stderr(&o);
    assert_eq!(o.status.code(), Some(2), "{err}");
    assert!(
        err.contains("no placement plans; planning the part as modelled in full"),
        "{err}"
    );
    let r = report(&out);
    assert_eq!(r["complete"], false);
    // The whole plan: every feature laid, each blade's unsupported layers listed.
    let features = r["features"].as_array().expect("features");
    assert_eq!(features.len(), 7);
    let unsupported: Vec<_> = r["failures"]
        .as_array()
        .expect("failures")
        .iter()
        .filter(|f| f["gate"] == "unsupported")
        .collect();
    assert_eq!(unsupported.len(), 6, "{unsupported:?}");
    for f in &features[1..] {
        assert!(
            f["unsupported_area_mm2"].as_f64().unwrap_or(0.0) > 0.0,
            "{f}"
        );
    }
    // The part as modelled stopped at the first blade found unsupported; the placements after
    // it extract the same blade and are refused for it before laying anything, with the same
    // figures; each says which.
    let tried = r["placement"]["tried"].as_array().expect("tried");
    assert!(tried.len() >= 2, "{tried:?}");
    let failures: Vec<&str> = tried
        .iter()
        .map(|t| t["failure"].as_str().expect("failure"))
        .collect();
    // The figures: the failure but its last parenthesis (how it was found).
    let figures = |f: &str| f[..f.rfind(" (").expect("how found")].to_string();
    for (k, f) in failures.iter().enumerate() {
        assert!(
            f.starts_with("layers not held up: feature 1 (freeform)"),
            "{f}"
        );
        let how = match k {
            0 => "the rest of the plan was not made",
            _ => "as an earlier placement laid the same curved feature",
        };
        assert!(f.contains(how), "{f}");
        assert_eq!(figures(f), figures(failures[0]));
    }
    // Why that holds: planned in full on that face (#3661, the top of the hub, turned down),
    // each blade's curved layers and their unsupported area are those of the part as modelled.
    let face = s.path("face");
    let o = plan_at(
        &fixture("impeller.step"),
        "delta5",
        &face,
        &[
            "--set",
            "slicing=features",
            "--base-face",
            "3661",
            "--keep-going",
            "--set",
            "pedestal=off",
        ],
    );
    // (Refused there by the work envelope, the pedestal left off: laid in full all the same.)
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
    let on_face = report(&face);
    let curved = |r: &Value| -> Vec<(Value, Value, Value)> {
        r["features"]
            .as_array()
            .expect("features")
            .iter()
            .filter(|f| f["kind"] == "freeform")
            .map(|f| {
                (
                    f["faces"].clone(),
                    f["layers"].clone(),
                    f["unsupported_area_mm2"].clone(),
                )
            })
            .collect()
    };
    assert_eq!(curved(&on_face).len(), 6);
    assert_eq!(curved(&on_face), curved(&r));
}
