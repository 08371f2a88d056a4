//! Placements the machine can print: where a planned part can go so that every point fits the
//! machine, found rather than assumed (issue 31, item 3).
//!
//! - [`turn`](mod@turn): the least turn of the part about the build direction (+Z) that fits the
//!   bed (Marlin, and the KUKA table) or the work envelope (`delta5`), as each post places the
//!   part ([`turn_to_fit`]).
//! - [`reach`](mod@reach): on `kuka`, the least move of the part on the table (the cell's
//!   `part_position`) that brings every point into the arm's reach and joint limits
//!   ([`reach_shift`]).
//! - [`size`](mod@size): whether the part can fit in any placement at all: the most it may
//!   measure across ([`largest_across`]).
//!
//! The two searches run with a cheap model of the post's check and confirm their choice with
//! the post itself, so a placement they return is one the post accepts.

pub mod reach;
pub mod size;
pub mod turn;

pub use reach::{reach_shift, unreachable_points, ReachShift};
pub use size::{across, largest_across};
pub use turn::{bounding_path, envelope_excess, turn_to_fit, turn_to_fit_until, turned, TurnFit};

use crate::sink::ProgramSink;
use crate::PostError;

/// Why no placement was found.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum FitError {
    /// The post refused the path for a reason a placement does not change (a tool axis
    /// outside the B limits, a non-finite point, a profile of another kind).
    #[error(transparent)]
    Post(#[from] PostError),
    /// No turn about the build direction fits the bed or work envelope.
    #[error("no turn about the build direction fits the part on `{name}`: the best, {angle_deg:.1} degrees, still misses by {excess_mm:.3} mm")]
    NoTurn {
        /// The profile's `name`.
        name: String,
        /// The turn (degrees) that missed least.
        angle_deg: f64,
        /// By how much it missed (mm).
        excess_mm: f64,
    },
    /// The search was given up at its time limit ([`turn_to_fit_until`]).
    #[error("the search for a turn that fits was given up at its time limit")]
    TimeLimit,
    /// No move of the part on the table brings every point into the arm's reach.
    #[error("no place on the table of `{name}` brings every point into the arm's reach: the best, part_position [{x:.1}, {y:.1}], leaves {unreachable} point(s) out of reach")]
    NoShift {
        /// The profile's `name`.
        name: String,
        /// The best `part_position` X tried (mm).
        x: f64,
        /// The best `part_position` Y tried (mm).
        y: f64,
        /// Points out of reach there.
        unreachable: usize,
    },
}

/// A sink that drops everything written to it: the posts run to check a placement.
struct Discard;

impl ProgramSink for Discard {
    fn file(&mut self, _name: &str) -> std::io::Result<Box<dyn std::io::Write + '_>> {
        Ok(Box::new(std::io::sink()))
    }
}
