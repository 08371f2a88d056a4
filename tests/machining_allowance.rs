//! The machining allowance (issue 37, item 2): with `machining_allowance` a feature's faces
//! (but the build plate's and those it grows from) are offset outward on the exact B-rep and
//! the grown solid is planned. Checked on the planned path itself (`toolpath.csv`: where the
//! beads reach against the nominal faces of plate_boss_boss), on the grown solids' volumes
//! against their closed forms, and on `plan.json`'s measure of the allowance left over every
//! nominal face (the impeller, the fan, a freeform pin on a sphere).

#[path = "common/cli.rs"]
mod cli;

use cli::{fixture, stderr, Scratch, BIN};
use serde_json::Value;
use std::f64::consts::PI;
use std::process::Command;

/// The allowance asked for in these tests, mm.
const ALLOWANCE: f64 = 1.0;
/// The process's default `tolerance`, mm.
const TOLERANCE: f64 = 0.05;
/// Marlin's and delta5's bead width (the 0.4 mm nozzle's), mm.
const BEAD: f64 = 0.45;

/// One planned print point: feature, position, bead width.
struct Bead {
    feature: usize,
    p: [f64; 3],
    width: f64,
    role: String,
}

/// Plans `step` with the allowance on `machine`; the plan.json and the print points.
fn plan(step: &str, machine: &str, scratch: &Scratch) -> (Value, Vec<Bead>) {
    let (report, out, _) = plan_with(step, machine, ALLOWANCE, scratch);
    (report, beads_of(&out))
}

/// Plans `step` on `machine` with `machining_allowance = allowance` (none for 0): plan.json,
/// the output folder and stderr.
fn plan_with(
    step: &str,
    machine: &str,
    allowance: f64,
    scratch: &Scratch,
) -> (Value, std::path::PathBuf, String) {
    let out = scratch.path(&format!("{machine}_{}", step.replace(".step", "")));
    let mut cmd = Command::new(BIN);
    cmd.args([
        "plan",
        fixture(step).to_str().unwrap(),
        "--machine",
        machine,
    ]);
    if allowance > 0.0 {
        cmd.args(["--set", &format!("machining_allowance={allowance}")]);
    }
    let o = cmd.arg("-o").arg(&out).output().expect("runs");
    assert!(o.status.success(), "{step} on {machine}: {}", stderr(&o));
    let report: Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("plan.json")).unwrap()).unwrap();
    (report, out, stderr(&o))
}

/// The print points of the plan written to `out`.
fn beads_of(out: &std::path::Path) -> Vec<Bead> {
    let csv = std::fs::read_to_string(out.join("toolpath.csv")).unwrap();
    csv.lines()
        .skip(1)
        .filter_map(|l| {
            let c: Vec<&str> = l.split(',').collect();
            (c[2] == "print").then(|| Bead {
                feature: c[0].parse().unwrap(),
                p: [c[3], c[4], c[5]].map(|x| x.parse().unwrap()),
                width: c[11].parse().unwrap(),
                role: c[12].to_string(),
            })
        })
        .collect()
}

fn allowance(f: &Value) -> &Value {
    &f["machining_allowance"]
}

fn num(v: &Value) -> f64 {
    v.as_f64().unwrap_or(f64::NAN)
}

/// Every feature left at least the allowance less the tolerance over its nominal faces.
fn assert_left_at_least(report: &Value, part: &str) {
    for f in report["features"].as_array().unwrap() {
        if f["kind"] == "pedestal" {
            continue;
        }
        let a = allowance(f);
        assert_eq!(num(&a["requested_mm"]), ALLOWANCE, "{part}: {a}");
        assert!(
            num(&a["min_mm"]) >= ALLOWANCE - TOLERANCE,
            "{part} feature {}: {a}",
            f["id"]
        );
        assert!(a["samples"].as_u64().unwrap() > 0, "{part}: {a}");
        // The plan lays what its layers hold (planar layers: the union of their sections;
        // curved ones: the grown solid), within 1 %.
        let expected = match a["layered_volume_mm3"].is_null() {
            true => num(&a["grown_volume_mm3"]),
            false => num(&a["layered_volume_mm3"]),
        };
        let laid = num(&f["extruded_volume_mm3"]);
        assert!(
            (laid / expected - 1.0).abs() < 0.01,
            "{part} feature {}: {laid} mm^3 laid for {expected}",
            f["id"]
        );
    }
}

