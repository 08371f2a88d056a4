//! Helpers shared by the slicer's integration tests.

use brep::math::P3;
use brep::mesh::Mesh;
use features::{extract, ExtractOptions, FeatureTree};
use std::path::PathBuf;

/// The feature tree of a fixture's (first) solid.
pub fn tree(name: &str) -> FeatureTree {
    let path = PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("../../fixtures")
        .join(format!("{name}.step"));
    let part = brep::read_step(&path).expect("fixture reads");
    let s = part.brep.solid_ids().next().expect("a solid");
    extract(&part.brep, s, &ExtractOptions::default()).expect("extracts")
}

/// The distance from `p` to the nearest triangle of `mesh` (not every test binary uses it).
#[allow(dead_code)]
pub fn distance_to_mesh(mesh: &Mesh, p: &P3) -> f64 {
    let seg = |a: &P3, b: &P3| {
        let ab = b - a;
        let t = ((p - a).dot(&ab) / ab.norm_squared().max(1e-300)).clamp(0.0, 1.0);
        (p - (a + ab * t)).norm()
    };
    mesh.triangles()
        .iter()
        .map(|t| {
            let [a, b, c] = t.map(|i| mesh.positions[i as usize]);
            let nrm = (b - a).cross(&(c - a));
            let edges = seg(&a, &b).min(seg(&b, &c)).min(seg(&c, &a));
            if nrm.norm() < 1e-15 {
                return edges;
            }
            let nu = nrm / nrm.norm();
            let h = (p - a).dot(&nu);
            let q = p - nu * h;
            // Inside the triangle: the normal distance; else the nearest edge.
            let inside = [(a, b), (b, c), (c, a)]
                .iter()
                .all(|(u, v)| (v - u).cross(&(q - u)).dot(&nrm) >= 0.0);
            if inside {
                h.abs()
            } else {
                edges
            }
        })
        .fold(f64::INFINITY, f64::min)
}
