//! Faces whose normal runs against their neighbours': a closed shell whose faces, meshed by
//! their normals, cross a shared edge the same way (ASCON KOMPAS writes mirrored sheet-metal
//! legs with the planes' `same_sense` against their loops; OpenCASCADE's reader heals the same
//! with ShapeFix). The faces fall in two sets, each consistent within itself; the set whose
//! turning leaves the shell facing outward (a void: inward) is turned round.

use crate::mesh::{mesh_faces, MeshOptions};
use crate::topology::{Brep, FaceId, ShellId};
use std::collections::HashMap;

/// Turns round (toggles `same_sense`) the faces of `shell` that run against their neighbours,
/// when the shell's faces make two consistently oriented sets; returns the faces turned (none
/// when the shell is consistent, cannot be meshed, or no such split exists).
///
/// The sets are found on a coarse mesh (chords within 1 % of the shell's size) and confirmed on
/// one ten times finer: where a coarse face's triangles fold (a sharply curved face of a
/// revolved or offset wall), the coarse vote can find a consistent shell inconsistent, and
/// turning its faces would break it. A face is turned only where both meshes find the same
/// faces against the rest and the turned shell encloses volume (a void: the other way).
pub fn orient_shell(brep: &mut Brep, shell: ShellId) -> Vec<FaceId> {
    orient_shell_at(brep, shell, [COARSE_SHARE, FINE_SHARE])
}

/// The coarse mesh's chord tolerance, as a share of the shell's bounding-box diagonal.
const COARSE_SHARE: f64 = 1e-2;
/// The confirming mesh's ([`orient_shell`]).
const FINE_SHARE: f64 = 1e-3;

/// [`orient_shell`] with the coarse and the confirming meshes' tolerances (shares of the
/// shell's size), for tests.
pub fn orient_shell_at(brep: &mut Brep, shell: ShellId, shares: [f64; 2]) -> Vec<FaceId> {
    let faces = brep.shells[shell.idx()].faces.clone();
    if faces.len() < 2 {
        return vec![];
    }
    let void = brep.shells[shell.idx()].void;
    let Some(coarse) = against_set(brep, &faces, shares[0], void) else {
        return vec![];
    };
    if coarse.is_empty() {
        return vec![];
    }
    match against_set(brep, &faces, shares[1], void) {
        Some(fine) if fine == coarse => {
            for f in &coarse {
                brep.faces[f.idx()].same_sense ^= true;
            }
            coarse
        }
        _ => vec![],
    }
}

/// The faces of `faces` (a closed shell's) to turn for the shell to be consistent and face
/// outward (`void`: inward), judged on a mesh whose chords are within `share` of the shell's
/// size: sorted, empty when it is consistent; `None` when it cannot be meshed or its faces make
/// no two consistent sets.
fn against_set(brep: &Brep, faces: &[FaceId], share: f64, void: bool) -> Option<Vec<FaceId>> {
    let bbox = crate::bbox::faces_rough_bbox(brep, faces);
    // Only which way the triangles run along the edges is asked of this mesh: coarse is
    // enough where a face's triangles do not fold (then they run its edges both ways).
    let opts = MeshOptions::with_tolerance((bbox.diagonal() * share).max(1e-4));
    let mesh = mesh_faces(brep, faces, &opts).ok()?;
    // Each mesh edge (low vertex first) with the faces (local index) that run it, and which way.
    let mut uses: HashMap<(u32, u32), Vec<(usize, bool)>> = HashMap::new();
    for (k, ft) in mesh.faces.iter().enumerate() {
        for t in &ft.triangles {
            let g = t.map(|i| ft.vertex[i as usize]);
            if g[0] == g[1] || g[1] == g[2] || g[0] == g[2] {
                continue;
            }
            for j in 0..3 {
                let (a, b) = (g[j], g[(j + 1) % 3]);
                uses.entry((a.min(b), a.max(b)))
                    .or_default()
                    .push((k, a < b));
            }
        }
    }
    // Votes per pair of faces meeting at an edge: (same way, opposite ways).
    let mut votes: HashMap<(usize, usize), (u32, u32)> = HashMap::new();
    // Only an edge two triangles share votes: of three or more on one edge (a non-manifold
    // edge, where two faces' samplings of a thread's flank or a dense B-spline's trim do not
    // match), two run it the same way whatever the faces' orientation, which would read as a
    // face against its neighbour.
    for us in uses.values() {
        if let [(f, up), (g, up2)] = us[..] {
            if f != g {
                let v = votes.entry((f.min(g), f.max(g))).or_default();
                if up == up2 {
                    v.0 += 1;
                } else {
                    v.1 += 1;
                }
            }
        }
    }
    let n = mesh.faces.len();
    let mut next: Vec<Vec<(usize, bool)>> = vec![vec![]; n];
    let mut any_against = false;
    for (&(f, g), &(same, opposite)) in &votes {
        // A pair whose triangles run their edges both ways (a fold) says nothing.
        if same > 0 && opposite > 0 {
            continue;
        }
        let against = same > 0;
        any_against |= against;
        next[f].push((g, against));
        next[g].push((f, against));
    }
    if !any_against {
        return Some(vec![]);
    }
    // Two-colour the faces: across an edge run the same way, the colour changes.
    let mut colour: Vec<Option<bool>> = vec![None; n];
    for start in 0..n {
        if colour[start].is_some() {
            continue;
        }
        colour[start] = Some(false);
        let mut stack = vec![start];
        while let Some(f) = stack.pop() {
            let c = colour[f].unwrap_or(false);
            for &(g, against) in &next[f] {
                let want = c ^ against;
                match colour[g] {
                    None => {
                        colour[g] = Some(want);
                        stack.push(g);
                    }
                    Some(have) if have != want => return None, // no consistent split
                    Some(_) => {}
                }
            }
        }
    }
    // Each set's share of the signed volume: turn the set that leaves the shell enclosing
    // volume (a void shell: the other way).
    let c = bbox.min + 0.5 * (bbox.max - bbox.min);
    let share = |which: bool| -> f64 {
        mesh.faces
            .iter()
            .zip(&colour)
            .filter(|(_, k)| **k == Some(which))
            .flat_map(|(ft, _)| {
                ft.triangles.iter().map(|t| {
                    let p = t.map(|i| mesh.positions[ft.vertex[i as usize] as usize] - c);
                    p[0].dot(&p[1].cross(&p[2])) / 6.0
                })
            })
            .sum()
    };
    let (v_false, v_true) = (share(false), share(true));
    // Turning the `true` set gives v_false − v_true; the `false` set, the opposite.
    if v_false == v_true {
        return None;
    }
    let outward = v_false - v_true > 0.0;
    let turn = outward != void;
    let mut turned: Vec<FaceId> = mesh
        .faces
        .iter()
        .zip(&colour)
        .filter(|(_, k)| **k == Some(turn))
        .map(|(ft, _)| ft.face)
        .collect();
    turned.sort();
    Some(turned)
}
