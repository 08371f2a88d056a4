//! AM feature extraction (feature-based AM paper, "Extraction of AM features", Figs. 6–8):
//! find concave loops, split the shell along them, heal both open shells with the host face's
//! untrimmed surface trimmed to the loop, repeat; classify each closed shell by its reference
//! surface and order them by what grows on what.

use crate::aag::{self, Convexity};
use crate::measure::{measure, vol_of, MeasureError, Measured};
use crate::split;
use brep::math::V3;
use brep::mesh::{loop_roles, mesh_faces, LoopRole, MeshError};
use brep::solid::analysis_options;
use brep::surface::Surface;
use brep::topology::*;
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
    /// A solid could not be measured (no shell, or a face that does not mesh).
    #[error(transparent)]
    Measure(#[from] MeasureError),
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
    /// On the build plate without a face (a part planned whole): a point of the plate, the
    /// feature's lowest along `normal` ([`lowest_point`]), found once here rather than by
    /// every stage that needs the plate.
    pub origin: Option<[f64; 3]>,
}

/// Chord tolerance (mm) of the mesh that finds how low a feature reaches ([`lowest_point`]).
pub const EXTREME_TOL: f64 = 0.01;

/// The lowest point of `faces` along `n`: of their mesh at [`EXTREME_TOL`] (a torus or a
/// cylinder lying on its side is lowest between its vertices, which may all lie at its middle
/// height), or of their vertices where they do not mesh. `None` without a point.
pub fn lowest_point(b: &Brep, faces: &[FaceId], n: [f64; 3]) -> Option<[f64; 3]> {
    let mut pts = brep::mesh::mesh_faces(
        b,
        faces,
        &brep::mesh::MeshOptions::with_tolerance(EXTREME_TOL),
    )
    .map(|m| m.positions)
    .unwrap_or_default();
    if pts.is_empty() {
        pts = b
            .vertices_of(faces)
            .iter()
            .map(|v| b.vertices[v.idx()].point)
            .collect();
    }
    let n = V3::new(n[0], n[1], n[2]);
    pts.into_iter()
        .min_by(|a, c| a.coords.dot(&n).total_cmp(&c.coords.dot(&n)))
        .map(|p| [p.x, p.y, p.z])
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
    /// It passed [`check_solid`](crate::check::check_solid): a closed, outward, watertight
    /// shell of valid faces enclosing a positive volume.
    pub closed: bool,
    /// What [`check_solid`](crate::check::check_solid) found wrong (empty when `closed`).
    pub problems: Vec<crate::check::SolidProblem>,
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
    /// Every closed concave loop found, and whether it was split off or kept (and why).
    pub roots: Vec<RootLoop>,
    /// What the user should know.
    pub warnings: Vec<String>,
}

struct Draft {
    faces: Vec<FaceId>,
    /// The face it was cut from and how many root loops the cut followed.
    host: Option<(FaceId, usize)>,
    heal: Vec<FaceId>,
}

/// For each void shell, the draft whose faces enclose it (winding number of the draft's mesh
/// about one of the void's vertices); the base (0) where none does or a draft does not mesh.
fn void_owners(
    b: &Brep,
    drafts: &[Draft],
    voids: &[Vec<FaceId>],
    opts: &brep::mesh::MeshOptions,
) -> Vec<usize> {
    if voids.is_empty() || drafts.len() < 2 {
        return vec![0; voids.len()];
    }
    let meshes: Vec<Option<brep::mesh::Mesh>> = drafts
        .iter()
        .map(|d| mesh_faces(b, &d.faces, opts).ok())
        .collect();
    voids
        .iter()
        .map(|v| {
            let vertex = v.iter().find_map(|f| {
                b.faces[f.idx()].loops.iter().find_map(|l| {
                    let lp = &b.loops[l.idx()];
                    lp.coedges
                        .first()
                        .map(|c| b.edges[b.coedges[c.idx()].edge.idx()].start)
                        .or(lp.vertex)
                })
            });
            let Some(p) = vertex.map(|v| b.vertices[v.idx()].point) else {
                return 0;
            };
            meshes
                .iter()
                .position(|m| m.as_ref().is_some_and(|m| m.winding_number(&p) > 0.5))
                .unwrap_or(0)
        })
        .collect()
}

