//! slicer: layers and tool paths of the feature-based planner (issue "features plan").
//!
//! - [`params`]: a feature's layer parameters (the paper's process keys) with defaults,
//!   validation, per-feature patches and the layer thicknesses they give;
//! - [`fill`]: filling one planar layer by path mode (raster, zig-zag, contour,
//!   contour-zig-zag), with sparse infill in a pattern away from its solid skin
//!   ([`fill::sparse`]), and ordering the paths for print;
//! - [`feature_fill`]: a feature's layers filled by its planner before they are laid from where
//!   the nozzle is (the part of planning that features do in parallel);
//! - [`feature_plan`]: what a planner returns ([`FeaturePlan`] of [`Layer`]s of paths) and
//!   [`feature_plan::sequence`], which joins the features' plans into the tool path;
//! - [`freeform`]: curved layers of `freeform` features: offsets of the reference surface,
//!   spatial slicing, paths spaced by geodesic distance ([`geodesic`]);
//! - [`geom2d`]: points, regions, distances, areas and point-in-polygon tests of the plane;
//! - [`error`], [`figures`]: why a feature could not be planned, and the figures of one that
//!   was (both planners);
//! - private: `chart` (the chart of a reference surface), `fold` (offset folds), `region_fill`
//!   (one region of a curved or thin planar layer filled with beads of varying width, shared
//!   by both planners), `lift` (chart paths onto a curved layer), `feature_mesh`, `tolerance`,
//!   `skins` (the solid skins of planar layers, from their neighbours' sections);
//! - [`allowance`]: the machining allowance a plan leaves over a grown feature's nominal
//!   faces (its bead envelope measured);
//! - [`orient`]: tool-axis smoothing inside a tolerance cone;
//! - [`support`]: what holds each layer up (the overhang limit), from the features alone;
//! - [`support_material`]: columns of support under what the overhang limit leaves unheld;
//!   [`support_below`]: their layers below a lifted solid's first layer, down to the plate;
//! - [`skirt`]: skirt and brim loops around the first layer's footprint;
//! - [`planar`]: planar layers of `two5d` features, sections, fills and extrusion (Eq. 1);
//! - [`toolpath`]: the planned path (`toolpath.csv`) the posts consume (the `toolpath` crate,
//!   re-exported);
//! - [`vec3`]: arithmetic on the `[f64; 3]` positions and axes of planned points (from
//!   `toolpath`).
//!
//! Polygon offsets and booleans come from the `i_overlay` crate.
//!
//! Layers are made in parallel (rayon), one layer a job (`with_max_len(1)`): rayon's own
//! split leaves each of two cores a quarter of the layers to run in one piece, and a core
//! that finishes its quarter first finds nothing left to take (NIST CTC-05's feature 0: its
//! last second of fills on one core).

#![warn(missing_docs)]

pub mod allowance;
mod chart;
pub mod error;
mod fast_hash;
pub mod feature_fill;
mod feature_mesh;
pub mod feature_plan;
pub mod figures;
pub mod fill;
mod fold;
pub mod freeform;
pub mod geodesic;
pub mod geom2d;
mod lift;
pub mod orient;
pub mod params;
pub mod planar;
mod region_fill;
pub mod resolution;
mod skins;
pub mod skirt;
mod sst;
pub mod support;
pub mod support_below;
pub mod support_material;
mod tolerance;
mod top_field;
pub mod transition;
pub mod verify;

pub use toolpath;
pub use toolpath::vec3;

pub use feature_fill::{fill_feature, FeatureFill};
pub use feature_mesh::{Allowance, Grown};
pub use feature_plan::{sequence, FeaturePlan, Layer, LayerPath, LayerSurface};
pub use fill::{fill_layer, order_paths, regions_from_loops, Path2, PathKind, Point2, Region};
pub use params::{InfillPattern, LayerHeightPattern, LayerParams, LayerParamsPatch, PathMode};
