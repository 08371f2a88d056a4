//! Arc fitting (issue 33, the process key `arc_fitting`): a run of print moves whose points
//! lie on one circle is written as one `G2` (clockwise) or `G3` (counter-clockwise) with the
//! centre's offset from the start as `I`/`J`, as firmware reads it (Marlin's `ARC_SUPPORT`,
//! on by default).
//!
//! The circle is found from the points as written (machine coordinates, 0.001 mm): the one
//! through the run's start, its middle point and its end. It stands for the run when every
//! point lies within the tolerance of it (the process key `tolerance`, the chord tolerance the
//! planner used for the B-rep's circles), the arc strays from each planned segment by no more
//! than that (its sagitta over the segment), the points go round one way, the radius is
//! [`MIN_ARC_RADIUS`] to [`MAX_ARC_RADIUS`] and the sweep below [`MAX_SWEEP_DEG`]. Perimeters of
//! bosses and holes, whose B-rep circles the planner chorded, are such runs; straight lines
//! and corners are not. The longest such run from the start is taken (doubling, then halving
//! between the last that fits and the first that does not).

/// Smallest radius written as an arc, mm (firmware draws smaller ones poorly).
pub const MIN_ARC_RADIUS: f64 = 0.5;
/// Largest radius written as an arc, mm: beyond it a run is as good as straight.
pub const MAX_ARC_RADIUS: f64 = 1000.0;
/// Fewest print points one arc stands for.
pub const MIN_ARC_POINTS: usize = 4;
/// Largest sweep of one arc, degrees: a whole circle is written as two arcs, never as one
/// whose start and end would coincide.
pub const MAX_SWEEP_DEG: f64 = 300.0;
/// Smallest turn about the centre between two points, radians: a point that does not move on
/// the circle ends the run.
const MIN_STEP_RAD: f64 = 1e-6;

/// An arc standing for the first `count` points of a run.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Arc {
    /// Points of the run it stands for (it ends on the last of them).
    pub count: usize,
    /// Its centre (the run's coordinates).
    pub centre: [f64; 2],
    /// Counter-clockwise (`G3`), else clockwise (`G2`).
    pub ccw: bool,
}

/// The longest arc from `start` through the first points of `run` within `tol` mm, if at
/// least [`MIN_ARC_POINTS`] of them lie on one.
pub fn fit(start: [f64; 2], run: &[[f64; 2]], tol: f64) -> Option<Arc> {
    let max = run.len();
    let mut n = MIN_ARC_POINTS;
    let mut good = None;
    while n <= max {
        match on_arc(start, &run[..n], tol) {
            Some(a) => good = Some(a),
            None => break,
        }
        if n == max {
            break;
        }
        n = (2 * n).min(max);
    }
    let mut best = good?;
    // `best` fits; the first count known not to (or one past the run).
    let mut bad = if best.count == max { max + 1 } else { n };
    while bad - best.count > 1 {
        let mid = (best.count + bad) / 2;
        match on_arc(start, &run[..mid], tol) {
            Some(a) => best = a,
            None => bad = mid,
        }
    }
    Some(best)
}

/// The arc from `start` through every point of `pts` within `tol`, if they make one.
fn on_arc(start: [f64; 2], pts: &[[f64; 2]], tol: f64) -> Option<Arc> {
    let n = pts.len();
    if n < MIN_ARC_POINTS {
        return None;
    }
    let (c, r) = circumcircle(start, pts[n / 2], pts[n - 1])?;
    if !(MIN_ARC_RADIUS..=MAX_ARC_RADIUS).contains(&r) {
        return None;
    }
    let (mut prev, mut sweep, mut turn) = (start, 0.0f64, 0.0f64);
    for &p in pts {
        let (a, b) = ([prev[0] - c[0], prev[1] - c[1]], [p[0] - c[0], p[1] - c[1]]);
        if (b[0].hypot(b[1]) - r).abs() > tol {
            return None;
        }
        let step = (a[0] * b[1] - a[1] * b[0]).atan2(a[0] * b[0] + a[1] * b[1]);
        if step.abs() < MIN_STEP_RAD || (turn != 0.0 && step.signum() != turn) {
            return None;
        }
        turn = step.signum();
        sweep += step.abs();
        // The arc's farthest from the planned segment: its sagitta over the chord.
        let half = 0.5 * (p[0] - prev[0]).hypot(p[1] - prev[1]);
        if r - (r * r - half * half).max(0.0).sqrt() > tol {
            return None;
        }
        prev = p;
    }
    (sweep.to_degrees() < MAX_SWEEP_DEG).then_some(Arc {
        count: n,
        centre: c,
        ccw: turn > 0.0,
    })
}

