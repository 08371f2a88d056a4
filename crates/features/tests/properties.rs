//! Properties every extraction must have, on every fixture and every file of both shared corpora
//! (the second set's files that still fail are listed with why): the features'
//! volumes add up to the part's (measured independently), each feature is a closed, non-empty
//! solid that re-reads from its exported STEP as the same closed solid, and the dependency order
//! puts parents first.

use brep::topology::SolidId;
use features::{extract, ExtractOptions, FeatureKind};
use std::path::{Path, PathBuf};

fn steps_in(dir: &Path) -> Vec<PathBuf> {
    let mut v: Vec<PathBuf> = std::fs::read_dir(dir)
        .map(|d| {
            d.filter_map(|e| e.ok())
                .map(|e| e.path())
                .filter(|p| p.extension().is_some_and(|x| x == "step"))
                .collect()
        })
        .unwrap_or_default();
    v.sort();
    v
}

fn check_file(path: &Path, failures: &mut Vec<String>) {
    let name = path
        .file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .unwrap_or_default();
    let part = brep::read_step(path).expect("readable");
    for s in part.brep.solid_ids() {
        let part_volume = match brep::solid::report_solid(&part.brep, s) {
            Ok(r) => r.volume,
            Err(e) => {
                failures.push(format!("{name} solid {}: {e}", s.0));
                continue;
            }
        };
        let tree = match extract(&part.brep, s, &ExtractOptions::default()) {
            Ok(t) => t,
            Err(e) => {
                failures.push(format!("{name} solid {}: {e}", s.0));
                continue;
            }
        };
        let check_opts = brep::solid::analysis_options(
            brep::solid::rough_bbox(&tree.brep, tree.solid).diagonal(),
        );
        let sum: f64 = tree.features.iter().map(|f| f.volume).sum();
        if (sum - part_volume).abs() > 5e-3 * part_volume.abs().max(1e-9) {
            failures.push(format!(
                "{name} solid {}: features add up to {sum:.3}, part {part_volume:.3}",
                s.0
            ));
        }
        // Build order: a permutation with parents first; depth is the longest parent chain.
        let mut pos = vec![usize::MAX; tree.features.len()];
        for (k, &f) in tree.build_order.iter().enumerate() {
            pos[f] = k;
        }
        if pos.contains(&usize::MAX) || tree.build_order.len() != tree.features.len() {
            failures.push(format!(
                "{name}: build order {:?} is not a permutation",
                tree.build_order
            ));
        }
        for f in &tree.features {
            for &p in &f.parents {
                if pos[p] >= pos[f.id] {
                    failures.push(format!(
                        "{name}: feature {} is built before its parent {p}",
                        f.id
                    ));
                }
                if f.depth <= tree.features[p].depth {
                    failures.push(format!(
                        "{name}: feature {} depth {} not below parent {p}",
                        f.id, f.depth
                    ));
                }
            }
            if !f.closed || f.faces.is_empty() || f.volume <= 0.0 {
                failures.push(format!(
                    "{name}: feature {} closed={} faces={} volume={}",
                    f.id,
                    f.closed,
                    f.faces.len(),
                    f.volume
                ));
            }
            // The library's solid check, called as a user of the crate would.
            let c = features::check_solid(&tree.brep, &f.faces, &f.voids, &check_opts);
            if !c.is_valid() {
                failures.push(format!(
                    "{name}: feature {} fails the solid check: {:?}",
                    f.id, c.problems
                ));
            }
            if let Some(n) = f.reference.normal {
                let len = (n[0] * n[0] + n[1] * n[1] + n[2] * n[2]).sqrt();
                if (len - 1.0).abs() > 1e-9 {
                    failures.push(format!(
                        "{name}: feature {} reference normal not unit",
                        f.id
                    ));
                }
            }
            if (f.kind == FeatureKind::Two5d)
                != (f.reference.surface == "plane" || f.reference.surface == "build_plate")
            {
                failures.push(format!(
                    "{name}: feature {} kind {:?} on {}",
                    f.id, f.kind, f.reference.surface
                ));
            }
            // The exported solid re-reads as the same closed solid.
            let text = brep::write::write_step_shells(
                &tree.brep,
                &[(f.faces.clone(), f.voids.clone())],
                "feature",
            );
            match brep::read_step_bytes(text.as_bytes()) {
                Ok(back) if back.brep.solids.len() == 1 => {
                    let r = match brep::solid::report_solid(&back.brep, SolidId(0)) {
                        Ok(r) => r,
                        Err(e) => {
                            failures.push(format!(
                                "{name}: exported feature {} does not mesh: {e}",
                                f.id
                            ));
                            continue;
                        }
                    };
                    if !r.closed || !r.watertight || (r.volume - f.volume).abs() > 5e-3 * f.volume {
                        failures.push(format!(
                            "{name}: exported feature {} closed={} watertight={} volume {:.6} vs {:.6}",
                            f.id, r.closed, r.watertight, r.volume, f.volume
                        ));
                    }
                }
                Ok(back) => failures.push(format!(
                    "{name}: exported feature {} has {} solids",
                    f.id,
                    back.brep.solids.len()
                )),
                Err(e) => failures.push(format!(
                    "{name}: exported feature {} does not read: {e}",
                    f.id
                )),
            }
        }
    }
}

