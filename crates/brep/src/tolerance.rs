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

/// A Newton step on a curve's parameter below this fraction of `1 + |t|` has converged.
pub const CURVE_NEWTON_STEP: f64 = 1e-14;

/// A step of a point's projection onto a surface, `|Δu| + |Δv|` in parameters, below this has
/// converged.
pub const PROJECTION_STEP: f64 = 1e-13;

/// A segment of a planar curve bows off its chord by less than this fraction of `1 + length`:
/// it is straight and has no sliver worth an integral.
pub const STRAIGHT_BOW: f64 = 1e-9;

/// A floor, mm, for a tolerance or a model size that may be zero (an empty box's diagonal, a
/// degenerate face's size) before a tolerance is taken as a fraction of it.
pub const LENGTH_FLOOR: f64 = 1e-9;

/// A floor for a face's parameter span before a finite-difference step is taken as a
/// thousandth of it.
pub const PARAMETER_SPAN_FLOOR: f64 = 1e-9;

/// A surface curves in a direction where its second derivative exceeds this fraction of
/// `1 + |first derivative|`.
pub const CURVATURE_RELATIVE: f64 = 1e-9;

/// A first derivative (length per unit parameter) at or below this is zero.
pub const DERIVATIVE_ZERO: f64 = 1e-12;

/// A signed area in a face's parameter domain above this is positive (the loop turns counter
/// to the face's sense).
pub const PARAMETER_AREA: f64 = 1e-12;

/// The triangulator (spade) refuses coordinate magnitudes below 2^-142; a scaled parameter
/// below this is zero.
pub const TRIANGULATOR_ZERO: f64 = 1e-30;

/// A placement is the identity where every entry of its rotation matrix is within this of the
/// identity's.
pub const ROTATION_IDENTITY: f64 = 1e-12;

/// Two placements' rotation matrices are equal where every entry differs by less than this.
pub const ROTATION_EQUAL: f64 = 1e-9;

/// A placement's shift, mm, shorter than this is no shift.
pub const SHIFT_ZERO: f64 = 1e-9;

/// A surface's normal is defined where `|S_u × S_v|` exceeds this fraction of
/// `1 + |S_u||S_v|`.
pub const NORMAL_ZERO: f64 = 1e-14;

/// A profile curve whose two ends are within this, mm, is closed (an extrusion of it is
/// periodic).
pub const CLOSED_PROFILE: f64 = 1e-7;

/// The 2 × 2 normal equations of a surface projection are singular where the determinant is
/// below this fraction of the product of their diagonal.
pub const SINGULAR_DET_RELATIVE: f64 = 1e-18;

/// Two unit normals closer than this (`1 − cos`) at a mesh vertex are one (the faces are
/// tangent there): an offset moves the vertex once along it (`mesh::offset`).
pub const OFFSET_TANGENT: f64 = 1e-7;

/// An offset's mitre drops the directions where the eigenvalues of `NᵀN` fall below this share
/// of the largest: the faces constrain no move along them (`mesh::offset`).
pub const OFFSET_RANK_CUTOFF: f64 = 1e-9;

/// An offset's slide of a face's edge along the face shorter than this, mm, is none
/// (`mesh::offset`).
pub const SLIDE_ZERO: f64 = 1e-9;
