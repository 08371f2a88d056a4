//! The motions of a KRL program: the part's placement on the table, the travels (retreat,
//! rise, move across, approach) and print moves, speeds and extruder switching, as steps.

use super::cell::KukaCell;
use super::rotation::{
    apply, col, exp_rot, frame_from_zx, log_rot, mul, rotation_angle_deg, transport, transpose,
    Mat3, Pose, IDENTITY,
};
use crate::machine::MachineProfile;
use crate::placement::bed_offset;
use crate::tolerance::{FEED_RATIO_CHANGE, POSE_SAME_DEG, POSE_SAME_MM};
use crate::PostError;
use std::collections::VecDeque;
use toolpath::vec3::{add, cross, norm, scale, sub, V3};
use toolpath::{fixed, MoveKind, ToolPath};

/// Largest orientation change of one LIN of a travel (degrees): a travel that turns the tool
/// further is split into several LINs.
pub const TRAVEL_ROTATION_STEP_DEG: f64 = 5.0;

/// Cell size (mm) of the height map that sets travel heights.
pub const HEIGHT_CELL: f64 = 2.0;

/// One step of the program, in order.
#[derive(Debug, Clone)]
pub(super) enum Step {
    Comment(String),
    /// `$VEL.CP` (m/s).
    Vel(f64),
    Extruder(bool),
    /// The feed ratio (filament mm per mm of path) of the next motion, a print LIN.
    Feed(f64),
    /// Wait for the extruder's ready input (the cell's `ready_input`).
    WaitReady,
    /// A motion to a tool pose in `$BASE`, for path point `point`; `print` for the motions
    /// that lay a bead.
    Move {
        kind: Kind,
        print: bool,
        pose: Pose,
        point: usize,
    },
    /// `SPLINE`: a spline block opens (its segments, feed and extruder triggers follow).
    SplineStart,
    /// `ENDSPLINE`.
    SplineEnd,
}

/// How a motion goes.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(super) enum Kind {
    /// `PTP` (with Status and Turn).
    Ptp,
    /// `LIN ... C_DIS`.
    Lin,
    /// `SPL`, a spline segment (in a spline block).
    Spl,
    /// `SLIN`, a straight segment in a spline block.
    Slin,
}

/// The part offset (part + offset = `$BASE` coordinates): [`bed_offset`]'s placement moved
/// by the cell's `part_position` (`[0, 0]` leaves it centred on the table's origin); a part
/// larger than the table, or moved off it, is placed the same way, with a warning.
pub(super) fn placement(
    path: &ToolPath,
    m: &MachineProfile,
    warnings: &mut Vec<String>,
) -> Result<[f64; 3], PostError> {
    let shift = m.kuka.as_ref().map_or([0.0; 2], |c| c.part_position);
    let centred = match bed_offset(path, m) {
        Ok(o) => o,
        Err(e @ PostError::DoesNotFit { .. }) => {
            warnings.push(format!("{e} (written anyway: the arm's reach decides)"));
            let mut open = m.clone();
            open.bed_origin_centre = true;
            open.bed_size = [f64::INFINITY; 3];
            let o = bed_offset(path, &open)?;
            let centre = if m.bed_origin_centre {
                [0.0, 0.0]
            } else {
                [m.bed_size[0] / 2.0, m.bed_size[1] / 2.0]
            };
            return Ok([
                o[0] + centre[0] + shift[0],
                o[1] + centre[1] + shift[1],
                o[2],
            ]);
        }
        Err(e) => Err(e)?,
    };
    if shift != [0.0, 0.0] {
        let over = crate::placement::bed_overhang_xy(path, m, shift);
        if over > 0.0 {
            warnings.push(format!(
                "the part, moved by part_position [{}, {}], overhangs the {} mm table of `{}` by up to {} mm (written anyway: the arm's reach decides)",
                fixed(shift[0], 3),
                fixed(shift[1], 3),
                m.bed_size.map(|v| fixed(v, 0)).join("x"),
                m.name,
                fixed(over, 3)
            ));
        }
    }
    Ok([centred[0] + shift[0], centred[1] + shift[1], centred[2]])
}

