//! The highest point of a field along a ray over a layer mesh: where a gap fill's loop, moved
//! up the distance to the boundary, meets the ridge of that distance.

use super::mesh::LayerMesh;
use crate::geom2d::Point2;
use crate::tolerance::BARYCENTRIC_SLACK;

/// No triangle across this edge (the region's boundary).
const NONE: u32 = u32::MAX;

/// How far outside a triangle (in barycentric coordinates) a ray's exit point may be found for
/// the ray to be taken as crossing it: the round-off of the exit's line intersection.
const HOLD_SLACK: f64 = 1e-6;

/// The least rise, as a share of the ray's slope, that counts as the field still rising along
/// it ([`LayerMesh::ray_max`]): over a coarse lattice aslant, the field rises unevenly, and
/// along a strip's ridge it does not rise at all.
const RISE_SHARE: f64 = 0.05;

/// How near a value looked at along a ray must be to a flank's line to be taken as on it, as a
/// share of the ray's slack ([`LayerMesh::ray_max`]).
const FLANK_SHARE: f64 = 0.02;

/// The widest span, as a share of the ray's slack, between the last point on a tent's rising
/// flank and the first on its falling one ([`LayerMesh::ray_max`]): triangles spanning a ridge
/// the ray crosses square are a lattice step or two across; a wider span is a ray aslant.
const TENT_SPAN: f64 = 0.7;

/// Most triangles a ray is followed through.
const MAX_STEPS: usize = 10_000;

/// Where a ray up a field stops rising ([`LayerMesh::ray_max`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RayTop {
    /// The ridge: where the ray's rising and falling flanks meet, or where the sampled field
    /// stops rising when it does not fall beyond.
    pub at: Point2,
    /// The field's height at `at` (the tent's top where the flanks meet).
    pub height: f64,
    /// The highest value of the piecewise-linear field sampled along the ray: what the
    /// field's iso-lines see there.
    pub sampled: f64,
}

impl LayerMesh {
    /// The triangle across each edge of each triangle (`k`: the edge from vertex `k` to
    /// `k + 1`), [`NONE`] on the boundary; made by the first search that needs it.
    fn across(&self) -> &[[u32; 3]] {
        self.tri_adjacency.get_or_init(|| {
            self.tris
                .iter()
                .enumerate()
                .map(|(t, tri)| {
                    [0, 1, 2].map(|k| {
                        let (a, b) = (tri[k], tri[(k + 1) % 3]);
                        self.around[a as usize]
                            .iter()
                            .copied()
                            .find(|&o| o as usize != t && self.tris[o as usize].contains(&b))
                            .unwrap_or(NONE)
                    })
                })
                .collect()
        })
    }

    /// Follows the ray from `q` (a point of a triangle around vertex `v`) up the field `f`
    /// along `ascent` ([`LayerMesh::ascent`] at `v`: its direction, and one over its length
    /// the field's slope) through the triangles to where `f` stops rising: the last point
    /// where `f` had risen by at least a twentieth of that slope over the way from the
    /// point before, once `f` has not done so for `slack` (the field's units, mm of distance; the
    /// piecewise-linear field wobbles on irregular triangles, and is level along a strip's
    /// ridge). The field is linear in each triangle, so the points looked at are where the
    /// ray enters or leaves one. `None` when no triangle around `v` holds `q` with the ray
    /// going into it.
    pub fn ray_max(
        &self,
        f: &[f64],
        v: u32,
        q: Point2,
        ascent: Point2,
        slack: f64,
    ) -> Option<RayTop> {
        let n = ascent[0].hypot(ascent[1]);
        if !(n > 0.0 && n.is_finite()) {
            return None;
        }
        let d = [ascent[0] / n, ascent[1] / n];
        // Slope of `f` along the ray (per chart length), and `slack` as a chart length.
        let slope = 1.0 / n;
        // How near a looked-at value must be to a flank's line to lie on it.
        let (on_flank, slack_f) = (FLANK_SHARE * slack, slack);
        let slack = slack * n;
        let across = self.across();
        let start = self.around.get(v as usize)?.iter().copied().find(|&t| {
            let s = self.exit(t, q, d);
            s.is_some_and(|(s, _)| s > 0.0) && self.holds(t, q)
        })?;
        let value = |t: u32, p: Point2| self.interpolate(f, t, p);
        let (mut t, mut s0) = (start, 0.0);
        let f0 = value(t, q)?;
        // Every point looked at (length along the ray, value), and the last where the field
        // had risen enough.
        let mut seen = vec![(0.0, f0)];
        let mut best = (0.0, f0);
        for _ in 0..MAX_STEPS {
            let Some((s, k)) = self.exit(t, q, d) else {
                break;
            };
            let s = s.max(s0);
            let p = [q[0] + d[0] * s, q[1] + d[1] * s];
            // A ray through a vertex may be handed to a triangle it does not cross.
            if !self.holds_within(t, p, HOLD_SLACK) {
                break;
            }
            let fp = value(t, p)?;
            seen.push((s, fp));
            if fp > best.1 + RISE_SHARE * slope * (s - best.0) {
                best = (s, fp);
            } else if s - best.0 > slack {
                break;
            }
            let next = across[t as usize][k];
            if next == NONE {
                break;
            }
            (t, s0) = (next, s);
        }
        let peak = (0..seen.len())
            .max_by(|&a, &b| seen[a].1.total_cmp(&seen[b].1))
            .unwrap_or(0);
        let top = |s: f64, h: f64| RayTop {
            at: [q[0] + d[0] * s, q[1] + d[1] * s],
            height: h,
            sampled: seen[peak].1,
        };
        // The distance to a boundary is a tent over a strip: rising at `slope` from `q`,
        // falling as steeply beyond the ridge. Where the ray went down the far side to a
        // point on that flank (the last looked at), the ridge is where the two flanks meet,
        // between the last point on the rising one and the first on the falling one: the
        // piecewise-linear field between them, over triangles that span the ridge, lies up to
        // half a lattice step off it and below it (a 2.4 mm strip's 0.6 mm core read 0.45 to
        // 0.56 mm wide). Elsewhere (a ray along a plateau, or aslant into a corner, where the
        // flanks are not one tent) it is where the field stopped rising, as sampled.
        let last = seen[seen.len() - 1];
        let rising = |&(s, f): &(f64, f64)| (f - (f0 + slope * s)).abs() <= on_flank;
        let falling =
            |&(s, f): &(f64, f64)| (f - (last.1 + slope * (last.0 - s))).abs() <= on_flank;
        let lo = seen.iter().skip(1).take_while(|x| rising(x)).last();
        let hi = seen.iter().find(|x| falling(x));
        match (lo, hi) {
            (Some(&(lo, _)), Some(&(hi, _)))
                if last.0 > hi
                    && hi > lo
                    && slope * (hi - lo) <= TENT_SPAN * slack_f
                    && last.1 < seen[peak].1 - 0.25 * slope * (last.0 - seen[peak].0) =>
            {
                let s = ((last.1 + slope * last.0 - f0) / (2.0 * slope)).clamp(lo, hi);
                // No higher than the sampled top by half the span between the flanks (the
                // most the piecewise-linear field falls short of a tent there).
                let peak = seen[peak].1;
                let h = (f0 + slope * s).min(peak + 0.5 * slope * (hi - lo));
                Some(top(s, h.max(peak)))
            }
            _ => Some(top(best.0, best.1)),
        }
    }

