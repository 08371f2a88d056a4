//! The mesh a feature is sliced from, its chord tolerance, and its growth by a machining
//! allowance (issue 37, item 2).

use crate::error::FeatureError;
use crate::geom2d::Region;
use crate::params::LayerParams;
use crate::tolerance::MICROMETRE;
use brep::mesh::{enclosed_volume, mesh_faces, offset_mesh, MeshOptions};
use features::{Feature, FeatureTree};

/// Chord tolerance of the mesh a feature is sliced from: much finer than a layer, since its
/// chords are what the sections see.
pub(crate) fn slicing_tolerance(params: &LayerParams) -> f64 {
    (params.tolerance * 0.25)
        .min(0.25 * params.uniform_layer_height)
        .max(MICROMETRE)
}

/// How far a feature's mesh is grown for machining (issue 37, item 2), mm: `own` its
/// `machining_allowance` (every face but the build-plate face, the feature's base and its voids,
/// outward), `base` its parent's (the base faces, which lie on the parent's face, moved with
/// that face's offset: into the feature by that much).
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct Allowance {
    /// The feature's own faces' offset, mm.
    pub own: f64,
    /// Its base faces' lift, mm.
    pub base: f64,
}

impl Allowance {
    /// A feature's allowance from its parameters.
    pub fn of(params: &LayerParams) -> Allowance {
        Allowance {
            own: params.machining_allowance,
            base: params.base_allowance,
        }
    }

    /// The allowance of the feature a feature with `params` grows from (its own faces grown by
    /// the child's `base_allowance`; its base, far under the child, taken as not lifted).
    pub fn of_parent(params: &LayerParams) -> Allowance {
        Allowance {
            own: params.base_allowance,
            base: 0.0,
        }
    }

    /// The allowance of a solid built before the one with `params` (its own allowance taken
    /// as this one's, standing on the plate).
    pub fn of_parent_solid(params: &LayerParams) -> Allowance {
        Allowance {
            own: params.machining_allowance,
            base: 0.0,
        }
    }

    /// Nothing is grown.
    pub fn is_none(&self) -> bool {
        self.own == 0.0 && self.base == 0.0
    }
}

/// What growing a feature by its allowance gave (issue 37, item 2).
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Grown {
    /// The grown solid's volume, mm³: the nominal volume plus what the offset added to the
    /// mesh (so the mesh's chords count the same in both).
    pub volume: f64,
    /// Nominal points where the offset turned a triangle over (a concave radius under the
    /// allowance): the grown surface crosses itself there and its sections are read by winding.
    pub folds: Vec<[f64; 3]>,
    /// Nominal points of knife edges whose mitre was cut back.
    pub capped: Vec<[f64; 3]>,
    /// Planar layers only: the volume of the layers that cover the grown solid (each the union
    /// of its sections over its thickness, `crate::planar`), mm³; more than `volume` by the
    /// stair-steps they keep outside the allowance. What the self-check expects then.
    pub layered_volume: Option<f64>,
}

impl Grown {
    /// The volume the plan of the grown feature is checked against, mm³: its layers' where
    /// they cover it, else the grown solid's.
    pub fn planned_volume(&self) -> f64 {
        self.layered_volume.unwrap_or(self.volume)
    }
}

/// The reference plane of a two5d feature: through its healing faces (or build-plate face),
/// normal pointing into the feature.
pub fn reference_plane(tree: &FeatureTree, f: &Feature) -> Option<brep::section::Plane> {
    let n = f
        .reference
        .normal
        .map(|n| brep::math::V3::new(n[0], n[1], n[2]))?;
    let b = &tree.brep;
    // A point of the reference: a vertex of the reference face; else the feature's lowest
    // point, on its surfaces (a torus or a cylinder lying on its side is lowest between its
    // vertices, which may all lie at its middle height).
    let face = f.heal_faces.first().copied().or(f.reference.face);
    let p = match (face, f.reference.origin) {
        (Some(fc), _) => b
            .vertices_of(&[fc])
            .first()
            .map(|v| b.vertices[v.idx()].point),
        (None, Some(o)) => Some(brep::math::P3::from(o)),
        (None, None) => {
            features::extract::lowest_point(b, &f.faces, [n.x, n.y, n.z]).map(brep::math::P3::from)
        }
    }?;
    Some(brep::section::Plane::new(p, n))
}

