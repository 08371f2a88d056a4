//! The same part on a 3-axis printer (issue 33, item 4): the process key `slicing`. On
//! `marlin` (prints only along +Z) a part with a feature growing along another direction is
//! planned whole, one two5d feature per solid in planar layers along +Z, instead of being
//! refused for its tool axes; `slicing = "features"` keeps the refusal; `slicing = "planar"`
//! plans any machine's part in +Z layers.

#[path = "common/cli.rs"]
mod cli;

use cli::{fixture, plan, stderr, Scratch, BIN};
use serde_json::Value;
use std::path::Path;
use std::process::Command;

/// The self-check's tolerance on a feature's laid volume (±3 %).
const SELF_CHECK: f64 = 0.03;
/// How close the planned feature's volume is to the solid's as measured by `features
/// extract` (two meshes of the same faces).
const SAME_VOLUME: f64 = 0.005;
/// A tool axis component within this of +Z's is +Z (the CSV's six decimals).
const AXIS_SLACK: f64 = 1e-5;
/// The warning of a feature `auto` put into planar layers.
const PLANAR_WARNING: &str =
    "planned with the part in planar layers along +Z; a 5-axis machine (delta5, kuka) prints it without support";

fn read_json(path: &Path) -> Value {
    let text = std::fs::read_to_string(path).expect("plan.json written");
    serde_json::from_str(&text).expect("plan.json is JSON")
}

/// `features extract --json` of a fixture.
fn extract(part: &str) -> Value {
    let o = Command::new(BIN)
        .args(["extract", "--json"])
        .arg(fixture(part))
        .output()
        .expect("runs");
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    serde_json::from_slice(&o.stdout).expect("extract JSON")
}

/// The ids of the features of an extraction whose build direction is not +Z: freeform ones,
/// and two5d ones whose reference normal is off +Z.
fn tilted(extracted: &Value) -> Vec<u64> {
    extracted["features"]
        .as_array()
        .expect("features")
        .iter()
        .filter(|f| {
            let up = f["reference"]["normal"][2]
                .as_f64()
                .is_some_and(|z| z > 1.0 - AXIS_SLACK);
            f["kind"] == "freeform" || !up
        })
        .map(|f| f["id"].as_u64().expect("id"))
        .collect()
}

/// Every tool axis of a plan's `toolpath.csv` is +Z; the number of rows.
fn all_axes_plus_z(csv: &Path) -> usize {
    let text = std::fs::read_to_string(csv).expect("toolpath.csv written");
    let mut lines = text.lines();
    let header: Vec<&str> = lines.next().expect("header").split(',').collect();
    let col = |name: &str| header.iter().position(|h| *h == name).expect("column");
    let (i, j, k) = (col("i"), col("j"), col("k"));
    let mut rows = 0;
    for line in lines {
        let v: Vec<f64> = line
            .split(',')
            .map(|x| x.parse().unwrap_or(f64::NAN))
            .collect();
        assert!(
            v[i].abs() <= AXIS_SLACK
                && v[j].abs() <= AXIS_SLACK
                && (v[k] - 1.0).abs() <= AXIS_SLACK,
            "not +Z: {line}"
        );
        rows += 1;
    }
    rows
}

/// A feature of a plan laid its volume within the self-check's tolerance.
fn laid_its_volume(f: &Value) {
    let volume = f["volume_mm3"].as_f64().expect("volume");
    let laid = f["extruded_volume_mm3"].as_f64().expect("extruded");
    assert!(
        (laid - volume).abs() <= SELF_CHECK * volume,
        "laid {laid} mm^3 for {volume} mm^3"
    );
}

#[test]
fn marlin_plans_a_part_with_tilted_features_whole_in_planar_layers() {
    let s = Scratch::new("auto");
    let part = "sphere_boss.step";
    let extracted = extract(part);
    let tilted = tilted(&extracted);
    assert!(
        !tilted.is_empty(),
        "sphere_boss's boss grows 30 degrees off +Z"
    );
    let out = s.path("m");
    let o = plan(
        part,
        &["--machine", "marlin", "-o", out.to_str().expect("utf-8")],
    );
    let err = stderr(&o);
    assert_eq!(o.status.code(), Some(0), "{err}");
    let report = read_json(&out.join("plan.json"));
    assert_eq!(report["slicing"], "planar");
    assert_eq!(report["complete"], true);
    // One feature for its one solid: the whole part along +Z, its volume the solid's.
    let features = report["features"].as_array().expect("features");
    assert_eq!(features.len(), 1);
    let f = &features[0];
    assert_eq!(f["kind"], "two5d");
    assert_eq!(f["subtype"], "whole_part");
    assert_eq!(f["reference"]["normal"], serde_json::json!([0.0, 0.0, 1.0]));
    let solid = extracted["part"]["volume_mm3"]
        .as_f64()
        .expect("part volume");
    let volume = f["volume_mm3"].as_f64().expect("volume");
    assert!(
        (volume - solid).abs() <= SAME_VOLUME * solid,
        "{volume} mm^3 planned for a {solid} mm^3 solid"
    );
    laid_its_volume(f);
    // One warning per tilted feature, naming it, in plan.json and on stderr.
    let warnings: Vec<&str> = report["warnings"]
        .as_array()
        .expect("warnings")
        .iter()
        .filter_map(Value::as_str)
        .filter(|w| w.contains(PLANAR_WARNING))
        .collect();
    assert_eq!(warnings.len(), tilted.len(), "{warnings:?}");
    for id in &tilted {
        let head = format!("feature {id} (");
        assert!(
            warnings.iter().any(|w| w.starts_with(&head)),
            "{warnings:?}"
        );
        assert!(err.contains(&head), "{err}");
    }
    let summary = String::from_utf8_lossy(&o.stdout);
    assert!(summary.contains("planar layers along +Z"), "{summary}");
    assert!(all_axes_plus_z(&out.join("toolpath.csv")) > 0);
}

