//! Curve entities, B-spline knots included.

use super::translator::{as_real, names_of, Translator, R};
use crate::curve::{Curve, NurbsData};
use crate::step::error::ReadError;
use crate::step::p21::{Param, Record};
use crate::topology::CurveId;
use truck_geometry::prelude as tg;

impl<'a> Translator<'a> {
    // ---------- curves ----------

    pub(super) fn curve(&mut self, id: u64, from: u64) -> R<CurveId> {
        if let Some(c) = self.curves.get(&id) {
            return Ok(*c);
        }
        self.enter(id)?;
        let c = self.build_curve(id, from);
        self.depth -= 1;
        let c = c?;
        let cid = CurveId(self.brep.curves.len() as u32);
        self.brep.curves.push(c);
        self.curves.insert(id, cid);
        Ok(cid)
    }

    pub(super) fn build_curve(&mut self, id: u64, from: u64) -> R<Curve> {
        let e = self.entity(id, from)?;
        let i = &e.instance;
        if let Some(r) = i.record("LINE") {
            let p = self.point(self.reference(id, r, 1)?, id)?;
            let (dir, _) = self.vector(self.reference(id, r, 2)?, id)?;
            return Ok(Curve::Line { origin: p, dir });
        }
        if let Some(r) = i.record("CIRCLE") {
            let frame = self.placement(self.reference(id, r, 1)?, id)?;
            let radius = self.positive(id, r, 2, "radius")?;
            return Ok(Curve::Circle { frame, radius });
        }
        if let Some(r) = i.record("ELLIPSE") {
            let frame = self.placement(self.reference(id, r, 1)?, id)?;
            let a = self.positive(id, r, 2, "semi-axis 1")?;
            let b = self.positive(id, r, 3, "semi-axis 2")?;
            return Ok(Curve::Ellipse { frame, a, b });
        }
        if let Some(r) = i.record("HYPERBOLA") {
            let frame = self.placement(self.reference(id, r, 1)?, id)?;
            let a = self.positive(id, r, 2, "semi-axis")?;
            let b = self.positive(id, r, 3, "semi-imaginary axis")?;
            return Ok(Curve::Hyperbola { frame, a, b });
        }
        if let Some(r) = i.record("PARABOLA") {
            let frame = self.placement(self.reference(id, r, 1)?, id)?;
            let focal = self.positive(id, r, 2, "focal distance")?;
            return Ok(Curve::Parabola { frame, focal });
        }
        if i.record("B_SPLINE_CURVE").is_some() || CURVE_FORMS.iter().any(|n| i.record(n).is_some())
        {
            return self.bspline_curve(id);
        }
        for n in [
            "SURFACE_CURVE",
            "SEAM_CURVE",
            "INTERSECTION_CURVE",
            "BOUNDED_SURFACE_CURVE",
        ] {
            if let Some(r) = i.record(n) {
                let c3 = self.reference(id, r, 1)?;
                let c = self.curve(c3, id)?;
                return Ok(self.brep.curves[c.idx()].clone());
            }
        }
        if let Some(r) = i.record("TRIMMED_CURVE") {
            let b = self.reference(id, r, 1)?;
            let bc = self.curve(b, id)?;
            let basis = self.brep.curves[bc.idx()].clone();
            let t1 = self.trim_param(id, &basis, b, self.list(id, r, 2)?)?;
            let t2 = self.trim_param(id, &basis, b, self.list(id, r, 3)?)?;
            let sense = self.bool(id, r, 4)?;
            let (mut t0, mut t1) = (t1, t2);
            if let Some(per) = basis.period() {
                if sense {
                    while t1 <= t0 {
                        t1 += per;
                    }
                } else {
                    while t1 >= t0 {
                        t1 -= per;
                    }
                }
            } else if (t1 > t0) != sense && t1 != t0 {
                std::mem::swap(&mut t0, &mut t1);
            }
            return Ok(Curve::Trimmed {
                basis: Box::new(basis),
                t0,
                t1,
            });
        }
        if let Some(r) = i.record("POLYLINE") {
            let pts = self.refs(id, r, 1)?;
            if pts.len() < 2 {
                return Err(self.bad(id, "polyline with fewer than 2 points"));
            }
            let pts = pts
                .into_iter()
                .map(|p| self.point(p, id))
                .collect::<R<Vec<_>>>()?;
            return Ok(Curve::Polyline(pts));
        }
        Err(ReadError::Unsupported {
            id,
            entity: names_of(e),
        })
    }

    /// A trimming parameter of `basis` from a `trimming_select` list: the point when given,
    /// otherwise the parameter value in the file's units.
    pub(super) fn trim_param(
        &self,
        id: u64,
        basis: &Curve,
        basis_id: u64,
        sel: &[Param],
    ) -> R<f64> {
        for s in sel {
            if let Param::Ref(p) = s {
                let pt = self.point(*p, id)?;
                return Ok(basis.project(&pt));
            }
        }
        for s in sel {
            if let Some(x) = as_real(s) {
                let be = self.entity(basis_id, id)?;
                let t = if be.instance.record("CIRCLE").is_some()
                    || be.instance.record("ELLIPSE").is_some()
                {
                    x * self.rad
                } else if let Some(lr) = be.instance.record("LINE") {
                    let (_, mag) = self.vector(self.reference(basis_id, lr, 2)?, basis_id)?;
                    x * mag
                } else {
                    x
                };
                return Ok(t);
            }
        }
        Err(self.bad(id, "trimming select holds neither a point nor a parameter"))
    }

