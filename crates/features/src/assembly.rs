//! A file of several solids: each solid's feature tree, the order the solids are built in, and
//! what the user should know about how they sit together.
//!
//! CAD systems often write one body per solid (Shapr3D writes an impeller's hub and blades
//! apart), and the bodies may touch, overlap or float. Each solid is planned on its own, so:
//! - solids are built lowest first (along +Z, the build direction), so a body standing on another
//!   is built after it;
//! - two solids that overlap are reported with the overlap's volume: each is planned whole, so
//!   that material would be laid twice (the cure is a union in CAD);
//! - a solid that starts above the build plate without resting on another solid is reported:
//!   its first layer would be laid in the air;
//! - a solid that encloses no volume (a sliver a CAD system left) is skipped with a warning.

use crate::extract::{ExtractError, FeatureTree};
use brep::math::{Aabb, P3};
use brep::topology::{Brep, SolidId};
use parry3d::na::Point3;
use parry3d::query::PointQuery;
use parry3d::shape::{TriMesh, TriMeshFlags};

/// Solids enclosing less than this (mm³, a 0.1 mm cube) are skipped: no bead can print them.
pub const EMPTY_VOLUME: f64 = 1e-3;
/// Grid points per axis over the common box of two solids when their overlap is measured.
const OVERLAP_GRID: usize = 24;
/// Overlaps under this share of the smaller solid's volume are not reported: the analysis
/// meshes' chords alone make touching solids seem to overlap by about that much.
const OVERLAP_SHARE: f64 = 0.01;
/// How far above the lowest solid (mm) a solid must start to need something under it.
const PLATE_TOL: f64 = 0.05;
/// Points of a solid's bottom probed for a solid under it, at most.
const PROBES: usize = 32;

/// The feature trees of a file's solids, in build order.
#[derive(Debug, Clone)]
pub struct Assembly {
    /// One tree per solid that encloses a volume, lowest first.
    pub trees: Vec<FeatureTree>,
    /// About the solids together: skipped, overlapping, floating.
    pub warnings: Vec<String>,
    /// Some of its solids overlap (bodies pushed into each other, sharing more than 1 % of
    /// the smaller's volume): planned one feature tree per solid, the material they share
    /// would be laid twice.
    pub overlapping: bool,
}

impl Assembly {
    /// Every warning: those about the solids together, then each tree's own, with its solid
    /// named when there are several.
    pub fn all_warnings(&self) -> Vec<String> {
        let mut out = self.warnings.clone();
        for t in &self.trees {
            let name = (self.trees.len() > 1).then(|| solid_name(t));
            out.extend(t.warnings.iter().map(|w| match &name {
                Some(n) => format!("{n}: {w}"),
                None => w.clone(),
            }));
        }
        out
    }
}

/// `solid #id`, the STEP entity of a tree's solid; `body N` for a mesh's body (its place
/// among the file's bodies), with the object's name when it has one.
pub fn solid_name(t: &FeatureTree) -> String {
    let s = &t.brep.solids[t.solid.idx()];
    match (t.brep.origin, s.name.as_str()) {
        (brep::topology::Origin::Step, _) => format!("solid #{}", s.step_id),
        (brep::topology::Origin::Mesh, "") => format!("body {}", s.step_id),
        (brep::topology::Origin::Mesh, name) => format!("body {} (`{name}`)", s.step_id),
    }
}

/// Each solid of `brep` made a tree by `tree_of`, then ordered and checked together (see
/// [`crate::extract_all`]).
pub(crate) fn assemble(
    brep: &Brep,
    tree_of: impl Fn(&Brep, SolidId) -> Result<FeatureTree, ExtractError>,
) -> Result<Assembly, ExtractError> {
    let (trees, warnings) = solid_trees(brep, tree_of)?;
    Ok(relate(
        trees.into_iter().map(|(_, t)| t).collect(),
        warnings,
    ))
}

