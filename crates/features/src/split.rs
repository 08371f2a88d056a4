//! Cutting a shell along root loops and healing both open shells (feature-based AM paper,
//! "Extraction of AM features", Fig. 8), for roots wherever they lie on their host surface:
//! across the seam of a periodic surface, over several faces of one surface (writers split a
//! cylinder into halves, a plane by an edge), or as several loops bounding one region (a tube's
//! outer and inner roots).
//!
//! The parent's host faces drop the roots' edges; where a host face's boundary ran into a root
//! (a seam, or the edge between two faces of the host surface, cut short by the root), the two
//! pieces on either side are joined into one edge along their curve, so the surface runs across.
//! Host faces that become one region through a removed root are merged into one face. The child
//! gets faces on the host surface, facing the other way, bounded by the roots (one face per
//! outer root, with the roots it encloses as holes).

use crate::tolerance::{EMPTY_SPAN, PERIOD_SLACK};
use brep::math::P3;
use brep::mesh::{face_domain, MeshOptions};
use brep::topology::*;
use std::collections::{HashMap, HashSet};

/// Why a root loop was not split off.
#[derive(Debug, Clone, PartialEq)]
pub enum Refusal {
    /// Cutting along it separates nothing (a pocket's or slot's floor), or a root edge does not
    /// have one face on either side.
    NoSeparation,
    /// Its root runs over faces of different surfaces (a blade taller than its hub, rooted on
    /// the hub's side and top): `(face #id, surface kind)` of the host faces.
    MixedSurfaces(Vec<(u64, String)>),
    /// On its host surface the root bounds no region: it winds round the surface (the floor
    /// of a blind hole, seen from the hole's wall; a ring round a shaft).
    NoRegion(u64),
    /// Healing could not re-make the host's boundary across the root.
    Heal(String),
    /// Healing gave a shell that is not a valid solid.
    Invalid(String),
}

impl std::fmt::Display for Refusal {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Refusal::NoSeparation => write!(f, "it separates nothing (a pocket or slot floor)"),
            Refusal::MixedSurfaces(faces) => {
                let names: Vec<String> = faces.iter().map(|(i, k)| format!("#{i} {k}")).collect();
                write!(
                    f,
                    "its root runs over faces of different surfaces ({})",
                    names.join(", ")
                )
            }
            Refusal::NoRegion(face) => write!(
                f,
                "on its host face #{face} it bounds no region (it winds round the surface: a blind hole's floor, a ring round a shaft)"
            ),
            Refusal::Heal(s) => write!(f, "the host cannot be healed across it: {s}"),
            Refusal::Invalid(s) => write!(f, "healing would not give a valid solid: {s}"),
        }
    }
}

/// The parent-side faces along some roots, all on one surface, and those roots.
#[derive(Debug, Clone)]
pub struct HostGroup {
    /// Parent-side faces along the roots.
    pub faces: Vec<FaceId>,
    /// The roots (closed chains of edges).
    pub chains: Vec<Vec<EdgeId>>,
}

/// A planned cut: which faces leave, and the host faces on the parent side, by surface.
#[derive(Debug, Clone)]
pub struct Cut {
    /// Faces of the child side.
    pub child: Vec<FaceId>,
    /// Host faces by surface.
    pub groups: Vec<HostGroup>,
}

/// Tolerances of the geometric comparisons, from the part's size.
#[derive(Debug, Clone, Copy)]
pub struct Tol {
    /// Distance, mm.
    pub dist: f64,
}

impl Tol {
    /// For a part of bounding-box diagonal `diag`.
    pub fn for_size(diag: f64) -> Self {
        Tol {
            dist: (diag * 2e-5).max(1e-3),
        }
    }
}

/// The faces using an edge through their current loops.
pub fn edge_faces(b: &Brep, e: EdgeId) -> Vec<FaceId> {
    let mut out = vec![];
    for &c in &b.edge(e).coedges {
        let f = b.coedge_face(c);
        if b.face(f).loops.contains(&b.coedges[c.idx()].lp) && !out.contains(&f) {
            out.push(f);
        }
    }
    out
}

/// Points along a face's boundary: its vertices and the middle of each edge.
fn boundary_samples(b: &Brep, f: FaceId) -> Vec<P3> {
    let mut out = vec![];
    for e in b.edges_of(&[f]) {
        let ed = b.edge(e);
        out.push(b.vertices[ed.start.idx()].point);
        out.push(b.edge_curve(e).eval(0.5 * (ed.t_start + ed.t_end)));
    }
    out
}

