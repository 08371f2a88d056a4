//! Regions of a layer from the loops of its section, and as i_overlay shapes.

use super::{Contour, Shape, Shapes, MAX_COORD};
use crate::geom2d::{area2, inside, on_boundary, perimeter, region_area, Point2, Region};
use crate::tolerance::{NOISE_AREA, ROUND_OFF, SLIVER_AREA, UNION_GAIN};
use i_overlay::core::fill_rule::FillRule;
use i_overlay::core::overlay_rule::OverlayRule;
use i_overlay::float::simplify::SimplifyShape;
use i_overlay::float::single::SingleFloatOverlay;

/// A loop as a slicer hands it over, cleaned: finite, no repeated points (the closing repeat
/// included), at least three points and some area. `None` when nothing usable is left.
fn clean_loop(pts: &[Point2]) -> Option<Vec<Point2>> {
    if pts
        .iter()
        .any(|p| !(p[0].is_finite() && p[1].is_finite()) || p[0].abs().max(p[1].abs()) > MAX_COORD)
    {
        return None;
    }
    let mut out: Vec<Point2> = Vec::with_capacity(pts.len());
    for &p in pts {
        if out.last() != Some(&p) {
            out.push(p);
        }
    }
    while out.len() > 1 && out.first() == out.last() {
        out.pop();
    }
    if out.len() < 3 {
        return None;
    }
    let a = area2(&out).abs();
    let scale = perimeter(&out);
    // Zero-area slivers (all points on a line) carry nothing to fill.
    if a.is_nan() || a <= SLIVER_AREA * scale * scale.max(1.0) {
        return None;
    }
    Some(out)
}

fn oriented(mut pts: Vec<Point2>, ccw: bool) -> Vec<Point2> {
    if (area2(&pts) > 0.0) != ccw {
        pts.reverse();
    }
    pts
}

/// Groups closed loops (any orientation, as a slicer finds them) into regions by even-odd
/// nesting.
///
/// A loop inside an even number of other loops is an outer boundary, one inside an odd number
/// is a hole of the smallest loop around it (so an island inside a hole is a region of its
/// own). Outer boundaries come out counter-clockwise and holes clockwise; the points are the
/// input's (closing repeats, repeated points, non-finite loops and loops without area are
/// dropped). Loops are assumed not to cross each other.
pub fn regions_from_loops(loops: &[Vec<Point2>]) -> Vec<Region> {
    struct L {
        pts: Vec<Point2>,
        area: f64,
        bbox: [f64; 4],
    }
    let mut ls: Vec<L> = loops
        .iter()
        .filter_map(|l| clean_loop(l))
        .map(|pts| {
            let mut bbox = [f64::INFINITY, f64::INFINITY, -f64::INFINITY, -f64::INFINITY];
            for p in &pts {
                bbox[0] = bbox[0].min(p[0]);
                bbox[1] = bbox[1].min(p[1]);
                bbox[2] = bbox[2].max(p[0]);
                bbox[3] = bbox[3].max(p[1]);
            }
            let area = area2(&pts).abs();
            L { pts, area, bbox }
        })
        .collect();
    // Largest first: a loop's parent comes before it.
    ls.sort_by(|a, b| b.area.total_cmp(&a.area));
    let contains = |outer: &L, inner: &L| -> bool {
        let (o, i) = (outer.bbox, inner.bbox);
        if i[0] < o[0] || i[1] < o[1] || i[2] > o[2] || i[3] > o[3] {
            return false;
        }
        let eps = ROUND_OFF * (1.0 + (o[2] - o[0]).max(o[3] - o[1]));
        match inner
            .pts
            .iter()
            .find(|p| !on_boundary(**p, &outer.pts, eps))
        {
            Some(p) => inside(*p, &outer.pts),
            // Every point on the other loop: the same loop twice, which even-odd cancels.
            None => true,
        }
    };
    let n = ls.len();
    let mut depth = vec![0usize; n];
    let mut parent = vec![usize::MAX; n];
    for i in 0..n {
        if let Some(j) = (0..i).rev().find(|&j| contains(&ls[j], &ls[i])) {
            parent[i] = j;
            depth[i] = depth[j] + 1;
        }
    }
    let mut region_of = vec![usize::MAX; n];
    let mut regions: Vec<Region> = Vec::new();
    for i in 0..n {
        if depth[i] & 1 == 0 {
            region_of[i] = regions.len();
            regions.push(Region {
                outer: oriented(ls[i].pts.clone(), true),
                holes: Vec::new(),
            });
        }
    }
    for i in 0..n {
        if depth[i] & 1 == 1 {
            let r = region_of[parent[i]];
            regions[r].holes.push(oriented(ls[i].pts.clone(), false));
        }
    }
    regions
}

