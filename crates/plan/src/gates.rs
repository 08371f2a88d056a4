//! The gates: what refuses a plan. Before the post, the self-check (every feature got layers
//! and the material it holds, `slicer::verify`) and the print head's collisions left; after the
//! post (whose figures they read), the points a robot cannot reach and `strict`'s warnings.
//! Each gate an option lets pass turns its lines into warnings instead.

use crate::head::Checked;
use crate::lay::LaidFeature;
use crate::report::{FailureEntry, PostEntry};
use crate::warning::{Warning, WarningKind};
use crate::{Gate, Options, Plan};
use slicer::verify::{check_plan, PlanProblem};

/// What the gates before the post let pass, as warnings of the part.
#[derive(Debug, Default)]
pub struct Passed {
    /// Whether every feature passed the self-check.
    pub complete: bool,
    /// The self-check's and the collisions' lines the options let pass.
    pub warnings: Vec<Warning>,
}

/// The gates before the post: the self-check, then support, then the collisions left.
pub fn before_post(
    features: &[LaidFeature],
    checked: &Checked,
    options: &Options,
) -> Result<Passed, Gate> {
    // The pedestal's first (printed first), then the part's features.
    let planned: Vec<_> = checked
        .pedestal_planned
        .iter()
        .cloned()
        .chain(features.iter().map(|f| f.planned.clone()))
        .collect();
    let problems = check_plan(&planned);
    let mut passed = Passed {
        complete: problems.is_empty(),
        warnings: vec![],
    };
    if !problems.is_empty() {
        if !options.keep_going {
            return Err(Gate::SelfCheck(problems));
        }
        passed.warnings.extend(
            problems
                .into_iter()
                .map(|p| Warning::part(WarningKind::SelfCheck(p))),
        );
    }
    // Support: every layer held up (issue 31).
    let unsupported: Vec<String> = features
        .iter()
        .filter_map(|f| crate::support::line(f.planned.id, f.held.as_ref()?))
        .collect();
    if !unsupported.is_empty() {
        if !options.keep_going {
            return Err(Gate::Unsupported(unsupported));
        }
        passed.complete = false;
        passed.warnings.extend(
            unsupported
                .into_iter()
                .map(|l| Warning::part(WarningKind::Unsupported(l))),
        );
    }
    let collided = crate::collisions::lines(&checked.collisions);
    if !collided.is_empty() {
        if !options.allow_collisions {
            return Err(Gate::Collisions(collided));
        }
        passed.warnings.extend(
            collided
                .into_iter()
                .map(|l| Warning::part(WarningKind::Collisions(l))),
        );
    }
    Ok(passed)
}

/// The gates after the post, on its figures: `strict` refuses any warning, then points the
/// robot cannot reach are refused unless allowed.
pub fn after_post(plan: &Plan, options: &Options) -> Result<(), Gate> {
    let warnings = plan.warnings().len();
    if options.strict && warnings > 0 {
        return Err(Gate::Strict(warnings));
    }
    let unreachable = plan.report.unreachable_points();
    if unreachable > 0 && !options.allow_unreachable {
        return Err(Gate::Unreachable(unreachable));
    }
    Ok(())
}

/// What `plan.json` lists of a refusal by `gate`: each failure with its feature and, where the
/// gate has one, its position.
pub fn failures(gate: &Gate, plan: &Plan) -> Vec<FailureEntry> {
    let entry = |feature: Option<usize>, position: Option<[f64; 3]>, text: String| FailureEntry {
        gate: gate.name(),
        feature,
        position,
        text,
    };
    match gate {
        Gate::SelfCheck(problems) => problems
            .iter()
            .map(|p| {
                let id = match p {
                    PlanProblem::NoLayers { id, .. } | PlanProblem::Volume { id, .. } => *id,
                };
                entry(Some(id), None, p.to_string())
            })
            .collect(),
        Gate::Unsupported(lines) => lines
            .iter()
            .map(|l| {
                let id = l
                    .strip_prefix("feature ")
                    .and_then(|r| r.split(' ').next())
                    .and_then(|n| n.parse().ok());
                entry(id, None, l.clone())
            })
            .collect(),
        Gate::Collisions(lines) => plan
            .features()
            .iter()
            .filter_map(|f| {
                let first = f.collision.first_collision.as_ref()?;
                let line = lines
                    .iter()
                    .find(|l| l.starts_with(&format!("feature {}:", f.feature.id)))?;
                Some(entry(Some(f.feature.id), Some(first.position), line.clone()))
            })
            .collect(),
        Gate::Strict(_) => plan
            .warnings()
            .iter()
            .map(|w| entry(None, None, w.to_string()))
            .collect(),
        Gate::Unreachable(_) => plan
            .features()
            .iter()
            .filter_map(|f| match f.post {
                Some(PostEntry::Kuka {
                    unreachable_points, ..
                }) if unreachable_points > 0 => Some(entry(
                    Some(f.feature.id),
                    None,
                    format!(
                        "feature {}: {unreachable_points} point(s) out of the arm's reach or joint limits",
                        f.feature.id
                    ),
                )),
                _ => None,
            })
            .collect(),
        Gate::Machine(line) => vec![entry(None, None, line.clone())],
    }
}

/// `plan` refused by `gate`: its report says so (`"complete": false`, the `failures`).
pub fn refused(gate: Gate, mut plan: Plan) -> crate::PlanError {
    plan.report.complete = false;
    plan.report.failures = failures(&gate, &plan);
    crate::PlanError::Refused {
        gate,
        plan: Box::new(plan),
    }
}
