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

/// A divisor (a polygon's area in the moments of a fill's direction, a segment's squared
/// length) above this is not zero. It guards divisions only.
pub(crate) const NONZERO: f64 = 1e-300;

/// Relative slack of a count (of layers, lines or whole layers under a level) taken from a
/// ratio: a ratio within this of a whole number counts as that number.
pub(crate) const COUNT_SLACK: f64 = 1e-9;

/// A height or level (mm, or a morph level) within this of another is at it: a stack of
/// layers this short of the top is complete, a point of a transition band this far below a
/// layer's level is under it.
pub(crate) const HEIGHT_SLACK: f64 = 1e-9;

/// A chart point's Newton inversion has converged where the residual in the chart's plane
/// (`|r_x| + |r_y|`, mm) is below this.
pub(crate) const CHART_RESIDUAL: f64 = 1e-10;

/// A Gauss–Newton step on a surface's parameters (`|Δu| + |Δv|`) below this has converged.
pub(crate) const PARAMETER_STEP: f64 = 1e-12;

/// Slack of a parameter checked against a surface's bounds.
pub(crate) const PARAMETER_SLACK: f64 = 1e-9;

/// A foot on a surface's boundary is off the point's normal where the point's offset from the
/// normal line exceeds this fraction of `1 + distance`.
pub(crate) const FOOT_OFF_NORMAL: f64 = 1e-7;

/// A surface's area element `|S_u × S_v|` at or below this is singular: no native chart.
pub(crate) const AREA_ELEMENT_MIN: f64 = 1e-12;

/// A hole whose area (mm²) is below this, a micrometre square, is the noise of a boolean
/// between nearly coincident edges, not a hole in the part or its support.
pub(crate) const NOISE_AREA: f64 = 1e-6;

/// A contour whose doubled signed area (mm²) is at most this is empty.
pub(crate) const EMPTY_AREA2: f64 = 1e-18;

/// A ray is parallel to an edge where their cross product is at most this fraction of
/// `1 + |edge|`.
pub(crate) const PARALLEL_RAY: f64 = 1e-15;

/// Area slack, mm²: an opening that removes less than this removes nothing.
pub(crate) const AREA_SLACK: f64 = 1e-9;

/// A contour whose area is at most this fraction of its squared perimeter (times the perimeter
/// where above 1 mm) is a zero-area sliver: all its points on a line.
pub(crate) const SLIVER_AREA: f64 = 1e-12;

/// A vector (mm, or a sum of unit vectors) shorter than this has no direction: it is not
/// normalised, and a triangle side or height this short is degenerate.
pub(crate) const SHORT_VECTOR: f64 = 1e-12;

/// Squared distance (mm²) by which a cell's box must lie beyond the least segment distance so
/// far for the cell to be passed over: far above the round-off of either (some 1e-13 mm² for
/// parts a metre across), far below any distance that matters.
pub(crate) const BOX_SLACK: f64 = 1e-9;

/// A floor, mm, for a grid cell size taken as a share of a reach that may be zero.
pub(crate) const CELL_FLOOR: f64 = 1e-9;

/// A chart metric's Cholesky pivot at or below this (relative to its diagonal, itself floored at
/// it) is degenerate: the lattice falls back to the chart's own frame.
pub(crate) const METRIC_DEGENERATE: f64 = 1e-12;

/// Degrees under the tilt limit a tool axis is brought back to, so it lands inside the limit
/// after rounding.
pub(crate) const TILT_MARGIN_DEG: f64 = 1e-7;

/// The cross product of a planned axis and the surface normal (Eq. 5's `b × T_S`) shorter than
/// this: the two are opposite and give no rotation axis.
pub(crate) const PARALLEL_HEADING: f64 = 1e-9;

/// An orientation step rate (degrees per mm, or per point) larger by no more than this is not
/// rougher.
pub(crate) const RATE_SLACK: f64 = 1e-9;

/// A fixed tool axis shorter than this has no direction.
pub(crate) const ZERO_AXIS: f64 = 1e-9;

/// The step sections are compared in, mm: a ten-thousandth of a micrometre, far below any
/// tolerance of the fill (a layer taking another's fill lays it on a section this close).
pub(crate) const KEY_GRID: f64 = 1e-7;

/// Three points are collinear where their cross product is at most this fraction of the
/// squared length of the span.
pub(crate) const COLLINEAR: f64 = 1e-12;

/// A triangle's normal (cross product, mm²) shorter than this is degenerate: it has no normal.
pub(crate) const DEGENERATE_NORMAL: f64 = 1e-15;

/// A triangle's doubled area in the plane (its determinant, mm²) below this rasters nothing.
pub(crate) const TRIANGLE_DET: f64 = 1e-12;

/// Slack of a barycentric coordinate: a grid point this far outside a triangle's edge is in it.
pub(crate) const BARYCENTRIC_SLACK: f64 = 1e-9;

/// A floor, mm³, for a feature's expected volume before its extrusion error is taken relative
/// to it.
pub(crate) const VOLUME_FLOOR: f64 = 1e-12;

/// Share of a section's area (and as many mm²) by which the winding reading of crossing loops
/// must exceed the even-odd one to be taken ([`crate::fill::regions_by_winding`]): above
/// i_overlay's snapping, far below any overlap of two bodies worth a bead.
pub(crate) const UNION_GAIN: f64 = 1e-6;
