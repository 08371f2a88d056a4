//! Exact surfaces with their natural parametrisation, as ISO 10303-42 defines it, so that the
//! natural normal `S_u × S_v` is the one a face's `same_sense` refers to.

use crate::curve::Curve;
use crate::math::{wrap, Frame, P3, V3};
use crate::tolerance::*;
use std::f64::consts::{FRAC_PI_2, TAU};
use truck_geometry::prelude as tg;

mod project;

/// A closed parameter interval `(first, last)`.
pub type Range = (f64, f64);

/// A rational B-spline surface (truck's homogeneous representation).
pub type NurbsSurface = tg::NurbsSurface<tg::Vector4>;

/// A surface `(u, v) ↦ S(u, v)`.
#[derive(Debug, Clone)]
pub enum Surface {
    /// `o + u·x + v·y`.
    Plane {
        /// Placement.
        frame: Frame,
    },
    /// `o + r(cos u·x + sin u·y) + v·z`.
    Cylinder {
        /// Placement; `z` is the axis.
        frame: Frame,
        /// Radius.
        radius: f64,
    },
    /// `o + (r + v tan α)(cos u·x + sin u·y) + v·z`.
    Cone {
        /// Placement; `z` is the axis.
        frame: Frame,
        /// Radius in the plane `v = 0`.
        radius: f64,
        /// Semi-angle α in radians.
        semi_angle: f64,
    },
    /// `o + r cos v(cos u·x + sin u·y) + r sin v·z`.
    Sphere {
        /// Placement.
        frame: Frame,
        /// Radius.
        radius: f64,
    },
    /// `o + (R + r cos v)(cos u·x + sin u·y) + r sin v·z`.
    Torus {
        /// Placement; `z` is the axis.
        frame: Frame,
        /// Major radius `R`.
        major: f64,
        /// Minor radius `r`.
        minor: f64,
    },
    /// A profile `λ(v)` rotated by `u` about an axis.
    Revolution(Box<Revolution>),
    /// `λ(u) + v·d`.
    Extrusion {
        /// The profile.
        profile: Box<Curve>,
        /// Unit extrusion direction.
        dir: V3,
    },
    /// A (rational) B-spline surface.
    Nurbs(Box<NurbsSurfaceData>),
    /// `B(u,v) + d·N_B(u,v)`.
    Offset {
        /// The surface offset.
        basis: Box<Surface>,
        /// Signed distance along the basis' natural normal.
        distance: f64,
    },
}

/// A surface of revolution: `u` is the angle, `v` the profile's parameter.
#[derive(Debug, Clone)]
pub struct Revolution {
    /// The profile curve `λ(v)`.
    pub profile: Curve,
    /// A point on the axis.
    pub origin: P3,
    /// Unit axis direction.
    pub axis: V3,
    /// Unit radial direction of the profile's half-plane (angle 0 of the projection).
    pub e1: V3,
}

impl Revolution {
    /// Builds the revolution, finding the profile's half-plane.
    pub fn new(profile: Curve, origin: P3, axis: V3) -> Self {
        let (a, b) = profile.range();
        let (a, b) = if a.is_finite() && b.is_finite() {
            (a, b)
        } else {
            (0.0, 1.0)
        };
        let mut e1 = None;
        let mut best = 0.0;
        for i in 0..=32 {
            let w = profile.eval(a + (b - a) * i as f64 / 32.0) - origin;
            let r = w - axis * w.dot(&axis);
            if r.norm() > best {
                best = r.norm();
                e1 = Some(r / best);
            }
        }
        let e1 = e1.unwrap_or_else(|| crate::math::any_perpendicular(&axis));
        Revolution {
            profile,
            origin,
            axis,
            e1,
        }
    }
    fn parts(&self, v: f64) -> (f64, V3) {
        let w = self.profile.eval(v) - self.origin;
        let a = w.dot(&self.axis);
        (a, w - self.axis * a)
    }
}

