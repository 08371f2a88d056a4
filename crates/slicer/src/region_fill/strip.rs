//! The gap fill of a planar strip without rings, from its chordal axis: the strip's own
//! boundary triangulated (a few points per strip width), the triangles crossing it chained end
//! to end and fork to fork, and one bead laid through the middles of the edges they cross, as
//! wide as the strip there. It lays what [`super::gap::gap_fill`] lays on such a strip (one bead on the ridge,
//! 2β wide, the narrow ends left out, extruded for the strip's area) without the lattice, the
//! distance field and the ridge search under it.
//!
//! Why: the strips the rings of a planar contour fill leave between them are a fraction of a
//! bead wide and up to the part's whole perimeter long; their lattice holds (steps across)² ×
//! length over width vertices (a 0.2 mm strip 310 mm long, 28,000), and NIST CTC-05's contour
//! fill spent 54 of its 113 s of strip fills on 447 such strips, 0.3 s each. Their boundary
//! triangulated holds some 3,000 points.
//!
//! Strips this does not take (a hole, a part wide enough for a ring or two beads, a polygon
//! that crosses itself) are left to the lattice: [`strip_fill`] says `None`.

use super::gap::{MIN_STEP_SHARE, SINGLE_BEAD_MAX, SINGLE_MIN_SHARE, SINGLE_MIN_WIDTH};
use super::thin_out::{thin_out, THIN_LINE_SHARE, THIN_WIDTH_SHARE};
use super::{scale_to_area, FillPath};
use crate::fast_hash::FastMap;
use crate::geom2d::{dist, perimeter, region_area, Point2, Region, RegionIndex};
use crate::toolpath::Role;
use spade::{ConstrainedDelaunayTriangulation, Point2 as SPoint, Triangulation};

/// The boundary's points are at most this share of the strip's mean width apart (twice its
/// area over its perimeter): the triangles then cross the strip, each with one side on the
/// boundary, rather than run along it.
const RESAMPLE_SHARE: f64 = 0.75;

/// Triangles smaller than this share of the resampling step squared are slivers of
/// round-off between points of a straight side, not the strip's ([`chordal_axis`]).
const SLIVER_AREA: f64 = 1e-6;

/// The finest resampling step, in bead widths (a strip thinner than this share of a bead
/// over its length gets its points no closer: the lattice's finest step is about as fine).
const FINEST_STEP_SHARE: f64 = 0.01;

/// The most boundary points a strip is triangulated with; a longer or thinner strip is left
/// to the lattice.
const MAX_POINTS: usize = 400_000;

/// The widest a strip may be anywhere, in bead widths, for this fill: one bead on its ridge
/// ([`SINGLE_BEAD_MAX`]), where the lattice's fill lays no ring (a ring takes a strip whose
/// half width reaches 0.6 of a bead: `ring_levels`).
const WIDEST_SHARE: f64 = SINGLE_BEAD_MAX;

/// The gap fill of `region` (planar, in mm) for beads `width` wide, no narrower than
/// `min_width` (the gap's narrowest flank bead, as [`super::gap::Gap::min_width`]): beads
/// along the strip's chordal axis, as wide as the strip at each point, tapering into each end
/// down to the narrowest bead a single bead on a ridge gets, then widened or narrowed (by at
/// most [`super::MAX_CORE_WIDENING`]) to put down the region's area. `rings` says whether the fill
/// would lay rings where the region is wide enough (a ring needs a half width of 0.6 of a
/// bead); without, a strip over a bead across gets infill lines, so only narrower strips are
/// taken. `None` where the strip is not one this fill takes (the module's docs).
pub(super) fn strip_fill(
    region: &Region,
    width: f64,
    min_width: f64,
    rings: bool,
) -> Option<Vec<FillPath>> {
    if !region.holes.is_empty() || region.outer.len() < 3 || width.is_nan() || width <= 0.0 {
        return None;
    }
    let area = region_area(region);
    let around = perimeter(&region.outer);
    if !(area > 0.0 && around > 0.0 && area.is_finite() && around.is_finite()) {
        return None;
    }
    let widest = if rings { WIDEST_SHARE } else { 1.0 } * width;
    if 2.0 * area / around > widest {
        return None;
    }
    let step = (RESAMPLE_SHARE * 2.0 * area / around).max(FINEST_STEP_SHARE * width);
    if around / step > MAX_POINTS as f64 {
        return None;
    }
    let axis = chordal_axis(region, step)?;
    if axis.iter().flatten().any(|(_, w)| *w > widest) {
        return None;
    }
    let mut paths = beads(&axis, width, min_width);
    // The strip's area put down ([`super::conserved`], whose held area is the whole region's).
    let covered: f64 = paths.iter().map(|p| p.strip_area(dist)).sum();
    scale_to_area(&mut paths, covered, area);
    Some(paths)
}

