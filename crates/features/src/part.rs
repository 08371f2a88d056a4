//! A part's features, whatever it was read from: a STEP file's solids recognised feature by
//! feature ([`crate::extract()`]), a mesh's bodies each one `mesh_two5d` feature
//! ([`crate::whole::mesh_features`]).

use crate::assembly::{assemble, Assembly};
use crate::extract::{extract, ExtractError, ExtractOptions};
use brep::topology::{Brep, Origin};

/// Extracts every solid of `brep` and orders and checks them together; a mesh's bodies
/// ([`Origin::Mesh`]) are each one feature ([`crate::whole::mesh_features`]).
///
/// Fails on the first solid whose extraction fails, or when no solid encloses a volume.
pub fn extract_all(brep: &Brep, opts: &ExtractOptions) -> Result<Assembly, ExtractError> {
    match brep.origin {
        Origin::Mesh => crate::whole::mesh_features(brep),
        Origin::Step => assemble(brep, |b, s| extract(b, s, opts)),
    }
}
