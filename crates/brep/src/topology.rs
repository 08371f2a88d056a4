//! The boundary representation: index-based arenas of solids, shells, faces, loops, coedges,
//! edges and vertices, each carrying the STEP `#id` it was read from.

use crate::curve::Curve;
use crate::math::P3;
use crate::surface::Surface;

macro_rules! id_type {
    ($($(#[$m:meta])* $name:ident),*) => {$(
        $(#[$m])*
        #[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
        pub struct $name(pub u32);
        impl $name {
            /// The index into its arena.
            pub fn idx(self) -> usize { self.0 as usize }
        }
    )*};
}
id_type!(
    /// Index of a [`Solid`].
    SolidId,
    /// Index of a [`Shell`].
    ShellId,
    /// Index of a [`Face`].
    FaceId,
    /// Index of a [`Loop`].
    LoopId,
    /// Index of a [`Coedge`].
    CoedgeId,
    /// Index of an [`Edge`].
    EdgeId,
    /// Index of a [`Vertex`].
    VertexId,
    /// Index of a surface in [`Brep::surfaces`].
    SurfaceId,
    /// Index of a curve in [`Brep::curves`].
    CurveId
);

/// A solid: one outer shell and any number of void shells.
#[derive(Debug, Clone)]
pub struct Solid {
    /// STEP `#id` of the `MANIFOLD_SOLID_BREP`, `BREP_WITH_VOIDS` or surface model.
    pub step_id: u64,
    /// The solid's name in the file (may be empty).
    pub name: String,
    /// `shells[0]` is the outer shell; the rest are voids.
    pub shells: Vec<ShellId>,
}

/// A closed shell.
#[derive(Debug, Clone)]
pub struct Shell {
    /// STEP `#id` of the `CLOSED_SHELL` / `OPEN_SHELL`.
    pub step_id: u64,
    /// Faces of the shell.
    pub faces: Vec<FaceId>,
    /// Whether this shell bounds a void inside its solid.
    pub void: bool,
}

/// A face: a trimmed piece of a surface.
#[derive(Debug, Clone)]
pub struct Face {
    /// STEP `#id` of the `ADVANCED_FACE` / `FACE_SURFACE`.
    pub step_id: u64,
    /// The underlying surface.
    pub surface: SurfaceId,
    /// Whether the face's outward normal is the surface's natural normal `S_u × S_v`.
    pub same_sense: bool,
    /// Boundary loops (outer first when the file says which is outer).
    pub loops: Vec<LoopId>,
    /// The shell holding the face.
    pub shell: ShellId,
}

/// A boundary loop of a face.
#[derive(Debug, Clone)]
pub struct Loop {
    /// STEP `#id` of the `FACE_BOUND` / `FACE_OUTER_BOUND`.
    pub step_id: u64,
    /// The face bounded.
    pub face: FaceId,
    /// Whether the file marks it as the outer bound.
    pub outer: bool,
    /// Coedges in traversal order (already reversed when the bound's orientation is `.F.`).
    pub coedges: Vec<CoedgeId>,
    /// For a `VERTEX_LOOP`: its single vertex (and no coedges).
    pub vertex: Option<VertexId>,
}

/// One use of an edge by a loop.
#[derive(Debug, Clone)]
pub struct Coedge {
    /// STEP `#id` of the `ORIENTED_EDGE`.
    pub step_id: u64,
    /// The edge used.
    pub edge: EdgeId,
    /// Whether the loop runs along the edge (start → end).
    pub forward: bool,
    /// The loop using it.
    pub lp: LoopId,
}

/// An edge: a piece of a curve between two vertices.
#[derive(Debug, Clone)]
pub struct Edge {
    /// STEP `#id` of the `EDGE_CURVE`.
    pub step_id: u64,
    /// The underlying curve.
    pub curve: CurveId,
    /// Start vertex.
    pub start: VertexId,
    /// End vertex (equal to `start` for a closed edge).
    pub end: VertexId,
    /// Curve parameter at the start vertex.
    pub t_start: f64,
    /// Curve parameter at the end vertex (`< t_start` when the edge runs against the curve).
    pub t_end: f64,
    /// Every coedge using this edge.
    pub coedges: Vec<CoedgeId>,
}

/// A vertex.
#[derive(Debug, Clone)]
pub struct Vertex {
    /// STEP `#id` of the `VERTEX_POINT`.
    pub step_id: u64,
    /// Position, mm.
    pub point: P3,
}

/// The length unit the file was written in.
#[derive(Debug, Clone, PartialEq)]
pub struct LengthUnit {
    /// A readable name: "mm", "m", "cm", "inch", "foot", ...
    pub name: String,
    /// Millimetres per file unit.
    pub mm_per_unit: f64,
}

/// What a B-rep was made from.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Origin {
    /// A STEP file's exact geometry.
    #[default]
    Step,
    /// A triangle mesh's facets (STL, 3MF, OBJ; [`crate::faceted`]): every face a planar
    /// triangle with line edges, planned whole as `mesh_two5d` features.
    Mesh,
}

/// A whole file read into one arena.
#[derive(Debug, Clone, Default)]
pub struct Brep {
    /// What it was made from.
    pub origin: Origin,
    /// Solids in file order.
    pub solids: Vec<Solid>,
    /// Shells.
    pub shells: Vec<Shell>,
    /// Faces.
    pub faces: Vec<Face>,
    /// Loops.
    pub loops: Vec<Loop>,
    /// Coedges.
    pub coedges: Vec<Coedge>,
    /// Edges.
    pub edges: Vec<Edge>,
    /// Vertices.
    pub vertices: Vec<Vertex>,
    /// Surfaces.
    pub surfaces: Vec<Surface>,
    /// Curves.
    pub curves: Vec<Curve>,
    /// Length units of the file (all geometry here is already in mm).
    pub units: Vec<LengthUnit>,
    /// Things worth telling the user that did not stop the reading.
    pub warnings: Vec<String>,
}

impl Brep {
    /// The face.
    pub fn face(&self, id: FaceId) -> &Face {
        &self.faces[id.idx()]
    }
    /// The surface of a face.
    pub fn face_surface(&self, id: FaceId) -> &Surface {
        &self.surfaces[self.faces[id.idx()].surface.idx()]
    }
    /// A planar face's unit normal pointing out of its solid (into whatever grows from it);
    /// `None` for a face that is not planar.
    pub fn plane_normal(&self, id: FaceId) -> Option<crate::math::V3> {
        match self.face_surface(id) {
            Surface::Plane { frame } => Some(if self.face(id).same_sense {
                frame.z
            } else {
                -frame.z
            }),
            _ => None,
        }
    }
    /// The point of a face's surface at `(u, v)`.
    pub fn face_point(&self, id: FaceId, u: f64, v: f64) -> P3 {
        self.face_surface(id).eval(u, v)
    }
    /// The first derivatives `(S_u, S_v)` of a face's surface at `(u, v)`.
    pub fn face_derivs(&self, id: FaceId, u: f64, v: f64) -> (crate::math::V3, crate::math::V3) {
        self.face_surface(id).derivs(u, v)
    }
    /// The unit normal pointing out of the solid at `(u, v)` of a face (its surface's natural
    /// normal, reversed where the face runs against its surface).
    pub fn face_normal(&self, id: FaceId, u: f64, v: f64) -> Option<crate::math::V3> {
        let n = self.face_surface(id).normal(u, v)?;
        Some(if self.faces[id.idx()].same_sense {
            n
        } else {
            -n
        })
    }
    /// The parameters of the point of a face's surface nearest to `p` (in any period; use
    /// [`crate::mesh::face_domain`] to ask whether it lies inside the face's trim).
    pub fn face_project(&self, id: FaceId, p: &P3) -> (f64, f64) {
        self.face_surface(id).project(p, None)
    }
    /// The edge.
    pub fn edge(&self, id: EdgeId) -> &Edge {
        &self.edges[id.idx()]
    }
    /// The curve of an edge.
    pub fn edge_curve(&self, id: EdgeId) -> &Curve {
        &self.curves[self.edges[id.idx()].curve.idx()]
    }
    /// All faces of a solid, outer shell first.
    pub fn solid_faces(&self, id: SolidId) -> Vec<FaceId> {
        self.solids[id.idx()]
            .shells
            .iter()
            .flat_map(|s| self.shells[s.idx()].faces.iter().copied())
            .collect()
    }
    /// Ids of all solids.
    pub fn solid_ids(&self) -> impl Iterator<Item = SolidId> {
        (0..self.solids.len() as u32).map(SolidId)
    }
    /// The face that a coedge's loop bounds.
    pub fn coedge_face(&self, id: CoedgeId) -> FaceId {
        self.loops[self.coedges[id.idx()].lp.idx()].face
    }
    /// The distinct edges used by a set of faces.
    pub fn edges_of(&self, faces: &[FaceId]) -> Vec<EdgeId> {
        let mut seen = vec![false; self.edges.len()];
        let mut out = vec![];
        for f in faces {
            for l in &self.faces[f.idx()].loops {
                for c in &self.loops[l.idx()].coedges {
                    let e = self.coedges[c.idx()].edge;
                    if !seen[e.idx()] {
                        seen[e.idx()] = true;
                        out.push(e);
                    }
                }
            }
        }
        out
    }
    /// The distinct vertices used by a set of faces.
    pub fn vertices_of(&self, faces: &[FaceId]) -> Vec<VertexId> {
        let mut seen = vec![false; self.vertices.len()];
        let mut out = vec![];
        let mut push = |v: VertexId, out: &mut Vec<VertexId>| {
            if !seen[v.idx()] {
                seen[v.idx()] = true;
                out.push(v);
            }
        };
        for e in self.edges_of(faces) {
            push(self.edges[e.idx()].start, &mut out);
            push(self.edges[e.idx()].end, &mut out);
        }
        for f in faces {
            for l in &self.faces[f.idx()].loops {
                if let Some(v) = self.loops[l.idx()].vertex {
                    push(v, &mut out);
                }
            }
        }
        out
    }
}
