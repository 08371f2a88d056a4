//! Helpers shared by the slicer's integration tests.

use features::{extract, ExtractOptions, FeatureTree};
use std::path::PathBuf;

/// The feature tree of a fixture's (first) solid.
pub fn tree(name: &str) -> FeatureTree {
    let path = PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("../../fixtures")
        .join(format!("{name}.step"));
    let part = brep::read_step(&path).expect("fixture reads");
    let s = part.brep.solid_ids().next().expect("a solid");
    extract(&part.brep, s, &ExtractOptions::default()).expect("extracts")
}
