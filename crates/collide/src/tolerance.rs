//! Named tolerances for the bare epsilons the collision check and the tilt compare against.
//! Each constant keeps the value of the literal it replaced, so naming changes no result.

/// Angle, radians, an axis may exceed a limit by (a turn the slope between two keys, or a cone
/// or B limit), for rounding.
pub(crate) const ANGLE_SLACK: f64 = 1e-9;

/// A floor, mm, for a blend window before a turn per mm is taken over it.
pub(crate) const WINDOW_FLOOR: f64 = 1e-9;

/// A rotation vector shorter than this (radians) turns nothing.
pub(crate) const TURN_ZERO: f64 = 1e-15;

/// Padding, mm, of a deposit leaf cell's half-size, so a bead centre on a cell's face is held
/// by the cell.
pub(crate) const CELL_PAD: f64 = 1e-9;
