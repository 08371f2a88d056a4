//! Avoidance by tilt (issue 18, item 3, its first step): the tool axis of a colliding print move
//! turned, inside the orientation's tolerance cone about the point's planned axis (the cone
//! smoothing keeps, `slicer::orient`), to an axis whose head clears what lies before the move
//! and the table, and the turn blended into the path's neighbouring points so the axes stay
//! continuous.
//!
//! Each run (a continuous path: the point a bead starts from and the print points after it,
//! one feature and layer, with the travel points of that feature and layer leading to it) is
//! tilted on its own, against the material deposited before its group (feature, layer), which
//! a tilt does not change:
//!
//! 1. **keys**: for each colliding print move, the smallest turn ω (a rotation vector: axis ×
//!    angle) of the point's axis that clears the move (its start turned by its own key where it
//!    has one, as the blend will turn it, else alike): first the turn of the nearest key, then
//!    rings of [`RING_STEP_DEG`] about the axis (every other one, then the one inside the
//!    first that clears), [`AZIMUTHS`] directions each, starting the way the nearest key turns
//!    (two turns the other way about would average to less than either between them), else
//!    towards +Z (away from the table); against the table, before the rings, the turns towards
//!    the allowed axis nearest +Z in steps of [`FINE_STEP_DEG`] (near the cone's rim the clear
//!    turns are too few for the rings' directions to meet). A turn is allowed when it keeps the axis within the
//!    cone (and a B/C bed's B limit) and differs from the keys beside it by at most the blend's
//!    slope ([`TiltLimits::slope`]). The bead's start, which a lift cannot clear when the head
//!    collides there, gets a key of its own on the same terms; so does each travel point
//!    leading to it, but bound to no other key (a travel lays no bead, and those points all
//!    lie at arc length 0, where the slope would force one turn on them all). Keys found in
//!    one pass lie [`KEY_SPACING_MM`] apart at least, and the search waits [`RETRY_MM`] after
//!    a move no turn clears (the moves it passed over are tried in the next pass). Against the
//!    table, a move no one turn clears (its ends need different turns) gets a key at its start
//!    first, the least turn towards the highest allowed axis that clears the head there, or
//!    both ends that axis, and is searched again; a key at its start that holds its turn back
//!    by the slope is moved to its turn. Where a key's move still collides and the key's turn
//!    is not allowed at the point before, that point gets the least turn clearing the head
//!    there; so does a key's own point where the head still meets something;
//! 2. **blend**: the turn field along the path, linear in arc length between keys closer than
//!    two windows, held from the bead's start (and its lead) to a first key that close,
//!    falling to nothing over one window (the smoothing's `window_mm`) beyond the outer keys
//!    ([`blend`]); each point's axis turned by it (a lead travel point with a key of its own,
//!    by that), scaled back where it would leave the cone or the B limit;
//! 3. **check again**, with new keys where moves still collide, a few passes; the run keeps
//!    its tilt only when every move that collides after it collided before it and fewer do.

use crate::scene::{move_hit, Collision, Obstacle, Scene};
use crate::tolerance::{ANGLE_SLACK, TURN_ZERO, WINDOW_FLOOR};
use std::collections::BTreeMap;
use std::ops::Range;
use toolpath::vec3::{add, cross, dot, norm, scale, sub, unit, V3};
use toolpath::{PathPoint, ToolPath};

/// Angle between rings of axes tried about a colliding point's axis, degrees.
pub const RING_STEP_DEG: f64 = 5.0;

/// Step, degrees, of the turns tried towards the allowed axis nearest +Z where the head meets
/// the table.
pub const FINE_STEP_DEG: f64 = 1.0;

/// Directions tried on each ring.
pub const AZIMUTHS: usize = 8;

/// Length of path, mm, after a point no turn clears before the search is tried again.
pub const RETRY_MM: f64 = 1.0;

/// Least length of path, mm, between keys found in one pass.
pub const KEY_SPACING_MM: f64 = 1.0;

/// Passes of key search, blend and check per continuous path.
const PASSES: usize = 4;

