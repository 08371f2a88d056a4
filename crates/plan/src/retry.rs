//! Placement found, not assumed (issue 31): when the plan of the part as modelled is refused
//! for something another placement may avoid ([`placement_may_help`]: unsupported beads, the
//! head meeting material or the table, even on the tallest pedestal, a tool axis the machine
//! cannot take, the bed or work envelope, the arm's reach), [`find`] plans the other
//! placements ([`Candidate`]) in turn and keeps the first whose plan passes every gate.
//!
//! **The rule.** The candidates, in the order tried ([`candidates`]):
//!
//! 1. when the part as modelled leaves the bed or the work envelope, the part turned about the
//!    build direction (+Z) by the least turn that fits ([`robot_post::fit::turn_to_fit`] on
//!    its tool path; a turn changes nothing else, so it comes first);
//! 2. the part's other planar faces turned down, best first as `--orient auto` ranks them
//!    ([`crate::place::ranked_faces`]), at most [`MAX_FACES`] of them;
//! 3. last, when the process leaves `slicing` at `auto` and the part was planned feature by
//!    feature, the part as modelled sliced whole in planar layers along +Z
//!    ([`Candidate::Planar`], [`crate::extract::planar_assembly`]), as a planar slicer prints
//!    it, with support material under what overhangs: no tilt, so no axis beyond the machine's
//!    limits and no head below its layers. It is also the one candidate tried after a failed
//!    self-check ([`planar_may_help`]): small split-off features (pins, contacts) that their
//!    own layers cannot hold are laid with the part around them. Not when the part as
//!    modelled already is that plan ([`planar_may_help`]). Also after a curved feature's
//!    offsets fold (paper, Fig. 9), which planar layers cannot.
//!
//! None is planned when no placement can fit the machine: the part as modelled measures
//! across more than any placement holds ([`robot_post::fit::largest_across`]).
//!
//! A candidate that leaves the bed or envelope in its turn is tried once more turned to fit,
//! right after it; when no turn fits, that is listed among the failures. The first candidate that plans wins; the report's `placement` says which
//! and lists what the ones before it failed on (`tried`, the part as modelled first). When
//! none plans, the refusal of the part as modelled is returned, with every candidate's
//! failure ([`PlanError::NoPlacement`]).
//!
//! With [`crate::Options::placement_time_limit`] the search stops at the limit, the plan in
//! progress given up ([`crate::Options::stop_at`]); the refusal says so ([`Stopped`]).
//!
//! Each candidate is a whole plan, written afresh into the caller's [`Outputs`] (a refused
//! attempt's files are dropped with it), so only the chosen plan's files are left.
//!
//! **Given up early.** Every attempt, the part as modelled's too, stops at the first group of
//! features with a curved feature whose layers are not held up ([`crate::Options::fail_fast`],
//! [`PlanError::Unsupported`]): the support gate would refuse it whatever came after, and its
//! failure names that feature. When no placement plans and the part as modelled was given up
//! so, it is planned again in full ([`Progress::Reporting`]): the refusal reported is a whole
//! plan, with every feature's failures, for `plan.json` and the preview. (The impeller on
//! delta5: 11.0 s before, 5.4 s with it, the same program; docs/measurements.md.)
//!
//! **Known before it is laid.** A curved feature's layers lie on its reference surface along
//! its own tool axes and are measured against the layer below along them, so a placement
//! that extracts the same curved feature again finds the same unsupported area: the features
//! one attempt finds so are remembered ([`crate::support::KnownUnsupported`]), and a later
//! attempt that extracts one of them is refused for it before anything is laid (its failure
//! says so). The impeller's face #3661: refused in 0.4 s where laying it again took 1.7 s.

use crate::place::{entry_turned, Placed};
use crate::report::{PlacementEntry, TriedEntry};
use crate::{Gate, Options, Plan, PlanError, Process, Progress};
use brep::PartFile;
use robot_post::machine::MachineProfile;
use robot_post::ProgramSink;

