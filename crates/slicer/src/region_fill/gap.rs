//! Gap fill: the strip of a region too narrow for a bead, filled along its ridge by one bead
//! as wide as the strip at each point (or, a strip over a bead across, one bead on each half).

use super::thin_out::{thin_out, THIN_LINE_SHARE, THIN_WIDTH_SHARE};
use super::FillPath;
use crate::geodesic::{LayerMesh, RayTop, Reach};
use crate::geom2d::Point2;
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

/// The local ridge height of `db` (within `reach`) seen from the flanks of
/// the region, at the vertices the iso-lines at `levels` interpolate between (the ends of the
/// lattice edges each `(level, top)` crosses), where the fills read it only through
/// thresholds no higher than that level's `top` (a ring's width limit, a gap's `below` or
/// full bead). Exact at a vertex up to the highest `top` of the levels its edges cross (plus
/// [`RIDGE_CAP_MARGIN`]), and wherever a crossing edge joins it to a vertex exact below its
/// own; a vertex above its cap whose crossing edges all end above theirs keeps some value
/// above it (its search stops there), and so does every value interpolated between two such
/// ends, which the fills then read as they would the exact one.
pub(super) fn ridge(lm: &LayerMesh, db: &[f64], levels: &[(f64, f64)], reach: Reach) -> Vec<f64> {
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
    let mut r = lm.local_max(db, reach, &mask, &cap);
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
        let exact = lm.local_max(db, reach, &redo, &vec![f64::INFINITY; n]);
        for (v, x) in r.iter_mut().enumerate() {
            if redo[v] {
                *x = exact[v];
            }
        }
    }
    r
}