#[test]
fn plate_boss_boss_is_printed_a_millimetre_oversize_on_every_face_but_the_plate() {
    let scratch = Scratch::new("allowance_pbb");
    let (report, beads) = plan("plate_boss_boss.step", "marlin", &scratch);
    let part = |f: usize| {
        beads
            .iter()
            .filter(move |b| b.feature == f && !matches!(b.role.as_str(), "skirt" | "brim"))
    };
    // Nominal: a 60 x 40 x 6 plate, a boss of radius 12 to z = 15, one of radius 5 to z = 23.
    // The beads' outer edge (centre + half a width) lies at the grown faces.
    let reach = |f: usize, along: &dyn Fn(&[f64; 3]) -> f64| {
        part(f)
            .map(|b| along(&b.p) + 0.5 * b.width)
            .fold(f64::NEG_INFINITY, f64::max)
    };
    let within = |got: f64, nominal: f64, what: &str| {
        assert!(
            got >= nominal + ALLOWANCE - TOLERANCE && got <= nominal + ALLOWANCE + BEAD,
            "{what}: beads reach {got}, nominal face at {nominal}"
        );
    };
    within(reach(0, &|p| p[0].abs()), 30.0, "plate, x");
    within(reach(0, &|p| p[1].abs()), 20.0, "plate, y");
    within(reach(1, &|p| p[0].hypot(p[1])), 12.0, "boss, radius");
    within(reach(2, &|p| p[0].hypot(p[1])), 5.0, "pin, radius");
    // Tops: the nozzle's height is its layer's top.
    let top = |f: usize| part(f).map(|b| b.p[2]).fold(f64::NEG_INFINITY, f64::max);
    let bottom = |f: usize| part(f).map(|b| b.p[2]).fold(f64::INFINITY, f64::min);
    for (f, nominal) in [(0, 6.0), (1, 15.0), (2, 23.0)] {
        within(top(f), nominal, &format!("feature {f}, top"));
    }
    // The plate stays on the table; each boss stands on its parent's grown top.
    assert!(
        bottom(0) <= 0.2 + 1e-6,
        "plate's first layer at {}",
        bottom(0)
    );
    assert!(
        (bottom(1) - (7.0 + 0.2)).abs() < 1e-3,
        "boss's first layer at {}",
        bottom(1)
    );
    assert!(
        (bottom(2) - (16.0 + 0.2)).abs() < 1e-3,
        "pin's first layer at {}",
        bottom(2)
    );
    // The grown solids against their closed forms (the chords of the boss's and the pin's
    // circles within 0.5 %).
    let features = report["features"].as_array().unwrap();
    let grown = |i: usize| num(&allowance(&features[i])["grown_volume_mm3"]);
    assert!((grown(0) - 62.0 * 42.0 * 7.0).abs() < 1.0, "{}", grown(0));
    for (i, r, h) in [(1, 13.0, 9.0), (2, 6.0, 8.0)] {
        let exact = PI * r * r * h;
        assert!(
            (grown(i) / exact - 1.0).abs() < 0.005,
            "feature {i}: {} for {exact}",
            grown(i)
        );
    }
    assert_left_at_least(&report, "plate_boss_boss");
    // Prismatic features have no concave corner of their own: nothing over a bead more.
    for f in features {
        let a = allowance(f);
        assert!(num(&a["max_mm"]) <= ALLOWANCE + BEAD, "{a}");
        assert_eq!(a["folds"], 0, "{a}");
    }
}

