//! Planar layers for `two5d` features (feature-based AM paper: "the slicing plane is parallel
//! to the reference plane, ... the tool direction is vertical to them").
//!
//! Each feature is cut at the middle of every layer by a plane parallel to its reference plane;
//! the cross-section's loops are grouped into regions and filled by the feature's path mode; the
//! paths are lifted to the layer's top (where the nozzle runs) with the reference normal as the
//! tool axis, and each segment gets its filament length from Eq. 1.

use crate::feature_mesh::{feature_mesh, slicing_tolerance};
use crate::fill::{fill_layer, order_greedy, regions_from_loops, thinner_than, Region};
use crate::params::{LayerParams, PathMode};
use crate::region_fill::{fill_flat_region, solid_on_skins, Boundary, FillPath};
use crate::toolpath::{MoveKind, PathPoint};
use brep::math::{P3, V3};
use brep::mesh::{mesh_faces, MeshOptions};
use brep::section::{section, Plane};
use features::{Feature, FeatureKind, FeatureTree};
use rayon::prelude::*;

pub use crate::error::PlanError;
use crate::feature_plan::{FeaturePlan, Layer, LayerPath, LayerSurface};
pub use crate::figures::FeatureFigures;
pub use toolpath::Bead;

/// The reference plane of a two5d feature: through its healing faces (or build-plate face),
/// normal pointing into the feature.
pub fn reference_plane(tree: &FeatureTree, f: &Feature) -> Option<Plane> {
    let n = f.reference.normal.map(|n| V3::new(n[0], n[1], n[2]))?;
    let b = &tree.brep;
    // A point of the reference: a vertex of the reference face; else the feature's lowest
    // point, on its surfaces (a torus or a cylinder lying on its side is lowest between its
    // vertices, which may all lie at its middle height).
    let face = f.heal_faces.first().copied().or(f.reference.face);
    let p = match face {
        Some(fc) => b
            .vertices_of(&[fc])
            .first()
            .map(|v| b.vertices[v.idx()].point),
        None => {
            let mut pts = surface_points(tree, f);
            if pts.is_empty() {
                pts = b
                    .vertices_of(&f.faces)
                    .iter()
                    .map(|v| b.vertices[v.idx()].point)
                    .collect();
            }
            pts.into_iter()
                .min_by(|a, c| a.coords.dot(&n).total_cmp(&c.coords.dot(&n)))
        }
    }?;
    Some(Plane::new(p, n))
}

/// Chord tolerance (mm) of the mesh that finds how low a feature reaches.
const EXTREME_TOL: f64 = 0.01;

/// Points of a feature's faces, on their exact surfaces, no farther apart than a chord
/// tolerance of [`EXTREME_TOL`] allows: where a curved face reaches lowest between its
/// vertices, one of them lies within that of the lowest point. Empty if the faces do not
/// mesh.
fn surface_points(tree: &FeatureTree, f: &Feature) -> Vec<P3> {
    mesh_faces(
        &tree.brep,
        &f.faces,
        &MeshOptions::with_tolerance(EXTREME_TOL),
    )
    .map(|m| m.positions)
    .unwrap_or_default()
}

/// How far (mm) `points` (a feature's mesh) reach below the build plate of `tree` (its base
/// feature's reference plane): 0 when they do not, or when the tree has no plate.
pub(crate) fn below_plate(tree: &FeatureTree, points: &[P3]) -> f64 {
    let Some(plate) = tree.features.first().and_then(|b| reference_plane(tree, b)) else {
        return 0.0;
    };
    points
        .iter()
        .map(|p| -plate.height(p))
        .fold(0.0f64, f64::max)
}

/// How deep (mm) a planar region must reach inside its boundary to be filled by offsets of
/// one bead width (`fill::fill_layer`): room for the first ring's half bead, the perimeters
/// (at least one) and one more spacing for the infill or the next ring. Thinner regions get
/// `freeform::fill_flat_region`.
fn thin_depth(params: &LayerParams, width: f64, spacing: f64) -> f64 {
    0.5 * width + (params.perimeters.max(1) as f64) * spacing
}

/// The paths of a planar layer's regions, for layer number `layer`, beads `width` wide and
/// `spacing` apart: `fill::fill_layer` where offsets of one bead width fit, and beads as wide
/// as the region there (`freeform::fill_flat_region`) for regions too thin for those rings
/// and infill, where they would overlap or drop beads, and for the strips the rings of the
/// others leave (thin parts, the middle between rings). Raster and zig-zag lines run
/// boundary to boundary whatever the width: only the modes with rings need this.
pub fn fill_regions(
    regions: Vec<Region>,
    params: &LayerParams,
    layer: usize,
    width: f64,
    spacing: f64,
) -> Vec<FillPath> {
    let rings = matches!(
        params.path_mode,
        PathMode::Contour | PathMode::ContourZigzag
    );
    let (thin, thick): (Vec<Region>, Vec<Region>) = regions
        .into_iter()
        .partition(|r| rings && thinner_than(r, thin_depth(params, width, spacing)));
    let filled = fill_layer(&thick, params, layer, width, spacing);
    let mut paths: Vec<FillPath> = filled
        .paths
        .into_iter()
        .map(|p| FillPath::uniform(p.points, width, p.role))
        .collect();
    for r in &thin {
        paths.extend(fill_flat_region(
            r,
            params,
            layer,
            width,
            spacing,
            Boundary::Part,
        ));
    }
    for r in &filled.gaps {
        paths.extend(fill_flat_region(
            r,
            params,
            layer,
            width,
            spacing,
            Boundary::Beads,
        ));
    }
    paths
}