/// What a tilt may do.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TiltLimits {
    /// Half the opening of the tolerance cone about each point's planned axis, degrees: γ/2 of
    /// the orientation smoothing (`cone_angle_deg / 2`).
    pub cone_half_deg: f64,
    /// Largest angle of an axis from +Z, degrees (a B/C bed's B limit); `None`: no limit. An
    /// axis already beyond it may be tilted, but not farther from +Z.
    pub max_from_z_deg: Option<f64>,
    /// Length of path, mm, over which a tilt is blended into its neighbours: the smoothing's
    /// window, so the turn per mm stays within `2 · cone_half_deg / window_mm`.
    pub window_mm: f64,
}

impl TiltLimits {
    /// The largest change of the turn field per mm of path, radians: two cone half-angles (the
    /// most a turn inside the cone can be) over one window.
    pub fn slope(&self) -> f64 {
        2.0 * self.cone_half_deg.to_radians() / self.window_mm.max(WINDOW_FLOOR)
    }
}

/// A path after [`tilt`](crate::tilt()).
#[derive(Debug, Clone)]
pub struct Tilted {
    /// The path, its tool axes tilted where that clears moves (positions and all else as
    /// given).
    pub path: ToolPath,
    /// Per feature id, its print moves that collided as given and are clear tilted.
    pub cleared: BTreeMap<usize, usize>,
    /// The colliding moves left, in path order, as [`crate::scene::check`] finds them on `path`.
    pub left: Vec<Collision>,
}

/// `v` turned by the rotation vector `w` (Rodrigues).
fn rotate(v: V3, w: V3) -> V3 {
    let t = norm(w);
    if t < TURN_ZERO {
        return v;
    }
    let k = scale(w, 1.0 / t);
    let (s, c) = t.sin_cos();
    add(
        add(scale(v, c), scale(cross(k, v), s)),
        scale(k, dot(k, v) * (1.0 - c)),
    )
}

/// Angle between unit vectors, radians.
fn angle(a: V3, b: V3) -> f64 {
    norm(cross(a, b)).atan2(dot(a, b))
}

/// The allowed axes at one point: within the cone about its planned axis, and within the B
/// limit (or no farther from +Z than the given axis already is).
struct Allowed {
    planned: V3,
    half: f64,
    from_z: f64,
}

impl Allowed {
    fn new(planned: V3, given: V3, limits: &TiltLimits) -> Allowed {
        let from_z = limits.max_from_z_deg.map_or(f64::INFINITY, |b| {
            b.to_radians().max(angle(given, [0.0, 0.0, 1.0]))
        });
        Allowed {
            planned,
            half: limits.cone_half_deg.to_radians(),
            from_z,
        }
    }

    fn holds(&self, a: V3) -> bool {
        angle(a, self.planned) <= self.half + ANGLE_SLACK
            && (self.from_z.is_infinite() || angle(a, [0.0, 0.0, 1.0]) <= self.from_z + ANGLE_SLACK)
    }

    /// The allowed axis nearest +Z: the most a tilt can lift the head off the table.
    fn highest(&self) -> V3 {
        let z = [0.0, 0.0, 1.0];
        let off = angle(self.planned, z);
        if off <= self.half {
            return z;
        }
        let towards = cross(self.planned, z);
        match unit(towards) {
            Some(k) => rotate(self.planned, scale(k, self.half)),
            None => self.planned,
        }
    }
}