    pub(super) fn knots(
        &self,
        id: u64,
        r: &Record,
        mi: usize,
        ki: usize,
        n_ctrl: usize,
        degree: usize,
    ) -> R<tg::KnotVec> {
        let mults: Vec<i64> = self
            .list(id, r, mi)?
            .iter()
            .map(|p| match p {
                Param::Int(n) => Ok(*n),
                _ => Err(self.bad(id, "knot multiplicity is not an integer")),
            })
            .collect::<R<_>>()?;
        let knots: Vec<f64> = self
            .list(id, r, ki)?
            .iter()
            .map(|p| as_real(p).ok_or_else(|| self.bad(id, "knot is not a number")))
            .collect::<R<_>>()?;
        if mults.len() != knots.len() || mults.iter().any(|&m| !(1..=64).contains(&m)) {
            return Err(self.bad(
                id,
                format!(
                    "{} knots but {} multiplicities (or a multiplicity out of range)",
                    knots.len(),
                    mults.len()
                ),
            ));
        }
        let total: i64 = mults.iter().sum();
        if total as usize != n_ctrl + degree + 1 {
            return Err(self.bad(id, format!("knot multiplicities sum to {total}, expected {} control points + degree {} + 1", n_ctrl, degree)));
        }
        if knots
            .windows(2)
            .any(|w| w[0].partial_cmp(&w[1]) != Some(std::cmp::Ordering::Less))
            || knots.iter().any(|k| !k.is_finite())
        {
            return Err(self.bad(id, "knots are not strictly increasing"));
        }
        tg::KnotVec::from_single_multi(knots, mults.iter().map(|&m| m as usize).collect())
            .map_err(|e| self.bad(id, format!("bad knot vector: {e}")))
    }

    pub(super) fn degree(&self, id: u64, r: &Record, i: usize) -> R<usize> {
        let d = self.int(id, r, i)?;
        if !(1..=25).contains(&d) {
            return Err(self.bad(id, format!("degree {d} out of range")));
        }
        Ok(d as usize)
    }

    pub(super) fn bspline_curve(&mut self, id: u64) -> R<Curve> {
        let e = self.entity(id, id)?;
        let i = &e.instance;
        // Simple B_SPLINE_CURVE_WITH_KNOTS carries everything; a complex entity splits it.
        // A complex entity's B_SPLINE_CURVE record has no name; a simple instance of any
        // form (with knots, uniform, quasi-uniform, Bezier) starts with its name.
        let (base, base_off) = match i.record("B_SPLINE_CURVE") {
            Some(b) => (b, 0usize),
            None => (
                CURVE_FORMS
                    .iter()
                    .find_map(|n| i.record(n))
                    .ok_or_else(|| self.bad(id, "missing B-spline data"))?,
                1usize,
            ),
        };
        let degree = self.degree(id, base, base_off)?;
        let ctrl = self.refs(id, base, base_off + 1)?;
        let pts = ctrl
            .iter()
            .map(|p| self.point(*p, id))
            .collect::<R<Vec<_>>>()?;
        let kv = if let Some(k) = i.record("B_SPLINE_CURVE_WITH_KNOTS") {
            let off = if base_off == 1 { 6 } else { 0 };
            self.knots(id, k, off, off + 1, pts.len(), degree)?
        } else if i.record("BEZIER_CURVE").is_some() {
            if pts.len() != degree + 1 {
                return Err(self.bad(id, "Bezier curve needs degree + 1 control points"));
            }
            tg::KnotVec::bezier_knot(degree)
        } else if i.record("UNIFORM_CURVE").is_some() || i.record("QUASI_UNIFORM_CURVE").is_some() {
            uniform_knots(pts.len(), degree, i.record("QUASI_UNIFORM_CURVE").is_some())
        } else {
            return Err(ReadError::Unsupported {
                id,
                entity: names_of(e),
            });
        };
        let weights = match i.record("RATIONAL_B_SPLINE_CURVE") {
            Some(w) => {
                let ws: Vec<f64> = self.list(id, w, 0)?.iter().filter_map(as_real).collect();
                if ws.len() != pts.len() || ws.iter().any(|w| !(w.is_finite() && *w > 0.0)) {
                    return Err(self.bad(
                        id,
                        "weights do not match control points or are not positive",
                    ));
                }
                ws
            }
            None => vec![1.0; pts.len()],
        };
        let cps: Vec<tg::Vector4> = pts
            .iter()
            .zip(&weights)
            .map(|(p, w)| tg::Vector4::new(p.x * w, p.y * w, p.z * w, *w))
            .collect();
        let bs = tg::BSplineCurve::try_new(kv, cps)
            .map_err(|e| self.bad(id, format!("invalid B-spline: {e}")))?;
        Ok(Curve::Nurbs(Box::new(NurbsData::new(tg::NurbsCurve::new(
            bs,
        )))))
    }
}

pub(super) fn uniform_knots(n: usize, degree: usize, quasi: bool) -> tg::KnotVec {
    let len = n + degree + 1;
    let v: Vec<f64> = if quasi {
        (0..len)
            .map(|i| (i.saturating_sub(degree)).min(n - degree) as f64)
            .collect()
    } else {
        (0..len).map(|i| i as f64 - degree as f64).collect()
    };
    tg::KnotVec::from(v)
}

/// The B-spline curve forms STEP writes, each a record of its own in a simple instance.
const CURVE_FORMS: [&str; 4] = [
    "B_SPLINE_CURVE_WITH_KNOTS",
    "UNIFORM_CURVE",
    "QUASI_UNIFORM_CURVE",
    "BEZIER_CURVE",
];
