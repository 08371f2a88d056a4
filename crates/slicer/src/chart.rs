//! The chart of a freeform feature's reference surface S: every computation on curved layers
//! runs in 2-D chart coordinates `q = (s, t)` and the signed distance `d` from S along its unit
//! normal N (pointing into the feature), the point `(q, d)` being `S(q) + d·N(q)`. The chart is
//! the surface's own `(u, v)` scaled to millimetres at the feature's centre
//! ([`ChartKind::Native`]), or, where `(u, v)` collapses under the feature (a boss on a sphere's
//! pole), the orthogonal projection onto the tangent plane at the feature's centre
//! ([`ChartKind::Ortho`]). Also the feature's mesh mapped into `(s, t, d)`.

use crate::error::FeatureError;
use crate::geom2d::{Point2, Region};
use crate::tolerance::{
    AREA_ELEMENT_MIN, CHART_RESIDUAL, DEGENERATE_LENGTH, FOOT_OFF_NORMAL, MICROMETRE,
    PARAMETER_SLACK, PARAMETER_STEP, SINGULAR_DET,
};
use crate::top_field::TopField;
use brep::math::{any_perpendicular, P3, V3};
use brep::mesh::Mesh;
use brep::surface::Surface;

/// Longest edge of the feature mesh mapped into `(s, t, d)`, mm: over 1 mm the distance to a
/// reference of curvature 1/R strays from linear by at most 1/(8R) mm (3 µm for R = 40 mm).
pub(crate) const MAX_MAPPED_EDGE: f64 = 1.0;

/// How chart coordinates map to the reference surface.
#[derive(Debug, Clone, Copy)]
pub enum ChartKind {
    /// `q = ((u − u0)·su, (v − v0)·sv)`: the surface's parameters scaled by `|S_u|`, `|S_v|` at
    /// the feature's centre (`su` negated where needed so the chart turns as N does).
    Native {
        /// Centre parameters.
        u0: f64,
        /// Centre parameters.
        v0: f64,
        /// Scale of u, mm per unit (signed).
        su: f64,
        /// Scale of v, mm per unit.
        sv: f64,
    },
    /// `q = ((F − c)·e1, (F − c)·e2)` for the surface point F: projection onto the tangent
    /// plane at the centre c.
    Ortho {
        /// Centre point.
        c: P3,
        /// First in-plane axis.
        e1: V3,
        /// Second in-plane axis (`e1 × e2` is the normal into the feature).
        e2: V3,
    },
}

/// A chart of a feature's reference surface with the normal into the feature.
#[derive(Debug, Clone, Copy)]
pub struct Chart<'a> {
    pub(crate) surf: &'a Surface,
    /// +1 when N is the surface's natural normal, −1 when reversed.
    pub(crate) sign: f64,
    /// The chart's form.
    pub kind: ChartKind,
    /// Transition layers: when set, the chart's normal coordinate is the morph level
    /// `w = d / h_T(q)` (0 on the base, 1 on the top) instead of the distance `d`
    /// ([`crate::transition`]).
    pub(crate) blend: Option<&'a TopField>,
    /// A translate chart (issue 17, item 5): the normal coordinate grows along this fixed unit
    /// direction `a` instead of the reference's normal, the point `(q, d)` being `S(q) + d·a`
    /// with `S(q)` the reference point whose projection along `a` is `q` (always with
    /// [`ChartKind::Ortho`], `e1 × e2 = a`). Its levels are translates of the reference, which
    /// cannot fold over a concave valley the way its offsets do (feature-based AM paper, Fig. 9).
    pub(crate) along: Option<V3>,
}

