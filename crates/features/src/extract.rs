//! AM feature extraction (feature-based AM paper, "Extraction of AM features", Figs. 6–8):
//! find concave loops, split the shell along them, heal both open shells with the host face's
//! untrimmed surface trimmed to the loop, repeat; classify each closed shell by its reference
//! surface and order them by what grows on what.

use crate::aag::{self, Convexity};
use brep::math::V3;
use brep::mesh::{loop_roles, mesh_faces, LoopRole, MeshError};
use brep::solid::analysis_options;
use brep::surface::Surface;
use brep::topology::*;
use petgraph::graph::DiGraph;
use std::collections::{HashMap, HashSet};

/// Knobs of the recognition.
#[derive(Debug, Clone, Copy)]
pub struct ExtractOptions {
    /// Two faces meeting within this angle are tangent (a smooth edge), degrees.
    pub smooth_angle_deg: f64,
}

impl Default for ExtractOptions {
    fn default() -> Self {
        ExtractOptions {
            smooth_angle_deg: 3.0,
        }
    }
}

/// Why extraction failed.
#[derive(Debug, thiserror::Error)]
pub enum ExtractError {
    /// A face could not be meshed for measuring.
    #[error(transparent)]
    Mesh(#[from] MeshError),
    /// Nothing in the file encloses a volume.
    #[error("{0}")]
    Empty(String),
}

/// Two kinds of AM feature (paper: `two5D_AM_feature`, `freeform_AM_feature`).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum FeatureKind {
    /// Built by planar layers parallel to a reference plane.
    Two5d,
    /// Built by layers offset from a curved reference surface.
    Freeform,
}

impl FeatureKind {
    /// The name used in JSON.
    pub fn as_str(self) -> &'static str {
        match self {
            FeatureKind::Two5d => "two5d",
            FeatureKind::Freeform => "freeform",
        }
    }
}

/// What a feature is built on.
#[derive(Debug, Clone, PartialEq)]
pub struct Reference {
    /// `build_plate`, or the kind of the host face's surface (`plane`, `cylinder`, ...).
    pub surface: String,
    /// The face in the extraction's B-rep the feature grows from (the build-plate face for the
    /// base feature, when there is a downward planar face).
    pub face: Option<FaceId>,
    /// STEP `#id` of that face.
    pub step_face: Option<u64>,
    /// For planes and the build plate: the unit normal pointing into the feature (the build
    /// direction of its layers).
    pub normal: Option<[f64; 3]>,
}

/// One AM feature: a closed shell.
#[derive(Debug, Clone)]
pub struct Feature {
    /// Index in [`FeatureTree::features`].
    pub id: usize,
    /// Planar or curved reference.
    pub kind: FeatureKind,
    /// `stretch`, `loft`, `brep_two5d` or `brep_freeform`.
    pub subtype: String,
    /// What it is built on.
    pub reference: Reference,
    /// Features it grows from.
    pub parents: Vec<usize>,
    /// Its faces in the extraction's B-rep (healing faces included).
    pub faces: Vec<FaceId>,
    /// Void shells kept with it.
    pub voids: Vec<Vec<FaceId>>,
    /// The faces that close it where it was split off (on its reference surface).
    pub heal_faces: Vec<FaceId>,
    /// Its shell in the extraction's B-rep.
    pub shell: ShellId,
    /// Enclosed volume, mm³.
    pub volume: f64,
    /// How many loops it was split off along (0 for the base feature).
    pub root_loops: usize,
    /// Longest chain of parents above it.
    pub depth: usize,
    /// Every edge of its shell used twice in opposite directions.
    pub closed: bool,
}

impl Feature {
    /// STEP `#id`s of the part's faces in this feature (healing faces have none).
    pub fn step_faces(&self, brep: &Brep) -> Vec<u64> {
        let mut ids: Vec<u64> = self
            .faces
            .iter()
            .map(|f| brep.face(*f).step_id)
            .filter(|&i| i != 0)
            .collect();
        ids.sort_unstable();
        ids
    }
}

