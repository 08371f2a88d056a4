//! The pedestal (issue 31): every `ledge` part of the generated families (bosses, ribs and
//! blades growing 2.5–15 mm sideways, low over the table, from cylinders, cones and boxes)
//! plans on `delta5` with exit 0 and no colliding move, on a pedestal that is the least that
//! works: one layer less (`--set pedestal=<h − one layer>`) leaves the head hitting the table.
//! The pedestal is a feature of kind `pedestal` with the next free id, printed first, extruding
//! its prism's volume within the self-check's ±3 %, in `toolpath.csv` and the program.

use serde_json::Value;
use std::path::{Path, PathBuf};
use std::process::{Command, Output};

const BIN: &str = env!("CARGO_BIN_EXE_features");

fn families_dir() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../../fixtures/families")
}

/// The `ledge` parts listed in `reference.json`, with their feature counts.
fn ledge_parts() -> Vec<(String, u64)> {
    let text = std::fs::read_to_string(families_dir().join("reference.json"))
        .expect("fixtures/families/reference.json");
    let v: Value = serde_json::from_str(&text).expect("reference.json is JSON");
    v["parts"]
        .as_array()
        .expect("parts")
        .iter()
        .filter(|p| p["family"] == "ledge")
        .map(|p| {
            (
                p["file"].as_str().expect("file").to_string(),
                p["features"].as_u64().expect("features"),
            )
        })
        .collect()
}

/// A directory removed when dropped.
struct Out(PathBuf);
impl Drop for Out {
    fn drop(&mut self) {
        let _ = std::fs::remove_dir_all(&self.0);
    }
}

/// Plans `part` on delta5 as modelled (`--orient modelled`: the pedestal under the part as it
/// stands; other placements and the planar slicing, tried by default after a refusal, are
/// tests/placement.rs's).
fn plan(part: &Path, dir: &Path, extra: &[&str]) -> Output {
    let _ = std::fs::remove_dir_all(dir);
    Command::new(BIN)
        .arg("plan")
        .arg(part)
        .args(["--machine", "delta5", "--orient", "modelled", "-o"])
        .arg(dir)
        .args(extra)
        .output()
        .expect("run features")
}

fn read_json(path: &Path) -> Option<Value> {
    serde_json::from_str(&std::fs::read_to_string(path).ok()?).ok()
}

/// Colliding moves of a plan, and those hitting the table (by each feature's first one, and
/// the count of features whose first one is the table).
fn collisions(plan: &Value) -> (u64, u64) {
    let fs = plan["features"].as_array().cloned().unwrap_or_default();
    let all = fs
        .iter()
        .map(|f| f["collisions"].as_u64().unwrap_or(0))
        .sum();
    let table = fs
        .iter()
        .filter(|f| f["first_collision"]["hits"] == "table")
        .count() as u64;
    (all, table)
}

/// What is wrong with one part (empty when nothing is).
fn check(file: &str, features: u64) -> Vec<String> {
    let part = families_dir().join(file);
    let stem = file.trim_end_matches(".step");
    let dir =
        Out(std::env::temp_dir().join(format!("features-pedestal-{}-{stem}", std::process::id())));
    let out = plan(&part, &dir.0, &[]);
    if !out.status.success() {
        let err = String::from_utf8_lossy(&out.stderr);
        return vec![format!("plan exits {}: {}", out.status, err.trim())];
    }
    let mut why = vec![];
    let Some(p) = read_json(&dir.0.join("plan.json")) else {
        return vec!["no plan.json".into()];
    };
    let (all, _) = collisions(&p);
    if all != 0 {
        why.push(format!("{all} colliding moves"));
    }
    let fs = p["features"].as_array().cloned().unwrap_or_default();
    let Some(ped) = fs.iter().find(|f| f["kind"] == "pedestal") else {
        return [why, vec!["no pedestal".into()]].concat();
    };
    // Printed first, with the next free id.
    if fs[0]["kind"] != "pedestal" || ped["id"].as_u64() != Some(features) {
        why.push(format!(
            "the pedestal is not feature {features} printed first: {}",
            ped["id"]
        ));
    }
    let h = ped["pedestal_height_mm"].as_f64().unwrap_or(0.0);
    let n = ped["layers"].as_u64().unwrap_or(0);
    let (v, e) = (
        ped["volume_mm3"].as_f64().unwrap_or(f64::NAN),
        ped["extruded_volume_mm3"].as_f64().unwrap_or(f64::NAN),
    );
    if !(h > 0.0 && n > 0 && ((e - v) / v).abs() <= 0.03) {
        why.push(format!(
            "pedestal {h} mm, {n} layers: {e} mm^3 extruded for {v} mm^3"
        ));
        return why;
    }
    // Its points first in toolpath.csv and marked in the program.
    let csv = std::fs::read_to_string(dir.0.join("toolpath.csv")).unwrap_or_default();
    let first = csv.lines().nth(1).and_then(|l| l.split(',').next());
    if first != Some(features.to_string().as_str()) {
        why.push(format!("toolpath.csv starts with feature {first:?}"));
    }
    let gcode = std::fs::read_to_string(dir.0.join("program.gcode")).unwrap_or_default();
    if !gcode.contains(&format!(";FEATURE:{features}\n")) {
        why.push("the program does not mark the pedestal's feature".into());
    }
    // One layer less hits the table.
    let layer = h / n as f64;
    let less = if n == 1 {
        "pedestal=off".to_string()
    } else {
        format!("pedestal={}", h - layer)
    };
    let out = plan(&part, &dir.0, &["--set", &less, "--allow-collisions"]);
    match read_json(&dir.0.join("plan.json")) {
        Some(q) if out.status.success() => {
            let lower = q["features"]
                .as_array()
                .and_then(|fs| fs.iter().find(|f| f["kind"] == "pedestal"))
                .map_or(0, |f| f["layers"].as_u64().unwrap_or(0));
            if lower + 1 != n {
                why.push(format!("{less} gave {lower} layers, not {}", n - 1));
            }
            let (_, table) = collisions(&q);
            if table == 0 {
                why.push(format!(
                    "a pedestal of {h} mm is not the least: {less} leaves no table hit"
                ));
            }
        }
        _ => why.push(format!(
            "{less}: plan exits {}: {}",
            out.status,
            String::from_utf8_lossy(&out.stderr).trim()
        )),
    }
    eprintln!("{file}: pedestal {h} mm ({n} layers); {less} hits the table");
    why
}

