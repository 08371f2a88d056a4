//! The preview's tolerances: every float comparison below 1e-6 names one of these.

/// A tool axis shorter than this is no direction; the head is drawn along +Z then.
pub const AXIS_MIN_LENGTH: f64 = 1e-9;