/// A B-spline surface with its parameter ranges and closure cached.
#[derive(Debug, Clone)]
pub struct NurbsSurfaceData {
    /// The surface.
    pub surface: NurbsSurface,
    /// `u` range.
    pub u: (f64, f64),
    /// `v` range.
    pub v: (f64, f64),
    /// Knot spans in `u` and `v`.
    pub spans: (usize, usize),
    /// Degrees in `u` and `v`.
    pub degree: (usize, usize),
    /// Whether `S(u0, v) = S(u1, v)` for all `v`.
    pub closed_u: bool,
    /// Whether `S(u, v0) = S(u, v1)` for all `u`.
    pub closed_v: bool,
    /// The same surface for fast local evaluation.
    pub local: crate::nurbs::LocalSurface,
    /// A grid of sample points, made on first use, that seeds point projection.
    pub samples: std::sync::OnceLock<(usize, usize, Vec<P3>)>,
}

fn knot_range(kv: &tg::KnotVec, degree: usize) -> ((f64, f64), usize) {
    let n = kv.len();
    let d = degree.min(n.saturating_sub(1) / 2);
    let mut spans = 0;
    for i in d..n.saturating_sub(d + 1) {
        if kv[i + 1] > kv[i] {
            spans += 1;
        }
    }
    ((kv[d], kv[n - 1 - d]), spans.max(1))
}

impl NurbsSurfaceData {
    /// Wraps a truck NURBS surface, finding its ranges and whether it closes on itself.
    pub fn new(surface: NurbsSurface) -> Self {
        let (du, dv) = (surface.udegree(), surface.vdegree());
        let (u, su) = knot_range(surface.uknot_vec(), du);
        let (v, sv) = knot_range(surface.vknot_vec(), dv);
        let local = crate::nurbs::LocalSurface {
            ku: surface.uknot_vec().to_vec(),
            kv: surface.vknot_vec().to_vec(),
            degree: (du, dv),
            n: (
                surface.control_points().len(),
                surface.control_points().first().map_or(0, |r| r.len()),
            ),
            cps: surface
                .control_points()
                .iter()
                .flatten()
                .map(|c| [c.x, c.y, c.z, c.w])
                .collect(),
        };
        let mut d = NurbsSurfaceData {
            surface,
            u,
            v,
            spans: (su, sv),
            degree: (du, dv),
            closed_u: false,
            closed_v: false,
            local,
            samples: std::sync::OnceLock::new(),
        };
        let size = d.size_estimate();
        let tol = SURFACE_COINCIDENCE * size.max(1e-3);
        d.closed_u = (0..=8).all(|i| {
            let t = v.0 + (v.1 - v.0) * i as f64 / 8.0;
            (d.raw(u.0, t) - d.raw(u.1, t)).norm() <= tol
        });
        d.closed_v = (0..=8).all(|i| {
            let t = u.0 + (u.1 - u.0) * i as f64 / 8.0;
            (d.raw(t, v.0) - d.raw(t, v.1)).norm() <= tol
        });
        d
    }
    fn size_estimate(&self) -> f64 {
        let mut bb = crate::math::Aabb::empty();
        for i in 0..=4 {
            for j in 0..=4 {
                let p = self.raw(
                    self.u.0 + (self.u.1 - self.u.0) * i as f64 / 4.0,
                    self.v.0 + (self.v.1 - self.v.0) * j as f64 / 4.0,
                );
                bb.add(&p);
            }
        }
        bb.diagonal()
    }
    fn raw(&self, u: f64, v: f64) -> P3 {
        let [p, _, _] = self.local.eval_d1(u, v);
        P3::new(p[0], p[1], p[2])
    }
    fn clamp_uv(&self, u: f64, v: f64) -> (f64, f64) {
        let u = if self.closed_u {
            wrap(u, self.u.0, self.u.1 - self.u.0)
        } else {
            u.clamp(self.u.0, self.u.1)
        };
        let v = if self.closed_v {
            wrap(v, self.v.0, self.v.1 - self.v.0)
        } else {
            v.clamp(self.v.0, self.v.1)
        };
        (u, v)
    }
}

