//! robot-post: the programs a machine runs, written from a planned tool path.
//!
//! - [`machine`]: machine profiles ([`MachineProfile`]), read from TOML; the built-in ones are
//!   the files in the repository's `profiles/` folder.
//! - [`toolpath`]: the planned path the posts consume ([`ToolPath`] of [`PathPoint`]s), from the
//!   `toolpath` crate (re-exported).
//! - [`marlin`](mod@marlin): 3-axis Marlin G-code for paths whose tool axis is +Z throughout.
//!
//! Every fallible function returns a [`PostError`] whose message is one line.

pub mod delta5;
pub mod error;
mod gcode;
mod kind;
pub mod krl;
pub mod kuka;
pub mod machine;
pub mod marlin;
pub mod placement;
pub use toolpath;

pub use delta5::{delta5, Delta5Geometry, Delta5Program, KinematicFigures};
pub use error::PostError;
pub use kuka::{kuka, KrlProgram, KukaCell, KukaFigures};
pub use machine::{MachineKind, MachineProfile};
pub use marlin::marlin;
pub use toolpath::{MoveKind, PathPoint, ToolPath};