/// The most planar faces tried after the part as modelled, best first.
pub const MAX_FACES: usize = 4;

/// The share of what the part as modelled measures across ([`none_fits`]) that another
/// placement's tool path may measure less: its layers cut the part elsewhere, and reach each
/// of its extremes to within about half a bead and half a layer (1 mm across with the
/// built-in profiles' 0.45 mm beads and 0.2 mm layers).
const ACROSS_SLACK_SHARE: f64 = 0.02;

/// ... and as much again, mm. With 5 % and 5 mm before, NIST CTC-05 on delta5 (558 mm across
/// its print points, 531.6 mm held) was planned in other placements until the 150 s limit.
const ACROSS_SLACK_MM: f64 = 2.0;

/// The `features plan` default of [`crate::Options::placement_time_limit`], seconds: the
/// slowest corpus parts refused in every placement stop in time for a 240 s budget
/// (docs/measurements.md).
pub const DEFAULT_TIME_LIMIT_S: f64 = 150.0;

/// Where plans are written: afresh for each placement tried, so that only the chosen plan's
/// files are left ([`crate::plan_file_to`]).
pub trait Outputs {
    /// A program sink and a `toolpath.csv` writer with nothing in them: whatever an earlier
    /// call gave is dropped.
    #[allow(clippy::type_complexity)]
    fn fresh(
        &mut self,
    ) -> std::io::Result<(
        &mut dyn ProgramSink,
        Option<&mut (dyn std::io::Write + Send)>,
    )>;
}

impl Outputs for crate::post::Discard {
    fn fresh(
        &mut self,
    ) -> std::io::Result<(
        &mut dyn ProgramSink,
        Option<&mut (dyn std::io::Write + Send)>,
    )> {
        Ok((self, None))
    }
}

impl Outputs for robot_post::InMemory {
    fn fresh(
        &mut self,
    ) -> std::io::Result<(
        &mut dyn ProgramSink,
        Option<&mut (dyn std::io::Write + Send)>,
    )> {
        self.files.clear();
        Ok((self, None))
    }
}

/// One placement [`find`] tries. New kinds are appended here and in [`candidates`], and
/// planned in [`Candidate::plan`].
#[derive(Debug, Clone, PartialEq)]
pub enum Candidate {
    /// The part as modelled (−Z down), turned about +Z by `turn_deg` (0: as modelled).
    Modelled {
        /// Degrees, counter-clockwise seen from above.
        turn_deg: f64,
    },
    /// The part as modelled, each solid sliced whole in planar layers along +Z (the process
    /// key `slicing = "planar"`), turned about +Z by `turn_deg`.
    Planar {
        /// Degrees, counter-clockwise seen from above.
        turn_deg: f64,
    },
    /// The part on a planar face: its outward normal turned down, then turned about +Z by
    /// `turn_deg`.
    Face {
        /// STEP `#id` of the largest planar face pointing that way.
        id: u64,
        /// The outward normal (file frame).
        down: [f64; 3],
        /// Its place in `--orient auto`'s order (1: its choice).
        rank: usize,
        /// Degrees, counter-clockwise seen from above.
        turn_deg: f64,
    },
}

impl Candidate {
    /// The part as modelled.
    pub const MODELLED: Candidate = Candidate::Modelled { turn_deg: 0.0 };

    /// What stderr and `plan.json` call it.
    pub fn label(&self) -> String {
        let turn = |t: f64| {
            if t == 0.0 {
                String::new()
            } else {
                format!(" turned {t:.1} degrees about +Z")
            }
        };
        match *self {
            Candidate::Modelled { turn_deg } => format!("the part as modelled{}", turn(turn_deg)),
            Candidate::Planar { turn_deg } => format!(
                "the part as modelled, sliced whole in planar layers along +Z{}",
                turn(turn_deg)
            ),
            Candidate::Face {
                id,
                down,
                rank,
                turn_deg,
            } => format!(
                "face #{id} (outward normal {:.4} {:.4} {:.4} down, #{rank} by --orient auto){}",
                // + 0.0: no "-0.0000".
                down[0] + 0.0,
                down[1] + 0.0,
                down[2] + 0.0,
                turn(turn_deg)
            ),
        }
    }