/// One continuous path's tilted axes and its moves' collisions after them, or `None` when no
/// tilt leaves fewer colliding moves without a new one. The run `r` holds `lead` travel
/// points before the point its bead starts from (`r.start + lead`); `before[k]` is the
/// collision of the move ending at `r.start + k` as given; `planned` is the run's planned
/// axes; the travel moves into the run's lead and bead start are checked when `travels`.
#[allow(clippy::too_many_arguments)]
pub(crate) fn tilt_run(
    scene: &Scene,
    pts: &[PathPoint],
    r: Range<usize>,
    lead: usize,
    planned: &[V3],
    limits: &TiltLimits,
    before: &[Option<Collision>],
    travels: bool,
) -> Option<(Vec<V3>, Vec<Option<Collision>>)> {
    let run = &pts[r.clone()];
    let given: Vec<V3> = run.iter().map(|q| unit(q.axis)).collect::<Option<_>>()?;
    let planned: Vec<V3> = planned.iter().map(|&a| unit(a)).collect::<Option<_>>()?;
    let allowed: Vec<Allowed> = planned
        .iter()
        .zip(&given)
        .map(|(&p, &g)| Allowed::new(p, g, limits))
        .collect();
    // Arc length along the bead, its start and the travel points before it at 0.
    let mut s = vec![0.0; run.len()];
    for k in lead + 1..run.len() {
        s[k] = s[k - 1] + norm(sub(run[k].p, run[k - 1].p));
    }
    let mut keys: BTreeMap<usize, V3> = BTreeMap::new();
    // The lead's travel points before the bead start: a travel does not lay a bead, so each
    // takes a turn of its own, bound neither to the bead's keys nor to each other (they all lie
    // at arc length 0, where the slope would demand one turn for all).
    let mut lead_keys: BTreeMap<usize, V3> = BTreeMap::new();
    let mut tried = vec![false; run.len()];
    // Points before a key given the least turn that clears the head there (see below).
    let mut lifted = vec![false; run.len()];
    let mut axes = given.clone();
    let mut now: Vec<Option<Collision>> = before.to_vec();
    let cx = Run {
        scene,
        run,
        given: &given,
        allowed: &allowed,
        s: &s,
        limits,
        lead,
    };
    for _ in 0..PASSES {
        let (added, waited) = find_keys(
            &cx,
            &now,
            &axes,
            (&mut keys, &mut lead_keys),
            (&mut tried, &mut lifted),
        );
        if !added {
            if waited {
                continue;
            }
            break;
        }
        let field = blend(&keys, &s, limits.window_mm);
        let last = axes.clone();
        for k in 0..run.len() {
            let w = lead_keys.get(&k).copied().unwrap_or(field[k]);
            axes[k] = apply(given[k], w, &allowed[k]);
        }
        let mut moved: Vec<PathPoint> = run.to_vec();
        for (q, &a) in moved.iter_mut().zip(&axes) {
            q.axis = a;
        }
        // Only the moves whose ends turned are checked again.
        let turned = |k: usize| axes[k] != last[k];
        now = (0..run.len())
            .map(|k| {
                if !(turned(k) || k > 0 && turned(k - 1)) {
                    return now[k];
                }
                let from = match k {
                    _ if k <= lead && !travels => return None,
                    0 => r.start.checked_sub(1).map(|j| &pts[j]),
                    _ => Some(&moved[k - 1]),
                };
                move_hit(scene, from, &moved[k], r.start + k)
            })
            .collect();
    }
    let new = now
        .iter()
        .zip(before)
        .any(|(a, b)| a.is_some() && b.is_none());
    let fewer = now.iter().flatten().count() < before.iter().flatten().count();
    (fewer && !new).then_some((axes, now))
}

