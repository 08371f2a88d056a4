//! Named tolerances for the bare epsilons the posts compare against. Each constant keeps the
//! value of the literal it replaced, so naming changes no program.

/// Below this |(n_x, n_y)| the tool axis is the delta5 bed's singular point itself: θ is
/// undefined.
pub(crate) const POLE: f64 = 1e-9;

/// Slack (degrees) allowed when checking the B and C limits.
pub(crate) const ANGLE_TOLERANCE: f64 = 1e-9;

/// `cos B` below which a rotation is treated as gimbal-locked (B = ±90°).
pub(crate) const GIMBAL_EPS: f64 = 1e-9;

/// A floor for a chart's span per tick before its round tick step is taken.
pub(crate) const TICK_STEP_FLOOR: f64 = 1e-12;

/// A floor for a chart axis's largest value, so an axis of zeros still has a scale.
pub(crate) const AXIS_MAX_FLOOR: f64 = 1e-9;

/// Relative slack of a chart's last tick: a tick this fraction past the axis's end is still
/// drawn.
pub(crate) const TICK_END_SLACK: f64 = 1e-9;

/// Arc length, mm, between two regular points below which they are one point (the
/// interpolation over a singular stretch takes the first one's value).
pub(crate) const ARC_ZERO: f64 = 1e-12;

/// A move, mm (in machine X Y Z, or of the part), shorter than this has no length: its feed is
/// taken over the rotary axes or not scaled.
pub(crate) const MOVE_ZERO: f64 = 1e-9;

/// Relative slack of a subdivision count: a C turn within this fraction of a whole number of
/// steps takes that number.
pub(crate) const STEP_COUNT_SLACK: f64 = 1e-9;

/// A KRL program's filament feed ratio (mm of filament per mm of path) changes only by more than
/// this.
pub(crate) const FEED_RATIO_CHANGE: f64 = 1e-7;

/// A KRL pose within this distance, mm, of the previous motion's goes nowhere.
pub(crate) const POSE_SAME_MM: f64 = 1e-9;

/// A KRL pose within this rotation, degrees, of the previous motion's goes nowhere.
pub(crate) const POSE_SAME_DEG: f64 = 1e-9;

/// Slack of a cosine computed by the arm's inverse kinematics beyond ±1 (rounding).
pub(crate) const COSINE_SLACK: f64 = 1e-12;

/// Sine of the wrist's A5 at or below which the wrist is singular (A4 and A6 on one axis).
pub(crate) const WRIST_SINGULAR: f64 = 1e-12;

/// A rotation angle (radians) below this takes the small-angle form of its rotation vector.
pub(crate) const SMALL_ROTATION: f64 = 1e-9;

/// A rotation vector shorter than this (radians) is the identity.
pub(crate) const ROTATION_ZERO: f64 = 1e-15;

/// Two unit axes whose cross product is shorter than this are parallel (or reversed).
pub(crate) const PARALLEL_AXES: f64 = 1e-12;

/// An X hint whose part normal to the Z axis is shorter than this is along Z: it makes no
/// frame.
pub(crate) const FRAME_HINT_MIN: f64 = 1e-9;

/// Slack, mm/min, of a speed checked against the machine's largest feed.
pub(crate) const FEED_SLACK: f64 = 1e-9;

/// Slack, mm, of a lift of the part rounded up to whole micrometres: a height this close to a
/// micrometre mark is not rounded past it. 1 nm: above the rounding of a bead thickness kept in
/// single precision (`PathPoint::thickness`: 0.008 nm at 0.2 mm, 0.12 nm at 2 mm), so a bead
/// bottom exactly on a mark stays there.
pub(crate) const ROUND_UP_SLACK: f64 = 1e-6;

/// Tool axes shorter than this are not directions (the post refuses them).
pub const MIN_AXIS: f64 = 1e-9;

/// Below this length (mm) the sum of a spline's incoming and outgoing chord directions has
/// no direction (the path turns back on itself): the tangent is the chord.
pub(crate) const BISECTOR_ZERO: f64 = 1e-9;
