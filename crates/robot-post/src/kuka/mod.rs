//! The KUKA robot post: KRL `.src`/`.dat` programs for a 6-axis arm carrying the extruder over
//! a fixed work table.
//!
//! Conventions, used by [`kuka`] and read back by [`crate::krl`]:
//!
//! - **Frames.** `$BASE` is the work table's frame in the robot's base frame (`$WORLD`, with a
//!   null `$ROBROOT`): the profile's `[kuka.base]`, Z up from the table top. The part is placed
//!   on the table by the rule of [`crate::placement::bed_offset`] (XY bounding-box centre on the
//!   table centre, lowest bead bottom on the table top), then moved by the cell's
//!   `part_position` (`$BASE` X and Y, `[0, 0]` when left out; [`crate::fit::reach_shift`]
//!   finds the least move that brings every point into reach); LIN targets are tool poses in `$BASE`,
//!   part point + offset, and the offset is written in a header comment
//!   `; part offset X.. Y.. Z.. (base = part + offset)`. `$TOOL` is the nozzle tip in the
//!   flange frame (`[kuka.tool]`), with its Z axis along the nozzle, out of the extruder into
//!   the deposit: the tool path's axis (deposit → nozzle) is the tool's −Z.
//! - **Orientation.** KUKA's A, B, C: R = R_z(A)·R_y(B)·R_x(C) (degrees), B within ±90°
//!   ([`abc_from_matrix`]). A and C are unwrapped: each is the value nearest the previous LIN's
//!   (they may leave ±180°), and at gimbal lock (B = ±90°, the tool's X axis along `$BASE` Z)
//!   A keeps its previous value and C takes the rest.
//! - **Rotation about the tool axis.** The axis fixes two angles. At the start of every path
//!   (a travel point, or the first point) the tool's X axis is the horizontal direction from
//!   the nozzle back to the robot's A1 axis, projected onto the plane normal to the tool axis
//!   (so A6 starts near its middle); along the path the frame is carried forward by the
//!   minimal rotation that turns one tool axis into the next (parallel transport), so the
//!   tool never spins about its own axis while printing.
//! - **Travel.** A travel point is visited where a path starts (a print point follows it); the
//!   planner's other travel points (lifts, waypoints) are superseded by this safe travel: from
//!   the end of a path, extruder off, retreat `travel_clearance` along the tool axis, rise
//!   straight up to the travel height (the highest point visited so far within about
//!   [`HEIGHT_CELL`] of the route, plus the clearance; no rise over planar layers), move
//!   across at that height while the orientation turns to the next path's (slerp, at most
//!   [`TRAVEL_ROTATION_STEP_DEG`] per LIN), go down to the approach point (`travel_clearance`
//!   out along the next tool axis) and approach along the axis to the path's first point. The
//!   program goes from home to the **safe point** by `PTP`: `safe_height` over the part's top
//!   (`$BASE` Z), over the first path's start, the tool upright; from there LINs go down to the
//!   first approach point while the tool turns to the path's orientation. It ends with the same
//!   retreat, a rise (turning upright) to the safe point's height (or the clearance over the
//!   part's top, if higher), a LIN across and a `PTP` to the safe point, then `PTP` home.
//!   Rising straight up assumes no material above the retreat point (no printing under an
//!   overhang); so does the way down from the safe point.
//! - **Extruder.** One digital output, on for the LINs that print. With `extruder_switch =
//!   "trigger"` a `TRIGGER WHEN DISTANCE=0 DELAY=0 DO $OUT[n]=...` before the first print LIN
//!   (on) and before the retreat (off) switches it where those motions start, without
//!   stopping the advance run; with `"out"` a plain `$OUT[n]=...` between the motions stops
//!   the robot there (exact stop) and switches. Temperatures are the extruder controller's;
//!   the header states them.
//! - **Filament feed.** One feed ratio per print LIN (or spline segment, see below), following
//!   the plan: the planned E of the path points the LIN reaches (a print move dropped as going
//!   nowhere hands its E on)
//!   over the LIN's length, in mm of filament per mm of path. It is written as the analog
//!   output `$ANOUT[feed_output]` = ratio / `feed_ratio_full_scale` (5 decimals, held at 1.0
//!   with a warning beyond full scale) by `TRIGGER WHEN DISTANCE=0 DELAY=0 DO $ANOUT[n]=v`
//!   right before the LIN, where it changes, so it switches where that LIN starts without
//!   stopping the advance run. The extruder's controller feeds v × `feed_ratio_full_scale`
//!   mm of filament per mm the tool moves (the impeller's blades need about 0.0286, its base
//!   0.0374; one ratio for the whole program over-extruded the blades by 26 %).
//! - **Spline.** With `motion = "spline"` each run of print moves (a path's, between changes of
//!   speed) is a `SPLINE` ... `ENDSPLINE` block after its `$VEL.CP`, through fewer points
//!   (`spline` module): points within half of `spline_tolerance` of the line through their
//!   neighbours are dropped, `SPL` segments where a cubic through the neighbours stays within
//!   the tolerance of the plan, `SLIN` elsewhere; the feed and the extruder by `TRIGGER WHEN
//!   PATH=0 ONSTART DELAY=0 DO ...` inside the block. A block a part file ends inside goes on in
//!   the next part (`ENDSPLINE` there, `SPLINE` again). Travels stay `LIN` and `PTP`.
//! - **Signals.** The `INI` declares `INTERRUPT DECL 10 WHEN $STOPMESS==TRUE DO
//!   EXTRUDER_STOP( )` and switches it on: when the robot stops on an error, the local
//!   subroutine `EXTRUDER_STOP` (after the main program's `END`) sets the feed's
//!   `$ANOUT[feed_output]` to 0 and `$OUT[extruder_output]` off, then `BRAKE`s. The program
//!   resets both the same way after its last motion, before `PTP` home. With `ready_input`
//!   set, the program waits at the safe point for `$IN[ready_input]` (the extruder at
//!   temperature) at most `ready_timeout` s (`$TIMER[1]`), and `HALT`s if it is not on; on
//!   the operator's start it waits for it without a limit.
//! - **Files.** `<name>.src` holds header comments (source, machine, part offset, tool and
//!   extruder conventions), the `INI` fold with `BAS (#INITMOV,0 )`, `$BASE` and `$TOOL`
//!   (or, with the cell's `base_index`/`tool_index`, `BAS (#BASE, n)`/`BAS (#TOOL, n)` after a
//!   comment `; assumed BASE_DATA[n] = {..}` stating the frame the program was planned for),
//!   `$ADVANCE`, `$APO.CDIS`, extruder off and `PTP` home (`DECL AXIS XHOME_PRINT` in
//!   `<name>.dat`), the motions (`$VEL.CP` in m/s where the speed changes, `LIN {X, Y, Z, A,
//!   B, C} C_DIS` per pose), then extruder off and `PTP` home. A program of more than
//!   `max_moves_per_file` motions keeps only the calls in the main program: the motions go to
//!   parts `<name>_p001.src` ... (each with its `.dat`), called in order.
//! - **Reach.** Every pose is checked against the arm model of `[kuka.arm]` (OPW kinematics,
//!   Brandstötter et al. 2014): the flange pose `$BASE · target · $TOOL⁻¹` must have an
//!   inverse-kinematics solution within the joint limits; the solution followed is the one
//!   nearest the previous pose's, in the same configuration when there is one. Unreachable
//!   poses and poses within `wrist_singularity_deg` of a stretched wrist (|A5| small) are
//!   reported ([`KukaFigures`], warnings, and a comment on the LIN), not refused.
//! - **Status and Turn.** The configuration is KUKA's Status S: bit 0 the wrist centre behind
//!   A1 (overhead area), bit 1 A3 at or past the stretched arm's angle (elbow up), bit 2 A5 ≤ 0
//!   (wrist flipped); the Turn T has bit n set where A(n+1) < 0 (below [`TURN_ZERO`]). Every
//!   Cartesian `PTP` carries the S and T of the solution the reach check followed (`PTP {X ..,
//!   ..., C .., S 'B010', T 'B000010'}`), so the controller takes that solution; LINs keep the
//!   configuration they start in. The program keeps home's configuration throughout: a motion
//!   on which it would change is a warning naming the motion (its number, file and line, and
//!   the two S). `joints.csv` ([`JOINTS_CSV`]) gives the joints of that solution for every
//!   Cartesian motion, numbered as the warnings number them.

