//! `features preview` and the `preview.html` of every plan: the features' meshes (coarse: for
//! the view) and, with a plan, its tool path, through the `preview` crate.

use crate::mesh::write_atomic;
use crate::{emit, Failure, PreviewArgs};
use brep::mesh::{mesh_faces, MeshOptions};
use features::{extract_all, Assembly, ExtractOptions};
use preview::{FeatureMesh, Preview};
use std::io::Write as _;

/// Chord tolerance of the meshes drawn, as a share of the part's size (at least 0.05 mm).
const VIEW_TOLERANCE_SHARE: f64 = 1.0 / 400.0;

/// Every feature of `assembly` meshed for the view, file-wide ids, in build order.
pub fn feature_meshes(assembly: &Assembly) -> Vec<FeatureMesh> {
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
            if let Ok(m) = mesh_faces(&t.brep, &f.faces, &opts) {
                mesh.positions = m
                    .positions
                    .iter()
                    .map(|p| [p.x as f32, p.y as f32, p.z as f32])
                    .collect();
                mesh.triangles = m.triangles();
            }
            out.push(mesh);
        }
        offset += t.features.len();
    }
    out
}

/// The `preview.html` of a plan: its features, its tool path and its figures.
pub fn plan_page(plan: &plan::Plan, title: &str) -> String {
    let f = plan.features();
    let layers: usize = f.iter().map(|x| x.layers).sum();
    let print: f64 = f.iter().map(|x| x.print_length_mm).sum();
    let travel: f64 = f.iter().map(|x| x.travel_length_mm).sum();
    let volume: f64 = f.iter().map(|x| x.extruded_volume_mm3).sum();
    preview::html(&Preview {
        title: title.to_string(),
        features: feature_meshes(&plan.assembly),
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
    })
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
    let part = brep::read_step(path).map_err(|e| Failure::new(path, e))?;
    let assembly =
        extract_all(&part.brep, &ExtractOptions::default()).map_err(|e| Failure::new(path, e))?;
    let features = feature_meshes(&assembly);
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