#[test]
fn without_an_allowance_the_report_says_nothing_of_it() {
    let scratch = Scratch::new("allowance_none");
    let (report, _, _) = plan_with("plate_boss_boss.step", "marlin", 0.0, &scratch);
    for f in report["features"].as_array().unwrap() {
        assert!(f.get("machining_allowance").is_none(), "{f}");
    }
}

#[test]
fn a_negative_or_huge_allowance_is_refused_naming_the_key() {
    for v in ["-1", "51", "nan"] {
        let o = Command::new(BIN)
            .args(["plan", fixture("box.step").to_str().unwrap()])
            .args(["--set", &format!("machining_allowance={v}")])
            .args(["-o", std::env::temp_dir().join("never").to_str().unwrap()])
            .output()
            .expect("runs");
        assert!(!o.status.success(), "{v} accepted");
        assert!(stderr(&o).contains("machining_allowance"), "{}", stderr(&o));
    }
}

#[test]
fn the_impeller_and_the_fan_plan_oversize_on_marlin() {
    let scratch = Scratch::new("allowance_bladed");
    for step in ["impeller.step", "fan.step"] {
        let (report, _) = plan(step, "marlin", &scratch);
        assert_left_at_least(&report, step);
        for f in report["features"].as_array().unwrap() {
            let a = allowance(f);
            // The layers cover the grown solid: they hold more than it by their stair-steps
            // only (kept outside the allowance), within the self-check's 3 %.
            let (layered, grown) = (num(&a["layered_volume_mm3"]), num(&a["grown_volume_mm3"]));
            assert!(
                layered >= grown && layered / grown - 1.0 < 0.03,
                "{step}: layers {layered} mm^3 for the grown {grown}"
            );
            // Grown by a millimetre over its area (10,971 mm^2 for the impeller): about that.
            let nominal = num(&f["volume_mm3"]);
            assert!(grown > nominal, "{step}: {grown} <= {nominal}");
        }
    }
}

#[test]
fn a_freeform_pin_stands_on_its_grown_sphere() {
    let scratch = Scratch::new("allowance_sphere");
    let (report, beads) = plan("sphere_boss.step", "delta5", &scratch);
    assert_eq!(report["slicing"], "features", "{}", report["placement"]);
    let features = report["features"].as_array().unwrap();
    let pin = features
        .iter()
        .find(|f| f["kind"] == "freeform")
        .expect("the pin is planned on curved layers");
    let a = allowance(pin);
    assert!(num(&a["max_mm"]) <= ALLOWANCE + BEAD, "{a}");
    assert!(a["layered_volume_mm3"].is_null(), "{a}");
    assert_left_at_least(&report, "sphere_boss");
    // Its beads start on the grown sphere (R = 30 about (0, 0, -8), grown to 31): the nozzle
    // at a bead's top is at least a millimetre and a layer off the nominal one, and the pin
    // (nominally 10 mm proud, to 40 mm from the centre) reaches 41.
    let id = pin["id"].as_u64().unwrap() as usize;
    let from_centre: Vec<f64> = beads
        .iter()
        .filter(|b| b.feature == id)
        .map(|b| (b.p[0].powi(2) + b.p[1].powi(2) + (b.p[2] + 8.0).powi(2)).sqrt())
        .collect();
    let nearest = from_centre.iter().copied().fold(f64::INFINITY, f64::min);
    let farthest = from_centre.iter().copied().fold(0.0f64, f64::max);
    assert!(
        nearest >= 30.0 + ALLOWANCE + 0.1,
        "the pin's beads reach down to {nearest}"
    );
    assert!(
        farthest >= 40.0 + ALLOWANCE - TOLERANCE,
        "the pin's beads reach up to {farthest}"
    );
}

