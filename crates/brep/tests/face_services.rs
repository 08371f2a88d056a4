//! Geometry services on faces: points, outward normals, projection and trimmed domains agree
//! with the solid they bound.

use brep::mesh::{face_domain, MeshOptions};
use brep::solid::mesh_solid;
use brep::topology::SolidId;
use std::path::PathBuf;

fn read(name: &str) -> brep::StepPart {
    brep::read_step(
        PathBuf::from(env!("CARGO_MANIFEST_DIR"))
            .join("../../fixtures")
            .join(name),
    )
    .expect("fixture reads")
}

#[test]
fn outward_normals_leave_the_solid_and_projection_round_trips() {
    for name in [
        "capsule.step",
        "sphere_boss.step",
        "impeller.step",
        "fan.step",
        "boss_fillet.step",
        "void_box.step",
    ] {
        let part = read(name);
        let b = &part.brep;
        // The same sampling for the mesh and the domains, so both have the same chords.
        let opts = MeshOptions::with_tolerance(0.01);
        let mesh = mesh_solid(b, SolidId(0), Some(opts)).expect("mesh");
        for ft in &mesh.faces {
            let f = ft.face;
            let domain = face_domain(b, f, &opts).expect("domain");
            // The centroid of the face's fattest triangle (farthest from its own corners), so
            // the probe is not at a boundary where another face turns away.
            let fat = ft
                .triangles
                .iter()
                .map(|t| {
                    let p: Vec<_> = t
                        .iter()
                        .map(|&i| mesh.positions[ft.vertex[i as usize] as usize])
                        .collect();
                    let c = (p[0].coords + p[1].coords + p[2].coords) / 3.0;
                    let r = p
                        .iter()
                        .map(|q| (q.coords - c).norm())
                        .fold(f64::INFINITY, f64::min);
                    (r, *t)
                })
                .max_by(|a, b| a.0.total_cmp(&b.0));
            if let Some((r, t)) = fat {
                let uv: Vec<[f64; 2]> = t.iter().map(|&i| ft.uv[i as usize]).collect();
                let (u, v) = (
                    (uv[0][0] + uv[1][0] + uv[2][0]) / 3.0,
                    (uv[0][1] + uv[1][1] + uv[2][1]) / 3.0,
                );
                let Some(n) = b.face_normal(f, u, v) else {
                    continue;
                };
                let p = b.face_point(f, u, v);
                assert!((n.norm() - 1.0).abs() < 1e-9);
                let d = (0.1 * r).clamp(0.02, 0.05);
                let out = mesh.winding_number(&(p + n * d));
                let inn = mesh.winding_number(&(p - n * d));
                assert!(out < 0.5 && inn > 0.5, "{name} face #{} ({}): winding out {out:.3}, in {inn:.3} at {p:?} uv ({u},{v}) n {n:?}", b.face(f).step_id, b.face_surface(f).kind());
                let (pu, pv) = b.face_project(f, &p);
                assert!(
                    (b.face_point(f, pu, pv) - p).norm() < 1e-6,
                    "{name} face #{}: projection",
                    b.face(f).step_id
                );
                assert!(
                    domain.contains([u, v]),
                    "{name} face #{}: ({u}, {v}) not in its own domain",
                    b.face(f).step_id
                );
            }
        }
    }
}

#[test]
fn domain_excludes_a_hole() {
    // plate_boss_boss: the plate's top face has the first boss's root as a hole; the boss axis
    // passes through the hole, so the plate top's domain must not contain the axis point.
    let part = read("plate_boss_boss.step");
    let b = &part.brep;
    let mut checked = 0;
    for f in b.solid_faces(SolidId(0)) {
        let face = b.face(f);
        if face.loops.len() == 2 && b.face_surface(f).kind() == "plane" {
            let dom = face_domain(b, f, &MeshOptions::default()).expect("domain");
            // A point inside the inner loop (its centroid) is outside the face.
            let inner = &dom.loops[1];
            let c = inner
                .iter()
                .fold([0.0, 0.0], |a, p| [a[0] + p[0], a[1] + p[1]]);
            let c = [c[0] / inner.len() as f64, c[1] / inner.len() as f64];
            assert!(
                !dom.contains(c),
                "hole centre is inside face #{}",
                face.step_id
            );
            checked += 1;
        }
    }
    assert!(checked > 0, "no planar face with a hole found");
}
