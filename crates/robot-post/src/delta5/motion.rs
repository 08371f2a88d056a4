//! The moves of a 5-axis program: travels (retract, hop, reorientation at the safe height),
//! print moves split into sub-moves for the C step and the kinematic error goal, the work
//! envelope check, and the kinematic error measured as the controller runs each move.

use std::collections::BTreeMap;

use super::figures::KinematicFigures;
use super::geometry::{Delta5Geometry, FIT_TOLERANCE};
use super::kinematics::{
    angle_deg, distance_to_segment, forward, lerp, machine_to_bed, to_machine, Pose,
};
use crate::gcode::{e_text, mergeable, push_line, Extrusion, Fan, LayerMarks};
use crate::machine::MachineProfile;
use crate::tolerance::{MOVE_ZERO, STEP_COUNT_SLACK};
use crate::PostError;
use toolpath::vec3::{norm, sub, unit};
use toolpath::{fixed, PathPoint};

/// Most sub-moves one planned segment is split into.
pub const MAX_SUBDIVISION: usize = 1024;

/// Machine joints `[X, Y, Z, B, C]` rounded as written: XYZ to 0.001 mm, B and C to 0.0001°.
type Joints = [f64; 5];

fn rounded(xyz: [f64; 3], b: f64, c: f64) -> Joints {
    let r3 = |v: f64| (v * 1e3).round() / 1e3;
    let r4 = |v: f64| (v * 1e4).round() / 1e4;
    [r3(xyz[0]), r3(xyz[1]), r3(xyz[2]), r4(b), r4(c)]
}

/// The kinematic error of one move ([`Writer::move_error`]): the largest distance, the sum of
/// the distances and the number of steps.
type MoveError = (f64, f64, usize);

/// Running kinematic figures of one feature.
#[derive(Default)]
pub(super) struct Accumulator {
    pub(super) figures: KinematicFigures,
    pub(super) sum: f64,
}

/// What a run of the [`Writer`] over the path is for: the program is made in two, so that its
/// header can give the kinematic figures while its moves are passed on as they are made.
pub(super) enum Pass {
    /// The first: each print segment split until its kinematic error meets the goal (the
    /// figures, plot and warnings are this run's), the number of its sub-moves recorded in
    /// `splits`, in order; the text is made and dropped.
    Measure { splits: Vec<u32> },
    /// The second: each print segment split as recorded, its error not measured again; the
    /// text is written (the figures this run gathers are not used).
    Write { splits: std::vec::IntoIter<u32> },
}

/// The program being written and the machine state it leaves.
pub(super) struct Writer<'a> {
    pub(super) out: String,
    pass: Pass,
    m: &'a MachineProfile,
    g: &'a Delta5Geometry,
    offset: [f64; 3],
    /// Joints the last move ended at, the hop excluded.
    pub(super) at: Option<Joints>,
    retracted: bool,
    printing: bool,
    hopped: bool,
    marks: LayerMarks,
    /// The feature being written, for envelope errors.
    current: usize,
    safe_z: f64,
    lo: [f64; 3],
    hi: [f64; 3],
    travel_f: String,
    retraction_f: String,
    extrusion: Extrusion,
    fan: Fan,
    /// Print moves whose scaled feed was clamped to `max_feed_mm_min`, and the largest feed
    /// asked for before clamping (mm/min).
    pub(super) clamped: (usize, f64),
    pub(super) figures: BTreeMap<usize, Accumulator>,
    /// (feature, length along the printed path, largest error of the move) per print move.
    pub(super) plot: Vec<(usize, f64, f64)>,
    printed_length: f64,
}

