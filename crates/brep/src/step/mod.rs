//! STEP I/O: the Part 21 parser ([`p21`]), the translation of its entities into our B-rep
//! ([`read`]), reading a file into a [`StepPart`] ([`read_step`]) and writing solids back
//! ([`mod@write`]).

pub mod error;
pub mod p21;
pub mod read;
pub mod write;

mod part;

pub use part::{read_step, read_step_bytes, read_step_turned, turn_down, StepFile, StepPart};
pub use read::translate;