pub(crate) mod cell;
mod checks;
mod joints;
mod krl_text;
mod motion;
mod opw;
mod rotation;
mod signals;
mod spline;

use std::collections::BTreeMap;

pub use cell::{
    ArmModel, ExtruderSwitch, KrlFrame, KrlMotion, KukaCell, DEFAULT_READY_TIMEOUT,
    DEFAULT_SAFE_HEIGHT, DEFAULT_SPLINE_TOLERANCE,
};
pub use checks::KukaFigures;
pub use joints::{JOINTS_CSV, JOINTS_HEADER};
pub use krl_text::{frame_text, krl_name, pos_text, HOME_NAME, KRL_NAME_MAX};
pub use motion::{HEIGHT_CELL, TRAVEL_ROTATION_STEP_DEG};
pub use opw::{bits_text, turn, TURN_ZERO};
pub use rotation::{abc_from_matrix, matrix_from_abc, rotation_angle_deg, Mat3, Pose};
pub use signals::{READY_TIMER, STOP_INTERRUPT, STOP_ROUTINE};
pub use spline::{
    cubic_point, SPLINE_ANGLE_TOLERANCE_DEG, SPLINE_FEED_SHORT, SPLINE_FEED_TOLERANCE,
    SPLINE_MAX_MERGED, SPLINE_MAX_SEGMENTS, SPLINE_MAX_TURN_DEG, SPLINE_MIN_SEGMENT,
};

