//! Stair-step error of our curved-layer (freeform) plans against PrusaSlicer's planar slicing of
//! the same part (issue #6: "stair-step a tenth of planar").
//!
//! For every freeform feature of a part, the true outer surface (the feature's faces without its
//! healing faces, meshed at 0.01 mm chord tolerance) is sampled at the mesh vertices and triangle
//! centroids. At each sample the error is the distance to the nearest bead-centre segment of a
//! plan, minus half a bead (0.225 mm): zero where the bead's side just touches the surface,
//! positive where the beads fall short of it (the stairs), negative where a bead's top or side
//! reaches past the centre-offset (a layer top lying on the surface is −(w − h)/2). Both plans
//! are measured the same way, over their extrusion segments of any feature or type whose box
//! meets the feature's box grown by 2 mm:
//!
//! - ours: `plan::plan` (what `features plan PART.step --machine delta5` runs), the tool path's
//!   print points; a point's segment runs from the previous point; the bead centre is the nozzle tip minus axis × thickness / 2;
//! - PrusaSlicer: planar slicing of `features mesh PART.step --tolerance 0.01` at the same 0.2 mm
//!   layers and 0.45 mm beads; G1 moves in X/Y that add filament; the bead centre is the layer's
//!   Z − h/2; coordinates mapped back from the bed (the XY box centred on `--center`, the lowest
//!   point on Z = 0) into the part's.
//!
//! A second table gives the envelope error, which does not let w/2 > h/2 hide the stairs on
//! surfaces at a shallow angle to the layers: each bead is a w × h rectangle swept along its
//! centre segment a→b, the height along the tool axis n made perpendicular to the tangent t (ours:
//! the segment's end row's `i,j,k`, `thickness` and `width`; PrusaSlicer: +Z, the extrusion's
//! `;HEIGHT:`, i.e. the 0.2 mm layer except on bridges, and 0.45 mm). With c the point of the
//! segment closest to a sample s and r = s − c, the gap is
//! √(max(|r·n| − h/2, 0)² + max(|r·l| − w/2, 0)² + (r·t)²), l = n × t: the distance from s to the
//! bead, 0 inside. A sample's envelope error is the least gap over the beads whose centre
//! segment lies within 2 mm of it (2 mm if there is none). The same statistics are given for the
//! face-interior samples only: those farther than 1 mm from every edge of their B-rep face (the
//! face's boundary in the feature's mesh: the mesh edges of the face's triangles that only one
//! of them uses, so not a periodic face's seam), away from the edges and corners where any
//! bead-based plan stops short. `errors.csv` in each part's folder has every sample's errors,
//! face, distance to its face's edges, normal, and the |cos| between the normal and the height
//! axis of our bead nearest in envelope.
//!
//! Also reported: material (our `extruded_volume_mm3` of the plan's report, PrusaSlicer's filament
//! used × filament area) and the wall time of each run.
//!
//! `cargo bench -p features-cli --bench stairstep [-- impeller fan PATH.step ...]` (default: the
//! impeller and fan fixtures). Without `prusa-slicer` on the PATH (or `$PRUSA_SLICER`) only ours
//! is measured.

use brep::math::{Aabb, P3, V3};
use brep::mesh::{mesh_faces, MeshOptions};
use features::{extract, ExtractOptions, FeatureKind};
use slicer::params::{LayerParamsPatch, LayerStrategy};
use std::collections::HashMap;
use std::path::{Path, PathBuf};
use std::time::Instant;

#[path = "common/prusa.rs"]
mod prusa;

/// Bead width of both plans, mm.
const W: f64 = 0.45;
/// Layer height of both plans, mm.
const H: f64 = 0.2;
/// Filament diameter of both, mm.
const FILAMENT: f64 = 1.75;
/// PrusaSlicer puts the part's XY box centre here.
const CENTER: (f64, f64) = (100.0, 100.0);
/// Segments whose box meets the feature's box grown by this much are candidates, mm.
const GROW: f64 = 2.0;
/// Sample points further than this from every segment count as this far, mm.
const FAR: f64 = 20.0;
/// Face-interior samples lie farther than this from every edge of their face, mm.
const EDGE: f64 = 1.0;
/// Top-face samples count (issue 17) farther than this from every edge of their face, mm.
const TOP_EDGE: f64 = 0.3;
/// The top faces' largest envelope gap issue 17 asks for, mm.
const TOP_GOAL_MAX: f64 = 0.03;
/// Distances to a face's edges are measured up to this, mm.
const EDGE_CAP: f64 = 2.0;

/// One extrusion, bead centre to bead centre, with its w × h cross-section.
#[derive(Clone, Copy)]
struct Seg {
    a: P3,
    b: P3,
    /// Unit tool axis made perpendicular to `b − a`: the bead's height direction.
    n: V3,
    /// Half the bead's thickness (along `n`), mm.
    hh: f64,
    /// Half the bead's width (along `n × t`), mm.
    hw: f64,
}

/// A unit vector perpendicular to the unit vector `t`.
fn any_perpendicular(t: &V3) -> V3 {
    let e = if t.x.abs() <= t.y.abs() && t.x.abs() <= t.z.abs() {
        V3::x()
    } else if t.y.abs() <= t.z.abs() {
        V3::y()
    } else {
        V3::z()
    };
    t.cross(&e).normalize()
}

impl Seg {
    /// A bead from `a` to `b` of thickness `h` along `axis` (made perpendicular to the segment)
    /// and width `w`.
    fn new(a: P3, b: P3, axis: V3, h: f64, w: f64) -> Seg {
        let d = b - a;
        let len = d.norm();
        let n = if len > 0.0 {
            let t = d / len;
            let m = axis - t * axis.dot(&t);
            if m.norm() > 1e-9 {
                m.normalize()
            } else {
                any_perpendicular(&t)
            }
        } else if axis.norm() > 1e-9 {
            axis.normalize()
        } else {
            V3::z()
        };
        Seg {
            a,
            b,
            n,
            hh: h / 2.0,
            hw: w / 2.0,
        }
    }

