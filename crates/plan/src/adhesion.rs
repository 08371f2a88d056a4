//! The skirt-and-brim stage (issue 33), after the head check: on a Marlin machine, the
//! process's skirt and brim ([`slicer::skirt`]) around the first layer's footprint, laid on
//! the first layer before the part.
//!
//! The first layer is the tool path's print points resting on the plate (their bottoms within
//! [`PLATE_SLACK`] of the lowest), the pedestal's when the part stands on one; its footprint
//! is the inside of the rings its external perimeters run along (the convex hull of its beads
//! where it has none). The loops go into the tool path before the first layer's first point,
//! with that point's feature and layer (so a program begins no layer of its own for them),
//! roles `skirt` and `brim`: not the part's, so the self-check, which compares what each
//! feature's planner laid, never counts them; nor do the features' `points` in `plan.json`.
//! Other machines get neither (their first layers may lie tilted on a turning table). Where
//! they would make the print wider or deeper than the bed, they are left out with a warning
//! rather than the part refused.

use crate::report::{round, AdhesionEntry};
use crate::warning::{Warning, WarningKind};
use collide::Collision;
use robot_post::machine::{MachineKind, MachineProfile};
use slicer::geom2d::Point2;
use slicer::params::LayerParams;
use slicer::skirt::{footprint, loops};
use slicer::toolpath::{MoveKind, PathPoint, Role, ToolPath};

/// Bead bottoms within this of the lowest rest on the plate, mm.
pub const PLATE_SLACK: f64 = 0.01;

/// A tool axis within this of +Z (each component) is vertical.
const VERTICAL: f64 = 1e-6;

/// Adds the skirt and brim `params` asks for to `toolpath` on `machine` (Marlin only), and
/// moves the path indices of `collisions` past them. `Ok(None)` when nothing was asked or
/// there is no first layer to lay them around; `Err` (a warning of the part) when they would
/// not fit the bed with the part, and were left out.
pub fn lay(
    toolpath: &mut ToolPath,
    collisions: &mut [Collision],
    params: &LayerParams,
    machine: &MachineProfile,
) -> Result<Option<AdhesionEntry>, Warning> {
    if machine.kind != MachineKind::Marlin
        || (params.skirt_loops == 0 && params.brim_width_mm <= 0.0)
    {
        return Ok(None);
    }
    let Some(first) = FirstLayer::of(toolpath) else {
        return Ok(None);
    };
    let bead = machine.bead();
    let foot = footprint(&first.rings(toolpath), bead.width, params.tolerance);
    let loops = loops(&foot, params, bead.width);
    if loops.is_empty() {
        return Ok(None);
    }
    // The beads' outer edges, as the post measures the fit.
    let extent = extent(toolpath, &loops).map(|e| e + bead.width);
    if extent[0] > machine.bed_size[0] || extent[1] > machine.bed_size[1] {
        return Err(Warning::part(WarningKind::Planner(format!(
            "skirt and brim left out: with them the print is {:.1} x {:.1} mm, more than the {:.0} x {:.0} mm bed (lower skirt_distance_mm or brim_width_mm, or set skirt_loops = 0)",
            extent[0], extent[1], machine.bed_size[0], machine.bed_size[1]
        ))));
    }
    let at = first.start;
    let anchor = toolpath.points[at];
    let mut added = vec![];
    let (mut length, mut filament) = (0.0, 0.0);
    for l in &loops {
        for (k, &q) in l.points.iter().enumerate() {
            let (kind, e) = match k {
                0 => (MoveKind::Travel, 0.0),
                _ => {
                    let d = (q[0] - l.points[k - 1][0]).hypot(q[1] - l.points[k - 1][1]);
                    length += d;
                    let e = bead.filament_length(bead.width, f64::from(anchor.thickness), d);
                    filament += e;
                    (MoveKind::Print, e)
                }
            };
            added.push(PathPoint {
                kind,
                p: [q[0], q[1], first.z],
                axis: [0.0, 0.0, 1.0],
                e,
                width: bead.width as f32,
                role: l.role,
                ..anchor
            });
        }
    }
    let n = added.len();
    toolpath.points.splice(at..at, added);
    for c in collisions.iter_mut().filter(|c| c.index >= at) {
        c.index += n;
    }
    let count = |role| loops.iter().filter(|l| l.role == role).count();
    Ok(Some(AdhesionEntry {
        skirt_loops: count(Role::Skirt),
        brim_loops: count(Role::Brim),
        points: n,
        length_mm: round(length, 1e1),
        volume_mm3: round(filament * bead.filament_area(), 1e3),
    }))
}

