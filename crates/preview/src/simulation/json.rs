//! The simulation as the viewer reads it: the machine's figures, the head in its own frame, and
//! the embedded moves (every k-th, the ends and the flagged ones) as base64 arrays.

use super::{SimArm, SimMachine, SimMove, Simulation};
use crate::encode::{base64_f32, base64_u32};
use crate::machine::head_overlay;
use toolpath::ToolPath;

/// Moves embedded in the page at most: a longer program is thinned for the view (every k-th
/// move, the first and the last kept, and the flagged moves up to [`MAX_SIM_FLAGGED`]).
pub const MAX_SIM_MOVES: usize = 20_000;

/// Flagged moves kept whatever the thinning, at most (the first ones); the page says how many
/// more there were.
pub const MAX_SIM_FLAGGED: usize = 5_000;

/// Bit of a move's flags word: the head collides.
const FLAG_COLLISION: u32 = 1;
/// Bit of a move's flags word: the wrist is near its singularity.
const FLAG_SINGULARITY: u32 = 2;
/// Bit of joint 0 near its limit in a move's flags word; joint i is this shifted by i.
const FLAG_LIMIT0: u32 = 4;

/// The moves embedded: the first [`MAX_SIM_FLAGGED`] flagged ones, every k-th and the last,
/// in order, [`MAX_SIM_MOVES`] at most.
pub(crate) fn embedded(moves: &[SimMove]) -> Vec<usize> {
    let n = moves.len();
    let flagged: Vec<usize> = (0..n)
        .filter(|&i| moves[i].flags.any())
        .take(MAX_SIM_FLAGGED)
        .collect();
    let budget = MAX_SIM_MOVES - flagged.len() - 1;
    let k = n.div_ceil(budget).max(1);
    let mut keep: Vec<usize> = (0..n).step_by(k).chain(n.checked_sub(1)).collect();
    keep.extend(flagged);
    keep.sort_unstable();
    keep.dedup();
    keep
}

/// A rigid transform as a row-major 4 × 4 matrix.
type Mat4 = [[f64; 4]; 4];

/// The transform of a KRL frame `[X, Y, Z, A, B, C]`: rotation R_z(A)·R_y(B)·R_x(C), then the
/// translation.
fn frame_matrix(f: [f64; 6]) -> Mat4 {
    let (sa, ca) = f[3].to_radians().sin_cos();
    let (sb, cb) = f[4].to_radians().sin_cos();
    let (sc, cc) = f[5].to_radians().sin_cos();
    [
        [
            ca * cb,
            ca * sb * sc - sa * cc,
            ca * sb * cc + sa * sc,
            f[0],
        ],
        [
            sa * cb,
            sa * sb * sc + ca * cc,
            sa * sb * cc - ca * sc,
            f[1],
        ],
        [-sb, cb * sc, cb * cc, f[2]],
        [0.0, 0.0, 0.0, 1.0],
    ]
}

/// The inverse of a rigid transform: `[Rᵀ, −Rᵀ·t]`.
fn invert_rigid(m: &Mat4) -> Mat4 {
    let mut out = [[0.0; 4]; 4];
    for i in 0..3 {
        for j in 0..3 {
            out[i][j] = m[j][i];
        }
        out[i][3] = -(0..3).map(|k| m[k][i] * m[k][3]).sum::<f64>();
    }
    out[3][3] = 1.0;
    out
}

/// Column-major, as WebGL's matrices are.
fn column_major(m: &Mat4) -> Vec<f64> {
    (0..16).map(|k| m[k % 4][k / 4]).collect()
}

impl SimArm {
    /// The tool path's frame in the robot's base frame: `$BASE` moved by the part offset
    /// (`$BASE` = part + offset), as a row-major rigid transform.
    fn part_in_robot(&self) -> Mat4 {
        let mut m = frame_matrix(self.base);
        for row in m.iter_mut().take(3) {
            row[3] += (0..3).map(|k| row[k] * self.part_offset[k]).sum::<f64>();
        }
        m
    }
}

/// The machine's figures as the viewer reads them.
fn machine_json(m: &SimMachine) -> serde_json::Value {
    let limits = m.limits();
    let min: Vec<Option<f64>> = limits.iter().map(|l| l.map(|l| l[0])).collect();
    let max: Vec<Option<f64>> = limits.iter().map(|l| l.map(|l| l[1])).collect();
    match m {
        SimMachine::Arm(a) => serde_json::json!({
            "kind": "arm",
            "opw": [a.a1, a.a2, a.b, a.c1, a.c2, a.c3, a.c4],
            "offsets": a.joint_offsets,
            "signs": a.joint_signs,
            "min": min,
            "max": max,
            "robot_to_part": column_major(&invert_rigid(&a.part_in_robot())),
            "tool": column_major(&frame_matrix(a.tool)),
        }),
        SimMachine::Table(t) => serde_json::json!({
            "kind": "table",
            "centre": t.centre,
            "z": t.z,
            "radius": t.radius,
            "above": t.table_above_b_axis,
            "min": min,
            "max": max,
        }),
    }
}

