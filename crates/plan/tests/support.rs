//! Support material (issue 33, item 3) on the Marlin profile: a slab bridging two posts and a
//! wall leaning out 60° get support exactly under what overhangs (beads under the overhang,
//! clear of the part's section by the XY gap), a box none; the part's own volume still passes
//! the self-check; `support_material = "off"` refuses them as before.

use plan::{plan, Gate, Options, PlanError, Process};
use robot_post::{MachineKind, MachineProfile, MoveKind};
use slicer::toolpath::PathPoint;
use std::path::Path;

fn fixture(name: &str) -> brep::StepPart {
    let p = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../../fixtures")
        .join(name);
    brep::read_step(&p).unwrap_or_else(|e| panic!("{}: {e}", p.display()))
}

fn options(name: &str) -> Options<'_> {
    Options {
        source: name.into(),
        stem: "part".into(),
        ..Default::default()
    }
}

fn planned(name: &str, process: &Process) -> Result<plan::Plan, PlanError> {
    plan(
        &fixture(name),
        process,
        &MachineProfile::builtin(MachineKind::Marlin),
        &options(name),
    )
}

/// XY gap (the default `support_xy_distance`) and how much closer a bead's centre line may
/// come (the section's chords and the offsets' arcs: well under a tenth of a mm).
const XY_GAP: f64 = 0.5;
const SLACK: f64 = 0.05;

/// Support print points (position), and the part's print points, of a plan (the skirt
/// around the first layer is neither).
fn split(p: &plan::Plan) -> (Vec<[f64; 3]>, Vec<[f64; 3]>) {
    let prints = p
        .toolpath
        .points
        .iter()
        .filter(|q| q.kind == MoveKind::Print && (q.role.is_support() || q.role.is_part()));
    let (s, part): (Vec<&PathPoint>, Vec<&PathPoint>) = prints.partition(|q| q.role.is_support());
    (
        s.iter().map(|q| q.p).collect(),
        part.iter().map(|q| q.p).collect(),
    )
}

/// The lowest corner of the part's beads (the part's frame on the plate: its points' x, y and
/// z less these are the model's, less a layer's top for z).
/// The lowest bead bottom (its point less its thickness) of `points`.
fn lowest_bottom<'a>(points: impl Iterator<Item = &'a PathPoint>) -> f64 {
    points
        .map(|q| q.p[2] - f64::from(q.thickness))
        .fold(f64::INFINITY, f64::min)
}

fn low(points: &[[f64; 3]]) -> [f64; 3] {
    let mut lo = [f64::INFINITY; 3];
    for p in points {
        for k in 0..3 {
            lo[k] = lo[k].min(p[k]);
        }
    }
    lo
}

/// The self-check passed for the part's volume alone, and support was reported apart.
fn part_volume_passes(p: &plan::Plan) -> f64 {
    assert!(p.report.complete);
    let mut support = 0.0;
    for f in p.features() {
        let rel = (f.extruded_volume_mm3 - f.feature.volume_mm3) / f.feature.volume_mm3;
        assert!(rel.abs() <= 0.03, "feature {}: {rel}", f.feature.id);
        assert_eq!(f.unsupported_area_mm2, 0.0);
        support += f.support_volume_mm3;
    }
    support
}

