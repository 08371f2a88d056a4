//! The simulation view (issue 36 item 2): a scrubber over the program's moves that shows, at
//! each move, the print head at the tool tip and the machine around it, with the moves near a
//! joint limit, near the wrist singularity or in collision marked on the path and listed.
//!
//! The caller computes the joints (the KUKA post's A1..A6, delta5's B and C: see
//! [`Simulation::table_from_axes`]); the page draws the machine from them (an arm by the OPW
//! forward kinematics in the viewer's script, a table tilted and turned), at most
//! [`MAX_SIM_MOVES`] moves of them ([`json`](self::json) says which).
//!
//! - **Arm** ([`SimArm`]): the view stays in the tool path's frame; the arm is drawn in it
//!   through `$BASE` and the part offset, links as cylinders from the OPW chain (base, A1
//!   column, shoulder offset `a1`, upper arm `c2`, elbow offset `a2`, forearm `c3`, wrist to
//!   flange `c4`, flange to the tool tip by `$TOOL`), and the head at the tool tip along the
//!   tool's −Z.
//! - **Table** ([`SimTable`]): the view is the machine's frame, shifted so that it is the tool
//!   path's frame at B = C = 0: the table, the part, the path and the marks turn with B and C
//!   as the bed does, and the head stays vertical over the move's point. Drawing the bed move
//!   (rather than the head tilt in the part's frame) shows what the machine does.

mod flags;
pub(crate) mod json;
mod table;

pub use flags::{SimMargins, NEAR_LIMIT_DEG, NEAR_SINGULARITY_DEG};
pub use json::{MAX_SIM_FLAGGED, MAX_SIM_MOVES};

use crate::HeadSize;

/// The machine and its moves, for the simulation view.
#[derive(Debug, Clone, PartialEq)]
pub struct Simulation {
    /// The machine that moves.
    pub machine: SimMachine,
    /// The print head's figures (drawn at each move's tool tip).
    pub head: HeadSize,
    /// The moves, in program order: each at a point of the tool path, with its joints.
    pub moves: Vec<SimMove>,
    /// Margins of the flags, shown in the page's text.
    pub margins: SimMargins,
}

/// The machine drawn in the simulation view.
#[derive(Debug, Clone, PartialEq)]
// One machine a page: its size does not matter.
#[allow(clippy::large_enum_variant)]
pub enum SimMachine {
    /// A 6-axis arm (the KUKA post's); joints A1..A6 (degrees).
    Arm(SimArm),
    /// delta5's tilting and turning table; joints B, C (degrees).
    Table(SimTable),
}

/// A 6-axis arm with an ortho-parallel base and a spherical wrist (OPW, Brandstötter,
/// Angerer & Hofbaur 2014), as the KUKA post's `[kuka.arm]` and `[kuka]` frames describe it
/// (`robot_post::kuka::ArmModel`, `KukaCell`): lengths in mm, angles in degrees, the zero
/// pose with the arm straight up, θi = Ai·sign_i − offset_i.
///
/// From a `robot_post::KukaCell` `cell`: `a1`..`c4` and the joint figures are `cell.arm`'s,
/// `base` is `cell.base.to_array()`, `tool` is `cell.tool.to_array()`, and `part_offset` the
/// offset the post placed the part with (`tests/preview.rs` builds one so).
#[derive(Debug, Clone, PartialEq)]
pub struct SimArm {
    /// Shoulder offset from the A1 axis (mm).
    pub a1: f64,
    /// Elbow offset, perpendicular to the forearm (mm).
    pub a2: f64,
    /// Lateral offset of the arm plane (mm).
    pub b: f64,
    /// Height of the A2 axis above the base (mm).
    pub c1: f64,
    /// Upper arm, A2 to A3 (mm).
    pub c2: f64,
    /// Forearm, A3 to the wrist centre (mm).
    pub c3: f64,
    /// Wrist centre to flange (mm).
    pub c4: f64,
    /// offset_i (degrees).
    pub joint_offsets: [f64; 6],
    /// sign_i, 1 or -1.
    pub joint_signs: [i32; 6],
    /// Lower limits of A1..A6 (degrees).
    pub joint_min: [f64; 6],
    /// Upper limits of A1..A6 (degrees).
    pub joint_max: [f64; 6],
    /// `$BASE`: the work table's frame in the robot's base frame, KRL `[X, Y, Z, A, B, C]`
    /// (mm, degrees; orientation R_z(A)·R_y(B)·R_x(C)).
    pub base: [f64; 6],
    /// The part's offset on the table: `$BASE` = tool path + offset (the KUKA program's
    /// `; part offset` header line).
    pub part_offset: [f64; 3],
    /// `$TOOL`: the nozzle tip in the flange frame, KRL `[X, Y, Z, A, B, C]`, its Z along the
    /// nozzle into the deposit (the tool path's axis is its −Z).
    pub tool: [f64; 6],
}

