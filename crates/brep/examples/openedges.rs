//! Debug: which faces border open mesh edges.
use std::collections::HashMap;
fn main() {
    let path = std::env::args().nth(1).unwrap();
    let part = brep::read_step(&path).unwrap();
    let b = &part.brep;
    for s in b.solid_ids() {
        let t = std::time::Instant::now();
        let mesh = brep::solid::mesh_solid(b, s, None).unwrap();
        println!(
            "solid {} mesh {:?} tris {}",
            s.0,
            t.elapsed(),
            mesh.triangles().len()
        );
        let mut count: HashMap<(u32, u32), Vec<usize>> = HashMap::new();
        for (fi, f) in mesh.faces.iter().enumerate() {
            for tr in &f.triangles {
                let g = [
                    f.vertex[tr[0] as usize],
                    f.vertex[tr[1] as usize],
                    f.vertex[tr[2] as usize],
                ];
                if g[0] == g[1] || g[1] == g[2] || g[0] == g[2] {
                    continue;
                }
                for k in 0..3 {
                    let (a, c) = (g[k], g[(k + 1) % 3]);
                    count.entry((a.min(c), a.max(c))).or_default().push(fi);
                }
            }
        }
        let mut per_face: HashMap<usize, usize> = HashMap::new();
        for v in count.values() {
            if v.len() != 2 {
                for f in v {
                    *per_face.entry(*f).or_default() += 1;
                }
            }
        }
        let mut pf: Vec<_> = per_face.into_iter().collect();
        pf.sort_by_key(|x| std::cmp::Reverse(x.1));
        for (fi, n) in pf.iter().take(8) {
            let ft = &mesh.faces[*fi];
            let face = b.face(ft.face);
            let kinds: Vec<String> = face
                .loops
                .iter()
                .map(|l| format!("{}ce", b.loops[l.idx()].coedges.len()))
                .collect();
            println!(
                "  face #{} {} same_sense={} loops={:?} open-edge-uses={} tris={}",
                face.step_id,
                b.face_surface(ft.face).kind(),
                face.same_sense,
                kinds,
                n,
                ft.triangles.len()
            );
        }
        // Slowest faces
        let mut times = vec![];
        for f in b.solid_faces(s) {
            let t = std::time::Instant::now();
            let opts = brep::solid::analysis_options(100.0);
            let _ = brep::mesh::mesh_faces(b, &[f], &opts);
            times.push((t.elapsed(), b.face(f).step_id, b.face_surface(f).kind()));
        }
        times.sort();
        times.reverse();
        println!("  slowest: {:?}", &times[..times.len().min(4)]);
    }
}
