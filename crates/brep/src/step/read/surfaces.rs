//! Surface entities.

use super::curves::uniform_knots;
use super::translator::{as_real, names_of, Translator, R};
use crate::math::{P3, V3};
use crate::step::error::ReadError;
use crate::step::p21::Param;
use crate::surface::{NurbsSurfaceData, Revolution, Surface};
use crate::topology::SurfaceId;
use truck_geometry::prelude as tg;

impl<'a> Translator<'a> {
    // ---------- surfaces ----------

    /// The surface and whether its natural normal is reversed by a trimming wrapper.
    pub(super) fn surface(&mut self, id: u64, from: u64) -> R<(SurfaceId, bool)> {
        if let Some(s) = self.surfaces.get(&id) {
            return Ok(*s);
        }
        self.enter(id)?;
        let s = self.build_surface(id, from);
        self.depth -= 1;
        let (s, flipped) = s?;
        let sid = SurfaceId(self.brep.surfaces.len() as u32);
        self.brep.surfaces.push(s);
        self.surfaces.insert(id, (sid, flipped));
        Ok((sid, flipped))
    }

    pub(super) fn build_surface(&mut self, id: u64, from: u64) -> R<(Surface, bool)> {
        let e = self.entity(id, from)?;
        let i = &e.instance;
        if let Some(r) = i.record("PLANE") {
            return Ok((
                Surface::Plane {
                    frame: self.placement(self.reference(id, r, 1)?, id)?,
                },
                false,
            ));
        }
        if let Some(r) = i.record("CYLINDRICAL_SURFACE") {
            let frame = self.placement(self.reference(id, r, 1)?, id)?;
            return Ok((
                Surface::Cylinder {
                    frame,
                    radius: self.positive(id, r, 2, "radius")?,
                },
                false,
            ));
        }
        if let Some(r) = i.record("CONICAL_SURFACE") {
            let frame = self.placement(self.reference(id, r, 1)?, id)?;
            let radius = self.real(id, r, 2)? * self.mm;
            let semi_angle = self.real(id, r, 3)? * self.rad;
            let radius_ok = radius.is_finite() && radius >= 0.0;
            let angle_ok = semi_angle.abs() < std::f64::consts::FRAC_PI_2 && semi_angle != 0.0;
            if !radius_ok || !angle_ok {
                return Err(self.bad(
                    id,
                    format!("cone radius {radius} / semi-angle {semi_angle} rad out of range"),
                ));
            }
            return Ok((
                Surface::Cone {
                    frame,
                    radius,
                    semi_angle,
                },
                false,
            ));
        }
        if let Some(r) = i.record("SPHERICAL_SURFACE") {
            let frame = self.placement(self.reference(id, r, 1)?, id)?;
            return Ok((
                Surface::Sphere {
                    frame,
                    radius: self.positive(id, r, 2, "radius")?,
                },
                false,
            ));
        }
        if let Some(r) = i
            .record("TOROIDAL_SURFACE")
            .or_else(|| i.record("DEGENERATE_TOROIDAL_SURFACE"))
        {
            let frame = self.placement(self.reference(id, r, 1)?, id)?;
            let major = self.positive(id, r, 2, "major radius")?;
            let minor = self.positive(id, r, 3, "minor radius")?;
            return Ok((
                Surface::Torus {
                    frame,
                    major,
                    minor,
                },
                false,
            ));
        }
        if let Some(r) = i.record("SURFACE_OF_REVOLUTION") {
            let c = self.curve(self.reference(id, r, 1)?, id)?;
            let ax = self.reference(id, r, 2)?;
            let (_, ar) = self.record(ax, id, &["AXIS1_PLACEMENT"])?;
            let origin = self.point(self.reference(ax, ar, 1)?, ax)?;
            let axis = match self.opt_reference(ax, ar, 2)? {
                Some(d) => self.direction(d, ax)?,
                None => V3::z(),
            };
            let profile = self.brep.curves[c.idx()].clone();
            return Ok((
                Surface::Revolution(Box::new(Revolution::new(profile, origin, axis))),
                false,
            ));
        }
        if let Some(r) = i.record("SURFACE_OF_LINEAR_EXTRUSION") {
            let c = self.curve(self.reference(id, r, 1)?, id)?;
            let (dir, mag) = self.vector(self.reference(id, r, 2)?, id)?;
            let dir = if mag < 0.0 { -dir } else { dir };
            let profile = Box::new(self.brep.curves[c.idx()].clone());
            return Ok((Surface::Extrusion { profile, dir }, false));
        }
        if i.record("B_SPLINE_SURFACE").is_some()
            || SURFACE_FORMS.iter().any(|n| i.record(n).is_some())
        {
            return Ok((self.bspline_surface(id)?, false));
        }
        if let Some(r) = i.record("OFFSET_SURFACE") {
            let (b, flipped) = self.surface(self.reference(id, r, 1)?, id)?;
            let mut distance = self.real(id, r, 2)? * self.mm;
            if flipped {
                distance = -distance;
            }
            let basis = Box::new(self.brep.surfaces[b.idx()].clone());
            return Ok((Surface::Offset { basis, distance }, flipped));
        }
        if let Some(r) = i.record("RECTANGULAR_TRIMMED_SURFACE") {
            let (b, flipped) = self.surface(self.reference(id, r, 1)?, id)?;
            let us = self.bool(id, r, 6).unwrap_or(true);
            let vs = self.bool(id, r, 7).unwrap_or(true);
            return Ok((self.brep.surfaces[b.idx()].clone(), flipped ^ (us != vs)));
        }
        if let Some(r) = i.record("CURVE_BOUNDED_SURFACE") {
            let (b, flipped) = self.surface(self.reference(id, r, 1)?, id)?;
            return Ok((self.brep.surfaces[b.idx()].clone(), flipped));
        }
        Err(ReadError::Unsupported {
            id,
            entity: names_of(e),
        })
    }