/// delta5's table (`robot_post::delta5` conventions), in the tool path's frame at B = C = 0:
/// a disc about the C axis, which crosses the B axis (parallel to machine Y) `table_above_b_axis`
/// below the table's surface. The tool axis in the part is `R_z(C)·R_y(B)·(0,0,1)` = (cos C sin
/// B, sin C sin B, cos B); the bed turns by −C about its axis and tilts by −B, so that a
/// tool-path point `p` is at `K + R_y(−B)·R_z(−C)·(p − K)` in the view, `K` the axes' crossing.
#[derive(Debug, Clone, PartialEq)]
pub struct SimTable {
    /// XY of the disc's centre (the C axis) in the tool path's frame, mm.
    pub centre: [f64; 2],
    /// Height of the table's surface in the tool path's frame, mm.
    pub z: f64,
    /// Radius of the disc, mm.
    pub radius: f64,
    /// Distance along the C axis from the B axis up to the table surface, mm (negative: the
    /// surface is below the B axis).
    pub table_above_b_axis: f64,
    /// Lowest and highest B (degrees).
    pub b_limits_deg: [f64; 2],
    /// Lowest and highest C (degrees), or `None` when C turns without end.
    pub c_limits_deg: Option<[f64; 2]>,
}

/// One move of the program.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct SimMove {
    /// The tool path's point the move goes to (an index into `ToolPath::points`); a move
    /// between points (a post's retreat, travel or approach) names the point it leads to. The
    /// point is where the move is dotted and up to where the path is drawn done; the machine
    /// is drawn by the joints alone.
    pub point: usize,
    /// A1..A6 for an arm, B and C for a table (degrees).
    pub joints: Vec<f64>,
    /// What is wrong or close to wrong at the move.
    pub flags: SimFlags,
}

/// What the simulation marks at a move.
#[derive(Debug, Clone, PartialEq, Eq, Default)]
pub struct SimFlags {
    /// The head meets the part, the deposit or the table (the caller's collision check).
    pub collision: bool,
    /// The joints (indices into [`SimMove::joints`]: 0 is A1 or B) within the margin of a
    /// limit, or beyond it.
    pub near_limit: Vec<usize>,
    /// The arm's wrist is within the margin of its singularity (θ5 near 0° or 180°).
    pub near_singularity: bool,
}

impl SimFlags {
    /// Whether anything is marked.
    pub fn any(&self) -> bool {
        self.collision || self.near_singularity || !self.near_limit.is_empty()
    }
}

impl SimMachine {
    /// Names of the joints: `A1`..`A6` or `B`, `C`.
    pub fn joint_names(&self) -> &'static [&'static str] {
        match self {
            SimMachine::Arm(_) => &["A1", "A2", "A3", "A4", "A5", "A6"],
            SimMachine::Table(_) => &["B", "C"],
        }
    }

    /// The joints' lower and upper limits (degrees), `None` where a joint has none.
    pub fn limits(&self) -> Vec<Option<[f64; 2]>> {
        match self {
            SimMachine::Arm(a) => (0..6)
                .map(|i| Some([a.joint_min[i], a.joint_max[i]]))
                .collect(),
            SimMachine::Table(t) => vec![Some(t.b_limits_deg), t.c_limits_deg],
        }
    }
}

impl Simulation {
    /// A simulation of `moves` with every move's near-limit and near-singularity flags set
    /// from its joints by `margins` ([`SimMachine::flags`]); collisions are kept as given.
    pub fn new(
        machine: SimMachine,
        head: HeadSize,
        moves: Vec<SimMove>,
        margins: SimMargins,
    ) -> Simulation {
        let mut s = Simulation {
            machine,
            head,
            moves,
            margins,
        };
        for m in &mut s.moves {
            let near = s.machine.flags(&m.joints, &s.margins);
            m.flags.near_limit = near.near_limit;
            m.flags.near_singularity = near.near_singularity;
        }
        s
    }
}