/// Whether face `g` lies on the surface of face `f`, facing the same way: every boundary sample
/// of `g` on `f`'s surface within `tol`, with the outward normals of both faces parallel there.
pub fn same_surface(b: &Brep, f: FaceId, g: FaceId, tol: Tol) -> bool {
    if f == g {
        return true;
    }
    let (ff, gg) = (b.face(f), b.face(g));
    if ff.surface == gg.surface {
        return ff.same_sense == gg.same_sense;
    }
    let samples = boundary_samples(b, g);
    if samples.is_empty() {
        return false;
    }
    let (sf, sg) = (b.face_surface(f), b.face_surface(g));
    let mut normals_seen = 0;
    for p in &samples {
        let (u, v) = sf.project(p, None);
        if (sf.eval(u, v) - p).norm() > tol.dist {
            return false;
        }
        let (ug, vg) = sg.project(p, None);
        if let (Some(nf), Some(ng)) = (b.face_normal(f, u, v), b.face_normal(g, ug, vg)) {
            if nf.dot(&ng) < 0.9998 {
                return false;
            }
            normals_seen += 1;
        }
    }
    normals_seen > 0
}

/// Connected components of `faces` through shared edges, not crossing `cut`.
pub fn components(b: &Brep, faces: &[FaceId], cut: &HashSet<EdgeId>) -> HashMap<FaceId, usize> {
    let mut by_edge: HashMap<EdgeId, Vec<FaceId>> = HashMap::new();
    for &f in faces {
        for l in &b.face(f).loops {
            for c in &b.loops[l.idx()].coedges {
                let e = b.coedges[c.idx()].edge;
                if !cut.contains(&e) {
                    by_edge.entry(e).or_default().push(f);
                }
            }
        }
    }
    let idx: HashMap<FaceId, usize> = faces.iter().enumerate().map(|(k, f)| (*f, k)).collect();
    let mut uf = UnionFind::new(faces.len());
    for fs in by_edge.values() {
        for w in fs.windows(2) {
            uf.union(idx[&w[0]], idx[&w[1]]);
        }
    }
    faces.iter().map(|f| (*f, uf.find(idx[f]))).collect()
}

struct UnionFind(Vec<usize>);

impl UnionFind {
    fn new(n: usize) -> Self {
        UnionFind((0..n).collect())
    }
    fn find(&mut self, x: usize) -> usize {
        let mut r = x;
        while self.0[r] != r {
            r = self.0[r];
        }
        let mut y = x;
        while self.0[y] != r {
            let n = self.0[y];
            self.0[y] = r;
            y = n;
        }
        r
    }
    fn union(&mut self, a: usize, c: usize) {
        let (a, c) = (self.find(a), self.find(c));
        if a != c {
            self.0[a] = c;
        }
    }
}

