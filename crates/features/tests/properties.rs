//! Properties every extraction must have, on every fixture and every corpus file: the features'
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
        let part_volume = brep::solid::report_solid(&part.brep, s)
            .expect("report")
            .volume;
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
                    let r = brep::solid::report_solid(&back.brep, SolidId(0)).expect("report");
                    if !r.closed || !r.watertight || (r.volume - f.volume).abs() > 5e-3 * f.volume {
                        failures.push(format!(
                            "{name}: exported feature {} closed={} watertight={} volume {:.3} vs {:.3}",
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

#[test]
fn every_corpus_file_extracts_into_closed_features_that_add_up() {
    let dir = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../../shared/corpus");
    if !dir.exists() {
        eprintln!("../shared/corpus not found beside the repository; skipped");
        return;
    }
    let mut failures = vec![];
    for p in steps_in(&dir) {
        check_file(&p, &mut failures);
    }
    assert!(failures.is_empty(), "{}", failures.join("\n"));
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