/// The features of one solid.
#[derive(Debug, Clone)]
pub struct FeatureTree {
    /// The part's B-rep with the healing faces added and host faces re-trimmed.
    pub brep: Brep,
    /// Which solid of the file.
    pub solid: SolidId,
    /// Features; `features[0]` is the base.
    pub features: Vec<Feature>,
    /// Parents before children.
    pub build_order: Vec<usize>,
    /// Longest parent chain.
    pub depth: usize,
    /// Part volume, mm³.
    pub part_volume: f64,
    /// Part area, mm².
    pub part_area: f64,
    /// Faces of the part.
    pub part_faces: usize,
    /// Genus of the part's outer shell.
    pub genus: Option<i64>,
    /// The solid as read (outer and void shells), meshed for analysis: closed, faces outward,
    /// chord tolerance 0.2 % of its size.
    pub mesh: brep::mesh::Mesh,
    /// What the user should know.
    pub warnings: Vec<String>,
}

struct Draft {
    faces: Vec<FaceId>,
    /// The face it was cut from and how many root loops the cut followed.
    host: Option<(FaceId, usize)>,
    heal: Vec<FaceId>,
}

/// Extracts the AM features of one solid.
pub fn extract(
    part: &Brep,
    solid: SolidId,
    opts: &ExtractOptions,
) -> Result<FeatureTree, ExtractError> {
    let mut b = part.clone();
    let mut warnings = vec![];
    let shells = b.solids[solid.idx()].shells.clone();
    let outer: Vec<FaceId> = b.shells[shells[0].idx()].faces.clone();
    let voids: Vec<Vec<FaceId>> = shells[1..]
        .iter()
        .map(|s| b.shells[s.idx()].faces.clone())
        .collect();
    if !voids.is_empty() {
        warnings.push(format!(
            "{} void shell(s) kept with the base feature",
            voids.len()
        ));
    }

    // The part as read, meshed once: figures, per-face shares of the volume, adjacency and
    // convexity.
    let mut all_faces = outer.clone();
    for v in &voids {
        all_faces.extend(v.iter().copied());
    }
    let rough = brep::solid::rough_bbox(&b, solid);
    let diag = rough.diagonal().max(1e-3);
    let mopts = analysis_options(diag);
    let mesh = mesh_faces(&b, &all_faces, &mopts)?;
    let origin = if rough.is_empty() {
        brep::math::P3::origin()
    } else {
        nalgebra::center(&rough.min, &rough.max)
    };
    let mut shares: HashMap<FaceId, (f64, f64)> = brep::mass::face_shares(&b, &mesh, &origin)
        .into_iter()
        .map(|(f, v, a)| (f, (v, a)))
        .collect();
    let vol_of = |shares: &HashMap<FaceId, (f64, f64)>, fs: &[FaceId]| {
        fs.iter()
            .map(|f| shares.get(f).map_or(0.0, |s| s.0))
            .sum::<f64>()
    };
    let part_volume =
        vol_of(&shares, &outer).abs() - voids.iter().map(|v| vol_of(&shares, v).abs()).sum::<f64>();
    let part_area: f64 = all_faces
        .iter()
        .map(|f| shares.get(f).map_or(0.0, |s| s.1))
        .sum();
    let genus = brep::validate::check_shell(&b, shells[0]).genus;
    let graph = aag::build(&b, &outer, &mesh, opts.smooth_angle_deg);

    // Candidate roots: closed chains of concave edges (a boss's root circle, a blade's root
    // curve), wherever they sit in the faces' loops; and holes in a face bounded by tangent edges
    // where the face across climbs off the host (a root blended by a concave fillet, which then
    // goes with what grows there).
    let mut chains: Vec<Vec<EdgeId>> = concave_chains(&b, &outer, &graph);
    for &f in &outer {
        let tangent_loop = b.face(f).loops.iter().any(|l| {
            let cs = &b.loops[l.idx()].coedges;
            !cs.is_empty()
                && cs.iter().all(|c| {
                    graph.convexity.get(&b.coedges[c.idx()].edge) == Some(&Convexity::Smooth)
                })
        });
        if !tangent_loop {
            continue;
        }
        for (l, role) in loop_roles(&b, f, &mopts)? {
            if role != LoopRole::Inner {
                continue;
            }
            let edges: Vec<EdgeId> = b.loops[l.idx()]
                .coedges
                .iter()
                .map(|c| b.coedges[c.idx()].edge)
                .collect();
            if edges
                .iter()
                .all(|e| graph.convexity.get(e) == Some(&Convexity::Smooth))
            {
                if edges
                    .iter()
                    .all(|e| graph.rise_from(*e, f).is_some_and(|r| r > 0.0))
                {
                    warnings.push(format!(
                        "face #{}: a root blended by a concave fillet; the fillet is built with the feature growing there",
                        b.face(f).step_id
                    ));
                    chains.push(edges);
                } else {
                    warnings.push(format!(
                        "face #{}: a hole bounded by tangent edges is kept in its parent feature",
                        b.face(f).step_id
                    ));
                }
            }
        }
    }

    // Split, heal, repeat. The parent side of a cut holds the draft's anchor: the build-plate
    // face for the base, the healing faces for a feature split off before.
    let plate = base_reference(&b, &outer, &mut vec![]).face;
    let mut drafts = vec![Draft {
        faces: outer.clone(),
        host: None,
        heal: vec![],
    }];
    let mut done = vec![false; chains.len()];
    let mut unsplit: Vec<usize> = vec![];
    let mut i = 0;
    while i < drafts.len() {
        loop {
            let here: HashSet<FaceId> = drafts[i].faces.iter().copied().collect();
            let live: Vec<usize> = (0..chains.len())
                .filter(|&k| {
                    !done[k]
                        && chains[k]
                            .iter()
                            .all(|e| edge_faces(&b, *e).iter().any(|f| here.contains(f)))
                })
                .collect();
            if live.is_empty() {
                break;
            }
            let anchor: Vec<FaceId> = if i == 0 {
                plate.into_iter().collect()
            } else {
                drafts[i].heal.clone()
            };
            let mut split = false;
            // One chain at a time.
            for &k in &live {
                if let Some(plan) = plan_cut(&b, &drafts[i].faces, &anchor, &[&chains[k]]) {
                    done[k] = true;
                    if try_split(&mut b, &mut drafts, i, plan) {
                        split = true;
                        break;
                    }
                    unsplit.push(k);
                }
            }
            if split {
                continue;
            }
            // Genus > 0: all live chains together (an arch standing on two feet).
            if live.len() > 1 {
                let all: Vec<&Vec<EdgeId>> = live.iter().map(|&k| &chains[k]).collect();
                if let Some(plan) = plan_cut(&b, &drafts[i].faces, &anchor, &all) {
                    split = try_split(&mut b, &mut drafts, i, plan);
                    if split {
                        for &k in &live {
                            done[k] = true;
                        }
                    }
                }
            }
            if !split {
                for &k in &live {
                    if !done[k] {
                        done[k] = true;
                        unsplit.push(k);
                    }
                }
                break;
            }
        }
        i += 1;
    }

    if !unsplit.is_empty() {
        let ids: Vec<String> = unsplit
            .iter()
            .take(6)
            .map(|&k| format!("#{}", b.edge(chains[k][0]).step_id))
            .collect();
        warnings.push(format!(
            "{} closed concave loop(s) do not bound a feature that can be split off (pocket floors, slots, or roots spread over several faces); kept in their features (through edges {}{})",
            unsplit.len(),
            ids.join(", "),
            if unsplit.len() > 6 { ", ..." } else { "" }
        ));
    }

    // Faces the splits changed (re-trimmed hosts, healing faces) get fresh shares.
    let changed: Vec<FaceId> = drafts
        .iter()
        .flat_map(|d| d.heal.iter().copied().chain(d.host.iter().map(|h| h.0)))
        .collect::<HashSet<_>>()
        .into_iter()
        .collect();
    if !changed.is_empty() {
        let m = mesh_faces(&b, &changed, &mopts)?;
        for (f, v, a) in brep::mass::face_shares(&b, &m, &origin) {
            shares.insert(f, (v, a));
        }
    }

    // Shells, parents, measures.
    let owner: HashMap<FaceId, usize> = drafts
        .iter()
        .enumerate()
        .flat_map(|(k, d)| d.faces.iter().map(move |f| (*f, k)))
        .collect();
    let mut features = vec![];
    for (k, d) in drafts.iter().enumerate() {
        let shell = ShellId(b.shells.len() as u32);
        b.shells.push(Shell {
            step_id: 0,
            faces: d.faces.clone(),
            void: false,
        });
        for f in &d.faces {
            b.faces[f.idx()].shell = shell;
        }
        let fvoids = if k == 0 { voids.clone() } else { vec![] };
        let volume = vol_of(&shares, &d.faces).abs()
            - fvoids.iter().map(|v| vol_of(&shares, v).abs()).sum::<f64>();
        let closed = brep::validate::check_shell(&b, shell).closed;
        if !closed {
            warnings.push(format!(
                "feature {k}: its shell is not closed after splitting"
            ));
        }
        let (parents, reference) = match &d.host {
            Some((t, _)) => {
                let p = owner.get(t).copied().into_iter().collect();
                (p, host_reference(&b, *t))
            }
            None => (vec![], base_reference(&b, &d.faces, &mut warnings)),
        };
        let kind = if reference.surface == "plane" || reference.surface == "build_plate" {
            FeatureKind::Two5d
        } else {
            FeatureKind::Freeform
        };
        let subtype = match kind {
            FeatureKind::Two5d => two5d_subtype(&b, &d.faces, &reference),
            FeatureKind::Freeform => "brep_freeform".to_string(),
        };
        features.push(Feature {
            id: k,
            kind,
            subtype,
            reference,
            parents,
            faces: d.faces.clone(),
            voids: fvoids,
            heal_faces: d.heal.clone(),
            shell,
            volume,
            root_loops: d.host.map_or(0, |h| h.1),
            depth: 0,
            closed,
        });
    }

    // Order and depth: parents first, and among features ready together the lowest id first
    // (Kahn's algorithm), so the order reads like the tree.
    let mut g = DiGraph::<usize, ()>::new();
    let nodes: Vec<_> = (0..features.len()).map(|k| g.add_node(k)).collect();
    for f in &features {
        for &p in &f.parents {
            g.add_edge(nodes[p], nodes[f.id], ());
        }
    }
    let mut indegree: Vec<usize> = nodes
        .iter()
        .map(|&n| {
            g.neighbors_directed(n, petgraph::Direction::Incoming)
                .count()
        })
        .collect();
    let mut ready: std::collections::BinaryHeap<std::cmp::Reverse<usize>> = (0..features.len())
        .filter(|&k| indegree[k] == 0)
        .map(std::cmp::Reverse)
        .collect();
    let mut build_order = vec![];
    while let Some(std::cmp::Reverse(k)) = ready.pop() {
        build_order.push(k);
        for c in g.neighbors_directed(nodes[k], petgraph::Direction::Outgoing) {
            let c = g[c];
            indegree[c] -= 1;
            if indegree[c] == 0 {
                ready.push(std::cmp::Reverse(c));
            }
        }
    }
    if build_order.len() != features.len() {
        warnings.push("feature dependencies form a cycle; listed in extraction order".into());
        build_order = (0..features.len()).collect();
    }
    for &k in &build_order {
        let d = features[k]
            .parents
            .iter()
            .map(|&p| features[p].depth + 1)
            .max()
            .unwrap_or(0);
        features[k].depth = d;
    }
    let depth = features.iter().map(|f| f.depth).max().unwrap_or(0);
    let sum: f64 = features.iter().map(|f| f.volume).sum();
    if (sum - part_volume).abs() > 5e-3 * part_volume.abs().max(1e-9) {
        warnings.push(format!(
            "feature volumes add up to {sum:.3} mm^3, the part has {part_volume:.3} mm^3"
        ));
    }
    Ok(FeatureTree {
        brep: b,
        solid,
        features,
        build_order,
        depth,
        part_volume,
        part_area,
        part_faces: all_faces.len(),
        genus,
        mesh,
        warnings,
    })
}

