//! plan: runs the pipeline for one STEP part — features (`features`), layers and paths of each
//! feature (`slicer`), tool-axis smoothing, the machine program (`robot-post`) and the
//! self-check — and returns it all as a [`Plan`], whose report is `plan.json`.
//!
//! ```no_run
//! let part = brep::read_step("fixtures/plate_boss_boss.step").unwrap();
//! let machine = robot_post::MachineProfile::builtin(robot_post::MachineKind::Marlin);
//! let plan = plan::plan(&part, &plan::Process::default(), &machine, &plan::Options::default());
//! ```

#![warn(missing_docs)]

pub mod collisions;
pub mod estimate;
pub mod pedestal;
pub mod process;
pub mod report;

pub use process::{Process, ProcessError};
pub use report::{FeatureEntry, FeatureReport, PlanReport, SettingsEntry};

use brep::math::P3;
use features::{extract_all, ExtractOptions};
use rayon::prelude::*;
use report::{round, FreeformEntry, PostEntry, PLAN_SCHEMA};
use robot_post::machine::MachineProfile;
use robot_post::{InMemory, Job, PostFigures, ProgramFile, ProgramSink};
use slicer::orient::{limit_tilt, smooth, OrientationFigures};

use slicer::params::{LayerParams, LayerStrategy};
use slicer::toolpath::{MoveKind, ToolPath};
use slicer::verify::{check_plan, PlanProblem, PlannedFeature, VOLUME_TOLERANCE};
use slicer::{fill_feature, sequence};

