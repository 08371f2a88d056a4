//! `features plan`: reads the settings and the part, runs [`plan::plan`] and writes its files.

use crate::mesh::write_atomic;
use crate::outputs::Outputs;
use crate::settings::settings;
use crate::staged::Staged;
use crate::{emit, Failure, PlanArgs};
use plan::{Options, PlanError, Progress};
use std::io::Write as _;

/// Runs the command.
pub fn run(args: &PlanArgs) -> Result<(), Failure> {
    let path = &args.part;
    // Settings first: a bad process or machine file fails before any work.
    let (process, machine) = settings(args)?;
    // Then where the outputs go: a place holding an earlier plan fails before any work too.
    let outputs = Outputs::from_arg(&args.output, machine.kind)?;
    let earlier = outputs.earlier();
    if !earlier.is_empty() && !args.force {
        return Err(Failure::new(
            &args.output,
            format!(
                "holds an earlier plan ({} file(s), e.g. {}): --force replaces it, or choose another output",
                earlier.len(),
                earlier[0].display()
            ),
        ));
    }
    // A feature's bad parameters are reported against the process file (or the part without one).
    let process_file = args.process.as_deref().unwrap_or(path);
    // One bar over the whole run (hidden when stderr is not a terminal): reading the part, each
    // feature, the stages after them (plan::STAGES) and writing the outputs, with the time
    // elapsed; cleared when the run ends, however it ends.
    let bar = Bar(crate::progress_bar(
        "{prefix} {bar:30} {pos}/{len} {msg} [{elapsed}]",
    ));
    bar.0.set_length(1);
    bar.0.set_prefix("reading");
    bar.0.set_message(path.file_name().map_or_else(
        || path.display().to_string(),
        |n| n.to_string_lossy().into_owned(),
    ));
    let auto = args.orient.as_deref() == Some("auto");
    let (part, placement) = crate::placement::read_placed(path, args.base_face, auto)?;
    bar.0.inc(1);
    bar.0.set_prefix("planning");
    if let Some(p) = &placement {
        let d = p.down;
        bar.0.suspend(|| {
            eprintln!(
            "features: {}: standing on face #{} (outward normal {:.4} {:.4} {:.4} turned down; {})",
            path.display(),
            p.base_face,
            d[0],
            d[1],
            d[2],
            p.rule
        )
        });
    }
    // Reading, the features, the stages after them, writing.
    let progress = |p: Progress| match p {
        Progress::Start { features } => bar
            .0
            .set_length(1 + features + plan::STAGES.len() as u64 + 1),
        Progress::Feature { id } => bar.0.set_message(format!("feature {id}")),
        Progress::FeatureDone => {
            // The feature's fills are freed: their pages go back before the next is laid.
            crate::memory::release_freed();
            bar.0.inc(1)
        }
        Progress::Planned => {}
        Progress::Stage(name) => {
            if name != plan::STAGES[0] {
                bar.0.inc(1);
            }
            bar.0.set_message(name);
        }
    };
    let part_stem = path
        .file_stem()
        .map_or("part".into(), |s| s.to_string_lossy().into_owned());
    let options = Options {
        source: path.display().to_string(),
        stem: outputs.stem(&part_stem),
        keep_going: args.keep_going,
        allow_collisions: args.allow_collisions,
        progress: Some(&progress),
    };
    // The program goes to its files as the post makes it, under temporary names until every
    // check below has passed (dropped on any failure: nothing written).
    let mut staged = Staged::new(&outputs);
    // toolpath.csv likewise, written beside the program as the plan ends.
    let mut csv = staged
        .open("toolpath.csv")
        .map_err(|e| Failure::new(&outputs.dir, format!("cannot write toolpath.csv: {e}")))?;
    let result = plan::plan_into(
        &part,
        &process,
        &machine,
        &options,
        &mut staged,
        Some(&mut csv),
    );
    drop(csv);
    bar.0.inc(1);
    bar.0.set_prefix("writing");
    bar.0.set_message("outputs");
    let mut plan = result.map_err(|e| match e {
        PlanError::Process(e) => Failure::new(process_file, e),
        PlanError::SelfCheck(problems) => {
            for p in &problems {
                bar.0.suspend(|| eprintln!("features: {}: {p}", path.display()));
            }
            let n = problems.len();
            Failure::new(path, format!("the plan fails its self-check for {n} feature(s) (listed above); nothing written (--keep-going writes it anyway)"))
        }
        PlanError::Collisions(lines) => {
            for l in &lines {
                bar.0.suspend(|| eprintln!("features: {}: {l}", path.display()));
            }
            let n = lines.len();
            Failure::new(path, format!("the print head collides in {n} feature(s) (listed above); nothing written (--allow-collisions writes it anyway)"))
        }
        e => Failure::new(path, e),
    })?;
    // Every warning on stderr, one line each, as plan.json holds them; before anything is
    // written, since --strict and unreachable points stop the plan here.
    let warnings: Vec<String> = plan.warnings().iter().map(|w| w.to_string()).collect();
    for w in &warnings {
        bar.0
            .suspend(|| eprintln!("features: {}: warning: {w}", path.display()));
    }
    if args.strict && !warnings.is_empty() {
        return Err(Failure::new(
            path,
            format!(
                "{} warning(s) (listed above) and --strict: nothing written",
                warnings.len()
            ),
        ));
    }
    let unreachable = plan.report.unreachable_points();
    if unreachable > 0 && !args.allow_unreachable {
        return Err(Failure::new(
            path,
            format!("{unreachable} point(s) out of the arm's reach or joint limits (listed above): nothing written (--allow-unreachable writes the program anyway)"),
        ));
    }
    // Everything is ready: write the files.
    let dir = &outputs.dir;
    std::fs::create_dir_all(dir)
        .map_err(|e| Failure::new(dir, format!("cannot create output directory: {e}")))?;
    if args.force {
        outputs.clear_earlier()?;
    }
    plan.report.placement = placement;
    // toolpath.csv and the program, as staged.
    let staged_names = staged.names();
    // The preview: the features and the path, in one page that opens offline.
    let preview_name = outputs.name("preview.html");
    let page = crate::preview::plan_page(&plan, &path.display().to_string());
    // The colliding moves left, one line each, where there are any.
    let collisions_name =
        (!plan.collisions.left.is_empty()).then(|| outputs.name("collisions.csv"));
    plan.report.outputs = staged_names
        .into_iter()
        .chain(std::iter::once(preview_name.clone()))
        .chain(collisions_name.clone())
        .collect();
    let json = plan.report.to_json().map_err(|e| Failure::new(path, e))?;
    let written = |name: &str, r: std::io::Result<()>| {
        r.map_err(|e| Failure::new(&dir.join(name), format!("cannot write: {e}")))
    };
    staged
        .commit()
        .map_err(|e| Failure::new(dir, format!("cannot write the program: {e}")))?;
    written(
        &preview_name,
        write_atomic(&dir.join(&preview_name), |w| w.write_all(page.as_bytes())),
    )?;
    if let Some(name) = &collisions_name {
        written(
            name,
            write_atomic(&dir.join(name), |w| {
                plan::collisions::write_csv(&plan.collisions, w)
            }),
        )?;
    }
    // The report last: a folder with plan.json holds a whole plan.
    let report = outputs.name("plan.json");
    written(
        &report,
        write_atomic(&dir.join(&report), |w| w.write_all(json.as_bytes())),
    )?;
    let print: f64 = plan.features().iter().map(|f| f.print_length_mm).sum();
    let widened: f64 = plan.features().iter().map(|f| f.widened_volume_mm3).sum();
    let vol = widened
        + plan
            .features()
            .iter()
            .map(|f| f.extruded_volume_mm3)
            .sum::<f64>();
    let widened = if widened > 0.0 {
        format!(" ({widened:.1} of it widening narrow beads)")
    } else {
        String::new()
    };
    bar.0.inc(1);
    drop(bar);
    // Where it went: the folder, or the program file `-o` named.
    let to = match &args.output {
        o if o.is_dir() => dir.display().to_string(),
        o => o.display().to_string(),
    };
    // The pedestal, if the part stands on one (issue 31).
    let pedestal = plan
        .features()
        .iter()
        .find_map(|f| {
            let h = f.pedestal_height_mm?;
            Some(format!(
                " on a pedestal of {h} mm ({} layers, feature {}),",
                f.layers, f.feature.id
            ))
        })
        .unwrap_or_default();
    emit(&format!(
        "{}: {} feature(s),{pedestal} {} points, {print:.1} mm printed, {vol:.1} mm^3 extruded{widened}, {} warning(s) -> {to}\n",
        path.display(),
        plan.features().len(),
        plan.toolpath.points.len(),
        warnings.len(),
    ))
}

/// The run's progress bar, cleared when dropped (the run ended, or failed).
struct Bar(indicatif::ProgressBar);

impl Drop for Bar {
    fn drop(&mut self) {
        self.0.finish_and_clear();
    }
}