/// The single beads along the branches of `axis` (points and the strip's width there): split
/// where the strip is narrower than the narrowest single bead (a ridge's, [`SINGLE_MIN_SHARE`]
/// times `min_width`, or into a corner a quarter bead or half the strip's median width,
/// [`SINGLE_MIN_WIDTH`]), points closer than [`MIN_STEP_SHARE`] of a bead merged, the rest
/// thinned as the lattice's gap fill is ([`thin_out`]).
fn beads(axis: &[Vec<(Point2, f64)>], width: f64, min_width: f64) -> Vec<FillPath> {
    let mut widths: Vec<f64> = axis
        .iter()
        .flatten()
        .map(|(_, w)| *w)
        .filter(|w| *w > 0.0)
        .collect();
    widths.sort_by(f64::total_cmp);
    let median_half = widths.get(widths.len() / 2).map_or(0.0, |w| 0.5 * w);
    let narrowest = (SINGLE_MIN_SHARE * min_width).max((SINGLE_MIN_WIDTH * width).min(median_half));
    let mut out = vec![];
    for branch in axis {
        let mut cur = FillPath::empty(Role::GapFill);
        for &(q, w) in branch {
            if w < narrowest {
                let done = std::mem::replace(&mut cur, FillPath::empty(Role::GapFill));
                if done.points.len() >= 2 {
                    out.push(done);
                }
                continue;
            }
            if cur
                .points
                .last()
                .is_some_and(|&l| dist(l, q) < MIN_STEP_SHARE * width)
            {
                if let Some(last) = cur.widths.last_mut() {
                    *last = last.max(w);
                }
                continue;
            }
            cur.points.push(q);
            cur.widths.push(w);
        }
        if cur.points.len() >= 2 {
            out.push(cur);
        }
    }
    let (line, spread) = (THIN_LINE_SHARE * width, THIN_WIDTH_SHARE * width);
    out.into_iter()
        .map(|p| thin_out(p, |q| q, line, spread))
        .collect()
}

/// The chordal axis of a strip (a polygon without holes), branch by branch: its boundary
/// resampled `step` apart and triangulated (constrained Delaunay), each triangle inside with
/// two sides on the boundary (an end), one (a sleeve) or none (a fork); from each end or fork
/// along the sleeves to the next. A branch runs through the middles of the edges it crosses,
/// each with the strip's width there (the edge measured square to the branch), from a fork's
/// circumcentre (as wide as its circle) or an end's tip (tapering with the end's triangle).
/// `None` where the resampled points collide or the polygon crosses itself.
fn chordal_axis(region: &Region, step: f64) -> Option<Vec<Vec<(Point2, f64)>>> {
    let ring = resample(&region.outer, step);
    let n = ring.len();
    let mut cdt: ConstrainedDelaunayTriangulation<SPoint<f64>> =
        ConstrainedDelaunayTriangulation::new();
    let mut handles = Vec::with_capacity(n);
    for q in &ring {
        handles.push(cdt.insert(SPoint::new(q[0], q[1])).ok()?);
    }
    if cdt.num_vertices() != n {
        return None;
    }
    // Ring position of each triangulation vertex.
    let mut pos = vec![u32::MAX; n];
    for (i, h) in handles.iter().enumerate() {
        *pos.get_mut(h.index())? = i as u32;
    }
    for i in 0..n {
        let (a, b) = (handles[i], handles[(i + 1) % n]);
        if !cdt.can_add_constraint(a, b) {
            return None;
        }
        cdt.add_constraint(a, b);
    }
    if cdt.num_vertices() != n {
        return None;
    }
    // The triangles inside, less the slivers between neighbouring points of a straight side
    // (resampled points in a row are collinear only to round-off): such a sliver's chord then
    // borders one triangle, as the boundary's sides do.
    let inside = RegionIndex::new(region);
    let sliver = SLIVER_AREA * step * step;
    let mut tris: Vec<[u32; 3]> = vec![];
    for f in cdt.inner_faces() {
        let v = f.vertices().map(|v| pos[v.fix().index()]);
        let [a, b, c] = v.map(|i| ring[i as usize]);
        let twice = (b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0]);
        let centre = [(a[0] + b[0] + c[0]) / 3.0, (a[1] + b[1] + c[1]) / 3.0];
        if 0.5 * twice.abs() > sliver && inside.contains(centre) {
            tris.push(v);
        }
    }
    let (beside, sides) = pruned(&mut tris)?;
    Some(branches(&ring, &tris, &beside, &sides))
}

