//! Avoidance along the path: colliding travels re-routed over the material when a lift clears
//! them ([`check_and_route`]), colliding print moves tilted inside the orientation cone first
//! where asked ([`tilt_and_route`], [`tilt`]: [`crate::tilt`]), in one walk that checks every
//! move with [`crate::scene::Scene`].

use crate::head::Head;
use crate::scene::{move_collision, same_group, Collision, Obstacle, Scene, TOLERANCE};
use crate::table::Table;
use crate::tilt::{tilt_run, TiltLimits, Tilted};
use std::collections::BTreeMap;
use toolpath::vec3::{add, scale, unit, V3};
use toolpath::{MoveKind, PathPoint, ToolPath};
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

/// How far a walk goes.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Stop {
    /// To the path's end.
    #[default]
    AtEnd,
    /// To the end of the first run that leaves a move hitting the table (a check that only
    /// asks whether any does: the pedestal's search, where most heights tried fail).
    AtTableHit,
}

/// [`check`](crate::check()), re-routing each colliding travel over the material: from its start up its tool
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
    walk(path, head, table, Some(travels), None, Stop::AtEnd).left
}

/// What [`tilt_and_route`] leaves.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Routed {
    /// The colliding moves left, in path order (indices in the path as re-routed).
    pub left: Vec<Collision>,
    /// Per feature id, its print moves that collided with the axes given and are clear tilted.
    pub cleared: BTreeMap<usize, usize>,
    /// The walk stopped ([`Stop::AtTableHit`]) after the run of a move left hitting the table:
    /// the moves after that run were not checked (nor tilted, nor routed).
    pub stopped: bool,
}

/// [`check_and_route`], each continuous path first tilted inside the cone about its `planned`
/// axes (one per point of `path`) where that clears print moves ([`crate::tilt`]; no tilt
/// when `limits` is `None`), its travels then routed with the axes tilted: the whole
/// avoidance in one walk along the path, each move checked once against what lies before it;
/// the walk goes as far as `stop` says.
pub fn tilt_and_route(
    path: &mut ToolPath,
    planned: &[V3],
    head: &Head,
    table: Option<Table>,
    travels: Travels,
    limits: Option<&TiltLimits>,
    stop: Stop,
) -> Routed {
    walk(
        path,
        head,
        table,
        Some(travels),
        limits.map(|l| (planned, l)),
        stop,
    )
}

/// Tilts the tool axes of `path` inside the cone about `planned` (each point's planned axis,
/// before smoothing: one per point) to clear its colliding print moves, with `head` over
/// `table`; see [`crate::tilt`]. Points whose planned or given axis has no direction are
/// not tilted. A pure stage: `path` is not changed, and its travels are checked, not routed
/// ([`tilt_and_route`] does both in one walk).
pub fn tilt(
    path: &ToolPath,
    planned: &[V3],
    head: &Head,
    table: Option<Table>,
    limits: &TiltLimits,
) -> Tilted {
    let mut out = path.clone();
    let Routed { left, cleared, .. } = walk(
        &mut out,
        head,
        table,
        None,
        Some((planned, limits)),
        Stop::AtEnd,
    );
    Tilted {
        path: out,
        cleared,
        left,
    }
}

/// The walk along `path` behind [`check_and_route`], [`tilt_and_route`] and [`crate::tilt`]:
/// run by run (continuous paths), the material before each run's group deposited, its moves
/// checked, tilted by `tilt` (planned axes and limits) where that clears print moves (or the
/// head at the travel points leading to its bead), and its colliding travels routed by
/// `travels` (`None`: checked and reported, not routed); as far as `stop` says.
pub(crate) fn walk(
    path: &mut ToolPath,
    head: &Head,
    table: Option<Table>,
    travels: Option<Travels>,
    tilt: Option<(&[V3], &TiltLimits)>,
    stop: Stop,
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
        // The beads before are needed unless every move of the run (from the point before
        // it) stays above them with the axis up, untilted.
        if tilt.is_some() || !scene.above_pending(&pts[r.start.saturating_sub(1)..r.end]) {
            scene.flush(pts);
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
                *out.cleared
                    .entry(pts[r.start].feature as usize)
                    .or_default() += n;
                found = after;
            }
        }
        let left_before = out.left.len();
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
        let hits_table = |c: &Collision| c.hits == Obstacle::Table;
        if stop == Stop::AtTableHit && out.left[left_before..].iter().any(hits_table) {
            out.stopped = true;
            break;
        }
    }
    // What was deposited is not needed any more: its memory goes before the path grows.
    drop(scene);
    insert_detours(&mut path.points, &detours);
    out
}