/// Plans one two5d feature in planar layers parallel to its reference plane; its first travel
/// starts at `entry` (where the nozzle is, if anywhere): [`fill_two5d`], then
/// [`Two5dFill::lay`].
pub fn plan_two5d(
    tree: &FeatureTree,
    f: &Feature,
    params: &LayerParams,
    bead: Bead,
    entry: Option<P3>,
) -> Result<FeaturePlan, PlanError> {
    Ok(fill_two5d(tree, f, params, bead)?.lay(entry))
}

/// A two5d feature's layers sectioned and filled in their planes, before they are ordered
/// from where the nozzle is and joined by travel (see [`crate::freeform::FreeformFill`]).
pub struct Two5dFill {
    id: usize,
    plane: Plane,
    bead: Bead,
    /// Each layer's middle and top height and thickness.
    tops: Vec<(f64, f64, f64)>,
    /// Each layer's fill paths in its plane.
    filled: Vec<Vec<FillPath>>,
    fig: FeatureFigures,
}

/// Sections and fills every layer of a two5d feature (in parallel).
pub fn fill_two5d(
    tree: &FeatureTree,
    f: &Feature,
    params: &LayerParams,
    bead: Bead,
) -> Result<Two5dFill, PlanError> {
    if f.kind != FeatureKind::Two5d {
        return Err(PlanError::NotTwo5d(f.id));
    }
    params
        .validate()
        .map_err(|msg| PlanError::Params { id: f.id, msg })?;
    let plane = reference_plane(tree, f).ok_or(PlanError::NoPlane(f.id))?;
    let mesh = feature_mesh(tree, f, slicing_tolerance(params))?;
    let top = mesh
        .positions
        .iter()
        .map(|p| plane.height(p))
        .fold(0.0f64, f64::max);
    let heights = params.layer_heights(top);
    let spacing = params.spacing(bead.width);
    let fig = FeatureFigures {
        below_plate: below_plate(tree, &mesh.positions),
        ..FeatureFigures::default()
    };
    // Each layer's section and fill depend on that layer alone: computed in parallel, then
    // ordered and joined by travel one layer after the other.
    let mut tops = Vec::with_capacity(heights.len());
    let mut z = 0.0;
    for &dl in &heights {
        tops.push((z + 0.5 * dl, z + dl, dl));
        z += dl;
    }
    let filled: Vec<Vec<FillPath>> = tops
        .par_iter()
        .enumerate()
        .map(|(layer, &(mid, _, _))| {
            let cut = plane.offset(mid);
            let loops: Vec<Vec<[f64; 2]>> = section(&mesh, &cut)
                .iter()
                .map(|l| l.iter().map(|p| cut.to_2d(p)).collect())
                .collect();
            let regions = regions_from_loops(&loops);
            let paths = fill_regions(regions, params, layer, bead.width, spacing);
            solid_on_skins(paths, layer, heights.len())
        })
        .collect();
    Ok(Two5dFill {
        id: f.id,
        plane,
        bead,
        tops,
        filled,
        fig,
    })
}

impl Two5dFill {
    /// Orders each layer's paths from where the nozzle is (starting at `entry`) and joins them
    /// by travel.
    pub fn lay(self, entry: Option<P3>) -> FeaturePlan {
        let Two5dFill {
            id,
            plane,
            bead,
            tops,
            filled,
            mut fig,
        } = self;
        let mut cursor = entry;
        let axis = [plane.normal.x, plane.normal.y, plane.normal.z];
        let mut layers = vec![];
        let mut points: Vec<PathPoint> = vec![];
        for (layer, (paths, &(_, z, dl))) in filled.into_iter().zip(&tops).enumerate() {
            let start = cursor.map(|c| plane.to_2d(&c)).unwrap_or([0.0, 0.0]);
            let paths = order_greedy(paths, start, |p| &p.points, FillPath::reverse);
            if paths.is_empty() {
                continue;
            }
            let mut layer_paths = Vec::with_capacity(paths.len());
            for path in paths {
                let pts: Vec<P3> = path.points.iter().map(|q| plane.to_3d(*q, z)).collect();
                let Some(first) = pts.first() else { continue };
                // Travel to the start of the path.
                if let Some(c) = cursor {
                    fig.travel_length += (first - c).norm();
                }
                let start = points.len();
                points.push(PathPoint {
                    feature: id,
                    layer,
                    kind: MoveKind::Travel,
                    p: [first.x, first.y, first.z],
                    axis,
                    e: 0.0,
                    thickness: dl,
                    width: path.widths[0],
                    role: path.role,
                });
                for (i, w) in pts.windows(2).enumerate() {
                    let l = (w[1] - w[0]).norm();
                    // Eq. 1 with the bead's width along the segment.
                    let width = 0.5 * (path.widths[i] + path.widths[i + 1]);
                    let e = bead.filament_length(width, dl, l);
                    fig.print_length += l;
                    fig.filament += e;
                    points.push(PathPoint {
                        feature: id,
                        layer,
                        kind: MoveKind::Print,
                        p: [w[1].x, w[1].y, w[1].z],
                        axis,
                        e,
                        thickness: dl,
                        width: path.widths[i + 1],
                        role: path.role,
                    });
                }
                cursor = pts.last().copied();
                layer_paths.push(LayerPath {
                    travel: start..start + 1,
                    print: start + 1..points.len(),
                });
            }
            layers.push(Layer {
                index: layer,
                thickness: dl,
                surface: LayerSurface::Plane {
                    normal: axis,
                    height: z,
                },
                paths: layer_paths,
            });
        }
        let printed: Vec<f64> = layers.iter().map(|l: &Layer| l.thickness).collect();
        fig.finish(id, points.len(), &printed);
        FeaturePlan {
            feature: id,
            points,
            layers,
            figures: fig,
            freeform: None,
        }
    }
}