/// The motions of the program, planned as they are asked for: travels, print moves, speeds
/// and extruder switching, the steps in order ([`Iterator`]); a path point at a time, so that
/// the program is written as it is planned.
pub(super) struct Planner<'a> {
    path: &'a ToolPath,
    /// The path's tool axes, unit.
    axes: &'a [V3],
    offset: [f64; 3],
    base: &'a Pose,
    /// `$VEL.CP` (m/s) of print moves, of those resting on the plate, and of travels.
    print_v: f64,
    first_v: f64,
    travel_v: f64,
    w: Motion,
    /// The next path point.
    i: usize,
    /// The layer and feature of the last comment.
    layer: Option<usize>,
    feature: Option<usize>,
    /// The pose the last point left the tool at, and that point.
    cur: Option<(Pose, usize)>,
    /// The end (retreat and rise) is planned.
    done: bool,
}

impl<'a> Planner<'a> {
    /// The planner of the path's motions; `axes` are its points' tool axes made unit,
    /// `offset` the part's placement ([`placement`]), `base` the table's frame.
    pub(super) fn new(
        path: &'a ToolPath,
        axes: &'a [V3],
        offset: [f64; 3],
        m: &MachineProfile,
        cell: &KukaCell,
        base: &'a Pose,
    ) -> Planner<'a> {
        let (print_v, first_v) = if cell.print_vel_cp > 0.0 {
            (
                cell.print_vel_cp,
                cell.print_vel_cp * m.first_layer_speed / m.print_speed,
            )
        } else {
            (m.print_speed / 1000.0, m.first_layer_speed / 1000.0)
        };
        let travel_v = if cell.travel_vel_cp > 0.0 {
            cell.travel_vel_cp
        } else {
            m.travel_speed / 1000.0
        };
        Planner {
            path,
            axes,
            offset,
            base,
            print_v,
            first_v,
            travel_v,
            w: Motion {
                steps: VecDeque::new(),
                last: None,
                vel: None,
                feed: None,
                on: false,
                clearance: cell.travel_clearance,
                safe_z: part_top(path, offset) + cell.safe_height,
                safe: None,
                ready: cell.ready_input.is_some(),
                z_top: f64::NEG_INFINITY,
                height: HeightMap {
                    cell: HEIGHT_CELL,
                    z: Default::default(),
                },
            },
            i: 0,
            layer: None,
            feature: None,
            cur: None,
            done: false,
        }
    }

    /// Plans the steps of the next path point (none for some), or the end after the last.
    fn advance(&mut self) {
        let path = self.path;
        let Some(q) = path.points.get(self.i) else {
            if let Some((end, i)) = self.cur {
                self.w.leave(&end, i, self.travel_v);
            }
            self.done = true;
            return;
        };
        let i = self.i;
        self.i += 1;
        let w = &mut self.w;
        let p = add(q.p, self.offset);
        let z = scale(self.axes[i], -1.0);
        w.z_top = w.z_top.max(p[2]);
        // A travel point goes only where a path starts (a print point follows): the
        // planner's other travel points (lifts, waypoints) are superseded by the safe travel.
        let starts_path = path
            .points
            .get(i + 1)
            .is_some_and(|n| n.kind == MoveKind::Print);
        if q.kind == MoveKind::Travel && !starts_path {
            return;
        }
        if self.layer != Some(q.layer as usize) || self.feature != Some(q.feature as usize) {
            self.layer = Some(q.layer as usize);
            self.feature = Some(q.feature as usize);
            w.steps.push_back(Step::Comment(format!(
                "FEATURE {} LAYER {}",
                q.feature, q.layer
            )));
        }
        let next = match (q.kind, self.cur) {
            (MoveKind::Print, Some((prev, _))) => {
                let pose = Pose {
                    r: transport(&prev.r, z),
                    t: p,
                };
                // A print move that goes nowhere (the nozzle is already there) is dropped,
                // with its switching. Speed first: a TRIGGER goes right before its motion.
                if w.goes_nowhere(&pose) {
                    self.cur = Some((pose, i));
                    return;
                }
                let on_plate = p[2] - f64::from(q.thickness.max(0.0)) <= 0.01;
                w.vel(if on_plate { self.first_v } else { self.print_v });
                if !w.on {
                    w.extruder(true);
                }
                w.feed(path, &pose, i);
                w.step(Kind::Lin, true, pose, i);
                pose
            }
            _ => {
                let pose = Pose {
                    r: start_frame(z, p, self.base),
                    t: p,
                };
                w.travel(self.cur.map(|c| c.0), pose, i, self.travel_v, self.base);
                pose
            }
        };
        // The bead just laid (or the path's start) is material the travels must clear.
        match (q.kind, self.cur) {
            (MoveKind::Print, Some((prev, _))) => w.height.add_segment(prev.t, p),
            _ => w.height.add(p),
        }
        self.cur = Some((next, i));
    }
}

