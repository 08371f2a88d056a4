//! Marlin G-code for 3-axis printers: every feature's tool axis must be +Z.
//!
//! The program is what slicer G-code viewers expect: `;LAYER_CHANGE`, `;Z:`, `;HEIGHT:`,
//! `;LAYER:<n>` over the whole build order, `;FEATURE:<id>` and `;FEATURE_LAYER:<n>`, `;TYPE:`, `;WIDTH:`
//! (see `gcode::LayerMarks`), relative extrusion (`M83`, each `G1`'s `E` is that segment's filament length),
//! fixed-point numbers (X/Y/Z 3 decimals, E 5, F whole mm/min), retraction around travels, and
//! the profile's motion limits in the header (`M201`, `M204`, `M205`).
//!
//! The profile's `start_gcode` runs after the header (placeholders filled in, see
//! [`crate::custom`]), `end_gcode` after the last move, retraction and lift; the fan follows
//! `fan_first_layer` on beads resting on the plate and `fan_speed` above (`M106`/`M107`).
//! E is rounded cumulatively, so the E written adds up to the planned filament; a print move
//! that goes nowhere once rounded (X, Y and Z as written) is not written, its filament going
//! with the next move, nor one whose E rounds to 0 over less than 0.01 mm.
//!
//! What viewers and printers read (issue 33): the header's `; bed_shape = ` and a config block
//! at the end ([`config`]); the profile's start G-code under `;TYPE:Skirt/Brim` with its
//! `{first_layer_z}` at the first layer's height, so that its purge line is neither "Unknown"
//! nor a layer of its own in a viewer; with [`crate::Job::arcs`], runs of print moves along a
//! circle as `G2`/`G3` ([`arcs`]).

pub mod arcs;
pub mod config;

use crate::gcode::{
    comment_text, e_text, mergeable, push_e_text, push_line, Extrusion, Fan, LayerMarks,
};
use crate::kind::MachineKind;
use crate::machine::MachineProfile;
use crate::placement::bed_offset;
use crate::sink::{insert_notes, Chunked, InMemory, ProgramSink};
use crate::PostError;
use toolpath::{fixed, push_fixed};
use toolpath::{MoveKind, PathPoint, ToolPath};

/// Largest deviation of a tool axis component from +Z (0, 0, 1) that Marlin accepts.
pub const AXIS_TOLERANCE: f64 = 1e-6;

/// Lift of the nozzle at the end of the program (mm), kept within the bed height.
const END_LIFT: f64 = 10.0;

/// A Marlin program for the path, or an error naming the first feature whose tool axis is not
/// +Z (within [`AXIS_TOLERANCE`]), saying it needs `delta5` or `kuka`.
///
/// The part is placed with [`bed_offset`] (XY bounding-box centre on the bed centre, lowest
/// bead bottom on Z0); the header states the offset (`; offset X.. Y.. Z..`, machine = part +
/// offset). `source` (the STEP file's name) is written in the first comment line.
///
/// Other errors: the profile is not a `marlin` profile or is invalid, a point holds a NaN or
/// infinite number, or the path does not fit the bed (saying by how much per axis).
///
/// Moves: a travel that follows printing is preceded by a retraction (`G1 E-r`), lifts by
/// `z_hop`, goes by `G0` at the hop height, lowers again and un-retracts (`G1 E+r`) before the
/// next print move; a print move is `G1 X Y Z E F`, at `first_layer_speed` for beads resting
/// on the plate and `print_speed` otherwise. A path that starts with a print point first
/// travels to it.
pub fn marlin(path: &ToolPath, m: &MachineProfile, source: &str) -> Result<String, PostError> {
    let mut files = InMemory::default();
    marlin_to(path, m, source, &[], &mut files)?;
    let bytes = files.files.pop().map(|f| f.bytes).unwrap_or_default();
    // The program is made of `str`s.
    Ok(String::from_utf8(bytes).unwrap_or_default())
}

/// [`marlin`]'s program, with `notes` (comment lines after the one naming the source, see
/// [`crate::Job::notes`]), written into `sink`'s `program.gcode` as it is made, a megabyte at
/// a time ([`ProgramSink::chunk`]). The file is opened once the path passed the checks [`marlin`] makes; an error
/// writing it is [`PostError::Write`].
pub fn marlin_to(
    path: &ToolPath,
    m: &MachineProfile,
    source: &str,
    notes: &[String],
    sink: &mut dyn ProgramSink,
) -> Result<(), PostError> {
    let job = crate::Job {
        source,
        stem: "",
        notes,
        config: &[],
        arcs: None,
        refused_unreachable: false,
    };
    marlin_job_to(path, m, &job, sink)
}

