//! Transition layers of a freeform feature (Isa & Lazoglu 2019, seed 000, section 3.3): layers
//! that morph the feature's base B into its top T, so that the last layer lies on T and the top
//! has no stair-steps.
//!
//! - **Base, top, sides (section 3.1, Fig. 4).** B is where the feature grows from: its
//!   reference region, `d = 0` in the chart of the reference surface (see `crate::chart`).
//!   T is the feature's faces that look the way it grows: the faces other than its healing
//!   faces whose area-weighted normal, in chart space `(s, t, d)`, points up (`d`-share at
//!   least `TOP_SHARE`). The rest are the sides S_i.
//! - **Correspondence.** B and T of a real part are trimmed faces of unrelated surfaces, not
//!   the aligned `(u, v)` patches the paper assumes. The correspondence is the chart's: the
//!   point of T over chart point `q` is the one met along the reference's normal N(q), at
//!   distance `h_T(q)` ([`TopField`]). Where T does not cover `q` (over a side leaning out, or
//!   past T's edge) `h_T` is continued smoothly from T's values (nearest value, then relaxed).
//! - **Layers, Eq. 4.** `L_n(q) = (1 − n/N)·B(q) + (n/N)·T(q)` is, in the chart, the surface
//!   `d = (n/N)·h_T(q)`: the chart's normal coordinate `w = d / h_T(q)` is 0 on B and 1 on T,
//!   and layer n spans `w ∈ [(n−1)/N, n/N]`. A point's local thickness is `h_T(q)/N`.
//! - **Outlines, Eq. 5–8.** The paper fits each blended layer's outline to the side surfaces
//!   by interpolated displacements. Here the layer's region is the section of the feature's
//!   mesh mapped into `(s, t, w)` by the plane `w = (n − ½)/N`: the side faces cut at that
//!   level of the morph, so the outline lies on the sides by construction, and the layer
//!   surface inside it is the blend.
//! - **N.** With `h_min`, `h_max`, `h_mean` the base-to-top distance over T, every point's
//!   thickness lies in `[h_min/N, h_max/N]`: N must be in
//!   `[ceil(h_max / max_layer_height), floor(h_min / min_layer_height)]`; it is the number of
//!   that range nearest `h_mean / uniform_layer_height`. An empty range (the top comes too
//!   close to the base somewhere for one N, `Levels::Infeasible`) gets offset layers first, then
//!   a band of transition layers over them (`band`); where not even that keeps the bounds, the
//!   feature is refused.
//! - **Volume, Eq. 1.** A transition layer leans on the reference by the angle α between its
//!   normal n_L and N: its beads are `t_N·cos α` thick across it, and a segment counts by its
//!   length along the layer (not up the steps over a hybrid's staircase); `thickness` in the
//!   tool path is that `t_N·cos α`.
//! - **Leaning features.** Nothing above requires the top to lie over the base: the outlines
//!   come from the sides, so a pitched blade's layers follow its lean. Where T does not cover
//!   q, h_T is continued from T's values, so the layers there are near-offsets that bend into T
//!   where they reach it; their normals lean by the continuation's slope (a B/C bed tilts axes
//!   that lean past its B limit back into it, inside the orientation cone).
//! - **Orientation (TSN).** The layer surface's normal, from the chart by central differences.

use crate::chart::{mapped_mesh, refined, Chart};
use crate::error::FeatureError;
use crate::geom2d::Point2;
use crate::params::LayerParams;
use crate::tolerance::{BARYCENTRIC_SLACK, COUNT_SLACK, TRIANGLE_DET};
pub use crate::top_field::TopField;
use brep::math::P3;
use brep::mesh::{FaceTriangulation, Mesh};
use brep::topology::FaceId;

/// A face belongs to the top when the `d`-share of its area-weighted normal in chart space is
/// at least this (its mean normal within 60° of the growth direction).
const TOP_SHARE: f64 = 0.5;

/// Longest edge of the top's triangles sampled into a [`TopField`], mm.
const TOP_EDGE: f64 = 0.25;

/// Most cells of a [`TopField`] grid.
const MAX_CELLS: f64 = 400_000.0;

/// The top faces T of the feature whose mesh is `mesh` (its faces' triangulations) and whose
/// healing faces are `heal`, in `chart`: the others whose [`up_share`] is at least
/// [`TOP_SHARE`].
pub(crate) fn top_faces(chart: &Chart, mesh: &Mesh, heal: &[FaceId], id: usize) -> Vec<FaceId> {
    mesh.faces
        .iter()
        .filter(|ft| {
            !ft.triangles.is_empty()
                && !heal.contains(&ft.face)
                && up_share(chart, mesh, ft, id) >= TOP_SHARE
        })
        .map(|ft| ft.face)
        .collect()
}

