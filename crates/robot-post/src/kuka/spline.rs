//! Spline output (`motion = "spline"`): the print motions of each run (a path's print moves
//! between changes of speed) become a `SPLINE` block through fewer points.
//!
//! A point is dropped where the line from the last point kept to a later one passes within
//! half the cell's `spline_tolerance` of it, its orientation within
//! [`SPLINE_ANGLE_TOLERANCE_DEG`] of the orientation turned evenly (by length) between the two,
//! and its motion's feed ratio within [`SPLINE_FEED_TOLERANCE`] of theirs merged (for a motion
//! shorter than [`SPLINE_FEED_SHORT`], the filament it shifts within that share of so long a
//! motion's); the merged
//! segment feeds the filament of the motions it replaces over its own length. A segment is
//! written `SPL` where the path runs on through both its ends: the cubic through them whose end
//! tangents bisect the turns there ([`cubic_point`]) must pass within the tolerance of the
//! planned points the segment stands for; otherwise (corners, a block's first and last
//! segments) `SLIN`, a straight line. The feed is set by `TRIGGER WHEN PATH=0 ONSTART
//! DELAY=0 DO $ANOUT[n]=v` inside the block, where its written value changes by more than one
//! step (1e-5 of full scale: less is rounding); travels stay
//! `LIN` and `PTP`.

use super::cell::{ExtruderSwitch, KrlMotion, KukaCell};
use super::motion::{Kind, Step};
use super::rotation::{exp_rot, log_rot, mul, rotation_angle_deg, transpose, Pose};
use std::collections::VecDeque;
use toolpath::vec3::{add, dot, norm, scale, sub, V3};

/// Largest rotation (degrees) between a dropped point's orientation and the one turned evenly
/// between the points kept around it.
pub const SPLINE_ANGLE_TOLERANCE_DEG: f64 = 0.1;

/// Largest relative difference between a dropped motion's feed ratio and its merged segment's
/// (for motions shorter than [`SPLINE_FEED_SHORT`], of the filament of that length).
pub const SPLINE_FEED_TOLERANCE: f64 = 0.02;

/// Length (mm) below which a motion's feed is compared by its filament, not its ratio.
pub const SPLINE_FEED_SHORT: f64 = 0.5;

/// Largest turn (degrees) at either end of an `SPL` segment: sharper corners are `SLIN`.
pub const SPLINE_MAX_TURN_DEG: f64 = 30.0;

/// Shortest segment (mm) that has a direction: shorter ones, and their neighbours, are `SLIN`.
pub const SPLINE_MIN_SEGMENT: f64 = 0.01;

/// Most segments of one `SPLINE` block: a longer run goes on in the next block.
pub const SPLINE_MAX_SEGMENTS: usize = 500;

/// Most motions merged into one segment.
pub const SPLINE_MAX_MERGED: usize = 1000;

/// One print motion as planned.
#[derive(Debug, Clone, Copy)]
struct Planned {
    pose: Pose,
    point: usize,
    /// Its length (mm) and feed ratio (filament mm per mm).
    len: f64,
    ratio: f64,
}

/// A segment decided, not yet written: whether it is `SPL` waits for the next one's
/// direction.
#[derive(Debug, Clone)]
struct Segment {
    pose: Pose,
    point: usize,
    /// Its unit direction and feed ratio (the merged motions' filament over its length).
    dir: V3,
    ratio: f64,
    /// The planned points it stands for: its start, the points dropped, its end.
    planned: Vec<V3>,
    /// The direction of the segment before it in its block; `None` for a block's first.
    dir_in: Option<V3>,
}

/// The steps of a program with its print runs written as spline blocks (`motion =
/// "spline"`), or as they are (`lin`).
pub(super) struct Splined<I> {
    inner: I,
    spline: bool,
    switch: ExtruderSwitch,
    /// The spline tolerance (mm): a cubic segment's distance from the planned path; half of it
    /// a dropped point's from its segment.
    tol: f64,
    full_scale: f64,
    out: VecDeque<Step>,
    /// Speed, extruder and feed steps after the last motion, held until the next motion
    /// shows whether a block opens before it.
    held: Vec<Step>,
    /// The last motion's pose.
    last: Option<Pose>,
    in_block: bool,
    /// The last point kept, and the planned motions since.
    anchor: Option<Pose>,
    window: Vec<Planned>,
    /// The planned feed ratio in force.
    ratio: f64,
    pending: Option<Segment>,
    /// Segments written in the current block.
    segments: usize,
    /// The feed's analog value written last, in its written steps of 1e-5.
    written: Option<i64>,
    done: bool,
}