    /// A bare polyline piece (no cross-section).
    fn line(a: P3, b: P3) -> Seg {
        Seg::new(a, b, V3::z(), 0.0, 0.0)
    }

    fn distance(&self, p: &P3) -> f64 {
        let d = self.b - self.a;
        let l2 = d.norm_squared();
        let t = if l2 > 0.0 {
            ((p - self.a).dot(&d) / l2).clamp(0.0, 1.0)
        } else {
            0.0
        };
        (p - (self.a + d * t)).norm()
    }

    /// Distance from `p` to the bead's envelope, the w × h rectangle (height along `n`, width
    /// along `n × t`) swept from `a` to `b`: 0 inside. Infinite for a segment of no length.
    fn gap(&self, p: &P3) -> f64 {
        let d = self.b - self.a;
        let len = d.norm();
        if len <= 1e-12 {
            return f64::INFINITY;
        }
        let t = d / len;
        let u = (p - self.a).dot(&t);
        let over = if u < 0.0 {
            -u
        } else if u > len {
            u - len
        } else {
            0.0
        };
        let r = p - (self.a + t * u.clamp(0.0, len));
        let l = self.n.cross(&t);
        let dn = (r.dot(&self.n).abs() - self.hh).max(0.0);
        let dl = (r.dot(&l).abs() - self.hw).max(0.0);
        (dn * dn + dl * dl + over * over).sqrt()
    }

    fn meets(&self, b: &Aabb) -> bool {
        let lo = self.a.inf(&self.b);
        let hi = self.a.sup(&self.b);
        (0..3).all(|i| hi[i] >= b.min[i] && lo[i] <= b.max[i])
    }
}

/// Nearest-segment queries over a uniform hash grid.
struct SegGrid {
    cell: f64,
    segs: Vec<Seg>,
    /// The largest half-diagonal of a bead's cross-section, mm.
    diag: f64,
    grid: HashMap<(i64, i64, i64), Vec<u32>>,
}

impl SegGrid {
    fn new(segs: Vec<Seg>, cell: f64) -> SegGrid {
        let mut grid: HashMap<(i64, i64, i64), Vec<u32>> = HashMap::new();
        let c = |x: f64| (x / cell).floor() as i64;
        for (idx, s) in segs.iter().enumerate() {
            let idx = idx as u32;
            let d = s.b - s.a;
            let n = (d.norm() / cell).ceil().max(1.0) as usize;
            for k in 0..n {
                let p = s.a + d * (k as f64 / n as f64);
                let q = s.a + d * ((k + 1) as f64 / n as f64);
                let (lo, hi) = (p.inf(&q), p.sup(&q));
                for i in c(lo.x)..=c(hi.x) {
                    for j in c(lo.y)..=c(hi.y) {
                        for l in c(lo.z)..=c(hi.z) {
                            let v = grid.entry((i, j, l)).or_default();
                            if v.last() != Some(&idx) {
                                v.push(idx);
                            }
                        }
                    }
                }
            }
        }
        let diag = segs.iter().map(|s| s.hh.hypot(s.hw)).fold(0.0, f64::max);
        SegGrid {
            cell,
            segs,
            diag,
            grid,
        }
    }

    /// Distance from `p` to the nearest segment, at most [`FAR`].
    fn nearest(&self, p: &P3) -> f64 {
        let c = |x: f64| (x / self.cell).floor() as i64;
        let (i0, j0, l0) = (c(p.x), c(p.y), c(p.z));
        let mut best = FAR;
        let rmax = (FAR / self.cell).ceil() as i64 + 1;
        for r in 0..=rmax {
            // The shell of cells at Chebyshev distance r.
            for i in i0 - r..=i0 + r {
                for j in j0 - r..=j0 + r {
                    let edge = (i - i0).abs() == r || (j - j0).abs() == r;
                    let ls: Vec<i64> = if edge {
                        (l0 - r..=l0 + r).collect()
                    } else {
                        vec![l0 - r, l0 + r]
                    };
                    for l in ls {
                        if let Some(v) = self.grid.get(&(i, j, l)) {
                            for &s in v {
                                best = best.min(self.segs[s as usize].distance(p));
                            }
                        }
                    }
                }
            }
            // Everything unseen lies in cells at least r + 1 away: at least r cells from p.
            if best <= r as f64 * self.cell {
                break;
            }
        }
        best
    }

    /// Calls `visit` with the index of every segment in the shells of cells around `p`, nearest
    /// shells first, until everything unseen is farther than the reach `visit` returns (at most
    /// `reach`).
    fn scan(&self, p: &P3, reach: f64, mut visit: impl FnMut(usize) -> f64) {
        let c = |x: f64| (x / self.cell).floor() as i64;
        let (i0, j0, l0) = (c(p.x), c(p.y), c(p.z));
        let mut now = reach;
        let rmax = (reach / self.cell).ceil() as i64 + 1;
        for r in 0..=rmax {
            for i in i0 - r..=i0 + r {
                for j in j0 - r..=j0 + r {
                    let edge = (i - i0).abs() == r || (j - j0).abs() == r;
                    let mut cell = |l: i64| {
                        if let Some(v) = self.grid.get(&(i, j, l)) {
                            for &s in v {
                                now = now.min(visit(s as usize));
                            }
                        }
                    };
                    if edge {
                        (l0 - r..=l0 + r).for_each(&mut cell);
                    } else {
                        cell(l0 - r);
                        if r > 0 {
                            cell(l0 + r);
                        }
                    }
                }
            }
            if now <= r as f64 * self.cell {
                break;
            }
        }
    }

    /// Distance from `p` to the nearest segment, at most `cap`.
    fn nearest_within(&self, p: &P3, cap: f64) -> f64 {
        let mut best = cap;
        self.scan(p, cap, |s| {
            best = best.min(self.segs[s].distance(p));
            best
        });
        best
    }