/// [`marlin_to`] for a [`crate::Job`]: its `config` lines join the program's config block, and
/// with its `arcs` tolerance runs of print moves along a circle are written as `G2`/`G3`.
pub fn marlin_job_to(
    path: &ToolPath,
    m: &MachineProfile,
    job: &crate::Job,
    sink: &mut dyn ProgramSink,
) -> Result<(), PostError> {
    m.check_for(MachineKind::Marlin)?;
    path.check_finite()?;
    if let Some(q) = path.points.iter().find(|q| !is_plus_z(q.axis)) {
        return Err(PostError::ToolAxis {
            feature: q.feature as usize,
            i: q.axis[0],
            j: q.axis[1],
            k: q.axis[2],
            machine: MachineKind::Marlin,
        });
    }
    let offset = bed_offset(path, m)?;
    let mut file = Chunked::open(sink, "program.gcode")?;

    let mut w = Writer::new(m);
    // The purge line's height: the first layer's, when a nozzle can lay it.
    let first_layer = config::layer_heights(path)
        .map(|h| h.0)
        .filter(|&t| t > 0.0 && t <= m.nozzle_diameter)
        .unwrap_or(crate::custom::PURGE_THICKNESS);
    w.header(m, job.source, offset, first_layer);
    insert_notes(&mut w.out, job.notes);
    let machine = |q: &PathPoint| [0, 1, 2].map(|k| ((q.p[k] + offset[k]) * 1e3).round() / 1e3);
    let mut i = 0;
    while i < path.points.len() {
        let q = &path.points[i];
        // Machine coordinates as written (0.001 mm).
        let t = machine(q);
        if let (Some(tol), Some(at), MoveKind::Print) = (job.arcs, w.at, q.kind) {
            // The first few points first: most runs (lines, corners) end there, cheaply.
            let start = [at[0], at[1]];
            let head = arc_run(&path.points[i..], t[2], &machine, arcs::MIN_ARC_POINTS);
            let arc = arcs::fit(start, &head, tol).and_then(|_| {
                arcs::fit(
                    start,
                    &arc_run(&path.points[i..], t[2], &machine, ARC_RUN),
                    tol,
                )
            });
            if let Some(arc) = arc {
                let points = &path.points[i..i + arc.count];
                for p in points {
                    w.comments(p, t[2]);
                }
                let end = machine(&points[arc.count - 1]);
                w.arc(end, arc, points);
                file.pass_on(&mut w.out)?;
                i += arc.count;
                continue;
            }
        }
        w.comments(q, t[2]);
        match q.kind {
            MoveKind::Travel => w.travel(t),
            MoveKind::Print => {
                if w.at.is_none() {
                    w.travel(t);
                }
                w.print(t, q);
            }
        }
        file.pass_on(&mut w.out)?;
        i += 1;
    }
    w.footer(m);
    w.out.push_str(&config::block(m, path, job.config));
    file.finish(&w.out)
}

/// Most print points one arc is looked for over.
const ARC_RUN: usize = 4096;

/// The machine XY of the print points from the first of `points` on that an arc may stand
/// for: the same feature, layer, role, bead width (within half a micrometre) and machine Z
/// `z`, at most `most` of them.
fn arc_run(
    points: &[PathPoint],
    z: f64,
    machine: &dyn Fn(&PathPoint) -> [f64; 3],
    most: usize,
) -> Vec<[f64; 2]> {
    let Some(first) = points.first() else {
        return vec![];
    };
    points
        .iter()
        .take(most)
        .take_while(|q| {
            q.kind == MoveKind::Print
                && (q.feature, q.layer, q.role) == (first.feature, first.layer, first.role)
                && (f64::from(q.width) - f64::from(first.width)).abs() <= WIDTH_STEP
        })
        .map(machine)
        .take_while(|t| t[2] == z)
        .map(|t| [t[0], t[1]])
        .collect()
}

/// Bead widths within this of each other (mm) are one `;WIDTH:`.
const WIDTH_STEP: f64 = 5e-4;

