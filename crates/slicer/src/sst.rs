//! Side-surface-tangent (SST) tool axes for the wall paths of freeform features (Isa &
//! Lazoglu 2019, seed 000, section 3.2, Eq. 3): along a bead that runs against a side face of
//! the feature, the nozzle is held perpendicular to both the path's tangent t̂ and the side
//! face's normal n̂_s, `â = (n̂_s × t̂) / |n̂_s × t̂|`, turned to the side the layers grow (its dot
//! with the layer normal positive). The wall is then laid by the nozzle's side, tangent to the
//! face, rather than by stair-stepped layer edges.
//!
//! Which beads are wall beads: those whose centre lies within [`WALL_REACH`] bead widths of a
//! side face (the feature's faces other than its healing faces and its top, see
//! [`crate::transition::top_faces`]), so the outermost ring of each layer. The side faces are
//! held as triangles on a uniform grid for the nearest-face query.

use crate::geom2d::Point2;
use crate::lift::Lifted;

use crate::tolerance::{DEGENERATE_NORMAL, NONZERO, SHORT_VECTOR};
use brep::math::{P3, V3};
use brep::mesh::Mesh;
use brep::topology::FaceId;
use std::collections::HashMap;

/// A bead is a wall bead when its centre lies within this many bead widths of a side face.
pub(crate) const WALL_REACH: f64 = 0.75;

/// The side faces of a feature as triangles on a grid.
pub(crate) struct Sides {
    tris: Vec<[P3; 3]>,
    cell: f64,
    grid: HashMap<(i64, i64, i64), Vec<u32>>,
}

impl Sides {
    /// The faces of `mesh` (a feature's) that are neither in `heal` nor in `tops` (its top
    /// faces, [`crate::transition::top_faces`]).
    pub(crate) fn new(mesh: &Mesh, heal: &[FaceId], tops: &[FaceId], cell: f64) -> Sides {
        let mut tris = vec![];
        for ft in &mesh.faces {
            if heal.contains(&ft.face) || tops.contains(&ft.face) {
                continue;
            }
            for t in &ft.triangles {
                tris.push(t.map(|k| mesh.positions[ft.vertex[k as usize] as usize]));
            }
        }
        let cell = cell.max(1e-3);
        let key = |x: f64| (x / cell).floor() as i64;
        let mut grid: HashMap<(i64, i64, i64), Vec<u32>> = HashMap::new();
        for (i, t) in tris.iter().enumerate() {
            let lo = [0, 1, 2].map(|k| t.iter().map(|p| p[k]).fold(f64::INFINITY, f64::min));
            let hi = [0, 1, 2].map(|k| t.iter().map(|p| p[k]).fold(f64::NEG_INFINITY, f64::max));
            for a in key(lo[0])..=key(hi[0]) {
                for b in key(lo[1])..=key(hi[1]) {
                    for c in key(lo[2])..=key(hi[2]) {
                        grid.entry((a, b, c)).or_default().push(i as u32);
                    }
                }
            }
        }
        Sides { tris, cell, grid }
    }

    /// Whether the feature has side faces.
    pub(crate) fn is_empty(&self) -> bool {
        self.tris.is_empty()
    }

    /// The unit normal of the side triangle nearest `p`, if one lies within `reach` (at most
    /// one grid cell).
    pub(crate) fn normal_near(&self, p: &P3, reach: f64) -> Option<V3> {
        let key = |x: f64| (x / self.cell).floor() as i64;
        let (i, j, k) = (key(p.x), key(p.y), key(p.z));
        let mut best: Option<(f64, V3)> = None;
        for a in i - 1..=i + 1 {
            for b in j - 1..=j + 1 {
                for c in k - 1..=k + 1 {
                    let Some(list) = self.grid.get(&(a, b, c)) else {
                        continue;
                    };
                    for &t in list {
                        let [x, y, z] = self.tris[t as usize];
                        let n = (y - x).cross(&(z - x));
                        let len = n.norm();
                        if len < DEGENERATE_NORMAL {
                            continue;
                        }
                        let d = triangle_distance(p, &x, &y, &z);
                        if d <= reach && best.is_none_or(|(bd, _)| d < bd) {
                            best = Some((d, n / len));
                        }
                    }
                }
            }
        }
        best.map(|b| b.1)
    }
}

