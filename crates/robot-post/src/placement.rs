//! Where a post puts the part: the machine coordinates of the planned (part) coordinates.

use crate::machine::MachineProfile;
use crate::tolerance::ROUND_UP_SLACK;
use crate::PostError;
use toolpath::vec3::unit;
use toolpath::{fixed, MoveKind, PathPoint, ToolPath};

/// Slack (mm) allowed when checking that the path fits the bed.
const FIT_TOLERANCE: f64 = 1e-6;

/// The offset (mm, rounded to 0.001) added to part coordinates to get machine coordinates:
/// the XY bounding-box centre of the print points goes to the bed centre (`bed_size / 2`, or
/// X0 Y0 when `bed_origin_centre`), and the lowest bead bottom (`z − thickness` over print
/// points) to Z0. A path without print points is placed by its travel points; an empty path
/// gets the bed centre.
///
/// Errors with [`PostError::DoesNotFit`] when any point (print points with half their bead
/// width and their thickness) lies outside the bed volume, saying by how much per axis.
pub fn bed_offset(path: &ToolPath, m: &MachineProfile) -> Result<[f64; 3], PostError> {
    let half = [m.bed_size[0] / 2.0, m.bed_size[1] / 2.0];
    let centre = if m.bed_origin_centre {
        [0.0, 0.0]
    } else {
        half
    };
    let placed = placed_points(path);
    let mut lo = [f64::INFINITY; 3];
    let mut hi = [f64::NEG_INFINITY; 3];
    for q in placed.clone() {
        let bottom = match q.kind {
            MoveKind::Print => q.p[2] - f64::from(q.thickness.max(0.0)),
            MoveKind::Travel => q.p[2],
        };
        for k in 0..2 {
            lo[k] = lo[k].min(q.p[k]);
            hi[k] = hi[k].max(q.p[k]);
        }
        lo[2] = lo[2].min(bottom);
    }
    let offset = if placed.clone().next().is_none() {
        [centre[0], centre[1], 0.0]
    } else {
        [
            round3(centre[0] - (lo[0] / 2.0 + hi[0] / 2.0)),
            round3(centre[1] - (lo[1] / 2.0 + hi[1] / 2.0)),
            // Up, never down: the lowest bead must not end below the plate.
            ((-lo[2] - ROUND_UP_SLACK) * 1000.0).ceil() / 1000.0,
        ]
    };

    // Extent of everything the nozzle and the beads occupy, in machine coordinates.
    let mut lo = [f64::INFINITY; 3];
    let mut hi = [f64::NEG_INFINITY; 3];
    for q in &path.points {
        let (r, bottom) = match q.kind {
            MoveKind::Print => (
                f64::from(q.width.max(0.0)) / 2.0,
                q.p[2] - f64::from(q.thickness.max(0.0)),
            ),
            MoveKind::Travel => (0.0, q.p[2]),
        };
        for k in 0..2 {
            lo[k] = lo[k].min(q.p[k] + offset[k] - r);
            hi[k] = hi[k].max(q.p[k] + offset[k] + r);
        }
        lo[2] = lo[2].min(bottom + offset[2]);
        hi[2] = hi[2].max(q.p[2] + offset[2]);
    }
    let bed_lo = [centre[0] - half[0], centre[1] - half[1], 0.0];
    let bed_hi = [centre[0] + half[0], centre[1] + half[1], m.bed_size[2]];
    let mut excess = Vec::new();
    if !path.points.is_empty() {
        for (k, letter) in ["X", "Y", "Z"].iter().enumerate() {
            let over = (bed_lo[k] - lo[k]).max(0.0) + (hi[k] - bed_hi[k]).max(0.0);
            // NaN (from overflowing coordinates) counts as not fitting.
            let fits = over <= FIT_TOLERANCE && offset[k].is_finite();
            if !fits {
                excess.push(format!("{letter} {} mm", fixed(over, 3)));
            }
        }
    }
    if !excess.is_empty() {
        return Err(PostError::DoesNotFit {
            name: m.name.clone(),
            bed: m.bed_size.map(|v| fixed(v, 0)).join("x"),
            excess: excess.join(", "),
        });
    }
    Ok(offset)
}

/// How far (mm) the part reaches past the bed's edge in X or Y when placed by
/// [`bed_offset`]'s rule (XY bounding-box centre of the placed points on the bed centre) and
/// then moved by `shift`: the largest overhang over the four edges, print points taken with
/// half their bead width; 0 when it stays on the bed, and for an empty path.
pub fn bed_overhang_xy(path: &ToolPath, m: &MachineProfile, shift: [f64; 2]) -> f64 {
    bed_gaps_xy(path, m).map_or(0.0, |g| g.overhang(shift))
}

