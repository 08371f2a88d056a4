//! Exact 3-D curves: the geometry of edges and of swept-surface profiles.

use crate::math::{nearest_periodic, Frame, P3, V3};
use crate::tolerance::{CURVE_NEWTON_STEP, NONZERO, POINT_COINCIDENCE};
use std::f64::consts::TAU;
use truck_geometry::prelude as tg;

/// A rational B-spline curve (truck's homogeneous representation).
pub type NurbsCurve = tg::NurbsCurve<tg::Vector4>;

/// A curve with a parametrisation `t ↦ C(t)`.
#[derive(Debug, Clone)]
pub enum Curve {
    /// `origin + t·dir`, `dir` a unit vector (so `t` is arc length).
    Line {
        /// A point on the line.
        origin: P3,
        /// Unit direction.
        dir: V3,
    },
    /// `c + r(cos t·x + sin t·y)`, `t` in radians.
    Circle {
        /// Centre and plane.
        frame: Frame,
        /// Radius.
        radius: f64,
    },
    /// `c + a cos t·x + b sin t·y`.
    Ellipse {
        /// Centre and plane.
        frame: Frame,
        /// Semi-axis along `x`.
        a: f64,
        /// Semi-axis along `y`.
        b: f64,
    },
    /// `c + a cosh t·x + b sinh t·y`.
    Hyperbola {
        /// Centre and plane.
        frame: Frame,
        /// Semi-axis along `x`.
        a: f64,
        /// Semi-imaginary axis along `y`.
        b: f64,
    },
    /// `c + f t²·x + 2 f t·y`, `f` the focal distance.
    Parabola {
        /// Apex and plane.
        frame: Frame,
        /// Focal distance.
        focal: f64,
    },
    /// A (rational) B-spline.
    Nurbs(Box<NurbsData>),
    /// Straight segments through the points, `t ∈ [0, n-1]`.
    Polyline(Vec<P3>),
    /// A piece of `basis` re-parametrised to `t ∈ [0, 1]`: `basis(t0 + t·(t1 − t0))`.
    /// `t1 < t0` runs the basis backwards (STEP `sense_agreement = .F.`).
    Trimmed {
        /// The curve trimmed.
        basis: Box<Curve>,
        /// Basis parameter at `t = 0`.
        t0: f64,
        /// Basis parameter at `t = 1`.
        t1: f64,
    },
}

/// A B-spline curve with its parameter range cached.
#[derive(Debug, Clone)]
pub struct NurbsData {
    /// The curve.
    pub curve: NurbsCurve,
    /// First valid parameter.
    pub t0: f64,
    /// Last valid parameter.
    pub t1: f64,
    /// Number of non-empty knot spans (a measure of complexity for sampling).
    pub spans: usize,
    /// Degree.
    pub degree: usize,
    /// The same curve for fast local evaluation.
    pub local: crate::nurbs::LocalCurve,
    /// The points [`Curve::project`] compares `p` with to seed its Newton iterations, made on
    /// first use: the curve at `samples + 1` evenly spaced parameters over `[t0, t1]`.
    pub samples: std::sync::OnceLock<Vec<P3>>,
}

impl NurbsData {
    /// Wraps a truck NURBS curve, computing its valid range.
    pub fn new(curve: NurbsCurve) -> Self {
        let kv = curve.knot_vec();
        let degree = curve.degree();
        let n = kv.len();
        let t0 = kv[degree.min(n - 1)];
        let t1 = kv[n - 1 - degree.min(n - 1)];
        let mut spans = 0;
        for i in degree..n.saturating_sub(degree + 1) {
            if kv[i + 1] > kv[i] {
                spans += 1;
            }
        }
        NurbsData {
            local: crate::nurbs::LocalCurve {
                knots: curve.knot_vec().to_vec(),
                degree,
                cps: curve
                    .control_points()
                    .iter()
                    .map(|c| [c.x, c.y, c.z, c.w])
                    .collect(),
            },
            curve,
            t0,
            t1,
            spans: spans.max(1),
            degree,
            samples: std::sync::OnceLock::new(),
        }
    }