/// Gap fill: the strip of a region farther than `gap.edge` from its boundary (`db`, the
/// distance to the boundary) but too narrow for a bead: its local half width β is the height
/// of the ridge of `db` above the edge. The fill follows one loop round the ridge,
/// `gap.inset` inside the strip's edge (an iso-line of `db`), each point moved up the
/// distance along its steepest ascent to where it stops rising ([`LayerMesh::ray_max`]):
///
/// - where the strip is at most [`SINGLE_BEAD_MAX`] beads across, onto the ridge, as one bead
///   2β wide: the loop's two flanks meet there, and the second time the loop comes along a
///   stretch of ridge it has laid ([`Laid`]) it is cut. A wall one bead across (a 0.45 mm
///   frame of a connector housing) took two beads 0.2 mm wide a tenth of a bead inside its
///   faces, each under the narrowest bead the machine lays, and its middle stayed empty;
/// - where it is wider, to the middle of its own half, a bead β wide: the two flanks lie edge
///   to edge.
///
/// Each point is extruded for its width by Eq. 1, so the fill puts down the strip's volume.
/// Beads narrower than `gap.min_width`, where the ridge reaches `gap.below` (the next ring
/// runs there), or lying more than half inside the beads `beside` (the ring beside the gap: at
/// a convex corner of the region the ridge runs into the corner below the ring's level, but
/// the ring's bead rounds the corner), are left out.
pub(super) fn gap_fill(
    lm: &LayerMesh,
    db: &[f64],
    gap: Gap,
    width: f64,
    beside: Option<&Beside>,
) -> Vec<FillPath> {
    let mut out = vec![];
    let dmax = db
        .iter()
        .copied()
        .filter(|d| d.is_finite())
        .fold(0.0f64, f64::max);
    let level = gap.edge + gap.inset;
    if dmax <= gap.edge + gap.inset.max(0.05 * width) {
        return out;
    }
    let mut laid = Laid::new(RETRACE_SHARE * width);
    // The highest distance near each loop point (on a lattice coarse for the strip, the loop
    // breaks into islands along the ridge, and a ray from it may meet the ridge between
    // vertices that sample it low). Told apart up to the fill's `below` only: it is read no
    // higher (`near.min(gap.below)`).
    let near = ridge(
        lm,
        db,
        &[(level, (gap.edge + width).min(gap.below))],
        Reach::Steps {
            most: NEAR_RIDGE_SHARE * width,
            steps: NEAR_RIDGE_STEPS,
        },
    );
    for line in lm.iso_lines(db, level, &near) {
        // Up the distance from the loop to where it stops rising: the ridge the flanks meet
        // on, the strip's local half width β there. Where the ridge reaches `below` as the
        // lattice's iso-lines see it, the next ring runs.
        let ups: Vec<(Option<Point2>, Option<RayTop>, f64)> = line
            .q
            .iter()
            .zip(&line.low)
            .zip(&line.other)
            .map(|((q, low), near)| {
                let ascent = lm.ascent(db, *low);
                let top = ascent.and_then(|a| lm.ray_max(db, *low, *q, a, RIDGE_SLACK * width));
                let beta = match top {
                    Some(t) if t.sampled < gap.below => {
                        (t.height.max(near.min(gap.below)) - gap.edge).clamp(0.0, width)
                    }
                    _ => 0.0,
                };
                (ascent, top, beta)
            })
            .collect();
        // A closed loop starts where the strip is narrowest (a strip's end): its first flank
        // is laid from there along the whole ridge, and the other comes back over it. From
        // anywhere else, the stretch between that start and the end was laid by neither.
        let (q, ups) = if line.closed && ups.len() > 2 {
            let n = ups.len() - 1;
            let k = (0..n)
                .min_by(|&a, &b| ups[a].2.total_cmp(&ups[b].2))
                .unwrap_or(0);
            let order = (k..n).chain(0..=k);
            let q: Vec<Point2> = order.clone().map(|i| line.q[i]).collect();
            (q, order.map(|i| ups[i]).collect())
        } else {
            (line.q, ups)
        };
        // One bead on the ridge or one on each flank, for the whole loop by its median width
        // (point by point, a strip near the limit went to and fro between the two).
        let mut betas: Vec<f64> = ups.iter().map(|u| u.2).filter(|b| *b > 0.0).collect();
        betas.sort_by(f64::total_cmp);
        let median = betas.get(betas.len() / 2).copied();
        let single = median.is_none_or(|b| 2.0 * b <= SINGLE_BEAD_MAX * width);
        // Into a corner, the ridge's branch narrows to nothing: its single beads stop at a
        // quarter bead, or at half the loop's usual width where the whole strip is narrower
        // (a contact thinner than a bead keeps its beads).
        let corner_floor = (SINGLE_MIN_WIDTH * width).min(median.unwrap_or(0.0));
        let mut cur = FillPath::empty(Role::GapFill);
        for (q, (ascent, top, beta)) in q.iter().zip(ups) {
            let (at, w) = match (top, ascent) {
                (Some(t), _) if single => (t.at, 2.0 * beta),
                (_, Some(a)) => {
                    let up = (gap.edge + 0.5 * beta - level).max(0.0);
                    ([q[0] + a[0] * up, q[1] + a[1] * up], beta)
                }
                _ => (*q, beta),
            };
            // The bead's half width, mm, and where it lies in the metric's frame (mm).
            let half = if single { beta } else { 0.5 * beta };
            let m = lm.metric_point(at);
            let narrowest = if single {
                (SINGLE_MIN_SHARE * gap.min_width).max(corner_floor)
            } else {
                gap.min_width
            };
            let keep = w >= narrowest
                && !(single && laid.retraces(m, out.len()))
                && !beside.is_some_and(|b| b.covers(m, half));
            if !keep {
                let done = std::mem::replace(&mut cur, FillPath::empty(Role::GapFill));
                if done.points.len() >= 2 {
                    out.push(done);
                }
                laid.next_path();
                continue;
            }
            // Neighbouring loop points may land on one spot of the ridge: one point there, as
            // wide as the wider.
            if cur.points.last().is_some_and(|&l| {
                crate::geom2d::dist(lm.metric_point(l), m) < MIN_STEP_SHARE * width
            }) {
                if let Some(last) = cur.widths.last_mut() {
                    *last = last.max(w);
                }
                continue;
            }
            if single {
                laid.add(m, out.len());
            }
            cur.points.push(at);
            cur.widths.push(w);
        }
        if cur.points.len() >= 2 {
            out.push(cur);
        }
        laid.next_path();
    }
    // The ridge's wander between lattice edges thinned out of the points.
    let (line, spread) = (THIN_LINE_SHARE * width, THIN_WIDTH_SHARE * width);
    out.into_iter()
        .map(|p| thin_out(p, |q| lm.metric_point(q), line, spread))
        .collect()
}

