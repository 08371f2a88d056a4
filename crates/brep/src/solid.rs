//! Reporting on each solid: the figures `features inspect` prints.

use crate::mass::mass_properties;
use crate::math::Aabb;
use crate::mesh::{mesh_faces, Mesh, MeshError, MeshOptions};
use crate::topology::{Brep, SolidId};
use crate::validate::check_shell;
use std::collections::BTreeMap;

pub use crate::bbox::{faces_rough_bbox, rough_bbox};

/// Figures for one solid.
#[derive(Debug, Clone)]
pub struct SolidReport {
    /// Which solid.
    pub solid: SolidId,
    /// STEP `#id` of the solid.
    pub step_id: u64,
    /// Enclosed volume (outer shell less voids), mm³.
    pub volume: f64,
    /// Total area of all its shells, mm².
    pub area: f64,
    /// Centroid of the volume.
    pub centroid: [f64; 3],
    /// Faces, edges, vertices over all shells.
    pub faces: usize,
    /// Distinct edges.
    pub edges: usize,
    /// Distinct vertices.
    pub vertices: usize,
    /// Void shells.
    pub voids: usize,
    /// Genus of the outer shell (through-holes), when closed.
    pub genus: Option<i64>,
    /// Euler characteristic of the outer shell.
    pub euler: i64,
    /// Every shell closed (each edge used twice, in opposite directions).
    pub closed: bool,
    /// Faces by surface kind.
    pub surfaces: BTreeMap<String, usize>,
    /// Edges by curve kind.
    pub curves: BTreeMap<String, usize>,
    /// Bounding box.
    pub bbox: Aabb,
    /// The mesh is watertight: every edge shared by exactly two triangles.
    pub watertight: bool,
    /// Problems found, naming `#id`s.
    pub findings: Vec<String>,
}

/// Mesh options for mass properties of a solid of bounding-box diagonal `diag`.
pub fn analysis_options(diag: f64) -> MeshOptions {
    MeshOptions {
        chord_tol: (diag * 2e-3).max(1e-3),
        angle_tol: 10f64.to_radians(),
        edge_chord_tol: Some((diag * 1e-4).max(1e-4)),
    }
}

/// Meshes one solid (all its shells) at `opts`, or at analysis precision when `None`.
pub fn mesh_solid(brep: &Brep, s: SolidId, opts: Option<MeshOptions>) -> Result<Mesh, MeshError> {
    let opts = opts.unwrap_or_else(|| analysis_options(rough_bbox(brep, s).diagonal().max(1e-3)));
    mesh_faces(brep, &brep.solid_faces(s), &opts)
}

/// Measures and checks one solid.
pub fn report_solid(brep: &Brep, s: SolidId) -> Result<SolidReport, MeshError> {
    let solid = &brep.solids[s.idx()];
    let opts = analysis_options(rough_bbox(brep, s).diagonal().max(1e-3));
    let mut findings = vec![];
    let mut volume = 0.0;
    let mut area = 0.0;
    let mut moment = nalgebra::Vector3::zeros();
    let mut bbox = Aabb::empty();
    let mut closed = true;
    let mut watertight = true;
    let mut genus = None;
    let mut euler = 0;
    for (k, &sh) in solid.shells.iter().enumerate() {
        let rep = check_shell(brep, sh);
        closed &= rep.closed;
        if k == 0 {
            genus = rep.genus;
            euler = rep.euler;
        }
        findings.extend(rep.findings);
        let shell = &brep.shells[sh.idx()];
        let mesh = mesh_faces(brep, &shell.faces, &opts)?;
        let (open, bad) = mesh.open_edges();
        if open + bad > 0 {
            watertight = false;
            let faces = mesh.faces_at_open_edges();
            let names: Vec<String> = faces
                .iter()
                .take(8)
                .map(|f| format!("#{}", brep.face(*f).step_id))
                .collect();
            findings.push(format!(
                "shell #{} is not watertight: its mesh has {open} open and {bad} non-manifold edge(s), at face(s) {}{}",
                shell.step_id,
                names.join(", "),
                if faces.len() > 8 {
                    format!(" and {} more", faces.len() - 8)
                } else {
                    String::new()
                }
            ));
        }
        let mp = mass_properties(brep, &mesh);
        let void = k > 0;
        let signed = mp.volume;
        if (signed < 0.0) != void && signed != 0.0 {
            findings.push(format!(
                "shell #{} is oriented {} (signed volume {:.3} mm^3); taken as {}",
                shell.step_id,
                if signed < 0.0 { "inward" } else { "outward" },
                signed,
                if void { "a void" } else { "the outer shell" }
            ));
        }
        let v = if void { -signed.abs() } else { signed.abs() };
        volume += v;
        moment += mp.centroid.coords * v;
        area += mp.area;
        if let (Some(b), false) = (Some(mp.bbox), mp.bbox.is_empty()) {
            bbox.add(&b.min);
            bbox.add(&b.max);
        }
    }
    if volume <= 0.0 {
        findings.push(format!(
            "solid #{} encloses no positive volume ({volume:.3} mm^3): its voids outweigh its outer shell",
            solid.step_id
        ));
    }
    let faces_ids = brep.solid_faces(s);
    let mut surfaces = BTreeMap::new();
    for f in &faces_ids {
        *surfaces
            .entry(brep.face_surface(*f).kind().to_string())
            .or_insert(0) += 1;
    }
    let edges = brep.edges_of(&faces_ids);
    let mut curves = BTreeMap::new();
    for e in &edges {
        *curves
            .entry(brep.edge_curve(*e).kind().to_string())
            .or_insert(0) += 1;
    }
    let centroid = if volume != 0.0 {
        moment / volume
    } else {
        moment
    };
    Ok(SolidReport {
        solid: s,
        step_id: solid.step_id,
        volume,
        area,
        centroid: [centroid.x, centroid.y, centroid.z],
        faces: faces_ids.len(),
        edges: edges.len(),
        vertices: brep.vertices_of(&faces_ids).len(),
        voids: solid.shells.len().saturating_sub(1),
        genus,
        euler,
        closed,
        surfaces,
        curves,
        bbox,
        watertight,
        findings,
    })
}