/// The gaps (mm) between the part, placed by [`bed_offset`]'s rule, and the bed's edges in X
/// and Y: `low[k]` from the bed's low edge to the part, `high[k]` from the part to the high
/// edge (negative where the part overhangs).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BedGaps {
    /// Gap at the low edge, X and Y (mm).
    pub low: [f64; 2],
    /// Gap at the high edge, X and Y (mm).
    pub high: [f64; 2],
}

impl BedGaps {
    /// The largest overhang (mm, 0 when none) of the part moved by `shift`.
    pub fn overhang(&self, shift: [f64; 2]) -> f64 {
        (0..2)
            .map(|k| (-(self.low[k] + shift[k])).max(-(self.high[k] - shift[k])))
            .fold(0.0, f64::max)
    }
}

/// The [`BedGaps`] of `path` on `m`'s bed; `None` for an empty path.
pub fn bed_gaps_xy(path: &ToolPath, m: &MachineProfile) -> Option<BedGaps> {
    let (plo, phi) = xy_box(placed_points(path), false)?;
    let (lo, hi) = xy_box(path.points.iter(), true)?;
    let centre = if m.bed_origin_centre {
        [0.0, 0.0]
    } else {
        [m.bed_size[0] / 2.0, m.bed_size[1] / 2.0]
    };
    let mut gaps = BedGaps {
        low: [0.0; 2],
        high: [0.0; 2],
    };
    for k in 0..2 {
        let offset = centre[k] - (plo[k] + phi[k]) / 2.0;
        let half = m.bed_size[k] / 2.0;
        gaps.low[k] = lo[k] + offset - (centre[k] - half);
        gaps.high[k] = centre[k] + half - (hi[k] + offset);
    }
    Some(gaps)
}

/// The XY bounding box of `points`, print points grown by half their bead width when
/// `beads`; `None` without points.
fn xy_box<'a>(
    points: impl Iterator<Item = &'a PathPoint>,
    beads: bool,
) -> Option<([f64; 2], [f64; 2])> {
    let mut lo = [f64::INFINITY; 2];
    let mut hi = [f64::NEG_INFINITY; 2];
    let mut any = false;
    for q in points {
        any = true;
        let r = if beads && q.kind == MoveKind::Print {
            f64::from(q.width.max(0.0)) / 2.0
        } else {
            0.0
        };
        for k in 0..2 {
            lo[k] = lo[k].min(q.p[k] - r);
            hi[k] = hi[k].max(q.p[k] + r);
        }
    }
    any.then_some((lo, hi))
}

/// `v` rounded to 0.001, so the offset written in the header is exact.
fn round3(v: f64) -> f64 {
    (v * 1000.0).round() / 1000.0
}

/// The points a post places the part by: the print points, or every point of a path without
/// any (travel only).
pub(crate) fn placed_points(path: &ToolPath) -> impl Iterator<Item = &PathPoint> + Clone {
    // Walked, not collected: a list of references would take 8 bytes a point of a path that
    // may hold millions.
    let any_print = path.points.iter().any(|q| q.kind == MoveKind::Print);
    path.points
        .iter()
        .filter(move |q| !any_print || q.kind == MoveKind::Print)
}

/// The offset (mm, rounded to 0.001) from part to table coordinates: the XY bounding-box
/// centre of the print points on the C axis, the lowest bead bottom (`p − thickness·axis` over
/// print points) on the table surface. A path without print points is placed by its travel
/// points; an empty path gets no offset.
pub fn table_offset(path: &ToolPath) -> [f64; 3] {
    let placed = placed_points(path);
    if placed.clone().next().is_none() {
        return [0.0; 3];
    }
    let mut lo = [f64::INFINITY; 3];
    let mut hi = [f64::NEG_INFINITY; 2];
    for q in placed {
        let bottom = match (q.kind, unit(q.axis)) {
            (MoveKind::Print, Some(a)) => q.p[2] - f64::from(q.thickness.max(0.0)) * a[2],
            _ => q.p[2],
        };
        for k in 0..2 {
            lo[k] = lo[k].min(q.p[k]);
            hi[k] = hi[k].max(q.p[k]);
        }
        lo[2] = lo[2].min(bottom);
    }
    let round3 = |v: f64| (v * 1000.0).round() / 1000.0;
    [
        round3(-(lo[0] / 2.0 + hi[0] / 2.0)),
        round3(-(lo[1] / 2.0 + hi[1] / 2.0)),
        // Up, never down: the lowest bead must not end below the table.
        ((-lo[2] - ROUND_UP_SLACK) * 1000.0).ceil() / 1000.0,
    ]
}
