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

/// How far above the highest level a fill tells apart a ridge value must be to count as
/// above it, mm: far more than the round-off of interpolating between two such values.
const RIDGE_CAP_MARGIN: f64 = 1e-6;

/// The local ridge height of `db` (within one and a half spacings) seen from the flanks of
/// the region, at the vertices the iso-lines at `levels` interpolate between (the ends of the
/// lattice edges each `(level, top)` crosses), where the fills read it only through
/// thresholds no higher than that level's `top` (a ring's width limit, a gap's `below` or
/// full bead). Exact at a vertex up to the highest `top` of the levels its edges cross (plus
/// [`RIDGE_CAP_MARGIN`]), and wherever a crossing edge joins it to a vertex exact below its
/// own; a vertex above its cap whose crossing edges all end above theirs keeps some value
/// above it (its search stops there), and so does every value interpolated between two such
/// ends, which the fills then read as they would the exact one.
pub(super) fn ridge(lm: &LayerMesh, db: &[f64], levels: &[(f64, f64)], spacing: f64) -> Vec<f64> {
    let radius = 1.5 * spacing;
    let n = db.len();
    let crosses = |a: usize, b: usize, l: f64| (db[a] - l) * (db[b] - l) <= 0.0;
    let mut cap = vec![f64::NEG_INFINITY; n];
    for t in &lm.tris {
        for k in 0..3 {
            let (a, b) = (t[k] as usize, t[(k + 1) % 3] as usize);
            for &(l, top) in levels {
                if crosses(a, b, l) {
                    let c = top + RIDGE_CAP_MARGIN;
                    cap[a] = cap[a].max(c);
                    cap[b] = cap[b].max(c);
                }
            }
        }
    }
    let mask: Vec<bool> = cap.iter().map(|c| *c > f64::NEG_INFINITY).collect();
    let mut r = lm.local_max(db, radius, &mask, &cap);
    // A crossing edge with one end above its cap and the other exact: that end exact too.
    let above = |v: usize| r[v] > cap[v];
    let mut redo = vec![false; n];
    let mut any = false;
    for t in &lm.tris {
        for k in 0..3 {
            let (a, b) = (t[k] as usize, t[(k + 1) % 3] as usize);
            if above(a) != above(b) && levels.iter().any(|&(l, _)| crosses(a, b, l)) {
                redo[if above(a) { a } else { b }] = true;
                any = true;
            }
        }
    }
    if any {
        let exact = lm.local_max(db, radius, &redo, &vec![f64::INFINITY; n]);
        for (v, x) in r.iter_mut().enumerate() {
            if redo[v] {
                *x = exact[v];
            }
        }
    }
    r
}

/// [`ridge`] where [`gap_fill`] runs for `gap`: it reads the ridge only through `below`
/// (nothing at or above it) or, without one, through the edge plus a bead `width` (a full
/// bead from there up).
pub(super) fn ridge_for(
    lm: &LayerMesh,
    db: &[f64],
    gap: Gap,
    spacing: f64,
    width: f64,
) -> Vec<f64> {
    let top = if gap.below.is_finite() {
        gap.below
    } else {
        gap.edge + width
    };
    ridge(lm, db, &[(gap.edge + gap.inset, top)], spacing)
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
