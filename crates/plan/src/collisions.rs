//! The collision stage, between smoothing and the post (issue 18): the head of the machine
//! profile checked along every move against what was deposited before it and the table
//! (`collide`), colliding travels lifted over the material, sibling features (the same
//! parents) printed layer by layer in turn where that leaves fewer collisions, and colliding
//! print moves cleared by tilting the tool axis inside the orientation's tolerance cone.

use crate::report::{round, CollisionEntry, FeatureEntry, HitEntry};
use collide::{interleave, tilt_and_route, Collision, Obstacle, Stop, Table, TiltLimits, Travels};
use robot_post::machine::MachineProfile;
use robot_post::placement::table_offset;
use robot_post::MachineKind;
use slicer::orient::SmoothParams;
use slicer::toolpath::ToolPath;
use slicer::vec3::V3;
use std::collections::BTreeMap;

/// The machine's table in part coordinates, placed as the post will place the part: the lowest
/// bead bottom on the table surface; for delta5 the table disc centred on the C axis (the XY
/// bounding-box centre).
pub fn table(path: &ToolPath, machine: &MachineProfile) -> Table {
    let offset = table_offset(path);
    match (&machine.delta5, machine.kind) {
        (Some(g), MachineKind::Delta5) => Table::Disc {
            centre: [-offset[0], -offset[1]],
            z: -offset[2],
            radius: g.table_radius,
        },
        _ => Table::Plane { z: -offset[2] },
    }
}

/// Runs of features in build order with the same parents (siblings, none built on another),
/// two or more, as file-wide ids.
pub fn sibling_groups(features: &[FeatureEntry]) -> Vec<Vec<usize>> {
    let mut groups: Vec<Vec<usize>> = vec![];
    for (i, f) in features.iter().enumerate() {
        let parents = &f.parents;
        let joins = i > 0 && !parents.is_empty() && features[i - 1].parents == *parents;
        match groups.last_mut() {
            Some(g) if joins => g.push(f.id),
            _ => groups.push(vec![f.id]),
        }
    }
    groups.retain(|g| g.len() > 1);
    groups
}

/// What [`avoid`] leaves.
#[derive(Debug, Clone, Default)]
pub struct Avoided {
    /// The colliding moves left, in path order.
    pub left: Vec<Collision>,
    /// Per feature id, its print moves cleared by tilting the tool axis.
    pub cleared: BTreeMap<usize, usize>,
    /// The planned tool axes (before smoothing: the axes of the cones a tilt stays in) at the
    /// start and the end of each move of `left`, in its order (the start: the end's, for a
    /// path's first point).
    pub planned: Vec<[V3; 2]>,
    /// The walk stopped at a move left hitting the table ([`Stop::AtTableHit`]): the path
    /// hits it, and `left` holds the collisions up to there only.
    pub stopped: bool,
}

/// Header of `collisions.csv`: one line per colliding move left, `index` its end point's row
/// in `toolpath.csv` (0 the first point after the header), `hits` a feature id or `table`,
/// `x,y,z` where the head first meets it, `from_i,from_j,from_k` and
/// `planned_i,planned_j,planned_k` the planned tool axes at the move's start and end points
/// (before smoothing: the axes of the tolerance cones a tilt stays in).
pub const CSV_HEADER: &str =
    "index,feature,kind,hits,x,y,z,from_i,from_j,from_k,planned_i,planned_j,planned_k";

/// Writes `collisions.csv` (see [`CSV_HEADER`]) for the moves `avoided` leaves.
pub fn write_csv(avoided: &Avoided, w: &mut impl std::io::Write) -> std::io::Result<()> {
    writeln!(w, "{CSV_HEADER}")?;
    for (c, [f, a]) in avoided.left.iter().zip(&avoided.planned) {
        let hits = match c.hits {
            Obstacle::Feature(f) => f.to_string(),
            Obstacle::Table => "table".into(),
        };
        writeln!(
            w,
            "{},{},{},{hits},{:.6},{:.6},{:.6},{:.6},{:.6},{:.6},{:.6},{:.6},{:.6}",
            c.index,
            c.feature,
            c.kind.as_str(),
            c.at[0],
            c.at[1],
            c.at[2],
            f[0],
            f[1],
            f[2],
            a[0],
            a[1],
            a[2]
        )?;
    }
    Ok(())
}