/// A machine whose tallest pedestal is one layer short refuses the plan, naming a height that
/// does clear the table (planned on it: no colliding move).
fn refused_naming_the_height(file: &str) -> Vec<String> {
    let part = families_dir().join(file);
    let stem = file.trim_end_matches(".step");
    let dir = Out(std::env::temp_dir().join(format!(
        "features-pedestal-max-{}-{stem}",
        std::process::id()
    )));
    let out = plan(&part, &dir.0, &[]);
    let Some(p) = read_json(&dir.0.join("plan.json")).filter(|_| out.status.success()) else {
        return vec!["no plan".into()];
    };
    let ped = p["features"][0].clone();
    let (h, n) = (
        ped["pedestal_height_mm"].as_f64().unwrap_or(0.0),
        ped["layers"].as_u64().unwrap_or(0),
    );
    if n < 2 {
        return vec![format!(
            "a pedestal of {n} layers: none one layer shorter to refuse"
        )];
    }
    let max = format!("machine.max_pedestal_height={}", h - h / n as f64);
    let out = plan(&part, &dir.0, &["--set", &max]);
    let err = String::from_utf8_lossy(&out.stderr).to_string();
    let named = err
        .split("; a pedestal of ")
        .nth(1)
        .and_then(|t| t.split(" mm clears").next())
        .and_then(|t| t.parse::<f64>().ok());
    let Some(named) = named.filter(|_| out.status.code() == Some(2)) else {
        return vec![format!("{max}: exit {}, {err}", out.status)];
    };
    let mut why = vec![];
    if named < h {
        why.push(format!("{max} names {named} mm, under the least {h} mm"));
    }
    let set = format!("pedestal={named}");
    let out = plan(&part, &dir.0, &["--set", &set]);
    if !out.status.success() {
        why.push(format!(
            "{set} (named by {max}): exit {}: {}",
            out.status,
            String::from_utf8_lossy(&out.stderr).trim()
        ));
    }
    why
}

#[test]
fn ledge_parts_stand_on_the_least_pedestal_that_clears_the_table() {
    let parts = ledge_parts();
    assert!(parts.len() >= 6, "{parts:?}");
    let failures: Vec<String> = std::thread::scope(|s| {
        let handles: Vec<_> = parts
            .chunks(parts.len().div_ceil(2))
            .map(|chunk| {
                s.spawn(move || {
                    chunk
                        .iter()
                        .flat_map(|(f, n)| {
                            check(f, *n).into_iter().map(move |w| format!("{f}: {w}"))
                        })
                        .collect::<Vec<_>>()
                })
            })
            .collect();
        handles
            .into_iter()
            .flat_map(|h| h.join().expect("thread"))
            .collect()
    });
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}

#[test]
fn a_pedestal_taller_than_the_machine_allows_is_refused_naming_one_that_clears() {
    let parts = ledge_parts();
    let (file, _) = &parts[0];
    let why = refused_naming_the_height(file);
    assert!(why.is_empty(), "{file}: {}", why.join("\n"));
}