    /// The smallest envelope gap from `p` over the beads whose centre segment lies within
    /// [`GROW`] of it, and that bead's index; [`GROW`] and `None` if there is none.
    fn envelope(&self, p: &P3) -> (f64, Option<usize>) {
        let mut best = GROW;
        let mut which = None;
        self.scan(p, GROW, |s| {
            let seg = &self.segs[s];
            // The envelope lies within `diag` of the centre segment.
            if seg.distance(p) <= GROW {
                let g = seg.gap(p);
                if g < best || (which.is_none() && g <= best) {
                    best = g;
                    which = Some(s);
                }
            }
            (best + self.diag).min(GROW)
        });
        (best, which)
    }
}

/// Stair-step errors of one plan at each sample, mm.
#[derive(Clone, Default)]
struct Err {
    each: Vec<f64>,
}

/// Both measures of one plan at each sample of a surface.
struct Measured {
    /// Distance to the nearest bead centre − w/2 (the definition).
    centre: Err,
    /// Distance to the nearest bead envelope.
    envelope: Err,
    /// |cos| of the angle between the surface normal and the height axis of the bead giving
    /// the envelope error (1: the surface lies along the layers), NaN without one.
    axis_cos: Vec<f64>,
}

impl Measured {
    /// Measures the samples against the segments that meet the box grown by [`GROW`].
    fn new(s: &Surface, segs: &[Seg]) -> Measured {
        let mut grown = s.bbox;
        grown.min -= V3::repeat(GROW);
        grown.max += V3::repeat(GROW);
        let near: Vec<Seg> = segs.iter().copied().filter(|s| s.meets(&grown)).collect();
        let grid = SegGrid::new(near, 0.5);
        let centre = Err {
            each: s
                .samples
                .iter()
                .map(|p| grid.nearest(p) - W / 2.0)
                .collect(),
        };
        let mut envelope = Err::default();
        let mut axis_cos = vec![];
        for (p, n) in s.samples.iter().zip(&s.normal) {
            let (g, which) = grid.envelope(p);
            envelope.each.push(g);
            axis_cos.push(which.map_or(f64::NAN, |i| grid.segs[i].n.dot(n).abs()));
        }
        Measured {
            centre,
            envelope,
            axis_cos,
        }
    }
}

impl Err {
    /// The errors at the samples of top faces farther than [`TOP_EDGE`] from their face's edges.
    fn top_interior(&self, s: &Surface) -> Err {
        Err {
            each: self
                .each
                .iter()
                .zip(s.edge.iter().zip(&s.top))
                .filter(|(_, (d, top))| **d > TOP_EDGE && **top)
                .map(|(e, _)| *e)
                .collect(),
        }
    }

    /// The errors at the samples farther than [`EDGE`] from their face's edges.
    fn interior(&self, s: &Surface) -> Err {
        Err {
            each: self
                .each
                .iter()
                .zip(&s.edge)
                .filter(|(_, d)| **d > EDGE)
                .map(|(e, _)| *e)
                .collect(),
        }
    }

    /// The share of the samples over `x`, %.
    fn share_over(&self, x: f64) -> f64 {
        100.0 * self.each.iter().filter(|e| **e > x).count() as f64 / self.each.len().max(1) as f64
    }

    /// Max, p95 and mean, or `None` without samples.
    fn stats(&self) -> Option<(f64, f64, f64)> {
        (!self.each.is_empty()).then(|| (self.max(), self.quantile(0.95), self.mean()))
    }

    fn merge(&mut self, o: &Err) {
        self.each.extend_from_slice(&o.each);
    }

    fn max(&self) -> f64 {
        self.each.iter().copied().fold(f64::NEG_INFINITY, f64::max)
    }

    fn mean(&self) -> f64 {
        self.each.iter().sum::<f64>() / self.each.len().max(1) as f64
    }

    /// The `q`-quantile (nearest rank).
    fn quantile(&self, q: f64) -> f64 {
        let mut v = self.each.clone();
        v.sort_by(f64::total_cmp);
        let i = ((q * v.len() as f64).ceil() as usize).clamp(1, v.len().max(1)) - 1;
        v.get(i).copied().unwrap_or(f64::NAN)
    }
}

/// One freeform feature's true outer surface.
struct Surface {
    id: usize,
    samples: Vec<P3>,
    /// Unit outward surface normal at each sample (area-weighted at vertices).
    normal: Vec<V3>,
    /// Distance from each sample to the nearest edge of its B-rep face (0 on an edge), at most
    /// [`EDGE_CAP`], mm.
    edge: Vec<f64>,
    /// STEP id of each sample's face (the first one for a vertex on an edge).
    face: Vec<u64>,
    /// Whether each sample's face is a top face: its samples' mean normal within 60° of the
    /// reference surface's normal into the feature (the planner's rule for T, issue 17).
    top: Vec<bool>,
    bbox: Aabb,
    volume: f64,
    step_faces: Vec<u64>,
}

fn filament_area() -> f64 {
    std::f64::consts::PI * FILAMENT * FILAMENT / 4.0
}