impl<'a> Chart<'a> {
    /// The chart of `surf` in its own (u, v), unscaled: exact on a plane.
    pub(crate) fn unit(surf: &'a Surface) -> Chart<'a> {
        Chart {
            surf,
            sign: 1.0,
            blend: None,
            along: None,
            kind: ChartKind::Native {
                u0: 0.0,
                v0: 0.0,
                su: 1.0,
                sv: 1.0,
            },
        }
    }

    pub(crate) fn normal_at(&self, u: f64, v: f64) -> Option<V3> {
        self.surf.normal(u, v).map(|n| n * self.sign)
    }

    /// Surface parameters of chart point `q`.
    pub(crate) fn uv(&self, q: Point2) -> Option<(f64, f64)> {
        match self.kind {
            ChartKind::Native { u0, v0, su, sv } => Some((u0 + q[0] / su, v0 + q[1] / sv)),
            ChartKind::Ortho { c, e1, e2 } => {
                // Iterated projection: move the target by the chart residual and project again.
                let mut x = c + e1 * q[0] + e2 * q[1];
                let mut uv = self.surf.project(&x, None);
                for _ in 0..40 {
                    let f = self.surf.eval(uv.0, uv.1);
                    let r = [q[0] - (f - c).dot(&e1), q[1] - (f - c).dot(&e2)];
                    if r[0].abs() + r[1].abs() < CHART_RESIDUAL {
                        return Some(uv);
                    }
                    x = f + e1 * r[0] + e2 * r[1];
                    uv = self.surf.project(&x, Some(uv));
                }
                let f = self.surf.eval(uv.0, uv.1);
                let r = [q[0] - (f - c).dot(&e1), q[1] - (f - c).dot(&e2)];
                (r[0].abs() + r[1].abs() < 1e-6).then_some(uv)
            }
        }
    }

    /// The reference surface at `(u, v)` and its unit normal into the feature, continued past
    /// a bounded parameter range (a revolved profile's or a B-spline's end) by its tangent
    /// plane along the boundary, so that a feature overhanging its reference face's edge still
    /// has a foot under every point. Poles are not continued.
    pub(crate) fn eval_ext(&self, u: f64, v: f64) -> Option<(P3, V3)> {
        let (bu, bv) = if matches!(self.surf, Surface::Sphere { .. }) {
            (None, None)
        } else {
            self.surf.bounds()
        };
        let clamp = |x: f64, r: Option<(f64, f64)>| {
            r.map(|(a, b)| x.clamp(a.min(b), a.max(b))).unwrap_or(x)
        };
        let (uc, vc) = (clamp(u, bu), clamp(v, bv));
        if uc == u && vc == v {
            let (p, n) = self.surf.eval_normal(u, v);
            return Some((p, n? * self.sign));
        }
        let n = self.normal_at(uc, vc)?;
        let (p, su, sv) = self.surf.eval_d1(uc, vc);
        Some((p + su * (u - uc) + sv * (v - vc), n))
    }

    /// Whether chart point `q` lies on the reference surface proper, not on its continuation
    /// past a bounded parameter range.
    pub(crate) fn on_face(&self, q: Point2) -> bool {
        let Some((u, v)) = self.uv(q) else {
            return false;
        };
        if matches!(self.kind, ChartKind::Ortho { .. }) {
            return true;
        }
        let (bu, bv) = self.surf.bounds();
        let inside = |x: f64, r: Option<(f64, f64)>| {
            r.is_none_or(|(a, b)| {
                x >= a.min(b) - PARAMETER_SLACK && x <= a.max(b) + PARAMETER_SLACK
            })
        };
        inside(u, bu) && inside(v, bv)
    }

    /// The most millimetres one chart unit spans at `q` on the offset at `d` (the chart's
    /// largest stretch there), to turn 3-D lengths into chart lengths conservatively.
    pub(crate) fn stretch(&self, q: Point2, d: f64) -> f64 {
        let e = 1e-4;
        let at = |dq: [f64; 2]| self.point([q[0] + dq[0], q[1] + dq[1]], d);
        match (at([0.0, 0.0]), at([e, 0.0]), at([0.0, e])) {
            (Some(p), Some(a), Some(b)) => ((a - p).norm().max((b - p).norm()) / e).max(1e-6),
            _ => 1.0,
        }
    }

    /// The first fundamental form of the offset surface at `d` in the chart, at the centre of
    /// `region`'s box: `[[p_s·p_s, p_s·p_t], [p_s·p_t, p_t·p_t]]` by central differences.
    /// The identity where the chart cannot be evaluated there.
    pub(crate) fn metric(&self, region: &Region, d: f64) -> [[f64; 2]; 2] {
        let (mut lo, mut hi) = ([f64::INFINITY; 2], [f64::NEG_INFINITY; 2]);
        for q in &region.outer {
            for k in 0..2 {
                lo[k] = lo[k].min(q[k]);
                hi[k] = hi[k].max(q[k]);
            }
        }
        let c = [0.5 * (lo[0] + hi[0]), 0.5 * (lo[1] + hi[1])];
        let e = 1e-3;
        let diff = |k: usize| -> Option<V3> {
            let (mut a, mut b) = (c, c);
            a[k] -= e;
            b[k] += e;
            Some((self.point(b, d)? - self.point(a, d)?) / (2.0 * e))
        };
        match (diff(0), diff(1)) {
            (Some(ps), Some(pt)) if c[0].is_finite() && c[1].is_finite() => {
                [[ps.dot(&ps), ps.dot(&pt)], [ps.dot(&pt), pt.dot(&pt)]]
            }
            _ => [[1.0, 0.0], [0.0, 1.0]],
        }
    }

    /// The projection chart onto the plane through `c` square to the unit normal `n` (into the
    /// feature), its normal coordinate growing along `along` when set ([`Chart::along`]).
    fn tangent_plane(surf: &'a Surface, sign: f64, c: P3, n: V3, along: Option<V3>) -> Chart<'a> {
        let e1 = any_perpendicular(&n).normalize();
        let e2 = n.cross(&e1);
        Chart {
            surf,
            sign,
            blend: None,
            along,
            kind: ChartKind::Ortho { c, e1, e2 },
        }
    }

    /// The same chart with its normal coordinate the morph level towards `top`.
    pub(crate) fn blended<'b>(&self, top: &'b TopField) -> Chart<'b>
    where
        'a: 'b,
    {
        Chart {
            surf: self.surf,
            sign: self.sign,
            kind: self.kind,
            blend: Some(top),
            along: self.along,
        }
    }

    /// The point at chart `q` and level `d` (the distance from the reference, or on a blended
    /// chart the morph level), and the unit normal of the layer surface there: the reference's
    /// on an offset (its normal is the reference's), by central differences on a transition
    /// layer (TSN).
    pub fn at(&self, q: Point2, d: f64) -> Option<(P3, V3)> {
        let Some(top) = self.blend else {
            return self.offset_at(q, d);
        };
        let plain = Chart {
            blend: None,
            ..*self
        };
        // Between the transition layers' start (0, or the offset layers' staircase) and the
        // top; the normal from the staircase's smooth counterpart.
        let level = |x: Point2, lower: f64| lower + d * (top.height(x) - lower);
        let (p, n) = plain.offset_at(q, level(q, top.lower(q)))?;
        if d == 0.0 && top.lower_smooth(q) == 0.0 {
            return Some((p, n));
        }
        let e = 1e-3;
        let side = |k: usize, s: f64| {
            let mut x = q;
            x[k] += s * e;
            plain
                .offset_at(x, level(x, top.lower_smooth(x)))
                .map(|r| r.0)
        };
        let (Some(a), Some(b), Some(c), Some(g)) =
            (side(0, 1.0), side(0, -1.0), side(1, 1.0), side(1, -1.0))
        else {
            return Some((p, n));
        };
        let m = (a - b).cross(&(c - g));
        let len = m.norm();
        if !(len.is_finite() && len > 0.0) {
            return Some((p, n));
        }
        let m = m / len;
        Some((p, if m.dot(&n) < 0.0 { -m } else { m }))
    }

    /// The point of [`Chart::at`] alone, without the layer surface's normal (which a
    /// transition layer takes by central differences, four more evaluations): `None` exactly
    /// where [`Chart::at`] is.
    pub fn point(&self, q: Point2, d: f64) -> Option<P3> {
        let Some(top) = self.blend else {
            return self.offset_at(q, d).map(|x| x.0);
        };
        let plain = Chart {
            blend: None,
            ..*self
        };
        let lower = top.lower(q);
        plain
            .offset_at(q, lower + d * (top.height(q) - lower))
            .map(|x| x.0)
    }

    /// [`Chart::at`] on an offset of the reference.
    fn offset_at(&self, q: Point2, d: f64) -> Option<(P3, V3)> {
        let (u, v) = self.uv(q)?;
        let (f, n) = match self.kind {
            ChartKind::Native { .. } => self.eval_ext(u, v)?,
            ChartKind::Ortho { .. } => {
                let (p, n) = self.surf.eval_normal(u, v);
                (p, n? * self.sign)
            }
        };
        let p = f + self.along.unwrap_or(n) * d;
        (p.coords.iter().all(|x| x.is_finite()) && n.iter().all(|x| x.is_finite()))
            .then_some((p, n))
    }

    /// Chart coordinates and distance `d` of `p` (its nearest point on the reference); on a
    /// blended chart, the morph level instead of the distance.
    pub fn inverse(&self, p: &P3) -> Option<(Point2, f64)> {
        if let Some(a) = self.along {
            let (q, (u, v)) = self.foot_along(p)?;
            let d = (p - self.surf.eval(u, v)).dot(&a);
            return self.level(q, d);
        }
        let (mut u, mut v) = self.surf.project(p, None);
        let (mut f, mut n) = (self.surf.eval(u, v), self.normal_at(u, v)?);
        if let ChartKind::Native { u0, v0, .. } = self.kind {
            // A foot on the boundary with `p` off its normal: continue onto the extension
            // (Gauss–Newton on the continued surface).
            let off = |f: P3, n: V3| (p - f - n * (p - f).dot(&n)).norm();
            if off(f, n) > FOOT_OFF_NORMAL * (1.0 + (p - f).norm()) {
                let uv = self.surf.unwrap_near((u, v), (u0, v0));
                u = uv.0;
                v = uv.1;
                for _ in 0..30 {
                    let (e, _) = self.eval_ext(u, v)?;
                    let h = 1e-6;
                    let (eu, _) = self.eval_ext(u + h, v)?;
                    let (ev, _) = self.eval_ext(u, v + h)?;
                    let (a, b) = ((eu - e) / h, (ev - e) / h);
                    let r = p - e;
                    let g = [[a.dot(&a), a.dot(&b)], [a.dot(&b), b.dot(&b)]];
                    let det = g[0][0] * g[1][1] - g[0][1] * g[1][0];
                    if det.abs() < SINGULAR_DET {
                        break;
                    }
                    let (ra, rb) = (a.dot(&r), b.dot(&r));
                    let du = (g[1][1] * ra - g[0][1] * rb) / det;
                    let dv = (g[0][0] * rb - g[0][1] * ra) / det;
                    u += du;
                    v += dv;
                    if du.abs() + dv.abs() < PARAMETER_STEP {
                        break;
                    }
                }
                let (e, m) = self.eval_ext(u, v)?;
                f = e;
                n = m;
            }
        }
        let d = (p - f).dot(&n);
        let q = match self.kind {
            ChartKind::Native { u0, v0, su, sv } => {
                let (u, v) = self.surf.unwrap_near((u, v), (u0, v0));
                [(u - u0) * su, (v - v0) * sv]
            }
            ChartKind::Ortho { c, e1, e2 } => [(f - c).dot(&e1), (f - c).dot(&e2)],
        };
        self.level(q, d)
    }

    /// On a translate chart, the chart point of `p` and the parameters of the reference point
    /// under it along [`Chart::along`]; `None` on other charts.
    fn foot_along(&self, p: &P3) -> Option<(Point2, (f64, f64))> {
        let ChartKind::Ortho { c, e1, e2 } = self.kind else {
            return None;
        };
        self.along?;
        let q = [(p - c).dot(&e1), (p - c).dot(&e2)];
        Some((q, self.uv(q)?))
    }

    /// Chart point `q` at distance `d`, with `d` made the morph level on a blended chart (the
    /// distance over the top's there).
    fn level(&self, q: Point2, d: f64) -> Option<(Point2, f64)> {
        let d = match self.blend {
            Some(top) => {
                let lower = top.lower(q);
                (d - lower) / (top.height(q) - lower).max(MICROMETRE)
            }
            None => d,
        };
        (q[0].is_finite() && q[1].is_finite() && d.is_finite()).then_some((q, d))
    }

    /// The unit direction the chart's normal coordinate grows along at `q`: the fixed
    /// direction of a translate chart, the reference's normal otherwise.
    pub(crate) fn growth(&self, q: Point2) -> Option<V3> {
        match self.along {
            Some(a) => Some(a),
            None => {
                let plain = Chart {
                    blend: None,
                    ..*self
                };
                plain.offset_at(q, 0.0).map(|x| x.1)
            }
        }
    }

    /// The smallest principal curvature `λ` of the reference at `q`, with `dN = λ·dS` along
    /// principal directions (N into the feature): negative where the surface curves towards
    /// the feature, whose offset at distance `d` then folds where `1 + d·λ ≤ 0`.
    pub(crate) fn min_curvature(&self, q: Point2, step: f64) -> Option<f64> {
        let e = |dq: [f64; 2]| self.at([q[0] + dq[0], q[1] + dq[1]], 0.0);
        let (ps, ns) = e([step, 0.0])?;
        let (pm, nm) = e([-step, 0.0])?;
        let (pt, nt) = e([0.0, step])?;
        let (pn, nn) = e([0.0, -step])?;
        let (js, jt) = (ps - pm, pt - pn);
        let (ks, kt) = (ns - nm, nt - nn);
        // Least squares W with [ks kt] = [js jt]·W, then its eigenvalues.
        let g = [[js.dot(&js), js.dot(&jt)], [js.dot(&jt), jt.dot(&jt)]];
        let det = g[0][0] * g[1][1] - g[0][1] * g[1][0];
        if det.abs() < SINGULAR_DET {
            return None;
        }
        let gi = [
            [g[1][1] / det, -g[0][1] / det],
            [-g[1][0] / det, g[0][0] / det],
        ];
        let b = [[js.dot(&ks), js.dot(&kt)], [jt.dot(&ks), jt.dot(&kt)]];
        let w = [
            [
                gi[0][0] * b[0][0] + gi[0][1] * b[1][0],
                gi[0][0] * b[0][1] + gi[0][1] * b[1][1],
            ],
            [
                gi[1][0] * b[0][0] + gi[1][1] * b[1][0],
                gi[1][0] * b[0][1] + gi[1][1] * b[1][1],
            ],
        ];
        let tr = w[0][0] + w[1][1];
        let dt = w[0][0] * w[1][1] - w[0][1] * w[1][0];
        let disc = (0.25 * tr * tr - dt).max(0.0).sqrt();
        let l = 0.5 * tr - disc;
        l.is_finite().then_some(l)
    }
}

/// The feature's chart: the surface's own parameters unless they collapse under the feature.
pub(crate) fn choose_chart<'a>(
    surf: &'a Surface,
    sign: f64,
    id: usize,
    mesh: &Mesh,
) -> Result<Chart<'a>, FeatureError> {
    let err = |msg: String| FeatureError::Freeform { id, msg };
    let n = mesh.positions.len().max(1) as f64;
    let centroid = mesh.positions.iter().fold(V3::zeros(), |a, p| a + p.coords) / n;
    let centroid = P3::from(centroid);
    let (u0, v0) = surf.project(&centroid, None);
    let (su, sv) = surf.derivs(u0, v0);
    let area = |u: f64, v: f64| {
        let (a, b) = surf.derivs(u, v);
        a.cross(&b).norm()
    };
    let a0 = area(u0, v0);
    // Native when the parameters stay regular under the whole feature.
    let stride = (mesh.positions.len() / 400).max(1);
    let mut native =
        a0 > AREA_ELEMENT_MIN && su.norm() > DEGENERATE_LENGTH && sv.norm() > DEGENERATE_LENGTH;
    if native {
        let (mut ulo, mut uhi) = (f64::INFINITY, f64::NEG_INFINITY);
        for p in mesh.positions.iter().step_by(stride) {
            let (u, v) = surf.unwrap_near(surf.project(p, None), (u0, v0));
            ulo = ulo.min(u);
            uhi = uhi.max(u);
            if area(u, v) < 0.2 * a0 {
                native = false;
                break;
            }
        }
        if let Some(per) = surf.u_period() {
            if uhi - ulo > 0.9 * per {
                native = false;
            }
        }
    }
    let n0 = surf
        .normal(u0, v0)
        .map(|n| n * sign)
        .ok_or_else(|| err("its reference surface has no normal under its centre".into()))?;
    if native {
        let flip = if su.cross(&sv).dot(&n0) < 0.0 {
            -1.0
        } else {
            1.0
        };
        return Ok(Chart {
            surf,
            sign,
            blend: None,
            along: None,
            kind: ChartKind::Native {
                u0,
                v0,
                su: su.norm() * flip,
                sv: sv.norm(),
            },
        });
    }
    let chart = Chart::tangent_plane(surf, sign, surf.eval(u0, v0), n0, None);
    // The projection chart needs the reference to be a height field over the tangent plane.
    for p in mesh.positions.iter().step_by(stride) {
        let (u, v) = surf.project(p, None);
        let ok = chart.normal_at(u, v).is_some_and(|n| n.dot(&n0) > 0.17);
        if !ok {
            return Err(err(
                "its reference surface turns more than 80° under it and its parameters collapse there: no chart for curved layers"
                    .into(),
            ));
        }
    }
    Ok(chart)
}

