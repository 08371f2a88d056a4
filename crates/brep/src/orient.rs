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
pub fn orient_shell(brep: &mut Brep, shell: ShellId) -> Vec<FaceId> {
    let faces = brep.shells[shell.idx()].faces.clone();
    if faces.len() < 2 {
        return vec![];
    }
    let bbox = crate::bbox::faces_rough_bbox(brep, &faces);
    // Coarse, but not so coarse that a face's triangles fold (then they run its edges both ways):
    // only which way the triangles run along the edges is asked of this mesh.
    let opts = MeshOptions::with_tolerance((bbox.diagonal() * 1e-2).max(1e-4));
    let Ok(mesh) = mesh_faces(brep, &faces, &opts) else {
        return vec![];
    };
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
    for us in uses.values() {
        for (i, &(f, up)) in us.iter().enumerate() {
            for &(g, up2) in &us[i + 1..] {
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
        return vec![];
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
                    Some(have) if have != want => return vec![], // no consistent split
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
    let outward = v_false - v_true > 0.0;
    let turn = outward != brep.shells[shell.idx()].void;
    let turned: Vec<FaceId> = mesh
        .faces
        .iter()
        .zip(&colour)
        .filter(|(_, k)| **k == Some(turn))
        .map(|(ft, _)| ft.face)
        .collect();
    for f in &turned {
        brep.faces[f.idx()].same_sense ^= true;
    }
    turned
}
