//! `cargo bench -p features --bench extract`: feature extraction time per fixture and corpus
//! file (file already read; goal: impeller under 100 ms end to end, reading included).

use std::path::{Path, PathBuf};
use std::time::{Duration, Instant};

fn median(mut v: Vec<Duration>) -> Duration {
    v.sort();
    v[v.len() / 2]
}

fn files(dir: &Path) -> Vec<PathBuf> {
    let mut v: Vec<PathBuf> = std::fs::read_dir(dir)
        .map(|d| {
            d.filter_map(|e| e.ok())
                .map(|e| e.path())
                .filter(|p| p.extension().is_some_and(|x| x == "step"))
                .collect()
        })
        .unwrap_or_default();
    v.sort();
    v
}

fn main() {
    let root = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../..");
    let mut all = files(&root.join("fixtures"));
    all.extend(files(&root.join("../shared/corpus")));
    println!("goal: impeller read + extract < 100 ms");
    println!(
        "{:<40} {:>7} {:>9} {:>11} {:>11}",
        "file", "solids", "features", "read ms", "extract ms"
    );
    for path in all {
        let name = path
            .file_name()
            .map(|n| n.to_string_lossy().into_owned())
            .unwrap_or_default();
        let Ok(bytes) = std::fs::read(&path) else {
            continue;
        };
        let Ok(part) = brep::read_step_bytes(&bytes) else {
            println!("{name:<40} unreadable");
            continue;
        };
        let run = || {
            let mut n = 0;
            for s in part.brep.solid_ids() {
                if let Ok(t) = features::extract(&part.brep, s, &Default::default()) {
                    n += t.features.len();
                }
            }
            n
        };
        let n = run();
        let (mut reads, mut extracts) = (vec![], vec![]);
        let start = Instant::now();
        while reads.len() < 3 || (start.elapsed() < Duration::from_millis(800) && reads.len() < 30)
        {
            let t = Instant::now();
            let _ = brep::read_step_bytes(&bytes);
            reads.push(t.elapsed());
            let t = Instant::now();
            let _ = run();
            extracts.push(t.elapsed());
        }
        println!(
            "{name:<40} {:>7} {:>9} {:>11.2} {:>11.2}",
            part.brep.solids.len(),
            n,
            median(reads).as_secs_f64() * 1e3,
            median(extracts).as_secs_f64() * 1e3
        );
    }
}
