//! The plan crate's tolerances: every float comparison below 1e-6 names one of these.

/// A volume below which a feature holds nothing, mm³ (a divisor's floor: shares of it are
/// meaningless).
pub const VOLUME_MM3: f64 = 1e-12;

/// How far below the build plate a point must lie to be reported as below it, mm.
pub const BELOW_PLATE_MM: f64 = 1e-3;

/// A build direction whose z is below this points below the horizon (`--orient auto`).
pub const BELOW_HORIZON_Z: f64 = -1e-3;

/// Two planar faces' outward normals whose dot product exceeds this point the same way.
pub const SAME_DIRECTION_DOT: f64 = 1.0 - 1e-9;

/// A `down` whose z is below this already points down (−Z): the part stands as modelled.
pub const STANDS_Z: f64 = -1.0 + 1e-12;

/// Heights (mm) within this of each other are one: a pedestal height a whole number of layers
/// to within rounding.
pub const HEIGHT_SLACK: f64 = 1e-9;

/// A build direction whose z is within this of 1 is +Z (`slicing = "auto"` on a machine that
/// prints only along +Z): about 2.6° off.
pub const PLUS_Z_SLACK: f64 = 1e-3;

/// Two points closer than this (mm) give no direction from one to the other.
pub const SAME_POINT_MM: f64 = 1e-9;