impl Surface {
    /// The point at `(u, v)`.
    pub fn eval(&self, u: f64, v: f64) -> P3 {
        match self {
            Surface::Plane { frame } => frame.at(u, v, 0.0),
            Surface::Cylinder { frame, radius } => frame.at(radius * u.cos(), radius * u.sin(), v),
            Surface::Cone {
                frame,
                radius,
                semi_angle,
            } => {
                let r = radius + v * semi_angle.tan();
                frame.at(r * u.cos(), r * u.sin(), v)
            }
            Surface::Sphere { frame, radius } => frame.at(
                radius * v.cos() * u.cos(),
                radius * v.cos() * u.sin(),
                radius * v.sin(),
            ),
            Surface::Torus {
                frame,
                major,
                minor,
            } => {
                let r = major + minor * v.cos();
                frame.at(r * u.cos(), r * u.sin(), minor * v.sin())
            }
            Surface::Revolution(rev) => {
                let (a, r) = rev.parts(v);
                rev.origin + rev.axis * a + r * u.cos() + rev.axis.cross(&r) * u.sin()
            }
            Surface::Extrusion { profile, dir } => profile.eval(u) + dir * v,
            Surface::Nurbs(n) => {
                let (u, v) = n.clamp_uv(u, v);
                n.raw(u, v)
            }
            Surface::Offset { basis, distance } => {
                let n = basis.normal(u, v).unwrap_or_else(V3::zeros);
                basis.eval(u, v) + n * *distance
            }
        }
    }

    /// The point and first partial derivatives `(S, S_u, S_v)` in one evaluation where the
    /// surface allows (B-splines, surfaces of revolution); the same as `eval` and `derivs`.
    pub fn eval_d1(&self, u: f64, v: f64) -> (P3, V3, V3) {
        match self {
            Surface::Nurbs(n) => {
                let (u, v) = n.clamp_uv(u, v);
                let [p, a, b] = n.local.eval_d1(u, v);
                (
                    P3::new(p[0], p[1], p[2]),
                    V3::new(a[0], a[1], a[2]),
                    V3::new(b[0], b[1], b[2]),
                )
            }
            Surface::Revolution(rev) => {
                let (pt, w1) = rev.profile.eval_d1(v);
                let w = pt - rev.origin;
                let ax = rev.axis;
                let a = w.dot(&ax);
                let r = w - ax * a;
                let a1 = w1.dot(&ax);
                let r1 = w1 - ax * a1;
                let (s, c) = u.sin_cos();
                let p = rev.origin + ax * a + r * c + ax.cross(&r) * s;
                let su = -r * s + ax.cross(&r) * c;
                let sv = ax * a1 + r1 * c + ax.cross(&r1) * s;
                (p, su, sv)
            }
            _ => {
                let (su, sv) = self.derivs(u, v);
                (self.eval(u, v), su, sv)
            }
        }
    }

    /// The first partial derivatives `(S_u, S_v)`.
    pub fn derivs(&self, u: f64, v: f64) -> (V3, V3) {
        match self {
            Surface::Plane { frame } => (frame.x, frame.y),
            Surface::Cylinder { frame, radius } => {
                (frame.vec(-radius * u.sin(), radius * u.cos(), 0.0), frame.z)
            }
            Surface::Cone {
                frame,
                radius,
                semi_angle,
            } => {
                let t = semi_angle.tan();
                let r = radius + v * t;
                (
                    frame.vec(-r * u.sin(), r * u.cos(), 0.0),
                    frame.vec(t * u.cos(), t * u.sin(), 1.0),
                )
            }
            Surface::Sphere { frame, radius } => (
                frame.vec(-radius * v.cos() * u.sin(), radius * v.cos() * u.cos(), 0.0),
                frame.vec(
                    -radius * v.sin() * u.cos(),
                    -radius * v.sin() * u.sin(),
                    radius * v.cos(),
                ),
            ),
            Surface::Torus {
                frame,
                major,
                minor,
            } => {
                let r = major + minor * v.cos();
                (
                    frame.vec(-r * u.sin(), r * u.cos(), 0.0),
                    frame.vec(
                        -minor * v.sin() * u.cos(),
                        -minor * v.sin() * u.sin(),
                        minor * v.cos(),
                    ),
                )
            }
            Surface::Revolution(rev) => {
                let (_, r) = rev.parts(v);
                let w1 = rev.profile.deriv(v);
                let a1 = w1.dot(&rev.axis);
                let r1 = w1 - rev.axis * a1;
                let ax = rev.axis;
                (
                    -r * u.sin() + ax.cross(&r) * u.cos(),
                    ax * a1 + r1 * u.cos() + ax.cross(&r1) * u.sin(),
                )
            }
            Surface::Extrusion { profile, dir } => (profile.deriv(u), *dir),
            Surface::Nurbs(n) => {
                let (u, v) = n.clamp_uv(u, v);
                let [_, a, b] = n.local.eval_d1(u, v);
                (V3::new(a[0], a[1], a[2]), V3::new(b[0], b[1], b[2]))
            }
            Surface::Offset { .. } => {
                let h = 1e-6;
                let su = (self.eval(u + h, v) - self.eval(u - h, v)) / (2.0 * h);
                let sv = (self.eval(u, v + h) - self.eval(u, v - h)) / (2.0 * h);
                (su, sv)
            }
        }
    }

