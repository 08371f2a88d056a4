//! Debug: dump one face's uv triangulation as JSON.
fn main() {
    let mut a = std::env::args().skip(1);
    let path = a.next().unwrap();
    let id: u64 = a.next().unwrap().parse().unwrap();
    let part = brep::read_step(&path).unwrap();
    let b = &part.brep;
    let f = (0..b.faces.len() as u32)
        .map(brep::topology::FaceId)
        .find(|f| b.face(*f).step_id == id)
        .unwrap();
    let s = b.solid_ids().next().unwrap();
    let opts = brep::solid::analysis_options(
        b.vertices
            .iter()
            .fold(brep::math::Aabb::empty(), |mut bb, v| {
                bb.add(&v.point);
                bb
            })
            .diagonal(),
    );
    let all = b.solid_faces(s);
    let mesh = brep::mesh::mesh_faces(b, &all, &opts).unwrap();
    let ft = mesh.faces.iter().find(|x| x.face == f).unwrap();
    println!(
        "{{\"uv\": {:?}, \"vertex\": {:?}, \"tris\": {:?}}}",
        ft.uv, ft.vertex, ft.triangles
    );
}
