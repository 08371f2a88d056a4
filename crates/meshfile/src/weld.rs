//! Welding: vertices at the same place made one, so that triangles meeting there share them.
//! An STL writes every facet's corners anew; a mesh with small gaps has corners a hair apart.

use crate::Object;
use std::collections::HashMap;

/// A mesh welded.
#[derive(Debug, Clone, PartialEq)]
pub struct Welded {
    /// The object with its vertices joined and the triangles that collapsed dropped.
    pub object: Object,
    /// Vertices joined to another at a distance above zero (the gaps closed).
    pub moved: usize,
    /// Triangles dropped because two of their corners became one.
    pub collapsed: usize,
}

/// `o` with every two vertices closer than `tol` (mm) joined (transitively: a chain of close
/// vertices becomes one, at its first vertex's place), exactly equal ones always; triangles
/// with two corners joined are dropped; vertices no triangle uses are left out.
pub fn weld(o: &Object, tol: f64) -> Welded {
    let n = o.positions.len();
    let mut parent: Vec<u32> = (0..n as u32).collect();
    fn root(parent: &mut [u32], mut i: u32) -> u32 {
        while parent[i as usize] != i {
            let p = parent[parent[i as usize] as usize];
            parent[i as usize] = p;
            i = p;
        }
        i
    }
    let union = |parent: &mut Vec<u32>, a: u32, b: u32| {
        let (ra, rb) = (root(parent, a), root(parent, b));
        if ra != rb {
            let (lo, hi) = (ra.min(rb), ra.max(rb));
            parent[hi as usize] = lo;
        }
    };
    // Exactly equal positions.
    let mut same: HashMap<[u64; 3], u32> = HashMap::with_capacity(n);
    for (i, p) in o.positions.iter().enumerate() {
        let key = p.map(|x| (x + 0.0).to_bits());
        let first = *same.entry(key).or_insert(i as u32);
        union(&mut parent, first, i as u32);
    }
    let exact: Vec<u32> = (0..n as u32).map(|i| root(&mut parent, i)).collect();
    // Within `tol`: a grid of cells `tol` wide, each vertex against its cell's neighbours.
    if tol > 0.0 {
        let cell = |p: &[f64; 3]| p.map(|x| (x / tol).floor() as i64);
        let mut grid: HashMap<[i64; 3], Vec<u32>> = HashMap::new();
        for (i, p) in o.positions.iter().enumerate() {
            if exact[i] == i as u32 {
                grid.entry(cell(p)).or_default().push(i as u32);
            }
        }
        for (i, p) in o.positions.iter().enumerate() {
            if exact[i] != i as u32 {
                continue;
            }
            let c = cell(p);
            for dx in -1..=1 {
                for dy in -1..=1 {
                    for dz in -1..=1 {
                        let Some(others) = grid.get(&[c[0] + dx, c[1] + dy, c[2] + dz]) else {
                            continue;
                        };
                        for &j in others {
                            if j as usize > i && dist2(p, &o.positions[j as usize]) <= tol * tol {
                                union(&mut parent, i as u32, j);
                            }
                        }
                    }
                }
            }
        }
    }
    let reps: Vec<u32> = (0..n as u32).map(|i| root(&mut parent, i)).collect();
    let moved = (0..n)
        .filter(|&i| exact[i] == i as u32 && reps[i] != i as u32)
        .count();
    // Renumber the vertices the triangles use.
    let mut new = vec![u32::MAX; n];
    let mut out = Object {
        name: o.name.clone(),
        ..Object::default()
    };
    let mut collapsed = 0;
    for t in &o.triangles {
        let t = t.map(|i| reps[i as usize]);
        if t[0] == t[1] || t[1] == t[2] || t[0] == t[2] {
            collapsed += 1;
            continue;
        }
        out.triangles.push(t.map(|r| {
            if new[r as usize] == u32::MAX {
                new[r as usize] = out.positions.len() as u32;
                out.positions.push(o.positions[r as usize]);
            }
            new[r as usize]
        }));
    }
    Welded {
        object: out,
        moved,
        collapsed,
    }
}

fn dist2(a: &[f64; 3], b: &[f64; 3]) -> f64 {
    (0..3).map(|k| (a[k] - b[k]).powi(2)).sum()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn close_corners_join_and_collapsed_triangles_go() {
        let o = Object {
            name: String::new(),
            positions: vec![
                [0., 0., 0.],
                [1., 0., 0.],
                [0., 1., 0.],
                [1., 0., 0.],
                [1.0005, 0., 0.],
                [0., 1., 0.],
            ],
            triangles: vec![[0, 1, 2], [3, 4, 5]],
        };
        let exact = weld(&o, 0.0);
        assert_eq!(exact.object.positions.len(), 4);
        assert_eq!((exact.moved, exact.collapsed), (0, 0));
        let near = weld(&o, 0.001);
        assert_eq!(near.object.positions.len(), 3);
        assert_eq!((near.moved, near.collapsed), (1, 1));
    }
}