    pub(super) fn bspline_surface(&mut self, id: u64) -> R<Surface> {
        let e = self.entity(id, id)?;
        let i = &e.instance;
        let (base, off) = match i.record("B_SPLINE_SURFACE") {
            Some(b) => (b, 0usize),
            None => (
                SURFACE_FORMS
                    .iter()
                    .find_map(|n| i.record(n))
                    .ok_or_else(|| self.bad(id, "missing B-spline data"))?,
                1usize,
            ),
        };
        let du = self.degree(id, base, off)?;
        let dv = self.degree(id, base, off + 1)?;
        let rows = self.list(id, base, off + 2)?;
        let mut grid: Vec<Vec<P3>> = vec![];
        for row in rows {
            let Param::List(row) = row else {
                return Err(self.bad(id, "control points are not a list of lists"));
            };
            let pts = row
                .iter()
                .map(|p| match p {
                    Param::Ref(x) => self.point(*x, id),
                    _ => Err(self.bad(id, "control point is not a reference")),
                })
                .collect::<R<Vec<_>>>()?;
            grid.push(pts);
        }
        let nu = grid.len();
        let nv = grid.first().map(|r| r.len()).unwrap_or(0);
        if nu == 0 || nv == 0 || grid.iter().any(|r| r.len() != nv) {
            return Err(self.bad(id, "control point grid is empty or ragged"));
        }
        let (ukv, vkv) = if let Some(k) = i.record("B_SPLINE_SURFACE_WITH_KNOTS") {
            let o = if off == 1 { 8 } else { 0 };
            (
                self.knots(id, k, o, o + 2, nu, du)?,
                self.knots(id, k, o + 1, o + 3, nv, dv)?,
            )
        } else if i.record("BEZIER_SURFACE").is_some() {
            if nu != du + 1 || nv != dv + 1 {
                return Err(self.bad(
                    id,
                    "Bezier surface needs degree + 1 control points each way",
                ));
            }
            (tg::KnotVec::bezier_knot(du), tg::KnotVec::bezier_knot(dv))
        } else if i.record("UNIFORM_SURFACE").is_some()
            || i.record("QUASI_UNIFORM_SURFACE").is_some()
        {
            let q = i.record("QUASI_UNIFORM_SURFACE").is_some();
            (uniform_knots(nu, du, q), uniform_knots(nv, dv, q))
        } else {
            return Err(ReadError::Unsupported {
                id,
                entity: names_of(e),
            });
        };
        let weights: Vec<Vec<f64>> = match i.record("RATIONAL_B_SPLINE_SURFACE") {
            Some(w) => {
                let rows = self.list(id, w, 0)?;
                let ws: Vec<Vec<f64>> = rows
                    .iter()
                    .map(|r| match r {
                        Param::List(l) => l.iter().filter_map(as_real).collect(),
                        _ => vec![],
                    })
                    .collect();
                if ws.len() != nu
                    || ws
                        .iter()
                        .any(|r| r.len() != nv || r.iter().any(|w| !(w.is_finite() && *w > 0.0)))
                {
                    return Err(self.bad(
                        id,
                        "weights do not match the control grid or are not positive",
                    ));
                }
                ws
            }
            None => vec![vec![1.0; nv]; nu],
        };
        let cps: Vec<Vec<tg::Vector4>> = grid
            .iter()
            .zip(&weights)
            .map(|(row, wr)| {
                row.iter()
                    .zip(wr)
                    .map(|(p, w)| tg::Vector4::new(p.x * w, p.y * w, p.z * w, *w))
                    .collect()
            })
            .collect();
        let bs = tg::BSplineSurface::try_new((ukv, vkv), cps)
            .map_err(|e| self.bad(id, format!("invalid B-spline surface: {e}")))?;
        Ok(Surface::Nurbs(Box::new(NurbsSurfaceData::new(
            tg::NurbsSurface::new(bs),
        ))))
    }
}

/// The B-spline surface forms, as [`CURVE_FORMS`].
const SURFACE_FORMS: [&str; 4] = [
    "B_SPLINE_SURFACE_WITH_KNOTS",
    "UNIFORM_SURFACE",
    "QUASI_UNIFORM_SURFACE",
    "BEZIER_SURFACE",
];
