//! The machining allowance a plan leaves (issue 37, item 2): how much bead lies over each
//! nominal face of a feature grown by `machining_allowance`, measured on the planned path.
//!
//! The bead envelope is the union of the planned print segments' beads: a segment from `a` to
//! `b` lays a bead `width` wide across and `thickness` deep under the nozzle tip along the tool
//! axis (Isa & Lazoglu 2019, Eq. 1's rectangular section). The allowance left at a point `p` of
//! a nominal outer face is the radius of the largest ball around `p` inside the envelope: the
//! nearest way out, taken over rays leaving `p` within [`RAY_CONE_DEG`] of the face's outward
//! normal (a ray into the feature meets its own infill, which need not be solid), each marched
//! in steps of [`STEP_MM`] to its last point in a bead, with the envelope closed over a layer's
//! inner slivers ([`CLOSING_SHARE`]). Over a face the rays' least exit is the
//! normal's; at a concave corner between a feature and its parent it is the way out past the
//! corner. Points are the nominal mesh's vertices on the feature's own faces (not the
//! build-plate face, not the faces it grows from, not voids), at an even stride with a few on
//! every face; each is kept with what was left over it ([`AllowanceSample`]), for a picture of
//! the surface coloured by the allowance.

use crate::error::FeatureError;
use crate::feature_mesh::{feature_mesh, plate_faces, slicing_tolerance, Allowance};
use crate::params::LayerParams;
use crate::tolerance::SHORT_VECTOR;
use crate::toolpath::{MoveKind, PathPoint, Role};
use brep::math::{P3, V3};
use brep::section::Plane;
use brep::topology::FaceId;
use features::{Feature, FeatureTree};
use std::collections::HashMap;

/// Step of the march along each ray, mm: the measured allowance is within half of it.
pub const STEP_MM: f64 = 0.02;
/// Rays leave a point within this of its outward normal, degrees.
pub const RAY_CONE_DEG: f64 = 70.0;
/// Most points measured per feature (the vertices are taken at an even stride).
const MAX_SAMPLES: usize = 1500;
/// Each bead is taken larger by this share of the widest bead, and every exit that much
/// shorter: the envelope closed over the slivers a layer leaves between its perimeters and its
/// infill's turns (0.14 mm across at a boss's rim, 0.3 mm in a hub's top skin at its rim),
/// which the flowing bead fills and which are not outside the part. Beads of neighbouring
/// layers then also overlap on the surface they share.
pub const CLOSING_SHARE: f64 = 0.5;
/// A point this far out of a face that lies in a child feature is covered by it, mm.
const INSIDE_PROBE_MM: f64 = 0.05;
/// Side of the envelope's grid cells, mm.
const CELL_MM: f64 = 1.0;

/// Fewest points measured on each own face (all of a face with fewer vertices).
const MIN_PER_FACE: usize = 4;

/// One point of a nominal face and the allowance the beads leave over it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct AllowanceSample {
    /// The point, mm.
    pub at: [f64; 3],
    /// The B-rep face it lies on.
    pub face: FaceId,
    /// The allowance left over it, mm; `None` where a child feature covers the point (inside
    /// the part: nothing to machine).
    pub left: Option<f64>,
}

/// The allowance a plan leaves over a feature's nominal faces.
#[derive(Debug, Clone, PartialEq)]
pub struct AllowanceLeft {
    /// `machining_allowance` asked for, mm.
    pub requested: f64,
    /// Least allowance left over any measured point, mm.
    pub min: f64,
    /// Most, mm (a ray still in material at `requested` + 2 × bead width + 1 mm stops there).
    pub max: f64,
    /// Points measured.
    pub samples: usize,
    /// The nominal point where the least was measured.
    pub thinnest_at: [f64; 3],
    /// Every point measured, and those a child covers, face by face.
    pub measured: Vec<AllowanceSample>,
}

/// One print segment's bead.
#[derive(Debug, Clone, Copy)]
struct Bead {
    a: P3,
    b: P3,
    axis: V3,
    half_width: f64,
    thickness: f64,
}

impl Bead {
    /// Whether `x` lies in the bead grown by `closing` (module docs).
    fn holds(&self, x: &P3, closing: f64) -> bool {
        let h = (x - self.b).dot(&self.axis);
        if !(-self.thickness - closing..=closing).contains(&h) {
            return false;
        }
        let xp = x - self.axis * h;
        let ap = self.a - self.axis * (self.a - self.b).dot(&self.axis);
        let ab = self.b - ap;
        let len2 = ab.norm_squared();
        let t = if len2 > 0.0 {
            ((xp - ap).dot(&ab) / len2).clamp(0.0, 1.0)
        } else {
            0.0
        };
        (xp - (ap + ab * t)).norm() <= self.half_width + closing
    }
}

