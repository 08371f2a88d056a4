//! The place stage: how the part stands on the build plate: as modelled (its −Z down), on a
//! chosen planar face (`--base-face ID`), or on the planar face the rule of `--orient auto`
//! picks. The file is parsed once ([`brep::PartFile`]: STEP, or a mesh) and translated turned for each
//! candidate; the winner's features come out extracted.
//!
//! **The rule of `--orient auto`.** Every direction in which planar faces of the part point
//! outward is a candidate (the 8 with the largest planar area facing that way). The part is
//! turned so that the candidate points down and its features are extracted. Printability
//! first: a candidate whose planar layers leave no area unsupported within the overhang limit
//! ([`crate::support::planar_area`], issue 31) wins over any that leaves some (however little:
//! a placement with less, but some, is no more printable). Then a feature *needs a tool axis
//! below the horizon* when its build direction (the normal of its reference plane, into the
//! feature) points below the horizontal plane (z < −0.001): the candidate with the fewest such
//! features wins; ties go to the larger planar area facing down, then to the candidate first
//! in the file.

use crate::report::PlacementEntry;
use brep::math::V3;
use brep::mesh::{mesh_faces, MeshOptions};
use brep::topology::{Brep, FaceId};
use brep::{PartFile, StepPart};
use features::{extract_all, Assembly, ExtractOptions};

/// How many candidate directions `--orient auto` tries.
const CANDIDATES: usize = 8;

use crate::tolerance::{BELOW_HORIZON_Z, SAME_DIRECTION_DOT, STANDS_Z};

/// How the part is to stand on the plate.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Placement {
    /// As modelled: its −Z down.
    #[default]
    AsModelled,
    /// On the planar face with this STEP `#id` (`--base-face`).
    BaseFace(u64),
    /// On the planar face the rule of `--orient auto` picks.
    Auto,
    /// As modelled, and when that plan is refused for something another placement may avoid,
    /// the first other placement that plans ([`crate::retry`], through
    /// [`crate::plan_file_to`]; [`place`] stands the part as modelled).
    Find,
}