    /// [`Surface::eval`] and [`Surface::normal`] together, the same values bit for bit: a
    /// cylinder, cone or surface of revolution takes the angle's sine and cosine once for
    /// both, and a surface of revolution evaluates its profile once (point and derivative in
    /// one pass) instead of three times.
    pub fn eval_normal(&self, u: f64, v: f64) -> (P3, Option<V3>) {
        let (p, su, sv) = match self {
            Surface::Cylinder { frame, radius } => {
                let (s, c) = (u.sin(), u.cos());
                (
                    frame.at(radius * c, radius * s, v),
                    frame.vec(-radius * s, radius * c, 0.0),
                    frame.z,
                )
            }
            Surface::Cone {
                frame,
                radius,
                semi_angle,
            } => {
                let (s, c) = (u.sin(), u.cos());
                let t = semi_angle.tan();
                let r = radius + v * t;
                (
                    frame.at(r * c, r * s, v),
                    frame.vec(-r * s, r * c, 0.0),
                    frame.vec(t * c, t * s, 1.0),
                )
            }
            Surface::Revolution(rev) => {
                let (pt, w1) = rev.profile.eval_d1(v);
                let ax = rev.axis;
                let w = pt - rev.origin;
                let a = w.dot(&ax);
                let r = w - ax * a;
                let (s, c) = (u.sin(), u.cos());
                let a1 = w1.dot(&ax);
                let r1 = w1 - ax * a1;
                (
                    rev.origin + ax * a + r * c + ax.cross(&r) * s,
                    -r * s + ax.cross(&r) * c,
                    ax * a1 + r1 * c + ax.cross(&r1) * s,
                )
            }
            _ => return (self.eval(u, v), self.normal(u, v)),
        };
        // As `normal`; where the derivatives degenerate, `normal` itself steps off.
        let n = su.cross(&sv);
        let scale = su.norm() * sv.norm();
        if scale > 0.0 && n.norm() > PARALLEL * scale {
            return (p, Some(n / n.norm()));
        }
        (p, self.normal(u, v))
    }

    /// The natural unit normal `S_u × S_v / |S_u × S_v|`, or `None` where it degenerates (a pole,
    /// an apex). Poles of spheres, cones and revolved profiles touching the axis get their limit.
    pub fn normal(&self, u: f64, v: f64) -> Option<V3> {
        match self {
            Surface::Sphere { frame, .. } => {
                Some(frame.vec(v.cos() * u.cos(), v.cos() * u.sin(), v.sin()))
            }
            Surface::Offset { basis, .. } => basis.normal(u, v),
            _ => {
                let (su, sv) = self.derivs(u, v);
                let n = su.cross(&sv);
                let scale = su.norm() * sv.norm();
                if scale > 0.0 && n.norm() > PARALLEL * scale {
                    return Some(n / n.norm());
                }
                // Degenerate: step a little into the domain and take the limit.
                let (du, dv) = self.param_scale();
                for (a, b) in [(0.0, 1e-5), (0.0, -1e-5), (1e-5, 0.0), (-1e-5, 0.0)] {
                    let (su, sv) = self.derivs(u + a * du, v + b * dv);
                    let n = su.cross(&sv);
                    if n.norm() > NORMAL_ZERO * (1.0 + su.norm() * sv.norm()) && n.norm() > 0.0 {
                        return Some(n / n.norm());
                    }
                }
                None
            }
        }
    }

