//! Constrained Delaunay triangulation (spade) of a face's parameter domain, with interior
//! points spaced by the surface's curvature.

use super::grid::{grid_steps, step_count};
use super::model::FaceTriangulation;
use super::options::{face_err, MeshError, MeshOptions};
use super::uv::Pt;
use crate::math::P3;
use crate::surface::Surface;
use crate::tolerance::{NONZERO, TRIANGULATOR_ZERO};
use crate::topology::{Brep, FaceId};
use spade::{ConstrainedDelaunayTriangulation, Point2, Triangulation};
use std::collections::HashMap;

/// Segments of the boundary, bucketed in horizontal bands, for inside tests and distances.
struct Boundary {
    segs: Vec<([f64; 2], [f64; 2])>,
    y0: f64,
    band: f64,
    bands: Vec<Vec<u32>>,
}

impl Boundary {
    fn new(polys: &[Vec<[f64; 2]>], bb: (f64, f64)) -> Self {
        let mut segs = vec![];
        for p in polys {
            let n = p.len();
            for k in 0..n {
                let a = p[k];
                let b = p[(k + 1) % n];
                if a != b {
                    segs.push((a, b));
                }
            }
        }
        let nb = ((segs.len() as f64).sqrt() as usize).clamp(1, 512);
        let band = ((bb.1 - bb.0) / nb as f64).max(NONZERO);
        let mut bands = vec![vec![]; nb];
        for (i, (a, b)) in segs.iter().enumerate() {
            let lo = (((a[1].min(b[1]) - bb.0) / band).floor().max(0.0) as usize).min(nb - 1);
            let hi = (((a[1].max(b[1]) - bb.0) / band).floor().max(0.0) as usize).min(nb - 1);
            for bandv in bands.iter_mut().take(hi + 1).skip(lo) {
                bandv.push(i as u32);
            }
        }
        Boundary {
            segs,
            y0: bb.0,
            band,
            bands,
        }
    }

    fn band_of(&self, y: f64) -> usize {
        (((y - self.y0) / self.band).floor().max(0.0) as usize).min(self.bands.len() - 1)
    }

    /// Even-odd inside test by a ray towards +x.
    fn inside(&self, p: [f64; 2]) -> bool {
        let mut c = false;
        for &i in &self.bands[self.band_of(p[1])] {
            let (a, b) = self.segs[i as usize];
            if (a[1] > p[1]) != (b[1] > p[1]) {
                let x = a[0] + (p[1] - a[1]) * (b[0] - a[0]) / (b[1] - a[1]);
                if x > p[0] {
                    c = !c;
                }
            }
        }
        c
    }

    /// Whether a boundary segment passes within `r` of `p`.
    fn near(&self, p: [f64; 2], r: f64) -> bool {
        let lo = self.band_of(p[1] - r);
        let hi = self.band_of(p[1] + r);
        for band in &self.bands[lo..=hi] {
            for &i in band {
                let (a, b) = self.segs[i as usize];
                let d = [b[0] - a[0], b[1] - a[1]];
                let l2 = d[0] * d[0] + d[1] * d[1];
                let t = if l2 > 0.0 {
                    (((p[0] - a[0]) * d[0] + (p[1] - a[1]) * d[1]) / l2).clamp(0.0, 1.0)
                } else {
                    0.0
                };
                let q = [a[0] + t * d[0] - p[0], a[1] + t * d[1] - p[1]];
                if q[0] * q[0] + q[1] * q[1] < r * r {
                    return true;
                }
            }
        }
        false
    }
}

