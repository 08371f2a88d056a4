//! Support material under the planar layers of a two5d feature (issue 33, item 3): where the
//! support check ([`crate::support`]) finds pieces of a layer that the layer below does not
//! hold within the overhang limit, columns are built under them, top down, in the feature's
//! own layers (same heights, tool axis along the layers' normal) and filled with sparse lines.
//!
//! - **A column** starts under its piece, `support_contact_distance` below it (whole layers:
//!   those layers stay empty under the held surface), and goes down layer by layer. Where the
//!   part's own section lies under it, that much of the column lands and stops (a column over a
//!   lower step of the part stands on it); the rest goes on down to the plate.
//! - **What is printed** of a column in a layer is the column less the part's section there
//!   grown by `support_xy_distance`; the top `support_interface_layers` printed layers of each
//!   column are interface (denser lines), the rest sparse lines at `support_density`.
//! - **What it stands on**: support stands only on the plate or on the feature's own lower
//!   layers. A base feature on the plate carries every piece, and so does the base of a solid
//!   lifted over the plate: its columns go on below its first layer ([`crate::support_below`]).
//!   A feature growing from others carries only the part of a piece over its own lower layers
//!   or its parents (its sections up to the piece's layer): what would need a column reaching
//!   below its first layer is not supported, and stays unsupported (the gate refuses it).
//!
//! Only the feature's own sections are known here: a column is not kept out of another
//! feature's material at the same height (features are planned one at a time).

use crate::fill::{difference, grow, intersection, simplified, union, Region};
use crate::geom2d::{dist, region_area, Point2};
use crate::params::{LayerParams, PathMode};
use crate::region_fill::FillPath;
use crate::tolerance::HEIGHT_SLACK;
use crate::toolpath::Role;
use rayon::prelude::*;
use std::collections::VecDeque;
use std::time::Instant;

/// Where support is printed in each layer of a feature, in its reference plane's 2-D frame.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct SupportRegions {
    /// Each layer's sparse support (one entry a layer, empty where none).
    pub sparse: Vec<Vec<Region>>,
    /// Each layer's interface support, right under a held surface.
    pub interface: Vec<Vec<Region>>,
    /// The thicknesses (bottom up) of the layers below the feature's reference plane, for
    /// a solid lifted over the plate ([`crate::support_below`]): the first `below.len()`
    /// entries of `sparse` and `interface` are theirs, laid before the feature's first layer.
    pub below: Vec<f64>,
}

impl SupportRegions {
    /// True when no layer has any support.
    pub fn is_empty(&self) -> bool {
        self.sparse.iter().chain(&self.interface).all(Vec::is_empty)
    }

    /// The area of support summed over the layers, mm² (sparse and interface).
    pub fn area(&self) -> f64 {
        self.sparse
            .iter()
            .chain(&self.interface)
            .flatten()
            .map(region_area)
            .sum()
    }
}

/// What the columns under a feature's overhangs do ([`columns`]).
#[derive(Debug, Clone, Default)]
pub struct Columns {
    /// Where support is printed.
    pub regions: SupportRegions,
    /// Each layer's area left unsupported (mm², pieces of `sliver` mm² or more): what would
    /// need a column below the feature's first layer.
    pub left: Vec<f64>,
}