/// The beads of a planned path on a grid, for "is this point in material".
pub struct Envelope {
    beads: Vec<Bead>,
    cells: HashMap<[i32; 3], Vec<u32>>,
    widest: f64,
    /// How much larger each bead is taken ([`CLOSING_SHARE`] of the widest), mm.
    closing: f64,
}

fn cell_of(p: &P3) -> [i32; 3] {
    [
        (p.x / CELL_MM).floor() as i32,
        (p.y / CELL_MM).floor() as i32,
        (p.z / CELL_MM).floor() as i32,
    ]
}

impl Envelope {
    /// The envelope of the print moves of each path of `paths` (the part's, support, skirt and
    /// brim left out), a move running from the point before it in its own path.
    pub fn new<'p>(paths: impl IntoIterator<Item = &'p [PathPoint]>) -> Envelope {
        let mut beads = vec![];
        for w in paths.into_iter().flat_map(|p| p.windows(2)) {
            let (a, b) = (&w[0], &w[1]);
            let part = !(b.role.is_support() || matches!(b.role, Role::Skirt | Role::Brim));
            if b.kind != MoveKind::Print || !part || b.width <= 0.0 {
                continue;
            }
            let axis = V3::from(b.axis);
            let Some(axis) = axis.try_normalize(SHORT_VECTOR) else {
                continue;
            };
            beads.push(Bead {
                a: P3::from(a.p),
                b: P3::from(b.p),
                axis,
                half_width: 0.5 * f64::from(b.width),
                thickness: f64::from(b.thickness),
            });
        }
        let mut cells: HashMap<[i32; 3], Vec<u32>> = HashMap::new();
        let widest = beads
            .iter()
            .map(|b| 2.0 * b.half_width)
            .fold(0.0f64, f64::max);
        let closing = CLOSING_SHARE * widest;
        for (i, bd) in beads.iter().enumerate() {
            let r = bd.half_width.max(bd.thickness) + closing;
            let lo = P3::new(
                bd.a.x.min(bd.b.x) - r,
                bd.a.y.min(bd.b.y) - r,
                bd.a.z.min(bd.b.z) - r,
            );
            let hi = P3::new(
                bd.a.x.max(bd.b.x) + r,
                bd.a.y.max(bd.b.y) + r,
                bd.a.z.max(bd.b.z) + r,
            );
            let (l, h) = (cell_of(&lo), cell_of(&hi));
            for x in l[0]..=h[0] {
                for y in l[1]..=h[1] {
                    for z in l[2]..=h[2] {
                        cells.entry([x, y, z]).or_default().push(i as u32);
                    }
                }
            }
        }
        Envelope {
            beads,
            cells,
            widest,
            closing,
        }
    }

    /// Whether `x` lies in some bead.
    pub fn holds(&self, x: &P3) -> bool {
        self.cells.get(&cell_of(x)).is_some_and(|ix| {
            ix.iter()
                .any(|&i| self.beads[i as usize].holds(x, self.closing))
        })
    }

    /// How far a ray from `p` along `dir` runs before it leaves material for good, up to
    /// `reach`: its last point in a bead (the voids a layer leaves inside, between a perimeter
    /// and the infill's turns, are passed through: they are not outside the part). A ray that
    /// reaches the build plate `plate` first counts as `reach`: no cutter comes from under the
    /// plate.
    fn exit(&self, p: &P3, dir: &V3, reach: f64, plate: Option<&Plane>) -> f64 {
        let mut last = 0.0;
        let mut s = STEP_MM;
        while s < reach {
            let x = p + dir * s;
            if plate.is_some_and(|pl| pl.height(&x) < 0.0) {
                return reach;
            }
            if self.holds(&x) {
                last = s;
            }
            s += STEP_MM;
        }
        (last + 0.5 * STEP_MM).min(reach)
    }

    /// [`Envelope::exit`] less the closing: the distance to the beads' own boundary.
    fn exit_unclosed(&self, p: &P3, dir: &V3, reach: f64, plate: Option<&Plane>) -> f64 {
        (self.exit(p, dir, reach + self.closing, plate) - self.closing).max(0.0)
    }
}