impl<'a> Writer<'a> {
    pub(super) fn new(
        m: &'a MachineProfile,
        g: &'a Delta5Geometry,
        offset: [f64; 3],
        safe_z: f64,
        pass: Pass,
    ) -> Writer<'a> {
        let (x0, y0) = if m.bed_origin_centre {
            (-m.bed_size[0] / 2.0, -m.bed_size[1] / 2.0)
        } else {
            (0.0, 0.0)
        };
        Writer {
            out: String::new(),
            pass,
            m,
            g,
            offset,
            at: None,
            retracted: false,
            printing: false,
            hopped: false,
            marks: LayerMarks::default(),
            current: 0,
            safe_z,
            lo: [x0, y0, g.z_min],
            hi: [x0 + m.bed_size[0], y0 + m.bed_size[1], m.bed_size[2]],
            travel_f: fixed(m.travel_speed * 60.0, 0),
            retraction_f: fixed(m.retraction_speed * 60.0, 0),
            extrusion: Extrusion::default(),
            fan: Fan::new(m),
            clamped: (0, 0.0),
            figures: BTreeMap::new(),
            plot: Vec::new(),
            printed_length: 0.0,
        }
    }

    /// Appends the line `s` (and its line break) to the text, unless measuring: that pass
    /// drops its text.
    fn line(&mut self, s: &str) {
        if !self.measuring() {
            push_line(&mut self.out, s);
        }
    }

    /// Whether this is the measuring pass, whose text is dropped.
    fn measuring(&self) -> bool {
        matches!(self.pass, Pass::Measure { .. })
    }

    /// The pass that writes what this one measured: the same splits of the print segments.
    pub(super) fn replay(&mut self) -> Pass {
        let splits = match &mut self.pass {
            Pass::Measure { splits } => std::mem::take(splits),
            Pass::Write { .. } => Vec::new(),
        };
        Pass::Write {
            splits: splits.into_iter(),
        }
    }

    /// `;LAYER:` and `;FEATURE:` comments where the point's layer or feature changes.
    pub(super) fn comments(&mut self, q: &PathPoint) {
        self.current = q.feature as usize;
        self.marks.write(q, q.p[2] + self.offset[2], &mut self.out);
    }

    /// Refuses a nozzle position outside the work envelope.
    fn check(&self, xyz: [f64; 3]) -> Result<(), PostError> {
        let mut excess = Vec::new();
        for (k, letter) in ["X", "Y", "Z"].iter().enumerate() {
            if xyz[k] < self.lo[k] - FIT_TOLERANCE {
                excess.push(format!(
                    "{letter} {} is {} mm below {}",
                    fixed(xyz[k], 3),
                    fixed(self.lo[k] - xyz[k], 3),
                    fixed(self.lo[k], 3)
                ));
            } else if xyz[k] > self.hi[k] + FIT_TOLERANCE || xyz[k].is_nan() {
                excess.push(format!(
                    "{letter} {} is {} mm above {}",
                    fixed(xyz[k], 3),
                    fixed(xyz[k] - self.hi[k], 3),
                    fixed(self.hi[k], 3)
                ));
            }
        }
        if excess.is_empty() {
            Ok(())
        } else {
            Err(PostError::Delta5Envelope {
                feature: self.current,
                name: self.m.name.clone(),
                excess: excess.join(", "),
            })
        }
    }

    fn joints(&self, p: [f64; 3], b: f64, c: f64) -> Joints {
        rounded(to_machine(p, b, c, self.g, self.offset), b, c)
    }

    fn hop_z(&self, z: f64) -> f64 {
        (z + self.m.z_hop).min(self.hi[2]).max(z)
    }

    fn retract(&mut self) {
        if self.m.retraction_length > 0.0 && !self.retracted {
            let line = format!(
                "G1 E-{} F{}",
                fixed(self.m.retraction_length, 5),
                self.retraction_f
            );
            self.line(&line);
            self.retracted = true;
        }
    }

    fn g0_z(&mut self, at: Joints, z: f64) -> Result<(), PostError> {
        self.check([at[0], at[1], z])?;
        let line = format!("G0 Z{} F{}", fixed(z, 3), self.travel_f);
        self.line(&line);
        Ok(())
    }

    /// How far a travel from where the machine is through the poses `run` turns the bed in
    /// all: the turns of B and of C summed over its steps (degrees).
    pub(super) fn turn(&self, run: &[Pose]) -> f64 {
        let Some(at) = self.at else {
            return 0.0;
        };
        let (mut b, mut c) = (at[3], at[4]);
        let mut turn = 0.0;
        for p in run {
            turn += (p.b - b).abs() + (p.c - c).abs();
            (b, c) = (p.b, p.c);
        }
        turn
    }

    /// To the point `q` (bed at `pose`) at hop height, by the safe height when `lift` or when
    /// this step turns B or C by more than `reorient_lift_deg`; see the module documentation.
    pub(super) fn travel(
        &mut self,
        q: &PathPoint,
        pose: &Pose,
        lift: bool,
    ) -> Result<(), PostError> {
        self.flush();
        if self.printing {
            self.retract();
        }
        self.printing = false;
        let target = self.joints(q.p, pose.b, pose.c);
        self.check([target[0], target[1], target[2]])?;
        let hop = self.hop_z(target[2]);
        let reorient = match self.at {
            Some(at) => {
                lift || (target[3] - at[3]).abs() > self.g.reorient_lift_deg
                    || (target[4] - at[4]).abs() > self.g.reorient_lift_deg
            }
            None => true,
        };
        if let Some(at) = self.at {
            if !self.hopped {
                if self.m.z_hop > 0.0 {
                    self.g0_z(at, self.hop_z(at[2]))?;
                }
                self.hopped = true;
            }
        }
        if reorient {
            let (x, y) = self.at.map_or((target[0], target[1]), |at| (at[0], at[1]));
            self.check([x, y, self.safe_z])?;
            let lines = [
                format!("G0 Z{} F{}", fixed(self.safe_z, 3), self.travel_f),
                format!(
                    "G0 B{} C{} F{} ; reorient at the safe height",
                    fixed(target[3], 4),
                    fixed(target[4], 4),
                    self.travel_f
                ),
                format!(
                    "G0 X{} Y{} F{}",
                    fixed(target[0], 3),
                    fixed(target[1], 3),
                    self.travel_f
                ),
                format!("G0 Z{} F{}", fixed(hop, 3), self.travel_f),
            ];
            self.check([target[0], target[1], self.safe_z])?;
            for l in &lines {
                self.line(l);
            }
        } else {
            self.check([target[0], target[1], hop])?;
            let line = format!(
                "G0 X{} Y{} Z{} B{} C{} F{}",
                fixed(target[0], 3),
                fixed(target[1], 3),
                fixed(hop, 3),
                fixed(target[3], 4),
                fixed(target[4], 4),
                self.travel_f
            );
            self.line(&line);
        }
        self.hopped = true;
        self.at = Some(target);
        Ok(())
    }

    /// The planned segment from `a` (bed at `pa`, where the machine is) to `q` (bed at `pq`),
    /// as one or more `G1` moves.
    pub(super) fn print(
        &mut self,
        a: &PathPoint,
        pa: &Pose,
        q: &PathPoint,
        pq: &Pose,
    ) -> Result<(), PostError> {
        let Some(start) = self.at else {
            return Ok(());
        };
        if self.hopped {
            self.g0_z(start, start[2])?;
            self.hopped = false;
        }
        if self.retracted {
            let line = format!(
                "G1 E{} F{}",
                fixed(self.m.retraction_length, 5),
                self.retraction_f
            );
            self.line(&line);
            self.retracted = false;
        }
        let length = norm(sub(q.p, a.p));
        let replayed = match &mut self.pass {
            Pass::Write { splits } => splits.next(),
            Pass::Measure { .. } => None,
        };
        let (moves, errors) = match replayed {
            Some(n) => (self.sub_moves(a, pa, q, pq, n as usize), Vec::new()),
            None => self.subdivide(start, a, pa, q, pq, length),
        };
        if let Pass::Measure { splits } = &mut self.pass {
            // At most MAX_SUBDIVISION.
            splits.push(moves.len() as u32);
        }
        let n = moves.len();
        let measuring = self.measuring();

        // Planned deposition speed along the part.
        let bottom = match unit(q.axis) {
            Some(ax) => q.p[2] - f64::from(q.thickness.max(0.0)) * ax[2],
            None => q.p[2],
        };
        let on_table = bottom + self.offset[2] <= 0.01;
        let v = if on_table {
            self.m.first_layer_speed
        } else {
            self.m.print_speed
        };
        let part_step = length / n as f64;
        let mut from = start;
        let acc = self.figures.entry(q.feature as usize).or_default();
        if n > 1 {
            acc.figures.subdivided_segments += 1;
        }
        if pq.patched {
            acc.figures.singular_points += 1;
        }
        let realised = machine_to_bed([0.0, 0.0, 1.0], pq.b.to_radians(), pq.c.to_radians());
        if let Some(planned) = unit(q.axis) {
            let dev = angle_deg(planned, realised);
            acc.figures.max_axis_deviation_deg = acc.figures.max_axis_deviation_deg.max(dev);
        }
        let max_feed = self.m.max_feed_mm_min();
        self.fan.set(on_table, &mut self.out);
        let mut lines = Vec::with_capacity(n);
        let mut written = Vec::with_capacity(n);
        for (k, &to) in moves.iter().enumerate() {
            let xyz = norm(sub([to[0], to[1], to[2]], [from[0], from[1], from[2]]));
            let rotary = (to[3] - from[3]).hypot(to[4] - from[4]);
            let de = self.extrusion.add(q.e / n as f64);
            if let Some(&(worst, sum, count)) = errors.get(k) {
                acc.figures.max_mm = acc.figures.max_mm.max(worst);
                acc.sum += sum;
                acc.figures.samples += count;
                self.printed_length += part_step;
                self.plot
                    .push((q.feature as usize, self.printed_length, worst));
            }
            // Zero-length in machine coordinates (X, Y, Z, B and C as written), or extruding
            // nothing over a few micrometres: merged into the next move, which carries its E.
            if to == from || (de == 0 && mergeable(xyz, rotary)) {
                continue;
            }
            let distance = if xyz > MOVE_ZERO { xyz } else { rotary };
            let f = if part_step > MOVE_ZERO && distance > 0.0 {
                60.0 * v * distance / part_step
            } else {
                60.0 * v
            };
            let f = if f > max_feed {
                self.clamped.0 += 1;
                self.clamped.1 = self.clamped.1.max(f);
                max_feed
            } else {
                f.max(0.001)
            };
            self.extrusion.written(de);
            acc.figures.max_c_step_deg = acc.figures.max_c_step_deg.max((to[4] - from[4]).abs());
            if !measuring {
                let e = if de == 0 {
                    String::new()
                } else {
                    format!(" E{}", e_text(de))
                };
                lines.push(format!(
                    "G1 X{} Y{} Z{} B{} C{}{e} F{}",
                    fixed(to[0], 3),
                    fixed(to[1], 3),
                    fixed(to[2], 3),
                    fixed(to[3], 4),
                    fixed(to[4], 4),
                    fixed(f, 3)
                ));
            }
            written.push(to);
            from = to;
        }
        acc.figures.print_moves += written.len();
        for to in &written {
            self.check([to[0], to[1], to[2]])?;
        }
        for l in &lines {
            self.line(l);
        }
        if let Some(&last) = written.last() {
            self.printing = true;
            self.at = Some(last);
        }
        Ok(())
    }

    /// The planned segment from `a` (bed at `pa`) to `q` (bed at `pq`) split into `n` equal
    /// sub-moves: positions on the segment, B and C linear along it, as joints.
    fn sub_moves(
        &self,
        a: &PathPoint,
        pa: &Pose,
        q: &PathPoint,
        pq: &Pose,
        n: usize,
    ) -> Vec<Joints> {
        (1..=n)
            .map(|k| {
                if k == n {
                    self.joints(q.p, pq.b, pq.c)
                } else {
                    let f = k as f64 / n as f64;
                    let b = pa.b + (pq.b - pa.b) * f;
                    let c = pa.c + (pq.c - pa.c) * f;
                    self.joints(lerp(a.p, q.p, f), b, c)
                }
            })
            .collect()
    }

    /// The sub-moves of the planned segment from `a` (bed at `pa`) to `q` (bed at `pq`,
    /// `length` mm from `a`), the machine at `start`: split until no move turns C by more
    /// than `max_c_step_deg` and the kinematic error stays within its goal (or
    /// [`MAX_SUBDIVISION`] moves, or sub-moves of less than a micrometre); with each move's
    /// error ([`Writer::move_error`]).
    fn subdivide(
        &self,
        start: Joints,
        a: &PathPoint,
        pa: &Pose,
        q: &PathPoint,
        pq: &Pose,
        length: f64,
    ) -> (Vec<Joints>, Vec<MoveError>) {
        let g = self.g;
        let dc = (pq.c - pa.c).abs();
        let mut n = ((dc / g.max_c_step_deg - STEP_COUNT_SLACK).ceil().max(1.0) as usize)
            .min(MAX_SUBDIVISION);
        loop {
            let moves = self.sub_moves(a, pa, q, pq, n);
            let mut from = start;
            let mut errors = Vec::with_capacity(n);
            for &to in &moves {
                errors.push(self.move_error(from, to, a.p, q.p));
                from = to;
            }
            let worst = errors.iter().map(|e| e.0).fold(0.0, f64::max);
            if worst <= g.kinematic_error_goal || n >= MAX_SUBDIVISION || length / (n as f64) < 1e-3
            {
                return (moves, errors);
            }
            // The error of a turning move shrinks with the square of its length.
            let grow = (n as f64 * (worst / g.kinematic_error_goal).sqrt() * 1.1).ceil() as usize;
            n = grow.max(n + 1).min(MAX_SUBDIVISION);
        }
    }

    /// Kinematic error of the move `from` → `to` against the planned segment `p0`–`p1`: the
    /// controller's linear interpolation of the joints in steps of the resolutions, each step
    /// transformed back to the part (Isa & Lazoglu 2019, Fig. 16, after Makhanov). Returns the
    /// largest distance, the sum of the distances and the number of steps.
    fn move_error(&self, from: Joints, to: Joints, p0: [f64; 3], p1: [f64; 3]) -> MoveError {
        let g = self.g;
        let steps = [
            (to[0] - from[0]).abs() / g.resolution_xyz,
            (to[1] - from[1]).abs() / g.resolution_xyz,
            (to[2] - from[2]).abs() / g.resolution_xyz,
            (to[3] - from[3]).abs() / g.resolution_b_deg,
            (to[4] - from[4]).abs() / g.resolution_c_deg,
        ]
        .into_iter()
        .fold(1.0, f64::max)
        .ceil()
        .min(1e6) as usize;
        let (mut worst, mut sum) = (0.0f64, 0.0);
        for k in 1..=steps {
            let f = k as f64 / steps as f64;
            let j: Joints = std::array::from_fn(|i| from[i] + (to[i] - from[i]) * f);
            let (p, _) = forward(j, g, self.offset);
            let d = distance_to_segment(p, p0, p1);
            worst = worst.max(d);
            sum += d;
        }
        (worst, sum, steps)
    }

    /// Writes the filament of print moves merged away at the end of a run (moves that went
    /// nowhere once rounded) as an extrusion in place, so none is lost.
    fn flush(&mut self) {
        let de = self.extrusion.add(0.0);
        if de != 0 {
            let line = format!(
                "G1 E{} F{} ; filament of moves that went nowhere",
                e_text(de),
                fixed(self.m.print_speed * 60.0, 0)
            );
            self.line(&line);
            self.extrusion.written(de);
            self.printing = true;
        }
    }

    pub(super) fn footer(&mut self) -> Result<(), PostError> {
        self.flush();
        self.line("; end");
        self.retract();
        if let Some(at) = self.at {
            self.g0_z(at, self.safe_z.max(at[2]).min(self.hi[2]))?;
            let line = format!("G0 B0.0000 F{} ; level the bed", self.travel_f);
            self.line(&line);
        }
        self.line("; end_gcode");
        let end = self.m.end_gcode_text();
        for l in end.lines() {
            self.line(l);
        }
        Ok(())
    }
}
