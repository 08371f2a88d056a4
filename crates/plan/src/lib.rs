//! plan: runs the stages for one STEP part and returns it all as a [`Plan`], whose report is
//! `plan.json`. The stages ([`Stage`]), each a function in its own module taking the previous
//! stage's value and returning its own:
//!
//! read (`brep::StepFile`, or a mesh file: `brep::FacetedFile`) → [`place`] → [`extract`] → [`lay`] (fill and lay each feature, in
//! parallel; then sequence them into one tool path) → [`smooth`] → [`head`] (the print head's
//! check and avoidance; then the skirt and brim on the first layer, [`adhesion`]) → [`gates`] (self-check, collisions; refused plans stop here) →
//! [`post`] (the program) → [`gates::after_post`] (reach, `strict`). The report is built once,
//! from the stages' values, by [`assemble`].
//!
//! ```no_run
//! let part = brep::read_step("fixtures/plate_boss_boss.step").unwrap();
//! let machine = robot_post::MachineProfile::builtin(robot_post::MachineKind::Marlin);
//! let plan = plan::plan(&part, &plan::Process::default(), &machine, &plan::Options::default());
//! ```

#![warn(missing_docs)]

pub mod adhesion;
pub mod assemble;
pub mod collisions;
pub mod error;
pub mod estimate;
pub mod extract;
pub mod gates;
pub mod head;
pub mod lay;
pub mod pedestal;
pub mod place;
pub mod post;
pub mod process;
pub mod reach;
pub mod report;
pub mod resolution;
pub mod retry;
pub mod settings;
pub mod smooth;
pub mod stage;
pub mod support;
mod tolerance;
pub mod warning;

pub use error::{Gate, PlanError};
pub use place::Placement;
pub use process::{Process, ProcessError};
pub use report::{FeatureEntry, FeatureReport, PlanReport, SettingsEntry};
pub use retry::{Candidate, Outputs};
pub use stage::Stage;
pub use warning::{Warning, WarningKind};

use extract::Extracted;
use report::PlacementEntry;
use robot_post::machine::MachineProfile;
use robot_post::{InMemory, ProgramFile, ProgramSink};
use slicer::toolpath::ToolPath;

/// The most bead one plan lays, km: some 60 million path points, gigabytes of path and
/// program (NIST CTC-05, half a metre across, lays 141 km). A part past it is refused before
/// any layer is made rather than planned until memory runs out (a building's model in
/// millimetres: thousands of cubic metres).
pub const MAX_BEAD_KM: f64 = 1000.0;

/// Where a plan is: reported to [`Options::progress`].
#[derive(Debug, Clone, PartialEq)]
pub enum Progress {
    /// The part as modelled was refused, and another placement is tried ([`retry`]): a whole
    /// plan of its own, whose stages are reported next.
    Trying {
        /// Its place among the placements tried after the part as modelled (1 first).
        index: usize,
        /// How many are queued so far (a turn to fit may be added after a candidate).
        of: usize,
        /// The placement ([`Candidate::label`]).
        candidate: String,
        /// Why the previous one was refused.
        after: String,
    },
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
    /// One of [`Stage::AFTER_FEATURES`] begins; the previous one, if any, is done.
    Stage(Stage),
    /// No placement plans, and the part as modelled was given up at its first unsupported
    /// curved feature ([`Options::fail_fast`]): it is planned again in full, for the refusal
    /// reported (whose stages are reported next).
    Reporting,
}

