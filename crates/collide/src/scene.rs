//! The check of every move: the head swept along it (tip and tool axis interpolated, positions
//! at most [`SWEEP_STEP`] apart, the head's far end included) against what was deposited before
//! it and the table ([`Scene`]). Before a move of feature F in layer L lie every bead of the
//! groups of points (feature, layer) that precede its own in the path: the features built
//! before, and F's earlier layers ([`check`]).

use crate::deposit::{Deposit, GRAIN_SPACING};
use crate::head::{Head, HeadShape};
use crate::table::Table;
use toolpath::vec3::{add, norm, scale, sub, unit, V3};
use toolpath::{MoveKind, PathPoint, ToolPath};

/// Largest distance (mm) between head positions checked along a move, measured at the head's
/// farthest point (a turn of the tool axis sweeps the body's top furthest).
pub const SWEEP_STEP: f64 = 1.0;

/// Depth (mm) material must lie inside the head (a quarter-millimetre cell of it wholly, see
/// [`crate::Deposit`]), or the head below the table surface, to count:
/// the tip rests on the layer below and beside the beads of its own layer, and bead surfaces
/// are not exact.
pub const TOLERANCE: f64 = 0.1;

/// What a colliding move hits.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Obstacle {
    /// Material laid by the feature of this file-wide id.
    Feature(usize),
    /// The machine's table.
    Table,
}

/// A move that drives the head into material or the table.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Collision {
    /// Index in the path of the point that ends the move.
    pub index: usize,
    /// The feature of that point.
    pub feature: usize,
    /// Print or travel.
    pub kind: MoveKind,
    /// Tip position where the head first meets the obstacle along the move, mm.
    pub at: V3,
    /// What it meets.
    pub hits: Obstacle,
}

/// The head, the table and what is deposited, as a move is checked.
pub struct Scene {
    shape: HeadShape,
    table: Option<Table>,
    /// What lies before the move being checked, but for the beads still pending (`Scene::pending`).
    pub deposit: Deposit,
    /// Ranges of the path whose beads lie before the move too but are not in `deposit` yet
    /// ([`Scene::deposit`], [`Scene::flush`]): a head above them all cannot meet them.
    pending: Vec<std::ops::Range<usize>>,
    /// The top of their grains (−∞: none).
    pending_top: f64,
}

impl Scene {
    /// Nothing deposited yet.
    pub fn new(head: &Head, table: Option<Table>) -> Scene {
        Scene {
            shape: head.shape(),
            table,
            deposit: Deposit::new(),
            pending: vec![],
            pending_top: f64::NEG_INFINITY,
        }
    }

    /// The top of every grain before the move: deposited and pending alike.
    pub fn z_max(&self) -> f64 {
        self.deposit.z_max().max(self.pending_top)
    }

    /// Whether moves between `points` (each from the point before it) may be checked without
    /// the pending beads: every tool axis exactly +Z and every tip at or above the pending
    /// grains' top. Such a head lies wholly at or above its tip's level (the nozzle cone starts
    /// at the tip), and a cell counts only with its centre deeper inside than the tolerance
    /// and the grain's slack, i.e. higher than the tip by that: above every pending grain.
    pub(crate) fn above_pending(&self, points: &[PathPoint]) -> bool {
        self.pending.is_empty()
            || points
                .iter()
                .all(|q| q.axis == [0.0, 0.0, 1.0] && q.p[2] >= self.pending_top)
    }

    /// Deposits the pending beads, in the order they were laid: the deposit is then what
    /// depositing each at once would have made.
    pub(crate) fn flush(&mut self, points: &[PathPoint]) {
        for r in std::mem::take(&mut self.pending) {
            grains(points, r, &mut |g| match g {
                Grain::Point(p, f) => self.deposit.add(p, f),
                Grain::Bead(a, b, f) => self.deposit.add_bead(a, b, f),
            });
        }
    }

    /// What the head with its tip at `tip` and tool axis `axis` meets, if anything.
    pub fn at(&self, tip: V3, axis: V3) -> Option<Obstacle> {
        let axis = unit(axis)?;
        if let Some(t) = &self.table {
            if t.hits(&self.shape, tip, axis, TOLERANCE) {
                return Some(Obstacle::Table);
            }
        }
        self.deposit
            .first_inside(&self.shape, tip, axis, TOLERANCE)
            .map(Obstacle::Feature)
    }

    /// Whether the head with its tip at `tip` and unit tool axis `axis` meets the table.
    pub(crate) fn hits_table(&self, tip: V3, axis: V3) -> bool {
        self.table
            .as_ref()
            .is_some_and(|t| t.hits(&self.shape, tip, axis, TOLERANCE))
    }

