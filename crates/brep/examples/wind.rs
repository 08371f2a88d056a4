//! Debug: winding numbers at a few points.
fn main() {
    let part = brep::read_step("../../fixtures/capsule.step").unwrap();
    let m = brep::solid::mesh_solid(&part.brep, brep::topology::SolidId(0), Some(brep::mesh::MeshOptions::with_tolerance(0.01))).unwrap();
    for p in [[0.0, 0.0, 20.0], [-16.253457516457306, 32.81864752589357, 25.39489532775146], [-16.253457516457306 + 0.0179, 32.81864752589357 - 0.036, 25.39489532775146 + 0.0295], [-15.0, 30.0, 25.4], [0.0, 0.0, 100.0]] {
        let p = brep::math::P3::new(p[0], p[1], p[2]);
        println!("{p:?} -> {:.4}", m.winding_number(&p));
    }
    // nearest vertex
    let q = brep::math::P3::new(-16.253457516457306, 32.81864752589357, 25.39489532775146);
    let mut best = (f64::INFINITY, 0);
    for (i, v) in m.positions.iter().enumerate() { let d = (v - q).norm(); if d < best.0 { best = (d, i); } }
    println!("nearest vertex {:?} at {}", m.positions[best.1], best.0);
    println!("tris {}", m.triangles().len());
}