    /// A typical parameter length in `u` and `v` (to size finite differences and steps).
    fn param_scale(&self) -> (f64, f64) {
        match self {
            Surface::Nurbs(n) => (n.u.1 - n.u.0, n.v.1 - n.v.0),
            Surface::Revolution(r) => {
                let (a, b) = r.profile.range();
                (
                    1.0,
                    if a.is_finite() && b.is_finite() {
                        b - a
                    } else {
                        1.0
                    },
                )
            }
            Surface::Extrusion { profile, .. } => {
                let (a, b) = profile.range();
                (
                    if a.is_finite() && b.is_finite() {
                        b - a
                    } else {
                        1.0
                    },
                    1.0,
                )
            }
            Surface::Offset { basis, .. } => basis.param_scale(),
            _ => (1.0, 1.0),
        }
    }

    /// The period in `u`, where the surface closes on itself in `u`.
    pub fn u_period(&self) -> Option<f64> {
        match self {
            Surface::Cylinder { .. }
            | Surface::Cone { .. }
            | Surface::Sphere { .. }
            | Surface::Torus { .. }
            | Surface::Revolution(_) => Some(TAU),
            Surface::Extrusion { profile, .. } => {
                if let Some(p) = profile.period() {
                    Some(p)
                } else if profile.is_closed(CLOSED_PROFILE) {
                    let (a, b) = profile.range();
                    Some(b - a)
                } else {
                    None
                }
            }
            Surface::Nurbs(n) => n.closed_u.then_some(n.u.1 - n.u.0),
            Surface::Offset { basis, .. } => basis.u_period(),
            Surface::Plane { .. } => None,
        }
    }

    /// The period in `v`, where the surface closes on itself in `v`.
    pub fn v_period(&self) -> Option<f64> {
        match self {
            Surface::Torus { .. } => Some(TAU),
            Surface::Revolution(r) if r.profile.period().is_some() => r.profile.period(),
            Surface::Nurbs(n) => n.closed_v.then_some(n.v.1 - n.v.0),
            Surface::Offset { basis, .. } => basis.v_period(),
            _ => None,
        }
    }

    /// The finite parameter bounds of the surface, per direction (`None` where unbounded or
    /// periodic).
    pub fn bounds(&self) -> (Option<Range>, Option<Range>) {
        match self {
            Surface::Sphere { .. } => (None, Some((-FRAC_PI_2, FRAC_PI_2))),
            Surface::Revolution(r) => {
                let (a, b) = r.profile.range();
                (None, (a.is_finite() && b.is_finite()).then_some((a, b)))
            }
            Surface::Extrusion { profile, .. } => {
                let (a, b) = profile.range();
                ((a.is_finite() && b.is_finite()).then_some((a, b)), None)
            }
            Surface::Nurbs(n) => (Some(n.u), Some(n.v)),
            Surface::Offset { basis, .. } => basis.bounds(),
            _ => (None, None),
        }
    }

    /// Parameter values where the surface collapses: `(v values where S_u = 0, u values where
    /// S_v = 0)`. A sphere's poles, a cone's apex, a revolved profile touching the axis, a
    /// B-spline with a collapsed boundary row.
    pub fn singular_lines(&self) -> (Vec<f64>, Vec<f64>) {
        match self {
            Surface::Sphere { .. } => (vec![-FRAC_PI_2, FRAC_PI_2], vec![]),
            Surface::Cone {
                radius, semi_angle, ..
            } => {
                let t = semi_angle.tan();
                if t.abs() > ANGLE_ZERO {
                    (vec![-radius / t], vec![])
                } else {
                    (vec![], vec![])
                }
            }
            Surface::Offset { basis, .. } => basis.singular_lines(),
            Surface::Plane { .. } | Surface::Cylinder { .. } | Surface::Torus { .. } => {
                (vec![], vec![])
            }
            _ => {
                let (bu, bv) = self.bounds();
                let mut vs = vec![];
                let mut us = vec![];
                let size = self.size_hint();
                let tol = SURFACE_COINCIDENCE * size.max(1e-3);
                let (ur, vr) = self.sample_ranges();
                if let Some((a, b)) = bv {
                    for v in [a, b] {
                        let p0 = self.eval(ur.0, v);
                        if (0..=8).all(|i| {
                            (self.eval(ur.0 + (ur.1 - ur.0) * i as f64 / 8.0, v) - p0).norm() <= tol
                        }) {
                            vs.push(v);
                        }
                    }
                }
                if let Some((a, b)) = bu {
                    for u in [a, b] {
                        let p0 = self.eval(u, vr.0);
                        if (0..=8).all(|i| {
                            (self.eval(u, vr.0 + (vr.1 - vr.0) * i as f64 / 8.0) - p0).norm() <= tol
                        }) {
                            us.push(u);
                        }
                    }
                }
                (vs, us)
            }
        }
    }