/// The branches of the chain of triangles `tris` (`beside`: the triangles on each side of
/// each edge; `sides`: each triangle's sides on the boundary), each from an end or a fork to
/// the next, as [`chordal_axis`] lays them.
fn branches(
    ring: &[Point2],
    tris: &[[u32; 3]],
    beside: &FastMap<(u32, u32), Vec<u32>>,
    sides: &[usize],
) -> Vec<Vec<(Point2, f64)>> {
    let across = |t: usize| -> Vec<(u32, u32)> {
        let v = tris[t];
        (0..3)
            .map(|k| key(v[k], v[(k + 1) % 3]))
            .filter(|e| beside.get(e).is_some_and(|ts| ts.len() == 2))
            .collect()
    };
    let other = |t: usize, e: (u32, u32)| -> Option<usize> {
        let ts = beside.get(&e)?;
        Some(if ts[0] as usize == t { ts[1] } else { ts[0] } as usize)
    };
    let at = |i: u32| ring[i as usize];
    let mut walked: crate::fast_hash::FastSet<(u32, u32)> = Default::default();
    let mut out = vec![];
    for start in (0..tris.len()).filter(|&t| sides[t] != 1) {
        for first in across(start) {
            if !walked.insert(first) {
                continue;
            }
            let mut crossed = vec![first];
            let (mut t, mut e) = (start, first);
            let end = loop {
                let Some(next) = other(t, e) else { break t };
                t = next;
                if sides[t] != 1 {
                    break t;
                }
                let Some(on) = across(t).into_iter().find(|&x| x != e) else {
                    break t;
                };
                crossed.push(on);
                e = on;
            };
            walked.insert(e);
            let head = node(ring, tris[start], sides[start], first);
            let tail = node(ring, tris[end], sides[end], e);
            out.push(branch_points(&at, &crossed, head, tail));
        }
    }
    out
}

/// Where a branch starts or ends in triangle `v` (entered by edge `e`): an end's tip (`Tip`)
/// or a fork's circumcentre with the width of its circle (`Fork`, the triangle's centroid and
/// its narrowest side where the circumcentre lies outside it).
enum Node {
    Tip(Point2),
    Fork(Point2, f64),
}

fn node(ring: &[Point2], v: [u32; 3], sides: usize, e: (u32, u32)) -> Node {
    let [a, b, c] = v.map(|i| ring[i as usize]);
    if sides == 2 {
        let tip = v
            .into_iter()
            .find(|&x| x != e.0 && x != e.1)
            .unwrap_or(v[0]);
        return Node::Tip(ring[tip as usize]);
    }
    // Circumcentre.
    let (bx, by, cx, cy) = (b[0] - a[0], b[1] - a[1], c[0] - a[0], c[1] - a[1]);
    let d = 2.0 * (bx * cy - by * cx);
    let (b2, c2) = (bx * bx + by * by, cx * cx + cy * cy);
    let o = [
        a[0] + (cy * b2 - by * c2) / d,
        a[1] + (bx * c2 - cx * b2) / d,
    ];
    let within = {
        let s =
            |p: Point2, q: Point2| (q[0] - p[0]) * (o[1] - p[1]) - (q[1] - p[1]) * (o[0] - p[0]);
        let (s0, s1, s2) = (s(a, b), s(b, c), s(c, a));
        (s0 >= 0.0 && s1 >= 0.0 && s2 >= 0.0) || (s0 <= 0.0 && s1 <= 0.0 && s2 <= 0.0)
    };
    if d.abs() > 0.0 && within && o.iter().all(|x| x.is_finite()) {
        Node::Fork(o, 2.0 * dist(o, a))
    } else {
        let centre = [(a[0] + b[0] + c[0]) / 3.0, (a[1] + b[1] + c[1]) / 3.0];
        Node::Fork(centre, dist(a, b).min(dist(b, c)).min(dist(c, a)))
    }
}

