//! Topology entities: bodies, shells, faces, loops, edges and vertices.

use super::text::*;
use super::writer::{Body, Writer};
use crate::topology::{EdgeId, FaceId, VertexId};

impl<'a> Writer<'a> {
    // ---------- topology ----------

    pub(super) fn body(&mut self, b: &Body) -> Option<u64> {
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
    pub(super) fn shell(&mut self, faces: &[FaceId], flip: bool) -> u64 {
        let ids: Vec<u64> = faces.iter().map(|&f| self.face(f, flip)).collect();
        self.add(format!("CLOSED_SHELL('',{})", ref_list(&ids)))
    }

    pub(super) fn face(&mut self, f: FaceId, flip: bool) -> u64 {
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

    pub(super) fn edge(&mut self, e: EdgeId) -> u64 {
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

    pub(super) fn vertex(&mut self, v: VertexId) -> u64 {
        if let Some(&id) = self.vertices.get(&v) {
            return id;
        }
        let p = self.point(&self.brep.vertices[v.idx()].point);
        let id = self.add(format!("VERTEX_POINT('',#{p})"));
        self.vertices.insert(v, id);
        id
    }
}