/// The planned axes of each of `left`'s start and end points in `path` after avoidance, which holds the
/// points `before` (as given, `planned` their planned axes) in order with travel points lifted
/// over the material put between some: a point of `path` at the position of the next point
/// of `before` is that point; a lifted travel point takes its own axis.
fn planned_at(path: &ToolPath, before: &[V3], planned: &[V3], left: &[Collision]) -> Vec<[V3; 2]> {
    // The indices asked for, in order; each one's planned axis found in one walk along the
    // path (no list of every point's planned axis: 32 bytes a point of a long path).
    let mut wanted: Vec<usize> = left
        .iter()
        .flat_map(|c| [c.index.saturating_sub(1), c.index])
        .collect();
    wanted.sort_unstable();
    wanted.dedup();
    let mut found: Vec<(usize, V3)> = Vec::with_capacity(wanted.len());
    let mut next = wanted.iter().copied().peekable();
    let mut i = 0;
    for (k, q) in path.points.iter().enumerate() {
        let Some(&w) = next.peek() else { break };
        let own = i < before.len() && q.p == before[i];
        if k == w {
            let axis = own.then(|| planned.get(i).copied()).flatten();
            found.push((k, axis.unwrap_or(q.axis)));
            next.next();
        }
        if own {
            i += 1;
        }
    }
    let at = |k: usize| match found.binary_search_by_key(&k, |f| f.0) {
        Ok(j) => found[j].1,
        Err(_) => path.points.get(k).map_or([0.0, 0.0, 1.0], |q| q.axis),
    };
    left.iter()
        .map(|c| [at(c.index.saturating_sub(1)), at(c.index)])
        .collect()
}

/// How far [`avoid`] may tilt tool axes: inside the smoothing's tolerance cone, blended over its
/// window, within a B/C bed's B limit; `None` on a 3-axis printer (its tool axis is +Z only),
/// when smoothing is off (the planned axes are kept) or when its options are wrong.
pub fn tilt_limits(machine: &MachineProfile, orientation: &SmoothParams) -> Option<TiltLimits> {
    let turns = machine.kind != MachineKind::Marlin;
    (turns && orientation.enabled && orientation.validate().is_ok()).then(|| TiltLimits {
        cone_half_deg: 0.5 * orientation.cone_angle_deg,
        max_from_z_deg: machine
            .delta5_table()
            .ok()
            .map(|g| g.b_limits_deg[0].abs().max(g.b_limits_deg[1].abs())),
        window_mm: orientation.window_mm,
    })
}