/// A branch's points: the middle of each edge `crossed` (ring indices, through `at`) with the
/// strip's width there (the edge measured square to the branch), from `head` to `tail`: into
/// a tip the end's triangle's taper, [`TIP_STEPS`] points to where the bead is [`TIP_SHARE`]
/// of its edge's width.
fn branch_points(
    at: &impl Fn(u32) -> Point2,
    crossed: &[(u32, u32)],
    head: Node,
    tail: Node,
) -> Vec<(Point2, f64)> {
    let mid = |(a, b): (u32, u32)| {
        let (p, q) = (at(a), at(b));
        [0.5 * (p[0] + q[0]), 0.5 * (p[1] + q[1])]
    };
    let m: Vec<Point2> = crossed.iter().map(|&e| mid(e)).collect();
    let point = |n: &Node| match n {
        Node::Tip(q) | Node::Fork(q, _) => *q,
    };
    let k = m.len();
    let widths: Vec<f64> = (0..k)
        .map(|i| {
            let before = if i == 0 { point(&head) } else { m[i - 1] };
            let after = if i + 1 == k { point(&tail) } else { m[i + 1] };
            let d = [after[0] - before[0], after[1] - before[1]];
            let len = d[0].hypot(d[1]);
            let (a, b) = (at(crossed[i].0), at(crossed[i].1));
            let e = [b[0] - a[0], b[1] - a[1]];
            let full = e[0].hypot(e[1]);
            if len > 0.0 {
                ((e[0] * d[1] - e[1] * d[0]).abs() / len).min(full)
            } else {
                full
            }
        })
        .collect();
    let taper = |from: Point2, w: f64, to: Point2| -> Vec<(Point2, f64)> {
        (1..=TIP_STEPS)
            .map(|j| {
                let f = (1.0 - TIP_SHARE) * j as f64 / TIP_STEPS as f64;
                let q = [
                    from[0] + f * (to[0] - from[0]),
                    from[1] + f * (to[1] - from[1]),
                ];
                (q, w * (1.0 - f))
            })
            .collect()
    };
    let mut out = Vec::with_capacity(k + 2 * TIP_STEPS);
    match head {
        Node::Tip(t) => out.extend(taper(m[0], widths[0], t).into_iter().rev()),
        Node::Fork(q, w) => out.push((q, w)),
    }
    out.extend(m.iter().copied().zip(widths.iter().copied()));
    match tail {
        Node::Tip(t) => out.extend(taper(m[k - 1], widths[k - 1], t)),
        Node::Fork(q, w) => out.push((q, w)),
    }
    out
}

/// Points laid into each end's tip past the last edge crossed.
const TIP_STEPS: usize = 4;
/// How far short of an end's tip its taper stops, as a share of the way from the last edge
/// crossed (where the bead would be that share of its edge's width).
const TIP_SHARE: f64 = 0.1;

/// An edge's key: its two vertices, the lower first.
fn key(a: u32, b: u32) -> (u32, u32) {
    (a.min(b), a.max(b))
}

