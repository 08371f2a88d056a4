//! Debug: per-face volume contributions, quadrature vs flat triangles.
fn main() {
    let path = std::env::args().nth(1).unwrap();
    let part = brep::read_step(&path).unwrap();
    let b = &part.brep;
    for s in b.solid_ids() {
        let mesh = brep::solid::mesh_solid(b, s, None).unwrap();
        let c = mesh.bbox();
        let c = nalgebra::center(&c.min, &c.max);
        let (mut tq, mut tf) = (0.0, 0.0);
        for ft in &mesh.faces {
            let one = brep::mesh::Mesh { positions: mesh.positions.clone(), faces: vec![ft.clone()] };
            let q = brep::mass::mass_properties(b, &one);
            // flat
            let mut fv = 0.0;
            for t in &ft.triangles {
                let p: Vec<_> = t.iter().map(|&i| mesh.positions[ft.vertex[i as usize] as usize] - c).collect();
                fv += p[0].dot(&p[1].cross(&p[2])) / 6.0;
            }
            // re-centre quadrature volume: mass_properties uses its own bbox centre, so recompute flat with that
            let cc = one.bbox();
            let _ = cc;
            tq += q.volume; tf += fv;
            let face = b.face(ft.face);
            println!("face #{} {} sense={} quad_area={:.4} flatvol={:.4}", face.step_id, b.face_surface(ft.face).kind(), face.same_sense, q.area, fv);
        }
        let all = brep::mass::mass_properties(b, &mesh);
        println!("total quad vol {:.4} flat vol {:.4}", all.volume, tf);
        let _ = tq;
    }
}
