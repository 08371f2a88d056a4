//! What a planner returns for one feature: its [`Layer`]s of bead paths, the surface each lies
//! on and the feature's figures (as libslic3r's `Layer` → `ExtrusionEntity`). The points of a
//! feature are one arena ([`FeaturePlan::points`]) that its layers' paths index, so [`sequence`]
//! joins the features' plans into the one [`ToolPath`] the posts read without copying them.

use crate::figures::{FeatureFigures, FreeformFigures};
use crate::toolpath::{PathPoint, ToolPath};
use std::ops::Range;

/// The surface a layer's beads are laid on (their top, where the nozzle tip runs).
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum LayerSurface {
    /// A plane parallel to the feature's reference plane, `height` mm above it along `normal`.
    Plane {
        /// The reference plane's unit normal, into the feature.
        normal: [f64; 3],
        /// Height above the reference plane, mm.
        height: f64,
    },
    /// The feature's reference surface offset by `offset` mm along its unit normal (feature-based
    /// AM paper: offset surfaces `S_k(q) = S(q) + z_k·N(q)`).
    Offset {
        /// The offset `z_k`, mm.
        offset: f64,
    },
    /// A transition layer (Isa & Lazoglu 2019, Eq. 4): the morph `L = (1 − w)·B + w·T` of the
    /// feature's base B (its reference region) into its top T at level `w = n/N`, each point
    /// `w·h_T(q)` from the reference along its normal.
    Blend {
        /// The morph level `n/N`, in (0, 1].
        level: f64,
    },
}

/// One bead path of a layer, as ranges of its feature's [`FeaturePlan::points`]: the travel
/// that reaches its start, then the beads it lays.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct LayerPath {
    /// Travel points, the last one the path's start.
    pub travel: Range<usize>,
    /// Print points: each lays a bead from the point before it.
    pub print: Range<usize>,
}

/// One layer of a feature that prints.
#[derive(Debug, Clone, PartialEq)]
pub struct Layer {
    /// Index of the layer in its feature, from 0 at the reference (layers that print nothing
    /// leave gaps in the numbering).
    pub index: usize,
    /// Thickness `Δl`, mm.
    pub thickness: f64,
    /// Where its beads are laid.
    pub surface: LayerSurface,
    /// Its paths in print order.
    pub paths: Vec<LayerPath>,
}

/// The plan of one feature: its points, its layers in print order and its figures.
#[derive(Debug, Clone)]
pub struct FeaturePlan {
    /// The feature's index in its tree.
    pub feature: usize,
    /// Every point of the plan in print order; the layers' paths are ranges of it.
    pub points: Vec<PathPoint>,
    /// The layers that print, bottom up.
    pub layers: Vec<Layer>,
    /// Lengths, filament, layer thicknesses, warnings.
    pub figures: FeatureFigures,
    /// The freeform planner's figures (curved features).
    pub freeform: Option<FreeformFigures>,
}

impl FeaturePlan {
    /// Where the nozzle is when the feature is done: its last point, if it has any.
    pub fn exit(&self) -> Option<[f64; 3]> {
        self.points.last().map(|q| q.p)
    }

    /// The travel and print points of one path of a layer.
    pub fn path_points(&self, path: &LayerPath) -> (&[PathPoint], &[PathPoint]) {
        (
            &self.points[path.travel.clone()],
            &self.points[path.print.clone()],
        )
    }
}

/// The tool path of a part: the features' points one plan after the other, each point tagged
/// with its feature's file-wide id (the `usize` beside its plan). The travel into each feature
/// is already in its plan (planned from the previous plan's [`FeaturePlan::exit`]).
pub fn sequence(plans: Vec<(usize, FeaturePlan)>) -> ToolPath {
    let mut points: Vec<PathPoint> = vec![];
    let total: usize = plans.iter().map(|(_, p)| p.points.len()).sum();
    for (id, plan) in plans {
        let mut own = plan.points;
        for q in &mut own {
            q.feature = id as u32;
        }
        // The first plan's points become the path's (no copy); the others are appended.
        if points.is_empty() {
            points = own;
            // Room for the rest once; none to spare (a plan's points grew by doubling).
            points.reserve_exact(total - points.len());
        } else {
            points.append(&mut own);
        }
    }
    points.shrink_to_fit();
    ToolPath { points }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::toolpath::MoveKind;

    fn point(kind: MoveKind, x: f64) -> PathPoint {
        PathPoint {
            feature: 0,
            layer: 0,
            kind,
            p: [x, 0.0, 0.0],
            axis: [0.0, 0.0, 1.0],
            e: 0.0,
            thickness: 0.2,
            width: 0.45,
            role: crate::toolpath::Role::Perimeter,
        }
    }

    fn plan(xs: &[f64]) -> FeaturePlan {
        let mut points = vec![point(MoveKind::Travel, xs[0])];
        points.extend(xs[1..].iter().map(|&x| point(MoveKind::Print, x)));
        FeaturePlan {
            feature: 0,
            layers: vec![Layer {
                index: 0,
                thickness: 0.2,
                surface: LayerSurface::Offset { offset: 0.2 },
                paths: vec![LayerPath {
                    travel: 0..1,
                    print: 1..xs.len(),
                }],
            }],
            points,
            figures: FeatureFigures::default(),
            freeform: None,
        }
    }

    #[test]
    fn sequencing_keeps_every_point_in_order_under_its_file_wide_id() {
        let a = plan(&[0.0, 1.0, 2.0]);
        let b = plan(&[5.0, 6.0]);
        assert_eq!(a.exit(), Some([2.0, 0.0, 0.0]));
        let (travel, print) = a.path_points(&a.layers[0].paths[0]);
        assert_eq!((travel.len(), print.len()), (1, 2));
        let path = sequence(vec![(3, a), (7, b)]);
        let xs: Vec<f64> = path.points.iter().map(|q| q.p[0]).collect();
        assert_eq!(xs, [0.0, 1.0, 2.0, 5.0, 6.0]);
        let ids: Vec<usize> = path.points.iter().map(|q| q.feature as usize).collect();
        assert_eq!(ids, [3, 3, 3, 7, 7]);
        assert_eq!(path.points[3].kind, MoveKind::Travel);
    }
}