/// The columns under the unsupported `pieces` of each layer (same indexing as `sections`, the
/// part's section of each layer, and `heights`, the layers' thicknesses), top down. `ground`
/// `None`: the feature's first layer stands on the plate (a column may reach it anywhere);
/// else what its first layer rests on, and only what lies over it or over the feature's own
/// lower sections is carried. Pieces left unsupported under `sliver` mm² are not counted.
/// Nothing is generated when `support_material` is `off`. Past `stop_at` (checked layer by
/// layer) the columns are given up ([`Stopped`]).
pub fn columns(
    sections: &[Vec<Region>],
    heights: &[f64],
    pieces: &[Vec<Region>],
    ground: Option<&[Region]>,
    params: &LayerParams,
    sliver: f64,
    stop_at: Option<Instant>,
) -> Result<Columns, Stopped> {
    let n = sections.len().min(heights.len()).min(pieces.len());
    let tol = params.tolerance;
    let area = |r: &[Region]| -> f64 {
        r.iter()
            .map(region_area)
            .filter(|a| *a >= sliver)
            .sum::<f64>()
    };
    let mut out = Columns {
        regions: SupportRegions {
            sparse: vec![vec![]; n],
            interface: vec![vec![]; n],
            below: vec![],
        },
        left: vec![0.0; n],
    };
    // Bottom of each layer over the feature's reference plane.
    let mut bottoms = Vec::with_capacity(n);
    let mut z = 0.0;
    for &h in &heights[..n] {
        bottoms.push(z);
        z += h;
    }
    // Where each column enters: the highest layer whose top lies `contact` or more below the
    // piece; `None` when no layer does (the plate, or the material under the first layer).
    let contact = params.support_contact_distance;
    let entry = |k: usize| -> Option<usize> {
        (0..k)
            .rev()
            .find(|&j| bottoms[j] + heights[j] <= bottoms[k] - contact + HEIGHT_SLACK)
    };
    // What a column may stand on under each layer (off the plate only): the ground and the
    // union of the feature's sections below.
    let on_plate = ground.is_none();
    let mut below: Vec<Region> = ground.map(|g| union(g, &[])).unwrap_or_default();
    let mut entering: Vec<Vec<Region>> = vec![vec![]; n];
    for k in 0..n {
        in_time(stop_at)?;
        if !pieces[k].is_empty() {
            let footprint = footprint(sections, k, &pieces[k], ground, heights[k], params);
            let (carried, left) = match on_plate {
                true => (footprint, vec![]),
                false => (
                    intersection(&footprint, &below),
                    difference(&pieces[k], &below),
                ),
            };
            out.left[k] = area(&left);
            if params.support_material == crate::params::SupportMaterial::Off {
                out.left[k] = area(&pieces[k]);
            } else if let Some(e) = entry(k) {
                // What lands on the part within the contact gap needs no column.
                let mut column = carried;
                for s in &sections[e + 1..k] {
                    column = difference(&column, s);
                }
                entering[e] = union(&entering[e], &column);
            }
        }
        if !on_plate {
            below = union(&below, &sections[k]);
        }
    }
    if params.support_material == crate::params::SupportMaterial::Off {
        return Ok(out);
    }
    sweep(sections, entering, params, tol, &mut out.regions, stop_at)?;
    Ok(out)
}

/// The columns were given up at the caller's time limit ([`columns`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Stopped;

/// [`Stopped`] once `stop_at` has passed (`None`: never).
fn in_time(stop_at: Option<Instant>) -> Result<(), Stopped> {
    match stop_at {
        Some(t) if Instant::now() >= t => Err(Stopped),
        _ => Ok(()),
    }
}

/// What a column under the unsupported `pieces` of layer `k` holds: the whole overhang they
/// lie in, the layer's section outside the one below (or outside `ground` for the first
/// layer) within the overhang limit's reach of them. A wall leaning past the limit leaves a
/// thin strip unsupported on each layer (`h·(tan θ − tan α)` wide), strips a bead apart from
/// layer to layer; the overhangs they lie in (`h·tan θ` wide) meet, and make one column.
fn footprint(
    sections: &[Vec<Region>],
    k: usize,
    pieces: &[Region],
    ground: Option<&[Region]>,
    height: f64,
    params: &LayerParams,
) -> Vec<Region> {
    let below = match k {
        0 => ground.unwrap_or_default(),
        _ => &sections[k - 1],
    };
    let reach = height * params.overhang_angle_deg.to_radians().tan();
    let overhang = difference(&sections[k], below);
    union(
        pieces,
        &intersection(&overhang, &grow(pieces, reach, params.tolerance)),
    )
}

