//! Topology entities: solids, shells, faces, bounds, edges and vertices.

use super::translator::{Translator, R};
use crate::curve::Curve;
use crate::math::V3;
use crate::step::error::ReadError;
use crate::tolerance::{LENGTH_FLOOR, NONZERO, PERIOD_FRACTION, POINT_COINCIDENCE};
use crate::topology::*;
use std::collections::HashMap;

#[derive(Clone, Copy, Debug)]
pub(super) enum BodyKind {
    Manifold,
    WithVoids,
    SurfaceModel,
}

impl<'a> Translator<'a> {
    // ---------- bodies ----------

    pub(super) fn find_bodies(&self) -> R<Vec<(u64, BodyKind)>> {
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

    pub(super) fn why_no_solid(&self) -> String {
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

    pub(super) fn read_body(&mut self, id: u64, kind: BodyKind) -> R<()> {
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
                let outer_box = crate::bbox::faces_rough_bbox(
                    &self.brep,
                    &self.brep.shells[shells[0].idx()].faces,
                );
                let slack = POINT_COINCIDENCE * outer_box.diagonal().max(LENGTH_FLOOR);
                let mut own = vec![];
                let first = shells[0];
                shells.retain(|&sh| {
                    if sh == first {
                        return true;
                    }
                    let b = crate::bbox::faces_rough_bbox(
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

    pub(super) fn shell_is_closed(&self, shell: ShellId) -> bool {
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

    pub(super) fn read_shell(
        &mut self,
        id: u64,
        from: u64,
        void: bool,
        _solid: SolidId,
    ) -> R<ShellId> {
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

    pub(super) fn read_face(
        &mut self,
        id: u64,
        from: u64,
        flip: bool,
        shell: ShellId,
    ) -> R<FaceId> {
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
        // Outer bounds first, each kind in file order (a band may have two outer bounds: read
        // back from our own writing, their order must not swap).
        let mut loops = vec![];
        let mut outers = 0;
        for b in bounds {
            let lp = self.read_bound(b, id, face)?;
            if self.brep.loops[lp.idx()].outer {
                loops.insert(outers, lp);
                outers += 1;
            } else {
                loops.push(lp);
            }
        }
        self.brep.faces[face.idx()].loops = loops;
        Ok(face)
    }

    pub(super) fn read_bound(&mut self, id: u64, from: u64, face: FaceId) -> R<LoopId> {
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

    pub(super) fn vertex(&mut self, id: u64, from: u64) -> R<VertexId> {
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

    pub(super) fn edge(&mut self, id: u64, from: u64) -> R<EdgeId> {
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
                let dir = (pe - ps).try_normalize(NONZERO).unwrap_or_else(V3::x);
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
            let eps = PERIOD_FRACTION * per;
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
        let limit = 1.0 + POINT_COINCIDENCE * ps.coords.norm().max(pe.coords.norm());
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
}