#[test]
fn a_bridge_gets_support_between_its_posts_only() {
    let p = planned("bridge.step", &Process::default()).expect("plans with support");
    let support = part_volume_passes(&p);
    let (s, part) = split(&p);
    assert!(!s.is_empty());
    // The model: posts x −25..−15 and 15..25, y −10..10, z 0..20; slab z 20..25. Beads are
    // laid at their layer's top; the part's lowest bead marks x −25 (less half a bead), y −10.
    let lo = low(&part);
    let width = MachineProfile::builtin(MachineKind::Marlin).bead().width;
    let (x0, y0) = (lo[0] - 0.5 * width - (-25.0), lo[1] - 0.5 * width - (-10.0));
    let z0 = lo[2] - 0.2;
    for q in &s {
        let (x, y, z) = (q[0] - x0, q[1] - y0, q[2] - z0);
        // Between the posts, clear of them by the XY gap, under the slab less the contact gap.
        assert!(x.abs() <= 15.0 - XY_GAP + SLACK, "{q:?}: x {x}");
        assert!(y.abs() <= 10.0 + SLACK, "{q:?}: y {y}");
        assert!(z <= 20.0 - 0.2 + SLACK && z > 0.0, "{q:?}: z {z}");
    }
    // Some of it down at the plate, and at the top under the slab.
    assert!(s.iter().any(|q| q[2] - z0 < 0.2 + SLACK));
    assert!(s.iter().any(|q| q[2] - z0 > 19.8 - SLACK - 0.2));
    // Sparse: more than nothing, less than the column under the slab (30 × 20 × 20).
    assert!(
        support > 0.0 && support < 0.5 * 30.0 * 20.0 * 20.0,
        "{support}"
    );
    // The program names it.
    let gcode = p
        .program
        .iter()
        .find(|f| f.name == "program.gcode")
        .expect("program");
    let text = String::from_utf8_lossy(&gcode.bytes);
    assert!(text.contains(";TYPE:Support material\n"));
    assert!(text.contains(";TYPE:Support material interface\n"));
}

#[test]
fn a_60_degree_overhang_gets_support_under_it_and_a_box_none() {
    let p = planned("overhang_60.step", &Process::default()).expect("plans with support");
    let support = part_volume_passes(&p);
    let (s, part) = split(&p);
    assert!(!s.is_empty());
    let width = MachineProfile::builtin(MachineKind::Marlin).bead().width;
    let lo = low(&part);
    let (x0, y0, z0) = (lo[0] - 0.5 * width, lo[1] - 0.5 * width, lo[2] - 0.2);
    let t = 60f64.to_radians().tan();
    for q in &s {
        let (x, y, z) = (q[0] - x0, q[1] - y0, q[2] - z0);
        // Outside the part's section at the bead's layer (x up to 20 + z·tan 60) grown by the
        // XY gap, under the overhang's top reach, inside the part's width along y.
        assert!(
            x >= 20.0 + (z - 0.2) * t + XY_GAP - SLACK,
            "{q:?}: x {x}, z {z}"
        );
        assert!(x <= 20.0 + 10.0 * t + SLACK, "{q:?}: x {x}");
        assert!((-SLACK..=20.0 + SLACK).contains(&y), "{q:?}: y {y}");
    }
    // Less than the wedge of air under the overhang (½ · 10 · 10 tan 60 · 20).
    let wedge = 0.5 * 10.0 * 10.0 * t * 20.0;
    assert!(support > 0.0 && support < wedge, "{support} vs {wedge}");

    let p = planned("box.step", &Process::default()).expect("a box plans");
    assert_eq!(part_volume_passes(&p), 0.0);
    assert!(split(&p).0.is_empty());
}

#[test]
fn with_support_off_the_bridge_is_refused_as_before() {
    let off = Process::from_toml("[defaults]\nsupport_material = \"off\"\n").expect("process");
    match planned("bridge.step", &off) {
        Err(PlanError::Refused {
            gate: Gate::Unsupported(lines),
            ..
        }) => assert!(lines.iter().any(|l| l.starts_with("feature 0 "))),
        Err(e) => panic!("refused otherwise: {e}"),
        Ok(_) => panic!("planned without support"),
    }
}

