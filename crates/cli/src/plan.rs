//! `features plan`: the settings, then [`plan::plan_file_into`] (every stage, its gates
//! included), then the plan's files written: all of them, or none.

use crate::mesh::write_atomic;
use crate::outputs::Outputs;
use crate::staged::{Fresh, Staged};
use crate::{emit, Failure, PlanArgs};
use plan::{Gate, Options, Placement, Plan, PlanError, Progress, Stage};
use std::io::Write as _;
use std::path::Path;

/// Runs the command.
pub fn run(args: &PlanArgs) -> Result<(), Failure> {
    let path = &args.part;
    // Settings first: a bad process or machine file fails before any work.
    let (process, machine) = plan::settings::load(&sources(args)).map_err(|e| Failure {
        path: e.origin,
        cause: e.cause,
    })?;
    // Then where the outputs go: a place holding files no plan wrote fails before any work too.
    let outputs = Outputs::from_arg(args.output.as_deref(), path, machine.kind)?;
    let earlier = outputs.claim(args.force)?;
    let bar = Bar::new(path);
    // STEP, or a mesh (STL, 3MF, OBJ) whose gaps within the process tolerance are welded.
    let file =
        brep::read_part(path, process.base().tolerance).map_err(|e| Failure::new(path, e))?;
    bar.0.inc(1);
    bar.0.set_prefix("planning");
    let progress = |p: Progress| bar.progress(p);
    let part_stem = path
        .file_stem()
        .map_or("part".into(), |s| s.to_string_lossy().into_owned());
    let options = Options {
        source: path.display().to_string(),
        stem: outputs.stem(&part_stem),
        placement: placement(args),
        keep_going: args.keep_going,
        allow_collisions: args.allow_collisions,
        allow_unreachable: args.allow_unreachable,
        strict: args.strict,
        progress: Some(&progress),
        // `inf`: no limit.
        placement_time_limit: std::time::Duration::try_from_secs_f64(args.placement_time_limit)
            .ok(),
        stop_at: None,
        fail_fast: false,
        known_unsupported: None,
    };
    // The program goes to its files as the post makes it, under temporary names until every
    // gate has passed (dropped on any failure: nothing written); toolpath.csv likewise. Each
    // placement tried starts afresh.
    let mut fresh = Fresh::new(&outputs);
    let result = plan::plan_file_to(&*file, &process, &machine, &options, &mut fresh);
    let staged = fresh.last();
    bar.0.inc(1);
    bar.0.set_prefix("writing");
    bar.0.set_message("outputs");
    let process_file = args.process.as_deref().unwrap_or(path);
    let refusal = Refusal {
        machine: &machine,
        outputs: &outputs,
        earlier: &earlier,
        bar: &bar,
    };
    let plan = result.map_err(|e| refusal.fail(e, path, process_file, options.placement))?;
    let staged = staged.ok_or_else(|| Failure::new(&outputs.dir, "no program was staged"))?;
    tell_placement(&plan, path, &bar);
    let warnings = print_warnings(&plan, path, &bar);
    let summary = write_plan(plan, &machine, &outputs, staged, &earlier, args, warnings)?;
    bar.0.inc(1);
    drop(bar);
    emit(&summary)
}

/// The settings' sources as the command line gives them.
fn sources(args: &PlanArgs) -> plan::settings::Sources {
    plan::settings::Sources {
        part: args.part.clone(),
        process: args.process.clone(),
        machine: args.machine.clone(),
        machine_profile: args.machine_profile.clone(),
        set: args.set.clone(),
    }
}

/// How the part is to stand, by `--base-face` and `--orient`; without either, as modelled or
/// the first other placement that plans ([`Placement::Find`]).
fn placement(args: &PlanArgs) -> Placement {
    match (args.base_face, args.orient.as_deref()) {
        (Some(id), _) => Placement::BaseFace(id),
        (None, Some("auto")) => Placement::Auto,
        (None, Some(_)) => Placement::AsModelled,
        (None, None) => Placement::Find,
    }
}

