//! The preview's tolerances: every float comparison below 1e-6 names one of these.

/// A tool axis shorter than this is no direction; the head is drawn along +Z then.
pub const AXIS_MIN_LENGTH: f64 = 1e-9;

/// A tool axis whose XY part is shorter than this points along the C axis: delta5's pole,
/// where C is not defined (as `robot_post`'s `POLE`).
pub const POLE: f64 = 1e-9;

/// Slack of an angle (degrees) at a limit (as `robot_post`'s `ANGLE_TOLERANCE`).
pub const ANGLE_TOLERANCE: f64 = 1e-9;
