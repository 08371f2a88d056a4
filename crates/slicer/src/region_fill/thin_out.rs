//! Thinning a gap fill's points: the ridge a gap fill follows is read off the lattice, one
//! point per lattice edge its loop crosses, and wanders by a fraction of a lattice step from
//! one to the next. Those points only multiply the plan's points (the fan's gap fill: 41 % of
//! its print points for 6 % of its bead length, a point every 0.26 mm where its rings have one
//! every 1.8 mm); [`thin_out`] keeps the ones the bead's line, width and length need.

use super::FillPath;
use crate::geom2d::{dist, peucker_by, segment_foot, Point2};

/// How far (in bead widths) a thinned gap fill's line may move from the ridge its points
/// were read at: a tenth of a bead (0.045 mm for 0.45 mm beads), under the lattice's own
/// step (a third of a spacing, [`super::lattice_step`]) and the feature's chord tolerance
/// (0.05 mm by default). Measured on the fan's `toolpath.csv` (delta5), thinned by line and
/// width alone: at a twentieth of a bead the ridge's wander kept 55 % of the gap fill's points,
/// at a tenth 15 %.
pub(super) const THIN_LINE_SHARE: f64 = 0.1;

/// How far (in bead widths) a thinned gap fill's width may differ from the width read at a
/// dropped point.
pub(super) const THIN_WIDTH_SHARE: f64 = 0.05;

/// How much shorter (a share of its length) the chord that replaces a stretch of a gap fill
/// may be. The ridge's wander lengthens a path by a few per cent, which the chord drops: that
/// much bead was laid twice over the same strip. A path that doubles back within the line's
/// reach (the gap fill of a core a lattice step or two across, a loop of a few points) is
/// many times its chord, and keeps its points; without this, such cores were laid short
/// (a 2 mm square's contour-zig-zag fill covered 96.7 % of it, 97.9 % before thinning).
/// Measured on the fan (delta5): the gap fill's 71,018 print points thinned to 50,356 at 3 %,
/// 40,867 at 6 %, 2026-11-29.
pub(super) const THIN_LENGTH_SHARE: f64 = 0.06;

/// `path` with the points dropped that lie within `line` (mm, in the frame `at` maps chart
/// points to, where lengths are the surface's) of the chord between the points kept on
/// either side, whose width is within `spread` (mm) of the width interpolated along it, and
/// whose stretch is at most [`THIN_LENGTH_SHARE`] longer than that chord (Douglas–Peucker on
/// line, width and length). The widths kept are the widths read there: the beads cover the
/// strip along its ridge as before, less the wander's overlap.
pub(super) fn thin_out(
    path: FillPath,
    at: impl Fn(Point2) -> Point2,
    line: f64,
    spread: f64,
) -> FillPath {
    let keep = kept_points(&path, &at, line, spread);
    if keep.iter().all(|k| *k) {
        return path;
    }
    let mut thin = FillPath {
        points: Vec::with_capacity(keep.len()),
        widths: Vec::with_capacity(keep.len()),
        role: path.role,
    };
    for ((q, w), kept) in path.points.into_iter().zip(path.widths).zip(keep) {
        if kept {
            thin.points.push(q);
            thin.widths.push(w);
        }
    }
    thin
}

