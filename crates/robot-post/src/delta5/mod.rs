//! The 5-axis printer post: a delta (or Cartesian) printer whose nozzle stays pointing down
//! (−Z) while the bed tilts (B) and rotates (C) so that each point's tool axis becomes machine
//! +Z (Isa & Lazoglu 2019, §4, Eq. 9–12, the singularity cone with C-axis patching, and the
//! kinematic error of their Fig. 16).
//!
//! # Conventions
//!
//! - The B axis is parallel to machine Y, at height `b_axis_z`, and crosses the C axis, which
//!   stands vertical at `c_axis_xy` when B = 0. The table surface is `table_above_b_axis` above
//!   the B axis along the C axis. The part is placed in the table frame (origin where the C axis
//!   meets the table surface) with its XY bounding-box centre on the C axis and its lowest bead
//!   bottom on the table surface: table = part + offset, the offset written in the header.
//! - B and C are the paper's φ and θ: the tool axis in the part is
//!   `n_b = R_z(C)·R_y(B)·(0,0,1) = (cos C sin B, sin C sin B, cos B)`. As ISO 841 has it for axes
//!   that move the workpiece, positive B and C turn the tool relative to the part, so the bed
//!   itself turns by −C about its axis and tilts by −B: a table-frame point `t` is at machine
//!   `Q + R_y(−B)·R_z(−C)·(t + h·ẑ)` with `Q` the crossing of the axes and `h` =
//!   `table_above_b_axis` ([`forward`] is the inverse of that).
//! - The paper prints Eq. 9 with minus signs on the first two components; its Eqs. 10–11 and
//!   its text (θ₁ = atan2(n_y, n_x) is the solution with φ > 0) hold for the signs above, which
//!   are those of the standard rotation matrices, so we use those.
//!
//! # Moves
//!
//! Print moves are `G1 X Y Z B C E F`, travels `G0`. XYZ have 3 decimals, B and C 4 (degrees),
//! E 5 (relative extrusion, `M83`), F 3 (mm/min: a move that hardly moves X, Y and Z while the
//! bed turns gets a small F). C is unwrapped (it never jumps by 360°) unless
//! the profile limits it, in which case every path is shifted by whole turns to fit the limits.
//! Each planned print segment may be split into equal sub-moves (positions on the planned
//! segment, B and C linear along it, as the controller would move them) so that no move turns C
//! by more than `max_c_step_deg` and the kinematic error stays within its goal.
//!
//! Travels: after printing the filament is retracted and the nozzle lifted by `z_hop` along the
//! current tool axis (machine +Z). A travel (the run of travel points between two print moves,
//! taken whole) that turns the bed by more than `reorient_lift_deg` in all (B and C, every
//! step) first goes up to the safe height (above the sphere the part sweeps about the B/C crossing,
//! plus `z_hop` and `reorient_clearance`), turns the bed there, moves over the next point and
//! comes down; a smaller one goes straight to the next point at hop height. Then the nozzle
//! lowers by the hop (along the new tool axis) and un-retracts.
//!
//! # Feed
//!
//! The controller (Marlin with rotary axes) takes F as the speed along the machine XYZ path of a
//! move, or along the rotary axes (degrees) when XYZ do not move. F is scaled by that distance
//! over the move's length along the part, so the nozzle moves over the part at the planned
//! deposition speed (`first_layer_speed` for beads on the table, `print_speed` otherwise), and
//! clamped to the profile's `max_feed_mm_min`: a move asking for more is slowed to it (the
//! program's warnings count them). The header says so in a `; F:` line.
//!
//! # Moves that are not written
//!
//! A print move that goes nowhere in machine coordinates (X, Y, Z, B and C as written: a move
//! that only turns the bed is a real move) is not written, nor one whose E rounds to 0 over
//! less than 0.01 mm and 0.01 degrees: the next move carries its filament (E is rounded
//! cumulatively, so the E written adds up to the planned filament). A longer move whose E
//! rounds to 0 is written without E. Retraction and un-retraction stay E-only moves.
//!
//! # Start, end, fan
//!
//! The profile's `start_gcode` follows the header and `end_gcode` the last retraction, lift
//! and levelling of the bed, placeholders filled in ([`crate::custom`]); the fan follows
//! `fan_first_layer` on beads resting on the table and `fan_speed` above (`M106`/`M107`).