/// The allowance the beads of `envelope` leave over feature `f`'s nominal faces (module docs),
/// the tree standing on `plate`; `None` when the feature is not grown or has no face to
/// measure.
pub fn allowance_left(
    tree: &FeatureTree,
    f: &Feature,
    params: &LayerParams,
    envelope: &Envelope,
    plate: Option<&Plane>,
) -> Result<Option<AllowanceLeft>, FeatureError> {
    let requested = params.machining_allowance;
    if requested <= 0.0 {
        return Ok(None);
    }
    let mesh = feature_mesh(tree, f, slicing_tolerance(params), Allowance::default())?;
    let b = &tree.brep;
    let on_plate = plate_faces(f, &mesh);
    let own = |face| {
        !on_plate.contains(&face)
            && !f.heal_faces.contains(&face)
            && !f.voids.iter().any(|v| v.contains(&face))
    };
    // Vertices of faces that are not the feature's own (its base, the plate) are left out:
    // the allowance there is the neighbour's.
    let mut foreign = vec![false; mesh.positions.len()];
    for t in mesh.faces.iter().filter(|t| !own(t.face)) {
        for &g in &t.vertex {
            foreign[g as usize] = true;
        }
    }
    // Each own face's vertices, with its own normal there (an edge's vertices measured once
    // for each face it bounds).
    let mut per_face: Vec<(FaceId, Vec<(P3, V3)>)> = vec![];
    for t in mesh.faces.iter().filter(|t| own(t.face)) {
        let surf = b.face_surface(t.face);
        let sense = if b.face(t.face).same_sense { 1.0 } else { -1.0 };
        let mut on_face = vec![];
        let mut seen = std::collections::HashSet::new();
        for (&g, uv) in t.vertex.iter().zip(&t.uv) {
            let g = g as usize;
            if foreign[g] || !seen.insert(g) {
                continue;
            }
            if let Some(n) = surf.normal(uv[0], uv[1]) {
                on_face.push((mesh.positions[g], n * sense));
            }
        }
        if !on_face.is_empty() {
            per_face.push((t.face, on_face));
        }
    }
    // An even stride over the feature, at least MIN_PER_FACE points on every face.
    let total: usize = per_face.iter().map(|(_, s)| s.len()).sum();
    let stride = total.div_ceil(MAX_SAMPLES).max(1);
    let samples: Vec<(FaceId, P3, V3)> = per_face
        .iter()
        .flat_map(|(face, s)| {
            let k = stride.min(s.len().div_ceil(MIN_PER_FACE)).max(1);
            s.iter().step_by(k).map(move |&(p, n)| (*face, p, n))
        })
        .collect();
    // Where a feature grows from this one its face is inside the part: not measured.
    let children = tree
        .features
        .iter()
        .filter(|g| g.parents.contains(&f.id))
        .map(|g| feature_mesh(tree, g, slicing_tolerance(params), Allowance::default()))
        .collect::<Result<Vec<_>, _>>()?;
    let boxes: Vec<_> = children.iter().map(|m| m.bbox()).collect();
    let covered = |p: &P3, n: &V3| {
        let q = p + n * INSIDE_PROBE_MM;
        children
            .iter()
            .zip(&boxes)
            .any(|(m, b)| b.contains(&q) && m.winding_number(&q) > 0.5)
    };
    let reach = requested + 2.0 * envelope.widest + 1.0;
    let measured: Vec<AllowanceSample> = samples
        .iter()
        .map(|(face, p, n)| AllowanceSample {
            at: [p.x, p.y, p.z],
            face: *face,
            left: (!covered(p, n)).then(|| nearest_exit(envelope, (p, n), reach, plate)),
        })
        .collect();
    let mut left = measured.iter().filter_map(|m| Some((m.left?, m.at)));
    let Some(first) = left.next() else {
        return Ok(None);
    };
    let (mut min, mut max, mut at, mut count) = (first.0, first.0, first.1, 1);
    for (a, p) in left {
        if a < min {
            (min, at) = (a, p);
        }
        max = max.max(a);
        count += 1;
    }
    Ok(Some(AllowanceLeft {
        requested,
        min,
        max,
        samples: count,
        thinnest_at: at,
        measured,
    }))
}

/// The least exit over rays from `p` within [`RAY_CONE_DEG`] of `n`: the normal, and rings of
/// 8 at a third, two thirds and all of the cone's angle.
fn nearest_exit(envelope: &Envelope, (p, n): (&P3, &V3), reach: f64, plate: Option<&Plane>) -> f64 {
    let u = brep::math::any_perpendicular(n);
    let v = n.cross(&u);
    let mut best = envelope.exit_unclosed(p, n, reach, plate);
    for ring in 1..=3 {
        let tilt = (RAY_CONE_DEG * ring as f64 / 3.0).to_radians();
        for k in 0..8 {
            let phi = std::f64::consts::TAU * (k as f64 + 0.5 * (ring % 2) as f64) / 8.0;
            let dir = n * tilt.cos() + (u * phi.cos() + v * phi.sin()) * tilt.sin();
            best = best.min(envelope.exit_unclosed(p, &dir, best, plate));
        }
    }
    best
}