fn surfaces(step: &Path) -> Result<(Vec<Surface>, f64), String> {
    let part = brep::read_step(step).map_err(|e| format!("reading: {e}"))?;
    let solid = part.brep.solid_ids().next().ok_or("no solid in the file")?;
    let tree = extract(&part.brep, solid, &ExtractOptions::default())
        .map_err(|e| format!("extracting: {e}"))?;
    let mut out = vec![];
    for f in &tree.features {
        if f.kind != FeatureKind::Freeform {
            continue;
        }
        let outer: Vec<_> = f
            .faces
            .iter()
            .copied()
            .filter(|x| !f.heal_faces.contains(x))
            .collect();
        let mesh = mesh_faces(&tree.brep, &outer, &MeshOptions::with_tolerance(0.01))
            .map_err(|e| format!("meshing feature {}: {e}", f.id))?;
        let pos = &mesh.positions;
        let mut samples = pos.clone();
        // Vertices first, then each face's triangle centroids in the order of `mesh.triangles()`.
        let mut edge = vec![f64::INFINITY; pos.len()];
        let mut face = vec![0u64; pos.len()];
        let mut normal = vec![V3::zeros(); pos.len()];
        let (mut c_edge, mut c_face, mut c_normal) = (vec![], vec![], vec![]);
        for ft in &mesh.faces {
            let sid = tree.brep.face(ft.face).step_id;
            let tris: Vec<[u32; 3]> = ft
                .triangles
                .iter()
                .map(|t| t.map(|i| ft.vertex[i as usize]))
                .filter(|g| g[0] != g[1] && g[1] != g[2] && g[0] != g[2])
                .collect();
            // The face's boundary: its mesh edges used by one triangle only (its B-rep edges,
            // not a seam, whose two sides share vertices).
            let mut uses: HashMap<(u32, u32), u32> = HashMap::new();
            for t in &tris {
                for k in 0..3 {
                    let (a, b) = (t[k], t[(k + 1) % 3]);
                    *uses.entry((a.min(b), a.max(b))).or_default() += 1;
                }
            }
            let bounds: Vec<Seg> = uses
                .iter()
                .filter(|(_, n)| **n == 1)
                .map(|((a, b), _)| Seg::line(pos[*a as usize], pos[*b as usize]))
                .collect();
            let grid = SegGrid::new(bounds, 1.0);
            for &v in &ft.vertex {
                let v = v as usize;
                edge[v] = edge[v].min(grid.nearest_within(&pos[v], EDGE_CAP));
                if face[v] == 0 {
                    face[v] = sid;
                }
            }
            for t in &tris {
                let [a, b, c] = t.map(|i| pos[i as usize]);
                let n = (b - a).cross(&(c - a));
                for &i in t {
                    normal[i as usize] += n;
                }
                let m = P3::from((a.coords + b.coords + c.coords) / 3.0);
                samples.push(m);
                c_edge.push(grid.nearest_within(&m, EDGE_CAP));
                c_face.push(sid);
                c_normal.push(n.try_normalize(0.0).unwrap_or_else(V3::zeros));
            }
        }
        if samples.len() != pos.len() + mesh.triangles().len() {
            return Err(format!(
                "feature {}: samples out of step with the mesh",
                f.id
            ));
        }
        // A vertex in no face is not known to lie inside one.
        for e in &mut edge {
            if !e.is_finite() {
                *e = 0.0;
            }
        }
        let mut normal: Vec<V3> = normal
            .into_iter()
            .map(|n| n.try_normalize(0.0).unwrap_or_else(V3::zeros))
            .collect();
        normal.extend(c_normal);
        edge.extend(c_edge);
        face.extend(c_face);
        // Top faces: the reference's normal at each sample's foot, turned into the feature.
        let rf = f
            .reference
            .face
            .ok_or(format!("feature {}: no reference face", f.id))?;
        let rs = tree.brep.face_surface(rf);
        let feet: Vec<(V3, V3)> = samples
            .iter()
            .map(|p| {
                let (u, v) = rs.project(p, None);
                (p - rs.eval(u, v), rs.normal(u, v).unwrap_or_else(V3::z))
            })
            .collect();
        let side: f64 = feet.iter().map(|(r, n)| r.dot(n)).sum();
        let sign = if side < 0.0 { -1.0 } else { 1.0 };
        let mut by_face: HashMap<u64, (f64, usize)> = HashMap::new();
        for ((fid, n), (_, rn)) in face.iter().zip(&normal).zip(&feet) {
            let e = by_face.entry(*fid).or_default();
            e.0 += sign * n.dot(rn);
            e.1 += 1;
        }
        let top = face
            .iter()
            .map(|fid| by_face.get(fid).is_some_and(|(s, n)| *s >= 0.5 * *n as f64))
            .collect();
        out.push(Surface {
            id: f.id,
            samples,
            normal,
            edge,
            face,
            top,
            bbox: mesh.bbox(),
            volume: f.volume,
            step_faces: f.step_faces(&tree.brep),
        });
    }
    Ok((out, tree.part_volume))
}

/// Our plan: bead-centre segments of the print rows, and `plan.json`.
struct Ours {
    segs: Vec<Seg>,
    /// Extruded volume by feature id, mm³.
    volume: HashMap<usize, f64>,
    /// STEP face ids by feature id.
    faces: HashMap<usize, Vec<u64>>,
    /// The layers each freeform feature got (`offset` or `transition`), by feature id.
    layers: HashMap<usize, String>,
    seconds: f64,
}

/// Plans `step` for the built-in 5-axis printer with the planner library (no files written),
/// every feature's `layer_strategy` set to `strategy`.
fn run_ours(step: &Path, strategy: LayerStrategy) -> Result<Ours, String> {
    let t = Instant::now();
    let part = brep::read_step(step).map_err(|e| format!("{}: {e}", step.display()))?;
    let machine = robot_post::MachineProfile::builtin(robot_post::MachineKind::Delta5);
    let options = plan::Options {
        source: step.display().to_string(),
        stem: "part".into(),
        allow_collisions: true,
        ..Default::default()
    };
    let mut process = plan::Process::default();
    process.defaults = Some(LayerParamsPatch {
        layer_strategy: Some(strategy),
        ..Default::default()
    });
    let planned = plan::plan(&part, &process, &machine, &options)
        .map_err(|e| format!("{}: features plan failed: {e}", step.display()))?;
    let seconds = t.elapsed().as_secs_f64();
    let mut segs = vec![];
    let mut prev: Option<P3> = None;
    for q in &planned.toolpath.points {
        let p = P3::from(q.p);
        let axis = V3::from(q.axis);
        let centre = p - axis * (f64::from(q.thickness) / 2.0);
        if q.kind == robot_post::MoveKind::Print {
            if let Some(a) = prev {
                segs.push(Seg::new(
                    a,
                    centre,
                    axis,
                    f64::from(q.thickness),
                    f64::from(q.width),
                ));
            }
        }
        prev = Some(centre);
    }
    let mut volume = HashMap::new();
    let mut faces = HashMap::new();
    let mut layers = HashMap::new();
    for f in planned.features() {
        if let Some(ff) = &f.freeform {
            layers.insert(f.feature.id, ff.layer_strategy.clone());
        }
        volume.insert(f.feature.id, f.extruded_volume_mm3);
        let mut fs = f.feature.faces.clone();
        fs.sort_unstable();
        faces.insert(f.feature.id, fs);
    }
    Ok(Ours {
        segs,
        volume,
        faces,
        layers,
        seconds,
    })
}

