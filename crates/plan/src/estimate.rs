//! How long a plan prints and how much filament it takes, as a slicer's estimate does: every
//! move at its programmed speed (no acceleration), print moves at `print_speed`, those of
//! beads resting on the build plate (the plan's lowest layer) at `first_layer_speed`, travels at
//! `travel_speed`, and a retraction and its return at `retraction_speed` around each travel
//! that follows printing. Filament mass from the filament's cross-section and
//! `filament_density` (g/cm³; 1.24, PLA, when the profile does not say).

use robot_post::machine::MachineProfile;
use slicer::toolpath::{MoveKind, ToolPath};

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
        .map(|q| q.p[2] - q.thickness.max(0.0))
        .fold(f64::INFINITY, f64::min);
    let mut time = 0.0;
    let mut filament = 0.0;
    let mut printing = false;
    for w in pts.windows(2) {
        let (a, q) = (&w[0], &w[1]);
        let d = ((q.p[0] - a.p[0]).powi(2) + (q.p[1] - a.p[1]).powi(2) + (q.p[2] - a.p[2]).powi(2))
            .sqrt();
        match q.kind {
            MoveKind::Print => {
                let on_plate = q.p[2] - q.thickness.max(0.0) <= plate + 0.01;
                let v = if on_plate {
                    machine.first_layer_speed
                } else {
                    machine.print_speed
                };
                time += d / v;
                filament += q.e;
                printing = true;
            }
            MoveKind::Travel => {
                if printing && machine.retraction_length > 0.0 {
                    time += 2.0 * machine.retraction_length / machine.retraction_speed;
                }
                time += d / machine.travel_speed;
                printing = false;
            }
        }
    }
    let area = std::f64::consts::PI * machine.filament_diameter.powi(2) / 4.0;
    let density = machine.filament_density.unwrap_or(PLA_DENSITY) / 1000.0;
    Estimate {
        time_s: time,
        filament_mm: filament,
        filament_g: filament * area * density,
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

    #[test]
    fn time_is_length_over_speed_plus_retractions() {
        let m = MachineProfile::builtin(MachineKind::Marlin);
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
}
