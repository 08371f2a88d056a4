//! A B-rep of a triangle mesh's facets: each triangle of a closed, manifold mesh (read by
//! [`meshfile`], welded, told apart into bodies) a planar face bounded by three line edges,
//! each edge shared by the two triangles across it. The B-rep is exact for the mesh, so every
//! later stage (mass properties, sections, the head's check) reads it as it reads a STEP
//! solid; its [`Origin::Mesh`] tells the feature stage to plan each body whole.

use crate::curve::Curve;
use crate::error::ReadError;
use crate::math::{Frame, P3, V3};
use crate::step::StepPart;
use crate::surface::Surface;
use crate::topology::{
    Brep, Coedge, CoedgeId, CurveId, Edge, EdgeId, Face, FaceId, LengthUnit, Loop, LoopId, Origin,
    Shell, ShellId, Solid, SurfaceId, Vertex, VertexId,
};
use meshfile::{Closed, Format};
use std::collections::HashMap;
use std::path::Path;

/// A mesh file read and closed: its objects welded and in bodies, turned into a B-rep
/// ([`FacetedFile::brep`]) as often as placements need.
#[derive(Debug, Clone)]
pub struct FacetedFile {
    /// The file's format.
    pub format: Format,
    /// The length unit it was written in.
    pub unit: LengthUnit,
    /// Its objects, closed.
    pub objects: Vec<Closed>,
    /// What was mended (gaps welded), one line each.
    pub warnings: Vec<String>,
}

impl FacetedFile {
    /// Reads a mesh file (`.stl`, `.3mf`, `.obj`) and closes each object
    /// ([`meshfile::close`]): gaps within `tolerance` mm welded with a warning, an object
    /// still open or non-manifold refused with its edge counts.
    pub fn read(path: impl AsRef<Path>, tolerance: f64) -> Result<FacetedFile, ReadError> {
        FacetedFile::from_mesh(meshfile::read(path)?, tolerance)
    }

    /// [`FacetedFile::read`] for a mesh file already read.
    pub fn from_mesh(file: meshfile::MeshFile, tolerance: f64) -> Result<FacetedFile, ReadError> {
        let several = file.objects.len() > 1;
        let mut objects = vec![];
        let mut warnings = vec![];
        for o in &file.objects {
            if o.triangles.is_empty() {
                continue;
            }
            let named = if several || !o.name.is_empty() {
                o.name.clone()
            } else {
                String::new()
            };
            let closed = meshfile::close(o, tolerance).map_err(|why| ReadError::NotClosed {
                object: named.clone(),
                why,
            })?;
            if let Some(c) = closed.mended {
                warnings.push(format!(
                    "{}{} open edge(s) and {} non-manifold edge(s) closed by welding {} vertice(s) within {tolerance} mm (the process tolerance)",
                    if named.is_empty() { String::new() } else { format!("object `{named}`: ") },
                    c.open,
                    c.non_manifold,
                    closed.moved
                ));
            }
            objects.push(closed);
        }
        Ok(FacetedFile {
            format: file.format,
            unit: LengthUnit {
                name: file.unit.0,
                mm_per_unit: file.unit.1,
            },
            objects,
            warnings,
        })
    }

    /// The B-rep of every body of every object, turned by `rotation` (rows first: plate =
    /// rotation × file) when given: one solid per body, its faces numbered as the file's
    /// triangles are (1 first, across the objects).
    pub fn brep(&self, rotation: Option<[[f64; 3]; 3]>) -> Brep {
        let mut b = Brep {
            origin: Origin::Mesh,
            units: vec![self.unit.clone()],
            warnings: self.warnings.clone(),
            ..Brep::default()
        };
        let turn = |p: &[f64; 3]| match rotation {
            Some(r) => {
                P3::from([0, 1, 2].map(|k| r[k][0] * p[0] + r[k][1] * p[1] + r[k][2] * p[2]))
            }
            None => P3::new(p[0], p[1], p[2]),
        };
        for o in &self.objects {
            let positions: Vec<P3> = o.object.positions.iter().map(turn).collect();
            let mut build = Builder {
                b: &mut b,
                positions: &positions,
                vertices: vec![None; positions.len()],
                edges: HashMap::new(),
            };
            for body in &o.bodies {
                let id = build.b.solids.len() as u64 + 1;
                let mut shells = vec![build.shell(&body.outer, false)];
                shells.extend(body.voids.iter().map(|v| build.shell(v, true)));
                build.b.solids.push(Solid {
                    step_id: id,
                    name: o.object.name.clone(),
                    shells,
                });
            }
        }
        b
    }

    /// The part: [`FacetedFile::brep`] with no schema.
    pub fn part_turned(&self, rotation: Option<[[f64; 3]; 3]>) -> StepPart {
        StepPart {
            brep: self.brep(rotation),
            schemas: vec![],
        }
    }
}

/// Adds one object's shells to a B-rep, sharing its vertices and edges.
struct Builder<'a> {
    b: &'a mut Brep,
    positions: &'a [P3],
    vertices: Vec<Option<VertexId>>,
    edges: HashMap<(u32, u32), EdgeId>,
}

