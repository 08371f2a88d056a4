//! One solid of a file as a B-rep of its own.

use crate::topology::{
    Brep, CoedgeId, CurveId, EdgeId, FaceId, LoopId, ShellId, SolidId, SurfaceId, VertexId,
};

/// Old index → new index of the entities kept, in their old order.
struct Keep {
    new: Vec<Option<u32>>,
    old: Vec<usize>,
}

impl Keep {
    fn new(len: usize) -> Keep {
        Keep {
            new: vec![None; len],
            old: vec![],
        }
    }
    fn mark(&mut self, i: usize) {
        if self.new[i].is_none() {
            self.new[i] = Some(u32::MAX);
        }
    }
    /// Numbers the marked entities in their old order.
    fn number(&mut self) {
        for (i, n) in self.new.iter_mut().enumerate() {
            if n.is_some() {
                *n = Some(self.old.len() as u32);
                self.old.push(i);
            }
        }
    }
    fn get(&self, i: usize) -> u32 {
        self.new[i].unwrap_or(u32::MAX)
    }
}

impl Brep {
    /// Solid `id` alone: its shells, faces, loops, coedges, edges, vertices, surfaces and curves,
    /// in the order they have here (so that anything iterating over them visits them in the same
    /// order), renumbered; the solid is `SolidId(0)`. Units and warnings are kept. A solid's
    /// features are extracted from this instead of from a copy of the whole file.
    pub fn solid_alone(&self, id: SolidId) -> Brep {
        let solid = &self.solids[id.idx()];
        let mut shells = Keep::new(self.shells.len());
        let mut faces = Keep::new(self.faces.len());
        let mut loops = Keep::new(self.loops.len());
        let mut coedges = Keep::new(self.coedges.len());
        let mut edges = Keep::new(self.edges.len());
        let mut vertices = Keep::new(self.vertices.len());
        let mut surfaces = Keep::new(self.surfaces.len());
        let mut curves = Keep::new(self.curves.len());
        for s in &solid.shells {
            shells.mark(s.idx());
            for f in &self.shells[s.idx()].faces {
                faces.mark(f.idx());
                let face = &self.faces[f.idx()];
                surfaces.mark(face.surface.idx());
                for l in &face.loops {
                    loops.mark(l.idx());
                    let lp = &self.loops[l.idx()];
                    if let Some(v) = lp.vertex {
                        vertices.mark(v.idx());
                    }
                    for c in &lp.coedges {
                        coedges.mark(c.idx());
                        let e = self.coedges[c.idx()].edge;
                        edges.mark(e.idx());
                        let edge = &self.edges[e.idx()];
                        curves.mark(edge.curve.idx());
                        vertices.mark(edge.start.idx());
                        vertices.mark(edge.end.idx());
                    }
                }
            }
        }
        for k in [
            &mut shells,
            &mut faces,
            &mut loops,
            &mut coedges,
            &mut edges,
            &mut vertices,
            &mut surfaces,
            &mut curves,
        ] {
            k.number();
        }
        let mut out = Brep {
            solids: vec![solid.clone()],
            origin: self.origin,
            units: self.units.clone(),
            warnings: self.warnings.clone(),
            ..Brep::default()
        };
        out.solids[0].shells = solid
            .shells
            .iter()
            .map(|s| ShellId(shells.get(s.idx())))
            .collect();
        out.shells = shells
            .old
            .iter()
            .map(|&i| {
                let mut s = self.shells[i].clone();
                s.faces = s.faces.iter().map(|f| FaceId(faces.get(f.idx()))).collect();
                s
            })
            .collect();
        out.faces = faces
            .old
            .iter()
            .map(|&i| {
                let mut f = self.faces[i].clone();
                f.surface = SurfaceId(surfaces.get(f.surface.idx()));
                f.loops = f.loops.iter().map(|l| LoopId(loops.get(l.idx()))).collect();
                f.shell = ShellId(shells.get(f.shell.idx()));
                f
            })
            .collect();
        out.loops = loops
            .old
            .iter()
            .map(|&i| {
                let mut l = self.loops[i].clone();
                l.face = FaceId(faces.get(l.face.idx()));
                l.coedges = l
                    .coedges
                    .iter()
                    .map(|c| CoedgeId(coedges.get(c.idx())))
                    .collect();
                l.vertex = l.vertex.map(|v| VertexId(vertices.get(v.idx())));
                l
            })
            .collect();
        out.coedges = coedges
            .old
            .iter()
            .map(|&i| {
                let mut c = self.coedges[i].clone();
                c.edge = EdgeId(edges.get(c.edge.idx()));
                c.lp = LoopId(loops.get(c.lp.idx()));
                c
            })
            .collect();
        out.edges = edges
            .old
            .iter()
            .map(|&i| {
                let mut e = self.edges[i].clone();
                e.curve = CurveId(curves.get(e.curve.idx()));
                e.start = VertexId(vertices.get(e.start.idx()));
                e.end = VertexId(vertices.get(e.end.idx()));
                // Coedges of other solids sharing the edge (non-manifold files) are dropped.
                e.coedges = e
                    .coedges
                    .iter()
                    .filter(|c| coedges.new[c.idx()].is_some())
                    .map(|c| CoedgeId(coedges.get(c.idx())))
                    .collect();
                e
            })
            .collect();
        out.vertices = vertices
            .old
            .iter()
            .map(|&i| self.vertices[i].clone())
            .collect();
        out.surfaces = surfaces
            .old
            .iter()
            .map(|&i| self.surfaces[i].clone())
            .collect();
        out.curves = curves.old.iter().map(|&i| self.curves[i].clone()).collect();
        out
    }
}
