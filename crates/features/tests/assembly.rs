//! Files of several solids (`features::extract_all`): built lowest first, overlapping solids and
//! solids floating above the build plate reported, solids enclosing nothing skipped.

use features::{extract_all, solid_name, ExtractOptions};
use serde_json::Value;
use std::f64::consts::PI;
use std::path::PathBuf;

fn fixture(name: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("../../fixtures")
        .join(name)
}

fn lowest_z(t: &features::FeatureTree) -> f64 {
    t.mesh.bbox().min.z
}

/// `stacked_solids`: written highest first; a base box on the plate, a cylinder sunk 5 mm into
/// it, a box resting on its top face and a box floating 20 mm up.
#[test]
fn stacked_solids_are_built_lowest_first_and_their_overlap_and_gap_reported() {
    let part = brep::read_step(fixture("stacked_solids.step")).expect("reads");
    let reference: Value = serde_json::from_str(
        &std::fs::read_to_string(fixture("stacked_solids.json")).expect("json"),
    )
    .expect("parses");
    let a = extract_all(&part.brep, &ExtractOptions::default()).expect("extracts");
    assert_eq!(a.trees.len(), 4);

    // Lowest first: each solid starts no lower than the one before it.
    let lows: Vec<f64> = a.trees.iter().map(lowest_z).collect();
    assert!(
        lows.windows(2).all(|w| w[0] <= w[1]),
        "solids in build order start at {lows:?}"
    );
    // The file lists them highest first, so the order is the file's reversed.
    let file_order: Vec<u64> = part.brep.solids.iter().map(|s| s.step_id).rev().collect();
    let built: Vec<u64> = a
        .trees
        .iter()
        .map(|t| t.brep.solids[t.solid.idx()].step_id)
        .collect();
    assert_eq!(built, file_order);

    // One overlap: the base and the sunk cylinder, by OpenCASCADE's common volume within 5 %.
    let pairs = reference["overlaps_mm3"].as_array().expect("overlaps");
    assert_eq!(pairs.len(), 1);
    let want = pairs[0][2].as_f64().expect("volume");
    let overlaps: Vec<&String> = a
        .warnings
        .iter()
        .filter(|w| w.contains("overlap"))
        .collect();
    assert_eq!(overlaps.len(), 1, "{:?}", a.warnings);
    let (base, cylinder) = (solid_name(&a.trees[0]), solid_name(&a.trees[1]));
    assert!(
        overlaps[0].starts_with(&format!("{base} and {cylinder} overlap by about ")),
        "{}",
        overlaps[0]
    );
    let got: f64 = overlaps[0]
        .split("about ")
        .nth(1)
        .and_then(|s| s.split(' ').next())
        .and_then(|s| s.parse().ok())
        .expect("a volume");
    assert!(
        (got - want).abs() < 0.05 * want,
        "overlap {got} mm^3 against {want}"
    );

    // Only the floating box is in the air, by the gap under it.
    let floating: Vec<&String> = a.warnings.iter().filter(|w| w.contains("air")).collect();
    assert_eq!(floating.len(), 1, "{:?}", a.warnings);
    let top = solid_name(&a.trees[3]);
    let lift = lows[3] - lows[0];
    assert!((lift - 20.0).abs() < 1e-6, "floating box starts {lift} up");
    assert_eq!(
        floating[0],
        &format!(
            "{top} starts {lift:.3} mm above the build plate and rests on no other solid: its \
             first layer would be laid in the air"
        )
    );
    assert_eq!(a.warnings.len(), 2, "{:?}", a.warnings);
}

/// Two boxes side by side on the plate: nothing to report about them together.
#[test]
fn solids_side_by_side_on_the_plate_raise_no_warning() {
    let part = brep::read_step(fixture("two_solids.step")).expect("reads");
    let a = extract_all(&part.brep, &ExtractOptions::default()).expect("extracts");
    assert_eq!(a.trees.len(), 2);
    assert!(a.warnings.is_empty(), "{:?}", a.warnings);
}

