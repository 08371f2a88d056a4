//! The reach check of a KRL program: every motion's Euler angles (unwrapped along the
//! program) and its pose checked against the arm model, counted per feature.

use std::collections::BTreeMap;

use super::cell::KukaCell;
use super::opw::{bits_text, turn};
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

/// The reach check, motion by motion in the program's order ([`Reach::motion`]): each
/// motion's Euler angles (unwrapped along the program) and its pose against the arm model.
pub(super) struct Reach<'a> {
    /// The cell the arm stands in.
    pub(super) cell: &'a KukaCell,
    base: &'a Pose,
    tool_inv: Pose,
    /// Per path point: a motion for it is out of reach, near the wrist singularity.
    unreachable: Vec<bool>,
    singular: Vec<bool>,
    figures: BTreeMap<usize, KukaFigures>,
    prev_abc: Option<[f64; 3]>,
    /// The joints and configuration the arm is in.
    joints: [f64; 6],
    config: Option<u8>,
    /// Motions checked so far.
    motions: usize,
    /// Per feature: where its first configuration change is, and the change.
    first_change: BTreeMap<usize, String>,
}

/// What the check found for one motion.
#[derive(Debug, Clone, Copy)]
pub(super) struct Solved {
    /// The KRL frame written (Euler angles unwrapped along the program).
    pub(super) frame: [f64; 6],
    /// `UNREACHABLE` or `WRIST SINGULAR`, for the motion's line.
    pub(super) note: Option<&'static str>,
    /// The joint angles A1..A6 (degrees) of the solution followed, with its Status and Turn;
    /// `None` when out of reach.
    pub(super) joints: Option<([f64; 6], u8, u8)>,
}

impl<'a> Reach<'a> {
    /// The check of `path`'s motions, the arm at home.
    pub(super) fn new(path: &ToolPath, cell: &'a KukaCell, base: &'a Pose) -> Reach<'a> {
        let n = path.points.len();
        let mut figures: BTreeMap<usize, KukaFigures> = BTreeMap::new();
        for q in &path.points {
            figures.entry(q.feature as usize).or_default().points += 1;
        }
        Reach {
            cell,
            base,
            tool_inv: cell.tool.pose().inverse(),
            unreachable: vec![false; n],
            singular: vec![false; n],
            figures,
            prev_abc: None,
            joints: cell.home,
            config: Some(cell.arm.configuration(&cell.home)),
            motions: 0,
            first_change: BTreeMap::new(),
        }
    }

    /// The next motion, to `pose` for path point `point` of `feature`, written at `at` (file
    /// and one-based line): the KRL frame written, the solution followed, and a note for its
    /// line when the arm cannot reach it or it is near the wrist singularity.
    pub(super) fn motion(
        &mut self,
        pose: &Pose,
        point: usize,
        feature: usize,
        at: (&str, usize),
    ) -> Solved {
        let (cell, arm) = (self.cell, &self.cell.arm);
        self.motions += 1;
        let fig = self.figures.entry(feature).or_default();
        fig.moves += 1;
        let f = pose.to_frame(self.prev_abc);
        if let Some(p) = self.prev_abc {
            if (f[3] - p[0]).abs() > 90.0 || (f[5] - p[2]).abs() > 90.0 {
                fig.gimbal_crossings += 1;
            }
        }
        self.prev_abc = Some([f[3], f[4], f[5]]);
        let flange = self.base.compose(pose).compose(&self.tool_inv);
        let mut joints = None;
        let note = match arm.nearest(&flange, &self.joints, self.config) {
            None => {
                self.unreachable[point] = true;
                if fig.first_unreachable.is_none_or(|i| point < i) {
                    fig.first_unreachable = Some(point);
                }
                Some("UNREACHABLE")
            }
            Some((j, c)) => {
                if let Some(k) = self.config.filter(|k| *k != c) {
                    fig.configuration_changes += 1;
                    self.first_change.entry(feature).or_insert_with(|| {
                        format!(
                            "motion {} ({}:{}, point {point}), S {} to {}",
                            self.motions,
                            at.0,
                            at.1,
                            bits_text(k, 3),
                            bits_text(c, 3)
                        )
                    });
                }
                joints = Some((j, c, turn(&j)));
                self.joints = j;
                self.config = Some(c);
                let bend = arm.wrist_bend(&j);
                let bend = bend.min(180.0 - bend);
                fig.min_wrist_bend_deg = Some(fig.min_wrist_bend_deg.map_or(bend, |b| b.min(bend)));
                if bend < cell.wrist_singularity_deg {
                    self.singular[point] = true;
                    if fig.first_wrist_singular.is_none_or(|i| point < i) {
                        fig.first_wrist_singular = Some(point);
                    }
                    Some("WRIST SINGULAR")
                } else {
                    None
                }
            }
        };
        Solved {
            frame: f,
            note,
            joints,
        }
    }

    /// What the check found per feature, once every motion is checked; its warnings, one line
    /// each, pushed onto `warnings`.
    pub(super) fn finish(
        self,
        path: &ToolPath,
        warnings: &mut Vec<String>,
    ) -> BTreeMap<usize, KukaFigures> {
        let Reach {
            cell,
            unreachable,
            singular,
            mut figures,
            first_change,
            ..
        } = self;
        for (i, q) in path.points.iter().enumerate() {
            if let Some(fig) = figures.get_mut(&(q.feature as usize)) {
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
                    "feature {id}: the arm changes configuration on {} motions (a LIN cannot), first at {}",
                    fig.configuration_changes,
                    first_change.get(id).map_or("?", String::as_str)
                ));
            }
            if fig.gimbal_crossings > 0 {
                warnings.push(format!(
                "feature {id}: the tool's X axis passes through or near $BASE Z on {} motions: A or C turns by more than 90° there (B stays within ±90°)",
                fig.gimbal_crossings
            ));
            }
        }
        figures
    }
}