/// A solid of a B-rep and the tree made of it.
pub(crate) type SolidTree = (SolidId, FeatureTree);

/// Each solid of `brep` that encloses a volume with the tree `tree_of` made of it, lowest
/// first; a warning for each solid skipped as empty. An error when none encloses a volume.
pub(crate) fn solid_trees(
    brep: &Brep,
    tree_of: impl Fn(&Brep, SolidId) -> Result<FeatureTree, ExtractError>,
) -> Result<(Vec<SolidTree>, Vec<String>), ExtractError> {
    let mut trees = vec![];
    let mut warnings = vec![];
    let mut empty = vec![];
    for s in brep.solid_ids() {
        let t = tree_of(brep, s)?;
        if t.part_volume < EMPTY_VOLUME {
            empty.push(t);
        } else {
            trees.push((s, t));
        }
    }
    if trees.is_empty() {
        return Err(match empty.first() {
            Some(t) => ExtractError::Empty(format!(
                "{} encloses {:.3} mm^3: nothing to print",
                solid_name(t),
                t.part_volume
            )),
            None => ExtractError::Empty("the file holds no solid".into()),
        });
    }
    for t in &empty {
        warnings.push(format!(
            "{} encloses {:.3} mm^3 ({:.3} mm^2 of surface): nothing to print, skipped",
            solid_name(t),
            t.part_volume,
            t.part_area
        ));
    }
    trees.sort_by(|(_, a), (_, b)| a.mesh.bbox().min.z.total_cmp(&b.mesh.bbox().min.z));
    Ok((trees, warnings))
}

/// Two solids (indices into the trees, lowest first) that share more than [`OVERLAP_SHARE`]
/// of the smaller one's volume.
pub(crate) struct Overlap {
    /// The lower solid.
    pub first: usize,
    /// The solid that overlaps it.
    pub second: usize,
    /// The volume they share, mm³.
    pub volume: f64,
    /// The smaller solid's volume, mm³.
    pub smaller: f64,
}

/// The pairs of `trees` (lowest first) that overlap.
pub(crate) fn overlaps(trees: &[FeatureTree]) -> Vec<Overlap> {
    let solids: Vec<Solid> = trees.iter().map(|t| Solid::new(t, t.mesh.bbox())).collect();
    overlaps_of(&solids)
}

fn overlaps_of(solids: &[Solid]) -> Vec<Overlap> {
    let mut out = vec![];
    for i in 0..solids.len() {
        for j in i + 1..solids.len() {
            let volume = overlap_volume(&solids[i], &solids[j]);
            let smaller = solids[i].volume.min(solids[j].volume);
            if volume > OVERLAP_SHARE * smaller {
                out.push(Overlap {
                    first: i,
                    second: j,
                    volume,
                    smaller,
                });
            }
        }
    }
    out
}

/// `trees` (lowest first) as an assembly, with `warnings` and what the user should know about
/// how its solids sit together: overlaps, and solids that start in the air.
pub(crate) fn relate(trees: Vec<FeatureTree>, mut warnings: Vec<String>) -> Assembly {
    let mut overlapping = false;
    if trees.len() > 1 {
        let solids: Vec<Solid> = trees.iter().map(|t| Solid::new(t, t.mesh.bbox())).collect();
        // Solids that overlap one built before them stand on it.
        let mut supported = vec![false; solids.len()];
        let shared = overlaps_of(&solids);
        overlapping = !shared.is_empty();
        for o in shared {
            supported[o.second] = true;
            warnings.push(format!(
                "{} and {} overlap by about {:.0} mm^3 ({:.0} % of the smaller): each is planned \
                 whole, so that material would be laid twice; unite them in CAD",
                solid_name(&trees[o.first]),
                solid_name(&trees[o.second]),
                o.volume,
                100.0 * o.volume / o.smaller
            ));
        }
        let plate = solids[0].bbox.min.z;
        for j in 1..solids.len() {
            let lift = solids[j].bbox.min.z - plate;
            if lift > PLATE_TOL && !supported[j] && !rests_on_another(&trees[j], &solids, j) {
                warnings.push(format!(
                    "{} starts {lift:.3} mm above the build plate and rests on no other solid: \
                     its first layer would be laid in the air",
                    solid_name(&trees[j])
                ));
            }
        }
    }
    Assembly {
        trees,
        warnings,
        overlapping,
    }
}