    /// How many intervals [`Curve::project`] samples the curve in before Newton's method.
    fn sample_count(&self) -> usize {
        (self.spans * (self.degree + 1) * 2).clamp(16, 2000)
    }

    /// The parameter of the sample nearest to `p` (the first of equals), the samples evaluated
    /// once per curve and kept.
    fn nearest_sample(&self, p: &P3) -> f64 {
        let n = self.sample_count();
        let at = |i: usize| self.t0 + (self.t1 - self.t0) * i as f64 / n as f64;
        let pts = self.samples.get_or_init(|| {
            (0..=n)
                .map(|i| {
                    let [q, _, _] = self.local.ders_upto(at(i).clamp(self.t0, self.t1), 0);
                    P3::new(q[0], q[1], q[2])
                })
                .collect()
        });
        let mut best = (f64::INFINITY, self.t0);
        for (i, q) in pts.iter().enumerate() {
            let d = (q - p).norm_squared();
            if d < best.0 {
                best = (d, at(i));
            }
        }
        best.1
    }
}

#[cfg(test)]
pub(crate) fn p3(p: tg::Point3) -> P3 {
    P3::new(p.x, p.y, p.z)
}
#[cfg(test)]
pub(crate) fn v3(v: tg::Vector3) -> V3 {
    V3::new(v.x, v.y, v.z)
}

impl Curve {
    /// The point at parameter `t`.
    pub fn eval(&self, t: f64) -> P3 {
        match self {
            Curve::Line { origin, dir } => origin + dir * t,
            Curve::Circle { frame, radius } => frame.at(radius * t.cos(), radius * t.sin(), 0.0),
            Curve::Ellipse { frame, a, b } => frame.at(a * t.cos(), b * t.sin(), 0.0),
            Curve::Hyperbola { frame, a, b } => frame.at(a * t.cosh(), b * t.sinh(), 0.0),
            Curve::Parabola { frame, focal } => frame.at(focal * t * t, 2.0 * focal * t, 0.0),
            Curve::Nurbs(n) => {
                let [p, _, _] = n.local.ders_upto(t.clamp(n.t0, n.t1), 0);
                P3::new(p[0], p[1], p[2])
            }
            Curve::Polyline(pts) => {
                let (i, f) = poly_index(pts.len(), t);
                pts[i] + (pts[i + 1] - pts[i]) * f
            }
            Curve::Trimmed { basis, t0, t1 } => basis.eval(t0 + t * (t1 - t0)),
        }
    }

    /// The point and first derivative at `t`, in one evaluation where the curve allows.
    pub fn eval_d1(&self, t: f64) -> (P3, V3) {
        match self {
            Curve::Nurbs(n) => {
                let [p, d, _] = n.local.ders_upto(t.clamp(n.t0, n.t1), 1);
                (P3::new(p[0], p[1], p[2]), V3::new(d[0], d[1], d[2]))
            }
            _ => (self.eval(t), self.deriv(t)),
        }
    }

    /// The point and first two derivatives at `t`, in one evaluation where the curve allows
    /// (the same values as [`Curve::eval`], [`Curve::deriv`] and [`Curve::deriv2`]).
    pub fn eval_d2(&self, t: f64) -> (P3, V3, V3) {
        match self {
            Curve::Nurbs(n) => {
                let [p, d, dd] = n.local.ders(t.clamp(n.t0, n.t1));
                (
                    P3::new(p[0], p[1], p[2]),
                    V3::new(d[0], d[1], d[2]),
                    V3::new(dd[0], dd[1], dd[2]),
                )
            }
            _ => (self.eval(t), self.deriv(t), self.deriv2(t)),
        }
    }

    /// The first derivative `C'(t)`.
    pub fn deriv(&self, t: f64) -> V3 {
        match self {
            Curve::Line { dir, .. } => *dir,
            Curve::Circle { frame, radius } => frame.vec(-radius * t.sin(), radius * t.cos(), 0.0),
            Curve::Ellipse { frame, a, b } => frame.vec(-a * t.sin(), b * t.cos(), 0.0),
            Curve::Hyperbola { frame, a, b } => frame.vec(a * t.sinh(), b * t.cosh(), 0.0),
            Curve::Parabola { frame, focal } => frame.vec(2.0 * focal * t, 2.0 * focal, 0.0),
            Curve::Nurbs(n) => {
                let [_, d, _] = n.local.ders_upto(t.clamp(n.t0, n.t1), 1);
                V3::new(d[0], d[1], d[2])
            }
            Curve::Polyline(pts) => {
                let (i, _) = poly_index(pts.len(), t);
                pts[i + 1] - pts[i]
            }
            Curve::Trimmed { basis, t0, t1 } => basis.deriv(t0 + t * (t1 - t0)) * (t1 - t0),
        }
    }