mod figures;
pub(crate) mod geometry;
mod joints;
mod kinematics;
mod motion;
mod text;

use std::collections::BTreeMap;

pub use figures::KinematicFigures;
pub use geometry::Delta5Geometry;
pub use joints::DELTA5_JOINTS_HEADER;
pub use kinematics::{forward, inverse, tilt_for, to_machine};
pub use motion::MAX_SUBDIVISION;

use crate::kuka::JOINTS_CSV;
use crate::machine::MachineProfile;
use crate::placement::table_offset;
use crate::sink::{insert_notes, write_file, Chunked, InMemory, ProgramSink};
use crate::PostError;
use figures::error_plot;
use geometry::FIT_TOLERANCE;
use joints::JointRows;
use kinematics::{plan_poses, Pose};
use motion::{Pass, Writer};
use text::header;
use toolpath::vec3::norm;
use toolpath::{fixed, MoveKind, ToolPath};

/// The share of a program's print moves that may be slowed to `max_feed_mm_min` before the
/// post warns of it (issue 31: below it the count is a figure, `feed_clamped_moves`).
pub const FEED_CLAMP_WARN_SHARE: f64 = 0.01;

/// A 5-axis program and what the post measured of it.
#[derive(Debug, Clone, PartialEq)]
pub struct Delta5Program {
    /// The G-code.
    pub gcode: String,
    /// Kinematic figures per feature id (features with print moves only).
    pub figures: BTreeMap<usize, KinematicFigures>,
    /// The kinematic error along the printed path as a stand-alone SVG: one colour per
    /// feature, axes labelled, the goal as a dashed line.
    pub error_plot_svg: String,
    /// `joints.csv`: the B and C after every move of the path ([`DELTA5_JOINTS_HEADER`]).
    pub joints_csv: String,
    /// Things to know, one line each (feeds clamped to `max_feed_mm_min`, when more than
    /// [`FEED_CLAMP_WARN_SHARE`] of the print moves were).
    pub warnings: Vec<String>,
    /// Print moves whose feed was clamped to `max_feed_mm_min`.
    pub feed_clamped_moves: usize,
    /// table = part + offset (mm), as in the header.
    pub offset: [f64; 3],
    /// Machine Z of the safe height used for large reorientations.
    pub safe_z: f64,
}

/// A 5-axis program for the path on a `delta5` machine, with its kinematic figures and error
/// plot.
///
/// Every point goes through the same bed kinematics in the path's (build) order: `two5d`
/// features, whose axis is their reference plane's normal, print with the bed held at that
/// plane's angles (B = 0, C unchanged for +Z). `source` (the STEP file's name) is written in
/// the first comment line.
///
/// The kinematic error (paper Fig. 16) of a print move is measured as the controller would
/// run it: X, Y, Z, B and C interpolated linearly in as many steps as the coarsest of the
/// resolutions needs, each step transformed back to the part ([`forward`]) and its distance to
/// the planned segment taken. A planned segment is split into equal sub-moves (on the planned
/// segment, B and C linear along it) until no move turns C by more than `max_c_step_deg` and
/// the error stays within `kinematic_error_goal` (or [`MAX_SUBDIVISION`] moves are reached;
/// the figures then show it).
///
/// Errors: the profile is not a valid `delta5` profile; a point holds a NaN or infinite number;
/// a tool axis is not a direction or needs a B outside the B limits (naming the feature); a
/// path cannot fit the C limits; a move leaves the work envelope (X and Y within `bed_size`
/// around the bed centre, Z within `z_min`..`bed_size` Z) or a point lies below the table
/// surface (naming the feature and by how much).
pub fn delta5(
    path: &ToolPath,
    m: &MachineProfile,
    source: &str,
) -> Result<Delta5Program, PostError> {
    let mut files = InMemory::default();
    let mut program = delta5_to(path, m, source, &[], &mut files)?;
    let mut texts = files
        .files
        .into_iter()
        // The program is made of `str`s.
        .map(|f| String::from_utf8(f.bytes).unwrap_or_default());
    program.gcode = texts.next().unwrap_or_default();
    program.error_plot_svg = texts.next().unwrap_or_default();
    program.joints_csv = texts.next().unwrap_or_default();
    Ok(program)
}