    /// The turn about +Z.
    fn turn_deg(&self) -> f64 {
        match *self {
            Candidate::Modelled { turn_deg }
            | Candidate::Planar { turn_deg }
            | Candidate::Face { turn_deg, .. } => turn_deg,
        }
    }

    /// This candidate turned further by `deg` about +Z.
    fn turned(&self, deg: f64) -> Candidate {
        let mut c = self.clone();
        match &mut c {
            Candidate::Modelled { turn_deg }
            | Candidate::Planar { turn_deg }
            | Candidate::Face { turn_deg, .. } => *turn_deg += deg,
        }
        c
    }

    /// The rotation standing the part so (rows first): plate = rotation × file.
    pub fn rotation(&self) -> [[f64; 3]; 3] {
        let base = match *self {
            Candidate::Modelled { .. } | Candidate::Planar { .. } => {
                [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]]
            }
            Candidate::Face { down, .. } => brep::turn_down(down),
        };
        let (s, c) = self.turn_deg().to_radians().sin_cos();
        let z = [[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]];
        [0, 1, 2].map(|r| [0, 1, 2].map(|k| (0..3).map(|j| z[r][j] * base[j][k]).sum()))
    }

    /// What `plan.json` records of it, with `rule`.
    fn entry(&self, rule: String) -> PlacementEntry {
        let (face, down) = match *self {
            Candidate::Modelled { .. } | Candidate::Planar { .. } => (None, [0.0, 0.0, -1.0]),
            Candidate::Face { id, down, .. } => (Some(id), down),
        };
        let mut e = entry_turned(face, down, self.rotation(), rule);
        e.turn_deg = crate::report::round(self.turn_deg(), 1e9);
        e
    }

    /// Its whole plan, written into `sink` and `csv`.
    pub fn plan(
        &self,
        file: &dyn PartFile,
        process: &Process,
        machine: &MachineProfile,
        options: &Options,
        sink: &mut dyn ProgramSink,
        csv: Option<&mut (dyn std::io::Write + Send)>,
    ) -> Result<Plan, PlanError> {
        let part = match *self {
            Candidate::Modelled { turn_deg: 0.0 } | Candidate::Planar { turn_deg: 0.0 } => {
                file.part()
            }
            Candidate::Modelled { .. } | Candidate::Planar { .. } | Candidate::Face { .. } => {
                file.rotated(self.rotation())
            }
        };
        let part = part.map_err(crate::place::PlaceError::from)?;
        let assembly = match self {
            Candidate::Planar { .. } => Some(crate::extract::planar_assembly(&part.brep)?),
            Candidate::Modelled { .. } | Candidate::Face { .. } => None,
        };
        let placed = Placed {
            part,
            assembly,
            entry: None,
        };
        crate::plan_placed_into(placed, process, machine, options, sink, csv)
    }
}

/// Whether another placement may avoid the failure `e`: unsupported beads, collisions, a
/// refusal of the machine's post (the bed or envelope, B beyond the limits, a 3-axis printer's
/// tool axis), points out of reach, the head meeting the table even on the tallest pedestal.
/// Not the self-check, `strict`'s warnings, a part too big, without features, or a file or
/// setting in error: no placement changes those.
pub fn placement_may_help(e: &PlanError) -> bool {
    use crate::pedestal::PedestalError;
    match e {
        PlanError::Refused { gate, .. } => matches!(
            gate,
            Gate::Unsupported(_) | Gate::Collisions(_) | Gate::Machine(_) | Gate::Unreachable(_)
        ),
        PlanError::Unsupported { .. } => true,
        PlanError::Pedestal(p) => matches!(
            p,
            PedestalError::TooLow { .. } | PedestalError::NoneClears { .. }
        ),
        _ => false,
    }
}