/// Checks `path` with the machine's head and table in one walk along it: colliding print
/// moves tilted inside the cone about their `planned` axes (one per point of `path`, before
/// smoothing) by `limits` ([`collide::tilt`]; `None`: no tilt), then colliding travels lifted
/// (left to the post on a KUKA cell, whose post makes its own). Where print moves still hit
/// siblings, the siblings interleaved (their planned axes along) are walked alike, and that
/// order kept when it leaves fewer colliding moves; where every sibling group is crowded, that
/// walk is the one made beside the first, on the other thread. Returns the collisions left, in path order,
/// and the moves tilt cleared. With [`Stop::AtTableHit`] the walks stop at their first move
/// left hitting the table where that decides that the order kept would hit it too
/// ([`Avoided::stopped`]; a part of one sibling group at most: with more, the order kept
/// may be one no walk made whole).
pub fn avoid(
    path: &mut ToolPath,
    planned: &[V3],
    machine: &MachineProfile,
    features: &[FeatureEntry],
    limits: Option<TiltLimits>,
    stop: Stop,
) -> Avoided {
    let head = machine.head;
    let table = table(path, machine);
    // The KUKA post makes its own travels (retreat, rise, cross, approach).
    let travels = match machine.kind {
        MachineKind::Kuka => Travels::Skip,
        _ => Travels::Route,
    };
    let walk = |path: &mut ToolPath, planned: &[V3], stop: Stop| {
        // Where the points were before travel was lifted, to find their planned axes after;
        // without planned axes (a 3-axis printer) each point's own axis is its planned one.
        let before: Vec<V3> = if planned.is_empty() {
            vec![]
        } else {
            path.points.iter().map(|q| q.p).collect()
        };
        let r = tilt_and_route(
            path,
            planned,
            &head,
            Some(table),
            travels,
            limits.as_ref(),
            stop,
        );
        Avoided {
            planned: planned_at(path, &before, planned, &r.left),
            left: r.left,
            cleared: r.cleared,
            stopped: r.stopped,
        }
    };
    let groups = sibling_groups(features);
    if groups.is_empty() {
        // No order to try but the one built: walked in place, without copies of the path.
        return walk(path, planned, stop);
    }
    let stop = if groups.len() == 1 { stop } else { Stop::AtEnd };
    // The siblings interleaved: the path and its planned axes (a path of them interleaved
    // alike), `None` where no group interleaves.
    let mixed = |groups: &[&Vec<usize>]| {
        let mut mixed = path.clone();
        let mut mixed_planned = with_axes(path, planned);
        let mut any = false;
        for g in groups {
            if let (Some(m), Some(p)) = (interleave(&mixed, g), interleave(&mixed_planned, g)) {
                mixed = m;
                mixed_planned = p;
                any = true;
            }
        }
        let planned: Vec<V3> = mixed_planned.points.iter().map(|q| q.axis).collect();
        any.then_some((mixed, planned))
    };
    let walk_mixed = |groups: &[&Vec<usize>], stop: Stop| {
        mixed(groups).map(|(mut m, p)| {
            let w = walk(&mut m, &p, stop);
            (m, w)
        })
    };
    // Where the part has siblings, every group interleaved is walked beside the first walk
    // (the machine's other thread), in case the first leaves them all crowded.
    let all: Vec<&Vec<usize>> = groups.iter().collect();
    let mut first_path = path.clone();
    let (mut first, every) = rayon::join(
        || walk(&mut first_path, planned, stop),
        || walk_mixed(&all, stop),
    );
    // One group: the order kept is the first or `every`. Both hit the table where both
    // stopped (or nothing interleaves); where only the first did, it is walked whole to
    // choose.
    if first.stopped {
        if every.as_ref().is_none_or(|(_, w)| w.stopped) {
            *path = first_path;
            return first;
        }
        first_path = path.clone();
        first = walk(&mut first_path, planned, Stop::AtEnd);
    }
    // Groups one of whose members hits another.
    let crowded: Vec<&Vec<usize>> = groups
        .iter()
        .filter(|g| {
            first.left.iter().any(|c| {
                g.contains(&c.feature)
                    && matches!(c.hits, Obstacle::Feature(f) if f != c.feature && g.contains(&f))
            })
        })
        .collect();
    let second = match every {
        _ if crowded.is_empty() => None,
        // Stopped with already as many collisions as the first: not kept, whole or not.
        Some((_, done)) if done.stopped && done.left.len() >= first.left.len() => None,
        Some((_, done)) if done.stopped => walk_mixed(&crowded, Stop::AtEnd),
        Some(done) if crowded.len() == all.len() => Some(done),
        _ => walk_mixed(&crowded, Stop::AtEnd),
    };
    match second {
        Some((m, second)) if second.left.len() < first.left.len() => {
            *path = m;
            second
        }
        _ => {
            *path = first_path;
            first
        }
    }
}

/// `path` with the tool axes `axes` (one per point).
fn with_axes(path: &ToolPath, axes: &[V3]) -> ToolPath {
    let mut out = path.clone();
    for (q, &a) in out.points.iter_mut().zip(axes) {
        q.axis = a;
    }
    out
}

/// Per feature id, its points in the tool path (travels lifted over material add some).
pub fn points(path: &ToolPath) -> BTreeMap<usize, usize> {
    let mut out = BTreeMap::new();
    for q in &path.points {
        *out.entry(q.feature as usize).or_default() += 1;
    }
    out
}

/// Per feature id, its colliding moves, the first one and the moves tilt cleared, as
/// `plan.json` reports them.
pub fn entries(avoided: &Avoided) -> BTreeMap<usize, CollisionEntry> {
    let mut out: BTreeMap<usize, CollisionEntry> = BTreeMap::new();
    for (&id, &n) in &avoided.cleared {
        out.entry(id).or_default().collisions_cleared_by_tilt = n;
    }
    for c in &avoided.left {
        let e = out.entry(c.feature).or_default();
        e.collisions += 1;
        e.first_collision
            .get_or_insert_with(|| crate::report::FirstCollision {
                position: c.at.map(|x| round(x, 1e3)),
                hits: match c.hits {
                    Obstacle::Feature(f) => HitEntry::Feature(f),
                    Obstacle::Table => HitEntry::Named("table".into()),
                },
            });
    }
    out
}

/// One line per feature with colliding moves, for stderr and the warnings.
pub fn lines(entries: &BTreeMap<usize, CollisionEntry>) -> Vec<String> {
    entries
        .iter()
        .filter_map(|(id, e)| {
            let first = e.first_collision.as_ref()?;
            let [x, y, z] = first.position;
            let what = match &first.hits {
                HitEntry::Feature(f) => format!("feature {f}"),
                HitEntry::Named(n) => format!("the {n}"),
            };
            Some(format!(
                "feature {id}: {} colliding move(s) of the head, the first at ({x}, {y}, {z}) hitting {what}",
                e.collisions
            ))
        })
        .collect()
}
