//! Interior point spacing: parameter steps from the surface's curvature.

use super::options::MeshOptions;
use crate::surface::Surface;
use crate::tolerance::{CURVATURE_RELATIVE, DERIVATIVE_ZERO, PARAMETER_SPAN_FLOOR};

/// How many steps of `step` cover `range`: at least `min`, at most 400 (a grid's side).
pub(super) fn step_count(range: (f64, f64), step: f64, min: usize) -> usize {
    if step.is_finite() {
        ((range.1 - range.0) / step).ceil().clamp(min as f64, 400.0) as usize
    } else {
        min
    }
}

/// Parameter steps `(du, dv)` that keep chords within tolerance, from sampled second differences.
pub(super) fn grid_steps(
    s: &Surface,
    ub: (f64, f64),
    vb: (f64, f64),
    opts: &MeshOptions,
) -> (f64, f64) {
    if matches!(s, Surface::Plane { .. }) {
        return (f64::INFINITY, f64::INFINITY);
    }
    let n = 8;
    let (mut du, mut dv) = (f64::INFINITY, f64::INFINITY);
    let hu = (ub.1 - ub.0).max(PARAMETER_SPAN_FLOOR) * 1e-3;
    let hv = (vb.1 - vb.0).max(PARAMETER_SPAN_FLOOR) * 1e-3;
    for i in 0..=n {
        for j in 0..=n {
            // Sample cell centres: second differences at a clamped domain edge are meaningless.
            let u = ub.0 + (ub.1 - ub.0) * (i as f64 + 0.5) / (n + 1) as f64;
            let v = vb.0 + (vb.1 - vb.0) * (j as f64 + 0.5) / (n + 1) as f64;
            let p = s.eval(u, v);
            let (su, sv) = s.derivs(u, v);
            let suu =
                (s.eval(u + hu, v).coords - p.coords * 2.0 + s.eval(u - hu, v).coords) / (hu * hu);
            let svv =
                (s.eval(u, v + hv).coords - p.coords * 2.0 + s.eval(u, v - hv).coords) / (hv * hv);
            let (muu, mvv) = (suu.norm(), svv.norm());
            if muu > CURVATURE_RELATIVE * (1.0 + su.norm()) {
                du = du.min((8.0 * opts.chord_tol / muu).sqrt());
                if su.norm() > DERIVATIVE_ZERO {
                    du = du.min(opts.angle_tol * su.norm() / muu);
                }
            }
            if mvv > CURVATURE_RELATIVE * (1.0 + sv.norm()) {
                dv = dv.min((8.0 * opts.chord_tol / mvv).sqrt());
                if sv.norm() > DERIVATIVE_ZERO {
                    dv = dv.min(opts.angle_tol * sv.norm() / mvv);
                }
            }
        }
    }
    (du, dv)
}
