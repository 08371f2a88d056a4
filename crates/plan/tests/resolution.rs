//! Features below the nozzle's resolution (issue 31, item 4): a contact thinner than the
//! narrowest bead the machine lays is named with its width and the nozzle it needs, printed,
//! and judged by the self-check within the share of it that narrow; a feature of ordinary
//! width keeps the plan's 3 %, and a feature with no layer fails whatever its width.

use plan::{plan, Options, Process};
use robot_post::{MachineKind, MachineProfile};
use slicer::verify::{check_planned, PlanProblem, PlannedFeature, VOLUME_TOLERANCE};
use std::path::Path;

/// Narrowest bead of the test machine, mm: wider than the contact of `thin_wall_2`
/// (0.2967 mm thick), narrower than its walls (1.1 mm and more).
const MIN_BEAD: f64 = 0.4;

#[test]
fn a_contact_thinner_than_the_narrowest_bead_plans_and_is_named() {
    let p = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../fixtures/families/thin_wall_2.step");
    let part = brep::read_step(&p).unwrap_or_else(|e| panic!("{}: {e}", p.display()));
    let machine = MachineProfile {
        min_bead_width: Some(MIN_BEAD),
        ..MachineProfile::builtin(MachineKind::Marlin)
    };
    let options = Options {
        source: "thin_wall_2.step".into(),
        stem: "part".into(),
        allow_collisions: true,
        ..Default::default()
    };
    // Not kept going: the self-check passes.
    let planned = plan(&part, &Process::default(), &machine, &options)
        .unwrap_or_else(|e| panic!("thin_wall_2: {e}"));
    assert!(planned.report.complete);
    let below: Vec<_> = planned
        .features()
        .iter()
        .filter_map(|f| Some((f, f.below_resolution?)))
        .collect();
    assert_eq!(below.len(), 1, "one contact below resolution");
    let (f, b) = below[0];
    assert!((b.narrowest_mm - 0.2967).abs() < 0.01, "{b:?}");
    let nozzle = machine.nozzle_diameter * b.narrowest_mm / MIN_BEAD;
    assert!((b.nozzle_needed_mm - nozzle).abs() < 0.002, "{b:?}");
    assert!(b.nozzle_needed_mm < machine.nozzle_diameter);
    // Tolerance: 3 % plus the share of it narrower than the bead (all of a straight contact).
    assert!(b.narrow_share > 0.9, "{b:?}");
    assert!((b.tolerance_pct - 100.0 * (VOLUME_TOLERANCE + b.narrow_share)).abs() < 0.01);
    assert!(f.layers > 0 && f.extruded_volume_mm3 > 0.0);
    // Printed as well as the beads allow: its narrow beads laid min_bead_width wide.
    assert!(f.widened_volume_mm3 > 0.0);
    assert!(f
        .warnings
        .iter()
        .any(|w| w.contains("below the nozzle's resolution")));
    // The plate and the walls are of ordinary width: within the plan's 3 %.
    for g in planned
        .features()
        .iter()
        .filter(|g| g.below_resolution.is_none())
    {
        let rel = g.extruded_volume_mm3 / g.feature.volume_mm3 - 1.0;
        assert!(
            rel.abs() <= VOLUME_TOLERANCE,
            "feature {}: {rel}",
            g.feature.id
        );
    }
}

#[test]
fn a_lost_feature_fails_below_resolution_or_not() {
    let tolerance = plan::resolution::tolerance(0.6);
    let f = |layers: usize, extruded: f64, tolerance: f64| PlannedFeature {
        id: 4,
        kind: "two5d".into(),
        volume: 1.0,
        fill: 1.0,
        layers,
        extruded,
        tolerance,
        smallest_bead: 0.0,
        sparse: 0.0,
        density: 1.0,
    };
    // No layer: a lost feature, whatever its tolerance.
    assert!(matches!(
        check_planned(&f(0, 0.0, tolerance)),
        Some(PlanProblem::NoLayers { .. })
    ));
    // Below resolution, 60 % of it narrow: 50 % short passes, 70 % short fails.
    assert!(check_planned(&f(3, 0.5, tolerance)).is_none());
    assert!(check_planned(&f(3, 0.3, tolerance)).is_some());
    // Of ordinary width: 3.5 % short fails.
    assert!(check_planned(&f(3, 0.965, VOLUME_TOLERANCE)).is_some());
}