/// PrusaSlicer's plan of the STL, in part coordinates.
struct Prusa {
    segs: Vec<Seg>,
    volume: f64,
    seconds: f64,
}

enum PrusaRun {
    Missing(String),
    Failed(String),
    Done(Prusa),
}

/// The box of a binary STL's vertices.
fn stl_bbox(path: &Path) -> Result<Aabb, String> {
    let b = std::fs::read(path).map_err(|e| format!("{}: {e}", path.display()))?;
    if b.len() < 84 {
        return Err(format!("{}: too short for a binary STL", path.display()));
    }
    let n = u32::from_le_bytes([b[80], b[81], b[82], b[83]]) as usize;
    if b.len() < 84 + 50 * n {
        return Err(format!("{}: truncated binary STL", path.display()));
    }
    let mut bb = Aabb::empty();
    let f = |o: usize| f32::from_le_bytes([b[o], b[o + 1], b[o + 2], b[o + 3]]) as f64;
    for t in 0..n {
        for v in 0..3 {
            let o = 84 + 50 * t + 12 + 12 * v;
            bb.add(&P3::new(f(o), f(o + 4), f(o + 8)));
        }
    }
    Ok(bb)
}

fn run_prusa(stl: &Path, gcode: &Path) -> PrusaRun {
    let bbox = match stl_bbox(stl) {
        Ok(b) => b,
        Err(e) => return PrusaRun::Failed(e),
    };
    let settings = prusa::Settings {
        layer: H,
        width: W,
        filament: FILAMENT,
        center: CENTER,
        supports: false,
    };
    let seconds = match prusa::slice(stl, gcode, &settings, &[]) {
        prusa::Run::Done(s) => s,
        prusa::Run::Missing(why) => return PrusaRun::Missing(why),
        prusa::Run::Failed(why) => return PrusaRun::Failed(why),
    };
    let text = match std::fs::read_to_string(gcode) {
        Ok(t) => t,
        Err(e) => return PrusaRun::Failed(format!("{}: {e}", gcode.display())),
    };
    // Bed → part: the XY box centre moved to CENTER, the lowest point to Z = 0.
    let shift = V3::new(
        0.5 * (bbox.min.x + bbox.max.x) - CENTER.0,
        0.5 * (bbox.min.y + bbox.max.y) - CENTER.1,
        bbox.min.z,
    );
    match parse_gcode(&text, shift) {
        Ok(mut p) => {
            p.seconds = seconds;
            PrusaRun::Done(p)
        }
        Err(e) => PrusaRun::Failed(format!("{}: {e}", gcode.display())),
    }
}

/// Extrusions of a Marlin/RepRap G-code file: G0/G1 moves in X/Y that add filament, at bead
/// centres (Z − h/2, h from `;HEIGHT:` or the layer step), shifted by `shift`.
fn parse_gcode(text: &str, shift: V3) -> Result<Prusa, String> {
    let (mut x, mut y, mut z, mut e) = (0.0f64, 0.0f64, 0.0f64, 0.0f64);
    let (mut abs_xyz, mut abs_e) = (true, true);
    let mut height = H;
    let mut segs = vec![];
    let mut extruded = 0.0;
    let mut used_mm: Option<f64> = None;
    for (n, raw) in text.lines().enumerate() {
        let (code, comment) = match raw.find(';') {
            Some(i) => (&raw[..i], raw[i + 1..].trim()),
            None => (raw, ""),
        };
        if let Some(v) = comment.strip_prefix("HEIGHT:") {
            height = v.trim().parse().unwrap_or(H);
        }
        if let Some(v) = comment.strip_prefix("filament used [mm] =") {
            used_mm = v.trim().parse().ok();
        }
        let mut words = code.split_whitespace();
        let Some(cmd) = words.next() else { continue };
        let mut val: HashMap<char, f64> = HashMap::new();
        for w in words {
            let mut ch = w.chars();
            let Some(letter) = ch.next() else { continue };
            let v: f64 = ch
                .as_str()
                .parse()
                .map_err(|_| format!("line {}: bad word {w:?}", n + 1))?;
            val.insert(letter.to_ascii_uppercase(), v);
        }
        match cmd.to_ascii_uppercase().as_str() {
            "G90" => abs_xyz = true,
            "G91" => abs_xyz = false,
            "M82" => abs_e = true,
            "M83" => abs_e = false,
            "G92" => {
                if let Some(v) = val.get(&'E') {
                    e = *v;
                }
            }
            "G0" | "G1" | "G2" | "G3" => {
                let ax = |cur: f64, k: char, abs: bool| match val.get(&k) {
                    Some(v) if abs => *v,
                    Some(v) => cur + v,
                    None => cur,
                };
                let (nx, ny, nz) = (
                    ax(x, 'X', abs_xyz),
                    ax(y, 'Y', abs_xyz),
                    ax(z, 'Z', abs_xyz),
                );
                let ne = ax(e, 'E', abs_e);
                let moved = nx != x || ny != y;
                if moved && ne > e + 1e-9 && nz == z {
                    let c = V3::new(0.0, 0.0, -height / 2.0) + shift;
                    segs.push(Seg::new(
                        P3::new(x, y, z) + c,
                        P3::new(nx, ny, nz) + c,
                        V3::z(),
                        height,
                        W,
                    ));
                    extruded += ne - e;
                }
                (x, y, z, e) = (nx, ny, nz, ne);
            }
            _ => {}
        }
    }
    let volume = used_mm.unwrap_or(extruded) * filament_area();
    Ok(Prusa {
        segs,
        volume,
        seconds: 0.0,
    })
}