/// One solid: its own warnings, without its name.
#[test]
fn a_single_solid_keeps_its_warnings_unprefixed() {
    let part = brep::read_step(fixture("void_box.step")).expect("reads");
    let a = extract_all(&part.brep, &ExtractOptions::default()).expect("extracts");
    assert_eq!(a.trees.len(), 1);
    assert!(a.warnings.is_empty());
    assert_eq!(a.all_warnings(), a.trees[0].warnings);
    assert!(!a.all_warnings().is_empty(), "the void shell is reported");
}

/// Shapr3D writes the impeller's hub and ten blades as separate solids, each blade sunk into
/// the hub, plus a sliver that encloses nothing (`../shared/corpus/MANIFEST.md`). Skipped when
/// the corpus is not beside the repository.
#[test]
fn shapr3d_impeller_bodies_skip_the_sliver_and_report_each_blade_in_the_hub() {
    let path = PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("../../../shared/corpus/shapr3d_impeller.step");
    if !path.exists() {
        eprintln!("skipped: {} is missing", path.display());
        return;
    }
    let part = brep::read_step(&path).expect("reads");
    let a = extract_all(&part.brep, &ExtractOptions::default()).expect("extracts");
    assert_eq!(a.trees.len(), part.brep.solids.len() - 1);
    let skipped: Vec<&String> = a
        .warnings
        .iter()
        .filter(|w| w.contains("skipped"))
        .collect();
    assert_eq!(skipped.len(), 1, "{:?}", a.warnings);
    // The hub is the largest solid and the lowest: built first.
    let hub = a
        .trees
        .iter()
        .enumerate()
        .max_by(|x, y| x.1.part_volume.total_cmp(&y.1.part_volume))
        .map(|(k, _)| k);
    assert_eq!(hub, Some(0));
    let hub = solid_name(&a.trees[0]);
    let overlaps = a.warnings.iter().filter(|w| w.contains("overlap")).count();
    assert_eq!(overlaps, a.trees.len() - 1, "{:?}", a.warnings);
    assert!(a
        .warnings
        .iter()
        .filter(|w| w.contains("overlap"))
        .all(|w| w.starts_with(&format!("{hub} and "))));
    // Each blade stands in the hub, so none is in the air.
    assert!(
        !a.warnings.iter().any(|w| w.contains("air")),
        "{:?}",
        a.warnings
    );
}

/// Planned whole (`slicing = "planar"`), the solids are one feature sliced in the same layers;
/// the material overlapping ones share is counted once, the overlap reported.
#[test]
fn whole_part_slices_solids_together_and_counts_their_overlap_once() {
    let two = brep::read_step(fixture("two_solids.step")).expect("reads");
    let a = features::whole_part_features(&two.brep).expect("whole part");
    assert_eq!(a.trees.len(), 1);
    let t = &a.trees[0];
    assert_eq!(t.features.len(), 1);
    let f = &t.features[0];
    assert!(f.closed);
    // Two boxes of 4000 and 3000 mm^3, 12 faces in all.
    assert!((f.volume - 7000.0).abs() < 7.0, "{}", f.volume);
    assert_eq!(f.faces.len(), 12);
    let b = t.mesh.bbox();
    assert!(b.min.x.abs() < 1e-6 && (b.max.x - 50.0).abs() < 1e-6 && (b.max.z - 30.0).abs() < 1e-6);

    // Overlapping solids too: the cylinder sunk 5 mm into the base box (r 5 mm) shares
    // 25π·5 = 392.7 mm^3 with it, which the one feature counts once.
    let stacked = brep::read_step(fixture("stacked_solids.step")).expect("reads");
    let a = features::whole_part_features(&stacked.brep).expect("whole part");
    assert_eq!(a.trees.len(), 1);
    let f = &a.trees[0].features[0];
    assert_eq!(a.trees[0].features.len(), 1);
    let sum = 9000.0 + 500.0 + 500.0 + 25.0 * PI * 20.0;
    let shared = 25.0 * PI * 5.0;
    assert!(
        (f.volume - (sum - shared)).abs() < 0.05 * shared,
        "{} for {}",
        f.volume,
        sum - shared
    );
    assert!(
        a.warnings
            .iter()
            .any(|w| w.contains("overlap") && w.contains("laid once")),
        "{:?}",
        a.warnings
    );
}
