//! Prints the feature tree of each STEP file given.
fn main() {
    for path in std::env::args().skip(1) {
        let part = match brep::read_step(&path) {
            Ok(p) => p,
            Err(e) => {
                println!("{path}: {e}");
                continue;
            }
        };
        for s in part.brep.solid_ids() {
            let t0 = std::time::Instant::now();
            match features::extract(&part.brep, s, &Default::default()) {
                Err(e) => println!("{path}: {e}"),
                Ok(t) => {
                    let sum: f64 = t.features.iter().map(|f| f.volume).sum();
                    println!(
                        "{path} solid {}: {} features, part {:.2} sum {:.2} ({:?})",
                        s.0,
                        t.features.len(),
                        t.part_volume,
                        sum,
                        t0.elapsed()
                    );
                    for f in &t.features {
                        println!(
                            "  #{} {} {} ref={} {:?} parents={:?} vol={:.2} loops={} depth={} closed={} faces={}",
                            f.id, f.kind.as_str(), f.subtype, f.reference.surface, f.reference.step_face, f.parents, f.volume, f.root_loops, f.depth, f.closed, f.faces.len()
                        );
                    }
                    for w in &t.warnings {
                        println!("  warning: {w}");
                    }
                }
            }
        }
    }
}
