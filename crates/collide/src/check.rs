//! The check of every move: the head swept along it (tip and tool axis interpolated, positions
//! at most [`SWEEP_STEP`] apart, the head's far end included) against what was deposited before
//! it and the table. Before a move of feature F in layer L lie every bead of the groups of
//! points (feature, layer) that precede its own in the path: the features built before, and
//! F's earlier layers. Colliding travels are re-routed over the material when a lift clears them
//! ([`check_and_route`]).

use crate::deposit::{Deposit, GRAIN_SPACING};
use crate::head::{Head, HeadShape};
use crate::table::Table;
use crate::tilt::{tilt_run, TiltLimits};
use std::collections::BTreeMap;
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
    /// What lies before the move being checked.
    pub deposit: Deposit,
}

impl Scene {
    /// Nothing deposited yet.
    pub fn new(head: &Head, table: Option<Table>) -> Scene {
        Scene {
            shape: head.shape(),
            table,
            deposit: Deposit::new(),
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
        (1..=n).find_map(|k| {
            let t = k as f64 / n as f64;
            let tip = add(a, scale(sub(b, a), t));
            let axis = add(scale(aa, 1.0 - t), scale(ab, t));
            self.at(tip, axis).map(|o| (tip, o))
        })
    }

    /// Deposits the beads of the print points `points[range]` (each from the point before it):
    /// along each run of beads, grains at most [`GRAIN_SPACING`] apart and, where the planned
    /// points lie closer, at least half that apart (every point of a bead is then within a
    /// quarter of the spacing of a grain), the run's ends always.
    pub(crate) fn deposit(&mut self, points: &[PathPoint], range: std::ops::Range<usize>) {
        let mut last: Option<V3> = None;
        for j in range {
            let q = &points[j];
            if j == 0 || q.kind != MoveKind::Print {
                last = None;
                continue;
            }
            let from = last.unwrap_or(points[j - 1].p);
            if last.is_none() {
                self.deposit.add(from, q.feature);
            }
            let ends = points.get(j + 1).is_none_or(|n| n.kind != MoveKind::Print);
            if ends || norm(sub(q.p, from)) >= GRAIN_SPACING / 2.0 {
                self.deposit.add_bead(from, q.p, q.feature);
                last = Some(q.p);
            } else {
                last = Some(from);
            }
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
        feature: q.feature,
        kind: q.kind,
        at: hit.0,
        hits: hit.1,
    })
}

/// Lifts tried for a detour, as multiples of the head's length (then the material's height).
const LIFTS: [f64; 4] = [0.05, 0.15, 0.5, 1.0];

/// What [`check_and_route`] does with travel moves.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Travels {
    /// Checked, and lifted over the material where they collide.
    Route,
    /// Neither checked nor changed: the post replaces them with travels of its own (the KUKA
    /// post's retreat, rise, cross and approach).
    Skip,
}

/// [`check`], re-routing each colliding travel over the material: from its start up its tool
/// axis, across at one height, and down the next point's axis, by the least lift (a share of the head's
/// length, or clear of the highest material) that makes all three moves clear. A travel no lift
/// clears (or whose head collides at either end) is left as planned and reported. With
/// [`Travels::Skip`] travels are left alone. The detour's points are travel points of the
/// travel's end point (same feature, layer, width and thickness). Returns the collisions left.
pub fn check_and_route(
    path: &mut ToolPath,
    head: &Head,
    table: Option<Table>,
    travels: Travels,
) -> Vec<Collision> {
    walk(path, head, table, Some(travels), None).left
}

/// What [`tilt_and_route`] leaves.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Routed {
    /// The colliding moves left, in path order (indices in the path as re-routed).
    pub left: Vec<Collision>,
    /// Per feature id, its print moves that collided with the axes given and are clear tilted.
    pub cleared: BTreeMap<usize, usize>,
}

/// [`check_and_route`], each continuous path first tilted inside the cone about its `planned`
/// axes (one per point of `path`) where that clears print moves ([`crate::tilt`]; no tilt
/// when `limits` is `None`), its travels then routed with the axes tilted: the whole
/// avoidance in one walk along the path, each move checked once against what lies before it.
pub fn tilt_and_route(
    path: &mut ToolPath,
    planned: &[V3],
    head: &Head,
    table: Option<Table>,
    travels: Travels,
    limits: Option<&TiltLimits>,
) -> Routed {
    walk(
        path,
        head,
        table,
        Some(travels),
        limits.map(|l| (planned, l)),
    )
}