/// A solid's closed analysis mesh and figures.
struct Solid {
    /// The mesh for inside tests (parry's angle-weighted pseudo-normals over a bounding volume
    /// hierarchy); `None` when it has no triangles.
    shape: Option<TriMesh>,
    bbox: Aabb,
    volume: f64,
    /// Chord tolerance of its analysis mesh, mm.
    chord: f64,
}

impl Solid {
    /// `t`'s solid, whose analysis mesh has the box `bbox`.
    fn new(t: &FeatureTree, bbox: Aabb) -> Solid {
        let vertices: Vec<Point3<f32>> = t
            .mesh
            .positions
            .iter()
            .map(|p| Point3::new(p.x as f32, p.y as f32, p.z as f32))
            .collect();
        let triangles = t.mesh.triangles();
        let shape = (!triangles.is_empty()).then(|| {
            let mut m = TriMesh::new(vertices, triangles);
            // Pseudo-normals need each edge shared by two triangles; an analysis mesh is
            // closed, and where it is not, the answer is still parry's best guess.
            let _ = m.set_flags(TriMeshFlags::ORIENTED);
            m
        });
        Solid {
            shape,
            bbox,
            volume: t.part_volume,
            chord: brep::solid::analysis_options(bbox.diagonal().max(1e-3)).chord_tol,
        }
    }

    fn contains(&self, p: &P3) -> bool {
        self.bbox.contains(p)
            && self.shape.as_ref().is_some_and(|m| {
                m.contains_local_point(&Point3::new(p.x as f32, p.y as f32, p.z as f32))
            })
    }
}

/// The volume (mm³) two solids share, counted on a grid of [`OVERLAP_GRID`]³ cell centres over
/// their common box: 0 when the boxes do not meet.
fn overlap_volume(a: &Solid, b: &Solid) -> f64 {
    let lo = a.bbox.min.sup(&b.bbox.min);
    let hi = a.bbox.max.inf(&b.bbox.max);
    let size = hi - lo;
    if size.iter().any(|&d| d <= 0.0) {
        return 0.0;
    }
    let (first, second) = (a, b);
    let n = OVERLAP_GRID;
    let step = size / n as f64;
    let mut hits = 0usize;
    for i in 0..n {
        for j in 0..n {
            for k in 0..n {
                let p = lo
                    + brep::math::V3::new(
                        (i as f64 + 0.5) * step.x,
                        (j as f64 + 0.5) * step.y,
                        (k as f64 + 0.5) * step.z,
                    );
                if first.contains(&p) && second.contains(&p) {
                    hits += 1;
                }
            }
        }
    }
    hits as f64 * step.x * step.y * step.z
}

/// Whether some point of solid `j`'s bottom has another solid, one that starts lower,
/// just under it (or around it).
fn rests_on_another(t: &FeatureTree, solids: &[Solid], j: usize) -> bool {
    let low = solids[j].bbox.min.z;
    let bottom: Vec<&P3> = t
        .mesh
        .positions
        .iter()
        .filter(|p| p.z <= low + PLATE_TOL)
        .collect();
    let stride = bottom.len().div_ceil(PROBES).max(1);
    solids.iter().enumerate().any(|(i, s)| {
        i != j
            && s.bbox.min.z < low
            && bottom.iter().step_by(stride).any(|p| {
                // Below the chords of a convex face of `s` the exact surface may still be
                // above the probe; go a chord deeper than that.
                let probe = P3::new(p.x, p.y, p.z - (s.chord + PLATE_TOL));
                s.contains(&probe)
            })
    })
}
