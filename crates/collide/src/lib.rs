//! collide: print-head collisions (issue 18).
//!
//! - [`Head`]: the head's shape, the machine profile's `[head]` table (a nozzle cone under a
//!   body cylinder on the tool axis);
//! - [`Table`]: the machine's table in part coordinates (a plane, or the disc of a B/C bed);
//! - [`Deposit`]: the material laid so far, grains along the beads' top centrelines in a
//!   hierarchy of occupied cells, asked whether any grain lies inside the head;
//! - [`check`]: every move of a [`toolpath::ToolPath`], the head swept along it, against what
//!   was deposited before it (earlier features, the feature's earlier layers) and the table;
//!   [`check_and_route`] also lifts colliding travels over the material, and
//!   [`tilt_and_route`] first tilts colliding print moves clear ([`tilt`]);
//! - [`tilt`]: colliding print moves cleared by turning the tool axis inside the orientation's
//!   tolerance cone, the turn blended along the path;
//! - [`interleave`]: sibling features printed layer by layer in turn, when that clears the head.
//!
//! It reads only the tool path: the beads a feature lays are the material it leaves.

#![warn(missing_docs)]

mod check;
mod deposit;
mod head;
mod order;
mod scene;
mod table;
mod tilt;
mod tolerance;

pub use check::{check_and_route, tilt, tilt_and_route, Routed, Stop, Travels};
pub use deposit::{Deposit, GRAIN_SPACING};
pub use head::{Head, HeadShape};
pub use order::interleave;
pub use scene::{check, Collision, Obstacle, Scene, SWEEP_STEP, TOLERANCE};
pub use table::Table;
pub use tilt::{blend, TiltLimits, Tilted, AZIMUTHS, FINE_STEP_DEG, RING_STEP_DEG};
