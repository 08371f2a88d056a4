//! Filling one planar layer with extrusion paths.
//!
//! A layer's cross-section arrives as closed loops ([`regions_from_loops`] groups them into
//! [`Region`]s); [`fill_layer`] turns the regions into bead centre lines by the feature's
//! [`PathMode`], and [`order_paths`] puts them in a print order with short travels.
//!
//! Geometry: every bead centre line lies half a bead width or more inside the region, but
//! for the free ends of raster and zig-zag lines. The first perimeter is the region offset
//! inward by `width / 2`, each further one by another `spacing`; infill lines are `spacing`
//! apart and end on the boundary of the infill area (the region offset inward by
//! `width / 2`, plus `perimeters · spacing` for contour-zig-zag), where connectors join them.
//! A line end that nothing joins and no ring surrounds (every raster end, the first and last
//! end of a zig-zag chain) runs on to the region's boundary ([`bead_end_reach`]). Offsets are
//! Euclidean: around a reflex corner (a hole's polygon, an inner corner) the offset is an
//! arc, chorded within 1 % of the width, so there a centre line may come that much closer
//! than `width / 2`; convex corners and straight edges are exact.
//! Offsets and booleans are i_overlay's (`OutlineOffset`, `overlay`); offsets use its float
//! arithmetic and are made from contours rid of vertices too flat for its integer grid (the
//! collinear points a mesh's cross-section has on every chord of a curved face), on which its
//! construction leaves a spike from the offset out to the boundary. The infill lines are cut
//! against the (clean, non-self-intersecting) polygons i_overlay returns with an even-odd
//! scan, which also tells on which boundary ring, and where along it, each line ends — what
//! zig-zag needs to join neighbouring lines along the boundary.
//!
//! Where successive rings leave a strip narrower than a bead uncovered (the middle of a
//! rectangle whose width is not a multiple of the spacing, the neck between a hole and the
//! outside), that strip gets a gap-fill line along its length (kind [`PathKind::Infill`]).
//! Where a part of the region is too narrow for a ring's beads from both sides, or for the
//! first ring at all, that part is handed back ([`FilledLayer::gaps`]) to be filled with beads
//! as wide as it is. So contour fills cover the region without laying any of it twice.

use crate::params::{LayerParams, PathMode};
use i_overlay::core::fill_rule::FillRule;
use i_overlay::core::overlay_rule::OverlayRule;
use i_overlay::float::simplify::SimplifyShape;
use i_overlay::float::single::SingleFloatOverlay;
use i_overlay::mesh::float::outline::offset::OutlineOffset;
use i_overlay::mesh::float::style::{LineJoin, OutlineStyle};
use i_overlay::mesh::math::MathMode;
use std::f64::consts::PI;

/// A point of the layer plane, mm.
pub type Point2 = [f64; 2];

/// A region: an outer boundary (counter-clockwise) and holes (clockwise), closed implicitly.
#[derive(Debug, Clone, PartialEq)]
pub struct Region {
    /// Outer boundary, counter-clockwise, first point not repeated.
    pub outer: Vec<Point2>,
    /// Holes, each clockwise, first point not repeated.
    pub holes: Vec<Vec<Point2>>,
}

/// One continuous extrusion path (an open polyline; a closed perimeter repeats its first point
/// at the end).
#[derive(Debug, Clone, PartialEq)]
pub struct Path2 {
    /// Bead centre line, mm.
    pub points: Vec<Point2>,
    /// What the path is.
    pub kind: PathKind,
}

/// What a path is for.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum PathKind {
    /// A closed ring following the boundary (perimeters, and every ring of contour fill).
    Perimeter,
    /// Raster or zig-zag lines, and gap fill between rings.
    Infill,
}

impl Path2 {
    /// True when the path ends where it starts (a ring).
    pub fn is_closed(&self) -> bool {
        self.points.len() > 2 && self.points.first() == self.points.last()
    }

    /// Length of the polyline, mm.
    pub fn length(&self) -> f64 {
        self.points.windows(2).map(|w| dist(w[0], w[1])).sum()
    }
}

// i_overlay's nested-vector polygon types.
type Contour = Vec<Point2>;
type Shape = Vec<Contour>;
type Shapes = Vec<Shape>;

/// Coordinates beyond this (mm) are treated as garbage: the loop is dropped.
const MAX_COORD: f64 = 1e9;
/// Most scan lines one fill may use (a spacing far too small for the part gives nothing).
const MAX_LINES: f64 = 1e6;
/// Most rings contour fill makes.
const MAX_RINGS: usize = 100_000;
/// Path segments shorter than this (mm) are dropped: nothing to print.
const MIN_SEGMENT: f64 = 1e-6;

fn dist(a: Point2, b: Point2) -> f64 {
    (a[0] - b[0]).hypot(a[1] - b[1])
}

/// Twice the signed area of a closed polygon (positive when counter-clockwise).
fn area2(pts: &[Point2]) -> f64 {
    let n = pts.len();
    if n < 3 {
        return 0.0;
    }
    // Relative to the first point, for accuracy far from the origin.
    let o = pts[0];
    let mut s = 0.0;
    for i in 1..n - 1 {
        let a = [pts[i][0] - o[0], pts[i][1] - o[1]];
        let b = [pts[i + 1][0] - o[0], pts[i + 1][1] - o[1]];
        s += a[0] * b[1] - a[1] * b[0];
    }
    s
}

fn shapes_area(s: &Shapes) -> f64 {
    s.iter().flatten().map(|c| 0.5 * area2(c)).sum()
}

fn perimeter(pts: &[Point2]) -> f64 {
    let n = pts.len();
    (0..n).map(|i| dist(pts[i], pts[(i + 1) % n])).sum()
}

/// Even-odd point in polygon (points on the boundary may go either way).
fn inside(p: Point2, poly: &[Point2]) -> bool {
    let n = poly.len();
    let mut c = false;
    let mut j = n.wrapping_sub(1);
    for i in 0..n {
        let (a, b) = (poly[i], poly[j]);
        if (a[1] > p[1]) != (b[1] > p[1])
            && p[0] < (b[0] - a[0]) * (p[1] - a[1]) / (b[1] - a[1]) + a[0]
        {
            c = !c;
        }
        j = i;
    }
    c
}

/// Distance from `p` to the segment `a`–`b`.
fn seg_dist(p: Point2, a: Point2, b: Point2) -> f64 {
    let d = [b[0] - a[0], b[1] - a[1]];
    let l2 = d[0] * d[0] + d[1] * d[1];
    let t = if l2 > 0.0 {
        (((p[0] - a[0]) * d[0] + (p[1] - a[1]) * d[1]) / l2).clamp(0.0, 1.0)
    } else {
        0.0
    };
    dist(p, [a[0] + t * d[0], a[1] + t * d[1]])
}