/// Plans cutting `faces` along `chains`: the child is the component(s) across the chains from
/// the anchor (the largest component when there is no anchor); the parent-side faces along the
/// chains are grouped by the surface they lie on, and each chain's must lie on one surface.
pub fn plan_cut(
    b: &Brep,
    faces: &[FaceId],
    anchor: &[FaceId],
    chains: &[&Vec<EdgeId>],
    tol: Tol,
) -> Result<Cut, Refusal> {
    let cut: HashSet<EdgeId> = chains.iter().flat_map(|c| c.iter().copied()).collect();
    let comps = components(b, faces, &cut);
    let parent = match anchor.iter().find_map(|f| comps.get(f)) {
        Some(&c) => c,
        None => {
            let mut count: HashMap<usize, usize> = HashMap::new();
            for c in comps.values() {
                *count.entry(*c).or_default() += 1;
            }
            count
                .into_iter()
                .max_by_key(|x| (x.1, usize::MAX - x.0))
                .ok_or(Refusal::NoSeparation)?
                .0
        }
    };
    // A component lying wholly on the surface of a parent-side host face, facing the same
    // way, is part of the parent's surface (the plate's top inside a tube standing on it).
    let mut parent_comps: HashSet<usize> = HashSet::from([parent]);
    let mut hosts0: Vec<FaceId> = vec![];
    for e in chains.iter().flat_map(|c| c.iter()) {
        for f in edge_faces(b, *e) {
            if comps.get(&f) == Some(&parent) && !hosts0.contains(&f) {
                hosts0.push(f);
            }
        }
    }
    let mut by_comp: HashMap<usize, Vec<FaceId>> = HashMap::new();
    for (f, c) in &comps {
        if *c != parent {
            by_comp.entry(*c).or_default().push(*f);
        }
    }
    for (c, fs) in by_comp {
        if fs
            .iter()
            .all(|&f| hosts0.iter().any(|&h| same_surface(b, h, f, tol)))
        {
            parent_comps.insert(c);
        }
    }
    let is_parent = |f: &FaceId| parent_comps.contains(&comps[f]);
    let mut child: HashSet<usize> = HashSet::new();
    let mut groups: Vec<HostGroup> = vec![];
    for chain in chains {
        let mut hosts: Vec<FaceId> = vec![];
        for e in chain.iter() {
            let fs: Vec<FaceId> = edge_faces(b, *e)
                .into_iter()
                .filter(|f| comps.contains_key(f))
                .collect();
            if fs.len() != 2 {
                return Err(Refusal::NoSeparation);
            }
            let (p, c): (Vec<FaceId>, Vec<FaceId>) = fs.into_iter().partition(is_parent);
            if p.len() != 1 || c.len() != 1 {
                return Err(Refusal::NoSeparation);
            }
            if !hosts.contains(&p[0]) {
                hosts.push(p[0]);
            }
            child.insert(comps[&c[0]]);
        }
        if hosts.iter().any(|&h| !same_surface(b, hosts[0], h, tol)) {
            return Err(Refusal::MixedSurfaces(
                hosts
                    .iter()
                    .map(|&h| (b.face(h).step_id, b.face_surface(h).kind().to_string()))
                    .collect(),
            ));
        }
        match groups
            .iter_mut()
            .find(|g| same_surface(b, g.faces[0], hosts[0], tol))
        {
            Some(g) => {
                for h in hosts {
                    if !g.faces.contains(&h) {
                        g.faces.push(h);
                    }
                }
                g.chains.push(chain.to_vec());
            }
            None => groups.push(HostGroup {
                faces: hosts,
                chains: vec![chain.to_vec()],
            }),
        }
    }
    if child.is_empty() || child.iter().any(|c| parent_comps.contains(c)) {
        return Err(Refusal::NoSeparation);
    }
    let child_faces: Vec<FaceId> = faces
        .iter()
        .copied()
        .filter(|f| child.contains(&comps[f]))
        .collect();
    Ok(Cut {
        child: child_faces,
        groups,
    })
}

/// Child faces that lie on a host surface of the cut, facing the same way: they belong to the
/// parent (the plate's top inside a tube standing on it).
pub fn child_faces_on_hosts(b: &Brep, cut: &Cut, tol: Tol) -> Vec<FaceId> {
    cut.child
        .iter()
        .copied()
        .filter(|&f| {
            cut.groups
                .iter()
                .any(|g| same_surface(b, g.faces[0], f, tol))
        })
        .collect()
}

/// A host face after healing and its loops, as edge uses `(edge, forward)`.
type HealedFace = (FaceId, Vec<Vec<(EdgeId, bool)>>);

/// One use of an edge in a loop.
#[derive(Debug, Clone, Copy, PartialEq)]
struct Use {
    edge: EdgeId,
    fwd: bool,
    face: FaceId,
}

/// The vertices an edge used along (`fwd`) or against its direction runs from and to.
fn oriented_ends(b: &Brep, e: EdgeId, fwd: bool) -> (VertexId, VertexId) {
    let ed = b.edge(e);
    if fwd {
        (ed.start, ed.end)
    } else {
        (ed.end, ed.start)
    }
}

fn use_start(b: &Brep, u: &Use) -> VertexId {
    oriented_ends(b, u.edge, u.fwd).0
}

fn use_end(b: &Brep, u: &Use) -> VertexId {
    oriented_ends(b, u.edge, u.fwd).1
}

/// Curve parameters of a use's start and end.
fn use_params(b: &Brep, u: &Use) -> (f64, f64) {
    let e = b.edge(u.edge);
    if u.fwd {
        (e.t_start, e.t_end)
    } else {
        (e.t_end, e.t_start)
    }
}