#[allow(clippy::too_many_arguments)]
pub(super) fn triangulate(
    brep: &Brep,
    f: FaceId,
    s: &Surface,
    polys: Vec<Vec<Pt>>,
    edge_of: &HashMap<u32, Vec<u32>>,
    positions: &mut Vec<P3>,
    opts: &MeshOptions,
    sense: f64,
) -> Result<FaceTriangulation, MeshError> {
    // Scale (u, v) so that a unit step is about a unit length on the surface.
    let (su, sv, ub, vb) = parameter_scale(s, &polys);
    let scaled: Vec<Vec<[f64; 2]>> = polys
        .iter()
        .map(|p| p.iter().map(|q| [q.uv[0] * su, q.uv[1] * sv]).collect())
        .collect();
    let bnd = Boundary::new(&scaled, (vb.0 * sv, vb.1 * sv));

    let mut cdt: ConstrainedDelaunayTriangulation<Point2<f64>> =
        ConstrainedDelaunayTriangulation::new();
    let mut loc = Local::default();

    // Boundary points, with pole bridges subdivided so the fan at a pole is well shaped.
    let constraints_failed = insert_boundary(brep, f, &polys, (su, sv), &mut cdt, &mut loc)?;

    // Interior grid points.
    insert_grid(
        s,
        (ub, vb),
        (su, sv),
        opts,
        &bnd,
        positions,
        &mut cdt,
        &mut loc,
    );

    // Which triangles are inside: count constraint crossings from the hull (odd = inside). This
    // is exact where the boundary's points are collinear to rounding; the centroid test is the
    // fallback when a boundary segment could not be inserted (crossing loops in bad files).
    // A chord between two points of the same B-rep edge could be drawn by the face on the other
    // side of that edge too, giving four triangles on one segment: split such chords with a
    // point of this face's own until none is left.
    const MAX_ROUNDS: usize = 10;
    const MAX_ADDED: usize = 200_000;
    let planar = matches!(s, Surface::Plane { .. });
    let mut rounds = 0;
    let mut added = 0usize;
    loop {
        let depth = (constraints_failed == 0).then(|| constraint_depth(&cdt));
        let mut triangles = vec![];
        let mut splits: Vec<[f64; 2]> = vec![];
        let mut seen = std::collections::HashSet::new();
        // Every drawn edge: (local handles, mesh vertices, constraint, middle).
        #[allow(clippy::type_complexity)]
        let mut drawn: Vec<((usize, usize), (u32, u32), bool, [f64; 2])> = vec![];
        for face in cdt.inner_faces() {
            let vs = face.vertices();
            let inside = match &depth {
                Some(d) => d[face.fix().index()] % 2 == 1,
                None => bnd.inside([
                    (vs[0].position().x + vs[1].position().x + vs[2].position().x) / 3.0,
                    (vs[0].position().y + vs[1].position().y + vs[2].position().y) / 3.0,
                ]),
            };
            if !inside {
                continue;
            }
            let mut t = [0u32; 3];
            let mut known = true;
            for k in 0..3 {
                match loc.handle_local.get(&vs[k].fix().index()) {
                    Some(&l) => t[k] = l as u32,
                    None => known = false,
                }
            }
            if !known {
                continue;
            }
            if rounds < MAX_ROUNDS {
                // Chord error: the flat triangle's centroid against the surface's. Stops two
                // rounds before chord splitting does, so that has the last word.
                if !planar && rounds + 2 < MAX_ROUNDS && added < MAX_ADDED {
                    if let Some(xy) = chord_split(s, &loc, t, positions, (su, sv), &bnd, opts) {
                        splits.push(xy);
                    }
                }
                for e in face.adjacent_edges() {
                    let (ha, hb) = (e.from().fix().index(), e.to().fix().index());
                    if let (Some(&la), Some(&lb)) =
                        (loc.handle_local.get(&ha), loc.handle_local.get(&hb))
                    {
                        let (pa, pb) = (e.from().position(), e.to().position());
                        drawn.push((
                            (ha.min(hb), ha.max(hb)),
                            (loc.vertex[la], loc.vertex[lb]),
                            e.is_constraint_edge(),
                            [(pa.x + pb.x) * 0.5, (pa.y + pb.y) * 0.5],
                        ));
                    }
                    if e.is_constraint_edge() {
                        continue;
                    }
                    let (Some(&la), Some(&lb)) =
                        (loc.handle_local.get(&ha), loc.handle_local.get(&hb))
                    else {
                        continue;
                    };
                    let (ga, gb) = (loc.vertex[la], loc.vertex[lb]);
                    let shared = match (edge_of.get(&ga), edge_of.get(&gb)) {
                        (Some(ea), Some(eb)) => ea.iter().any(|x| eb.contains(x)),
                        _ => false,
                    };
                    if shared && seen.insert((ha.min(hb), ha.max(hb))) {
                        let (pa, pb) = (e.from().position(), e.to().position());
                        splits.push([(pa.x + pb.x) * 0.5, (pa.y + pb.y) * 0.5]);
                    }
                }
            }
            if sense < 0.0 {
                t.swap(1, 2);
            }
            triangles.push(t);
        }
        // A pair of mesh vertices joined by more than one triangle on the same side: points
        // that are one vertex in 3-D (a pole's points along its singular line, the two sides
        // of the cut to a pole) joined to the same neighbour twice over. Split the free edges
        // drawn between them.
        split_doubled_edges(&triangles, &loc, &drawn, &mut seen, &mut splits);
        if splits.is_empty() || rounds >= MAX_ROUNDS {
            return Ok(FaceTriangulation {
                face: f,
                uv: loc.uv,
                vertex: loc.vertex,
                triangles,
            });
        }
        added += splits.len();
        for xy in splits {
            let uv = [xy[0] / su, xy[1] / sv];
            let idx = positions.len() as u32;
            positions.push(s.eval(uv[0], uv[1]));
            loc.insert(&mut cdt, xy, uv, idx);
        }
        rounds += 1;
    }
}