/// The walk along `path` behind [`check_and_route`], [`tilt_and_route`] and [`crate::tilt`]:
/// run by run (continuous paths), the material before each run's group deposited, its moves
/// checked, tilted by `tilt` (planned axes and limits) where that clears print moves (or the
/// head at the travel points leading to its bead), and its colliding travels routed by
/// `travels` (`None`: checked and reported, not routed).
pub(crate) fn walk(
    path: &mut ToolPath,
    head: &Head,
    table: Option<Table>,
    travels: Option<Travels>,
    tilt: Option<(&[V3], &TiltLimits)>,
) -> Routed {
    let mut scene = Scene::new(head, table);
    // Detours by the index of the point they go before; the path is rebuilt once, if at all.
    let mut detours: Vec<(usize, [PathPoint; 2])> = vec![];
    let mut out = Routed::default();
    let mut group = 0;
    let skip = |q: &PathPoint| travels == Some(Travels::Skip) && q.kind == MoveKind::Travel;
    for (r, lead) in runs(&path.points) {
        let pts = &mut path.points;
        if r.start > 0 && !same_group(&pts[r.start - 1], &pts[r.start]) {
            scene.deposit(pts, group..r.start);
            group = r.start;
        }
        let mut found: Vec<Option<Collision>> = r
            .clone()
            .map(|i| (!skip(&pts[i])).then(|| move_collision(&scene, pts, i))?)
            .collect();
        if let Some((planned, limits)) = tilt {
            // Print moves that collide, or lead points the head collides at (no lift clears
            // those).
            let prints = found[lead + 1..].iter().any(Option::is_some)
                || (r.start..=r.start + lead)
                    .zip(&found)
                    .any(|(i, c)| c.is_some() && scene.at(pts[i].p, pts[i].axis).is_some());
            let checked = travels != Some(Travels::Skip);
            if let Some((axes, after)) = (prints && planned.len() == pts.len())
                .then(|| {
                    let planned = &planned[r.clone()];
                    tilt_run(
                        &scene,
                        pts,
                        r.clone(),
                        lead,
                        planned,
                        limits,
                        &found,
                        checked,
                    )
                })
                .flatten()
            {
                for (q, a) in pts[r.clone()].iter_mut().zip(axes) {
                    q.axis = a;
                }
                let n = found[lead + 1..]
                    .iter()
                    .zip(&after[lead + 1..])
                    .filter(|(b, a)| b.is_some() && a.is_none())
                    .count();
                *out.cleared.entry(pts[r.start].feature).or_default() += n;
                found = after;
            }
        }
        for c in found.into_iter().flatten() {
            let i = c.index;
            let via = match (c.kind, travels, i.checked_sub(1)) {
                (MoveKind::Travel, Some(Travels::Route), Some(j)) => {
                    detour(&scene, &pts[j], &pts[i], head)
                }
                _ => None,
            };
            match via {
                Some(via) => detours.push((i, via)),
                None => out.left.push(Collision {
                    index: i + 2 * detours.len(),
                    ..c
                }),
            }
        }
    }
    if !detours.is_empty() {
        let old = std::mem::take(&mut path.points);
        let mut points = Vec::with_capacity(old.len() + 2 * detours.len());
        let mut from = 0;
        for (i, via) in detours {
            points.extend_from_slice(&old[from..i]);
            points.extend(via);
            from = i;
        }
        points.extend_from_slice(&old[from..]);
        path.points = points;
    }
    out
}

/// The runs of `points` the walk tilts on their own, as index ranges covering every point once,
/// in order, each with its lead: the travel points of one feature and layer before the point
/// its bead starts from (the lead's count), that point, and the print points of that feature
/// and layer after it (the continuous path of `slicer::orient::continuous_paths`, with the
/// travel points that lead to it). Travel points followed by no bead are a run of their own.
pub(crate) fn runs(points: &[PathPoint]) -> Vec<(std::ops::Range<usize>, usize)> {
    let mut out = vec![];
    let mut start = 0;
    let next = |end: usize, kind: MoveKind| {
        end < points.len() && points[end].kind == kind && same_group(&points[end - 1], &points[end])
    };
    while start < points.len() {
        let mut end = start + 1;
        if points[start].kind == MoveKind::Travel {
            while next(end, MoveKind::Travel) {
                end += 1;
            }
        }
        let lead = end - 1 - start;
        while next(end, MoveKind::Print) {
            end += 1;
        }
        out.push((start..end, lead));
        start = end;
    }
    out
}

