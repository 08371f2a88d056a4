//! Corner spurs: beads along the bisector of a sharp convex corner, into the tip the outer
//! beads leave empty.

use super::FillPath;
use crate::chart::Chart;
use crate::geom2d::{Point2, Region};
use crate::tolerance::DEGENERATE_LENGTH;
use crate::toolpath::Role;
use brep::math::P3;

/// A corner spur is laid only at a convex corner of the layer region sharper than this
/// (radians, measured on the layer surface).
const SPUR_MAX_ANGLE: f64 = 1.75;
/// Shortest corner spur, mm.
const SPUR_MIN_LENGTH: f64 = 0.1;

/// Corner spurs: the outermost paths (rings, or lines without rings) run half a bead inside
/// the boundary, so at a convex corner of angle θ their beads stop `(w/2)(1/sin(θ/2) − 1)`
/// short of it along the bisector, and the tip of the wedge stays empty: at the sharp corners
/// where curved layers cut a blade's end obliquely, a millimetre and more. Each such corner
/// gets a short path along its bisector (on the layer surface) from where the outer beads stop
/// towards the tip, each point as wide as the wedge there (`2ρ·sin(θ/2)` at distance ρ from the
/// corner, capped by twice the distance to the boundary), down to 0.3 of a bead; the
/// extrusion follows that width by Eq. 1, so the wedge is filled rather than over-filled.
///
/// Those whose tip the region's `fill` reaches with its gap fill already (a bead middle
/// within half a bead of the spur's tip end) are left out: the gap fill of a region's
/// stretches too narrow for its first ring runs into the tip of a wedge that sharp, and a
/// spur there would lay it twice.
pub(crate) fn corner_spurs_beside(
    chart: &Chart,
    region: &Region,
    z: f64,
    width: f64,
    fill: &[FillPath],
) -> Vec<FillPath> {
    let gap: Vec<Point2> = fill
        .iter()
        .filter(|p| p.role == Role::GapFill)
        .flat_map(|p| p.points.iter().copied())
        .collect();
    let reached = |spur: &FillPath| {
        spur.points.last().is_some_and(|t| {
            gap.iter()
                .any(|q| (q[0] - t[0]).hypot(q[1] - t[1]) < 0.5 * width)
        })
    };
    let mut spurs = all_corner_spurs(chart, region, z, width);
    spurs.retain(|s| !reached(s));
    spurs
}