/// The circle through three points (centre, radius), `None` when they are (nearly) on a line.
fn circumcircle(a: [f64; 2], b: [f64; 2], c: [f64; 2]) -> Option<([f64; 2], f64)> {
    let (bx, by) = (b[0] - a[0], b[1] - a[1]);
    let (cx, cy) = (c[0] - a[0], c[1] - a[1]);
    let d = 2.0 * (bx * cy - by * cx);
    let (b2, c2) = (bx * bx + by * by, cx * cx + cy * cy);
    let ux = (cy * b2 - by * c2) / d;
    let uy = (bx * c2 - cx * b2) / d;
    let r = ux.hypot(uy);
    (d != 0.0 && r.is_finite()).then_some(([a[0] + ux, a[1] + uy], r))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Points on a circle of radius `r` about (10, 20), from angle `a0` by `step` (radians).
    fn circle(r: f64, a0: f64, step: f64, n: usize) -> Vec<[f64; 2]> {
        (0..n)
            .map(|k| {
                let a = a0 + step * k as f64;
                [10.0 + r * a.cos(), 20.0 + r * a.sin()]
            })
            .collect()
    }

    #[test]
    fn a_chorded_circle_is_one_arc_each_way() {
        let pts = circle(5.0, 0.0, 0.1, 30);
        let arc = fit(pts[0], &pts[1..], 0.01).expect("an arc");
        assert_eq!(arc.count, 29);
        assert!(arc.ccw);
        assert!((arc.centre[0] - 10.0).abs() < 1e-6 && (arc.centre[1] - 20.0).abs() < 1e-6);
        let back: Vec<[f64; 2]> = pts.iter().rev().copied().collect();
        assert!(!fit(back[0], &back[1..], 0.01).expect("an arc").ccw);
    }

    #[test]
    fn the_arc_stops_where_the_circle_does() {
        // A quarter circle, then a straight line on from its end, away from the centre.
        let mut pts = circle(5.0, 0.0, 0.1, 16);
        let end = pts[15];
        let (c, s) = (1.5f64.cos(), 1.5f64.sin());
        pts.extend((1..10).map(|k| [end[0] + 0.5 * k as f64 * c, end[1] + 0.5 * k as f64 * s]));
        let arc = fit(pts[0], &pts[1..], 0.01).expect("an arc");
        assert_eq!(arc.count, 15);
    }

    #[test]
    fn lines_small_circles_coarse_chords_and_whole_turns_are_not_arcs() {
        let line: Vec<[f64; 2]> = (0..10).map(|k| [k as f64, 2.0 * k as f64]).collect();
        assert_eq!(fit(line[0], &line[1..], 0.01), None);
        let small = circle(0.3, 0.0, 0.3, 12);
        assert_eq!(fit(small[0], &small[1..], 0.01), None);
        // Chords of 1 rad on a 5 mm circle stray 0.6 mm from the arc.
        let coarse = circle(5.0, 0.0, 1.0, 6);
        assert_eq!(fit(coarse[0], &coarse[1..], 0.05), None);
        // A whole turn is cut below MAX_SWEEP_DEG.
        let full = circle(5.0, 0.0, 0.05, 127);
        let arc = fit(full[0], &full[1..], 0.01).expect("an arc");
        assert!((arc.count as f64 * 0.05).to_degrees() < MAX_SWEEP_DEG);
        // Off the circle by more than the tolerance: not an arc through that point.
        let mut bumpy = circle(5.0, 0.0, 0.1, 8);
        bumpy[4][0] += 0.2;
        assert!(fit(bumpy[0], &bumpy[1..], 0.01).is_none_or(|a| a.count < 4));
    }
}