/// The parameter scale of a face (mean `|S_u|`, `|S_v|` at its regular boundary points, so a
/// unit step of scaled parameters is about a unit length on the surface) and its boundary's
/// parameter box.
#[allow(clippy::type_complexity)]
fn parameter_scale(s: &Surface, polys: &[Vec<Pt>]) -> (f64, f64, (f64, f64), (f64, f64)) {
    let (mut su, mut sv, mut n) = (0.0, 0.0, 0.0);
    let (mut ub, mut vb) = (
        (f64::INFINITY, f64::NEG_INFINITY),
        (f64::INFINITY, f64::NEG_INFINITY),
    );
    for p in polys.iter().flatten() {
        ub = (ub.0.min(p.uv[0]), ub.1.max(p.uv[0]));
        vb = (vb.0.min(p.uv[1]), vb.1.max(p.uv[1]));
        if p.sing == 0 {
            let (a, b) = s.derivs(p.uv[0], p.uv[1]);
            su += a.norm();
            sv += b.norm();
            n += 1.0;
        }
    }
    let (su, sv) = if n > 0.0 && su > 0.0 && sv > 0.0 {
        (su / n, sv / n)
    } else {
        (1.0, 1.0)
    };
    (su, sv, ub, vb)
}

/// Inserts the boundary loops' points (pole bridges subdivided so the fan at a pole is well
/// shaped) and their segments as constraints; the number of segments that could not be
/// inserted.
fn insert_boundary(
    brep: &Brep,
    f: FaceId,
    polys: &[Vec<Pt>],
    (su, sv): (f64, f64),
    cdt: &mut ConstrainedDelaunayTriangulation<Point2<f64>>,
    loc: &mut Local,
) -> Result<usize, MeshError> {
    let mut constraints_failed = 0usize;
    for poly in polys {
        let mut handles = vec![];
        let m = poly.len();
        for k in 0..m {
            let p = poly[k];
            let q = poly[(k + 1) % m];
            let Some((h, _)) = loc.insert(cdt, [p.uv[0] * su, p.uv[1] * sv], p.uv, p.idx) else {
                return Err(face_err(
                    brep,
                    f,
                    "boundary point is not a finite parameter",
                ));
            };
            handles.push(h);
            if p.sing != 0 && p.sing == q.sing {
                let axis = (p.sing - 1) as usize;
                let span = (q.uv[axis] - p.uv[axis]).abs();
                let steps = ((span / 0.2).ceil() as usize).clamp(1, 64);
                for j in 1..steps {
                    let t = j as f64 / steps as f64;
                    let uv = [
                        p.uv[0] + t * (q.uv[0] - p.uv[0]),
                        p.uv[1] + t * (q.uv[1] - p.uv[1]),
                    ];
                    if let Some((h, _)) = loc.insert(cdt, [uv[0] * su, uv[1] * sv], uv, p.idx) {
                        handles.push(h);
                    }
                }
            }
        }
        let hn = handles.len();
        for k in 0..hn {
            let (a, b) = (handles[k], handles[(k + 1) % hn]);
            if a != b && cdt.try_add_constraint(a, b).is_empty() {
                constraints_failed += 1;
            }
        }
    }
    Ok(constraints_failed)
}

