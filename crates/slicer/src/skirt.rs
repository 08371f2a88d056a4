//! Skirt and brim (issue 33): loops laid on the first layer around the part, before it.
//!
//! - the footprint: the inside of the first layer's outer beads (the rings of its external
//!   perimeters, united, holes filled), grown by half a bead to the beads' outer edges
//!   ([`footprint`]);
//! - the brim: loops a bead apart touching the footprint outward, as many as fit in
//!   `brim_width_mm` (at least one when it is above 0), laid from the outermost in, so the last
//!   ends against the part;
//! - the skirt: `skirt_loops` loops `skirt_distance_mm` outside the footprint and its brim,
//!   from the outermost in.
//!
//! Both are outlines of the footprint grown (round joins chorded within `tolerance`), so a
//! part of several islands gets one loop around those that lie close and one each around
//! those that lie apart.

use crate::fill::{grow, union, Region};
use crate::geom2d::{area2, Point2};
use crate::params::LayerParams;
use crate::toolpath::Role;

/// One closed loop to lay (its first point repeated at its end), a skirt's or a brim's.
#[derive(Debug, Clone, PartialEq)]
pub struct AdhesionLoop {
    /// The loop's points, closed.
    pub points: Vec<Point2>,
    /// [`Role::Skirt`] or [`Role::Brim`].
    pub role: Role,
}

/// The first layer's footprint from the rings its outer beads run along (bead centre lines,
/// either way round): their insides united, holes dropped, grown by half of `bead` mm.
pub fn footprint(rings: &[Vec<Point2>], bead: f64, tol: f64) -> Vec<Region> {
    let regions: Vec<Region> = rings
        .iter()
        .filter(|r| r.len() >= 3 && area2(r) != 0.0)
        .map(|r| {
            let mut outer = r.clone();
            if area2(&outer) < 0.0 {
                outer.reverse();
            }
            Region {
                outer,
                holes: vec![],
            }
        })
        .collect();
    let united = match regions.len() {
        0 => return vec![],
        1 => regions,
        _ => union(&regions[..1], &regions[1..]),
    };
    outlines(&grow(&united, 0.5 * bead, tol))
}

/// `regions` without their holes.
fn outlines(regions: &[Region]) -> Vec<Region> {
    regions
        .iter()
        .map(|r| Region {
            outer: r.outer.clone(),
            holes: vec![],
        })
        .collect()
}

/// Brim loops a `bead` apart touching `footprint` outward: as many as fit in `width` mm (one
/// at least when `width` is above 0), the outermost first.
fn brim(footprint: &[Region], width: f64, bead: f64, tol: f64) -> Vec<AdhesionLoop> {
    if width.is_nan() || width <= 0.0 || footprint.is_empty() {
        return vec![];
    }
    let n = ((width / bead).round() as usize).max(1);
    (0..n)
        .rev()
        .flat_map(|k| rings(&grow(footprint, bead * (k as f64 + 0.5), tol), Role::Brim))
        .collect()
}

/// The outer rings of `regions`, closed, as loops of `role`.
fn rings(regions: &[Region], role: Role) -> Vec<AdhesionLoop> {
    regions
        .iter()
        .filter(|r| r.outer.len() >= 3)
        .map(|r| {
            let mut points = r.outer.clone();
            points.push(r.outer[0]);
            AdhesionLoop { points, role }
        })
        .collect()
}

