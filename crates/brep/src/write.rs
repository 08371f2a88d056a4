//! Writing solids of our B-rep back to a STEP AP214 file (ISO 10303-21, millimetres, radians).
//!
//! The file holds exact geometry and topology only: one product whose
//! `ADVANCED_BREP_SHAPE_REPRESENTATION` lists the solids. Every surface and curve keeps its
//! natural parametrisation, so the faces' `same_sense` and the edges' directions mean the same
//! thing after a round trip, and [`crate::read_step_bytes`] reads back the B-rep that was written
//! (same faces, loops, coedges, edges and vertices, in the same order). No `PCURVE`s are written;
//! OpenCASCADE computes them when it reads the file.
//!
//! Void shells follow the reader's convention: a void face's `same_sense` already includes the
//! reversal of its shell, and its loops are those of the un-reversed shell. They are written as
//! `ORIENTED_CLOSED_SHELL(.F.)` around a `CLOSED_SHELL` whose faces carry the opposite
//! `same_sense`, which is how OpenCASCADE writes voids and what the reader undoes.
//!
//! ```no_run
//! let part = brep::read_step("part.step").unwrap();
//! let solids: Vec<_> = part.brep.solid_ids().collect();
//! std::fs::write("copy.step", brep::write::write_step(&part.brep, &solids, "copy")).unwrap();
//! ```

use crate::curve::Curve;
use crate::math::{Frame, P3, V3};
use crate::surface::Surface;
use crate::topology::{Brep, CurveId, EdgeId, FaceId, SolidId, SurfaceId, VertexId};
use std::collections::HashMap;

/// Writes the given solids (each a set of shells: outer first, then voids) as one STEP file.
pub fn write_step(brep: &Brep, solids: &[SolidId], name: &str) -> String {
    let bodies: Vec<Body> = solids
        .iter()
        .filter_map(|s| {
            let solid = &brep.solids[s.idx()];
            let (outer, voids) = solid.shells.split_first()?;
            Some(Body {
                name: solid.name.clone(),
                outer: brep.shells[outer.idx()].faces.clone(),
                voids: voids
                    .iter()
                    .map(|v| brep.shells[v.idx()].faces.clone())
                    .collect(),
            })
        })
        .collect();
    write_bodies(brep, &bodies, name)
}

/// For solids that exist only as face lists (a feature being extracted): each entry is (outer
/// shell faces, void shells' faces). Void faces are taken in the convention of the reader (see
/// the module documentation): a face copied from a void shell of a read solid is written as it
/// was read.
pub fn write_step_shells(
    brep: &Brep,
    shells: &[(Vec<FaceId>, Vec<Vec<FaceId>>)],
    name: &str,
) -> String {
    let bodies: Vec<Body> = shells
        .iter()
        .map(|(outer, voids)| Body {
            name: String::new(),
            outer: outer.clone(),
            voids: voids.clone(),
        })
        .collect();
    write_bodies(brep, &bodies, name)
}

/// One solid to write.
struct Body {
    name: String,
    outer: Vec<FaceId>,
    voids: Vec<Vec<FaceId>>,
}

/// The timestamp written into `FILE_NAME` (fixed, so that output is reproducible).
const TIMESTAMP: &str = "2024-01-01T00:00:00";

fn write_bodies(brep: &Brep, bodies: &[Body], name: &str) -> String {
    let mut w = Writer::new(brep);
    let app_protocol = w.reserve();
    let app_context = w.reserve();
    let sdr = w.reserve();
    let pds = w.reserve();
    let pd = w.reserve();
    let pdf = w.reserve();
    let product = w.reserve();
    let product_context = w.reserve();
    let pd_context = w.reserve();
    let rep = w.reserve();
    let qname = string(name);
    w.set(
        app_protocol,
        format!(
            "APPLICATION_PROTOCOL_DEFINITION('international standard','automotive_design',2000,#{app_context})"
        ),
    );
    w.set(
        app_context,
        "APPLICATION_CONTEXT('core data for automotive mechanical design processes')".into(),
    );
    w.set(
        sdr,
        format!("SHAPE_DEFINITION_REPRESENTATION(#{pds},#{rep})"),
    );
    w.set(pds, format!("PRODUCT_DEFINITION_SHAPE('','',#{pd})"));
    w.set(
        pd,
        format!("PRODUCT_DEFINITION('design','',#{pdf},#{pd_context})"),
    );
    w.set(
        pdf,
        format!("PRODUCT_DEFINITION_FORMATION('','',#{product})"),
    );
    w.set(
        product,
        format!("PRODUCT({qname},{qname},'',(#{product_context}))"),
    );
    w.set(
        product_context,
        format!("PRODUCT_CONTEXT('',#{app_context},'mechanical')"),
    );
    w.set(
        pd_context,
        format!("PRODUCT_DEFINITION_CONTEXT('part definition',#{app_context},'design')"),
    );
    let axes = w.placement(&Frame::world(P3::origin()));
    let mut items = vec![axes];
    for b in bodies {
        if let Some(s) = w.body(b) {
            items.push(s);
        }
    }
    // The geometric context: millimetres, radians, steradians, 1e-7 mm uncertainty.
    let mm = w.add("( LENGTH_UNIT() NAMED_UNIT(*) SI_UNIT(.MILLI.,.METRE.) )".into());
    let rad = w.add("( NAMED_UNIT(*) PLANE_ANGLE_UNIT() SI_UNIT($,.RADIAN.) )".into());
    let sr = w.add("( NAMED_UNIT(*) SI_UNIT($,.STERADIAN.) SOLID_ANGLE_UNIT() )".into());
    let unc = w.add(format!(
        "UNCERTAINTY_MEASURE_WITH_UNIT(LENGTH_MEASURE(1.E-07),#{mm},'distance_accuracy_value','confusion accuracy')"
    ));
    let ctx = w.add(format!(
        "( GEOMETRIC_REPRESENTATION_CONTEXT(3) GLOBAL_UNCERTAINTY_ASSIGNED_CONTEXT((#{unc})) GLOBAL_UNIT_ASSIGNED_CONTEXT((#{mm},#{rad},#{sr})) REPRESENTATION_CONTEXT('','') )"
    ));
    w.set(
        rep,
        format!(
            "ADVANCED_BREP_SHAPE_REPRESENTATION('',{},#{ctx})",
            ref_list(&items)
        ),
    );
    w.add(format!(
        "PRODUCT_RELATED_PRODUCT_CATEGORY('part',$,(#{product}))"
    ));

    let mut out =
        String::with_capacity(w.entities.iter().map(|e| e.len() + 12).sum::<usize>() + 512);
    out.push_str("ISO-10303-21;\nHEADER;\n");
    out.push_str("FILE_DESCRIPTION(('B-rep solids written by features'),'2;1');\n");
    out.push_str(&wrap(&format!(
        "FILE_NAME({qname},'{TIMESTAMP}',(''),(''),'features brep writer','features','');"
    )));
    out.push_str("FILE_SCHEMA(('AUTOMOTIVE_DESIGN { 1 0 10303 214 1 1 1 1 }'));\nENDSEC;\nDATA;\n");
    for (k, e) in w.entities.iter().enumerate() {
        out.push_str(&wrap(&format!("#{} = {};", k + 1, e)));
    }
    out.push_str("ENDSEC;\nEND-ISO-10303-21;\n");
    out
}

