//! Features a few beads across are filled to their volume (issue 31, item 4): the generated
//! family's small pins (`fixtures/families/pin_*.step`), whose volumes the B-rep gives.

use features::{extract_all, ExtractOptions, FeatureKind};
use slicer::fill_feature;
use slicer::params::LayerParams;
use slicer::planar::Bead;

const BEAD: Bead = Bead {
    width: 0.45,
    filament_diameter: 1.75,
};

/// What issue 31 asks of features a few beads across.
const WITHIN: f64 = 0.015;

fn family(file: &str) -> std::path::PathBuf {
    std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../../fixtures/families")
        .join(file)
}

#[test]
fn small_pins_on_a_plate_are_filled_to_their_volume() {
    // pin_2: pins 1.76, 1.92 and 3.2 mm across on a plate. Their sections were the inscribed
    // polygons of a mesh at the slicing tolerance (0.0125 mm), 1 % to 2 % short of the
    // circles (-1.87 % and -1.76 % with the last ring conserved); now meshed finer for their
    // thickness.
    let part = brep::read_step(family("pin_2.step")).expect("reads pin_2.step");
    let assembly = extract_all(&part.brep, &ExtractOptions::default()).expect("extracts");
    let params = LayerParams::default();
    let mut pins = 0;
    for t in &assembly.trees {
        for f in t.features.iter().skip(1) {
            assert_eq!(f.kind, FeatureKind::Two5d);
            let plan = fill_feature(t, f, &params, BEAD).expect("fills").lay(None);
            let extruded = plan.figures.filament * BEAD.filament_area();
            let rel = extruded / (f.volume * params.filling_ratio) - 1.0;
            assert!(
                rel.abs() <= WITHIN,
                "pin {} ({:.3} mm^3): {:+.2} %",
                f.id,
                f.volume,
                100.0 * rel
            );
            pins += 1;
        }
    }
    assert_eq!(pins, 3);
}