/// Puts Eq. 3's axis on the points of a lifted path whose bead (its centre half the local
/// thickness `thickness(q)` under the nozzle, along the layer normal) lies within `reach` of a
/// side face; the tangent at a point runs from its neighbour before to its neighbour after.
/// Returns how many points got it.
pub(crate) fn apply(
    pts: &mut [Lifted],
    sides: &Sides,
    thickness: impl Fn(Point2) -> f64,
    reach: f64,
) -> usize {
    let n = pts.len();
    if n < 2 || sides.is_empty() {
        return 0;
    }
    let mut axes = Vec::with_capacity(n);
    for i in 0..n {
        let x = &pts[i];
        let centre = x.p - x.n * (0.5 * thickness(x.q));
        let t = pts[(i + 1).min(n - 1)].p - pts[i.saturating_sub(1)].p;
        let axis = sides
            .normal_near(&centre, reach)
            .zip(t.try_normalize(SHORT_VECTOR))
            .and_then(|(ns, t)| sst_axis(&ns, &t, &x.n));
        axes.push(axis);
    }
    let mut count = 0;
    for (x, a) in pts.iter_mut().zip(axes) {
        if let Some(a) = a {
            x.n = a;
            count += 1;
        }
    }
    count
}

/// Eq. 3: the unit axis perpendicular to the side normal `ns` and the tangent `t`, on the side
/// of `layer_normal`; `None` where the two are parallel.
pub(crate) fn sst_axis(ns: &V3, t: &V3, layer_normal: &V3) -> Option<V3> {
    let a = ns.cross(t);
    let len = a.norm();
    if !(len.is_finite() && len > 1e-6) {
        return None;
    }
    let a = a / len;
    Some(if a.dot(layer_normal) < 0.0 { -a } else { a })
}

/// The distance from `p` to the triangle `a b c`.
fn triangle_distance(p: &P3, a: &P3, b: &P3, c: &P3) -> f64 {
    let seg = |u: &P3, v: &P3| {
        let uv = v - u;
        let t = ((p - u).dot(&uv) / uv.norm_squared().max(NONZERO)).clamp(0.0, 1.0);
        (p - (u + uv * t)).norm()
    };
    let n = (b - a).cross(&(c - a));
    let nn = n.norm();
    let edges = seg(a, b).min(seg(b, c)).min(seg(c, a));
    if nn < DEGENERATE_NORMAL {
        return edges;
    }
    let nu = n / nn;
    let h = (p - a).dot(&nu);
    let q = p - nu * h;
    let inside = [(a, b), (b, c), (c, a)]
        .iter()
        .all(|(u, v)| (*v - *u).cross(&(q - *u)).dot(&n) >= 0.0);
    if inside {
        h.abs()
    } else {
        edges
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn eq_3_is_perpendicular_to_the_side_normal_and_the_tangent() {
        let ns = V3::new(1.0, 0.0, 0.0);
        let t = V3::new(0.0, 1.0, 0.0);
        let a = sst_axis(&ns, &t, &V3::new(0.3, 0.0, 1.0)).expect("an axis");
        assert!(a.dot(&ns).abs() < 1e-12 && a.dot(&t).abs() < 1e-12);
        assert!((a - V3::z()).norm() < 1e-12);
        // The other side of the layer normal turns it round.
        let b = sst_axis(&ns, &t, &V3::new(0.0, 0.0, -1.0)).expect("an axis");
        assert!((b + V3::z()).norm() < 1e-12);
        assert!(sst_axis(&ns, &ns, &V3::z()).is_none());
    }

    #[test]
    fn triangle_distance_inside_and_past_an_edge() {
        let (a, b, c) = (
            P3::new(0.0, 0.0, 0.0),
            P3::new(1.0, 0.0, 0.0),
            P3::new(0.0, 1.0, 0.0),
        );
        assert!((triangle_distance(&P3::new(0.2, 0.2, 0.5), &a, &b, &c) - 0.5).abs() < 1e-12);
        assert!((triangle_distance(&P3::new(2.0, 0.0, 0.0), &a, &b, &c) - 1.0).abs() < 1e-12);
    }
}