/// How far, in bead widths, a gap fill looks round each loop point for the ridge's height
/// (besides up its ray).
const NEAR_RIDGE_SHARE: f64 = 0.5;

/// ... and at most this many lattice edges at the point's vertex ([`LayerMesh::edge_at`]): a
/// lattice finer than a twelfth of a bead finds the ridge up the ray by itself.
///
/// Why: the search's ball holds (radius / edge)² vertices, searched from every vertex along
/// the loop. Where the chart stretches the layer unevenly, its lattice (equilateral on the
/// surface at one point of the region) is much finer elsewhere: on the curved layers of a
/// connector's thin fins (AutoCAD's `k1_voids` on delta5, face #2592 down) half a bead held
/// some 1,650 vertices a search, and this search took 52 of the placement's 69 s.
const NEAR_RIDGE_STEPS: f64 = 6.0;

/// The shortest step between a gap fill's points, in bead widths.
pub(super) const MIN_STEP_SHARE: f64 = 0.002;

/// How far past the last rise of the distance, in bead widths, a gap fill's point looks for
/// it to rise again before taking that rise for the ridge ([`LayerMesh::ray_max`]).
const RIDGE_SLACK: f64 = 0.7;

/// Segments in a grid of square cells, each listed in every cell its box touches (they are
/// short: a lattice step or a bead's): which of them lie near a point.
struct SegmentGrid<T> {
    cell: f64,
    cells: crate::fast_hash::FastMap<(i64, i64), Vec<usize>>,
    segs: Vec<(Point2, Point2, T)>,
}

/// Most cells a [`SegmentGrid`] looks through for one point (none found past it).
const MAX_NEAR_CELLS: i64 = 10_000;

impl<T> SegmentGrid<T> {
    /// An empty grid of cells `cell` wide.
    fn new(cell: f64) -> SegmentGrid<T> {
        SegmentGrid {
            cell,
            cells: Default::default(),
            segs: vec![],
        }
    }

    fn at(&self, p: Point2) -> (i64, i64) {
        (
            (p[0] / self.cell).floor() as i64,
            (p[1] / self.cell).floor() as i64,
        )
    }

    /// Lists the segment `a`–`b` with `tag`.
    fn push(&mut self, a: Point2, b: Point2, tag: T) {
        let k = self.segs.len();
        self.segs.push((a, b, tag));
        let (c0, c1) = (self.at(a), self.at(b));
        for x in c0.0.min(c1.0)..=c0.0.max(c1.0) {
            for y in c0.1.min(c1.1)..=c0.1.max(c1.1) {
                self.cells.entry((x, y)).or_default().push(k);
            }
        }
    }

    /// Whether `hit` holds for a segment listed in a cell of the box `reach` round `p` (every
    /// segment within `reach` of `p` is among them, some more than once); false where that box
    /// spans more than [`MAX_NEAR_CELLS`] cells.
    fn any_near(
        &self,
        p: Point2,
        reach: f64,
        mut hit: impl FnMut(Point2, Point2, &T) -> bool,
    ) -> bool {
        let (lo, hi) = (
            self.at([p[0] - reach, p[1] - reach]),
            self.at([p[0] + reach, p[1] + reach]),
        );
        if (hi.0 - lo.0 + 1).saturating_mul(hi.1 - lo.1 + 1) > MAX_NEAR_CELLS {
            return false;
        }
        (lo.0..=hi.0).any(|x| {
            (lo.1..=hi.1).any(|y| {
                self.cells.get(&(x, y)).into_iter().flatten().any(|&k| {
                    let (a, b, tag) = &self.segs[k];
                    hit(*a, *b, tag)
                })
            })
        })
    }
}

/// Beads laid beside a gap fill (the ring it runs beside): segments in the frame of the
/// chart's metric ([`LayerMesh::metric_point`], mm) with their bead widths.
pub(super) struct Beside {
    widest: f64,
    grid: SegmentGrid<f64>,
}

