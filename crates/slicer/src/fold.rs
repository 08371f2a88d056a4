//! Offset deterioration (feature-based AM paper, Fig. 9): where the reference surface is
//! concave with a radius of curvature under a layer's offset, the offset folds over itself.

use crate::chart::{root, Chart, ChartKind};
use crate::error::FeatureError;
use crate::params::LayerParams;
use crate::tolerance::{DEGENERATE_LENGTH, FLAT_CURVATURE, MICROMETRE};

use brep::mesh::Mesh;
use brep::surface::Surface;

/// Offset deterioration (paper, Fig. 9) judged from the feature's root: the smallest principal
/// curvature of the reference where the feature stands on it, against the feature's height
/// along the normal there. `Err(OffsetFolds)` names the first layer whose offset reaches the
/// radius of a concave valley.
pub(crate) fn fold_check(
    surf: &Surface,
    sign: f64,
    mesh: &Mesh,
    tol: f64,
    params: &LayerParams,
    id: usize,
) -> Result<(), FeatureError> {
    // The root: mesh vertices on the reference surface.
    let Some((roots, (u0, v0))) = root(surf, mesh, tol) else {
        return Ok(());
    };
    let (su, sv) = surf.derivs(u0, v0);
    let Some(n0) = surf.normal(u0, v0).map(|n| n * sign) else {
        return Ok(());
    };
    if su.norm() < DEGENERATE_LENGTH || sv.norm() < DEGENERATE_LENGTH {
        return Ok(());
    }
    let flip = if su.cross(&sv).dot(&n0) < 0.0 {
        -1.0
    } else {
        1.0
    };
    let (su, sv) = (su.norm() * flip, sv.norm());
    let chart = Chart {
        surf,
        sign,
        blend: None,
        along: None,
        kind: ChartKind::Native { u0, v0, su, sv },
    };
    let f0 = surf.eval(u0, v0);
    let height = mesh
        .positions
        .iter()
        .map(|p| (p - f0).dot(&n0))
        .fold(0.0f64, f64::max);
    let step = (0.5 * params.uniform_layer_height).max(MICROMETRE);
    let mut lambda = 0.0f64;
    for r in roots.iter().step_by((roots.len() / 300).max(1)) {
        let (u, v) = surf.unwrap_near((r.0, r.1), (u0, v0));
        if let Some(l) = chart.min_curvature([(u - u0) * su, (v - v0) * sv], step) {
            lambda = lambda.min(l);
        }
    }
    if lambda < -FLAT_CURVATURE {
        check_folds(id, &params.layer_heights(height), -1.0 / lambda)?;
    }
    Ok(())
}

/// `Err(OffsetFolds)` at the first of the layers (thicknesses `heights`) whose top reaches
/// `radius`, the radius of a concave valley of the reference (infinite: none).
pub(crate) fn check_folds(id: usize, heights: &[f64], radius: f64) -> Result<(), FeatureError> {
    let mut z = 0.0;
    for (layer, dl) in heights.iter().enumerate() {
        z += dl;
        if z >= radius {
            return Err(FeatureError::OffsetFolds {
                id,
                layer: layer + 1,
                offset: z,
                radius,
            });
        }
    }
    Ok(())
}
