//! The generated part families (`fixtures/families`, issue 14): every part extracts into the
//! features it was built from. `fixtures/families/reference.json` holds, per part, the figures
//! known by construction (feature count, freeform and two5d counts, depth) and OpenCASCADE's
//! volume; `fixtures/families/README.md` gives the rules they follow. Each feature must also be a
//! valid solid by `features::check_solid`. Every part is checked and every failure collected, so
//! one run names them all.

use features::{check_solid, extract_all, ExtractOptions, FeatureKind, RootOutcome};
use serde_json::Value;
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicUsize, Ordering};
use std::sync::Mutex;

fn families_dir() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../../fixtures/families")
}

/// One part of `reference.json`.
struct Expected {
    file: String,
    volume: f64,
    features: usize,
    freeform: usize,
    two5d: usize,
    depth: usize,
}

fn reference() -> Vec<Expected> {
    let text = std::fs::read_to_string(families_dir().join("reference.json"))
        .expect("fixtures/families/reference.json");
    let v: Value = serde_json::from_str(&text).expect("reference.json is JSON");
    let n = |p: &Value, k: &str| p[k].as_u64().unwrap_or_else(|| panic!("{k} in {p}")) as usize;
    v["parts"]
        .as_array()
        .expect("parts")
        .iter()
        .map(|p| Expected {
            file: p["file"].as_str().expect("file").to_string(),
            volume: p["volume_mm3"].as_f64().expect("volume_mm3"),
            features: n(p, "features"),
            freeform: n(p, "freeform"),
            two5d: n(p, "two5d"),
            depth: n(p, "depth"),
        })
        .collect()
}

/// What is wrong with one part's extraction (empty when nothing is).
fn check_part(e: &Expected) -> Vec<String> {
    let mut why = vec![];
    let part = match brep::read_step(families_dir().join(&e.file)) {
        Ok(p) => p,
        Err(err) => return vec![format!("does not read: {err}")],
    };
    let assembly = match extract_all(&part.brep, &ExtractOptions::default()) {
        Ok(a) => a,
        Err(err) => return vec![format!("extraction fails: {err}")],
    };
    if assembly.trees.len() != 1 {
        why.push(format!(
            "{} solids extracted, expected 1",
            assembly.trees.len()
        ));
    }
    let Some(tree) = assembly.trees.first() else {
        return why;
    };
    let count = |k: FeatureKind| tree.features.iter().filter(|f| f.kind == k).count();
    let got = (
        tree.features.len(),
        count(FeatureKind::Freeform),
        count(FeatureKind::Two5d),
        tree.depth,
    );
    let want = (e.features, e.freeform, e.two5d, e.depth);
    if got != want {
        why.push(format!(
            "features/freeform/two5d/depth {}/{}/{}/{}, expected {}/{}/{}/{}",
            got.0, got.1, got.2, got.3, want.0, want.1, want.2, want.3
        ));
    }
    let sum: f64 = tree.features.iter().map(|f| f.volume).sum();
    if (sum - e.volume).abs() > 1e-3 * e.volume {
        why.push(format!(
            "feature volumes add up to {sum:.3} mm^3, the part is {:.3} ({:+.3} %)",
            e.volume,
            100.0 * (sum - e.volume) / e.volume
        ));
    }
    let opts = brep::solid::analysis_options(tree.mesh.bbox().diagonal().max(1e-3));
    for f in &tree.features {
        let name = format!(
            "feature {} ({} on {})",
            f.id,
            f.kind.as_str(),
            f.reference.surface
        );
        if f.volume <= 0.0 || !f.volume.is_finite() {
            why.push(format!("{name}: volume {}", f.volume));
        }
        if !f.closed {
            why.push(format!("{name}: shell not closed"));
        }
        // The check every feature passes as a solid: topology, meshable faces, watertight,
        // positive volume; at the tolerances of the extraction's analysis.
        let check = check_solid(&tree.brep, &f.faces, &f.voids, &opts);
        for problem in &check.problems {
            why.push(format!("{name}: {problem}"));
        }
    }
    // Where the counts are off, what became of the part's concave loops says why.
    if got != want {
        for r in &tree.roots {
            if let RootOutcome::Kept(reason) = &r.outcome {
                let edges: Vec<String> = r.edges.iter().map(|e| format!("#{e}")).collect();
                why.push(format!("loop {} kept: {reason}", edges.join(",")));
            }
        }
    }
    why
}

#[test]
fn every_family_part_extracts_into_the_features_it_was_built_from() {
    let parts = reference();
    assert!(parts.len() >= 60, "{} parts in reference.json", parts.len());
    let next = AtomicUsize::new(0);
    let results: Mutex<Vec<(usize, Vec<String>)>> = Mutex::new(vec![]);
    let threads = std::thread::available_parallelism().map_or(2, |n| n.get().min(4));
    std::thread::scope(|s| {
        for _ in 0..threads {
            s.spawn(|| loop {
                let k = next.fetch_add(1, Ordering::Relaxed);
                let Some(e) = parts.get(k) else { break };
                let why = std::panic::catch_unwind(|| check_part(e))
                    .unwrap_or_else(|_| vec!["panicked (see above)".to_string()]);
                results.lock().unwrap().push((k, why));
            });
        }
    });
    let mut results = results.into_inner().unwrap();
    results.sort_by_key(|r| r.0);
    let failures: Vec<String> = results
        .iter()
        .filter(|(_, why)| !why.is_empty())
        .map(|(k, why)| format!("{}: {}", parts[*k].file, why.join("; ")))
        .collect();
    assert!(
        failures.is_empty(),
        "{} of {} family parts fail:\n{}",
        failures.len(),
        parts.len(),
        failures.join("\n")
    );
}
