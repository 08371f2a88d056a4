//! Real files from other CAD writers (`../shared/corpus/` and `../shared/corpus-more/`): every
//! reference solid's volume within 0.1 % of OpenCASCADE's (adaptive integration), or a clear
//! one-line refusal; never a panic. Where OpenCASCADE's bounding boxes are given
//! (`occ_details.json`), its box holds all our solids (components stand inside the assembly). A solid that is not watertight, or whose volume is not
//! positive, always carries a warning. The files this reader cannot yet bring within 0.1 % are
//! listed in [`KNOWN_OFF`] with the measured reason; one that comes right fails the test until
//! it is taken off the list.

use serde_json::Value;
use std::path::PathBuf;

/// Files still off, with why (measured 2026-11-25).
const KNOWN_OFF: [(&str, &str); 2] = [
    (
        "fusion_atf65_example.step",
        "-0.22 % (9.558 vs 9.579 mm^3), OpenCASCADE's figure off, not ours: its pcurves, made by projecting the 3-D B-spline edges onto the thread's r = 0.7 cylinders, stray from the edges (edge tolerances 0.005-0.01 mm after reading); Green's theorem over the exact edges (sampled through OCC itself) gives face 1 0.727697 mm^2 as we do (OCC 0.741944 over its pcurves), face 2 0.846017 (we 0.846021, OCC 0.865914)",
    ),
    (
        "onshape_abc_0_13.step",
        "volume -0.006 % (13130.6 vs 13131.3 mm^3; -0.0004 % at finer edges) but not watertight (warned, faces named): the trims of four rational B-spline faces (#161, #145, #149, #281) lie up to 0.0018 mm off them, and where two trims run side by side into a cusp their projections cross in (u, v) (#2562 and #2500 on #161: 3 crossings at 200 samples an edge), so the face's domain folds there; finer meshes leave the mesh as open",
    ),
];

/// The one file whose faces the reader turns round, and those faces: ASCON KOMPAS writes
/// the mirrored legs of its sheet-metal switch with the planes' sense against their loops
/// (OpenCASCADE heals them the same way).
const TURNED: (&str, &[&str]) = ("ascon_kompas_push_switch.step", &["shell #62", "shell #82"]);

/// What the reader's warnings on `file` say wrongly (issue 34): a face turned round in a shell
/// that was consistent (every file but [`TURNED`]), or a valid entity warned as unknown.
fn reader_warnings(file: &str, warnings: &[String]) -> Vec<String> {
    let mut failures = vec![];
    let turned: Vec<&String> = warnings
        .iter()
        .filter(|w| w.contains("turned round"))
        .collect();
    if file == TURNED.0 {
        let all = turned
            .iter()
            .map(|w| w.as_str())
            .collect::<Vec<_>>()
            .join(" ");
        if TURNED.1.iter().any(|f| !all.contains(f)) {
            failures.push(format!(
                "{file}: shells {:?} not turned round: {turned:?}",
                TURNED.1
            ));
        }
    } else {
        failures.extend(turned.iter().map(|w| format!("{file}: {w}")));
    }
    failures.extend(
        warnings
            .iter()
            .filter(|w| w.contains("unknown entity"))
            .map(|w| format!("{file}: {w}")),
    );
    failures
}

/// The parts people print (`../shared/corpus-print/`): no face turned round, no valid entity
/// warned as unknown (their volumes are the planner's tests' concern).
#[test]
fn corpus_print_reads_without_turning_faces() {
    let dir = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../../shared/corpus-print");
    let Ok(entries) = std::fs::read_dir(&dir) else {
        eprintln!("../shared/corpus-print not found; skipped");
        return;
    };
    let mut failures = vec![];
    for e in entries.filter_map(|e| e.ok()) {
        let name = e.file_name().to_string_lossy().to_string();
        if !name.ends_with(".step") {
            continue;
        }
        match brep::read_step(e.path()) {
            Ok(part) => failures.extend(reader_warnings(&name, &part.brep.warnings)),
            Err(err) => failures.push(format!("{name}: {err}")),
        }
    }
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}

fn dirs() -> Vec<PathBuf> {
    ["corpus", "corpus-more"]
        .iter()
        .map(|d| {
            PathBuf::from(env!("CARGO_MANIFEST_DIR"))
                .join("../../../shared")
                .join(d)
        })
        .filter(|d| d.join("reference.json").exists())
        .collect()
}

/// Where OpenCASCADE places the file's solids, all together (`occ_details.json` beside
/// `reference.json`, where there is one): `[xmin, ymin, zmin, xmax, ymax, zmax]`, mm.
fn occ_bbox(dir: &std::path::Path, file: &str) -> Option<Vec<f64>> {
    let text = std::fs::read_to_string(dir.join("occ_details.json")).ok()?;
    let v: Value = serde_json::from_str(&text).ok()?;
    let b: Vec<f64> = v[file]["bbox_mm"]
        .as_array()?
        .iter()
        .filter_map(|x| x.as_f64())
        .collect();
    (b.len() == 6).then_some(b)
}