/// Regions of closed section loops that may cross: the loops of several solids that overlap
/// (a part modelled as bodies pushed into each other, sliced whole). A mesh section runs
/// counter-clockwise around material and clockwise around holes, so material is where the
/// loops wind round once or more (their union): of the two winding readings (the loops one
/// way round or the other), the one with more area. It is taken where it covers more than
/// the even-odd reading, which leaves out what two loops share; elsewhere (loops that do not
/// cross) the even-odd regions of [`regions_from_loops`] are kept.
pub fn regions_by_winding(loops: &[Vec<Point2>]) -> Vec<Region> {
    let contours: Shape = loops.iter().filter_map(|l| clean_loop(l)).collect();
    if contours.len() < 2 {
        return regions_from_loops(loops);
    }
    let area = |rs: &[Region]| -> f64 { rs.iter().map(region_area).sum() };
    let read = |rule: FillRule| -> Vec<Region> {
        let shapes: Shapes = contours.simplify_shape(rule);
        shapes.into_iter().filter_map(shape_region).collect()
    };
    let (positive, negative) = (read(FillRule::Positive), read(FillRule::Negative));
    let (pa, na) = (area(&positive), area(&negative));
    let (winding, wa) = match pa >= na {
        true => (positive, pa),
        false => (negative, na),
    };
    let even_odd = area(&read(FillRule::EvenOdd));
    match wa > even_odd * (1.0 + UNION_GAIN) + UNION_GAIN {
        true => winding,
        false => regions_from_loops(loops),
    }
}

/// The region as clean i_overlay shapes (outer minus holes, non-zero fill, so orientation and
/// holes poking out of the outer boundary do not matter). Empty when there is nothing to fill.
pub(super) fn region_shapes(region: &Region) -> Shapes {
    let Some(outer) = clean_loop(&region.outer) else {
        return Vec::new();
    };
    // Holes of no area are the noise of earlier booleans between nearly coincident edges:
    // each would be grown by half a bead where the region is eroded for its lines (a support
    // column under the sphere held 741 of them, 1e-16 to 1e-8 mm², and took 3.7 s to erode).
    let holes: Vec<Contour> = region
        .holes
        .iter()
        .filter_map(|h| clean_loop(h))
        .filter(|h| 0.5 * area2(h).abs() >= NOISE_AREA)
        .collect();
    let outer = vec![outer];
    if holes.is_empty() {
        outer.simplify_shape(FillRule::NonZero)
    } else {
        outer.overlay(&holes, OverlayRule::Difference, FillRule::NonZero)
    }
}

/// An i_overlay shape (outer contour, then holes) as a [`Region`] with the region's
/// orientation; `None` for a shape without an outer contour of area.
pub(super) fn shape_region(shape: Shape) -> Option<Region> {
    let mut contours = shape.into_iter();
    let mut outer = contours.next()?;
    if area2(&outer) < 0.0 {
        outer.reverse();
    }
    if area2(&outer) <= 0.0 {
        return None;
    }
    let holes = contours
        .map(|mut h| {
            if area2(&h) > 0.0 {
                h.reverse();
            }
            h
        })
        .collect();
    Some(Region { outer, holes })
}

/// The box of a set of shapes: lowest and highest corner.
pub(super) fn bounds(s: &Shapes) -> (Point2, Point2) {
    let mut lo = [f64::INFINITY; 2];
    let mut hi = [-f64::INFINITY; 2];
    for p in s.iter().flatten().flatten() {
        lo = [lo[0].min(p[0]), lo[1].min(p[1])];
        hi = [hi[0].max(p[0]), hi[1].max(p[1])];
    }
    (lo, hi)
}