impl Iterator for Planner<'_> {
    type Item = Step;

    fn next(&mut self) -> Option<Step> {
        loop {
            if let Some(s) = self.w.steps.pop_front() {
                return Some(s);
            }
            if self.done {
                return None;
            }
            self.advance();
        }
    }
}

/// The part's top in `$BASE` (mm): the highest print point placed by `offset` (the highest
/// point when none prints; 0 for an empty path).
fn part_top(path: &ToolPath, offset: [f64; 3]) -> f64 {
    let top = crate::placement::placed_points(path)
        .map(|q| q.p[2])
        .fold(f64::NEG_INFINITY, f64::max);
    if top.is_finite() {
        top + offset[2]
    } else {
        0.0
    }
}

/// The highest point visited so far over each cell of a square grid of the table (`$BASE`
/// X, Y), for travel heights.
pub(super) struct HeightMap {
    cell: f64,
    z: std::collections::HashMap<(i64, i64), f64>,
}

impl HeightMap {
    fn key(&self, x: f64, y: f64) -> (i64, i64) {
        (
            (x / self.cell).floor() as i64,
            (y / self.cell).floor() as i64,
        )
    }

    fn add(&mut self, p: V3) {
        let k = self.key(p[0], p[1]);
        let z = self.z.entry(k).or_insert(f64::NEG_INFINITY);
        *z = z.max(p[2]);
    }

    /// Every point of the segment from `a` to `b`, sampled at half a cell.
    fn add_segment(&mut self, a: V3, b: V3) {
        let len = (b[0] - a[0]).hypot(b[1] - a[1]);
        let n = ((2.0 * len / self.cell).ceil() as usize).clamp(1, 1_000_000);
        for k in 0..=n {
            let t = k as f64 / n as f64;
            self.add(add(scale(a, 1.0 - t), scale(b, t)));
        }
    }

    /// The highest point visited within about a cell of the XY segment from `a` to `b`
    /// (−∞ when none).
    fn max_along(&self, a: V3, b: V3) -> f64 {
        let len = (b[0] - a[0]).hypot(b[1] - a[1]);
        let n = ((2.0 * len / self.cell).ceil() as usize).clamp(1, 1_000_000);
        let mut top = f64::NEG_INFINITY;
        let mut last = None;
        for k in 0..=n {
            let t = k as f64 / n as f64;
            let (cx, cy) = self.key(a[0] + t * (b[0] - a[0]), a[1] + t * (b[1] - a[1]));
            if last == Some((cx, cy)) {
                continue;
            }
            last = Some((cx, cy));
            for dx in -1..=1 {
                for dy in -1..=1 {
                    if let Some(z) = self.z.get(&(cx + dx, cy + dy)) {
                        top = top.max(*z);
                    }
                }
            }
        }
        top
    }
}