#[test]
fn every_fixture_extracts_into_closed_features_that_add_up() {
    let dir = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../fixtures");
    let mut failures = vec![];
    for p in steps_in(&dir) {
        check_file(&p, &mut failures);
    }
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}

/// Files of `../shared/corpus-more` whose extraction still fails a property, with what fails
/// (measured 2026-11-25). A listed file that comes right fails the test until it is taken off.
const KNOWN_FAILING: [(&str, &str); 3] = [
    (
        "onshape_abc_0_13.step",
        "the part's mesh is not watertight (18 open edges where B-spline trims cross in (u, v); brep tests/corpus.rs)",
    ),
    (
        "psstep13_inductor.step",
        "exported feature 1's face #63 does not mesh (a loop wraps round its surface, nothing closes it); feature 2 (0.001064 mm^3) re-reads as 0.000737",
    ),
    (
        "solidedge_push_switch.step",
        "feature 2, a sliver of 0.000089 mm^3, re-reads as 0.000196 mm^3",
    ),
];

/// Every file of one shared corpus (`corpus`, `corpus-more`), skipped when it is not beside the
/// repository; files in `known` are reported, not failed, while they fail.
fn check_corpus(set: &str, known: &[(&str, &str)]) {
    let dir = PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("../../../shared")
        .join(set);
    if !dir.exists() {
        eprintln!("../shared/{set} not found beside the repository; skipped");
        return;
    }
    let mut failures = vec![];
    for p in steps_in(&dir) {
        let mut here = vec![];
        check_file(&p, &mut here);
        let name = p
            .file_name()
            .map(|n| n.to_string_lossy().into_owned())
            .unwrap_or_default();
        match known.iter().find(|(f, _)| *f == name) {
            Some((_, why)) if here.is_empty() => failures.push(format!(
                "{name} now passes: take it off the known failures ({why})"
            )),
            Some((_, why)) => eprintln!("{name}: known failure: {why}: {here:?}"),
            None => failures.extend(here),
        }
    }
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}

#[test]
fn every_corpus_file_extracts_into_closed_features_that_add_up() {
    check_corpus("corpus", &[]);
}

#[test]
fn every_second_corpus_file_extracts_into_closed_features_that_add_up() {
    check_corpus("corpus-more", &KNOWN_FAILING);
}

#[test]
fn the_arch_splits_along_both_feet_together() {
    // Genus 1: neither foot's root loop alone separates the shell.
    let dir = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../fixtures");
    let part = brep::read_step(dir.join("arch.step")).expect("reads");
    let tree = extract(&part.brep, SolidId(0), &ExtractOptions::default()).expect("extracts");
    assert_eq!(tree.genus, Some(1));
    assert_eq!(tree.features.len(), 2);
    assert_eq!(tree.features[1].root_loops, 2);
    assert_eq!(tree.features[1].parents, vec![0]);
}