/// What a two5d feature's planar layers are cut from: the layers' plane (its reference plane
/// lifted onto its parent's grown face, `base_allowance`), the feature's mesh at the slicing
/// tolerance grown by its allowance (with what growing gave) and its top, the height of its
/// highest mesh point over the plane. Made once for a feature's support, fill and resolution
/// check (the mesh is the costliest part of each: NIST CTC-05's largest feature 0.27 s).
#[derive(Debug, Clone)]
pub struct PlanarMesh {
    /// The layers' plane.
    pub plane: brep::section::Plane,
    /// The feature's mesh.
    pub mesh: brep::mesh::Mesh,
    /// What growing it by its machining allowance gave (`None` without one).
    pub grown: Option<Grown>,
    /// Its layers in order, each `(middle, top, thickness)` over `plane`, mm: the layer
    /// heights `params` give up to its highest mesh point, through the heights of its faces
    /// parallel to the plane (`two5d_layer_heights`). The support, the fill and the
    /// resolution check all cut these layers.
    pub layers: Vec<(f64, f64, f64)>,
    /// Each layer's section at its middle, simplified as the fill lays it, where found
    /// already (by the feature's support, [`crate::support::PlanarSupport::sections`]): the
    /// fill of a feature not grown by an allowance takes them (NIST CTC-05's largest feature:
    /// 0.6 s of sections). `None` from [`PlanarMesh::of`].
    pub mid_sections: Option<Vec<Vec<crate::geom2d::Region>>>,
}

impl PlanarMesh {
    /// `given` (made already for the feature), or the feature's own made now ([`PlanarMesh::of`]).
    pub fn given_or_of<'a>(
        given: Option<&'a PlanarMesh>,
        tree: &FeatureTree,
        f: &Feature,
        params: &crate::params::LayerParams,
    ) -> Result<std::borrow::Cow<'a, PlanarMesh>, FeatureError> {
        Ok(match given {
            Some(m) => std::borrow::Cow::Borrowed(m),
            None => std::borrow::Cow::Owned(PlanarMesh::of(tree, f, params)?),
        })
    }

    /// The planar mesh of two5d feature `f` of `tree` with its `params`.
    pub fn of(
        tree: &FeatureTree,
        f: &Feature,
        params: &crate::params::LayerParams,
    ) -> Result<Self, FeatureError> {
        let plane = reference_plane(tree, f).ok_or(FeatureError::NoPlane(f.id))?;
        let plane = plane.offset(params.base_allowance);
        let (mesh, grown) = grown_mesh(tree, f, slicing_tolerance(params), Allowance::of(params))?;
        let top = mesh
            .positions
            .iter()
            .map(|p| plane.height(p))
            .fold(0.0f64, f64::max);
        let layers = layer_tops(0.0, &two5d_layer_heights(params, &mesh, &plane, top));
        Ok(PlanarMesh {
            plane,
            mesh,
            grown,
            layers,
            mid_sections: None,
        })
    }
}

/// Layers `thicknesses` thick stacked from height `from`: each `(middle, top, thickness)`.
pub(crate) fn layer_tops(from: f64, thicknesses: &[f64]) -> Vec<(f64, f64, f64)> {
    let mut z = from;
    thicknesses
        .iter()
        .map(|&dl| {
            let layer = (z + 0.5 * dl, z + dl, dl);
            z += dl;
            layer
        })
        .collect()
}

/// The faces of a mesh whose points lie within this of one height over the layers' plane
/// (mm) are parallel to it: steps of the feature's section.
const FLAT_FACE_SPAN: f64 = 1e-4;

