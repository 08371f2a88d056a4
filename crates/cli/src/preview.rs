//! `features preview` and the `preview.html` of every plan: the features' meshes (coarse: for
//! the view) and, with a plan, its tool path, through the `preview` crate.

use crate::mesh::write_atomic;
use crate::{emit, Failure, PreviewArgs};
use brep::mesh::{mesh_faces, MeshOptions};
use features::{extract_all, Assembly, ExtractOptions};
use preview::{FeatureMesh, HeadShape, MachineShape, Mark, MarkKind, MeshAllowance, Preview};
use robot_post::{MachineKind, MachineProfile};
use slicer::allowance::AllowanceSample;
use std::collections::{BTreeMap, HashMap};
use std::io::Write as _;

/// Chord tolerance of the meshes drawn, as a share of the part's size (at least 0.05 mm).
const VIEW_TOLERANCE_SHARE: f64 = 1.0 / 400.0;

/// Every feature of `assembly` meshed for the view, file-wide ids, in build order; a feature
/// with a machining allowance measured (`allowance`, by file-wide id) coloured by what was left
/// ([`allowance_mesh`]).
pub fn feature_meshes(
    assembly: &Assembly,
    allowance: &BTreeMap<usize, Vec<AllowanceSample>>,
    requested: impl Fn(usize) -> Option<f64>,
) -> Vec<FeatureMesh> {
    let mut out = vec![];
    let mut offset = 0;
    for t in &assembly.trees {
        let size = brep::bbox::rough_bbox(&t.brep, t.solid).diagonal().max(1.0);
        let opts = MeshOptions::with_tolerance((size * VIEW_TOLERANCE_SHARE).max(0.05));
        for &k in &t.build_order {
            let f = &t.features[k];
            let on = crate::extract::reference_text(&f.reference);
            let mut mesh = FeatureMesh {
                id: offset + f.id,
                label: format!("{} {on}", f.kind.as_str()),
                ..FeatureMesh::default()
            };
            let samples = allowance.get(&mesh.id).zip(requested(mesh.id));
            match (mesh_faces(&t.brep, &f.faces, &opts), samples) {
                (Ok(m), Some((samples, requested))) => {
                    let (positions, triangles, allowance) = allowance_mesh(&m, samples, requested);
                    mesh.positions = positions;
                    mesh.triangles = triangles;
                    mesh.allowance = Some(allowance);
                }
                (Ok(m), None) => {
                    mesh.positions = m.positions.iter().map(to_f32).collect();
                    mesh.triangles = m.triangles();
                }
                (Err(_), _) => {}
            }
            out.push(mesh);
        }
        offset += t.features.len();
    }
    out
}

fn to_f32(p: &brep::math::P3) -> [f32; 3] {
    [p.x as f32, p.y as f32, p.z as f32]
}

/// A feature's view mesh coloured by the machining allowance left (issue 37, item 2): each
/// B-rep face's vertices its own (the colours do not run across an edge into a face that was
/// not measured), each valued by the nearest measured point of its face, NaN on faces with
/// none or where the nearest is covered by a child feature.
fn allowance_mesh(
    m: &brep::mesh::Mesh,
    samples: &[AllowanceSample],
    requested: f64,
) -> (Vec<[f32; 3]>, Vec<[u32; 3]>, MeshAllowance) {
    let mut on_face: HashMap<brep::topology::FaceId, Vec<&AllowanceSample>> = HashMap::new();
    for s in samples {
        on_face.entry(s.face).or_default().push(s);
    }
    let (mut positions, mut triangles, mut left) = (vec![], vec![], vec![]);
    for ft in &m.faces {
        let near = on_face.get(&ft.face);
        let mut index: HashMap<u32, u32> = HashMap::new();
        for t in &ft.triangles {
            let g = t.map(|i| ft.vertex.get(i as usize).copied().unwrap_or(u32::MAX));
            if g[0] == g[1] || g[1] == g[2] || g[0] == g[2] {
                continue;
            }
            let Some(corners) = g
                .iter()
                .map(|&v| m.positions.get(v as usize))
                .collect::<Option<Vec<_>>>()
            else {
                continue;
            };
            let mut tri = [0u32; 3];
            for (k, (&v, p)) in g.iter().zip(corners).enumerate() {
                tri[k] = *index.entry(v).or_insert_with(|| {
                    positions.push(to_f32(p));
                    let value = near
                        .and_then(|s| {
                            s.iter().min_by(|a, b| {
                                let da = (brep::math::P3::from(a.at) - p).norm_squared();
                                let db = (brep::math::P3::from(b.at) - p).norm_squared();
                                da.total_cmp(&db)
                            })
                        })
                        .and_then(|s| s.left);
                    left.push(value.map_or(f32::NAN, |x| x as f32));
                    (positions.len() - 1) as u32
                });
            }
            triangles.push(tri);
        }
    }
    let allowance = MeshAllowance {
        requested: requested as f32,
        left,
    };
    (positions, triangles, allowance)
}