/// Where use `o` continues use `i` along `i`'s curve past a gap: the parameter on `i`'s curve
/// at the end of `o` (unwrapped past `i`'s end), and the gap's length in parameter. `None` when
/// `o` does not lie on `i`'s curve running the same way.
fn continuation(b: &Brep, i: &Use, o: &Use, tol: Tol) -> Option<(f64, f64)> {
    let c = b.edge_curve(i.edge);
    let (ti0, ti1) = use_params(b, i);
    let s = (ti1 - ti0).signum();
    if s == 0.0 {
        return None;
    }
    let q0 = b.vertices[use_start(b, o).idx()].point;
    let q1 = b.vertices[use_end(b, o).idx()].point;
    let (to0, to1) = use_params(b, o);
    let mid = b.edge_curve(o.edge).eval(0.5 * (to0 + to1));
    let same_curve = b.edge(i.edge).curve == b.edge(o.edge).curve;
    let on = |p: &P3, t: f64| (c.eval(t) - p).norm() <= tol.dist;
    // Parameters of o's start and end on i's curve.
    let (mut a, mut z) = if same_curve {
        (to0, to1)
    } else {
        (c.project(&q0), c.project(&q1))
    };
    if !on(&q0, a) || !on(&q1, z) {
        return None;
    }
    if let Some(per) = c.period() {
        // o starts at or past i's end, within one turn.
        a = ti1 + s * (s * (a - ti1)).rem_euclid(per);
        if (a - ti1).abs() > per - PERIOD_SLACK {
            a = ti1;
        }
        z = a + s * (s * (z - a)).rem_euclid(per);
        if (z - a).abs() < EMPTY_SPAN {
            z = a + s * per;
        }
    }
    let tm = 0.5 * (a + z);
    if !on(&mid, tm) || (z - a) * s <= 0.0 || (a - ti1) * s < -PERIOD_SLACK {
        return None;
    }
    Some((z, (a - ti1).abs()))
}

/// Re-makes the boundary of a group's host faces without its roots. Returns the new faces'
/// loops: for each surviving face, its loops as edge uses; faces absent from the result are
/// dropped (they lay inside a root).
fn heal_hosts(b: &mut Brep, group: &HostGroup, tol: Tol) -> Result<Vec<HealedFace>, Refusal> {
    let chain: HashSet<EdgeId> = group.chains.iter().flatten().copied().collect();
    let fidx: HashMap<FaceId, usize> = group
        .faces
        .iter()
        .enumerate()
        .map(|(k, f)| (*f, k))
        .collect();
    // Every kept use, its successor where known, and the gaps the roots leave.
    let RootCut {
        mut uses,
        mut next,
        into,
        out_of,
        kept_loops,
        vertex_faces,
    } = cut_at_roots(b, group, &chain);
    // (a) A piece of boundary cut short by a root continues along its curve past the gap: the
    // two pieces become one edge (`i` takes the merged use, `o` goes).
    let Joins {
        mut into_left,
        mut out_left,
        skip,
        mut links,
    } = join_continuations(b, &mut uses, &mut next, (&into, &out_of), tol);
    // (b) Ends that meet at a vertex of the root join directly, a piece and its own way back
    // first (a seam that ran into the root; the pair cancels below).
    let mut lefts: Vec<usize> = into_left.iter().copied().collect();
    lefts.sort_unstable();
    for i in lefts {
        let end = use_end(b, &uses[i]);
        let mut outs: Vec<usize> = out_left
            .iter()
            .copied()
            .filter(|&o| use_start(b, &uses[o]) == end)
            .collect();
        outs.sort_by_key(|&o| (uses[o].edge != uses[i].edge, o));
        if let Some(&o) = outs.first() {
            into_left.remove(&i);
            out_left.remove(&o);
            next[i] = Some(o);
            links.push((i, o));
        }
    }
    if !into_left.is_empty() || !out_left.is_empty() {
        return Err(Refusal::Heal(format!(
            "{} boundary piece(s) end on the root with nothing to join",
            into_left.len().max(out_left.len())
        )));
    }
    // Faces joined through a root become one.
    let mut uf = UnionFind::new(group.faces.len());
    for (k, u) in uses.iter().enumerate() {
        if skip.contains(&k) {
            continue;
        }
        if let Some(n) = next[k] {
            uf.union(fidx[&u.face], fidx[&uses[n].face]);
        }
    }
    for (i, o) in &links {
        uf.union(fidx[&uses[*i].face], fidx[&uses[*o].face]);
    }
    let class: Vec<usize> = (0..group.faces.len()).map(|k| uf.find(k)).collect();
    // Walk the cycles.
    let mut seen = vec![false; uses.len()];
    let mut loops_by_class: HashMap<usize, Vec<Vec<(EdgeId, bool)>>> = HashMap::new();
    for s in 0..uses.len() {
        if seen[s] || skip.contains(&s) {
            continue;
        }
        let mut cyc = vec![];
        let mut k = s;
        while !seen[k] {
            seen[k] = true;
            cyc.push((uses[k].edge, uses[k].fwd));
            match next[k] {
                Some(n) if !skip.contains(&n) => k = n,
                _ => return Err(Refusal::Heal("the host's boundary does not close".into())),
            }
        }
        if k != s {
            return Err(Refusal::Heal("the host's boundary does not close".into()));
        }
        cancel_spikes(&mut cyc);
        if !cyc.is_empty() {
            loops_by_class
                .entry(class[fidx[&uses[s].face]])
                .or_default()
                .push(cyc);
        }
    }
    // A closed edge that is a whole loop on its own, once each way in one face, is a seam the
    // face no longer needs (two faces either side of a torus's seam circle, joined).
    drop_seam_pairs(&mut loops_by_class);
    for (f, seq) in kept_loops {
        loops_by_class.entry(class[fidx[&f]]).or_default().push(seq);
    }
    let mut out = vec![];
    let mut done: HashSet<usize> = HashSet::new();
    for (k, &f) in group.faces.iter().enumerate() {
        if !done.insert(class[k]) {
            continue;
        }
        let mut loops = loops_by_class.remove(&class[k]).unwrap_or_default();
        let has_vertex = vertex_faces.iter().any(|g| class[fidx[g]] == class[k]);
        if loops.is_empty() && !has_vertex {
            continue;
        }
        loops.sort_by_key(|l| std::cmp::Reverse(l.len()));
        out.push((f, loops));
    }
    Ok(out)
}

