//! Needles: triangles whose three corners lie on one line (a corner on the opposite edge, as
//! a T-junction mended by a zero-area triangle leaves them). They enclose nothing, but no
//! plane holds them, so no planar face can stand for them: each is taken out with the
//! triangle across its long edge, which is split at the needle's middle corner instead. The
//! surface stays closed and manifold and keeps its shape.

use crate::edges::edge_uses;
use crate::measure::{cross, dot, sub};
use crate::tolerance::NEEDLE_HEIGHT;

/// The passes made at most (a split triangle may itself be a needle).
const PASSES: usize = 8;

/// `triangles` over `positions` without needles; how many were taken out.
pub fn split_needles(positions: &[[f64; 3]], triangles: &mut Vec<[u32; 3]>) -> usize {
    let mut taken = 0;
    for _ in 0..PASSES {
        let uses = edge_uses(triangles);
        let mut done = vec![false; triangles.len()];
        let mut split = vec![];
        for k in 0..triangles.len() {
            let Some([a, b, m]) = needle(positions, triangles[k]) else {
                continue;
            };
            // The triangle across a → b runs b → a: (b, a, d).
            let Some(j) = uses[&(a.min(b), a.max(b))]
                .iter()
                .map(|&j| j as usize)
                .find(|&j| j != k)
            else {
                continue;
            };
            let Some(d) = (0..3).find_map(|f| {
                let u = triangles[j];
                (u[f] == b && u[(f + 1) % 3] == a).then_some(u[(f + 2) % 3])
            }) else {
                continue;
            };
            if done[k] || done[j] || d == m {
                continue;
            }
            done[k] = true;
            done[j] = true;
            split.push((k, j, [b, m, d], [m, a, d]));
        }
        if split.is_empty() {
            break;
        }
        let mut drop = vec![false; triangles.len()];
        for &(k, j, first, second) in &split {
            drop[k] = true;
            triangles[j] = first;
            triangles.push(second);
        }
        taken += split.len();
        let mut i = 0;
        triangles.retain(|_| {
            let keep = !drop.get(i).copied().unwrap_or(false);
            i += 1;
            keep
        });
    }
    taken
}

/// A needle's corners as `[a, b, m]`: its longest edge `a → b` (as the triangle runs it) and
/// the corner `m` within [`NEEDLE_HEIGHT`] of the edge's length from it; `None` for a
/// triangle with area.
fn needle(positions: &[[f64; 3]], t: [u32; 3]) -> Option<[u32; 3]> {
    let p = t.map(|i| positions[i as usize]);
    let len2 = |e: usize| {
        let d = sub(p[(e + 1) % 3], p[e]);
        dot(d, d)
    };
    let e = (0..3).max_by(|&x, &y| len2(x).total_cmp(&len2(y)))?;
    let long = len2(e);
    let n = cross(sub(p[(e + 1) % 3], p[e]), sub(p[(e + 2) % 3], p[e]));
    // |n| is the long edge's length times the height of the third corner over it.
    (long > 0.0 && dot(n, n) <= (NEEDLE_HEIGHT * long).powi(2)).then_some([
        t[e],
        t[(e + 1) % 3],
        t[(e + 2) % 3],
    ])
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::edges::count;
    use crate::measure::measure;

    #[test]
    fn a_needle_on_a_box_s_top_is_split_away() {
        let mut p: Vec<[f64; 3]> = (0..8)
            .map(|k| {
                [
                    if k & 1 == 0 { 0.0 } else { 10.0 },
                    if k & 2 == 0 { 0.0 } else { 10.0 },
                    if k & 4 == 0 { 0.0 } else { 10.0 },
                ]
            })
            .collect();
        let mut t = vec![];
        for q in [
            [0, 2, 3, 1],
            [4, 5, 7, 6],
            [0, 1, 5, 4],
            [2, 6, 7, 3],
            [0, 4, 6, 2],
            [1, 3, 7, 5],
        ] {
            t.push([q[0], q[1], q[2]]);
            t.push([q[0], q[2], q[3]]);
        }
        // The top (4 5 7), (4 7 6): its diagonal 4 → 7 split at its middle m by a needle.
        p.push([5.0, 5.0, 10.0]);
        let m = 8;
        t.retain(|x| *x != [4, 5, 7]);
        t.extend([[4, 5, m], [m, 5, 7], [4, m, 7]]);
        assert!(count(&t).closed_manifold());
        assert_eq!(split_needles(&p, &mut t), 1);
        assert!(count(&t).closed_manifold());
        assert!(t.iter().all(|&x| needle(&p, x).is_none()));
        assert!((measure(&p, &t).volume - 1000.0).abs() < 1e-9);
    }
}