/// Appends `code X.. Y.. Z..` (the machine position `t`, 0.001 mm) to `out`, straight into
/// the text: a plan writes millions of these moves.
fn push_move(out: &mut String, code: &str, t: [f64; 3]) {
    out.push_str(code);
    for (word, x) in [" X", " Y", " Z"].into_iter().zip(t) {
        out.push_str(word);
        push_fixed(out, x, 3);
    }
}

/// Whether `axis` is +Z within [`AXIS_TOLERANCE`].
fn is_plus_z(axis: [f64; 3]) -> bool {
    axis[0].abs() <= AXIS_TOLERANCE
        && axis[1].abs() <= AXIS_TOLERANCE
        && (axis[2] - 1.0).abs() <= AXIS_TOLERANCE
}

/// The program being written and the machine state it leaves.
struct Writer {
    out: String,
    /// Nozzle position (machine coordinates) the last move ended at, the hop excluded.
    at: Option<[f64; 3]>,
    /// The filament is retracted.
    retracted: bool,
    /// The last move printed.
    printing: bool,
    /// The nozzle is lifted by the z-hop.
    hopped: bool,
    marks: LayerMarks,
    fan: Fan,
    extrusion: Extrusion,
    retraction: f64,
    retraction_f: String,
    travel_f: String,
    print_f: String,
    first_layer_f: String,
    z_hop: f64,
    z_max: f64,
}

impl Writer {
    fn new(m: &MachineProfile) -> Writer {
        let f = |speed: f64| fixed(speed * 60.0, 0);
        Writer {
            out: String::new(),
            at: None,
            retracted: false,
            printing: false,
            hopped: false,
            marks: LayerMarks::default(),
            fan: Fan::new(m),
            extrusion: Extrusion::default(),
            retraction: m.retraction_length,
            retraction_f: f(m.retraction_speed),
            travel_f: f(m.travel_speed),
            print_f: f(m.print_speed),
            first_layer_f: f(m.first_layer_speed),
            z_hop: m.z_hop,
            z_max: m.bed_size[2],
        }
    }

    fn line(&mut self, s: &str) {
        push_line(&mut self.out, s);
    }

    fn header(&mut self, m: &MachineProfile, source: &str, offset: [f64; 3], first_layer: f64) {
        self.line(&format!(
            "; generated by features from {}",
            comment_text(source)
        ));
        self.line(&format!("; machine: {} (marlin)", comment_text(&m.name)));
        self.line(&format!(
            "; offset X{} Y{} Z{} (machine = part + offset)",
            fixed(offset[0], 3),
            fixed(offset[1], 3),
            fixed(offset[2], 3)
        ));
        self.line(&format!("; bed_shape = {}", config::bed_shape(m)));
        self.line(&format!(
            "; nozzle {} mm, filament {} mm, bead {} mm",
            fixed(m.nozzle_diameter, 2),
            fixed(m.filament_diameter, 2),
            fixed(m.bead_width, 2)
        ));
        self.line(&format!(
            "; F: mm/min along the XYZ path: print_speed {}, first_layer_speed {}, travel_speed {} (at most max_feed_mm_min {})",
            self.print_f,
            self.first_layer_f,
            self.travel_f,
            fixed(m.max_feed_mm_min(), 0)
        ));
        self.line(";FLAVOR:Marlin");
        self.line("G21 ; millimetres");
        self.line("G90 ; absolute XYZ");
        self.line("M83 ; relative extrusion: E is each segment's filament length");
        self.motion_limits(m);
        // The purge line of the start G-code is the skirt's kind of bead, on the first layer.
        self.line(";TYPE:Skirt/Brim");
        self.line(&format!(";WIDTH:{}", fixed(m.bead_width, 3)));
        self.line(&format!(";HEIGHT:{}", fixed(first_layer, 3)));
        self.line("; start_gcode");
        self.out.push_str(&m.start_gcode_text_at(first_layer));
        if !self.out.ends_with('\n') {
            self.out.push('\n');
        }
        self.line("; end of start_gcode");
        self.line("G90 ; absolute XYZ");
        self.line("M83 ; relative extrusion");
    }