/// The remedy of a refusal another placement may avoid, for a placement the user chose.
fn placement_remedy(placement: Placement) -> &'static str {
    match placement {
        Placement::BaseFace(_) => "; another placement may plan: try --orient auto, or leave out --base-face to try the part as modelled, turned about +Z and the best planar faces",
        Placement::Auto => "; another placement may plan: leave out --orient to try the part as modelled, turned about +Z and the best planar faces",
        Placement::AsModelled => "; another placement may plan: leave out --orient modelled to try the part turned about +Z and on the best planar faces",
        Placement::Find => "",
    }
}

/// Where a refused plan's report and preview go.
struct Refusal<'a> {
    machine: &'a robot_post::MachineProfile,
    outputs: &'a Outputs,
    earlier: &'a [std::path::PathBuf],
    bar: &'a Bar,
}

impl Refusal<'_> {
    /// The line of a plan not made, or refused: a refusal's lines first (one per feature, or
    /// the warnings `--strict` refuses), and its `plan.json` and `preview.html` written to show
    /// why (no program).
    fn fail(
        &self,
        e: PlanError,
        path: &Path,
        process_file: &Path,
        placement: Placement,
    ) -> Failure {
        let bar = self.bar;
        let say = |line: &str| {
            bar.0
                .suspend(|| eprintln!("features: {}: {line}", path.display()))
        };
        let remedy = if plan::retry::placement_may_help(&e) {
            placement_remedy(placement)
        } else {
            ""
        };
        // Every other placement refused too: each with its failure, then the part as modelled.
        let e = match e {
            PlanError::NoPlacement {
                modelled,
                tried,
                stopped,
            } => {
                for t in &tried {
                    say(&format!("placement {} refused: {}", t.candidate, t.failure));
                }
                match stopped {
                    None => say("no placement plans: the part as modelled and every other placement tried (listed above) were refused; the refusal as modelled follows"),
                    Some(s) if tried.is_empty() => say(&format!("no placement plans: the part as modelled was refused and no other placement was tried; {s}; the refusal as modelled follows")),
                    Some(s) => say(&format!("no placement plans: the part as modelled and the {} other placement(s) tried (listed above) were refused; {s}; the refusal as modelled follows", tried.len())),
                }
                *modelled
            }
            e => e,
        };
        let (gate, plan) = match e {
            PlanError::Process(e) => return Failure::new(process_file, e),
            PlanError::Refused { gate, plan } => (gate, plan),
            e => return Failure::new(path, format!("{e}{remedy}")),
        };
        let (cause, allow) = match &gate {
            Gate::SelfCheck(problems) => {
                problems.iter().for_each(|p| say(&p.to_string()));
                (
                    format!(
                        "the plan fails its self-check for {} feature(s) (listed above){}",
                        problems.len(),
                        resolution_remedy(&plan, problems)
                    ),
                    " (--keep-going writes it anyway)",
                )
            }
            Gate::Unsupported(lines) => {
                lines.iter().for_each(|l| say(l));
                (
                    format!("{} feature(s) have layers nothing holds up within the overhang limit (listed above)", lines.len()),
                    " (--keep-going writes it anyway)",
                )
            }
            Gate::Collisions(lines) => {
                lines.iter().for_each(|l| say(l));
                (
                    format!(
                        "the print head collides in {} feature(s) (listed above)",
                        lines.len()
                    ),
                    " (--allow-collisions writes it anyway)",
                )
            }
            Gate::Strict(n) => {
                tell_placement(&plan, path, bar);
                print_warnings(&plan, path, bar);
                (format!("{n} warning(s) (listed above) and --strict"), "")
            }
            Gate::Unreachable(n) => {
                tell_placement(&plan, path, bar);
                print_warnings(&plan, path, bar);
                (
                    format!("{n} point(s) out of the arm's reach or joint limits (listed above)"),
                    " (--allow-unreachable writes the program anyway)",
                )
            }
            Gate::Machine(line) => (line.clone(), ""),
        };
        let written = match write_refused(&plan, self, path, &cause) {
            Ok(names) => format!("no program written; {} show why", names.join(" and ")),
            Err(f) => format!("nothing written ({}: {})", f.path, f.cause),
        };
        Failure::new(path, format!("{cause}: {written}{allow}{remedy}"))
    }
}