#[test]
fn a_fillet_under_the_allowance_folds_and_is_filled_larger_never_less() {
    // boss_fillet: a boss on a plate with a concave fillet of radius 2 at its root. Grown by
    // 3 mm the fillet's offset folds over itself: the plan says where and fills it.
    let scratch = Scratch::new("allowance_fold");
    let (report, _, err) = plan_with("boss_fillet.step", "marlin", 3.0, &scratch);
    assert!(
        err.contains("machining allowance folds over itself") && err.contains("first near ("),
        "{err}"
    );
    let boss = &report["features"][1]["machining_allowance"];
    assert!(boss["folds"].as_u64().unwrap() > 0, "{boss}");
    assert!(num(&boss["min_mm"]) >= 3.0 - TOLERANCE, "{boss}");
    assert!(
        num(&boss["max_mm"]) > 3.0 + BEAD,
        "the fold is filled: {boss}"
    );
}

/// The data a `preview.html` draws (the JSON in its `<script id="data">`).
fn preview_data(page: &str) -> Value {
    let open = "<script id=\"data\" type=\"application/json\">";
    let json = page
        .split(open)
        .nth(1)
        .and_then(|s| s.split("</script>").next())
        .expect("the page holds its data");
    serde_json::from_str(&json.replace("<\\/", "</")).expect("JSON")
}

/// Little-endian `f32`s (or `u32`s read as such) from the page's URL-safe base64.
fn words(b64: &Value) -> Vec<u32> {
    let text = b64.as_str().expect("base64 text");
    let digit = |c: u8| -> u32 {
        match c {
            b'A'..=b'Z' => u32::from(c - b'A'),
            b'a'..=b'z' => u32::from(c - b'a') + 26,
            b'0'..=b'9' => u32::from(c - b'0') + 52,
            b'-' => 62,
            b'_' => 63,
            _ => panic!("not base64: {c}"),
        }
    };
    let mut bytes = vec![];
    for chunk in text.as_bytes().chunks(4) {
        let n = chunk
            .iter()
            .filter(|&&c| c != b'=')
            .enumerate()
            .fold(0u32, |n, (k, &c)| n | digit(c) << (18 - 6 * k));
        let kept = chunk.iter().filter(|&&c| c != b'=').count() - 1;
        bytes.extend((0..kept).map(|k| (n >> (16 - 8 * k)) as u8));
    }
    bytes
        .chunks(4)
        .map(|w| u32::from_le_bytes([w[0], w[1], w[2], w[3]]))
        .collect()
}

