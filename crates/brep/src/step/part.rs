//! Reading a STEP file into a B-rep: the parser and the translator in turn.

use super::error::ReadError;
use crate::topology::Brep;
use std::path::Path;

/// A STEP file read into a B-rep.
#[derive(Debug, Clone)]
pub struct StepPart {
    /// Every solid of the file, in millimetres.
    pub brep: Brep,
    /// The file's schema names (`FILE_SCHEMA`).
    pub schemas: Vec<String>,
}

/// Reads a STEP file from disk.
pub fn read_step(path: impl AsRef<Path>) -> Result<StepPart, ReadError> {
    let bytes = std::fs::read(path.as_ref())?;
    read_step_bytes(&bytes)
}

/// Reads a STEP file from memory.
pub fn read_step_bytes(bytes: &[u8]) -> Result<StepPart, ReadError> {
    let file = super::p21::parse(bytes)?;
    let brep = super::read::translate(&file)?;
    Ok(StepPart {
        brep,
        schemas: file.schemas(),
    })
}
