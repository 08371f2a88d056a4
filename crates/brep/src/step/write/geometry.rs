//! Geometry entities: points, directions, placements, curves and surfaces.

use super::text::*;
use super::writer::Writer;
use crate::curve::Curve;
use crate::math::{Frame, P3, V3};
use crate::surface::Surface;
use crate::topology::{CurveId, SurfaceId};

impl<'a> Writer<'a> {
    // ---------- geometry primitives ----------

    pub(super) fn point(&mut self, p: &P3) -> u64 {
        self.add(format!(
            "CARTESIAN_POINT('',({},{},{}))",
            real(p.x),
            real(p.y),
            real(p.z)
        ))
    }

    pub(super) fn direction(&mut self, v: &V3) -> u64 {
        self.add(format!(
            "DIRECTION('',({},{},{}))",
            real(v.x),
            real(v.y),
            real(v.z)
        ))
    }

    /// `VECTOR(dir, 1.)`: unit magnitude, so that a line's parameter is arc length.
    pub(super) fn unit_vector(&mut self, v: &V3) -> u64 {
        let d = self.direction(v);
        self.add(format!("VECTOR('',#{d},1.)"))
    }

    pub(super) fn placement(&mut self, f: &Frame) -> u64 {
        let o = self.point(&f.origin);
        let z = self.direction(&f.z);
        let x = self.direction(&f.x);
        self.add(format!("AXIS2_PLACEMENT_3D('',#{o},#{z},#{x})"))
    }

    // ---------- curves ----------

    pub(super) fn curve(&mut self, c: CurveId) -> u64 {
        if let Some(&id) = self.curves.get(&c) {
            return id;
        }
        let id = self.curve_geom(&self.brep.curves[c.idx()]);
        self.curves.insert(c, id);
        id
    }

    pub(super) fn curve_geom(&mut self, c: &Curve) -> u64 {
        match c {
            Curve::Line { origin, dir } => {
                let p = self.point(origin);
                let v = self.unit_vector(dir);
                self.add(format!("LINE('',#{p},#{v})"))
            }
            Curve::Circle { frame, radius } => {
                let a = self.placement(frame);
                self.add(format!("CIRCLE('',#{a},{})", real(*radius)))
            }
            Curve::Ellipse { frame, a, b } => {
                let p = self.placement(frame);
                self.add(format!("ELLIPSE('',#{p},{},{})", real(*a), real(*b)))
            }
            Curve::Hyperbola { frame, a, b } => {
                let p = self.placement(frame);
                self.add(format!("HYPERBOLA('',#{p},{},{})", real(*a), real(*b)))
            }
            Curve::Parabola { frame, focal } => {
                let p = self.placement(frame);
                self.add(format!("PARABOLA('',#{p},{})", real(*focal)))
            }
            Curve::Nurbs(n) => {
                let l = &n.local;
                let (pts, weights) = self.control_points(&l.cps);
                let (mults, knots) = knot_runs(&l.knots);
                let (deg, pts) = (l.degree, ref_list(&pts));
                match weights {
                    None => self.add(format!(
                        "B_SPLINE_CURVE_WITH_KNOTS('',{deg},{pts},.UNSPECIFIED.,.F.,.F.,{mults},{knots},.UNSPECIFIED.)"
                    )),
                    Some(w) => self.add(format!(
                        "( BOUNDED_CURVE() B_SPLINE_CURVE({deg},{pts},.UNSPECIFIED.,.F.,.F.) B_SPLINE_CURVE_WITH_KNOTS({mults},{knots},.UNSPECIFIED.) CURVE() GEOMETRIC_REPRESENTATION_ITEM() RATIONAL_B_SPLINE_CURVE({}) REPRESENTATION_ITEM('') )",
                        real_list(&w)
                    )),
                }
            }
            Curve::Polyline(pts) => {
                let ids: Vec<u64> = pts.iter().map(|p| self.point(p)).collect();
                self.add(format!("POLYLINE('',{})", ref_list(&ids)))
            }
            Curve::Trimmed { basis, t0, t1 } => {
                // A trimmed trimmed curve is a trim of the innermost basis (a TRIMMED_CURVE's
                // parameter in STEP is its basis' parameter, not our [0, 1]).
                let (mut b, mut a0, mut a1) = (&**basis, *t0, *t1);
                while let Curve::Trimmed { basis, t0, t1 } = b {
                    (a0, a1) = (t0 + a0 * (t1 - t0), t0 + a1 * (t1 - t0));
                    b = basis;
                }
                // Lines are written with a unit VECTOR and conics in radians, so STEP's
                // parameter of the basis is ours.
                let bid = self.curve_geom(b);
                self.add(format!(
                    "TRIMMED_CURVE('',#{bid},(PARAMETER_VALUE({})),(PARAMETER_VALUE({})),{},.PARAMETER.)",
                    real(a0),
                    real(a1),
                    logical(a1 >= a0)
                ))
            }
        }
    }

