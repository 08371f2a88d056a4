//! How the part stands on the build plate: as modelled (its −Z down), on a chosen planar face
//! (`--base-face ID`), or on the planar face the rule of `--orient auto` picks.
//!
//! **The rule of `--orient auto`.** Every direction in which planar faces of the part point
//! outward is a candidate (the 8 with the largest planar area facing that way). The part is
//! read turned so that the candidate points down and its features are extracted. Printability
//! first: a candidate whose planar layers leave no area unsupported within the overhang limit
//! (`plan::support::planar_area`, issue 31) wins over any that leaves some (however little: a
//! placement with less, but some, is no more printable, and may fail otherwise). Then a feature *needs a tool axis below the horizon* when its build direction
//! (the normal of its reference plane, into the feature) points below the horizontal plane
//! (z < −0.001): the candidate with the fewest such features wins; ties go to the larger
//! planar area facing down, then to the candidate first in the file.

use crate::Failure;
use brep::math::V3;
use brep::mesh::{mesh_faces, MeshOptions};
use brep::topology::{Brep, FaceId};
use brep::StepPart;
use features::{extract_all, ExtractOptions};
use plan::report::PlacementEntry;
use std::path::Path;

/// How many candidate directions `--orient auto` tries.
const CANDIDATES: usize = 8;

/// Reads `path` standing as `--base-face` or `--orient` say, with what plan.json records.
///
/// `process` and `bead_width` (mm) measure each candidate's support for `--orient auto`.
pub fn read_placed(
    path: &Path,
    base_face: Option<u64>,
    auto: bool,
    process: &plan::Process,
    bead_width: f64,
) -> Result<(StepPart, Option<PlacementEntry>), Failure> {
    let part = brep::read_step(path).map_err(|e| Failure::new(path, e))?;
    if let Some(id) = base_face {
        let b = &part.brep;
        let face = (0..b.faces.len())
            .map(|k| FaceId(k as u32))
            .find(|&f| b.face(f).step_id == id)
            .ok_or_else(|| {
                Failure::new(path, format!("--base-face {id}: no face #{id} in the file"))
            })?;
        let down = b.plane_normal(face).ok_or_else(|| {
            Failure::new(
                path,
                format!(
                    "--base-face {id}: face #{id} is not planar (a {} face): the part stands on a planar face",
                    features::extract::surface_kind(b.face_surface(face))
                ),
            )
        })?;
        let d = [down.x, down.y, down.z];
        let part = if stands(down) {
            part
        } else {
            brep::read_step_turned(path, d).map_err(|e| Failure::new(path, e))?
        };
        return Ok((part, Some(entry(id, d, "base-face".into()))));
    }
    if !auto {
        return Ok((part, None));
    }
    let candidates = candidates(&part.brep);
    if candidates.is_empty() {
        return Err(Failure::new(
            path,
            "--orient auto: the part has no planar face to stand on",
        ));
    }
    // (some area unsupported, features needing an axis below the horizon, −area, index) for
    // each candidate, with the part read turned onto it, and its unsupported area.
    let mut best: Option<(Rank, f64, &Candidate, StepPart)> = None;
    for (k, c) in candidates.iter().enumerate() {
        let turned = brep::read_step_turned(path, [c.down.x, c.down.y, c.down.z])
            .map_err(|e| Failure::new(path, e))?;
        let Ok(assembly) = extract_all(&turned.brep, &ExtractOptions::default()) else {
            continue;
        };
        let below = assembly
            .trees
            .iter()
            .flat_map(|t| t.features.iter())
            .filter(|f| f.reference.normal.is_some_and(|n| n[2] < -1e-3))
            .count();
        // A candidate whose support cannot be measured ranks after every one that can.
        let unsupported =
            plan::support::planar_area(&assembly, process, bead_width).unwrap_or(f64::INFINITY);
        let key = (unsupported > 0.0, below, -c.area, k);
        if best
            .as_ref()
            .is_none_or(|(b, _, _, _)| key.partial_cmp(b) == Some(std::cmp::Ordering::Less))
        {
            best = Some((key, unsupported, c, turned));
        }
    }
    let Some(((_, below, _, _), unsupported, c, turned)) = best else {
        return Err(Failure::new(
            path,
            "--orient auto: the features of no candidate placement could be extracted",
        ));
    };
    let rule = format!(
        "auto: of {} planar directions, one leaving no area unsupported where one does (this one: {unsupported:.1} mm^2), then the fewest features with a build direction below the horizon ({below}), then the most planar area down ({:.1} mm^2)",
        candidates.len(),
        c.area
    );
    // The part as read when the winner already points down, else as the loop read it turned.
    let part = if stands(c.down) { part } else { turned };
    let d = [c.down.x, c.down.y, c.down.z];
    Ok((part, Some(entry(c.face_id, d, rule))))
}

/// How `--orient auto` ranks a candidate, least first: some planar area unsupported, features
/// needing an axis below the horizon, −planar area down, index.
type Rank = (bool, usize, f64, usize);

/// Whether `down` already points down (−Z): the part stands as modelled.
fn stands(down: V3) -> bool {
    down.z < -1.0 + 1e-12
}

/// What plan.json records of standing the part on face `face`, whose outward normal `down` is
/// turned to −Z.
fn entry(face: u64, down: [f64; 3], rule: String) -> PlacementEntry {
    let r = |x: f64| plan::report::round(x, 1e9);
    PlacementEntry {
        base_face: face,
        down: down.map(r),
        rotation: brep::turn_down(down).map(|row| row.map(r)),
        rule,
    }
}

/// A direction the part may stand on.
struct Candidate {
    /// Outward normal of its planar faces, in the file's frame.
    down: V3,
    /// Their area, mm².
    area: f64,
    /// STEP `#id` of the largest of them.
    face_id: u64,
}

/// The directions planar faces point outward, largest planar area first (at most
/// [`CANDIDATES`]), each with its largest face.
fn candidates(b: &Brep) -> Vec<Candidate> {
    let mut out: Vec<(Candidate, f64)> = vec![];
    for k in 0..b.faces.len() {
        let f = FaceId(k as u32);
        let Some(n) = b.plane_normal(f) else {
            continue;
        };
        let area = face_area(b, f);
        match out.iter_mut().find(|(c, _)| c.down.dot(&n) > 1.0 - 1e-9) {
            Some((c, largest)) => {
                c.area += area;
                if area > *largest {
                    *largest = area;
                    c.face_id = b.face(f).step_id;
                }
            }
            None => out.push((
                Candidate {
                    down: n,
                    area,
                    face_id: b.face(f).step_id,
                },
                area,
            )),
        }
    }
    let mut out: Vec<Candidate> = out.into_iter().map(|(c, _)| c).collect();
    out.sort_by(|a, c| c.area.total_cmp(&a.area));
    out.truncate(CANDIDATES);
    out
}

/// A face's area from its mesh (0 when it does not mesh).
fn face_area(b: &Brep, f: FaceId) -> f64 {
    let Ok(m) = mesh_faces(b, &[f], &MeshOptions::default()) else {
        return 0.0;
    };
    m.triangles()
        .iter()
        .map(|t| {
            let [a, c, d] = t.map(|i| m.positions[i as usize]);
            0.5 * (c - a).cross(&(d - a)).norm()
        })
        .sum()
}
