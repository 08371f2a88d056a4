//! Writing solids of our B-rep back to a STEP AP214 file (ISO 10303-21, millimetres, radians).
//!
//! The file holds exact geometry and topology only: one product whose
//! `ADVANCED_BREP_SHAPE_REPRESENTATION` lists the solids. Every surface and curve keeps its
//! natural parametrisation, so the faces' `same_sense` and the edges' directions mean the same
//! thing after a round trip, and [`crate::read_step_bytes`] reads back the B-rep that was written
//! (same faces, loops, coedges, edges and vertices, in the same order). No `PCURVE`s are written;
//! OpenCASCADE computes them when it reads the file.
//!
//! Void shells follow the reader's convention: a void face's `same_sense` already includes the
//! reversal of its shell, and its loops are those of the un-reversed shell. They are written as
//! `ORIENTED_CLOSED_SHELL(.F.)` around a `CLOSED_SHELL` whose faces carry the opposite
//! `same_sense`, which is how OpenCASCADE writes voids and what the reader undoes.
//!
//! ```no_run
//! let part = brep::read_step("part.step").unwrap();
//! let solids: Vec<_> = part.brep.solid_ids().collect();
//! std::fs::write("copy.step", brep::write::write_step(&part.brep, &solids, "copy")).unwrap();
//! ```

mod file;
mod geometry;
mod text;
mod topology;
mod writer;

pub use file::{write_step, write_step_shells};
pub use text::{real, string};

#[cfg(test)]
mod tests;
