//! Prints volume, area and checks of every solid in the STEP files given.
fn main() {
    for path in std::env::args().skip(1) {
        let t = std::time::Instant::now();
        match brep::read_step(&path) {
            Err(e) => println!("{path}: ERROR {e}"),
            Ok(part) => {
                let tr = t.elapsed();
                for s in part.brep.solid_ids() {
                    match brep::solid::report_solid(&part.brep, s) {
                        Ok(r) => println!(
                            "{path} #{}: V={:.3} A={:.3} faces={} genus={:?} closed={} watertight={} findings={:?}",
                            r.step_id, r.volume, r.area, r.faces, r.genus, r.closed, r.watertight,
                            r.findings.iter().take(3).collect::<Vec<_>>()
                        ),
                        Err(e) => println!("{path} solid {}: MESH ERROR {e}", s.0),
                    }
                }
                println!(
                    "  read {:?}, total {:?}, warnings {:?}",
                    tr,
                    t.elapsed(),
                    part.brep.warnings
                );
            }
        }
    }
}
