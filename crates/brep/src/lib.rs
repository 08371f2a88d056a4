//! `brep`: a STEP solid read into an exact boundary representation that later stages can trust
//! for adjacency, normals, point projection, meshing and mass properties.
//!
//! ```no_run
//! let part = brep::read_step("part.step").expect("readable");
//! for s in part.brep.solid_ids() {
//!     let mesh = brep::mesh::mesh_faces(&part.brep, &part.brep.solid_faces(s), &Default::default()).unwrap();
//!     let props = brep::mass::mass_properties(&part.brep, &mesh);
//!     println!("{} mm³", props.volume);
//! }
//! ```
#![warn(missing_docs)]
// Numerical kernels (basis functions, grids) index several arrays in lockstep; index loops
// read more plainly there than zipped iterators.
#![allow(clippy::needless_range_loop)]

pub mod bbox;
pub mod curve;
pub mod faceted;
pub mod mass;
pub mod math;
pub mod mesh;
pub mod nurbs;
pub mod orient;
pub mod section;
pub mod solid;
pub mod source;
pub mod step;
pub mod subset;
pub mod surface;
pub mod tolerance;
pub mod topology;
pub mod validate;

// The STEP modules' former paths (`brep::p21`, `brep::write`, `brep::error`).
pub use step::{error, p21, write};

pub use error::ReadError;
pub use faceted::FacetedFile;
pub use solid::SolidReport;
pub use source::{read_part, PartFile};
pub use step::{read_step, read_step_bytes, read_step_turned, turn_down, StepFile, StepPart};
pub use topology::Brep;