/// Whether the part sliced whole in planar layers ([`Candidate::Planar`]) may avoid the
/// failure `e` of the part planned feature by feature: what [`placement_may_help`] lists, and
/// a failed self-check (features their own layers cannot hold). Only while the process leaves
/// `slicing` at `auto` and the failed plan was not planar already.
pub fn planar_may_help(e: &PlanError, process: &Process) -> bool {
    if process.base().slicing != slicer::params::Slicing::Auto {
        return false;
    }
    match e {
        PlanError::Refused { plan, .. }
            if plan.report.slicing == "planar" || is_planar_already(plan) =>
        {
            false
        }
        PlanError::Refused {
            gate: Gate::SelfCheck(_),
            ..
        } => true,
        // A curved feature's offsets folding (a machining allowance can take its layers past a
        // valley's radius): planar layers of the whole part have no reference to fold.
        PlanError::Feature(slicer::planar::FeatureError::OffsetFolds { .. }) => true,
        _ => placement_may_help(e),
    }
}

/// Whether `plan` is what slicing the part whole in planar layers along +Z plans: one solid,
/// one two5d feature (the whole solid: nothing split off) on the build plate, growing along
/// +Z, nothing of it below the plate (the whole solid's layers start at its lowest point).
/// Sliced whole, it would be planned and refused the same way. Several solids are not: sliced
/// whole, they are laid together in the same layers ([`features::whole_part_features`]).
fn is_planar_already(plan: &Plan) -> bool {
    let one_each = plan.assembly.trees.len() == 1
        && plan
            .assembly
            .trees
            .iter()
            .all(|t| match t.features.as_slice() {
                [f] => {
                    f.kind == features::FeatureKind::Two5d
                        && f.parents.is_empty()
                        && f.reference.surface == "build_plate"
                        && f.reference
                            .normal
                            .is_some_and(|n| n[2] > crate::tolerance::SAME_DIRECTION_DOT)
                }
                _ => false,
            });
    one_each
        && !plan
            .warnings()
            .iter()
            .any(|w| w.contains(crate::warning::BELOW_PLATE))
}

/// What a turn about +Z does for `c`, refused with `e`: `None` when `e` is no refusal by the
/// machine, `c` is turned already, its plan has unsupported layers or collisions (which a
/// turn keeps), or it fits unturned (the refusal is not the bed or envelope); else `c` turned by the least turn that fits the bed or work envelope
/// ([`robot_post::fit::turn_to_fit`] on its tool path), or why none does.
fn turned_to_fit(
    c: &Candidate,
    e: &PlanError,
    machine: &MachineProfile,
    options: &Options,
) -> Option<Result<Candidate, TriedEntry>> {
    let PlanError::Refused {
        gate: Gate::Machine(_),
        plan,
    } = e
    else {
        return None;
    };
    // A turn changes nothing but where the part lies on the machine: it cannot help a plan
    // whose layers are unsupported or whose head collides (the machine's refusal, reported
    // first, hides those).
    let held = plan.features().iter().all(|f| {
        (options.keep_going || f.unsupported_area_mm2 == 0.0)
            && (options.allow_collisions || f.collision.collisions == 0)
    });
    if c.turn_deg() != 0.0 || !held {
        return None;
    }
    match robot_post::fit::turn_to_fit_until(&plan.toolpath, machine, options.stop_at) {
        Ok(fit) => (fit.angle_deg != 0.0).then(|| Ok(c.turned(fit.angle_deg))),
        Err(e @ robot_post::fit::FitError::NoTurn { .. }) => Some(Err(TriedEntry {
            candidate: format!("{} turned about +Z", c.label()),
            failure: e.to_string(),
        })),
        Err(_) => None,
    }
}

