//! A feature's layers filled, before they are laid from where the nozzle is: the part of
//! planning a feature that does not depend on the feature printed before it, so a part's
//! features are filled in parallel and laid one after the other.

use crate::error::FeatureError;
use crate::feature_plan::FeaturePlan;
use crate::freeform::{fill_freeform, FreeformFill};
use crate::params::LayerParams;
use crate::planar::{fill_two5d_on, PlanarMesh, Two5dFill};
use crate::toolpath::Bead;
use brep::math::P3;
use features::{Feature, FeatureKind, FeatureTree};

/// A feature's layers filled by its planner: planar for `two5d`, offsets of the reference
/// surface for `freeform`. Only a few live at once (one per thread), so the variants are not
/// boxed.
#[allow(clippy::large_enum_variant)]
pub enum FeatureFill<'a> {
    /// Planar layers ([`crate::planar`]).
    Two5d(Two5dFill),
    /// Offset layers ([`crate::freeform`]).
    Freeform(FreeformFill<'a>),
}

/// Fills every layer of feature `f` of `tree` by its kind's planner.
pub fn fill_feature<'a>(
    tree: &'a FeatureTree,
    f: &Feature,
    params: &LayerParams,
    bead: Bead,
) -> Result<FeatureFill<'a>, FeatureError> {
    fill_feature_on(tree, f, params, bead, None)
}

/// [`fill_feature`], a two5d feature on its planar mesh made already (`meshed`; `None`: made
/// here).
pub fn fill_feature_on<'a>(
    tree: &'a FeatureTree,
    f: &Feature,
    params: &LayerParams,
    bead: Bead,
    meshed: Option<&PlanarMesh>,
) -> Result<FeatureFill<'a>, FeatureError> {
    Ok(match f.kind {
        FeatureKind::Two5d => FeatureFill::Two5d(fill_two5d_on(tree, f, params, bead, meshed)?),
        FeatureKind::Freeform => FeatureFill::Freeform(fill_freeform(tree, f, params, bead)?),
    })
}

impl FeatureFill<'_> {
    /// Planar layers with support material in `columns` ([`Two5dFill::with_support`]);
    /// curved layers as they are (support material is for planar layers only).
    pub fn with_support(
        self,
        columns: &crate::support_material::SupportRegions,
        params: &LayerParams,
    ) -> Self {
        match self {
            FeatureFill::Two5d(f) => FeatureFill::Two5d(f.with_support(columns, params)),
            other => other,
        }
    }

    /// The feature's plan, its first travel starting at `entry` (where the nozzle is).
    pub fn lay(self, entry: Option<P3>) -> FeaturePlan {
        match self {
            FeatureFill::Two5d(f) => f.lay(entry),
            FeatureFill::Freeform(f) => f.lay(entry),
        }
    }
}