/// Closed chains of concave edges: connected sets of concave edges in which every vertex joins
/// exactly two edge ends. Where concave edges branch, each face loop made only of them counts.
fn concave_chains(b: &Brep, faces: &[FaceId], g: &aag::Aag) -> Vec<Vec<EdgeId>> {
    let concave: Vec<EdgeId> = b
        .edges_of(faces)
        .into_iter()
        .filter(|e| g.convexity.get(e) == Some(&Convexity::Concave))
        .collect();
    let mut at: HashMap<VertexId, Vec<usize>> = HashMap::new();
    for (k, e) in concave.iter().enumerate() {
        let ed = b.edge(*e);
        at.entry(ed.start).or_default().push(k);
        at.entry(ed.end).or_default().push(k);
    }
    let mut seen = vec![false; concave.len()];
    let mut out = vec![];
    let mut branching = false;
    for s in 0..concave.len() {
        if seen[s] {
            continue;
        }
        let mut comp = vec![];
        let mut stack = vec![s];
        seen[s] = true;
        while let Some(k) = stack.pop() {
            comp.push(concave[k]);
            let ed = b.edge(concave[k]);
            for v in [ed.start, ed.end] {
                for &n in &at[&v] {
                    if !seen[n] {
                        seen[n] = true;
                        stack.push(n);
                    }
                }
            }
        }
        let simple = comp.iter().all(|e| {
            let ed = b.edge(*e);
            at[&ed.start].len() == 2 && at[&ed.end].len() == 2
        });
        if simple {
            out.push(comp);
        } else {
            branching = true;
        }
    }
    if branching {
        for &f in faces {
            for l in &b.face(f).loops {
                let edges: Vec<EdgeId> = b.loops[l.idx()]
                    .coedges
                    .iter()
                    .map(|c| b.coedges[c.idx()].edge)
                    .collect();
                if !edges.is_empty()
                    && edges
                        .iter()
                        .all(|e| g.convexity.get(e) == Some(&Convexity::Concave))
                    && !out.iter().any(|c: &Vec<EdgeId>| {
                        c.iter().all(|x| edges.contains(x)) && c.len() == edges.len()
                    })
                {
                    out.push(edges);
                }
            }
        }
    }
    out
}

