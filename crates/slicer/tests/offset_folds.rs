//! Offset deterioration of freeform features (feature-based AM paper, Fig. 9): a rib standing in
//! a trough of radius 4 mm (fixtures/trough_rib.step) rises 9 mm above the trough bottom, so the
//! offsets of the trough's cylinder face fold over themselves from 4 mm on, and the planner
//! refuses the rib on offset layers, naming it and the first layer that would fold.

mod support;

use features::FeatureKind;
use slicer::freeform::plan_freeform;
use slicer::params::{LayerParams, LayerStrategy};
use slicer::planar::{Bead, FeatureError};
use support::tree;

const BEAD: Bead = Bead {
    width: 0.45,
    filament_diameter: 1.75,
};

/// Radius of the trough (fixtures/make_fixtures.py, `make_trough_rib`), mm.
const TROUGH_RADIUS: f64 = 4.0;

#[test]
fn a_rib_taller_than_its_trough_radius_is_refused_at_the_first_folding_layer() {
    let t = tree("trough_rib");
    let ribs: Vec<_> = t
        .features
        .iter()
        .filter(|f| f.kind == FeatureKind::Freeform)
        .collect();
    assert_eq!(ribs.len(), 1, "one freeform feature, the rib");
    let rib = ribs[0];
    let rf = rib.reference.face.expect("the rib has a reference face");
    assert!(
        matches!(
            t.brep.face_surface(rf),
            brep::surface::Surface::Cylinder { .. }
        ),
        "the rib's reference is the trough's cylinder face"
    );
    // Offset layers asked for: along the trough's normals, which fold (the default carries
    // the rib over the valley by transition layers: tests/transition.rs).
    let params = LayerParams {
        layer_strategy: LayerStrategy::Offset,
        ..LayerParams::default()
    };
    let h = params.uniform_layer_height;
    let Err(e) = plan_freeform(&t, rib, &params, BEAD, None) else {
        panic!("the rib is refused");
    };
    let msg = e.to_string();
    let FeatureError::OffsetFolds {
        id,
        layer,
        offset,
        radius,
    } = e
    else {
        panic!("expected OffsetFolds, got {e:?}: {msg}");
    };
    assert_eq!(id, rib.id, "{msg}");
    assert!(
        (radius - TROUGH_RADIUS).abs() <= 0.02 * TROUGH_RADIUS,
        "radius {radius} is not the trough's {TROUGH_RADIUS}: {msg}"
    );
    assert!(offset >= radius, "{msg}");
    // The first layer whose top reaches the radius: uniform layers of thickness offset/layer,
    // at most h thick, and the layer below still under the radius.
    assert!(layer >= 1, "{msg}");
    let dl = offset / layer as f64;
    assert!(dl > 0.0 && dl <= h + 1e-9, "layers {dl} mm thick: {msg}");
    assert!(offset - dl < radius && radius <= offset, "{msg}");
    assert!(offset - h < radius, "{msg}");
    assert!(!msg.contains('\n'), "one line: {msg}");
    assert!(msg.contains(&format!("feature {id}")), "{msg}");
    assert!(msg.contains(&format!("layer {layer}")), "{msg}");
}

#[test]
fn a_boss_on_a_convex_reference_is_not_refused() {
    let t = tree("capsule");
    assert!(plan_freeform(&t, &t.features[2], &LayerParams::default(), BEAD, None).is_ok());
}