/// A refused plan's report and preview (and its colliding moves, when any) written to show why,
/// no program; the earlier plan's other files removed. Returns the names written.
fn write_refused(
    plan: &Plan,
    to: &Refusal,
    path: &Path,
    why: &str,
) -> Result<Vec<String>, Failure> {
    let (outputs, earlier) = (to.outputs, to.earlier);
    let dir = &outputs.dir;
    std::fs::create_dir_all(dir)
        .map_err(|e| Failure::new(dir, format!("cannot create output directory: {e}")))?;
    let written = |name: &str, r: std::io::Result<()>| {
        r.map_err(|e| Failure::new(&dir.join(name), format!("cannot write: {e}")))
    };
    let preview_name = outputs.name("preview.html");
    let page = crate::preview::refused_page(plan, &path.display().to_string(), to.machine, why);
    written(
        &preview_name,
        write_atomic(&dir.join(&preview_name), |w| w.write_all(page.as_bytes())),
    )?;
    let mut report = plan.report.clone();
    report.outputs = vec![preview_name.clone()];
    if !plan.collisions.left.is_empty() {
        let name = outputs.name("collisions.csv");
        written(
            &name,
            write_atomic(&dir.join(&name), |w| {
                plan::collisions::write_csv(&plan.collisions, w)
            }),
        )?;
        report.outputs.push(name);
    }
    let json = report.to_json().map_err(|e| Failure::new(path, e))?;
    let report_name = outputs.name("plan.json");
    written(
        &report_name,
        write_atomic(&dir.join(&report_name), |w| w.write_all(json.as_bytes())),
    )?;
    outputs.remove_stale(earlier, &report.outputs)?;
    let mut names = vec![report_name];
    names.extend(report.outputs);
    Ok(names)
}

/// Where the part stands, when it was turned or moved.
fn tell_placement(plan: &Plan, path: &Path, bar: &Bar) {
    if let Some(m) = &plan.report.moved_on_table {
        bar.0.suspend(|| {
            eprintln!(
                "features: {}: {} point(s) out of the arm's reach where the profile places the part: moved {:.1} mm on the table, to part_position [{}, {}]",
                path.display(),
                m.unreachable_before,
                m.distance_mm,
                m.part_position[0],
                m.part_position[1]
            )
        });
    }
    if let Some(p) = plan
        .report
        .placement
        .as_ref()
        .filter(|p| !p.tried.is_empty())
    {
        if !plan.report.complete {
            // A refusal as modelled, every other placement refused too: listed already.
            return;
        }
        let kind = plan.report.settings.machine["kind"].as_str().unwrap_or("");
        let on = match p.base_face {
            Some(id) => format!(
                "on face #{id} (outward normal {:.4} {:.4} {:.4} turned down)",
                p.down[0], p.down[1], p.down[2]
            ),
            None if plan.report.slicing == "planar" && !plus_z_only(kind) => {
                "as modelled, sliced whole in planar layers along +Z,".to_string()
            }
            None => "as modelled".to_string(),
        };
        let turn = if p.turn_deg == 0.0 {
            String::new()
        } else {
            format!(" turned {:.1} degrees about +Z", p.turn_deg)
        };
        let first = p.tried.first().map_or("", |t| t.failure.as_str());
        bar.0.suspend(|| {
            eprintln!(
                "features: {}: placed {on}{turn} after the part as modelled failed: {first} ({} placement(s) tried before it)",
                path.display(),
                p.tried.len()
            )
        });
        return;
    }
    if let Some(p) = &plan.report.placement {
        let d = p.down;
        let Some(face) = p.base_face else {
            return;
        };
        bar.0.suspend(|| {
            eprintln!(
                "features: {}: standing on face #{} (outward normal {:.4} {:.4} {:.4} turned down; {})",
                path.display(),
                face,
                d[0],
                d[1],
                d[2],
                p.rule
            )
        });
    }
}

