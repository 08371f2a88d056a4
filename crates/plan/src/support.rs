//! The support gate (issue 31): every bead rests on the bead below it, on material laid
//! before it or on the plate, within the overhang limit (`overhang_angle_deg`). The measure is
//! the slicer's ([`slicer::support`]): planar layers from the features alone, before any path
//! is filled ([`planar`], also what `--orient auto` ranks placements by), curved layers as
//! they are laid (`FreeformFigures::support`). A feature with unsupported area fails the plan
//! like the self-check ([`crate::Gate::Unsupported`], one [`line()`] each), unless support
//! material carries it (issue 33, [`slicer::support_material`]): then only what support
//! cannot stand under (below the first layer of a feature growing from others) is refused. A
//! solid lifted over the plate gets columns below its base's first layer down to the plate
//! ([`slicer::support_below`]), across the gap between its base plane and the lowest solid's.

use crate::{PlanError, Process};
use features::{Assembly, FeatureKind};
use rayon::prelude::*;
use slicer::planar::PlanarMesh;
use slicer::support::{planar_support, Carry, FeatureSupport};
use slicer::support_material::SupportRegions;
use std::collections::BTreeMap;

/// Each feature's support material regions by file-wide id (features with support only).
pub type Columns = BTreeMap<usize, SupportRegions>;

/// Each two5d feature's planar mesh by file-wide id, with the sections its support was found
/// on: the fill and the resolution check take them from here rather than mesh and cut the
/// feature again.
pub type Meshes = BTreeMap<usize, PlanarMesh>;

/// What [`planar`] finds.
pub struct Planar {
    /// What holds up each two5d feature, by file-wide id.
    pub held: BTreeMap<usize, Held>,
    /// Support material regions (features with support only).
    pub columns: Columns,
    /// The features' planar meshes.
    pub meshes: Meshes,
}

/// What holds up one feature.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Held {
    /// Its unsupported area, by layer.
    pub support: FeatureSupport,
    /// Its overhang limit, degrees from the build direction.
    pub angle_deg: f64,
    /// Its kind.
    pub kind: FeatureKind,
}

/// The support of every two5d feature of `assembly` by file-wide id, with its parameters from
/// `process` and beads `bead_width` wide: no path filled (freeform features are left out;
/// their curved layers are measured as they are laid). A solid whose base feature lies above
/// the plate (the lowest base plane, [`PLATE_SLACK`]) rests on the solids built before it.
/// With [`Carry::Until`], support material (issue 33; unless `support_material = "off"`)
/// carries what it can ([`slicer::support::planar_support`]): each [`Held`] gives what is
/// left, and [`Planar::columns`] each feature's support regions (features with support only);
/// its columns are given up past the instant given ([`PlanError::TimeLimit`]: under a part
/// turned over, NIST CTC-05's columns took minutes).
pub fn planar(
    assembly: &Assembly,
    process: &Process,
    bead_width: f64,
    carry: Carry,
) -> Result<Planar, PlanError> {
    let base = process.base();
    let trees = &assembly.trees;
    // How high each solid's base plane stands along the build direction (+Z).
    let standing: Vec<Option<f64>> = trees
        .iter()
        .map(|t| {
            let b = t.features.first()?;
            let plane = slicer::planar::reference_plane(t, b)?;
            Some(plane.origin.z)
        })
        .collect();
    let plate = standing
        .iter()
        .flatten()
        .copied()
        .fold(f64::INFINITY, f64::min);
    // Every feature of every solid with what it needs, file-wide ids in build order.
    let mut jobs = vec![];
    let mut offset = 0;
    for (ti, t) in trees.iter().enumerate() {
        let lifted = standing[ti].is_some_and(|z| z > plate + PLATE_SLACK);
        let gap = match (lifted, standing[ti]) {
            (true, Some(z)) => z - plate,
            _ => 0.0,
        };
        for f in &t.features {
            jobs.push((ti, offset, f, lifted, gap));
        }
        offset += t.features.len();
    }
    // Each feature's support on its own (in parallel: one feature's meshing and column
    // carrying run on one core, NIST CTC-05's three features side by side).
    let found: Vec<Result<_, PlanError>> = jobs
        .par_iter()
        .with_max_len(1)
        .map(|&(ti, offset, f, lifted, gap)| {
            let t = &trees[ti];
            let earlier: Vec<_> = match lifted {
                true => trees[..ti]
                    .iter()
                    .flat_map(|u| u.features.iter().map(move |g| (u, g)))
                    .collect(),
                false => vec![],
            };
            let params = process.feature_params(&base, offset, f)?;
            // Parameters that do not validate are refused by `planar_support`, before
            // a mesh is made.
            let mut meshed = (f.kind == FeatureKind::Two5d && params.validate().is_ok())
                .then(|| PlanarMesh::of(t, f, &params))
                .transpose()?;
            let mut found = planar_support(
                t,
                f,
                &params,
                bead_width,
                &earlier,
                gap,
                carry,
                meshed.as_ref(),
            )
            .map_err(|e| match e {
                slicer::planar::FeatureError::TimeLimit(_) => PlanError::TimeLimit,
                e => e.into(),
            })?;
            // The sections the support was found on are the fill's.
            if let (Some(m), Some(p)) = (meshed.as_mut(), found.as_mut()) {
                m.mid_sections = Some(std::mem::take(&mut p.sections));
            }
            Ok((
                offset + f.id,
                params.overhang_angle_deg,
                f.kind,
                found,
                meshed,
            ))
        })
        .collect();
    let mut out = BTreeMap::new();
    let mut regions = BTreeMap::new();
    let mut meshes = BTreeMap::new();
    for r in found {
        let (id, angle_deg, kind, found, meshed) = r?;
        if let Some(m) = meshed {
            meshes.insert(id, m);
        }
        if let Some(p) = found {
            out.insert(
                id,
                Held {
                    support: p.left,
                    angle_deg,
                    kind,
                },
            );
            if !p.columns.is_empty() {
                regions.insert(id, p.columns);
            }
        }
    }
    Ok(Planar {
        held: out,
        columns: regions,
        meshes,
    })
}

