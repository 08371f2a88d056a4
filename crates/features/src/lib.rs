//! `features`: what a part is built from. AM feature recognition after the feature-based
//! five-axis AM paper: an attributed adjacency graph with edge convexity ([`aag`]), concave
//! loops, shell splitting and healing, classification into `two5d` and `freeform` features and
//! their dependency graph ([`extract`]).
#![warn(missing_docs)]

pub mod aag;
pub mod extract;

pub use extract::{
    extract, ExtractError, ExtractOptions, Feature, FeatureKind, FeatureTree, Reference,
};