#[test]
fn features_slicing_on_marlin_keeps_the_axis_refusal() {
    let s = Scratch::new("features");
    let out = s.path("m");
    let o = plan(
        "sphere_boss.step",
        &[
            "--machine",
            "marlin",
            "--set",
            "slicing=features",
            // As modelled: by default the other placements are tried, and on the face whose
            // normal leans 30 degrees every feature grows along +Z.
            "--orient",
            "modelled",
            "-o",
            out.to_str().expect("utf-8"),
        ],
    );
    let err = stderr(&o);
    assert_eq!(o.status.code(), Some(2), "{err}");
    let last = err.lines().last().unwrap_or("");
    assert!(last.contains("not +Z") && last.contains("marlin"), "{last}");
    assert!(!out.join("program.gcode").exists());
    assert_eq!(read_json(&out.join("plan.json"))["slicing"], "features");
}

#[test]
fn planar_slicing_on_delta5_lays_every_point_along_plus_z() {
    let s = Scratch::new("delta5");
    let out = s.path("d");
    let o = plan(
        "sphere_boss.step",
        &[
            "--machine",
            "delta5",
            "--set",
            "slicing=planar",
            "-o",
            out.to_str().expect("utf-8"),
        ],
    );
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    let report = read_json(&out.join("plan.json"));
    assert_eq!(report["slicing"], "planar");
    // Asked for, not chosen: no warning of tilted features.
    let warned = report["warnings"]
        .as_array()
        .expect("warnings")
        .iter()
        .filter_map(Value::as_str)
        .any(|w| w.contains(PLANAR_WARNING));
    assert!(!warned);
    assert!(all_axes_plus_z(&out.join("toolpath.csv")) > 0);
}

#[test]
fn planar_slicing_plans_separate_solids_together_in_one_feature() {
    // Two boxes of 4000 and 3000 mm^3 (fixtures/two_solids.json): 20x20x10 at the origin and
    // 10x10x30 at x=40, sliced in the same layers as one feature.
    let s = Scratch::new("solids");
    let out = s.path("t");
    let o = plan(
        "two_solids.step",
        &[
            "--set",
            "slicing=planar",
            "-o",
            out.to_str().expect("utf-8"),
        ],
    );
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    let meta: Value = serde_json::from_str(
        &std::fs::read_to_string(fixture("two_solids.json")).expect("two_solids.json"),
    )
    .expect("JSON");
    let expected: f64 = meta["volumes_mm3"]
        .as_array()
        .expect("volumes")
        .iter()
        .filter_map(Value::as_f64)
        .sum();
    let report = read_json(&out.join("plan.json"));
    let features = report["features"].as_array().expect("features");
    assert_eq!(features.len(), 1);
    let f = &features[0];
    assert_eq!(f["subtype"], "whole_part");
    laid_its_volume(f);
    let planned = f["volume_mm3"].as_f64().expect("volume");
    assert!(
        (planned - expected).abs() <= SAME_VOLUME * expected,
        "{planned} mm^3 for {expected} mm^3"
    );
    // Both boxes in each layer up to the low box's top: the layers of the tall box below
    // z = 10 are laid between those of the low one, not after its last.
    let text = std::fs::read_to_string(out.join("toolpath.csv")).expect("toolpath.csv");
    let mut lines = text.lines();
    let header: Vec<&str> = lines.next().expect("header").split(',').collect();
    let col = |name: &str| header.iter().position(|h| *h == name).expect("column");
    let (x, z) = (col("x"), col("z"));
    let mut order: Vec<(f64, f64)> = vec![];
    for line in lines {
        let v: Vec<&str> = line.split(',').collect();
        let (Ok(px), Ok(pz)) = (v[x].parse::<f64>(), v[z].parse::<f64>()) else {
            continue;
        };
        order.push((px, pz));
    }
    let last_low = order
        .iter()
        .rposition(|p| p.0 <= 20.0)
        .expect("low box laid");
    let first_tall = order
        .iter()
        .position(|p| p.0 >= 40.0)
        .expect("tall box laid");
    assert!(
        first_tall < last_low,
        "the tall box starts at row {first_tall}, after the low box's last row {last_low}"
    );
    assert!(order.iter().any(|p| p.0 >= 40.0 && p.1 >= 29.0));
}

#[test]
fn a_bad_slicing_is_refused_naming_the_choices() {
    let s = Scratch::new("bad");
    let o = plan(
        "box.step",
        &[
            "--set",
            "slicing=tilted",
            "-o",
            s.path("b").to_str().expect("utf-8"),
        ],
    );
    let err = stderr(&o);
    assert_eq!(o.status.code(), Some(2), "{err}");
    for w in [
        "slicing",
        "\"auto\"",
        "\"features\"",
        "\"planar\"",
        "tilted",
    ] {
        assert!(err.contains(w), "`{w}` missing from: {err}");
    }
    let o = plan(
        "box.step",
        &[
            "--set",
            "features.0.slicing=planar",
            "-o",
            s.path("f").to_str().expect("utf-8"),
        ],
    );
    let err = stderr(&o);
    assert_eq!(o.status.code(), Some(2), "{err}");
    assert!(err.contains("[defaults]"), "{err}");
}
