//! How long a plan prints and how much filament it takes, as a slicer's estimate does: print
//! moves at `print_speed`, those of beads resting on the build plate (the plan's lowest layer)
//! at `first_layer_speed`, travels at `travel_speed`, each capped at `max_speed`, with
//! trapezoidal speed profiles at `max_acceleration` (prints) and `travel_acceleration`
//! (travels) and corners as fast as `max_jerk` allows ([`motion`]); a retraction and its
//! return at `retraction_speed` around each travel that follows printing, the machine at rest
//! for them. Without accelerations in the profile every move is at its speed throughout. The
//! tool tip's path is timed: z-hops and the turning axes of a 5-axis machine are not.
//! Filament mass from the filament's cross-section and `filament_density` (g/cm³; 1.24, PLA,
//! when the profile does not say).

pub mod motion;
mod tolerance;

use motion::Move;
use robot_post::machine::{MachineProfile, DEFAULT_JERK};
use slicer::toolpath::{MoveKind, PathPoint, ToolPath};
use tolerance::MIN_MOVE;

/// PLA's density, g/cm³, for profiles without `filament_density`.
pub const PLA_DENSITY: f64 = 1.24;

/// A plan's estimate.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Estimate {
    /// Printing time, s.
    pub time_s: f64,
    /// Filament fed, mm.
    pub filament_mm: f64,
    /// Its mass, g.
    pub filament_g: f64,
}

/// The estimate of `path` on `machine`.
pub fn estimate(path: &ToolPath, machine: &MachineProfile) -> Estimate {
    let pts = &path.points;
    // The plan's lowest bead bottom: beads resting on it go at first-layer speed.
    let plate = pts
        .iter()
        .filter(|q| q.kind == MoveKind::Print)
        .map(|q| q.p[2] - f64::from(q.thickness.max(0.0)))
        .fold(f64::INFINITY, f64::min);
    let cap = machine.max_speed.unwrap_or(f64::INFINITY);
    let print_accel = machine.max_acceleration.unwrap_or(f64::INFINITY);
    let travel_accel = machine.travel_acceleration.unwrap_or(print_accel);
    let jerk = machine.max_jerk.unwrap_or(DEFAULT_JERK);
    let retracts = machine.retraction_length > 0.0;
    // A move from the point before to `q`, at the speed and acceleration of its kind: made
    // again from the points whenever the motion planning asks (the moves of a long plan
    // would outweigh its points).
    let move_to = |a: &PathPoint, q: &PathPoint, stop_before: bool| {
        let d = [q.p[0] - a.p[0], q.p[1] - a.p[1], q.p[2] - a.p[2]];
        let length = (d[0] * d[0] + d[1] * d[1] + d[2] * d[2]).sqrt();
        let (speed, accel) = match q.kind {
            MoveKind::Print => {
                let on_plate = q.p[2] - f64::from(q.thickness.max(0.0)) <= plate + 0.01;
                let v = if on_plate {
                    machine.first_layer_speed
                } else {
                    machine.print_speed
                };
                (v, print_accel)
            }
            MoveKind::Travel => (machine.travel_speed, travel_accel),
        };
        Move {
            length,
            dir: [d[0] / length, d[1] / length, d[2] / length],
            speed: speed.min(cap),
            accel,
            stop_before,
        }
    };
    let long = |a: &PathPoint, q: &PathPoint| {
        let d = [q.p[0] - a.p[0], q.p[1] - a.p[1], q.p[2] - a.p[2]];
        (d[0] * d[0] + d[1] * d[1] + d[2] * d[2]).sqrt() >= MIN_MOVE
    };
    // The moves, first to last, each made again from its points whenever the motion planning
    // walks them (a list of a long plan's moves would outweigh its points). A retraction (or
    // its return) waits before the next move: the machine stops before it.
    let moves = || {
        let (mut printing, mut stop, mut any) = (false, true, false);
        pts.windows(2).filter_map(move |w| {
            let (a, q) = (&w[0], &w[1]);
            match filament_turn(&mut printing, q.kind) {
                Some(Turn::Retract) => stop |= retracts,
                Some(Turn::Resume) => stop |= retracts && any,
                None => {}
            }
            long(a, q).then(|| {
                any = true;
                move_to(a, q, std::mem::take(&mut stop))
            })
        })
    };
    // The same moves last to first (where the machine stops matters only going forward).
    let reversed = pts
        .windows(2)
        .rev()
        .filter(|w| long(&w[0], &w[1]))
        .map(|w| move_to(&w[0], &w[1], false));
    // The filament, and a retraction and its return around each travel that follows printing.
    let mut retraction_time = 0.0;
    let mut filament = 0.0;
    let mut printing = false;
    for q in pts.iter().skip(1) {
        if q.kind == MoveKind::Print {
            filament += q.e;
        }
        if filament_turn(&mut printing, q.kind) == Some(Turn::Retract) && retracts {
            retraction_time += 2.0 * machine.retraction_length / machine.retraction_speed;
        }
    }
    let area = std::f64::consts::PI * machine.filament_diameter.powi(2) / 4.0;
    let density = machine.filament_density.unwrap_or(PLA_DENSITY) / 1000.0;
    Estimate {
        time_s: motion::time_of(moves, reversed, jerk) + retraction_time,
        filament_mm: filament,
        filament_g: filament * area * density,
    }
}

