//! The collision stage, between smoothing and the post (issue 18): the head of the machine
//! profile checked along every move against what was deposited before it and the table
//! (`collide`), colliding travels lifted over the material, and sibling features (the same
//! parents) printed layer by layer in turn where that leaves fewer collisions.

use crate::report::{round, CollisionEntry, FeatureReport, HitEntry};
use collide::{check_and_route, interleave, Collision, Obstacle, Table, Travels};
use robot_post::machine::MachineProfile;
use robot_post::placement::table_offset;
use robot_post::MachineKind;
use slicer::toolpath::ToolPath;
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
pub fn sibling_groups(features: &[FeatureReport]) -> Vec<Vec<usize>> {
    let mut groups: Vec<Vec<usize>> = vec![];
    for (i, f) in features.iter().enumerate() {
        let parents = &f.feature.parents;
        let joins = i > 0 && !parents.is_empty() && features[i - 1].feature.parents == *parents;
        match groups.last_mut() {
            Some(g) if joins => g.push(f.feature.id),
            _ => groups.push(vec![f.feature.id]),
        }
    }
    groups.retain(|g| g.len() > 1);
    groups
}

/// Checks `path` with the machine's head and table, lifting colliding travels (left to the
/// post on a KUKA cell, whose post makes its own); where print
/// moves hit siblings, tries the siblings interleaved and keeps that order when it leaves fewer
/// colliding moves. Returns the collisions left, in path order.
pub fn avoid(
    path: &mut ToolPath,
    machine: &MachineProfile,
    features: &[FeatureReport],
) -> Vec<Collision> {
    let head = machine.head;
    let table = table(path, machine);
    // The KUKA post makes its own travels (retreat, rise, cross, approach).
    let travels = match machine.kind {
        MachineKind::Kuka => Travels::Skip,
        _ => Travels::Route,
    };
    let groups = sibling_groups(features);
    let left = check_and_route(path, &head, Some(table), travels);
    // Groups one of whose members hits another.
    let crowded: Vec<&Vec<usize>> = groups
        .iter()
        .filter(|g| {
            left.iter().any(|c| {
                g.contains(&c.feature)
                    && matches!(c.hits, Obstacle::Feature(f) if f != c.feature && g.contains(&f))
            })
        })
        .collect();
    if crowded.is_empty() {
        return left;
    }
    // The travels lifted for the first order go along with their layers: still travels, checked
    // again in the new order.
    let mut mixed = path.clone();
    for g in crowded {
        if let Some(m) = interleave(&mixed, g) {
            mixed = m;
        }
    }
    let mixed_left = check_and_route(&mut mixed, &head, Some(table), travels);
    if mixed_left.len() < left.len() {
        *path = mixed;
        mixed_left
    } else {
        left
    }
}

/// Per feature id, its points in the tool path (travels lifted over material add some).
pub fn points(path: &ToolPath) -> BTreeMap<usize, usize> {
    let mut out = BTreeMap::new();
    for q in &path.points {
        *out.entry(q.feature).or_default() += 1;
    }
    out
}

/// Per feature id, its colliding moves and the first one, as `plan.json` reports them.
pub fn entries(collisions: &[Collision]) -> BTreeMap<usize, CollisionEntry> {
    let mut out: BTreeMap<usize, CollisionEntry> = BTreeMap::new();
    for c in collisions {
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