/// Why no placement can fit the machine, when none can: the part as modelled (`e`'s plan,
/// its print points but the pedestal's, the support material's, the skirt's and the brim's)
/// measures across more than any placement holds ([`robot_post::fit::largest_across`]), by
/// more than another placement's path may measure less ([`ACROSS_SLACK_SHARE`],
/// [`ACROSS_SLACK_MM`]). Then
/// every other placement would be refused too, and none is planned.
fn none_fits(e: &PlanError, machine: &MachineProfile) -> Option<TriedEntry> {
    let PlanError::Refused { plan, .. } = e else {
        return None;
    };
    let holds = robot_post::fit::largest_across(machine).ok()??;
    let pedestals: Vec<usize> = plan
        .features()
        .iter()
        .filter(|f| f.pedestal_height_mm.is_some())
        .map(|f| f.feature.id)
        .collect();
    let across = robot_post::fit::across(
        plan.toolpath
            .points
            .iter()
            .filter(|q| {
                q.kind == slicer::toolpath::MoveKind::Print
                    && q.role.is_part()
                    && !pedestals.contains(&(q.feature as usize))
            })
            .map(|q| q.p),
    );
    (across * (1.0 - ACROSS_SLACK_SHARE) - ACROSS_SLACK_MM > holds).then(|| TriedEntry {
        candidate: "every other placement".into(),
        failure: format!(
            "none fits: the part measures at least {across:.1} mm across, more than the {holds:.1} mm `{}` holds in any placement",
            machine.name
        ),
    })
}

/// The placements to try after the part as modelled was refused, in order (module docs):
/// the other planar faces, best first, at most [`MAX_FACES`]. A turn to fit is tried after
/// any candidate that leaves the bed or envelope ([`find`]). Append new kinds at the end.
pub fn candidates(
    file: &dyn PartFile,
    process: &Process,
    machine: &MachineProfile,
) -> Result<Vec<Candidate>, PlanError> {
    let faces = crate::place::ranked_faces(file, process, machine.bead().width)?;
    Ok(faces
        .iter()
        .enumerate()
        .filter(|(_, f)| !f.as_modelled)
        .take(MAX_FACES)
        .map(|(k, f)| Candidate::Face {
            id: f.id,
            down: f.down,
            rank: k + 1,
            turn_deg: 0.0,
        })
        .collect())
}

/// The placement time limit reached ([`find`], [`crate::Options::placement_time_limit`]):
/// the search stopped, and these placements were not tried.
#[derive(Debug, Clone, PartialEq)]
pub struct Stopped {
    /// The limit, seconds.
    pub limit_s: f64,
    /// The placements queued and not tried (or given up part-way), in order
    /// ([`Candidate::label`]).
    pub untried: Vec<String>,
}

impl std::fmt::Display for Stopped {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let untried = match self.untried.len() {
            0 => String::new(),
            n => format!(
                ", {n} placement(s) not tried or given up ({})",
                self.untried.join("; ")
            ),
        };
        write!(
            f,
            "the search for a placement stopped at its time limit of {} s{untried}: raise the limit (--placement-time-limit SECONDS, inf: none) or choose the placement (--base-face ID, --orient auto, --set slicing=planar)",
            self.limit_s
        )
    }
}

