//! Named tolerances for the bare epsilons the planners compare against. Each constant keeps
//! the value of the literals it replaced; literals with the same value but another meaning
//! (a test's assertion, a finite-difference step) are left as they are.

/// One micrometre, mm: the floor of bead spacings, chord tolerances and curvature steps.
pub(crate) const MICROMETRE: f64 = 1e-3;

/// Length (mm) under which a surface derivative or a segment counts as degenerate (zero).
pub(crate) const DEGENERATE_LENGTH: f64 = 1e-9;

/// Relative round-off slack: comparisons of coordinates or lengths allow this times
/// `1 + magnitude` (or this share of the quantity itself).
pub(crate) const ROUND_OFF: f64 = 1e-9;

/// Principal curvature (1/mm) above which (less negative) a reference surface counts as not
/// concave: no valley for its offsets to fold in.
pub(crate) const FLAT_CURVATURE: f64 = 1e-9;

/// Determinant under which the 2 × 2 normal equations of a chart's Newton and least-squares
/// steps count as singular.
pub(crate) const SINGULAR_DET: f64 = 1e-18;
