//! Is a feature a valid solid? The check every feature passes before `extract` returns it, and
//! the one the tests call: edges used twice in opposite directions, loops connected and closed,
//! every face meshable, the mesh watertight, the volume positive (faces outward).

use brep::mesh::{mesh_faces, MeshOptions};
use brep::topology::{Brep, EdgeId, FaceId};
use std::collections::HashMap;

/// One reason a set of faces is not a valid solid. Each names the STEP `#id` of what it is about
/// where the entity came from the file (faces and edges made by the extraction have `#0`).
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum SolidProblem {
    /// An edge not used by exactly one coedge in each direction.
    #[error(
        "edge #{edge} is used {forward} time(s) forward and {backward} backward (want 1 and 1)"
    )]
    EdgeUse {
        /// STEP `#id` of the edge.
        edge: u64,
        /// Uses along the edge.
        forward: u32,
        /// Uses against it.
        backward: u32,
    },
    /// A loop whose coedges do not join head to tail.
    #[error("a loop of face #{face} is not connected after edge #{edge}")]
    LoopOpen {
        /// STEP `#id` of the face.
        face: u64,
        /// The edge after which the loop breaks.
        edge: u64,
    },
    /// A face with no boundary, or one that bounds no region of its surface.
    #[error("face #{face} cannot be meshed: {cause}")]
    Face {
        /// STEP `#id` of the face.
        face: u64,
        /// Why.
        cause: String,
    },
    /// The mesh has open or non-manifold edges.
    #[error("the mesh is not watertight ({open} open, {bad} non-manifold edges)")]
    NotWatertight {
        /// Mesh edges used by one triangle.
        open: usize,
        /// Mesh edges used otherwise than once each way.
        bad: usize,
    },
    /// The enclosed volume is not positive: faces inward, or nothing enclosed.
    #[error("its volume is {volume:.6} mm^3 (faces inward or nothing enclosed)")]
    Volume {
        /// Signed enclosed volume, mm³.
        volume: f64,
    },
}

/// The outcome of [`check_solid`].
#[derive(Debug, Clone, PartialEq)]
pub struct SolidCheck {
    /// Everything wrong; empty for a valid solid.
    pub problems: Vec<SolidProblem>,
    /// Signed enclosed volume, mm³ (0 when the faces could not be meshed).
    pub volume: f64,
}

impl SolidCheck {
    /// No problem found.
    pub fn is_valid(&self) -> bool {
        self.problems.is_empty()
    }
}

/// How many problems a warning lists before it says `...` ([`listed`]).
pub const LISTED_PROBLEMS: usize = 4;

/// `problems` as a warning lists them: the first [`LISTED_PROBLEMS`] joined by `; `, then
/// `; ...` when there are more.
pub fn listed(problems: &[SolidProblem]) -> String {
    let list: Vec<String> = problems
        .iter()
        .take(LISTED_PROBLEMS)
        .map(|p| p.to_string())
        .collect();
    let more = if problems.len() > LISTED_PROBLEMS {
        "; ..."
    } else {
        ""
    };
    format!("{}{more}", list.join("; "))
}

/// Topology alone: edge uses and loop connection over `faces` (outer and void shells together).
///
/// Some writers (OpenCASCADE for certain reversed faces) write a face's loops against its
/// `same_sense`; such a face disagrees with every neighbour on every edge it does not use twice,
/// and is read as reversed here as the reader and mesher read it (`brep::validate`).
pub fn check_topology(b: &Brep, faces: &[FaceId]) -> Vec<SolidProblem> {
    let mut problems = vec![];
    // Per face, its uses: (edge, forward).
    let mut face_uses: Vec<Vec<(EdgeId, bool)>> = vec![];
    for &f in faces {
        let face = b.face(f);
        if face.loops.is_empty() {
            problems.push(SolidProblem::Face {
                face: face.step_id,
                cause: "it has no boundary".into(),
            });
        }
        let mut mine = vec![];
        for &l in &face.loops {
            let cs = &b.loops[l.idx()].coedges;
            for (k, c) in cs.iter().enumerate() {
                let ce = &b.coedges[c.idx()];
                mine.push((ce.edge, ce.forward));
                let next = &b.coedges[cs[(k + 1) % cs.len()].idx()];
                let (e, n) = (b.edge(ce.edge), b.edge(next.edge));
                let end = if ce.forward { e.end } else { e.start };
                let start = if next.forward { n.start } else { n.end };
                if end != start {
                    problems.push(SolidProblem::LoopOpen {
                        face: face.step_id,
                        edge: e.step_id,
                    });
                }
            }
        }
        face_uses.push(mine);
    }
    let count = |flip: &[bool]| {
        let mut uses: HashMap<EdgeId, (u32, u32)> = HashMap::new();
        for (k, mine) in face_uses.iter().enumerate() {
            for &(e, fwd) in mine {
                let u = uses.entry(e).or_default();
                if fwd != flip[k] {
                    u.0 += 1;
                } else {
                    u.1 += 1;
                }
            }
        }
        uses
    };
    // One face at a time, in order (a healing face comes after the faces it closes), so that a
    // face agreeing with a reversed neighbour is not flipped with it.
    let mut flip = vec![false; faces.len()];
    let mut uses = count(&flip);
    for _ in 0..faces.len() {
        let reversed = face_uses.iter().enumerate().position(|(k, mine)| {
            let own: Vec<EdgeId> = mine
                .iter()
                .map(|u| u.0)
                .filter(|e| mine.iter().filter(|u| u.0 == *e).count() == 1)
                .collect();
            !flip[k]
                && !own.is_empty()
                && own.iter().all(|e| {
                    let (f, w) = uses[e];
                    f + w == 2 && (f == 2 || w == 2)
                })
        });
        let Some(k) = reversed else { break };
        flip[k] = true;
        uses = count(&flip);
    }
    let mut bad: Vec<(u64, u32, u32)> = uses
        .into_iter()
        .filter(|(_, (f, k))| (*f, *k) != (1, 1))
        .map(|(e, (f, k))| (b.edge(e).step_id, f, k))
        .collect();
    bad.sort_unstable();
    problems.extend(
        bad.into_iter()
            .map(|(edge, forward, backward)| SolidProblem::EdgeUse {
                edge,
                forward,
                backward,
            }),
    );
    problems
}

/// Checks that `faces` (an outer shell) with `voids` (void shells) bound a valid solid: the
/// topology ([`check_topology`]), every face meshed within `opts`, the mesh watertight and the
/// enclosed volume positive.
pub fn check_solid(
    b: &Brep,
    faces: &[FaceId],
    voids: &[Vec<FaceId>],
    opts: &MeshOptions,
) -> SolidCheck {
    let mut all = faces.to_vec();
    for v in voids {
        all.extend(v.iter().copied());
    }
    let mut problems = check_topology(b, &all);
    let mut volume = 0.0;
    match mesh_faces(b, &all, opts) {
        Err(brep::mesh::MeshError::Face { id, msg }) => problems.push(SolidProblem::Face {
            face: id,
            cause: msg,
        }),
        Ok(mesh) => {
            let (open, bad) = mesh.open_edges();
            if open + bad > 0 {
                problems.push(SolidProblem::NotWatertight { open, bad });
            }
            volume = brep::mass::mass_properties(b, &mesh).volume;
            if volume <= 0.0 {
                problems.push(SolidProblem::Volume { volume });
            }
        }
    }
    SolidCheck { problems, volume }
}
