//! Volume, area and centroid by integrating the exact surfaces over each face's parameter-domain
//! triangulation (divergence theorem, 7-point Gauss rule per triangle), so curved faces are not
//! flattened into chords.

use crate::math::{Aabb, P3, V3};
use crate::mesh::Mesh;
use crate::tolerance::{LENGTH_FLOOR, NONZERO, STRAIGHT_BOW};
use crate::topology::Brep;

/// Integrals over a set of faces.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct MassProperties {
    /// Signed enclosed volume, mm³ (positive for an outward-oriented closed shell).
    pub volume: f64,
    /// Surface area, mm².
    pub area: f64,
    /// Centroid of the enclosed volume.
    pub centroid: P3,
    /// Bounding box of the mesh.
    pub bbox: Aabb,
}

/// Dunavant's degree-5 rule: barycentric points and weights (weights sum to 1).
const GAUSS7: [([f64; 3], f64); 7] = [
    ([1.0 / 3.0, 1.0 / 3.0, 1.0 / 3.0], 0.225),
    (
        [
            0.059_715_871_789_770,
            0.470_142_064_105_115,
            0.470_142_064_105_115,
        ],
        0.132_394_152_788_506,
    ),
    (
        [
            0.470_142_064_105_115,
            0.059_715_871_789_770,
            0.470_142_064_105_115,
        ],
        0.132_394_152_788_506,
    ),
    (
        [
            0.470_142_064_105_115,
            0.470_142_064_105_115,
            0.059_715_871_789_770,
        ],
        0.132_394_152_788_506,
    ),
    (
        [
            0.797_426_985_353_087,
            0.101_286_507_323_456,
            0.101_286_507_323_456,
        ],
        0.125_939_180_544_827,
    ),
    (
        [
            0.101_286_507_323_456,
            0.797_426_985_353_087,
            0.101_286_507_323_456,
        ],
        0.125_939_180_544_827,
    ),
    (
        [
            0.101_286_507_323_456,
            0.101_286_507_323_456,
            0.797_426_985_353_087,
        ],
        0.125_939_180_544_827,
    ),
];

/// The divergence integrals of one face about `origin`: signed volume share, area, and the
/// first-moment share `∫ x_i² n_i / 2` (7-point Gauss rule on each parameter triangle, the
/// exact surface and its natural normal; the signed triangle area carries the face's sense).
fn face_integrals(
    brep: &Brep,
    mesh: &Mesh,
    ft: &crate::mesh::FaceTriangulation,
    origin: &P3,
) -> (f64, f64, V3) {
    let s = brep.face_surface(ft.face);
    let (mut vol, mut area, mut first) = (0.0, 0.0, V3::zeros());
    // Signed parameter-space area (a plane's exact area, less its slivers).
    let mut signed = 0.0;
    for t in &ft.triangles {
        let a = ft.uv[t[0] as usize];
        let b = ft.uv[t[1] as usize];
        let d = ft.uv[t[2] as usize];
        // Signed parameter-space area: negative where the face runs against the surface.
        let det = 0.5 * ((b[0] - a[0]) * (d[1] - a[1]) - (d[0] - a[0]) * (b[1] - a[1]));
        if det == 0.0 {
            continue;
        }
        for (w, wt) in GAUSS7.iter() {
            let u = w[0] * a[0] + w[1] * b[0] + w[2] * d[0];
            let v = w[0] * a[1] + w[1] * b[1] + w[2] * d[1];
            let (q, su, sv) = s.eval_d1(u, v);
            let p = q - origin;
            let n = su.cross(&sv);
            vol += wt * det * p.dot(&n) / 3.0;
            area += wt * det.abs() * n.norm();
            first += wt * det * V3::new(p.x * p.x * n.x, p.y * p.y * n.y, p.z * p.z * n.z) * 0.5;
        }
        signed += det;
    }
    if let crate::surface::Surface::Plane { frame } = s {
        // A plane's integrand is constant (`p·n = d`, `|su × sv| = 1`): its share is `d·A/3`
        // for its signed area A, which the chords of curved edges cut short. Each chord's
        // sliver (Green's theorem along the curve, less the chord) makes A that of the exact
        // boundary, so a planar face meets its curved neighbours (whose parameters follow the
        // edge) without a gap: a disc of radius 28 had lost 1.1 mm² of its 2449 to the chords
        // of its rim. The slivers' share of the first moment is left out.
        let slivers = plane_slivers(brep, mesh, ft.face, frame);
        let d = (frame.origin - origin).dot(&frame.z);
        vol += d * slivers / 3.0;
        area = (signed + slivers).abs();
    }
    (vol, area, first)
}

