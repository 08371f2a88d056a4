//! Reading a STEP file into a B-rep: the parser and the translator in turn.

use super::error::ReadError;
use super::p21::P21File;
use crate::tolerance::PARALLEL;
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
    StepFile::read(path)?.part()
}

/// Reads a STEP file from memory.
pub fn read_step_bytes(bytes: &[u8]) -> Result<StepPart, ReadError> {
    StepFile::from_bytes(bytes)?.part()
}

/// Reads a STEP file from disk with every solid turned so that the unit direction `down` (in
/// the file's frame) points down, −Z: a part modelled on its side is read standing on the face
/// whose outward normal is `down`. The turn is the least rotation doing so (about
/// `down` × −Z; half a turn about X when `down` is +Z), about the file's origin.
pub fn read_step_turned(path: impl AsRef<Path>, down: [f64; 3]) -> Result<StepPart, ReadError> {
    StepFile::read(path)?.turned(down)
}

/// A STEP file parsed once: translated into a part as it stands ([`StepFile::part`]) or turned
/// onto a face ([`StepFile::turned`]) as often as placements need, without reading or parsing
/// the file again.
#[derive(Debug)]
pub struct StepFile {
    file: P21File,
}

impl StepFile {
    /// Parses a STEP file from disk.
    pub fn read(path: impl AsRef<Path>) -> Result<StepFile, ReadError> {
        let bytes = std::fs::read(path.as_ref())?;
        StepFile::from_bytes(&bytes)
    }

    /// Parses a STEP file from memory.
    pub fn from_bytes(bytes: &[u8]) -> Result<StepFile, ReadError> {
        Ok(StepFile {
            file: super::p21::parse(bytes)?,
        })
    }

    /// The part as modelled.
    pub fn part(&self) -> Result<StepPart, ReadError> {
        Ok(StepPart {
            brep: super::read::translate(&self.file)?,
            schemas: self.file.schemas(),
        })
    }

    /// The part with every solid turned so that the unit direction `down` (file frame) points
    /// down, −Z ([`turn_down`], as [`read_step_turned`]).
    pub fn turned(&self, down: [f64; 3]) -> Result<StepPart, ReadError> {
        Ok(StepPart {
            brep: super::read::translate_turned(&self.file, Some(turn_down(down)))?,
            schemas: self.file.schemas(),
        })
    }

    /// The part with every solid turned by `rotation` (a rotation matrix, rows first: plate =
    /// rotation × file) about the file's origin: [`StepFile::turned`] for any rotation, e.g.
    /// a face turned down and then a turn about +Z.
    pub fn rotated(&self, rotation: [[f64; 3]; 3]) -> Result<StepPart, ReadError> {
        Ok(StepPart {
            brep: super::read::translate_turned(&self.file, Some(rotation))?,
            schemas: self.file.schemas(),
        })
    }
}

/// The least rotation (a matrix, rows first) taking the unit vector `n` onto −Z (Rodrigues).
pub fn turn_down(n: [f64; 3]) -> [[f64; 3]; 3] {
    let len = (n[0] * n[0] + n[1] * n[1] + n[2] * n[2]).sqrt();
    let n = if len > 0.0 {
        [n[0] / len, n[1] / len, n[2] / len]
    } else {
        [0.0, 0.0, -1.0]
    };
    // axis = n × (−Z) = (−n_y, n_x, 0); cos = −n_z.
    let (kx, ky) = (-n[1], n[0]);
    let s = (kx * kx + ky * ky).sqrt();
    let c = -n[2];
    if s < PARALLEL {
        return if c > 0.0 {
            [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]]
        } else {
            [[1.0, 0.0, 0.0], [0.0, -1.0, 0.0], [0.0, 0.0, -1.0]]
        };
    }
    let (x, y) = (kx / s, ky / s);
    let t = 1.0 - c;
    [
        [c + x * x * t, x * y * t, y * s],
        [x * y * t, c + y * y * t, -x * s],
        [-y * s, x * s, c],
    ]
}

#[cfg(test)]
mod tests {
    use super::turn_down;

    fn apply(m: [[f64; 3]; 3], v: [f64; 3]) -> [f64; 3] {
        [0, 1, 2].map(|r| m[r][0] * v[0] + m[r][1] * v[1] + m[r][2] * v[2])
    }

    #[test]
    fn the_turn_takes_the_direction_down_and_is_a_rotation() {
        let s = 0.5f64.sqrt();
        for n in [
            [1.0, 0.0, 0.0],
            [0.0, -1.0, 0.0],
            [0.0, 0.0, 1.0],
            [0.0, 0.0, -1.0],
            [s, 0.0, s],
            [0.3, -0.4, 0.866],
            [-0.6, 0.0, -0.8],
        ] {
            let l = (n[0] * n[0] + n[1] * n[1] + n[2] * n[2]).sqrt();
            let m = turn_down(n);
            let d = apply(m, [n[0] / l, n[1] / l, n[2] / l]);
            assert!(
                (d[0]).abs() < 1e-12 && d[1].abs() < 1e-12 && (d[2] + 1.0).abs() < 1e-12,
                "{n:?} -> {d:?}"
            );
            // Orthonormal with determinant +1.
            for a in 0..3 {
                for b in 0..3 {
                    let dot: f64 = (0..3).map(|k| m[k][a] * m[k][b]).sum();
                    assert!((dot - if a == b { 1.0 } else { 0.0 }).abs() < 1e-12);
                }
            }
            let det = m[0][0] * (m[1][1] * m[2][2] - m[1][2] * m[2][1])
                - m[0][1] * (m[1][0] * m[2][2] - m[1][2] * m[2][0])
                + m[0][2] * (m[1][0] * m[2][1] - m[1][1] * m[2][0]);
            assert!((det - 1.0).abs() < 1e-12);
        }
    }
}