/// One pass of key search along a run: for each move still colliding (`now`) at the axes
/// `axes`, a key (a turn) that clears it, searched where none was yet; the travel points of the
/// lead take keys of their own. Whether a key was added, and whether the search waited over
/// moves after one it found no turn for.
fn find_keys(
    cx: &Run,
    now: &[Option<Collision>],
    axes: &[V3],
    (keys, lead_keys): (&mut BTreeMap<usize, V3>, &mut BTreeMap<usize, V3>),
    (tried, lifted): (&mut [bool], &mut [bool]),
) -> (bool, bool) {
    let Run {
        scene,
        run,
        given,
        allowed,
        s,
        limits,
        lead,
    } = *cx;
    let none: BTreeMap<usize, V3> = BTreeMap::new();
    let mut added = false;
    // Where the last search along the bead found no turn: the moves just after it mostly
    // meet the same obstacle, so the search waits [`RETRY_MM`] of path; those it passed
    // over are tried in the next pass.
    let mut failed: Option<f64> = None;
    let mut waited = false;
    // The last key found in this pass: moves closer after it than [`KEY_SPACING_MM`] wait
    // for the blend, and are searched in the next pass if it leaves them colliding.
    let mut found: Option<f64> = None;
    for k in 0..run.len() {
        let Some(c) = now[k] else { continue };
        // Print moves; and travels into the lead or the bead start where the head
        // collides at the point itself (no lift clears that).
        let point = k <= lead && scene.at(run[k].p, axes[k]).is_some();
        if k <= lead && !point {
            continue;
        }
        if k < lead {
            if lead_keys.contains_key(&k) || tried[k] {
                continue;
            }
            tried[k] = true;
            let at = Candidate {
                k,
                lead,
                hits: c.hits,
            };
            if let Some(w) = search(scene, run, given, allowed, &none, s, at, limits) {
                lead_keys.insert(k, w);
                added = true;
            }
            continue;
        }
        // A key on the bead that still collides (its move starts from a blended axis):
        // the point before it takes the same turn.
        let (k, w, ahead) = match keys.get(&k) {
            Some(&w)
                if k > lead
                    && !keys.contains_key(&(k - 1))
                    && allowed[k - 1].holds(rotate(given[k - 1], w))
                    && near(keys, s, k - 1, w, limits) =>
            {
                (k - 1, Some(w), true)
            }
            // Or a turn of its own, if none was searched there yet, or none that clears
            // the head at the point alone.
            Some(_)
                if k > lead && !keys.contains_key(&(k - 1)) && !(tried[k - 1] && lifted[k - 1]) =>
            {
                (k - 1, None, true)
            }
            // Or, where the head meets something at the key's point itself, the least turn
            // that clears it there.
            Some(_) if !lifted[k] && scene.at(run[k].p, axes[k]).is_some() => (k, None, true),
            Some(_) => continue,
            None if tried[k] => continue,
            None if k > lead && failed.is_some_and(|f| s[k] - f < RETRY_MM) => {
                waited = true;
                continue;
            }
            None if k > lead && found.is_some_and(|f| s[k] - f < KEY_SPACING_MM) => continue,
            None => (k, None, false),
        };
        let searched = std::mem::replace(&mut tried[k], true);
        let w = w.or_else(|| {
            if searched {
                return None;
            }
            let at = Candidate {
                k,
                lead,
                hits: c.hits,
            };
            search(scene, run, given, allowed, keys, s, at, limits)
        });
        // Against the table, a move no one turn clears (its start needs a larger turn than
        // its end allows, or the other way about): its start gets a key of its own first,
        // the least turn towards the allowed axis nearest +Z that clears the head there,
        // and the move is searched again from it.
        let w = match w {
            None if !searched
                && c.hits == Obstacle::Table
                && k > lead
                && !keys.contains_key(&(k - 1)) =>
            {
                key_at_start(cx, keys, k, c.hits)
            }
            // Or, where the key at its start holds the turn back (the slope between them),
            // one turn for both: that key moved to it.
            None if !searched && c.hits == Obstacle::Table && k > lead => {
                key_moved_to(cx, keys, k, c.hits)
            }
            w => w,
        };
        // The point before a key whose move still collides, when no turn clears the move
        // into it: turned so the head clears it there at least, which the move from it
        // needs.
        let w = match w {
            None if ahead && !std::mem::replace(&mut lifted[k], true) => {
                lift_before_key(cx, keys, k)
            }
            w => w,
        };
        match w {
            Some(w) => {
                keys.insert(k, w);
                found = Some(s[k]);
                added = true;
            }
            None => failed = Some(s[k]),
        }
    }
    (added, waited)
}

/// What one continuous path's key search reads: the scene, the run (`lead` travel points
/// before its bead start), its given axes and allowed axes, its arc lengths and the limits.
#[derive(Clone, Copy)]
struct Run<'a> {
    scene: &'a Scene,
    run: &'a [PathPoint],
    given: &'a [V3],
    allowed: &'a [Allowed],
    s: &'a [f64],
    limits: &'a TiltLimits,
    lead: usize,
}