/// The tool frame at the start of a path: Z along `z` (unit, `$BASE`), X the horizontal
/// direction from the nozzle at `p` back to the robot's A1 axis made normal to Z (or, when
/// the tool points along that direction, the horizontal normal to it).
pub(crate) fn start_frame(z: V3, p: V3, base: &Pose) -> Mat3 {
    let world = base.apply(p);
    let back = [-world[0], -world[1], 0.0];
    let back = if norm(back) < 1.0 {
        [-1.0, 0.0, 0.0]
    } else {
        scale(back, 1.0 / norm(back))
    };
    let to_base = transpose(&base.r);
    let d = apply(&to_base, back);
    let side = apply(&to_base, cross([0.0, 0.0, 1.0], back));
    frame_from_zx(z, d, 0.2)
        .or_else(|| frame_from_zx(z, side, 1e-6))
        .or_else(|| frame_from_zx(z, [1.0, 0.0, 0.0], 1e-6))
        .or_else(|| frame_from_zx(z, [0.0, 1.0, 0.0], 1e-6))
        .unwrap_or(IDENTITY)
}

/// The steps being planned and the state they leave.
pub(super) struct Motion {
    /// Steps planned, not yet taken.
    steps: VecDeque<Step>,
    /// The pose and path point of the last motion.
    last: Option<(Pose, usize)>,
    vel: Option<f64>,
    /// The feed ratio in force.
    feed: Option<f64>,
    on: bool,
    clearance: f64,
    /// The safe point's height ($BASE Z, mm): `safe_height` over the part's top.
    safe_z: f64,
    /// The safe point, over the first path's start at `safe_z`, once the program went there.
    safe: Option<Pose>,
    /// The program waits for the extruder's ready input at the safe point.
    ready: bool,
    /// Highest point of the path so far ($BASE Z, mm).
    z_top: f64,
    /// The points visited so far.
    height: HeightMap,
}

impl Motion {
    fn vel(&mut self, v: f64) {
        if self.vel != Some(v) {
            self.vel = Some(v);
            self.steps.push_back(Step::Vel(v));
        }
    }

    fn extruder(&mut self, on: bool) {
        self.on = on;
        self.steps.push_back(Step::Extruder(on));
    }

    /// The feed ratio of a print LIN to `pose` (path point `point`): the planned filament of
    /// the print points since the previous motion's point (a print move dropped as going
    /// nowhere hands its filament on) over the LIN's length; a step only where it changes by
    /// more than the output's rounding.
    fn feed(&mut self, path: &ToolPath, pose: &Pose, point: usize) {
        let Some((last, from)) = self.last else {
            return;
        };
        let length = norm(sub(pose.t, last.t));
        if length <= 0.0 || from >= point {
            return;
        }
        let e: f64 = path.points[from + 1..=point]
            .iter()
            .filter(|q| q.kind == MoveKind::Print)
            .map(|q| q.e)
            .sum();
        let ratio = e / length;
        if self
            .feed
            .is_none_or(|f| (f - ratio).abs() > FEED_RATIO_CHANGE)
        {
            self.feed = Some(ratio);
            self.steps.push_back(Step::Feed(ratio));
        }
    }

    /// Whether `pose` is the previous motion's (within 1e-9 mm and 1e-9°).
    fn goes_nowhere(&self, pose: &Pose) -> bool {
        self.last.is_some_and(|(last, _)| {
            norm(sub(last.t, pose.t)) < POSE_SAME_MM
                && rotation_angle_deg(&last.r, &pose.r) < POSE_SAME_DEG
        })
    }

    /// A motion (`PTP` when `ptp`, else `LIN`), unless it would go nowhere.
    fn motion(&mut self, ptp: bool, pose: Pose, point: usize) {
        let kind = if ptp { Kind::Ptp } else { Kind::Lin };
        self.step(kind, false, pose, point);
    }

    /// A motion of `kind`, laying a bead when `print`, unless it would go nowhere.
    fn step(&mut self, kind: Kind, print: bool, pose: Pose, point: usize) {
        if !self.goes_nowhere(&pose) {
            self.last = Some((pose, point));
            self.steps.push_back(Step::Move {
                kind,
                print,
                pose,
                point,
            });
        }
    }