/// The `preview.html` of a plan, for [`preview::write_html`] to write as it is made: its
/// features, its tool path and its figures, and the simulation view of its program when
/// there is one ([`crate::simulation`]).
pub fn plan_page<'a>(
    plan: &'a plan::Plan,
    title: &str,
    simulation: Option<preview::Simulation>,
) -> Preview<'a> {
    let mut page = plan_preview(plan, title);
    page.simulation = simulation;
    page
}

/// The `preview.html` of a refused plan (issue 31): the plan's page with every failure of its
/// report marked in red (colliding moves, the features the self-check or reach refuses at
/// their first point), the machine's bed or turning table drawn, and the head at the first
/// colliding move.
pub fn refused_page(plan: &plan::Plan, title: &str, machine: &MachineProfile, why: &str) -> String {
    let mut page = plan_preview(plan, title);
    page.refusal = Some(why.to_string());
    page.marks = marks(plan);
    page.machine = Some(machine_shape(plan, machine));
    page.head = plan.collisions.left.first().and_then(|c| {
        let q = plan.toolpath.points.get(c.index)?;
        let h = &machine.head;
        Some(HeadShape {
            tip: q.p,
            axis: q.axis,
            tip_radius: h.nozzle_tip_radius,
            half_angle_deg: h.nozzle_cone_half_angle_deg,
            cone_length: h.nozzle_length,
            body_radius: h.body_radius,
            body_length: h.body_length,
        })
    });
    preview::html(&page)
}

/// The failures of a refused plan as red marks: each colliding move (its two ends), and each
/// failure of the report that names a feature but no move, at its position or the feature's
/// first point.
fn marks(plan: &plan::Plan) -> Vec<Mark> {
    let pts = &plan.toolpath.points;
    let mut out: Vec<Mark> = plan
        .collisions
        .left
        .iter()
        .map(|c| {
            let end = pts.get(c.index).map(|q| q.p).unwrap_or(c.at);
            let start = c.index.checked_sub(1).and_then(|i| pts.get(i)).map(|q| q.p);
            let hits = match c.hits {
                collide::Obstacle::Feature(f) => format!("feature {f}"),
                collide::Obstacle::Table => "the table".to_string(),
            };
            Mark {
                kind: MarkKind::Collision,
                feature: Some(c.feature),
                text: format!(
                    "feature {}: the head hits {hits} at ({:.3}, {:.3}, {:.3})",
                    c.feature, c.at[0], c.at[1], c.at[2]
                ),
                points: start.into_iter().chain([end]).collect(),
            }
        })
        .collect();
    for f in &plan.report.failures {
        if f.gate == "collisions" {
            continue;
        }
        let at = f.position.or_else(|| {
            let id = f.feature?;
            pts.iter().find(|q| q.feature as usize == id).map(|q| q.p)
        });
        out.push(Mark {
            kind: match f.gate {
                "selfcheck" => MarkKind::SelfCheck,
                "reach" => MarkKind::Unreachable,
                "unsupported" => MarkKind::Unsupported,
                _ => MarkKind::Machine,
            },
            feature: f.feature,
            text: f.text.clone(),
            points: at.into_iter().collect(),
        });
    }
    out
}

/// The machine's table where its post places the part: delta5's turning disc, else the bed
/// under the part (Marlin's of its size about the part, as the post centres it; a KUKA cell's
/// table plane shown 50 mm past the part).
fn machine_shape(plan: &plan::Plan, machine: &MachineProfile) -> MachineShape {
    match plan::collisions::table(&plan.toolpath, machine) {
        collide::Table::Disc { centre, z, radius } => MachineShape::Table { centre, z, radius },
        collide::Table::Plane { z } => {
            let (mut lo, mut hi) = ([f64::INFINITY; 2], [f64::NEG_INFINITY; 2]);
            for q in &plan.toolpath.points {
                for k in 0..2 {
                    lo[k] = lo[k].min(q.p[k]);
                    hi[k] = hi[k].max(q.p[k]);
                }
            }
            if !lo[0].is_finite() {
                (lo, hi) = ([0.0; 2], [0.0; 2]);
            }
            let half = match machine.kind {
                MachineKind::Marlin => [0.5 * machine.bed_size[0], 0.5 * machine.bed_size[1]],
                _ => [0.5 * (hi[0] - lo[0]) + 50.0, 0.5 * (hi[1] - lo[1]) + 50.0],
            };
            let mid = [0.5 * (lo[0] + hi[0]), 0.5 * (lo[1] + hi[1])];
            MachineShape::Bed {
                min: [mid[0] - half[0], mid[1] - half[1]],
                max: [mid[0] + half[0], mid[1] + half[1]],
                z,
            }
        }
    }
}

