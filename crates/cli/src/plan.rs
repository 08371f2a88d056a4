//! `features plan`: layers, paths and a machine program for every feature, in build order.

use crate::extract::feature_json_fields;
use crate::mesh::TempFile;
use crate::{emit, Failure, PlanArgs};
use features::{extract_all, ExtractOptions};
use robot_post::machine::{MachineKind, MachineProfile};
use robot_post::post::FigureValue;
use serde_json::json;
use slicer::freeform::plan_freeform;
use slicer::orient::{smooth, SmoothParams};
use slicer::params::{LayerParams, LayerParamsPatch};
use slicer::planar::plan_two5d;
use slicer::toolpath::ToolPath;
use std::collections::HashMap;
use std::io::Write as _;
use std::path::Path;

/// A process file: `[defaults]` and `[features.<id>]` overrides.
#[derive(Debug, Default, serde::Deserialize)]
#[serde(deny_unknown_fields)]
struct ProcessFile {
    #[serde(default)]
    defaults: Option<LayerParamsPatch>,
    #[serde(default)]
    features: HashMap<String, LayerParamsPatch>,
    /// Tool-axis smoothing (Chalvin et al. 2022, Eq. 3–7).
    #[serde(default)]
    orientation: SmoothParams,
}

fn round(x: f64, scale: f64) -> f64 {
    (x * scale).round() / scale + 0.0
}