/// How to plan.
#[derive(Default, Clone)]
pub struct Options<'a> {
    /// The part's name in the report and the programs (its path as given).
    pub source: String,
    /// The part's file stem (KRL module names).
    pub stem: String,
    /// How the part stands on the plate ([`plan_file_into`]; [`plan`] and [`plan_into`] take
    /// the part as it is).
    pub placement: Placement,
    /// Return the plan even when it fails its self-check: the failures become warnings and the
    /// report says `"complete": false`.
    pub keep_going: bool,
    /// Return the plan even when the head meets material or the table on some moves: the
    /// lines become warnings (`plan.json` reports the moves either way).
    pub allow_collisions: bool,
    /// Return the plan even when a robot cannot reach some of its points.
    pub allow_unreachable: bool,
    /// Refuse a plan with any warning.
    pub strict: bool,
    /// Told where the plan is.
    pub progress: Option<&'a (dyn Fn(Progress) + Sync)>,
    /// The most time [`retry::find`] spends on a part, the plan as modelled included: past
    /// it no other placement is begun, the one being planned is given up, and the refusal
    /// says so ([`retry::Stopped`]). `None`: no limit.
    pub placement_time_limit: Option<std::time::Duration>,
    /// Past this instant the plan is given up ([`PlanError::TimeLimit`]), checked before each
    /// group of features is laid and before each stage after them: [`retry::find`] sets it
    /// for the placements after the part as modelled. `None`: never.
    pub stop_at: Option<std::time::Instant>,
    /// Give the plan up at the first group of features laid with a curved feature whose
    /// layers the support gate refuses ([`PlanError::Unsupported`], no plan), unless
    /// [`Options::keep_going`]: the rest is not laid. [`retry::find`] sets it for the
    /// placements it tries, and plans the part as modelled again in full when none plans.
    pub fail_fast: bool,
    /// Curved features an earlier placement of the part found not held up: with
    /// [`Options::fail_fast`], a plan that extracts one again is refused for it before anything
    /// is laid, and one that finds another adds it ([`support::KnownUnsupported`]).
    pub known_unsupported: Option<&'a support::KnownUnsupported>,
}

impl Options<'_> {
    /// [`PlanError::TimeLimit`] once [`Options::stop_at`] has passed.
    pub fn in_time(&self) -> Result<(), PlanError> {
        in_time(self.stop_at)
    }
}