    /// The first obstacle the head meets swept from (`a`, axis `aa`) to (`b`, axis `ab`), with
    /// the tip position there; `a` itself is not checked (the move before ended there).
    pub fn sweep(&self, a: V3, aa: V3, b: V3, ab: V3) -> Option<(V3, Obstacle)> {
        let turn = norm(sub(aa, ab)) * self.shape.reach();
        let n = ((norm(sub(b, a)).max(turn)) / SWEEP_STEP)
            .ceil()
            .clamp(1.0, 1e5) as usize;
        // One tool axis all along, and no material the head may meet anywhere on the move:
        // only the table is asked at each position, and not even that when the head stays
        // above it all along.
        let along = (aa == ab).then(|| unit(aa)).flatten();
        let clear =
            along.is_some_and(|u| !self.deposit.may_meet_along(&self.shape, a, b, u, TOLERANCE));
        if let (true, Some(u)) = (clear, along) {
            let above = self
                .table
                .as_ref()
                .is_none_or(|t| t.clear_along(&self.shape, a, b, u, TOLERANCE));
            if above {
                return None;
            }
        }
        (1..=n).find_map(|k| {
            let t = k as f64 / n as f64;
            let tip = add(a, scale(sub(b, a), t));
            let axis = add(scale(aa, 1.0 - t), scale(ab, t));
            if clear {
                return self
                    .hits_table(tip, unit(axis)?)
                    .then_some((tip, Obstacle::Table));
            }
            self.at(tip, axis).map(|o| (tip, o))
        })
    }

    /// Deposits the beads of the print points `points[range]` (each from the point before it):
    /// along each run of beads, grains at most [`GRAIN_SPACING`] apart and, where the planned
    /// points lie closer, at least half that apart (every point of a bead is then within a
    /// quarter of the spacing of a grain), the run's ends always. They are kept pending (only
    /// the top of their grains taken) until a move needs them ([`Scene::flush`]): a part
    /// printed layer on layer with the tool axis up never does.
    pub(crate) fn deposit(&mut self, points: &[PathPoint], range: std::ops::Range<usize>) {
        let mut top = self.pending_top;
        grains(points, range.clone(), &mut |g| {
            top = top.max(match g {
                Grain::Point(p, _) => p[2],
                Grain::Bead(a, b, _) => Deposit::bead_top(a, b),
            })
        });
        self.pending_top = top;
        self.pending.push(range);
    }
}

/// A grain, or a bead of grains, of [`grains`].
enum Grain {
    /// A grain at this point, of this feature.
    Point(V3, usize),
    /// A bead of grains from the first point (not included) to the second, of this feature
    /// ([`Deposit::add_bead`]).
    Bead(V3, V3, usize),
}

/// The grains of the beads of the print points `points[range]` (see [`Scene::deposit`]).
fn grains(points: &[PathPoint], range: std::ops::Range<usize>, out: &mut impl FnMut(Grain)) {
    let mut last: Option<V3> = None;
    for j in range {
        let q = &points[j];
        if j == 0 || q.kind != MoveKind::Print {
            last = None;
            continue;
        }
        let from = last.unwrap_or(points[j - 1].p);
        if last.is_none() {
            out(Grain::Point(from, q.feature as usize));
        }
        let ends = points.get(j + 1).is_none_or(|n| n.kind != MoveKind::Print);
        if ends || norm(sub(q.p, from)) >= GRAIN_SPACING / 2.0 {
            out(Grain::Bead(from, q.p, q.feature as usize));
            last = Some(q.p);
        } else {
            last = Some(from);
        }
    }
}

/// Whether `a` and `b` belong to one group of points (same feature and layer).
pub(crate) fn same_group(a: &PathPoint, b: &PathPoint) -> bool {
    a.feature == b.feature && a.layer == b.layer
}

/// Every colliding move of `path` with `head` over `table`, in path order.
pub fn check(path: &ToolPath, head: &Head, table: Option<Table>) -> Vec<Collision> {
    let mut scene = Scene::new(head, table);
    let pts = &path.points;
    let mut out = vec![];
    let mut group = 0;
    for i in 0..pts.len() {
        if i > 0 && !same_group(&pts[i - 1], &pts[i]) {
            scene.deposit(pts, group..i);
            scene.flush(pts);
            group = i;
        }
        if let Some(c) = move_collision(&scene, pts, i) {
            out.push(c);
        }
    }
    out
}

/// The collision of the move ending at `pts[i]`, if any.
pub(crate) fn move_collision(scene: &Scene, pts: &[PathPoint], i: usize) -> Option<Collision> {
    move_hit(scene, i.checked_sub(1).map(|j| &pts[j]), &pts[i], i)
}

/// The collision of the move from `from` (none: the path's first point) to `q`, the point of
/// index `index` in its path, if any.
pub(crate) fn move_hit(
    scene: &Scene,
    from: Option<&PathPoint>,
    q: &PathPoint,
    index: usize,
) -> Option<Collision> {
    let hit = match from {
        Some(a) => scene.sweep(a.p, a.axis, q.p, q.axis),
        None => scene.at(q.p, q.axis).map(|o| (q.p, o)),
    }?;
    Some(Collision {
        index,
        feature: q.feature as usize,
        kind: q.kind,
        at: hit.0,
        hits: hit.1,
    })
}

/// A path point for the tests: +Z axis, no filament, a 0.45 × 0.2 mm perimeter bead.
#[cfg(test)]
pub(crate) fn test_point(feature: usize, layer: usize, kind: MoveKind, p: V3) -> PathPoint {
    PathPoint {
        feature: feature as u32,
        layer: layer as u32,
        kind,
        p,
        axis: [0.0, 0.0, 1.0],
        e: 0.0,
        thickness: 0.2,
        width: 0.45,
        role: toolpath::Role::Perimeter,
    }
}