/// Extracts the AM features of one solid.
pub fn extract(
    part: &Brep,
    solid: SolidId,
    opts: &ExtractOptions,
) -> Result<FeatureTree, ExtractError> {
    // The solid alone, not a copy of the whole file: healing adds faces to it.
    let mut b = part.solid_alone(solid);
    let solid = SolidId(0);
    let mut warnings = vec![];
    // The part as read, meshed once: figures, per-face shares of the volume, adjacency and
    // convexity.
    let Measured {
        outer_shell: _,
        outer,
        voids,
        all_faces,
        diag,
        mopts,
        mesh,
        origin,
        mut shares,
        part_volume,
        part_area,
        genus,
    } = measure(&b, solid)?;
    let graph = aag::build(&b, &outer, &mesh, opts.smooth_angle_deg);

    // Candidate roots: closed chains of concave edges (a boss's root circle, a blade's root
    // curve), wherever they sit in the faces' loops; and holes in a face bounded by tangent edges
    // where the face across climbs off the host (a root blended by a concave fillet, which then
    // goes with what grows there).
    let chains = candidate_roots(&b, &outer, &graph, &mopts, &mut warnings)?;

    // Split, heal, repeat. The parent side of a cut holds the draft's anchor: the build-plate
    // face for the base, the healing faces for a feature split off before.
    let plate = base_reference(&b, &outer, &mut vec![]).face;
    let tol = split::Tol::for_size(diag);
    let mut drafts = vec![Draft {
        faces: outer.clone(),
        host: None,
        heal: vec![],
    }];
    let mut ctx = SplitCtx {
        b: &mut b,
        shares: &mut shares,
        origin,
        mopts: &mopts,
        tol,
    };
    let outcome = split_drafts(&mut ctx, &mut drafts, &chains, plate);
    let roots = root_loops(part, &chains, outcome, &mut warnings);

    // Shells, parents, measures.
    let owner: HashMap<FaceId, usize> = drafts
        .iter()
        .enumerate()
        .flat_map(|(k, d)| d.faces.iter().map(move |f| (*f, k)))
        .collect();
    // The solid check meshes each feature again: coarser than the analysis mesh, since it asks
    // only whether every face meshes, the mesh closes and the volume is positive.
    let check_opts = analysis_options(diag * 4.0);
    // Each void shell goes with the feature whose shell holds it (the base where none does).
    let void_owner = void_owners(&b, &drafts, &voids, &check_opts);
    if !voids.is_empty() {
        let elsewhere = void_owner.iter().filter(|&&k| k != 0).count();
        warnings.insert(
            0,
            if elsewhere == 0 {
                format!("{} void shell(s) kept with the base feature", voids.len())
            } else {
                format!(
                    "{} void shell(s) kept with the features holding them ({elsewhere} not in the base)",
                    voids.len()
                )
            },
        );
    }
    let mut features = vec![];
    for (k, d) in drafts.iter().enumerate() {
        features.push(make_feature(
            &mut b,
            (k, d),
            (&voids, &void_owner),
            &shares,
            &owner,
            &check_opts,
            &mut warnings,
        ));
    }

    // Order and depth: parents first, and among features ready together the lowest id first
    // (Kahn's algorithm), so the order reads like the tree.
    let build_order = build_order(&mut features, &mut warnings);
    let depth = features.iter().map(|f| f.depth).max().unwrap_or(0);
    let sum: f64 = features.iter().map(|f| f.volume).sum();
    if (sum - part_volume).abs() > 5e-3 * part_volume.abs().max(crate::tolerance::VOLUME_FLOOR) {
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
        roots,
        warnings,
    })
}