/// How far (mm) from a column's outline a vertex [`sweep`] drops may lie: the outline does not
/// move (only vertices on it, or within round-off of it, go).
///
/// Each layer's difference leaves on the column's outline the vertices of that layer's section
/// where the column stands against the part: the sections' rings cross a wall's straight runs at
/// other points on every layer (a prismatic wall's triangle diagonals, a thread's helix), so a
/// column carried down gathers vertices on its straight runs, all within round-off of them.
/// Dropped after every layer, NIST CTC-05's support column under its plate stays near 400
/// vertices where it reached 18,000 (its sweep, one layer after the other on one core, took 3.5
/// of the plan's 15 s, now 0.5); in a threaded shell the column doubled every 25 layers to
/// 490,000 after 225. The round-off vertices also split the zig-zags laid in the columns: the
/// capsule's support on the KUKA cell, laid from columns without them, has 33 zig-zags on its
/// layer 33 where it had 41, and 7.7 % more volume (the connectors joining them).
const COLUMN_SLACK_MM: f64 = 1e-6;

/// The columns entering at each layer (`entering`) carried down through `sections`, top down:
/// each layer's printed support into `regions`; given up past `stop_at`.
fn sweep(
    sections: &[Vec<Region>],
    entering: Vec<Vec<Region>>,
    params: &LayerParams,
    tol: f64,
    regions: &mut SupportRegions,
    stop_at: Option<Instant>,
) -> Result<(), Stopped> {
    let n = entering.len();
    let interface_layers = params.support_interface_layers;
    // Top down, one layer after the other: the columns in each layer (what has not landed),
    // and those that entered within the interface layers above it.
    let mut active_at: Vec<Vec<Region>> = vec![vec![]; n];
    let mut top_at: Vec<Vec<Region>> = vec![vec![]; n];
    let mut active: Vec<Region> = vec![];
    let mut recent: VecDeque<Vec<Region>> = VecDeque::new();
    for j in (0..n).rev() {
        let new = &entering[j];
        if interface_layers > 0 {
            recent.push_front(new.clone());
            recent.truncate(interface_layers);
        }
        if active.is_empty() && new.is_empty() {
            continue;
        }
        in_time(stop_at)?;
        active = carried(&active, new, &sections[j]);
        if active.is_empty() {
            continue;
        }
        top_at[j] = recent
            .iter()
            .filter(|r| !r.is_empty())
            .fold(vec![], |acc, r| union(&acc, r));
        active_at[j] = active.clone();
    }
    // Each layer's printed support (in parallel): the columns less the part's section near
    // them grown by the XY gap, interface where a column entered within the interface layers.
    let xy = params.support_xy_distance;
    let printed: Vec<(Vec<Region>, Vec<Region>)> = (0..n)
        .into_par_iter()
        .with_max_len(1)
        .map(|j| {
            let a = &active_at[j];
            if a.is_empty() {
                return (vec![], vec![]);
            }
            // Only the part's section within reach of the columns is grown: clipped to their
            // box grown by more than the gap (the clip's own edges, grown, stay outside it).
            let part = match window(a, xy + 2.0 * tol) {
                Some(w) => grow(
                    &intersection(&near(&sections[j], a, xy + tol), &[w]),
                    xy,
                    tol,
                ),
                None => vec![],
            };
            let printed = difference(a, &part);
            let interface = intersection(&printed, &top_at[j]);
            (difference(&printed, &interface), interface)
        })
        .collect();
    for (j, (sparse, interface)) in printed.into_iter().enumerate() {
        regions.sparse[j] = sparse;
        regions.interface[j] = interface;
    }
    Ok(())
}

/// The columns `active` come down from the layer above, with those entering at this layer
/// (`new`), less this layer's section: what goes on down, its vertices within round-off of
/// its outline dropped ([`COLUMN_SLACK_MM`]).
fn carried(active: &[Region], new: &[Region], section: &[Region]) -> Vec<Region> {
    let column = union(active, new);
    simplified(
        difference(&column, &near(section, &column, 0.0)),
        COLUMN_SLACK_MM,
    )
}

/// The regions of `section` whose outer ring's box comes within `margin` of the box of
/// `column`'s outer rings: the only ones a boolean with `column` (or with `column` less the
/// section grown by up to `margin`) can meet.
fn near(section: &[Region], column: &[Region], margin: f64) -> Vec<Region> {
    let Some((lo, hi)) = bounds(column) else {
        return vec![];
    };
    section
        .iter()
        .filter(|r| {
            bounds(std::slice::from_ref(*r)).is_some_and(|(a, b)| {
                (0..2).all(|k| a[k] <= hi[k] + margin && b[k] >= lo[k] - margin)
            })
        })
        .cloned()
        .collect()
}