/// Entity numbering and the maps from our ids to written entities.
struct Writer<'a> {
    brep: &'a Brep,
    /// Entity `#k` is `entities[k - 1]` (without the `#k = ` and `;`).
    entities: Vec<String>,
    vertices: HashMap<VertexId, u64>,
    edges: HashMap<EdgeId, u64>,
    curves: HashMap<CurveId, u64>,
    surfaces: HashMap<SurfaceId, u64>,
}

impl<'a> Writer<'a> {
    fn new(brep: &'a Brep) -> Self {
        Writer {
            brep,
            entities: vec![],
            vertices: HashMap::new(),
            edges: HashMap::new(),
            curves: HashMap::new(),
            surfaces: HashMap::new(),
        }
    }

    /// A new entity number whose text is set later.
    fn reserve(&mut self) -> u64 {
        self.entities.push(String::new());
        self.entities.len() as u64
    }

    fn set(&mut self, id: u64, text: String) {
        self.entities[id as usize - 1] = text;
    }

    fn add(&mut self, text: String) -> u64 {
        self.entities.push(text);
        self.entities.len() as u64
    }

    // ---------- topology ----------

    fn body(&mut self, b: &Body) -> Option<u64> {
        if b.outer.is_empty() {
            return None;
        }
        let outer = self.shell(&b.outer, false);
        let name = string(&b.name);
        let voids: Vec<u64> = b
            .voids
            .iter()
            .filter(|v| !v.is_empty())
            .map(|v| {
                let cs = self.shell(v, true);
                self.add(format!("ORIENTED_CLOSED_SHELL('',*,#{cs},.F.)"))
            })
            .collect();
        Some(if voids.is_empty() {
            self.add(format!("MANIFOLD_SOLID_BREP({name},#{outer})"))
        } else {
            self.add(format!(
                "BREP_WITH_VOIDS({name},#{outer},{})",
                ref_list(&voids)
            ))
        })
    }

    /// A `CLOSED_SHELL` of the faces; `flip` reverses every face's `same_sense` (void shells).
    fn shell(&mut self, faces: &[FaceId], flip: bool) -> u64 {
        let ids: Vec<u64> = faces.iter().map(|&f| self.face(f, flip)).collect();
        self.add(format!("CLOSED_SHELL('',{})", ref_list(&ids)))
    }

    fn face(&mut self, f: FaceId, flip: bool) -> u64 {
        let brep = self.brep;
        let face = &brep.faces[f.idx()];
        let mut bounds = vec![];
        for l in &face.loops {
            let lp = &brep.loops[l.idx()];
            let lid = if lp.coedges.is_empty() {
                match lp.vertex {
                    Some(v) => {
                        let v = self.vertex(v);
                        self.add(format!("VERTEX_LOOP('',#{v})"))
                    }
                    // An empty loop bounds nothing (and an empty EDGE_LOOP is not valid).
                    None => continue,
                }
            } else {
                let oes: Vec<u64> = lp
                    .coedges
                    .iter()
                    .map(|c| {
                        let c = &brep.coedges[c.idx()];
                        let e = self.edge(c.edge);
                        self.add(format!("ORIENTED_EDGE('',*,*,#{e},{})", logical(c.forward)))
                    })
                    .collect();
                self.add(format!("EDGE_LOOP('',{})", ref_list(&oes)))
            };
            let kind = if lp.outer {
                "FACE_OUTER_BOUND"
            } else {
                "FACE_BOUND"
            };
            bounds.push(self.add(format!("{kind}('',#{lid},.T.)")));
        }
        let s = self.surface(face.surface);
        self.add(format!(
            "ADVANCED_FACE('',{},#{s},{})",
            ref_list(&bounds),
            logical(face.same_sense ^ flip)
        ))
    }