/// Runs the command.
pub fn run(args: &PlanArgs) -> Result<(), Failure> {
    let path = &args.part;
    // Settings first: a bad process or machine file fails before any work.
    let process: ProcessFile = match &args.process {
        Some(p) => {
            let text = std::fs::read_to_string(p)
                .map_err(|e| Failure::new(p, format!("cannot read process file: {e}")))?;
            toml::from_str(&text).map_err(|e| {
                let line = e
                    .span()
                    .map(|r| text[..r.start.min(text.len())].matches('\n').count() + 1);
                let at = line.map(|l| format!(" line {l}")).unwrap_or_default();
                Failure::new(p, format!("process file{at}: {}", e.message().trim()))
            })?
        }
        None => ProcessFile::default(),
    };
    let base = match &process.defaults {
        Some(p) => LayerParams::default().patched(p),
        None => LayerParams::default(),
    };
    base.validate().map_err(|e| {
        Failure::new(
            args.process.as_deref().unwrap_or(path),
            format!("process defaults: {e}"),
        )
    })?;
    let machine = match (&args.machine_profile, args.machine.as_deref()) {
        (Some(p), _) => {
            let text = std::fs::read_to_string(p)
                .map_err(|e| Failure::new(p, format!("cannot read machine profile: {e}")))?;
            MachineProfile::from_toml(&text).map_err(|e| Failure::new(p, e))?
        }
        (None, Some(name)) => {
            let kind = MachineKind::from_name(name).ok_or_else(|| {
                Failure::new(
                    path,
                    format!("unknown machine `{name}` (marlin, delta5 or kuka)"),
                )
            })?;
            MachineProfile::builtin(kind)
        }
        (None, None) => MachineProfile::builtin(MachineKind::Marlin),
    };
    process.orientation.validate().map_err(|e| {
        Failure::new(
            args.process.as_deref().unwrap_or(path),
            format!("process [orientation]: {e}"),
        )
    })?;
    let bead = machine.bead();
    let filament_area = bead.filament_area();

    let part = brep::read_step(path).map_err(|e| Failure::new(path, e))?;
    let assembly =
        extract_all(&part.brep, &ExtractOptions::default()).map_err(|e| Failure::new(path, e))?;
    let trees = &assembly.trees;
    let total: u64 = trees.iter().map(|t| t.features.len() as u64).sum();
    let bar = indicatif::ProgressBar::with_draw_target(
        Some(total),
        indicatif::ProgressDrawTarget::stderr(),
    );
    if !std::io::IsTerminal::is_terminal(&std::io::stderr()) {
        bar.set_draw_target(indicatif::ProgressDrawTarget::hidden());
    }
    bar.set_style(
        indicatif::ProgressStyle::with_template("planning {bar:30} {pos}/{len} features {msg}")
            .unwrap_or_else(|_| indicatif::ProgressStyle::default_bar()),
    );

    let mut points = vec![];
    let mut cursor = None;
    let mut feature_values = vec![];
    let mut warnings: Vec<String> = vec![];
    let mut offset = 0usize;
    let mut planned = vec![];
    for t in trees {
        let plate = t
            .features
            .first()
            .and_then(|b| slicer::planar::reference_plane(t, b));
        for &k in &t.build_order {
            let f = &t.features[k];
            let id = offset + f.id;
            bar.set_message(format!("feature {id}"));
            let params = match process.features.get(&id.to_string()) {
                Some(p) => base.patched(p),
                None => base.clone(),
            };
            params.validate().map_err(|e| {
                Failure::new(
                    args.process.as_deref().unwrap_or(path),
                    format!("feature {id}: {e}"),
                )
            })?;
            let start = points.len();
            let (fig, freeform) = match f.kind {
                features::FeatureKind::Two5d => (
                    plan_two5d(t, f, &params, bead, &mut points, &mut cursor)
                        .map_err(|e| Failure::new(path, e))?,
                    None,
                ),
                features::FeatureKind::Freeform => {
                    let (fig, ff) = plan_freeform(t, f, &params, bead, &mut points, &mut cursor)
                        .map_err(|e| Failure::new(path, e))?;
                    (fig, Some(ff))
                }
            };
            for p in &mut points[start..] {
                p.feature = id;
            }
            planned.push(slicer::verify::PlannedFeature {
                id,
                kind: f.kind.as_str().to_string(),
                volume: f.volume,
                fill: params.filling_ratio,
                layers: fig.layers,
                extruded: fig.filament * filament_area,
            });
            let mut v = feature_json_fields(t, f, offset);
            let o = v.as_object_mut().expect("object");
            o.insert("layers".into(), json!(fig.layers));
            o.insert("points".into(), json!(points.len() - start));
            o.insert(
                "print_length_mm".into(),
                json!(round(fig.print_length, 1e3)),
            );
            o.insert(
                "travel_length_mm".into(),
                json!(round(fig.travel_length, 1e3)),
            );
            o.insert(
                "extruded_volume_mm3".into(),
                json!(round(fig.filament * filament_area, 1e3)),
            );
            o.insert("volume_mm3".into(), json!(round(f.volume, 1e3)));
            o.insert(
                "thickness_min_mm".into(),
                json!(round(fig.thickness.0, 1e6)),
            );
            o.insert(
                "thickness_mean_mm".into(),
                json!(round(fig.thickness.1, 1e6)),
            );
            o.insert(
                "thickness_max_mm".into(),
                json!(round(fig.thickness.2, 1e6)),
            );
            if let Some(ff) = freeform {
                o.insert("chart".into(), json!(ff.chart));
                o.insert("overhang_points".into(), json!(ff.overhang_points));
                o.insert(
                    "concave_radius_mm".into(),
                    if ff.concave_radius.is_finite() {
                        json!(round(ff.concave_radius, 1e3))
                    } else {
                        serde_json::Value::Null
                    },
                );
            }
            let mut fw = fig.warnings.clone();
            // Below the build plate (the base feature's reference plane): any point of the
            // feature, planned or not (a planar layer starts at its reference plane, so what
            // lies below that is not printed).
            if let Some(plate) = &plate {
                let planned = points[start..]
                    .iter()
                    .map(|q| -plate.height(&brep::math::P3::from(q.p)))
                    .fold(0.0f64, f64::max);
                let depth = planned.max(slicer::planar::depth_below(t, f, plate));
                if depth > 1e-3 {
                    let w = format!("feature {id} reaches {depth:.3} mm below the build plate");
                    fw.push(w.clone());
                    warnings.push(w);
                }
            }
            o.insert("warnings".into(), json!(fw));
            feature_values.push(v);
            bar.inc(1);
        }
        offset += t.features.len();
    }
    warnings.extend(assembly.all_warnings());
    bar.finish_and_clear();
    let mut toolpath = ToolPath { points };
    // Orientation smoothing between planning and posting.
    let orientation = smooth(&mut toolpath, &process.orientation);
    for v in &mut feature_values {
        let id = v["id"].as_u64().unwrap_or(u64::MAX) as usize;
        if let (Some(o), Some(fig)) = (v.as_object_mut(), orientation.get(&id)) {
            if let Ok(serde_json::Value::Object(m)) = serde_json::to_value(fig) {
                for (k, x) in m {
                    let x = x.as_f64().map(|f| json!(round(f, 1e6))).unwrap_or(x);
                    o.insert(k, x);
                }
            }
        }
    }
    let source = path.display().to_string();
    let stem = path
        .file_stem()
        .map(|s| s.to_string_lossy().to_string())
        .unwrap_or_else(|| "part".into());
    let job = robot_post::Job {
        source: &source,
        stem: &stem,
    };
    let program = machine
        .post()
        .post(&toolpath, &job)
        .map_err(|e| Failure::new(path, e))?;
    for v in &mut feature_values {
        let id = v["id"].as_u64().unwrap_or(u64::MAX) as usize;
        if let (Some(o), Some(k)) = (v.as_object_mut(), program.figures.get(&id)) {
            for (key, x) in k.named() {
                let x = match x {
                    FigureValue::Real(x) => json!(round(x, 1e6)),
                    FigureValue::Count(n) => json!(n),
                };
                o.insert(key.into(), x);
            }
        }
    }
    warnings.extend(program.warnings.iter().cloned());
    let mut files: Vec<(String, Vec<u8>)> = program
        .files
        .into_iter()
        .map(|f| (f.name, f.bytes))
        .collect();
    // The self-check: every feature got layers and the material it holds. A failure stops the
    // run before any file is written, unless --keep-going.
    let problems = slicer::verify::check_plan(&planned);
    if !problems.is_empty() {
        if !args.keep_going {
            for p in &problems {
                eprintln!("features: {}: {p}", path.display());
            }
            return Err(Failure::new(
                path,
                format!(
                    "the plan fails its self-check for {} feature(s) (listed above); nothing written (--keep-going writes it anyway)",
                    problems.len()
                ),
            ));
        }
        warnings.extend(problems.iter().map(|p| p.to_string()));
    }
    let plan = json!({
        "schema": "features.plan/1",
        "source": source,
        "machine": machine.name,
        "complete": problems.is_empty(),
        "features": feature_values,
        "warnings": warnings,
    });
    let mut plan_text = serde_json::to_string_pretty(&plan).map_err(|e| Failure::new(path, e))?;
    plan_text.push('\n');
    // Everything is ready: write the three files.
    let dir = &args.output;
    std::fs::create_dir_all(dir)
        .map_err(|e| Failure::new(dir, format!("cannot create output directory: {e}")))?;
    files.insert(0, ("plan.json".into(), plan_text.into_bytes()));
    files.insert(0, ("toolpath.csv".into(), toolpath.to_csv().into_bytes()));
    for (name, bytes) in &files {
        write_atomic(&dir.join(name), bytes)
            .map_err(|e| Failure::new(&dir.join(name), format!("cannot write: {e}")))?;
    }
    let print: f64 = feature_values
        .iter()
        .filter_map(|v| v["print_length_mm"].as_f64())
        .sum();
    let vol: f64 = feature_values
        .iter()
        .filter_map(|v| v["extruded_volume_mm3"].as_f64())
        .sum();
    // The plan's warnings (a feature below the build plate, overhangs, ...) on stderr too,
    // one line each, so a run in a terminal shows them, not only plan.json.
    for w in &warnings {
        eprintln!("features: {}: warning: {w}", path.display());
    }
    emit(&format!(
        "{}: {} feature(s), {} points, {:.1} mm printed, {:.1} mm^3 extruded -> {}\n",
        path.display(),
        feature_values.len(),
        toolpath.points.len(),
        print,
        vol,
        dir.display()
    ))
}

fn write_atomic(dest: &Path, bytes: &[u8]) -> std::io::Result<()> {
    let (tmp, file) = TempFile::create(dest)?;
    let mut w = std::io::BufWriter::new(file);
    w.write_all(bytes)?;
    w.flush()?;
    w.get_ref().sync_all()?;
    drop(w);
    tmp.persist(dest)
}
