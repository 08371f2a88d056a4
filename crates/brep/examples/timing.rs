//! Debug: read and display-mesh timings.
fn main() {
    for path in std::env::args().skip(1) {
        let bytes = std::fs::read(&path).unwrap();
        let t = std::time::Instant::now();
        let part = brep::read_step_bytes(&bytes).unwrap();
        let tr = t.elapsed();
        let t = std::time::Instant::now();
        let mut tris = 0;
        for s in part.brep.solid_ids() {
            let m = brep::solid::mesh_solid(&part.brep, s, Some(Default::default())).unwrap();
            tris += m.triangles().len();
        }
        let tm = t.elapsed();
        let t = std::time::Instant::now();
        for s in part.brep.solid_ids() { let _ = brep::solid::report_solid(&part.brep, s); }
        println!("{path}: read {tr:?} mesh {tm:?} ({tris} tris) report {:?}", t.elapsed());
    }
}
