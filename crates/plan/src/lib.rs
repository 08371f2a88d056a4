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
pub mod process;
pub mod report;

pub use process::{Process, ProcessError};
pub use report::{FeatureEntry, FeatureReport, PlanReport};

use brep::math::P3;
use features::{extract_all, ExtractOptions, FeatureKind};
use report::{round, FreeformEntry, PostEntry, PLAN_SCHEMA};
use robot_post::machine::MachineProfile;
use robot_post::{Job, PostFigures, ProgramFile};
use slicer::freeform::plan_freeform;
use slicer::orient::{smooth, OrientationFigures};
use slicer::planar::plan_two5d;
use slicer::sequence;
use slicer::toolpath::ToolPath;
use slicer::verify::{check_plan, PlanProblem, PlannedFeature};

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
    /// The plan fails its self-check (and [`Options::keep_going`] is off): a feature has no
    /// layer, or its extruded volume is off its volume × fill.
    #[error("the plan fails its self-check for {} feature(s)", .0.len())]
    SelfCheck(Vec<PlanProblem>),
    /// The head meets material or the table on some moves (and
    /// [`Options::allow_collisions`] is off): one line per feature.
    #[error("the head collides in {} feature(s)", .0.len())]
    Collisions(Vec<String>),
}

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
}

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
    /// The machine program's files, in the order they are written.
    pub program: Vec<ProgramFile>,
}

impl Plan {
    /// The report's features.
    pub fn features(&self) -> &[FeatureReport] {
        &self.report.features
    }

    /// Things to know about the plan.
    pub fn warnings(&self) -> &[String] {
        &self.report.warnings
    }
}

/// Plans `part` for `machine` with the settings of `process`: every feature in build order,
/// then smoothing, the post and the self-check.
pub fn plan(
    part: &brep::StepPart,
    process: &Process,
    machine: &MachineProfile,
    options: &Options,
) -> Result<Plan, PlanError> {
    let tell = |p: Progress| {
        if let Some(f) = options.progress {
            f(p)
        }
    };
    let base = process.base();
    let bead = machine.bead();
    let filament_area = bead.filament_area();

    let assembly = extract_all(&part.brep, &ExtractOptions::default())?;
    let trees = &assembly.trees;
    tell(Progress::Start {
        features: trees.iter().map(|t| t.features.len() as u64).sum(),
    });

    let mut plans = vec![];
    let mut cursor: Option<P3> = None;
    let mut reports = vec![];
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
            tell(Progress::Feature { id });
            let params = process.params_for(&base, id)?;
            let plan = match f.kind {
                FeatureKind::Two5d => plan_two5d(t, f, &params, bead, cursor)?,
                FeatureKind::Freeform => plan_freeform(t, f, &params, bead, cursor)?,
            };
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
            // Below the build plate (the base feature's reference plane): any point of the
            // feature, planned or not (a planar layer starts at its reference plane, so what
            // lies below that is not printed).
            if let Some(plate) = &plate {
                let planned = plan
                    .points
                    .iter()
                    .map(|q| -plate.height(&P3::from(q.p)))
                    .fold(0.0f64, f64::max);
                let depth = planned.max(slicer::planar::depth_below(t, f, plate));
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
                }),
                warnings: fw,
                orientation: None,
                post: None,
                collision: Default::default(),
            });
            plans.push((id, plan));
            tell(Progress::FeatureDone);
        }
        offset += t.features.len();
    }
    warnings.extend(assembly.all_warnings());
    tell(Progress::Planned);
    // One tool path, features in build order with their file-wide ids.
    let mut toolpath = sequence(plans);
    // Orientation smoothing between planning and posting.
    let orientation = smooth(&mut toolpath, &process.orientation);
    for r in &mut reports {
        r.orientation = orientation.get(&r.feature.id).map(|o| OrientationFigures {
            step_max_deg_before: round(o.step_max_deg_before, 1e6),
            step_max_deg_after: round(o.step_max_deg_after, 1e6),
            rate_max_deg_per_mm_before: round(o.rate_max_deg_per_mm_before, 1e6),
            rate_max_deg_per_mm_after: round(o.rate_max_deg_per_mm_after, 1e6),
        });
    }
    // The head against what is built before each move and the table (issue 18).
    let collided = collisions::entries(&collisions::avoid(&mut toolpath, machine, &reports));
    let points = collisions::points(&toolpath);
    for r in &mut reports {
        r.collision = collided.get(&r.feature.id).cloned().unwrap_or_default();
        r.points = points.get(&r.feature.id).copied().unwrap_or(0);
    }
    let job = Job {
        source: &options.source,
        stem: &options.stem,
    };
    let program = machine.post().post(&toolpath, &job)?;
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
    };
    Ok(Plan {
        report,
        toolpath,
        program: program.files,
    })
}
