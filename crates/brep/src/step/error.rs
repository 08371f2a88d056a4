//! Errors of reading a STEP file into a B-rep.

use crate::step::p21::P21Error;

/// Why a file could not be read. Each message is one line; the CLI prefixes the file name.
#[derive(Debug, thiserror::Error)]
pub enum ReadError {
    /// The file could not be opened or read.
    #[error("cannot read file: {0}")]
    Io(#[from] std::io::Error),
    /// Not a valid Part 21 exchange file.
    #[error("{0}")]
    Syntax(#[from] P21Error),
    /// A reference to an entity that the file does not define.
    #[error("#{from} refers to #{missing}, which the file does not define")]
    Dangling {
        /// The entity holding the reference.
        from: u64,
        /// The missing entity.
        missing: u64,
    },
    /// An entity whose contents do not make sense.
    #[error("#{id} ({entity}): {msg}")]
    Entity {
        /// STEP `#id`.
        id: u64,
        /// Entity type name.
        entity: String,
        /// What is wrong.
        msg: String,
    },
    /// An entity kind we cannot turn into exact geometry.
    #[error("#{id}: unsupported entity {entity}")]
    Unsupported {
        /// STEP `#id`.
        id: u64,
        /// Entity type name.
        entity: String,
    },
    /// A mesh file (STL, 3MF, OBJ) that could not be read.
    #[error(transparent)]
    Mesh(#[from] meshfile::MeshReadError),
    /// A mesh object that is not closed and manifold, even with its small gaps welded.
    #[error("{}{why}", if object.is_empty() { String::new() } else { format!("object `{object}`: ") })]
    NotClosed {
        /// The object's name (empty when the file has one object without a name).
        object: String,
        /// Its edges.
        why: meshfile::NotClosed,
    },
    /// The file holds no solid at all.
    #[error(
        "no solid in the file (found no MANIFOLD_SOLID_BREP, BREP_WITH_VOIDS or closed shell){0}"
    )]
    NoSolid(String),
}