/// The triangles on each side of each edge of `tris` (one: the boundary; two: an edge across)
/// and each triangle's sides on the boundary, once the corners' spurs are pruned: an end
/// triangle (two sides on the boundary) beside a fork (none) is dropped, as a square end's two
/// corners are (the medial axis of a rectangle forks into its corners a half width from its
/// end). `None` where a triangle has all three sides on the boundary (the strip is one
/// triangle, or a part of it lies apart) or an edge has more than two triangles.
#[allow(clippy::type_complexity)]
fn pruned(tris: &mut Vec<[u32; 3]>) -> Option<(FastMap<(u32, u32), Vec<u32>>, Vec<usize>)> {
    loop {
        let mut beside: FastMap<(u32, u32), Vec<u32>> = FastMap::default();
        for (t, v) in tris.iter().enumerate() {
            for k in 0..3 {
                beside
                    .entry(key(v[k], v[(k + 1) % 3]))
                    .or_default()
                    .push(t as u32);
            }
        }
        if beside.values().any(|ts| ts.len() > 2) {
            return None;
        }
        let across = |v: &[u32; 3], k: usize| {
            beside
                .get(&key(v[k], v[(k + 1) % 3]))
                .filter(|ts| ts.len() == 2)
        };
        let sides: Vec<usize> = tris
            .iter()
            .map(|v| (0..3).filter(|&k| across(v, k).is_none()).count())
            .collect();
        if sides.contains(&3) || tris.is_empty() {
            return None;
        }
        // Ends beside a fork: spurs.
        let spur: Vec<bool> = tris
            .iter()
            .zip(&sides)
            .map(|(v, &s)| {
                s == 2
                    && (0..3).any(|k| {
                        across(v, k).is_some_and(|ts| ts.iter().any(|&t| sides[t as usize] == 0))
                    })
            })
            .collect();
        if !spur.contains(&true) {
            return Some((beside, sides));
        }
        // Each pass drops triangles, so the loop ends.
        let mut keep = spur.iter().map(|s| !s);
        tris.retain(|_| keep.next().unwrap_or(true));
    }
}

