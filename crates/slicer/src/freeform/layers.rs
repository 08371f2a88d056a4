//! A freeform feature's layers filled over its stack: the sections cut, the skins found along
//! the stack with sparse infill (issue 33), each layer's regions filled in the chart.

use super::clip_paths;
use crate::chart::Chart;
use crate::fill::regions_from_loops;
use crate::geom2d::{Point2, Region, RegionIndex};
use crate::params::LayerParams;
use crate::region_fill::sparse::{CurvedSparse, SparseVolume};
use crate::region_fill::{corner_spurs_beside, fill_region_with, FillPath, SLIVER_INSET};
use crate::tolerance::{HEIGHT_SLACK, MICROMETRE};
use crate::transition::TopField;
use brep::mesh::Mesh;
use brep::section::{section, Plane};
use rayon::prelude::*;

/// Every layer's regions and fill paths over the feature's stack, and the volume they lay
/// sparse: the sections cut first (the base `chart` and `mapped` mesh, or from
/// `offset_layers` on the `blended` chart and mesh of transition layers), then with sparse
/// infill each layer's skin found from them along the stack (issue 33, `crate::skins`), then
/// each layer filled (in parallel) at its top level `tops[layer].1`.
pub(super) fn fill_stack(
    (chart, mapped): (&Chart, &Mesh),
    blended: Option<&(Chart, Mesh, &TopField)>,
    blend: Option<&(TopField, usize, usize)>,
    (tops, heights, offset_layers): (&[(f64, f64)], &[f64], usize),
    up: &Plane,
    params: &LayerParams,
    (bead_width, spacing): (f64, f64),
) -> (Vec<LayerFill>, SparseVolume) {
    // Each layer's regions: the section of its mesh at its middle.
    let sections: Vec<Vec<Region>> = tops
        .par_iter()
        .enumerate()
        .with_max_len(1)
        .map(|(layer, &(mid, _))| {
            let mesh = match blended {
                Some((_, m, _)) if layer >= offset_layers => m,
                _ => mapped,
            };
            layer_regions(mesh, up, mid)
        })
        .collect();
    // Sparse infill (issue 33): each layer's skin along the stack, as on planar layers.
    let n = sections.len();
    let skins = params.sparse_infill().then(|| {
        let (top, bottom) = (params.top_solid_layers, params.bottom_solid_layers);
        let same = vec![false; n];
        crate::skins::skins(&sections, &same, top, bottom, bead_width, params.tolerance)
    });
    // Each layer's middle along the stack, mm (the gyroid's height).
    let along: Vec<f64> = heights
        .iter()
        .scan(0.0, |z, &dl| {
            *z += dl;
            Some(*z - 0.5 * dl)
        })
        .collect();
    let filled: Vec<(LayerFill, SparseVolume)> = sections
        .into_par_iter()
        .enumerate()
        .with_max_len(1)
        .map(|(layer, regions)| {
            let (chart, clip) = match blended {
                Some((c, _, _)) if layer >= offset_layers => (c, None),
                // Offset layers under a transition band: only where the band stays above.
                Some((_, _, field)) => (chart, Some((*field, tops[layer].1))),
                None => (chart, None),
            };
            let dl = heights[layer];
            let thickness = |q: Point2| match (blend, clip) {
                (Some((field, k, _)), None) if layer >= offset_layers => {
                    field.layer_thickness(q, *k as f64)
                }
                (_, Some((field, z))) if !under_band(field, z, q) => 0.0,
                _ => dl,
            };
            // Within the solid layers of the first or the last layer: all skin.
            let all = layer < params.bottom_solid_layers || layer + params.top_solid_layers >= n;
            let index: Option<Vec<RegionIndex>> = skins.as_ref().map(|s| match all {
                true => vec![],
                false => s[layer].iter().map(RegionIndex::new).collect(),
            });
            let sparse = index.as_ref().map(|i| CurvedSparse {
                skin: (!all).then_some(i.as_slice()),
                thickness: &thickness,
                height: along[layer],
            });
            let at = (layer, n, tops[layer].1);
            fill_layer(
                chart,
                regions,
                clip,
                at,
                params,
                (bead_width, spacing),
                sparse.as_ref(),
            )
        })
        .collect();
    let mut sparse_total = SparseVolume::default();
    let filled: Vec<LayerFill> = filled
        .into_iter()
        .map(|(f, v)| {
            sparse_total += v;
            f
        })
        .collect();
    (filled, sparse_total)
}

/// One layer's regions and fill paths in the chart.
pub(super) type LayerFill = (Vec<Region>, Vec<FillPath>);

/// One layer's regions: the section of its mapped mesh at `mid`.
fn layer_regions(mapped: &Mesh, up: &Plane, mid: f64) -> Vec<Region> {
    let loops: Vec<Vec<Point2>> = section(mapped, &up.offset(mid))
        .iter()
        .map(|l| l.iter().map(|p| [p.x, p.y]).collect())
        .collect();
    regions_from_loops(&loops)
}

/// One layer's fill paths at offset `z` (`at`: the layer, the number of layers and `z`) over
/// its `regions`, clipped to where the transition band `clip` stays above, skins made solid;
/// with `sparse`, its sparse infill and the volume laid sparse.
fn fill_layer(
    chart: &Chart,
    regions: Vec<Region>,
    clip: Option<(&TopField, f64)>,
    (layer, layers, z): (usize, usize, f64),
    params: &LayerParams,
    (bead_width, spacing): (f64, f64),
    sparse: Option<&CurvedSparse>,
) -> (LayerFill, SparseVolume) {
    let spacing = params
        .spacing_for_layer(bead_width, layer)
        .max(MICROMETRE)
        .min(spacing.max(MICROMETRE) * 1e3);
    let mut paths = vec![];
    let mut volume = SparseVolume::default();
    for r in &regions {
        let (fill, v) = fill_region_with(
            chart,
            r,
            z,
            params,
            (layer, bead_width, spacing, SLIVER_INSET * bead_width),
            sparse,
        );
        volume += v;
        let spurs = corner_spurs_beside(chart, r, z, bead_width, &fill);
        paths.extend(fill);
        paths.extend(spurs);
    }
    if let Some((field, z)) = clip {
        paths = clip_paths(paths, |q| under_band(field, z, q));
    }
    (
        (
            regions,
            crate::region_fill::solid_on_skins(paths, layer, layers),
        ),
        volume,
    )
}

/// Whether an offset layer topped at `z` is laid over chart point `q` under a transition band
/// (`field`): where the band starts at or above it.
fn under_band(field: &TopField, z: f64, q: Point2) -> bool {
    field.lower(q) >= z - HEIGHT_SLACK
}