/// Why the part could not be stood as asked. Each message is one line.
#[derive(Debug, thiserror::Error)]
pub enum PlaceError {
    /// The file could not be read into a part.
    #[error(transparent)]
    Read(#[from] brep::ReadError),
    /// `--base-face` names no face of the file.
    #[error("--base-face {0}: no face #{0} in the file")]
    NoFace(u64),
    /// `--base-face` names a face that is not planar.
    #[error("--base-face {id}: face #{id} is not planar (a {kind} face): the part stands on a planar face")]
    NotPlanar {
        /// The face's STEP `#id`.
        id: u64,
        /// Its surface's kind.
        kind: String,
    },
    /// `--orient auto` found no planar face.
    #[error("--orient auto: the part has no planar face to stand on")]
    NoPlanarFace,
    /// No candidate's features could be extracted.
    #[error("--orient auto: the features of no candidate placement could be extracted")]
    NoCandidate,
}

/// The part stood on the plate, with what `plan.json` records of it.
#[derive(Debug)]
pub struct Placed {
    /// The part as it stands.
    pub part: StepPart,
    /// Its features, when the placement extracted them (`--orient auto`).
    pub assembly: Option<Assembly>,
    /// How it was turned; `None`: as modelled.
    pub entry: Option<PlacementEntry>,
}

/// Stands the part of `file` as `how` says; `--orient auto` measures each candidate's support
/// with `process`'s layers and beads `bead_width` wide.
pub fn place(
    file: &dyn PartFile,
    how: Placement,
    process: &crate::Process,
    bead_width: f64,
) -> Result<Placed, PlaceError> {
    let part = file.part()?;
    match how {
        Placement::AsModelled | Placement::Find => Ok(Placed {
            part,
            assembly: None,
            entry: None,
        }),
        Placement::BaseFace(id) => base_face(file, part, id),
        Placement::Auto => auto(file, part, process, bead_width),
    }
}

/// The part on its planar face `#id`.
fn base_face(file: &dyn PartFile, part: StepPart, id: u64) -> Result<Placed, PlaceError> {
    let b = &part.brep;
    let face = (0..b.faces.len())
        .map(|k| FaceId(k as u32))
        .find(|&f| b.face(f).step_id == id)
        .ok_or(PlaceError::NoFace(id))?;
    let down = b.plane_normal(face).ok_or_else(|| PlaceError::NotPlanar {
        id,
        kind: features::extract::surface_kind(b.face_surface(face)),
    })?;
    let d = [down.x, down.y, down.z];
    let part = if stands(down) { part } else { file.turned(d)? };
    Ok(Placed {
        part,
        assembly: None,
        entry: Some(entry(id, d, "base-face".into())),
    })
}

/// The part on the face the rule of `--orient auto` picks (module docs).
fn auto(
    file: &dyn PartFile,
    part: StepPart,
    process: &crate::Process,
    bead_width: f64,
) -> Result<Placed, PlaceError> {
    let candidates = candidates(&part.brep);
    if candidates.is_empty() {
        return Err(PlaceError::NoPlanarFace);
    }
    // The best candidate by its rank key, with its unsupported area, the part turned onto it
    // and its features.
    let mut best: Option<(RankKey, f64, &Candidate, StepPart, Assembly)> = None;
    for (k, c) in candidates.iter().enumerate() {
        let Some((key, unsupported, turned, assembly)) = measure(file, c, k, process, bead_width)?
        else {
            continue;
        };
        if best
            .as_ref()
            .is_none_or(|(b, ..)| key.partial_cmp(b) == Some(std::cmp::Ordering::Less))
        {
            best = Some((key, unsupported, c, turned, assembly));
        }
    }
    let ((_, below, _, _), unsupported, c, turned, assembly) =
        best.ok_or(PlaceError::NoCandidate)?;
    let rule = format!(
        "auto: of {} planar directions, one leaving no area unsupported where one does (this one: {unsupported:.1} mm^2), then the fewest features with a build direction below the horizon ({below}), then the most planar area down ({:.1} mm^2)",
        candidates.len(),
        c.area
    );
    let d = [c.down.x, c.down.y, c.down.z];
    Ok(Placed {
        // The part as modelled when the winner already points down.
        part: if stands(c.down) { part } else { turned },
        assembly: Some(assembly),
        entry: Some(entry(c.face_id, d, rule)),
    })
}

/// `c`, the `k`-th candidate, measured: its rank key, its planar area unsupported (infinite
/// when it cannot be measured), the part turned onto it and its features; `None` when its
/// features cannot be extracted.
fn measure(
    file: &dyn PartFile,
    c: &Candidate,
    k: usize,
    process: &crate::Process,
    bead_width: f64,
) -> Result<Option<(RankKey, f64, StepPart, Assembly)>, PlaceError> {
    let turned = file.turned([c.down.x, c.down.y, c.down.z])?;
    let Ok(assembly) = extract_all(&turned.brep, &ExtractOptions::default()) else {
        return Ok(None);
    };
    let below = assembly
        .trees
        .iter()
        .flat_map(|t| t.features.iter())
        .filter(|f| f.reference.normal.is_some_and(|n| n[2] < BELOW_HORIZON_Z))
        .count();
    // A candidate whose support cannot be measured ranks after every one that can.
    let unsupported =
        crate::support::planar_area(&assembly, process, bead_width).unwrap_or(f64::INFINITY);
    let key = (unsupported > 0.0, below, -c.area, k);
    Ok(Some((key, unsupported, turned, assembly)))
}

/// A planar face the part may stand on, as `--orient auto` ranks them ([`ranked_faces`]).
#[derive(Debug, Clone, PartialEq)]
pub struct RankedFace {
    /// STEP `#id` of the largest planar face pointing this way.
    pub id: u64,
    /// Their outward normal in the file's frame, turned to −Z to stand on them.
    pub down: [f64; 3],
    /// Whether the part already stands this way as modelled (its −Z).
    pub as_modelled: bool,
}

/// The directions the part's planar faces point outward, best first by the rule of
/// `--orient auto` (module docs), each with its largest face; those whose features cannot be
/// extracted are left out.
pub fn ranked_faces(
    file: &dyn PartFile,
    process: &crate::Process,
    bead_width: f64,
) -> Result<Vec<RankedFace>, PlaceError> {
    let part = file.part()?;
    let candidates = candidates(&part.brep);
    let mut keyed = vec![];
    for (k, c) in candidates.iter().enumerate() {
        if let Some((key, ..)) = measure(file, c, k, process, bead_width)? {
            keyed.push((key, c));
        }
    }
    keyed.sort_by(|a, b| a.0.partial_cmp(&b.0).unwrap_or(std::cmp::Ordering::Equal));
    Ok(keyed
        .into_iter()
        .map(|(_, c)| RankedFace {
            id: c.face_id,
            down: [c.down.x, c.down.y, c.down.z],
            as_modelled: stands(c.down),
        })
        .collect())
}

/// A candidate's rank, least first: some planar area unsupported, features needing an axis
/// below the horizon, −planar area down, its index.
type RankKey = (bool, usize, f64, usize);

/// Whether `down` already points down (−Z): the part stands as modelled.
fn stands(down: V3) -> bool {
    down.z < STANDS_Z
}

/// What plan.json records of standing the part on face `face`, whose outward normal `down` is
/// turned to −Z.
pub fn entry(face: u64, down: [f64; 3], rule: String) -> PlacementEntry {
    entry_turned(Some(face), down, brep::turn_down(down), rule)
}

/// What plan.json records of standing the part by `rotation` (plate = rotation × file): on
/// face `face` (`None`: as modelled), whose outward normal `down` points down once turned.
pub fn entry_turned(
    face: Option<u64>,
    down: [f64; 3],
    rotation: [[f64; 3]; 3],
    rule: String,
) -> PlacementEntry {
    let r = |x: f64| crate::report::round(x, 1e9);
    PlacementEntry {
        base_face: face,
        down: down.map(r),
        rotation: rotation.map(|row| row.map(r)),
        rule,
        turn_deg: 0.0,
        tried: vec![],
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
    let planar: Vec<(FaceId, V3)> = (0..b.faces.len())
        .map(|k| FaceId(k as u32))
        .filter_map(|f| Some((f, b.plane_normal(f)?)))
        .collect();
    let faces: Vec<FaceId> = planar.iter().map(|p| p.0).collect();
    for (&(f, n), area) in planar.iter().zip(face_areas(b, &faces)) {
        match out
            .iter_mut()
            .find(|(c, _)| c.down.dot(&n) > SAME_DIRECTION_DOT)
        {
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

/// Each face's area from one mesh of them all (a mesh's B-rep has a face per triangle: one
/// mesh each was quadratic in them); face by face ([`face_area`]) when they do not mesh
/// together.
fn face_areas(b: &Brep, faces: &[FaceId]) -> Vec<f64> {
    let Ok(m) = mesh_faces(b, faces, &MeshOptions::default()) else {
        return faces.iter().map(|&f| face_area(b, f)).collect();
    };
    m.faces
        .iter()
        .map(|t| {
            t.triangles
                .iter()
                .map(|tri| {
                    let [a, c, d] = tri.map(|i| m.positions[t.vertex[i as usize] as usize]);
                    0.5 * (c - a).cross(&(d - a)).norm()
                })
                .sum()
        })
        .collect()
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