/// Inserts the interior grid points: the surface's curvature steps over the parameter box,
/// inside the boundary and off it by a margin.
#[allow(clippy::too_many_arguments)]
fn insert_grid(
    s: &Surface,
    (ub, vb): ((f64, f64), (f64, f64)),
    (su, sv): (f64, f64),
    opts: &MeshOptions,
    bnd: &Boundary,
    positions: &mut Vec<P3>,
    cdt: &mut ConstrainedDelaunayTriangulation<Point2<f64>>,
    loc: &mut Local,
) {
    let (mut du, mut dv) = grid_steps(s, ub, vb, opts);
    // A straight direction (cylinder and cone generators) still gets rows, at most `ASPECT`
    // times the curved direction's spacing on the surface, so holes do not fan out into
    // triangles spanning a wide arc.
    const ASPECT: f64 = 6.0;
    if du.is_finite() && !dv.is_finite() {
        dv = du * su / sv * ASPECT;
    } else if dv.is_finite() && !du.is_finite() {
        du = dv * sv / su * ASPECT;
    }
    let (nu, nv) = (step_count(ub, du, 1), step_count(vb, dv, 1));
    if nu > 1 || nv > 1 {
        let (gu, gv) = ((ub.1 - ub.0) / nu as f64, (vb.1 - vb.0) / nv as f64);
        let margin = 0.35
            * (if nu > 1 { gu * su } else { f64::INFINITY }).min(if nv > 1 {
                gv * sv
            } else {
                f64::INFINITY
            });
        // A direction that needs no subdivision still gets points where the other one does, at
        // a spacing that keeps triangles from being needles.
        let (nu, nv) = (nu.max(1), nv.max(1));
        for i in 0..=nu {
            for j in 0..=nv {
                let uv = [ub.0 + gu * i as f64, vb.0 + gv * j as f64];
                let xy = [uv[0] * su, uv[1] * sv];
                if (nu > 1 && (i == 0 || i == nu)) || (nv > 1 && (j == 0 || j == nv)) {
                    continue;
                }
                if !bnd.inside(xy) || bnd.near(xy, margin) {
                    continue;
                }
                let p = s.eval(uv[0], uv[1]);
                let idx = positions.len() as u32;
                positions.push(p);
                loc.insert(cdt, xy, uv, idx);
            }
        }
    }
}

/// Where the triangles join a pair of mesh vertices more than once on the same side (points
/// that are one vertex in 3-D: a pole's points along its singular line, the two sides of the
/// cut to a pole, joined to the same neighbour twice over): the middles of the free edges drawn
/// between them, not split before, go to `splits`.
#[allow(clippy::type_complexity)]
fn split_doubled_edges(
    triangles: &[[u32; 3]],
    loc: &Local,
    drawn: &[((usize, usize), (u32, u32), bool, [f64; 2])],
    seen: &mut std::collections::HashSet<(usize, usize)>,
    splits: &mut Vec<[f64; 2]>,
) {
    let mut uses: HashMap<(u32, u32), (u32, u32)> = HashMap::new();
    for t in triangles {
        let g = [
            loc.vertex[t[0] as usize],
            loc.vertex[t[1] as usize],
            loc.vertex[t[2] as usize],
        ];
        if g[0] == g[1] || g[1] == g[2] || g[0] == g[2] {
            continue;
        }
        for k in 0..3 {
            let (a, c) = (g[k], g[(k + 1) % 3]);
            let u = uses.entry((a.min(c), a.max(c))).or_default();
            if a < c {
                u.0 += 1;
            } else {
                u.1 += 1;
            }
        }
    }
    for (h, (ga, gb), constraint, mid) in drawn {
        if !constraint
            && ga != gb
            && uses
                .get(&(*ga.min(gb), *ga.max(gb)))
                .is_some_and(|u| u.0 > 1 || u.1 > 1)
            && seen.insert(*h)
        {
            splits.push(*mid);
        }
    }
}

