//! `features extract`: the AM feature tree of every solid in a file.

use crate::mesh::{solid_mesh, write_atomic, write_stl};
use crate::{emit, ExtractArgs, Failure};
use features::{extract_all, solid_name, ExtractOptions, FeatureTree};
use plan::report::round;
use serde_json::{json, Value};
use std::fmt::Write as _;
use std::io::Write as _;
use std::path::Path;

/// One solid's tree with the id offset of its features in the file-wide numbering.
struct Solid {
    tree: FeatureTree,
    offset: usize,
}

/// Runs the command.
pub fn run(args: &ExtractArgs) -> Result<(), Failure> {
    let path = &args.part;
    // STEP, or a mesh (STL, 3MF, OBJ) whose gaps within the default process tolerance are
    // welded.
    let tolerance = plan::Process::default().base().tolerance;
    let part = brep::read_part(path, tolerance)
        .and_then(|f| f.part())
        .map_err(|e| Failure::new(path, e))?;
    let assembly =
        extract_all(&part.brep, &ExtractOptions::default()).map_err(|e| Failure::new(path, e))?;
    // The reader's warnings (skipped header lines, unknown entities, faces turned round) first.
    let mut warnings = part.brep.warnings.clone();
    warnings.extend(assembly.all_warnings());
    let together: Vec<String> = part
        .brep
        .warnings
        .iter()
        .chain(&assembly.warnings)
        .cloned()
        .collect();
    let support = if args.json {
        support_json(&assembly).map_err(|e| Failure::new(path, e))?
    } else {
        vec![]
    };
    let mut solids = vec![];
    let mut offset = 0;
    for tree in assembly.trees {
        let n = tree.features.len();
        solids.push(Solid { tree, offset });
        offset += n;
    }
    if let Some(dir) = &args.export {
        if dir.exists() && !dir.is_dir() {
            return Err(Failure::new(
                dir,
                "is a file: --export writes one STEP and one STL file per feature into a folder",
            ));
        }
        export(dir, &solids).map_err(|e| Failure::new(dir, e))?;
    }
    let source = path.display().to_string();
    let text = if args.json {
        let mut t = serde_json::to_string_pretty(&to_json(&source, &solids, support, warnings))
            .map_err(|e| Failure::new(path, e))?;
        t.push('\n');
        t
    } else {
        to_text(&source, &solids, &together)
    };
    emit(&text)
}

/// Support material as features of the model (issue 37 item 3, the seed's
/// `support_structure`): for each two5d feature whose planar layers need support material
/// under the default process and the Marlin profile's bead, as the part is modelled
/// ([`plan::support::planar`], what `plan` lays), one feature of kind `support` with that
/// feature as its child, numbered after every feature of the file: the layers it is laid in
/// and their area summed.
fn support_json(assembly: &features::Assembly) -> Result<Vec<Value>, plan::PlanError> {
    let bead = robot_post::MachineProfile::builtin(robot_post::MachineKind::Marlin).bead();
    let columns = plan::support::planar(
        assembly,
        &plan::Process::default(),
        bead.width,
        slicer::support::Carry::Until(None),
    )?
    .columns;
    let next: usize = assembly.trees.iter().map(|t| t.features.len()).sum();
    Ok(columns
        .iter()
        .enumerate()
        .map(|(k, (&child, regions))| {
            let layers = regions
                .sparse
                .iter()
                .zip(&regions.interface)
                .filter(|(s, i)| !s.is_empty() || !i.is_empty())
                .count();
            json!({
                "id": next + k,
                "kind": "support",
                "children": [child],
                "layers": layers,
                "area_mm2": round(regions.area(), 1e3),
            })
        })
        .collect())
}

fn to_json(source: &str, solids: &[Solid], support: Vec<Value>, warnings: Vec<String>) -> Value {
    let volume: f64 = solids.iter().map(|s| s.tree.part_volume).sum();
    let area: f64 = solids.iter().map(|s| s.tree.part_area).sum();
    let faces: usize = solids.iter().map(|s| s.tree.part_faces).sum();
    let genus: Option<i64> = solids.iter().map(|s| s.tree.genus).sum();
    let mut features = vec![];
    let mut order = vec![];
    let mut roots = vec![];
    for s in solids {
        let t = &s.tree;
        for r in &t.roots {
            roots.push(match &r.outcome {
                features::RootOutcome::Split(k) => {
                    json!({"edges": r.edges, "split": true, "feature": s.offset + k})
                }
                features::RootOutcome::Kept(why) => {
                    json!({"edges": r.edges, "split": false, "reason": why})
                }
            });
        }
        for f in &t.features {
            features.push(feature_json_fields(t, f, s.offset));
        }
        order.extend(t.build_order.iter().map(|k| s.offset + k));
    }
    json!({
        "schema": "features.extract/1",
        "source": source,
        "units": "mm",
        "part": {"volume_mm3": round(volume, 1e3), "area_mm2": round(area, 1e3), "faces": faces, "genus": genus},
        "features": features,
        "support_features": support,
        "build_order": order,
        "depth": solids.iter().map(|s| s.tree.depth).max().unwrap_or(0),
        "concave_loops": roots,
        "warnings": warnings,
    })
}

