//! Translation of a parsed Part 21 file into our [`Brep`] (AP203, AP214 and AP242 share the
//! topology and geometry entities read here).
//!
//! Handles, beyond what truck-stepio 0.3 does: the file's length and plane-angle units, closed
//! edges and seam edges (any edge shape goes into our arena unchanged), `BREP_WITH_VOIDS`,
//! `OFFSET_SURFACE`, `RECTANGULAR_TRIMMED_SURFACE`, `TRIMMED_CURVE`, and `SURFACE_CURVE`s taken by
//! their 3-D curve (so a seam that ends at a sphere's pole reads like any other edge).

use crate::curve::{Curve, NurbsData};
use crate::error::ReadError;
use crate::math::{Frame, P3, V3};
use crate::p21::{Entity, P21File, Param, Record};
use crate::surface::{NurbsSurfaceData, Revolution, Surface};
use crate::topology::*;
use std::collections::HashMap;
use truck_geometry::prelude as tg;

type R<T> = Result<T, ReadError>;

/// Reads a parsed file into a B-rep of every solid it holds.
pub fn translate(file: &P21File) -> R<Brep> {
    if let Some((from, missing)) = file.first_dangling_ref() {
        return Err(ReadError::Dangling { from, missing });
    }
    let mut t = Translator::new(file);
    let contexts = t.item_contexts();
    let bodies = t.find_bodies()?;
    if bodies.is_empty() {
        return Err(ReadError::NoSolid(t.why_no_solid()));
    }
    let default_units = t.default_units();
    let mut unit_names: Vec<LengthUnit> = vec![];
    for (id, kind) in bodies {
        let units = contexts
            .get(&id)
            .and_then(|c| t.context_units(*c).ok())
            .unwrap_or_else(|| default_units.clone());
        t.mm = units.0.mm_per_unit;
        t.rad = units.1;
        if !unit_names.contains(&units.0) {
            unit_names.push(units.0.clone());
        }
        t.read_body(id, kind)?;
    }
    if t.off_curve.0 > 0 {
        t.brep.warnings.push(format!(
            "{} edge ends lie off their curves by up to {:.3} mm (worst at #{})",
            t.off_curve.0, t.off_curve.1, t.off_curve.2
        ));
    }
    t.brep.units = unit_names;
    // Entities of no schema the reader knows (a misspelt name): skipped, but said.
    let unknown: Vec<(u64, &str)> = file
        .entities
        .iter()
        .flat_map(|e| {
            e.instance
                .names()
                .into_iter()
                .filter(|n| !crate::schema_names::is_known(n))
                .map(move |n| (e.id, n))
        })
        .collect();
    for (id, name) in unknown.iter().take(5) {
        let hint = crate::schema_names::nearest(name)
            .map(|k| format!(" (did you mean {k}?)"))
            .unwrap_or_default();
        t.brep
            .warnings
            .push(format!("#{id}: unknown entity {name}{hint}; skipped"));
    }
    if unknown.len() > 5 {
        t.brep.warnings.push(format!(
            "{} more entities of unknown names skipped",
            unknown.len() - 5
        ));
    }
    if t.brep.solids.is_empty() {
        let mut why = String::new();
        for w in &t.brep.warnings {
            why.push_str("; ");
            why.push_str(w);
        }
        return Err(ReadError::NoSolid(why));
    }
    Ok(t.brep)
}

#[derive(Clone, Copy, Debug)]
enum BodyKind {
    Manifold,
    WithVoids,
    SurfaceModel,
}

struct Translator<'a> {
    file: &'a P21File,
    brep: Brep,
    /// Millimetres per file length unit.
    mm: f64,
    /// Radians per file plane-angle unit.
    rad: f64,
    vertices: HashMap<u64, VertexId>,
    edges: HashMap<u64, EdgeId>,
    curves: HashMap<u64, CurveId>,
    surfaces: HashMap<u64, (SurfaceId, bool)>,
    depth: u32,
    /// (count, worst distance, worst edge id) of edge ends off their curve.
    off_curve: (usize, f64, u64),
}

fn names_of(e: &Entity) -> String {
    e.instance.names().join("+")
}

