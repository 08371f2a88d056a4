//! `features plan`: reads the settings and the part, runs [`plan::plan`] and writes its files.

use crate::mesh::write_atomic;
use crate::settings::settings;
use crate::{emit, Failure, PlanArgs};
use plan::{Options, PlanError, Progress};
use std::io::Write as _;

/// Runs the command.
pub fn run(args: &PlanArgs) -> Result<(), Failure> {
    let path = &args.part;
    // Settings first: a bad process or machine file fails before any work.
    let (process, machine) = settings(args)?;
    // A feature's bad parameters are reported against the process file (or the part without one).
    let process_file = args.process.as_deref().unwrap_or(path);
    let part = brep::read_step(path).map_err(|e| Failure::new(path, e))?;
    let bar = crate::progress_bar("planning {bar:30} {pos}/{len} features {msg}");
    let progress = |p: Progress| match p {
        Progress::Start { features } => bar.set_length(features),
        Progress::Feature { id } => bar.set_message(format!("feature {id}")),
        Progress::FeatureDone => bar.inc(1),
        Progress::Planned => bar.finish_and_clear(),
    };
    let options = Options {
        source: path.display().to_string(),
        stem: path
            .file_stem()
            .map_or("part".into(), |s| s.to_string_lossy().into()),
        keep_going: args.keep_going,
        allow_collisions: args.allow_collisions,
        progress: Some(&progress),
    };
    let plan = plan::plan(&part, &process, &machine, &options).map_err(|e| match e {
        PlanError::Process(e) => Failure::new(process_file, e),
        PlanError::SelfCheck(problems) => {
            for p in &problems {
                eprintln!("features: {}: {p}", path.display());
            }
            let n = problems.len();
            Failure::new(path, format!("the plan fails its self-check for {n} feature(s) (listed above); nothing written (--keep-going writes it anyway)"))
        }
        PlanError::Collisions(lines) => {
            for l in &lines {
                eprintln!("features: {}: {l}", path.display());
            }
            let n = lines.len();
            Failure::new(path, format!("the print head collides in {n} feature(s) (listed above); nothing written (--allow-collisions writes it anyway)"))
        }
        e => Failure::new(path, e),
    })?;
    let json = plan.report.to_json().map_err(|e| Failure::new(path, e))?;
    // Everything is ready: write the files.
    let dir = &args.output;
    std::fs::create_dir_all(dir)
        .map_err(|e| Failure::new(dir, format!("cannot create output directory: {e}")))?;
    let written = |name: &str, r: std::io::Result<()>| {
        r.map_err(|e| Failure::new(&dir.join(name), format!("cannot write: {e}")))
    };
    // The tool path is written point by point, not built as one text first.
    let csv = "toolpath.csv";
    written(
        csv,
        write_atomic(&dir.join(csv), |w| plan.toolpath.write_csv(w)),
    )?;
    let files = std::iter::once(("plan.json", json.as_bytes())).chain(
        plan.program
            .iter()
            .map(|f| (f.name.as_str(), f.bytes.as_slice())),
    );
    for (name, bytes) in files {
        written(name, write_atomic(&dir.join(name), |w| w.write_all(bytes)))?;
    }
    // The plan's warnings on stderr too, one line each, so a terminal shows them.
    for w in plan.warnings() {
        eprintln!("features: {}: warning: {w}", path.display());
    }
    let print: f64 = plan.features().iter().map(|f| f.print_length_mm).sum();
    let vol: f64 = plan.features().iter().map(|f| f.extruded_volume_mm3).sum();
    emit(&format!(
        "{}: {} feature(s), {} points, {print:.1} mm printed, {vol:.1} mm^3 extruded -> {}\n",
        path.display(),
        plan.features().len(),
        plan.toolpath.points.len(),
        dir.display()
    ))
}
