//! Where a two5d feature is narrower than a nozzle lays (issue 31, item 4): its layers'
//! sections, each region's full width (twice the depth of its deepest point), and the share of
//! the feature in regions narrower than a given width (a contact 0.3 mm wide, a pin thinner
//! than a bead). The beads of a fill do not tell this: the gap fill of the strip between a
//! wall's rings is a loop of beads half the strip wide, however wide the wall.

use crate::error::FeatureError;
use crate::fill::{thinner_than, Region};
use crate::geom2d::area2;
use crate::params::LayerParams;
use crate::planar::{reference_plane, PlanarMesh};
use features::{Feature, FeatureKind, FeatureTree};
use rayon::prelude::*;

/// Bisection steps of a region's width: the width to within `limit / 2^STEPS`.
const WIDTH_STEPS: usize = 10;

/// A feature's sections narrower than a width.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct NarrowSections {
    /// The narrowest full width of a region of its sections, mm.
    pub narrowest: f64,
    /// The share of the feature's volume (sections × layer thickness) in regions narrower
    /// than the width asked about.
    pub share: f64,
}

/// The regions of a two5d feature's layer sections (the layers `params` makes, each cut at
/// its middle) narrower than `limit` mm, their narrowest width and share of the feature;
/// `None` when no region is narrower or the feature is not two5d (curved layers' slivers at a
/// blade's edge are cut-offs, not a narrow feature).
/// `meshed`: the feature's planar mesh made already (`None`: made here).
pub fn narrow_sections(
    tree: &FeatureTree,
    f: &Feature,
    params: &LayerParams,
    limit: f64,
    meshed: Option<&PlanarMesh>,
) -> Result<Option<NarrowSections>, FeatureError> {
    if f.kind != FeatureKind::Two5d || limit.is_nan() || limit <= 0.0 {
        return Ok(None);
    }
    if reference_plane(tree, f).is_none() {
        return Ok(None);
    }
    let pm = PlanarMesh::given_or_of(meshed, tree, f, params)?;
    let PlanarMesh {
        plane,
        mesh,
        layers,
        ..
    } = pm.as_ref();
    let mids: Vec<(f64, f64)> = layers.iter().map(|&(mid, _, dl)| (mid, dl)).collect();
    // Per layer: (all volume, narrow volume, narrowest width).
    let layers: Vec<(f64, f64, f64)> = mids
        .par_iter()
        .with_max_len(1)
        .map(|&(mid, dl)| {
            let cut = plane.offset(mid);
            let mut out = (0.0, 0.0, f64::INFINITY);
            for r in crate::planar::section_regions(mesh, &cut, &cut) {
                let v = region_area(&r) * dl;
                out.0 += v;
                if thinner_than(&r, 0.5 * limit) {
                    out.1 += v;
                    out.2 = out.2.min(width(&r, limit));
                }
            }
            out
        })
        .collect();
    let all: f64 = layers.iter().map(|l| l.0).sum();
    let narrow: f64 = layers.iter().map(|l| l.1).sum();
    let narrowest = layers.iter().map(|l| l.2).fold(f64::INFINITY, f64::min);
    Ok(
        (narrow > 0.0 && all > 0.0 && narrowest.is_finite()).then(|| NarrowSections {
            narrowest,
            share: narrow / all,
        }),
    )
}

/// A region's area, mm² (its holes taken out).
fn region_area(r: &Region) -> f64 {
    let outer = 0.5 * area2(&r.outer).abs();
    let holes: f64 = r.holes.iter().map(|h| 0.5 * area2(h).abs()).sum();
    (outer - holes).max(0.0)
}

/// The full width (twice the depth of its deepest point) of a region thinner than `limit`,
/// by bisection on [`thinner_than`].
fn width(r: &Region, limit: f64) -> f64 {
    let (mut lo, mut hi) = (0.0, 0.5 * limit);
    for _ in 0..WIDTH_STEPS {
        let mid = 0.5 * (lo + hi);
        if thinner_than(r, mid) {
            hi = mid;
        } else {
            lo = mid;
        }
    }
    lo + hi
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_strip_is_as_wide_as_it_is() {
        for w in [0.1, 0.2, 0.3] {
            let r = Region {
                outer: vec![[0.0, 0.0], [5.0, 0.0], [5.0, w], [0.0, w]],
                holes: vec![],
            };
            assert!(
                (width(&r, 0.45) - w).abs() < 0.002,
                "{w}: {}",
                width(&r, 0.45)
            );
            assert!((region_area(&r) - 5.0 * w).abs() < 1e-9);
        }
    }
}