impl Builder<'_> {
    fn vertex(&mut self, i: u32) -> VertexId {
        if let Some(v) = self.vertices[i as usize] {
            return v;
        }
        let v = VertexId(self.b.vertices.len() as u32);
        self.b.vertices.push(Vertex {
            step_id: v.0 as u64 + 1,
            point: self.positions[i as usize],
        });
        self.vertices[i as usize] = Some(v);
        v
    }

    /// The edge between mesh vertices `a` and `b` (made once, from the lower index to the
    /// higher), and whether `a → b` runs along it.
    fn edge(&mut self, a: u32, b: u32) -> (EdgeId, bool) {
        let key = (a.min(b), a.max(b));
        if let Some(&e) = self.edges.get(&key) {
            return (e, a == key.0);
        }
        let (start, end) = (self.vertex(key.0), self.vertex(key.1));
        let (p, q) = (
            self.positions[key.0 as usize],
            self.positions[key.1 as usize],
        );
        let d = q - p;
        let len = d.norm();
        let curve = CurveId(self.b.curves.len() as u32);
        self.b.curves.push(Curve::Line {
            origin: p,
            dir: if len > 0.0 { d / len } else { V3::x() },
        });
        let e = EdgeId(self.b.edges.len() as u32);
        self.b.edges.push(Edge {
            step_id: e.0 as u64 + 1,
            curve,
            start,
            end,
            t_start: 0.0,
            t_end: len,
            coedges: vec![],
        });
        self.edges.insert(key, e);
        (e, a == key.0)
    }

    /// A shell of `triangles`, each a planar face.
    fn shell(&mut self, triangles: &[[u32; 3]], void: bool) -> ShellId {
        let shell = ShellId(self.b.shells.len() as u32);
        let mut faces = Vec::with_capacity(triangles.len());
        for t in triangles {
            let [p, q, r] = t.map(|i| self.positions[i as usize]);
            let n = (q - p).cross(&(r - p));
            let frame = Frame::from_axes(p, Some(n), Some(q - p)).unwrap_or(Frame::world(p));
            let surface = SurfaceId(self.b.surfaces.len() as u32);
            self.b.surfaces.push(Surface::Plane { frame });
            let face = FaceId(self.b.faces.len() as u32);
            let lp = LoopId(self.b.loops.len() as u32);
            let mut coedges = vec![];
            for k in 0..3 {
                let (e, forward) = self.edge(t[k], t[(k + 1) % 3]);
                let c = CoedgeId(self.b.coedges.len() as u32);
                self.b.coedges.push(Coedge {
                    step_id: c.0 as u64 + 1,
                    edge: e,
                    forward,
                    lp,
                });
                self.b.edges[e.idx()].coedges.push(c);
                coedges.push(c);
            }
            self.b.loops.push(Loop {
                step_id: lp.0 as u64 + 1,
                face,
                outer: true,
                coedges,
                vertex: None,
            });
            self.b.faces.push(Face {
                step_id: face.0 as u64 + 1,
                surface,
                same_sense: true,
                loops: vec![lp],
                shell,
            });
            faces.push(face);
        }
        self.b.shells.push(Shell {
            step_id: shell.0 as u64 + 1,
            faces,
            void,
        });
        shell
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const TET: &[u8] =
        b"v 0 0 0\nv 10 0 0\nv 0 10 0\nv 0 0 10\nf 1 3 2\nf 1 2 4\nf 2 3 4\nf 3 1 4\n";

    #[test]
    fn a_tetrahedron_is_a_solid_of_four_faces_and_six_edges_of_its_volume() {
        let file = meshfile::read_bytes(TET, Format::Obj).unwrap();
        let f = FacetedFile::from_mesh(file, 0.05).unwrap();
        let part = f.part_turned(None);
        let b = &part.brep;
        assert_eq!(
            (
                b.solids.len(),
                b.faces.len(),
                b.edges.len(),
                b.vertices.len()
            ),
            (1, 4, 6, 4)
        );
        assert!(b.edges.iter().all(|e| e.coedges.len() == 2));
        let faces = b.solid_faces(crate::topology::SolidId(0));
        let mesh = crate::mesh::mesh_faces(b, &faces, &Default::default()).unwrap();
        let props = crate::mass::mass_properties(b, &mesh);
        assert!(
            (props.volume - 1000.0 / 6.0).abs() < 1e-6,
            "{}",
            props.volume
        );
        // Turned upside down, it still encloses the same volume.
        let down = f.part_turned(Some(crate::turn_down([0.0, 0.0, 1.0])));
        let mesh = crate::mesh::mesh_faces(&down.brep, &faces, &Default::default()).unwrap();
        let props = crate::mass::mass_properties(&down.brep, &mesh);
        assert!((props.volume - 1000.0 / 6.0).abs() < 1e-6);
    }

    #[test]
    fn a_face_less_is_refused_with_its_open_edges() {
        let open = &TET[..TET.len() - 8];
        let file = meshfile::read_bytes(open, Format::Obj).unwrap();
        let e = FacetedFile::from_mesh(file, 0.05).unwrap_err().to_string();
        assert!(e.contains("3 open edge(s)"), "{e}");
    }
}
