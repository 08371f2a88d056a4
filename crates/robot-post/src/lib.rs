//! robot-post: the programs a machine runs, written from a planned tool path.
//!
//! - [`machine`]: machine profiles ([`MachineProfile`]), read from TOML; the built-in ones are
//!   the files in the repository's `profiles/` folder.
//! - [`post`](mod@post): one entry for every post: [`MachineProfile::post`] gives the profile's
//!   [`Post`], which writes a [`Program`] (files, figures per feature, warnings) for a [`Job`].
//! - [`toolpath`]: the planned path the posts consume ([`ToolPath`] of [`PathPoint`]s), from the
//!   `toolpath` crate (re-exported).
//! - [`marlin`](mod@marlin): 3-axis Marlin G-code for paths whose tool axis is +Z throughout.
//! - [`delta5`](mod@delta5): 5-axis G-code for a printer with a tilting and rotating bed.
//! - [`kuka`](mod@kuka): KRL programs for a KUKA robot cell; [`krl`] reads them back.
//! - [`placement`]: where a post puts the part on the machine.
//! - [`fit`]: placements the machine can print, searched for: the least turn about the build
//!   direction that fits the bed or envelope, the least move on a KUKA table into the arm's reach.
//! - [`custom`]: the profile's start and end G-code and their placeholders.
//!
//! Every fallible function returns a [`PostError`] whose message is one line.

#![warn(missing_docs)]

pub mod custom;
pub mod delta5;
pub mod error;
pub mod fit;
mod gcode;
mod kind;
pub mod krl;
pub mod kuka;
pub mod machine;
pub mod marlin;
pub mod placement;
pub mod post;
pub mod sink;
mod tolerance;
pub use toolpath;

pub use delta5::{delta5, delta5_to, Delta5Geometry, Delta5Program, KinematicFigures};
pub use error::PostError;
pub use kuka::{kuka, kuka_to, KrlProgram, KukaCell, KukaFigures};
pub use machine::{MachineKind, MachineProfile};
pub use marlin::{marlin, marlin_job_to, marlin_to};
pub use post::{Job, Post, PostFigures, Program};
pub use sink::{InMemory, ProgramFile, ProgramSink};
pub use toolpath::{MoveKind, PathPoint, ToolPath};