/// Every corner spur of a region ([`corner_spurs_beside`] with no fill).
fn all_corner_spurs(chart: &Chart, region: &Region, z: f64, width: f64) -> Vec<FillPath> {
    let mut out = vec![];
    let rings: Vec<&Vec<Point2>> = std::iter::once(&region.outer)
        .chain(region.holes.iter())
        .filter(|r| r.len() >= 3)
        .collect();
    let lifted: Option<Vec<Vec<P3>>> = rings
        .iter()
        .map(|r| r.iter().map(|q| chart.point(*q, z)).collect())
        .collect();
    let Some(lifted) = lifted else { return out };
    let to_boundary = |p: &P3| -> f64 {
        let mut best = f64::INFINITY;
        for ring in &lifted {
            for i in 0..ring.len() {
                let (a, b) = (ring[i], ring[(i + 1) % ring.len()]);
                best = best.min(crate::geodesic::segment_distance(p, &a, &b));
            }
        }
        best
    };
    for (ring, lp) in rings.iter().zip(&lifted) {
        let n = ring.len();
        // The point `reach` away on the surface along the ring from vertex i, walking `dir`.
        let side = |i: usize, dir: isize, reach: f64| -> Option<(Point2, P3)> {
            let pc = lp[i];
            let mut prev = (ring[i], pc);
            for k in 1..n {
                let j = (i as isize + dir * k as isize).rem_euclid(n as isize) as usize;
                let (q, p) = (ring[j], lp[j]);
                let d = (p - pc).norm();
                if d >= reach {
                    let dp = (prev.1 - pc).norm();
                    let t = if d > dp {
                        ((reach - dp) / (d - dp)).clamp(0.0, 1.0)
                    } else {
                        1.0
                    };
                    let qq = [
                        prev.0[0] + (q[0] - prev.0[0]) * t,
                        prev.0[1] + (q[1] - prev.0[1]) * t,
                    ];
                    return Some((qq, prev.1 + (p - prev.1) * t));
                }
                prev = (q, p);
            }
            None
        };
        // The angle at each vertex between the ring's points half a bead either side, on the
        // surface; NaN where the ring turns away from the region there.
        let angle: Vec<f64> = (0..n)
            .map(|i| {
                let (Some((qa, pa)), Some((qb, pb))) =
                    (side(i, -1, 0.5 * width), side(i, 1, 0.5 * width))
                else {
                    return f64::NAN;
                };
                let (u, v) = (
                    [ring[i][0] - qa[0], ring[i][1] - qa[1]],
                    [qb[0] - ring[i][0], qb[1] - ring[i][1]],
                );
                if u[0] * v[1] - u[1] * v[0] <= 0.0 {
                    return f64::NAN;
                }
                let (a, b) = ((pa - lp[i]).normalize(), (pb - lp[i]).normalize());
                a.dot(&b).clamp(-1.0, 1.0).acos()
            })
            .collect();
        for i in 0..n {
            let theta = angle[i];
            if !(theta > 1e-3 && theta < SPUR_MAX_ANGLE) {
                continue;
            }
            // One spur a corner: the sharpest vertex within half a bead along the ring.
            let sharpest = [-1isize, 1].iter().all(|&dir| {
                (1..n)
                    .map_while(|k| {
                        let j = (i as isize + dir * k as isize).rem_euclid(n as isize) as usize;
                        ((lp[j] - lp[i]).norm() < 0.5 * width).then_some(j)
                    })
                    .all(|j| !(angle[j] < theta || (angle[j] == theta && j < i)))
            });
            if !sharpest {
                continue;
            }
            let (Some((q1, p1)), Some((q2, p2))) = (side(i, -1, width), side(i, 1, width)) else {
                continue;
            };
            let (qc, pc) = (ring[i], lp[i]);
            let (l1, l2) = ((p1 - pc).norm(), (p2 - pc).norm());
            if l1 < DEGENERATE_LENGTH || l2 < DEGENERATE_LENGTH {
                continue;
            }
            // The bisector in the chart: the chart is linear over the corner's neighbourhood,
            // so the chart steps to the unit surface steps along both sides add up to a step
            // of length 2·cos(θ/2) along the bisector on the surface.
            let b = [
                (q1[0] - qc[0]) / l1 + (q2[0] - qc[0]) / l2,
                (q1[1] - qc[1]) / l1 + (q2[1] - qc[1]) / l2,
            ];
            let (sn, cs) = ((0.5 * theta).sin(), (0.5 * theta).cos());
            let rho_s = 0.5 * width * (1.0 / sn - 1.0);
            // The tip ends where the wedge is 0.3 bead wide: its middle stays 0.15 bead off
            // the sides, clear of the region's sampling error.
            let rho_e = 0.15 * width / sn;
            if rho_s - rho_e < SPUR_MIN_LENGTH {
                continue;
            }
            let steps = ((rho_s - rho_e) / (0.25 * width)).ceil().clamp(1.0, 1e3) as usize;
            let mut spur = FillPath::empty(Role::GapFill);
            for k in 0..=steps {
                let rho = rho_e + (rho_s - rho_e) * k as f64 / steps as f64;
                let f = rho / (2.0 * cs);
                let q = [qc[0] + b[0] * f, qc[1] + b[1] * f];
                if !crate::geom2d::region_contains(region, q) {
                    break;
                }
                let Some(p) = chart.point(q, z) else { break };
                let db = to_boundary(&p);
                // Another side of the region comes nearer than the wedge's: stop.
                if db < 0.8 * rho * sn {
                    break;
                }
                spur.points.push(q);
                spur.widths.push((2.0 * db.min(rho * sn)).min(width));
            }
            if spur.points.len() >= 2 {
                spur.reverse();
                out.push(spur);
            }
        }
    }
    out
}
