//! A closed, manifold mesh told apart into bodies: its connected shells, each turned to run
//! one way throughout, nested by containment: a shell inside an odd number of others is a void
//! of the innermost (facing into it), any other an outer shell of its own body (facing out).

use crate::edges::edge_uses;
use crate::measure::{cross, dot, measure, sub};
use crate::tolerance::RAY_PARALLEL;
use crate::Object;

/// One body: an outer shell and its voids, triangles over the object's positions.
#[derive(Debug, Clone, PartialEq)]
pub struct Body {
    /// The outer shell, its triangles counter-clockwise seen from outside.
    pub outer: Vec<[u32; 3]>,
    /// The voids, each's triangles counter-clockwise seen from the void (out of the material).
    pub voids: Vec<Vec<[u32; 3]>>,
}

/// The bodies of a closed, manifold mesh `o` (every edge of two triangles), in the order their
/// outer shells first appear. Shells turned to run one way count as they were (a mesh with
/// some triangles the wrong way round is mended).
pub fn bodies(o: &Object) -> Vec<Body> {
    let shells = oriented_shells(&o.triangles);
    let measures: Vec<_> = shells.iter().map(|s| measure(&o.positions, s)).collect();
    let volumes: Vec<f64> = measures.iter().map(|m| m.volume).collect();
    // Which shells hold which: shell j inside shell i when a vertex of j is inside i (only
    // asked of a larger shell whose box holds j's).
    let n = shells.len();
    let boxed = |j: usize, i: usize| {
        (0..3).all(|k| {
            measures[i].min[k] <= measures[j].min[k] && measures[j].max[k] <= measures[i].max[k]
        })
    };
    let inside = |j: usize, i: usize| -> bool {
        if i == j || volumes[i].abs() <= volumes[j].abs() || !boxed(j, i) {
            return false;
        }
        let p = o.positions[shells[j][0][0] as usize];
        contains(&o.positions, &shells[i], p)
    };
    let holders: Vec<Vec<usize>> = (0..n)
        .map(|j| (0..n).filter(|&i| inside(j, i)).collect())
        .collect();
    let mut out: Vec<(usize, Body)> = vec![];
    let mut body_of = vec![usize::MAX; n];
    let facing = |s: &Vec<[u32; 3]>, v: f64, out: bool| -> Vec<[u32; 3]> {
        if (v > 0.0) == out {
            s.clone()
        } else {
            s.iter().map(|t| [t[0], t[2], t[1]]).collect()
        }
    };
    for i in 0..n {
        if holders[i].len().is_multiple_of(2) {
            body_of[i] = out.len();
            out.push((
                i,
                Body {
                    outer: facing(&shells[i], volumes[i], true),
                    voids: vec![],
                },
            ));
        }
    }
    for j in 0..n {
        if holders[j].len() % 2 == 1 {
            // The innermost holder: the smallest.
            let Some(&h) = holders[j]
                .iter()
                .filter(|&&h| body_of[h] != usize::MAX)
                .min_by(|&&a, &&b| volumes[a].abs().total_cmp(&volumes[b].abs()))
            else {
                continue;
            };
            out[body_of[h]]
                .1
                .voids
                .push(facing(&shells[j], volumes[j], false));
        }
    }
    out.into_iter().map(|(_, b)| b).collect()
}

/// The connected shells of a closed, manifold mesh, each turned to run one way: every edge
/// used once each way (a triangle running an edge the same way as its neighbour is turned).
fn oriented_shells(triangles: &[[u32; 3]]) -> Vec<Vec<[u32; 3]>> {
    let uses = edge_uses(triangles);
    let mut tris = triangles.to_vec();
    let mut seen = vec![false; tris.len()];
    let mut shells = vec![];
    for start in 0..tris.len() {
        if seen[start] {
            continue;
        }
        seen[start] = true;
        let mut stack = vec![start];
        let mut shell = vec![];
        while let Some(k) = stack.pop() {
            let t = tris[k];
            shell.push(t);
            for e in 0..3 {
                let (a, b) = (t[e], t[(e + 1) % 3]);
                for &m in &uses[&(a.min(b), a.max(b))] {
                    let m = m as usize;
                    if seen[m] {
                        continue;
                    }
                    seen[m] = true;
                    // The neighbour must run the edge b → a.
                    let u = tris[m];
                    let same_way = (0..3).any(|f| u[f] == a && u[(f + 1) % 3] == b);
                    if same_way {
                        tris[m] = [u[0], u[2], u[1]];
                    }
                    stack.push(m);
                }
            }
        }
        shells.push(shell);
    }
    shells
}

/// Whether `p` is inside the closed shell `s`: the parity of a ray's crossings (a direction
/// skewed off every axis, so that it meets no edge of a grid-aligned mesh).
fn contains(positions: &[[f64; 3]], s: &[[u32; 3]], p: [f64; 3]) -> bool {
    let d = [0.5773, 0.5774, 0.5775];
    let mut crossings = 0;
    for t in s {
        let [a, b, c] = t.map(|i| positions[i as usize]);
        // Möller–Trumbore.
        let (e1, e2) = (sub(b, a), sub(c, a));
        let h = cross(d, e2);
        let det = dot(e1, h);
        if det.abs() < RAY_PARALLEL {
            continue;
        }
        let s0 = sub(p, a);
        let u = dot(s0, h) / det;
        if !(0.0..=1.0).contains(&u) {
            continue;
        }
        let q = cross(s0, e1);
        let v = dot(d, q) / det;
        if v < 0.0 || u + v > 1.0 {
            continue;
        }
        if dot(e2, q) / det > 0.0 {
            crossings += 1;
        }
    }
    crossings % 2 == 1
}

#[cfg(test)]
mod tests {
    use super::*;

    fn cube(positions: &mut Vec<[f64; 3]>, lo: f64, hi: f64, out: &mut Vec<[u32; 3]>) {
        let b = positions.len() as u32;
        for k in 0..8 {
            positions.push([
                if k & 1 == 0 { lo } else { hi },
                if k & 2 == 0 { lo } else { hi },
                if k & 4 == 0 { lo } else { hi },
            ]);
        }
        for q in [
            [0, 2, 3, 1],
            [4, 5, 7, 6],
            [0, 1, 5, 4],
            [2, 6, 7, 3],
            [0, 4, 6, 2],
            [1, 3, 7, 5],
        ] {
            out.push([b + q[0], b + q[1], b + q[2]]);
            out.push([b + q[0], b + q[2], b + q[3]]);
        }
    }

    #[test]
    fn a_cube_in_a_cube_is_a_void_and_a_flipped_triangle_is_turned() {
        let (mut p, mut t) = (vec![], vec![]);
        cube(&mut p, 0.0, 10.0, &mut t);
        cube(&mut p, 4.0, 6.0, &mut t);
        t[3] = [t[3][0], t[3][2], t[3][1]];
        let o = Object {
            name: String::new(),
            positions: p.clone(),
            triangles: t,
        };
        let b = bodies(&o);
        assert_eq!(b.len(), 1);
        assert_eq!(b[0].voids.len(), 1);
        assert!((measure(&p, &b[0].outer).volume - 1000.0).abs() < 1e-9);
        assert!((measure(&p, &b[0].voids[0]).volume + 8.0).abs() < 1e-9);
    }
}