/// A point of a feature's root: its parameters on the reference and its place.
pub(crate) type RootPoint = (f64, f64, P3);

/// A feature's root on its reference: the vertices of its mesh that lie on the surface (within
/// `tol`, or a micrometre), as `(u, v, point)`, and the parameters of the surface point nearest
/// their centre. `None` without any.
pub(crate) fn root(surf: &Surface, mesh: &Mesh, tol: f64) -> Option<(Vec<RootPoint>, (f64, f64))> {
    let roots: Vec<RootPoint> = mesh
        .positions
        .iter()
        .filter_map(|p| {
            let (u, v) = surf.project(p, None);
            let f = surf.eval(u, v);
            ((p - f).norm() < 1e-3f64.max(2.0 * tol)).then_some((u, v, f))
        })
        .collect();
    if roots.is_empty() {
        return None;
    }
    let centre = roots.iter().fold(V3::zeros(), |a, r| a + r.2.coords) / roots.len() as f64;
    let uv = surf.project(&P3::from(centre), None);
    Some((roots, uv))
}

/// Most a translate chart's direction may lean from the reference's normal under the feature,
/// degrees: its levels' thickness across them is `cos` of the lean times their spacing, at
/// least half of it here.
const TRANSLATE_LEAN_DEG: f64 = 60.0;