/// Against the table, a move `k` no one turn clears: its start gets a key of its own first, the
/// least turn towards the allowed axis nearest +Z that clears the head there, and the move is
/// searched again from it; else both ends turned all the way to their highest allowed axes.
fn key_at_start(cx: &Run, keys: &mut BTreeMap<usize, V3>, k: usize, hits: Obstacle) -> Option<V3> {
    let Run {
        scene,
        run,
        given,
        allowed,
        s,
        limits,
        lead,
    } = *cx;
    let start = lift(scene, run[k - 1].p, given[k - 1], &allowed[k - 1], |w| {
        near(keys, s, k - 1, w, limits)
    });
    start
        .and_then(|w0| {
            keys.insert(k - 1, w0);
            let at = Candidate { k, lead, hits };
            let w = search(scene, run, given, allowed, keys, s, at, limits);
            if w.is_none() {
                keys.remove(&(k - 1));
            }
            w
        })
        .or_else(|| {
            // Else both ends turned all the way to their highest allowed axes.
            let w0 = towards(given[k - 1], allowed[k - 1].highest());
            let w1 = towards(given[k], allowed[k].highest());
            let (a0, a1) = (rotate(given[k - 1], w0), rotate(given[k], w1));
            let clear = near(keys, s, k - 1, w0, limits)
                && (k - 1 > lead || scene.at(run[k - 1].p, a0).is_none())
                && scene.sweep(run[k - 1].p, a0, run[k].p, a1).is_none();
            if !clear {
                return None;
            }
            keys.insert(k - 1, w0);
            if near(keys, s, k, w1, limits) {
                Some(w1)
            } else {
                keys.remove(&(k - 1));
                None
            }
        })
}

/// Where the key at the start of move `k` holds the turn back (the slope between them), one
/// turn for both: that key moved to it.
fn key_moved_to(cx: &Run, keys: &mut BTreeMap<usize, V3>, k: usize, hits: Obstacle) -> Option<V3> {
    let Run {
        scene,
        run,
        given,
        allowed,
        s,
        limits,
        lead,
    } = *cx;
    let old = keys.remove(&(k - 1));
    let at = Candidate { k, lead, hits };
    let w = search(scene, run, given, allowed, keys, s, at, limits).filter(|&w| {
        allowed[k - 1].holds(rotate(given[k - 1], w)) && near(keys, s, k - 1, w, limits)
    });
    match (w, old) {
        (Some(w), _) => {
            keys.insert(k - 1, w);
        }
        (None, Some(old)) => {
            keys.insert(k - 1, old);
        }
        (None, None) => {}
    }
    w
}

/// The point `k` before a key whose move still collides, when no turn clears the move into it:
/// turned so the head clears it there at least, which the move from it needs.
fn lift_before_key(cx: &Run, keys: &mut BTreeMap<usize, V3>, k: usize) -> Option<V3> {
    let Run {
        scene,
        run,
        given,
        allowed,
        s,
        limits,
        lead,
    } = *cx;
    lift(scene, run[k].p, given[k], &allowed[k], |w| {
        near(keys, s, k, w, limits)
    })
    .or_else(|| {
        // Where the key just before it holds the turn back (the slope between
        // them), that key moved to the same turn.
        let j = k.checked_sub(1).filter(|&j| j >= lead)?;
        let old = keys.remove(&j)?;
        let w = lift(scene, run[k].p, given[k], &allowed[k], |w| {
            near(keys, s, k, w, limits)
                && allowed[j].holds(rotate(given[j], w))
                && near(keys, s, j, w, limits)
        });
        keys.insert(j, w.unwrap_or(old));
        w
    })
}

/// The least turn of the axis `a` at `tip`, towards the allowed axis nearest +Z in steps of
/// [`FINE_STEP_DEG`], that keeps it allowed, passes `fits` and clears the head there; `None`
/// when none does (at once when that axis meets the table).
fn lift(scene: &Scene, tip: V3, a: V3, allowed: &Allowed, fits: impl Fn(V3) -> bool) -> Option<V3> {
    let h = allowed.highest();
    if !allowed.holds(a) || scene.hits_table(tip, h) {
        return None;
    }
    let full = angle(a, h);
    let about = unit(cross(a, h))?;
    let n = (full / FINE_STEP_DEG.to_radians()).ceil() as usize;
    (1..=n)
        .map(|i| scale(about, full * i as f64 / n as f64))
        .find(|&w| {
            let b = rotate(a, w);
            allowed.holds(b) && fits(w) && scene.at(tip, b).is_none()
        })
}

