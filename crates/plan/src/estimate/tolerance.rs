//! Named tolerances for the bare epsilons the estimate compares against. Each constant keeps
//! the value of the literal it replaced, so naming changes no estimate. (Under `estimate` while
//! `plan`'s crate root is being rewritten as stages, issue 32.)

/// Moves shorter than this (mm) take no time and do not turn.
pub(crate) const MIN_MOVE: f64 = 1e-9;

/// A change of unit direction between two moves smaller than this is no turn: the junction is
/// not slowed for it.
pub(crate) const NO_TURN: f64 = 1e-12;