#[test]
fn the_preview_colours_the_nominal_surface_by_the_allowance_left() {
    let scratch = Scratch::new("allowance_preview");
    let (report, out, _) = plan_with("plate_boss_boss.step", "marlin", ALLOWANCE, &scratch);
    let page = std::fs::read_to_string(out.join("preview.html")).unwrap();
    let data = preview_data(&page);
    let features = data["features"].as_array().unwrap();
    assert_eq!(features.len(), 3);
    for (f, reported) in features.iter().zip(report["features"].as_array().unwrap()) {
        let a = &f["allowance"];
        assert_eq!(num(&a["requested"]), ALLOWANCE, "{a}");
        let pos: Vec<f32> = words(&f["positions"])
            .into_iter()
            .map(f32::from_bits)
            .collect();
        let tri = words(&f["triangles"]);
        let left: Vec<f32> = words(&a["left"]).into_iter().map(f32::from_bits).collect();
        assert_eq!(left.len() * 3, pos.len(), "one value a vertex");
        let at = |v: u32| [0, 1, 2].map(|k| f64::from(pos[3 * v as usize + k]));
        // Every value shown lies within what the report measured, which is the allowance
        // give or take a bead.
        let (lo, hi) = (
            num(&allowance(reported)["min_mm"]),
            num(&allowance(reported)["max_mm"]),
        );
        let shown: Vec<f64> = left
            .iter()
            .filter(|x| x.is_finite())
            .map(|&x| f64::from(x))
            .collect();
        assert!(
            shown.len() >= 4,
            "feature {}: {} shown",
            f["id"],
            shown.len()
        );
        for x in &shown {
            assert!(
                *x >= lo - 1e-3 && *x <= hi + 1e-3,
                "feature {}: {x} outside {lo}..{hi}",
                f["id"]
            );
            assert!(*x >= ALLOWANCE - TOLERANCE && *x <= ALLOWANCE + BEAD, "{x}");
        }
        // Triangle by triangle: the plate's face (z = 0) and the plate's top under the boss
        // (radius 12) are not the outside: nothing shown; the plate's and the bosses' sides
        // are, at every corner.
        let mut sides = 0;
        for t in tri.chunks(3) {
            let corners = [t[0], t[1], t[2]].map(at);
            let measured = [t[0], t[1], t[2]].map(|v| left[v as usize].is_finite());
            let on_plate = corners.iter().all(|p| p[2].abs() < 1e-3);
            let under_boss = f["id"] == 0
                && corners
                    .iter()
                    .all(|p| (p[2] - 6.0).abs() < 1e-3 && p[0].hypot(p[1]) < 11.5);
            if on_plate || under_boss {
                assert!(
                    measured.iter().all(|m| !m),
                    "feature {}: {corners:?} coloured",
                    f["id"]
                );
            }
            let radius = |p: &[f64; 3]| p[0].hypot(p[1]);
            let side = match f["id"].as_u64() {
                Some(0) => corners.iter().all(|p| {
                    (p[0] - corners[0][0]).abs() < 1e-3 && (p[0].abs() - 30.0).abs() < 1e-3
                }),
                Some(1) => corners.iter().all(|p| (radius(p) - 12.0).abs() < 0.1),
                _ => corners.iter().all(|p| (radius(p) - 5.0).abs() < 0.1),
            };
            if side {
                sides += 1;
                assert!(
                    measured.iter().all(|m| *m),
                    "feature {}: {corners:?} blank",
                    f["id"]
                );
            }
        }
        assert!(sides > 0, "feature {}: no side triangle", f["id"]);
    }
    // Without an allowance the page has no such colours.
    let (_, out, _) = plan_with("plate_boss_boss.step", "marlin", 0.0, &scratch);
    let page = std::fs::read_to_string(out.join("preview.html")).unwrap();
    for f in preview_data(&page)["features"].as_array().unwrap() {
        assert!(f["allowance"].is_null(), "{}", f["allowance"]);
    }
}

#[test]
fn an_allowance_under_a_rounded_bead_corner_is_warned_where_it_is_thin() {
    // 0.1 mm over plate_boss_boss: the plate's perimeters turn its corners with round beads
    // (half a bead, 0.225 mm, about the corner of their centre line), which leave
    // 0.225 - √2 (0.225 - 0.1) = 0.048 mm over the nominal corner, under 0.1 less the
    // tolerance: the plan is written and says where. The bosses' round sides keep 0.1.
    let scratch = Scratch::new("allowance_thin");
    let (report, _, err) = plan_with("plate_boss_boss.step", "marlin", 0.1, &scratch);
    let features = report["features"].as_array().unwrap();
    let plate = allowance(&features[0]);
    let corner = 0.5 * BEAD - 2f64.sqrt() * (0.5 * BEAD - 0.1);
    assert!(
        (num(&plate["min_mm"]) - corner).abs() < 0.02,
        "{plate} for {corner}"
    );
    let at = &plate["thinnest_at"];
    assert!(
        (num(&at[0]).abs() - 30.0).abs() < 1e-6 && (num(&at[1]).abs() - 20.0).abs() < 1e-6,
        "thinnest at {at}, not a corner"
    );
    assert!(
        err.contains("feature 0: its beads leave") && err.contains("under the 0.1 mm asked"),
        "{err}"
    );
    for boss in &features[1..] {
        assert!(num(&allowance(boss)["min_mm"]) >= 0.1 - TOLERANCE, "{boss}");
    }
    assert!(
        !err.contains("feature 1: its beads leave") && !err.contains("feature 2: its beads leave")
    );
}