    /// The profile's motion limits, those it gives, as Marlin sets them (and PrusaSlicer's
    /// G-code viewer reads them for its time estimate): `M201` X/Y acceleration caps (the
    /// larger of the print and travel accelerations), `M204 P T` print and travel
    /// accelerations, `M205` X/Y jerk (`max_jerk`). Not `max_speed` as `M203`: firmwares read
    /// its units differently (mm/s in Marlin, mm/min in RepRapFirmware; PrusaSlicer's viewer
    /// took our 200 mm/s for 200 mm/min), and the programmed speeds stay below it anyway.
    fn motion_limits(&mut self, m: &MachineProfile) {
        let t = |v: f64| fixed(v, 0);
        let travel = m.travel_acceleration.or(m.max_acceleration);
        if let Some(cap) = m
            .max_acceleration
            .into_iter()
            .chain(travel)
            .reduce(f64::max)
        {
            self.line(&format!(
                "M201 X{} Y{} ; acceleration caps (mm/s^2)",
                t(cap),
                t(cap)
            ));
        }
        if let (Some(p), Some(tr)) = (m.max_acceleration, travel) {
            self.line(&format!(
                "M204 P{} T{} ; print and travel acceleration (mm/s^2)",
                t(p),
                t(tr)
            ));
        } else if let Some(tr) = travel {
            self.line(&format!("M204 T{} ; travel acceleration (mm/s^2)", t(tr)));
        }
        if let Some(j) = m.max_jerk {
            self.line(&format!("M205 X{} Y{} ; jerk (mm/s)", t(j), t(j)));
        }
    }

    /// The layer comments (`gcode::LayerMarks`) where the point's layer or feature changes.
    fn comments(&mut self, q: &PathPoint, z: f64) {
        self.marks.write(q, z, &mut self.out);
    }

    fn retract(&mut self) {
        if self.retraction > 0.0 && !self.retracted {
            let line = format!("G1 E-{} F{}", fixed(self.retraction, 5), self.retraction_f);
            self.line(&line);
            self.retracted = true;
        }
    }

    fn hop_z(&self, z: f64) -> f64 {
        (z + self.z_hop).min(self.z_max).max(z)
    }

    /// Before extruding again: down from a z-hop to where the nozzle is, and the retracted
    /// filament fed back.
    fn resume(&mut self) {
        if self.hopped {
            if let Some(at) = self.at {
                let line = format!("G0 Z{} F{}", fixed(at[2], 3), self.travel_f);
                self.line(&line);
            }
            self.hopped = false;
        }
        if self.retracted {
            let line = format!("G1 E{} F{}", fixed(self.retraction, 5), self.retraction_f);
            self.line(&line);
            self.retracted = false;
        }
    }

    /// Writes the filament of print moves merged away at the end of a run (a run that went
    /// nowhere once rounded, a dot) as an extrusion in place, so none is lost.
    fn flush(&mut self) {
        let de = self.extrusion.add(0.0);
        if de == 0 {
            return;
        }
        self.resume();
        let line = format!(
            "G1 E{} F{} ; filament of moves that went nowhere",
            e_text(de),
            self.print_f
        );
        self.line(&line);
        self.extrusion.written(de);
        self.printing = true;
    }

    fn travel(&mut self, t: [f64; 3]) {
        self.flush();
        if self.printing {
            self.retract();
        }
        self.printing = false;
        if self.z_hop > 0.0 && !self.hopped {
            if let Some(at) = self.at {
                let line = format!("G0 Z{} F{}", fixed(self.hop_z(at[2]), 3), self.travel_f);
                self.line(&line);
            }
            self.hopped = true;
        }
        let z = if self.hopped { self.hop_z(t[2]) } else { t[2] };
        let out = &mut self.out;
        push_move(out, "G0", [t[0], t[1], z]);
        out.push_str(" F");
        out.push_str(&self.travel_f);
        out.push('\n');
        self.at = Some(t);
    }

    fn print(&mut self, t: [f64; 3], q: &PathPoint) {
        let de = self.extrusion.add(q.e);
        // A move that goes nowhere as written, or extrudes nothing over a few micrometres, is
        // merged into the next: its filament goes with that move.
        if let Some(at) = self.at {
            let d =
                ((t[0] - at[0]).powi(2) + (t[1] - at[1]).powi(2) + (t[2] - at[2]).powi(2)).sqrt();
            if t == at || (de == 0 && mergeable(d, 0.0)) {
                return;
            }
        }
        self.resume();
        // A bead resting on the plate (its bottom within 10 µm of Z0) goes at first-layer speed.
        let on_plate = t[2] - f64::from(q.thickness.max(0.0)) <= 0.01;
        self.fan.set(on_plate, &mut self.out);
        push_move(&mut self.out, "G1", t);
        self.end_print_move(de, on_plate, t);
    }