/// Every warning on stderr, one line each, as plan.json holds them; their count.
fn print_warnings(plan: &Plan, path: &Path, bar: &Bar) -> usize {
    let warnings = plan.warnings();
    for w in &warnings {
        bar.0
            .suspend(|| eprintln!("features: {}: warning: {w}", path.display()));
    }
    warnings.len()
}

/// Writes the plan's files: the staged program and toolpath.csv, the preview, the colliding
/// moves left (when any), and plan.json last (a folder with plan.json holds a whole plan);
/// then the `earlier` plan's files this one did not write again are removed. Returns the
/// closing line to print.
fn write_plan(
    mut plan: Plan,
    machine: &robot_post::MachineProfile,
    outputs: &Outputs,
    staged: Staged,
    earlier: &[std::path::PathBuf],
    args: &PlanArgs,
    warnings: usize,
) -> Result<String, Failure> {
    let path = &args.part;
    let dir = &outputs.dir;
    std::fs::create_dir_all(dir)
        .map_err(|e| Failure::new(dir, format!("cannot create output directory: {e}")))?;
    let preview_name = outputs.name("preview.html");
    let joints_name = staged
        .names()
        .into_iter()
        .find(|n| n.ends_with("joints.csv"));
    let collisions_name =
        (!plan.collisions.left.is_empty()).then(|| outputs.name("collisions.csv"));
    plan.report.outputs = staged
        .names()
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
    // The simulation view reads the joints the post wrote.
    let joints = joints_name.map(|n| dir.join(n));
    let simulation = crate::simulation::simulation(&plan, machine, joints.as_deref());
    let page = crate::preview::plan_page(&plan, &path.display().to_string(), simulation);
    written(
        &preview_name,
        write_atomic(&dir.join(&preview_name), |w| preview::write_html(&page, w)),
    )?;
    if let Some(name) = &collisions_name {
        written(
            name,
            write_atomic(&dir.join(name), |w| {
                plan::collisions::write_csv(&plan.collisions, w)
            }),
        )?;
    }
    let report = outputs.name("plan.json");
    written(
        &report,
        write_atomic(&dir.join(&report), |w| w.write_all(json.as_bytes())),
    )?;
    outputs.remove_stale(earlier, &plan.report.outputs)?;
    Ok(summary_line(&plan, args, outputs, warnings))
}

/// The closing line: what was planned and where it went.
fn summary_line(plan: &Plan, args: &PlanArgs, outputs: &Outputs, warnings: usize) -> String {
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
    // Support material (issue 33): laid apart from the part's volume.
    let support: f64 = plan.features().iter().map(|f| f.support_volume_mm3).sum();
    let support = if support > 0.0 {
        format!(", {support:.1} mm^3 of support material")
    } else {
        String::new()
    };
    // Where it went: the folder, or the program file `-o` named.
    let to = outputs.shown();
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
    // Planar slicing `auto` chose (issue 33): on a machine printing only along +Z, because the
    // features' own directions were not +Z; on the others, because the feature-by-feature
    // plans were refused (the placement line before this one says why).
    let chosen = plan.report.settings.process["defaults"]["slicing"].as_str() == Some("auto");
    let kind = plan.report.settings.machine["kind"]
        .as_str()
        .unwrap_or("the machine");
    let overlap = plan
        .part_warnings
        .iter()
        .any(|w| w.kind == plan::WarningKind::OverlappingSolids);
    // A mesh (STL, 3MF, OBJ) is planned so whatever the settings: each body whole.
    let mesh = plan
        .features()
        .iter()
        .any(|f| f.feature.subtype == features::MESH_TWO5D);
    let planar = match (chosen && plan.report.slicing == "planar", plus_z_only(kind)) {
        _ if mesh => " sliced whole in planar layers along +Z (a mesh: each body one mesh_two5d feature),".to_string(),
        (false, _) => String::new(),
        (true, _) if overlap => {
            " sliced whole in planar layers along +Z (slicing auto: the part's solids overlap),"
                .to_string()
        }
        (true, true) => format!(
            " sliced whole in planar layers along +Z (slicing auto: `{kind}` prints only along +Z),"
        ),
        (true, false) => " sliced whole in planar layers along +Z (slicing auto: the feature-by-feature plan was refused),".to_string(),
    };
    format!(
        "{}: {} feature(s),{planar}{pedestal} {} points, {print:.1} mm printed, {vol:.1} mm^3 extruded{widened}{support}, {warnings} warning(s) -> {to}
",
        args.part.display(),
        plan.features().len(),
        plan.toolpath.points.len(),
    )
}

