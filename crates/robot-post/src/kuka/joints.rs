//! `joints.csv`: the joint angles of every Cartesian motion of a KRL program, as the reach
//! check solved them.

use super::checks::Reach;
use super::motion::Step;
use crate::sink::{Chunked, ProgramSink};
use crate::PostError;
use toolpath::{fixed, ToolPath};

/// The name of the joint table written beside the program.
pub const JOINTS_CSV: &str = "joints.csv";

/// The joint table's header: the motion's number, the tool path point the post made it for
/// (its row in `toolpath.csv`, 0 the first after the header: a print motion's pose is that
/// point's; a retreat, travel or approach names the point it leaves or leads to), then A1..A6
/// in degrees.
pub const JOINTS_HEADER: &str = "move,point,A1,A2,A3,A4,A5,A6";

/// Writes `joints.csv` into `sink`: after [`JOINTS_HEADER`], one row per Cartesian motion of
/// `steps` in the program's order (`move` counts them from 1, as the post's warnings do: the
/// axis `PTP`s home have none), the path point it goes to, the joints of the solution `reach`
/// follows for it, 4 decimals;
/// a motion out of reach has its number and empty joints. `reach` must start where the
/// program's check did (a fresh [`Reach`]), so that it follows the same solutions.
pub(super) fn write_joints(
    path: &ToolPath,
    steps: impl Iterator<Item = Step>,
    mut reach: Reach,
    sink: &mut dyn ProgramSink,
) -> Result<(), PostError> {
    let mut file = Chunked::open(sink, JOINTS_CSV)?;
    let mut text = format!("{JOINTS_HEADER}\n");
    let mut n = 0usize;
    for step in steps {
        let Step::Move { pose, point, .. } = step else {
            continue;
        };
        n += 1;
        let feature = path.points[point].feature;
        let solved = reach.motion(&pose, point, feature as usize, (JOINTS_CSV, n + 1));
        text.push_str(&n.to_string());
        text.push(',');
        text.push_str(&point.to_string());
        match solved.joints {
            Some((j, _, _)) => {
                for a in j {
                    text.push(',');
                    text.push_str(&fixed(a, 4));
                }
            }
            None => text.push_str(",,,,,,"),
        }
        text.push('\n');
        file.pass_on(&mut text)?;
    }
    file.finish(&text)
}