/// The turn (rotation vector) that takes the unit axis `a` to the unit axis `b` the short way.
fn towards(a: V3, b: V3) -> V3 {
    unit(cross(a, b)).map_or([0.0; 3], |k| scale(k, angle(a, b)))
}

/// Whether the turn `w` at `k` differs from the keys beside it (each side's nearest) by at most
/// the blend's slope times their distance along the path, where they are close enough (two
/// windows) to be blended linearly with it.
fn near(keys: &BTreeMap<usize, V3>, s: &[f64], k: usize, w: V3, limits: &TiltLimits) -> bool {
    let prev = keys.range(..k).next_back();
    let next = keys.range(k + 1..).next();
    [prev, next].into_iter().flatten().all(|(&j, &wj)| {
        let gap = (s[j] - s[k]).abs();
        gap > 2.0 * limits.window_mm || norm(sub(w, wj)) <= limits.slope() * gap + ANGLE_SLACK
    })
}

/// The point of a run a turn is searched for: its index `k`, the run's lead (travel points
/// before the bead start) and what the head hits there.
struct Candidate {
    k: usize,
    lead: usize,
    hits: Obstacle,
}

/// The smallest turn of the axis at `run[at.k]` that clears the print move ending there (its
/// start point turned alike, and clear itself when it starts the bead), or on the lead and the
/// bead start the head at the point; allowed there and within the blend's slope of the keys
/// beside it. `None` when no turn tried clears it, or the axis given is not allowed. Against
/// the table, the allowed axis nearest +Z is tried first: the head's lowest point rises with
/// the axis's height, so if that one meets the table plane, every allowed axis does.
#[allow(clippy::too_many_arguments)]
fn search(
    scene: &Scene,
    run: &[PathPoint],
    given: &[V3],
    allowed: &[Allowed],
    keys: &BTreeMap<usize, V3>,
    s: &[f64],
    at: Candidate,
    limits: &TiltLimits,
) -> Option<V3> {
    let Candidate { k, lead, hits } = at;
    let a = given[k];
    if !allowed[k].holds(a)
        || (hits == Obstacle::Table && scene.hits_table(run[k].p, allowed[k].highest()))
    {
        return None;
    }
    let prev = keys.range(..k).next_back();
    let next = keys.range(k + 1..).next();
    let near = |w: V3| near(keys, s, k, w, limits);
    let clears = |w: V3| {
        let b = rotate(a, w);
        if !allowed[k].holds(b) || !near(w) {
            return false;
        }
        if k <= lead {
            return scene.at(run[k].p, b).is_none();
        }
        // The move's start turned as the blend will turn it: by its own key, where it has one
        // (the blend passes through keys), else alike. The bead's start ends a travel; the
        // sweep leaves it out.
        let from_turn = keys.get(&(k - 1)).copied().unwrap_or(w);
        let from = (run[k - 1].p, rotate(given[k - 1], from_turn));
        (k > lead + 1 || scene.at(from.0, from.1).is_none())
            && scene.sweep(from.0, from.1, run[k].p, b).is_none()
    };
    // The nearest key's turn first: neighbours tilted alike keep the axes continuous.
    let nearest = [prev, next]
        .into_iter()
        .flatten()
        .min_by(|x, y| (s[*x.0] - s[k]).abs().total_cmp(&(s[*y.0] - s[k]).abs()));
    if let Some((_, &w)) = nearest {
        if clears(w) {
            return Some(w);
        }
    }
    // Against the table, the way to the allowed axis nearest +Z, in fine steps: the head's
    // lowest point rises with the axis's height, and near the cone's rim the clear turns are
    // too few for the rings' directions to meet.
    if hits == Obstacle::Table {
        let h = allowed[k].highest();
        let full = angle(a, h);
        if let Some(about) = unit(cross(a, h)) {
            let n = (full / FINE_STEP_DEG.to_radians()).ceil() as usize;
            if let Some(w) = (1..=n)
                .map(|i| scale(about, full * i as f64 / n as f64))
                .find(|&w| clears(w))
            {
                return Some(w);
            }
        }
    }
    // Directions across the axis, the first the way the nearest key turns (keys turned alike
    // keep the blend between them clear: two turns the other way about average to less than
    // either), else towards +Z.
    let up = sub([0.0, 0.0, 1.0], scale(a, a[2]));
    let along = nearest.and_then(|(_, &w)| {
        let d = cross(w, a);
        unit(sub(d, scale(a, dot(a, d))))
    });
    let e1 = along
        .or_else(|| unit(up))
        .or_else(|| unit(cross(a, [1.0, 0.0, 0.0])))
        .or_else(|| unit(cross(a, [0.0, 1.0, 0.0])))?;
    let e2 = cross(a, e1);
    let most = 2.0 * allowed[k].half;
    let ring = |t: f64| {
        (0..AZIMUTHS).find_map(|j| {
            let phi = std::f64::consts::TAU * j as f64 / AZIMUTHS as f64;
            let d = add(scale(e1, phi.cos()), scale(e2, phi.sin()));
            let w = scale(cross(a, d), t);
            clears(w).then_some(w)
        })
    };
    // Every other ring first (a move no turn clears costs half the rings), then the ring
    // inside the first that clears.
    let step = RING_STEP_DEG.to_radians();
    let rings = (most / step).ceil() as usize;
    (2..=rings + 1).step_by(2).find_map(|n| {
        let t = (n as f64 * step).min(most);
        let w = ring(t)?;
        Some(ring((n - 1) as f64 * step).unwrap_or(w))
    })
}