/// The run's progress bar over reading the part, each feature, the stages after them
/// ([`Stage::AFTER_FEATURES`]) and writing the outputs, with the time elapsed (hidden when
/// stderr is not a terminal); cleared when dropped (the run ended, or failed).
struct Bar(indicatif::ProgressBar, String);

impl Bar {
    fn new(path: &Path) -> Bar {
        let bar = Bar(
            crate::progress_bar("{prefix} {bar:30} {pos}/{len} {msg} [{elapsed}]"),
            path.display().to_string(),
        );
        bar.0.set_length(1);
        bar.0.set_prefix("reading");
        bar.0.set_message(path.file_name().map_or_else(
            || path.display().to_string(),
            |n| n.to_string_lossy().into_owned(),
        ));
        bar
    }

    /// Shows where the plan is.
    fn progress(&self, p: Progress) {
        match p {
            Progress::Trying {
                index,
                of,
                candidate,
                after,
            } => {
                let path = &self.1;
                self.0.suspend(|| {
                    if index == 1 {
                        eprintln!(
                            "features: {path}: as modelled: {after}; trying other placements"
                        );
                    } else {
                        eprintln!(
                            "features: {path}: placement {} of {of} refused: {after}",
                            index - 1
                        );
                    }
                    eprintln!("features: {path}: trying placement {index} of {of}: {candidate}")
                });
                self.0.set_position(0);
            }
            Progress::Start { features } => self
                .0
                .set_length(1 + features + Stage::AFTER_FEATURES.len() as u64 + 1),
            Progress::Feature { id } => self.0.set_message(format!("feature {id}")),
            Progress::FeatureDone => {
                // The feature's fills are freed: their pages go back before the next is laid.
                crate::memory::release_freed();
                self.0.inc(1)
            }
            Progress::Planned => {}
            Progress::Reporting => {
                let path = &self.1;
                self.0.suspend(|| {
                    eprintln!(
                        "features: {path}: no placement plans; planning the part as modelled in full for its report"
                    )
                });
                self.0.set_position(0);
            }
            Progress::Stage(stage) => {
                if stage != Stage::AFTER_FEATURES[0] {
                    self.0.inc(1);
                }
                self.0.set_message(stage.name());
            }
        }
    }
}

impl Drop for Bar {
    fn drop(&mut self) {
        self.0.finish_and_clear();
    }
}

/// Whether the machine of kind `kind` (as `plan.json` names it) prints only along +Z.
fn plus_z_only(kind: &str) -> bool {
    robot_post::MachineKind::from_name(kind).is_some_and(|k| k.plus_z_only())
}

/// What would print the features a self-check failed on, when they are below the nozzle's
/// resolution (issue 31, items 4 and 5): the finest nozzle those measured narrower than
/// `min_bead_width` need, or, for features with no layer at all, that they are smaller than
/// one layer of beads. Empty when neither.
fn resolution_remedy(plan: &Plan, problems: &[slicer::verify::PlanProblem]) -> String {
    let report = |id: usize| plan.features().iter().find(|f| f.feature.id == id);
    let nozzle = problems
        .iter()
        .filter_map(|p| report(p.id())?.below_resolution)
        .map(|b| b.nozzle_needed_mm)
        .fold(f64::INFINITY, f64::min);
    let unlaid = problems
        .iter()
        .filter(|p| matches!(p, slicer::verify::PlanProblem::NoLayers { .. }))
        .count();
    match (nozzle.is_finite(), unlaid) {
        (true, _) => format!(
            "; below the nozzle's resolution: a nozzle of {nozzle:.2} mm or finer would lay them"
        ),
        (false, n) if n > 0 => format!(
            "; {n} of them smaller than one layer of beads: below the nozzle's resolution (a finer nozzle and thinner layers would lay them)"
        ),
        _ => String::new(),
    }
}
