//! Topological checks and counts: edge use, loop closure, Euler characteristic and genus.

use crate::topology::{Brep, EdgeId, ShellId};
use std::collections::HashMap;

/// What the topology of one shell looks like.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct ShellReport {
    /// Vertices, edges, faces and loops used by the shell.
    pub vertices: usize,
    /// Distinct edges.
    pub edges: usize,
    /// Faces.
    pub faces: usize,
    /// Loops (edge and vertex loops).
    pub loops: usize,
    /// Every edge used exactly twice, in opposite directions.
    pub closed: bool,
    /// `V − E + F − (L − F)`: 2 − 2·genus for a closed orientable shell.
    pub euler: i64,
    /// Genus from Euler–Poincaré (through-holes), when closed.
    pub genus: Option<i64>,
    /// Problems found, each naming a STEP `#id`.
    pub findings: Vec<String>,
}

/// Checks one shell.
pub fn check_shell(brep: &Brep, shell: ShellId) -> ShellReport {
    let sh = &brep.shells[shell.idx()];
    let mut uses: HashMap<EdgeId, (u32, u32)> = HashMap::new();
    let mut loops = 0;
    let mut findings = vec![];
    for &f in &sh.faces {
        let face = brep.face(f);
        if face.loops.is_empty() {
            findings.push(format!("face #{} has no boundary", face.step_id));
        }
        for &l in &face.loops {
            loops += 1;
            let lp = &brep.loops[l.idx()];
            let n = lp.coedges.len();
            for k in 0..n {
                let c = &brep.coedges[lp.coedges[k].idx()];
                let e = uses.entry(c.edge).or_default();
                if c.forward {
                    e.0 += 1
                } else {
                    e.1 += 1
                }
                let next = &brep.coedges[lp.coedges[(k + 1) % n].idx()];
                let ec = brep.edge(c.edge);
                let en = brep.edge(next.edge);
                let end = if c.forward { ec.end } else { ec.start };
                let start = if next.forward { en.start } else { en.end };
                if end != start {
                    findings.push(format!(
                        "loop #{} is not connected after edge #{}",
                        lp.step_id, ec.step_id
                    ));
                }
            }
        }
    }
    // Some writers (OpenCASCADE for certain reversed faces) write a face's loops against its
    // `same_sense`. Such a face disagrees with every neighbour; read it as reversed.
    let mismatched = |uses: &HashMap<EdgeId, (u32, u32)>, e: EdgeId| {
        let (f, b) = uses[&e];
        f + b == 2 && (f == 2 || b == 2)
    };
    let mut reversed_faces = vec![];
    for &f in &sh.faces {
        let face = brep.face(f);
        let mut own: Vec<EdgeId> = vec![];
        let mut seams: Vec<EdgeId> = vec![];
        for &l in &face.loops {
            for &c in &brep.loops[l.idx()].coedges {
                let e = brep.coedges[c.idx()].edge;
                if own.contains(&e) {
                    seams.push(e);
                } else {
                    own.push(e);
                }
            }
        }
        own.retain(|e| !seams.contains(e));
        if !own.is_empty() && own.iter().all(|&e| mismatched(&uses, e)) {
            reversed_faces.push((f, own));
        }
    }
    for (f, own) in &reversed_faces {
        for e in own {
            if let Some(u) = uses.get_mut(e) {
                *u = (1, 1);
            }
        }
        findings.push(format!(
            "face #{}: loops are written against the face's orientation; read as reversed",
            brep.face(*f).step_id
        ));
    }
    let mut closed = !sh.faces.is_empty();
    let mut edge_ids: Vec<(u64, String)> = vec![];
    for (e, (f, b)) in &uses {
        if *f != 1 || *b != 1 {
            closed = false;
            let id = brep.edge(*e).step_id;
            let what = match f + b {
                1 => "is used by one face only (open edge)".to_string(),
                2 => "is used twice in the same direction (inconsistent face orientation)"
                    .to_string(),
                n => format!("is used {n} times (non-manifold)"),
            };
            edge_ids.push((id, what));
        }
    }
    edge_ids.sort();
    let total = edge_ids.len();
    for (id, what) in edge_ids.into_iter().take(10) {
        findings.push(format!("edge #{id} {what}"));
    }
    if total > 10 {
        findings.push(format!(
            "... and {} more edge problems in shell #{}",
            total - 10,
            sh.step_id
        ));
    }
    let vertices = brep.vertices_of(&sh.faces).len();
    let edges = uses.len();
    let faces = sh.faces.len();
    let euler = vertices as i64 - edges as i64 + faces as i64 - (loops as i64 - faces as i64);
    let genus = (closed && euler % 2 == 0).then(|| (2 - euler) / 2);
    ShellReport {
        vertices,
        edges,
        faces,
        loops,
        closed,
        euler,
        genus,
        findings,
    }
}