    /// The second derivative `C''(t)` (finite differences where no closed form is kept).
    pub fn deriv2(&self, t: f64) -> V3 {
        match self {
            Curve::Line { .. } | Curve::Polyline(_) => V3::zeros(),
            Curve::Circle { frame, radius } => frame.vec(-radius * t.cos(), -radius * t.sin(), 0.0),
            Curve::Ellipse { frame, a, b } => frame.vec(-a * t.cos(), -b * t.sin(), 0.0),
            Curve::Hyperbola { frame, a, b } => frame.vec(a * t.cosh(), b * t.sinh(), 0.0),
            Curve::Parabola { frame, focal } => frame.vec(2.0 * focal, 0.0, 0.0),
            Curve::Nurbs(n) => {
                let [_, _, d] = n.local.ders(t.clamp(n.t0, n.t1));
                V3::new(d[0], d[1], d[2])
            }
            Curve::Trimmed { basis, t0, t1 } => {
                basis.deriv2(t0 + t * (t1 - t0)) * (t1 - t0).powi(2)
            }
        }
    }

    /// The period of a closed periodic parametrisation (circles and ellipses).
    pub fn period(&self) -> Option<f64> {
        match self {
            Curve::Circle { .. } | Curve::Ellipse { .. } => Some(TAU),
            _ => None,
        }
    }

    /// The natural parameter range (infinite for lines).
    pub fn range(&self) -> (f64, f64) {
        match self {
            Curve::Line { .. } | Curve::Hyperbola { .. } | Curve::Parabola { .. } => {
                (f64::NEG_INFINITY, f64::INFINITY)
            }
            Curve::Circle { .. } | Curve::Ellipse { .. } => (0.0, TAU),
            Curve::Nurbs(n) => (n.t0, n.t1),
            Curve::Polyline(p) => (0.0, (p.len().max(2) - 1) as f64),
            Curve::Trimmed { .. } => (0.0, 1.0),
        }
    }

    /// Whether the curve is closed (first point equals last) within `tol`, periodic ones included.
    pub fn is_closed(&self, tol: f64) -> bool {
        if self.period().is_some() {
            return true;
        }
        let (a, b) = self.range();
        a.is_finite() && b.is_finite() && (self.eval(a) - self.eval(b)).norm() <= tol
    }