impl<I: Iterator<Item = Step>> Splined<I> {
    /// The steps of `inner` as the cell's `motion` writes them.
    pub(super) fn new(inner: I, cell: &KukaCell) -> Splined<I> {
        Splined {
            inner,
            spline: cell.motion == KrlMotion::Spline,
            switch: cell.extruder_switch,
            tol: cell.spline_tolerance,
            full_scale: cell.feed_ratio_full_scale,
            out: VecDeque::new(),
            held: vec![],
            last: None,
            in_block: false,
            anchor: None,
            window: vec![],
            ratio: 0.0,
            pending: None,
            segments: 0,
            written: None,
            done: false,
        }
    }

    /// Takes the next step of the planner.
    fn take(&mut self, step: Step) {
        if !self.spline {
            self.out.push_back(step);
            return;
        }
        match step {
            Step::Move {
                print: true,
                pose,
                point,
                ..
            } => {
                if !self.in_block {
                    self.open();
                }
                let len = self.last.map_or(0.0, |l| norm(sub(pose.t, l.t)));
                self.add(Planned {
                    pose,
                    point,
                    len,
                    ratio: self.ratio,
                });
                self.last = Some(pose);
            }
            Step::Feed(r) if self.in_block => self.ratio = r,
            Step::Feed(_) | Step::Vel(_) | Step::Extruder(_) => {
                self.close();
                self.held.push(step);
            }
            other => {
                self.close();
                self.flush_held();
                if let Step::Move { pose, .. } = other {
                    self.last = Some(pose);
                }
                self.out.push_back(other);
            }
        }
    }

    fn flush_held(&mut self) {
        for s in self.held.drain(..) {
            if let Step::Feed(r) = s {
                self.ratio = r;
                self.written = Some(written_value(r, self.full_scale));
            }
            self.out.push_back(s);
        }
    }

    /// Opens a block before a run's first print motion: the speed (and a switch by `$OUT`)
    /// before it, the extruder's trigger inside; the feed is the run's to write.
    fn open(&mut self) {
        let mut inside = vec![];
        for s in std::mem::take(&mut self.held) {
            match s {
                Step::Feed(r) => self.ratio = r,
                Step::Extruder(_) if self.switch == ExtruderSwitch::Trigger => inside.push(s),
                other => self.out.push_back(other),
            }
        }
        self.out.push_back(Step::SplineStart);
        self.out.extend(inside);
        self.in_block = true;
        self.anchor = self.last;
        self.segments = 0;
    }

    /// Closes the block: the last segment written, `ENDSPLINE`.
    fn close(&mut self) {
        if !self.in_block {
            return;
        }
        self.cut();
        if let Some(p) = self.pending.take() {
            self.emit(p, None);
        }
        self.out.push_back(Step::SplineEnd);
        self.in_block = false;
        self.anchor = None;
    }

    /// A planned motion: merged into the segment being grown if it still fits, else that
    /// segment is decided and a new one starts from its end.
    fn add(&mut self, m: Planned) {
        if !self.window.is_empty() && (self.window.len() >= SPLINE_MAX_MERGED || !self.fits(&m)) {
            self.cut();
        }
        self.window.push(m);
    }

    /// Whether the segment from the anchor to `m`'s end passes within half the tolerance of
    /// the window's points, turns evenly through their orientations, and merges their feeds.
    fn fits(&self, m: &Planned) -> bool {
        let Some(a) = self.anchor else {
            return false;
        };
        let chord = norm(sub(m.pose.t, a.t));
        let total: f64 = self.window.iter().map(|w| w.len).sum::<f64>() + m.len;
        if chord <= 0.0 || total <= 0.0 {
            return false;
        }
        let e: f64 = self.window.iter().map(|w| w.ratio * w.len).sum::<f64>() + m.ratio * m.len;
        // The filament a motion would get at the merged ratio, against its own: within
        // SPLINE_FEED_TOLERANCE of it, or of SPLINE_FEED_SHORT mm's worth for a shorter motion
        // (a sliver's ratio is its filament over next to no length).
        let merged = e / chord;
        let moved = |w: &Planned| (w.ratio - merged).abs() * w.len;
        let allowed =
            |w: &Planned| SPLINE_FEED_TOLERANCE * merged.abs() * w.len.max(SPLINE_FEED_SHORT);
        if self.window.iter().chain([m]).any(|w| moved(w) > allowed(w)) {
            return false;
        }
        let turn = log_rot(&mul(&transpose(&a.r), &m.pose.r));
        let mut run = 0.0;
        self.window.iter().all(|w| {
            run += w.len;
            let even = mul(&a.r, &exp_rot(scale(turn, run / total)));
            distance_to_segment(w.pose.t, a.t, m.pose.t) <= self.tol / 2.0
                && rotation_angle_deg(&even, &w.pose.r) <= SPLINE_ANGLE_TOLERANCE_DEG
        })
    }