/// Where the filament is retracted or fed back (with a retraction in the profile).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Turn {
    /// A travel after printing: the filament is retracted.
    Retract,
    /// Printing after travel: the filament is fed back.
    Resume,
}

/// The turn a move of `kind` makes after the moves before it (`printing`: the last one
/// printed, updated), if any.
fn filament_turn(printing: &mut bool, kind: MoveKind) -> Option<Turn> {
    let now = kind == MoveKind::Print;
    let was = std::mem::replace(printing, now);
    match (was, now) {
        (true, false) => Some(Turn::Retract),
        (false, true) => Some(Turn::Resume),
        _ => None,
    }
}

/// `1h 2m 3s`, as slicers write times.
pub fn hms(seconds: f64) -> String {
    let s = seconds.max(0.0).round() as u64;
    let (h, m, s) = (s / 3600, (s / 60) % 60, s % 60);
    if h > 0 {
        format!("{h}h {m}m {s}s")
    } else if m > 0 {
        format!("{m}m {s}s")
    } else {
        format!("{s}s")
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use robot_post::machine::MachineKind;
    use slicer::toolpath::PathPoint;

    fn q(x: f64, z: f64, kind: MoveKind, e: f64) -> PathPoint {
        PathPoint {
            feature: 0,
            layer: 0,
            kind,
            p: [x, 0.0, z],
            axis: [0.0, 0.0, 1.0],
            e,
            thickness: 0.2,
            width: 0.45,
            role: slicer::toolpath::Role::Perimeter,
        }
    }

    fn qy(x: f64, y: f64, z: f64, kind: MoveKind) -> PathPoint {
        let e = if kind == MoveKind::Print { 0.1 } else { 0.0 };
        PathPoint {
            p: [x, y, z],
            ..q(0.0, z, kind, e)
        }
    }

    /// Without accelerations in the profile: each move's length over its speed, exactly,
    /// plus the retractions.
    #[test]
    fn time_is_length_over_speed_plus_retractions() {
        let mut m = MachineProfile::builtin(MachineKind::Marlin);
        m.max_acceleration = None;
        m.travel_acceleration = None;
        // 10 mm on the plate, travel 5 mm, 20 mm one layer up.
        let path = ToolPath {
            points: vec![
                q(0.0, 0.2, MoveKind::Travel, 0.0),
                q(10.0, 0.2, MoveKind::Print, 0.4),
                q(15.0, 0.4, MoveKind::Travel, 0.0),
                q(35.0, 0.4, MoveKind::Print, 0.8),
            ],
        };
        let e = estimate(&path, &m);
        let travel = (25.0f64 + 0.04).sqrt();
        let want = 10.0 / m.first_layer_speed
            + 2.0 * m.retraction_length / m.retraction_speed
            + travel / m.travel_speed
            + 20.0 / m.print_speed;
        assert!((e.time_s - want).abs() < 1e-12, "{} vs {want}", e.time_s);
        assert!((e.filament_mm - 1.2).abs() < 1e-12);
        let g = 1.2 * std::f64::consts::PI * 1.75f64.powi(2) / 4.0 * PLA_DENSITY / 1000.0;
        assert!((e.filament_g - g).abs() < 1e-12);
        assert_eq!(hms(3723.4), "1h 2m 3s");
        assert_eq!(hms(59.6), "1m 0s");
    }

    /// The time of one move under the speed envelope `min(V, √(v0² + 2ax), √(v1² + 2a(L−x)))`,
    /// integrated numerically (`∫ dx / v`): apart from the closed form the estimate uses.
    fn integrated(l: f64, v: f64, a: f64, v0: f64, v1: f64) -> f64 {
        let n = 200_000;
        let dx = l / n as f64;
        (0..n)
            .map(|i| {
                let x = (i as f64 + 0.5) * dx;
                let s = v
                    .min((v0 * v0 + 2.0 * a * x).sqrt())
                    .min((v1 * v1 + 2.0 * a * (l - x)).sqrt());
                dx / s
            })
            .sum()
    }

    /// With the built-in Marlin profile's accelerations and jerk: a square on the plate, a
    /// travel up, a square on the next layer, a travel away. The speeds where moves meet,
    /// worked out by hand: the jerk at the program's start and end and around each
    /// retraction, jerk/√2 at the squares' right-angle corners, the travels' turn from the
    /// squares' last side. Each move's time integrated apart; the sum within 2 %.
    #[test]
    fn trapezoids_match_an_independent_sum() {
        let m = MachineProfile::builtin(MachineKind::Marlin);
        let (a, at) = (
            m.max_acceleration.unwrap_or(f64::INFINITY),
            m.travel_acceleration.unwrap_or(f64::INFINITY),
        );
        let j = m.max_jerk.unwrap_or(DEFAULT_JERK);
        let corner = j / 2f64.sqrt();
        let s = 20.0;
        let mut pts = vec![qy(0.0, 0.0, 0.2, MoveKind::Travel)];
        for z in [0.2, 0.4] {
            if z > 0.2 {
                pts.push(qy(0.0, 0.0, z, MoveKind::Travel));
            }
            for (x, y) in [(s, 0.0), (s, s), (0.0, s), (0.0, 0.0)] {
                pts.push(qy(x, y, z, MoveKind::Print));
            }
        }
        pts.push(qy(30.0, 40.0, 0.4, MoveKind::Travel));
        let path = ToolPath { points: pts };
        let got = estimate(&path, &m).time_s;
        let (v1, v2, vt) = (m.first_layer_speed, m.print_speed, m.travel_speed);
        // Each print square: from the stop (jerk) round three corners to the stop before the
        // travel (jerk).
        let square = |v: f64| {
            integrated(s, v, a, j, corner)
                + 2.0 * integrated(s, v, a, corner, corner)
                + integrated(s, v, a, corner, j)
        };
        let want = square(v1)
            + integrated(0.2, vt, at, j.min(vt), j)
            + square(v2)
            + integrated(50.0, vt, at, j, j)
            + 2.0 * 2.0 * m.retraction_length / m.retraction_speed;
        assert!(
            (got - want).abs() <= 0.02 * want,
            "estimate {got} s, independent sum {want} s"
        );
        // The accelerations slow the plan down against constant speeds.
        let mut flat = m.clone();
        flat.max_acceleration = None;
        flat.travel_acceleration = None;
        assert!(estimate(&path, &flat).time_s < got);
    }
}