    /// Where the ray `q + s·d` leaves triangle `t`: the largest `s` at which it is still in
    /// the triangle's closure, and the edge it leaves by.
    fn exit(&self, t: u32, q: Point2, d: Point2) -> Option<(f64, usize)> {
        let tri = self.tris[t as usize];
        let mut out: Option<(f64, usize)> = None;
        // Each edge's line: the ray leaves the triangle's half-plane where it crosses it going
        // outward (the triangle lies left of each edge when counter-clockwise).
        let ccw = {
            let [a, b, c] = tri.map(|i| self.q[i as usize]);
            (b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0]) > 0.0
        };
        for k in 0..3 {
            let (a, b) = (self.q[tri[k] as usize], self.q[tri[(k + 1) % 3] as usize]);
            let e = [b[0] - a[0], b[1] - a[1]];
            // Inward normal of the edge.
            let nin = if ccw { [-e[1], e[0]] } else { [e[1], -e[0]] };
            let dn = d[0] * nin[0] + d[1] * nin[1];
            if dn >= 0.0 {
                continue;
            }
            let h = (q[0] - a[0]) * nin[0] + (q[1] - a[1]) * nin[1];
            let s = h / -dn;
            if out.is_none_or(|(o, _)| s < o) {
                out = Some((s, k));
            }
        }
        out
    }

    /// Whether triangle `t` holds `p` (within [`BARYCENTRIC_SLACK`]: `p` may lie on an edge).
    fn holds(&self, t: u32, p: Point2) -> bool {
        self.holds_within(t, p, BARYCENTRIC_SLACK)
    }

    /// Whether triangle `t` holds `p`, each barycentric coordinate down to `-slack`.
    fn holds_within(&self, t: u32, p: Point2, slack: f64) -> bool {
        self.barycentric(t, p)
            .is_some_and(|l| l.iter().all(|x| *x >= -slack))
    }

    /// `f` at `p` by the barycentric coordinates of `p` in triangle `t`.
    fn interpolate(&self, f: &[f64], t: u32, p: Point2) -> Option<f64> {
        let l = self.barycentric(t, p)?;
        let tri = self.tris[t as usize];
        let v: f64 = (0..3).map(|k| l[k] * f[tri[k] as usize]).sum();
        v.is_finite().then_some(v)
    }

    fn barycentric(&self, t: u32, p: Point2) -> Option<[f64; 3]> {
        let [a, b, c] = self.tris[t as usize].map(|i| self.q[i as usize]);
        let det = (b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0]);
        if det.abs() < f64::MIN_POSITIVE.sqrt() {
            return None;
        }
        let l1 = ((p[0] - a[0]) * (c[1] - a[1]) - (p[1] - a[1]) * (c[0] - a[0])) / det;
        let l2 = ((b[0] - a[0]) * (p[1] - a[1]) - (b[1] - a[1]) * (p[0] - a[0])) / det;
        Some([1.0 - l1 - l2, l1, l2])
    }
}
