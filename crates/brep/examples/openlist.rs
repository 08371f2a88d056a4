//! Debug: list open mesh edges with the faces that own them.
use std::collections::HashMap;
fn main() {
    let path = std::env::args().nth(1).unwrap();
    let part = brep::read_step(&path).unwrap();
    let b = &part.brep;
    let s = b.solid_ids().next().unwrap();
    let mesh = brep::solid::mesh_solid(b, s, None).unwrap();
    let mut count: HashMap<(u32, u32), Vec<(u64, bool)>> = HashMap::new();
    for f in &mesh.faces {
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
                count
                    .entry((a.min(c), a.max(c)))
                    .or_default()
                    .push((b.face(f.face).step_id, a < c));
            }
        }
    }
    let mut n = 0;
    for (k, v) in &count {
        if v.len() != 2 || v[0].1 == v[1].1 {
            n += 1;
            if n < 15 {
                println!(
                    "edge {:?} {:?} {:?} -> {:?}",
                    k, mesh.positions[k.0 as usize], mesh.positions[k.1 as usize], v
                );
            }
        }
    }
    println!("{n} bad edges");
}
