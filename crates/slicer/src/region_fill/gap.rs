//! Gap fill: the strip of a region too narrow for a bead, filled by one loop of beads as wide
//! as the strip at each point.

use super::FillPath;
use crate::geodesic::LayerMesh;
use crate::toolpath::Role;

/// Where a gap fill runs: from `edge` (the distance to the region's boundary where the beads
/// outside it stop), its beads' middles `inset` further in, no narrower than `min_width`, and
/// only where the ridge of the distance is below `below` (deeper, the next ring takes over).
#[derive(Debug, Clone, Copy)]
pub(super) struct Gap {
    pub(super) edge: f64,
    pub(super) inset: f64,
    pub(super) min_width: f64,
    pub(super) below: f64,
}

/// Marks both ends of every lattice edge that one of `levels` of `db` crosses: the vertices
/// an iso-line at those levels interpolates between.
pub(super) fn crossing_vertices(lm: &LayerMesh, db: &[f64], levels: &[f64]) -> Vec<bool> {
    let mut mask = vec![false; db.len()];
    for t in &lm.tris {
        for k in 0..3 {
            let (a, b) = (t[k] as usize, t[(k + 1) % 3] as usize);
            if levels.iter().any(|l| (db[a] - l) * (db[b] - l) <= 0.0) {
                mask[a] = true;
                mask[b] = true;
            }
        }
    }
    mask
}

/// The local ridge height of `db` (within one and a half spacings) seen from the flanks of
/// the strip beyond `gap.edge`, where the gap fill's iso-line needs it: at the vertices it
/// interpolates between.
pub(super) fn ridge_for(lm: &LayerMesh, db: &[f64], gap: Gap, spacing: f64) -> Vec<f64> {
    let mask = crossing_vertices(lm, db, &[gap.edge + gap.inset]);
    lm.local_max(db, 1.5 * spacing, &mask)
}

/// Gap fill: the strip of a region farther than `gap.edge` from its boundary (`db`, the
/// distance to the boundary) but too narrow for a bead: its local half width β is the ridge
/// height (`ridge`, [`ridge_for`]) of `db` above the edge. The fill is one loop round the
/// ridge, `gap.inset` inside the strip's edge (an iso-line of `db`), each point β wide and
/// extruded for that width by Eq. 1: the two flanks together put down the strip's volume.
/// Stretches narrower than `gap.min_width`, or where the ridge reaches `gap.below`, are left
/// out.
pub(super) fn gap_fill(
    lm: &LayerMesh,
    db: &[f64],
    ridge: &[f64],
    gap: Gap,
    width: f64,
) -> Vec<FillPath> {
    let mut out = vec![];
    let dmax = db
        .iter()
        .copied()
        .filter(|d| d.is_finite())
        .fold(0.0f64, f64::max);
    if dmax <= gap.edge + gap.inset.max(0.05 * width) {
        return out;
    }
    for line in lm.iso_lines(db, gap.edge + gap.inset, ridge) {
        let mut cur = FillPath::empty(Role::GapFill);
        for (q, r) in line.q.iter().zip(&line.other) {
            let w = if *r < gap.below {
                (r - gap.edge).clamp(0.0, width)
            } else {
                0.0
            };
            if w >= gap.min_width {
                cur.points.push(*q);
                cur.widths.push(w);
            } else if cur.points.len() >= 2 {
                out.push(std::mem::replace(&mut cur, FillPath::empty(Role::GapFill)));
            } else {
                cur = FillPath::empty(Role::GapFill);
            }
        }
        if cur.points.len() >= 2 {
            out.push(cur);
        }
    }
    out
}