    fn sample_ranges(&self) -> ((f64, f64), (f64, f64)) {
        let (bu, bv) = self.bounds();
        let du = self.u_period().map(|p| (0.0, p));
        let dv = self.v_period().map(|p| (0.0, p));
        (
            bu.or(du).unwrap_or((0.0, 1.0)),
            bv.or(dv).unwrap_or((0.0, 1.0)),
        )
    }

    /// The diagonal of a 5×5 sample of the surface over its bounded or periodic range: a
    /// length scale for tolerances.
    pub(crate) fn size_hint(&self) -> f64 {
        let (ur, vr) = self.sample_ranges();
        let mut bb = crate::math::Aabb::empty();
        for i in 0..=4 {
            for j in 0..=4 {
                bb.add(&self.eval(
                    ur.0 + (ur.1 - ur.0) * i as f64 / 4.0,
                    vr.0 + (vr.1 - vr.0) * j as f64 / 4.0,
                ));
            }
        }
        bb.diagonal()
    }

    /// A short name of the surface kind, as `inspect` counts them.
    pub fn kind(&self) -> &'static str {
        match self {
            Surface::Plane { .. } => "plane",
            Surface::Cylinder { .. } => "cylinder",
            Surface::Cone { .. } => "cone",
            Surface::Sphere { .. } => "sphere",
            Surface::Torus { .. } => "torus",
            Surface::Revolution(_) => "revolution",
            Surface::Extrusion { .. } => "extrusion",
            Surface::Nurbs(_) => "bspline",
            Surface::Offset { .. } => "offset",
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::curve::{p3, v3};

    #[test]
    fn local_evaluation_agrees_with_truck() {
        // A rational bicubic-by-quadratic patch with interior knots and uneven weights.
        let ku = tg::KnotVec::from(vec![0.0, 0.0, 0.0, 0.0, 0.4, 0.7, 1.0, 1.0, 1.0, 1.0]);
        let kv = tg::KnotVec::from(vec![0.0, 0.0, 0.0, 0.5, 1.0, 1.0, 1.0]);
        let cps: Vec<Vec<tg::Vector4>> = (0..6)
            .map(|i| {
                (0..4)
                    .map(|j| {
                        let w = 1.0 + 0.3 * ((i * 3 + j) % 4) as f64;
                        let (x, y, z) = (i as f64, j as f64, ((i * j) % 3) as f64 - 1.0);
                        tg::Vector4::new(x * w, y * w, z * w, w)
                    })
                    .collect()
            })
            .collect();
        let bs = tg::BSplineSurface::new((ku, kv), cps);
        let surf = NurbsSurface::new(bs);
        let data = NurbsSurfaceData::new(surf.clone());
        let s = Surface::Nurbs(Box::new(data));
        for i in 0..=10 {
            for j in 0..=10 {
                let (u, v) = (i as f64 / 10.0, j as f64 / 10.0);
                let ours = s.eval(u, v);
                let theirs = p3(surf.subs(u, v));
                assert!((ours - theirs).norm() < 1e-10, "point at ({u},{v})");
                let (su, sv) = s.derivs(u, v);
                assert!((su - v3(surf.uder(u, v))).norm() < 1e-8, "S_u at ({u},{v})");
                assert!((sv - v3(surf.vder(u, v))).norm() < 1e-8, "S_v at ({u},{v})");
            }
        }
    }

    fn frame() -> Frame {
        Frame::from_axes(
            P3::new(1.0, -2.0, 0.5),
            Some(V3::new(0.3, 0.2, 1.0)),
            Some(V3::x()),
        )
        .unwrap()
    }

    fn check_round_trip(s: &Surface, uvs: &[(f64, f64)]) {
        for &(u, v) in uvs {
            let p = s.eval(u, v);
            let (pu, pv) = s.project(&p, None);
            let q = s.eval(pu, pv);
            assert!(
                (p - q).norm() < 1e-7,
                "{} at ({u},{v}): {:?} vs {:?}",
                s.kind(),
                p,
                q
            );
            // The analytic derivative agrees with a finite difference.
            let (su, sv) = s.derivs(u, v);
            let h = 1e-6;
            let fu = (s.eval(u + h, v) - s.eval(u - h, v)) / (2.0 * h);
            let fv = (s.eval(u, v + h) - s.eval(u, v - h)) / (2.0 * h);
            assert!(
                (su - fu).norm() < 1e-5 * (1.0 + su.norm()),
                "{} S_u",
                s.kind()
            );
            assert!(
                (sv - fv).norm() < 1e-5 * (1.0 + sv.norm()),
                "{} S_v",
                s.kind()
            );
        }
    }

    #[test]
    fn analytic_surfaces_project_and_differentiate() {
        let uvs = [(0.3, 0.2), (2.0, -0.4), (-2.5, 0.9), (4.0, 0.1)];
        check_round_trip(&Surface::Plane { frame: frame() }, &uvs);
        check_round_trip(
            &Surface::Cylinder {
                frame: frame(),
                radius: 3.0,
            },
            &uvs,
        );
        check_round_trip(
            &Surface::Cone {
                frame: frame(),
                radius: 3.0,
                semi_angle: 0.4,
            },
            &uvs,
        );
        check_round_trip(
            &Surface::Sphere {
                frame: frame(),
                radius: 3.0,
            },
            &uvs,
        );
        check_round_trip(
            &Surface::Torus {
                frame: frame(),
                major: 5.0,
                minor: 1.5,
            },
            &uvs,
        );
        let f = frame();
        let profile = Curve::Line {
            origin: f.at(2.0, 0.0, 0.0),
            dir: (f.x + f.z).normalize(),
        };
        let rev = Surface::Revolution(Box::new(Revolution::new(profile, f.origin, f.z)));
        check_round_trip(&rev, &uvs);
        let ext = Surface::Extrusion {
            profile: Box::new(Curve::Circle {
                frame: f,
                radius: 2.0,
            }),
            dir: (f.z + f.x * 0.2).normalize(),
        };
        check_round_trip(&ext, &uvs);
    }

    #[test]
    fn one_pass_evaluation_agrees_with_separate_calls() {
        let f = frame();
        let profile = Curve::Line {
            origin: f.at(2.0, 0.0, 0.0),
            dir: (f.x + f.z).normalize(),
        };
        let rev = Surface::Revolution(Box::new(Revolution::new(profile, f.origin, f.z)));
        for s in [
            rev,
            Surface::Torus {
                frame: f,
                major: 5.0,
                minor: 1.5,
            },
        ] {
            for (u, v) in [(0.3, 0.2), (2.0, -0.4), (-2.5, 0.9)] {
                let (p, su, sv) = s.eval_d1(u, v);
                let (a, b) = s.derivs(u, v);
                assert!(
                    (p - s.eval(u, v)).norm() < 1e-12
                        && (su - a).norm() < 1e-12
                        && (sv - b).norm() < 1e-12
                );
            }
        }
    }

    #[test]
    fn sphere_normal_points_outward_and_poles_are_singular() {
        let s = Surface::Sphere {
            frame: Frame::world(P3::origin()),
            radius: 2.0,
        };
        let n = s.normal(0.0, 0.0).unwrap();
        assert!((n - V3::x()).norm() < 1e-12);
        assert_eq!(s.singular_lines().0.len(), 2);
        let (su, _) = s.derivs(1.0, FRAC_PI_2);
        assert!(su.norm() < 1e-12);
    }
}
