//! toolpath: what the planner hands the posts.
//!
//! - the planned path ([`ToolPath`] of [`PathPoint`]s, [`MoveKind`]) and its `toolpath.csv`
//!   form, with [`fixed`] for the fixed-point numbers every program writes;
//! - [`Role`]: what a path is for (perimeter, infill, gap fill), as slicers name it;
//! - [`Bead`]: the bead a machine lays and the filament it feeds for it (Isa & Lazoglu 2019,
//!   Eq. 1);
//! - [`vec3`]: arithmetic on the `[f64; 3]` positions and axes of planned points.
//!
//! It depends on no geometry kernel: the slicer writes these types, the posts read them.

#![warn(missing_docs)]

mod bead;
mod fixed;
mod path;
mod role;
mod tolerance;
pub mod vec3;

pub use bead::Bead;
pub use fixed::{
    fixed, push_fixed, push_fixed_bytes, push_integer_bytes, push_scaled, MAX_SCALED_DECIMALS,
};
pub use path::{MoveKind, PathPoint, ToolPath, ToolPathError, CSV_HEADER};
pub use role::Role;