use crate::machine::MachineProfile;
use crate::sink::{InMemory, ProgramSink};
use crate::PostError;
use checks::Reach;
use joints::write_joints;
use krl_text::write_files;
pub(crate) use motion::start_frame;
use motion::{placement, Planner, Step};
use spline::Splined;
use toolpath::vec3::{norm, scale};
use toolpath::ToolPath;

/// Largest deviation of a tool axis's length from 1 accepted (the axis is then normalised).
pub const AXIS_LENGTH_TOLERANCE: f64 = 1e-3;

/// A KRL program: the files, what the reach check found per feature, and warnings.
#[derive(Debug, Clone, PartialEq)]
pub struct KrlProgram {
    /// `(file name, text)`: the main `<name>.src` and `<name>.dat` first, then the parts
    /// `<name>_p001.src`, `<name>_p001.dat`, ... when the program is split, then
    /// [`JOINTS_CSV`].
    pub files: Vec<(String, String)>,
    /// Per feature id.
    pub figures: BTreeMap<usize, KukaFigures>,
    /// One line each: the part overhanging the table, unreachable points, wrist
    /// singularities, configuration changes, gimbal crossings.
    pub warnings: Vec<String>,
}

/// A KRL program for the path, with every pose checked against the arm model.
///
/// `program_name` becomes the module name, made a KRL identifier by [`krl_name`]; `source`
/// (the STEP file's name) is written in the header. See the module documentation for the
/// frames, orientation, travel and extruder conventions.
///
/// Errors: the profile is not a `kuka` profile or is invalid, a point holds a NaN or infinite
/// number, or a tool axis is not a unit vector (within [`AXIS_LENGTH_TOLERANCE`]). Points the
/// arm cannot reach, and poses near the wrist singularity, are reported in
/// [`KrlProgram::figures`] and [`KrlProgram::warnings`] and marked on their LIN; so is a part
/// larger than the table (`bed_size`).
pub fn kuka(
    path: &ToolPath,
    m: &MachineProfile,
    program_name: &str,
    source: &str,
) -> Result<KrlProgram, PostError> {
    let mut files = InMemory::default();
    let mut program = kuka_to(
        path,
        m,
        program_name,
        source,
        &[],
        &mut files,
        JointsCsv::Always,
    )?;
    program.files = files
        .files
        .into_iter()
        // The program is made of `str`s.
        .map(|f| (f.name, String::from_utf8(f.bytes).unwrap_or_default()))
        .collect();
    Ok(program)
}