/// The turn field along a run with arc lengths `s`, from its keys (index → turn): between two
/// keys at most two windows apart, linear in arc length from one to the other; from the run's
/// start to a first key at most two windows along, that key's turn; elsewhere each key's turn
/// falling linearly to nothing over one window. Continuous, and its change per mm
/// is at most the keys' largest turn over `window`, or the change between two keys over their
/// distance.
pub fn blend(keys: &BTreeMap<usize, V3>, s: &[f64], window: f64) -> Vec<V3> {
    let w = window.max(WINDOW_FLOOR);
    (0..s.len())
        .map(|j| {
            let prev = keys.range(..=j).next_back();
            let next = keys.range(j..).next();
            match (prev, next) {
                // From the run's first point (where its bead starts, after a travel) to a key
                // within two windows, that key's turn is held.
                (None, Some((&i1, &w1))) if s[i1] - s[0] <= 2.0 * w => w1,
                (Some((&i0, &w0)), Some((&i1, &w1))) if s[i1] - s[i0] <= 2.0 * w => {
                    let gap = s[i1] - s[i0];
                    if gap <= 0.0 {
                        return w0;
                    }
                    let t = (s[j] - s[i0]) / gap;
                    add(scale(w0, 1.0 - t), scale(w1, t))
                }
                _ => {
                    let ramp = |key: Option<(&usize, &V3)>| {
                        key.map_or([0.0; 3], |(&i, &wi)| {
                            scale(wi, (1.0 - (s[j] - s[i]).abs() / w).max(0.0))
                        })
                    };
                    add(ramp(prev), ramp(next))
                }
            }
        })
        .collect()
}

/// `a` turned by `w`, or by the largest share of `w` (halved down to a 256th) that stays
/// allowed; `a` itself when it is not allowed.
fn apply(a: V3, w: V3, allowed: &Allowed) -> V3 {
    if norm(w) < TURN_ZERO || !allowed.holds(a) {
        return a;
    }
    let b = rotate(a, w);
    if allowed.holds(b) {
        return b;
    }
    // Bisect the share.
    let (mut lo, mut hi) = (0.0, 1.0);
    for _ in 0..8 {
        let mid = 0.5 * (lo + hi);
        if allowed.holds(rotate(a, scale(w, mid))) {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    rotate(a, scale(w, lo))
}

#[cfg(test)]
mod tests;