    /// A short name of the curve kind, as `inspect` counts them.
    pub fn kind(&self) -> &'static str {
        match self {
            Curve::Line { .. } => "line",
            Curve::Circle { .. } => "circle",
            Curve::Ellipse { .. } => "ellipse",
            Curve::Hyperbola { .. } => "hyperbola",
            Curve::Parabola { .. } => "parabola",
            Curve::Nurbs(_) => "bspline",
            Curve::Polyline(_) => "polyline",
            Curve::Trimmed { basis, .. } => basis.kind(),
        }
    }

    /// The parameter of the point of the curve nearest to `p` (for a periodic curve, in `[0, 2π)`).
    pub fn project(&self, p: &P3) -> f64 {
        match self {
            Curve::Line { origin, dir } => (p - origin).dot(dir),
            Curve::Circle { frame, .. } => {
                let l = frame.local(p);
                l.y.atan2(l.x).rem_euclid(TAU)
            }
            Curve::Ellipse { frame, a, b } => {
                let l = frame.local(p);
                let t = (l.y / b).atan2(l.x / a);
                self.newton(p, t, None).rem_euclid(TAU)
            }
            Curve::Hyperbola { frame, a, b } => {
                let l = frame.local(p);
                let t0 = (l.y / b).asinh();
                let _ = a;
                self.newton(p, t0, None)
            }
            Curve::Parabola { frame, focal } => {
                let l = frame.local(p);
                self.newton(p, l.y / (2.0 * focal), None)
            }
            Curve::Nurbs(n) => {
                let t = n.nearest_sample(p);
                self.newton(p, t, Some((n.t0, n.t1)))
            }
            Curve::Polyline(pts) => {
                let mut best = (f64::INFINITY, 0.0);
                for i in 0..pts.len().saturating_sub(1) {
                    let d = pts[i + 1] - pts[i];
                    let l2 = d.norm_squared();
                    let f = if l2 > 0.0 {
                        ((p - pts[i]).dot(&d) / l2).clamp(0.0, 1.0)
                    } else {
                        0.0
                    };
                    let dist = (pts[i] + d * f - p).norm();
                    if dist < best.0 {
                        best = (dist, i as f64 + f);
                    }
                }
                best.1
            }
            Curve::Trimmed { basis, t0, t1 } => {
                let mut tb = basis.project(p);
                if let Some(per) = basis.period() {
                    tb = nearest_periodic(tb, 0.5 * (t0 + t1), per);
                }
                if (t1 - t0).abs() < NONZERO {
                    0.0
                } else {
                    ((tb - t0) / (t1 - t0)).clamp(-0.5, 1.5)
                }
            }
        }
    }

    /// The parameter of the point nearest to `p`, searched near `hint` first (for points that
    /// move along the curve).
    pub fn project_near(&self, p: &P3, hint: f64) -> f64 {
        match self {
            Curve::Nurbs(n) => {
                let t = self.newton(p, hint, Some((n.t0, n.t1)));
                if (self.eval(t) - p).norm() <= POINT_COINCIDENCE * (1.0 + p.coords.norm()) {
                    t
                } else {
                    self.project(p)
                }
            }
            _ => self.project(p),
        }
    }

    /// Newton iterations on `f(t) = C'(t)·(C(t) − p)`.
    fn newton(&self, p: &P3, mut t: f64, clamp: Option<(f64, f64)>) -> f64 {
        for _ in 0..30 {
            let (c, c1, c2) = self.eval_d2(t);
            let d = c - p;
            let f = c1.dot(&d);
            let df = c2.dot(&d) + c1.norm_squared();
            if df.abs() < NONZERO || !df.is_finite() {
                break;
            }
            let mut step = f / df;
            let span = clamp.map(|(a, b)| (b - a) * 0.25).unwrap_or(0.5);
            step = step.clamp(-span, span);
            let mut nt = t - step;
            if let Some((a, b)) = clamp {
                nt = nt.clamp(a, b);
            }
            if (nt - t).abs() < CURVE_NEWTON_STEP * (1.0 + t.abs()) {
                t = nt;
                break;
            }
            t = nt;
        }
        t
    }
}

fn poly_index(n: usize, t: f64) -> (usize, f64) {
    let last = n.saturating_sub(2);
    let tc = t.clamp(0.0, (last + 1) as f64);
    let i = (tc.floor() as usize).min(last);
    (i, tc - i as f64)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn circle_projection_round_trips() {
        let f =
            Frame::from_axes(P3::new(1.0, 2.0, 3.0), Some(V3::new(0.0, 1.0, 1.0)), None).unwrap();
        let c = Curve::Circle {
            frame: f,
            radius: 5.0,
        };
        for i in 0..20 {
            let t = i as f64 * 0.3;
            let tp = c.project(&c.eval(t));
            assert!((c.eval(tp) - c.eval(t)).norm() < 1e-9);
        }
    }

    #[test]
    fn trimmed_reversed_runs_backwards() {
        let f = Frame::world(P3::origin());
        let c = Curve::Trimmed {
            basis: Box::new(Curve::Circle {
                frame: f,
                radius: 1.0,
            }),
            t0: 1.0,
            t1: 0.0,
        };
        assert!((c.eval(0.0) - P3::new(1f64.cos(), 1f64.sin(), 0.0)).norm() < 1e-12);
        let t = c.project(&P3::new(0.5f64.cos(), 0.5f64.sin(), 0.0));
        assert!((t - 0.5).abs() < 1e-9);
    }
}