/// A group's host loops cut at the roots: every kept use, its successor where known, and the
/// gaps the roots leave (`into[k]` is the use before a gap, `out_of[k]` the one after it); the
/// loops no root touches; the faces with a vertex loop.
struct RootCut {
    uses: Vec<Use>,
    next: Vec<Option<usize>>,
    into: Vec<usize>,
    out_of: Vec<usize>,
    kept_loops: Vec<(FaceId, Vec<(EdgeId, bool)>)>,
    vertex_faces: Vec<FaceId>,
}

/// Cuts the loops of a group's host faces at the root edges `chain`.
fn cut_at_roots(b: &Brep, group: &HostGroup, chain: &HashSet<EdgeId>) -> RootCut {
    let mut uses: Vec<Use> = vec![];
    let mut next: Vec<Option<usize>> = vec![];
    let mut into: Vec<usize> = vec![];
    let mut out_of: Vec<usize> = vec![];
    let mut kept_loops: Vec<(FaceId, Vec<(EdgeId, bool)>)> = vec![];
    // Faces with a vertex loop (a pole): such a face is kept even with no edge loop left.
    let mut vertex_faces: Vec<FaceId> = vec![];
    for &f in &group.faces {
        for &l in &b.face(f).loops {
            let lp = &b.loops[l.idx()];
            if lp.vertex.is_some() {
                vertex_faces.push(f);
                continue;
            }
            let seq: Vec<(EdgeId, bool)> = lp
                .coedges
                .iter()
                .map(|c| (b.coedges[c.idx()].edge, b.coedges[c.idx()].forward))
                .collect();
            if !seq.iter().any(|(e, _)| chain.contains(e)) {
                kept_loops.push((f, seq));
                continue;
            }
            let n = seq.len();
            let Some(first) = (0..n).find(|&k| chain.contains(&seq[k].0)) else {
                continue;
            };
            // Walk from just after a root use, so a gap is seen before the use after it.
            let mut prev: Option<usize> = None;
            let mut first_kept: Option<usize> = None;
            let mut gap = true;
            for k in 1..=n {
                let (e, fwd) = seq[(first + k) % n];
                if chain.contains(&e) {
                    gap = true;
                    continue;
                }
                let id = uses.len();
                uses.push(Use {
                    edge: e,
                    fwd,
                    face: f,
                });
                next.push(None);
                if let Some(p) = prev {
                    if gap {
                        into.push(p);
                        out_of.push(id);
                    } else {
                        next[p] = Some(id);
                    }
                } else {
                    first_kept = Some(id);
                }
                gap = false;
                prev = Some(id);
            }
            // The loop closes through the root at `first`.
            if let (Some(p), Some(q)) = (prev, first_kept) {
                into.push(p);
                out_of.push(q);
            }
        }
    }
    RootCut {
        uses,
        next,
        into,
        out_of,
        kept_loops,
        vertex_faces,
    }
}

/// The gaps left after continuing pieces along their curves: the uses before and after a gap
/// still open, the uses merged away, and the joins made (before, after).
struct Joins {
    into_left: HashSet<usize>,
    out_left: HashSet<usize>,
    skip: HashSet<usize>,
    links: Vec<(usize, usize)>,
}