/// Chord error of a triangle: its scaled centroid where the flat triangle's centroid is off the
/// surface's by more than the chord tolerance and far enough from the boundary to split there.
fn chord_split(
    s: &Surface,
    loc: &Local,
    t: [u32; 3],
    positions: &[P3],
    (su, sv): (f64, f64),
    bnd: &Boundary,
    opts: &MeshOptions,
) -> Option<[f64; 2]> {
    let c = [
        (loc.uv[t[0] as usize][0] + loc.uv[t[1] as usize][0] + loc.uv[t[2] as usize][0]) / 3.0,
        (loc.uv[t[0] as usize][1] + loc.uv[t[1] as usize][1] + loc.uv[t[2] as usize][1]) / 3.0,
    ];
    let flat = (positions[loc.vertex[t[0] as usize] as usize].coords
        + positions[loc.vertex[t[1] as usize] as usize].coords
        + positions[loc.vertex[t[2] as usize] as usize].coords)
        / 3.0;
    let xy = [c[0] * su, c[1] * sv];
    ((s.eval(c[0], c[1]).coords - flat).norm() > opts.chord_tol
        && !bnd.near(xy, 0.25 * min_edge(loc, t, su, sv)))
    .then_some(xy)
}

/// The shortest edge of a local triangle, in scaled parameters.
fn min_edge(loc: &Local, t: [u32; 3], su: f64, sv: f64) -> f64 {
    (0..3)
        .map(|k| {
            let a = loc.uv[t[k] as usize];
            let b = loc.uv[t[(k + 1) % 3] as usize];
            ((a[0] - b[0]) * su).hypot((a[1] - b[1]) * sv)
        })
        .fold(f64::INFINITY, f64::min)
}

/// Local vertices of one face's triangulation, keyed by spade's vertex handles.
#[derive(Default)]
struct Local {
    uv: Vec<[f64; 2]>,
    vertex: Vec<u32>,
    handle_local: HashMap<usize, usize>,
}

impl Local {
    fn insert(
        &mut self,
        cdt: &mut ConstrainedDelaunayTriangulation<Point2<f64>>,
        xy: [f64; 2],
        uv: [f64; 2],
        idx: u32,
    ) -> Option<(spade::handles::FixedVertexHandle, usize)> {
        // spade refuses magnitudes below 2^-142; such values are zero for us.
        let snap = |x: f64| if x.abs() < TRIANGULATOR_ZERO { 0.0 } else { x };
        let h = cdt.insert(Point2::new(snap(xy[0]), snap(xy[1]))).ok()?;
        let (uvs, verts) = (&mut self.uv, &mut self.vertex);
        let e = *self.handle_local.entry(h.index()).or_insert_with(|| {
            uvs.push(uv);
            verts.push(idx);
            uvs.len() - 1
        });
        Some((h, e))
    }
}

/// Fewest constraint edges crossed from outside the hull to each face (0-1 breadth-first search).
fn constraint_depth(cdt: &ConstrainedDelaunayTriangulation<Point2<f64>>) -> Vec<u32> {
    let mut depth = vec![u32::MAX; cdt.num_all_faces()];
    let mut queue = std::collections::VecDeque::new();
    for e in cdt.convex_hull() {
        if let Some(f) = e.rev().face().as_inner() {
            let d = u32::from(e.is_constraint_edge());
            let i = f.fix().index();
            if d < depth[i] {
                depth[i] = d;
                queue.push_back((f.fix(), d));
            }
        }
    }
    while let Some((fh, d)) = queue.pop_front() {
        if d > depth[fh.index()] {
            continue;
        }
        for e in cdt.face(fh).adjacent_edges() {
            let Some(nf) = e.rev().face().as_inner() else {
                continue;
            };
            let c = u32::from(e.is_constraint_edge());
            let nd = d + c;
            let i = nf.fix().index();
            if nd < depth[i] {
                depth[i] = nd;
                if c == 0 {
                    queue.push_front((nf.fix(), nd));
                } else {
                    queue.push_back((nf.fix(), nd));
                }
            }
        }
    }
    depth
}