    /// The window becomes a segment, queued; its end is the new anchor.
    fn cut(&mut self) {
        let (Some(a), Some(end)) = (self.anchor, self.window.last().copied()) else {
            self.window.clear();
            return;
        };
        let d = sub(end.pose.t, a.t);
        let len = norm(d);
        let e: f64 = self.window.iter().map(|w| w.ratio * w.len).sum();
        let mut planned = vec![a.t];
        planned.extend(self.window.iter().map(|w| w.pose.t));
        let seg = Segment {
            pose: end.pose,
            point: end.point,
            // A segment too short for its direction to survive the written rounding has none:
            // its neighbours are straight.
            dir: if len >= SPLINE_MIN_SEGMENT {
                scale(d, 1.0 / len)
            } else {
                [0.0; 3]
            },
            ratio: if len > 0.0 { e / len } else { end.ratio },
            planned,
            dir_in: None,
        };
        self.window.clear();
        self.anchor = Some(end.pose);
        self.queue(seg);
    }

    /// Writes the pending segment, now that the next one's direction is known, and holds
    /// `seg`.
    fn queue(&mut self, mut seg: Segment) {
        if let Some(p) = self.pending.take() {
            let dir = p.dir;
            let restarted = self.emit(p, Some(seg.dir));
            seg.dir_in = (!restarted).then_some(dir);
        }
        self.pending = Some(seg);
    }

    /// Writes segment `p` (its feed where the written value changes, then `SPL` or `SLIN`);
    /// `dir_out` is the next segment's direction, `None` when it ends the run. `SPL` where the
    /// cubic through its ends, tangent to the bisectors of the turns there
    /// ([`cubic_point`]), stays within the tolerance of the planned points it stands for;
    /// a block's first and last segments are `SLIN`. Returns whether the block was closed and
    /// a new one opened after it (it was the block's last).
    fn emit(&mut self, p: Segment, dir_out: Option<V3>) -> bool {
        let last_in_block = dir_out.is_none() || self.segments + 1 == SPLINE_MAX_SEGMENTS;
        let smooth = match (p.dir_in, dir_out, last_in_block) {
            (Some(din), Some(dout), false)
                // Turns the cubic can take: modest ones, between segments with a direction.
                if [din, dout].iter().all(|d| turn_deg(*d, p.dir) <= SPLINE_MAX_TURN_DEG) =>
            {
                let (p0, p1) = (p.planned[0], p.pose.t);
                (1..CUBIC_SAMPLES).all(|j| {
                    let c = cubic_point(p0, p1, din, dout, j as f64 / CUBIC_SAMPLES as f64);
                    distance_to_polyline(c, &p.planned) <= self.tol
                })
            }
            _ => false,
        };
        let kind = if smooth { Kind::Spl } else { Kind::Slin };
        // A change of one step of the written value (1e-5 of full scale) is rounding: not
        // written.
        let v = written_value(p.ratio, self.full_scale);
        if self.written.is_none_or(|w| (w - v).abs() > 1) {
            self.written = Some(v);
            self.out.push_back(Step::Feed(p.ratio));
        }
        self.out.push_back(Step::Move {
            kind,
            print: true,
            pose: p.pose,
            point: p.point,
        });
        self.segments += 1;
        if dir_out.is_some() && self.segments == SPLINE_MAX_SEGMENTS {
            self.out.push_back(Step::SplineEnd);
            self.out.push_back(Step::SplineStart);
            self.segments = 0;
            return true;
        }
        false
    }
}

/// Points of a cubic segment checked against the planned path.
const CUBIC_SAMPLES: usize = 16;

