//! Geodesic distances on a curved layer, and the iso-lines of those distances.
//!
//! The feature-based AM paper asks that on a curved layer "the distance between the parallel
//! toolpaths should be geodesic distance, namely geodesic offset on the surface". A layer's
//! region, given in a 2-D chart of its surface, is triangulated ([`LayerMesh::build`]); each
//! vertex is then placed on the layer surface in 3-D, and distances are marched over the
//! triangles in 3-D ([`LayerMesh::march`], the fast marching method of Kimmel & Sethian 1998
//! with the planar-wavefront triangle update). That update is only right on acute triangles,
//! so the lattice is laid equilateral on the surface, not in the chart
//! ([`LayerMesh::build_with_metric`]), and refined around convex corners of the boundary;
//! near the boundary the distances are exact seeds ([`LayerMesh::boundary_seeds`]) that the
//! front never lowers. Paths are the iso-lines of such distance fields
//! ([`LayerMesh::iso_lines`]): contour rings are iso-lines of the distance to the region's
//! boundary; raster and zig-zag lines are iso-lines of the signed distance to a seed curve, so
//! neighbouring lines are one spacing apart measured on the surface, not in the chart.

mod field;
mod iso;
mod mesh;
mod ray;
#[cfg(test)]
mod tests;

pub use crate::geom2d::region_contains;
pub(crate) use field::segment_distance;
pub use field::Reach;
pub use iso::{clip_reaching, Piece, RunOn};
pub use mesh::{IsoLine, LayerMesh};
pub use ray::RayTop;