/// The skirt's loops, then the brim's, around `footprint` ([`footprint`]) for the process's
/// `skirt_loops`, `skirt_distance_mm` and `brim_width_mm`, beads `bead` mm wide; in the order
/// they are laid.
pub fn loops(footprint: &[Region], params: &LayerParams, bead: f64) -> Vec<AdhesionLoop> {
    let tol = params.tolerance;
    let brim = brim(footprint, params.brim_width_mm, bead, tol);
    let n_brim = if brim.is_empty() {
        0.0
    } else {
        ((params.brim_width_mm / bead).round()).max(1.0)
    };
    let base = match n_brim > 0.0 {
        true => outlines(&grow(footprint, n_brim * bead, tol)),
        false => footprint.to_vec(),
    };
    let mut out: Vec<AdhesionLoop> = (0..params.skirt_loops)
        .rev()
        .flat_map(|j| {
            let d = params.skirt_distance_mm + bead * (j as f64 + 0.5);
            rings(&grow(&base, d, tol), Role::Skirt)
        })
        .collect();
    out.extend(brim);
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geom2d::dist;

    fn square(x0: f64, y0: f64, s: f64, ccw: bool) -> Vec<Point2> {
        let mut r = vec![[x0, y0], [x0 + s, y0], [x0 + s, y0 + s], [x0, y0 + s]];
        if !ccw {
            r.reverse();
        }
        r
    }

    /// The least distance from `p` to the edges of the square `[x0, x0 + s]²`, outside it.
    fn outside_square(p: Point2, x0: f64, s: f64) -> f64 {
        let dx = (x0 - p[0]).max(p[0] - x0 - s).max(0.0);
        let dy = (x0 - p[1]).max(p[1] - x0 - s).max(0.0);
        dx.hypot(dy)
    }

    #[test]
    fn skirt_and_brim_lie_where_asked() {
        let bead = 0.5;
        // A 20 mm square's perimeter centre line, and a hole's ring inside it (clockwise).
        let rings = [square(0.25, 0.25, 19.5, true), square(5.0, 5.0, 4.0, false)];
        let foot = footprint(&rings, bead, 0.01);
        assert_eq!(foot.len(), 1);
        assert!((area2(&foot[0].outer) / 2.0 - 400.0).abs() < 0.5);
        let params = LayerParams {
            skirt_loops: 2,
            skirt_distance_mm: 3.0,
            brim_width_mm: 2.0,
            tolerance: 0.01,
            ..LayerParams::default()
        };
        let loops = loops(&foot, &params, bead);
        let roles: Vec<Role> = loops.iter().map(|l| l.role).collect();
        assert_eq!(
            roles,
            [[Role::Skirt; 2].as_slice(), &[Role::Brim; 4]].concat()
        );
        // Each loop is closed, and lies its distance out from the footprint's edge (the
        // square of the ring grown by half a bead): the brim's k-th at (k + 1/2) beads, the
        // outermost first; the skirt 3 mm beyond the brim's 2 mm.
        let want = [5.75, 5.25, 1.75, 1.25, 0.75, 0.25];
        for (l, want) in loops.iter().zip(want) {
            assert_eq!(l.points.first(), l.points.last());
            let d: Vec<f64> = l
                .points
                .iter()
                .map(|&p| outside_square(p, 0.25, 19.5) - 0.25)
                .collect();
            let (lo, hi) = d
                .iter()
                .fold((f64::MAX, 0.0f64), |(a, b), &x| (a.min(x), b.max(x)));
            assert!(
                lo > want - 0.02 && hi < want + 0.02,
                "{:?} {lo} {hi} {want}",
                l.role
            );
        }
        // No skirt, no brim.
        let none = LayerParams {
            skirt_loops: 0,
            ..LayerParams::default()
        };
        assert!(super::loops(&foot, &none, bead).is_empty());
        assert!(footprint(&[], bead, 0.01).is_empty());
    }

    #[test]
    fn islands_far_apart_get_a_skirt_each_and_near_ones_share_one() {
        let bead = 0.45;
        let params = LayerParams {
            tolerance: 0.01,
            ..LayerParams::default()
        };
        let near = [square(0.0, 0.0, 10.0, true), square(12.0, 0.0, 10.0, true)];
        let far = [square(0.0, 0.0, 10.0, true), square(60.0, 0.0, 10.0, true)];
        let count =
            |rings: &[Vec<Point2>]| loops(&footprint(rings, bead, 0.01), &params, bead).len();
        assert_eq!(count(&near), 1);
        assert_eq!(count(&far), 2);
        let l = &loops(&footprint(&near[..1], bead, 0.01), &params, bead)[0];
        let len: f64 = l.points.windows(2).map(|w| dist(w[0], w[1])).sum();
        // The 10 mm ring grown by half a bead and then by 6 mm and half a bead: its sides and
        // a circle of 6.45 mm at the corners.
        let want = 4.0 * 10.0 + 2.0 * std::f64::consts::PI * 6.45;
        assert!((len - want).abs() < 0.1, "{len} {want}");
    }
}