/// `h_T` of the feature whose mesh is `mesh` (its faces' triangulations) and whose top faces
/// are `tops` ([`top_faces`]), in `chart`; `mapped` is the refined mesh already mapped into
/// `(s, t, d)` (its bounds set the grid). `None` when the feature has no top face.
pub(crate) fn build_top_field(
    chart: &Chart,
    brep: &brep::Brep,
    mesh: &Mesh,
    tops: &[FaceId],
    mapped: &Mesh,
    id: usize,
) -> Result<Option<TopField>, FeatureError> {
    // The top faces, each as its own triangles (refined, so that d is near linear over
    // every triangle of the chart).
    let top = Mesh {
        positions: mesh.positions.clone(),
        faces: mesh
            .faces
            .iter()
            .filter(|ft| tops.contains(&ft.face))
            .cloned()
            .collect(),
        edge_points: Default::default(),
        edge_params: Default::default(),
    };
    if top.faces.is_empty() {
        return Ok(None);
    }
    // Linear over each triangle in the chart, d's slope strays by about edge / radius of
    // curvature from the top's: each top face refined to a quarter millimetre, the new
    // points put back on its exact surface (the slicing mesh's own facets stray by degrees
    // at its chord tolerance), keeps it near 0.3° on R = 47 mm.
    let mut pieces = vec![];
    // One face at a time over the whole mesh's points (copied once, not once per face).
    let mut one = Mesh {
        positions: mesh.positions.clone(),
        faces: vec![],
        edge_points: Default::default(),
        edge_params: Default::default(),
    };
    for ft in &top.faces {
        one.faces = vec![ft.clone()];
        let mut fine = compact(&refined(&compact(&one), TOP_EDGE));
        let surf = brep.face_surface(ft.face);
        // Each point's foot from its (u, v), interpolated over its triangle of the face.
        let starts = fine.faces.first().map(|f| f.uv.clone()).unwrap_or_default();
        for (p, uv) in fine.positions.iter_mut().zip(starts) {
            let (u, v) = surf.project_from(p, (uv[0], uv[1]));
            let on = surf.eval(u, v);
            if (on - *p).norm() < TOP_EDGE {
                *p = on;
            }
        }
        pieces.push(fine);
    }
    let top = merge(&pieces);
    let top = mapped_mesh(chart, &top, id)?;
    // The grid over the whole feature's chart box.
    let (mut lo, mut hi) = ([f64::INFINITY; 2], [f64::NEG_INFINITY; 2]);
    for p in &mapped.positions {
        lo = [lo[0].min(p.x), lo[1].min(p.y)];
        hi = [hi[0].max(p.x), hi[1].max(p.y)];
    }
    let span = [(hi[0] - lo[0]).max(1e-3), (hi[1] - lo[1]).max(1e-3)];
    let cell = (span[0] * span[1] / MAX_CELLS).sqrt().clamp(0.05, 5.0);
    let nx = (span[0] / cell).ceil() as usize + 3;
    let ny = (span[1] / cell).ceil() as usize + 3;
    let origin = [lo[0] - cell, lo[1] - cell];
    let mut h = vec![f64::NEG_INFINITY; nx * ny];
    for t in top.triangles() {
        let [a, b, c] = t.map(|k| top.positions[k as usize]);
        raster(&mut h, origin, cell, nx, ny, a, b, c);
    }
    let covered: Vec<bool> = h.iter().map(|v| v.is_finite()).collect();
    Ok(TopField::from_grid(origin, cell, (nx, ny), h, &covered))
}

/// The meshes as one triangle list (one face triangulation).
fn merge(pieces: &[Mesh]) -> Mesh {
    let mut positions = vec![];
    let mut triangles = vec![];
    for m in pieces {
        let base = positions.len() as u32;
        positions.extend(m.positions.iter().copied());
        triangles.extend(m.triangles().into_iter().map(|t| t.map(|k| k + base)));
    }
    let n = positions.len();
    Mesh {
        positions,
        faces: vec![FaceTriangulation {
            face: pieces
                .first()
                .and_then(|m| m.faces.first())
                .map(|f| f.face)
                .unwrap_or(FaceId(0)),
            uv: vec![[0.0, 0.0]; n],
            vertex: (0..n as u32).collect(),
            triangles,
        }],
        edge_points: Default::default(),
        edge_params: Default::default(),
    }
}