/// The faces using an edge through their current loops.
fn edge_faces(b: &Brep, e: EdgeId) -> Vec<FaceId> {
    let mut out = vec![];
    for &c in &b.edge(e).coedges {
        let f = b.coedge_face(c);
        if b.face(f).loops.contains(&b.coedges[c.idx()].lp) && !out.contains(&f) {
            out.push(f);
        }
    }
    out
}

/// A planned cut: which faces leave, and for each chain, the host face on the parent side.
struct Cut {
    child: Vec<FaceId>,
    hosts: Vec<(FaceId, Vec<EdgeId>)>,
}

/// Plans cutting `faces` along `chains`: the child is the component(s) across the chains from
/// the anchor (the largest component when there is no anchor), each chain's host is the single
/// parent-side face along it. `None` when the chains do not separate anything or a chain runs
/// along several parent-side faces.
fn plan_cut(b: &Brep, faces: &[FaceId], anchor: &[FaceId], chains: &[&Vec<EdgeId>]) -> Option<Cut> {
    let cut: HashSet<EdgeId> = chains.iter().flat_map(|c| c.iter().copied()).collect();
    let comps = components(b, faces, &cut);
    let parent = match anchor.iter().find_map(|f| comps.get(f)) {
        Some(&c) => c,
        None => {
            let mut count: HashMap<usize, usize> = HashMap::new();
            for c in comps.values() {
                *count.entry(*c).or_default() += 1;
            }
            count.into_iter().max_by_key(|x| (x.1, usize::MAX - x.0))?.0
        }
    };
    let mut child: HashSet<usize> = HashSet::new();
    let mut hosts = vec![];
    for chain in chains {
        let mut host: Option<FaceId> = None;
        for e in chain.iter() {
            let fs: Vec<FaceId> = edge_faces(b, *e)
                .into_iter()
                .filter(|f| comps.contains_key(f))
                .collect();
            if fs.len() != 2 {
                return None;
            }
            let (p, c): (Vec<FaceId>, Vec<FaceId>) =
                fs.into_iter().partition(|f| comps[f] == parent);
            if p.len() != 1 || c.len() != 1 {
                return None;
            }
            if host.is_some_and(|h| h != p[0]) {
                return None;
            }
            host = Some(p[0]);
            child.insert(comps[&c[0]]);
        }
        hosts.push((host?, chain.to_vec()));
    }
    if child.is_empty() || child.contains(&parent) {
        return None;
    }
    let child_faces: Vec<FaceId> = faces
        .iter()
        .copied()
        .filter(|f| child.contains(&comps[f]))
        .collect();
    Some(Cut {
        child: child_faces,
        hosts,
    })
}

