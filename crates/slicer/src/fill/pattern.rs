//! The paths of the fill patterns: rings inward from the boundary (with the gap fill of the
//! strips they leave) and scan lines across an area, free or chained into zig-zags.

use super::offset::{
    clean_offset, dilate_sharp, drop_specks, erode, simplify, simplify_line, simplify_ring,
};
use super::{
    bead_end_reach, shapes_area, Ctx, Path2, PathKind, Shape, Shapes, MAX_LINES, MIN_SEGMENT,
};
use crate::geom2d::{area2, dist, perimeter, Point2};
use crate::tolerance::{
    AREA_SLACK, COUNT_SLACK, DEGENERATE_LENGTH, NONZERO, PARALLEL_RAY, ROUND_OFF,
};
use crate::toolpath::Role;
use i_overlay::core::fill_rule::FillRule;
use i_overlay::core::overlay_rule::OverlayRule;
use i_overlay::float::single::SingleFloatOverlay;

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
            if den.abs() <= PARALLEL_RAY * (1.0 + e[0].abs() + e[1].abs()) {
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
pub(super) fn drop_short_segments(pts: &mut Vec<Point2>) {
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
/// infill lines end exactly on the offset boundary. In every mode, every ring is laid
/// simplified within the print tolerance (`Ctx::print_tol`): i_overlay's offsets leave runs
/// of points micrometres apart (the two ends of neighbouring offset edges, arcs of a small
/// radius chorded as finely as the deepest ring's), which only multiply the plan's points
/// (NIST CTC-05's rings had three points in four of them). The next ring is offset from the
/// ring before this simplification, so the error does not add up.
pub(super) fn rings(
    base: &Shapes,
    ctx: &Ctx,
    max: usize,
    thin: bool,
    out: &mut Vec<Path2>,
    gaps: &mut Shapes,
) -> Shapes {
    let half = 0.5 * ctx.spacing;
    let slack = CLEAN_SLACK * ctx.width;
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
        let opened = !clean && shapes_area(&ring) < shapes_area(&cur) - AREA_SLACK;
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
        let role = if k == 0 {
            Role::ExternalPerimeter
        } else {
            Role::Perimeter
        };
        for c in ring.iter().flatten() {
            let mut pts = simplify_ring(c.clone(), ctx.print_tol);
            let Some(&first) = pts.first() else { continue };
            pts.push(first);
            out.push(Path2 {
                points: pts,
                kind: PathKind::Perimeter,
                role,
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
    let from = out.len();
    for shape in strips {
        let angle = principal_angle(&shape);
        scan_fill(
            &vec![shape],
            angle,
            ctx.spacing,
            Some(ctx.print_tol),
            None,
            out,
        );
    }
    for p in &mut out[from..] {
        p.role = Role::GapFill;
    }
}

/// How far (in bead widths) an offset's perimeter may stray from the one a clean offset has
/// ([`clean_offset`]) and still count as clean.
const CLEAN_SLACK: f64 = 0.25;

/// A ring keeps only the parts of its offset at least `2 · OPEN_SHARE` spacings wide: where
/// the offset is narrower, the ring's beads from either side overlap by more than a tenth of
/// a bead (a ring about a part exactly a spacing wide covers it, beads edge to edge).
pub(super) const OPEN_SHARE: f64 = 0.45;

/// `cur` without its parts narrower than `2·d`: eroded by `d` and grown back by `d` with
/// mitred corners, so that convex corners come back sharp (bevelled only past 9°), and
/// clipped to `cur` (a mitre grown from where the erosion pinched a neck would stick out).
fn opening(cur: &Shapes, d: f64, ctx: &Ctx) -> Shapes {
    let core = erode(cur, d, &ctx.open_join);
    if core.is_empty() {
        return core;
    }
    // An erosion that loses nothing (the same contours, the perimeter it should have, as
    // `rings` tells a clean offset): no part of `cur` is narrower than `2·d`, and the core
    // grown back is `cur` again, up to corners sharper than the mitre's limit.
    if clean_offset(cur, &core, d, CLEAN_SLACK * ctx.width) {
        return cur.clone();
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
    if a.abs() < NONZERO {
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
pub(super) struct Reach<'a> {
    pub(super) base: &'a Shapes,
    pub(super) width: f64,
}

/// Lines `spacing` apart at angle `angle` (radians from +x) across `area`, clipped to it.
/// With `join` (`Some(tol)`), neighbouring lines of a connected piece are chained along the
/// boundary (zig-zag), each connector simplified within `tol` (the area's offset arcs, chorded
/// micrometres apart, only multiply the plan's points); without, each line is its own path,
/// printed in the +angle direction. With
/// `reach`, the ends left free (every end without `join`, a chain's first and last with it)
/// run on past `area`'s edge towards the boundary of `reach.base`. The lines are
/// [`Role::InternalInfill`]; the caller gives them their role.
pub(super) fn scan_fill(
    area: &Shapes,
    angle: f64,
    spacing: f64,
    join: Option<f64>,
    reach: Option<Reach>,
    out: &mut Vec<Path2>,
) {
    if area.is_empty() {
        return;
    }
    let (sn, cs) = angle.sin_cos();
    let rot = |p: Point2| [p[0] * cs + p[1] * sn, -p[0] * sn + p[1] * cs];
    let unrot = |p: Point2| [p[0] * cs - p[1] * sn, p[0] * sn + p[1] * cs];
    let (rings, ymin, ymax) = scan_rings(area, rot);
    let h = ymax - ymin;
    let eps = ROUND_OFF * (1.0 + ymin.abs().max(ymax.abs()));
    let lines = h / spacing;
    if h.is_nan() || h <= 2.0 * eps || lines.is_nan() || lines >= MAX_LINES {
        return;
    }
    // Lines centred on the area's extent; the outermost pulled a hair inside so a line on a
    // boundary edge still cuts the area.
    let n = (h / spacing + COUNT_SLACK).floor() as usize + 1;
    let y0 = ymin + 0.5 * (h - (n - 1) as f64 * spacing);
    let ys: Vec<f64> = (0..n)
        .map(|j| (y0 + j as f64 * spacing).clamp(ymin + eps, ymax - eps))
        .collect();

    // Crossings of every line with every edge (half-open in y, so vertices count once).
    let mut hits = crossings(&rings, &ys);

    // Segments: even-odd pairs of crossings along each line.
    let (ends, segs, by_line) = segments(&mut hits, &ys);
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
    let Some(tol) = join else {
        for &(_, [a, b]) in &segs {
            out.push(Path2 {
                points: vec![unrot(run_on(a)), unrot(run_on(b))],
                kind: PathKind::Infill,
                role: Role::InternalInfill,
            });
        }
        return;
    };

    // Ends in order along each ring: neighbours there have no other line ending between them.
    let (order, rank) = ring_order(&ends, rings.len());
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
                let from = pts.len() - 1;
                connector(r, e, len, forward, &mut pts);
                let c = ends[nb];
                pts.push(c.p);
                let along = simplify_line(&pts[from..], tol);
                pts.truncate(from);
                pts.extend(along);
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
                role: Role::InternalInfill,
            });
        }
    }
}

/// The area's rings of three points or more turned into the scan frame by `rot`, with their
/// arc lengths, and the frame's y extent.
fn scan_rings(area: &Shapes, rot: impl Fn(Point2) -> Point2) -> (Vec<Ring>, f64, f64) {
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
    (rings, ymin, ymax)
}

/// Crossings of every scan line (at `ys`) with every edge of the rings (half-open in y, so
/// vertices count once): x, ring, edge and arc length, per line.
fn crossings(rings: &[Ring], ys: &[f64]) -> Vec<Vec<(f64, usize, usize, f64)>> {
    let mut hits: Vec<Vec<(f64, usize, usize, f64)>> = vec![Vec::new(); ys.len()];
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
            while j < ys.len() && ys[j] < hi {
                let t = (ys[j] - p[1]) / (q[1] - p[1]);
                let x = p[0] + t * (q[0] - p[0]);
                hits[j].push((x, ri, i, r.cum[i] + t * el));
                j += 1;
            }
        }
    }
    hits
}

/// Segments: even-odd pairs of crossings along each line (sorted in place). Their ends, each
/// segment's line and ends, and each line's segments.
#[allow(clippy::type_complexity)]
fn segments(
    hits: &mut [Vec<(f64, usize, usize, f64)>],
    ys: &[f64],
) -> (Vec<End>, Vec<(usize, [usize; 2])>, Vec<Vec<usize>>) {
    let mut ends: Vec<End> = Vec::new();
    let mut segs: Vec<(usize, [usize; 2])> = Vec::new();
    let mut by_line: Vec<Vec<usize>> = vec![Vec::new(); ys.len()];
    for (j, hs) in hits.iter_mut().enumerate() {
        hs.sort_by(|a, b| a.0.total_cmp(&b.0));
        for pair in hs.chunks_exact(2) {
            let (a, b) = (pair[0], pair[1]);
            if b.0 - a.0 <= DEGENERATE_LENGTH || b.0.is_nan() || a.0.is_nan() {
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
    (ends, segs, by_line)
}

/// Ends in order along each ring (neighbours there have no other line ending between them),
/// and each end's rank in its ring's order.
fn ring_order(ends: &[End], rings: usize) -> (Vec<Vec<usize>>, Vec<usize>) {
    let mut order: Vec<Vec<usize>> = vec![Vec::new(); rings];
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
    (order, rank)
}

/// Pushes the ring's vertices strictly between end `e` and the point `len` further along the
/// ring (forward or backward).
fn connector(r: &Ring, e: End, len: f64, forward: bool, pts: &mut Vec<Point2>) {
    let m = r.pts.len();
    let tiny = ROUND_OFF * (1.0 + r.len);
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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::fill::offset::min_width;
    use std::f64::consts::PI;

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
}