/// Feature `k` made of draft `d`: its shell added to the B-rep, the voids it holds, its
/// volume, whether it is a valid solid, its parents (the owner of its host face) and reference,
/// and its kind.
fn make_feature(
    b: &mut Brep,
    (k, d): (usize, &Draft),
    (voids, void_owner): (&[Vec<FaceId>], &[usize]),
    shares: &HashMap<FaceId, (f64, f64)>,
    owner: &HashMap<FaceId, usize>,
    check_opts: &brep::mesh::MeshOptions,
    warnings: &mut Vec<String>,
) -> Feature {
    let shell = ShellId(b.shells.len() as u32);
    b.shells.push(Shell {
        step_id: 0,
        faces: d.faces.clone(),
        void: false,
    });
    for f in &d.faces {
        b.faces[f.idx()].shell = shell;
    }
    let fvoids: Vec<Vec<FaceId>> = voids
        .iter()
        .zip(void_owner)
        .filter(|(_, &o)| o == k)
        .map(|(v, _)| v.clone())
        .collect();
    let volume = vol_of(shares, &d.faces).abs()
        - fvoids.iter().map(|v| vol_of(shares, v).abs()).sum::<f64>();
    let problems = crate::check::check_solid(b, &d.faces, &fvoids, check_opts).problems;
    let closed = problems.is_empty();
    if !closed {
        warnings.push(format!(
            "feature {k} is not a valid solid: {}",
            crate::check::listed(&problems)
        ));
    }
    let (parents, reference) = match &d.host {
        Some((t, _)) => {
            let p = owner.get(t).copied().into_iter().collect();
            (p, host_reference(b, *t))
        }
        None => (vec![], base_reference(b, &d.faces, warnings)),
    };
    let kind = if reference.surface == "plane" || reference.surface == "build_plate" {
        FeatureKind::Two5d
    } else {
        FeatureKind::Freeform
    };
    let subtype = match kind {
        FeatureKind::Two5d => two5d_subtype(b, &d.faces, &reference),
        FeatureKind::Freeform => "brep_freeform".to_string(),
    };
    Feature {
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
        problems,
    }
}