/// The box of `column`'s outer rings grown by `margin`, as a region.
fn window(column: &[Region], margin: f64) -> Option<Region> {
    let (lo, hi) = bounds(column)?;
    let (x0, y0, x1, y1) = (
        lo[0] - margin,
        lo[1] - margin,
        hi[0] + margin,
        hi[1] + margin,
    );
    Some(Region {
        outer: vec![[x0, y0], [x1, y0], [x1, y1], [x0, y1]],
        holes: vec![],
    })
}

/// The box of the outer rings of `regions`: lowest and highest corner; `None` for none.
fn bounds(regions: &[Region]) -> Option<(Point2, Point2)> {
    let mut pts = regions.iter().flat_map(|r| r.outer.iter());
    let first = *pts.next()?;
    Some(pts.fold((first, first), |(lo, hi), p| {
        (
            [lo[0].min(p[0]), lo[1].min(p[1])],
            [hi[0].max(p[0]), hi[1].max(p[1])],
        )
    }))
}

/// Support paths keep no two points closer than this many bead widths (but their ends): a
/// zig-zag's connectors follow the column's outline, the part's section grown by the XY gap,
/// whose round joins and chorded curves put vertices hundredths of a mm apart, points the
/// post would merge. Support needs no such detail.
const STEP_BEADS: f64 = 0.25;

/// `points` without those closer than `step` to the last one kept; the last point stays (in
/// place of the one kept before it when that one is too close and not the first).
fn thinned(points: Vec<Point2>, step: f64) -> Vec<Point2> {
    let Some(&last) = points.last() else {
        return points;
    };
    let mut out: Vec<Point2> = Vec::with_capacity(points.len());
    for p in points {
        if out.last().is_none_or(|q| dist(*q, p) >= step) {
            out.push(p);
        }
    }
    if out.last() != Some(&last) {
        if out.len() > 1 && out.last().is_some_and(|q| dist(*q, last) < step) {
            out.pop();
        }
        out.push(last);
    }
    out
}