/// [`kuka`]'s program, with `notes` (comment lines after the one naming the source in the
/// main `.src`, see [`crate::Job::notes`]), written into `sink` in the order of
/// [`KrlProgram::files`], each `.src` as its lines are made, a megabyte at a time ([`ProgramSink::chunk`]); the
/// returned program holds no file. The files are opened once the motions are planned and
/// checked; an error writing them is [`PostError::Write`].
pub fn kuka_to(
    path: &ToolPath,
    m: &MachineProfile,
    program_name: &str,
    source: &str,
    notes: &[String],
    sink: &mut dyn ProgramSink,
    joints: JointsCsv,
) -> Result<KrlProgram, PostError> {
    let cell = m.kuka_table()?;
    path.check_finite()?;
    let mut axes = Vec::with_capacity(path.points.len());
    for (index, q) in path.points.iter().enumerate() {
        let n = norm(q.axis);
        if n.is_nan() || (n - 1.0).abs() > AXIS_LENGTH_TOLERANCE {
            return Err(PostError::KukaAxisNotUnit {
                index,
                feature: q.feature as usize,
                i: q.axis[0],
                j: q.axis[1],
                k: q.axis[2],
            });
        }
        axes.push(scale(q.axis, 1.0 / n));
    }
    let mut warnings = Vec::new();
    let offset = placement(path, m, &mut warnings)?;
    let base = cell.base.pose();
    // The header counts the motions: a first run of the planner counts them, the second
    // plans them again as they are checked and written.
    let steps = || Splined::new(Planner::new(path, &axes, offset, m, cell, &base), cell);
    let moves = steps().filter(|s| matches!(s, Step::Move { .. })).count();
    let figures = write_files(
        m,
        path,
        steps(),
        moves,
        Reach::new(path, cell, &base),
        offset,
        (program_name, source, notes),
        sink,
        &mut warnings,
    )?;
    // The joints of the solutions the check followed, from a third run of the planner and the
    // same check again (as long again as the program's check).
    let unreachable: usize = figures.values().map(|f| f.unreachable_points).sum();
    let wanted = match joints {
        JointsCsv::Always => true,
        JointsCsv::UnlessUnreachable => unreachable == 0,
        JointsCsv::Never => false,
    };
    if wanted {
        write_joints(path, steps(), Reach::new(path, cell, &base), sink)?;
    }
    Ok(KrlProgram {
        files: vec![],
        figures,
        warnings,
    })
}

/// Whether [`kuka_to`] writes `joints.csv` ([`JOINTS_CSV`]), a third run of the planner and
/// the reach check.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum JointsCsv {
    /// Always.
    Always,
    /// Unless some point is out of reach: for a plan that is then refused (no
    /// `--allow-unreachable`), whose files are dropped.
    UnlessUnreachable,
    /// Never: the program is posted only to be measured ([`crate::fit`]).
    Never,
}

/// The part offset [`kuka`] places the part with (`$BASE` = part + offset, the cell's
/// `part_position` included), its warnings dropped.
pub fn part_offset(path: &ToolPath, m: &MachineProfile) -> Result<[f64; 3], PostError> {
    placement(path, m, &mut Vec::new())
}