/// The translate chart of a feature whose reference's offsets fold under it (a rib standing in
/// a trough narrower than its height; feature-based AM paper, Fig. 9): levels grow along the
/// reference's normal `a` at the centre of the feature's root (its mesh vertices on the
/// reference), chart coordinates by projection along `a` onto the plane through the root's
/// centre ([`Chart::along`]). `None` where the reference is not a height field along `a` under
/// the feature: a point with no reference point under it, or one whose normal there leans more
/// than [`TRANSLATE_LEAN_DEG`] from `a`, or a point of the feature under the reference.
pub(crate) fn translate_chart<'a>(
    surf: &'a Surface,
    sign: f64,
    mesh: &Mesh,
    tol: f64,
) -> Option<Chart<'a>> {
    let (_, (u0, v0)) = root(surf, mesh, tol)?;
    let a = surf.normal(u0, v0)? * sign;
    let chart = Chart::tangent_plane(surf, sign, surf.eval(u0, v0), a, Some(a));
    let lean = TRANSLATE_LEAN_DEG.to_radians().cos();
    let stride = (mesh.positions.len() / 2000).max(1);
    for p in mesh.positions.iter().step_by(stride) {
        let (_, (u, v)) = chart.foot_along(p)?;
        let n = chart.normal_at(u, v)?;
        if n.dot(&a) < lean || (p - surf.eval(u, v)).dot(&a) < -2.0 * tol.max(MICROMETRE) {
            return None;
        }
    }
    Some(chart)
}