/// Two travel points lifting the head from `a` over the material and down onto `b`, clear of
/// everything, or `None` when no lift tried clears it.
fn detour(scene: &Scene, a: &PathPoint, b: &PathPoint, head: &Head) -> Option<[PathPoint; 2]> {
    let (ua, ub) = (unit(a.axis)?, unit(b.axis)?);
    // A head that collides at either end collides on every route between them.
    if scene.at(a.p, ua).is_some() || scene.at(b.p, ub).is_some() {
        return None;
    }
    let above = scene.deposit.z_max() - a.p[2].max(b.p[2]);
    let lifts = LIFTS
        .iter()
        .map(|f| f * head.body_length)
        .chain([above + TOLERANCE * 10.0, above + head.body_length]);
    for s in lifts {
        if !(s.is_finite() && s > 0.0) {
            continue;
        }
        // Both ends up their axes to one height, `s` over the higher: across level.
        let z = a.p[2].max(b.p[2]) + s;
        let up = add(a.p, scale(ua, (z - a.p[2]) / ua[2].max(0.1)));
        let over = add(b.p, scale(ub, (z - b.p[2]) / ub[2].max(0.1)));
        let clear = scene.sweep(a.p, ua, up, ua).is_none()
            && scene.sweep(up, ua, over, ub).is_none()
            && scene.sweep(over, ub, b.p, ub).is_none();
        if clear {
            let at = |p: V3, axis: V3| PathPoint {
                p,
                axis,
                e: 0.0,
                kind: MoveKind::Travel,
                ..*b
            };
            return Some([at(up, a.axis), at(over, b.axis)]);
        }
    }
    None
}

#[cfg(test)]
mod tests {
    use super::*;

    fn pt(feature: usize, layer: usize, kind: MoveKind, p: V3) -> PathPoint {
        PathPoint {
            feature,
            layer,
            kind,
            p,
            axis: [0.0, 0.0, 1.0],
            e: 0.0,
            thickness: 0.2,
            width: 0.45,
            role: toolpath::Role::Perimeter,
        }
    }

    /// A wall 5 mm tall (feature 0, lower than the head's body is above its tip), then travels
    /// from its top down to the plate 15 mm beside it and across, through the wall.
    fn wall_and_travel() -> ToolPath {
        let mut points = vec![];
        for layer in 0..25 {
            let z = 0.2 * (layer + 1) as f64;
            points.push(pt(0, layer, MoveKind::Travel, [0.0, -10.0, z]));
            points.push(pt(0, layer, MoveKind::Print, [0.0, 10.0, z]));
        }
        // From the wall's top to the far side at the plate, through the wall.
        points.push(pt(1, 0, MoveKind::Travel, [-15.0, 0.0, 0.2]));
        points.push(pt(1, 0, MoveKind::Travel, [15.0, 0.0, 0.2]));
        points.push(pt(1, 0, MoveKind::Print, [25.0, 0.0, 0.2]));
        ToolPath { points }
    }

    #[test]
    fn a_travel_through_a_wall_is_lifted_over_it() {
        let head = Head::default();
        let table = Some(Table::Plane { z: 0.0 });
        let path = wall_and_travel();
        let found = check(&path, &head, table);
        assert!(found
            .iter()
            .any(|c| c.kind == MoveKind::Travel && c.hits == Obstacle::Feature(0)));
        let mut routed = path.clone();
        let left = check_and_route(&mut routed, &head, table, Travels::Route);
        // Every travel through the wall got a detour, and nothing collides after it.
        assert!(left.is_empty(), "{left:?}");
        assert!(routed.points.len() > path.points.len());
        assert!(check(&routed, &head, table).is_empty());
        let top = routed
            .points
            .iter()
            .map(|q| q.p[2])
            .fold(f64::NEG_INFINITY, f64::max);
        assert!(top > 5.0, "the detour rises over the wall: {top}");
        // Skipped travels: neither checked nor changed.
        let mut skipped = path.clone();
        let left = check_and_route(&mut skipped, &head, table, Travels::Skip);
        assert_eq!(skipped, path);
        assert!(left.iter().all(|c| c.kind == MoveKind::Print));
    }
}
