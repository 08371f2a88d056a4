//! Foot points on a surface: `(u, v)` of the point nearest to a given one, closed-form where
//! the surface has an inverse, Gauss–Newton from a hint or from a grid's nearest samples
//! elsewhere.

use super::{NurbsSurfaceData, Surface};
use crate::math::{nearest_periodic, P3};
use crate::tolerance::*;

/// Grid samples a B-spline projection starts from, nearest first, until one lands on the
/// surface ([`Surface::project`]).
const GRID_STARTS: usize = 16;
/// Grid samples a span of a B-spline, per degree plus one ([`GRID_MAX`] at most): a tap's
/// flank, 20 turns a pitch of 1 mm apart in 8 spans, got 88 samples along its 700 mm (a
/// sample 8 mm from the next, 16 starts all a turn away).
const GRID_PER_SPAN: usize = 4;
/// The most grid samples of a B-spline's direction for [`GRID_STARTS`]: its spans times its
/// degree plus one, up to this (64 left a helical flank of 13 turns sampled 7 mm apart along
/// the helix, its turns 1.5 mm apart).
const GRID_MAX: usize = 512;

impl Surface {
    /// The parameters `(u, v)` of the point of the surface nearest to `p`. Periodic parameters
    /// come back in any period: callers unwrap them. `hint` seeds the search for B-splines and
    /// other surfaces without a closed-form inverse.
    pub fn project(&self, p: &P3, hint: Option<(f64, f64)>) -> (f64, f64) {
        match self {
            Surface::Plane { frame } => {
                let l = frame.local(p);
                (l.x, l.y)
            }
            Surface::Cylinder { frame, .. } => {
                let l = frame.local(p);
                (l.y.atan2(l.x), l.z)
            }
            Surface::Cone {
                frame,
                radius,
                semi_angle,
            } => {
                let l = frame.local(p);
                let t = semi_angle.tan();
                let rho = (l.x * l.x + l.y * l.y).sqrt();
                let v = ((rho - radius) * t + l.z) / (1.0 + t * t);
                let r = radius + v * t;
                // On the other nappe the angle turns by π.
                let u = if r >= 0.0 {
                    l.y.atan2(l.x)
                } else {
                    (-l.y).atan2(-l.x)
                };
                (u, v)
            }
            Surface::Sphere { frame, .. } => {
                let l = frame.local(p);
                (l.y.atan2(l.x), l.z.atan2((l.x * l.x + l.y * l.y).sqrt()))
            }
            Surface::Torus { frame, major, .. } => {
                let l = frame.local(p);
                let rho = (l.x * l.x + l.y * l.y).sqrt();
                (l.y.atan2(l.x), l.z.atan2(rho - major))
            }
            Surface::Revolution(rev) => {
                let w = p - rev.origin;
                let a = w.dot(&rev.axis);
                let r = w - rev.axis * a;
                let e2 = rev.axis.cross(&rev.e1);
                let phi = r.dot(&e2).atan2(r.dot(&rev.e1));
                let q = rev.origin + rev.axis * a + rev.e1 * r.norm();
                let v = match hint {
                    Some((_, hv)) => rev.profile.project_near(&q, hv),
                    None => rev.profile.project(&q),
                };
                let (_, rv) = rev.parts(v);
                let phi_v = rv.dot(&e2).atan2(rv.dot(&rev.e1));
                self.polish(p, (phi - phi_v, v))
            }
            Surface::Extrusion { profile, dir } => {
                let mut v = 0.0;
                let mut u = hint.map(|h| h.0).unwrap_or_else(|| profile.project(p));
                for _ in 0..3 {
                    u = profile.project_near(&(p - dir * v), u);
                    v = (p - profile.eval(u)).dot(dir);
                }
                self.polish(p, (u, v))
            }
            Surface::Nurbs(n) => {
                // Points of other writers lie off the surface by their modelling tolerance.
                let near = 1e-4f64.max(POINT_COINCIDENCE * (1.0 + p.coords.norm()));
                let off = |q: (f64, f64)| (self.eval(q.0, q.1) - p).norm();
                if let Some(h) = hint {
                    let q = self.polish(p, h);
                    if off(q) < near {
                        return q;
                    }
                }
                // From the nearest samples of a grid over the surface, the best foot: the
                // nearest sample alone can lie on the wrong turn of a helical flank (turns
                // 1.5 mm apart), where the search stops on a foot a turn away or on the
                // surface's edge.
                let mut best: Option<((f64, f64), f64)> = None;
                for start in self.grid_starts(p, n, GRID_STARTS) {
                    let q = self.polish(p, start);
                    let d = off(q);
                    if best.is_none_or(|(_, b)| d < b) {
                        best = Some((q, d));
                    }
                    if d < near {
                        break;
                    }
                }
                best.map_or_else(|| self.polish(p, (n.u.0, n.v.0)), |(q, _)| q)
            }
            Surface::Offset { basis, .. } => {
                let uv = basis.project(p, hint);
                self.polish(p, uv)
            }
        }
    }