/// One line of the table.
struct Row {
    part: String,
    feature: String,
    ours: Option<Err>,
    prusa: Option<Err>,
    /// Envelope errors of ours and PrusaSlicer's, at all samples and at the face-interior ones.
    ours_env: Option<Err>,
    prusa_env: Option<Err>,
    ours_int: Option<Err>,
    prusa_int: Option<Err>,
    ours_volume: f64,
    prusa_volume: Option<f64>,
    cad_volume: f64,
    ours_s: Option<f64>,
    prusa_s: Option<f64>,
    /// Envelope errors at the top faces' interior samples, ours and PrusaSlicer's.
    ours_top: Option<Err>,
    prusa_top: Option<Err>,
}

fn fmt_opt(v: Option<f64>, prec: usize) -> String {
    v.map_or("-".into(), |v| format!("{v:.prec$}"))
}

fn print_table(rows: &[Row]) {
    println!();
    println!(
        "{:<9} {:<12} | {:>6} {:>6} {:>6} | {:>6} {:>6} {:>6} | {:>6} | {:>8} {:>8} {:>8} | {:>6} {:>6}",
        "", "", "ours", "", "", "prusa", "", "", "ratio", "volume", "mm3", "", "time", "s"
    );
    println!(
        "{:<9} {:<12} | {:>6} {:>6} {:>6} | {:>6} {:>6} {:>6} | {:>6} | {:>8} {:>8} {:>8} | {:>6} {:>6}",
        "part",
        "feature",
        "max",
        "p95",
        "mean",
        "max",
        "p95",
        "mean",
        "max",
        "ours",
        "prusa",
        "CAD",
        "ours",
        "prusa"
    );
    println!("{}", "-".repeat(118));
    for r in rows {
        let o = r.ours.as_ref();
        let p = r.prusa.as_ref();
        let ratio = o.zip(p).map(|(o, p)| o.max() / p.max());
        println!(
            "{:<9} {:<12} | {:>6} {:>6} {:>6} | {:>6} {:>6} {:>6} | {:>6} | {:>8.1} {:>8} {:>8.1} | {:>6} {:>6}",
            r.part,
            r.feature,
            fmt_opt(o.map(Err::max), 3),
            fmt_opt(o.map(|o| o.quantile(0.95)), 3),
            fmt_opt(o.map(Err::mean), 3),
            fmt_opt(p.map(Err::max), 3),
            fmt_opt(p.map(|p| p.quantile(0.95)), 3),
            fmt_opt(p.map(Err::mean), 3),
            fmt_opt(ratio, 2),
            r.ours_volume,
            fmt_opt(r.prusa_volume, 1),
            r.cad_volume,
            fmt_opt(r.ours_s, 1),
            fmt_opt(r.prusa_s, 1),
        );
    }
    println!(
        "stair-step in mm; ratio = ours max / PrusaSlicer max (goal <= 0.10); feature volumes are \
         ours only (PrusaSlicer's planar paths do not split by feature)"
    );
    // Where a layer cuts a convex edge of the part, its region has a corner of some angle θ;
    // a bead that stays inside the part has its middle at least w/2 from both sides, so at
    // least (w/2)/sin(θ/2) from the corner: the measure there is at least
    // (w/2)(1/sin(θ/2) − 1), whatever the plan.
    let floor = |deg: f64| 0.5 * W * (1.0 / (0.5 * deg.to_radians()).sin() - 1.0);
    println!(
        "floor of this measure where a layer cuts a convex edge, for any plan whose beads stay \
         inside the part: {:.3} mm at a 90 deg corner of the layer, {:.3} mm at 60 deg",
        floor(90.0),
        floor(60.0)
    );
    // On a face between two neighbouring beads (a wall between layers h apart, or a top between
    // lines w apart, each bead's side or top on the face) the surface point halfway is
    // √((w/2)² + (h/2)²) from both centres: that much minus w/2 wherever beads tile a face.
    println!(
        "floor of this measure on a face where beads w x h meet, layers or lines side by side: \
         {:.3} mm (a tenth of PrusaSlicer's max is below it wherever that max is under {:.3})",
        (0.25 * W * W + 0.25 * H * H).sqrt() - 0.5 * W,
        10.0 * ((0.25 * W * W + 0.25 * H * H).sqrt() - 0.5 * W)
    );
}

/// The issue-17 figure: the envelope gap on the top faces' interiors (samples of faces whose
/// normal is within 60° of the reference's, farther than [`TOP_EDGE`] from their edges).
fn print_top_table(rows: &[Row]) {
    println!();
    println!(
        "{:<20} {:<16} | {:>6} {:>6} {:>6} {:>7} | {:>6} {:>6} {:>6} {:>7} | {:>7}",
        "top faces, interior", "", "ours", "", "", "", "prusa", "", "", "", "samples"
    );
    println!(
        "{:<20} {:<16} | {:>6} {:>6} {:>6} {:>7} | {:>6} {:>6} {:>6} {:>7} | {:>7}",
        "part/plan",
        "feature layers",
        "max",
        "p95",
        "mean",
        ">0.03",
        "max",
        "p95",
        "mean",
        ">0.03",
        ""
    );
    println!("{}", "-".repeat(108));
    for r in rows {
        let Some(o) = r.ours_top.as_ref().filter(|o| !o.each.is_empty()) else {
            continue;
        };
        let p = r.prusa_top.as_ref().filter(|p| !p.each.is_empty());
        println!(
            "{:<20} {:<16} | {:>6.3} {:>6.3} {:>6.3} {:>6.2}% | {:>6} {:>6} {:>6} {:>7} | {:>7}",
            r.part,
            r.feature,
            o.max(),
            o.quantile(0.95),
            o.mean(),
            o.share_over(TOP_GOAL_MAX),
            fmt_opt(p.map(Err::max), 3),
            fmt_opt(p.map(|p| p.quantile(0.95)), 3),
            fmt_opt(p.map(Err::mean), 3),
            p.map_or("-".into(), |p| format!(
                "{:.2}%",
                p.share_over(TOP_GOAL_MAX)
            )),
            o.each.len()
        );
    }
    println!(
        "envelope gap in mm (0 inside a bead); plan `offset`: every freeform feature on offset \
         layers; `transition`: every one on transition layers; `auto` where the planner refused \
         those: its own choice per feature (the feature column says which); >0.03: the share \
         of samples over the goal's maximum; goal (issue 17): max <= 0.03, p95 <= 0.025 with \
         transition layers"
    );
}