impl Beside {
    /// The beads of `paths` (chart coordinates) on `lm`, in cells `cell` mm wide.
    pub(super) fn new(lm: &LayerMesh, paths: &[FillPath], cell: f64) -> Beside {
        let mut b = Beside {
            widest: 0.0,
            grid: SegmentGrid::new(cell),
        };
        for p in paths {
            for i in 1..p.points.len() {
                let w = 0.5 * (p.widths[i - 1] + p.widths[i]);
                b.widest = b.widest.max(w);
                let (a, c) = (p.points[i - 1], p.points[i]);
                b.grid.push(lm.metric_point(a), lm.metric_point(c), w);
            }
        }
        b
    }

    /// Whether a bead centred at `p` (the metric's frame), `half` mm to each side, lies more
    /// than half inside these beads.
    fn covers(&self, p: Point2, half: f64) -> bool {
        self.grid.any_near(p, 0.5 * self.widest + half, |a, b, &w| {
            crate::geom2d::seg_dist(p, a, b) - half < 0.5 * (w - half)
        })
    }
}

/// The narrowest single bead on a ridge, as a multiple of the gap's narrowest flank bead
/// (`Gap::min_width`): a little wider, so that a bead into a sharp corner keeps its middle
/// half a layer from the part's sides (a blade's last layer is checked so).
pub(super) const SINGLE_MIN_SHARE: f64 = 1.1;

/// The narrowest single bead on a ridge in bead widths where the strip is wider (twice that,
/// or more, as a rule): narrower, the medial axis's branches into a region's corners got beads
/// a tenth of a bead wide, which a nozzle lays several times as wide (the plan widens them to
/// the machine's narrowest bead), and the head leaned into the corner to lay them.
pub(super) const SINGLE_MIN_WIDTH: f64 = 0.25;

/// The widest strip, in bead widths, a gap fill lays as one bead on its ridge ([`gap_fill`]);
/// a wider one gets a bead on each flank.
pub(super) const SINGLE_BEAD_MAX: f64 = 1.1;

/// How close, in bead widths, a point of a gap fill's single beads may come to a stretch
/// laid before (other than the last [`RETRACE_SHARE`]·[`OWN_RUN`] of its own path) and still
/// be laid: the two flanks of a loop meet on the ridge within the lattice's error.
const RETRACE_SHARE: f64 = 0.25;

/// How much of a path's own last stretch, in multiples of the retrace distance, a new point
/// is not checked against (the point before it, and the turn at a strip's tip).
const OWN_RUN: f64 = 4.0;

/// The single beads a gap fill has laid, in the frame of the chart's metric (mm): segments in
/// a grid of cells the retrace distance wide, each with the path it belongs to and how far
/// along it it ends.
struct Laid {
    tol: f64,
    grid: SegmentGrid<(usize, f64)>,
    /// The last point laid on the current path, and the length laid on it so far.
    last: Option<(Point2, f64)>,
}

impl Laid {
    fn new(tol: f64) -> Laid {
        Laid {
            tol,
            grid: SegmentGrid::new(tol),
            last: None,
        }
    }

    /// Whether `p`, to be laid on path `path`, lies within the retrace distance of a stretch
    /// laid before: of another path, or of this one farther back than its own last run.
    fn retraces(&self, p: Point2, path: usize) -> bool {
        let along = self.last.map_or(0.0, |(_, s)| s);
        self.grid.any_near(p, self.tol, |a, b, &(on, s)| {
            !(on == path && s > along - OWN_RUN * self.tol)
                && crate::geom2d::seg_dist(p, a, b) < self.tol
        })
    }

    /// Lays `p` on path `path` (joined to the point laid before it on that path).
    fn add(&mut self, p: Point2, path: usize) {
        self.last = Some(match self.last {
            Some((a, s)) => {
                let s = s + crate::geom2d::dist(a, p);
                self.grid.push(a, p, (path, s));
                (p, s)
            }
            None => (p, 0.0),
        });
    }

    /// The path laid on is done: the next point starts another.
    fn next_path(&mut self) {
        self.last = None;
    }
}