/// How far (mm) above the lowest solid's base plane another solid's base may stand and still
/// be on the plate: a micrometre (solids modelled on one plane share it to round-off).
pub const PLATE_SLACK: f64 = 1e-3;

/// The unsupported area of `assembly`'s planar layers, mm², summed over its features
/// ([`planar`], without support material: a placement that needs less is better): 0 when
/// every layer is held up. What `--orient auto` ranks by first.
pub fn planar_area(
    assembly: &Assembly,
    process: &Process,
    bead_width: f64,
) -> Result<f64, PlanError> {
    Ok(planar(assembly, process, bead_width, Carry::Not)?
        .held
        .values()
        .map(|h| h.support.area_mm2)
        .sum())
}

/// The line a feature with unsupported area gets (`None` when it is held up): its id, kind,
/// the layer with the most unsupported area and that area, the total and the limit.
pub fn line(id: usize, held: &Held) -> Option<String> {
    let s = &held.support;
    let (layer, worst) = s.worst?;
    Some(format!(
        "feature {id} ({}): layer {layer}: {worst:.1} mm^2 unsupported ({:.1} mm^2 in {} layer(s); overhang limit {} degrees)",
        held.kind.as_str(),
        s.area_mm2,
        s.layers,
        held.angle_deg
    ))
}

/// One [`line()`] for each feature with unsupported area, by id.
pub fn lines(held: &BTreeMap<usize, Held>) -> Vec<String> {
    held.iter().filter_map(|(id, h)| line(*id, h)).collect()
}

/// A curved feature as another placement of the same part extracts it again: the part's faces
/// it holds and those of its voids (STEP `#id`s), the face it grows from, its parents' faces,
/// and its layer parameters. Its curved layers are laid on its reference surface along its
/// own tool axes, and measured against the layer below along them: gravity does not enter,
/// so a placement that turns the part extracts the same feature, lays the same layers and
/// finds the same unsupported area ([`KnownUnsupported`]).
#[derive(Debug, Clone, PartialEq)]
pub struct CurvedKey {
    faces: Vec<u64>,
    voids: Vec<u64>,
    reference: Option<u64>,
    parents: Vec<Vec<u64>>,
    params: slicer::params::LayerParams,
}

impl CurvedKey {
    /// The key of feature `f` of `tree` laid with `params`; `None` for a planar feature, or
    /// one without a face of the file (nothing to know it by).
    pub fn of(
        tree: &features::FeatureTree,
        f: &features::Feature,
        params: &slicer::params::LayerParams,
    ) -> Option<CurvedKey> {
        if f.kind != FeatureKind::Freeform {
            return None;
        }
        let faces = f.step_faces(&tree.brep);
        if faces.is_empty() {
            return None;
        }
        let mut voids: Vec<u64> = f
            .voids
            .iter()
            .flatten()
            .map(|&v| tree.brep.face(v).step_id)
            .collect();
        voids.sort_unstable();
        let parents = f
            .parents
            .iter()
            .filter_map(|&p| tree.features.get(p))
            .map(|p| p.step_faces(&tree.brep))
            .collect();
        Some(CurvedKey {
            faces,
            voids,
            reference: f.reference.step_face,
            parents,
            params: params.clone(),
        })
    }
}

/// Curved features whose layers one placement of a part found not held up, for the placements
/// tried after it ([`crate::retry::find`], [`crate::Options::known_unsupported`]): one that
/// extracts the same curved feature ([`CurvedKey`]) is refused for it before anything is
/// laid. The impeller on delta5: its second placement refused in 0.4 s where laying it again
/// to the blade's twelfth layer took 1.7 s (docs/measurements.md).
#[derive(Debug, Default)]
pub struct KnownUnsupported(std::sync::Mutex<Vec<(CurvedKey, Held)>>);

impl KnownUnsupported {
    /// Remembers that the feature `key` names is held up only as `held` says.
    pub fn add(&self, key: CurvedKey, held: Held) {
        if let Ok(mut known) = self.0.lock() {
            if !known.iter().any(|(k, _)| *k == key) {
                known.push((key, held));
            }
        }
    }

    /// What holds up the feature `key` names, when a placement before found it not held up.
    pub fn find(&self, key: &CurvedKey) -> Option<Held> {
        let known = self.0.lock().ok()?;
        known.iter().find(|(k, _)| k == key).map(|(_, h)| *h)
    }
}
