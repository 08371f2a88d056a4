//! Named tolerances, after truck-base's `tolerance` module: the bare epsilons that recur in the
//! kernel, each with what it means. Every constant has exactly the value the code used before it
//! was named, so naming changes no result.

/// A norm, length, derivative or denominator above this is not zero. It guards
/// normalisations and divisions only; it is no geometric tolerance.
pub const NONZERO: f64 = 1e-300;

/// Relative point coincidence: two points are the same when they lie within this fraction of
/// their magnitude (`1 + |p|`, the larger coordinate norm, or a model's size) of each other.
pub const POINT_COINCIDENCE: f64 = 1e-6;

/// Points of one surface coincide within this fraction of the surface's size: closed
/// parameter directions, pole vertices and collapsed sides of a parameter domain.
pub const SURFACE_COINCIDENCE: f64 = 1e-7;

/// A parameter direction is singular (a pole or apex line) where its derivative is shorter
/// than this fraction of the other direction's.
pub const SINGULAR_RATIO: f64 = 1e-7;

/// Two parameters of a periodic curve are equal within this fraction of its period.
pub const PERIOD_FRACTION: f64 = 1e-9;

/// Parallel vectors: a cross product, or a vector's part off an axis, shorter than this
/// fraction of its factors is zero.
pub const PARALLEL: f64 = 1e-12;

/// An angle (or its tangent) below this is zero: a cone whose semi-angle is zero is a cylinder.
pub const ANGLE_ZERO: f64 = 1e-12;