/// The `d`-share of a face's area-weighted normal in chart space (1: it faces the way the
/// feature grows, 0: along it, −1: against it), from a sample of its triangles; 0 where they
/// do not map.
fn up_share(chart: &Chart, mesh: &Mesh, ft: &FaceTriangulation, id: usize) -> f64 {
    let stride = (ft.triangles.len() / 64).max(1);
    let mut positions = vec![];
    let mut tris: Vec<[u32; 3]> = vec![];
    for t in ft.triangles.iter().step_by(stride) {
        let base = positions.len() as u32;
        for &k in t {
            positions.push(mesh.positions[ft.vertex[k as usize] as usize]);
        }
        tris.push([base, base + 1, base + 2]);
    }
    let n = positions.len();
    let probe = Mesh {
        positions,
        faces: vec![FaceTriangulation {
            face: ft.face,
            uv: vec![[0.0, 0.0]; n],
            vertex: (0..n as u32).collect(),
            triangles: tris.clone(),
        }],
        edge_points: Default::default(),
        edge_params: Default::default(),
    };
    let Ok(m) = mapped_mesh(chart, &probe, id) else {
        return 0.0;
    };
    let (mut up, mut all) = (0.0, 0.0);
    for t in &tris {
        let [a, b, c] = t.map(|k| m.positions[k as usize]);
        let n = (b - a).cross(&(c - a));
        up += n.z;
        all += n.norm();
    }
    if all > 0.0 {
        up / all
    } else {
        0.0
    }
}

/// Keeps only the vertices a mesh's triangles use (one face triangulation).
fn compact(m: &Mesh) -> Mesh {
    let tris = m.triangles();
    // Each point's (u, v) on its face (one face: the top faces are taken one at a time).
    let uv_of = crate::chart::position_uv(m);
    let mut map = vec![u32::MAX; m.positions.len()];
    let mut positions = vec![];
    let mut uv = vec![];
    let mut out = Vec::with_capacity(tris.len());
    for t in tris {
        out.push(t.map(|k| {
            let k = k as usize;
            if map[k] == u32::MAX {
                map[k] = positions.len() as u32;
                positions.push(m.positions[k]);
                uv.push(uv_of[k]);
            }
            map[k]
        }));
    }
    let n = positions.len();
    Mesh {
        positions,
        faces: vec![FaceTriangulation {
            face: m.faces.first().map(|f| f.face).unwrap_or(FaceId(0)),
            uv,
            vertex: (0..n as u32).collect(),
            triangles: out,
        }],
        edge_points: Default::default(),
        edge_params: Default::default(),
    }
}

/// Writes the triangle's `d` (its `z`) into the cells whose centres it covers, keeping the
/// greatest.
#[allow(clippy::too_many_arguments)]
fn raster(h: &mut [f64], origin: Point2, cell: f64, nx: usize, ny: usize, a: P3, b: P3, c: P3) {
    let det = (b.x - a.x) * (c.y - a.y) - (c.x - a.x) * (b.y - a.y);
    if det.abs() < TRIANGLE_DET {
        return;
    }
    let ix = |x: f64| ((x - origin[0]) / cell - 0.5).max(0.0);
    let iy = |y: f64| ((y - origin[1]) / cell - 0.5).max(0.0);
    let x0 = ix(a.x.min(b.x).min(c.x)).floor() as usize;
    let x1 = (ix(a.x.max(b.x).max(c.x)).ceil() as usize).min(nx - 1);
    let y0 = iy(a.y.min(b.y).min(c.y)).floor() as usize;
    let y1 = (iy(a.y.max(b.y).max(c.y)).ceil() as usize).min(ny - 1);
    let eps = BARYCENTRIC_SLACK;
    for y in y0..=y1 {
        for x in x0..=x1 {
            let px = origin[0] + (x as f64 + 0.5) * cell;
            let py = origin[1] + (y as f64 + 0.5) * cell;
            let l1 = ((b.x - px) * (c.y - py) - (c.x - px) * (b.y - py)) / det;
            let l2 = ((c.x - px) * (a.y - py) - (a.x - px) * (c.y - py)) / det;
            let l3 = 1.0 - l1 - l2;
            if l1 >= -eps && l2 >= -eps && l3 >= -eps {
                let d = l1 * a.z + l2 * b.z + l3 * c.z;
                let i = y * nx + x;
                if d > h[i] {
                    h[i] = d;
                }
            }
        }
    }
}