/// `stacked_solids.step` (issue 31 item 1): a box A 0..30 × 0..30 × 0..10, a cylinder B of
/// radius 5 round (15, 15) from z 5 to 25 sunk into it, a box C 0..10 × 0..10 × 10..15 on A, and
/// a box D 40..50 × 0..10 × 20..25 over nothing. D's columns go on below its first layer down
/// to the plate, clear of the other solids; its first layer is held. (The solids overlap, so
/// the head collides where B is printed inside A: collisions are allowed here.)
#[test]
fn a_box_over_nothing_gets_support_from_the_plate_to_its_first_layer() {
    let opts = Options {
        allow_collisions: true,
        ..options("stacked_solids.step")
    };
    // Feature by feature, each solid a tree of its own (`slicing = "auto"` plans these
    // overlapping solids whole, the box held up by support in the one feature's layers).
    let process = Process::from_toml("[defaults]\nslicing = \"features\"\n").expect("process");
    let p = plan(
        &fixture("stacked_solids.step"),
        &process,
        &MachineProfile::builtin(MachineKind::Marlin),
        &opts,
    )
    .expect("plans with support under the lifted box");
    let d = p.features().iter().find(|f| f.feature.id == 3).expect("D");
    assert_eq!(d.unsupported_area_mm2, 0.0);
    // The self-check counts D's part alone.
    let rel = (d.extruded_volume_mm3 - d.feature.volume_mm3) / d.feature.volume_mm3;
    assert!(rel.abs() <= 0.03, "{rel}");
    let prints: Vec<&PathPoint> = p
        .toolpath
        .points
        .iter()
        .filter(|q| q.kind == MoveKind::Print)
        .collect();
    let part: Vec<&PathPoint> = prints
        .iter()
        .copied()
        .filter(|q| q.role.is_part())
        .collect();
    let support: Vec<&PathPoint> = prints
        .iter()
        .copied()
        .filter(|q| q.role.is_support())
        .collect();
    assert!(
        support.iter().all(|q| q.feature == 3),
        "support under D only"
    );
    // The frame: A's corner at the lowest part bead (less half a bead), the plate under the
    // lowest bead's bottom.
    let width = MachineProfile::builtin(MachineKind::Marlin).bead().width;
    let pts: Vec<[f64; 3]> = part.iter().map(|q| q.p).collect();
    let lo = low(&pts);
    let (x0, y0) = (lo[0] - 0.5 * width, lo[1] - 0.5 * width);
    let plate = lowest_bottom(part.iter().copied());
    // D's first layer's bottom: 20 mm over the plate.
    let d_bottom = lowest_bottom(part.iter().copied().filter(|q| q.feature == 3));
    assert!(
        (d_bottom - plate - 20.0).abs() < SLACK,
        "{}",
        d_bottom - plate
    );
    // From the plate to the contact gap under D's first layer, in every layer between.
    let bottom = lowest_bottom(support.iter().copied());
    let top = support
        .iter()
        .map(|q| q.p[2])
        .fold(f64::NEG_INFINITY, f64::max);
    let contact = slicer::params::LayerParams::default().support_contact_distance;
    assert!((bottom - plate).abs() < SLACK, "{}", bottom - plate);
    assert!(
        (top - (d_bottom - contact)).abs() < SLACK,
        "{top} vs {d_bottom}"
    );
    let mut layers: Vec<i64> = support
        .iter()
        .map(|q| ((q.p[2] - plate) / f64::from(q.thickness)).round() as i64)
        .collect();
    layers.sort();
    layers.dedup();
    assert_eq!(
        layers.len() as i64,
        layers[layers.len() - 1] - layers[0] + 1
    );
    // Under D, and clear of A, B and C by the XY gap wherever it is at their heights.
    for q in &support {
        let (x, y, z) = (q.p[0] - x0, q.p[1] - y0, q.p[2] - plate);
        assert!((40.0 - SLACK..=50.0 + SLACK).contains(&x), "{q:?}");
        assert!((-SLACK..=10.0 + SLACK).contains(&y), "{q:?}");
        let clear = XY_GAP - SLACK;
        let outside_box = |x0: f64, y0: f64, x1: f64, y1: f64| {
            x < x0 - clear || x > x1 + clear || y < y0 - clear || y > y1 + clear
        };
        assert!(z > 10.0 || outside_box(0.0, 0.0, 30.0, 30.0), "in A: {q:?}");
        assert!(!(10.0..=15.0).contains(&z) || outside_box(0.0, 0.0, 10.0, 10.0));
        let r = ((x - 15.0).powi(2) + (y - 15.0).powi(2)).sqrt();
        assert!(!(5.0..=25.0).contains(&z) || r > 5.0 + clear, "in B: {q:?}");
    }
    // Sparse: more than nothing, less than the column under D (10 × 10 × 20).
    assert!(d.support_volume_mm3 > 0.0 && d.support_volume_mm3 < 0.5 * 10.0 * 10.0 * 20.0);
}