fn print_envelope_table(rows: &[Row]) {
    println!();
    println!(
        "{:<9} {:<12} | {:<20} | {:<20} | {:<11} || {:<20} | {:<20} | {:<11} | {:>8}",
        "",
        "",
        "envelope: ours",
        "envelope: prusa",
        "ours/prusa",
        "interior: ours",
        "interior: prusa",
        "ours/prusa",
        "interior"
    );
    println!(
        "{:<9} {:<12} | {:>6} {:>6} {:>6} | {:>6} {:>6} {:>6} | {:>5} {:>5} || {:>6} {:>6} {:>6} | {:>6} {:>6} {:>6} | {:>5} {:>5} | {:>8}",
        "part", "feature", "max", "p95", "mean", "max", "p95", "mean", "max", "p95", "max", "p95",
        "mean", "max", "p95", "mean", "max", "p95", "samples"
    );
    println!("{}", "-".repeat(147));
    let three = |e: Option<&Err>| {
        let st = e.and_then(Err::stats);
        [
            fmt_opt(st.map(|s| s.0), 3),
            fmt_opt(st.map(|s| s.1), 3),
            fmt_opt(st.map(|s| s.2), 3),
        ]
    };
    let ratio = |o: Option<&Err>, p: Option<&Err>| {
        let (o, p) = (o.and_then(Err::stats), p.and_then(Err::stats));
        let r = o.zip(p);
        [
            fmt_opt(r.map(|(o, p)| o.0 / p.0), 2),
            fmt_opt(r.map(|(o, p)| o.1 / p.1), 2),
        ]
    };
    for r in rows {
        if r.ours_env.is_none() && r.prusa_env.is_none() {
            continue;
        }
        let [a, b, c] = three(r.ours_env.as_ref());
        let [d, e, f] = three(r.prusa_env.as_ref());
        let [g, h] = ratio(r.ours_env.as_ref(), r.prusa_env.as_ref());
        let [i, j, k] = three(r.ours_int.as_ref());
        let [l, m, n] = three(r.prusa_int.as_ref());
        let [o, p] = ratio(r.ours_int.as_ref(), r.prusa_int.as_ref());
        let count = r.ours_int.as_ref().map_or(0, |e| e.each.len());
        println!(
            "{:<9} {:<12} | {a:>6} {b:>6} {c:>6} | {d:>6} {e:>6} {f:>6} | {g:>5} {h:>5} || {i:>6} {j:>6} {k:>6} | {l:>6} {m:>6} {n:>6} | {o:>5} {p:>5} | {count:>8}",
            r.part, r.feature
        );
    }
    println!(
        "envelope error in mm: distance from the true surface to the nearest bead envelope (each \
         bead a w x h rectangle swept along its centre segment, h along the tool axis; the min over \
         beads within {GROW} mm, capped at {GROW}); interior: samples farther than {EDGE} mm from \
         every edge of their B-rep face; ratio = ours / PrusaSlicer of max and of p95"
    );
}