/// Applies a cut and heals both sides (paper, Fig. 8): each host face drops the chain's edges
/// (and any seam left dangling), so its surface runs across the root; the child gets, per chain,
/// a face on the host's surface facing the other way, bounded by the chain. Kept only if both
/// shells come out closed.
fn try_split(b: &mut Brep, drafts: &mut Vec<Draft>, i: usize, cut: Cut) -> bool {
    let saved = b.clone();
    let mut heal = vec![];
    for (t, chain) in &cut.hosts {
        let host = b.face(*t).clone();
        // The host's own uses of the chain's edges, ordered head to tail.
        let mut uses: Vec<(EdgeId, bool)> = vec![];
        for l in &host.loops {
            for c in &b.loops[l.idx()].coedges {
                let ce = &b.coedges[c.idx()];
                if chain.contains(&ce.edge) && !uses.iter().any(|u| u.0 == ce.edge) {
                    uses.push((ce.edge, ce.forward));
                }
            }
        }
        let Some(ordered) = order_cycle(b, &uses) else {
            *b = saved;
            return false;
        };
        let h = FaceId(b.faces.len() as u32);
        let nl = LoopId(b.loops.len() as u32);
        let mut coedges = vec![];
        for (e, fwd) in ordered {
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
            face: h,
            outer: true,
            coedges,
            vertex: None,
        });
        b.faces.push(Face {
            step_id: 0,
            surface: host.surface,
            same_sense: !host.same_sense,
            loops: vec![nl],
            shell: host.shell,
        });
        heal.push(h);
        // The host drops the chain, and seams that now lead nowhere (used twice in a row).
        let mut loops = vec![];
        for l in &host.loops {
            let mut cs: Vec<CoedgeId> = b.loops[l.idx()]
                .coedges
                .iter()
                .copied()
                .filter(|c| !chain.contains(&b.coedges[c.idx()].edge))
                .collect();
            let mut changed = true;
            while changed && cs.len() >= 2 {
                changed = false;
                let n = cs.len();
                for k in 0..n {
                    let (x, y) = (&b.coedges[cs[k].idx()], &b.coedges[cs[(k + 1) % n].idx()]);
                    if x.edge == y.edge && x.forward != y.forward {
                        let (a, c) = (k, (k + 1) % n);
                        let (hi, lo) = (a.max(c), a.min(c));
                        cs.remove(hi);
                        cs.remove(lo);
                        changed = true;
                        break;
                    }
                }
            }
            if !cs.is_empty()
                || !b.loops[l.idx()]
                    .coedges
                    .iter()
                    .any(|c| chain.contains(&b.coedges[c.idx()].edge))
            {
                b.loops[l.idx()].coedges = cs;
                loops.push(*l);
            }
        }
        b.faces[t.idx()].loops = loops;
    }
    let set: HashSet<FaceId> = cut.child.iter().copied().collect();
    let parent: Vec<FaceId> = drafts[i]
        .faces
        .iter()
        .copied()
        .filter(|f| !set.contains(f))
        .collect();
    let mut child = cut.child.clone();
    child.extend(heal.iter().copied());
    // Both sides must close.
    let closed = |b: &mut Brep, faces: &[FaceId]| {
        let s = ShellId(b.shells.len() as u32);
        b.shells.push(Shell {
            step_id: 0,
            faces: faces.to_vec(),
            void: false,
        });
        let ok = brep::validate::check_shell(b, s).closed;
        b.shells.pop();
        ok
    };
    // And every changed face must still bound a region of its surface.
    let mut touched: Vec<FaceId> = cut.hosts.iter().map(|(t, _)| *t).collect();
    touched.extend(heal.iter().copied());
    let coarse = brep::mesh::MeshOptions::with_tolerance(0.5);
    let valid = touched
        .iter()
        .all(|f| brep::mesh::face_domain(b, *f, &coarse).is_ok_and(|d| !d.loops.is_empty()));
    if !valid || !closed(b, &parent) || !closed(b, &child) {
        *b = saved;
        return false;
    }
    let host = cut.hosts[0].0;
    let loops_n = cut.hosts.len();
    drafts[i].faces = parent;
    drafts.push(Draft {
        faces: child,
        host: Some((host, loops_n)),
        heal,
    });
    true
}