/// The layer thicknesses of a two5d feature meshed as `mesh`, `top` high over its reference
/// `plane`: [`crate::params::LayerParams::layer_heights_through`] the heights of its faces parallel to the
/// plane (each face's points within [`FLAT_FACE_SPAN`] of one height), so that a layer
/// boundary lies where the section changes at once.
fn two5d_layer_heights(
    params: &crate::params::LayerParams,
    mesh: &brep::mesh::Mesh,
    plane: &brep::section::Plane,
    top: f64,
) -> Vec<f64> {
    let mut steps = vec![];
    for f in &mesh.faces {
        let (lo, hi) = f
            .vertex
            .iter()
            .filter_map(|&v| mesh.positions.get(v as usize))
            .map(|p| plane.height(p))
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), z| {
                (lo.min(z), hi.max(z))
            });
        if hi - lo <= FLAT_FACE_SPAN && !f.triangles.is_empty() {
            steps.push(0.5 * (lo + hi));
        }
    }
    params.layer_heights_through(top, &steps)
}

/// The mesh of a feature's shell and its voids, at chord tolerance `tol`, grown by `allowance`.
pub(crate) fn feature_mesh(
    tree: &FeatureTree,
    f: &Feature,
    tol: f64,
    allowance: Allowance,
) -> Result<brep::mesh::Mesh, FeatureError> {
    Ok(grown_mesh(tree, f, tol, allowance)?.0)
}

/// [`feature_mesh`], and what growing it gave (`None` without an allowance).
pub(crate) fn grown_mesh(
    tree: &FeatureTree,
    f: &Feature,
    tol: f64,
    allowance: Allowance,
) -> Result<(brep::mesh::Mesh, Option<Grown>), FeatureError> {
    let mut faces = f.faces.clone();
    for v in &f.voids {
        faces.extend(v.iter().copied());
    }
    let mesh_at = |tol: f64| {
        mesh_faces(&tree.brep, &faces, &MeshOptions::with_tolerance(tol)).map_err(|e| {
            FeatureError::Mesh {
                id: f.id,
                msg: e.to_string(),
            }
        })
    };
    let mut mesh = mesh_at(tol)?;
    // A small feature's sections lose to their chords what its volume keeps (issue 31, item
    // 4): meshed again finer for its thickness.
    let fine = THICKNESS_CHORD_SHARE * thickness(f.volume, &mesh);
    if fine.is_finite() && fine < tol {
        mesh = mesh_at(fine.max(MICROMETRE))?;
    }
    let grown = match allowance.is_none() {
        true => None,
        false => {
            let nominal = enclosed_volume(&mesh);
            let (m, g) = grow(tree, f, &mesh, allowance);
            mesh = m;
            Some(Grown {
                volume: f.volume + enclosed_volume(&mesh) - nominal,
                ..g
            })
        }
    };
    orient_voids(&mut mesh, &f.voids);
    Ok((mesh, grown))
}

/// `mesh` (the feature's, voids not yet turned) offset by `allowance`: the build-plate face and
/// the voids (closed cavities no cutter reaches) stay, the base faces move in by `base`, every
/// other face out by `own`.
fn grow(
    tree: &FeatureTree,
    f: &Feature,
    mesh: &brep::mesh::Mesh,
    allowance: Allowance,
) -> (brep::mesh::Mesh, Grown) {
    let plate = plate_faces(f, mesh);
    let distance = |face: brep::topology::FaceId| {
        if plate.contains(&face) || f.voids.iter().any(|v| v.contains(&face)) {
            0.0
        } else if f.heal_faces.contains(&face) {
            -allowance.base
        } else {
            allowance.own
        }
    };
    let off = offset_mesh(&tree.brep, mesh, &distance);
    let xyz = |p: &brep::math::P3| [p.x, p.y, p.z];
    let grown = Grown {
        volume: 0.0,
        folds: off.folds.iter().map(xyz).collect(),
        capped: off.capped.iter().map(xyz).collect(),
        layered_volume: None,
    };
    (off.mesh, grown)
}

/// Where a layer's sections are taken near its bottom and top, as a share of its thickness in
/// from them ([`covering_section`]).
const COVER_INSET: f64 = 0.02;

