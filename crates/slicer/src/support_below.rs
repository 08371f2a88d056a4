//! Support below a lifted solid's first layer (issue 31 item 1, issue 33 item 3): the base
//! feature of a solid modelled above the plate rests on the solids built before it where
//! they lie under it, and on support material elsewhere. Its columns go on below its first
//! layer, down to the plate, in layers of its own heights laid before its first layer.
//!
//! - **The layers** fill the gap between the plate and the feature's reference plane:
//!   `support_contact_distance` at the top in layers of its own ([`heights`]), so that a column
//!   under the first layer enters right below the contact gap, the rest below it; both cut in
//!   `uniform_layer_height` layers (or the adaptive list) like the feature's own.
//! - **What other solids occupy** in each layer is their section at the layer's middle
//!   ([`Below::sections`]): a column over one lands on it and stops, and what is printed of a
//!   column keeps `support_xy_distance` from it ([`crate::support_material`]).
//! - **A gap thinner than the contact gap and a layer**: when less than
//!   `support_contact_distance` plus `min_layer_height` separates the plate from the
//!   feature's first layer, that layer is held by the plate as by a column's top (the same
//!   gap support leaves under a held surface): no column is built under it.

use crate::error::FeatureError;
use crate::feature_mesh::{feature_mesh, layer_tops, Allowance};
use crate::fill::{union, Region};
use crate::params::LayerParams;
use crate::tolerance::HEIGHT_SLACK;
use brep::section::Plane;
use features::{Feature, FeatureTree};
use rayon::prelude::*;

/// How far (each unit component) a feature's reference plane normal may lean from +Z and its
/// support still be built below it down to the plate.
pub const PLANE_TILT: f64 = 1e-6;

/// The layers between the plate and a lifted feature's reference plane, bottom up.
#[derive(Debug, Clone, Default)]
pub struct Below {
    /// Each layer's thickness, mm; they add up to the gap.
    pub heights: Vec<f64>,
    /// What the solids built before occupy in each layer: their sections at its middle, in
    /// the reference plane's 2-D frame.
    pub sections: Vec<Vec<Region>>,
}

/// The thicknesses (bottom up) of the support layers under a feature whose reference plane
/// stands `gap` mm over the plate: the top `support_contact_distance` in layers of its own,
/// the rest below; the whole gap as one stack when what is left under the contact gap is
/// thinner than `min_layer_height`. Empty when the gap is not positive or the layer heights
/// do not fill it.
pub fn heights(gap: f64, params: &LayerParams) -> Vec<f64> {
    if !(gap.is_finite() && gap > HEIGHT_SLACK) {
        return vec![];
    }
    let contact = params.support_contact_distance.max(0.0);
    let lower = gap - contact;
    let mut out = match lower >= params.min_layer_height {
        true => {
            let mut h = params.layer_heights(lower);
            if contact > HEIGHT_SLACK {
                h.extend(params.layer_heights(contact));
            }
            h
        }
        false => params.layer_heights(gap),
    };
    let sum: f64 = out.iter().sum();
    if (sum - gap).abs() > HEIGHT_SLACK.max(gap * HEIGHT_SLACK) * out.len().max(1) as f64 {
        out.clear();
    }
    out
}

/// The layers below `plane` down to the plate `gap` mm under it ([`heights`]), with what the
/// solids built before (`earlier`) occupy in each, their meshes at chord tolerance `tol`.
/// Empty when the plane does not face +Z (within [`PLANE_TILT`]): the plate is then not
/// parallel to the layers.
pub fn below(
    plane: &Plane,
    gap: f64,
    earlier: &[(&FeatureTree, &Feature)],
    params: &LayerParams,
    tol: f64,
) -> Result<Below, FeatureError> {
    let n = plane.normal;
    if n.x.abs() > PLANE_TILT || n.y.abs() > PLANE_TILT || n.z < 1.0 - PLANE_TILT {
        return Ok(Below::default());
    }
    let heights = heights(gap, params);
    if heights.is_empty() {
        return Ok(Below::default());
    }
    let meshes = earlier
        .iter()
        // Grown by this solid's allowance (each solid's own is not known here).
        .map(|(t, g)| feature_mesh(t, g, tol, Allowance::of_parent_solid(params)))
        .collect::<Result<Vec<_>, _>>()?;
    // Each layer's middle over the plane (negative: below it).
    let mids: Vec<f64> = layer_tops(-gap, &heights).iter().map(|l| l.0).collect();
    let sections = mids
        .par_iter()
        .with_max_len(1)
        .map(|&mid| {
            let cut = plane.offset(mid);
            let mut regions = vec![];
            for m in &meshes {
                regions.extend(crate::planar::section_regions(m, &cut, plane));
            }
            union(&regions, &[])
        })
        .collect();
    Ok(Below { heights, sections })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_gap_is_cut_in_layers_with_the_contact_gap_on_top() {
        let p = LayerParams::default();
        let h = heights(5.0, &p);
        assert!((h.iter().sum::<f64>() - 5.0).abs() < 1e-9);
        assert!(h.iter().all(|x| *x <= p.uniform_layer_height + 1e-9));
        // The top layers make up the contact distance exactly.
        let top: f64 = h[h.len() - 1];
        assert!((top - p.support_contact_distance).abs() < 1e-9, "{h:?}");
        // Thinner than the contact gap and a layer: one stack.
        let h = heights(0.25, &p);
        assert!((h.iter().sum::<f64>() - 0.25).abs() < 1e-9, "{h:?}");
        assert!(heights(0.0, &p).is_empty() && heights(f64::NAN, &p).is_empty());
    }
}
