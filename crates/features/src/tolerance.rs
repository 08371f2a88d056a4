//! Named tolerances for the bare epsilons feature recognition compares against. Each constant
//! keeps the value of the literal it replaced, so naming changes no result.

/// A direction shorter than this is not normalised (it has no direction).
pub(crate) const NORMALISABLE: f64 = 1e-300;

/// A floor, mm³, for a part's volume before a share of it is taken as the allowed mismatch of
/// the features' volumes.
pub(crate) const VOLUME_FLOOR: f64 = 1e-9;

/// Absolute slack, mm³, added to the relative slack when a split's two sides must hold the
/// volume before it.
pub(crate) const VOLUME_SLACK: f64 = 1e-9;

/// Parameters of a periodic curve closer than this to a whole period apart (or to each other,
/// going the wrong way) are the same point.
pub(crate) const PERIOD_SLACK: f64 = 1e-9;

/// A continuation along a periodic curve shorter than this in parameter is empty: it goes a
/// whole turn.
pub(crate) const EMPTY_SPAN: f64 = 1e-12;