/// A layer of a feature grown by a machining allowance (issue 37, item 2): what its sections
/// at its middle, near its bottom and near its top (`at` each height; the layer's middle, top
/// and thickness given) cover together, so that the layer holds the grown solid over its whole
/// thickness and a stair-step never eats into the allowance where a face slopes (a section at
/// the middle alone leaves `h/2·cos α` of it uncovered on a face at α from the layers). The
/// union (non-zero) also reads the grown mesh's trimmed folds as the solid they bound.
pub(crate) fn covering_section(
    at: impl Fn(f64) -> Vec<Region>,
    (mid, top, dl): (f64, f64, f64),
) -> Vec<Region> {
    let inset = COVER_INSET * dl;
    let mut r = crate::fill::union(&at(mid), &at(top - dl + inset));
    r = crate::fill::union(&r, &at(top - inset));
    r
}

/// A face of `mesh` this close (mm) to the plate all over lies on it.
const ON_PLATE_MM: f64 = 1e-4;

/// The faces of feature `f` (meshed as `mesh`) that lie on the build plate: for a feature on the
/// plate, its reference face and every face whose points all lie at its lowest height along
/// the build direction (a part sliced whole names no face).
pub(crate) fn plate_faces(f: &Feature, mesh: &brep::mesh::Mesh) -> Vec<brep::topology::FaceId> {
    if f.reference.surface != "build_plate" {
        return vec![];
    }
    let mut out: Vec<_> = f.reference.face.into_iter().collect();
    let Some(n) = f.reference.normal else {
        return out;
    };
    let up = brep::math::V3::new(n[0], n[1], n[2]);
    let height = |g: &u32| mesh.positions.get(*g as usize).map(|p| p.coords.dot(&up));
    let low = mesh
        .positions
        .iter()
        .map(|p| p.coords.dot(&up))
        .fold(f64::INFINITY, f64::min);
    for t in &mesh.faces {
        let flat = t
            .vertex
            .iter()
            .all(|g| height(g).is_some_and(|h| h - low <= ON_PLATE_MM));
        if flat && !t.triangles.is_empty() && !out.contains(&t.face) {
            out.push(t.face);
        }
    }
    out
}

/// Each void shell of `voids` turned to face into the void where a file wrote it facing out
/// (enclosing a positive volume, like a solid's outer shell): its sections then run clockwise
/// around the void, as a hole's do, which the winding reading of crossing loops
/// (`fill::regions_by_winding`) relies on.
fn orient_voids(mesh: &mut brep::mesh::Mesh, voids: &[Vec<brep::topology::FaceId>]) {
    for v in voids {
        let of_void = |t: &brep::mesh::FaceTriangulation| v.contains(&t.face);
        let volume: f64 = mesh
            .faces
            .iter()
            .filter(|t| of_void(t))
            .flat_map(|t| {
                t.triangles.iter().map(|tri| {
                    let [a, b, c] = tri.map(|i| mesh.positions[t.vertex[i as usize] as usize]);
                    a.coords.dot(&b.coords.cross(&c.coords)) / 6.0
                })
            })
            .sum();
        if volume > 0.0 {
            for t in mesh.faces.iter_mut().filter(|t| of_void(t)) {
                for tri in &mut t.triangles {
                    tri.swap(1, 2);
                }
            }
        }
    }
}

/// The chord tolerance of a feature's mesh as a share of its thickness ([`thickness`]): a
/// round section of radius r meshed at chord tolerance s keeps, as an inscribed polygon, about
/// `1 − (4/3)·s/r` of its area (each chord of length c cuts off a segment of area
/// `(2/3)·c·s`, and the chords add up to `2πr`). A pin's thickness `2V/A` is about its radius
/// (`r·h/(r + h)` with its ends), so this share keeps a pin's sections within 0.3 % of their
/// area: a 1.39 mm pin was 2.4 % short at the slicing tolerance of 0.0125 mm.
const THICKNESS_CHORD_SHARE: f64 = 0.002;

/// A feature's thickness, mm: twice its volume over its surface area (a wall's thickness, a
/// long pin's radius); infinite where the mesh has no area.
fn thickness(volume: f64, mesh: &brep::mesh::Mesh) -> f64 {
    let area: f64 = mesh
        .triangles()
        .iter()
        .map(|t| {
            let [a, b, c] = t.map(|i| mesh.positions[i as usize]);
            0.5 * (b - a).cross(&(c - a)).norm()
        })
        .sum();
    if area > 0.0 && volume.is_finite() && volume > 0.0 {
        2.0 * volume / area
    } else {
        f64::INFINITY
    }
}