/// What is wrong with one file's reading, if anything.
fn check_file(dir: &std::path::Path, file: &str, r: &Value) -> Vec<String> {
    let mut failures = vec![];
    let part = match brep::read_step(dir.join(file)) {
        Ok(p) => p,
        Err(e) => {
            // A refusal is acceptable only if it is one clear line.
            let msg = e.to_string();
            if msg.contains('\n') || msg.is_empty() {
                failures.push(format!("{file}: unclear refusal {msg:?}"));
            }
            eprintln!("{file}: refused: {msg}");
            return failures;
        }
    };
    let b = &part.brep;
    failures.extend(reader_warnings(file, &b.warnings));
    let mut want_vols: Vec<f64> = r["volumes_mm3"]
        .as_array()
        .map(|a| a.iter().filter_map(|v| v.as_f64()).collect())
        .unwrap_or_default();
    if b.solids.len() != want_vols.len() {
        failures.push(format!(
            "{file}: {} solids, reference {}",
            b.solids.len(),
            want_vols.len()
        ));
        return failures;
    }
    let mut got = vec![];
    let mut bbox = brep::math::Aabb::empty();
    for s in b.solid_ids() {
        match brep::solid::report_solid(b, s) {
            Ok(rep) => {
                bbox.add(&rep.bbox.min);
                bbox.add(&rep.bbox.max);
                if !rep.closed || !rep.watertight {
                    failures.push(format!(
                        "{file}: solid #{} closed={} watertight={}",
                        rep.step_id, rep.closed, rep.watertight
                    ));
                    if !rep
                        .findings
                        .iter()
                        .any(|f| f.contains("not watertight") || f.contains("open"))
                        && !rep.watertight
                    {
                        failures.push(format!(
                            "{file}: solid #{} is not watertight and says nothing: {:?}",
                            rep.step_id, rep.findings
                        ));
                    }
                }
                if rep.volume <= 0.0 && rep.findings.is_empty() {
                    failures.push(format!(
                        "{file}: solid #{} has volume {} and no warning",
                        rep.step_id, rep.volume
                    ));
                }
                got.push(rep.volume);
            }
            Err(e) => failures.push(format!("{file}: {e}")),
        }
    }
    // Components stand where the assembly places them: OpenCASCADE's box holds ours (its box
    // is widened by tolerances and, on B-spline faces, reaches to their control points).
    if let Some(occ) = occ_bbox(dir, file) {
        // (It is rounded to 1e-4 mm.)
        let slack = 1e-4 + 1e-6 * bbox.diagonal();
        for k in 0..3 {
            if bbox.min[k] < occ[k] - slack || bbox.max[k] > occ[k + 3] + slack {
                failures.push(format!(
                    "{file}: solids span [{:.4}, {:.4}] on axis {k}, OpenCASCADE's [{}, {}]",
                    bbox.min[k],
                    bbox.max[k],
                    occ[k],
                    occ[k + 3]
                ));
            }
        }
    }
    got.sort_by(f64::total_cmp);
    want_vols.sort_by(f64::total_cmp);
    for (g, w) in got.iter().zip(&want_vols) {
        // Tiny solids (a sliver OpenCASCADE gives almost no volume) are compared absolutely.
        let ok = if w.abs() < 1.0 {
            (g - w).abs() < 0.01
        } else {
            (g - w).abs() / w <= 1e-3
        };
        if !ok {
            failures.push(format!(
                "{file}: volume {g:.4} vs reference {w:.4} ({:+.3} %)",
                100.0 * (g - w) / w
            ));
        }
    }
    eprintln!("{file}: {got:?} vs {want_vols:?}");
    failures
}

#[test]
fn corpus_volumes_match_opencascade() {
    let dirs = dirs();
    if dirs.is_empty() {
        eprintln!("../shared/corpus not found beside the repository; corpus test skipped");
        return;
    }
    let mut failures = vec![];
    for dir in &dirs {
        let refs: Value =
            serde_json::from_str(&std::fs::read_to_string(dir.join("reference.json")).unwrap())
                .unwrap();
        for (file, r) in refs.as_object().unwrap() {
            if !dir.join(file).exists() {
                continue;
            }
            let why = check_file(dir, file, r);
            match KNOWN_OFF.iter().find(|(f, _)| f == file) {
                Some((_, reason)) if why.is_empty() => failures.push(format!(
                    "{file} now reads within 0.1 %: take it off KNOWN_OFF ({reason})"
                )),
                Some((_, reason)) => eprintln!("{file}: known off: {reason}: {why:?}"),
                None => failures.extend(why),
            }
        }
    }
    assert!(
        failures.is_empty(),
        "corpus failures:\n{}",
        failures.join("\n")
    );
}
