//! The gates: what refuses a plan. Before the post, the self-check (every feature got layers
//! and the material it holds, `slicer::verify`) and the print head's collisions left; after the
//! post (whose figures they read), the points a robot cannot reach and `strict`'s warnings.
//! Each gate an option lets pass turns its lines into warnings instead.

use crate::head::Checked;
use crate::lay::LaidFeature;
use crate::warning::{Warning, WarningKind};
use crate::{Gate, Options, Plan};
use slicer::verify::check_plan;

/// What the gates before the post let pass, as warnings of the part.
#[derive(Debug, Default)]
pub struct Passed {
    /// Whether every feature passed the self-check.
    pub complete: bool,
    /// The self-check's and the collisions' lines the options let pass.
    pub warnings: Vec<Warning>,
}

/// The gates before the post: the self-check, then the collisions left.
pub fn before_post(
    features: &[LaidFeature],
    checked: &Checked,
    options: &Options,
) -> Result<Passed, Gate> {
    let planned: Vec<_> = features.iter().map(|f| f.planned.clone()).collect();
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