/// [`delta5`]'s program, with `notes` (comment lines after the one naming the source, see
/// [`crate::Job::notes`]), written into `sink`: `program.gcode` as it is made, a megabyte at a
/// time ([`ProgramSink::chunk`]), then `kinematic_error.svg` and `joints.csv`; the returned
/// program holds none of them ([`Delta5Program::gcode`], [`Delta5Program::error_plot_svg`] and
/// [`Delta5Program::joints_csv`] are empty).
///
/// The header gives the kinematic figures of every feature, known once every print segment
/// is split: a first run over the path splits them (measuring the error) and records how,
/// the second writes the moves split as recorded, reading the joint table off them as it
/// goes. The files are opened once the path passed every check [`delta5`] makes; an error
/// writing them is [`PostError::Write`].
pub fn delta5_to(
    path: &ToolPath,
    m: &MachineProfile,
    source: &str,
    notes: &[String],
    sink: &mut dyn ProgramSink,
) -> Result<Delta5Program, PostError> {
    let g = m.delta5_table()?;
    if g.z_min >= m.bed_size[2] {
        return Err(PostError::ProfileValue {
            name: m.name.clone(),
            field: "delta5.z_min",
            reason: format!(
                "must be below the bed_size Z {}, got {}",
                m.bed_size[2], g.z_min
            ),
        });
    }
    path.check_finite()?;
    let offset = table_offset(path);
    for q in &path.points {
        let below = -(q.p[2] + offset[2]);
        if below > FIT_TOLERANCE {
            return Err(PostError::Delta5Envelope {
                feature: q.feature as usize,
                name: m.name.clone(),
                excess: format!(
                    "a point lies {} mm below the table surface",
                    fixed(below, 3)
                ),
            });
        }
    }
    let poses = plan_poses(&path.points, g, &m.name)?;

    // The sphere the part sweeps about the axes' crossing, for the safe height.
    let swing = path
        .points
        .iter()
        .map(|q| {
            let t = [
                q.p[0] + offset[0],
                q.p[1] + offset[1],
                q.p[2] + offset[2] + g.table_above_b_axis,
            ];
            norm(t) + f64::from(q.width.max(0.0)) / 2.0
        })
        .fold(0.0, f64::max);
    let wanted_safe = g.b_axis_z + swing + m.z_hop + g.reorient_clearance;
    let safe_z = wanted_safe.min(m.bed_size[2]);

    // First the figures the header gives, then the text, as it is made.
    let mut w = Writer::new(m, g, offset, safe_z, Pass::Measure { splits: Vec::new() });
    walk(&mut w, path, &poses, g, |out| {
        out.clear();
        Ok(())
    })?;
    w.footer()?;
    let figures: BTreeMap<usize, KinematicFigures> = w
        .figures
        .iter()
        .map(|(&f, a)| {
            let mut k = a.figures.clone();
            k.mean_mm = if k.samples > 0 {
                a.sum / k.samples as f64
            } else {
                0.0
            };
            (f, k)
        })
        .collect();

    let mut file = Chunked::open(sink, "program.gcode")?;
    let mut text = Writer::new(m, g, offset, safe_z, w.replay());
    text.out = header(m, g, source, offset, safe_z, wanted_safe, &figures);
    insert_notes(&mut text.out, notes);
    // joints.csv: B and C read off each move as it is written, the header's (start G-code's)
    // moves left out; held until the program is written (a row is some 25 bytes a move).
    let mut rows = JointRows::new();
    let mut scanned = text.out.len();
    walk(&mut text, path, &poses, g, |out| {
        rows.scan(&out[scanned..]);
        file.pass_on(out)?;
        scanned = out.len();
        Ok(())
    })?;
    text.footer()?;
    rows.scan(&text.out[scanned..]);
    file.finish(&text.out)?;
    drop(text);

    let error_plot_svg = error_plot(&w.plot, g.kinematic_error_goal, source);
    write_file(sink, "kinematic_error.svg", error_plot_svg.as_bytes())?;
    write_file(sink, JOINTS_CSV, rows.text.as_bytes())?;
    let mut warnings = Vec::new();
    // A few clamped moves (the short ones B and C turn fast on, nearly every part has some)
    // are a figure; a warning only where a share the user would notice is slowed.
    let print_moves: usize = figures.values().map(|k| k.print_moves).sum();
    if w.clamped.0 as f64 > FEED_CLAMP_WARN_SHARE * print_moves as f64 {
        warnings.push(format!(
            "{} print move(s) asked for a feed above max_feed_mm_min {} mm/min (up to F{}) and were slowed to it: the nozzle moves over the part slower than print_speed there",
            w.clamped.0,
            fixed(m.max_feed_mm_min(), 0),
            fixed(w.clamped.1, 0)
        ));
    }
    Ok(Delta5Program {
        gcode: String::new(),
        figures,
        error_plot_svg: String::new(),
        joints_csv: String::new(),
        warnings,
        feed_clamped_moves: w.clamped.0,
        offset,
        safe_z,
    })
}

