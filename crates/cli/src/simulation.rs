//! The simulation view's data (issue 36 item 2) for a plan's `preview.html`: the moves of its
//! program with the joints the post computed and the machine around them. A KUKA program's
//! moves are the rows of its `joints.csv` (every Cartesian motion: the path point it was made
//! for and A1..A6 of the solution the reach check followed); delta5's are the path's points
//! with B and C by Eq. 9–12 ([`Simulation::table_from_axes`]). Marlin has none.

use collide::Table;
use preview::{HeadSize, SimArm, SimMachine, SimMargins, SimMove, SimTable, Simulation};
use robot_post::{MachineKind, MachineProfile};
use std::collections::BTreeSet;
use std::path::Path;

/// The print head of `machine`, as the simulation draws it.
pub fn head_size(machine: &MachineProfile) -> HeadSize {
    let h = &machine.head;
    HeadSize {
        tip_radius: h.nozzle_tip_radius,
        half_angle_deg: h.nozzle_cone_half_angle_deg,
        cone_length: h.nozzle_length,
        body_radius: h.body_radius,
        body_length: h.body_length,
    }
}

/// The simulation of `plan`'s program on `machine` (the profile the plan was made with), its
/// KUKA joints read from `joints_csv` (the program's, as written); `None` for Marlin, or where
/// the joints cannot be had (then the page has no simulation view).
pub fn simulation(
    plan: &plan::Plan,
    machine: &MachineProfile,
    joints_csv: Option<&Path>,
) -> Option<Simulation> {
    let colliding: BTreeSet<usize> = plan.collisions.left.iter().map(|c| c.index).collect();
    let mut sim = match machine.kind {
        MachineKind::Marlin => return None,
        MachineKind::Delta5 => table(plan, machine)?,
        MachineKind::Kuka => arm(plan, machine, &std::fs::read_to_string(joints_csv?).ok()?)?,
    };
    for mv in &mut sim.moves {
        mv.flags.collision = colliding.contains(&mv.point);
    }
    Some(sim)
}

/// delta5: B and C at every point of the path, the table where the head check has it.
fn table(plan: &plan::Plan, machine: &MachineProfile) -> Option<Simulation> {
    let g = machine.delta5.as_ref()?;
    let Table::Disc { centre, z, radius } = plan::collisions::table(&plan.toolpath, machine) else {
        return None;
    };
    let table = SimTable {
        centre,
        z,
        radius,
        table_above_b_axis: g.table_above_b_axis,
        b_limits_deg: g.b_limits_deg,
        c_limits_deg: (!g.c_continuous).then_some(g.c_limits_deg),
    };
    Some(Simulation::table_from_axes(
        &plan.toolpath.points,
        table,
        head_size(machine),
        SimMargins::default(),
    ))
}

/// KUKA: the arm at the joints of every row of `joints_csv` (`move,point,A1..A6`; rows out of
/// reach, without joints, left out), the part where the post placed it (the cell's
/// `part_position`, moved into reach when the plan moved it).
fn arm(plan: &plan::Plan, machine: &MachineProfile, joints_csv: &str) -> Option<Simulation> {
    let mut placed = machine.clone();
    let cell = placed.kuka.as_mut()?;
    if let Some(moved) = &plan.report.moved_on_table {
        cell.part_position = moved.part_position;
    }
    let cell = cell.clone();
    let offset = robot_post::kuka::part_offset(&plan.toolpath, &placed).ok()?;
    let mut lines = joints_csv.lines();
    if lines.next() != Some(robot_post::kuka::JOINTS_HEADER) {
        return None;
    }
    let moves: Vec<SimMove> = lines
        .filter_map(|l| {
            let mut cells = l.split(',');
            let _move = cells.next()?;
            let point: usize = cells.next()?.parse().ok()?;
            let joints: Vec<f64> = cells.map(|c| c.parse().ok()).collect::<Option<_>>()?;
            (joints.len() == 6 && point < plan.toolpath.points.len()).then(|| SimMove {
                point,
                joints,
                ..SimMove::default()
            })
        })
        .collect();
    let a = &cell.arm;
    let arm = SimArm {
        a1: a.a1,
        a2: a.a2,
        b: a.b,
        c1: a.c1,
        c2: a.c2,
        c3: a.c3,
        c4: a.c4,
        joint_offsets: a.joint_offsets,
        joint_signs: a.joint_signs,
        joint_min: a.joint_min,
        joint_max: a.joint_max,
        base: cell.base.to_array(),
        part_offset: offset,
        tool: cell.tool.to_array(),
    };
    let margins = SimMargins {
        singularity_deg: cell.wrist_singularity_deg,
        ..SimMargins::default()
    };
    Some(Simulation::new(
        SimMachine::Arm(arm),
        head_size(machine),
        moves,
        margins,
    ))
}
