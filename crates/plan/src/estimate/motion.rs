//! The time a machine takes for a run of straight moves with trapezoidal speed profiles: each
//! move speeds up at its acceleration from the speed it is entered at, cruises at its speed
//! and slows down to the speed it leaves at; where two moves meet, the speed is at most what
//! the jerk allows for the turn (Marlin's classic jerk: the velocity vector may change by at
//! most `jerk` at once), and at a stop (start, end, a retraction between) at most `jerk`.
//! The speeds where moves meet are planned as firmware plans them: a backward pass (each
//! move must be able to slow down to the next junction's speed) and a forward pass (it must
//! be able to reach it).

/// One straight move.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Move {
    /// Length, mm (positive).
    pub length: f64,
    /// Unit direction.
    pub dir: [f64; 3],
    /// Cruise speed, mm/s (positive).
    pub speed: f64,
    /// Acceleration, mm/s²; `f64::INFINITY` for none (the move is at `speed` throughout).
    pub accel: f64,
    /// The machine comes to a stop before this move (a retraction, the program's start).
    pub stop_before: bool,
}

/// The time (s) of the moves one after another, the last ending at a stop, with velocity
/// jumps of at most `jerk` (mm/s).
pub fn time(moves: &[Move], jerk: f64) -> f64 {
    time_of(|| moves.iter().copied(), moves.iter().rev().copied(), jerk)
}

/// [`time`] of the moves `moves` makes (each call the same moves, first to last) and
/// `reversed` gives (the same, last to first), so a long plan's moves need not be held at
/// once: only the speed where each one starts is kept.
pub fn time_of<I: Iterator<Item = Move>>(
    moves: impl Fn() -> I,
    reversed: impl Iterator<Item = Move>,
    jerk: f64,
) -> f64 {
    // Node i is where move i starts (node n where the last ends): the fastest each may be
    // passed at.
    let mut node: Vec<f64> = vec![];
    let mut before: Option<Move> = None;
    for m in moves().map(Some).chain([None]) {
        node.push(match (before, m) {
            (Some(a), Some(b)) if !b.stop_before => junction_speed(&a, &b, jerk),
            _ => {
                let v = m.map_or(f64::INFINITY, |m| m.speed);
                let u = before.map_or(f64::INFINITY, |a| a.speed);
                jerk.min(v).min(u)
            }
        });
        before = m;
    }
    let n = node.len() - 1;
    if n == 0 {
        return 0.0;
    }
    // Backward: each move can slow down from its start node to its end node.
    for (i, m) in (0..n).rev().zip(reversed) {
        node[i] = node[i].min(reachable(node[i + 1], m.accel, m.length));
    }
    // Forward: each move can speed up from its start node to its end node, which is then
    // final (no later move changes it), and the move is timed.
    let mut total = 0.0;
    for (i, m) in moves().enumerate() {
        node[i + 1] = node[i + 1].min(reachable(node[i], m.accel, m.length));
        total += trapezoid_time(m.length, m.speed, m.accel, node[i], node[i + 1]);
    }
    total
}

/// The fastest speed where move `a` runs into move `b`: at most either's cruise speed, and
/// the velocity vector turning by at most `jerk`, `v·|u_a − u_b| ≤ jerk`.
fn junction_speed(a: &Move, b: &Move, jerk: f64) -> f64 {
    let du = ((a.dir[0] - b.dir[0]).powi(2)
        + (a.dir[1] - b.dir[1]).powi(2)
        + (a.dir[2] - b.dir[2]).powi(2))
    .sqrt();
    let turn = if du > super::tolerance::NO_TURN {
        jerk / du
    } else {
        f64::INFINITY
    };
    a.speed.min(b.speed).min(turn)
}

/// The speed reached from `v0` over `length` at acceleration `accel`: `√(v0² + 2·a·L)`.
fn reachable(v0: f64, accel: f64, length: f64) -> f64 {
    (v0 * v0 + 2.0 * accel * length).sqrt()
}

/// The time of one move of `length` entered at `v0` and left at `v1` (both reachable from
/// each other and at most `speed`): up to `speed` at `accel`, cruise, down to `v1`; a
/// triangle where the move is too short to reach `speed`. With an infinite acceleration
/// exactly `length / speed`.
pub fn trapezoid_time(length: f64, speed: f64, accel: f64, v0: f64, v1: f64) -> f64 {
    let up = (speed * speed - v0 * v0) / (2.0 * accel);
    let down = (speed * speed - v1 * v1) / (2.0 * accel);
    if up + down <= length {
        (speed - v0) / accel + (speed - v1) / accel + (length - up - down) / speed
    } else {
        let peak = ((2.0 * accel * length + v0 * v0 + v1 * v1) / 2.0).sqrt();
        (peak - v0) / accel + (peak - v1) / accel
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn mv(length: f64, dir: [f64; 3], speed: f64, accel: f64) -> Move {
        Move {
            length,
            dir,
            speed,
            accel,
            stop_before: false,
        }
    }

    /// Infinite acceleration: length over speed, exactly.
    #[test]
    fn constant_speed_is_exact() {
        let moves = [
            mv(10.0, [1.0, 0.0, 0.0], 40.0, f64::INFINITY),
            mv(3.0, [0.0, 1.0, 0.0], 120.0, f64::INFINITY),
            mv(7.5, [-1.0, 0.0, 0.0], 20.0, f64::INFINITY),
        ];
        let want = 10.0 / 40.0 + 3.0 / 120.0 + 7.5 / 20.0;
        assert_eq!(time(&moves, 10.0), want);
    }

    /// A long move from rest to rest: up from the jerk to the speed, cruise, down again, in
    /// closed form; a short one never reaches the speed (a triangle).
    #[test]
    fn one_move_from_rest_is_the_closed_form() {
        let (l, v, a, j) = (100.0, 50.0, 1000.0, 10.0);
        let ramp = (v * v - j * j) / (2.0 * a);
        let want = 2.0 * (v - j) / a + (l - 2.0 * ramp) / v;
        let got = time(&[mv(l, [1.0, 0.0, 0.0], v, a)], j);
        assert!((got - want).abs() < 1e-12, "{got} vs {want}");
        let l = 1.0;
        let peak = (a * l + j * j).sqrt();
        assert!(peak < v);
        let want = 2.0 * (peak - j) / a;
        let got = time(&[mv(l, [1.0, 0.0, 0.0], v, a)], j);
        assert!((got - want).abs() < 1e-12, "{got} vs {want}");
    }
}