/// (a) A piece of boundary cut short by a root continues along its curve past the gap: the two
/// pieces become one edge (`i` takes the merged use, `o` goes), the nearest continuations first.
fn join_continuations(
    b: &mut Brep,
    uses: &mut [Use],
    next: &mut [Option<usize>],
    (into, out_of): (&[usize], &[usize]),
    tol: Tol,
) -> Joins {
    let mut cands: Vec<(f64, usize, usize, f64)> = vec![];
    for &i in into {
        for &o in out_of {
            if let Some((z, gap)) = continuation(b, &uses[i], &uses[o], tol) {
                cands.push((gap, i, o, z));
            }
        }
    }
    cands.sort_by(|x, y| x.0.total_cmp(&y.0));
    let mut into_left: HashSet<usize> = into.iter().copied().collect();
    let mut out_left: HashSet<usize> = out_of.iter().copied().collect();
    let mut merged: HashMap<(EdgeId, EdgeId), EdgeId> = HashMap::new();
    let mut alias: HashMap<usize, usize> = HashMap::new();
    let mut skip: HashSet<usize> = HashSet::new();
    let mut links: Vec<(usize, usize)> = vec![];
    for (_, i0, o, z) in cands {
        let mut i = i0;
        while let Some(&a) = alias.get(&i) {
            i = a;
        }
        if !into_left.contains(&i) || !out_left.contains(&o) || skip.contains(&o) {
            continue;
        }
        let (ui, uo) = (uses[i], uses[o]);
        let (t0, t1) = use_params(b, &ui);
        // A piece that continues into itself closes round its curve through the gap.
        let (a, c, z) = if i == o {
            let per = b.edge_curve(ui.edge).period().unwrap_or(0.0);
            let a = use_start(b, &ui);
            (a, a, t0 + (t1 - t0).signum() * per)
        } else {
            (use_start(b, &ui), use_end(b, &uo), z)
        };
        let key = (ui.edge.min(uo.edge), ui.edge.max(uo.edge));
        let (m, fwd) = match merged.get(&key) {
            Some(&m) => {
                let me = b.edge(m);
                let fwd = if a != c {
                    (me.start, me.end) == (a, c)
                } else {
                    (me.t_end - me.t_start) * (z - t0) > 0.0
                };
                (m, fwd)
            }
            None => {
                let m = EdgeId(b.edges.len() as u32);
                b.edges.push(Edge {
                    step_id: 0,
                    curve: b.edge(ui.edge).curve,
                    start: a,
                    end: c,
                    t_start: t0,
                    t_end: z,
                    coedges: vec![],
                });
                merged.insert(key, m);
                (m, true)
            }
        };
        into_left.remove(&i);
        out_left.remove(&o);
        uses[i] = Use {
            edge: m,
            fwd,
            face: ui.face,
        };
        if i != o {
            skip.insert(o);
            next[i] = next[o];
            links.push((i, o));
            if into_left.remove(&o) {
                into_left.insert(i);
                alias.insert(o, i);
            }
        } else {
            next[i] = Some(i);
        }
    }
    Joins {
        into_left,
        out_left,
        skip,
        links,
    }
}

/// Drops the pairs of one-edge loops using a closed edge once each way in one face: a seam the
/// face no longer needs.
fn drop_seam_pairs(loops_by_class: &mut HashMap<usize, Vec<Vec<(EdgeId, bool)>>>) {
    for loops in loops_by_class.values_mut() {
        let single = |l: &Vec<(EdgeId, bool)>| (l.len() == 1).then(|| l[0]);
        let mut k = 0;
        while k < loops.len() {
            let pair = single(&loops[k]).and_then(|(e, fwd)| {
                (0..loops.len()).find(|&j| j != k && single(&loops[j]) == Some((e, !fwd)))
            });
            match pair {
                Some(j) => {
                    let (hi, lo) = (j.max(k), j.min(k));
                    loops.remove(hi);
                    loops.remove(lo);
                    k = 0;
                }
                None => k += 1,
            }
        }
    }
}

/// Removes adjacent uses of one edge in opposite directions (a seam that now leads nowhere).
fn cancel_spikes(cyc: &mut Vec<(EdgeId, bool)>) {
    let mut changed = true;
    while changed && cyc.len() >= 2 {
        changed = false;
        let n = cyc.len();
        for k in 0..n {
            let (x, y) = (cyc[k], cyc[(k + 1) % n]);
            if x.0 == y.0 && x.1 != y.1 {
                let (a, c) = (k, (k + 1) % n);
                let (hi, lo) = (a.max(c), a.min(c));
                cyc.remove(hi);
                cyc.remove(lo);
                changed = true;
                break;
            }
        }
    }
}

