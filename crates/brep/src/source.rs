//! A part file parsed once, stood on the plate as often as placements need: a STEP file
//! ([`StepFile`]) or a mesh file ([`FacetedFile`]), read by its extension ([`read_part`]).

use crate::error::ReadError;
use crate::faceted::FacetedFile;
use crate::step::{turn_down, StepFile, StepPart};
use std::path::Path;

/// A part file parsed once, translated into a part as it stands or turned.
pub trait PartFile: Sync {
    /// The part as modelled.
    fn part(&self) -> Result<StepPart, ReadError>;
    /// The part turned by `rotation` (a rotation matrix, rows first: plate = rotation ×
    /// file) about the file's origin.
    fn rotated(&self, rotation: [[f64; 3]; 3]) -> Result<StepPart, ReadError>;
    /// The part turned so that the unit direction `down` (file frame) points down, −Z
    /// ([`turn_down`]).
    fn turned(&self, down: [f64; 3]) -> Result<StepPart, ReadError> {
        self.rotated(turn_down(down))
    }
}

impl PartFile for StepFile {
    fn part(&self) -> Result<StepPart, ReadError> {
        StepFile::part(self)
    }
    fn rotated(&self, rotation: [[f64; 3]; 3]) -> Result<StepPart, ReadError> {
        StepFile::rotated(self, rotation)
    }
    fn turned(&self, down: [f64; 3]) -> Result<StepPart, ReadError> {
        StepFile::turned(self, down)
    }
}

impl PartFile for FacetedFile {
    fn part(&self) -> Result<StepPart, ReadError> {
        Ok(self.part_turned(None))
    }
    fn rotated(&self, rotation: [[f64; 3]; 3]) -> Result<StepPart, ReadError> {
        Ok(self.part_turned(Some(rotation)))
    }
}

/// Reads a part file by its extension: `.stl`, `.3mf` and `.obj` as meshes (their gaps within
/// `tolerance` mm welded, [`FacetedFile::read`]), anything else as STEP.
pub fn read_part(path: &Path, tolerance: f64) -> Result<Box<dyn PartFile>, ReadError> {
    Ok(if meshfile::is_mesh(path) {
        Box::new(FacetedFile::read(path, tolerance)?)
    } else {
        Box::new(StepFile::read(path)?)
    })
}