/// Orders edge uses `(edge, forward)` into one closed head-to-tail cycle.
fn order_cycle(b: &Brep, uses: &[(EdgeId, bool)]) -> Option<Vec<(EdgeId, bool)>> {
    let ends = |(e, f): (EdgeId, bool)| {
        let ed = b.edge(e);
        if f {
            (ed.start, ed.end)
        } else {
            (ed.end, ed.start)
        }
    };
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

/// Connected components of `faces` through shared edges, not crossing `cut`.
fn components(b: &Brep, faces: &[FaceId], cut: &HashSet<EdgeId>) -> HashMap<FaceId, usize> {
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
    let mut parent: Vec<usize> = (0..faces.len()).collect();
    fn find(p: &mut [usize], x: usize) -> usize {
        let mut r = x;
        while p[r] != r {
            r = p[r];
        }
        let mut y = x;
        while p[y] != r {
            let n = p[y];
            p[y] = r;
            y = n;
        }
        r
    }
    for fs in by_edge.values() {
        for w in fs.windows(2) {
            let (a, c) = (find(&mut parent, idx[&w[0]]), find(&mut parent, idx[&w[1]]));
            if a != c {
                parent[a] = c;
            }
        }
    }
    faces
        .iter()
        .map(|f| (*f, find(&mut parent, idx[f])))
        .collect()
}

fn surface_kind(s: &Surface) -> String {
    match s {
        Surface::Offset { basis, .. } => surface_kind(basis),
        s => s.kind().to_string(),
    }
}

/// A plane's unit normal pointing out of `f` (into whatever grows from it).
fn plane_normal(b: &Brep, f: FaceId) -> Option<V3> {
    match b.face_surface(f) {
        Surface::Plane { frame } => Some(if b.face(f).same_sense {
            frame.z
        } else {
            -frame.z
        }),
        _ => None,
    }
}

fn host_reference(b: &Brep, t: FaceId) -> Reference {
    let s = b.face_surface(t);
    let normal = plane_normal(b, t).map(|n| [n.x, n.y, n.z]);
    Reference {
        surface: surface_kind(s),
        face: Some(t),
        step_face: Some(b.face(t).step_id),
        normal,
    }
}

/// The base feature rests on the build plate: its lowest planar face pointing down.
fn base_reference(b: &Brep, faces: &[FaceId], warnings: &mut Vec<String>) -> Reference {
    let mut best: Option<(f64, FaceId)> = None;
    for &f in faces {
        let Some(n) = plane_normal(b, f) else {
            continue;
        };
        if n.z > -1.0 + 1e-6 {
            continue;
        }
        let z = b
            .vertices_of(&[f])
            .iter()
            .map(|v| b.vertices[v.idx()].point.z)
            .fold(f64::INFINITY, f64::min);
        let z = if z.is_finite() { z } else { 0.0 };
        if best.is_none_or(|(bz, _)| z < bz) {
            best = Some((z, f));
        }
    }
    if best.is_none() {
        warnings.push("no planar face points down: the base feature rests on the build plate at its lowest point".into());
    }
    Reference {
        surface: "build_plate".into(),
        face: best.map(|x| x.1),
        step_face: best.map(|x| b.face(x.1).step_id),
        normal: Some([0.0, 0.0, 1.0]),
    }
}

/// `stretch`: a prism of one planar profile along a direction; `loft`: two planar profiles on
/// parallel planes joined otherwise; `brep_two5d`: anything else built on a plane.
fn two5d_subtype(b: &Brep, faces: &[FaceId], r: &Reference) -> String {
    let Some(n) = r.normal.map(|n| V3::new(n[0], n[1], n[2])) else {
        return "brep_two5d".into();
    };
    let par = |a: &V3, c: &V3| a.cross(c).norm() < 1e-6;
    let mut bottom = vec![];
    let mut top = vec![];
    let mut sides = vec![];
    for &f in faces {
        match plane_normal(b, f) {
            Some(m) if par(&m, &n) && m.dot(&n) < 0.0 => bottom.push(f),
            Some(m) if par(&m, &n) && m.dot(&n) > 0.0 => top.push(f),
            _ => sides.push(f),
        }
    }
    if bottom.is_empty() || top.is_empty() {
        return "brep_two5d".into();
    }
    // Each profile lies in one plane.
    let level = |f: FaceId| match b.face_surface(f) {
        Surface::Plane { frame } => frame.origin.coords.dot(&n),
        _ => 0.0,
    };
    let coplanar = |fs: &[FaceId]| {
        let l0 = level(fs[0]);
        fs.iter()
            .all(|&f| (level(f) - l0).abs() <= 1e-6 * (1.0 + l0.abs()))
    };
    if !coplanar(&bottom) || !coplanar(&top) {
        return "brep_two5d".into();
    }
    // Every side face runs from the bottom profile to the top one.
    let touches = |f: FaceId, others: &[FaceId]| {
        let mine: HashSet<EdgeId> = b.edges_of(&[f]).into_iter().collect();
        others
            .iter()
            .any(|&o| b.edges_of(&[o]).iter().any(|e| mine.contains(e)))
    };
    if !sides
        .iter()
        .all(|&f| touches(f, &bottom) && touches(f, &top))
    {
        return "brep_two5d".into();
    }
    // Directions every side face could be swept along.
    let mut dirs: Vec<V3> = vec![n];
    let side_planes: Vec<V3> = sides.iter().filter_map(|&f| plane_normal(b, f)).collect();
    for s in &sides {
        match b.face_surface(*s) {
            Surface::Cylinder { frame, .. } => dirs.push(frame.z),
            Surface::Extrusion { dir, .. } => dirs.push(*dir),
            _ => {}
        }
    }
    for i in 0..side_planes.len() {
        for j in i + 1..side_planes.len() {
            if let Some(d) = side_planes[i].cross(&side_planes[j]).try_normalize(1e-6) {
                dirs.push(d);
                break;
            }
        }
    }
    let contains = |f: FaceId, d: &V3| match b.face_surface(f) {
        Surface::Plane { frame } => frame.z.dot(d).abs() < 1e-6,
        Surface::Cylinder { frame, .. } => par(&frame.z, d),
        Surface::Extrusion { dir, .. } => par(dir, d),
        _ => false,
    };
    if dirs
        .iter()
        .any(|d| d.dot(&n).abs() > 1e-6 && sides.iter().all(|&f| contains(f, d)))
    {
        "stretch".into()
    } else {
        "loft".into()
    }
}