/// Candidate roots: closed chains of concave edges (a boss's root circle, a blade's root
/// curve), wherever they sit in the faces' loops; and holes in a face bounded by tangent edges
/// where the face across climbs off the host (a root blended by a concave fillet, which then
/// goes with what grows there).
fn candidate_roots(
    b: &Brep,
    outer: &[FaceId],
    graph: &aag::Aag,
    mopts: &brep::mesh::MeshOptions,
    warnings: &mut Vec<String>,
) -> Result<Vec<Vec<EdgeId>>, ExtractError> {
    let mut chains: Vec<Vec<EdgeId>> = concave_chains(b, outer, graph);
    for &f in outer {
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
        for (l, role) in loop_roles(b, f, mopts)? {
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
    Ok(chains)
}

/// Split, heal, repeat: each draft, base first, is cut along the live chains lying on its faces
/// (one at a time with the chains it encloses, then all together for genus > 0) until none
/// splits; what became of each chain.
fn split_drafts(
    ctx: &mut SplitCtx,
    drafts: &mut Vec<Draft>,
    chains: &[Vec<EdgeId>],
    plate: Option<FaceId>,
) -> Vec<Option<RootOutcome>> {
    let mut outcome: Vec<Option<RootOutcome>> = vec![None; chains.len()];
    let mut i = 0;
    while i < drafts.len() {
        loop {
            let here: HashSet<FaceId> = drafts[i].faces.iter().copied().collect();
            let live: Vec<usize> = (0..chains.len())
                .filter(|&k| {
                    outcome[k].is_none()
                        && chains[k].iter().all(|e| {
                            split::edge_faces(ctx.b, *e)
                                .iter()
                                .any(|f| here.contains(f))
                        })
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
            let mut split_made = false;
            let mut refusals: Vec<(usize, split::Refusal)> = vec![];
            // One chain at a time, with the chains bounding any face it would wrongly take
            // along (the plate's top inside a tube).
            for &k in &live {
                let group = ctx.with_enclosed(&drafts[i].faces, &anchor, chains, &live, k);
                match ctx.split(drafts, i, &anchor, chains, &group) {
                    Ok(f) => {
                        for &g in &group {
                            outcome[g] = Some(RootOutcome::Split(f));
                        }
                        split_made = true;
                        break;
                    }
                    Err(r) => refusals.push((k, r)),
                }
            }
            if split_made {
                continue;
            }
            // Genus > 0: all live chains together (an arch standing on two feet, a collar).
            if live.len() > 1 {
                if let Ok(f) = ctx.split(drafts, i, &anchor, chains, &live) {
                    for &k in &live {
                        outcome[k] = Some(RootOutcome::Split(f));
                    }
                    continue;
                }
            }
            for (k, r) in refusals {
                if outcome[k].is_none() {
                    outcome[k] = Some(RootOutcome::Kept(r.to_string()));
                }
            }
            break;
        }
        i += 1;
    }
    outcome
}

/// The root loops, by the part's edge ids, with what became of each; a warning for each kept.
fn root_loops(
    part: &Brep,
    chains: &[Vec<EdgeId>],
    outcome: Vec<Option<RootOutcome>>,
    warnings: &mut Vec<String>,
) -> Vec<RootLoop> {
    let roots: Vec<RootLoop> = chains
        .iter()
        .zip(outcome)
        .map(|(c, o)| {
            let mut edges: Vec<u64> = c.iter().map(|e| part.edge(*e).step_id).collect();
            edges.sort_unstable();
            RootLoop {
                edges,
                outcome: o.unwrap_or_else(|| {
                    RootOutcome::Kept("it does not lie on one feature's faces".into())
                }),
            }
        })
        .collect();
    for r in &roots {
        if let RootOutcome::Kept(why) = &r.outcome {
            let ids: Vec<String> = r.edges.iter().take(6).map(|e| format!("#{e}")).collect();
            warnings.push(format!(
                "concave loop through edges {}{} kept in its feature: {why}",
                ids.join(", "),
                if r.edges.len() > 6 { ", ..." } else { "" }
            ));
        }
    }
    roots
}

/// Order and depth: parents first, and among features ready together the lowest id first
/// (Kahn's algorithm), so the order reads like the tree; each feature's depth set from it.
fn build_order(features: &mut [Feature], warnings: &mut Vec<String>) -> Vec<usize> {
    // Each feature's children (one entry per parent link, in link order) and parent-link count.
    let mut children: Vec<Vec<usize>> = vec![vec![]; features.len()];
    let mut indegree: Vec<usize> = vec![0; features.len()];
    for f in features.iter() {
        for &p in &f.parents {
            children[p].push(f.id);
            indegree[f.id] += 1;
        }
    }
    let mut ready: std::collections::BinaryHeap<std::cmp::Reverse<usize>> = (0..features.len())
        .filter(|&k| indegree[k] == 0)
        .map(std::cmp::Reverse)
        .collect();
    let mut build_order = vec![];
    while let Some(std::cmp::Reverse(k)) = ready.pop() {
        build_order.push(k);
        // Newest link first, as the directed graph this replaces listed a node's out-arcs.
        for &c in children[k].iter().rev() {
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
    build_order
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

/// The kind of a surface as features name references (`plane`, `cone`, ...): an offset
/// surface by its basis.
pub fn surface_kind(s: &Surface) -> String {
    match s {
        Surface::Offset { basis, .. } => surface_kind(basis),
        s => s.kind().to_string(),
    }
}

fn host_reference(b: &Brep, t: FaceId) -> Reference {
    let s = b.face_surface(t);
    let normal = b.plane_normal(t).map(|n| [n.x, n.y, n.z]);
    Reference {
        surface: surface_kind(s),
        face: Some(t),
        step_face: Some(b.face(t).step_id),
        normal,
        origin: None,
    }
}

/// The base feature rests on the build plate: its lowest planar face pointing down.
fn base_reference(b: &Brep, faces: &[FaceId], warnings: &mut Vec<String>) -> Reference {
    let mut best: Option<(f64, FaceId)> = None;
    for &f in faces {
        let Some(n) = b.plane_normal(f) else {
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
        // The feature's faces are not final yet (heal faces come later): found when needed.
        origin: None,
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
        match b.plane_normal(f) {
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
    let side_planes: Vec<V3> = sides.iter().filter_map(|&f| b.plane_normal(f)).collect();
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

/// What became of one closed concave loop.
#[derive(Debug, Clone, PartialEq)]
pub enum RootOutcome {
    /// The feature split off along it.
    Split(usize),
    /// Kept in its feature, and why.
    Kept(String),
}

/// One closed concave loop of the part and what became of it.
#[derive(Debug, Clone, PartialEq)]
pub struct RootLoop {
    /// STEP `#id`s of its edges, sorted.
    pub edges: Vec<u64>,
    /// Split off, or kept and why.
    pub outcome: RootOutcome,
}

/// What a split needs besides the drafts: the B-rep, the faces' volume shares (kept current for
/// the faces a split re-makes), and the tolerances.
struct SplitCtx<'a> {
    b: &'a mut Brep,
    shares: &'a mut HashMap<FaceId, (f64, f64)>,
    origin: brep::math::P3,
    mopts: &'a brep::mesh::MeshOptions,
    tol: split::Tol,
}

impl SplitCtx<'_> {
    /// Chain `k`, with the live chains that bound faces its cut would take along although they
    /// lie on its host surface (the plate's top inside a tube standing on it: its root is the
    /// tube's inner root).
    fn with_enclosed(
        &self,
        faces: &[FaceId],
        anchor: &[FaceId],
        chains: &[Vec<EdgeId>],
        live: &[usize],
        k: usize,
    ) -> Vec<usize> {
        let mut group = vec![k];
        if let Ok(cut) = split::plan_cut(self.b, faces, anchor, &[&chains[k]], self.tol) {
            let on: HashSet<FaceId> = split::child_faces_on_hosts(self.b, &cut, self.tol)
                .into_iter()
                .collect();
            if !on.is_empty() {
                for &j in live {
                    if j != k
                        && chains[j]
                            .iter()
                            .all(|e| split::edge_faces(self.b, *e).iter().any(|f| on.contains(f)))
                    {
                        group.push(j);
                    }
                }
            }
        }
        group
    }

    /// Splits draft `i` along the chains `group` and heals both sides. Kept only if both sides
    /// pass the topology check, every re-made face meshes, both volumes are positive and they
    /// add up to the draft's. Returns the new draft's index.
    fn split(
        &mut self,
        drafts: &mut Vec<Draft>,
        i: usize,
        anchor: &[FaceId],
        chains: &[Vec<EdgeId>],
        group: &[usize],
    ) -> Result<usize, split::Refusal> {
        let sel: Vec<&Vec<EdgeId>> = group.iter().map(|&k| &chains[k]).collect();
        let cut = split::plan_cut(self.b, &drafts[i].faces, anchor, &sel, self.tol)?;
        let vol = |shares: &HashMap<FaceId, (f64, f64)>, fs: &[FaceId]| {
            fs.iter()
                .map(|f| shares.get(f).map_or(0.0, |s| s.0))
                .sum::<f64>()
        };
        let before = vol(self.shares, &drafts[i].faces);
        let saved = self.b.clone();
        let s = split::apply_cut(self.b, &drafts[i].faces, &cut, self.tol)?;
        // The re-made faces mesh, and cleanly: no mesh edge of theirs used twice the same way
        // (their seams with untouched faces show as open edges here, which is expected).
        let fresh = match mesh_faces(self.b, &s.touched, self.mopts) {
            Ok(m) if m.open_edges().1 == 0 => brep::mass::face_shares(self.b, &m, &self.origin),
            Ok(m) => {
                *self.b = saved;
                return Err(split::Refusal::Invalid(format!(
                    "a healed face's mesh has {} non-manifold edge(s)",
                    m.open_edges().1
                )));
            }
            Err(e) => {
                *self.b = saved;
                return Err(split::Refusal::Invalid(e.to_string()));
            }
        };
        let mut shares = self.shares.clone();
        for (f, v, a) in fresh {
            shares.insert(f, (v, a));
        }
        let (pv, cv) = (vol(&shares, &s.parent), vol(&shares, &s.child));
        let conserved =
            (pv + cv - before).abs() <= 2e-3 * before.abs() + crate::tolerance::VOLUME_SLACK;
        if pv * before <= 0.0 || cv * before <= 0.0 || !conserved {
            *self.b = saved;
            return Err(split::Refusal::Invalid(format!(
                "the sides would enclose {:.3} and {:.3} mm^3 of the {:.3} mm^3 split",
                pv.abs(),
                cv * before.signum(),
                before.abs()
            )));
        }
        *self.shares = shares;
        drafts[i].faces = s.parent;
        drafts.push(Draft {
            faces: s.child,
            host: Some((s.host, group.len())),
            heal: s.heal,
        });
        Ok(drafts.len() - 1)
    }
}