/// Why a part could not be planned. Each message is one line.
#[derive(Debug, thiserror::Error)]
pub enum PlanError {
    /// The part's features could not be recognised.
    #[error(transparent)]
    Extract(#[from] features::ExtractError),
    /// A feature's parameters (process file) are wrong.
    #[error(transparent)]
    Process(#[from] ProcessError),
    /// A feature could not be planned.
    #[error(transparent)]
    Feature(#[from] slicer::planar::PlanError),
    /// The post could not write the program.
    #[error(transparent)]
    Post(#[from] robot_post::PostError),
    /// `toolpath.csv` could not be written ([`plan_into`]'s `csv`).
    #[error("cannot write toolpath.csv: {0}")]
    Csv(#[source] std::io::Error),
    /// The plan fails its self-check (and [`Options::keep_going`] is off): a feature has no
    /// layer, or its extruded volume is off its volume × fill.
    #[error("the plan fails its self-check for {} feature(s)", .0.len())]
    SelfCheck(Vec<PlanProblem>),
    /// The head meets material or the table on some moves (and
    /// [`Options::allow_collisions`] is off): one line per feature.
    #[error("the head collides in {} feature(s)", .0.len())]
    Collisions(Vec<String>),
    /// The pedestal cannot lift the part clear of the table, or the one asked for cannot be
    /// made.
    #[error(transparent)]
    Pedestal(#[from] pedestal::PedestalError),
    /// The part needs more bead than one plan holds ([`MAX_BEAD_KM`]), estimated before any
    /// layer is made: nothing planned.
    #[error("the part's features hold {volume_m3:.3} m^3: at these layer heights and bead spacings that is at least {bead_km:.0} km of bead, more than the {MAX_BEAD_KM} km one plan holds (is the file's length unit right?); nothing planned")]
    TooBig {
        /// The features' volume, m³.
        volume_m3: f64,
        /// The bead they need at the least, km.
        bead_km: f64,
    },
}

/// The most bead one plan lays, km: some 60 million path points, gigabytes of path and
/// program (NIST CTC-05, half a metre across, lays 141 km). A part past it is refused before
/// any layer is made rather than planned until memory runs out (a building's model in
/// millimetres: thousands of cubic metres).
pub const MAX_BEAD_KM: f64 = 1000.0;

/// Where a plan is: reported to [`Options::progress`].
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Progress {
    /// Features recognised: this many will be planned.
    Start {
        /// Features in the part.
        features: u64,
    },
    /// Planning the feature of this file-wide id.
    Feature {
        /// Its id.
        id: usize,
    },
    /// That feature is planned.
    FeatureDone,
    /// Every feature is planned.
    Planned,
    /// One of the [`STAGES`] after the features begins (its name, as `STAGES` has it); the
    /// previous one, if any, is done.
    Stage(&'static str),
}

/// The stages of a plan after its features, in order, each reported by [`Progress::Stage`]
/// as it begins: a progress display counts them with the features.
pub const STAGES: [&str; 3] = [
    "smoothing tool axes",
    "checking the print head",
    "writing the program",
];

/// How to plan.
#[derive(Default)]
pub struct Options<'a> {
    /// The part's name in the report and the programs (its path as given).
    pub source: String,
    /// The part's file stem (KRL module names).
    pub stem: String,
    /// Return the plan even when it fails its self-check: the failures become warnings and the
    /// report says `"complete": false`.
    pub keep_going: bool,
    /// Return the plan even when the head meets material or the table on some moves: the
    /// lines become warnings (`plan.json` reports the moves either way).
    pub allow_collisions: bool,
    /// Told where the plan is.
    pub progress: Option<&'a (dyn Fn(Progress) + Sync)>,
}

/// A planned part.
#[derive(Debug)]
pub struct Plan {
    /// The report (`plan.json`).
    pub report: PlanReport,
    /// The tool path every feature is printed along, in build order.
    pub toolpath: ToolPath,
    /// The machine program's files, in the order they are written ([`plan`]; empty from
    /// [`plan_into`], which writes them into its sink).
    pub program: Vec<ProgramFile>,
    /// The features the part was planned as (one tree per solid), for previews.
    pub assembly: features::Assembly,
    /// The print head's colliding moves left after avoidance (`collisions.csv`).
    pub collisions: collisions::Avoided,
}

impl Plan {
    /// The report's features.
    pub fn features(&self) -> &[FeatureReport] {
        &self.report.features
    }

    /// Things to know about the plan: the part's warnings and every feature's, each once.
    pub fn warnings(&self) -> Vec<&str> {
        self.report.every_warning()
    }
}

/// Plans `part` for `machine` with the settings of `process`: every feature in build order,
/// then smoothing, the post and the self-check; the program's files are held in the plan
/// ([`Plan::program`]).
pub fn plan(
    part: &brep::StepPart,
    process: &Process,
    machine: &MachineProfile,
    options: &Options,
) -> Result<Plan, PlanError> {
    let mut files = InMemory::default();
    let mut plan = plan_into(part, process, machine, options, &mut files, None)?;
    plan.program = files.files;
    Ok(plan)
}

/// [`plan`], the program's files written into `sink` as the post makes them (the Marlin
/// program a megabyte at a time), not held: [`Plan::program`] is left empty. With `csv`, the
/// tool path's `toolpath.csv` ([`ToolPath::write_csv`]) is written into it at the same time,
/// on another thread (the two texts are the bulk of a large plan's writing). When the plan
/// fails its self-check or meets collisions (and the options do not allow that), the error
/// comes after the files were written: the sink's owner discards them, and `csv`'s.
pub fn plan_into(
    part: &brep::StepPart,
    process: &Process,
    machine: &MachineProfile,
    options: &Options,
    sink: &mut dyn ProgramSink,
    csv: Option<&mut (dyn std::io::Write + Send)>,
) -> Result<Plan, PlanError> {
    let tell = |p: Progress| {
        if let Some(f) = options.progress {
            f(p)
        }
    };
    process.validate_for_nozzle(machine.nozzle_diameter)?;
    let base = process.base();
    let bead = machine.bead();
    let filament_area = bead.filament_area();
    let min_bead = machine.min_bead_width();

    let assembly = extract_all(&part.brep, &ExtractOptions::default())?;
    let trees = &assembly.trees;
    process.validate_feature_ids(trees.iter().map(|t| t.features.len()).sum())?;
    // Each tree's build plate: its base feature's reference plane.
    let plates: Vec<_> = trees
        .iter()
        .map(|t| {
            t.features
                .first()
                .and_then(|b| slicer::planar::reference_plane(t, b))
        })
        .collect();
    tell(Progress::Start {
        features: trees.iter().map(|t| t.features.len() as u64).sum(),
    });

    // Every feature in build order: its tree, its index there and its file-wide id.
    let mut order = vec![];
    let mut offset = 0usize;
    for (ti, t) in trees.iter().enumerate() {
        for &k in &t.build_order {
            order.push((ti, k, offset));
        }
        offset += t.features.len();
    }
    // The bead the features need at the least (volume over the thickest layer and the widest
    // spacing their parameters allow), before any of it is made.
    let (mut volume, mut bead_mm) = (0.0, 0.0);
    for &(ti, k, offset) in &order {
        let f = &trees[ti].features[k];
        let params = process.params_for(&base, offset + f.id)?;
        let thickest = params
            .adaptive_layer_height
            .iter()
            .copied()
            .chain([params.uniform_layer_height, params.max_layer_height])
            .filter(|h| h.is_finite() && *h > 0.0)
            .fold(0.0f64, f64::max);
        let widest = params
            .adaptive_offset
            .iter()
            .copied()
            .chain([params.spacing(bead.width)])
            .filter(|s| s.is_finite() && *s > 0.0)
            .fold(0.0f64, f64::max);
        if f.volume.is_finite() && thickest > 0.0 && widest > 0.0 {
            volume += f.volume;
            bead_mm += f.volume / (thickest * widest);
        }
    }
    if bead_mm > MAX_BEAD_KM * 1e6 {
        return Err(PlanError::TooBig {
            volume_m3: volume * 1e-9,
            bead_km: bead_mm * 1e-6,
        });
    }
    // Features are filled (sectioned and filled layer by layer: the bulk of the work) a few
    // at a time in parallel, as many as there are threads, so memory holds no more than that
    // many fills; then laid one after the other, each from where the one before ended.
    let window = rayon::current_num_threads().max(1);
    let mut plans = vec![];
    let mut cursor: Option<P3> = None;
    let mut reports = vec![];
    let mut warnings: Vec<String> = vec![];
    let mut planned = vec![];
    for chunk in order.chunks(window) {
        let fills: Vec<Result<_, PlanError>> = chunk
            .par_iter()
            .map(|&(ti, k, offset)| {
                let t = &trees[ti];
                let f = &t.features[k];
                let params = process.params_for(&base, offset + f.id)?;
                let fill = fill_feature(t, f, &params, bead)?;
                Ok((params, fill))
            })
            .collect();
        for (&(ti, k, offset), fill) in chunk.iter().zip(fills) {
            let t = &trees[ti];
            let f = &t.features[k];
            let id = offset + f.id;
            tell(Progress::Feature { id });
            let (params, fill) = fill?;
            let mut plan = fill.lay(cursor);
            // Transition layers chosen by `auto` that miss the feature's volume by more than
            // the self-check allows: the feature on offset layers instead, said in a warning.
            let mut fallback = None;
            if params.layer_strategy == LayerStrategy::Auto
                && plan.freeform.is_some_and(|ff| ff.layers == "transition")
            {
                let expected = f.volume * params.filling_ratio;
                let rel = plan.figures.filament * filament_area / expected.max(1e-12) - 1.0;
                if rel.abs() > VOLUME_TOLERANCE {
                    let offset_params = LayerParams {
                        layer_strategy: LayerStrategy::Offset,
                        ..params.clone()
                    };
                    plan = fill_feature(t, f, &offset_params, bead)?.lay(cursor);
                    fallback = Some(format!(
                        "feature {id}: offset layers, not transition layers: these missed its volume by {:+.2} %",
                        100.0 * rel
                    ));
                }
            }
            plan.figures.warnings.extend(fallback);
            cursor = plan.exit().map(P3::from).or(cursor);
            let fig = &plan.figures;
            let extruded = fig.filament * filament_area;
            planned.push(PlannedFeature {
                id,
                kind: f.kind.as_str().to_string(),
                volume: f.volume,
                fill: params.filling_ratio,
                layers: fig.layers,
                extruded,
            });
            let mut fw = fig.warnings.clone();
            // Printability: beads narrower than the nozzle lays well (thin walls, blade tips)
            // are widened to min_bead_width, their filament with them.
            let narrow = widen_narrow_beads(&mut plan.points, min_bead);
            let widened = narrow.added_filament * filament_area;
            if narrow.points > 0 {
                fw.push(format!(
                    "feature {id}: {:.1} % of its print points ({} of {}) lay beads narrower than min_bead_width {min_bead} mm, down to {:.3} mm: widened to {min_bead} mm, {widened:.1} mm^3 more than planned ({:.1} % of the feature's {extruded:.1} mm^3)",
                    100.0 * narrow.points as f64 / narrow.prints.max(1) as f64,
                    narrow.points,
                    narrow.prints,
                    narrow.thinnest,
                    100.0 * widened / extruded.max(1e-12)
                ));
            }
            // Below the build plate (the base feature's reference plane): any point of the
            // feature, planned or not (a planar layer starts at its reference plane, so what
            // lies below that is not printed).
            if let Some(plate) = &plates[ti] {
                let planned = plan
                    .points
                    .iter()
                    .map(|q| -plate.height(&P3::from(q.p)))
                    .fold(0.0f64, f64::max);
                let depth = planned.max(plan.figures.below_plate);
                if depth > 1e-3 {
                    let w = format!("feature {id} reaches {depth:.3} mm below the build plate");
                    fw.push(w.clone());
                    warnings.push(w);
                }
            }
            reports.push(FeatureReport {
                feature: FeatureEntry::new(t, f, offset),
                layers: fig.layers,
                points: fig.points,
                print_length_mm: round(fig.print_length, 1e3),
                travel_length_mm: round(fig.travel_length, 1e3),
                extruded_volume_mm3: round(extruded, 1e3),
                widened_volume_mm3: round(widened, 1e3),
                thickness_min_mm: round(fig.thickness.0, 1e6),
                thickness_mean_mm: round(fig.thickness.1, 1e6),
                thickness_max_mm: round(fig.thickness.2, 1e6),
                freeform: plan.freeform.map(|ff| FreeformEntry {
                    chart: ff.chart.to_string(),
                    overhang_points: ff.overhang_points,
                    concave_radius_mm: ff
                        .concave_radius
                        .is_finite()
                        .then(|| round(ff.concave_radius, 1e3)),
                    layer_strategy: ff.layers.to_string(),
                }),
                warnings: fw,
                orientation: None,
                post: None,
                collision: Default::default(),
                pedestal_height_mm: None,
            });
            plans.push((id, plan));
            tell(Progress::FeatureDone);
        }
    }
    warnings.extend(assembly.all_warnings());
    tell(Progress::Planned);
    // One tool path, features in build order with their file-wide ids.
    let mut toolpath = sequence(plans);
    // Orientation smoothing between planning and posting; the planned axes are kept for the
    // tilt that clears the head (inside the same cone about them).
    tell(Progress::Stage(STAGES[0]));
    // (Only where the head may tilt: a 3-axis printer's axes stay +Z.)
    let limits = collisions::tilt_limits(machine, &process.orientation);
    let planned_axes: Vec<_> = match limits {
        Some(_) => toolpath.points.iter().map(|q| q.axis).collect(),
        None => vec![],
    };
    let orientation = smooth(&mut toolpath, &process.orientation);
    // A B/C bed: axes that curved layers tip past the B limit are tilted back to it, inside
    // the orientation's tolerance cone (half its opening); farther, the post refuses them.
    if let Ok(g) = machine.delta5_table() {
        let limit = g.b_limits_deg[0].abs().max(g.b_limits_deg[1].abs());
        let slack = 0.5 * process.orientation.cone_angle_deg;
        for (id, (n, worst)) in limit_tilt(&mut toolpath, limit, slack) {
            if let Some(r) = reports.iter_mut().find(|r| r.feature.id == id) {
                r.warnings.push(format!(
                    "feature {id}: {n} tool axes tilted by up to {worst:.3} degrees towards +Z to stay within the machine's B limit of {limit} degrees"
                ));
            }
        }
    }
    for r in &mut reports {
        r.orientation = orientation.get(&r.feature.id).map(|o| OrientationFigures {
            step_max_deg_before: round(o.step_max_deg_before, 1e6),
            step_max_deg_after: round(o.step_max_deg_after, 1e6),
            rate_max_deg_per_mm_before: round(o.rate_max_deg_per_mm_before, 1e6),
            rate_max_deg_per_mm_after: round(o.rate_max_deg_per_mm_after, 1e6),
        });
    }
    // The head against what is built before each move and the table (issue 18).
    tell(Progress::Stage(STAGES[1]));
    // The check, on the pedestal the process asks for (issue 31): the least that keeps the
    // head off the table, printed first as feature `offset` (the next free id).
    let ctx = pedestal::Context {
        trees,
        params: &process.params_for(&base, 0)?,
        setting: base.pedestal,
        bead,
        machine,
        id: offset,
        allow_collisions: options.allow_collisions,
    };
    let avoid = |p: &mut ToolPath, axes: &[slicer::vec3::V3]| {
        collisions::avoid(p, axes, machine, &reports, limits)
    };
    let checked = pedestal::stand(&ctx, toolpath, planned_axes, avoid)?;
    let (toolpath, avoided) = (checked.path, checked.avoided);
    warnings.extend(checked.warnings);
    if let Some(p) = &checked.pedestal {
        reports.insert(0, p.report(filament_area));
        planned.insert(0, p.planned(filament_area, ctx.params.filling_ratio));
    }
    let collided = collisions::entries(&avoided);
    let points = collisions::points(&toolpath);
    for r in &mut reports {
        r.collision = collided.get(&r.feature.id).cloned().unwrap_or_default();
        r.points = points.get(&r.feature.id).copied().unwrap_or(0);
    }
    let settings = settings_entry(process, machine, &base);
    // The estimate first in the header, as slicers write it, then the settings.
    let est = estimate::estimate(&toolpath, machine);
    let mut notes = vec![
        format!(
            "estimated printing time (normal mode) = {}",
            estimate::hms(est.time_s)
        ),
        format!("filament used [mm] = {:.2}", est.filament_mm),
        format!("filament used [g] = {:.2}", est.filament_g),
    ];
    notes.extend(checked.pedestal.as_ref().map(pedestal::Stood::line));
    notes.extend(settings.lines());
    tell(Progress::Stage(STAGES[2]));
    let job = Job {
        source: &options.source,
        stem: &options.stem,
        notes: &notes,
    };
    let post = machine.post();
    let (program, csv) = match csv {
        // The program on this thread, toolpath.csv on another (its blocks of lines made by
        // the thread pool, idle while the post writes).
        Some(w) => std::thread::scope(|scope| {
            let path = &toolpath;
            let lines = scope.spawn(move || path.write_csv(&mut &mut *w).and_then(|()| w.flush()));
            let program = post.post_to(&toolpath, &job, sink);
            // A panic in the writer is a panic of the plan, as on this thread.
            let csv = lines
                .join()
                .unwrap_or_else(|p| std::panic::resume_unwind(p));
            (program, csv)
        }),
        None => (post.post_to(&toolpath, &job, sink), Ok(())),
    };
    let program = program?;
    csv.map_err(PlanError::Csv)?;
    for r in &mut reports {
        r.post = program.figures.get(&r.feature.id).map(|k| match k {
            PostFigures::Delta5(k) => PostEntry::delta5(k),
            PostFigures::Kuka(k) => PostEntry::kuka(k),
        });
    }
    warnings.extend(program.warnings.iter().cloned());
    // The self-check: every feature got layers and the material it holds.
    let problems = check_plan(&planned);
    if !problems.is_empty() {
        if !options.keep_going {
            return Err(PlanError::SelfCheck(problems));
        }
        warnings.extend(problems.iter().map(|p| p.to_string()));
    }
    let collided = collisions::lines(&collided);
    if !collided.is_empty() {
        if !options.allow_collisions {
            return Err(PlanError::Collisions(collided));
        }
        warnings.extend(collided);
    }
    let report = PlanReport {
        schema: PLAN_SCHEMA,
        source: options.source.clone(),
        machine: machine.name.clone(),
        complete: problems.is_empty(),
        features: reports,
        warnings,
        estimated_time_s: round(est.time_s, 1e1),
        filament_mm: round(est.filament_mm, 1e2),
        filament_g: round(est.filament_g, 1e2),
        settings,
        placement: None,
        outputs: vec![],
    };
    Ok(Plan {
        report,
        toolpath,
        program: vec![],
        assembly,
        collisions: avoided,
    })
}

/// What [`widen_narrow_beads`] did to a feature's points.
struct Widened {
    /// Print points whose bead was narrower than the narrowest the nozzle lays well.
    points: usize,
    /// Print points of the feature.
    prints: usize,
    /// The narrowest of those beads (mm).
    thinnest: f64,
    /// Filament (mm) added by widening them.
    added_filament: f64,
}

/// Printability (issue 21): every print point whose bead is narrower than `min_bead` (a thin
/// wall's or a blade tip's, which the nozzle lays poorly) is widened to `min_bead`, its
/// filament scaled with the width (Eq. 1 is linear in it), so the nozzle lays a bead it can
/// and the material it takes is counted. The plan's self-check keeps comparing what was
/// planned for the feature's volume; the plan's report gives the volume added apart
/// (`widened_volume_mm3`), and the program and the estimate carry it.
fn widen_narrow_beads(points: &mut [slicer::toolpath::PathPoint], min_bead: f64) -> Widened {
    let mut w = Widened {
        points: 0,
        prints: 0,
        thinnest: f64::INFINITY,
        added_filament: 0.0,
    };
    for q in points.iter_mut().filter(|q| q.kind == MoveKind::Print) {
        w.prints += 1;
        if q.width < min_bead && q.width > 0.0 {
            w.points += 1;
            w.thinnest = w.thinnest.min(q.width);
            let e = q.e * min_bead / q.width;
            w.added_filament += e - q.e;
            q.e = e;
            q.width = min_bead;
        }
    }
    w
}

/// The settings of a plan, every key: the process's defaults with `base`'s values, each
/// overridden feature's full parameters, the smoothing, and the machine profile.
fn settings_entry(
    process: &Process,
    machine: &MachineProfile,
    base: &LayerParams,
) -> SettingsEntry {
    let json = |v: Result<serde_json::Value, serde_json::Error>| v.unwrap_or_default();
    let mut features = serde_json::Map::new();
    for (_, key) in process.feature_keys() {
        let p = base.patched(&process.features[key]);
        features.insert(key.clone(), json(serde_json::to_value(p)));
    }
    SettingsEntry {
        version: env!("CARGO_PKG_VERSION"),
        process: serde_json::json!({
            "defaults": json(serde_json::to_value(base)),
            "features": features,
            "orientation": json(serde_json::to_value(&process.orientation)),
        }),
        machine: json(serde_json::to_value(machine)),
    }
}
