//! Lifting a chart path onto a curved layer: points inserted until every chord is within the
//! tolerance of the surface, then the ones not needed for that dropped.

use crate::chart::Chart;
use crate::geodesic::segment_distance;
use crate::geom2d::Point2;
use crate::region_fill::FillPath;
use crate::toolpath::Role;
use brep::math::{P3, V3};

/// A lifted path point: chart coordinates, position and unit normal.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Lifted {
    pub(crate) q: Point2,
    pub(crate) p: P3,
    pub(crate) n: V3,
    /// Bead width here.
    pub(crate) w: f64,
    /// The layer surface's unit normal here (`n` may be turned to another axis, e.g. SST's).
    pub(crate) ln: V3,
    /// What the path is for.
    pub(crate) role: Role,
}

/// The share of a dropped stretch's length the chord that replaces it may be shorter by
/// ([`lift`]): what it lays is that much short.
const LENGTH_SLACK: f64 = 0.01;

/// Lifts a chart polyline onto the offset surface at `z`, inserting points until every chord
/// is within `tol` of the surface, then dropping points whose removal keeps the polyline
/// within `tol / 2` of the dense one (Douglas–Peucker in 3-D) and its length within
/// [`LENGTH_SLACK`] of theirs. On a transition layer, whose
/// normal takes four more evaluations than its point, only the points kept get a normal.
pub(crate) fn lift(chart: &Chart, path: &FillPath, z: f64, tol: f64) -> Vec<Lifted> {
    // The point at `q`, with its normal where that costs nothing more (zero: to be taken).
    let lazy = chart.blend.is_some();
    let eval = |q: Point2| -> Option<(P3, V3)> {
        if lazy {
            chart.point(q, z).map(|p| (p, V3::zeros()))
        } else {
            chart.at(q, z)
        }
    };
    fn refine(
        eval: &dyn Fn(Point2) -> Option<(P3, V3)>,
        a: Lifted,
        b: Lifted,
        tol: f64,
        depth: u32,
        out: &mut Vec<Lifted>,
    ) {
        if depth < 10 {
            let qm = [0.5 * (a.q[0] + b.q[0]), 0.5 * (a.q[1] + b.q[1])];
            if let Some((p, n)) = eval(qm) {
                let mid = Lifted {
                    q: qm,
                    p,
                    n,
                    w: 0.5 * (a.w + b.w),
                    ln: n,
                    role: a.role,
                };
                if (p - P3::from(0.5 * (a.p.coords + b.p.coords))).norm() > tol {
                    refine(eval, a, mid, tol, depth + 1, out);
                    refine(eval, mid, b, tol, depth + 1, out);
                    return;
                }
            }
        }
        out.push(b);
    }
    let mut dense: Vec<Lifted> = vec![];
    for (q, w) in path.points.iter().zip(&path.widths) {
        let Some((p, n)) = eval(*q) else {
            continue;
        };
        let cur = Lifted {
            q: *q,
            p,
            n,
            w: *w,
            ln: n,
            role: path.role,
        };
        match dense.last().copied() {
            Some(prev) => refine(&eval, prev, cur, tol, 0, &mut dense),
            None => dense.push(cur),
        }
    }
    let mut kept = if dense.len() <= 2 {
        dense
    } else {
        let mut keep = vec![false; dense.len()];
        keep[0] = true;
        keep[dense.len() - 1] = true;
        // The dense path's length from its start to each point.
        let mut run = Vec::with_capacity(dense.len());
        run.push(0.0);
        for k in 1..dense.len() {
            run.push(run[k - 1] + (dense[k].p - dense[k - 1].p).norm());
        }
        crate::geom2d::peucker_by(vec![(0, dense.len() - 1)], &mut keep, |i, j| {
            let (a, b) = (dense[i].p, dense[j].p);
            let (mut worst, mut at) = (0.0f64, i);
            for (k, x) in dense.iter().enumerate().take(j).skip(i + 1) {
                let d = segment_distance(&x.p, &a, &b);
                if d > worst {
                    worst = d;
                    at = k;
                }
            }
            // Within the distance, the chord may still be shorter than the points it drops:
            // a path that doubles back inside the tolerance (the gap fill of a pin's core 0.2
            // mm across, a loop of nine points, was laid 45 % short).
            let along = run[j] - run[i];
            let long_enough = along - (b - a).norm() <= LENGTH_SLACK * along;
            (worst > 0.5 * tol || !long_enough).then_some(if at == i { (i + j) / 2 } else { at })
        });
        dense
            .into_iter()
            .zip(keep)
            .filter_map(|(x, k)| k.then_some(x))
            .collect::<Vec<_>>()
    };
    if lazy {
        // The same point again, with its normal.
        for x in &mut kept {
            if let Some((_, n)) = chart.at(x.q, z) {
                x.n = n;
                x.ln = n;
            }
        }
    }
    kept
}

#[cfg(test)]
mod tests {
    use super::*;
    use brep::math::Frame;
    use brep::surface::Surface;

    /// The strip (length × mean width) of lifted points.
    fn strip(points: &[Lifted]) -> f64 {
        points
            .windows(2)
            .map(|s| 0.5 * (s[0].w + s[1].w) * (s[1].p - s[0].p).norm())
            .sum()
    }

    #[test]
    fn dropped_points_keep_the_length_they_laid() {
        let plane = Surface::Plane {
            frame: Frame::world(P3::origin()),
        };
        let chart = Chart::unit(&plane);
        let tol = 0.05;
        // The gap fill of a core 0.06 mm across: nine points doubling back well inside the
        // tolerance, which the distance test alone dropped down to its two ends.
        let scribble = FillPath {
            points: vec![
                [0.0, 0.0],
                [0.04, -0.05],
                [0.01, -0.02],
                [0.02, -0.06],
                [0.04, -0.03],
                [-0.01, -0.05],
                [0.01, -0.03],
                [0.04, -0.05],
                [0.0, -0.03],
            ],
            widths: vec![0.12; 9],
            role: Role::GapFill,
        };
        // A bead zig-zagging a hundredth of a millimetre either side of its line.
        let zigzag = FillPath {
            points: (0..=10)
                .map(|i| [0.05 * i as f64, 1.0 + 0.01 * (i % 2) as f64])
                .collect(),
            widths: vec![0.45; 11],
            role: Role::GapFill,
        };
        for path in [scribble, zigzag] {
            let want = path.strip_area(crate::geom2d::dist);
            let kept = lift(&chart, &path, 0.0, tol);
            let got = strip(&kept);
            assert!(
                (got - want).abs() <= LENGTH_SLACK * want * 1.0001,
                "{} points kept of {}: strip {got:.5} of {want:.5}",
                kept.len(),
                path.points.len()
            );
        }
    }
}