/// Writes the moves of the path: every point in the path's order, through `w`; `pass_on` is
/// handed the text made after each point (and may take it).
fn walk(
    w: &mut Writer,
    path: &ToolPath,
    poses: &[Pose],
    g: &Delta5Geometry,
    mut pass_on: impl FnMut(&mut String) -> Result<(), PostError>,
) -> Result<(), PostError> {
    let mut previous: Option<usize> = None;
    // Points up to here were passed by a travel lifted to the safe height.
    let mut passed = 0;
    for (i, q) in path.points.iter().enumerate() {
        if i < passed {
            continue;
        }
        match q.kind {
            MoveKind::Travel => {
                // The whole travel (its run of travel points) turns the bed further than the
                // lift rule allows: one travel at the safe height to its last point.
                let end = i + path.points[i..]
                    .iter()
                    .take_while(|p| p.kind == MoveKind::Travel)
                    .count();
                if w.turn(&poses[i..end]) > g.reorient_lift_deg {
                    for p in &path.points[i..end] {
                        w.comments(p);
                    }
                    w.travel(&path.points[end - 1], &poses[end - 1], true)?;
                    passed = end;
                    previous = Some(end - 1);
                    pass_on(&mut w.out)?;
                    continue;
                }
                w.comments(q);
                w.travel(q, &poses[i], false)?
            }
            MoveKind::Print => {
                w.comments(q);
                let from = match previous {
                    Some(j) if w.at.is_some() => j,
                    _ => {
                        w.travel(q, &poses[i], false)?;
                        i
                    }
                };
                w.print(&path.points[from], &poses[from], q, &poses[i])?;
            }
        }
        previous = Some(i);
        pass_on(&mut w.out)?;
    }
    Ok(())
}

/// The work envelope of `m` (with geometry `g`) in machine coordinates: its lowest and
/// highest corners, mm (X and Y over the bed, from the bed's origin; Z from `g.z_min` to the
/// bed size's height).
pub(crate) fn work_envelope(
    m: &MachineProfile,
    g: &geometry::Delta5Geometry,
) -> ([f64; 3], [f64; 3]) {
    let (x0, y0) = if m.bed_origin_centre {
        (-m.bed_size[0] / 2.0, -m.bed_size[1] / 2.0)
    } else {
        (0.0, 0.0)
    };
    (
        [x0, y0, g.z_min],
        [x0 + m.bed_size[0], y0 + m.bed_size[1], m.bed_size[2]],
    )
}

/// How far (mm) the nozzle positions of the path's points leave the work envelope (X and Y
/// within `bed_size` around the bed centre, Z within `z_min`..`bed_size` Z) as [`delta5`]
/// places the part ([`table_offset`]) and turns the bed (its bed angles, C patched inside the
/// singularity cone): the largest excess over the points and the three axes, 0 when every
/// point is inside. A point below the table surface counts by how far it is below.
///
/// A cheap stand-in for the post's check, which also checks the moves between the points
/// (sub-moves, hops, travels at the safe height): [`crate::fit`] searches with it and
/// confirms its choice with the post.
///
/// Errors as [`delta5`]'s: not a valid `delta5` profile, a non-finite point, a tool axis
/// outside the B limits.
pub fn envelope_excess(path: &ToolPath, m: &MachineProfile) -> Result<f64, PostError> {
    let g = m.delta5_table()?;
    path.check_finite()?;
    let offset = table_offset(path);
    let poses = plan_poses(&path.points, g, &m.name)?;
    let (lo, hi) = work_envelope(m, g);
    let mut excess: f64 = 0.0;
    for (q, pose) in path.points.iter().zip(&poses) {
        excess = excess.max(-(q.p[2] + offset[2]));
        let xyz = to_machine(q.p, pose.b, pose.c, g, offset);
        for k in 0..3 {
            excess = excess.max(lo[k] - xyz[k]).max(xyz[k] - hi[k]);
        }
    }
    Ok(excess)
}