/// Each layer's support paths in its plane: sparse zig-zag lines `width / support_density`
/// apart at `raster_angle_deg` (one direction on every layer), interface lines `width /
/// support_interface_density` apart turning 90° every layer, under their roles.
pub(crate) fn fill_columns(
    regions: &SupportRegions,
    params: &LayerParams,
    width: f64,
) -> Vec<Vec<FillPath>> {
    let lines = LayerParams {
        path_mode: PathMode::Zigzag,
        ..params.clone()
    };
    let fill = |r: &[Region], layer: usize, density: f64, role: Role| -> Vec<FillPath> {
        if r.is_empty() {
            return vec![];
        }
        crate::fill::fill_layer(r, &lines, layer, width, width / density)
            .paths
            .into_iter()
            .map(|p| FillPath::uniform(thinned(p.points, STEP_BEADS * width), width, role))
            .filter(|p| p.points.len() >= 2)
            .collect()
    };
    // The sparse lines are laid in one direction on every layer, so a layer whose sparse
    // support is the layer below's has the same lines: a column standing clear of the part
    // keeps its outline for many layers (67 of the impeller's 92 support layers), each
    // thousands of vertices.
    let firsts: Vec<usize> = (0..regions.sparse.len())
        .filter(|&k| k == 0 || regions.sparse[k] != regions.sparse[k - 1])
        .collect();
    let sparse: Vec<Vec<FillPath>> = firsts
        .par_iter()
        .with_max_len(1)
        .map(|&k| {
            fill(
                &regions.sparse[k],
                0,
                params.support_density,
                Role::SupportMaterial,
            )
        })
        .collect();
    // Layer k's sparse lines: those of the last first layer at or below it.
    let first_below = |k: usize| firsts.partition_point(|&f| f <= k).saturating_sub(1);
    regions
        .interface
        .par_iter()
        .enumerate()
        .map(|(k, interface)| {
            let mut paths = sparse.get(first_below(k)).cloned().unwrap_or_default();
            paths.extend(fill(
                interface,
                k,
                params.support_interface_density,
                Role::SupportMaterialInterface,
            ));
            paths
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geom2d::shapes::{area, rect};

    /// A bridge: two posts 10 × 10 (x 0–10 and 30–40) for layers 0..10, a slab 40 × 10 on
    /// them for layers 10..15; the slab's first layer is unsupported between the posts.
    fn bridge() -> (Vec<Vec<Region>>, Vec<Vec<Region>>) {
        let posts = vec![rect(0.0, 0.0, 10.0, 10.0), rect(30.0, 0.0, 40.0, 10.0)];
        let slab = vec![rect(0.0, 0.0, 40.0, 10.0)];
        let sections: Vec<Vec<Region>> = (0..15)
            .map(|k| if k < 10 { posts.clone() } else { slab.clone() })
            .collect();
        let mut pieces = vec![vec![]; 15];
        pieces[10] = vec![rect(10.0, 0.0, 30.0, 10.0)];
        (sections, pieces)
    }

    /// Past the caller's time limit the columns are given up, not half made; the same columns
    /// with a limit ahead are those made without one.
    #[test]
    fn columns_past_the_time_limit_are_given_up() {
        let (sections, pieces) = bridge();
        let params = LayerParams::default();
        let past = Some(Instant::now());
        let got = columns(&sections, &[0.2; 15], &pieces, None, &params, 0.48, past);
        assert_eq!(got.err(), Some(Stopped));
        let ahead = Instant::now().checked_add(std::time::Duration::from_secs(3600));
        let later = columns(&sections, &[0.2; 15], &pieces, None, &params, 0.48, ahead);
        let none = columns(&sections, &[0.2; 15], &pieces, None, &params, 0.48, None);
        let (later, none) = (later.expect("in time"), none.expect("in time"));
        assert_eq!(later.left, none.left);
        assert_eq!(later.regions.sparse, none.regions.sparse);
    }

    #[test]
    fn a_bridge_gets_a_column_between_its_posts_down_to_the_plate() {
        let (sections, pieces) = bridge();
        let params = LayerParams::default();
        let c =
            columns(&sections, &[0.2; 15], &pieces, None, &params, 0.48, None).expect("in time");
        assert!(c.left.iter().all(|a| *a == 0.0));
        // One layer of contact gap: layers 0..=8 carry support, 9 and up none.
        for k in 0..15 {
            let a = area(&c.regions.sparse[k]) + area(&c.regions.interface[k]);
            // The gap between the posts less the XY gap on both sides: 19 × 10.
            let expect = if k <= 8 {
                10.0 * (20.0 - 2.0 * 0.5)
            } else {
                0.0
            };
            assert!((a - expect).abs() < 0.01, "layer {k}: {a}");
        }
        // The top two printed layers are interface.
        assert!(area(&c.regions.interface[8]) > 0.0 && area(&c.regions.interface[7]) > 0.0);
        assert_eq!(area(&c.regions.interface[6]), 0.0);
        assert_eq!(area(&c.regions.sparse[8]), 0.0);
        // Filled with lines of their roles, inside the support.
        let paths = fill_columns(&c.regions, &params, 0.45);
        assert!(paths[0].iter().all(|p| p.role == Role::SupportMaterial));
        assert!(paths[8]
            .iter()
            .all(|p| p.role == Role::SupportMaterialInterface));
        assert!(!paths[0].is_empty() && paths[9].is_empty());
        for p in paths.iter().flatten() {
            assert!(p
                .points
                .iter()
                .all(|q| q[0] > 10.5 - 0.01 && q[0] < 29.5 + 0.01));
        }
    }

    #[test]
    fn off_the_plate_or_when_off_support_that_cannot_stand_is_left() {
        let (sections, pieces) = bridge();
        // Off the plate on nothing: the gap between the posts has nothing below it.
        let params = LayerParams::default();
        let c = columns(
            &sections,
            &[0.2; 15],
            &pieces,
            Some(&[]),
            &params,
            0.48,
            None,
        )
        .expect("in time");
        assert!((c.left[10] - 200.0).abs() < 1e-6);
        assert!(c.regions.is_empty());
        // Standing on a parent under the whole slab: carried, down to the first layer.
        let ground = [rect(-5.0, -5.0, 45.0, 15.0)];
        let c = columns(
            &sections,
            &[0.2; 15],
            &pieces,
            Some(&ground),
            &params,
            0.48,
            None,
        )
        .expect("in time");
        assert!(c.left.iter().all(|a| *a == 0.0));
        assert!((area(&c.regions.sparse[0]) - 190.0).abs() < 0.01);
        let off = LayerParams {
            support_material: crate::params::SupportMaterial::Off,
            ..LayerParams::default()
        };
        let c = columns(&sections, &[0.2; 15], &pieces, None, &off, 0.48, None).expect("in time");
        assert!((c.left[10] - 200.0).abs() < 1e-6);
        assert!(c.regions.is_empty());
    }

    #[test]
    fn a_column_carried_down_a_wall_keeps_the_vertices_of_one_layer() {
        // A column 25 × 10 standing against a pillar 10 × 10, its left side (x = 10) the
        // crossings of 300 sections above with the wall, each within round-off of it.
        let mut outer = vec![[30.0, 0.0], [30.0, 10.0], [10.0, 10.0]];
        outer.extend((1..300).rev().map(|k| {
            let x = 10.0 + (k % 7) as f64 * 1e-7;
            [x, k as f64 * 10.0 / 300.0]
        }));
        outer.push([10.0, 0.0]);
        let column = Region {
            outer,
            holes: vec![],
        };
        let pillar = rect(0.0, 0.0, 10.0, 10.0);
        let active = carried(&[column], &[], &[pillar]);
        assert!((area(&active) - 200.0).abs() < 1e-5, "{}", area(&active));
        let vertices: usize = active
            .iter()
            .map(|r| r.outer.len() + r.holes.iter().map(Vec::len).sum::<usize>())
            .sum();
        assert!(vertices <= 6, "{vertices} vertices");
    }

    #[test]
    fn a_column_lands_on_a_lower_step_of_the_part() {
        // A step 10 × 10 at x 0–10 for layers 0..5, a wall at x 30–40 to the top, and a
        // ceiling over both from layer 10.
        let sections: Vec<Vec<Region>> = (0..12)
            .map(|k| match k {
                0..=4 => vec![rect(0.0, 0.0, 10.0, 10.0), rect(30.0, 0.0, 40.0, 10.0)],
                5..=9 => vec![rect(30.0, 0.0, 40.0, 10.0)],
                _ => vec![rect(0.0, 0.0, 40.0, 10.0)],
            })
            .collect();
        let mut pieces = vec![vec![]; 12];
        pieces[10] = vec![rect(0.0, 0.0, 30.0, 10.0)];
        let c = columns(
            &sections,
            &[0.2; 12],
            &pieces,
            None,
            &LayerParams::default(),
            0.48,
            None,
        )
        .expect("in time");
        let at = |k: usize| area(&c.regions.sparse[k]) + area(&c.regions.interface[k]);
        // Over the step (x 0–10) the column stands on layer 4; between, on the plate.
        assert!((at(8) - 10.0 * 29.5).abs() < 0.01, "{}", at(8));
        assert!((at(5) - 10.0 * 29.5).abs() < 0.01, "{}", at(5));
        assert!((at(4) - 10.0 * 19.0).abs() < 0.01, "{}", at(4));
        // Off the plate: the middle has nothing of the feature below it.
        let c = columns(
            &sections,
            &[0.2; 12],
            &pieces,
            Some(&[]),
            &LayerParams::default(),
            0.48,
            None,
        )
        .expect("in time");
        assert!((c.left[10] - 200.0).abs() < 1e-6, "{}", c.left[10]);
        let at = |k: usize| area(&c.regions.sparse[k]) + area(&c.regions.interface[k]);
        assert!((at(5) - 10.0 * 10.0).abs() < 0.01, "{}", at(5));
        assert_eq!(at(4), 0.0);
    }
}
