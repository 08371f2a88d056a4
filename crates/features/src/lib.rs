//! `features`: what a part is built from. AM feature recognition after the feature-based
//! five-axis AM paper: an attributed adjacency graph with edge convexity ([`aag`]), concave
//! loops, shell splitting and healing, classification into `two5d` and `freeform` features and
//! their dependency graph ([`extract`](mod@extract)); the solids of a file together ([`assembly`]);
//! each solid whole as one planar feature ([`whole`]).
#![warn(missing_docs)]

pub mod aag;
pub mod assembly;
pub mod check;
pub mod extract;
pub mod measure;
pub mod part;
pub mod split;
mod tolerance;
pub mod whole;

pub use assembly::{solid_name, Assembly};
pub use check::{check_solid, SolidCheck, SolidProblem};
pub use extract::{
    extract, ExtractError, ExtractOptions, Feature, FeatureKind, FeatureTree, Reference, RootLoop,
    RootOutcome,
};
pub use part::extract_all;
pub use whole::{is_whole_part, mesh_features, whole_part_features, MESH_TWO5D};
