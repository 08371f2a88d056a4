//! The solid check (`features::check_solid`): it passes every feature extracted from the seam
//! reproduction, and it finds each kind of broken shell made from a good one.

use brep::solid::analysis_options;
use brep::topology::{Brep, SolidId};
use features::{check_solid, extract, ExtractOptions, SolidProblem};
use std::path::PathBuf;

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../..")
}

fn tree(file: &str) -> features::FeatureTree {
    let part = brep::read_step(root().join(file)).expect("reads");
    extract(&part.brep, SolidId(0), &ExtractOptions::default()).expect("extracts")
}

fn opts(b: &Brep) -> brep::mesh::MeshOptions {
    analysis_options(brep::solid::rough_bbox(b, SolidId(0)).diagonal())
}

#[test]
fn a_boss_whose_root_crosses_the_hub_seam_splits_into_two_valid_solids() {
    // The reproduction: the boss's root crosses the seam of the hub's cylinder (+X).
    let t = tree("fixtures/families/hub_boss_0.step");
    assert_eq!(t.features.len(), 2);
    let o = opts(&t.brep);
    for f in &t.features {
        let c = check_solid(&t.brep, &f.faces, &f.voids, &o);
        assert!(c.is_valid(), "feature {}: {:?}", f.id, c.problems);
        assert!(
            (c.volume - f.volume).abs() < 1e-3 * f.volume,
            "{} vs {}",
            c.volume,
            f.volume
        );
    }
    // The hub's side face carries the cylinder across the root: it is one face again, with
    // its seam re-made as one edge.
    // The hub is the whole cylinder (within the reader's 0.1 %).
    let hub = &t.features[0];
    let cylinder = std::f64::consts::PI * 144.0 * 16.0;
    assert!(
        (hub.volume - cylinder).abs() < 1e-3 * cylinder,
        "{}",
        hub.volume
    );
    assert_eq!(t.features[1].kind, features::FeatureKind::Freeform);
    assert!(t
        .roots
        .iter()
        .all(|r| r.outcome == features::RootOutcome::Split(1)));
}

#[test]
fn a_shell_missing_a_face_is_open() {
    let t = tree("fixtures/plate_boss_boss.step");
    let f = &t.features[1];
    let c = check_solid(&t.brep, &f.faces[1..], &[], &opts(&t.brep));
    assert!(c
        .problems
        .iter()
        .any(|p| matches!(p, SolidProblem::EdgeUse { .. })));
    assert!(c
        .problems
        .iter()
        .any(|p| matches!(p, SolidProblem::NotWatertight { open, .. } if *open > 0)));
}

#[test]
fn a_loop_with_an_edge_taken_out_is_not_connected() {
    let t = tree("fixtures/plate_boss_boss.step");
    let f = &t.features[1];
    let mut b = t.brep.clone();
    let face = f.faces[0];
    let l = b.face(face).loops[0];
    let n = b.loops[l.idx()].coedges.len();
    assert!(n > 1);
    b.loops[l.idx()].coedges.remove(n / 2);
    let c = check_solid(&b, &f.faces, &[], &opts(&b));
    assert!(
        c.problems
            .iter()
            .any(|p| matches!(p, SolidProblem::LoopOpen { .. })),
        "{:?}",
        c.problems
    );
}

#[test]
fn a_shell_turned_inside_out_has_a_negative_volume() {
    let t = tree("fixtures/plate_boss_boss.step");
    let f = &t.features[0];
    let mut b = t.brep.clone();
    for &face in &f.faces {
        b.faces[face.idx()].same_sense = !b.faces[face.idx()].same_sense;
        for l in b.faces[face.idx()].loops.clone() {
            let cs = b.loops[l.idx()].coedges.clone();
            for c in &cs {
                b.coedges[c.idx()].forward = !b.coedges[c.idx()].forward;
            }
            b.loops[l.idx()].coedges = cs.into_iter().rev().collect();
        }
    }
    let c = check_solid(&b, &f.faces, &[], &opts(&b));
    assert!(c.volume < 0.0, "{}", c.volume);
    assert_eq!(
        c.problems,
        vec![SolidProblem::Volume { volume: c.volume }],
        "only the volume is wrong: the topology is consistent"
    );
}