/// The signed area, in a plane face's `(u, v)`, between its boundary's curved edges and the
/// chords the mesher drew along them: for each sampled segment, Green's `½∮(u dv − v du)`
/// along the curve (3-point Gauss–Legendre) less the same along the chord, in the direction
/// each coedge runs in its loop.
fn plane_slivers(
    brep: &Brep,
    mesh: &Mesh,
    f: crate::topology::FaceId,
    frame: &crate::math::Frame,
) -> f64 {
    // 3-point Gauss–Legendre: exact to degree 5, and a sampled segment of an edge is short.
    const GL3: [(f64, f64); 3] = [
        (0.0, 0.888_888_888_888_889),
        (-0.774_596_669_241_483, 0.555_555_555_555_556),
        (0.774_596_669_241_483, 0.555_555_555_555_556),
    ];
    let face = brep.face(f);
    let mut sum = 0.0;
    for &l in &face.loops {
        for &ce in &brep.loops[l.idx()].coedges {
            let co = &brep.coedges[ce.idx()];
            let c = brep.edge_curve(co.edge);
            if matches!(
                c,
                crate::curve::Curve::Line { .. } | crate::curve::Curve::Polyline(_)
            ) {
                continue;
            }
            let Some(ts) = mesh.edge_params.get(&co.edge) else {
                continue;
            };
            let mut piece = 0.0;
            for w in ts.windows(2) {
                let (t0, t1) = (w[0], w[1]);
                let (h, m) = (0.5 * (t1 - t0), 0.5 * (t1 + t0));
                let (a, b) = (frame.local(&c.eval(t0)), frame.local(&c.eval(t1)));
                // A segment that does not bow off its chord has no sliver worth the integral.
                let mid = frame.local(&c.eval(m));
                let (cx, cy) = (b.x - a.x, b.y - a.y);
                let len = cx.hypot(cy);
                let bow = ((mid.x - a.x) * cy - (mid.y - a.y) * cx).abs() / len.max(NONZERO);
                if bow <= STRAIGHT_BOW * (1.0 + len) {
                    continue;
                }
                let mut curve = 0.0;
                for (x, wt) in GL3 {
                    let t = m + h * x;
                    let p = frame.local(&c.eval(t));
                    let d = c.deriv(t);
                    let (du, dv) = (d.dot(&frame.x), d.dot(&frame.y));
                    curve += wt * h * 0.5 * (p.x * dv - p.y * du);
                }
                let chord = 0.5 * (a.x * b.y - b.x * a.y);
                piece += curve - chord;
            }
            if piece.is_finite() {
                sum += if co.forward { piece } else { -piece };
            }
        }
    }
    sum
}

/// Each face's share of the divergence integrals about `origin`: `(face, signed volume, area)`.
/// Shares about one origin add up, so the volume of any closed set of faces is the sum of its
/// faces' shares, however the faces were meshed.
pub fn face_shares(
    brep: &Brep,
    mesh: &Mesh,
    origin: &P3,
) -> Vec<(crate::topology::FaceId, f64, f64)> {
    mesh.faces
        .iter()
        .map(|ft| {
            let (v, a, _) = face_integrals(brep, mesh, ft, origin);
            (ft.face, v, a)
        })
        .collect()
}

/// Integrates the faces of `mesh` (all of them) over their exact surfaces.
pub fn mass_properties(brep: &Brep, mesh: &Mesh) -> MassProperties {
    let bbox = exact_bbox(brep, mesh);
    let c = if bbox.is_empty() {
        P3::origin()
    } else {
        nalgebra::center(&bbox.min, &bbox.max)
    };
    let (mut vol, mut area, mut first) = (0.0, 0.0, V3::zeros());
    for ft in &mesh.faces {
        let (v, a, m) = face_integrals(brep, mesh, ft, &c);
        vol += v;
        area += a;
        first += m;
    }
    let centroid = if vol.abs() > 0.0 { c + first / vol } else { c };
    MassProperties {
        volume: vol,
        area,
        centroid,
        bbox,
    }
}

/// The mesh's bounding box pushed out to the exact surfaces: triangles with a corner near an
/// extreme are subdivided in `(u, v)` and their sub-points evaluated on the surface, twice over
/// (each level cuts the chord error about sixteen-fold).
pub fn exact_bbox(brep: &Brep, mesh: &Mesh) -> Aabb {
    let mut bbox = mesh.bbox();
    if bbox.is_empty() {
        return bbox;
    }
    let near =
        |p: &P3, b: &Aabb, tol: f64| (0..3).any(|k| p[k] - b.min[k] < tol || b.max[k] - p[k] < tol);
    // Candidate parameter triangles, refined level by level.
    let mut tol = 1e-3 * bbox.diagonal();
    let mut cands: Vec<(usize, [[f64; 2]; 3])> = vec![];
    for (fi, ft) in mesh.faces.iter().enumerate() {
        // A plane's extremes over a triangle are at its corners, already in the mesh's box.
        if matches!(
            brep.face_surface(ft.face),
            crate::surface::Surface::Plane { .. }
        ) {
            continue;
        }
        for t in &ft.triangles {
            let ps = t.map(|i| mesh.positions[ft.vertex[i as usize] as usize]);
            if ps.iter().any(|p| near(p, &bbox, tol.max(LENGTH_FLOOR))) {
                cands.push((fi, t.map(|i| ft.uv[i as usize])));
            }
        }
    }
    for _level in 0..2 {
        let mut next = vec![];
        let n = 4;
        for (fi, tri) in &cands {
            let s = brep.face_surface(mesh.faces[*fi].face);
            let at = |a: usize, b: usize| {
                let (fa, fb) = (a as f64 / n as f64, b as f64 / n as f64);
                let fc = 1.0 - fa - fb;
                [
                    fc * tri[0][0] + fa * tri[1][0] + fb * tri[2][0],
                    fc * tri[0][1] + fa * tri[1][1] + fb * tri[2][1],
                ]
            };
            for a in 0..=n {
                for b in 0..=(n - a) {
                    let uv = at(a, b);
                    bbox.add(&s.eval(uv[0], uv[1]));
                }
            }
            // Sub-triangles of this one for the next level.
            for a in 0..n {
                for b in 0..(n - a) {
                    next.push((*fi, [at(a, b), at(a + 1, b), at(a, b + 1)]));
                    if a + b + 1 < n {
                        next.push((*fi, [at(a + 1, b), at(a + 1, b + 1), at(a, b + 1)]));
                    }
                }
            }
        }
        tol /= 16.0;
        cands = next
            .into_iter()
            .filter(|(fi, tri)| {
                let s = brep.face_surface(mesh.faces[*fi].face);
                tri.iter().any(|uv| near(&s.eval(uv[0], uv[1]), &bbox, tol))
            })
            .collect();
        if cands.len() > 200_000 {
            break;
        }
    }
    bbox
}