/// Plans the part as modelled and, when it is refused for something another placement may
/// avoid, the other [`candidates`] in turn; the first that plans is returned, its report's
/// `placement` saying which and what the ones before it failed on. Every attempt is written
/// afresh into `out`.
///
/// With [`crate::Options::placement_time_limit`], the time is counted from the start, the
/// plan as modelled included: past the limit no other placement is begun and the one being
/// planned is given up ([`crate::Options::stop_at`]); the refusal lists what was tried and
/// what was not ([`Stopped`]).
pub fn find(
    file: &dyn PartFile,
    process: &Process,
    machine: &MachineProfile,
    options: &Options,
    out: &mut dyn Outputs,
) -> Result<Plan, PlanError> {
    let stop_at = options
        .placement_time_limit
        .and_then(|l| std::time::Instant::now().checked_add(l));
    let attempt = |c: &Candidate, options: &Options, out: &mut dyn Outputs| {
        let (sink, csv) = out.fresh().map_err(PlanError::Csv)?;
        c.plan(file, process, machine, options, sink, csv)
    };
    // Every attempt is given up at its first curved feature the support gate refuses; the
    // part as modelled is planned again in full if no placement plans (its refusal is the
    // one reported, with its plan to show).
    let given = options;
    // Curved features found not held up, for the placements after (their layers are the
    // same in every placement).
    let known = crate::support::KnownUnsupported::default();
    let fast = Options {
        fail_fast: true,
        known_unsupported: Some(&known),
        ..options.clone()
    };
    let mut first = match attempt(&Candidate::MODELLED, &fast, out) {
        Err(e) if placement_may_help(&e) || planar_may_help(&e, process) => e,
        done => return done,
    };
    // The other placements are given up at the limit (or the caller's own, if sooner).
    let options = &Options {
        stop_at: match (stop_at, options.stop_at) {
            (Some(a), Some(b)) => Some(a.min(b)),
            (a, b) => a.or(b),
        },
        ..fast
    };
    let mut tried = vec![TriedEntry {
        candidate: Candidate::MODELLED.label(),
        failure: first.to_string(),
    }];
    let mut queue = vec![];
    // Whether the limit came before the other placements were listed.
    let mut unlisted = false;
    // No placement fits the machine: none is planned.
    let too_big = none_fits(&first, machine);
    let fits_nowhere = too_big.is_some();
    if let Some(t) = too_big {
        tried.push(t);
    } else if placement_may_help(&first) {
        unlisted = options.in_time().is_err();
        if !unlisted {
            match turned_to_fit(&Candidate::MODELLED, &first, machine, options) {
                Some(Ok(t)) => queue.push(t),
                Some(Err(none)) => tried.push(none),
                None => {}
            }
            unlisted = options.in_time().is_err();
        }
        if !unlisted {
            queue.extend(candidates(file, process, machine)?);
        }
    }
    if planar_may_help(&first, process) && !fits_nowhere {
        queue.push(Candidate::Planar { turn_deg: 0.0 });
    }
    // The previous attempt's failure.
    let mut last = first.to_string();
    let mut stopped = None;
    let mut k = 0;
    while k < queue.len() {
        let c = queue[k].clone();
        if options.in_time().is_err() {
            stopped = Some(k);
            break;
        }
        if let Some(f) = options.progress {
            f(Progress::Trying {
                index: k + 1,
                of: queue.len(),
                candidate: c.label(),
                after: last.clone(),
            });
        }
        match attempt(&c, options, out) {
            Ok(mut plan) => {
                let rule = format!(
                    "found: the part as modelled was refused ({}); the first placement tried that plans",
                    tried[0].failure
                );
                let mut entry = c.entry(rule);
                entry.tried = tried;
                plan.report.placement = Some(entry);
                return Ok(plan);
            }
            Err(PlanError::TimeLimit) => {
                stopped = Some(k);
                break;
            }
            Err(e) => {
                let turn = turned_to_fit(&c, &e, machine, options);
                last = e.to_string();
                tried.push(TriedEntry {
                    candidate: c.label(),
                    failure: e.to_string(),
                });
                match turn {
                    Some(Ok(t)) => queue.insert(k + 1, t),
                    Some(Err(none)) => tried.push(none),
                    None => {}
                }
            }
        }
        k += 1;
    }
    // Stopped by the limit: at the `k`-th placement queued, or before the faces were listed.
    let untried = |k: usize| -> Vec<String> {
        let mut u: Vec<String> = queue[k..].iter().map(Candidate::label).collect();
        if unlisted {
            u.insert(0, format!("the planar faces, up to {MAX_FACES}"));
        }
        u
    };
    let stopped = match (options.placement_time_limit, stopped) {
        (Some(l), Some(k)) => Some((l, untried(k))),
        (Some(l), None) if unlisted => Some((l, untried(queue.len()))),
        _ => None,
    }
    .map(|(l, untried)| Stopped {
        limit_s: crate::report::round(l.as_secs_f64(), 1e3),
        untried,
    });
    // Given up at its first unsupported curved feature: the part as modelled planned in full,
    // as the caller asked, for the refusal reported.
    if matches!(first, PlanError::Unsupported { .. }) {
        if let Some(f) = given.progress {
            f(Progress::Reporting);
        }
        match attempt(&Candidate::MODELLED, given, out) {
            Ok(plan) => return Ok(plan),
            Err(e) => first = e,
        }
    }
    Err(no_placement(first, tried, stopped, k, fits_nowhere))
}

