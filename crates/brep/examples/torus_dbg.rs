//! Debug: analysis-mesh timing on one file.
fn main() {
    let path = std::env::args().nth(1).unwrap();
    let part = brep::read_step(&path).unwrap();
    let b = &part.brep;
    for tol in [0.05, 0.14, 0.5] {
        for angle in [15.0f64, 10.0] {
            let o = brep::mesh::MeshOptions { chord_tol: tol, angle_tol: angle.to_radians(), edge_chord_tol: None };
            let t = std::time::Instant::now();
            let m = brep::solid::mesh_solid(b, brep::topology::SolidId(0), Some(o)).unwrap();
            println!("tol {tol} angle {angle}: {:?} {} tris {} verts", t.elapsed(), m.triangles().len(), m.positions.len());
        }
    }
}