/// Orders edge uses into one closed head-to-tail cycle.
fn order_cycle(b: &Brep, uses: &[(EdgeId, bool)]) -> Option<Vec<(EdgeId, bool)>> {
    let ends = |(e, f): (EdgeId, bool)| oriented_ends(b, e, f);
    let mut left: Vec<(EdgeId, bool)> = uses.to_vec();
    let first = left.pop()?;
    let mut out = vec![first];
    let start = ends(first).0;
    let mut at = ends(first).1;
    while !left.is_empty() {
        let k = left.iter().position(|u| ends(*u).0 == at)?;
        let u = left.remove(k);
        at = ends(u).1;
        out.push(u);
    }
    (at == start).then_some(out)
}

/// Adds a loop of edge uses to `face` in the arena.
fn push_loop(b: &mut Brep, face: FaceId, seq: &[(EdgeId, bool)]) -> LoopId {
    let nl = LoopId(b.loops.len() as u32);
    let mut coedges = vec![];
    for &(e, fwd) in seq {
        let nc = CoedgeId(b.coedges.len() as u32);
        b.coedges.push(Coedge {
            step_id: 0,
            edge: e,
            forward: fwd,
            lp: nl,
        });
        b.edges[e.idx()].coedges.push(nc);
        coedges.push(nc);
    }
    b.loops.push(Loop {
        step_id: 0,
        face,
        outer: false,
        coedges,
        vertex: None,
    });
    nl
}

/// Adds a face on `like`'s surface facing the other way, bounded by `loops`.
fn push_face(b: &mut Brep, like: FaceId, loops: &[Vec<(EdgeId, bool)>]) -> FaceId {
    let host = b.face(like).clone();
    let h = FaceId(b.faces.len() as u32);
    b.faces.push(Face {
        step_id: 0,
        surface: host.surface,
        same_sense: !host.same_sense,
        loops: vec![],
        shell: host.shell,
    });
    let ls: Vec<LoopId> = loops.iter().map(|seq| push_loop(b, h, seq)).collect();
    if let Some(l) = ls.first() {
        b.loops[l.idx()].outer = true;
    }
    b.faces[h.idx()].loops = ls;
    h
}

/// The healing faces of the child for one group: one face per outer root, with the roots it
/// encloses as holes; all roots in one face when a root alone bounds no region (two rims of a
/// band round a cylinder).
fn heal_child(b: &mut Brep, group: &HostGroup) -> Result<Vec<FaceId>, Refusal> {
    let mut cycles = vec![];
    for chain in &group.chains {
        let set: HashSet<EdgeId> = chain.iter().copied().collect();
        let mut uses: Vec<(EdgeId, bool)> = vec![];
        for &f in &group.faces {
            for l in &b.face(f).loops {
                for c in &b.loops[l.idx()].coedges {
                    let ce = &b.coedges[c.idx()];
                    if set.contains(&ce.edge) && !uses.iter().any(|u| u.0 == ce.edge) {
                        uses.push((ce.edge, ce.forward));
                    }
                }
            }
        }
        let cyc = order_cycle(b, &uses)
            .ok_or_else(|| Refusal::Heal("a root is not one closed loop on its host".into()))?;
        cycles.push(cyc);
    }
    let like = group.faces[0];
    if cycles.len() == 1 {
        return Ok(vec![push_face(b, like, &cycles)]);
    }
    // Each root alone: does it bound a region, and which others lie inside it?
    let coarse = MeshOptions::with_tolerance(0.5);
    let mut domains = vec![];
    for cyc in &cycles {
        let f = push_face(b, like, std::slice::from_ref(cyc));
        let d = face_domain(b, f, &coarse)
            .ok()
            .filter(|d| !d.loops.is_empty());
        domains.push((f, d));
    }
    let singles: Vec<FaceId> = domains.iter().map(|x| x.0).collect();
    let all_bound = domains.iter().all(|(_, d)| d.is_some());
    let out = if all_bound {
        let s = b.face_surface(like).clone();
        let n = cycles.len();
        let mut inside = vec![vec![false; n]; n];
        for j in 0..n {
            let p = b.vertices[b.edge(cycles[j][0].0).start.idx()].point;
            let (u, v) = s.project(&p, None);
            for (i, (_, d)) in domains.iter().enumerate() {
                if i != j {
                    inside[i][j] = d.as_ref().is_some_and(|d| d.contains([u, v]));
                }
            }
        }
        let depth: Vec<usize> = (0..n)
            .map(|j| (0..n).filter(|&i| inside[i][j]).count())
            .collect();
        let mut faces = vec![];
        for i in 0..n {
            if depth[i] % 2 == 1 {
                continue;
            }
            let mut loops = vec![cycles[i].clone()];
            for j in 0..n {
                if inside[i][j] && depth[j] == depth[i] + 1 {
                    loops.push(cycles[j].clone());
                }
            }
            faces.push(push_face(b, like, &loops));
        }
        faces
    } else {
        vec![push_face(b, like, &cycles)]
    };
    // The trial faces stay in the arena unused; no shell lists them.
    for f in singles {
        b.faces[f.idx()].loops.clear();
    }
    Ok(out)
}