/// The point at `s` (0..1) of the cubic (Hermite) from `p0` to `p1` whose end tangents bisect
/// the turns from `d_in` into the segment and from it into `d_out` (unit directions), each as
/// long as the segment: the model of an `SPL` segment through its neighbours the post checks
/// against the tolerance. A turn back on itself gives the chord's direction.
pub fn cubic_point(p0: V3, p1: V3, d_in: V3, d_out: V3, s: f64) -> V3 {
    let d = sub(p1, p0);
    let len = norm(d);
    if len <= 0.0 {
        return p0;
    }
    let dir = scale(d, 1.0 / len);
    let bisector = |a: V3| {
        let m = add(a, dir);
        let n = norm(m);
        if n > crate::tolerance::BISECTOR_ZERO {
            scale(m, len / n)
        } else {
            d
        }
    };
    let (m0, m1) = (bisector(d_in), bisector(d_out));
    let (s2, s3) = (s * s, s * s * s);
    let h = [
        2.0 * s3 - 3.0 * s2 + 1.0,
        s3 - 2.0 * s2 + s,
        -2.0 * s3 + 3.0 * s2,
        s3 - s2,
    ];
    std::array::from_fn(|i| h[0] * p0[i] + h[1] * m0[i] + h[2] * p1[i] + h[3] * m1[i])
}

/// The angle (degrees) between two directions; 90 when either is null.
fn turn_deg(a: V3, b: V3) -> f64 {
    if norm(a) == 0.0 || norm(b) == 0.0 {
        return 90.0;
    }
    dot(a, b).clamp(-1.0, 1.0).acos().to_degrees()
}

/// The distance (mm) from `p` to a polyline (to its point when it has one).
fn distance_to_polyline(p: V3, line: &[V3]) -> f64 {
    match line {
        [] => f64::INFINITY,
        [one] => norm(sub(p, *one)),
        _ => line
            .windows(2)
            .map(|w| distance_to_segment(p, w[0], w[1]))
            .fold(f64::INFINITY, f64::min),
    }
}

impl<I: Iterator<Item = Step>> Iterator for Splined<I> {
    type Item = Step;

    fn next(&mut self) -> Option<Step> {
        loop {
            if let Some(s) = self.out.pop_front() {
                return Some(s);
            }
            if self.done {
                return None;
            }
            match self.inner.next() {
                Some(step) => self.take(step),
                None => {
                    self.close();
                    self.flush_held();
                    self.done = true;
                }
            }
        }
    }
}

/// The feed's analog value as written (`ratio / full_scale` within 0..1, 5 decimals), in
/// steps of 1e-5.
fn written_value(ratio: f64, full_scale: f64) -> i64 {
    ((ratio / full_scale).clamp(0.0, 1.0) * 1e5).round() as i64
}

/// The distance (mm) from `p` to the segment from `a` to `b`.
fn distance_to_segment(p: V3, a: V3, b: V3) -> f64 {
    let ab = sub(b, a);
    let l2 = dot(ab, ab);
    let t = if l2 > 0.0 {
        (dot(sub(p, a), ab) / l2).clamp(0.0, 1.0)
    } else {
        0.0
    };
    norm(sub(sub(p, a), scale(ab, t)))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn cubic_and_distances() {
        let x = [1.0, 0.0, 0.0];
        // Straight on: the cubic is the line.
        let c = cubic_point([0.0; 3], [2.0, 0.0, 0.0], x, x, 0.5);
        assert!(norm(sub(c, [1.0, 0.0, 0.0])) < 1e-12);
        // Its ends are the segment's.
        let y = [0.0, 1.0, 0.0];
        assert_eq!(cubic_point([0.0; 3], [2.0, 0.0, 0.0], y, y, 0.0), [0.0; 3]);
        let d = distance_to_segment([1.0, 1.0, 0.0], [0.0; 3], [2.0, 0.0, 0.0]);
        assert!((d - 1.0).abs() < 1e-12);
        let d = distance_to_segment([3.0, 0.0, 0.0], [0.0; 3], [2.0, 0.0, 0.0]);
        assert!((d - 1.0).abs() < 1e-12);
        let line = [[0.0; 3], [1.0, 0.0, 0.0], [1.0, 2.0, 0.0]];
        assert!(distance_to_polyline([1.0, 1.0, 0.0], &line).abs() < 1e-12);
    }
}