/// The refusal when no placement plans: the part as modelled's (`first`), its report's
/// `placement` saying why none other was kept (`k` others tried; `fits_nowhere`: none could
/// fit, the last of `tried` says why), every placement `tried` listed, the part as modelled
/// first in its report and left out of the error's list.
fn no_placement(
    mut first: PlanError,
    mut tried: Vec<TriedEntry>,
    stopped: Option<Stopped>,
    k: usize,
    fits_nowhere: bool,
) -> PlanError {
    if let PlanError::Refused { plan, .. } = &mut first {
        let rule = match &stopped {
            None if fits_nowhere => format!(
                "as modelled: no other placement tried: {}",
                tried[tried.len() - 1].failure
            ),
            None => format!("as modelled: none of the {k} other placement(s) tried plans"),
            Some(s) if k == 0 => format!("as modelled: no other placement tried; {s}"),
            Some(s) => format!("as modelled: none of the {k} other placement(s) tried plans; {s}"),
        };
        let mut entry = Candidate::MODELLED.entry(rule);
        entry.tried = tried.clone();
        plan.report.placement = Some(entry);
    }
    tried.remove(0);
    PlanError::NoPlacement {
        modelled: Box::new(first),
        tried,
        stopped,
    }
}

#[cfg(test)]
mod tests {
    use super::Candidate;

    fn apply(m: [[f64; 3]; 3], v: [f64; 3]) -> [f64; 3] {
        [0, 1, 2].map(|r| (0..3).map(|k| m[r][k] * v[k]).sum())
    }

    /// Rounding of the products of a few sines and cosines.
    const CLOSE: f64 = 1e-6;

    #[test]
    fn a_candidates_rotation_turns_its_face_down_then_about_z() {
        // As modelled turned a quarter turn: X goes to Y, Z stays.
        let m = Candidate::Modelled { turn_deg: 90.0 }.rotation();
        let x = apply(m, [1.0, 0.0, 0.0]);
        assert!((x[1] - 1.0).abs() < CLOSE && x[0].abs() < CLOSE && x[2].abs() < CLOSE);
        // A face whose normal is +X, turned down and then 30 degrees: the normal points down,
        // and the matrix is a rotation.
        let s = 0.5f64.sqrt();
        for down in [[1.0, 0.0, 0.0], [0.0, 0.0, 1.0], [s, 0.0, -s]] {
            let c = Candidate::Face {
                id: 1,
                down,
                rank: 1,
                turn_deg: 30.0,
            };
            let m = c.rotation();
            let d = apply(m, down);
            assert!(d[0].abs() < CLOSE && d[1].abs() < CLOSE && (d[2] + 1.0).abs() < CLOSE);
            for a in 0..3 {
                for b in 0..3 {
                    let dot: f64 = (0..3).map(|k| m[k][a] * m[k][b]).sum();
                    let want = if a == b { 1.0 } else { 0.0 };
                    assert!((dot - want).abs() < CLOSE);
                }
            }
        }
    }
}
