//! The pedestal's steps (issue 31) on a real part: the build-plate outline and its area, the
//! inset, the layers of a pedestal and their volume, and a plan standing on one.

use plan::pedestal::{layers, outline, NoPedestal, KIND};
use plan::{plan, Options, Process};
use robot_post::{MachineKind, MachineProfile, MoveKind};
use slicer::params::LayerParams;
use std::path::Path;

fn fixture(name: &str) -> brep::StepPart {
    let p = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../../fixtures")
        .join(name);
    brep::read_step(&p).unwrap_or_else(|e| panic!("{}: {e}", p.display()))
}

/// The plate of `plate_boss_boss` (a 60 × 40 mm plate), as the features see it.
fn trees() -> Vec<features::FeatureTree> {
    let part = fixture("plate_boss_boss.step");
    features::extract_all(&part.brep, &features::ExtractOptions::default())
        .expect("features")
        .trees
}

#[test]
fn the_outline_is_the_plate_face_and_the_inset_shrinks_it() {
    let trees = trees();
    let params = LayerParams::default();
    let o = outline(&trees, &params, 0.0).expect("outline");
    // The plate's bottom face: the base feature's box in XY.
    let mesh = brep::mesh::mesh_faces(
        &trees[0].brep,
        &trees[0].features[0].faces,
        &brep::mesh::MeshOptions::with_tolerance(0.01),
    )
    .expect("mesh");
    let bb = mesh.bbox();
    let rect = (bb.max.x - bb.min.x) * (bb.max.y - bb.min.y);
    assert!((o.area - rect).abs() < 1e-6 * rect, "{} vs {rect}", o.area);
    // Shrunk by 2 mm: 4 mm off each side, corners rounded (a 2 mm radius, (4 − π)·4 mm² less).
    let inset = 2.0;
    let small = outline(&trees, &params, inset).expect("inset");
    let want = (bb.max.x - bb.min.x - 2.0 * inset) * (bb.max.y - bb.min.y - 2.0 * inset)
        - (4.0 - std::f64::consts::PI) * inset * inset;
    assert!(
        (small.area - want).abs() < 0.005 * want,
        "{} vs {want}",
        small.area
    );
    // Shrunk past its half width: nothing left.
    assert_eq!(
        outline(&trees, &params, 100.0).err(),
        Some(NoPedestal::Empty(100.0))
    );
}

#[test]
fn a_pedestal_s_layers_fill_its_prism_under_the_plate() {
    let trees = trees();
    let params = LayerParams::default();
    let o = outline(&trees, &params, 0.0).expect("outline");
    let bead = MachineProfile::builtin(MachineKind::Delta5).bead();
    let (n, h) = (10, params.uniform_layer_height);
    let p = layers(&o, n, h, 7, &params, bead);
    assert_eq!(p.layers.len(), n);
    let extruded = p.figures.filament * bead.filament_area();
    let volume = o.area * n as f64 * h;
    assert!(
        ((extruded - volume) / volume).abs() < 0.03,
        "{extruded} for {volume}"
    );
    // Under the plate, from its floor up to it, every axis the plate's normal, every point
    // feature 7's.
    let plate = o.plane.origin.z;
    for q in &p.points {
        assert_eq!(q.feature, 7);
        assert_eq!(q.axis, [0.0, 0.0, 1.0]);
        if q.kind == MoveKind::Print {
            let below = plate - q.p[2];
            assert!(
                below > -1e-9 && below < (n as f64 - 1.0) * h + 1e-9,
                "{below}"
            );
        }
    }
}

#[test]
fn a_part_planned_on_a_pedestal_prints_it_first_as_a_feature_of_its_own() {
    let part = fixture("plate_boss_boss.step");
    let process = Process::from_toml("[defaults]\npedestal = 2.0\n").expect("process");
    let machine = MachineProfile::builtin(MachineKind::Delta5);
    let options = Options {
        source: "plate_boss_boss.step".into(),
        stem: "part".into(),
        ..Default::default()
    };
    let p = plan(&part, &process, &machine, &options).expect("plan");
    let fs = p.features();
    let ped = &fs[0];
    assert_eq!(ped.feature.kind, KIND);
    // The next free id after the part's features.
    assert_eq!(ped.feature.id, fs.len() - 1);
    assert_eq!(ped.pedestal_height_mm, Some(2.0));
    assert_eq!(ped.layers, 10);
    assert!(
        ((ped.extruded_volume_mm3 - ped.feature.volume_mm3) / ped.feature.volume_mm3).abs() < 0.03
    );
    assert_eq!(p.toolpath.points[0].feature as usize, ped.feature.id);
    let own = p
        .toolpath
        .points
        .iter()
        .filter(|q| q.feature as usize == ped.feature.id)
        .count();
    assert_eq!(own, ped.points);
    // Its layers lie under the part's lowest bead, 2 mm of them.
    let lowest = |id: usize| {
        p.toolpath
            .points
            .iter()
            .filter(|q| q.feature as usize == id && q.kind == MoveKind::Print)
            .map(|q| q.p[2] - f64::from(q.thickness))
            .fold(f64::INFINITY, f64::min)
    };
    let drop = lowest(0) - lowest(ped.feature.id);
    assert!((drop - 2.0).abs() < 1e-9, "{drop}");
    // The pedestal is the part's, not a feature's.
    let e = Process::from_toml("[features.0]\npedestal = 2.0\n").expect_err("refused");
    assert!(e.to_string().contains("[defaults]"), "{e}");
}