    /// Writes homogeneous control points as points; returns their ids and the weights when any
    /// differs from 1.
    pub(super) fn control_points(&mut self, cps: &[[f64; 4]]) -> (Vec<u64>, Option<Vec<f64>>) {
        let ids = cps
            .iter()
            .map(|c| self.point(&P3::new(c[0] / c[3], c[1] / c[3], c[2] / c[3])))
            .collect();
        let rational = cps.iter().any(|c| c[3] != 1.0);
        (ids, rational.then(|| cps.iter().map(|c| c[3]).collect()))
    }

    // ---------- surfaces ----------

    pub(super) fn surface(&mut self, s: SurfaceId) -> u64 {
        if let Some(&id) = self.surfaces.get(&s) {
            return id;
        }
        let id = self.surface_geom(&self.brep.surfaces[s.idx()]);
        self.surfaces.insert(s, id);
        id
    }

    pub(super) fn surface_geom(&mut self, s: &Surface) -> u64 {
        match s {
            Surface::Plane { frame } => {
                let a = self.placement(frame);
                self.add(format!("PLANE('',#{a})"))
            }
            Surface::Cylinder { frame, radius } => {
                let a = self.placement(frame);
                self.add(format!("CYLINDRICAL_SURFACE('',#{a},{})", real(*radius)))
            }
            Surface::Cone {
                frame,
                radius,
                semi_angle,
            } => {
                let a = self.placement(frame);
                self.add(format!(
                    "CONICAL_SURFACE('',#{a},{},{})",
                    real(*radius),
                    real(*semi_angle)
                ))
            }
            Surface::Sphere { frame, radius } => {
                let a = self.placement(frame);
                self.add(format!("SPHERICAL_SURFACE('',#{a},{})", real(*radius)))
            }
            Surface::Torus {
                frame,
                major,
                minor,
            } => {
                let a = self.placement(frame);
                self.add(format!(
                    "TOROIDAL_SURFACE('',#{a},{},{})",
                    real(*major),
                    real(*minor)
                ))
            }
            Surface::Revolution(rev) => {
                let c = self.curve_geom(&rev.profile);
                let o = self.point(&rev.origin);
                let d = self.direction(&rev.axis);
                let ax = self.add(format!("AXIS1_PLACEMENT('',#{o},#{d})"));
                self.add(format!("SURFACE_OF_REVOLUTION('',#{c},#{ax})"))
            }
            Surface::Extrusion { profile, dir } => {
                let c = self.curve_geom(profile);
                let v = self.unit_vector(dir);
                self.add(format!("SURFACE_OF_LINEAR_EXTRUSION('',#{c},#{v})"))
            }
            Surface::Nurbs(n) => {
                let l = &n.local;
                let (du, dv) = l.degree;
                let (nu, nv) = l.n;
                let (pts, weights) = self.control_points(&l.cps);
                let rows: Vec<String> = pts.chunks(nv.max(1)).take(nu).map(ref_list).collect();
                let grid = format!("({})", rows.join(","));
                let (um, uk) = knot_runs(&l.ku);
                let (vm, vk) = knot_runs(&l.kv);
                match weights {
                    None => self.add(format!(
                        "B_SPLINE_SURFACE_WITH_KNOTS('',{du},{dv},{grid},.UNSPECIFIED.,.F.,.F.,.F.,{um},{vm},{uk},{vk},.UNSPECIFIED.)"
                    )),
                    Some(w) => {
                        let wrows: Vec<String> =
                            w.chunks(nv.max(1)).take(nu).map(real_list).collect();
                        self.add(format!(
                            "( BOUNDED_SURFACE() B_SPLINE_SURFACE({du},{dv},{grid},.UNSPECIFIED.,.F.,.F.,.F.) B_SPLINE_SURFACE_WITH_KNOTS({um},{vm},{uk},{vk},.UNSPECIFIED.) GEOMETRIC_REPRESENTATION_ITEM() RATIONAL_B_SPLINE_SURFACE(({})) REPRESENTATION_ITEM('') SURFACE() )",
                            wrows.join(",")
                        ))
                    }
                }
            }
            Surface::Offset { basis, distance } => {
                let b = self.surface_geom(basis);
                self.add(format!("OFFSET_SURFACE('',#{b},{},.F.)", real(*distance)))
            }
        }
    }
}
