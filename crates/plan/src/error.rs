//! Why a part was not planned ([`PlanError`]), and why a plan that was made is refused
//! ([`Gate`]).

use crate::Plan;
use slicer::verify::PlanProblem;

/// Why a part could not be planned, or why its plan is refused. Each message is one line.
#[derive(Debug, thiserror::Error)]
pub enum PlanError {
    /// The part could not be stood on the plate as asked.
    #[error(transparent)]
    Place(#[from] crate::place::PlaceError),
    /// The part's features could not be recognised.
    #[error(transparent)]
    Extract(#[from] features::ExtractError),
    /// A feature's parameters (process file) are wrong.
    #[error(transparent)]
    Process(#[from] crate::ProcessError),
    /// A feature could not be planned.
    #[error(transparent)]
    Feature(#[from] slicer::planar::FeatureError),
    /// The post could not write the program.
    #[error(transparent)]
    Post(#[from] robot_post::PostError),
    /// The pedestal cannot lift the part clear of the table, or the one asked for cannot be
    /// made.
    #[error(transparent)]
    Pedestal(#[from] crate::pedestal::PedestalError),
    /// `toolpath.csv` could not be written ([`crate::plan_into`]'s `csv`).
    #[error("cannot write toolpath.csv: {0}")]
    Csv(#[source] std::io::Error),
    /// The part needs more bead than one plan holds ([`crate::MAX_BEAD_KM`]), estimated
    /// before any layer is made: nothing planned.
    #[error("the part's features hold {volume_m3:.3} m^3: at these layer heights and bead spacings that is at least {bead_km:.0} km of bead, more than the {} km one plan holds (is the file's length unit right?); nothing planned", crate::MAX_BEAD_KM)]
    TooBig {
        /// The features' volume, m³.
        volume_m3: f64,
        /// The bead they need at the least, km.
        bead_km: f64,
    },
    /// The part as modelled was refused (`modelled`, the refusal reported) and so was every
    /// other placement tried ([`crate::retry`]): each with what it failed on.
    #[error("{modelled}")]
    NoPlacement {
        /// The refusal of the part as modelled.
        modelled: Box<PlanError>,
        /// The other placements tried and their failures, in the order tried.
        tried: Vec<crate::report::TriedEntry>,
        /// When the search stopped at [`crate::Options::placement_time_limit`]: what it left
        /// untried. `None`: every placement queued was tried.
        stopped: Option<crate::retry::Stopped>,
    },
    /// The plan was given up at its first curved feature whose layers are not held up
    /// ([`crate::Options::fail_fast`]): the features after it were not laid, and there is no
    /// plan to show; one [`crate::support::line`] for each feature of its group of features.
    /// Or refused before anything was laid, for a curved feature an earlier placement found
    /// so ([`crate::support::KnownUnsupported`]).
    #[error("layers not held up: {} ({})", lines.join("; "), if *earlier { "as an earlier placement laid the same curved feature: its layers do not change with the placement; nothing of this one was laid" } else { "found as the features were laid; the rest of the plan was not made" })]
    Unsupported {
        /// The features found unsupported, one line each.
        lines: Vec<String>,
        /// Known from an earlier placement, not laid in this one.
        earlier: bool,
    },
    /// The plan was given up at [`crate::Options::stop_at`] (the placement time limit of
    /// [`crate::retry::find`]).
    #[error("given up at the placement time limit")]
    TimeLimit,
    /// The plan was made, and a gate refuses it: the plan is here to show why (its report
    /// says `"complete": false`), but no program was written.
    #[error("{gate}")]
    Refused {
        /// What refused it.
        gate: Gate,
        /// The plan refused.
        plan: Box<Plan>,
    },
}

/// A gate that refuses a plan ([`crate::gates`]).
#[derive(Debug, Clone, PartialEq)]
pub enum Gate {
    /// The self-check fails (and [`crate::Options::keep_going`] is off): a feature has no
    /// layer, or its extruded volume is off its volume × fill.
    SelfCheck(Vec<PlanProblem>),
    /// Some layers are not held up within the overhang limit (and
    /// [`crate::Options::keep_going`] is off): one line per feature
    /// ([`crate::support::line`]).
    Unsupported(Vec<String>),
    /// The head meets material or the table on some moves (and
    /// [`crate::Options::allow_collisions`] is off): one line per feature.
    Collisions(Vec<String>),
    /// The plan has warnings and [`crate::Options::strict`] is on.
    Strict(usize),
    /// Points the robot cannot reach (and [`crate::Options::allow_unreachable`] is off).
    Unreachable(usize),
    /// The machine cannot make the path (its post's checks: the bed, the work envelope, a B/C
    /// bed's limits, a 3-axis printer's tool axis): the post's line.
    Machine(String),
}

impl Gate {
    /// Its name in `plan.json`'s `failures`.
    pub fn name(&self) -> &'static str {
        match self {
            Gate::SelfCheck(_) => "selfcheck",
            Gate::Unsupported(_) => "unsupported",
            Gate::Collisions(_) => "collisions",
            Gate::Strict(_) => "strict",
            Gate::Unreachable(_) => "reach",
            Gate::Machine(_) => "machine",
        }
    }
}

impl std::fmt::Display for Gate {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Gate::SelfCheck(p) => {
                write!(
                    f,
                    "the plan fails its self-check for {} feature(s)",
                    p.len()
                )
            }
            Gate::Unsupported(l) => write!(f, "{} feature(s) have unsupported layers", l.len()),
            Gate::Collisions(l) => write!(f, "the head collides in {} feature(s)", l.len()),
            Gate::Strict(n) => write!(f, "{n} warning(s) and strict"),
            Gate::Unreachable(n) => {
                write!(f, "{n} point(s) out of the arm's reach or joint limits")
            }
            Gate::Machine(line) => f.write_str(line),
        }
    }
}