fn bench_part(step: &Path, tmp: &Path, rows: &mut Vec<Row>) -> Result<(), String> {
    let name = step
        .file_stem()
        .map(|s| s.to_string_lossy().into_owned())
        .unwrap_or_else(|| "part".into());
    let exe = PathBuf::from(env!("CARGO_BIN_EXE_features"));
    let dir = tmp.join(&name);
    std::fs::create_dir_all(&dir).map_err(|e| format!("{}: {e}", dir.display()))?;

    let (surfs, part_volume) = surfaces(step)?;
    if surfs.is_empty() {
        println!("{name}: no freeform features");
        return Ok(());
    }
    let stl = dir.join(format!("{name}.stl"));
    prusa::mesh_stl(&exe, step, &stl)?;
    let prusa = match run_prusa(&stl, &dir.join(format!("{name}.gcode"))) {
        PrusaRun::Done(p) => Some(p),
        PrusaRun::Missing(why) => {
            println!("{name}: PrusaSlicer not run ({why}); measuring ours only");
            None
        }
        PrusaRun::Failed(why) => {
            println!("{name}: PrusaSlicer failed ({why}); measuring ours only");
            None
        }
    };

    // Offset layers, then transition layers on every freeform feature; where the planner refuses
    // those (a top too close to the base somewhere for the thickness bounds), what `auto` gives.
    let mut dump = String::from(
        "plan,feature,x,y,z,ours,prusa,face,edge_mm,nx,ny,nz,ours_env,prusa_env,ours_axis_cos,top\n",
    );
    for strategy in [LayerStrategy::Offset, LayerStrategy::Transition] {
        let (label, ours) = match (strategy, run_ours(step, strategy)) {
            (LayerStrategy::Offset, Ok(o)) => ("offset", o),
            (LayerStrategy::Offset, Err(e)) => {
                // A rib in a trough narrower than its height: its offsets fold.
                println!("{name}: offset layers refused ({e})");
                continue;
            }
            (_, Ok(o)) => ("transition", o),
            (_, Err(e)) => {
                println!(
                    "{name}: transition layers refused ({e}); measuring layer_strategy = auto"
                );
                ("auto", run_ours(step, LayerStrategy::Auto)?)
            }
        };
        for s in &surfs {
            match ours.faces.get(&s.id) {
                Some(f) if *f == s.step_faces => {}
                _ => println!(
                    "{name}: warning: feature {} of the extraction and of plan.json differ in faces",
                    s.id
                ),
            }
        }

        let mut total_ours = Err::default();
        let mut total_prusa = Err::default();
        let mut totals: [Err; 4] = Default::default();
        let mut ff_volume = 0.0;
        let mut ff_cad = 0.0;
        let mut totals_top: [Err; 2] = Default::default();
        let part = format!("{name}/{label}");
        for s in &surfs {
            let om = Measured::new(s, &ours.segs);
            let pm = prusa.as_ref().map(|p| Measured::new(s, &p.segs));
            let o = om.centre.clone();
            let p = pm.as_ref().map(|m| m.centre.clone());
            for (i, q) in s.samples.iter().enumerate() {
                let pe = p
                    .as_ref()
                    .map_or(String::new(), |p| format!("{:.4}", p.each[i]));
                let pv = pm
                    .as_ref()
                    .map_or(String::new(), |p| format!("{:.4}", p.envelope.each[i]));
                let n = s.normal[i];
                dump.push_str(&format!(
                    "{label},{},{:.4},{:.4},{:.4},{:.4},{pe},{},{:.4},{:.4},{:.4},{:.4},{:.4},{pv},{:.4},{}\n",
                    s.id,
                    q.x,
                    q.y,
                    q.z,
                    o.each[i],
                    s.face[i],
                    s.edge[i],
                    n.x,
                    n.y,
                    n.z,
                    om.envelope.each[i],
                    om.axis_cos[i],
                    u8::from(s.top[i])
                ));
            }
            let oi = om.envelope.interior(s);
            let pi = pm.as_ref().map(|m| m.envelope.interior(s));
            let ot = om.envelope.top_interior(s);
            let pt = pm.as_ref().map(|m| m.envelope.top_interior(s));
            totals_top[0].merge(&ot);
            if let Some(m) = &pt {
                totals_top[1].merge(m);
            }
            totals[0].merge(&om.envelope);
            totals[2].merge(&oi);
            if let Some(m) = &pm {
                totals[1].merge(&m.envelope);
            }
            if let Some(m) = &pi {
                totals[3].merge(m);
            }
            total_ours.merge(&o);
            if let Some(p) = &p {
                total_prusa.merge(p);
            }
            let v = ours.volume.get(&s.id).copied().unwrap_or(0.0);
            ff_volume += v;
            ff_cad += s.volume;
            let layers = ours.layers.get(&s.id).map_or("?", |l| l.as_str());
            rows.push(Row {
                part: part.clone(),
                feature: format!("{} {layers}", s.id),
                ours: Some(o),
                prusa: p,
                ours_env: Some(om.envelope),
                prusa_env: pm.map(|m| m.envelope),
                ours_int: Some(oi),
                prusa_int: pi,
                ours_volume: v,
                prusa_volume: None,
                cad_volume: s.volume,
                ours_s: None,
                prusa_s: None,
                ours_top: Some(ot),
                prusa_top: pt,
            });
        }
        rows.push(Row {
            part: part.clone(),
            feature: "all freeform".into(),
            ours: Some(total_ours),
            prusa: prusa.as_ref().map(|_| total_prusa.clone()),
            ours_env: Some(totals[0].clone()),
            prusa_env: prusa.as_ref().map(|_| totals[1].clone()),
            ours_int: Some(totals[2].clone()),
            prusa_int: prusa.as_ref().map(|_| totals[3].clone()),
            ours_volume: ff_volume,
            prusa_volume: None,
            cad_volume: ff_cad,
            ours_s: None,
            prusa_s: None,
            ours_top: Some(totals_top[0].clone()),
            prusa_top: prusa.as_ref().map(|_| totals_top[1].clone()),
        });
        rows.push(Row {
            part,
            feature: "whole part".into(),
            ours: None,
            prusa: None,
            ours_env: None,
            prusa_env: None,
            ours_int: None,
            prusa_int: None,
            ours_volume: ours.volume.values().sum(),
            prusa_volume: prusa.as_ref().map(|p| p.volume),
            cad_volume: part_volume,
            ours_s: Some(ours.seconds),
            prusa_s: prusa.as_ref().map(|p| p.seconds),
            ours_top: None,
            prusa_top: None,
        });
    }
    let dump_path = dir.join("errors.csv");
    std::fs::write(&dump_path, dump).map_err(|e| format!("{}: {e}", dump_path.display()))?;
    let samples: usize = surfs.iter().map(|s| s.samples.len()).sum();
    println!(
        "{name}: {} freeform feature(s), {samples} surface samples, {} of PrusaSlicer's segments",
        surfs.len(),
        fmt_opt(prusa.as_ref().map(|p| p.segs.len() as f64), 0)
    );
    Ok(())
}

fn main() {
    let root = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../..");
    let mut parts: Vec<PathBuf> = std::env::args()
        .skip(1)
        .filter(|a| !a.starts_with('-'))
        .map(|a| {
            if a.ends_with(".step") || a.ends_with(".stp") {
                PathBuf::from(a)
            } else {
                root.join("fixtures").join(format!("{a}.step"))
            }
        })
        .collect();
    if parts.is_empty() {
        parts = ["impeller", "fan", "domed_pad"]
            .iter()
            .map(|n| root.join("fixtures").join(format!("{n}.step")))
            .collect();
    }
    let tmp = PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join("stairstep");
    println!(
        "stair-step error = max (mean) over samples of the freeform features' true outer surfaces \
         of (distance to the nearest bead-centre extrusion segment) - {:.3} mm; same {H} mm layers, \
         {W} mm beads; goal: ours max <= 0.1 x PrusaSlicer's",
        W / 2.0
    );
    let mut rows = vec![];
    let mut failed = false;
    for p in &parts {
        if let Err(e) = bench_part(p, &tmp, &mut rows) {
            println!("{}: {e}", p.display());
            failed = true;
        }
    }
    print_table(&rows);
    print_envelope_table(&rows);
    print_top_table(&rows);
    println!("(files in {})", tmp.display());
    if failed {
        std::process::exit(1);
    }
}