    /// The parameters of the foot of `p` found from `start` alone: the closed form where the
    /// surface has one, else Gauss–Newton steps from `start` (no grid search). For a point
    /// known to lie near the surface about `start`, such as a point of a face's triangulation
    /// whose `(u, v)` was interpolated from its triangle's corners: [`Surface::project`]
    /// without a hint searches the whole surface for each point.
    pub fn project_from(&self, p: &P3, start: (f64, f64)) -> (f64, f64) {
        match self {
            Surface::Nurbs(_) => self.polish(p, start),
            _ => self.project(p, Some(start)),
        }
    }

    /// The `k` samples of a grid over the surface nearest to `p` (nearest first), as `(u, v)`:
    /// starts for [`Surface::polish`].
    fn grid_starts(&self, p: &P3, n: &NurbsSurfaceData, k: usize) -> Vec<(f64, f64)> {
        let (nu, nv, pts) = n.samples.get_or_init(|| {
            let nu = (GRID_PER_SPAN * n.spans.0 * (n.degree.0 + 1)).clamp(8, GRID_MAX);
            let nv = (GRID_PER_SPAN * n.spans.1 * (n.degree.1 + 1)).clamp(8, GRID_MAX);
            let mut pts = Vec::with_capacity((nu + 1) * (nv + 1));
            for i in 0..=nu {
                let u = n.u.0 + (n.u.1 - n.u.0) * i as f64 / nu as f64;
                for j in 0..=nv {
                    let v = n.v.0 + (n.v.1 - n.v.0) * j as f64 / nv as f64;
                    pts.push(n.raw(u, v));
                }
            }
            (nu, nv, pts)
        });
        let mut by: Vec<(f64, usize)> = pts
            .iter()
            .enumerate()
            .map(|(k, q)| ((q - p).norm_squared(), k))
            .collect();
        let k = k.min(by.len());
        if k == 0 {
            return vec![];
        }
        by.select_nth_unstable_by(k - 1, |a, b| a.0.total_cmp(&b.0));
        by.truncate(k);
        by.sort_by(|a, b| a.0.total_cmp(&b.0));
        by.into_iter()
            .map(|(_, best)| {
                let (i, j) = (best / (nv + 1), best % (nv + 1));
                (
                    n.u.0 + (n.u.1 - n.u.0) * i as f64 / *nu as f64,
                    n.v.0 + (n.v.1 - n.v.0) * j as f64 / *nv as f64,
                )
            })
            .collect()
    }

    /// Gauss–Newton steps towards the foot point of `p`, staying inside bounded ranges.
    fn polish(&self, p: &P3, (mut u, mut v): (f64, f64)) -> (f64, f64) {
        let (bu, bv) = self.bounds();
        let (pu, pv) = (self.u_period(), self.v_period());
        let clamp_u = |x: f64| {
            if pu.is_none() {
                bu.map(|(a, b)| x.clamp(a, b)).unwrap_or(x)
            } else {
                x
            }
        };
        let clamp_v = |x: f64| {
            if pv.is_none() {
                bv.map(|(a, b)| x.clamp(a, b)).unwrap_or(x)
            } else {
                x
            }
        };
        let mut dist = (self.eval(u, v) - p).norm();
        for _ in 0..40 {
            let (q, su, sv) = self.eval_d1(u, v);
            let d = q - p;
            let a11 = su.norm_squared();
            let a12 = su.dot(&sv);
            let a22 = sv.norm_squared();
            let b1 = -su.dot(&d);
            let b2 = -sv.dot(&d);
            let det = a11 * a22 - a12 * a12;
            let (du, dv) = if det.abs() > SINGULAR_DET_RELATIVE * (a11 * a22).max(NONZERO) {
                ((b1 * a22 - b2 * a12) / det, (a11 * b2 - a12 * b1) / det)
            } else if a11 > a22 && a11 > 0.0 {
                (b1 / a11, 0.0)
            } else if a22 > 0.0 {
                (0.0, b2 / a22)
            } else {
                break;
            };
            if !du.is_finite() || !dv.is_finite() {
                break;
            }
            // Backtrack so the distance never grows.
            let mut f = 1.0;
            let mut improved = false;
            for _ in 0..8 {
                let nu = clamp_u(u + f * du);
                let nv = clamp_v(v + f * dv);
                let nd = (self.eval(nu, nv) - p).norm();
                if nd <= dist {
                    let small = (nu - u).abs() + (nv - v).abs() < PROJECTION_STEP;
                    u = nu;
                    v = nv;
                    dist = nd;
                    improved = !small;
                    break;
                }
                f *= 0.5;
            }
            if !improved {
                break;
            }
        }
        (u, v)
    }

    /// Shifts a periodic parameter pair so it lies nearest to `reference`.
    pub fn unwrap_near(&self, uv: (f64, f64), reference: (f64, f64)) -> (f64, f64) {
        let u = self
            .u_period()
            .map(|p| nearest_periodic(uv.0, reference.0, p))
            .unwrap_or(uv.0);
        let v = self
            .v_period()
            .map(|p| nearest_periodic(uv.1, reference.1, p))
            .unwrap_or(uv.1);
        (u, v)
    }
}