/// The X and Y extent of the bead centres of `path` and of `loops` together, mm.
fn extent(path: &ToolPath, loops: &[slicer::skirt::AdhesionLoop]) -> [f64; 2] {
    let xy = path
        .points
        .iter()
        .filter(|q| q.kind == MoveKind::Print)
        .map(|q| [q.p[0], q.p[1]])
        .chain(loops.iter().flat_map(|l| l.points.iter().copied()));
    let (lo, hi) = xy.fold(
        ([f64::INFINITY; 2], [f64::NEG_INFINITY; 2]),
        |(lo, hi), p| {
            (
                [lo[0].min(p[0]), lo[1].min(p[1])],
                [hi[0].max(p[0]), hi[1].max(p[1])],
            )
        },
    );
    [hi[0] - lo[0], hi[1] - lo[1]]
}

/// Where the first layer lies in a tool path.
struct FirstLayer {
    /// Index of the first point of its first path's feature and layer.
    start: usize,
    /// Its beads' top (part coordinates).
    z: f64,
    /// Its beads' bottom.
    bottom: f64,
}

impl FirstLayer {
    /// The first layer of `path`: `None` when it prints nothing or its first bead on the plate
    /// is not laid along +Z.
    fn of(path: &ToolPath) -> Option<FirstLayer> {
        let prints = path.points.iter().filter(|q| q.kind == MoveKind::Print);
        let bottom = prints
            .map(|q| q.p[2] - f64::from(q.thickness))
            .fold(f64::INFINITY, f64::min);
        let i = path.points.iter().position(|q| {
            q.kind == MoveKind::Print && q.p[2] - f64::from(q.thickness) <= bottom + PLATE_SLACK
        })?;
        let q = path.points[i];
        let vertical = q.axis[0].abs() <= VERTICAL && q.axis[1].abs() <= VERTICAL;
        if !vertical {
            return None;
        }
        let mut start = i;
        while start > 0 && {
            let p = &path.points[start - 1];
            (p.feature, p.layer) == (q.feature, q.layer)
        } {
            start -= 1;
        }
        Some(FirstLayer {
            start,
            z: q.p[2],
            bottom,
        })
    }

    /// Whether `q` is one of its beads.
    fn holds(&self, q: &PathPoint) -> bool {
        q.kind == MoveKind::Print
            && (q.p[2] - f64::from(q.thickness) - self.bottom).abs() <= PLATE_SLACK
    }

    /// The rings its external perimeters run along (each path: its travel's point and its
    /// prints), or the convex hull of its beads where it has none.
    fn rings(&self, path: &ToolPath) -> Vec<Vec<Point2>> {
        let mut rings: Vec<Vec<Point2>> = vec![];
        let mut open = false;
        for (k, q) in path.points.iter().enumerate() {
            let outer = q.role == Role::ExternalPerimeter;
            let xy = [q.p[0], q.p[1]];
            match q.kind {
                MoveKind::Travel => {
                    // The path this travel leads to starts here, if it is a first-layer ring.
                    let next = path.points.get(k + 1);
                    open = outer && next.is_some_and(|n| self.holds(n));
                    if open {
                        rings.push(vec![xy]);
                    }
                }
                MoveKind::Print if outer && self.holds(q) => {
                    if !open {
                        rings.push(vec![]);
                        open = true;
                    }
                    if let Some(r) = rings.last_mut() {
                        r.push(xy);
                    }
                }
                MoveKind::Print => open = false,
            }
        }
        rings.retain(|r| r.len() >= 3);
        if rings.is_empty() {
            let beads: Vec<Point2> = path
                .points
                .iter()
                .filter(|q| self.holds(q))
                .map(|q| [q.p[0], q.p[1]])
                .collect();
            rings.push(convex_hull(beads));
        }
        rings
    }
}

