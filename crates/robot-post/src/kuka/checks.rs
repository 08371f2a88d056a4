//! The reach check of a KRL program: every motion's Euler angles (unwrapped along the
//! program) and its pose checked against the arm model, counted per feature.

use std::collections::BTreeMap;

use super::cell::KukaCell;
use super::motion::Step;
use super::rotation::Pose;
use toolpath::{fixed, ToolPath};

/// What the post found for one feature's points.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct KukaFigures {
    /// Path points of the feature.
    pub points: usize,
    /// Motions (LIN, and the first PTP) written for them, travel moves included.
    pub moves: usize,
    /// Points with a pose out of the arm's reach or joint limits.
    pub unreachable_points: usize,
    /// Points with a pose within `wrist_singularity_deg` of the wrist singularity.
    pub wrist_singular_points: usize,
    /// Index (in the tool path) of the first unreachable point.
    pub first_unreachable: Option<usize>,
    /// Index of the first point near the wrist singularity.
    pub first_wrist_singular: Option<usize>,
    /// Smallest wrist bend |A5| over the reachable poses (degrees).
    pub min_wrist_bend_deg: Option<f64>,
    /// Motions on which the arm would have to change configuration (shoulder, elbow or wrist
    /// flip), which a LIN cannot do.
    pub configuration_changes: usize,
    /// Motions on which A or C turns by more than 90°: the tool's X axis passes through (or
    /// close by) `$BASE` Z, the gimbal lock, where A and C turn by about 180° because B stays
    /// within ±90°.
    pub gimbal_crossings: usize,
}

/// What the reach check found, per motion and per feature.
pub(super) struct Checked {
    /// Per `Step::Move`, in order: the KRL frame written.
    pub(super) frames: Vec<[f64; 6]>,
    /// Per `Step::Move`: a note for the LIN's comment, if any.
    pub(super) notes: Vec<Option<&'static str>>,
    pub(super) figures: BTreeMap<usize, KukaFigures>,
}

/// Euler angles (unwrapped along the program) and the reach check of every motion.
pub(super) fn check(
    path: &ToolPath,
    steps: &[Step],
    cell: &KukaCell,
    base: &Pose,
    warnings: &mut Vec<String>,
) -> Checked {
    let arm = &cell.arm;
    let tool_inv = cell.tool.pose().inverse();
    let n = path.points.len();
    let mut unreachable = vec![false; n];
    let mut singular = vec![false; n];
    let mut figures: BTreeMap<usize, KukaFigures> = BTreeMap::new();
    for q in &path.points {
        figures.entry(q.feature).or_default().points += 1;
    }
    let mut frames = Vec::new();
    let mut notes = Vec::new();
    let mut prev_abc: Option<[f64; 3]> = None;
    let mut joints = cell.home;
    let mut config = Some(arm.configuration(&cell.home));
    for step in steps {
        let Step::Move { pose, point, .. } = step else {
            continue;
        };
        let feature = path.points[*point].feature;
        let fig = figures.entry(feature).or_default();
        fig.moves += 1;
        let f = pose.to_frame(prev_abc);
        if let Some(p) = prev_abc {
            if (f[3] - p[0]).abs() > 90.0 || (f[5] - p[2]).abs() > 90.0 {
                fig.gimbal_crossings += 1;
            }
        }
        prev_abc = Some([f[3], f[4], f[5]]);
        frames.push(f);
        let flange = base.compose(pose).compose(&tool_inv);
        let note = match arm.nearest(&flange, &joints, config) {
            None => {
                unreachable[*point] = true;
                if fig.first_unreachable.is_none_or(|i| *point < i) {
                    fig.first_unreachable = Some(*point);
                }
                Some("UNREACHABLE")
            }
            Some((j, c)) => {
                if config.is_some_and(|k| k != c) {
                    fig.configuration_changes += 1;
                }
                joints = j;
                config = Some(c);
                let bend = arm.wrist_bend(&j);
                let bend = bend.min(180.0 - bend);
                fig.min_wrist_bend_deg = Some(fig.min_wrist_bend_deg.map_or(bend, |b| b.min(bend)));
                if bend < cell.wrist_singularity_deg {
                    singular[*point] = true;
                    if fig.first_wrist_singular.is_none_or(|i| *point < i) {
                        fig.first_wrist_singular = Some(*point);
                    }
                    Some("WRIST SINGULAR")
                } else {
                    None
                }
            }
        };
        notes.push(note);
    }
    for (i, q) in path.points.iter().enumerate() {
        if let Some(fig) = figures.get_mut(&q.feature) {
            fig.unreachable_points += usize::from(unreachable[i]);
            fig.wrist_singular_points += usize::from(singular[i]);
        }
    }
    let at = |i: usize| {
        let p = path.points[i].p;
        format!(
            "point {i} (part X{} Y{} Z{})",
            fixed(p[0], 3),
            fixed(p[1], 3),
            fixed(p[2], 3)
        )
    };
    for (id, fig) in &figures {
        if let Some(i) = fig.first_unreachable {
            warnings.push(format!(
                "feature {id}: {} of {} points out of the arm's reach or joint limits, first at {}",
                fig.unreachable_points,
                fig.points,
                at(i)
            ));
        }
        if let Some(i) = fig.first_wrist_singular {
            warnings.push(format!(
                "feature {id}: {} points within {}° of the wrist singularity (|A5| small), first at {}",
                fig.wrist_singular_points,
                fixed(cell.wrist_singularity_deg, 1),
                at(i)
            ));
        }
        if fig.configuration_changes > 0 {
            warnings.push(format!(
                "feature {id}: the arm changes configuration on {} motions (a LIN cannot)",
                fig.configuration_changes
            ));
        }
        if fig.gimbal_crossings > 0 {
            warnings.push(format!(
                "feature {id}: the tool's X axis passes through or near $BASE Z on {} motions: A or C turns by more than 90° there (B stays within ±90°)",
                fig.gimbal_crossings
            ));
        }
    }
    Checked {
        frames,
        notes,
        figures,
    }
}