/// The result of a split: the parent's faces, the child's, the child's healing faces, and every
/// face whose boundary changed.
#[derive(Debug, Clone)]
pub struct Split {
    /// The parent's faces after the split.
    pub parent: Vec<FaceId>,
    /// The child's faces (healing faces included).
    pub child: Vec<FaceId>,
    /// The child's healing faces.
    pub heal: Vec<FaceId>,
    /// The host face the child is built on (it stays in the parent).
    pub host: FaceId,
    /// Faces with new boundaries (re-made hosts and healing faces).
    pub touched: Vec<FaceId>,
}

/// Applies a cut to `faces` and heals both sides. On refusal `b` is left as it was.
pub fn apply_cut(b: &mut Brep, faces: &[FaceId], cut: &Cut, tol: Tol) -> Result<Split, Refusal> {
    let saved = b.clone();
    let r = apply_inner(b, faces, cut, tol);
    if r.is_err() {
        *b = saved;
    }
    r
}

fn apply_inner(b: &mut Brep, faces: &[FaceId], cut: &Cut, tol: Tol) -> Result<Split, Refusal> {
    let mut heal = vec![];
    let mut hosts_after: Vec<HealedFace> = vec![];
    let mut dropped: HashSet<FaceId> = HashSet::new();
    let coarse = MeshOptions::with_tolerance(0.5);
    for g in &cut.groups {
        let faces = heal_child(b, g)?;
        for &h in &faces {
            match face_domain(b, h, &coarse) {
                Ok(d) if !d.loops.is_empty() => {}
                Err(e) if !e.to_string().contains("wraps around") => {
                    return Err(Refusal::Invalid(e.to_string()))
                }
                _ => return Err(Refusal::NoRegion(b.face(g.faces[0]).step_id)),
            }
        }
        heal.extend(faces);
        let healed = heal_hosts(b, g, tol)?;
        for &f in &g.faces {
            if !healed.iter().any(|(h, _)| *h == f) {
                dropped.insert(f);
            }
        }
        hosts_after.extend(healed);
    }
    for (f, loops) in &hosts_after {
        let vertex_loops: Vec<LoopId> = b
            .face(*f)
            .loops
            .iter()
            .copied()
            .filter(|l| b.loops[l.idx()].vertex.is_some())
            .collect();
        let mut ls: Vec<LoopId> = loops.iter().map(|seq| push_loop(b, *f, seq)).collect();
        if let Some(l) = ls.first() {
            b.loops[l.idx()].outer = true;
        }
        ls.extend(vertex_loops);
        b.faces[f.idx()].loops = ls;
    }
    for f in &dropped {
        b.faces[f.idx()].loops.clear();
    }
    let child_set: HashSet<FaceId> = cut.child.iter().copied().collect();
    let parent: Vec<FaceId> = faces
        .iter()
        .copied()
        .filter(|f| !child_set.contains(f) && !dropped.contains(f))
        .collect();
    let mut child = cut.child.clone();
    child.extend(heal.iter().copied());
    for (side, fs) in [("parent", &parent), ("child", &child)] {
        if let Some(p) = crate::check::check_topology(b, fs).first() {
            return Err(Refusal::Invalid(format!("{side}: {p}")));
        }
    }
    let host = hosts_after
        .first()
        .map(|h| h.0)
        .ok_or_else(|| Refusal::Heal("no host face is left".into()))?;
    let mut touched: Vec<FaceId> = hosts_after.iter().map(|h| h.0).collect();
    touched.extend(heal.iter().copied());
    Ok(Split {
        parent,
        child,
        heal,
        host,
        touched,
    })
}