/// The simulation as the viewer reads it; `path` gives the moves' points (NaN where a move's
/// point is not in it), `drawn` the path's points the view draws (ascending), by which each
/// move says how much of the drawn path is behind it (`drawn_at`: the drawn points up to its
/// point).
pub(crate) fn simulation_json(
    s: &Simulation,
    path: Option<&ToolPath>,
    drawn: &[usize],
) -> serde_json::Value {
    let keep = embedded(&s.moves);
    let dof = s.machine.joint_names().len();
    let mut number = Vec::with_capacity(keep.len());
    let mut point = Vec::with_capacity(keep.len());
    let mut xyz = Vec::with_capacity(3 * keep.len());
    let mut joints = Vec::with_capacity(dof * keep.len());
    let mut flags = Vec::with_capacity(keep.len());
    let mut drawn_at = Vec::with_capacity(keep.len());
    for &i in &keep {
        let m = &s.moves[i];
        number.push(i as u32);
        point.push(m.point as u32);
        drawn_at.push(drawn.partition_point(|&d| d <= m.point) as u32);
        let p = path
            .and_then(|t| t.points.get(m.point))
            .map_or([f64::NAN; 3], |q| q.p);
        xyz.extend(p.map(|x| x as f32));
        joints.extend((0..dof).map(|j| m.joints.get(j).map_or(f32::NAN, |&v| v as f32)));
        let mut f = 0;
        if m.flags.collision {
            f |= FLAG_COLLISION;
        }
        if m.flags.near_singularity {
            f |= FLAG_SINGULARITY;
        }
        for &j in m.flags.near_limit.iter().filter(|&&j| j < dof) {
            f |= FLAG_LIMIT0 << j;
        }
        flags.push(f);
    }
    let count = |f: fn(&SimMove) -> bool| s.moves.iter().filter(|m| f(m)).count();
    serde_json::json!({
        "machine": machine_json(&s.machine),
        "names": s.machine.joint_names(),
        "head": head_overlay(&s.head.at([0.0; 3], [0.0, 0.0, 1.0])).json(),
        // Where the arm's tool holder meets the head, up the axis from the tip.
        "head_length": s.head.body_length.max(s.head.cone_length).max(0.0),
        "moves": keep.len(),
        "total": s.moves.len(),
        "number": base64_u32(&number),
        "point": base64_u32(&point),
        "xyz": base64_f32(&xyz),
        "joints": base64_f32(&joints),
        "flags": base64_u32(&flags),
        "drawn_at": base64_u32(&drawn_at),
        "flagged": {
            "any": count(|m| m.flags.any()),
            "collision": count(|m| m.flags.collision),
            "near_limit": count(|m| !m.flags.near_limit.is_empty()),
            "near_singularity": count(|m| m.flags.near_singularity),
        },
        "margins": { "limit_deg": s.margins.limit_deg, "singularity_deg": s.margins.singularity_deg },
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::simulation::SimFlags;

    fn moves(n: usize, flagged_every: usize) -> Vec<SimMove> {
        (0..n)
            .map(|i| SimMove {
                point: i,
                joints: vec![0.0; 6],
                flags: SimFlags {
                    collision: flagged_every > 0 && i % flagged_every == 7 % flagged_every,
                    ..SimFlags::default()
                },
            })
            .collect()
    }

    #[test]
    fn long_programs_are_thinned_keeping_the_ends_and_the_flagged_moves() {
        let m = moves(3 * MAX_SIM_MOVES + 11, 1000);
        let keep = embedded(&m);
        assert!(keep.len() <= MAX_SIM_MOVES, "{}", keep.len());
        assert_eq!(keep.first(), Some(&0));
        assert_eq!(keep.last(), Some(&(m.len() - 1)));
        for i in (7..m.len()).step_by(1000) {
            assert!(keep.binary_search(&i).is_ok(), "flagged move {i} dropped");
        }
        // Short ones whole; more flagged moves than kept: the first ones, still within bounds.
        assert_eq!(embedded(&moves(50, 0)), (0..50).collect::<Vec<_>>());
        let many = moves(10 * MAX_SIM_MOVES, 2);
        let keep = embedded(&many);
        assert!(keep.len() <= MAX_SIM_MOVES);
        assert!(keep.binary_search(&7).is_ok());
        assert!(embedded(&[]).is_empty());
    }

    /// The base64 text of `j[key]` as u32s.
    fn u32s(j: &serde_json::Value, key: &str) -> Vec<u32> {
        let text = j[key].as_str().unwrap_or_default();
        let mut bits: Vec<u8> = vec![];
        let alphabet = b"ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789-_";
        let (mut acc, mut n) = (0u32, 0);
        for c in text.bytes().filter(|&c| c != b'=') {
            let v = alphabet.iter().position(|&a| a == c).unwrap_or(0) as u32;
            acc = (acc << 6) | v;
            n += 6;
            if n >= 8 {
                n -= 8;
                bits.push((acc >> n) as u8);
            }
        }
        bits.chunks_exact(4)
            .map(|b| u32::from_le_bytes([b[0], b[1], b[2], b[3]]))
            .collect()
    }

    #[test]
    fn each_move_carries_its_flags_and_the_drawn_path_behind_it() {
        let table = crate::simulation::SimTable {
            centre: [0.0, 0.0],
            z: 0.0,
            radius: 100.0,
            table_above_b_axis: 20.0,
            b_limits_deg: [-90.0, 90.0],
            c_limits_deg: Some([-360.0, 360.0]),
        };
        let head = crate::HeadSize {
            tip_radius: 0.5,
            half_angle_deg: 30.0,
            cone_length: 8.0,
            body_radius: 20.0,
            body_length: 60.0,
        };
        let mv = |point: usize, b: f64, c: f64, collision: bool| SimMove {
            point,
            joints: vec![b, c],
            flags: SimFlags {
                collision,
                ..SimFlags::default()
            },
        };
        let sim = Simulation::new(
            SimMachine::Table(table),
            head,
            vec![
                mv(0, 0.0, 0.0, false),
                mv(3, 88.0, 358.0, false),
                mv(4, 10.0, 0.0, true),
            ],
            crate::SimMargins::default(),
        );
        let j = simulation_json(&sim, None, &[0, 2, 4]);
        assert_eq!(j["names"], serde_json::json!(["B", "C"]));
        assert_eq!(
            (j["moves"].as_u64(), j["total"].as_u64()),
            (Some(3), Some(3))
        );
        // B and C both near a limit at the second move (bits 2 and 3), a collision at the third.
        assert_eq!(u32s(&j, "flags"), vec![0, 4 | 8, 1]);
        assert_eq!(u32s(&j, "point"), vec![0, 3, 4]);
        // Drawn points up to each move's point: 0; 0 and 2; all three.
        assert_eq!(u32s(&j, "drawn_at"), vec![1, 2, 3]);
        assert_eq!(j["flagged"]["any"], 2);
        assert_eq!(j["machine"]["max"], serde_json::json!([90.0, 360.0]));
    }

    #[test]
    fn the_part_frame_is_base_moved_by_the_offset_and_inverts() {
        let a = SimArm {
            a1: 25.0,
            a2: -35.0,
            b: 0.0,
            c1: 400.0,
            c2: 455.0,
            c3: 420.0,
            c4: 80.0,
            joint_offsets: [0.0; 6],
            joint_signs: [1; 6],
            joint_min: [-170.0; 6],
            joint_max: [170.0; 6],
            base: [450.0, 10.0, 400.0, 90.0, 0.0, 0.0],
            part_offset: [5.0, 0.0, 2.0],
            tool: [0.0, 0.0, 150.0, 0.0, 0.0, 0.0],
        };
        let m = a.part_in_robot();
        // The part's origin is at base + R_z(90°)·offset = (450, 15, 402).
        let t = [m[0][3], m[1][3], m[2][3]];
        assert!(
            (t[0] - 450.0).abs() < 1e-9 && (t[1] - 15.0).abs() < 1e-9,
            "{t:?}"
        );
        assert!((t[2] - 402.0).abs() < 1e-9);
        let back = invert_rigid(&m);
        let product: Vec<f64> = (0..16)
            .map(|ij| (0..4).map(|k| back[ij / 4][k] * m[k][ij % 4]).sum())
            .collect();
        for (ij, p) in product.iter().enumerate() {
            let identity = f64::from(u8::from(ij / 4 == ij % 4));
            assert!((p - identity).abs() < 1e-9, "{product:?}");
        }
        // KUKA's A, B, C: R_z(A)·R_y(B)·R_x(C); B = 90° takes X to −Z.
        let r = frame_matrix([0.0, 0.0, 0.0, 0.0, 90.0, 0.0]);
        assert!((r[2][0] + 1.0).abs() < 1e-12);
    }
}