    /// Travel speed, extruder off, and back off `from` along the tool axis by the clearance;
    /// returns where it backed off to.
    fn retreat(&mut self, from: &Pose, point: usize, travel_v: f64) -> [f64; 3] {
        self.vel(travel_v);
        if self.on {
            self.extruder(false);
        }
        let retreat = add(from.t, scale(col(&from.r, 2), -self.clearance));
        self.motion(
            false,
            Pose {
                r: from.r,
                t: retreat,
            },
            point,
        );
        retreat
    }

    /// Travel from `cur` (or from home) to the path start `to` (point `point`).
    fn travel(&mut self, cur: Option<Pose>, to: Pose, point: usize, travel_v: f64, base: &Pose) {
        let c = self.clearance;
        let approach = add(to.t, scale(col(&to.r, 2), -c));
        let Some(from) = cur else {
            // From home: to the safe point over the path's start (PTP, the tool upright), down
            // to the approach point turning to the path's orientation, and along the axis to
            // the start.
            self.vel(travel_v);
            let safe = Pose {
                r: start_frame([0.0, 0.0, -1.0], to.t, base),
                t: [to.t[0], to.t[1], self.safe_z.max(approach[2])],
            };
            self.safe = Some(safe);
            self.steps
                .push_back(Step::Comment("safe point over the part".into()));
            self.motion(true, safe, point);
            if self.ready {
                self.steps.push_back(Step::WaitReady);
            }
            self.turn_across(&safe, to.r, approach, point);
            self.motion(false, to, point);
            return;
        };
        let retreat = self.retreat(&from, point, travel_v);
        let h = (self.height.max_along(retreat, approach) + c)
            .max(retreat[2])
            .max(approach[2]);
        let up = [retreat[0], retreat[1], h];
        let up = Pose { r: from.r, t: up };
        self.motion(false, up, point);
        self.turn_across(&up, to.r, [approach[0], approach[1], h], point);
        self.motion(
            false,
            Pose {
                r: to.r,
                t: approach,
            },
            point,
        );
        self.motion(false, to, point);
    }

    /// LINs from `from` to `over` while the orientation turns to `r` (slerp, at most
    /// [`TRAVEL_ROTATION_STEP_DEG`] a LIN).
    fn turn_across(&mut self, from: &Pose, r: Mat3, over: V3, point: usize) {
        let turn = log_rot(&mul(&transpose(&from.r), &r));
        let angle = norm(turn).to_degrees();
        let n = ((angle / TRAVEL_ROTATION_STEP_DEG).ceil() as usize).max(1);
        for k in 1..=n {
            let t = k as f64 / n as f64;
            let pose = if k == n {
                Pose { r, t: over }
            } else {
                Pose {
                    r: mul(&from.r, &exp_rot(scale(turn, t))),
                    t: add(scale(from.t, 1.0 - t), scale(over, t)),
                }
            };
            self.motion(false, pose, point);
        }
    }

    /// The end: extruder off, retreat along the tool axis, rise to the safe point's height
    /// (or the clearance over the part's top, if higher) and go to the safe point (PTP).
    fn leave(&mut self, from: &Pose, point: usize, travel_v: f64) {
        let c = self.clearance;
        let retreat = self.retreat(from, point, travel_v);
        let h = (self.z_top + c).max(self.safe_z).max(retreat[2]);
        let up = [retreat[0], retreat[1], h];
        let Some(safe) = self.safe else {
            self.motion(false, Pose { r: from.r, t: up }, point);
            return;
        };
        // Up, turning the tool upright, across, and the safe point by PTP.
        let back = Pose {
            r: from.r,
            t: retreat,
        };
        self.turn_across(&back, safe.r, up, point);
        self.motion(
            false,
            Pose {
                r: safe.r,
                t: [safe.t[0], safe.t[1], h],
            },
            point,
        );
        self.steps
            .push_back(Step::Comment("safe point over the part".into()));
        // Always written, even where the LIN across ended there: the program ends at it.
        self.last = Some((safe, point));
        self.steps.push_back(Step::Move {
            kind: Kind::Ptp,
            print: false,
            pose: safe,
            point,
        });
    }
}