/// Puts each detour's two points before the point of its index (`detours` in increasing index
/// order), in place: the path grows by their count and its points move back once each, from
/// the end, so no second copy of the path is held.
fn insert_detours(points: &mut Vec<PathPoint>, detours: &[(usize, [PathPoint; 2])]) {
    let Some(&(_, filler)) = detours.first() else {
        return;
    };
    let old = points.len();
    points.reserve_exact(2 * detours.len());
    points.resize(old + 2 * detours.len(), filler[0]);
    let mut end = old;
    for (k, (i, via)) in detours.iter().enumerate().rev() {
        // The points from `i` to `end` move back by the detours up to this one.
        let shift = 2 * (k + 1);
        points.copy_within(*i..end, i + shift);
        points[i + shift - 2..i + shift].copy_from_slice(via);
        end = *i;
    }
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
    let above = scene.z_max() - a.p[2].max(b.p[2]);
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
    use crate::scene::{check, test_point as pt, Scene};

    #[test]
    fn detours_go_in_place_before_their_points() {
        let p = |x: f64| pt(0, 0, MoveKind::Travel, [x, 0.0, 0.0]);
        let mut points: Vec<PathPoint> = (0..6).map(|x| p(x as f64)).collect();
        let detours = [
            (1, [p(10.0), p(11.0)]),
            (4, [p(40.0), p(41.0)]),
            (6, [p(60.0), p(61.0)]),
        ];
        insert_detours(&mut points, &detours);
        let xs: Vec<f64> = points.iter().map(|q| q.p[0]).collect();
        assert_eq!(
            xs,
            [0.0, 10.0, 11.0, 1.0, 2.0, 3.0, 40.0, 41.0, 4.0, 5.0, 60.0, 61.0]
        );
        insert_detours(&mut points, &[]);
        assert_eq!(points.len(), 12);
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

    /// Layers of a 12 mm wall (feature 0), then a second wall (feature 1) 15 mm beside it from
    /// the plate up, inside the reach of the head's body: its low layers hit the first wall.
    fn two_walls() -> ToolPath {
        let mut points = vec![];
        for (feature, x) in [(0, 0.0), (1, 15.0)] {
            for layer in 0..60 {
                let z = 0.2 * (layer + 1) as f64;
                points.push(pt(feature, layer, MoveKind::Travel, [x, -10.0, z]));
                points.push(pt(feature, layer, MoveKind::Print, [x, 10.0, z]));
                points.push(pt(feature, layer, MoveKind::Print, [x + 0.4, 10.0, z]));
                points.push(pt(feature, layer, MoveKind::Print, [x + 0.4, -10.0, z]));
            }
        }
        ToolPath { points }
    }

    /// The walk leaves beads pending while the head stays above them with its axis up (each
    /// layer of a wall over the last) and deposits them when a move may reach them: it finds
    /// exactly the collisions of the check that deposits every group at once.
    #[test]
    fn pending_beads_are_deposited_before_any_move_that_may_meet_them() {
        let head = Head::default();
        let table = Some(Table::Plane { z: 0.0 });
        let path = two_walls();
        let eager = check(&path, &head, table);
        assert!(eager
            .iter()
            .any(|c| c.feature == 1 && c.hits == Obstacle::Feature(0)));
        let mut walked = path.clone();
        let lazy = check_and_route(&mut walked, &head, table, Travels::Skip);
        assert_eq!(
            lazy,
            eager
                .iter()
                .filter(|c| c.kind == MoveKind::Print)
                .copied()
                .collect::<Vec<_>>()
        );
        // The first wall alone: nothing collides, and nothing had to be deposited.
        let first = ToolPath {
            points: path
                .points
                .iter()
                .filter(|q| q.feature == 0)
                .copied()
                .collect(),
        };
        let mut scene = Scene::new(&head, table);
        let pts = &first.points;
        for layer in 1..60 {
            scene.deposit(pts, 4 * (layer - 1)..4 * layer);
            assert!(scene.above_pending(&pts[4 * layer - 1..4 * (layer + 1)]));
        }
        assert_eq!(scene.deposit.z_max(), f64::NEG_INFINITY);
        assert!((scene.z_max() - 0.2 * 59.0).abs() < 1e-12);
        // A tilted axis, or a tip below the top, needs them.
        let mut tilted = pts[4 * 59..].to_vec();
        tilted[1].axis = [0.0, 0.1, 0.995];
        assert!(!scene.above_pending(&tilted));
        let mut low = pts[4 * 59..].to_vec();
        low[2].p[2] = 5.0;
        assert!(!scene.above_pending(&low));
        scene.flush(pts);
        assert_eq!(scene.deposit.z_max(), scene.z_max());
    }

    /// Beads on the plate laid with the axis lying down (the head's body under the table), two
    /// features apart: walked to the end, both hit the table; stopped at the first table hit,
    /// the walk reports the first run's and stops.
    #[test]
    fn a_walk_stops_at_its_first_table_hit_when_asked() {
        let head = Head::default();
        let table = Some(Table::Plane { z: 0.0 });
        let lying = unit([1.0, 0.0, 0.05]).unwrap_or([0.0, 0.0, 1.0]);
        let mut points = vec![];
        for (feature, y) in [(0, 0.0), (1, 60.0)] {
            points.push(pt(feature, 0, MoveKind::Travel, [0.0, y, 0.2]));
            for x in 1..4 {
                points.push(pt(feature, 0, MoveKind::Print, [f64::from(x), y, 0.2]));
            }
        }
        for q in &mut points {
            q.axis = lying;
        }
        let path = ToolPath { points };
        let walked = |stop: Stop| {
            let mut p = path.clone();
            tilt_and_route(&mut p, &[], &head, table, Travels::Skip, None, stop)
        };
        let whole = walked(Stop::AtEnd);
        assert!(!whole.stopped);
        let on_table = |r: &Routed, f: usize| {
            r.left
                .iter()
                .any(|c| c.feature == f && c.hits == Obstacle::Table)
        };
        assert!(
            on_table(&whole, 0) && on_table(&whole, 1),
            "{:?}",
            whole.left
        );
        let stopped = walked(Stop::AtTableHit);
        assert!(stopped.stopped);
        assert!(on_table(&stopped, 0) && !stopped.left.iter().any(|c| c.feature == 1));
        // Nothing on the table: the walk goes to the end either way.
        let mut up = path.clone();
        for q in &mut up.points {
            q.axis = [0.0, 0.0, 1.0];
        }
        let r = tilt_and_route(
            &mut up,
            &[],
            &head,
            table,
            Travels::Skip,
            None,
            Stop::AtTableHit,
        );
        assert!(!r.stopped && r.left.is_empty());
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