/// [`PlanError::TimeLimit`] once `stop_at` has passed (`None`: never).
pub fn in_time(stop_at: Option<std::time::Instant>) -> Result<(), PlanError> {
    match stop_at {
        Some(t) if std::time::Instant::now() >= t => Err(PlanError::TimeLimit),
        _ => Ok(()),
    }
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
    /// The part's warnings as typed values, in the report's order (its `warnings` are their
    /// texts): what a caller branches on.
    pub part_warnings: Vec<Warning>,
    /// Per feature with a machining allowance (file-wide id), the points of its nominal faces
    /// where the allowance left was measured and what was left (issue 37, item 2): the
    /// preview's colours.
    pub allowance_left: std::collections::BTreeMap<usize, Vec<slicer::allowance::AllowanceSample>>,
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

/// Plans `part` for `machine` with the settings of `process`, the program's files held in the
/// plan ([`Plan::program`]).
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
/// tool path's `toolpath.csv` is written into it at the same time, on another thread. A plan
/// the gates before the post refuse writes nothing; one refused after it (reach, `strict`)
/// has written into `sink` and `csv`, whose owner discards them.
pub fn plan_into(
    part: &brep::StepPart,
    process: &Process,
    machine: &MachineProfile,
    options: &Options,
    sink: &mut dyn ProgramSink,
    csv: Option<&mut (dyn std::io::Write + Send)>,
) -> Result<Plan, PlanError> {
    let extracted = extract::extract(part, process, machine)?;
    run(extracted, None, process, machine, options, sink, csv)
}

/// [`plan_into`] for the part of a parsed STEP file, stood on the plate as
/// [`Options::placement`] says ([`place`]).
pub fn plan_file_into(
    file: &dyn brep::PartFile,
    process: &Process,
    machine: &MachineProfile,
    options: &Options,
    sink: &mut dyn ProgramSink,
    csv: Option<&mut (dyn std::io::Write + Send)>,
) -> Result<Plan, PlanError> {
    let placed = place::place(file, options.placement, process, machine.bead().width)?;
    plan_placed_into(placed, process, machine, options, sink, csv)
}

/// [`plan_file_into`] writing into `out`: with [`Placement::Find`], the part as modelled and,
/// when that plan is refused for something another placement may avoid, the other placements
/// in turn ([`retry::find`]), each written afresh into `out` so that only the chosen plan's
/// files are left in it; otherwise the one placement asked for.
pub fn plan_file_to(
    file: &dyn brep::PartFile,
    process: &Process,
    machine: &MachineProfile,
    options: &Options,
    out: &mut dyn Outputs,
) -> Result<Plan, PlanError> {
    if options.placement == Placement::Find {
        return retry::find(file, process, machine, options, out);
    }
    let (sink, csv) = out.fresh().map_err(PlanError::Csv)?;
    plan_file_into(file, process, machine, options, sink, csv)
}

/// [`plan_into`] for a part already stood on the plate.
pub fn plan_placed_into(
    placed: place::Placed,
    process: &Process,
    machine: &MachineProfile,
    options: &Options,
    sink: &mut dyn ProgramSink,
    csv: Option<&mut (dyn std::io::Write + Send)>,
) -> Result<Plan, PlanError> {
    process.validate_for_nozzle(machine.nozzle_diameter)?;
    let extracted = match placed.assembly {
        Some(assembly) => extract::arrange(assembly, &placed.part.brep, process, machine)?,
        None => extract::extract(&placed.part, process, machine)?,
    };
    run(
        extracted,
        placed.entry,
        process,
        machine,
        options,
        sink,
        csv,
    )
}

/// The stages from the features on.
fn run(
    extracted: Extracted,
    placement: Option<PlacementEntry>,
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
    tell(Progress::Start {
        features: extracted.order.len() as u64,
    });
    let laid = lay::lay(&extracted, process, machine, options, &tell)?;
    options.in_time()?;
    tell(Progress::Stage(Stage::Smooth));
    let smoothed = smooth::smooth(laid.toolpath, process, machine);
    options.in_time()?;
    tell(Progress::Stage(Stage::HeadCheck));
    let mut checked = if head::unsupported(&laid.features, options) {
        head::unchecked(smoothed)
    } else {
        head::head_check(
            smoothed,
            &extracted,
            process,
            machine,
            &laid.features,
            options,
        )?
    };
    let mut warnings = laid.warnings;
    let adhesion = adhesion::lay(
        &mut checked.toolpath,
        &mut checked.avoided.left,
        &process.base(),
        machine,
    )
    .unwrap_or_else(|w| {
        warnings.push(w);
        None
    });
    let stages = assemble::Stages {
        extracted,
        placement,
        features: laid.features,
        warnings,
        checked,
        adhesion,
    };
    options.in_time()?;
    let passed = match gates::before_post(&stages.features, &stages.checked, options) {
        Ok(passed) => passed,
        Err(gate) => return Err(refuse(gate, stages, process, machine, options)),
    };
    tell(Progress::Stage(Stage::Post));
    // A KUKA part out of the arm's reach is moved on the table first.
    let moved = reach::into_reach(&stages.checked.toolpath, machine, options);
    let machine = moved.as_ref().map_or(machine, |m| &m.machine);
    let toolpath = &stages.checked.toolpath;
    let ((settings, est, program), written) = post::beside_csv(toolpath, csv, || {
        let (settings, est, notes) = post::header(&stages.checked, process, machine);
        let program = post::post(toolpath, machine, &process.base(), options, &notes, sink);
        (settings, est, program)
    });
    let program = match program.and_then(|p| written.map(|()| p)) {
        Ok(program) => program,
        Err(PlanError::Post(e)) => {
            let plan = stages.assemble(machine, options, None, passed, &est, settings);
            return Err(gates::refused(Gate::Machine(e.to_string()), plan));
        }
        Err(e) => return Err(e),
    };
    let posted = assemble::Posted {
        program: &program,
        moved: moved.as_ref(),
    };
    let plan = stages.assemble(machine, options, Some(posted), passed, &est, settings);
    match gates::after_post(&plan, options) {
        Ok(()) => Ok(plan),
        Err(gate) => Err(gates::refused(gate, plan)),
    }
}

/// A plan refused by a gate before the post: the machine's own refusal first, when its post
/// would refuse the path too (it is what a user fixes first), else the gate's, with the plan
/// as far as it went (`"complete": false`, its `failures`).
fn refuse(
    gate: Gate,
    stages: assemble::Stages,
    process: &Process,
    machine: &MachineProfile,
    options: &Options,
) -> PlanError {
    let (settings, est, notes) = post::header(&stages.checked, process, machine);
    let gate = match post::post(
        &stages.checked.toolpath,
        machine,
        &process.base(),
        options,
        &notes,
        &mut post::Discard,
    ) {
        Err(e) => Gate::Machine(e.to_string()),
        Ok(_) => gate,
    };
    let passed = gates::Passed {
        complete: false,
        warnings: vec![],
    };
    gates::refused(
        gate,
        stages.assemble(machine, options, None, passed, &est, settings),
    )
}
