//! Why a feature could not be planned.

/// Why a feature could not be planned.
#[derive(Debug, thiserror::Error)]
pub enum FeatureError {
    /// The feature is freeform: [`crate::freeform::plan_freeform`] plans it.
    #[error("feature {0} is freeform, not two5d")]
    NotTwo5d(usize),
    /// A freeform feature cannot be planned on offsets of its reference surface.
    #[error("feature {id}: {msg}")]
    Freeform {
        /// Feature id.
        id: usize,
        /// Cause.
        msg: String,
    },
    /// The offset of a freeform feature's reference surface folds over itself (feature-based
    /// AM paper, Fig. 9: a concave valley narrower than the offset).
    #[error("feature {id}: layer {layer} would lie {offset:.3} mm off its reference surface, past the {radius:.3} mm radius of a concave valley of it, where the offset surface folds over itself; split the feature at the valley (paper, Fig. 9) or build it from another reference")]
    OffsetFolds {
        /// Feature id.
        id: usize,
        /// First layer (1-based) that folds.
        layer: usize,
        /// Its offset, mm.
        offset: f64,
        /// Smallest concave radius of the reference under the feature, mm.
        radius: f64,
    },
    /// The feature has no reference plane.
    #[error("feature {0} has no reference plane")]
    NoPlane(usize),
    /// Meshing the feature failed.
    #[error("feature {id}: {msg}")]
    Mesh {
        /// Feature id.
        id: usize,
        /// Cause.
        msg: String,
    },
    /// Bad layer parameters.
    #[error("feature {id}: {msg}")]
    Params {
        /// Feature id.
        id: usize,
        /// Cause.
        msg: String,
    },
    /// The work on the feature was given up at the caller's time limit
    /// ([`crate::support::Carry::Until`]).
    #[error("feature {0}: given up at the time limit")]
    TimeLimit(usize),
}
