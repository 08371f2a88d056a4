//! The crate's tolerances, named once.

/// The determinant (Möller–Trumbore) under which a ray is taken as parallel to a triangle's
/// plane, missing it: the crossing count of an inside test.
pub(crate) const RAY_PARALLEL: f64 = 1e-14;

/// A triangle whose third corner is within this share of its longest edge's length of that
/// edge is a needle ([`crate::needles`]): no plane holds it.
pub(crate) const NEEDLE_HEIGHT: f64 = 1e-9;