    fn edge(&mut self, e: EdgeId) -> u64 {
        if let Some(&id) = self.edges.get(&e) {
            return id;
        }
        let edge = &self.brep.edges[e.idx()];
        let vs = self.vertex(edge.start);
        let ve = self.vertex(edge.end);
        let c = self.curve(edge.curve);
        let id = self.add(format!(
            "EDGE_CURVE('',#{vs},#{ve},#{c},{})",
            logical(edge.t_end >= edge.t_start)
        ));
        self.edges.insert(e, id);
        id
    }

    fn vertex(&mut self, v: VertexId) -> u64 {
        if let Some(&id) = self.vertices.get(&v) {
            return id;
        }
        let p = self.point(&self.brep.vertices[v.idx()].point);
        let id = self.add(format!("VERTEX_POINT('',#{p})"));
        self.vertices.insert(v, id);
        id
    }

    // ---------- geometry primitives ----------

    fn point(&mut self, p: &P3) -> u64 {
        self.add(format!(
            "CARTESIAN_POINT('',({},{},{}))",
            real(p.x),
            real(p.y),
            real(p.z)
        ))
    }

    fn direction(&mut self, v: &V3) -> u64 {
        self.add(format!(
            "DIRECTION('',({},{},{}))",
            real(v.x),
            real(v.y),
            real(v.z)
        ))
    }

    /// `VECTOR(dir, 1.)`: unit magnitude, so that a line's parameter is arc length.
    fn unit_vector(&mut self, v: &V3) -> u64 {
        let d = self.direction(v);
        self.add(format!("VECTOR('',#{d},1.)"))
    }

    fn placement(&mut self, f: &Frame) -> u64 {
        let o = self.point(&f.origin);
        let z = self.direction(&f.z);
        let x = self.direction(&f.x);
        self.add(format!("AXIS2_PLACEMENT_3D('',#{o},#{z},#{x})"))
    }

    // ---------- curves ----------

    fn curve(&mut self, c: CurveId) -> u64 {
        if let Some(&id) = self.curves.get(&c) {
            return id;
        }
        let id = self.curve_geom(&self.brep.curves[c.idx()]);
        self.curves.insert(c, id);
        id
    }

