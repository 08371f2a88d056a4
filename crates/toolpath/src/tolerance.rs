//! Named tolerances for the bare epsilons the tool path's vector helpers compare against. Each
//! constant keeps the value of the literal it replaced.

/// A vector shorter than this (mm, or for a direction its length) is too small to normalise.
pub(crate) const UNIT_MIN: f64 = 1e-12;