impl<'a> Translator<'a> {
    fn new(file: &'a P21File) -> Self {
        Translator {
            file,
            brep: Brep::default(),
            mm: 1.0,
            rad: 1.0,
            vertices: HashMap::new(),
            edges: HashMap::new(),
            curves: HashMap::new(),
            surfaces: HashMap::new(),
            depth: 0,
            off_curve: (0, 0.0, 0),
        }
    }

    // ---------- access helpers ----------

    fn entity(&self, id: u64, from: u64) -> R<&'a Entity> {
        self.file
            .get(id)
            .ok_or(ReadError::Dangling { from, missing: id })
    }

    /// The record of entity `id` named one of `names` (simple or part of a complex entity).
    fn record(&self, id: u64, from: u64, names: &[&'static str]) -> R<(&'static str, &'a Record)> {
        let e = self.entity(id, from)?;
        for n in names {
            if let Some(r) = e.instance.record(n) {
                return Ok((n, r));
            }
        }
        Err(ReadError::Entity {
            id,
            entity: names_of(e),
            msg: format!(
                "expected {} here (referenced from #{from})",
                names.join(" or ")
            ),
        })
    }

    fn bad(&self, id: u64, msg: impl Into<String>) -> ReadError {
        let entity = self.file.get(id).map(names_of).unwrap_or_default();
        ReadError::Entity {
            id,
            entity,
            msg: msg.into(),
        }
    }

    fn param<'r>(&self, id: u64, r: &'r Record, i: usize) -> R<&'r Param> {
        r.params.get(i).ok_or_else(|| {
            self.bad(
                id,
                format!(
                    "{} has {} parameters, expected more than {i}",
                    r.name,
                    r.params.len()
                ),
            )
        })
    }

    fn real(&self, id: u64, r: &Record, i: usize) -> R<f64> {
        let p = self.param(id, r, i)?;
        as_real(p).ok_or_else(|| {
            self.bad(
                id,
                format!("parameter {} of {} is not a number", i + 1, r.name),
            )
        })
    }

    fn int(&self, id: u64, r: &Record, i: usize) -> R<i64> {
        match self.param(id, r, i)? {
            Param::Int(n) => Ok(*n),
            Param::Real(x) if x.fract() == 0.0 && x.abs() < 1e15 => Ok(*x as i64),
            _ => Err(self.bad(
                id,
                format!("parameter {} of {} is not an integer", i + 1, r.name),
            )),
        }
    }

    fn bool(&self, id: u64, r: &Record, i: usize) -> R<bool> {
        match self.param(id, r, i)? {
            Param::Enum(e) if e.eq_ignore_ascii_case("T") => Ok(true),
            Param::Enum(e) if e.eq_ignore_ascii_case("F") => Ok(false),
            Param::Null | Param::Derived => Ok(true),
            _ => Err(self.bad(
                id,
                format!("parameter {} of {} is not .T. or .F.", i + 1, r.name),
            )),
        }
    }

    fn reference(&self, id: u64, r: &Record, i: usize) -> R<u64> {
        match self.param(id, r, i)? {
            Param::Ref(x) => Ok(*x),
            _ => Err(self.bad(
                id,
                format!("parameter {} of {} is not a #reference", i + 1, r.name),
            )),
        }
    }

    fn opt_reference(&self, id: u64, r: &Record, i: usize) -> R<Option<u64>> {
        match self.param(id, r, i)? {
            Param::Ref(x) => Ok(Some(*x)),
            Param::Null | Param::Derived => Ok(None),
            _ => Err(self.bad(
                id,
                format!("parameter {} of {} is not a #reference", i + 1, r.name),
            )),
        }
    }

    fn list<'r>(&self, id: u64, r: &'r Record, i: usize) -> R<&'r [Param]> {
        match self.param(id, r, i)? {
            Param::List(l) => Ok(l),
            _ => Err(self.bad(
                id,
                format!("parameter {} of {} is not a list", i + 1, r.name),
            )),
        }
    }

    fn refs(&self, id: u64, r: &Record, i: usize) -> R<Vec<u64>> {
        self.list(id, r, i)?
            .iter()
            .map(|p| match p {
                Param::Ref(x) => Ok(*x),
                _ => Err(self.bad(
                    id,
                    format!("parameter {} of {} holds a non-reference", i + 1, r.name),
                )),
            })
            .collect()
    }

    fn name(r: &Record) -> String {
        match r.params.first() {
            Some(Param::Str(s)) => s.clone(),
            _ => String::new(),
        }
    }

    fn enter(&mut self, id: u64) -> R<()> {
        self.depth += 1;
        if self.depth > 24 {
            return Err(self.bad(id, "geometry nested too deep (a reference cycle?)"));
        }
        Ok(())
    }

    // ---------- units ----------

    /// Maps each representation item (solid) to the context of its representation.
    fn item_contexts(&self) -> HashMap<u64, u64> {
        let mut out = HashMap::new();
        for e in &self.file.entities {
            for name in e.instance.names() {
                if !name.ends_with("REPRESENTATION") || name.contains("RELATIONSHIP") {
                    continue;
                }
                let Some(r) = e.instance.record(name) else {
                    continue;
                };
                if r.params.len() < 3 {
                    continue;
                }
                let (Param::List(items), Param::Ref(ctx)) = (&r.params[1], &r.params[2]) else {
                    continue;
                };
                for it in items {
                    if let Param::Ref(i) = it {
                        out.entry(*i).or_insert(*ctx);
                    }
                }
            }
        }
        out
    }

    fn default_units(&mut self) -> (LengthUnit, f64) {
        for e in &self.file.entities {
            if e.instance.record("GLOBAL_UNIT_ASSIGNED_CONTEXT").is_some() {
                if let Ok(u) = self.context_units(e.id) {
                    return u;
                }
            }
        }
        self.brep
            .warnings
            .push("no length unit in the file; assuming millimetres".into());
        (
            LengthUnit {
                name: "mm".into(),
                mm_per_unit: 1.0,
            },
            1.0,
        )
    }

    /// (length unit, radians per angle unit) of a representation context.
    fn context_units(&self, ctx: u64) -> R<(LengthUnit, f64)> {
        let (_, r) = self.record(ctx, ctx, &["GLOBAL_UNIT_ASSIGNED_CONTEXT"])?;
        let units = self.refs(ctx, r, 0)?;
        let mut length = None;
        let mut angle = 1.0;
        for u in units {
            let e = self.entity(u, ctx)?;
            if e.instance.record("LENGTH_UNIT").is_some() {
                length = Some(self.length_unit(u, ctx, 0)?);
            } else if e.instance.record("PLANE_ANGLE_UNIT").is_some() {
                angle = self.angle_unit(u, ctx, 0)?;
            }
        }
        let length = length.ok_or_else(|| self.bad(ctx, "context has no length unit"))?;
        Ok((length, angle))
    }

    fn length_unit(&self, u: u64, from: u64, depth: u32) -> R<LengthUnit> {
        if depth > 8 {
            return Err(self.bad(u, "unit definitions nested too deep"));
        }
        let e = self.entity(u, from)?;
        if let Some(si) = e.instance.record("SI_UNIT") {
            let prefix = match si.params.first() {
                Some(Param::Enum(p)) => p.to_ascii_uppercase(),
                _ => String::new(),
            };
            let (f, name) = match prefix.as_str() {
                "" => (1000.0, "m"),
                "MILLI" => (1.0, "mm"),
                "CENTI" => (10.0, "cm"),
                "DECI" => (100.0, "dm"),
                "KILO" => (1e6, "km"),
                "MICRO" => (1e-3, "um"),
                "NANO" => (1e-6, "nm"),
                "DECA" => (1e4, "dam"),
                "HECTO" => (1e5, "hm"),
                other => {
                    return Err(self.bad(
                        u,
                        format!("unsupported SI prefix .{other}. on a length unit"),
                    ))
                }
            };
            return Ok(LengthUnit {
                name: name.into(),
                mm_per_unit: f,
            });
        }
        if let Some(cb) = e.instance.record("CONVERSION_BASED_UNIT") {
            let name = Self::name(cb).to_ascii_lowercase();
            let m = self.reference(u, cb, 1)?;
            let (_, mr) = self.record(m, u, &["LENGTH_MEASURE_WITH_UNIT", "MEASURE_WITH_UNIT"])?;
            let value = self.real(m, mr, 0)?;
            let base = self.reference(m, mr, 1)?;
            let base = self.length_unit(base, m, depth + 1)?;
            let f = value * base.mm_per_unit;
            if !(f.is_finite() && f > 0.0) {
                return Err(self.bad(u, "length unit conversion factor is not positive"));
            }
            let name = match name.as_str() {
                "inch" | "in" | "\"" => "inch".to_string(),
                "foot" | "ft" | "feet" => "foot".to_string(),
                "" => format!("{f} mm"),
                n => n.to_string(),
            };
            return Ok(LengthUnit {
                name,
                mm_per_unit: f,
            });
        }
        Err(self.bad(
            u,
            "length unit is neither SI_UNIT nor CONVERSION_BASED_UNIT",
        ))
    }

    fn angle_unit(&self, u: u64, from: u64, depth: u32) -> R<f64> {
        if depth > 8 {
            return Err(self.bad(u, "unit definitions nested too deep"));
        }
        let e = self.entity(u, from)?;
        if e.instance.record("SI_UNIT").is_some() {
            return Ok(1.0);
        }
        if let Some(cb) = e.instance.record("CONVERSION_BASED_UNIT") {
            let m = self.reference(u, cb, 1)?;
            let (_, mr) = self.record(
                m,
                u,
                &["PLANE_ANGLE_MEASURE_WITH_UNIT", "MEASURE_WITH_UNIT"],
            )?;
            let value = self.real(m, mr, 0)?;
            let base = self.reference(m, mr, 1)?;
            return Ok(value * self.angle_unit(base, m, depth + 1)?);
        }
        Ok(1.0)
    }

    // ---------- bodies ----------

    fn find_bodies(&self) -> R<Vec<(u64, BodyKind)>> {
        let mut out = vec![];
        for e in &self.file.entities {
            let i = &e.instance;
            if i.record("BREP_WITH_VOIDS").is_some() {
                out.push((e.id, BodyKind::WithVoids));
            } else if i.record("MANIFOLD_SOLID_BREP").is_some() {
                out.push((e.id, BodyKind::Manifold));
            } else if i.record("SHELL_BASED_SURFACE_MODEL").is_some() {
                out.push((e.id, BodyKind::SurfaceModel));
            } else if i.record("FACETED_BREP").is_some() {
                return Err(ReadError::Unsupported {
                    id: e.id,
                    entity: "FACETED_BREP".into(),
                });
            }
        }
        Ok(out)
    }

    fn why_no_solid(&self) -> String {
        let mut tess = false;
        let mut wire = false;
        for e in &self.file.entities {
            for n in e.instance.names() {
                tess |= n.contains("TESSELLATED") || n.contains("TRIANGULATED");
                wire |= n == "GEOMETRIC_CURVE_SET" || n == "EDGE_BASED_WIREFRAME_MODEL";
            }
        }
        if tess {
            "; the file holds only tessellated geometry".into()
        } else if wire {
            "; the file holds only curves (wireframe)".into()
        } else {
            String::new()
        }
    }

    fn read_body(&mut self, id: u64, kind: BodyKind) -> R<()> {
        match kind {
            BodyKind::Manifold => {
                let (_, r) = self.record(id, id, &["MANIFOLD_SOLID_BREP"])?;
                let outer = self.reference(id, r, 1)?;
                let name = Self::name(r);
                let solid = SolidId(self.brep.solids.len() as u32);
                let sh = self.read_shell(outer, id, false, solid)?;
                self.brep.solids.push(Solid {
                    step_id: id,
                    name,
                    shells: vec![sh],
                });
            }
            BodyKind::WithVoids => {
                let (_, r) = self.record(id, id, &["BREP_WITH_VOIDS"])?;
                let (_, m) = self
                    .record(id, id, &["MANIFOLD_SOLID_BREP"])
                    .unwrap_or(("", r));
                let name = Self::name(m);
                let outer = match self.entity(id, id)?.instance.record("MANIFOLD_SOLID_BREP") {
                    Some(ms) => self.reference(id, ms, 1)?,
                    None => self.reference(id, r, 1)?,
                };
                let voids_idx = if self
                    .entity(id, id)?
                    .instance
                    .record("MANIFOLD_SOLID_BREP")
                    .is_some()
                {
                    0
                } else {
                    2
                };
                let voids = self
                    .refs(id, r, voids_idx)
                    .or_else(|_| self.refs(id, r, 2))?;
                let solid = SolidId(self.brep.solids.len() as u32);
                let mut shells = vec![self.read_shell(outer, id, false, solid)?];
                for v in voids {
                    shells.push(self.read_shell(v, id, true, solid)?);
                }
                // A void lies inside its outer shell. One that does not (an AutoCAD 2000i
                // file lists a second body as a "void" of the first) is a solid of its own:
                // subtracted, it gave a negative volume.
                let outer_box = crate::solid::faces_rough_bbox(
                    &self.brep,
                    &self.brep.shells[shells[0].idx()].faces,
                );
                let slack = 1e-6 * outer_box.diagonal().max(1e-9);
                let mut own = vec![];
                let first = shells[0];
                shells.retain(|&sh| {
                    if sh == first {
                        return true;
                    }
                    let b = crate::solid::faces_rough_bbox(
                        &self.brep,
                        &self.brep.shells[sh.idx()].faces,
                    );
                    let inside = (0..3).all(|k| {
                        b.min[k] >= outer_box.min[k] - slack && b.max[k] <= outer_box.max[k] + slack
                    });
                    if !inside {
                        own.push(sh);
                    }
                    inside
                });
                self.brep.solids.push(Solid {
                    step_id: id,
                    name: name.clone(),
                    shells,
                });
                for sh in own {
                    self.brep.shells[sh.idx()].void = false;
                    let sid = self.brep.shells[sh.idx()].step_id;
                    self.brep.warnings.push(format!(
                        "#{id}: void shell #{sid} is not inside the outer shell #{outer}; read as a solid of its own"
                    ));
                    self.brep.solids.push(Solid {
                        step_id: id,
                        name: name.clone(),
                        shells: vec![sh],
                    });
                }
            }
            BodyKind::SurfaceModel => {
                let (_, r) = self.record(id, id, &["SHELL_BASED_SURFACE_MODEL"])?;
                let name = Self::name(r);
                for sh in self.refs(id, r, 1)? {
                    let solid = SolidId(self.brep.solids.len() as u32);
                    let shell = self.read_shell(sh, id, false, solid)?;
                    if self.shell_is_closed(shell) {
                        self.brep.solids.push(Solid {
                            step_id: id,
                            name: name.clone(),
                            shells: vec![shell],
                        });
                    } else {
                        let n = self.brep.shells[shell.idx()].faces.len();
                        self.brep.warnings.push(format!(
                            "#{sh}: open shell of {n} face(s) in surface model #{id} is not a solid; skipped"
                        ));
                    }
                }
            }
        }
        Ok(())
    }

    fn shell_is_closed(&self, shell: ShellId) -> bool {
        let faces = &self.brep.shells[shell.idx()].faces;
        let mut uses: HashMap<EdgeId, i32> = HashMap::new();
        for f in faces {
            for l in &self.brep.faces[f.idx()].loops {
                for c in &self.brep.loops[l.idx()].coedges {
                    *uses.entry(self.brep.coedges[c.idx()].edge).or_default() += 1;
                }
            }
        }
        !faces.is_empty() && uses.values().all(|&n| n == 2)
    }

    fn read_shell(&mut self, id: u64, from: u64, void: bool, _solid: SolidId) -> R<ShellId> {
        let (kind, r) = self.record(
            id,
            from,
            &[
                "ORIENTED_CLOSED_SHELL",
                "CLOSED_SHELL",
                "OPEN_SHELL",
                "ORIENTED_OPEN_SHELL",
            ],
        )?;
        let (faces_ref, flip) = if kind.starts_with("ORIENTED") {
            let inner = self.reference(id, r, 2)?;
            let orient = self.bool(id, r, 3)?;
            let (_, ir) = self.record(inner, id, &["CLOSED_SHELL", "OPEN_SHELL"])?;
            (self.refs(inner, ir, 1)?, !orient)
        } else {
            (self.refs(id, r, 1)?, false)
        };
        let shell = ShellId(self.brep.shells.len() as u32);
        self.brep.shells.push(Shell {
            step_id: id,
            faces: vec![],
            void,
        });
        for f in faces_ref {
            let face = self.read_face(f, id, flip, shell)?;
            self.brep.shells[shell.idx()].faces.push(face);
        }
        Ok(shell)
    }

    fn read_face(&mut self, id: u64, from: u64, flip: bool, shell: ShellId) -> R<FaceId> {
        let (kind, r) = self.record(
            id,
            from,
            &["ADVANCED_FACE", "FACE_SURFACE", "ORIENTED_FACE"],
        )?;
        if kind == "ORIENTED_FACE" {
            let inner = self.reference(id, r, 2)?;
            let orient = self.bool(id, r, 3)?;
            return self.read_face(inner, id, flip ^ !orient, shell);
        }
        let bounds = self.refs(id, r, 1)?;
        let geom = self.reference(id, r, 2)?;
        let same_sense = self.bool(id, r, 3)?;
        let (surface, flipped) = self.surface(geom, id)?;
        let face = FaceId(self.brep.faces.len() as u32);
        self.brep.faces.push(Face {
            step_id: id,
            surface,
            same_sense: same_sense ^ flipped ^ flip,
            loops: vec![],
            shell,
        });
        let mut loops = vec![];
        for b in bounds {
            let lp = self.read_bound(b, id, face)?;
            if self.brep.loops[lp.idx()].outer {
                loops.insert(0, lp);
            } else {
                loops.push(lp);
            }
        }
        self.brep.faces[face.idx()].loops = loops;
        Ok(face)
    }

    fn read_bound(&mut self, id: u64, from: u64, face: FaceId) -> R<LoopId> {
        let (kind, r) = self.record(id, from, &["FACE_OUTER_BOUND", "FACE_BOUND"])?;
        let bound = self.reference(id, r, 1)?;
        let orient = self.bool(id, r, 2)?;
        let lp = LoopId(self.brep.loops.len() as u32);
        self.brep.loops.push(Loop {
            step_id: id,
            face,
            outer: kind == "FACE_OUTER_BOUND",
            coedges: vec![],
            vertex: None,
        });
        let (lkind, lr) = self.record(bound, id, &["EDGE_LOOP", "VERTEX_LOOP", "POLY_LOOP"])?;
        match lkind {
            "VERTEX_LOOP" => {
                let v = self.reference(bound, lr, 1)?;
                let v = self.vertex(v, bound)?;
                self.brep.loops[lp.idx()].vertex = Some(v);
            }
            "POLY_LOOP" => {
                return Err(ReadError::Unsupported {
                    id: bound,
                    entity: "POLY_LOOP".into(),
                })
            }
            _ => {
                let oes = self.refs(bound, lr, 1)?;
                if oes.is_empty() {
                    return Err(self.bad(bound, "edge loop has no edges"));
                }
                let mut coedges = vec![];
                for oe in oes {
                    let (_, or) = self.record(oe, bound, &["ORIENTED_EDGE"])?;
                    let edge_ref = self.reference(oe, or, 3)?;
                    let o = self.bool(oe, or, 4)?;
                    let edge = self.edge(edge_ref, oe)?;
                    let c = CoedgeId(self.brep.coedges.len() as u32);
                    self.brep.coedges.push(Coedge {
                        step_id: oe,
                        edge,
                        forward: o == orient,
                        lp,
                    });
                    self.brep.edges[edge.idx()].coedges.push(c);
                    coedges.push(c);
                }
                if !orient {
                    coedges.reverse();
                }
                self.brep.loops[lp.idx()].coedges = coedges;
            }
        }
        Ok(lp)
    }

    fn vertex(&mut self, id: u64, from: u64) -> R<VertexId> {
        if let Some(v) = self.vertices.get(&id) {
            return Ok(*v);
        }
        let (_, r) = self.record(id, from, &["VERTEX_POINT"])?;
        let p = self.reference(id, r, 1)?;
        let point = self.point(p, id)?;
        let v = VertexId(self.brep.vertices.len() as u32);
        self.brep.vertices.push(Vertex { step_id: id, point });
        self.vertices.insert(id, v);
        Ok(v)
    }

    fn edge(&mut self, id: u64, from: u64) -> R<EdgeId> {
        if let Some(e) = self.edges.get(&id) {
            return Ok(*e);
        }
        let (_, r) = self.record(id, from, &["EDGE_CURVE"])?;
        let s = self.reference(id, r, 1)?;
        let e = self.reference(id, r, 2)?;
        let g = self.reference(id, r, 3)?;
        let same_sense = self.bool(id, r, 4)?;
        let start = self.vertex(s, id)?;
        let end = self.vertex(e, id)?;
        let ps = self.brep.vertices[start.idx()].point;
        let pe = self.brep.vertices[end.idx()].point;
        let curve = match self.curve(g, id) {
            Ok(c) => c,
            Err(ReadError::Unsupported { entity, .. }) if start != end => {
                self.brep.warnings.push(format!(
                    "#{id}: edge geometry {entity} is not supported; using a straight line"
                ));
                let dir = (pe - ps).try_normalize(1e-300).unwrap_or_else(V3::x);
                let c = CurveId(self.brep.curves.len() as u32);
                self.brep.curves.push(Curve::Line { origin: ps, dir });
                c
            }
            Err(err) => return Err(err),
        };
        let cv = &self.brep.curves[curve.idx()];
        let mut t_start = cv.project(&ps);
        let mut t_end = cv.project(&pe);
        let closed = start == end;
        if let Some(per) = cv.period() {
            let eps = 1e-9 * per;
            if same_sense {
                while t_end <= t_start + eps {
                    t_end += per;
                }
                if closed {
                    t_end = t_start + per;
                }
            } else {
                while t_end >= t_start - eps {
                    t_end -= per;
                }
                if closed {
                    t_end = t_start - per;
                }
            }
        } else if closed {
            let (a, b) = cv.range();
            if a.is_finite() && b.is_finite() {
                (t_start, t_end) = if same_sense { (a, b) } else { (b, a) };
            }
        }
        // How far the vertices are from the curve ends they stand for.
        let off = (cv.eval(t_start) - ps)
            .norm()
            .max((cv.eval(t_end) - pe).norm());
        // Far off (not modelling tolerance but a broken edge, e.g. a circle whose radius does
        // not match its vertices): refuse rather than mesh a curve that is not the edge.
        let limit = 1.0 + 1e-6 * ps.coords.norm().max(pe.coords.norm());
        if off.is_nan() || off > limit {
            return Err(ReadError::Entity {
                id,
                entity: "EDGE_CURVE".into(),
                msg: format!("its vertices lie {off:.3} mm off its curve #{g}"),
            });
        }
        if off > 1e-2 {
            self.off_curve.0 += 1;
            if off > self.off_curve.1 {
                self.off_curve.1 = off;
                self.off_curve.2 = id;
            }
        }
        let eid = EdgeId(self.brep.edges.len() as u32);
        self.brep.edges.push(Edge {
            step_id: id,
            curve,
            start,
            end,
            t_start,
            t_end,
            coedges: vec![],
        });
        self.edges.insert(id, eid);
        Ok(eid)
    }

    // ---------- geometry primitives ----------

    fn point(&self, id: u64, from: u64) -> R<P3> {
        let (_, r) = self.record(id, from, &["CARTESIAN_POINT"])?;
        let l = self.list(id, r, 1)?;
        let c: Vec<f64> = l.iter().filter_map(as_real).collect();
        if c.len() != l.len() || c.len() < 2 || c.iter().any(|x| !x.is_finite()) {
            return Err(self.bad(id, "coordinates are not 2 or 3 finite numbers"));
        }
        let z = c.get(2).copied().unwrap_or(0.0);
        Ok(P3::new(c[0], c[1], z) * self.mm)
    }

    fn direction(&self, id: u64, from: u64) -> R<V3> {
        let (_, r) = self.record(id, from, &["DIRECTION"])?;
        let l = self.list(id, r, 1)?;
        let c: Vec<f64> = l.iter().filter_map(as_real).collect();
        if c.len() != l.len() || c.len() < 2 || c.iter().any(|x| !x.is_finite()) {
            return Err(self.bad(id, "direction ratios are not 2 or 3 finite numbers"));
        }
        let v = V3::new(c[0], c[1], c.get(2).copied().unwrap_or(0.0));
        v.try_normalize(1e-300)
            .ok_or_else(|| self.bad(id, "zero-length direction"))
    }

    fn vector(&self, id: u64, from: u64) -> R<(V3, f64)> {
        let (kind, r) = self.record(id, from, &["VECTOR", "DIRECTION"])?;
        if kind == "DIRECTION" {
            return Ok((self.direction(id, from)?, 1.0));
        }
        let d = self.reference(id, r, 1)?;
        let mag = self.real(id, r, 2)?;
        Ok((self.direction(d, id)?, mag * self.mm))
    }

    fn placement(&self, id: u64, from: u64) -> R<Frame> {
        let (_, r) = self.record(id, from, &["AXIS2_PLACEMENT_3D"])?;
        let o = self.reference(id, r, 1)?;
        let origin = self.point(o, id)?;
        let z = match self.opt_reference(id, r, 2)? {
            Some(d) => Some(self.direction(d, id)?),
            None => None,
        };
        let x = match self.opt_reference(id, r, 3)? {
            Some(d) => Some(self.direction(d, id)?),
            None => None,
        };
        Frame::from_axes(origin, z, x).ok_or_else(|| self.bad(id, "degenerate placement"))
    }

    fn positive(&self, id: u64, r: &Record, i: usize, what: &str) -> R<f64> {
        let x = self.real(id, r, i)? * self.mm;
        if !(x.is_finite() && x > 0.0) {
            return Err(self.bad(id, format!("{what} must be positive, found {x}")));
        }
        Ok(x)
    }

    // ---------- curves ----------

    fn curve(&mut self, id: u64, from: u64) -> R<CurveId> {
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

    fn build_curve(&mut self, id: u64, from: u64) -> R<Curve> {
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
    fn trim_param(&self, id: u64, basis: &Curve, basis_id: u64, sel: &[Param]) -> R<f64> {
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

    fn knots(
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

    fn degree(&self, id: u64, r: &Record, i: usize) -> R<usize> {
        let d = self.int(id, r, i)?;
        if !(1..=25).contains(&d) {
            return Err(self.bad(id, format!("degree {d} out of range")));
        }
        Ok(d as usize)
    }

    fn bspline_curve(&mut self, id: u64) -> R<Curve> {
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

    // ---------- surfaces ----------

    /// The surface and whether its natural normal is reversed by a trimming wrapper.
    fn surface(&mut self, id: u64, from: u64) -> R<(SurfaceId, bool)> {
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

    fn build_surface(&mut self, id: u64, from: u64) -> R<(Surface, bool)> {
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

    fn bspline_surface(&mut self, id: u64) -> R<Surface> {
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

fn uniform_knots(n: usize, degree: usize, quasi: bool) -> tg::KnotVec {
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

/// A real from a parameter, looking through typed wrappers like `LENGTH_MEASURE(2.)`.
pub(crate) fn as_real(p: &Param) -> Option<f64> {
    match p {
        Param::Real(x) => Some(*x),
        Param::Int(n) => Some(*n as f64),
        Param::Typed(_, inner) => as_real(inner),
        _ => None,
    }
}

/// The B-spline curve forms STEP writes, each a record of its own in a simple instance.
const CURVE_FORMS: [&str; 4] = [
    "B_SPLINE_CURVE_WITH_KNOTS",
    "UNIFORM_CURVE",
    "QUASI_UNIFORM_CURVE",
    "BEZIER_CURVE",
];

/// The B-spline surface forms, as [`CURVE_FORMS`].
const SURFACE_FORMS: [&str; 4] = [
    "B_SPLINE_SURFACE_WITH_KNOTS",
    "UNIFORM_SURFACE",
    "QUASI_UNIFORM_SURFACE",
    "BEZIER_SURFACE",
];