/// A closed ring resampled so no segment is longer than `step` (first point not repeated).
fn resample(ring: &[Point2], step: f64) -> Vec<Point2> {
    let n = ring.len();
    let mut out = Vec::with_capacity(n);
    for i in 0..n {
        let (a, b) = (ring[i], ring[(i + 1) % n]);
        let k = (dist(a, b) / step).ceil().clamp(1.0, 1e6) as usize;
        for j in 0..k {
            let t = j as f64 / k as f64;
            out.push([a[0] + (b[0] - a[0]) * t, a[1] + (b[1] - a[1]) * t]);
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::super::MAX_CORE_WIDENING;
    use super::*;

    /// A strip `w` wide along an arc of radius `r` through `sweep` radians, `n` points a side.
    fn arc_strip(r: f64, w: f64, sweep: f64, n: usize) -> Region {
        let side = |rad: f64| -> Vec<Point2> {
            (0..=n)
                .map(|i| {
                    let t = sweep * i as f64 / n as f64;
                    [rad * t.cos(), rad * t.sin()]
                })
                .collect()
        };
        let mut outer = side(r + 0.5 * w);
        outer.extend(side(r - 0.5 * w).into_iter().rev());
        Region {
            outer,
            holes: vec![],
        }
    }

    /// A strip `w` wide about the wave `y = a·sin(x / l)` for x in 0..`len`, `n` points a side
    /// (its sides the wave moved square to itself by half the width).
    fn wavy_strip(a: f64, l: f64, w: f64, len: f64, n: usize) -> Region {
        let side = |s: f64| -> Vec<Point2> {
            (0..=n)
                .map(|i| {
                    let x = len * i as f64 / n as f64;
                    let slope = a / l * (x / l).cos();
                    let k = 0.5 * w * s / (1.0 + slope * slope).sqrt();
                    [x - k * slope, a * (x / l).sin() + k]
                })
                .collect()
        };
        let mut outer = side(-1.0);
        outer.extend(side(1.0).into_iter().rev());
        Region {
            outer,
            holes: vec![],
        }
    }

    /// The lattice's fill of a strip the rings leave (`fill_region` on the plane, as
    /// `fill_flat_region` lays it without this module), contour mode, 0.45 mm beads.
    fn lattice_fill(region: &Region) -> Vec<FillPath> {
        let plane = brep::surface::Surface::Plane {
            frame: brep::math::Frame::world(brep::math::P3::origin()),
        };
        let chart = crate::chart::Chart::unit(&plane);
        let params = crate::params::LayerParams {
            path_mode: crate::params::PathMode::Contour,
            ..Default::default()
        };
        super::super::fill_region(&chart, region, 0.0, &params, 0, 0.45, 0.45, 0.02 * 0.45)
    }

    /// The distance from `q` to the nearest segment of `paths`.
    fn off(q: Point2, paths: &[FillPath]) -> f64 {
        paths
            .iter()
            .flat_map(|p| p.points.windows(2))
            .map(|s| crate::geom2d::seg_dist(q, s[0], s[1]))
            .fold(f64::INFINITY, f64::min)
    }

    #[test]
    fn the_chordal_axis_lays_what_the_lattice_lays_on_plain_strips() {
        let t = Region {
            outer: vec![
                [0.0, 0.0],
                [10.0, 0.0],
                [10.0, 0.25],
                [5.125, 0.25],
                [5.125, 5.0],
                [4.875, 5.0],
                [4.875, 0.25],
                [0.0, 0.25],
            ],
            holes: vec![],
        };
        let wedge = Region {
            outer: vec![[0.0, -0.2], [12.0, 0.0], [0.0, 0.2]],
            holes: vec![],
        };
        let strips = [
            ("arc", arc_strip(20.0, 0.2, 1.0, 200)),
            ("wavy", wavy_strip(1.0, 2.0, 0.3, 20.0, 400)),
            ("wedge", wedge),
            ("T", t),
        ];
        for (name, region) in strips {
            let new = strip_fill(&region, 0.45, 0.09, true).expect(name);
            let old = lattice_fill(&region);
            let area = region_area(&region);
            let laid = |ps: &[FillPath]| ps.iter().map(|p| p.strip_area(dist)).sum::<f64>();
            // The strip's area laid by each, within 3 % of it (the lattice's within its own
            // conservation, the axis's exactly).
            assert!(
                (laid(&new) / area - 1.0).abs() < 1e-6,
                "{name}: {}",
                laid(&new)
            );
            assert!(
                (laid(&old) / area - 1.0).abs() < 0.03,
                "{name}: {}",
                laid(&old)
            );
            // The same line: each fill's points, where its bead is at least half the strip's
            // median width and a bead from either fill's ends (where the lattice's follows the
            // ridge into a square end's corner, the axis's into the end's middle), within a
            // tenth of a bead of the other's beads.
            let ends: Vec<Point2> = new
                .iter()
                .chain(&old)
                .flat_map(|p| [p.points[0], p.points[p.points.len() - 1]])
                .collect();
            let inner = |q: Point2| ends.iter().all(|e| dist(*e, q) > 0.45);
            for (a, b, which) in [(&new, &old, "new off old"), (&old, &new, "old off new")] {
                let mut ws: Vec<f64> = a.iter().flat_map(|p| p.widths.iter().copied()).collect();
                ws.sort_by(f64::total_cmp);
                let half = 0.5 * ws[ws.len() / 2];
                for p in a.iter() {
                    for (q, w) in p.points.iter().zip(&p.widths) {
                        if *w >= half && inner(*q) {
                            let d = off(*q, b);
                            assert!(d < 0.045, "{name}: {which} by {d} at {q:?}");
                        }
                    }
                }
            }
            // As long: the bead lengths within a bead and a half of each other per end.
            let len = |ps: &[FillPath]| {
                ps.iter()
                    .flat_map(|p| p.points.windows(2))
                    .map(|s| dist(s[0], s[1]))
                    .sum::<f64>()
            };
            let ends = 2.0 * (1 + usize::from(name == "T")) as f64;
            assert!(
                (len(&new) - len(&old)).abs() < ends * 0.675,
                "{name}: {} vs {}",
                len(&new),
                len(&old)
            );
        }
    }

    #[test]
    fn an_arc_strip_gets_one_bead_as_wide_as_it_on_its_middle() {
        let (r, w) = (20.0, 0.2);
        let region = arc_strip(r, w, 1.5, 300);
        let paths = strip_fill(&region, 0.45, 0.09, true).expect("a plain strip");
        assert_eq!(paths.len(), 1);
        let p = &paths[0];
        // On the middle line, within the thinning's tenth of a bead.
        for q in &p.points {
            assert!((q[0].hypot(q[1]) - r).abs() < 0.045 * 0.5, "{q:?}");
        }
        // As wide as the strip along its length, and its area put down.
        let mid = p.widths[p.widths.len() / 2];
        assert!((mid - w).abs() < 0.02 * w, "width {mid}");
        let laid = p.strip_area(dist);
        let area = region_area(&region);
        assert!((laid - area).abs() < 1e-6 * area, "{laid} vs {area}");
        // From end to end: the ends within a bead of the strip's.
        let ends = [[r, 0.0], [r * 1.5f64.cos(), r * 1.5f64.sin()]];
        let (a, b) = (p.points[0], p.points[p.points.len() - 1]);
        let near = |x: Point2| ends.iter().any(|e| dist(*e, x) < 0.45);
        assert!(near(a) && near(b), "{a:?} {b:?}");
    }

    #[test]
    fn strips_with_rings_or_holes_are_left_to_the_lattice() {
        // Wider than a bead and a tenth: rings.
        let wide = arc_strip(20.0, 0.6, 1.0, 100);
        assert!(strip_fill(&wide, 0.45, 0.09, true).is_none());
        // Over a bead without rings: infill lines.
        let bead = arc_strip(20.0, 0.47, 1.0, 100);
        assert!(strip_fill(&bead, 0.45, 0.09, false).is_none());
        assert!(strip_fill(&bead, 0.45, 0.09, true).is_some());
        // A ring: a hole.
        let mut ring = crate::geom2d::shapes::rect(0.0, 0.0, 5.0, 5.0);
        ring.holes
            .push(vec![[0.2, 0.2], [0.2, 4.8], [4.8, 4.8], [4.8, 0.2]]);
        assert!(strip_fill(&ring, 0.45, 0.09, true).is_none());
    }

    #[test]
    fn a_t_of_strips_gets_a_bead_along_each_arm_from_the_fork() {
        let t = Region {
            outer: vec![
                [0.0, 0.0],
                [10.0, 0.0],
                [10.0, 0.2],
                [5.1, 0.2],
                [5.1, 5.0],
                [4.9, 5.0],
                [4.9, 0.2],
                [0.0, 0.2],
            ],
            holes: vec![],
        };
        let paths = strip_fill(&t, 0.45, 0.09, true).expect("a T");
        let pts: Vec<Point2> = paths
            .iter()
            .flat_map(|p| p.points.iter().copied())
            .collect();
        // Each arm's far end reached within a bead, and every point on an arm's middle.
        for end in [[0.0, 0.1], [10.0, 0.1], [5.0, 5.0]] {
            assert!(pts.iter().any(|q| dist(*q, end) < 0.45), "{end:?}");
        }
        for q in &pts {
            let on_bar = (q[1] - 0.1).abs() < 0.05;
            let on_stem = (q[0] - 5.0).abs() < 0.05;
            assert!(on_bar || on_stem, "{q:?}");
        }
        // About the T's area laid: its beads as wide as the arms.
        let laid: f64 = paths.iter().map(|p| p.strip_area(dist)).sum();
        let area = region_area(&t);
        assert!((laid - area).abs() < 1e-6 * area, "{laid} vs {area}");
        for w in paths.iter().flat_map(|p| p.widths.iter()) {
            assert!(*w < 0.3, "{w}");
        }
    }

    #[test]
    fn a_strip_narrowing_to_nothing_stops_where_its_bead_would_be_too_narrow() {
        // A wedge 0.3 mm wide at one end, a point at the other, 10 mm long.
        let region = Region {
            outer: vec![[0.0, -0.15], [10.0, 0.0], [0.0, 0.15]],
            holes: vec![],
        };
        let paths = strip_fill(&region, 0.45, 0.09, true).expect("a wedge");
        assert!(!paths.is_empty());
        let narrowest = SINGLE_MIN_SHARE * 0.09;
        for p in &paths {
            // Before the widening to the area, each bead at least the narrowest; after it, by
            // at most the widening.
            for w in &p.widths {
                assert!(*w >= narrowest / MAX_CORE_WIDENING - 1e-9, "{w}");
            }
            for q in &p.points {
                assert!(q[0] > -1e-9 && q[0] < 10.0, "{q:?}");
            }
        }
        // The tip past where the wedge is as narrow as that bead is left out.
        let far = paths
            .iter()
            .flat_map(|p| p.points.iter())
            .map(|q| q[0])
            .fold(0.0f64, f64::max);
        let stop = 10.0 * (1.0 - narrowest / 0.3);
        assert!(
            far < stop + 0.3 && far > stop - 1.5,
            "far {far} stop {stop}"
        );
    }
}