/// Which of `path`'s points [`thin_out`] keeps: its ends, and each point further than `line`
/// from the chord of the kept points on either side (or whose width is further than `spread`
/// from the width interpolated along it, or where the stretch between is too long for the
/// chord), found Douglas–Peucker fashion in the frame of `at`.
fn kept_points(
    path: &FillPath,
    at: &impl Fn(Point2) -> Point2,
    line: f64,
    spread: f64,
) -> Vec<bool> {
    let n = path.points.len();
    if n <= 2 || !(line > 0.0 && spread > 0.0) {
        return vec![true; n];
    }
    let m: Vec<Point2> = path.points.iter().map(|q| at(*q)).collect();
    let w = &path.widths;
    // The path's length from its start to each point.
    let mut run = Vec::with_capacity(n);
    run.push(0.0);
    for k in 1..n {
        run.push(run[k - 1] + dist(m[k - 1], m[k]));
    }
    let mut keep = vec![false; n];
    keep[0] = true;
    keep[n - 1] = true;
    peucker_by(vec![(0, n - 1)], &mut keep, |i, j| {
        let (a, b) = (m[i], m[j]);
        let len = dist(a, b);
        let (mut worst, mut at_k) = (0.0f64, i);
        for k in i + 1..j {
            // Where along the chord `k` falls (for the width there), and how far off it.
            let (t, foot, _) = segment_foot(m[k], a, b);
            let wk = w[i] + (w[j] - w[i]) * t;
            let err = (dist(m[k], foot) / line).max((w[k] - wk).abs() / spread);
            if err > worst {
                worst = err;
                at_k = k;
            }
        }
        let along = run[j] - run[i];
        (worst > 1.0 || along - len > THIN_LENGTH_SHARE * along).then_some(if at_k == i {
            (i + j) / 2
        } else {
            at_k
        })
    });
    keep
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geom2d::seg_dist;
    use crate::toolpath::Role;

    fn strip(p: &FillPath) -> f64 {
        p.strip_area(dist)
    }

    /// A ridge read off a lattice: a straight strip's middle, wandering ±0.02 mm, its width
    /// wandering ±0.01 mm about a taper from 0.3 to 0.2 mm.
    fn wandering() -> FillPath {
        let n = 201;
        let points = (0..n)
            .map(|i| {
                let x = 0.1 * i as f64;
                [x, 0.02 * ((i * 7919) % 13) as f64 / 6.0 - 0.02]
            })
            .collect();
        let widths = (0..n)
            .map(|i| 0.3 - 0.1 * i as f64 / (n - 1) as f64 + 0.01 * ((i % 3) as f64 - 1.0))
            .collect();
        FillPath {
            points,
            widths,
            role: Role::GapFill,
        }
    }

    #[test]
    fn a_wandering_ridge_keeps_few_points_and_its_line() {
        let path = wandering();
        let (line, spread) = (0.045, 0.0225);
        let keep = kept_points(&path, &|q| q, line, spread);
        let kept: Vec<usize> = (0..keep.len()).filter(|k| keep[*k]).collect();
        assert!(
            kept.len() * 5 < path.points.len(),
            "{} of {} points kept",
            kept.len(),
            path.points.len()
        );
        // Every dropped point lies within `line` of the chord of the kept points either side,
        // its width within `spread` of the width interpolated there, and the chord is at
        // most THIN_LENGTH_SHARE shorter than the stretch it replaces.
        let len = |i: usize, j: usize| (i..j).map(|k| dist(path.points[k], path.points[k + 1]));
        for pair in kept.windows(2) {
            let (i, j) = (pair[0], pair[1]);
            let (a, b) = (path.points[i], path.points[j]);
            let along: f64 = len(i, j).sum();
            assert!(along - dist(a, b) <= THIN_LENGTH_SHARE * along);
            for k in i + 1..j {
                let q = path.points[k];
                let d = seg_dist(q, a, b);
                assert!(d <= line, "{q:?} lies {d} off the chord {a:?} {b:?}");
                let t = ((q[0] - a[0]) / (b[0] - a[0])).clamp(0.0, 1.0);
                let wt = path.widths[i] + (path.widths[j] - path.widths[i]) * t;
                assert!(
                    (wt - path.widths[k]).abs() <= spread,
                    "width {wt} for {}",
                    path.widths[k]
                );
            }
        }
        // Thinned, the path is those points with their widths; its strip is short by the
        // wander's overlap only.
        let thin = thin_out(path.clone(), |q| q, line, spread);
        assert_eq!(thin.points.len(), kept.len());
        assert_eq!(thin.points.first(), path.points.first());
        assert_eq!(thin.points.last(), path.points.last());
        for (k, i) in kept.iter().enumerate() {
            assert_eq!(thin.widths[k], path.widths[*i]);
        }
        let (a, b) = (strip(&path), strip(&thin));
        assert!(
            b < a && b > (1.0 - THIN_LENGTH_SHARE) * a,
            "strip {b} of {a}"
        );
    }

    #[test]
    fn a_path_doubling_back_within_the_line_keeps_its_length() {
        // The gap fill of a core 0.06 mm across: two turns of a loop 0.04 mm across, well
        // within the line of its ends' chord and many times as long.
        let scribble = FillPath {
            points: (0..=16)
                .map(|k| {
                    let a = std::f64::consts::PI * k as f64 / 4.0;
                    [0.02 * a.cos() + 0.001 * k as f64, 0.02 * a.sin()]
                })
                .collect(),
            widths: vec![0.12; 17],
            role: Role::GapFill,
        };
        let thin = thin_out(scribble.clone(), |q| q, 0.045, 0.0225);
        let (a, b) = (strip(&scribble), strip(&thin));
        // Within a tenth of its strip (at most a chord of each dropped stretch shorter).
        assert!(b >= 0.9 * a, "strip {b} of {a}");
    }

    #[test]
    fn a_turn_and_a_step_in_width_are_kept() {
        // An L: the corner is further than `line` off the chord of the ends.
        let l = FillPath {
            points: vec![[0.0, 0.0], [1.0, 0.0], [2.0, 0.0], [2.0, 1.0], [2.0, 2.0]],
            widths: vec![0.3; 5],
            role: Role::GapFill,
        };
        let thin = thin_out(l, |q| q, 0.045, 0.0225);
        assert_eq!(thin.points, vec![[0.0, 0.0], [2.0, 0.0], [2.0, 2.0]]);
        // A straight line whose width steps from 0.3 to 0.1 half-way: the step is kept.
        let step = FillPath {
            points: (0..=10).map(|i| [0.1 * i as f64, 0.0]).collect(),
            widths: (0..=10).map(|i| if i <= 5 { 0.3 } else { 0.1 }).collect(),
            role: Role::GapFill,
        };
        let thin = thin_out(step.clone(), |q| q, 0.045, 0.0225);
        assert!(thin.points.len() >= 4, "{:?}", thin.points);
        // The step is laid where it was: the same strip.
        assert!((strip(&thin) - strip(&step)).abs() <= 1e-12);
    }

    #[test]
    fn lengths_are_taken_in_the_metric_frame() {
        // Chart v stretched 10 times on the surface: a wander of 0.01 in v is 0.1 mm there,
        // more than the line's 0.045 mm, and is kept.
        let path = FillPath {
            points: (0..=20)
                .map(|i| [0.1 * i as f64, 0.01 * (i % 2) as f64])
                .collect(),
            widths: vec![0.3; 21],
            role: Role::GapFill,
        };
        let flat = thin_out(path.clone(), |q| q, 0.045, 0.0225);
        assert_eq!(flat.points.len(), 2);
        let stretched = thin_out(path.clone(), |q| [q[0], 10.0 * q[1]], 0.045, 0.0225);
        assert_eq!(stretched.points.len(), path.points.len());
    }
}