    /// The end of a print move's line written: its filament `de`, its feed (first-layer speed
    /// for a bead `on_plate`); the head then stands at `to`.
    fn end_print_move(&mut self, de: i64, on_plate: bool, to: [f64; 3]) {
        let f = if on_plate {
            &self.first_layer_f
        } else {
            &self.print_f
        };
        let out = &mut self.out;
        if de != 0 {
            out.push_str(" E");
            push_e_text(out, de);
        }
        out.push_str(" F");
        out.push_str(f);
        out.push('\n');
        self.extrusion.written(de);
        self.printing = true;
        self.at = Some(to);
    }

    /// A print arc ending at `end` (machine coordinates) standing for `points`: their
    /// filament, at their speed.
    fn arc(&mut self, end: [f64; 3], arc: arcs::Arc, points: &[PathPoint]) {
        let Some(at) = self.at else { return };
        let mut de = 0;
        for q in points {
            de = self.extrusion.add(q.e);
        }
        self.resume();
        let on_plate = points
            .first()
            .is_some_and(|q| end[2] - f64::from(q.thickness.max(0.0)) <= 0.01);
        self.fan.set(on_plate, &mut self.out);
        let out = &mut self.out;
        out.push_str(if arc.ccw { "G3 X" } else { "G2 X" });
        push_fixed(out, end[0], 3);
        out.push_str(" Y");
        push_fixed(out, end[1], 3);
        out.push_str(" I");
        push_fixed(out, arc.centre[0] - at[0], 3);
        out.push_str(" J");
        push_fixed(out, arc.centre[1] - at[1], 3);
        self.end_print_move(de, on_plate, end);
    }

    fn footer(&mut self, m: &MachineProfile) {
        self.flush();
        self.line("; end");
        self.retract();
        if let Some(at) = self.at {
            let z = (at[2].max(0.0) + END_LIFT).min(self.z_max);
            let line = format!("G0 Z{} F{}", fixed(z, 3), self.travel_f);
            self.line(&line);
        }
        self.line("; end_gcode");
        self.out.push_str(&m.end_gcode_text());
        if !self.out.ends_with('\n') {
            self.out.push('\n');
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use toolpath::Role;

    /// Passed on in pieces of any size, the program is the same text: the writer's look back
    /// at the last character (the end G-code's line break) survives the cuts.
    #[test]
    fn the_program_is_the_same_in_pieces_of_any_size() {
        let mut m = MachineProfile::builtin(MachineKind::Marlin);
        let mut points = vec![];
        for layer in 0..4 {
            let z = 0.2 * (layer + 1) as f64;
            for k in 0..60 {
                let kind = if k % 20 == 0 {
                    MoveKind::Travel
                } else {
                    MoveKind::Print
                };
                points.push(PathPoint {
                    feature: layer / 2,
                    layer,
                    kind,
                    p: [50.0 + k as f64, 50.0 + (k % 7) as f64, z],
                    axis: [0.0, 0.0, 1.0],
                    e: if kind == MoveKind::Print { 0.03 } else { 0.0 },
                    thickness: 0.2,
                    width: 0.45,
                    role: Role::Perimeter,
                });
            }
        }
        let path = ToolPath { points };
        let notes = ["a note".to_string()];
        for end in [None, Some(String::new()), Some("M84".to_string())] {
            m.end_gcode = end;
            let texts: Vec<Vec<u8>> = [1, 100, usize::MAX]
                .iter()
                .map(|&chunk| {
                    let mut files = InMemory::chunked(chunk);
                    marlin_to(&path, &m, "part.step", &notes, &mut files).unwrap();
                    assert_eq!(files.files.len(), 1);
                    files.files.remove(0).bytes
                })
                .collect();
            assert!(texts[0].len() > 2_000);
            assert_eq!(texts[0], texts[2]);
            assert_eq!(texts[1], texts[2]);
            let text = String::from_utf8_lossy(&texts[0]);
            assert!(text.contains("; a note\n") && text.ends_with('\n'));
        }
    }
}
