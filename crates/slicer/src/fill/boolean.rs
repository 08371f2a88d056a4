//! Booleans and growth of whole sets of regions (i_overlay's, non-zero fill), for the support
//! material's columns ([`crate::support_material`]).

use super::offset::{offset, round_join};
use super::region::{region_shapes, shape_region};
use super::{Region, Shapes};
use i_overlay::core::fill_rule::FillRule;
use i_overlay::core::overlay_rule::OverlayRule;
use i_overlay::float::single::SingleFloatOverlay;

fn shapes(regions: &[Region]) -> Shapes {
    regions.iter().flat_map(region_shapes).collect()
}

fn regions(shapes: Shapes) -> Vec<Region> {
    shapes.into_iter().filter_map(shape_region).collect()
}

fn overlay(a: &[Region], b: &[Region], rule: OverlayRule) -> Vec<Region> {
    let (sa, sb) = (shapes(a), shapes(b));
    match (sa.is_empty(), sb.is_empty(), rule) {
        (true, _, OverlayRule::Union) => return regions(sb),
        (_, true, OverlayRule::Union | OverlayRule::Difference) => return regions(sa),
        (true, _, _) | (_, true, _) => return vec![],
        _ => {}
    }
    regions(sa.overlay(&sb, rule, FillRule::NonZero))
}

/// What of `a` lies outside `b`.
pub(crate) fn difference(a: &[Region], b: &[Region]) -> Vec<Region> {
    overlay(a, b, OverlayRule::Difference)
}

/// What lies in `a` or in `b`.
pub(crate) fn union(a: &[Region], b: &[Region]) -> Vec<Region> {
    overlay(a, b, OverlayRule::Union)
}

/// What lies in both `a` and `b`.
pub(crate) fn intersection(a: &[Region], b: &[Region]) -> Vec<Region> {
    overlay(a, b, OverlayRule::Intersect)
}

/// `a` grown outward by `d` mm (≥ 0; round joins chorded within `tol` mm).
pub(crate) fn grow(a: &[Region], d: f64, tol: f64) -> Vec<Region> {
    let s = shapes(a);
    if s.is_empty() || !(d.is_finite() && d > 0.0) {
        return regions(s);
    }
    regions(offset(&s, d, &round_join(tol, d), 1.1))
}

/// The pieces of `layer` lying outside `below` grown by `reach` mm (round joins chorded within
/// `tol`), as regions: what a layer holds that the one under it does not carry.
pub(crate) fn outside_grown(
    layer: &[Region],
    below: &[Region],
    reach: f64,
    tol: f64,
) -> Vec<Region> {
    difference(layer, &grow(below, reach, tol))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geom2d::shapes::{area, rect};

    #[test]
    fn booleans_of_two_squares() {
        let a = [rect(0.0, 0.0, 10.0, 10.0)];
        let b = [rect(5.0, 0.0, 15.0, 10.0)];
        assert!((area(&difference(&a, &b)) - 50.0).abs() < 1e-6);
        assert!((area(&union(&a, &b)) - 150.0).abs() < 1e-6);
        assert!((area(&intersection(&a, &b)) - 50.0).abs() < 1e-6);
        assert!((area(&difference(&a, &[])) - 100.0).abs() < 1e-6);
        assert!(intersection(&a, &[]).is_empty());
        // Grown by 1: 12 × 12 less the four corners' squares plus their quarter discs.
        let g = area(&grow(&a, 1.0, 0.001));
        let expect = 144.0 - 4.0 + std::f64::consts::PI;
        assert!((g - expect).abs() < 0.01, "{g}");
    }
}