/// The convex hull of `points`, counter-clockwise (Andrew's monotone chain).
fn convex_hull(mut points: Vec<Point2>) -> Vec<Point2> {
    points.sort_by(|a, b| a[0].total_cmp(&b[0]).then(a[1].total_cmp(&b[1])));
    points.dedup();
    if points.len() < 3 {
        return points;
    }
    let cross = |o: Point2, a: Point2, b: Point2| {
        (a[0] - o[0]) * (b[1] - o[1]) - (a[1] - o[1]) * (b[0] - o[0])
    };
    let mut hull: Vec<Point2> = vec![];
    for pass in 0..2 {
        let base = hull.len();
        let iter: Box<dyn Iterator<Item = &Point2>> = match pass {
            0 => Box::new(points.iter()),
            _ => Box::new(points.iter().rev()),
        };
        for &p in iter {
            while hull.len() >= base + 2
                && cross(hull[hull.len() - 2], hull[hull.len() - 1], p) <= 0.0
            {
                hull.pop();
            }
            hull.push(p);
        }
        hull.pop();
    }
    hull
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A square plate's first layer: its outer ring (an external perimeter) and a line of
    /// infill, `size` mm across, at the bed's middle.
    fn plate(size: f64) -> ToolPath {
        let q = |kind, x: f64, y: f64, role| PathPoint {
            feature: 0,
            layer: 0,
            kind,
            p: [x, y, 0.2],
            axis: [0.0, 0.0, 1.0],
            e: 0.01,
            thickness: 0.2,
            width: 0.45,
            role,
        };
        let h = size / 2.0;
        let ring = [[-h, -h], [h, -h], [h, h], [-h, h], [-h, -h]];
        let mut points: Vec<PathPoint> = ring
            .iter()
            .enumerate()
            .map(|(k, p)| {
                let kind = if k == 0 {
                    MoveKind::Travel
                } else {
                    MoveKind::Print
                };
                q(kind, p[0], p[1], Role::ExternalPerimeter)
            })
            .collect();
        points.push(q(MoveKind::Travel, -1.0, 0.0, Role::SolidInfill));
        points.push(q(MoveKind::Print, 1.0, 0.0, Role::SolidInfill));
        ToolPath { points }
    }

    #[test]
    fn the_skirt_goes_first_around_the_first_layer_unless_the_bed_is_too_small() {
        let m = MachineProfile::builtin(MachineKind::Marlin);
        let params = LayerParams::default();
        let mut path = plate(20.0);
        let before = path.points.len();
        let mut collisions = [];
        let entry = lay(&mut path, &mut collisions, &params, &m)
            .expect("fits")
            .expect("a skirt");
        assert_eq!((entry.skirt_loops, entry.brim_loops), (1, 0));
        assert_eq!(path.points.len(), before + entry.points);
        // The skirt first, on the first layer, 6 mm and half a bead out from the ring's
        // outer edge (a 20.45 mm square grown by 6.225 mm: the sides and round corners).
        let skirt = &path.points[..entry.points];
        assert!(skirt.iter().all(|q| q.role == Role::Skirt && q.p[2] == 0.2));
        assert_eq!(skirt[0].kind, MoveKind::Travel);
        let want = 4.0 * 20.0 + 2.0 * std::f64::consts::PI * 6.45;
        assert!((entry.length_mm - want).abs() < 0.2, "{}", entry.length_mm);
        assert_eq!(path.points[entry.points].role, Role::ExternalPerimeter);
        // A plate as wide as the bed leaves no room: left out with a warning.
        let mut wide = plate(m.bed_size[0] - 1.0);
        let w = lay(&mut wide, &mut collisions, &params, &m).expect_err("too wide");
        assert!(w.to_string().contains("skirt and brim left out"), "{w}");
        assert_eq!(wide.points.len(), before);
        // None asked, none on another machine.
        let none = LayerParams {
            skirt_loops: 0,
            ..LayerParams::default()
        };
        assert_eq!(lay(&mut plate(20.0), &mut collisions, &none, &m), Ok(None));
        let d5 = MachineProfile::builtin(MachineKind::Delta5);
        assert_eq!(
            lay(&mut plate(20.0), &mut collisions, &params, &d5),
            Ok(None)
        );
    }

    #[test]
    fn the_hull_of_a_square_and_its_inside() {
        let pts = vec![
            [0.0, 0.0],
            [2.0, 0.0],
            [1.0, 1.0],
            [2.0, 2.0],
            [0.0, 2.0],
            [1.0, 0.5],
        ];
        let hull = convex_hull(pts);
        assert_eq!(hull, vec![[0.0, 0.0], [2.0, 0.0], [2.0, 2.0], [0.0, 2.0]]);
    }
}