/// The `extract` fields of one feature, numbered from `offset` (the features of earlier solids).
fn feature_json_fields(t: &FeatureTree, f: &features::Feature, offset: usize) -> Value {
    serde_json::to_value(plan::FeatureEntry::new(t, f, offset)).unwrap_or(Value::Null)
}

/// The trees as text, each solid's warnings under it and those about the solids together
/// (`together`) last.
fn to_text(source: &str, solids: &[Solid], together: &[String]) -> String {
    let mut out = String::new();
    for s in solids {
        let t = &s.tree;
        let _ = writeln!(
            out,
            "{source}{}: {} feature(s), depth {}, part {:.3} mm^3",
            if solids.len() > 1 {
                format!(" {}", solid_name(t))
            } else {
                String::new()
            },
            t.features.len(),
            t.depth,
            t.part_volume
        );
        // Children under their parents, in build order: `├─` before a sibling that follows,
        // `└─` before the last, and `│` down the side of a parent with more to come.
        fn walk(
            out: &mut String,
            t: &FeatureTree,
            offset: usize,
            k: usize,
            lead: &str,
            branch: &str,
        ) {
            let f = &t.features[k];
            let on = reference_text(&f.reference);
            let _ = writeln!(
                out,
                "{lead}{branch}feature {}  {} {}  {}  {:.3} mm^3{}",
                offset + f.id,
                f.kind.as_str(),
                f.subtype,
                on,
                f.volume,
                if f.root_loops > 1 {
                    format!("  ({} root loops)", f.root_loops)
                } else {
                    String::new()
                }
            );
            let children: Vec<usize> = t
                .build_order
                .iter()
                .copied()
                .filter(|&c| t.features[c].parents.first() == Some(&k))
                .collect();
            let below = match branch {
                "" => lead.to_string(),
                "├─ " => format!("{lead}│  "),
                _ => format!("{lead}   "),
            };
            for (i, &c) in children.iter().enumerate() {
                let b = if i + 1 == children.len() {
                    "└─ "
                } else {
                    "├─ "
                };
                walk(out, t, offset, c, &below, b);
            }
        }
        for &k in t
            .build_order
            .iter()
            .filter(|&&k| t.features[k].parents.is_empty())
        {
            walk(&mut out, t, s.offset, k, "", "");
        }
        for w in &t.warnings {
            let _ = writeln!(out, "warning: {w}");
        }
    }
    for w in together {
        let _ = writeln!(out, "warning: {w}");
    }
    out
}

fn export(dir: &Path, solids: &[Solid]) -> std::io::Result<()> {
    std::fs::create_dir_all(dir)?;
    for s in solids {
        let t = &s.tree;
        for f in &t.features {
            let id = s.offset + f.id;
            let name = format!("feature_{id}");
            let step = brep::write::write_step_shells(
                &t.brep,
                &[(f.faces.clone(), f.voids.clone())],
                &name,
            );
            write_atomic(&dir.join(format!("{name}.step")), |w| {
                w.write_all(step.as_bytes())
            })?;
            let mut faces = f.faces.clone();
            for v in &f.voids {
                faces.extend(v.iter().copied());
            }
            let mesh = brep::mesh::mesh_faces(&t.brep, &faces, &brep::mesh::MeshOptions::default())
                .map_err(|e| std::io::Error::other(e.to_string()))?;
            let sm = solid_mesh(0, &mesh);
            let n = sm.triangles.len() as u32;
            write_atomic(&dir.join(format!("{name}.stl")), |w| {
                write_stl(w, &name, std::slice::from_ref(&sm), n)
            })?;
        }
    }
    Ok(())
}

/// Where a feature grows from, as the tree and the preview say it: `on the build plate (face
/// #17)`, `on cone face #54`.
pub fn reference_text(r: &features::Reference) -> String {
    match (r.surface.as_str(), r.step_face) {
        ("build_plate", Some(id)) => format!("on the build plate (face #{id})"),
        ("build_plate", None) => "on the build plate".to_string(),
        (kind, Some(id)) => format!("on {kind} face #{id}"),
        (kind, None) => format!("on {kind}"),
    }
}