    fn curve_geom(&mut self, c: &Curve) -> u64 {
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
    fn control_points(&mut self, cps: &[[f64; 4]]) -> (Vec<u64>, Option<Vec<f64>>) {
        let ids = cps
            .iter()
            .map(|c| self.point(&P3::new(c[0] / c[3], c[1] / c[3], c[2] / c[3])))
            .collect();
        let rational = cps.iter().any(|c| c[3] != 1.0);
        (ids, rational.then(|| cps.iter().map(|c| c[3]).collect()))
    }

    // ---------- surfaces ----------

    fn surface(&mut self, s: SurfaceId) -> u64 {
        if let Some(&id) = self.surfaces.get(&s) {
            return id;
        }
        let id = self.surface_geom(&self.brep.surfaces[s.idx()]);
        self.surfaces.insert(s, id);
        id
    }

    fn surface_geom(&mut self, s: &Surface) -> u64 {
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

/// A full knot vector as STEP's (multiplicities, distinct knots) lists.
fn knot_runs(knots: &[f64]) -> (String, String) {
    let mut distinct: Vec<f64> = vec![];
    let mut mults: Vec<usize> = vec![];
    for &k in knots {
        match distinct.last() {
            Some(&last) if last == k => *mults.last_mut().unwrap() += 1,
            _ => {
                distinct.push(k);
                mults.push(1);
            }
        }
    }
    let m: Vec<String> = mults.iter().map(|m| m.to_string()).collect();
    (format!("({})", m.join(",")), real_list(&distinct))
}

fn ref_list(ids: &[u64]) -> String {
    let v: Vec<String> = ids.iter().map(|i| format!("#{i}")).collect();
    format!("({})", v.join(","))
}

fn real_list(xs: &[f64]) -> String {
    let v: Vec<String> = xs.iter().map(|&x| real(x)).collect();
    format!("({})", v.join(","))
}

fn logical(b: bool) -> &'static str {
    if b {
        ".T."
    } else {
        ".F."
    }
}

/// A Part 21 real: always a decimal point, an `E±XX` exponent for very small or large
/// magnitudes, and the shortest digits that read back as the same `f64`. Non-finite values
/// (which a valid B-rep never holds) are written as `0.`.
pub fn real(x: f64) -> String {
    if !x.is_finite() || x == 0.0 {
        return "0.".into();
    }
    let a = x.abs();
    if (1e-4..1e15).contains(&a) {
        // Display gives the shortest round-trip digits without an exponent.
        let mut s = format!("{x}");
        if !s.contains('.') {
            s.push('.');
        }
        return s;
    }
    // LowerExp gives the shortest round-trip digits as `d[.ddd]e[-]x`.
    let s = format!("{x:e}");
    let (mant, exp) = s.split_once('e').expect("LowerExp has an exponent");
    let exp: i32 = exp.parse().expect("integer exponent");
    let mut m = mant.to_string();
    if !m.contains('.') {
        m.push('.');
    }
    format!("{m}E{}{:02}", if exp < 0 { '-' } else { '+' }, exp.abs())
}

/// A Part 21 string literal, quotes included: `'` and `\` doubled, characters outside printable
/// ASCII in `\X2\…\X0\` (UTF-16) form.
pub fn string(s: &str) -> String {
    let mut out = String::with_capacity(s.len() + 2);
    out.push('\'');
    let mut wide: Vec<u16> = vec![];
    let flush = |wide: &mut Vec<u16>, out: &mut String| {
        if !wide.is_empty() {
            out.push_str("\\X2\\");
            for u in wide.drain(..) {
                out.push_str(&format!("{u:04X}"));
            }
            out.push_str("\\X0\\");
        }
    };
    for ch in s.chars() {
        if (' '..='~').contains(&ch) {
            flush(&mut wide, &mut out);
            match ch {
                '\'' => out.push_str("''"),
                '\\' => out.push_str("\\\\"),
                c => out.push(c),
            }
        } else {
            let mut buf = [0u16; 2];
            wide.extend_from_slice(ch.encode_utf16(&mut buf));
        }
    }
    flush(&mut wide, &mut out);
    out.push('\'');
    out
}

/// Breaks a long entity or header line after commas (outside strings) so that lines stay near
/// 80 characters; a line always ends with `\n`.
fn wrap(s: &str) -> String {
    const WIDTH: usize = 76;
    if s.len() <= WIDTH {
        return format!("{s}\n");
    }
    let mut out = String::with_capacity(s.len() + s.len() / 32);
    let mut col = 0;
    let mut in_string = false;
    for ch in s.chars() {
        out.push(ch);
        col += 1;
        if ch == '\'' {
            in_string = !in_string;
        }
        if ch == ',' && !in_string && col >= WIDTH - 12 {
            out.push_str("\n  ");
            col = 2;
        }
    }
    out.push('\n');
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn reals_read_back_exactly_and_always_have_a_point() {
        let xs = [
            0.0,
            -0.0,
            1.0,
            -1.0,
            0.5,
            1e-7,
            -1.5e-7,
            1e-4,
            9.99e-5,
            123456.789,
            1e15,
            1e300,
            -2.5e-300,
            0.1,
            1.0 / 3.0,
            6000.0,
            1e14,
            f64::MIN_POSITIVE,
            f64::MAX,
        ];
        for x in xs {
            let s = real(x);
            assert!(s.contains('.'), "{x} -> {s}");
            assert!(
                !s.contains('e') && !s.contains("inf") && !s.contains("NaN"),
                "{s}"
            );
            let mant_ok = s.split('E').next().unwrap().ends_with('.')
                || s.split('E').next().unwrap().contains('.');
            assert!(mant_ok);
            // Part 21 and Rust agree on `1.E-07`-style text.
            let back: f64 = s.parse().unwrap();
            assert_eq!(back, x, "{x} -> {s}");
            // And our Part 21 parser reads it as the same number.
            let file =
                format!("ISO-10303-21;HEADER;ENDSEC;DATA;#1=A({s});ENDSEC;END-ISO-10303-21;");
            let f = crate::p21::parse(file.as_bytes()).unwrap();
            let p = &f.get(1).unwrap().instance.record("A").unwrap().params[0];
            assert_eq!(crate::step::as_real(p), Some(x), "{s}");
        }
        assert_eq!(real(1e-7), "1.E-07");
        assert_eq!(real(1.5e-7), "1.5E-07");
        assert_eq!(real(2.0), "2.");
        assert_eq!(real(-0.25), "-0.25");
        assert_eq!(real(1e20), "1.E+20");
        assert_eq!(real(f64::NAN), "0.");
    }

    #[test]
    fn strings_escape_quotes_backslashes_and_unicode() {
        assert_eq!(string("it's"), "'it''s'");
        assert_eq!(string("a\\b"), "'a\\\\b'");
        assert_eq!(
            string("café 😀"),
            "'caf\\X2\\00E9\\X0\\ \\X2\\D83DDE00\\X0\\'"
        );
        for s in ["it's", "a\\b", "café 😀", "", "tab\there"] {
            let file = format!(
                "ISO-10303-21;HEADER;ENDSEC;DATA;#1=A({});ENDSEC;END-ISO-10303-21;",
                string(s)
            );
            let f = crate::p21::parse(file.as_bytes()).unwrap();
            let p = &f.get(1).unwrap().instance.record("A").unwrap().params[0];
            assert_eq!(p, &crate::p21::Param::Str(s.to_string()));
        }
    }

    #[test]
    fn knots_become_distinct_values_and_multiplicities() {
        let (m, k) = knot_runs(&[0.0, 0.0, 0.0, 0.5, 1.0, 1.0, 1.0]);
        assert_eq!(m, "(3,1,3)");
        assert_eq!(k, "(0.,0.5,1.)");
    }

    #[test]
    fn long_lines_wrap_outside_strings() {
        let long = format!(
            "A('{}',{})",
            "x,".repeat(60),
            (0..40)
                .map(|i| format!("#{i}"))
                .collect::<Vec<_>>()
                .join(",")
        );
        let w = wrap(&long);
        assert!(w.lines().count() > 1);
        assert!(w.contains(&"x,".repeat(60)), "a string was broken");
        assert_eq!(
            w.split_whitespace().collect::<String>(),
            long.split_whitespace().collect::<String>()
        );
    }

    // ---------- every curve and surface kind, on hand-made B-reps ----------

    use crate::curve::NurbsData;
    use crate::surface::{NurbsSurfaceData, Revolution};
    use crate::topology::*;
    use std::f64::consts::{FRAC_PI_2, PI};
    use truck_geometry::prelude as tg;

    fn fixture(name: &str) -> Brep {
        let p = format!("{}/../../fixtures/{name}.step", env!("CARGO_MANIFEST_DIR"));
        crate::read_step(p).expect("fixture reads").brep
    }

    fn keep(name: &str, text: &str) {
        if let Ok(dir) = std::env::var("BREP_WRITE_DIR") {
            std::fs::write(format!("{dir}/{name}.step"), text).unwrap();
        }
    }

    fn nurbs_curve(knots: Vec<f64>, pts: &[(P3, f64)]) -> Curve {
        let cps = pts
            .iter()
            .map(|(p, w)| tg::Vector4::new(p.x * w, p.y * w, p.z * w, *w))
            .collect();
        let bs = tg::BSplineCurve::new(tg::KnotVec::from(knots), cps);
        Curve::Nurbs(Box::new(NurbsData::new(tg::NurbsCurve::new(bs))))
    }

    /// A degree-1 patch equal to the plane `frame` (same parametrisation) over `[u0,u1]×[v0,v1]`,
    /// with weight `w` everywhere.
    fn nurbs_plane(frame: &Frame, (u0, u1): (f64, f64), (v0, v1): (f64, f64), w: f64) -> Surface {
        let ku = tg::KnotVec::from(vec![u0, u0, u1, u1]);
        let kv = tg::KnotVec::from(vec![v0, v0, v1, v1]);
        let cps: Vec<Vec<tg::Vector4>> = [u0, u1]
            .iter()
            .map(|&u| {
                [v0, v1]
                    .iter()
                    .map(|&v| {
                        let p = frame.at(u, v, 0.0);
                        tg::Vector4::new(p.x * w, p.y * w, p.z * w, w)
                    })
                    .collect()
            })
            .collect();
        let bs = tg::BSplineSurface::new((ku, kv), cps);
        Surface::Nurbs(Box::new(NurbsSurfaceData::new(tg::NurbsSurface::new(bs))))
    }

    fn measure(b: &Brep) -> crate::SolidReport {
        crate::solid::report_solid(b, SolidId(0)).expect("measurable")
    }

    fn round_trip(b: &Brep, name: &str) -> Brep {
        let solids: Vec<SolidId> = b.solid_ids().collect();
        let text = write_step(b, &solids, name);
        keep(name, &text);
        let f = crate::p21::parse(text.as_bytes()).expect("parses");
        assert_eq!(f.first_dangling_ref(), None);
        crate::read_step_bytes(text.as_bytes())
            .expect("reads back")
            .brep
    }

    /// Every face and edge of `b` evaluates the same in `c`, met in the same traversal order
    /// (faces, loops, coedges) with the same parametrisation.
    fn assert_same_geometry(b: &Brep, c: &Brep) {
        assert_eq!(b.faces.len(), c.faces.len());
        assert_eq!(b.edges.len(), c.edges.len());
        for (fa, fb) in b.faces.iter().zip(&c.faces) {
            let (sa, sb) = (&b.surfaces[fa.surface.idx()], &c.surfaces[fb.surface.idx()]);
            assert_eq!(sa.kind(), sb.kind());
            assert_eq!(fa.same_sense, fb.same_sense);
            for (u, v) in [
                (0.1, 0.2),
                (0.7, -0.3),
                (1.9, 0.6),
                (3.0, 0.9),
                (-1.2, 0.05),
            ] {
                let (pa, pb) = (sa.eval(u, v), sb.eval(u, v));
                assert!((pa - pb).norm() < 1e-9, "{} moved at ({u},{v})", sa.kind());
                if let (Some(na), Some(nb)) = (sa.normal(u, v), sb.normal(u, v)) {
                    assert!(na.dot(&nb) > 1.0 - 1e-9, "{} normal flipped", sa.kind());
                }
            }
            assert_eq!(fa.loops.len(), fb.loops.len());
            for (la, lb) in fa.loops.iter().zip(&fb.loops) {
                let (la, lb) = (&b.loops[la.idx()], &c.loops[lb.idx()]);
                assert_eq!(la.coedges.len(), lb.coedges.len());
                for (ka, kb) in la.coedges.iter().zip(&lb.coedges) {
                    let (ka, kb) = (&b.coedges[ka.idx()], &c.coedges[kb.idx()]);
                    assert_eq!(ka.forward, kb.forward);
                    let (ea, eb) = (b.edge(ka.edge), c.edge(kb.edge));
                    let (ca, cb) = (&b.curves[ea.curve.idx()], &c.curves[eb.curve.idx()]);
                    assert_eq!(ca.kind(), cb.kind());
                    for k in 0..=8 {
                        let f = k as f64 / 8.0;
                        let pa = ca.eval(ea.t_start + f * (ea.t_end - ea.t_start));
                        let pb = cb.eval(eb.t_start + f * (eb.t_end - eb.t_start));
                        assert!(
                            (pa - pb).norm() < 1e-9,
                            "{} edge moved at {f}: {pa} vs {pb}",
                            ca.kind()
                        );
                        // The same parametrisation, not only the same point set.
                        let t = ea.t_start + f * (ea.t_end - ea.t_start);
                        assert!(
                            (ca.eval(t) - cb.eval(t)).norm() < 1e-9,
                            "{} reparametrised",
                            ca.kind()
                        );
                    }
                }
            }
        }
    }

    #[test]
    fn a_box_with_every_kind_of_straight_edge_and_flat_face_round_trips() {
        let mut b = fixture("box");
        let before = measure(&b).volume;
        for k in 0..b.edges.len() {
            let e = b.edges[k].clone();
            let (ps, pe) = (
                b.vertices[e.start.idx()].point,
                b.vertices[e.end.idx()].point,
            );
            let len = (pe - ps).norm();
            let dir = (pe - ps) / len;
            let (curve, t0, t1) = match k % 5 {
                // Runs against its trimmed basis, which starts 5 mm before the edge.
                0 => (
                    Curve::Trimmed {
                        basis: Box::new(Curve::Line {
                            origin: ps - dir * 5.0,
                            dir,
                        }),
                        t0: 5.0 + len,
                        t1: 5.0,
                    },
                    1.0,
                    0.0,
                ),
                1 => (
                    Curve::Polyline(vec![ps, ps + dir * (0.3 * len), pe]),
                    0.0,
                    2.0,
                ),
                // A rational straight segment (uneven weights: non-uniform speed).
                2 => (
                    nurbs_curve(vec![0.0, 0.0, 1.0, 1.0], &[(ps, 1.0), (pe, 3.0)]),
                    0.0,
                    1.0,
                ),
                // A trim of a trim of a longer line, run backwards by the edge.
                3 => (
                    Curve::Trimmed {
                        basis: Box::new(Curve::Trimmed {
                            basis: Box::new(Curve::Line {
                                origin: pe + dir * 2.0,
                                dir: -dir,
                            }),
                            t0: 0.0,
                            t1: 4.0 + len,
                        }),
                        t0: 2.0 / (4.0 + len),
                        t1: (2.0 + len) / (4.0 + len),
                    },
                    1.0,
                    0.0,
                ),
                _ => continue,
            };
            let id = CurveId(b.curves.len() as u32);
            b.curves.push(curve);
            let e = &mut b.edges[k];
            (e.curve, e.t_start, e.t_end) = (id, t0, t1);
            let c = &b.curves[id.idx()];
            assert!((c.eval(t0) - ps).norm() < 1e-9 && (c.eval(t1) - pe).norm() < 1e-9);
        }
        for k in 0..b.faces.len() {
            let f = FaceId(k as u32);
            let Surface::Plane { frame } = b.face_surface(f).clone() else {
                panic!("box faces are planes")
            };
            let uvs: Vec<(f64, f64)> = b
                .vertices_of(&[f])
                .iter()
                .map(|v| b.face_project(f, &b.vertices[v.idx()].point))
                .collect();
            let ur = uvs.iter().fold((f64::MAX, f64::MIN), |r, p| {
                (r.0.min(p.0 - 1.0), r.1.max(p.0 + 1.0))
            });
            let vr = uvs.iter().fold((f64::MAX, f64::MIN), |r, p| {
                (r.0.min(p.1 - 1.0), r.1.max(p.1 + 1.0))
            });
            let s = match k % 3 {
                0 => Surface::Extrusion {
                    profile: Box::new(Curve::Line {
                        origin: frame.origin,
                        dir: frame.x,
                    }),
                    dir: frame.y,
                },
                1 => Surface::Offset {
                    basis: Box::new(Surface::Plane {
                        frame: Frame {
                            origin: frame.origin - frame.z * 2.5,
                            ..frame
                        },
                    }),
                    distance: 2.5,
                },
                _ => nurbs_plane(&frame, ur, vr, 2.0),
            };
            let id = SurfaceId(b.surfaces.len() as u32);
            b.surfaces.push(s);
            b.faces[k].surface = id;
        }
        let r = measure(&b);
        assert!(r.closed && r.watertight);
        assert!(
            (r.volume - before).abs() < 1e-6 * before,
            "{} vs {before}",
            r.volume
        );
        let c = round_trip(&b, "synthetic_box");
        assert_same_geometry(&b, &c);
        let r2 = measure(&c);
        assert!(r2.closed && r2.watertight);
        assert!(
            (r2.volume - r.volume).abs() < 1e-9 * r.volume,
            "{} vs {}",
            r2.volume,
            r.volume
        );
        assert_eq!(r.curves, r2.curves);
        assert_eq!(r.surfaces, r2.surfaces);
    }

    #[test]
    fn a_cylinder_with_elliptic_rims_and_an_offset_side_round_trips() {
        let mut b = fixture("cylinder");
        for c in b.curves.iter_mut() {
            if let Curve::Circle { frame, radius } = c.clone() {
                *c = Curve::Ellipse {
                    frame,
                    a: radius,
                    b: radius,
                };
            }
        }
        for s in b.surfaces.iter_mut() {
            if let Surface::Cylinder { frame, radius } = s.clone() {
                *s = Surface::Offset {
                    basis: Box::new(Surface::Cylinder {
                        frame,
                        radius: radius - 1.5,
                    }),
                    distance: 1.5,
                };
            }
        }
        let r = measure(&b);
        assert!(r.closed && r.watertight);
        let c = round_trip(&b, "synthetic_cylinder");
        assert_same_geometry(&b, &c);
        let r2 = measure(&c);
        assert!(
            (r2.volume - r.volume).abs() < 1e-9 * r.volume,
            "{} vs {}",
            r2.volume,
            r.volume
        );
        assert_eq!(r2.curves.get("ellipse"), Some(&2));
        assert_eq!(r2.surfaces.get("offset"), Some(&1));
    }

    /// One face on `surface` bounded by one loop of the given (curve, t_start, t_end) edges, each
    /// with its own vertices (the reader does not check that loops connect).
    fn one_face(surface: Surface, same_sense: bool, edges: Vec<(Curve, f64, f64)>) -> Brep {
        let mut b = Brep::default();
        b.surfaces.push(surface);
        b.solids.push(Solid {
            step_id: 0,
            name: "it's a test".into(),
            shells: vec![ShellId(0)],
        });
        b.shells.push(Shell {
            step_id: 0,
            faces: vec![FaceId(0)],
            void: false,
        });
        b.faces.push(Face {
            step_id: 0,
            surface: SurfaceId(0),
            same_sense,
            loops: vec![LoopId(0)],
            shell: ShellId(0),
        });
        b.loops.push(Loop {
            step_id: 0,
            face: FaceId(0),
            outer: true,
            coedges: vec![],
            vertex: None,
        });
        for (k, (c, t0, t1)) in edges.into_iter().enumerate() {
            let (p0, p1) = (c.eval(t0), c.eval(t1));
            let v = b.vertices.len() as u32;
            b.vertices.push(Vertex {
                step_id: 0,
                point: p0,
            });
            b.vertices.push(Vertex {
                step_id: 0,
                point: p1,
            });
            b.curves.push(c);
            b.edges.push(Edge {
                step_id: 0,
                curve: CurveId(k as u32),
                start: VertexId(v),
                end: VertexId(v + 1),
                t_start: t0,
                t_end: t1,
                coedges: vec![CoedgeId(k as u32)],
            });
            b.coedges.push(Coedge {
                step_id: 0,
                edge: EdgeId(k as u32),
                forward: k % 2 == 0,
                lp: LoopId(0),
            });
            b.loops[0].coedges.push(CoedgeId(k as u32));
        }
        b
    }

    #[test]
    fn every_curve_kind_keeps_its_parametrisation() {
        let f = Frame::from_axes(
            P3::new(1.0, -2.0, 3.0),
            Some(V3::new(0.2, -0.3, 1.0)),
            Some(V3::new(1.0, 0.4, 0.0)),
        )
        .unwrap();
        let line = Curve::Line {
            origin: f.origin,
            dir: f.x,
        };
        let circle = Curve::Circle {
            frame: f,
            radius: 4.0,
        };
        let edges = vec![
            (
                Curve::Ellipse {
                    frame: f,
                    a: 3.0,
                    b: 5.0,
                },
                0.3,
                2.0,
            ),
            (
                Curve::Ellipse {
                    frame: f,
                    a: 3.0,
                    b: 5.0,
                },
                5.0,
                1.0,
            ), // against the curve
            (
                Curve::Hyperbola {
                    frame: f,
                    a: 2.0,
                    b: 1.5,
                },
                -0.7,
                1.1,
            ),
            (
                Curve::Parabola {
                    frame: f,
                    focal: 0.8,
                },
                1.5,
                -2.0,
            ),
            (
                Curve::Trimmed {
                    basis: Box::new(circle.clone()),
                    t0: 5.5,
                    t1: 7.0,
                },
                0.0,
                1.0,
            ),
            (
                Curve::Trimmed {
                    basis: Box::new(circle.clone()),
                    t0: 1.0,
                    t1: -0.5,
                },
                0.0,
                1.0,
            ),
            (
                Curve::Trimmed {
                    basis: Box::new(Curve::Hyperbola {
                        frame: f,
                        a: 2.0,
                        b: 1.5,
                    }),
                    t0: 0.5,
                    t1: -0.5,
                },
                0.0,
                1.0,
            ),
            (
                Curve::Trimmed {
                    basis: Box::new(Curve::Parabola {
                        frame: f,
                        focal: 0.8,
                    }),
                    t0: -1.0,
                    t1: 2.0,
                },
                0.0,
                1.0,
            ),
            (
                Curve::Trimmed {
                    basis: Box::new(line.clone()),
                    t0: -3.0,
                    t1: 4.0,
                },
                1.0,
                0.0,
            ),
            (
                Curve::Trimmed {
                    basis: Box::new(Curve::Trimmed {
                        basis: Box::new(Curve::Ellipse {
                            frame: f,
                            a: 3.0,
                            b: 5.0,
                        }),
                        t0: 1.0,
                        t1: 3.0,
                    }),
                    t0: 0.75,
                    t1: 0.25,
                },
                0.0,
                1.0,
            ),
            (
                Curve::Polyline(vec![
                    f.at(0.0, 0.0, 0.0),
                    f.at(1.0, 2.0, 0.5),
                    f.at(3.0, -1.0, 0.0),
                    f.at(4.0, 0.0, 1.0),
                ]),
                0.5,
                2.5,
            ),
            (
                nurbs_curve(
                    vec![0.0, 0.0, 0.0, 0.25, 0.5, 0.5, 1.0, 1.0, 1.0],
                    &[
                        (f.at(0.0, 0.0, 0.0), 1.0),
                        (f.at(1.0, 1.0, 0.0), 0.7),
                        (f.at(2.0, 0.0, 1.0), 2.0),
                        (f.at(3.0, 1.0, 0.0), 1.0),
                        (f.at(4.0, -1.0, 0.0), 0.5),
                        (f.at(5.0, 0.0, 0.0), 1.0),
                    ],
                ),
                0.9,
                0.1,
            ),
            (
                nurbs_curve(
                    vec![-1.0, -1.0, -1.0, 2.0, 2.0, 2.0],
                    &[
                        (f.at(0.0, 0.0, 0.0), 1.0),
                        (f.at(1.0, 3.0, 0.0), 1.0),
                        (f.at(2.0, 0.0, 1e-9), 1.0),
                    ],
                ),
                -1.0,
                2.0,
            ),
        ];
        let b = one_face(Surface::Plane { frame: f }, true, edges);
        let c = round_trip(&b, "synthetic_curves");
        assert_same_geometry(&b, &c);
        assert_eq!(c.solids[0].name, "it's a test");
        // The written text says what it should.
        let text = write_step(&b, &[SolidId(0)], "curves");
        for kind in [
            "HYPERBOLA(",
            "PARABOLA(",
            "ELLIPSE(",
            "TRIMMED_CURVE(",
            "POLYLINE(",
            "RATIONAL_B_SPLINE_CURVE(",
            "= B_SPLINE_CURVE_WITH_KNOTS(",
        ] {
            assert!(text.contains(kind), "{kind} missing");
        }
        // A trim of a trim is written as one trim of the innermost basis.
        let f = crate::p21::parse(text.as_bytes()).unwrap();
        for e in &f.entities {
            if let Some(r) = e.instance.record("TRIMMED_CURVE") {
                let crate::p21::Param::Ref(basis) = r.params[1] else {
                    panic!()
                };
                assert!(f
                    .get(basis)
                    .unwrap()
                    .instance
                    .record("TRIMMED_CURVE")
                    .is_none());
            }
        }
    }

    #[test]
    fn every_surface_kind_keeps_its_parametrisation_and_normal() {
        let f = Frame::from_axes(
            P3::new(1.0, -2.0, 3.0),
            Some(V3::new(0.2, -0.3, 1.0)),
            Some(V3::new(1.0, 0.4, 0.0)),
        )
        .unwrap();
        let edge = || {
            vec![(
                Curve::Line {
                    origin: f.origin,
                    dir: f.x,
                },
                0.0,
                1.0,
            )]
        };
        let profile = nurbs_curve(
            vec![0.0, 0.0, 0.0, 1.0, 1.0, 1.0],
            &[
                (f.at(3.0, 0.0, 0.0), 1.0),
                (f.at(4.0, 0.0, 1.0), 0.6),
                (f.at(2.5, 0.0, 2.0), 1.0),
            ],
        );
        let surfaces = vec![
            Surface::Plane { frame: f },
            Surface::Cylinder {
                frame: f,
                radius: 2.5,
            },
            Surface::Cone {
                frame: f,
                radius: 2.5,
                semi_angle: 0.3,
            },
            Surface::Cone {
                frame: f,
                radius: 0.0,
                semi_angle: PI / 4.0,
            },
            Surface::Sphere {
                frame: f,
                radius: 7.0,
            },
            Surface::Torus {
                frame: f,
                major: 5.0,
                minor: 1.25,
            },
            Surface::Revolution(Box::new(Revolution::new(profile.clone(), f.origin, f.z))),
            Surface::Revolution(Box::new(Revolution::new(
                Curve::Trimmed {
                    basis: Box::new(Curve::Circle {
                        frame: Frame::from_axes(f.at(6.0, 0.0, 0.0), Some(f.y), Some(f.x)).unwrap(),
                        radius: 1.0,
                    }),
                    t0: 0.0,
                    t1: -FRAC_PI_2,
                },
                f.origin,
                f.z,
            ))),
            Surface::Extrusion {
                profile: Box::new(profile.clone()),
                dir: f.y,
            },
            Surface::Extrusion {
                profile: Box::new(Curve::Ellipse {
                    frame: f,
                    a: 2.0,
                    b: 1.0,
                }),
                dir: (f.z + f.x * 0.3).normalize(),
            },
            nurbs_plane(&f, (-2.0, 3.0), (-1.0, 4.0), 1.0),
            nurbs_plane(&f, (-2.0, 3.0), (-1.0, 4.0), 0.25),
            Surface::Offset {
                basis: Box::new(Surface::Sphere {
                    frame: f,
                    radius: 7.0,
                }),
                distance: -1.5,
            },
            Surface::Offset {
                basis: Box::new(nurbs_plane(&f, (-2.0, 3.0), (-1.0, 4.0), 3.0)),
                distance: 0.75,
            },
        ];
        for (k, s) in surfaces.into_iter().enumerate() {
            for same_sense in [true, false] {
                let b = one_face(s.clone(), same_sense, edge());
                let c = round_trip(&b, &format!("synthetic_surface_{k}"));
                assert_same_geometry(&b, &c);
            }
        }
    }

    #[test]
    fn a_rational_bspline_surface_is_one_complex_entity() {
        let f = Frame::world(P3::origin());
        let b = one_face(
            nurbs_plane(&f, (0.0, 1.0), (0.0, 1.0), 2.0),
            true,
            vec![(
                Curve::Line {
                    origin: f.origin,
                    dir: f.x,
                },
                0.0,
                1.0,
            )],
        );
        let text = write_step(&b, &[SolidId(0)], "rational");
        let f = crate::p21::parse(text.as_bytes()).unwrap();
        let e = f
            .entities
            .iter()
            .find(|e| e.instance.record("RATIONAL_B_SPLINE_SURFACE").is_some())
            .expect("rational surface");
        let names = e.instance.names();
        let mut sorted = names.clone();
        sorted.sort();
        assert_eq!(
            names, sorted,
            "complex entity parts must be in alphabetical order"
        );
        assert!(
            names.contains(&"B_SPLINE_SURFACE_WITH_KNOTS") && names.contains(&"B_SPLINE_SURFACE")
        );
    }
}
