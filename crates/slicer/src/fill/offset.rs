//! Offsets of i_overlay shapes: inward (erosion) and outward, with round or sharp joins;
//! simplification of the contours they give, and the check that an offset lost nothing.

use super::region::{bounds, region_shapes};
use super::{Contour, Shapes};
use crate::geom2d::{area2, dist, perimeter, peucker_by, seg_dist, Point2, Region};
use crate::tolerance::{EMPTY_AREA2, ROUND_OFF};
use i_overlay::mesh::float::outline::offset::OutlineOffset;
use i_overlay::mesh::float::style::{LineJoin, OutlineStyle};
use i_overlay::mesh::math::MathMode;
use std::f64::consts::PI;

/// True when no point of `region` lies `depth` or more inside its boundary (its inward offset
/// by `depth` is empty): a region too thin for that many beads side by side.
pub fn thinner_than(region: &Region, depth: f64) -> bool {
    let base = region_shapes(region);
    base.is_empty() || erode(&base, depth, &round_join(0.01 * depth, depth)).is_empty()
}

/// Join for inward offsets: reflex corners of the region become arcs, chorded within `tol` up
/// to radius `radius` (the deepest offset the fill will make).
pub(super) fn round_join(tol: f64, radius: f64) -> LineJoin<f64> {
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
pub(super) fn erode(base: &Shapes, d: f64, join: &LineJoin<f64>) -> Shapes {
    if base.is_empty() || !(d.is_finite() && d >= 0.0) {
        return Vec::new();
    }
    let survivors: Shapes = base
        .iter()
        .filter(|shape| {
            shape
                .first()
                .is_some_and(|outer| min_width(outer) > 2.0 * d * (1.0 + ROUND_OFF))
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
pub(super) fn offset(base: &Shapes, d: f64, join: &LineJoin<f64>, reach: f64) -> Shapes {
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
pub(super) fn min_width(pts: &[Point2]) -> f64 {
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
pub(super) fn simplify(shapes: Shapes, tol: f64) -> Shapes {
    shapes
        .into_iter()
        .map(|shape| shape.into_iter().map(|c| simplify_ring(c, tol)).collect())
        .collect()
}

/// `regions` with each ring, outer and holes, simplified within `tol` ([`simplify_ring`]: the
/// vertices kept are original ones; a ring that would lose its area is kept whole).
pub(crate) fn simplified(regions: Vec<Region>, tol: f64) -> Vec<Region> {
    regions
        .into_iter()
        .map(|r| Region {
            outer: simplify_ring(r.outer, tol),
            holes: r.holes.into_iter().map(|h| simplify_ring(h, tol)).collect(),
        })
        .collect()
}

/// An open polyline without the points that lie within `tol` of the chord that replaces
/// them (Douglas–Peucker, [`peucker`]): the gyroid's samples along its straighter stretches, a
/// zig-zag connector's run along an offset's arcs.
pub(super) fn simplify_line(pts: &[Point2], tol: f64) -> Vec<Point2> {
    let n = pts.len();
    if n < 3 || tol.is_nan() || tol <= 0.0 {
        return pts.to_vec();
    }
    let mut keep = vec![false; n];
    keep[0] = true;
    keep[n - 1] = true;
    // Walked from the last point, so that of points equally far from a chord the last is
    // kept (as this simplification always has; `peucker` keeps the first it meets).
    peucker(|k| pts[n - 1 - k], vec![(0, n - 1)], tol, &mut keep);
    pts.iter()
        .zip(keep.iter().rev())
        .filter_map(|(p, k)| k.then_some(*p))
        .collect()
}

/// Douglas–Peucker over the chains `spans` (`(i, j)`: the points `at(i)` to `at(j)`, both
/// kept already): in each, the point farthest from the chord (the first of equals) is kept
/// when it lies more than `tol` from it, and the two chains it splits into are done alike.
fn peucker(at: impl Fn(usize) -> Point2, spans: Vec<(usize, usize)>, tol: f64, keep: &mut [bool]) {
    peucker_by(spans, keep, |i, j| {
        let (a, b) = (at(i), at(j));
        let (mut worst, mut far) = (-1.0, i);
        for k in i + 1..j {
            let d = seg_dist(at(k), a, b);
            if d > worst {
                worst = d;
                far = k;
            }
        }
        (worst > tol).then_some(far)
    });
}

/// Douglas-Peucker on one closed contour (see [`simplify`]): every dropped vertex lies within
/// `tol` of the contour left, whose vertices are original ones. Contours of four points or
/// fewer, and any that would lose all their area, come back as they were.
pub(super) fn simplify_ring(c: Contour, tol: f64) -> Contour {
    let n = c.len();
    if n <= 4 {
        return c;
    }
    // Split at vertex 0 and the vertex farthest from it; simplify both chains (the second
    // closes back to vertex 0, index `n`).
    let far = (1..n)
        .max_by(|&a, &b| dist(c[0], c[a]).total_cmp(&dist(c[0], c[b])))
        .unwrap_or(n / 2);
    let mut keep = vec![false; n];
    keep[0] = true;
    keep[far] = true;
    peucker(|k| c[k % n], vec![(0, far), (far, n)], tol, &mut keep);
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
pub(super) fn dilate_sharp(base: &Shapes, d: f64) -> Shapes {
    if base.is_empty() || !(d.is_finite() && d >= 0.0) {
        return Vec::new();
    }
    // A mitre reaches d / sin(θ / 2) at a corner of angle θ: at most 14 d, as i_overlay
    // bevels corners sharper than this 9°.
    offset(base, d, &LineJoin::Miter(0.05 * PI), 14.0)
}

/// Drops contours with fewer than three points and shapes whose outer contour has no area.
pub(super) fn drop_specks(shapes: Shapes) -> Shapes {
    shapes
        .into_iter()
        .filter_map(|shape| {
            let mut it = shape.into_iter().filter(|c| c.len() >= 3);
            let outer = it.next()?;
            if area2(&outer).abs() <= EMPTY_AREA2 {
                return None;
            }
            let mut s = vec![outer];
            s.extend(it);
            Some(s)
        })
        .collect()
}

/// True when `next` is `cur` offset inward by `d` with nothing lost: as many contours, and the
/// perimeter a parallel offset gives (each convex corner of turn θ shortens it by
/// `2·d·tan(θ/2)`, each reflex one lengthens it by an arc `d·|θ|`) within `slack`. Where part
/// of `cur` is too thin to survive the offset, the perimeter drops by about twice that part's
/// length, so a gap worth filling (longer than a quarter bead) shows; this spares the gap
/// test's two offsets and boolean on every ring.
pub(super) fn clean_offset(cur: &Shapes, next: &Shapes, d: f64, slack: f64) -> bool {
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
    fn erode_drops_what_cannot_survive() {
        let join = round_join(0.004, 1.0);
        let small: Shapes = vec![vec![circle(0.2, 256)]];
        assert!(erode(&small, 0.2, &join).is_empty());
        assert!(erode(&small, 0.25, &join).is_empty());
        assert_eq!(erode(&small, 0.1, &join).len(), 1);
    }
}