/// The mesh with every edge longer than `max_edge` split (conforming: a triangle is cut by
/// the midpoints of its long edges, shared with its neighbours), as one triangle list. The
/// distance field is linear over each triangle of the mapped mesh, so a planar face's few large
/// triangles would cut a curved layer along chords far from the true section curve. Each
/// point's `(u, v)` comes along (a midpoint's the mean of its ends': meaningful within one
/// face, whose parameters a triangulation gives unwrapped).
pub(crate) fn refined(mesh: &Mesh, max_edge: f64) -> Mesh {
    let mut pos = mesh.positions.clone();
    let mut uv = position_uv(mesh);
    let mut tris = mesh.triangles();
    for _ in 0..12 {
        let long =
            |a: u32, b: u32, pos: &[P3]| (pos[a as usize] - pos[b as usize]).norm() > max_edge;
        let mut mid: std::collections::HashMap<(u32, u32), u32> = std::collections::HashMap::new();
        for t in &tris {
            for k in 0..3 {
                let (a, b) = (t[k], t[(k + 1) % 3]);
                if long(a, b, &pos) {
                    let key = (a.min(b), a.max(b));
                    mid.entry(key).or_insert_with(|| {
                        let (a, b) = (a as usize, b as usize);
                        pos.push(P3::from(0.5 * (pos[a].coords + pos[b].coords)));
                        uv.push([0.5 * (uv[a][0] + uv[b][0]), 0.5 * (uv[a][1] + uv[b][1])]);
                        (pos.len() - 1) as u32
                    });
                }
            }
        }
        if mid.is_empty() {
            break;
        }
        let mut next = Vec::with_capacity(tris.len() * 2);
        for t in &tris {
            let m = [0, 1, 2].map(|k| {
                let (a, b) = (t[k], t[(k + 1) % 3]);
                mid.get(&(a.min(b), a.max(b))).copied()
            });
            match m {
                [None, None, None] => next.push(*t),
                [Some(x), Some(y), Some(z)] => {
                    next.extend([[t[0], x, z], [x, t[1], y], [z, y, t[2]], [x, y, z]]);
                }
                _ => {
                    // One or two split edges: fan from the first split edge's midpoint.
                    let k = (0..3).find(|&k| m[k].is_some()).unwrap_or(0);
                    let x = m[k].unwrap_or(t[k]);
                    let (a, b, c) = (t[k], t[(k + 1) % 3], t[(k + 2) % 3]);
                    let (mb, mc) = (m[(k + 1) % 3], m[(k + 2) % 3]);
                    // Polygon a, x, b, [mb], c, [mc]; fan around x.
                    let mut poly = vec![b];
                    if let Some(y) = mb {
                        poly.push(y);
                    }
                    poly.push(c);
                    if let Some(z) = mc {
                        poly.push(z);
                    }
                    poly.push(a);
                    for w in poly.windows(2) {
                        next.push([x, w[0], w[1]]);
                    }
                }
            }
        }
        tris = next;
    }
    let n = pos.len();
    Mesh {
        positions: pos,
        faces: vec![brep::mesh::FaceTriangulation {
            face: mesh
                .faces
                .first()
                .map(|f| f.face)
                .unwrap_or(brep::topology::FaceId(0)),
            uv,
            vertex: (0..n as u32).collect(),
            triangles: tris,
        }],
        edge_points: Default::default(),
        edge_params: Default::default(),
    }
}

/// Each position's `(u, v)` on the face (of the last face triangulation listing it; `(0, 0)`
/// where none does): meaningful for a mesh of one face.
pub(crate) fn position_uv(mesh: &Mesh) -> Vec<[f64; 2]> {
    let mut uv = vec![[0.0, 0.0]; mesh.positions.len()];
    for f in &mesh.faces {
        for (&g, &w) in f.vertex.iter().zip(&f.uv) {
            if let Some(x) = uv.get_mut(g as usize) {
                *x = w;
            }
        }
    }
    uv
}

/// Chart coordinates and distance of every mesh vertex, as a mesh in `(s, t, d)` space.
pub(crate) fn mapped_mesh(chart: &Chart, mesh: &Mesh, id: usize) -> Result<Mesh, FeatureError> {
    let mut m = mesh.clone();
    for (i, p) in mesh.positions.iter().enumerate() {
        let (q, d) = chart.inverse(p).ok_or_else(|| FeatureError::Freeform {
            id,
            msg: format!(
                "a point ({:.3}, {:.3}, {:.3}) of it has no foot on its reference surface",
                p.x, p.y, p.z
            ),
        })?;
        m.positions[i] = P3::new(q[0], q[1], d);
    }
    Ok(m)
}