fn on_boundary(p: Point2, poly: &[Point2], eps: f64) -> bool {
    let n = poly.len();
    (0..n).any(|i| seg_dist(p, poly[i], poly[(i + 1) % n]) <= eps)
}

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
    if a.is_nan() || a <= 1e-12 * scale * scale.max(1.0) {
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
        let eps = 1e-9 * (1.0 + (o[2] - o[0]).max(o[3] - o[1]));
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

/// The region as clean i_overlay shapes (outer minus holes, non-zero fill, so orientation and
/// holes poking out of the outer boundary do not matter). Empty when there is nothing to fill.
fn region_shapes(region: &Region) -> Shapes {
    let Some(outer) = clean_loop(&region.outer) else {
        return Vec::new();
    };
    let holes: Vec<Contour> = region.holes.iter().filter_map(|h| clean_loop(h)).collect();
    let outer = vec![outer];
    if holes.is_empty() {
        outer.simplify_shape(FillRule::NonZero)
    } else {
        outer.overlay(&holes, OverlayRule::Difference, FillRule::NonZero)
    }
}

/// True when no point of `region` lies `depth` or more inside its boundary (its inward offset
/// by `depth` is empty): a region too thin for that many beads side by side.
pub fn thinner_than(region: &Region, depth: f64) -> bool {
    let base = region_shapes(region);
    base.is_empty() || erode(&base, depth, &round_join(0.01 * depth, depth)).is_empty()
}

/// Join for inward offsets: reflex corners of the region become arcs, chorded within `tol` up
/// to radius `radius` (the deepest offset the fill will make).
fn round_join(tol: f64, radius: f64) -> LineJoin<f64> {
    let a = if radius > 0.0 {
        (8.0 * tol / radius).sqrt()
    } else {
        0.25 * PI
    };
    let a = if a.is_finite() { a } else { 0.25 * PI };
    LineJoin::Round(a.clamp(0.01 * PI, 0.25 * PI))
}

/// `base` offset inward by `d` (> 0), reflex corners rounded by `join`.
///
/// Shapes too narrow to survive are dropped before i_overlay sees them: an offset that
/// collapses a many-sided polygon makes every offset edge cross every other, and i_overlay's
/// time goes quadratic (0.6 s for a 256-gon).
fn erode(base: &Shapes, d: f64, join: &LineJoin<f64>) -> Shapes {
    if base.is_empty() || !(d.is_finite() && d >= 0.0) {
        return Vec::new();
    }
    let survivors: Shapes = base
        .iter()
        .filter(|shape| {
            shape
                .first()
                .is_some_and(|outer| min_width(outer) > 2.0 * d * (1.0 + 1e-9))
        })
        .cloned()
        .collect();
    if survivors.is_empty() {
        return Vec::new();
    }
    drop_specks(offset(&survivors, -d, join, 1.1))
}

/// `base` offset by `d` (negative: inward) with `join` (whose reach is `reach · |d|`), by
/// i_overlay, from the contours rid of vertices too flat for it ([`drop_flat`]).
fn offset(base: &Shapes, d: f64, join: &LineJoin<f64>, reach: f64) -> Shapes {
    let (lo, hi) = bounds(base);
    // i_overlay's grid: the bounds grown by the join's reach, mapped onto 29-bit integers
    // (rounded up to a power of two, so this is at most twice the real step).
    let radius = 0.5 * (hi[0] - lo[0]).max(hi[1] - lo[1]) + reach * d.abs();
    let grid = radius * 2f64.powi(-28);
    // Far above the construction's rounding (a grid step at each offset end), far below
    // anything a tolerance can see (a 20 mm region offset by 0.2 mm: 3e-6 rad, 2e-7 mm).
    let min_turn = if d != 0.0 {
        (16.0 * grid / d.abs()).min(1e-3)
    } else {
        0.0
    };
    let min_dev = 4.0 * grid;
    let clean: Shapes = base
        .iter()
        .map(|shape| {
            shape
                .iter()
                .map(|c| drop_flat(c, min_turn, min_dev))
                .collect()
        })
        .collect();
    let style = OutlineStyle::new(d)
        .line_join(join.clone())
        .math(MathMode::Float);
    clean.outline(&style)
}

/// A closed contour without the vertices whose turn is under `min_turn` (radians) or that lie
/// within `min_dev` of the segment between their neighbours (repeated and nearly repeated
/// points included); each is judged against the neighbours left after the ones before it are
/// dropped. The contour itself when too little would be left.
///
/// Such vertices carry no shape but break i_overlay's offset: it tells a convex corner from a
/// reflex one by the exact turn of the snapped edges, and at a convex one joins the two
/// offset edges through the original vertex (a sliver of negative winding that its fill rule
/// removes). When the turn is so small that the offset edges' rounded ends come out in the
/// wrong order, the sliver winds positively and stays: a spike from the offset out to the
/// vertex (on the region's boundary, for the first ring) and back, and a near-zero edge at
/// its base. A mesh's cross-section has such
/// vertices on every chord of a curved face (where the cutting plane crosses a facet's
/// diagonal). Vertices kept turn by at least 16 grid steps over the offset distance and stand
/// 4 steps off their chord, so snapping keeps their turn within a factor 0.6 and the offset
/// edges' ends some ten steps apart, in the right order.
fn drop_flat(c: &[Point2], min_turn: f64, min_dev: f64) -> Contour {
    let flat = |a: Point2, b: Point2, q: Point2| -> bool {
        if seg_dist(b, a, q) <= min_dev {
            return true;
        }
        let u = [b[0] - a[0], b[1] - a[1]];
        let v = [q[0] - b[0], q[1] - b[1]];
        let cr = u[0] * v[1] - u[1] * v[0];
        let dt = u[0] * v[0] + u[1] * v[1];
        dt > 0.0 && cr.abs().atan2(dt) <= min_turn
    };
    let mut out: Contour = Vec::with_capacity(c.len());
    for &p in c {
        while out.len() >= 2 && flat(out[out.len() - 2], out[out.len() - 1], p) {
            out.pop();
        }
        out.push(p);
    }
    // Around the closing vertex.
    let mut start = 0;
    while out.len() - start >= 3 {
        let m = out.len();
        if flat(out[m - 2], out[m - 1], out[start]) {
            out.pop();
        } else if flat(out[m - 1], out[start], out[start + 1]) {
            start += 1;
        } else {
            break;
        }
    }
    let out = out.split_off(start);
    if out.len() >= 3 && area2(&out).abs() > 0.5 * area2(c).abs() {
        out
    } else {
        c.to_vec()
    }
}

/// An upper bound of a polygon's width (the smallest over 16 directions of its extent), so of
/// twice its inradius.
fn min_width(pts: &[Point2]) -> f64 {
    (0..16)
        .map(|k| {
            let (sn, cs) = (k as f64 * PI / 16.0).sin_cos();
            let (mut lo, mut hi) = (f64::INFINITY, -f64::INFINITY);
            for p in pts {
                let t = p[0] * cs + p[1] * sn;
                lo = lo.min(t);
                hi = hi.max(t);
            }
            hi - lo
        })
        .fold(f64::INFINITY, f64::min)
}

/// Douglas-Peucker on each closed contour: drops vertices while the outline moves at most
/// `tol` (kept vertices are original ones). Offsets keep every vertex of their input, so
/// without this each ring inward is as dense as the region's boundary however small it gets.
fn simplify(shapes: Shapes, tol: f64) -> Shapes {
    shapes
        .into_iter()
        .map(|shape| shape.into_iter().map(|c| simplify_ring(c, tol)).collect())
        .collect()
}

fn simplify_ring(c: Contour, tol: f64) -> Contour {
    let n = c.len();
    if n <= 4 {
        return c;
    }
    // Split at vertex 0 and the vertex farthest from it; simplify both chains.
    let far = (1..n)
        .max_by(|&a, &b| dist(c[0], c[a]).total_cmp(&dist(c[0], c[b])))
        .unwrap_or(n / 2);
    let mut keep = vec![false; n];
    keep[0] = true;
    keep[far] = true;
    let mut stack = vec![(0usize, far), (far, n)];
    while let Some((i, j)) = stack.pop() {
        if j <= i + 1 {
            continue;
        }
        let (a, b) = (c[i], c[j % n]);
        let (mut worst, mut at) = (-1.0, i);
        for (k, &p) in c.iter().enumerate().take(j).skip(i + 1) {
            let dd = seg_dist(p, a, b);
            if dd > worst {
                worst = dd;
                at = k;
            }
        }
        if worst > tol {
            keep[at] = true;
            stack.push((i, at));
            stack.push((at, j));
        }
    }
    let out: Contour = c
        .iter()
        .zip(&keep)
        .filter(|(_, k)| **k)
        .map(|(p, _)| *p)
        .collect();
    if out.len() >= 3 && area2(&out).abs() > 0.0 {
        out
    } else {
        c
    }
}

/// `base` offset outward by `d` (> 0), convex corners kept sharp (mitred).
fn dilate_sharp(base: &Shapes, d: f64) -> Shapes {
    if base.is_empty() || !(d.is_finite() && d >= 0.0) {
        return Vec::new();
    }
    // A mitre reaches d / sin(θ / 2) at a corner of angle θ: at most 14 d, as i_overlay
    // bevels corners sharper than this 9°.
    offset(base, d, &LineJoin::Miter(0.05 * PI), 14.0)
}

/// Drops contours with fewer than three points and shapes whose outer contour has no area.
fn drop_specks(shapes: Shapes) -> Shapes {
    shapes
        .into_iter()
        .filter_map(|shape| {
            let mut it = shape.into_iter().filter(|c| c.len() >= 3);
            let outer = it.next()?;
            if area2(&outer).abs() <= 1e-18 {
                return None;
            }
            let mut s = vec![outer];
            s.extend(it);
            Some(s)
        })
        .collect()
}

/// What one fill call needs to know.
#[derive(Debug, Clone)]
struct Ctx {
    width: f64,
    spacing: f64,
    /// Join of inward offsets (arcs at reflex corners).
    join: LineJoin<f64>,
    /// How far contour fill's inner rings may be simplified, mm: the feature's tolerance, at
    /// most 0.25 % of the width (small, because each ring is offset from the simplified one
    /// before it and the error adds up).
    tol: f64,
}

/// Paths filling `regions` for layer number `layer` (for zig-zag angle alternation), bead width
/// `width`, spacing `spacing` between neighbouring path centre lines.
///
/// - raster: lines at `raster_angle_deg`, each a separate path, all printed in the same
///   direction, cut by the region offset inward by `width / 2` and then run on to the
///   region's boundary ([`bead_end_reach`]);
/// - zigzag: the same lines (at `raster_angle_deg + 90°` on odd layers), neighbours within a
///   connected piece joined by a connector along the infill boundary when no other line ends
///   on the boundary between them (and the connector is shorter than ten spacings); the
///   first and last end of each chain run on to the boundary as raster ends do;
/// - contour: rings offset inward by `width / 2`, `width / 2 + spacing`, ... until nothing is
///   left, plus gap-fill lines in strips the rings leave uncovered (parts too narrow for a
///   ring go to [`FilledLayer::gaps`]);
/// - contour_zigzag: `perimeters` rings, then zig-zag inside the region offset inward by
///   `width / 2 + perimeters · spacing`.
///
/// Rings are [`PathKind::Perimeter`] and closed (first point repeated); lines are
/// [`PathKind::Infill`]. Paths come region by region, rings outermost first (a gap-fill line
/// right after the ring it lies inside), infill last; use [`order_paths`] for a print order. No
/// path has a segment shorter than a micrometre (none of zero length). Degenerate input (no
/// regions, slivers, a region narrower than a bead, width or spacing not positive) gives fewer
/// paths or none, never a panic.
pub fn fill_layer(
    regions: &[Region],
    params: &LayerParams,
    layer: usize,
    width: f64,
    spacing: f64,
) -> FilledLayer {
    let mut out = Vec::new();
    let mut gaps: Shapes = Vec::new();
    if !(width.is_finite() && width > 0.0 && spacing.is_finite() && spacing > 0.0) {
        return FilledLayer::default();
    }
    let tol = if params.tolerance.is_finite() && params.tolerance > 0.0 {
        params.tolerance
    } else {
        0.05
    };
    let base_angle = if params.raster_angle_deg.is_finite() {
        params.raster_angle_deg
    } else {
        0.0
    };
    let zigzag_angle = if layer % 2 == 1 {
        base_angle + 90.0
    } else {
        base_angle
    }
    .to_radians();
    for region in regions {
        let base = region_shapes(region);
        if base.is_empty() {
            continue;
        }
        // Too many lines or rings for this spacing: the parameters are wrong, fill nothing.
        let (lo, hi) = bounds(&base);
        let size = (hi[0] - lo[0]).hypot(hi[1] - lo[1]);
        if size / spacing > MAX_LINES {
            continue;
        }
        // Arcs grow as rings move inward: chord them for the deepest offset this fill makes.
        let deepest = 0.5 * width
            + spacing
                * match params.path_mode {
                    PathMode::Raster | PathMode::Zigzag => 0.0,
                    PathMode::Contour => f64::INFINITY,
                    PathMode::ContourZigzag => params.perimeters as f64,
                };
        let ctx = Ctx {
            width,
            spacing,
            join: round_join(tol.min(0.01 * width), deepest.min(0.5 * size)),
            tol: tol.min(0.0025 * width),
        };
        match params.path_mode {
            PathMode::Raster => {
                let area = erode(&base, 0.5 * width, &ctx.join);
                let reach = Some(Reach { base: &base, width });
                scan_fill(
                    &area,
                    base_angle.to_radians(),
                    spacing,
                    false,
                    reach,
                    &mut out,
                );
            }
            PathMode::Zigzag => {
                let area = erode(&base, 0.5 * width, &ctx.join);
                let reach = Some(Reach { base: &base, width });
                scan_fill(&area, zigzag_angle, spacing, true, reach, &mut out);
            }
            PathMode::Contour => {
                rings(&base, &ctx, MAX_RINGS, true, &mut out, &mut gaps);
            }
            PathMode::ContourZigzag => {
                let area = rings(
                    &base,
                    &ctx,
                    params.perimeters.min(MAX_RINGS),
                    false,
                    &mut out,
                    &mut gaps,
                );
                // Free chain ends run on to the inner edge of the last ring's bead: the
                // infill area grown back by half a spacing (not the ring itself eroded, which
                // would take in the strips left to the gaps).
                let edge = offset(&area, 0.5 * spacing, &ctx.join, 1.0);
                let reach = Some(Reach { base: &edge, width });
                scan_fill(&area, zigzag_angle, spacing, true, reach, &mut out);
            }
        }
    }
    for p in &mut out {
        drop_short_segments(&mut p.points);
    }
    out.retain(|p| {
        let n = p.points.len();
        n >= 2 && (p.kind != PathKind::Perimeter || (n >= 4 && p.is_closed()))
    });
    FilledLayer {
        paths: out,
        gaps: gaps.into_iter().filter_map(shape_region).collect(),
    }
}

/// The paths of a layer's regions, and the strips they leave for beads as wide as each strip.
#[derive(Debug, Clone, Default)]
pub struct FilledLayer {
    /// Paths of one bead width.
    pub paths: Vec<Path2>,
    /// Parts of the regions too narrow for a ring (where its beads would meet from both
    /// sides, or the first ring cannot reach): each is to be filled with beads as wide as it
    /// is there (`freeform::fill_flat_region`; `planar::fill_regions` does so).
    pub gaps: Vec<Region>,
}

/// An i_overlay shape (outer contour, then holes) as a [`Region`] with the region's
/// orientation; `None` for a shape without an outer contour of area.
fn shape_region(shape: Shape) -> Option<Region> {
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

/// The part of a bead width by which a free line end stops short of the boundary it runs
/// towards: a hundredth, so that no print point lies on the boundary
/// itself.
pub const END_MARGIN: f64 = 0.01;

/// The most, in bead widths, a free line end runs on past the edge of the infill area: a line
/// nearly parallel to the boundary meets it only far on.
pub const MAX_END_REACH: f64 = 4.0;

/// How far (mm) a free line end (one that no connector joins and no ring surrounds: every
/// raster end, the first and last of a zig-zag chain) runs on past the edge of the infill
/// area where it was cut, half a bead inside the region, for beads `width` wide: to [`END_MARGIN`] of a bead
/// before the boundary, which lies `boundary` mm on along the line; no more than `room`
/// (half the way to the next piece of the same line) nor [`MAX_END_REACH`] beads.
///
/// Eq. 1 lays a bead `w` wide and `h` high along its centre line: the line's share of the
/// region is the strip `w` wide about it, and where a straight boundary cuts that strip, at
/// any angle, the strip holds `w` times the centre line's length up to the boundary. An end
/// that stops on the infill area instead leaves `w/2 · w` unfilled at a square end and more
/// at a slanting one (where a connector joins two ends, it puts that volume down along the
/// boundary): raster fills lost 2–9 % of a small feature's volume so, and zig-zag fills of
/// thin blades, whose slanting lines few connectors join, up to 7 %.
pub fn bead_end_reach(width: f64, boundary: f64, room: f64) -> f64 {
    let r = (boundary - END_MARGIN * width)
        .min(MAX_END_REACH * width)
        .min(room);
    if r.is_finite() && r > 0.0 {
        r
    } else {
        0.0
    }
}

/// Distance from `p` along the unit direction `d` to the first boundary edge of `base`
/// ahead of it; `None` when the ray meets none.
fn ray_to_boundary(base: &Shapes, p: Point2, d: Point2) -> Option<f64> {
    let cross = |a: Point2, b: Point2| a[0] * b[1] - a[1] * b[0];
    let mut best: Option<f64> = None;
    for c in base.iter().flatten() {
        let n = c.len();
        for i in 0..n {
            let (a, b) = (c[i], c[(i + 1) % n]);
            let e = [b[0] - a[0], b[1] - a[1]];
            let den = cross(d, e);
            if den.abs() <= 1e-15 * (1.0 + e[0].abs() + e[1].abs()) {
                continue;
            }
            let ap = [a[0] - p[0], a[1] - p[1]];
            let t = cross(ap, e) / den;
            let u = cross(ap, d) / den;
            if t > 0.0 && (0.0..=1.0).contains(&u) && best.is_none_or(|x| t < x) {
                best = Some(t);
            }
        }
    }
    best
}

/// Drops the points of a path closer than [`MIN_SEGMENT`] to the point kept before them (a
/// segment too short to print), keeping both ends: a dropped last point replaces the point
/// kept before it, so a ring stays closed.
fn drop_short_segments(pts: &mut Vec<Point2>) {
    let Some(&last) = pts.last() else { return };
    let mut k = 0;
    for i in 0..pts.len() {
        if k == 0 || dist(pts[i], pts[k - 1]) >= MIN_SEGMENT {
            pts[k] = pts[i];
            k += 1;
        }
    }
    pts.truncate(k);
    if k >= 2 {
        pts[k - 1] = last;
        while pts.len() >= 3 && dist(pts[pts.len() - 2], last) < MIN_SEGMENT {
            pts.remove(pts.len() - 2);
        }
    }
}

fn bounds(s: &Shapes) -> (Point2, Point2) {
    let mut lo = [f64::INFINITY; 2];
    let mut hi = [-f64::INFINITY; 2];
    for p in s.iter().flatten().flatten() {
        lo = [lo[0].min(p[0]), lo[1].min(p[1])];
        hi = [hi[0].max(p[0]), hi[1].max(p[1])];
    }
    (lo, hi)
}

/// Up to `max` rings inward from `base` (the first at `width / 2`, then every `spacing`);
/// returns the area inside the last ring, offset by one more spacing (the infill area of
/// contour-zig-zag; empty once the region is used up). Strips narrower than a bead that the
/// rings leave uncovered get gap-fill lines; parts too narrow for a ring go to `gaps`.
///
/// Where a ring's offset has parts narrower than a spacing, its beads from either side
/// overlap there (a 1.5 mm web took two rings of 0.45 mm beads 0.15 mm apart, 0.3 mm of bead
/// laid twice): the ring keeps only where a whole bead nearly fits (the offset opened by
/// [`OPEN_SHARE`] of a spacing), and the part it drops goes to `gaps`, to be filled by beads
/// as wide as it is ([`FilledLayer::gaps`]). The same goes for parts of the region narrower
/// than a bead, which the first ring cannot reach at all.
///
/// Each ring is offset from the one before rather than from `base` (a large offset that
/// collapses a many-sided polygon costs i_overlay time quadratic in its vertices: a 256-gon
/// disk took 0.7 s at its radius). With `thin`, rings after the first are simplified within
/// the chord tolerance, so that inner rings are not as dense as the boundary (contour fill,
/// where rings go all the way in); contour-zig-zag keeps its few perimeters exact, so its
/// infill lines end exactly on the offset boundary.
fn rings(
    base: &Shapes,
    ctx: &Ctx,
    max: usize,
    thin: bool,
    out: &mut Vec<Path2>,
    gaps: &mut Shapes,
) -> Shapes {
    let half = 0.5 * ctx.spacing;
    let slack = 0.25 * ctx.width;
    let mut cur = erode(base, 0.5 * ctx.width, &ctx.join);
    // Whether the offset that made `cur` dropped part of what lay before it, and the ring
    // before (`None`: the region's boundary, where the first ring's beads reach).
    let mut lost = !clean_offset(base, &cur, 0.5 * ctx.width, slack);
    let mut before: Option<Shapes> = None;
    let mut k = 0;
    while !cur.is_empty() && k < max {
        let mut next = erode(&cur, ctx.spacing, &ctx.join);
        let clean = clean_offset(&cur, &next, ctx.spacing, slack);
        let ring = if clean {
            cur.clone()
        } else {
            opening(&cur, OPEN_SHARE * ctx.spacing, ctx)
        };
        let opened = !clean && shapes_area(&ring) < shapes_area(&cur) - 1e-9;
        if lost || opened {
            let edge = match &before {
                Some(b) => erode(b, half, &ctx.join),
                None => base.clone(),
            };
            let strips = gap(&edge, &ring, half, ctx);
            if opened || before.is_none() {
                // Where a ring was dropped (a bead to two beads wide) or the first ring cannot
                // reach (parts of the region narrower than a bead): beads as wide as it.
                gaps.extend(strips);
            } else {
                line_fill(strips, ctx, out);
            }
        }
        for c in ring.iter().flatten() {
            let mut pts = c.clone();
            pts.push(c[0]);
            out.push(Path2 {
                points: pts,
                kind: PathKind::Perimeter,
            });
        }
        lost = !clean;
        if thin {
            next = simplify(next, ctx.tol);
        }
        before = Some(ring);
        cur = next;
        k += 1;
    }
    // Between the last ring and the infill area (or nothing).
    if let (true, Some(b)) = (lost, &before) {
        line_fill(gap(&erode(b, half, &ctx.join), &cur, half, ctx), ctx, out);
    }
    cur
}

/// Fills strips narrower than a bead (the middle rings leave) with lines along each strip's
/// long axis, `spacing` apart.
fn line_fill(strips: Shapes, ctx: &Ctx, out: &mut Vec<Path2>) {
    for shape in strips {
        let angle = principal_angle(&shape);
        scan_fill(&vec![shape], angle, ctx.spacing, true, None, out);
    }
}

/// A ring keeps only the parts of its offset at least `2 · OPEN_SHARE` spacings wide: where
/// the offset is narrower, the ring's beads from either side overlap by more than a tenth of
/// a bead (a ring about a part exactly a spacing wide covers it, beads edge to edge).
const OPEN_SHARE: f64 = 0.45;

/// `cur` without its parts narrower than `2·d`: eroded by `d` and grown back by `d` with
/// mitred corners, so that convex corners come back sharp (bevelled only past 9°), and
/// clipped to `cur` (a mitre grown from where the erosion pinched a neck would stick out).
fn opening(cur: &Shapes, d: f64, ctx: &Ctx) -> Shapes {
    let core = erode(cur, d, &ctx.join);
    if core.is_empty() {
        return core;
    }
    let grown = dilate_sharp(&core, d);
    drop_specks(grown.overlay(cur, OverlayRule::Intersect, FillRule::NonZero))
}

/// What lies inside `edge` (the inner edge of the beads so far, or the region's boundary) but
/// outside the beads of the next ring (or the infill lines' strips) about `next`, which reach
/// `half` beyond it: strips where the region is too narrow for another ring. Strips thinner
/// than a quarter bead are left (the beads' squash covers them).
fn gap(edge: &Shapes, next: &Shapes, half: f64, ctx: &Ctx) -> Shapes {
    if edge.is_empty() {
        return Vec::new();
    }
    let covered = dilate_sharp(next, half);
    let min_area = 0.25 * ctx.width * ctx.width;
    // `covered` lies inside `edge` (an opening is inside its set), so the gap's area is the
    // difference of the areas: skip the boolean when there is nothing worth filling.
    if shapes_area(edge) - shapes_area(&covered) < min_area {
        return Vec::new();
    }
    let gap = if covered.is_empty() {
        edge.clone()
    } else {
        edge.overlay(&covered, OverlayRule::Difference, FillRule::NonZero)
    };
    gap.into_iter()
        .filter(|shape| {
            let a: f64 = shape.iter().map(|c| 0.5 * area2(c)).sum();
            let p: f64 = shape.iter().map(|c| perimeter(c)).sum();
            a >= min_area && 2.0 * a / p >= 0.25 * ctx.width
        })
        .collect()
}

/// True when `next` is `cur` offset inward by `d` with nothing lost: as many contours, and the
/// perimeter a parallel offset gives (each convex corner of turn θ shortens it by
/// `2·d·tan(θ/2)`, each reflex one lengthens it by an arc `d·|θ|`) within `slack`. Where part
/// of `cur` is too thin to survive the offset, the perimeter drops by about twice that part's
/// length, so a gap worth filling (longer than a quarter bead) shows; this spares the gap
/// test's two offsets and boolean on every ring.
fn clean_offset(cur: &Shapes, next: &Shapes, d: f64, slack: f64) -> bool {
    let count = |s: &Shapes| s.iter().map(|sh| sh.len()).sum::<usize>();
    if count(cur) != count(next) {
        return false;
    }
    let mut expect = 0.0;
    for c in cur.iter().flatten() {
        let n = c.len();
        expect += perimeter(c);
        for i in 0..n {
            let (a, b, q) = (c[(i + n - 1) % n], c[i], c[(i + 1) % n]);
            let u = [b[0] - a[0], b[1] - a[1]];
            let v = [q[0] - b[0], q[1] - b[1]];
            // Turn angle at b, positive to the left (towards the region: convex).
            let t = (u[0] * v[1] - u[1] * v[0]).atan2(u[0] * v[0] + u[1] * v[1]);
            if t > 0.0 {
                expect -= 2.0 * d * (0.5 * t).tan();
            } else {
                expect -= d * t;
            }
        }
    }
    let got: f64 = next.iter().flatten().map(|c| perimeter(c)).sum();
    (got - expect).abs() <= slack
}

/// Direction (radians) of a shape's long axis, from its second moments of area.
fn principal_angle(shape: &Shape) -> f64 {
    let o = shape
        .first()
        .and_then(|c| c.first())
        .copied()
        .unwrap_or([0.0; 2]);
    let (mut a, mut sx, mut sy, mut sxx, mut syy, mut sxy) = (0.0, 0.0, 0.0, 0.0, 0.0, 0.0);
    for c in shape {
        let n = c.len();
        for i in 0..n {
            let (x0, y0) = (c[i][0] - o[0], c[i][1] - o[1]);
            let (x1, y1) = (c[(i + 1) % n][0] - o[0], c[(i + 1) % n][1] - o[1]);
            let cr = x0 * y1 - x1 * y0;
            a += cr / 2.0;
            sx += (x0 + x1) * cr / 6.0;
            sy += (y0 + y1) * cr / 6.0;
            sxx += (x0 * x0 + x0 * x1 + x1 * x1) * cr / 12.0;
            syy += (y0 * y0 + y0 * y1 + y1 * y1) * cr / 12.0;
            sxy += (x0 * y1 + 2.0 * x0 * y0 + 2.0 * x1 * y1 + x1 * y0) * cr / 24.0;
        }
    }
    if a.abs() < 1e-300 {
        return 0.0;
    }
    let (cx, cy) = (sx / a, sy / a);
    let mxx = sxx - a * cx * cx;
    let myy = syy - a * cy * cy;
    let mxy = sxy - a * cx * cy;
    let t = 0.5 * (2.0 * mxy).atan2(mxx - myy);
    if t.is_finite() {
        t
    } else {
        0.0
    }
}

/// A boundary ring of the infill area, in the scan frame.
struct Ring {
    pts: Vec<Point2>,
    /// Arc length from the first point to each point.
    cum: Vec<f64>,
    len: f64,
}

/// One end of a scan segment, on a boundary ring.
#[derive(Clone, Copy)]
struct End {
    seg: usize,
    /// 0: the low-x end, 1: the high-x end (scan frame).
    side: u8,
    ring: usize,
    edge: usize,
    /// Arc length along the ring.
    pos: f64,
    p: Point2,
}

/// The region whose boundary the free ends of [`scan_fill`]'s lines run on to
/// ([`bead_end_reach`]), and the bead width.
#[derive(Clone, Copy)]
struct Reach<'a> {
    base: &'a Shapes,
    width: f64,
}

/// Lines `spacing` apart at angle `angle` (radians from +x) across `area`, clipped to it.
/// With `join`, neighbouring lines of a connected piece are chained along the boundary
/// (zig-zag); without, each line is its own path, printed in the +angle direction. With
/// `reach`, the ends left free (every end without `join`, a chain's first and last with it)
/// run on past `area`'s edge towards the boundary of `reach.base`.
fn scan_fill(
    area: &Shapes,
    angle: f64,
    spacing: f64,
    join: bool,
    reach: Option<Reach>,
    out: &mut Vec<Path2>,
) {
    if area.is_empty() {
        return;
    }
    let (sn, cs) = angle.sin_cos();
    let rot = |p: Point2| [p[0] * cs + p[1] * sn, -p[0] * sn + p[1] * cs];
    let unrot = |p: Point2| [p[0] * cs - p[1] * sn, p[0] * sn + p[1] * cs];
    let mut rings: Vec<Ring> = Vec::new();
    let (mut ymin, mut ymax) = (f64::INFINITY, -f64::INFINITY);
    for c in area.iter().flatten() {
        if c.len() < 3 {
            continue;
        }
        let pts: Vec<Point2> = c.iter().map(|&p| rot(p)).collect();
        let mut cum = Vec::with_capacity(pts.len());
        let mut l = 0.0;
        for i in 0..pts.len() {
            cum.push(l);
            l += dist(pts[i], pts[(i + 1) % pts.len()]);
            ymin = ymin.min(pts[i][1]);
            ymax = ymax.max(pts[i][1]);
        }
        rings.push(Ring { pts, cum, len: l });
    }
    let h = ymax - ymin;
    let eps = 1e-9 * (1.0 + ymin.abs().max(ymax.abs()));
    let lines = h / spacing;
    if h.is_nan() || h <= 2.0 * eps || lines.is_nan() || lines >= MAX_LINES {
        return;
    }
    // Lines centred on the area's extent; the outermost pulled a hair inside so a line on a
    // boundary edge still cuts the area.
    let n = (h / spacing + 1e-9).floor() as usize + 1;
    let y0 = ymin + 0.5 * (h - (n - 1) as f64 * spacing);
    let ys: Vec<f64> = (0..n)
        .map(|j| (y0 + j as f64 * spacing).clamp(ymin + eps, ymax - eps))
        .collect();

    // Crossings of every line with every edge (half-open in y, so vertices count once).
    let mut hits: Vec<Vec<(f64, usize, usize, f64)>> = vec![Vec::new(); n];
    for (ri, r) in rings.iter().enumerate() {
        let m = r.pts.len();
        for i in 0..m {
            let (p, q) = (r.pts[i], r.pts[(i + 1) % m]);
            if p[1] == q[1] {
                continue;
            }
            let (lo, hi) = if p[1] < q[1] {
                (p[1], q[1])
            } else {
                (q[1], p[1])
            };
            let el = dist(p, q);
            let mut j = ys.partition_point(|&y| y < lo);
            while j < n && ys[j] < hi {
                let t = (ys[j] - p[1]) / (q[1] - p[1]);
                let x = p[0] + t * (q[0] - p[0]);
                hits[j].push((x, ri, i, r.cum[i] + t * el));
                j += 1;
            }
        }
    }

    // Segments: even-odd pairs of crossings along each line.
    let mut ends: Vec<End> = Vec::new();
    let mut segs: Vec<(usize, [usize; 2])> = Vec::new();
    let mut by_line: Vec<Vec<usize>> = vec![Vec::new(); n];
    for (j, hs) in hits.iter_mut().enumerate() {
        hs.sort_by(|a, b| a.0.total_cmp(&b.0));
        for pair in hs.chunks_exact(2) {
            let (a, b) = (pair[0], pair[1]);
            if b.0 - a.0 <= 1e-9 || b.0.is_nan() || a.0.is_nan() {
                continue;
            }
            let sid = segs.len();
            let mk = |h: (f64, usize, usize, f64), side| End {
                seg: sid,
                side,
                ring: h.1,
                edge: h.2,
                pos: h.3,
                p: [h.0, ys[j]],
            };
            ends.push(mk(a, 0));
            ends.push(mk(b, 1));
            segs.push((j, [ends.len() - 2, ends.len() - 1]));
            by_line[j].push(sid);
        }
    }
    // Where a free end runs on to (in the scan frame): along its line, outward, to the
    // boundary of `reach.base`, but no more than half the way to the next piece of the line.
    let mut slot = vec![0usize; segs.len()];
    for line in &by_line {
        for (k, &sid) in line.iter().enumerate() {
            slot[sid] = k;
        }
    }
    let run_on = |e: usize| -> Point2 {
        let end = ends[e];
        let Some(Reach { base, width }) = reach else {
            return end.p;
        };
        let line = &by_line[segs[end.seg].0];
        let k = slot[end.seg];
        let (out, room) = if end.side == 0 {
            let room = k.checked_sub(1).map_or(f64::INFINITY, |i| {
                0.5 * (end.p[0] - ends[segs[line[i]].1[1]].p[0])
            });
            (-1.0, room)
        } else {
            let room = line.get(k + 1).map_or(f64::INFINITY, |&i| {
                0.5 * (ends[segs[i].1[0]].p[0] - end.p[0])
            });
            (1.0, room)
        };
        let r = ray_to_boundary(base, unrot(end.p), [out * cs, out * sn])
            .map_or(0.0, |b| bead_end_reach(width, b, room));
        [end.p[0] + out * r, end.p[1]]
    };
    if !join {
        for &(_, [a, b]) in &segs {
            out.push(Path2 {
                points: vec![unrot(run_on(a)), unrot(run_on(b))],
                kind: PathKind::Infill,
            });
        }
        return;
    }

    // Ends in order along each ring: neighbours there have no other line ending between them.
    let mut order: Vec<Vec<usize>> = vec![Vec::new(); rings.len()];
    for (e, end) in ends.iter().enumerate() {
        order[end.ring].push(e);
    }
    let mut rank = vec![0usize; ends.len()];
    for o in order.iter_mut() {
        o.sort_by(|&a, &b| ends[a].pos.total_cmp(&ends[b].pos));
        for (k, &e) in o.iter().enumerate() {
            rank[e] = k;
        }
    }
    let cap = 10.0 * spacing;
    let mut used = vec![false; segs.len()];
    for line in &by_line {
        for &start in line {
            if used[start] {
                continue;
            }
            used[start] = true;
            let [a, b] = segs[start].1;
            let mut pts = vec![run_on(a), ends[b].p];
            let mut exit = b;
            loop {
                let e = ends[exit];
                let r = &rings[e.ring];
                let o = &order[e.ring];
                let m = o.len();
                let mut best: Option<(f64, usize, bool)> = None;
                for (forward, nb) in [
                    (true, o[(rank[exit] + 1) % m]),
                    (false, o[(rank[exit] + m - 1) % m]),
                ] {
                    let c = ends[nb];
                    if nb == exit
                        || used[c.seg]
                        || segs[c.seg].0 != segs[e.seg].0 + 1
                        || c.side != e.side
                    {
                        continue;
                    }
                    let len = if forward {
                        (c.pos - e.pos).rem_euclid(r.len)
                    } else {
                        (e.pos - c.pos).rem_euclid(r.len)
                    };
                    if len <= cap && best.is_none_or(|(l, _, _)| len < l) {
                        best = Some((len, nb, forward));
                    }
                }
                let Some((len, nb, forward)) = best else {
                    break;
                };
                connector(r, e, len, forward, &mut pts);
                let c = ends[nb];
                pts.push(c.p);
                let other = segs[c.seg].1[1 - c.side as usize];
                pts.push(ends[other].p);
                used[c.seg] = true;
                exit = other;
            }
            if let Some(last) = pts.last_mut() {
                *last = run_on(exit);
            }
            out.push(Path2 {
                points: pts.into_iter().map(unrot).collect(),
                kind: PathKind::Infill,
            });
        }
    }
}

/// Pushes the ring's vertices strictly between end `e` and the point `len` further along the
/// ring (forward or backward).
fn connector(r: &Ring, e: End, len: f64, forward: bool, pts: &mut Vec<Point2>) {
    let m = r.pts.len();
    let tiny = 1e-9 * (1.0 + r.len);
    let mut idx = if forward { (e.edge + 1) % m } else { e.edge };
    for _ in 0..m {
        let d = if forward {
            (r.cum[idx] - e.pos).rem_euclid(r.len)
        } else {
            (e.pos - r.cum[idx]).rem_euclid(r.len)
        };
        // A vertex at the end itself (the line crossed exactly there) is skipped.
        if d > tiny && d < r.len - tiny {
            if d >= len - tiny {
                break;
            }
            pts.push(r.pts[idx]);
        }
        idx = if forward {
            (idx + 1) % m
        } else {
            (idx + m - 1) % m
        };
    }
}

/// Orders paths to keep travel short (greedy nearest start/end from `start`, reversing open
/// paths where that is shorter) and returns them in print order.
///
/// Closed paths are entered at their first point and kept as they are; empty paths go last.
/// Reversing open paths means raster lines no longer all run the same way: keep
/// [`fill_layer`]'s order for raster when that matters.
pub fn order_paths(paths: Vec<Path2>, start: Point2) -> Vec<Path2> {
    let (todo, empty): (Vec<Path2>, Vec<Path2>) =
        paths.into_iter().partition(|p| !p.points.is_empty());
    let mut out = order_greedy(todo, start, |p| &p.points, |p| p.points.reverse());
    out.extend(empty);
    out
}

/// The greedy order of [`order_paths`] for any path type: `points` gives a path's (non-empty)
/// polyline, closed when it ends where it starts; `reverse` turns a path round (with anything
/// it carries per point).
pub fn order_greedy<T>(
    paths: Vec<T>,
    start: Point2,
    points: impl Fn(&T) -> &[Point2],
    reverse: impl Fn(&mut T),
) -> Vec<T> {
    let mut todo: Vec<Option<T>> = paths
        .into_iter()
        .filter(|p| !points(p).is_empty())
        .map(Some)
        .collect();
    let mut out = Vec::with_capacity(todo.len());
    let d = |a: Point2, b: Point2| {
        let v = dist(a, b);
        if v.is_nan() {
            f64::INFINITY
        } else {
            v
        }
    };
    let mut cur = start;
    for _ in 0..todo.len() {
        // (distance, index, reverse); ties go to the earlier path.
        let mut best: Option<(f64, usize, bool)> = None;
        for (i, p) in todo.iter().enumerate() {
            let Some(p) = p else { continue };
            let pts = points(p);
            let ds = d(cur, pts[0]);
            if best.is_none_or(|b| ds < b.0) {
                best = Some((ds, i, false));
            }
            let closed = pts.len() > 2 && pts.first() == pts.last();
            if !closed {
                let de = d(cur, pts[pts.len() - 1]);
                if best.is_none_or(|b| de < b.0) {
                    best = Some((de, i, true));
                }
            }
        }
        let Some((_, i, rev)) = best else { break };
        let Some(mut p) = todo[i].take() else { break };
        if rev {
            reverse(&mut p);
        }
        let pts = points(&p);
        cur = pts[pts.len() - 1];
        out.push(p);
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    fn circle(r: f64, n: usize) -> Contour {
        (0..n)
            .map(|i| {
                let t = 2.0 * PI * i as f64 / n as f64;
                [r * t.cos(), r * t.sin()]
            })
            .collect()
    }

    #[test]
    fn simplify_keeps_shape_within_tolerance() {
        let c = circle(1.0, 512);
        let s = simplify_ring(c.clone(), 1e-3);
        assert!(s.len() <= 128 && s.len() > 10, "{}", s.len());
        // Kept points are original points; every dropped one is within tol of the outline.
        assert!(s.iter().all(|p| c.contains(p)));
        for p in &c {
            let n = s.len();
            let d = (0..n)
                .map(|i| seg_dist(*p, s[i], s[(i + 1) % n]))
                .fold(f64::INFINITY, f64::min);
            assert!(d <= 1e-3 + 1e-12);
        }
        // Small polygons are left alone.
        let sq = vec![[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]];
        assert_eq!(simplify_ring(sq.clone(), 0.5), sq);
    }

    #[test]
    fn clean_offset_spots_lost_parts() {
        let sq: Shapes = vec![vec![vec![
            [0.0, 0.0],
            [10.0, 0.0],
            [10.0, 10.0],
            [0.0, 10.0],
        ]]];
        let join = round_join(0.004, 5.0);
        let next = erode(&sq, 0.4, &join);
        assert!(clean_offset(&sq, &next, 0.4, 0.1));
        // A thin tab on the side vanishes: the perimeter drops by about twice its length.
        let tab: Shapes = vec![vec![vec![
            [0.0, 0.0],
            [10.0, 0.0],
            [10.0, 4.8],
            [15.0, 4.8],
            [15.0, 5.2],
            [10.0, 5.2],
            [10.0, 10.0],
            [0.0, 10.0],
        ]]];
        let next = erode(&tab, 0.4, &join);
        assert!(!clean_offset(&tab, &next, 0.4, 0.1));
        assert!(!clean_offset(&sq, &Vec::new(), 0.4, 0.1));
    }

    #[test]
    fn principal_angle_follows_the_long_side() {
        let strip: Shape = vec![vec![[0.0, 0.0], [10.0, 10.0], [9.0, 11.0], [-1.0, 1.0]]];
        let a = principal_angle(&strip);
        assert!(
            (a - PI / 4.0).abs() < 1e-9 || (a + 3.0 * PI / 4.0).abs() < 1e-9,
            "{a}"
        );
        assert!(min_width(&strip[0]) < 1.5);
    }

    #[test]
    fn drop_flat_keeps_the_corners() {
        // A square with collinear and nearly repeated points on its sides, one at the start.
        let c = vec![
            [5.0, 0.0],
            [10.0, 0.0],
            [10.0, 3.0],
            [10.0, 3.0 + 1e-12],
            [10.0, 10.0],
            [0.0, 10.0],
            [1e-13, 4.0],
            [0.0, 0.0],
        ];
        let sq = vec![[10.0, 0.0], [10.0, 10.0], [0.0, 10.0], [0.0, 0.0]];
        assert_eq!(drop_flat(&c, 1e-6, 1e-9), sq);
        assert_eq!(drop_flat(&sq, 1e-6, 1e-9), sq);
        // A turn under the limit goes however far the vertex stands off its chord.
        let kink = vec![[0.0, 0.0], [500.0, 1e-4], [1000.0, 0.0], [500.0, 500.0]];
        assert_eq!(drop_flat(&kink, 1e-6, 1e-9).len(), 3);
        assert_eq!(drop_flat(&kink, 1e-7, 1e-9).len(), 4);
        // Nothing sensible left: the contour as it was.
        let sliver = vec![[0.0, 0.0], [1.0, 1e-12], [2.0, 0.0]];
        assert_eq!(drop_flat(&sliver, 1e-6, 1e-9), sliver);
    }

    #[test]
    fn short_segments_go_ends_stay() {
        let mut ring = vec![
            [0.0, 0.0],
            [1.0, 0.0],
            [1.0, 1e-7],
            [1.0, 1.0],
            [1e-7, 1.0],
            [0.0, 1.0],
            [0.0, 1e-7],
            [0.0, 0.0],
        ];
        drop_short_segments(&mut ring);
        // Each point is judged against the one kept before it; the ends stay.
        assert_eq!(
            ring,
            vec![[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [1e-7, 1.0], [0.0, 0.0]]
        );
        let mut dot = vec![[2.0, 2.0], [2.0, 2.0 + 1e-7]];
        drop_short_segments(&mut dot);
        assert_eq!(dot.len(), 1);
    }

    #[test]
    fn erode_drops_what_cannot_survive() {
        let join = round_join(0.004, 1.0);
        let small: Shapes = vec![vec![circle(0.2, 256)]];
        assert!(erode(&small, 0.2, &join).is_empty());
        assert!(erode(&small, 0.25, &join).is_empty());
        assert_eq!(erode(&small, 0.1, &join).len(), 1);
    }
}