/// A plan's page as [`plan_page`] draws it.
fn plan_preview<'a>(plan: &'a plan::Plan, title: &str) -> Preview<'a> {
    let f = plan.features();
    let layers: usize = f.iter().map(|x| x.layers).sum();
    let print: f64 = f.iter().map(|x| x.print_length_mm).sum();
    let travel: f64 = f.iter().map(|x| x.travel_length_mm).sum();
    let volume: f64 = f.iter().map(|x| x.extruded_volume_mm3).sum();
    Preview {
        title: title.to_string(),
        features: feature_meshes(&plan.assembly, &plan.allowance_left, |id| {
            f.iter()
                .find(|x| x.feature.id == id)?
                .machining_allowance
                .as_ref()
                .map(|a| a.requested_mm)
        }),
        path: Some(&plan.toolpath),
        figures: vec![
            ("machine".into(), plan.report.machine.clone()),
            ("features".into(), f.len().to_string()),
            ("layers".into(), layers.to_string()),
            ("points".into(), plan.toolpath.points.len().to_string()),
            ("print length".into(), format!("{print:.1} mm")),
            ("travel length".into(), format!("{travel:.1} mm")),
            ("extruded volume".into(), format!("{volume:.1} mm³")),
            (
                "support volume".into(),
                format!(
                    "{:.1} mm³",
                    f.iter().map(|x| x.support_volume_mm3).sum::<f64>()
                ),
            ),
            (
                "estimated time".into(),
                plan::estimate::hms(plan.report.estimated_time_s),
            ),
            (
                "filament".into(),
                format!(
                    "{:.2} m, {:.1} g",
                    plan.report.filament_mm / 1000.0,
                    plan.report.filament_g
                ),
            ),
            ("warnings".into(), plan.warnings().len().to_string()),
        ]
        .into_iter()
        .chain(f.iter().find_map(|x| {
            let h = x.pedestal_height_mm?;
            Some((
                "pedestal".into(),
                format!("{h} mm, {} layers (feature {})", x.layers, x.feature.id),
            ))
        }))
        .collect(),
        ..Preview::default()
    }
}

/// Runs `features preview`: the extracted features alone.
pub fn run(args: &PreviewArgs) -> Result<(), Failure> {
    let path = &args.part;
    if args.output.extension().and_then(|e| e.to_str()) != Some("html") {
        return Err(Failure::new(
            &args.output,
            "the preview is a web page: give -o a file ending in .html",
        ));
    }
    // STEP, or a mesh (STL, 3MF, OBJ): each body one mesh_two5d feature.
    let tolerance = plan::Process::default().base().tolerance;
    let part = brep::read_part(path, tolerance)
        .and_then(|f| f.part())
        .map_err(|e| Failure::new(path, e))?;
    let assembly =
        extract_all(&part.brep, &ExtractOptions::default()).map_err(|e| Failure::new(path, e))?;
    let features = feature_meshes(&assembly, &BTreeMap::new(), |_| None);
    let volume: f64 = assembly.trees.iter().map(|t| t.part_volume).sum();
    let page = preview::html(&Preview {
        title: path.display().to_string(),
        figures: vec![
            ("features".into(), features.len().to_string()),
            ("solids".into(), assembly.trees.len().to_string()),
            ("volume".into(), format!("{volume:.1} mm³")),
        ],
        features,
        path: None,
        ..Preview::default()
    });
    write_atomic(&args.output, |w| w.write_all(page.as_bytes()))
        .map_err(|e| Failure::new(&args.output, format!("cannot write: {e}")))?;
    emit(&format!(
        "{}: {} feature(s) -> {}\n",
        path.display(),
        assembly
            .trees
            .iter()
            .map(|t| t.features.len())
            .sum::<usize>(),
        args.output.display()
    ))
}
