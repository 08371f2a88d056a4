//! The plan crate's tolerances: every float comparison below 1e-6 names one of these.

/// A volume below which a feature holds nothing, mm³ (a divisor's floor: shares of it are
/// meaningless).
pub const VOLUME_MM3: f64 = 1e-12;

/// How far below the build plate a point must lie to be reported as below it, mm.
pub const BELOW_PLATE_MM: f64 = 1e-3;