/// How many transition layers a feature gets.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) enum Levels {
    /// The top is an offset of the reference within the tolerance: offset layers are exact.
    Offset,
    /// N transition layers.
    Transition(usize),
    /// No N keeps every point's thickness within the bounds from the base (the top comes too
    /// close to it somewhere): `(lo, hi)` is the range N would have to lie in (`lo > hi`).
    /// [`band`] tries offset layers first.
    Infeasible(usize, usize),
}

/// The number of transition layers for base-to-top distances `range` (least, mean, greatest):
/// see the module documentation.
pub(crate) fn levels(range: (f64, f64, f64), params: &LayerParams) -> Levels {
    let (hmin, hmean, hmax) = range;
    if hmax - hmin <= params.tolerance {
        return Levels::Offset;
    }
    let lo = ((hmax / params.max_layer_height) - COUNT_SLACK)
        .ceil()
        .max(1.0) as usize;
    let hi = ((hmin / params.min_layer_height) + COUNT_SLACK)
        .floor()
        .max(0.0) as usize;
    if lo > hi {
        return Levels::Infeasible(lo, hi);
    }
    let want = (hmean / params.uniform_layer_height).round().max(1.0) as usize;
    Levels::Transition(want.clamp(lo, hi))
}

/// A band of transition layers over offset layers, for a top that comes too close to the base
/// somewhere for one N ("offset layers first, transition layers for the rest"):
///
/// - offset layers `h0 = uniform_layer_height` thick stack over `q` to `D(q)`, each printed
///   where the stack reaches its top; `D` is `max(0, h_T − c)` with `c = h_min` (the band
///   everywhere at least as thick as the top's least height), lowered until it climbs at most
///   one layer per half bead width (`|∇D| ≤ h0 / (w/2)`, so that no bead of a transition layer
///   lies beside a stack more than one layer taller than its own), then cut to whole layers;
/// - N transition layers from `D` to the top, each point `(h_T(q) − D(q))/N` thick: N must
///   lie in `[⌈max(h_T − D)/max_layer_height⌉, ⌊min(h_T − D)/min_layer_height⌋]`, and is the
///   one nearest the band's mean thickness over `uniform_layer_height`.
///
/// Returns the field with its band, N and the number of offset layers; `None` when no N keeps
/// the bounds.
pub(crate) fn band(
    field: TopField,
    params: &LayerParams,
    bead_width: f64,
) -> Option<(TopField, usize, usize)> {
    let h0 = params.uniform_layer_height;
    if !(h0 > 0.0 && bead_width > 0.0) {
        return None;
    }
    let c = field.range.0;
    let f = field.with_band(c, h0, h0 / (0.5 * bead_width));
    let (mut lo, mut hi, mut sum, mut top) = (f64::INFINITY, 0.0f64, 0.0, 0.0f64);
    for (h, e) in f.h.iter().zip(&f.env) {
        let d = h0 * (e / h0 + COUNT_SLACK).floor();
        let b = h - d;
        lo = lo.min(b);
        hi = hi.max(b);
        sum += b;
        top = top.max(d);
    }
    let mean = sum / f.h.len().max(1) as f64;
    let nlo = ((hi / params.max_layer_height) - COUNT_SLACK)
        .ceil()
        .max(1.0) as usize;
    let nhi = ((lo / params.min_layer_height) + COUNT_SLACK)
        .floor()
        .max(0.0) as usize;
    if nlo > nhi {
        return None;
    }
    let n = ((mean / params.uniform_layer_height).round().max(1.0) as usize).clamp(nlo, nhi);
    let k = (top / h0 + COUNT_SLACK).round() as usize;
    Some((f, n, k))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn levels_keep_thickness_bounds_and_aim_at_the_layer_height() {
        let p = LayerParams::default();
        // 7..11 mm, mean 9: N = 45 is within [ceil(11/0.3), floor(7/0.1)] = [37, 70].
        assert_eq!(levels((7.0, 9.0, 11.0), &p), Levels::Transition(45));
        // An offset top.
        assert_eq!(levels((5.0, 5.0, 5.02), &p), Levels::Offset);
        // 1..10 mm: N would have to be at least 34 and at most 10.
        assert_eq!(levels((1.0, 5.0, 10.0), &p), Levels::Infeasible(34, 10));
        // 2..5 mm, mean 3.5: 18 wanted, at most 20, at least 17.
        assert_eq!(levels((2.0, 3.5, 5.0), &p), Levels::Transition(18));
        // Thick target clamped to the thinnest allowed N.
        let q = LayerParams {
            uniform_layer_height: 0.5,
            ..p
        };
        assert_eq!(levels((3.0, 4.0, 6.0), &q), Levels::Transition(20));
    }
}
